//! Scripted call sequences on both embodiments, checking the observer after every step:
//! pick and place into the toy box, a cylinder into the open bottom drawer then closing it,
//! opening the hinge lid by its handle / dropping a fruit in / closing it, and sweeping chess
//! pieces into their boxes.

use crate::common;

use common::{expect, load};
use nesy_sim::api::{Direction, RobotApi};
use nesy_sim::tasks::layout::PUSH_DEPTH_DIVISOR;
use nesy_sim::world::Sim;

fn grasp(sim: &mut Sim) {
    match sim.embodiment() {
        nesy_core::Embodiment::Finger => sim.close_gripper().unwrap(),
        nesy_core::Embodiment::Vacuum => sim.activate_vacuum().unwrap(),
    }
}

fn release(sim: &mut Sim) {
    match sim.embodiment() {
        nesy_core::Embodiment::Finger => sim.open_gripper().unwrap(),
        nesy_core::Embodiment::Vacuum => sim.deactivate_vacuum().unwrap(),
    }
}

fn grab_handle(sim: &mut Sim, handle: &str) {
    sim.move_gripper_to(handle, Direction::Down, 0.0).unwrap();
    match sim.embodiment() {
        nesy_core::Embodiment::Finger => sim.grasp_handle(handle).unwrap(),
        nesy_core::Embodiment::Vacuum => sim.attach_vacuum_handle(handle).unwrap(),
    }
}

fn let_go_handle(sim: &mut Sim) {
    match sim.embodiment() {
        nesy_core::Embodiment::Finger => sim.release_handle().unwrap(),
        nesy_core::Embodiment::Vacuum => sim.detach_vacuum_handle().unwrap(),
    }
}

/// Predicate names for the embodiment: (open, closed, holding, surrounding).
fn names(sim: &Sim) -> (&'static str, &'static str, &'static str, &'static str) {
    match sim.embodiment() {
        nesy_core::Embodiment::Finger => (
            "GripperOpen",
            "GripperClosed",
            "GripperHolding",
            "GripperSurrounding",
        ),
        nesy_core::Embodiment::Vacuum => (
            "VacuumInactive",
            "VacuumActive",
            "VacuumAttached",
            "VacuumAligned",
        ),
    }
}

fn pick_place(scene: &str) {
    let mut sim = load(scene);
    let (open, closed, holding, surrounding) = names(&sim);
    expect(
        &sim,
        "reset",
        &[
            &format!("({open})"),
            "(OnTopOf green_cube blue_cube)",
            "(OnTopOf red_cube floor)",
        ],
        &[],
    );
    let grid = [[-0.02, -0.03], [0.02, -0.03], [0.0, 0.03]];
    // The stacked cube first, then the others, as the authors' expert does.
    for (k, cube) in ["green_cube", "red_cube", "blue_cube"].into_iter().enumerate() {
        let h = sim.get_obj_size(cube).unwrap()[2];
        sim.move_gripper_to(cube, Direction::Down, h / 2.0).unwrap();
        expect(
            &sim,
            "approach",
            &[&format!("({surrounding} {cube})"), &format!("({open})")],
            &[],
        );
        grasp(&mut sim);
        expect(
            &sim,
            "grasp",
            &[&format!("({holding} {cube})"), &format!("({closed})")],
            &[],
        );
        let c = sim.get_obj_pos("toy_box").unwrap();
        let top = sim.get_obj_bbox("toy_box").unwrap()[1][2];
        sim.move_to_position(
            [c[0] + grid[k][0], c[1] + grid[k][1], top + h + 0.03],
            Direction::Down,
            0.12,
            0.0,
        )
        .unwrap();
        expect(
            &sim,
            "carry",
            &[
                &format!("(OverOf {cube} toy_box)"),
                &format!("({holding} {cube})"),
            ],
            &[],
        );
        release(&mut sim);
        expect(
            &sim,
            "release",
            &[&format!("(InsideOf {cube} toy_box)"), &format!("({open})")],
            &[&format!("({holding} {cube})")],
        );
    }
    sim.step_idle(100);
    expect(
        &sim,
        "settle",
        &[
            "(InsideOf green_cube toy_box)",
            "(InsideOf red_cube toy_box)",
            "(InsideOf blue_cube toy_box)",
        ],
        &[],
    );
    assert!(sim.trace().iter().all(|e| e.result.is_ok()));
}

