//! One unit: its client and responder, phase A (the method's specification and its code)
//! and phase B (execution in the sandboxed simulator), and its result line.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use nesy_core::benchmark::Factor;
use nesy_core::format_procedure;
use nesy_pipeline::PipelineError;
use nesy_pipeline::execute::ExecutionReport;
use nesy_pipeline::output::RunDir;
use nesy_pipeline::states::StateSource;
use nesy_pipeline::synth::{CodegenMode, SandboxChecks, SynthError, SynthesisRequest};
use nesy_pipeline::{AdaptOptions, DemoInput, ImagesMode, derive_setting, execute, output, synth, vlm};
use nesy_policy::Limits;
use nesy_reasoner::VlmReasoner;
use nesy_reasoner::codegen::CodeGenerationRequest;
use nesy_sim::tasks::scenario::Side;
use nesy_vlm::{CassetteFile, RunUsage};
use nesy_vlm::{CassetteMode, CassetteOptions, CassetteTransport, Transport, VlmClient, VlmConfig};

use crate::manifest::Observation;
use crate::meter::{CallCounts, Metered};
use crate::methods::{self, FailureKind, Method, Specification, Specified, UnitInputs};
use crate::status::UnitStatus;
use crate::unit::Unit;
use crate::unit_record::{Agreement, Effort, Scores, SpecSummary, SubtaskScore, UnitRecord};
use crate::variant::Variant;

use super::config::ResponderSetup;
use super::reexec::reexecuted;
use super::shared::{PhaseA, PhaseAFailure, ScenarioInputs, Shared, UnitClient, cpu, scenario_inputs};

pub(super) fn unit_dir(shared: &Shared, unit: &Unit) -> PathBuf {
    shared
        .config
        .run_dir
        .join("units")
        .join(unit.key.folder(&unit.variant))
}

/// `ROOT/<scenario>/<variant>[.r<k>].json`. The suffix is appended, not set: a variant id
/// holds dots (`noise=op-drop=0.1`) and a repeat ends in `.r<k>`, and `set_extension` would
/// replace either, so two units would share one recording.
pub(super) fn cassette_path(unit: &Unit, root: &Path) -> PathBuf {
    recording_path(&unit.key, &unit.variant, root)
}

pub(super) fn recording_path(key: &crate::unit::UnitKey, variant: &Variant, root: &Path) -> PathBuf {
    let mut p = root.join(key.folder(variant)).into_os_string();
    p.push(".json");
    PathBuf::from(p)
}

/// The target scene's goal label and subtask names, for units that never executed.
pub(super) fn target_label(unit: &Unit) -> (Vec<String>, Vec<String>) {
    match unit.scenario.generate(Side::Target) {
        Ok(t) => (
            t.goal_label,
            t.scene
                .goals
                .iter()
                .map(|g| g.kind().as_str().to_owned())
                .collect(),
        ),
        Err(_) => (Vec::new(), Vec::new()),
    }
}

pub(super) fn failed_record(
    shared: &Shared,
    unit: &Unit,
    status: UnitStatus,
    error: String,
    effort: Effort,
) -> UnitRecord {
    let (label, subtasks) = target_label(unit);
    base_record(
        shared,
        unit,
        status,
        Some(error),
        Scores::not_executed(label, &subtasks),
        effort,
    )
}

pub(super) fn base_record(
    shared: &Shared,
    unit: &Unit,
    status: UnitStatus,
    error: Option<String>,
    scores: Scores,
    effort: Effort,
) -> UnitRecord {
    UnitRecord {
        key: unit.key.clone(),
        method: unit.variant.method.clone(),
        factor: unit.factor(),
        complexity: unit.complexity(),
        added_subtasks: unit.scenario.added_subtasks,
        obstruction_change: unit.scenario.obstruction_change(),
        seed: unit.seed,
        config_hash: shared
            .manifest
            .variant(&unit.key.variant)
            .map(|v| v.config_hash.clone())
            .unwrap_or_default(),
        status,
        error,
        scores,
        spec: None,
        states: None,
        effort,
        artifacts: Path::new("units")
            .join(unit.key.folder(&unit.variant))
            .to_string_lossy()
            .into_owned(),
        finished_at: nesy_vlm::now_rfc3339(),
    }
}

