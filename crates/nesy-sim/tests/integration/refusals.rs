//! Calls the robot must refuse, each with its typed error and without moving; scene files
//! that must not load, each with an error naming the JSON path.

use crate::common;

use common::{expect, load};
use nesy_core::Embodiment;
use nesy_sim::api::{ApiError, Direction, RobotApi};
use nesy_sim::scene::{SceneError, SceneSpec};
use nesy_sim::world::{Sim, SimConfig};
use nesy_testkit::scene_fixture;

fn wrong_embodiment(result: Result<(), ApiError>, call: &str, use_instead: &str, embodiment: Embodiment) {
    match result {
        Err(ApiError::WrongEmbodiment {
            call: c,
            embodiment: e,
            use_instead: u,
        }) => {
            assert_eq!((c.as_str(), e, u.as_str()), (call, embodiment, use_instead));
        }
        other => panic!("{call}: expected WrongEmbodiment, got {other:?}"),
    }
}

#[test]
fn vacuum_calls_on_the_finger_robot_and_the_reverse() {
    let mut sim = load("pick_place_finger");
    let q = sim.arm_joints().to_vec();
    wrong_embodiment(
        sim.activate_vacuum(),
        "activate_vacuum",
        "close_gripper",
        Embodiment::Finger,
    );
    wrong_embodiment(
        sim.deactivate_vacuum(),
        "deactivate_vacuum",
        "open_gripper",
        Embodiment::Finger,
    );
    wrong_embodiment(
        sim.attach_vacuum_handle("x"),
        "attach_vacuum_handle",
        "grasp_handle",
        Embodiment::Finger,
    );
    wrong_embodiment(
        sim.detach_vacuum_handle(),
        "detach_vacuum_handle",
        "release_handle",
        Embodiment::Finger,
    );
    assert_eq!(sim.arm_joints(), q.as_slice());
    assert_eq!(sim.trace().len(), 4);
    let mut sim = load("pick_place_vacuum");
    wrong_embodiment(
        sim.close_gripper(),
        "close_gripper",
        "activate_vacuum",
        Embodiment::Vacuum,
    );
    wrong_embodiment(
        sim.open_gripper(),
        "open_gripper",
        "deactivate_vacuum",
        Embodiment::Vacuum,
    );
    wrong_embodiment(
        sim.grasp_handle("x"),
        "grasp_handle",
        "attach_vacuum_handle",
        Embodiment::Vacuum,
    );
    wrong_embodiment(
        sim.release_handle(),
        "release_handle",
        "detach_vacuum_handle",
        Embodiment::Vacuum,
    );
    expect(&sim, "refusals", &["(VacuumInactive)"], &["(VacuumActive)"]);
}

#[test]
fn a_cube_under_another_cube_is_refused() {
    for scene in ["pick_place_finger", "pick_place_vacuum"] {
        let mut sim = load(scene);
        let q = sim.arm_joints().to_vec();
        let t = sim.time();
        match sim.move_gripper_to("blue_cube", Direction::Down, 0.015) {
            Err(ApiError::Infeasible { call, target, reason }) => {
                assert_eq!((call.as_str(), target.as_str()), ("move_gripper_to", "blue_cube"));
                assert!(reason.contains("green_cube"), "{reason}");
            }
            other => panic!("expected Infeasible, got {other:?}"),
        }
        assert_eq!(
            sim.arm_joints(),
            q.as_slice(),
            "a refused call does not move the robot"
        );
        assert_eq!(sim.time(), t);
        assert!(sim.trace()[0].result.is_err());
        // The top cube is fine.
        sim.move_gripper_to("green_cube", Direction::Down, 0.015).unwrap();
    }
}