#[test]
fn pick_cubes_into_the_toy_box_finger() {
    pick_place("pick_place_finger");
}

#[test]
fn pick_cubes_into_the_toy_box_vacuum() {
    pick_place("pick_place_vacuum");
}

fn drawer(scene: &str, cylinder: &str) {
    let mut sim = load(scene);
    let (open, _, holding, _) = names(&sim);
    expect(
        &sim,
        "reset",
        &["(Open bottom_drawer)", "(Closed top_drawer)"],
        &[],
    );
    let h = sim.get_obj_size(cylinder).unwrap()[2];
    sim.move_gripper_to(cylinder, Direction::Down, h / 2.0).unwrap();
    grasp(&mut sim);
    expect(&sim, "grasp", &[&format!("({holding} {cylinder})")], &[]);
    let c = sim.get_obj_pos("bottom_drawer").unwrap();
    let s = sim.get_obj_size("bottom_drawer").unwrap();
    sim.move_to_position([c[0], c[1], c[2] + s[2] + h], Direction::Down, 0.12, 0.0)
        .unwrap();
    expect(
        &sim,
        "carry",
        &[&format!("(OverOf {cylinder} bottom_drawer)")],
        &[],
    );
    release(&mut sim);
    expect(
        &sim,
        "drop",
        &[
            &format!("(InsideOf {cylinder} bottom_drawer)"),
            &format!("({open})"),
        ],
        &[],
    );
    grab_handle(&mut sim, "bottom_drawer_handle");
    expect(
        &sim,
        "grasp handle",
        &[&format!("({holding} bottom_drawer_handle)")],
        &[],
    );
    sim.move_parallel(Direction::Right, s[1] * 0.85, Direction::Down)
        .unwrap();
    expect(
        &sim,
        "push",
        &[
            "(Closed bottom_drawer)",
            &format!("({holding} bottom_drawer_handle)"),
        ],
        &[],
    );
    let_go_handle(&mut sim);
    sim.move_parallel(Direction::Up, 0.05, Direction::Down).unwrap();
    sim.step_idle(100);
    expect(
        &sim,
        "final",
        &[
            "(Closed bottom_drawer)",
            &format!("(InsideOf {cylinder} bottom_drawer)"),
        ],
        &["(Open bottom_drawer)"],
    );
    assert!(
        sim.articulation_q("bottom_drawer").unwrap() < 0.04,
        "closed per the success check"
    );
}

#[test]
fn cylinder_into_the_open_bottom_drawer_then_close_finger() {
    drawer("drawer_finger", "red_cylinder");
}

#[test]
fn cylinder_into_the_open_bottom_drawer_then_close_vacuum() {
    drawer("drawer_vacuum", "red_cylinder");
}

