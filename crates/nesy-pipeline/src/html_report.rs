//! `report.html`: one `nesy adapt` run for a person to look at, self-contained in the run
//! directory. The demonstration's keyframes with their states, the induced operators with the
//! verifier's verdicts, the demonstrated and adapted procedures side by side (each violated
//! precondition and each accepted patch marked where it happened), the policy, the rollout,
//! the metrics and the times. Pictures are embedded; the rollout video and the other files
//! are linked beside the page. `report.md` says the same in text.

use std::collections::{BTreeMap, BTreeSet};

use nesy_core::adapt::{Outcome, TraceEvent, Verdict};
use nesy_core::{Operator, format_procedure};
use nesy_sim::demo::{CameraImages, ImageFormat};
use nesy_view::{Html, Page};

use crate::AdaptRun;
use crate::inputs::{DemoInput, TargetInput};
use crate::output::{
    ADAPTATION_FILE, EXECUTION_FILE, POLICY_FILE, PROCEDURE_FILE, REPORT_FILE, SUMMARY_FILE,
    TARGET_SCENE_FILE, WORLD_MODEL_FILE, induction_counts, proposals, violations,
};
use crate::states::StateSource;
use crate::synth::CodegenMode;

/// `report.html`.
pub const HTML_REPORT_FILE: &str = "report.html";

/// The execution's recording files beside the page, when the run wrote them.
#[derive(Debug, Clone, Default)]
pub struct RolloutFiles {
    /// The rollout video (`rollout.mp4`), relative to the run directory.
    pub video: String,
    /// The execution recording (`execution.mcap`), relative to the run directory.
    pub recording: String,
    /// One line on what they hold (frames, keyframes, any divergence).
    pub summary: String,
}

/// The page for `run` (its demonstration `demo`, its target `target`, and the rollout files
/// when there are some).
pub fn report_html(
    run: &AdaptRun,
    demo: &DemoInput,
    target: &TargetInput,
    rollout: Option<&RolloutFiles>,
) -> String {
    let mut page = Page::new(&format!("nesy adapt: {}", run.status.as_str()));
    page.push(overview(run));
    page.section("demonstration", "Demonstration", demonstration(run, demo));
    page.section("operators", "Induced operators", operators(run));
    page.section("adaptation", "Counterfactual adaptation", adaptation(run));
    page.section("target", "Target scene", target_views(run, target));
    page.section("policy", "Policy", policy(run));
    page.section("execution", "Execution", execution(run, rollout));
    page.section("time", "Time and model calls", time(run));
    page.section("files", "Files", files(run, rollout));
    page.finish()
}

/// The verdict line and the run's inputs and setting.
fn overview(run: &AdaptRun) -> Html {
    let class = if run.exit_code() == 0 { "ok" } else { "bad" };
    let s = &run.setting;
    let states = match &run.states {
        StateSource::Observed => "observed (ground truth)".to_owned(),
        StateSource::Vlm {
            translated,
            agreement,
            ..
        } => format!(
            "translated by the model ({translated} states{})",
            agreement
                .map(|a| format!(", F1 {:.2} against ground truth", a.f1))
                .unwrap_or_default()
        ),
    };
    let models = if run.usage.by_model.is_empty() {
        "no model call".to_owned()
    } else {
        run.usage.by_model.keys().cloned().collect::<Vec<_>>().join(", ")
    };
    let rows = [
        ("instruction", run.instruction.clone()),
        ("demonstration", run.demo_path.display().to_string()),
        ("target", run.target_path.display().to_string()),
        (
            "embodiment",
            format!("{} → {}", s.source_embodiment, s.target_embodiment),
        ),
        (
            "setting",
            format!(
                "predicate tier {:?}; factor {:?}, complexity {:?}; budget {} ({})",
                s.tier, s.factor, s.complexity, s.budget, s.budget_origin
            ),
        ),
        ("states", states),
        ("answered by", models),
    ];
    Html::concat([
        Html::tag("p", class, Html::text(&verdict_line(run))),
        Html::key_values(rows.iter().map(|(k, v)| (k.to_string(), Html::text(v)))),
    ])
}