/// The unit's client: its responder under the meter. The offline responder is given the
/// demonstration's recorded robot calls.
pub(super) fn unit_client(
    shared: &Shared,
    unit: &Unit,
    demo: &DemoInput,
) -> Result<UnitClient, (UnitStatus, String)> {
    let config = &shared.config;
    let (client_config, base): (VlmConfig, Arc<dyn Transport>) = match &config.responder {
        ResponderSetup::Oracle => {
            let noise = unit.variant.option("noise").unwrap_or("").replace(';', ",");
            let transport = vlm::oracle_transport(&noise, unit.seed, demo.recorded_calls())
                .map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
            let transport: Arc<dyn Transport> = if config.record_cassettes {
                let path = cassette_path(unit, &config.run_dir.join("cassettes"));
                record_to(&path, transport, &vlm::oracle_config())?
            } else {
                transport
            };
            (vlm::oracle_config(), transport)
        }
        ResponderSetup::Replay(dir) => {
            let path = cassette_path(unit, dir);
            if path.is_file() {
                let file =
                    CassetteFile::load(&path).map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
                let c = vlm::replay_config(&path, &file)
                    .map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
                let options = CassetteOptions {
                    allow_playback_repeats: true,
                    ..CassetteOptions::default()
                };
                let t = CassetteTransport::open(&path, CassetteMode::None, None, options)
                    .map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
                (c, Arc::new(t))
            } else if methods::find(&unit.variant.method)
                .is_ok_and(|m| m.info().offline == methods::OfflineMeaning::ModelFree)
            {
                // A control that calls no model leaves no cassette; it replays without one.
                (vlm::oracle_config(), Arc::new(NoRecording { path }))
            } else {
                return Err((UnitStatus::TransportError, NoRecording { path }.message()));
            }
        }
        ResponderSetup::Live(_) => {
            let (c, http) = shared
                .live
                .clone()
                .ok_or_else(|| (UnitStatus::MethodError, "no live client".into()))?;
            let path = cassette_path(unit, &config.run_dir.join("cassettes"));
            let t = record_to(&path, http, &c)?;
            (c, t)
        }
    };
    let metered = Metered::new(base, config.settings.max_calls_per_unit, shared.model.clone());
    let counts = metered.counts();
    Ok((
        VlmClient::with_transport(&client_config, Arc::new(metered)),
        counts,
    ))
}

/// A replayed unit's missing cassette: the transport of a control that calls no model (a
/// call it makes after all fails, naming the file), and the message that names it.
#[derive(Debug)]
struct NoRecording {
    path: PathBuf,
}

impl NoRecording {
    fn message(&self) -> String {
        format!("{}: no recorded cassette for this unit", self.path.display())
    }
}

impl Transport for NoRecording {
    fn send<'a>(
        &'a self,
        _: &'a nesy_vlm::WireRequest,
    ) -> nesy_vlm::BoxFuture<'a, Result<nesy_vlm::WireResponse, nesy_vlm::TransportError>> {
        Box::pin(async move {
            Err(nesy_vlm::TransportError::Failed {
                message: self.message(),
                retryable: false,
            })
        })
    }

    fn label(&self) -> String {
        "no recording".into()
    }
}

/// A cassette at `path` recording (new episodes; replaying what it already holds) around
/// `inner`, with the key redacted.
pub(super) fn record_to(
    path: &Path,
    inner: Arc<dyn Transport>,
    config: &VlmConfig,
) -> Result<Arc<dyn Transport>, (UnitStatus, String)> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| (UnitStatus::MethodError, format!("{}: {e}", dir.display())))?;
    }
    let t = CassetteTransport::open(
        path,
        CassetteMode::NewEpisodes,
        Some(inner),
        CassetteOptions::recording(config),
    )
    .map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
    Ok(Arc::new(t))
}