fn hinge(scene: &str) {
    let mut sim = load(scene);
    let (open, _, holding, _) = names(&sim);
    expect(
        &sim,
        "reset",
        &["(Closed hinge_lid)", "(OnTopOf apple floor)"],
        &[],
    );
    grab_handle(&mut sim, "hinge_handle");
    expect(&sim, "grasp handle", &[&format!("({holding} hinge_handle)")], &[]);
    let lid = sim.get_obj_pos("hinge_lid").unwrap();
    let r = sim.get_obj_size("hinge_lid").unwrap()[0];
    sim.move_to_position([lid[0] + 0.5 * r, lid[1], lid[2] + r], Direction::Down, 0.0, 0.0)
        .unwrap();
    expect(
        &sim,
        "lift lid",
        &["(Open hinge_lid)", &format!("({holding} hinge_handle)")],
        &[],
    );
    let_go_handle(&mut sim);
    expect(
        &sim,
        "release handle",
        &["(Open hinge_lid)", &format!("({open})")],
        &[],
    );
    let h = sim.get_obj_size("apple").unwrap()[2];
    sim.move_gripper_to("apple", Direction::Down, h / 2.0).unwrap();
    grasp(&mut sim);
    expect(&sim, "grasp apple", &[&format!("({holding} apple)")], &[]);
    let body = sim.get_obj_pos("hinge_body").unwrap();
    let top = sim.get_obj_bbox("hinge_body").unwrap()[1][2];
    // Suction holds the fruit by its top, the fingers by its middle.
    let hang = if sim.embodiment() == nesy_core::Embodiment::Vacuum {
        h
    } else {
        h / 2.0
    };
    sim.move_to_position([body[0], body[1], top + hang + 0.03], Direction::Down, 0.12, 0.0)
        .unwrap();
    expect(&sim, "carry", &["(OverOf apple hinge_body)"], &[]);
    release(&mut sim);
    expect(&sim, "drop", &["(InsideOf apple hinge_body)"], &[]);
    grab_handle(&mut sim, "hinge_handle");
    let size = sim.get_obj_size("hinge_body").unwrap();
    sim.move_to_position(
        [body[0] - 0.5 * size[0], body[1], body[2] + 0.5 * size[2]],
        Direction::Down,
        0.0,
        0.0,
    )
    .unwrap();
    let_go_handle(&mut sim);
    sim.step_idle(100);
    expect(
        &sim,
        "final",
        &["(Closed hinge_lid)", "(InsideOf apple hinge_body)"],
        &["(Open hinge_lid)"],
    );
    assert!(
        (sim.articulation_q("hinge_lid").unwrap() + 0.785).abs() < 0.2,
        "closed per the success check"
    );
}

#[test]
fn open_the_hinge_lid_drop_a_fruit_close_it_finger() {
    hinge("hinge_finger");
}

#[test]
fn open_the_hinge_lid_drop_a_fruit_close_it_vacuum() {
    hinge("hinge_vacuum");
}

fn sweep(scene: &str) {
    let mut sim = load(scene);
    let vacuum = sim.embodiment() == nesy_core::Embodiment::Vacuum;
    expect(
        &sim,
        "reset",
        &["(OnTopOf white_rook board)", "(OnTopOf black_bishop board)"],
        &[],
    );
    for (piece, target) in [
        ("white_rook", "left_chess_box"),
        ("black_bishop", "right_chess_box"),
    ] {
        let h = sim.get_obj_size(piece).unwrap()[2];
        sim.move_gripper_to(piece, Direction::Down, h / PUSH_DEPTH_DIVISOR)
            .unwrap();
        if vacuum {
            sim.activate_vacuum().unwrap();
            expect(&sim, "attach", &[&format!("(VacuumAttached {piece})")], &[]);
        } else {
            expect(&sim, "approach", &[&format!("(GripperSurrounding {piece})")], &[]);
        }
        let py = sim.get_obj_pos(piece).unwrap()[1];
        let by = sim.get_obj_pos(target).unwrap()[1];
        let dir = if py > by {
            Direction::Left
        } else {
            Direction::Right
        };
        sim.move_parallel(dir, (py - by).abs() + 0.02, Direction::Down)
            .unwrap();
        if vacuum {
            sim.deactivate_vacuum().unwrap();
        }
        expect(
            &sim,
            "sweep",
            &[&format!("(InsideOf {piece} {target})")],
            &[&format!("(OnTopOf {piece} board)")],
        );
        sim.move_parallel(Direction::Up, 0.08, Direction::Down).unwrap();
    }
    sim.step_idle(100);
    expect(
        &sim,
        "final",
        &[
            "(InsideOf white_rook left_chess_box)",
            "(InsideOf black_bishop right_chess_box)",
        ],
        &[],
    );
}

