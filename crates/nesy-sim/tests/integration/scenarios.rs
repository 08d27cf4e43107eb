//! The scenario suite: the paper's Table 6 counts, the committed configuration files and
//! schemas, determinism, and the expert on low-complexity scenarios.
//!
//! Regenerate the committed files with
//! `NESY_UPDATE_SCHEMA=1 cargo test -p nesy-sim --test integration scenarios::`.

use std::path::{Path, PathBuf};

use nesy_core::benchmark::{Complexity, Factor};
use nesy_sim::tasks::scenario::{self, CountTable, Side};

fn repo(path: &str) -> PathBuf {
    nesy_testkit::workspace_root().join(path)
}

fn updating() -> bool {
    std::env::var_os("NESY_UPDATE_SCHEMA").is_some()
}

/// Compares a committed file with its generated content (or rewrites it when updating).
fn check_committed(path: &Path, generated: &str) {
    if updating() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, generated).unwrap();
    }
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale; regenerate with NESY_UPDATE_SCHEMA=1 cargo test -p nesy-sim --test integration scenarios::",
        path.display()
    );
}

#[test]
fn counts_match_the_papers_table_6() {
    let all = scenario::scenarios(&scenario::generate_suite());
    assert_eq!(all.len(), 440);
    let table = CountTable::of(&all);
    // Table 6 of the paper: scenarios (configurations × 2 seeds) per row and complexity.
    assert_eq!(
        table.paper_rows(),
        vec![
            ("Obstruction & Object Affordance", [60, 60, 40]),
            ("Kinematic Config & Gripper", [60, 60, 40]),
            ("Combination", [40, 40, 40]),
        ]
    );
    assert_eq!(table.totals(), [160, 160, 120]);
    // Spec §6: 15/15/10 configurations per factor, 20/20/20 for comb.
    for (factor, row) in &table.by_factor {
        let expected = if *factor == Factor::Comb {
            [40, 40, 40]
        } else {
            [30, 30, 20]
        };
        assert_eq!(*row, expected, "{factor}");
    }
    let mut ids: Vec<&str> = all.iter().map(|s| s.id.as_str()).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), 440, "ids are unique");
    let text = table.render();
    assert!(text.contains("Total scenarios") && text.contains("440"), "{text}");
}

#[test]
fn committed_suite_and_schemas_are_current() {
    let files = scenario::generate_suite();
    for file in &files {
        let path = repo("fixtures/benchmark").join(scenario::config_file_name(file.factor, file.complexity));
        check_committed(&path, &file.to_json_pretty());
    }
    assert_eq!(scenario::read_suite(&repo("fixtures/benchmark")).unwrap(), files);
    check_committed(
        &repo("assets/schema/scenario.schema.json"),
        &scenario::config_schema(),
    );
    use nesy_sim::demo::{manifest_schema, mcap_format};
    check_committed(
        &repo("assets/schema/demo-state.schema.json"),
        &mcap_format::state_schema(),
    );
    check_committed(
        &repo("assets/schema/demo-action.schema.json"),
        &mcap_format::action_schema(),
    );
    check_committed(
        &repo("assets/schema/demo-image.schema.json"),
        &mcap_format::image_schema(),
    );
    check_committed(
        &repo("assets/schema/demo-manifest.schema.json"),
        &manifest_schema(),
    );
}

#[test]
fn same_seed_gives_identical_scenes() {
    let a = scenario::scenarios(&scenario::generate_suite());
    let b = scenario::scenarios(&scenario::generate_suite());
    for (x, y) in a.iter().zip(&b).step_by(7) {
        assert_eq!(x.scenes().unwrap(), y.scenes().unwrap(), "{}", x.id);
    }
    // The two seeds of a configuration differ.
    let s0 = &a[0];
    let s1 = &a[1];
    assert_eq!(s0.episode, s1.episode);
    assert_ne!(
        s0.generate(Side::Source).unwrap().scene,
        s1.generate(Side::Source).unwrap().scene
    );
}

#[test]
fn every_scenario_generates_both_scenes() {
    for s in scenario::scenarios(&scenario::generate_suite()) {
        let scenes = s.scenes().unwrap();
        assert_eq!(
            scenes.source.scene.goals.len(),
            s.complexity.subtasks(),
            "{}",
            s.id
        );
        assert_eq!(scenes.source.scene.embodiment, s.episode.source_embodiment);
        assert_eq!(scenes.target.scene.embodiment, s.episode.target_embodiment);
        assert!(!scenes.goal_label().is_empty());
    }
}

/// The expert on both sides of one low-complexity scenario per factor (the full sweep over
/// all 880 scenes is `nesy scenarios sweep`; one per factor × complexity is the ignored
/// test below).
#[test]
fn expert_succeeds_on_one_low_scenario_per_factor() {
    let all = scenario::scenarios(&scenario::generate_suite());
    for factor in Factor::ALL {
        let s = all
            .iter()
            .find(|s| s.factor == factor && s.complexity == Complexity::Low)
            .unwrap();
        for side in [Side::Source, Side::Target] {
            let scene = s.generate(side).unwrap().scene;
            let run = nesy_sim::demo::run_expert(&scene).unwrap();
            assert!(
                run.full_success(),
                "{} {side}: {:?} {}",
                s.id,
                run.expert_error,
                run.outcome.summary()
            );
        }
    }
}

#[test]
#[ignore = "slow: the expert on both sides of one scenario per factor × complexity (minutes)"]
fn expert_succeeds_on_one_scenario_per_factor_and_complexity() {
    let all = scenario::scenarios(&scenario::generate_suite());
    let mut failures = Vec::new();
    for factor in Factor::ALL {
        for complexity in Complexity::ALL {
            let s = all
                .iter()
                .find(|s| s.factor == factor && s.complexity == complexity)
                .unwrap();
            for side in [Side::Source, Side::Target] {
                let scene = s.generate(side).unwrap().scene;
                let run = nesy_sim::demo::run_expert(&scene).unwrap();
                if !run.full_success() {
                    failures.push(format!(
                        "{} {side}: {:?} {}",
                        s.id,
                        run.expert_error,
                        run.outcome.summary()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