/// The code of a specification: the template compiler, or the model's code generation.
pub(super) async fn make_code(
    client: &VlmClient,
    inputs: &UnitInputs,
    specified: &Specified,
) -> Result<(String, f64, f64), (UnitStatus, String)> {
    let started = Instant::now();
    let target = &inputs.target;
    let mut instruction = target.instruction(&inputs.demo);
    let (procedure, plan) = match &specified.spec {
        Specification::Procedure { procedure, .. } => (procedure.clone(), Vec::new()),
        Specification::Plan {
            steps,
            instruction: rewritten,
        } => {
            if let Some(rewritten) = rewritten {
                instruction = rewritten.clone();
            }
            (Vec::new(), steps.clone())
        }
    };
    match specified.codegen {
        CodegenMode::Template => {
            let request = SynthesisRequest {
                instruction,
                objects: target.objects.clone(),
                procedure,
                source: inputs.setting.source_embodiment,
                target: inputs.setting.target_embodiment,
                tools: target.holds_tool(),
                protective_stop: target.protective_stop(),
            };
            let reasoner =
                VlmReasoner::new(client.clone()).map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
            let p = synth::synthesize(&reasoner, CodegenMode::Template, &request)
                .await
                .map_err(|e| synth_status(&e))?;
            Ok((p.code, 0.0, started.elapsed().as_secs_f64()))
        }
        CodegenMode::Vlm => {
            let reasoner = VlmReasoner::new(client.clone())
                .map_err(|e| (UnitStatus::MethodError, e.to_string()))?
                .with_embodiments(inputs.setting.source_embodiment, inputs.setting.target_embodiment)
                .with_program_check(Arc::new(SandboxChecks));
            let request = CodeGenerationRequest {
                instruction,
                objects: target.objects.clone(),
                procedure,
                plan,
                embodiment: inputs.setting.target_embodiment,
                // The authors' rule: the extended prompt for the embodiment factors and for
                // Combination (whose scenarios may change the end effector).
                extended: matches!(inputs.setting.factor, Factor::Grip | Factor::Vacu | Factor::Comb)
                    || inputs.setting.source_embodiment != inputs.setting.target_embodiment,
                tools: target.holds_tool(),
                protective_stop: target.protective_stop(),
            };
            let source = reasoner.generate_code(&request).await.map_err(|e| {
                let status = match FailureKind::of_reasoner(e.reasoner_kind()) {
                    // No usable program is the code tail's failure, not the method's.
                    FailureKind::Method => UnitStatus::CodegenFailed,
                    kind => status_of(kind),
                };
                (status, e.to_string())
            })?;
            Ok((source.code, started.elapsed().as_secs_f64(), 0.0))
        }
    }
}

/// The unit status a method's failure of `kind` gives its unit.
fn status_of(kind: FailureKind) -> UnitStatus {
    match kind {
        FailureKind::Unresolved => UnitStatus::Unresolved,
        FailureKind::Method => UnitStatus::MethodError,
        FailureKind::Refused => UnitStatus::RequestRefused,
        FailureKind::Transport => UnitStatus::TransportError,
    }
}

pub(super) fn synth_status(e: &SynthError) -> (UnitStatus, String) {
    match e {
        SynthError::NoProgram { message, .. } => (UnitStatus::CodegenFailed, message.clone()),
        SynthError::Call { message, failure } => {
            (status_of(FailureKind::of_reasoner(*failure)), message.clone())
        }
    }
}

pub(super) fn agreement(states: &Option<StateSource>) -> Option<Agreement> {
    match states {
        Some(StateSource::Vlm {
            agreement: Some(a), ..
        }) => Some(*a),
        _ => None,
    }
}

