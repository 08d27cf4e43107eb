//! # nesy-pipeline
//!
//! NeSyCR on one episode: from a demonstration and a target scene to an executed, verified
//! code policy (the paper's Algorithm 1 plus code synthesis and execution). `nesy adapt` and
//! the benchmark harness both run it.
//!
//! The stages, each callable on its own:
//!
//! 1. [`DemoInput`] and [`TargetInput`]: the demo (`demo.mcap` or a folder, read by `nesy_sim::demo::read`) and the
//!    target scene, built in nesy-sim, which observes its ground-truth initial state and
//!    renders its three views.
//! 2. [`derive_setting`]: embodiments, predicate tier, factor, complexity, budget.
//! 3. [`states`]: symbolic states, observed (ground truth) or translated by the VLM from the
//!    marked views.
//! 4. [`adapt_episode`]: world model and counterfactual adaptation (`nesy_core::adapt::run`
//!    over the [`nesy_reasoner::VlmReasoner`], timed so that model time and symbolic time are
//!    reported apart).
//! 5. [`synth`]: code synthesis, by the VLM's code-generation prompt or by the template
//!    compiler. An unresolved adaptation is never compiled.
//! 6. [`execute`]: the policy in the sandbox against the target scene; SR, GC, PD from
//!    `nesy_core::metrics`.
//! 7. [`output`]: writing the run directory, a separate step after the run.
//!
//! [`run`] drives stages 2–6 as one `async` function; the caller owns the runtime. Errors
//! are typed ([`PipelineError`]): a caller can tell bad input from a transport failure from
//! an episode's own failure.
//!
//! The first two stages on the bundled quick-start demo, whose target scene closes the
//! drawer the demonstration found open:
//!
//! ```
//! use nesy_pipeline::{AdaptOptions, DemoInput, TargetInput, derive_setting};
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/demos/adapt-realstyle");
//! let demo = DemoInput::load(dir.as_ref(), &nesy_core::Vocabulary::new()).unwrap();
//! let target = TargetInput::load(Some(format!("{dir}/target.json").as_ref()), &demo).unwrap();
//! assert_eq!(demo.demo.keyframes.len(), 9);
//! let setting = derive_setting(&demo, &target, &AdaptOptions::default());
//! assert_eq!(setting.source_embodiment, setting.target_embodiment);
//! ```

mod error;
pub mod execute;
mod html_report;
mod inputs;
pub mod output;
mod progress;
mod setting;
pub mod states;
pub mod synth;
mod timing;
pub mod vlm;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use nesy_core::Symbol;
use nesy_core::Vocabulary;
use nesy_core::adapt::{self, AdaptConfig, Adaptation, Demonstration, Target, TaskContext};
use nesy_core::{Operator, State};
use nesy_policy::{Limits, WorkerCommand};
use nesy_reasoner::VlmReasoner;
use nesy_reasoner::prompts::{Prompts, TemplateRecord};
use nesy_vlm::RunUsage;
use serde::Serialize;

use execute::ExecutionReport;
use states::{StateSource, StatesMode, SymbolicStates};
use synth::{CodegenMode, SandboxChecks, SynthError, SynthesisRequest, SynthesizedPolicy};

pub use error::{PipelineError, StopReason};
pub use html_report::{HTML_REPORT_FILE, RolloutFiles, report_html};
pub use inputs::{DemoInput, DemoKeyframes, TARGET_SCENE_BESIDE, TargetInput, load_vocabulary};
pub use progress::{LogProgress, NoProgress, Progress};
pub use setting::{ImagesMode, Setting, derive_setting};
pub use timing::TimeBreakdown;