#[test]
fn the_bottom_handle_under_the_open_top_drawer_is_refused() {
    let mut sim = load("drawer_blocked_finger");
    expect(
        &sim,
        "reset",
        &["(OnTopOf top_drawer bottom_drawer_handle)", "(Open top_drawer)"],
        &[],
    );
    let q = sim.arm_joints().to_vec();
    for result in [
        sim.move_gripper_to("bottom_drawer_handle", Direction::Down, 0.0),
        sim.grasp_handle("bottom_drawer_handle"),
    ] {
        match result {
            Err(ApiError::Infeasible { reason, .. }) => assert!(reason.contains("top_drawer"), "{reason}"),
            other => panic!("expected Infeasible, got {other:?}"),
        }
    }
    assert_eq!(sim.arm_joints(), q.as_slice());
    // Closing the top drawer first uncovers it.
    sim.move_gripper_to("top_drawer_handle", Direction::Down, 0.0)
        .unwrap();
    sim.grasp_handle("top_drawer_handle").unwrap();
    let dy = sim.get_obj_size("bottom_drawer").unwrap()[1] * 0.85;
    sim.move_parallel(Direction::Right, dy, Direction::Down).unwrap();
    sim.release_handle().unwrap();
    expect(
        &sim,
        "top closed",
        &["(Closed top_drawer)"],
        &["(OnTopOf top_drawer bottom_drawer_handle)"],
    );
    sim.move_gripper_to("bottom_drawer_handle", Direction::Down, 0.0)
        .unwrap();
    sim.grasp_handle("bottom_drawer_handle").unwrap();
    sim.move_parallel(Direction::Left, dy, Direction::Down).unwrap();
    sim.release_handle().unwrap();
    expect(
        &sim,
        "bottom opened",
        &["(Open bottom_drawer)", "(Closed top_drawer)"],
        &[],
    );
}

#[test]
fn unreachable_and_out_of_workspace_targets_are_refused() {
    let mut sim = load("pick_place_finger");
    let q = sim.arm_joints().to_vec();
    // Inside FLOOR_AABB's footprint but beyond the arm's reach.
    match sim.move_to_position([0.72, 0.6, 0.52], Direction::Down, 0.12, 0.0) {
        Err(ApiError::IkFailed { target, pointing_to }) => {
            assert_eq!(target, [0.72, 0.6, 0.52]);
            assert_eq!(pointing_to, Direction::Down);
        }
        other => panic!("expected IkFailed, got {other:?}"),
    }
    // Outside the workspace.
    assert!(matches!(
        sim.move_to_position([1.0, 0.0, 0.6], Direction::Down, 0.12, 0.0),
        Err(ApiError::OutOfWorkspace { .. })
    ));
    assert!(matches!(
        sim.move_parallel(Direction::Back, 0.5, Direction::Down),
        Err(ApiError::OutOfWorkspace { .. })
    ));
    assert!(matches!(
        sim.move_parallel(Direction::Left, -0.1, Direction::Down),
        Err(ApiError::InvalidArgument { .. })
    ));
    assert_eq!(sim.arm_joints(), q.as_slice());
    assert!(matches!(
        sim.get_obj_pos("unicorn"),
        Err(ApiError::UnknownObject { .. })
    ));
}

#[test]
fn a_lid_with_fruit_on_it_cannot_be_opened() {
    let text = std::fs::read_to_string(scene_fixture("hinge_finger")).unwrap();
    let mut spec = SceneSpec::from_json_str(&text, "hinge").unwrap();
    // Put the apple on the closed lid (lid top at 0.6265 + handle clearance).
    spec.objects[1].pose.position = [0.525, 0.02, 0.627];
    let mut sim = Sim::new(&spec).unwrap();
    expect(&sim, "reset", &["(OnTopOf apple hinge_lid)"], &[]);
    sim.move_gripper_to("hinge_handle", Direction::Down, 0.0).unwrap();
    match sim.grasp_handle("hinge_handle") {
        Err(ApiError::Infeasible { reason, .. }) => assert!(reason.contains("apple"), "{reason}"),
        other => panic!("expected Infeasible, got {other:?}"),
    }
    assert_eq!(sim.grasped_handle(), None);
}