/// Runs one unit to its record. Never fails: every failure becomes the unit's status.
pub(super) async fn run_unit(shared: &Arc<Shared>, unit: &Unit) -> UnitRecord {
    let started = Instant::now();
    let mut effort = Effort::default();
    let (inputs, dir, unit_inputs) = match prepare_unit(shared, unit).await {
        Ok(prepared) => prepared,
        Err((status, message)) => return failed_record(shared, unit, status, message, effort),
    };
    let (client, counts) = match unit_client(shared, unit, &inputs.demo) {
        Ok(c) => c,
        Err((status, e)) => return failed_record(shared, unit, status, e, effort),
    };

    // Phase A: the specification and its code (or the earlier run's, when re-executing).
    let phase_a = match &shared.config.reexecute {
        Some(source) => reexecuted(source, unit),
        None => specify_and_code(&client, &unit_inputs, &dir, unit).await,
    };
    let usage = client.finish().ok();
    let counts = counts.lock().unwrap_or_else(|e| e.into_inner()).clone();
    account_calls(&mut effort, &counts, usage.as_ref());
    let (code, mut record_base) = match phase_a {
        Ok(a) => a,
        Err(failure) => {
            let status = if counts.cap_reached {
                UnitStatus::MethodError
            } else {
                failure.status
            };
            if let Some(symbolic_s) = failure.symbolic_s {
                effort.time.set_symbolic(symbolic_s);
            }
            effort.time.total_s = started.elapsed().as_secs_f64();
            let mut r = failed_record(shared, unit, status, failure.message, effort);
            r.spec = failure.spec.map(|spec| *spec);
            return r;
        }
    };
    effort.time.vlm_s = record_base.vlm_s;
    effort.time.set_symbolic(record_base.symbolic_s);
    effort.time.codegen_template_s = record_base.template_s;

    // Phase B: execution in the sandboxed simulator.
    let executed = execute_code(shared, &inputs, &dir, code).await;
    effort.time.sim_s = inputs.target.sim_time.as_secs_f64();
    let report = match executed {
        Ok(r) => r,
        Err(e) => {
            effort.time.total_s = started.elapsed().as_secs_f64();
            let mut r = failed_record(shared, unit, UnitStatus::ExecutionFailed, e, effort);
            r.spec = record_base.spec.take();
            return r;
        }
    };
    effort.time.sim_s += report.result.wall_time_s;
    if let Err(e) = dir.write_json(output::EXECUTION_FILE, &report) {
        // The episode's evidence could not be kept: the unit runs again on resume rather
        // than be scored without it.
        effort.time.total_s = started.elapsed().as_secs_f64();
        let message =
            format!("the execution record could not be written ({e}); the unit runs again on resume");
        return failed_record(shared, unit, UnitStatus::Interrupted, message, effort);
    }
    if shared.config.record_executions {
        record_execution(shared, &dir, &report).await;
    }
    let scores = scores_of(&report, unit);
    let (status, error) = execution_verdict(&report);
    effort.time.total_s = started.elapsed().as_secs_f64();
    let mut r = base_record(shared, unit, status, error, scores, effort);
    r.spec = record_base.spec.take();
    r.states = record_base.states;
    r
}

/// The unit's scenario inputs, its directory and the method's inputs; or why it cannot run
/// (its scenario could not be prepared, its demonstration is unusable, its directory cannot
/// be made).
async fn prepare_unit(
    shared: &Arc<Shared>,
    unit: &Unit,
) -> Result<(Arc<ScenarioInputs>, RunDir, UnitInputs), (UnitStatus, String)> {
    let inputs = scenario_inputs(shared, &unit.scenario)
        .await
        .map_err(|e| (UnitStatus::MethodError, format!("preparing the scenario: {e}")))?;
    if !inputs.cached.record.usable() && !shared.config.settings.keep_gapped_demos {
        let why = inputs.cached.record.unusable_reason().unwrap_or_default();
        return Err((UnitStatus::DemoUnusable, why));
    }
    let dir = RunDir::create(unit_dir(shared, unit)).map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
    let options = AdaptOptions {
        images: match shared.config.settings.observation {
            Observation::Images => ImagesMode::Auto,
            Observation::StateText => ImagesMode::Never,
        },
        ..AdaptOptions::default()
    };
    let setting = derive_setting(&inputs.demo, &inputs.target, &options);
    let unit_inputs = UnitInputs {
        vocabulary: inputs.vocabulary.clone(),
        demo: inputs.demo.clone(),
        keyframes: inputs.keyframes.clone(),
        target: inputs.target.clone(),
        setting,
        variant: unit.variant.clone(),
        seed: unit.seed,
    };
    Ok((inputs, dir, unit_inputs))
}