/// Everything a run can be asked to do, besides its inputs and the VLM.
#[derive(Debug, Clone)]
pub struct AdaptOptions {
    /// Where symbolic states come from.
    pub states: StatesMode,
    /// How the adapted procedure becomes code.
    pub codegen: CodegenMode,
    /// Run the policy in the sandbox against the target scene.
    pub execute: bool,
    /// Whether requests carry the keyframes' pictures.
    pub images: ImagesMode,
    /// Patch-proposal budget; `None` takes the benchmark's 10/15/20/30 for the scenario.
    pub budget: Option<usize>,
    /// The adaptation loop's settings: induction attempts per transition, the transition
    /// check and the ablation switches. Its budget is replaced by the run's (see `budget`).
    pub adapt: AdaptConfig,
    /// Sandbox limits for execution.
    pub limits: Limits,
    /// The `nesy` binary whose hidden `policy-worker` subcommand runs policies; `None` uses
    /// the running executable.
    pub worker: Option<WorkerCommand>,
    /// The run directory: the target scene and the program are written here before
    /// execution, and [`output::RunDir::write_all`] writes the rest.
    pub out_dir: PathBuf,
    /// The task's predicates and object kinds: the built-ins, or a vocabulary file's
    /// ([`load_vocabulary`]).
    pub vocabulary: Vocabulary,
    /// NeSyCR's prompt templates with a user's overrides (`--prompts DIR`); `None` uses the
    /// bundled ones.
    pub prompts: Option<Arc<Prompts>>,
}

impl Default for AdaptOptions {
    fn default() -> Self {
        AdaptOptions {
            states: StatesMode::Auto,
            codegen: CodegenMode::Vlm,
            execute: false,
            images: ImagesMode::Auto,
            budget: None,
            adapt: AdaptConfig::default(),
            limits: Limits::default(),
            worker: None,
            out_dir: PathBuf::from("nesy-out"),
            vocabulary: Vocabulary::new(),
            prompts: None,
        }
    }
}

/// How a run ended, from the pipeline's point of view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunStatus {
    /// Adapted, compiled, and (if asked) executed with every subtask successful.
    Succeeded,
    /// The adaptation budget ran out: no verified procedure, so no policy was produced.
    Unresolved,
    /// Adapted, but no program could be obtained from the code generator.
    CodegenFailed,
    /// Adapted and compiled, but the executed policy did not succeed.
    ExecutionFailed,
}

impl RunStatus {
    /// `succeeded`, `unresolved`, ...
    pub fn as_str(self) -> &'static str {
        match self {
            RunStatus::Succeeded => "succeeded",
            RunStatus::Unresolved => "unresolved",
            RunStatus::CodegenFailed => "codegen_failed",
            RunStatus::ExecutionFailed => "execution_failed",
        }
    }
}

/// What a run says when `--execute` meets a target with nothing to execute on.
pub const NO_SCENE_TO_EXECUTE: &str = "nothing to execute on: the target is a camera's view without a simulated scene (scene.json beside its manifest), and no robot bridge is configured; the run ends with the verified procedure and the policy";

/// Everything a run produced (what `--json` prints, minus bulky traces).
#[derive(Debug, Clone, Serialize)]
pub struct AdaptRun {
    /// The demo path.
    pub demo_path: PathBuf,
    /// The target scene path (or `<demo>#target_scene` when the demo carried it).
    pub target_path: PathBuf,
    /// The run directory.
    pub out_dir: PathBuf,
    /// The target's instruction.
    pub instruction: String,
    /// Scenario derivations.
    pub setting: Setting,
    /// Where the states came from.
    pub states: StateSource,
    /// The demonstrated states s_1 … s_N as used.
    #[serde(skip)]
    pub demo_states: Vec<State>,
    /// The target's initial state ŝ_1 as used.
    pub target_state: State,
    /// World model, outcome and full trace.
    #[serde(skip)]
    pub adaptation: Adaptation,
    /// Final status.
    pub status: RunStatus,
    /// The synthesized policy, when the adaptation resolved.
    #[serde(skip)]
    pub policy: Option<SynthesizedPolicy>,
    /// Why code synthesis failed, if it did.
    pub codegen_error: Option<SynthError>,
    /// The execution, when asked for.
    #[serde(skip)]
    pub execution: Option<ExecutionReport>,
    /// Why execution was asked for and not done (a camera target without a simulated scene).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_executed: Option<String>,
    /// Time spent, by kind.
    pub timing: TimeBreakdown,
    /// Model calls, tokens, latency.
    pub usage: RunUsage,
    /// Every prompt file the run's model calls were rendered from, with its SHA-256 (and the
    /// override's path where `--prompts` replaced it).
    pub prompts: Vec<TemplateRecord>,
    /// The vocabulary's predicates beyond the built-ins, as the prompts define them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub declared_predicates: Vec<String>,
}

