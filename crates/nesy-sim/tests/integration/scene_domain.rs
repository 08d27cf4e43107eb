//! The true domain of a scene with several articulated assets: each asset's schemas under
//! its own part names, the `Blocks` relation the observer finds in the geometry, and the
//! precondition that keeps a drawer shut while another one stands open in its way.

use nesy_core::text::parse_formula;
use nesy_core::{Atom, Embodiment, State};
use nesy_sim::codegen::{compile_policy, resolve_action};
use nesy_sim::domain::{Planning, WorldDomain, control_planner_config, schema_instance};
use nesy_sim::perception::observer::{self, BLOCKS};
use nesy_sim::scene::SceneSpec;
use nesy_sim::world::Sim;

/// The two cabinets at right angles of `fixtures/scenes/drawers_perpendicular_finger.json`,
/// with `side_top_drawer` at `side_top` and a cube on the table.
fn perpendicular_cabinets(side_top: f64) -> SceneSpec {
    let mut scene =
        SceneSpec::from_file(&nesy_testkit::scene_fixture("drawers_perpendicular_finger")).unwrap();
    scene.articulations.insert("side_top_drawer".into(), side_top);
    scene
}

/// The same two cabinets side by side, both facing −y: nothing stands in another's way.
fn side_by_side_cabinets() -> SceneSpec {
    let text = r#"{
      "schema_version": 1,
      "embodiment": "finger",
      "objects": [
        { "name": "front_drawer_body", "kind": "drawer_cabinet", "pose": { "position": [0.46, 0.19, 0.5], "yaw": 0.0 } },
        { "name": "side_drawer_body", "kind": "drawer_cabinet", "pose": { "position": [0.46, -0.19, 0.5], "yaw": 0.0 } }
      ],
      "goals": []
    }"#;
    SceneSpec::from_json_str(text, "side by side").unwrap()
}

fn blocks(a: &str, b: &str) -> Atom {
    Atom::new(BLOCKS, &[a, b])
}

#[test]
fn drawers_at_right_angles_block_the_drawer_at_their_own_height() {
    let sim = Sim::new(&perpendicular_cabinets(0.0)).unwrap();
    let mut pairs = sim.blocking_pairs();
    pairs.sort();
    let expected: Vec<(String, String)> = [
        ("front_bottom_drawer", "side_bottom_drawer"),
        ("front_top_drawer", "side_top_drawer"),
        ("side_bottom_drawer", "front_bottom_drawer"),
        ("side_top_drawer", "front_top_drawer"),
    ]
    .iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect();
    assert_eq!(pairs, expected);
    let state = observer::observe(&sim);
    assert!(
        state.contains(&blocks("side_top_drawer", "front_top_drawer")),
        "{state:?}"
    );
    assert!(!state.contains(&blocks("side_top_drawer", "front_bottom_drawer")));

    let apart = Sim::new(&side_by_side_cabinets()).unwrap();
    assert!(apart.blocking_pairs().is_empty(), "{:?}", apart.blocking_pairs());
    let state = observer::observe(&apart);
    assert!(!state.iter().any(|a| a.pred().as_str() == BLOCKS), "{state:?}");
}

fn scene_names(scene: &SceneSpec) -> Vec<String> {
    let mut names = scene.part_names();
    names.push("floor".into());
    names
}