/// The unit's model calls, images, tokens and cost, from the meter's counts and the client's
/// accounting.
fn account_calls(effort: &mut Effort, counts: &CallCounts, usage: Option<&RunUsage>) {
    effort.calls = counts.calls;
    effort.images = counts.images;
    effort.calls_by_purpose = counts.by_purpose.clone();
    if let Some(u) = usage {
        // The wall time with a call in flight (concurrent calls share it); a specification
        // that completes replaces it with the method's own measure, but a unit that fails
        // keeps it, so its model seconds are not lost.
        effort.time.vlm_s = u.total.waiting_ms_total / 1e3;
        effort.tokens = u.total.prompt_tokens + u.total.completion_tokens;
        effort.cost_usd = u.total.cost_usd;
        effort.cost_by_purpose = u
            .by_purpose
            .iter()
            .filter(|(_, t)| t.cost_usd > 0.0)
            .map(|(purpose, t)| (purpose.clone(), t.cost_usd))
            .collect();
    }
}

/// Phase B: the program written beside the target scene and run in the sandboxed worker,
/// under a CPU slot.
async fn execute_code(
    shared: &Shared,
    inputs: &ScenarioInputs,
    dir: &RunDir,
    code: String,
) -> Result<ExecutionReport, String> {
    let target = inputs.target.clone();
    let worker = shared.config.worker.clone();
    let limits = Limits {
        wall_time_ms: shared.config.settings.policy_wall_ms,
        ..Limits::default()
    };
    let exec_dir = dir.clone();
    cpu(shared, move || {
        let scene = exec_dir
            .prepare(&target, Some(&code))
            .map_err(|e| e.to_string())?
            .ok_or_else(|| nesy_pipeline::NO_SCENE_TO_EXECUTE.to_owned())?;
        execute::execute(&worker, &code, &scene, &limits).map_err(|e| e.to_string())
    })
    .await
    .and_then(|r| r)
}

/// The view the failure gallery shows of each recorded execution.
pub(super) const GALLERY_VIEW: &str = "front";

/// Replays the unit's execution and writes its recording and first and last frames, under a
/// CPU slot. The unit's result does not depend on it: a recording that cannot be written is
/// logged and left out.
async fn record_execution(shared: &Shared, dir: &RunDir, report: &ExecutionReport) {
    let dir = dir.clone();
    let report = report.clone();
    let written = cpu(shared, move || {
        dir.write_execution_recording(&report, GALLERY_VIEW, 1)
            .map(|_| ())
            .map_err(|e| e.to_string())
    })
    .await
    .and_then(|r| r);
    if let Err(e) = written {
        tracing::warn!("the execution recording was not written: {e}");
    }
}

/// The unit's scores: the episode's goal checks, or zeros with the target's label when no
/// check was reported.
fn scores_of(report: &ExecutionReport, unit: &Unit) -> Scores {
    match &report.metrics {
        Some(m) => Scores {
            sr: m.sr,
            gc: m.gc,
            latched_sr: m.latched_sr,
            latched_gc: m.latched_gc,
            pd: m.pd.unwrap_or(0.0),
            label: m.label.clone(),
            achieved: m.achieved.clone(),
            subtasks: m
                .subtasks
                .iter()
                .map(|s| SubtaskScore {
                    subtask: s.subtask.clone(),
                    result: s.status,
                    displaced: s.displaced.clone(),
                })
                .collect(),
        },
        None => {
            let (label, subtask_names) = target_label(unit);
            Scores::not_executed(label, &subtask_names)
        }
    }
}

/// Succeeded, or execution failed with why: the subtasks that failed or left objects out
/// of place, the exception the policy raised, or how else the episode ended.
fn execution_verdict(report: &ExecutionReport) -> (UnitStatus, Option<String>) {
    if report.success() {
        return (UnitStatus::Succeeded, None);
    }
    let why = match &report.result.outcome {
        nesy_policy::Outcome::Ok => {
            let failed: Vec<String> = report
                .metrics
                .iter()
                .flat_map(|m| &m.subtasks)
                .filter(|s| !s.status.is_success() || !s.displaced.is_empty())
                .map(|s| {
                    if s.displaced.is_empty() {
                        format!("{} {}", s.subtask, s.status)
                    } else {
                        format!("{} displaced {}", s.subtask, s.displaced.join(" "))
                    }
                })
                .collect();
            format!("the policy ran to its end; {}", failed.join(", "))
        }
        nesy_policy::Outcome::PythonError(e) => {
            format!(
                "the policy raised {}: {}{}",
                e.exception,
                e.message,
                e.line
                    .map(|l| format!(" (policy.py line {l})"))
                    .unwrap_or_default()
            )
        }
        other => format!("the policy ended with {}", other.kind()),
    };
    (UnitStatus::ExecutionFailed, Some(why))
}

