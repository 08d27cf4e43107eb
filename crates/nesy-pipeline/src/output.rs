//! The run directory:
//!
//! | file | what it holds |
//! |---|---|
//! | `world_model.json` | the demonstrated states, the verified operators (structured and as action blocks), the goal, unverified steps |
//! | `adaptation.json` | status and budget; every violation found, every proposal with its verdict and feedback, every induction attempt; the outcome; the full nesy-core trace |
//! | `procedure.txt` | the demonstrated procedure and the adapted one, as action blocks |
//! | `policy.py` | the synthesized program (only when the adaptation resolved) |
//! | `execution.json` | the sandbox's result (outcome, API trace, output, subtasks, final state) and SR/GC/PD |
//! | `target_scene.json` | the scene as run (the input plus `embodiment_in_state` when embodiments differ) |
//! | `target_{top,front,back}[_marked].png` | the rendered target views |
//! | `report.md` | a readable summary embedding the target views |
//! | `summary.json` | what `--json` prints |
//! | `report.html` | the run for a browser: keyframes, operators, both procedures, policy, rollout ([`crate::report_html`]) |
//! | `execution.mcap`, `rollout.mp4` | the execution recorded (`--render-every N`) |
//! | `rollout_first.png`, `rollout_last.png` | a benchmark unit's recorded first and last frames |
//! | `failure.json` | only for a run that stopped before an outcome: the error, naming the call, and its failure kind (with `target_scene.json`) |

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nesy_core::adapt::{Adaptation, Outcome, ReasonerErrorKind, TraceEvent, Verdict};
use nesy_core::format_procedure;
use serde::Serialize;
use serde_json::json;

use crate::execute::ExecutionReport;
use crate::inputs::TargetInput;
use crate::states::StateSource;
use crate::synth::{CodegenMode, SynthError};
use crate::{AdaptRun, PipelineError, StopReason};
use nesy_vlm::RunUsage;

/// `world_model.json`.
pub const WORLD_MODEL_FILE: &str = "world_model.json";
/// `adaptation.json`.
pub const ADAPTATION_FILE: &str = "adaptation.json";
/// `procedure.txt`.
pub const PROCEDURE_FILE: &str = "procedure.txt";
/// `policy.py`.
pub const POLICY_FILE: &str = "policy.py";
/// `execution.json`.
pub const EXECUTION_FILE: &str = "execution.json";
/// `target_scene.json`.
pub const TARGET_SCENE_FILE: &str = "target_scene.json";
/// `report.md`.
pub const REPORT_FILE: &str = "report.md";
/// `summary.json`.
pub const SUMMARY_FILE: &str = "summary.json";
/// `execution.mcap`: the execution replayed and recorded in the demo format (a keyframe
/// after every action with the three views and the observer's state, and the goal checks).
pub const EXECUTION_RECORDING_FILE: &str = "execution.mcap";
/// `rollout.mp4`: the execution filmed from one camera, each frame captioned with its call.
pub const ROLLOUT_VIDEO_FILE: &str = "rollout.mp4";
/// `rollout_first.png`: the execution recording's first keyframe (before any call), one view.
pub const ROLLOUT_FIRST_FRAME_FILE: &str = "rollout_first.png";
/// `rollout_last.png`: the execution recording's last keyframe, one view.
pub const ROLLOUT_LAST_FRAME_FILE: &str = "rollout_last.png";
/// `failure.json`: written instead of the usual outputs when a run stops before it has an
/// outcome (a model call whose re-ask budget ran out, a transport failure, a cassette miss).
pub const FAILURE_FILE: &str = "failure.json";

/// What `failure.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct RunFailure<'a> {
    /// Always `failed`.
    pub status: &'static str,
    /// Why the run stopped (`no_usable_reply`, `request_refused`, ...).
    pub stopped: StopReason,
    /// The error, with the call that failed (`operator induction for transition 3 (attempt
    /// 2): ...`, `state translation for target/initial: ...`).
    pub error: String,
    /// The reasoner failure kind, when a model call failed (`transport`, `reply`, `replay`, ...).
    pub failure: Option<ReasonerErrorKind>,
    /// The target scene as given.
    pub target: &'a Path,
    /// Seconds from the start of the run to the stop.
    pub elapsed_s: f64,
    /// The model calls made before the stop: counts, tokens and latency, by purpose.
    pub calls: &'a RunUsage,
}