/// One line: how the run ended.
fn verdict_line(run: &AdaptRun) -> String {
    let mut line = match &run.adaptation.outcome {
        Outcome::Adapted {
            procedure,
            iterations,
            ..
        } => format!(
            "Adapted: a verified procedure of {} actions after {iterations} proposal(s).",
            procedure.len()
        ),
        Outcome::Unresolved { iterations, .. } => {
            format!("Unresolved after {iterations} proposal(s): no verified procedure.")
        }
    };
    if let Some(m) = run.execution.as_ref().and_then(|e| e.metrics.as_ref()) {
        line.push_str(&format!(
            " Executed: SR {:.0}, GC {:.2}, PD {}.",
            m.sr,
            m.gc,
            m.pd.map(|p| format!("{p:.2}")).unwrap_or_else(|| "n/a".into())
        ));
    }
    line
}

/// A picture of a view (its marked version when there is one), embedded.
fn view_image(images: &CameraImages, alt: &str) -> Html {
    let bytes = images.marked_or_raw();
    let format = ImageFormat::of(bytes).unwrap_or(ImageFormat::Png);
    Html::image(bytes, format.mime(), alt)
}

/// Each keyframe: its first view, the call that led to it, and its state (folded).
fn demonstration(run: &AdaptRun, demo: &DemoInput) -> Html {
    let keyframes = &demo.demo.keyframes;
    let meta = &demo.demo.metadata;
    let intro = Html::tag(
        "p",
        "",
        Html::text(&format!(
            "{} keyframes demonstrated by {} ({} end effector): \"{}\". One view per keyframe; the state under each is the one the run used.",
            keyframes.len(),
            match meta.demonstrator {
                nesy_sim::demo::Demonstrator::Robot => "a robot",
                nesy_sim::demo::Demonstrator::Human => "a person",
            },
            meta.embodiment,
            meta.instruction
        )),
    );
    let procedure = run.demonstrated();
    let cards = keyframes.iter().enumerate().map(|(i, keyframe)| {
        let picture = keyframe
            .views
            .iter()
            .next()
            .map(|view| view_image(&view.images, &format!("keyframe {i}, {} view", view.name)))
            .unwrap_or_else(Html::empty);
        let call = keyframe
            .action
            .as_ref()
            .map(|a| format!("after {}", a.call.label()))
            .unwrap_or_else(|| "initial scene".into());
        let operator = if i > 0 {
            procedure
                .get(i - 1)
                .map(|op| format!("a_{i} = {}", op.display_name()))
                .unwrap_or_default()
        } else {
            String::new()
        };
        let state = run
            .demo_states
            .get(i)
            .map(|s| {
                Html::details(
                    &format!("s_{} ({} facts)", i + 1, s.len()),
                    Html::pre(&s.to_string()),
                    false,
                )
            })
            .unwrap_or_else(Html::empty);
        Html::tag(
            "div",
            "card",
            Html::concat([
                Html::tag("h3", "", Html::text(&format!("keyframe {i}"))),
                picture,
                Html::tag("p", "muted", Html::text(&call)),
                Html::tag("p", "", Html::text(&operator)),
                state,
            ]),
        )
    });
    Html::concat([intro, Html::tag("div", "grid", Html::concat(cards))])
}