impl AdaptRun {
    /// The demonstrated procedure (world model).
    pub fn demonstrated(&self) -> &[Operator] {
        &self.adaptation.world_model.procedure
    }

    /// The adapted procedure if the run resolved.
    pub fn adapted(&self) -> Option<&[Operator]> {
        match &self.adaptation.outcome {
            adapt::Outcome::Adapted { procedure, .. } => Some(procedure),
            adapt::Outcome::Unresolved { .. } => None,
        }
    }

    /// Process exit code: 0 succeeded, 1 a negative verdict, 2 when code generation could not
    /// be asked at all (transport failure, cassette miss).
    pub fn exit_code(&self) -> u8 {
        match (&self.status, &self.codegen_error) {
            (_, Some(SynthError::Call { .. })) => 2,
            (RunStatus::Succeeded, _) => 0,
            _ => 1,
        }
    }
}

/// The demonstration and the target as the adaptation loop takes them, built from the
/// states a run uses.
pub fn adaptation_inputs(
    demo: &DemoInput,
    target: &TargetInput,
    setting: &Setting,
    states: &SymbolicStates,
    vocabulary: &Vocabulary,
) -> (Demonstration, Target) {
    let demonstration = Demonstration {
        states: states.demo_states.clone(),
        task: TaskContext {
            instruction: demo.demo.metadata.instruction.clone(),
            objects: demo.objects().iter().map(|o| Symbol::new(o)).collect(),
            tier: setting.tier,
            vocabulary: vocabulary.clone(),
        },
    };
    let target_task = Target {
        init: states.target_state.clone(),
        task: TaskContext {
            instruction: target.instruction(demo),
            objects: target.objects.iter().map(|o| Symbol::new(o)).collect(),
            tier: setting.tier,
            vocabulary: vocabulary.clone(),
        },
        scene_names: target.scene_names.iter().map(|n| Symbol::new(n)).collect(),
        goal: None,
    };
    (demonstration, target_task)
}

/// What [`adapt_episode`] returns: the adaptation and where its time went.
#[derive(Debug, Clone)]
pub struct AdaptedEpisode {
    /// World model, outcome and trace.
    pub adaptation: Adaptation,
    /// The reasoner, returned for code generation and usage accounting.
    pub reasoner: VlmReasoner,
    /// Model time inside the loop.
    pub vlm: Duration,
    /// Symbolic time in all (the loop outside model calls and progress reporting).
    pub symbolic: Duration,
    /// The part of `symbolic` before the first patch request (world model and first
    /// identification).
    pub symbolic_world_model: Duration,
    /// Wall time of the loop.
    pub wall: Duration,
    /// Model calls made by the loop.
    pub calls: usize,
}

/// Stage 4: world-model construction and counterfactual adaptation, timed.
pub async fn adapt_episode(
    reasoner: VlmReasoner,
    demonstration: &Demonstration,
    target: &Target,
    config: &AdaptConfig,
    progress: Arc<dyn Progress>,
) -> Result<AdaptedEpisode, PipelineError> {
    let mut timed = timing::TimedReasoner::new(
        reasoner,
        progress,
        demonstration.states.len().saturating_sub(1),
        config.budget,
    );
    let started = Instant::now();
    let adaptation = adapt::run(&mut timed, demonstration, target, config).await?;
    let wall = started.elapsed();
    let symbolic = wall
        .saturating_sub(timed.vlm_time())
        .saturating_sub(timed.reporting_time());
    // Split at the first patch request: before it, world-model construction and the first
    // identification (the demonstrated procedure verified from the target state); after it,
    // the adaptation loop. Progress reporting is neither.
    let symbolic_world_model = match timed.first_patch() {
        Some(first) => first
            .at
            .saturating_duration_since(started)
            .saturating_sub(first.vlm_before)
            .saturating_sub(first.reporting_before),
        None => symbolic,
    };
    let vlm = timed.vlm_time();
    let calls = timed.calls();
    Ok(AdaptedEpisode {
        adaptation,
        reasoner: timed.into_inner(),
        vlm,
        symbolic,
        symbolic_world_model,
        wall,
        calls,
    })
}