#[test]
fn sweep_chess_pieces_into_their_boxes_finger() {
    sweep("sweep_finger");
}

#[test]
fn sweep_chess_pieces_into_their_boxes_vacuum() {
    sweep("sweep_vacuum");
}

fn unstack(scene: &str) {
    let mut sim = load(scene);
    let (open, _, holding, _) = names(&sim);
    expect(&sim, "reset", &["(OnTopOf green_cube blue_cube)"], &[]);
    let h = sim.get_obj_size("green_cube").unwrap()[2];
    sim.move_gripper_to("green_cube", Direction::Down, h / 2.0)
        .unwrap();
    grasp(&mut sim);
    expect(&sim, "grasp", &[&format!("({holding} green_cube)")], &[]);
    let [x, y] = sim.get_empty_floor_xy("green_cube").unwrap();
    // The spot is in the search region and clear of every other object.
    assert!(
        (0.11..=0.53).contains(&x) && (-0.15..=0.16).contains(&y),
        "{x} {y}"
    );
    let hang = if sim.embodiment() == nesy_core::Embodiment::Vacuum {
        h
    } else {
        h / 2.0
    };
    sim.move_to_position([x, y, 0.5 + hang + 0.01], Direction::Down, 0.12, 0.0)
        .unwrap();
    release(&mut sim);
    expect(
        &sim,
        "put down",
        &[
            "(OnTopOf green_cube floor)",
            "(OnTopOf blue_cube floor)",
            &format!("({open})"),
        ],
        &["(OnTopOf green_cube blue_cube)"],
    );
    // Now the lower cube can be picked.
    sim.move_gripper_to("blue_cube", Direction::Down, h / 2.0)
        .unwrap();
    grasp(&mut sim);
    expect(&sim, "grasp lower", &[&format!("({holding} blue_cube)")], &[]);
}

#[test]
fn unstack_onto_an_empty_floor_spot_finger() {
    unstack("pick_place_finger");
}

#[test]
fn unstack_onto_an_empty_floor_spot_vacuum() {
    unstack("pick_place_vacuum");
}

