//! Several articulated assets in one scene: prefixed part names, and a drawer opened into
//! another cabinet's open drawer stopped where the two meet.

use nesy_sim::api::{ApiError, Direction, RobotApi};
use nesy_sim::perception::observer;
use nesy_sim::scene::SceneSpec;
use nesy_sim::scene::parts::DRAWER_OPEN;
use nesy_sim::world::Sim;

/// Two cabinets at right angles: `front_` faces −y (its drawers open toward −y), `side_`
/// is turned a quarter turn so that its drawers open toward +x, across the front cabinet's
/// drawer path. `side_top_drawer` starts at `side_top`.
fn perpendicular_cabinets(side_top: f64) -> SceneSpec {
    let scene = serde_json::json!({
        "schema_version": 1,
        "embodiment": "finger",
        "objects": [
            {"name": "front_drawer_body", "kind": "drawer_cabinet",
             "pose": {"position": [0.46, 0.19, 0.5], "yaw": 0.0}},
            {"name": "side_drawer_body", "kind": "drawer_cabinet",
             "pose": {"position": [0.30, 0.0, 0.5], "yaw": std::f64::consts::FRAC_PI_2}}
        ],
        "articulations": {"side_top_drawer": side_top},
        "goals": []
    });
    SceneSpec::from_json_str(&scene.to_string(), "perpendicular cabinets").unwrap()
}

/// Grasps the front cabinet's top handle from above and pulls it open by a full travel.
fn pull_front_top_drawer(sim: &mut Sim) -> Result<(), ApiError> {
    sim.move_gripper_to("front_top_drawer_handle", Direction::Down, 0.01)
        .expect("reach the handle");
    sim.grasp_handle("front_top_drawer_handle")
        .expect("grasp the handle");
    sim.move_parallel(Direction::Left, DRAWER_OPEN, Direction::Down)
}

#[test]
fn every_asset_names_its_parts_after_its_body() {
    let scene = perpendicular_cabinets(0.0);
    let names = scene.part_names();
    for part in [
        "front_drawer_body",
        "front_top_drawer",
        "front_bottom_drawer_handle",
        "side_drawer_body",
        "side_bottom_drawer",
        "side_top_drawer_handle",
    ] {
        assert!(names.iter().any(|n| n == part), "{part} missing from {names:?}");
    }
    let sim = Sim::new(&scene).unwrap();
    assert_eq!(sim.articulation_q("side_top_drawer"), Some(0.0));
    assert_eq!(sim.articulations().len(), 4);
    let state = format!("{:?}", observer::observe(&sim));
    assert!(state.contains("front_top_drawer"), "{state}");
}

#[test]
fn a_drawer_opened_into_another_open_drawer_stops_at_contact() {
    // Clear: the side cabinet's drawers are closed, the front drawer opens fully.
    let mut sim = Sim::new(&perpendicular_cabinets(0.0)).unwrap();
    pull_front_top_drawer(&mut sim).expect("the way is clear");
    let open = sim.articulation_q("front_top_drawer").unwrap();
    assert!(open > DRAWER_OPEN - 0.01, "travel {open:.4} with the way clear");

    // Blocked: the side cabinet's open top drawer lies across the front drawer's path.
    let mut sim = Sim::new(&perpendicular_cabinets(DRAWER_OPEN)).unwrap();
    match pull_front_top_drawer(&mut sim) {
        Err(ApiError::Collision {
            call,
            moving,
            obstacle,
        }) => {
            assert_eq!(call, "move_parallel");
            assert_eq!(moving, "front_top_drawer");
            assert_eq!(obstacle, "side_top_drawer");
        }
        other => panic!("expected a collision, got {other:?}"),
    }
    let stopped = sim.articulation_q("front_top_drawer").unwrap();
    // The front panel starts 4.5 cm from the side drawer's wall.
    assert!(
        (0.03..0.05).contains(&stopped),
        "the drawer stopped after {stopped:.4} m"
    );
    assert_eq!(sim.articulation_q("side_top_drawer"), Some(DRAWER_OPEN));
    assert_eq!(sim.grasped_handle(), Some("front_top_drawer_handle"));
    // Pushing it closed again is not hindered.
    sim.move_parallel(Direction::Right, stopped, Direction::Down)
        .expect("closing is clear");
    assert!(sim.articulation_q("front_top_drawer").unwrap() < 0.01);
}

#[test]
fn a_second_asset_needs_its_own_prefix() {
    let scene = serde_json::json!({
        "schema_version": 1,
        "embodiment": "finger",
        "objects": [
            {"name": "drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}},
            {"name": "drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.30, 0.0, 0.5]}}
        ]
    });
    let err = SceneSpec::from_json_str(&scene.to_string(), "twice")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("objects[1].name") && err.contains("duplicate"),
        "{err}"
    );
    let scene = serde_json::json!({
        "schema_version": 1,
        "embodiment": "finger",
        "objects": [{"name": "leftdrawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}}]
    });
    let err = SceneSpec::from_json_str(&scene.to_string(), "glued")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("objects[0].name") && err.contains("left_drawer_body"),
        "{err}"
    );
    let scene = serde_json::json!({
        "schema_version": 1,
        "embodiment": "finger",
        "objects": [
            {"name": "left_drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}},
            {"name": "top_drawer", "kind": "cube", "pose": {"position": [0.3, -0.2, 0.5]}}
        ],
        "articulations": {"top_drawer": 0.05}
    });
    let err = SceneSpec::from_json_str(&scene.to_string(), "cube")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("articulations.top_drawer") && err.contains("no asset provides"),
        "{err}"
    );
}
