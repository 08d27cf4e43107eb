//! Many small pick-and-place episodes with varied cube poses across the table, on both
//! robots: every cube must end inside the toy box.

use nesy_core::Embodiment;
use nesy_core::rng::SplitMix64;
use nesy_sim::api::{Direction, RobotApi};
use nesy_sim::scene::{ObjectKind, ObjectSpec, PoseSpec, SceneSpec};
use nesy_sim::world::Sim;

/// Test layouts draw from nesy-core's SplitMix64.
struct Rng(SplitMix64);
impl Rng {
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.0.unit()
    }
}

fn episode(embodiment: Embodiment, seed: u64) -> Result<(), String> {
    let mut rng = Rng(SplitMix64::new(seed));
    // pick_place takes the default offset or the composite's low offsets (`docs/benchmark.md` §3).
    let (ox, oy) = [(0.5, 0.0), (0.35, 0.2), (0.35, -0.2)][(seed % 3) as usize];
    let object = |name: &str, kind, x: f64, y: f64, yaw: f64| ObjectSpec {
        name: name.into(),
        kind,
        pose: PoseSpec {
            position: [x, y, 0.5],
            yaw,
        },
        colour: None,
        size: None,
        pieces: None,
    };
    let a = rng.range(0.0, std::f64::consts::TAU);
    let spec = SceneSpec {
        schema_version: 1,
        embodiment,
        embodiment_in_state: false,
        instruction: String::new(),
        seed,
        objects: vec![
            object("toy_box", ObjectKind::ToyBox, ox + 0.05, oy + 0.1, 0.0),
            object(
                "red_cube",
                ObjectKind::Cube,
                ox + 0.05 + 0.05 * a.cos(),
                oy - 0.1 + 0.05 * a.sin(),
                rng.range(-0.785, 0.785),
            ),
            object(
                "blue_cylinder",
                ObjectKind::Cylinder,
                ox + 0.05 - 0.05 * a.cos(),
                oy - 0.1 - 0.05 * a.sin(),
                0.0,
            ),
        ],
        articulations: Default::default(),
        goals: vec![],
        protective_stop: false,
    };
    let mut sim = Sim::new(&spec).map_err(|e| e.to_string())?;
    for (k, obj) in ["red_cube", "blue_cylinder"].into_iter().enumerate() {
        let h = 0.03;
        sim.move_gripper_to(obj, Direction::Down, h / 2.0)
            .map_err(|e| e.to_string())?;
        match embodiment {
            Embodiment::Finger => sim.close_gripper(),
            Embodiment::Vacuum => sim.activate_vacuum(),
        }
        .map_err(|e| e.to_string())?;
        if sim.held_object() != Some(obj) {
            return Err(format!("{obj} not held"));
        }
        let c = sim.get_obj_pos("toy_box").map_err(|e| e.to_string())?;
        let top = sim.get_obj_bbox("toy_box").map_err(|e| e.to_string())?[1][2];
        let dx = if k == 0 { -0.03 } else { 0.03 };
        sim.move_to_position([c[0] + dx, c[1], top + h + 0.03], Direction::Down, 0.12, 0.0)
            .map_err(|e| e.to_string())?;
        match embodiment {
            Embodiment::Finger => sim.open_gripper(),
            Embodiment::Vacuum => sim.deactivate_vacuum(),
        }
        .map_err(|e| e.to_string())?;
    }
    sim.step_idle(50);
    let state = nesy_sim::perception::observer::observe(&sim).to_string();
    for obj in ["red_cube", "blue_cylinder"] {
        if !state.contains(&format!("(InsideOf {obj} toy_box)")) {
            return Err(format!("{obj} not in the box:\n{state}"));
        }
    }
    Ok(())
}

#[test]
fn varied_pick_and_place_episodes_succeed() {
    let mut failures = Vec::new();
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        for seed in 0..15 {
            if let Err(e) = episode(embodiment, seed) {
                failures.push(format!("{embodiment} seed {seed}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
