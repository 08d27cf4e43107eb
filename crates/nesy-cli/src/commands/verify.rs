//! `nesy verify`: check a plan against a PDDL domain and problem, like VAL.
//!
//! Exit codes: 0 the plan is valid (every step applies and the goal holds), 1 it is not
//! (the failing step and its unmet preconditions, or the unmet goal conditions, are
//! printed), 2 bad input (the file, line and column are named).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, anyhow};
use nesy_core::pddl::{ground_plan, parse_domain, parse_plan, parse_problem};
use nesy_core::text::ParseError;
use nesy_core::{Report, UnmetPrecondition};
use nesy_core::{StepStatus, verify_procedure_in};
use serde::Serialize;

/// Arguments of `nesy verify`.
#[derive(Debug, clap::Args)]
pub(crate) struct VerifyArgs {
    /// PDDL domain file.
    #[arg(long)]
    pub domain: PathBuf,
    /// PDDL problem file.
    #[arg(long)]
    pub problem: PathBuf,
    /// Plan file: one `(action args...)` per line, `;` comments.
    #[arg(long)]
    pub plan: PathBuf,
    /// Print the verdict as JSON.
    #[arg(long)]
    pub json: bool,
}

fn read(path: &Path) -> anyhow::Result<String> {
    nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))
}

fn located(path: &Path, e: ParseError) -> anyhow::Error {
    anyhow!(
        "{}:{}:{}: expected {}, found {}",
        path.display(),
        e.line,
        e.column,
        e.expected,
        e.found
    )
}

/// The verdict printed with `--json`.
#[derive(Debug, Serialize)]
struct Verdict<'a> {
    valid: bool,
    steps: usize,
    executed: usize,
    failure: Option<Failure>,
    goal_satisfied: Option<bool>,
    unmet_goal: Vec<String>,
    report: &'a Report,
}

#[derive(Debug, Serialize)]
struct Failure {
    /// 1-based step number.
    step: usize,
    action: String,
    plan_line: usize,
    unmet: Vec<String>,
    error: Option<String>,
}

fn literals(unmet: &[UnmetPrecondition]) -> Vec<String> {
    unmet.iter().map(|u| u.literal.to_string()).collect()
}

fn explain(u: &UnmetPrecondition) -> String {
    let mut s = format!("- {}", u.literal);
    if !u.atoms.is_empty() {
        let why: Vec<String> = u.atoms.iter().map(|t| t.to_string()).collect();
        s.push_str(&format!("   ({})", why.join(", ")));
    }
    s
}

/// Runs `nesy verify`.
pub(crate) fn run(args: VerifyArgs) -> anyhow::Result<ExitCode> {
    let domain_text = read(&args.domain)?;
    let problem_text = read(&args.problem)?;
    let plan_text = read(&args.plan)?;
    let domain = parse_domain(&domain_text).map_err(|e| located(&args.domain, e))?;
    let problem = parse_problem(&problem_text, &domain).map_err(|e| located(&args.problem, e))?;
    let universe = domain
        .universe(&problem)
        .with_context(|| format!("{}: inconsistent types", args.problem.display()))?;
    let steps = parse_plan(&plan_text).map_err(|e| located(&args.plan, e))?;
    let ops = ground_plan(&domain, &universe, &steps, &plan_text).map_err(|e| located(&args.plan, e))?;
    let report = verify_procedure_in(&universe, &problem.init, &ops, Some(&problem.goal));

    let failure = report.first_failure.map(|i| {
        let (unmet, error) = match &report.steps[i].status {
            StepStatus::Failed { violation } => (literals(&violation.unmet), None),
            StepStatus::Invalid { error } => (Vec::new(), Some(error.to_string())),
            _ => (Vec::new(), None),
        };
        Failure {
            step: i + 1,
            action: ops[i].display_name(),
            plan_line: steps[i].line,
            unmet,
            error,
        }
    });
    let verdict = Verdict {
        valid: report.is_valid(),
        steps: ops.len(),
        executed: report.applied_steps(),
        failure,
        goal_satisfied: report.goal.as_ref().map(|g| g.satisfied),
        unmet_goal: report
            .goal
            .as_ref()
            .map(|g| literals(&g.unmet))
            .unwrap_or_default(),
        report: &report,
    };

    if args.json {
        outln!("{}", serde_json::to_string_pretty(&verdict)?)?;
    } else if verdict.valid {
        outln!("Plan valid: {} step(s) executed, goal satisfied.", verdict.steps)?;
    } else if let Some(i) = report.first_failure {
        outln!(
            "Plan invalid: step {} {} (plan line {}) cannot be executed.",
            i + 1,
            ops[i].display_name(),
            steps[i].line
        )?;
        match &report.steps[i].status {
            StepStatus::Failed { violation } => {
                outln!("Unmet preconditions:")?;
                for u in &violation.unmet {
                    outln!("{}", explain(u))?;
                }
            }
            StepStatus::Invalid { error } => outln!("The step cannot be grounded: {error}")?,
            _ => {}
        }
        outln!("Goal: not checked (execution stopped at step {}).", i + 1)?;
    } else if let Some(g) = &report.goal {
        outln!(
            "Plan invalid: all {} step(s) executed, but the goal is not satisfied.",
            verdict.steps
        )?;
        outln!("Unmet goal conditions:")?;
        for u in &g.unmet {
            outln!("{}", explain(u))?;
        }
    } else if let Some(e) = &report.goal_error {
        return Err(anyhow!(
            "{}: the goal cannot be grounded: {e}",
            args.problem.display()
        ));
    }
    Ok(if verdict.valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