/// Runs stages 2–6 on a demo and a target with `client`'s model: states, world model and
/// adaptation, code synthesis, and execution when `options.execute`. The target scene and
/// the program are written to `options.out_dir` before execution, so a crash loses neither;
/// [`output::RunDir::write_all`] writes the rest of the run directory.
pub async fn run(
    demo: &DemoInput,
    target: &TargetInput,
    client: nesy_vlm::VlmClient,
    options: &AdaptOptions,
    progress: Arc<dyn Progress>,
) -> Result<AdaptRun, PipelineError> {
    let started = Instant::now();
    let mut timing = TimeBreakdown {
        load_s: demo.load_time.as_secs_f64(),
        sim_s: target.sim_time.as_secs_f64(),
        ..TimeBreakdown::default()
    };
    let mut setting = derive_setting(demo, target, options);
    setting.images = options.images.sends_images(&client.capabilities().await);
    let reasoner = build_reasoner(client, demo, &setting, options.prompts.clone())?;
    let prompts = reasoner.prompts().templates().to_vec();

    progress.stage("symbolic states");
    let vocabulary = &options.vocabulary;
    inputs::check_target_state(target, vocabulary)?;
    let states = states::symbolic_states(
        &reasoner,
        demo,
        target,
        &setting,
        options.states,
        vocabulary,
        progress.as_ref(),
    )
    .await?;
    timing.vlm_s += states.vlm_time.as_secs_f64();
    let (demonstration, target_task) = adaptation_inputs(demo, target, &setting, &states, vocabulary);
    let config = AdaptConfig {
        budget: setting.budget,
        ..options.adapt
    };

    progress.stage("world model and adaptation");
    let adapted = adapt_episode(reasoner, &demonstration, &target_task, &config, progress.clone()).await?;
    adapted.add_times(&mut timing);
    let AdaptedEpisode {
        adaptation, reasoner, ..
    } = adapted;

    let mut status = if adaptation.outcome.is_adapted() {
        RunStatus::Succeeded
    } else {
        RunStatus::Unresolved
    };

    // Code synthesis (never for an unresolved adaptation).
    let inputs = SynthesisInputs {
        demo,
        target,
        setting: &setting,
        adaptation: &adaptation,
        options,
    };
    let (policy, codegen_error) = synthesize_adapted(&reasoner, inputs, &mut timing, progress.as_ref()).await;
    if codegen_error.is_some() {
        status = RunStatus::CodegenFailed;
    }

    let usage = reasoner.client().finish().map_err(|e| PipelineError::Finish {
        message: e.to_string(),
    })?;

    // Execution. The scene and the program are written first, so a crash loses nothing.
    let run_dir = output::RunDir::create(&options.out_dir)?;
    let scene_path = run_dir.prepare(target, policy.as_ref().map(|p| p.code.as_str()))?;
    let mut execution = None;
    let mut not_executed = None;
    if let (true, Some(p)) = (options.execute, &policy) {
        match &scene_path {
            Some(scene_path) => {
                progress.stage("executing the policy in the sandbox");
                let report = execute_policy(&p.code, scene_path, options).await?;
                timing.sim_s += report.result.wall_time_s;
                if !report.success() {
                    status = RunStatus::ExecutionFailed;
                }
                execution = Some(report);
            }
            None => {
                not_executed = Some(NO_SCENE_TO_EXECUTE.to_owned());
            }
        }
    }
    timing.total_s = started.elapsed().as_secs_f64() + timing.load_s + target.sim_time.as_secs_f64();

    Ok(AdaptRun {
        demo_path: demo.path.clone(),
        target_path: target.path.clone(),
        out_dir: options.out_dir.clone(),
        instruction: target.instruction(demo),
        setting,
        states: states.source,
        demo_states: states.demo_states,
        target_state: states.target_state,
        adaptation,
        status,
        policy,
        codegen_error,
        execution,
        not_executed,
        timing,
        usage,
        prompts,
        declared_predicates: declared_predicates(vocabulary),
    })
}

/// The definition lines of the predicates `vocabulary` adds to, or redefines among, the
/// built-ins.
fn declared_predicates(vocabulary: &Vocabulary) -> Vec<String> {
    let builtins = nesy_core::builtin_predicates();
    vocabulary
        .predicates()
        .iter()
        .filter(|p| !builtins.contains(p))
        .map(|p| p.definition_line())
        .collect()
}

