//! Same scene and same calls give a bit-identical trace and world; hooks fire on schedule.

use crate::common;

use std::sync::{Arc, Mutex};

use common::load;
use nesy_sim::api::{Direction, RobotApi, TraceEntry};
use nesy_sim::world::{Sim, SimHook};

fn run(scene: &str) -> (String, Vec<u32>) {
    let mut sim = load(scene);
    sim.move_gripper_to("red_cube", Direction::Down, 0.015).unwrap();
    let vacuum = sim.embodiment() == nesy_core::Embodiment::Vacuum;
    if vacuum {
        sim.activate_vacuum().unwrap()
    } else {
        sim.close_gripper().unwrap()
    }
    let c = sim.get_obj_pos("toy_box").unwrap();
    sim.move_to_position([c[0], c[1], 0.6], Direction::Down, 0.12, 0.0)
        .unwrap();
    if vacuum {
        sim.deactivate_vacuum().unwrap()
    } else {
        sim.open_gripper().unwrap()
    }
    let _ = sim.move_gripper_to("blue_cube", Direction::Down, 0.015);
    sim.move_parallel(Direction::Left, 0.05, Direction::Down).unwrap();
    let trace = serde_json::to_string(sim.trace()).unwrap();
    let mut bits = Vec::new();
    for (_, body) in sim.physics().bodies.iter() {
        let p = body.position();
        bits.extend([p.translation.x, p.translation.y, p.translation.z].map(f32::to_bits));
        bits.extend([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w].map(f32::to_bits));
    }
    (trace, bits)
}

#[test]
fn same_scene_same_calls_bit_identical() {
    for scene in ["pick_place_finger", "pick_place_vacuum"] {
        let (t1, w1) = run(scene);
        let (t2, w2) = run(scene);
        assert_eq!(t1, t2, "{scene}: traces differ");
        assert!(w1 == w2, "{scene}: world states differ");
    }
}

#[derive(Default)]
struct Log {
    step_times: Vec<f64>,
    calls: Vec<TraceEntry>,
}

struct Recorder(Arc<Mutex<Log>>);

impl SimHook for Recorder {
    fn step_interval(&self) -> Option<u64> {
        Some(30)
    }
    fn on_step(&mut self, sim: &Sim) {
        self.0.lock().unwrap().step_times.push(sim.time());
    }
    fn on_call(&mut self, sim: &Sim, entry: &TraceEntry) {
        assert_eq!(entry.sim_time, sim.time());
        self.0.lock().unwrap().calls.push(entry.clone());
    }
}

#[test]
fn hooks_run_every_n_steps_and_after_every_call() {
    let mut sim = load("pick_place_finger");
    let log = Arc::new(Mutex::new(Log::default()));
    sim.add_hook(Box::new(Recorder(log.clone())));
    sim.get_obj_names();
    sim.move_gripper_to("red_cube", Direction::Down, 0.015).unwrap();
    sim.close_gripper().unwrap();
    sim.step_idle(45);
    assert!(sim.hook::<Recorder>().is_some());
    let log = log.lock().unwrap();
    let steps = sim.step_count();
    assert_eq!(log.step_times.len() as u64, steps / 30);
    for (k, t) in log.step_times.iter().enumerate() {
        assert!((t - 0.3 * (k + 1) as f64).abs() < 1e-9);
    }
    assert_eq!(log.calls.len(), 3);
    assert_eq!(log.calls[1].call.name(), "move_gripper_to");
    assert_eq!(log.calls.as_slice(), sim.trace());
}

#[test]
fn the_simulator_can_move_between_threads() {
    fn assert_send<T: Send>() {}
    assert_send::<Sim>();
}