/// All four subtasks at the benchmark's composite offsets (pick_place at (0.35, 0.2), sweep at
/// (0.35, −0.2), hinge at (0.65, 0.2), a reflected drawer cabinet at (0.65, −0.2)).
fn composite(embodiment: nesy_core::Embodiment) {
    let text = std::fs::read_to_string(nesy_testkit::scene_fixture("composite_all_finger")).unwrap();
    let mut spec = nesy_sim::scene::SceneSpec::from_json_str(&text, "composite").unwrap();
    spec.embodiment = embodiment;
    let mut sim = Sim::new(&spec).unwrap();
    let vacuum = embodiment == nesy_core::Embodiment::Vacuum;
    let hang = |sim: &mut Sim, obj: &str| {
        let h = sim.get_obj_size(obj).unwrap()[2];
        if vacuum { h } else { h / 2.0 }
    };
    // Cubes into the toy box, on a 2×2 grid.
    let grid = [
        [-0.03, -0.02],
        [0.03, -0.02],
        [-0.03, 0.02],
        [0.03, 0.02],
        [0.0, 0.0],
    ];
    for (k, cube) in [
        "red_cube",
        "blue_cube",
        "yellow_cube",
        "green_cube",
        "purple_cube",
    ]
    .into_iter()
    .enumerate()
    {
        let h = sim.get_obj_size(cube).unwrap()[2];
        sim.move_gripper_to(cube, Direction::Down, h / 2.0).unwrap();
        grasp(&mut sim);
        let c = sim.get_obj_pos("toy_box").unwrap();
        let top = sim.get_obj_bbox("toy_box").unwrap()[1][2];
        let z = top + hang(&mut sim, cube) + 0.03 + if k == 4 { 0.03 } else { 0.0 };
        sim.move_to_position(
            [c[0] + grid[k][0], c[1] + grid[k][1], z],
            Direction::Down,
            0.12,
            0.0,
        )
        .unwrap();
        release(&mut sim);
        expect(&sim, cube, &[&format!("(InsideOf {cube} toy_box)")], &[]);
    }
    // Sweep.
    for (piece, target) in [
        ("white_rook", "left_chess_box"),
        ("black_knight", "right_chess_box"),
        ("white_bishop", "left_chess_box"),
    ] {
        let h = sim.get_obj_size(piece).unwrap()[2];
        sim.move_gripper_to(piece, Direction::Down, h / PUSH_DEPTH_DIVISOR)
            .unwrap();
        if vacuum {
            sim.activate_vacuum().unwrap();
        }
        let py = sim.get_obj_pos(piece).unwrap()[1];
        let by = sim.get_obj_pos(target).unwrap()[1];
        let dir = if py > by {
            Direction::Left
        } else {
            Direction::Right
        };
        sim.move_parallel(dir, (py - by).abs() + 0.02, Direction::Down)
            .unwrap();
        if vacuum {
            sim.deactivate_vacuum().unwrap();
        }
        sim.move_parallel(Direction::Up, 0.08, Direction::Down).unwrap();
        expect(&sim, piece, &[&format!("(InsideOf {piece} {target})")], &[]);
    }
    // Fruits into the open hinge box, then close the lid.
    // Spread along the body's long side: the fruits have flat bases and do not roll aside.
    for (fruit, dy) in [("apple", -0.06), ("orange", 0.0), ("lemon", 0.06)] {
        let h = sim.get_obj_size(fruit).unwrap()[2];
        sim.move_gripper_to(fruit, Direction::Down, h / 2.0).unwrap();
        grasp(&mut sim);
        let body = sim.get_obj_pos("hinge_body").unwrap();
        let top = sim.get_obj_bbox("hinge_body").unwrap()[1][2];
        let z = top + hang(&mut sim, fruit) + 0.03;
        sim.move_to_position([body[0], body[1] + dy, z], Direction::Down, 0.12, 0.0)
            .unwrap();
        release(&mut sim);
        expect(&sim, fruit, &[&format!("(InsideOf {fruit} hinge_body)")], &[]);
    }
    grab_handle(&mut sim, "hinge_handle");
    let body = sim.get_obj_pos("hinge_body").unwrap();
    let size = sim.get_obj_size("hinge_body").unwrap();
    sim.move_to_position(
        [body[0] - 0.5 * size[0], body[1], body[2] + 0.5 * size[2]],
        Direction::Down,
        0.0,
        0.0,
    )
    .unwrap();
    let_go_handle(&mut sim);
    expect(&sim, "close lid", &["(Closed hinge_lid)"], &[]);
    // Cylinders from the cabinet top into the open bottom drawer (opening toward +y here).
    // Spots 5 cm or more apart and 1.5 cm inside the walls: a cylinder dropped onto another
    // one tips over, and one lying on its side rolls on without stopping (Rapier has no
    // rolling resistance); one clipping a wall's top edge is flung out.
    for (cyl, dx, dy) in [
        ("red_cylinder", -0.035, -0.005),
        ("green_cylinder", 0.035, -0.005),
        ("blue_cylinder", 0.0, 0.035),
    ] {
        let h = sim.get_obj_size(cyl).unwrap()[2];
        sim.move_gripper_to(cyl, Direction::Down, h / 2.0).unwrap();
        grasp(&mut sim);
        let c = sim.get_obj_pos("bottom_drawer").unwrap();
        let s = sim.get_obj_size("bottom_drawer").unwrap();
        // High enough that the 20 cm wide hand clears the other cylinders on the cabinet top.
        sim.move_to_position(
            [c[0] + dx, c[1] + dy, c[2] + s[2] + h + 0.05],
            Direction::Down,
            0.12,
            0.0,
        )
        .unwrap();
        release(&mut sim);
        expect(&sim, cyl, &[&format!("(InsideOf {cyl} bottom_drawer)")], &[]);
    }
    grab_handle(&mut sim, "bottom_drawer_handle");
    let dy = sim.get_obj_size("bottom_drawer").unwrap()[1] * 0.85;
    sim.move_parallel(Direction::Left, dy, Direction::Down).unwrap();
    let_go_handle(&mut sim);
    sim.step_idle(100);
    let mut want: Vec<String> = [
        "red_cube",
        "blue_cube",
        "yellow_cube",
        "green_cube",
        "purple_cube",
    ]
    .iter()
    .map(|c| format!("(InsideOf {c} toy_box)"))
    .collect();
    want.extend(
        ["apple", "orange", "lemon"]
            .iter()
            .map(|f| format!("(InsideOf {f} hinge_body)")),
    );
    want.extend(
        ["red_cylinder", "green_cylinder", "blue_cylinder"]
            .iter()
            .map(|c| format!("(InsideOf {c} bottom_drawer)")),
    );
    want.extend([
        "(Closed hinge_lid)".to_owned(),
        "(Closed bottom_drawer)".to_owned(),
    ]);
    let want: Vec<&str> = want.iter().map(String::as_str).collect();
    expect(&sim, "final", &want, &[]);
    assert!(sim.trace().iter().all(|e| e.result.is_ok()));
    // Everything is at rest, as the benchmark's success check (speed ≤ 0.02 m/s) requires.
    for (i, part) in sim.parts().iter().enumerate() {
        let v = sim.part_velocity(i);
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(speed <= 0.02, "{} moves at {speed:.3} m/s", part.name);
    }
}

