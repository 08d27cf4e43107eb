//! The committed JSON Schema of `scene.json` must match the one generated from the types.
//! Regenerate with `NESY_UPDATE_SCHEMA=1 cargo test -p nesy-sim --test integration schema::`.

#[test]
fn committed_scene_schema_is_current() {
    let path = nesy_testkit::workspace_root().join("assets/schema/scene.schema.json");
    let generated = nesy_sim::scene::json_schema();
    if std::env::var_os("NESY_UPDATE_SCHEMA").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale; regenerate it with NESY_UPDATE_SCHEMA=1 cargo test -p nesy-sim --test integration schema::",
        path.display()
    );
}

#[test]
fn fixture_scenes_round_trip_through_the_types() {
    let dir = nesy_testkit::workspace_root().join("fixtures/scenes");
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let spec = nesy_sim::scene::SceneSpec::from_file(&path).unwrap();
        let again = nesy_sim::scene::SceneSpec::from_json_str(&spec.to_json_pretty(), "round trip").unwrap();
        assert_eq!(spec, again, "{}", path.display());
    }
}