#[test]
fn each_cabinet_has_its_own_schemas_and_opening_one_needs_the_other_shut() {
    let world = WorldDomain::builtin().unwrap();
    let names = scene_names(&perpendicular_cabinets(0.0));
    let universe = world.universe(names.iter().map(String::as_str));
    let schemas = world.schemas_for(Embodiment::Finger, &universe);
    let find = |name: &str| {
        schemas
            .iter()
            .find(|s| s.name == name)
            .unwrap_or_else(|| panic!("no schema {name}"))
    };
    let open = find("open-front-top-drawer");
    let pre: Vec<String> = open.pre.iter().map(ToString::to_string).collect();
    assert!(pre.contains(&"(Closed front_top_drawer)".to_owned()), "{pre:?}");
    for other in ["side_top_drawer", "side_bottom_drawer"] {
        let kept_shut = format!("(not (and (Blocks {other} front_top_drawer) (Open {other})))");
        assert!(pre.contains(&kept_shut), "{kept_shut} missing from {pre:?}");
    }
    assert!(
        !pre.iter().any(|p| p.contains("front_bottom_drawer)")),
        "a cabinet's own drawers do not block each other: {pre:?}"
    );
    let grasp = find("grasp-side-bottom-drawer-handle");
    assert!(
        grasp
            .pre
            .iter()
            .any(|p| p.to_string() == "(not (OnTopOf side_top_drawer side_bottom_drawer_handle))"),
        "the covered-handle rule renamed for the side cabinet"
    );
    // Reaching for a handle goes where the other cabinet's open drawer would stand.
    for reach in [
        "move-to-side-bottom-drawer-handle",
        "grasp-side-bottom-drawer-handle",
    ] {
        let pre: Vec<String> = find(reach).pre.iter().map(ToString::to_string).collect();
        let kept_shut =
            "(not (and (Blocks front_bottom_drawer side_bottom_drawer) (Open front_bottom_drawer)))"
                .to_owned();
        assert!(
            pre.contains(&kept_shut),
            "{reach}: {kept_shut} missing from {pre:?}"
        );
    }
    // No bare-named schema survives for parts the scene does not have.
    assert!(schemas.iter().all(|s| s.name != "open-top-drawer"));
    let instance = schema_instance("open-front-top-drawer").unwrap();
    assert_eq!(instance.part().as_deref(), Some("front_top_drawer"));
}

#[test]
fn a_scene_with_one_bare_named_asset_keeps_the_domain_file_schemas() {
    let world = WorldDomain::builtin().unwrap();
    let names = [
        "floor",
        "red_cube",
        "drawer_body",
        "top_drawer",
        "bottom_drawer",
        "top_drawer_handle",
    ];
    let universe = world.universe(names);
    let schemas = world.schemas_for(Embodiment::Finger, &universe);
    let in_file: Vec<_> = world
        .domain
        .actions
        .iter()
        .filter(|a| {
            nesy_sim::domain::schema_embodiment(a) == Embodiment::Finger
                && a.constants().iter().all(|c| universe.contains(*c))
        })
        .cloned()
        .collect();
    assert_eq!(schemas, in_file);
}

#[test]
fn the_planner_shuts_the_drawer_in_the_way_before_opening_the_other() {
    let scene = perpendicular_cabinets(0.12);
    let sim = Sim::new(&scene).unwrap();
    let state: State = observer::observe(&sim);
    assert!(
        state.contains(&Atom::new("Open", &["side_top_drawer"])),
        "{state:?}"
    );
    let world = WorldDomain::builtin().unwrap();
    let names = scene_names(&scene);
    let config = control_planner_config();
    let planning = Planning::over(
        world,
        names.iter().map(String::as_str),
        Embodiment::Finger,
        &config,
    );
    let goal = parse_formula("(Open front_top_drawer)").unwrap();
    let (plan, end) = planning.plan(&state, &goal).expect("a plan");
    let steps: Vec<&str> = plan.iter().map(|op| op.name.as_str()).collect();
    let close = steps.iter().position(|s| *s == "CloseSideTopDrawer");
    let open = steps.iter().position(|s| *s == "OpenFrontTopDrawer");
    assert!(
        matches!((close, open), (Some(c), Some(o)) if c < o),
        "the side drawer is closed before the front one opens: {steps:?}"
    );
    assert!(end.contains(&Atom::new("Open", &["front_top_drawer"])));

    // The plan compiles to a program that names the cabinets' own parts and opens the front
    // drawer along −y and closes the side one along x.
    let objects: Vec<String> = names.clone();
    let resolved = resolve_action("CloseSideTopDrawer", &objects).expect("resolves");
    assert_eq!(resolved.schema, "close-side-top-drawer");
    let policy = compile_policy(&plan, &objects, Embodiment::Finger, false).expect("compiles");
    assert!(
        policy.code.contains("grasp_handle(\"side_top_drawer_handle\")"),
        "{}",
        policy.code
    );
    assert!(
        policy.code.contains("get_obj_pos(\"side_drawer_body\")"),
        "{}",
        policy.code
    );
    assert!(!policy.code.contains("\"top_drawer_handle\""), "{}", policy.code);
}