#[test]
fn all_four_subtasks_at_composite_offsets_finger() {
    composite(nesy_core::Embodiment::Finger);
}

#[test]
fn all_four_subtasks_at_composite_offsets_vacuum() {
    composite(nesy_core::Embodiment::Vacuum);
}

/// Obstruction level 1 of the sweep: a piece in the wrong box is lifted back onto the board,
/// then swept into the right one.
fn wrong_box_piece(embodiment: nesy_core::Embodiment) {
    let text = std::fs::read_to_string(nesy_testkit::scene_fixture("sweep_finger")).unwrap();
    let mut spec = nesy_sim::scene::SceneSpec::from_json_str(&text, "sweep").unwrap();
    spec.embodiment = embodiment;
    // The white rook starts in the right (black) box.
    spec.objects[3].pose.position = [0.46, 0.087, 0.503];
    let mut sim = Sim::new(&spec).unwrap();
    expect(&sim, "reset", &["(InsideOf white_rook right_chess_box)"], &[]);
    let vacuum = embodiment == nesy_core::Embodiment::Vacuum;
    let h = sim.get_obj_size("white_rook").unwrap()[2];
    sim.move_gripper_to("white_rook", Direction::Down, h / 2.0)
        .unwrap();
    grasp(&mut sim);
    let board = sim.get_obj_bbox("board").unwrap();
    let x = sim.get_obj_pos("white_rook").unwrap()[0];
    let hang = if vacuum { h } else { h / 2.0 };
    sim.move_to_position([x, 0.0, board[1][2] + hang + 0.01], Direction::Down, 0.12, 0.0)
        .unwrap();
    release(&mut sim);
    expect(
        &sim,
        "back on the board",
        &["(OnTopOf white_rook board)"],
        &["(InsideOf white_rook right_chess_box)"],
    );
    sim.move_gripper_to("white_rook", Direction::Down, h / PUSH_DEPTH_DIVISOR)
        .unwrap();
    if vacuum {
        sim.activate_vacuum().unwrap();
    }
    let py = sim.get_obj_pos("white_rook").unwrap()[1];
    let by = sim.get_obj_pos("left_chess_box").unwrap()[1];
    sim.move_parallel(Direction::Left, (py - by).abs() + 0.02, Direction::Down)
        .unwrap();
    if vacuum {
        sim.deactivate_vacuum().unwrap();
    }
    sim.step_idle(50);
    expect(&sim, "swept", &["(InsideOf white_rook left_chess_box)"], &[]);
}