/// A run directory: where one episode's files go, each under its fixed name. Every write
/// names the file it could not write; none is dropped. `nesy adapt`, the pipeline's
/// execution step and the benchmark's units all write through it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunDir {
    path: PathBuf,
}

impl RunDir {
    /// The directory at `path`, created (with its parents) if missing.
    pub fn create(path: impl Into<PathBuf>) -> Result<RunDir, PipelineError> {
        let path = path.into();
        std::fs::create_dir_all(&path).map_err(|e| PipelineError::write(&path, e))?;
        Ok(RunDir { path })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path of the file `name` in the directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Writes the text file `name`; returns its path.
    pub fn write_text(&self, name: &str, contents: &str) -> Result<PathBuf, PipelineError> {
        let path = self.file(name);
        std::fs::write(&path, contents).map_err(|e| PipelineError::write(&path, e))?;
        Ok(path)
    }

    /// Writes `value` as pretty JSON with a trailing newline to the file `name`; returns its
    /// path.
    pub fn write_json(&self, name: &str, value: &impl Serialize) -> Result<PathBuf, PipelineError> {
        let text = serde_json::to_string_pretty(value)
            .map_err(|e| PipelineError::write(self.file(name), std::io::Error::other(e)))?;
        self.write_text(name, &(text + "\n"))
    }

    /// Writes what execution needs before it starts: the target scene as run (when the
    /// target has one) and, when there is one, the program. Returns the scene file's path.
    pub fn prepare(
        &self,
        target: &TargetInput,
        program: Option<&str>,
    ) -> Result<Option<PathBuf>, PipelineError> {
        let scene_path = self.write_scene(target)?;
        if let Some(code) = program {
            self.write_text(POLICY_FILE, code)?;
        }
        Ok(scene_path)
    }

    /// Writes the target's simulated scene, when it has one.
    fn write_scene(&self, target: &TargetInput) -> Result<Option<PathBuf>, PipelineError> {
        target
            .scene
            .as_ref()
            .map(|scene| self.write_text(TARGET_SCENE_FILE, &scene.to_json_pretty()))
            .transpose()
    }

    /// Writes `failure.json` and the target scene for a run that stopped with `error`
    /// before it had an outcome, so no failed run leaves an empty directory. Errors of bad
    /// input (the demo, the scene, the settings) write nothing: they happen before the run.
    /// `calls` are the model calls made before the stop, `elapsed` the run's time to it.
    pub fn write_failure(
        &self,
        target: &TargetInput,
        error: &PipelineError,
        calls: &RunUsage,
        elapsed: std::time::Duration,
    ) -> Result<Option<PathBuf>, PipelineError> {
        if error.is_bad_input() {
            return Ok(None);
        }
        self.write_scene(target)?;
        let path = self.write_json(
            FAILURE_FILE,
            &RunFailure {
                status: "failed",
                stopped: error.stop_reason(),
                error: error.to_string(),
                failure: error.reasoner_kind(),
                target: &target.path,
                elapsed_s: elapsed.as_secs_f64(),
                calls,
            },
        )?;
        Ok(Some(path))
    }

    /// Replays `execution`'s recorded API calls on its scene and writes the recording
    /// (`execution.mcap`) and the first and last keyframes' `view` as PNG
    /// (`rollout_first.png`, `rollout_last.png`; the first view when there is no `view`).
    /// Rendering runs on `render_threads` threads. Returns the recording.
    pub fn write_execution_recording(
        &self,
        execution: &ExecutionReport,
        view: &str,
        render_threads: usize,
    ) -> Result<nesy_sim::demo::ExecutionRecording, PipelineError> {
        let mcap = self.file(EXECUTION_RECORDING_FILE);
        let failed = |message: String| PipelineError::write(&mcap, std::io::Error::other(message));
        let scene = nesy_sim::scene::SceneSpec::from_file(&execution.scene_path).map_err(|e| {
            failed(format!(
                "reading the scene {}: {e}",
                execution.scene_path.display()
            ))
        })?;
        let options = nesy_sim::demo::RecordOptions {
            side: Some("execution".to_owned()),
            render_threads,
            ..nesy_sim::demo::RecordOptions::default()
        };
        let recording = nesy_sim::demo::replay_execution(&scene, &execution.result.trace, &options, None)
            .map_err(|e| failed(format!("replaying the execution: {e}")))?;
        recording
            .write_mcap_file(&mcap, None)
            .map_err(|e| failed(e.to_string()))?;
        let keyframes = &recording.demo.keyframes;
        for (name, keyframe) in [
            (ROLLOUT_FIRST_FRAME_FILE, keyframes.first()),
            (ROLLOUT_LAST_FRAME_FILE, keyframes.last()),
        ] {
            let Some(keyframe) = keyframe else { continue };
            let images = keyframe
                .views
                .get(view)
                .or_else(|| keyframe.views.iter().next().map(|v| &v.images));
            if let Some(images) = images {
                let path = self.file(name);
                std::fs::write(&path, &images.raw).map_err(|e| PipelineError::write(&path, e))?;
            }
        }
        Ok(recording)
    }

    /// Writes every output of `run`.
    pub fn write_all(&self, run: &AdaptRun, target: &TargetInput) -> Result<(), PipelineError> {
        self.prepare(target, run.policy.as_ref().map(|p| p.code.as_str()))?;
        let wm = &run.adaptation.world_model;
        self.write_json(
            WORLD_MODEL_FILE,
            &json!({
                "demo": run.demo_path,
                "tier": run.setting.tier,
                "states": run.demo_states,
                "procedure": wm.procedure,
                "procedure_text": format_procedure(&wm.procedure),
                "goal": wm.goal.to_string(),
                "unverified_steps": wm.unverified_steps,
                "verified": wm.is_verified(),
            }),
        )?;
        let outcome_name = if run.adaptation.outcome.is_adapted() {
            "adapted"
        } else {
            "unresolved"
        };
        self.write_json(
            ADAPTATION_FILE,
            &json!({
                "status": outcome_name,
                "budget": run.setting.budget,
                "target_state": run.target_state,
                "violations": violations(&run.adaptation),
                "proposals": proposals(&run.adaptation),
                "inductions": inductions(&run.adaptation),
                "outcome": run.adaptation.outcome,
                "trace": run.adaptation.trace,
            }),
        )?;
        self.write_text(PROCEDURE_FILE, &procedure_text(run))?;
        if let Some(execution) = &run.execution {
            self.write_json(EXECUTION_FILE, execution)?;
        }
        for view in &target.views {
            let images = [
                (false, Some(&view.images.raw)),
                (true, view.images.marked.as_ref()),
            ];
            for (marked, bytes) in images {
                let Some(bytes) = bytes else { continue };
                let path = self.file(&target_view_file(&view.name, marked, bytes));
                std::fs::write(&path, bytes).map_err(|e| PipelineError::write(&path, e))?;
            }
        }
        self.write_text(REPORT_FILE, &report_markdown(run, target))?;
        self.write_json(SUMMARY_FILE, run)?;
        Ok(())
    }
}

/// One violation the symbolic executor found while identifying (Eq. 6).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct FoundViolation {
    /// Loop iteration.
    pub iteration: usize,
    /// `precondition` or `goal`.
    pub kind: &'static str,
    /// 0-based failing step (precondition violations).
    pub step: Option<usize>,
    /// The failing action.
    pub action: Option<String>,
    /// The unmet literals, as written.
    pub unmet: Vec<String>,
}