/// Per transition: the operator used, how many replies it took, the verdict, and the
/// verifier's messages on the rejected replies.
fn operators(run: &AdaptRun) -> Html {
    let wm = &run.adaptation.world_model;
    let mut attempts: BTreeMap<usize, Vec<(usize, &Verdict, &str)>> = BTreeMap::new();
    for event in &run.adaptation.trace.events {
        if let TraceEvent::Induction {
            step,
            attempt,
            reply,
            verdict,
            ..
        } = event
        {
            attempts
                .entry(*step)
                .or_default()
                .push((*attempt, verdict, reply));
        }
    }
    let summary = Html::tag(
        "p",
        "",
        Html::text(&format!(
            "{} operators; {}; goal {}.",
            wm.procedure.len(),
            induction_counts(&run.adaptation).summary(),
            wm.goal
        )),
    );
    let rows = wm.procedure.iter().enumerate().map(|(step, op)| {
        let tries = attempts.get(&step).map(Vec::as_slice).unwrap_or_default();
        let verified = !wm.unverified_steps.contains(&step);
        let verdict = if verified {
            Html::tag("span", "ok", Html::text("verified"))
        } else {
            Html::tag("span", "bad", Html::text("UNVERIFIED (last readable reply used)"))
        };
        let rejected = tries
            .iter()
            .filter_map(|(attempt, verdict, reply)| match verdict {
                Verdict::Rejected { feedback } => Some(Html::details(
                    &format!(
                        "reply {} rejected: {}",
                        attempt + 1,
                        first_line(&feedback.message)
                    ),
                    Html::concat([Html::pre(&feedback.message), Html::pre(reply)]),
                    false,
                )),
                Verdict::Accepted { .. } => None,
            });
        vec![
            Html::text(&format!("{} → {}", step + 1, step + 2)),
            Html::pre(&format_procedure(std::slice::from_ref(op))),
            Html::concat([
                verdict,
                Html::tag(
                    "p",
                    "muted",
                    Html::text(&format!(
                        "{} repl{}",
                        tries.len(),
                        if tries.len() == 1 { "y" } else { "ies" }
                    )),
                ),
                Html::concat(rejected),
            ]),
        ]
    });
    Html::concat([
        summary,
        Html::table(&["transition", "operator", "verifier"], rows),
    ])
}

/// The iterations (violation found, proposal and verdict), then both procedures side by side.
fn adaptation(run: &AdaptRun) -> Html {
    let found = violations(&run.adaptation);
    let proposed = proposals(&run.adaptation);
    let mut rows = Vec::new();
    let iterations: BTreeSet<usize> = found
        .iter()
        .map(|v| v.iteration)
        .chain(proposed.iter().map(|p| p.iteration))
        .collect();
    for iteration in iterations {
        let violation = found
            .iter()
            .filter(|v| v.iteration == iteration)
            .map(|v| match v.step {
                Some(step) => Html::text(&format!(
                    "step {} {} needs {}",
                    step + 1,
                    v.action.clone().unwrap_or_default(),
                    v.unmet.join(", ")
                )),
                None => Html::text(&format!("goal unmet: {}", v.unmet.join(", "))),
            });
        let proposal = proposed.iter().filter(|p| p.iteration == iteration).map(|p| {
            let class = if p.verdict == "accepted" { "ok" } else { "bad" };
            let headline = match (&p.feedback, p.actions_after) {
                (Some(feedback), _) => format!("rejected: {}", first_line(feedback)),
                (None, Some(n)) => format!("accepted ({n} actions after it)"),
                (None, None) => "accepted".to_owned(),
            };
            Html::concat([
                Html::tag("span", class, Html::text(&headline)),
                Html::details("the reply", Html::pre(&p.reply), false),
            ])
        });
        let violation = Html::concat(violation);
        let violation = if violation.is_empty() {
            Html::tag("span", "muted", Html::text("the same as before"))
        } else {
            violation
        };
        rows.push(vec![
            Html::text(&(iteration + 1).to_string()),
            violation,
            Html::concat(proposal),
        ]);
    }
    if let Some(TraceEvent::GaveUp { iteration, message }) = run
        .adaptation
        .trace
        .events
        .iter()
        .find(|e| matches!(e, TraceEvent::GaveUp { .. }))
    {
        rows.push(vec![
            Html::text(&(iteration + 1).to_string()),
            Html::empty(),
            Html::tag("span", "bad", Html::text(&format!("gave up: {message}"))),
        ]);
    }
    let timeline = if rows.is_empty() {
        Html::tag(
            "p",
            "",
            Html::text("The demonstrated procedure holds in the target scene as it is: nothing to adapt."),
        )
    } else {
        Html::table(&["iteration", "violation found", "proposal"], rows)
    };
    let (adapted, title) = match &run.adaptation.outcome {
        Outcome::Adapted { procedure, .. } => (procedure.as_slice(), "Adapted (verified)"),
        Outcome::Unresolved { best, .. } => (best.as_slice(), "Furthest attempt (NOT verified)"),
    };
    Html::concat([timeline, side_by_side(run.demonstrated(), adapted, title, &found)])
}

