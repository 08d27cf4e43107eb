//! The planner on nesy's own world: high-complexity scenes of the benchmark, written by
//! `nesy scenarios pddl` into `fixtures/planning/` (the observed initial state and the scene's
//! goal over `assets/pddl/nesy-world.pddl`). Greedy search on h_FF with preferred operators
//! must solve each in a few hundred expansions, with a plan the executor verifies; without
//! preferred operators the same searches expand tens of thousands of states on the
//! plateaus that closed lids and drawers make.

use std::path::PathBuf;

use nesy_core::pddl::{parse_domain, parse_problem};
use nesy_core::planner::{PlannerConfig, plan};
use nesy_core::verify_procedure_in;

fn root() -> PathBuf {
    nesy_testkit::workspace_root()
}

#[test]
fn high_complexity_scenes_plan_in_few_expansions() {
    let domain_text = std::fs::read_to_string(root().join("assets/pddl/nesy-world.pddl")).unwrap();
    let domain = parse_domain(&domain_text).unwrap();
    let mut problems: Vec<PathBuf> = std::fs::read_dir(root().join("fixtures/planning"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "pddl"))
        .collect();
    problems.sort();
    assert!(problems.len() >= 3, "{problems:?}");
    for path in problems {
        let problem = parse_problem(&std::fs::read_to_string(&path).unwrap(), &domain).unwrap();
        let universe = domain.universe(&problem).unwrap();
        let config = PlannerConfig {
            // Expansions bound the search here, not the clock (debug builds are slower).
            time_limit: None,
            max_expansions: 5_000,
            ..PlannerConfig::default()
        };
        let found = plan(&domain.actions, &universe, &problem.init, &problem.goal, &config)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let report = verify_procedure_in(&universe, &problem.init, &found.steps, Some(&problem.goal));
        assert!(report.is_valid(), "{}: {report:?}", path.display());
        assert!(
            found.expanded < 2_000,
            "{}: {} states expanded",
            path.display(),
            found.expanded
        );
        let again = plan(&domain.actions, &universe, &problem.init, &problem.goal, &config).unwrap();
        assert_eq!(again, found, "{}: deterministic", path.display());
    }
}