/// One patch proposal and its verdict.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ProposalSummary {
    /// Loop iteration.
    pub iteration: usize,
    /// `accepted` or `rejected`.
    pub verdict: &'static str,
    /// Why it was rejected (the verifier's message).
    pub feedback: Option<String>,
    /// Number of actions after the patch, when accepted.
    pub actions_after: Option<usize>,
    /// The model's reply.
    pub reply: String,
}

/// Every violation identification found, in order.
pub fn violations(adaptation: &Adaptation) -> Vec<FoundViolation> {
    let mut found = Vec::new();
    for event in &adaptation.trace.events {
        let TraceEvent::Identification {
            iteration,
            procedure,
            report,
        } = event
        else {
            continue;
        };
        if let Some(v) = report.first_violation() {
            found.push(FoundViolation {
                iteration: *iteration,
                kind: "precondition",
                step: report.first_failure,
                action: report
                    .first_failure
                    .and_then(|i| procedure.get(i))
                    .map(|o| o.display_name())
                    .or_else(|| Some(v.action.clone())),
                unmet: v.unmet.iter().map(|u| u.literal.to_string()).collect(),
            });
        } else if let Some(goal) = report.goal.as_ref().filter(|g| !g.satisfied) {
            found.push(FoundViolation {
                iteration: *iteration,
                kind: "goal",
                step: None,
                action: None,
                unmet: goal.unmet.iter().map(|u| u.literal.to_string()).collect(),
            });
        }
    }
    found
}

