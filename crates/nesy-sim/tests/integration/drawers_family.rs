//! The real-world drawers task (`sort_into_drawers`): its scenes in every setting, and the
//! scripted expert on them.

use nesy_core::Embodiment;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::TaskConfig;
use nesy_sim::tasks::experts::run_scene;
use nesy_sim::world::Sim;

fn scene(variant: u64, obst: u8, multi: u8, embodiment: Embodiment) -> nesy_sim::scene::SceneSpec {
    TaskConfig::single(SubtaskKind::SortIntoDrawers, variant, obst, multi, embodiment)
        .generate()
        .unwrap_or_else(|e| panic!("variant {variant}, obstruction {obst}: {e}"))
        .scene
}

#[test]
fn side_by_side_cabinets_block_nothing_and_turned_ones_block_the_drawers_at_their_height() {
    for variant in 0..5 {
        let apart = Sim::new(&scene(variant, 0, 2, Embodiment::Finger)).unwrap();
        assert!(apart.blocking_pairs().is_empty(), "{:?}", apart.blocking_pairs());
        let turned = Sim::new(&scene(variant, 2, 2, Embodiment::Finger)).unwrap();
        let pairs = turned.blocking_pairs();
        for pair in [
            ("front_bottom_drawer", "side_bottom_drawer"),
            ("side_bottom_drawer", "front_bottom_drawer"),
        ] {
            assert!(
                pairs.iter().any(|(a, b)| (a.as_str(), b.as_str()) == pair),
                "variant {variant}: {pair:?} missing from {pairs:?}"
            );
        }
    }
}

/// A cube lying close in front of the turned cabinet can be neither reached with the hand
/// along y (the 20 cm hand meets the cabinet) nor across (the wrist does): every cube keeps
/// 18 cm in y from the turned cabinet's centre.
#[test]
fn cubes_keep_clear_of_the_turned_cabinet() {
    for variant in 0..20 {
        for obst in [1, 2] {
            let scene = scene(variant, obst, 2, Embodiment::Finger);
            let at = |name: &str| {
                scene
                    .objects
                    .iter()
                    .find(|o| o.name == name)
                    .unwrap_or_else(|| panic!("variant {variant}: no {name}"))
                    .pose
                    .position
            };
            let cabinet = at("side_drawer_body");
            for cube in scene.objects.iter().filter(|o| o.name.ends_with("_cube")) {
                let gap = cabinet[1] - cube.pose.position[1];
                assert!(
                    gap >= 0.18 - 1e-9,
                    "variant {variant}, obstruction {obst}: {} {gap:.3} m in front",
                    cube.name
                );
            }
        }
    }
}

/// The expert sweep over the family's demonstration and deployment settings.
#[test]
fn the_expert_meets_every_goal_in_every_setting() {
    let mut failures = Vec::new();
    for variant in 0..20u64 {
        for obst in [0, 2] {
            let spec = scene(variant, obst, (variant % 3) as u8, Embodiment::Finger);
            let episode = run_scene(&spec).unwrap();
            if !episode.full_success() || !episode.outcome.displaced.is_empty() {
                failures.push(format!(
                    "variant {variant} obstruction {obst}: {:?} displaced {:?}",
                    episode.failure(),
                    episode.outcome.displaced
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
