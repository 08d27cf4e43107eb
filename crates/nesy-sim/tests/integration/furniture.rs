//! Several articulated assets in one scene: prefixed part names, and a drawer opened into
//! another cabinet's open drawer stopped where the two meet, and how deep the arm goes into
//! furniture.

use nesy_sim::api::{ApiError, Direction, RobotApi};
use nesy_sim::perception::observer;
use nesy_sim::scene::SceneSpec;
use nesy_sim::scene::parts::DRAWER_OPEN;
use nesy_sim::world::{FURNITURE_TOUCH_DEPTH, FurnitureContactProbe, Sim};

/// Two cabinets at right angles (`fixtures/scenes/drawers_perpendicular_finger.json`):
/// `front_` faces −y (its drawers open toward −y), `side_` is turned a quarter turn so that
/// its drawers open toward +x, across the front cabinet's drawer path. `side_top_drawer`
/// starts at `side_top`.
fn perpendicular_cabinets(side_top: f64) -> SceneSpec {
    let mut scene =
        SceneSpec::from_file(&nesy_testkit::scene_fixture("drawers_perpendicular_finger")).unwrap();
    scene.articulations.insert("side_top_drawer".into(), side_top);
    scene
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
    let mut scene = perpendicular_cabinets(0.0);
    scene.protective_stop = true;
    let mut sim = Sim::new(&scene).unwrap();
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

/// The error loading a finger scene of `objects` and `articulations` gives.
fn load_error(objects: serde_json::Value, articulations: serde_json::Value) -> String {
    let scene = serde_json::json!({
        "schema_version": 1,
        "embodiment": "finger",
        "objects": objects,
        "articulations": articulations
    });
    SceneSpec::from_json_str(&scene.to_string(), "scene")
        .unwrap_err()
        .to_string()
}

#[test]
fn a_second_asset_needs_its_own_prefix() {
    let twice = load_error(
        serde_json::json!([
            {"name": "drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}},
            {"name": "drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.30, 0.0, 0.5]}}
        ]),
        serde_json::json!({}),
    );
    assert!(
        twice.contains("objects[1].name") && twice.contains("duplicate"),
        "{twice}"
    );
    let glued = load_error(
        serde_json::json!([
            {"name": "leftdrawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}}
        ]),
        serde_json::json!({}),
    );
    assert!(
        glued.contains("objects[0].name") && glued.contains("left_drawer_body"),
        "{glued}"
    );
    let cube = load_error(
        serde_json::json!([
            {"name": "left_drawer_body", "kind": "drawer_cabinet", "pose": {"position": [0.46, 0.19, 0.5]}},
            {"name": "top_drawer", "kind": "cube", "pose": {"position": [0.3, -0.2, 0.5]}}
        ]),
        serde_json::json!({"top_drawer": 0.05}),
    );
    assert!(
        cube.contains("articulations.top_drawer") && cube.contains("no asset provides"),
        "{cube}"
    );
}

/// A magnetic hook on the table with screws around its magnet: two pieces within the
/// magnet's reach, two beyond it (`fixtures/scenes/hook_screws_finger.json`).
fn hook_and_screws() -> SceneSpec {
    SceneSpec::from_file(&nesy_testkit::scene_fixture("hook_screws_finger")).unwrap()
}

#[test]
fn screws_near_the_magnet_gather_under_it_and_the_others_stay_put() {
    use nesy_sim::world::magnet::MAGNET_RADIUS;
    let scene = hook_and_screws();
    assert_eq!(
        scene.part_names(),
        [
            "magnetic_hook",
            "black_screws_1",
            "black_screws_2",
            "black_screws_3",
            "black_screws_4"
        ]
    );
    let mut sim = Sim::new(&scene).unwrap();
    let magnet = sim.magnet_centres()[0];
    let distance = |sim: &Sim, piece: &str| {
        let p = sim.part_pose(sim.part_index(piece).unwrap()).translation.vector;
        ((p.x - magnet[0]).powi(2) + (p.y - magnet[1]).powi(2) + (p.z - magnet[2]).powi(2)).sqrt()
    };
    let position = |sim: &Sim, piece: &str| sim.part_pose(sim.part_index(piece).unwrap()).translation.vector;
    let far_before = [position(&sim, "black_screws_3"), position(&sim, "black_screws_4")];
    for piece in ["black_screws_3", "black_screws_4"] {
        assert!(
            distance(&sim, piece) > MAGNET_RADIUS,
            "{piece} starts within reach"
        );
    }
    sim.step_idle(100);
    for piece in ["black_screws_1", "black_screws_2"] {
        let d = distance(&sim, piece);
        assert!(d < 0.03, "{piece} is still {d:.4} m from the magnet");
    }
    for (piece, before) in ["black_screws_3", "black_screws_4"].into_iter().zip(far_before) {
        let moved = (position(&sim, piece) - before).norm();
        assert!(
            moved < 1e-3,
            "{piece} moved {moved:.4} m outside the magnet's reach"
        );
    }
    // Perception reports the pieces as one object, fine-grained and, with two pieces
    // still far off, not gathered.
    let state = format!("{:?}", observer::observe(&sim));
    assert!(
        state.contains("Finegrained") && !state.contains("Gathered"),
        "{state}"
    );
    assert!(!state.contains("black_screws_1"), "{state}");
    // The magnet does not drag the hook itself across the table.
    let hook = position(&sim, "magnetic_hook");
    assert!(
        (hook.x - 0.45).abs() < 2e-3 && hook.y.abs() < 2e-3,
        "hook at {hook:?}"
    );
}

#[test]
fn screws_all_within_reach_end_gathered() {
    use nesy_sim::perception::observer::GATHERED_SPREAD;
    let mut scene = hook_and_screws();
    // Around the magnet's free end and both its sides, each within its reach.
    let pieces = vec![[-0.015, 0.0], [-0.05, 0.045], [-0.05, -0.045]];
    let n = pieces.len() as f64;
    let mean = [0, 1].map(|k| pieces.iter().map(|p: &[f64; 2]| p[k]).sum::<f64>() / n);
    let spread = pieces
        .iter()
        .map(|p| ((p[0] - mean[0]).powi(2) + (p[1] - mean[1]).powi(2)).sqrt())
        .fold(0.0, f64::max);
    assert!(
        spread > GATHERED_SPREAD,
        "the pieces start together ({spread:.3} m)"
    );
    scene.objects[1].pieces = Some(pieces);
    let mut sim = Sim::new(&scene).unwrap();
    sim.step_idle(100);
    let after = format!("{:?}", observer::observe(&sim));
    assert!(after.contains("(Gathered black_screws)"), "{after}");
}

#[test]
fn the_lifted_hook_carries_the_screws_it_gathered() {
    let mut scene = hook_and_screws();
    scene.objects[1].pieces = Some(vec![[-0.015, 0.0], [-0.05, 0.045]]);
    let mut sim = Sim::new(&scene).unwrap();
    sim.step_idle(50);
    sim.move_gripper_to("magnetic_hook", Direction::Down, 0.01)
        .unwrap();
    sim.close_gripper().unwrap();
    assert_eq!(sim.held_object(), Some("magnetic_hook"));
    sim.move_parallel(Direction::Up, 0.1, Direction::Down).unwrap();
    sim.step_idle(50);
    for piece in ["black_screws_1", "black_screws_2"] {
        let z = sim.part_pose(sim.part_index(piece).unwrap()).translation.vector.z;
        assert!(z > 0.5 + 0.08, "{piece} stayed at z {z:.3}");
    }
}

#[test]
fn the_api_knows_screws_as_one_object_too_small_to_grasp() {
    let mut sim = Sim::new(&hook_and_screws()).unwrap();
    let names = sim.get_obj_names();
    assert!(names.iter().any(|n| n == "black_screws"), "{names:?}");
    assert!(!names.iter().any(|n| n.starts_with("black_screws_")), "{names:?}");
    let [[x0, _, _], [x1, _, _]] = sim.get_obj_bbox("black_screws").unwrap();
    assert!(x1 - x0 > 0.1, "the box spans every piece: {x0}..{x1}");
    match sim.move_gripper_to("black_screws", Direction::Down, 0.01) {
        Err(ApiError::Infeasible { reason, .. }) => assert!(reason.contains("magnetic hook"), "{reason}"),
        other => panic!("expected a refusal, got {other:?}"),
    }
    assert_eq!(sim.obj_in_gripper("black_screws"), Ok(false));
}

#[test]
fn gather_with_hook_sweeps_the_magnet_over_every_piece() {
    use nesy_sim::api::ApiCall;
    use nesy_sim::world::magnet::MAGNET_RADIUS;
    let mut sim = Sim::new(&hook_and_screws()).unwrap();
    sim.step_idle(50);
    // Two pieces lie beyond the resting magnet's reach: only a sweep brings them in.
    let magnet = sim.magnet_centres()[0];
    let beyond = sim
        .pieces_of("black_screws")
        .into_iter()
        .filter(|&p| {
            let at = sim.part_pose(p).translation.vector;
            ((at.x - magnet[0]).powi(2) + (at.y - magnet[1]).powi(2)).sqrt() > MAGNET_RADIUS
        })
        .count();
    assert_eq!(beyond, 2);
    sim.move_gripper_to("magnetic_hook", Direction::Down, 0.01)
        .unwrap();
    sim.close_gripper().unwrap();
    sim.gather_with_hook("black_screws").unwrap();
    sim.step_idle(50);
    let state = format!("{:?}", observer::observe(&sim));
    assert!(state.contains("(Gathered black_screws)"), "{state}");
    let magnet = sim.magnet_centres()[0];
    for piece in sim.pieces_of("black_screws") {
        let at = sim.part_pose(piece).translation.vector;
        let d = ((at.x - magnet[0]).powi(2) + (at.y - magnet[1]).powi(2) + (at.z - magnet[2]).powi(2)).sqrt();
        assert!(
            d < 0.03,
            "{} is {d:.3} m from the magnet",
            sim.parts()[piece].name
        );
    }
    assert_eq!(sim.held_object(), Some("magnetic_hook"));
    let last = sim.trace().last().unwrap();
    assert_eq!(
        last.call,
        ApiCall::GatherWithHook {
            obj_name: "black_screws".into()
        }
    );
    assert_eq!(last.call.label(), "gather_with_hook(black_screws)");
}

#[test]
fn gather_with_hook_needs_a_held_hook_and_a_fine_grained_object() {
    let mut sim = Sim::new(&hook_and_screws()).unwrap();
    let reason = |r: Result<(), ApiError>| match r {
        Err(ApiError::Infeasible { reason, .. }) => reason,
        other => panic!("expected a refusal, got {other:?}"),
    };
    let empty_handed = reason(sim.gather_with_hook("black_screws"));
    assert!(empty_handed.contains("grasp a magnetic hook"), "{empty_handed}");
    let rigid = reason(sim.gather_with_hook("magnetic_hook"));
    assert!(rigid.contains("not small pieces"), "{rigid}");
    assert!(matches!(
        sim.gather_with_hook("red_screws"),
        Err(ApiError::UnknownObject { .. })
    ));
}

#[test]
fn the_furniture_probe_measures_a_descent_into_a_cabinet_and_names_the_part() {
    let mut sim = Sim::new(&perpendicular_cabinets(0.0)).unwrap();
    sim.add_hook(Box::new(FurnitureContactProbe::default()));
    let [lo, hi] = sim.get_obj_bbox("side_drawer_body").unwrap();
    let (x, y) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
    let deepest = |sim: &Sim| {
        let probe = sim.hook::<FurnitureContactProbe>().unwrap();
        probe.contacts().into_iter().next()
    };

    sim.move_to_position([x, y, hi[2] + 0.05], Direction::Down, 0.12, 0.0)
        .unwrap();
    assert_eq!(
        deepest(&sim),
        None,
        "5 cm above the cabinet the hand touches nothing"
    );

    // Without the protective stop the kinematic arm goes on; the probe says how far it went
    // in, and where.
    sim.move_to_position([x, y, hi[2] - 0.03], Direction::Down, 0.0, 0.0)
        .unwrap();
    let probe = sim.hook::<FurnitureContactProbe>().unwrap();
    let into_top = probe
        .contacts()
        .into_iter()
        .find(|c| c.obstacle == "side_drawer_body")
        .expect("the fingers went through the cabinet's top");
    assert!(into_top.moving.starts_with("the robot's panda_"), "{into_top:?}");
    assert!(into_top.depth > FURNITURE_TOUCH_DEPTH, "{into_top:?}");
    assert_eq!(
        into_top.call, "move_to_position #2",
        "the second move, after get_obj_bbox and the first"
    );
}

#[test]
fn with_the_protective_stop_a_descent_through_a_fixed_part_fails_naming_the_part() {
    // Turned on by the scene.
    let mut scene = perpendicular_cabinets(0.0);
    scene.protective_stop = true;
    let mut sim = Sim::new(&scene).unwrap();
    let [lo, hi] = sim.get_obj_bbox("side_drawer_body").unwrap();
    let (x, y) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
    sim.move_to_position([x, y, hi[2] + 0.05], Direction::Down, 0.12, 0.0)
        .expect("5 cm above the cabinet the way is clear");

    let err = sim
        .move_to_position([x, y, hi[2] - 0.03], Direction::Down, 0.0, 0.0)
        .expect_err("the cabinet's top is in the way");
    let ApiError::Collision {
        call,
        moving,
        obstacle,
    } = &err
    else {
        panic!("expected a collision, got {err:?}");
    };
    assert_eq!(call, "move_to_position");
    assert_eq!(obstacle, "side_drawer_body", "{err}");
    assert!(moving.starts_with("the robot's panda_"), "{err}");
    assert!(
        err.to_string().contains("ran into side_drawer_body"),
        "the message names the part: {err}"
    );
    // The arm halted at the top, a touch deep at most, well short of the 3 cm it was sent.
    let tool_z = sim.tool_pose().translation.vector.z;
    assert!(
        tool_z > hi[2] - 0.015,
        "tool stopped at z {tool_z:.4}, top at {:.4}",
        hi[2]
    );

    // Back up the way it came: a motion out of the contact is not stopped.
    sim.move_to_position([x, y, hi[2] + 0.05], Direction::Down, 0.0, 0.0)
        .expect("leaving the contact");
}

#[test]
fn the_protective_stop_is_off_unless_the_scene_turns_it_on() {
    let mut scene = perpendicular_cabinets(0.0);
    assert!(!scene.protective_stop, "off unless the scene says otherwise");
    assert!(
        !scene.to_json_pretty().contains("protective_stop"),
        "written out only when on"
    );
    scene.protective_stop = true;
    let text = scene.to_json_pretty();
    assert!(text.contains("\"protective_stop\": true"), "{text}");
    let on = SceneSpec::from_json_str(&text, "stop on").unwrap();
    assert!(Sim::new(&on).unwrap().scene().protective_stop);
    scene.protective_stop = false;
    let mut sim = Sim::new(&scene).unwrap();
    let [lo, hi] = sim.get_obj_bbox("side_drawer_body").unwrap();
    let (x, y) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
    sim.move_to_position([x, y, hi[2] + 0.05], Direction::Down, 0.12, 0.0)
        .unwrap();
    sim.move_to_position([x, y, hi[2] - 0.03], Direction::Down, 0.0, 0.0)
        .expect("nothing stops the kinematic arm");
}

#[test]
fn with_the_protective_stop_a_drawer_is_still_pulled_by_its_handle() {
    // The authors' handles stand 2.5 cm off the face, closer than a Panda hand fits: the hand
    // overlaps its own cabinet while it reaches for, holds and leaves the handle.
    let mut sim = Sim::new(&perpendicular_cabinets(0.0)).unwrap();
    pull_front_top_drawer(&mut sim).expect("the pull is not stopped by its own cabinet");
    let open = sim.articulation_q("front_top_drawer").unwrap();
    assert!(open > DRAWER_OPEN - 0.01, "travel {open:.4}");
    sim.release_handle().unwrap();
    sim.move_parallel(Direction::Up, 0.1, Direction::Down)
        .expect("the hand leaves the handle upward");
}