#[test]
fn an_object_wider_than_the_opening_is_not_grasped() {
    let text = std::fs::read_to_string(scene_fixture("pick_place_finger")).unwrap();
    let mut spec = SceneSpec::from_json_str(&text, "wide").unwrap();
    spec.objects[1].size = Some([0.1, 0.1, 0.03]);
    spec.objects[1].pose.yaw = 0.0;
    spec.objects[1].pose.position = [0.45, -0.3, 0.5];
    let mut sim = Sim::new(&spec).unwrap();
    sim.move_gripper_to("red_cube", Direction::Down, 0.015).unwrap();
    sim.close_gripper().unwrap();
    assert_eq!(sim.held_object(), None);
    expect(
        &sim,
        "close",
        &["(GripperClosed)"],
        &["(GripperHolding red_cube)"],
    );
}

#[test]
fn the_action_budget_is_enforced() {
    let text = std::fs::read_to_string(scene_fixture("pick_place_finger")).unwrap();
    let spec = SceneSpec::from_json_str(&text, "budget").unwrap();
    let mut sim = Sim::with_config(
        &spec,
        SimConfig {
            action_budget: 2,
            ..SimConfig::default()
        },
    )
    .unwrap();
    sim.open_gripper().unwrap();
    sim.get_obj_names(); // perception is free
    sim.close_gripper().unwrap();
    assert_eq!(sim.open_gripper(), Err(ApiError::BudgetExhausted { limit: 2 }));
    assert_eq!(sim.trace().len(), 4);
}