#[test]
fn a_piece_in_the_wrong_box_is_moved_back_and_swept_finger() {
    wrong_box_piece(nesy_core::Embodiment::Finger);
}

#[test]
fn a_piece_in_the_wrong_box_is_moved_back_and_swept_vacuum() {
    wrong_box_piece(nesy_core::Embodiment::Vacuum);
}

/// Obstruction level 2 of the hinge: a fruit on the closed lid is moved to the floor first.
fn fruit_on_lid(embodiment: nesy_core::Embodiment) {
    let text = std::fs::read_to_string(nesy_testkit::scene_fixture("hinge_finger")).unwrap();
    let mut spec = nesy_sim::scene::SceneSpec::from_json_str(&text, "hinge").unwrap();
    spec.embodiment = embodiment;
    spec.objects[1].pose.position = [0.525, 0.02, 0.627];
    let mut sim = Sim::new(&spec).unwrap();
    expect(
        &sim,
        "reset",
        &["(OnTopOf apple hinge_lid)", "(Closed hinge_lid)"],
        &[],
    );
    let vacuum = embodiment == nesy_core::Embodiment::Vacuum;
    let h = sim.get_obj_size("apple").unwrap()[2];
    sim.move_gripper_to("apple", Direction::Down, h / 2.0).unwrap();
    grasp(&mut sim);
    let [x, y] = sim.get_empty_floor_xy("apple").unwrap();
    let hang = if vacuum { h } else { h / 2.0 };
    sim.move_to_position([x, y, 0.5 + hang + 0.01], Direction::Down, 0.12, 0.0)
        .unwrap();
    release(&mut sim);
    expect(
        &sim,
        "fruit off the lid",
        &["(OnTopOf apple floor)"],
        &["(OnTopOf apple hinge_lid)"],
    );
    grab_handle(&mut sim, "hinge_handle");
    let lid = sim.get_obj_pos("hinge_lid").unwrap();
    let r = sim.get_obj_size("hinge_lid").unwrap()[0];
    sim.move_to_position([lid[0] + 0.5 * r, lid[1], lid[2] + r], Direction::Down, 0.0, 0.0)
        .unwrap();
    let_go_handle(&mut sim);
    expect(&sim, "opened", &["(Open hinge_lid)"], &[]);
}

#[test]
fn a_fruit_on_the_lid_is_moved_away_before_opening_finger() {
    fruit_on_lid(nesy_core::Embodiment::Finger);
}

#[test]
fn a_fruit_on_the_lid_is_moved_away_before_opening_vacuum() {
    fruit_on_lid(nesy_core::Embodiment::Vacuum);
}

#[test]
fn side_approaches_point_the_tool_sideways() {
    for (dir, axis) in [
        (Direction::Left, [0.0, -1.0, 0.0]),
        (Direction::Right, [0.0, 1.0, 0.0]),
    ] {
        let mut sim = load("hinge_finger");
        sim.move_gripper_to("apple", dir, 0.02).unwrap();
        let tool = sim.tool_pose();
        let z = tool.rotation * nalgebra::Vector3::z();
        assert!(
            (z - nalgebra::Vector3::from(axis)).norm() < 0.01,
            "{dir:?}: tool axis {z}"
        );
        let apple = sim.get_obj_bbox("apple").unwrap();
        // `depth` past the near face along the approach.
        let near_face = if axis[1] < 0.0 { apple[1][1] } else { apple[0][1] };
        assert!((tool.translation.vector.y - (near_face + axis[1] * 0.02)).abs() < 2e-3);
    }
}