/// The demonstrated procedure (the first violation it met marked) beside the adapted one
/// (each action the patches added marked).
fn side_by_side(
    demonstrated: &[Operator],
    adapted: &[Operator],
    adapted_title: &str,
    found: &[crate::output::FoundViolation],
) -> Html {
    let first_violation = found.iter().find(|v| v.iteration == 0).and_then(|v| v.step);
    let demonstrated_names: BTreeSet<String> = demonstrated.iter().map(Operator::display_name).collect();
    let demo_rows = demonstrated.iter().enumerate().map(|(i, op)| {
        let violated = first_violation == Some(i);
        let name = op.display_name();
        let cell = if violated {
            Html::tag(
                "span",
                "violation",
                Html::text(&format!("{name}  ← first violated precondition in the target")),
            )
        } else {
            Html::text(&name)
        };
        vec![Html::text(&(i + 1).to_string()), cell]
    });
    let adapted_rows = adapted.iter().enumerate().map(|(i, op)| {
        let name = op.display_name();
        let cell = if demonstrated_names.contains(&name) {
            Html::text(&name)
        } else {
            Html::tag(
                "span",
                "patched",
                Html::text(&format!("{name}  ← added by a patch")),
            )
        };
        vec![Html::text(&(i + 1).to_string()), cell]
    });
    Html::tag(
        "div",
        "columns",
        Html::concat([
            procedure_column(
                &format!("Demonstrated ({} actions)", demonstrated.len()),
                demo_rows,
            ),
            procedure_column(
                &format!("{adapted_title} ({} actions)", adapted.len()),
                adapted_rows,
            ),
        ]),
    )
}

/// One column of the side-by-side procedures: its title over its numbered actions.
fn procedure_column(title: &str, rows: impl IntoIterator<Item = Vec<Html>>) -> Html {
    Html::tag(
        "div",
        "",
        Html::concat([
            Html::tag("h3", "", Html::text(title)),
            Html::table(&["#", "action"], rows),
        ]),
    )
}

/// The target's views and initial state.
fn target_views(run: &AdaptRun, target: &TargetInput) -> Html {
    let views = target
        .views
        .iter()
        .map(|view| view_image(&view.images, &format!("target, {} view", view.name)));
    Html::concat([
        Html::tag("p", "", Html::text(&format!("Instruction: {}", run.instruction))),
        Html::tag("div", "frames", Html::concat(views)),
        Html::details(
            &format!("initial state ŝ_1 ({} facts)", run.target_state.len()),
            Html::pre(&run.target_state.to_string()),
            false,
        ),
    ])
}

/// The program and how it was made, or why there is none.
fn policy(run: &AdaptRun) -> Html {
    match (&run.policy, &run.codegen_error) {
        (Some(p), _) => {
            let how = match p.mode {
                CodegenMode::Vlm => "the model's code generation",
                CodegenMode::Template => "the template compiler",
            };
            let rejected = p.rejected.iter().enumerate().map(|(i, r)| {
                Html::details(
                    &format!("reply {} not used: {}", i + 1, r.problem),
                    Html::pre(&r.reply),
                    false,
                )
            });
            Html::concat([
                Html::tag("p", "", Html::text(&format!("From {how}:"))),
                Html::pre(&p.code),
                Html::concat(rejected),
            ])
        }
        (None, Some(e)) => Html::tag("p", "bad", Html::text(&format!("Code synthesis failed: {e}"))),
        (None, None) => Html::tag(
            "p",
            "",
            Html::text(
                "No policy: the adaptation did not resolve, and an unverified plan is never compiled.",
            ),
        ),
    }
}