/// Every proposal, in order.
pub fn proposals(adaptation: &Adaptation) -> Vec<ProposalSummary> {
    adaptation
        .trace
        .events
        .iter()
        .filter_map(|event| match event {
            TraceEvent::Proposal {
                iteration,
                reply,
                verdict,
                procedure_after,
                ..
            } => Some(ProposalSummary {
                iteration: *iteration,
                verdict: match verdict {
                    Verdict::Accepted { .. } => "accepted",
                    Verdict::Rejected { .. } => "rejected",
                },
                feedback: match verdict {
                    Verdict::Rejected { feedback } => Some(feedback.message.clone()),
                    Verdict::Accepted { .. } => None,
                },
                actions_after: procedure_after.as_ref().map(Vec::len),
                reply: reply.clone(),
            }),
            _ => None,
        })
        .collect()
}

/// Induction attempts: (transition, attempt, accepted, feedback).
fn inductions(adaptation: &Adaptation) -> Vec<serde_json::Value> {
    adaptation
        .trace
        .events
        .iter()
        .filter_map(|event| match event {
            TraceEvent::Induction {
                step,
                attempt,
                reply,
                verdict,
                ..
            } => Some(json!({
                "step": step,
                "attempt": attempt,
                "verdict": match verdict { Verdict::Accepted { .. } => "accepted", Verdict::Rejected { .. } => "rejected" },
                "feedback": match verdict { Verdict::Rejected { feedback } => Some(feedback.message.clone()), _ => None },
                "reply": reply,
            })),
            _ => None,
        })
        .collect()
}

/// The code-generation replies that were re-asked, each with its problem and the reply.
fn write_rejected_programs(md: &mut String, rejected: &[nesy_reasoner::codegen::RejectedProgram]) {
    for (i, r) in rejected.iter().enumerate() {
        let _ = writeln!(
            md,
            "Reply {} was not used ({}):\n\n````text\n{}\n````\n",
            i + 1,
            r.problem,
            r.reply.trim_end()
        );
    }
}

/// How many induction calls the run made, and how many replies were rejected or unreadable.
pub fn induction_counts(adaptation: &Adaptation) -> InductionCounts {
    let mut counts = InductionCounts::default();
    for event in &adaptation.trace.events {
        if let TraceEvent::Induction { verdict, .. } = event {
            counts.calls += 1;
            if let Verdict::Rejected { feedback } = verdict {
                if feedback.problem.is_unreadable() {
                    counts.unreadable += 1;
                } else {
                    counts.rejected += 1;
                }
            }
        }
    }
    counts
}

/// How the induction calls of a run went.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InductionCounts {
    /// Induction calls made.
    pub calls: usize,
    /// Replies the verifier rejected.
    pub rejected: usize,
    /// Replies that could not be read (nothing was verified).
    pub unreadable: usize,
}

impl InductionCounts {
    /// `N induction calls, M rejected by the verifier[, K could not be read]`.
    pub fn summary(&self) -> String {
        let mut text = format!(
            "{} induction call{}, {} rejected by the verifier",
            self.calls,
            if self.calls == 1 { "" } else { "s" },
            self.rejected
        );
        if self.unreadable > 0 {
            text.push_str(&format!(", {} could not be read", self.unreadable));
        }
        text
    }
}

