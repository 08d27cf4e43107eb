use nesy_sim::*;
use std::path::Path;

#[test]
fn scratch_pick() {
    let t = std::time::Instant::now();
    let mut sim = Sim::from_file(Path::new("../../fixtures/scenes/pick_place_finger.json")).unwrap();
    println!("built {:?}", t.elapsed());
    println!("tool {:?}", sim.tool_pose().translation.vector);
    println!("{}", observe(&sim));
    let r = sim.move_gripper_to("red_cube", Direction::Down, 0.015);
    println!("move {:?} t={} {:?}", r, sim.time(), t.elapsed());
    println!("tool {:?}", sim.tool_pose().translation.vector);
    println!("{}", observe(&sim));
    sim.close_gripper().unwrap();
    println!("{}", observe(&sim));
    let b = sim.get_obj_bbox("toy_box").unwrap();
    let c = sim.get_obj_pos("toy_box").unwrap();
    let r = sim.move_to_position([c[0], c[1], b[1][2] + 0.05], Direction::Down, 0.12, 0.0);
    println!("move {:?} t={}", r, sim.time());
    println!("{}", observe(&sim));
    sim.open_gripper().unwrap();
    println!("{}", observe(&sim));
    println!("red {:?}", sim.get_obj_bbox("red_cube"));
    println!("total {:?} sim {}", t.elapsed(), sim.time());
}