fn load_error(mutate: impl FnOnce(&mut serde_json::Value)) -> SceneError {
    let text = std::fs::read_to_string(scene_fixture("pick_place_finger")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    mutate(&mut json);
    let text = serde_json::to_string_pretty(&json).unwrap();
    match SceneSpec::from_json_str(&text, "bad.json").and_then(|s| Sim::new(&s)) {
        Ok(_) => panic!("scene loaded"),
        Err(e) => e,
    }
}

#[test]
fn malformed_scenes_name_the_json_path_and_the_expectation() {
    let e = load_error(|j| j["objects"][1]["kind"] = "sphere".into());
    assert_eq!(e.json_path(), Some("objects[1].kind"));
    assert!(
        e.to_string()
            .contains("unknown variant `sphere`, expected one of `cube`"),
        "{e}"
    );

    let e = load_error(|j| j["embodiment"] = "suction".into());
    assert_eq!(e.json_path(), Some("embodiment"));
    assert!(e.to_string().contains("expected `finger` or `vacuum`"), "{e}");

    // Not a string at all: the same two choices, not serde's bare "expected value".
    let e = load_error(|j| j["embodiment"] = 5.into());
    assert_eq!(e.json_path(), Some("embodiment"));
    assert!(
        e.to_string()
            .contains("invalid type: integer `5`, expected `finger` or `vacuum`"),
        "{e}"
    );

    let e = load_error(|j| j["objects"][2]["size"] = serde_json::json!([0.03, -0.03, 0.03]));
    assert_eq!(e.json_path(), Some("objects[2].size[1]"));
    assert!(
        e.to_string()
            .contains("expected a size in metres from 0.001 to 2"),
        "{e}"
    );

    let e = load_error(|j| j["objects"][2]["size"] = serde_json::json!([0.03, 1e-300, 0.03]));
    assert_eq!(e.json_path(), Some("objects[2].size[1]"));

    // Values that would overflow the simulator's f32, or are simply far off the table.
    for (k, v) in [(0, 1e308), (0, 3.5e38), (1, 100.0), (2, -5.0)] {
        let e = load_error(|j| j["objects"][1]["pose"]["position"][k] = v.into());
        assert_eq!(
            e.json_path(),
            Some(format!("objects[1].pose.position[{k}]").as_str()),
            "{v}"
        );
        assert!(e.to_string().contains("a position in metres from"), "{e}");
    }

    let e = load_error(|j| j["goals"][0]["objects"] = serde_json::json!([]));
    assert_eq!(e.json_path(), Some("goals[0].objects"));
    assert!(e.to_string().contains("at least one object"), "{e}");

    let e = load_error(|j| {
        let cube = j["objects"][1].clone();
        let objects = j["objects"].as_array_mut().unwrap();
        for i in 0..2000 {
            let mut c = cube.clone();
            c["name"] = format!("cube_{i}").into();
            objects.push(c);
        }
    });
    assert_eq!(e.json_path(), Some("objects"));
    assert!(e.to_string().contains("at most 100 objects"), "{e}");

    let e = load_error(|j| j["objects"][3]["name"] = "red_cube".into());
    assert_eq!(e.json_path(), Some("objects[3].name"));
    assert!(e.to_string().contains("duplicate \"red_cube\""), "{e}");

    let e = load_error(|j| j["objects"][1]["pose"]["position"] = serde_json::json!([0.52, -0.13, 0.5]));
    assert_eq!(e.json_path(), Some("objects[2].pose"));
    assert!(e.to_string().contains("overlapping objects[1] (red_cube)"), "{e}");

    let e = load_error(|j| j["schema_version"] = 7.into());
    assert_eq!(e.json_path(), Some("schema_version"));

    let e = load_error(|j| j["goals"][0]["objects"][0] = "grey_cube".into());
    assert_eq!(e.json_path(), Some("goals[0].objects[0]"));

    let e = load_error(|j| j["articulations"] = serde_json::json!({"hinge_lid": 0.0}));
    assert_eq!(e.json_path(), Some("articulations.hinge_lid"));

    // JSON has no NaN: a NaN pose is a syntax error at its position; a value serde cannot
    // represent as finite is refused by validation.
    let text = std::fs::read_to_string(scene_fixture("pick_place_finger")).unwrap();
    let bad = text.replacen("[0.6, -0.1, 0.5]", "[0.6, NaN, 0.5]", 1);
    let e = SceneSpec::from_json_str(&bad, "nan.json").unwrap_err();
    assert_eq!(e.json_path(), Some("objects[1].pose.position[1]"));
    assert!(
        matches!(
            e,
            SceneError::Json {
                line: 8,
                column: 71,
                ..
            }
        ),
        "{e}"
    );
    let mut spec = SceneSpec::from_json_str(&text, "ok").unwrap();
    spec.objects[1].pose.position[1] = f64::NAN;
    let e = Sim::new(&spec).err().unwrap();
    assert_eq!(e.json_path(), Some("objects[1].pose.position[1]"));
    assert!(
        e.to_string().contains("a position in metres from -2 to 2") && e.to_string().contains("NaN"),
        "{e}"
    );
}

#[test]
fn every_fixture_scene_loads() {
    for entry in std::fs::read_dir(scene_fixture("x").parent().unwrap()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            Sim::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let spec = SceneSpec::from_json_str(
        r#"{"schema_version": 1, "embodiment": "vacuum", "objects": []}"#,
        "empty",
    )
    .unwrap();
    let mut sim = Sim::new(&spec).unwrap();
    assert_eq!(
        sim.get_obj_names(),
        vec!["floor".to_owned(), "vacuum_gripper".to_owned()]
    );
    assert!(matches!(
        sim.move_gripper_to("floor", Direction::Down, 0.01),
        Err(ApiError::Infeasible { .. })
    ));
    assert!(matches!(
        sim.move_to_position([f64::NAN, 0.0, 0.6], Direction::Down, 0.12, 0.0),
        Err(ApiError::OutOfWorkspace { .. })
    ));
    assert!(matches!(
        sim.move_to_position([0.4, 0.0, 0.6], Direction::Down, f64::INFINITY, 0.0),
        Err(ApiError::InvalidArgument { .. })
    ));
    assert!(matches!(
        sim.move_parallel(Direction::Up, f64::NAN, Direction::Down),
        Err(ApiError::InvalidArgument { .. })
    ));
    assert_eq!(sim.get_obj_pos("floor").unwrap()[2], 0.5);
    let views = nesy_sim::perception::render::render_views(&sim, 0, 2);
    assert!(views.iter().all(|v| v.image.rgb.is_empty()));
    let views = nesy_sim::perception::render::render_views(&sim, 17, 3);
    assert!(
        views
            .iter()
            .all(|v| v.image.rgb.len() == 17 * 17 * 3 && v.marked.rgb.len() == 17 * 17 * 3)
    );
    assert!(SceneSpec::from_json_str("{", "truncated").is_err());
    assert!(SceneSpec::from_json_str("", "empty").is_err());
}