/// `procedure.txt`.
pub fn procedure_text(run: &AdaptRun) -> String {
    let mut text = String::new();
    let demonstrated = run.demonstrated();
    let _ = writeln!(
        text,
        "# Demonstrated procedure ({} actions)\n",
        demonstrated.len()
    );
    text.push_str(&format_procedure(demonstrated));
    text.push_str("\n\n");
    match &run.adaptation.outcome {
        Outcome::Adapted {
            procedure,
            iterations,
            ..
        } => {
            let _ = writeln!(
                text,
                "# Adapted procedure ({} actions, verified from the target's initial state; {iterations} proposal(s))\n",
                procedure.len()
            );
            text.push_str(&format_procedure(procedure));
        }
        Outcome::Unresolved { best, iterations, .. } => {
            let _ = writeln!(
                text,
                "# UNRESOLVED after {iterations} proposal(s): no verified procedure. The one that got furthest ({} actions), NOT verified:\n",
                best.len()
            );
            text.push_str(&format_procedure(best));
        }
    }
    text.push('\n');
    text
}

/// `report.md`: the run for a human, with the target views embedded.
pub fn report_markdown(run: &AdaptRun, target: &TargetInput) -> String {
    let mut md = String::new();
    write_run_header(&mut md, run);
    write_target(&mut md, run, target);
    write_world_model(&mut md, run);
    write_adaptation(&mut md, run);
    write_policy(&mut md, run);
    if let Some(execution) = &run.execution {
        write_execution(&mut md, execution);
    }
    write_time(&mut md, run);
    md
}

/// The title, the inputs, the setting and where the states came from.
fn write_run_header(md: &mut String, run: &AdaptRun) {
    let _ = writeln!(md, "# nesy adapt: {}\n", run.status.as_str());
    let _ = writeln!(md, "- demo: `{}`", run.demo_path.display());
    let _ = writeln!(md, "- target: `{}`", run.target_path.display());
    let s = &run.setting;
    let _ = writeln!(
        md,
        "- embodiment: {} → {}; predicate tier `{:?}`; factor {:?}, complexity {:?}; budget {} ({})",
        s.source_embodiment, s.target_embodiment, s.tier, s.factor, s.complexity, s.budget, s.budget_origin
    );
    let states = match &run.states {
        StateSource::Observed => "observed (simulator ground truth)".to_owned(),
        StateSource::Vlm {
            translated,
            rejected_atoms,
            reasked_replies,
            agreement,
        } => format!(
            "VLM state translation ({translated} states, {reasked_replies} replies re-asked, {rejected_atoms} atoms outside the tier left out{})",
            agreement
                .map(|a| format!(", F1 {:.2} against ground truth", a.f1))
                .unwrap_or_default()
        ),
    };
    let _ = writeln!(md, "- states: {states}\n");
}

/// The run directory's file for one of the target's views: `target_<view>[_marked].<png|jpg>`.
fn target_view_file(view: &str, marked: bool, bytes: &[u8]) -> String {
    let format = nesy_sim::demo::ImageFormat::of(bytes).unwrap_or(nesy_sim::demo::ImageFormat::Png);
    let suffix = if marked { "_marked" } else { "" };
    format!("target_{view}{suffix}.{}", format.extension())
}

/// The target's instruction, marked views and initial state.
fn write_target(md: &mut String, run: &AdaptRun, target: &TargetInput) {
    let _ = writeln!(md, "## Target scene\n");
    let _ = writeln!(md, "Instruction: {}\n", run.instruction);
    for view in &target.views {
        let marked = view.images.marked.is_some();
        let file = target_view_file(&view.name, marked, view.images.marked_or_raw());
        let _ = write!(md, "![{} view]({file}) ", view.name);
    }
    let _ = writeln!(md, "\n\nInitial state:\n\n```\n{}\n```\n", run.target_state);
}

/// How many operators were induced and verified, and the goal.
fn write_world_model(md: &mut String, run: &AdaptRun) {
    let counts = induction_counts(&run.adaptation);
    let wm = &run.adaptation.world_model;
    let _ = writeln!(md, "## World model\n");
    let _ = writeln!(
        md,
        "{} operators from {} keyframes; {}; {}.\n",
        wm.procedure.len(),
        run.demo_states.len(),
        counts.summary(),
        if wm.is_verified() {
            "every operator verified".to_owned()
        } else {
            format!("UNVERIFIED transitions: {:?}", wm.unverified_steps)
        }
    );
    let _ = writeln!(md, "Goal: `{}`\n", wm.goal);
}