/// A unit artifact that could not be written: the unit is recorded as interrupted, so that
/// it runs again on resume rather than be scored without its evidence.
fn unkept(summary: Option<SpecSummary>) -> impl FnOnce(PipelineError) -> PhaseAFailure {
    move |e| PhaseAFailure {
        status: UnitStatus::Interrupted,
        message: format!("a unit artifact could not be written ({e}); the unit runs again on resume"),
        spec: summary.map(Box::new),
        symbolic_s: None,
    }
}

/// A unit's specification: its summary, its text and the method's notes.
const SPEC_FILE: &str = "spec.json";

/// Phase A: the method's specification, its artifacts written, and its code.
pub(super) async fn specify_and_code(
    client: &VlmClient,
    inputs: &UnitInputs,
    dir: &RunDir,
    unit: &Unit,
) -> Result<(String, PhaseA), PhaseAFailure> {
    let method: Arc<dyn Method> = methods::find(&unit.variant.method)
        .map_err(|e| PhaseAFailure::new(UnitStatus::MethodError, e.to_string()))?;
    let specified = match method.specify(inputs, client).await {
        Ok(s) => s,
        Err(f) => {
            if let Some(a) = &f.adaptation {
                dir.write_json(output::ADAPTATION_FILE, a.as_ref())
                    .map_err(unkept(None))?;
            }
            let summary = f.iterations.map(|(iterations, budget)| SpecSummary {
                kind: "none".into(),
                steps: 0,
                verified: false,
                iterations: Some(iterations),
                budget: Some(budget),
            });
            return Err(PhaseAFailure {
                status: status_of(f.kind),
                message: f.message,
                spec: summary.map(Box::new),
                symbolic_s: f.symbolic_s,
            });
        }
    };
    let summary = SpecSummary {
        kind: specified.spec.kind().into(),
        steps: specified.spec.len(),
        verified: matches!(specified.spec, Specification::Procedure { verified: true, .. }),
        iterations: specified.iterations.map(|i| i.0),
        budget: specified.iterations.map(|i| i.1),
    };
    let spec_text = match &specified.spec {
        Specification::Procedure { procedure, .. } => format_procedure(procedure),
        Specification::Plan { steps, .. } => steps
            .iter()
            .enumerate()
            .map(|(i, s)| format!("{}. {s}", i + 1))
            .collect::<Vec<_>>()
            .join("\n"),
    };
    dir.write_json(
        SPEC_FILE,
        &serde_json::json!({
            "summary": summary,
            "text": spec_text,
            "notes": specified.notes,
        }),
    )
    .map_err(unkept(Some(summary.clone())))?;
    if let Some(a) = &specified.adaptation {
        dir.write_json(output::ADAPTATION_FILE, a)
            .map_err(unkept(Some(summary.clone())))?;
    }
    let (code, vlm_code_s, template_s) =
        make_code(client, inputs, &specified)
            .await
            .map_err(|(status, message)| PhaseAFailure {
                status,
                message,
                spec: Some(Box::new(summary.clone())),
                symbolic_s: Some(specified.symbolic_s),
            })?;
    Ok((
        code,
        PhaseA {
            spec: Some(summary),
            states: agreement(&specified.states),
            vlm_s: specified.vlm_s + vlm_code_s,
            symbolic_s: specified.symbolic_s,
            template_s,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_that_fails_keeps_its_model_seconds() {
        let mut usage = RunUsage::default();
        usage.total.calls = 3;
        usage.total.latency_ms_total = 9_000.0;
        usage.total.waiting_ms_total = 4_500.0;
        usage.total.prompt_tokens = 100;
        usage.total.completion_tokens = 20;
        let mut effort = Effort::default();
        account_calls(&mut effort, &CallCounts::default(), Some(&usage));
        assert_eq!(effort.time.vlm_s, 4.5);
        assert_eq!(effort.tokens, 120);
    }
}