/// The rollout, the goal checks and the API trace.
fn execution(run: &AdaptRun, rollout: Option<&RolloutFiles>) -> Html {
    let Some(execution) = &run.execution else {
        let why = run.not_executed.clone().unwrap_or_else(|| {
            "Not executed (run with --execute to run the policy in the simulator).".into()
        });
        return Html::tag("p", "muted", Html::text(&why));
    };
    let r = &execution.result;
    let mut parts = vec![Html::tag(
        "p",
        "",
        Html::text(&format!(
            "Outcome {}; {} API calls ({} actions); {:.2} s in the sandbox.",
            r.outcome.kind(),
            r.trace.len(),
            r.trace.iter().filter(|e| e.call.is_action()).count(),
            r.wall_time_s
        )),
    )];
    match rollout {
        Some(files) => {
            parts.push(Html::video_file(&files.video, "the rollout"));
            parts.push(Html::tag("p", "muted", Html::text(&files.summary)));
        }
        None => parts.push(Html::tag(
            "p",
            "muted",
            Html::text("No rollout recorded (add --render-every N to film it)."),
        )),
    }
    if let Some(m) = &execution.metrics {
        let rows = m.subtasks.iter().map(|s| {
            vec![
                Html::text(&s.subtask.to_string()),
                Html::text(&format!("{:?}", s.status)),
            ]
        });
        parts.push(Html::table(&["subtask", "result"], rows));
    }
    let trace: String = r
        .trace
        .iter()
        .map(|e| {
            format!(
                "{:>3} {} {}\n",
                e.index,
                e.call.label(),
                match &e.result {
                    Ok(_) => "ok".to_owned(),
                    Err(err) => format!("REFUSED: {err}"),
                }
            )
        })
        .collect();
    parts.push(Html::details("API trace", Html::pre(&trace), false));
    Html::concat(parts)
}

/// The paper's Table 9 breakdown and the model calls by purpose.
fn time(run: &AdaptRun) -> Html {
    let t = &run.timing;
    let timing = Html::table(
        &[
            "model",
            "symbolic (world model + adaptation)",
            "template compiler",
            "simulation",
            "total",
        ],
        [vec![
            Html::text(&format!("{:.3} s", t.vlm_s)),
            Html::text(&format!(
                "{:.3} ms ({:.3} + {:.3})",
                t.symbolic_s * 1e3,
                t.symbolic_world_model_s * 1e3,
                t.symbolic_adaptation_s * 1e3
            )),
            Html::text(&format!("{:.3} ms", t.codegen_template_s * 1e3)),
            Html::text(&format!("{:.3} s", t.sim_s)),
            Html::text(&format!("{:.3} s", t.total_s)),
        ]],
    );
    let calls = Html::table(
        &["purpose", "calls", "prompt tokens", "completion tokens"],
        run.usage.by_purpose.iter().map(|(purpose, u)| {
            vec![
                Html::text(purpose),
                Html::text(&u.calls.to_string()),
                Html::text(&u.prompt_tokens.to_string()),
                Html::text(&u.completion_tokens.to_string()),
            ]
        }),
    );
    Html::concat([timing, calls])
}

/// Links to the run directory's other files.
fn files(run: &AdaptRun, rollout: Option<&RolloutFiles>) -> Html {
    let mut names = vec![
        REPORT_FILE,
        SUMMARY_FILE,
        WORLD_MODEL_FILE,
        ADAPTATION_FILE,
        PROCEDURE_FILE,
    ];
    if run.policy.is_some() {
        names.push(POLICY_FILE);
    }
    if run.execution.is_some() {
        names.push(EXECUTION_FILE);
        names.push(TARGET_SCENE_FILE);
    }
    let mut links: Vec<Html> = names.iter().map(|n| Html::link(n, n)).collect();
    if let Some(files) = rollout {
        links.push(Html::concat([
            Html::link(&files.recording, &files.recording),
            Html::text(" (opens in Foxglove)"),
        ]));
        links.push(Html::link(&files.video, &files.video));
    }
    Html::list(links)
}

/// The first line of a message.
fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or_default()
}