/// Each violation found and each proposal's verdict, then the procedures.
fn write_adaptation(md: &mut String, run: &AdaptRun) {
    let _ = writeln!(md, "## Counterfactual adaptation\n");
    for v in violations(&run.adaptation) {
        match v.kind {
            "precondition" => {
                let _ = writeln!(
                    md,
                    "- iteration {}: step {} `{}` violates {}",
                    v.iteration + 1,
                    v.step.map(|s| s + 1).unwrap_or_default(),
                    v.action.unwrap_or_default(),
                    v.unmet.join(", ")
                );
            }
            _ => {
                let _ = writeln!(
                    md,
                    "- iteration {}: goal unmet: {}",
                    v.iteration + 1,
                    v.unmet.join(", ")
                );
            }
        }
    }
    for p in proposals(&run.adaptation) {
        let _ = writeln!(
            md,
            "- proposal {}: {}{}",
            p.iteration + 1,
            p.verdict,
            p.feedback
                .map(|f| format!(" — {}", f.lines().next().unwrap_or_default()))
                .unwrap_or_default()
        );
    }
    let _ = writeln!(md, "\n```\n{}```\n", procedure_text(run));
}

/// The program and how it was obtained, or why there is none.
fn write_policy(md: &mut String, run: &AdaptRun) {
    let _ = writeln!(md, "## Policy\n");
    match (&run.policy, &run.codegen_error) {
        (Some(p), _) => {
            let how = match p.mode {
                CodegenMode::Vlm => "the VLM's code generation",
                CodegenMode::Template => "the template compiler",
            };
            let _ = writeln!(
                md,
                "`policy.py`, from {how}:\n\n```python\n{}\n```\n",
                p.code.trim_end()
            );
            write_rejected_programs(md, &p.rejected);
        }
        (None, Some(e)) => {
            let _ = writeln!(md, "Code synthesis failed: {e}\n");
            if let SynthError::NoProgram { replies, .. } = e {
                write_rejected_programs(md, replies);
            }
        }
        (None, None) => {
            let _ = writeln!(
                md,
                "No policy: the adaptation did not resolve, and an unverified plan is never compiled.\n"
            );
        }
    }
}

/// The episode's outcome, its goal checks and its API trace.
fn write_execution(md: &mut String, execution: &ExecutionReport) {
    let _ = writeln!(md, "## Execution\n");
    let r = &execution.result;
    let actions = r.trace.iter().filter(|e| e.call.is_action()).count();
    let _ = writeln!(
        md,
        "Outcome `{}`; {} API calls ({} actions); {:.2} s.\n",
        r.outcome.kind(),
        r.trace.len(),
        actions,
        r.wall_time_s
    );
    match &execution.metrics {
        Some(m) => {
            for s in &m.subtasks {
                let _ = writeln!(md, "- {}: {:?}", s.subtask, s.status);
            }
            let _ = writeln!(
                md,
                "\nSR {:.0}, GC {:.2}, PD {}\n",
                m.sr,
                m.gc,
                m.pd.map(|p| format!("{p:.2}")).unwrap_or_else(|| "n/a".into())
            );
        }
        None => {
            let _ = writeln!(md, "No goal checks were reported for this episode.\n");
        }
    }
    let _ = writeln!(md, "API trace:\n\n```");
    for e in &r.trace {
        let _ = writeln!(
            md,
            "{:>3} {} {}",
            e.index,
            serde_json::to_string(&e.call).unwrap_or_default(),
            match &e.result {
                Ok(_) => "ok".to_owned(),
                Err(err) => format!("REFUSED: {err}"),
            }
        );
    }
    let _ = writeln!(md, "```\n");
}

/// The time breakdown (the paper's Table 9).
fn write_time(md: &mut String, run: &AdaptRun) {
    let t = &run.timing;
    let _ = writeln!(md, "## Time\n");
    let _ = writeln!(
        md,
        "| VLM | symbolic (world model + adaptation) | template compiler | simulation | total |\n|---|---|---|---|---|"
    );
    let _ = writeln!(
        md,
        "| {:.3} s | {:.3} ms ({:.3} + {:.3}) | {:.3} ms | {:.3} s | {:.3} s |",
        t.vlm_s,
        t.symbolic_s * 1e3,
        t.symbolic_world_model_s * 1e3,
        t.symbolic_adaptation_s * 1e3,
        t.codegen_template_s * 1e3,
        t.sim_s,
        t.total_s
    );
}