/// NeSyCR's reasoner over `client`: the demo's keyframe images, both end effectors, and the
/// sandbox's static checks on generated programs.
fn build_reasoner(
    client: nesy_vlm::VlmClient,
    demo: &DemoInput,
    setting: &Setting,
    prompts: Option<Arc<Prompts>>,
) -> Result<VlmReasoner, PipelineError> {
    let mut reasoner = VlmReasoner::new(client).map_err(|e| PipelineError::VlmSetup {
        message: format!("loading nesy's prompts: {e}"),
    })?;
    if let Some(prompts) = prompts {
        reasoner = reasoner.with_prompts(prompts);
    }
    // Without pictures the prompts carry the states as text alone, as they always do.
    let reasoner = if setting.images {
        reasoner.with_keyframes(Arc::new(DemoKeyframes::from_demo(demo)?))
    } else {
        reasoner
    };
    Ok(reasoner
        .with_embodiments(setting.source_embodiment, setting.target_embodiment)
        .with_program_check(Arc::new(SandboxChecks)))
}

impl AdaptedEpisode {
    /// Adds the episode's model time, symbolic time (world model and adaptation) and wall
    /// time to `timing`.
    fn add_times(&self, timing: &mut TimeBreakdown) {
        timing.vlm_s += self.vlm.as_secs_f64();
        timing.set_symbolic((
            self.symbolic.as_secs_f64(),
            self.symbolic_world_model.as_secs_f64(),
        ));
        timing.adapt_wall_s = self.wall.as_secs_f64();
    }
}

/// What code synthesis needs from the run so far.
struct SynthesisInputs<'a> {
    demo: &'a DemoInput,
    target: &'a TargetInput,
    setting: &'a Setting,
    adaptation: &'a Adaptation,
    options: &'a AdaptOptions,
}

/// Step 5: the adapted procedure becomes a program, by the model or the template compiler,
/// its time counted as model time or template-compiler time. Nothing is synthesized for an
/// unresolved adaptation.
async fn synthesize_adapted(
    reasoner: &VlmReasoner,
    inputs: SynthesisInputs<'_>,
    timing: &mut TimeBreakdown,
    progress: &dyn Progress,
) -> (Option<SynthesizedPolicy>, Option<SynthError>) {
    let adapt::Outcome::Adapted { procedure, .. } = &inputs.adaptation.outcome else {
        return (None, None);
    };
    progress.stage("code synthesis");
    let request = SynthesisRequest {
        instruction: inputs.target.instruction(inputs.demo),
        objects: inputs.target.objects.clone(),
        procedure: procedure.clone(),
        source: inputs.setting.source_embodiment,
        target: inputs.setting.target_embodiment,
        tools: inputs.target.holds_tool(),
        protective_stop: inputs.target.protective_stop(),
    };
    let synth_started = Instant::now();
    let result = synth::synthesize(reasoner, inputs.options.codegen, &request).await;
    let spent = synth_started.elapsed().as_secs_f64();
    match inputs.options.codegen {
        CodegenMode::Vlm => timing.vlm_s += spent,
        CodegenMode::Template => timing.codegen_template_s += spent,
    }
    match result {
        Ok(p) => (Some(p), None),
        Err(e) => (None, Some(e)),
    }
}

/// Step 6: the program in the sandboxed worker against the scene written at `scene_path`,
/// on the blocking pool.
async fn execute_policy(
    code: &str,
    scene_path: &Path,
    options: &AdaptOptions,
) -> Result<ExecutionReport, PipelineError> {
    let worker = match &options.worker {
        Some(w) => w.clone(),
        None => WorkerCommand::current_exe().map_err(|e| PipelineError::Execute {
            scene: scene_path.to_owned(),
            message: format!("locating the nesy executable: {e}"),
        })?,
    };
    let code = code.to_owned();
    let limits = options.limits.clone();
    let path = scene_path.to_owned();
    tokio::task::spawn_blocking(move || execute::execute(&worker, &code, &path, &limits))
        .await
        .map_err(|e| PipelineError::Execute {
            scene: scene_path.to_owned(),
            message: format!("the execution task ended abnormally: {e}"),
        })?
}
