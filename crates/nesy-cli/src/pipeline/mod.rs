//! The `nesy adapt` pipeline: NeSyCR from a demonstration to an executed, verified code
//! policy (the paper's Algorithm 1 plus code synthesis and execution).
//!
//! 1. [`inputs`]: the demo (`demo.mcap` or a folder, read by `nesy_sim::demo::read`) and the
//!    target scene, built in nesy-sim, which observes its ground-truth initial state and
//!    renders its three views.
//! 2. [`states`]: symbolic states, observed (ground truth) or translated by the VLM from the
//!    marked views.
//! 3. World model and counterfactual adaptation: `nesy_core::adapt::run` over the
//!    [`nesy_vlm::VlmReasoner`], timed by [`timing::TimedReasoner`].
//! 4. [`synth`]: code synthesis, by the VLM's code-generation prompt or by the template
//!    compiler. An unresolved adaptation is never compiled.
//! 5. [`execute`]: the policy in the sandbox against the target scene; SR, GC, PD.
//! 6. [`output`]: the run directory (world model, adaptation trace, procedures, policy,
//!    execution, report with the rendered target views).
//!
//! The CLI (`commands::adapt`) only parses flags, shows progress and prints the summary.

pub mod execute;
pub mod inputs;
pub mod output;
pub mod progress;
pub mod states;
pub mod synth;
pub mod timing;
pub mod vlm;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context as _;
use nesy_core::adapt::{self, AdaptConfig, Adaptation, Demonstration, Target, TaskContext};
use nesy_core::benchmark::{Complexity, Factor, iteration_budget, parse_scenario_id};
use nesy_core::predicates::{Tier, Vocabulary};
use nesy_core::symbol::Symbol;
use nesy_core::{Operator, State};
use nesy_policy::{Limits, WorkerCommand};
use nesy_sim::api::Embodiment;
use nesy_vlm::{RunUsage, VlmReasoner};
use serde::Serialize;

pub use execute::ExecutionReport;
pub use inputs::{DemoInput, TargetInput};
pub use progress::{NoProgress, Progress};
pub use states::{StateSource, StatesMode};
pub use synth::{CodegenMode, SynthError, SynthesizedPolicy};
pub use timing::TimeBreakdown;
pub use vlm::{VlmSetup, VlmSource};

/// Everything `nesy adapt` can be asked to do, besides its inputs and the VLM.
#[derive(Debug, Clone)]
pub struct AdaptOptions {
    /// Where symbolic states come from.
    pub states: StatesMode,
    /// How the adapted procedure becomes code.
    pub codegen: CodegenMode,
    /// Run the policy in the sandbox against the target scene.
    pub execute: bool,
    /// Patch-proposal budget; `None` takes the benchmark's 10/15/20/30 for the scenario.
    pub budget: Option<usize>,
    /// Induction attempts per demonstrated transition.
    pub induction_tries: usize,
    /// Sandbox limits for `--execute`.
    pub limits: Limits,
    /// The `nesy` binary whose hidden `policy-worker` subcommand runs policies; `None` uses
    /// the running executable.
    pub worker: Option<WorkerCommand>,
    /// The run directory: every output is written here.
    pub out_dir: PathBuf,
}

impl Default for AdaptOptions {
    fn default() -> Self {
        AdaptOptions {
            states: StatesMode::Auto,
            codegen: CodegenMode::Vlm,
            execute: false,
            budget: None,
            induction_tries: AdaptConfig::default().induction_tries,
            limits: Limits::default(),
            worker: None,
            out_dir: PathBuf::from("nesy-out"),
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

/// The scenario settings the run derived (factor and complexity decide the budget).
#[derive(Debug, Clone, Serialize)]
pub struct Setting {
    /// The demo's end effector.
    pub source_embodiment: Embodiment,
    /// The target's end effector.
    pub target_embodiment: Embodiment,
    /// Predicate tier shown to the model (`extended` when a vacuum tool is involved).
    pub tier: Tier,
    /// Whether embodiment atoms (`(FingerGripper)`, `(VacuumSuction)`) are in the states.
    pub embodiment_in_state: bool,
    /// The domain factor (from the demo's scenario id, else inferred).
    pub factor: Factor,
    /// The complexity (from the scenario id, else the number of target subtasks).
    pub complexity: Complexity,
    /// The patch-proposal budget used.
    pub budget: usize,
    /// Where that budget came from: `flag` or `scenario`.
    pub budget_origin: &'static str,
}

/// Everything a run produced (what `--json` prints, minus bulky traces).
#[derive(Debug, Clone, Serialize)]
pub struct AdaptRun {
    /// The demo path.
    pub demo_path: PathBuf,
    /// The target scene path (or `<demo metadata>` when the demo carried it).
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
    pub codegen_error: Option<synth::SynthError>,
    /// The execution, with `--execute`.
    #[serde(skip)]
    pub execution: Option<ExecutionReport>,
    /// Time spent, by kind.
    pub timing: TimeBreakdown,
    /// Model calls, tokens, latency.
    pub usage: RunUsage,
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
            (_, Some(synth::SynthError::Call { .. })) => 2,
            (RunStatus::Succeeded, _) => 0,
            _ => 1,
        }
    }
}

/// Runs the whole pipeline. `progress` receives stage and detail messages.
pub fn run(
    demo: DemoInput,
    target: TargetInput,
    setup: VlmSetup,
    options: &AdaptOptions,
    progress: Arc<dyn Progress>,
) -> anyhow::Result<AdaptRun> {
    let started = Instant::now();
    let mut timing = TimeBreakdown {
        load_s: demo.load_time.as_secs_f64(),
        sim_s: target.sim_time.as_secs_f64(),
        ..TimeBreakdown::default()
    };

    let setting = derive_setting(&demo, &target, options);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the async runtime")?;

    progress.stage("connecting the VLM");
    let client = vlm::build_client(&setup).context("setting up the VLM")?;
    let keyframes = Arc::new(inputs::DemoKeyframes::from_demo(&demo.demo)?);
    let reasoner = VlmReasoner::new(client)
        .context("loading nesy's prompts")?
        .with_keyframes(keyframes)
        .with_embodiments(setting.source_embodiment, setting.target_embodiment);

    // 2. Symbolic states.
    progress.stage("symbolic states");
    let vocabulary = Vocabulary::new();
    let translated = runtime.block_on(states::symbolic_states(
        &reasoner,
        &demo,
        &target,
        &setting,
        options.states,
        &vocabulary,
        progress.as_ref(),
    ))?;
    timing.vlm_s += translated.vlm_time.as_secs_f64();

    let demonstration = Demonstration {
        states: translated.demo_states.clone(),
        task: TaskContext {
            instruction: demo.demo.metadata.instruction.clone(),
            objects: demo.objects().iter().map(|o| Symbol::new(o)).collect(),
            tier: setting.tier,
            vocabulary: vocabulary.clone(),
        },
    };
    let target_task = Target {
        init: translated.target_state.clone(),
        task: TaskContext {
            instruction: target.instruction(&demo),
            objects: target.objects.iter().map(|o| Symbol::new(o)).collect(),
            tier: setting.tier,
            vocabulary,
        },
    };
    let config = AdaptConfig {
        induction_tries: options.induction_tries,
        budget: setting.budget,
        ..AdaptConfig::default()
    };

    // 3–4. World model and counterfactual adaptation.
    progress.stage("world model and adaptation");
    let mut timed = timing::TimedReasoner::new(
        reasoner,
        progress.clone(),
        demonstration.states.len().saturating_sub(1),
        setting.budget,
    );
    let adapt_started = Instant::now();
    let adaptation = runtime
        .block_on(adapt::run(&mut timed, &demonstration, &target_task, &config))
        .context("adaptation")?;
    let adapt_wall = adapt_started.elapsed();
    timing.vlm_s += timed.vlm_time().as_secs_f64();
    timing.symbolic_s = adapt_wall
        .saturating_sub(timed.vlm_time())
        .saturating_sub(timed.reporting_time())
        .as_secs_f64();
    // Split at the first patch request: before it, world-model construction and the first
    // identification (the demonstrated procedure verified from the target state); after it,
    // the adaptation loop. Progress reporting is neither.
    timing.symbolic_world_model_s = match timed.first_patch() {
        Some(first) => first
            .at
            .saturating_duration_since(adapt_started)
            .saturating_sub(first.vlm_before)
            .saturating_sub(first.reporting_before)
            .as_secs_f64(),
        None => timing.symbolic_s,
    };
    timing.symbolic_adaptation_s = (timing.symbolic_s - timing.symbolic_world_model_s).max(0.0);
    timing.adapt_wall_s = adapt_wall.as_secs_f64();
    let reasoner = timed.into_inner();

    let mut status = if adaptation.outcome.is_adapted() {
        RunStatus::Succeeded
    } else {
        RunStatus::Unresolved
    };

    // 5. Code synthesis (never for an unresolved adaptation).
    let mut policy = None;
    let mut codegen_error = None;
    if let adapt::Outcome::Adapted { procedure, .. } = &adaptation.outcome {
        progress.stage("code synthesis");
        let request = synth::SynthesisRequest {
            instruction: target.instruction(&demo),
            objects: target.objects.clone(),
            procedure: procedure.clone(),
            source: setting.source_embodiment,
            target: setting.target_embodiment,
            scene: &target.scene,
        };
        let synth_started = Instant::now();
        match runtime.block_on(synth::synthesize(&reasoner, options.codegen, &request)) {
            Ok(p) => policy = Some(p),
            Err(e) => {
                status = RunStatus::CodegenFailed;
                codegen_error = Some(e);
            }
        }
        let spent = synth_started.elapsed().as_secs_f64();
        match options.codegen {
            CodegenMode::Vlm => timing.vlm_s += spent,
            CodegenMode::Template => timing.codegen_template_s += spent,
        }
    }

    let usage = reasoner
        .client()
        .finish()
        .context("closing the VLM client (cassette)")?;
    drop(runtime);

    // 6. Execution. The scene and the program are written first, so a crash loses nothing.
    std::fs::create_dir_all(&options.out_dir)
        .with_context(|| format!("creating the output directory {}", options.out_dir.display()))?;
    let scene_path = options.out_dir.join(output::TARGET_SCENE_FILE);
    output::write(&scene_path, &target.scene.to_json_pretty())?;
    if let Some(p) = &policy {
        output::write(&options.out_dir.join(output::POLICY_FILE), &p.code)?;
    }
    let mut execution = None;
    if let (true, Some(p)) = (options.execute, &policy) {
        progress.stage("executing the policy in the sandbox");
        let worker = match &options.worker {
            Some(w) => w.clone(),
            None => WorkerCommand::current_exe().context("locating the nesy executable")?,
        };
        let report = execute::execute(&worker, &p.code, &scene_path, &options.limits)?;
        timing.sim_s += report.result.wall_time_s;
        if !report.success() {
            status = RunStatus::ExecutionFailed;
        }
        execution = Some(report);
    }
    timing.total_s = started.elapsed().as_secs_f64() + timing.load_s + target.sim_time.as_secs_f64();

    let run = AdaptRun {
        demo_path: demo.path.clone(),
        target_path: target.path.clone(),
        out_dir: options.out_dir.clone(),
        instruction: target.instruction(&demo),
        setting,
        states: translated.source,
        demo_states: translated.demo_states,
        target_state: translated.target_state,
        adaptation,
        status,
        policy,
        codegen_error,
        execution,
        timing,
        usage,
    };
    progress.stage("writing the outputs");
    output::write_all(&run, &target, &options.out_dir)?;
    Ok(run)
}

/// Tier, embodiment atoms, factor, complexity and budget for a demo and a target.
pub fn derive_setting(demo: &DemoInput, target: &TargetInput, options: &AdaptOptions) -> Setting {
    let source = demo.demo.metadata.embodiment;
    let target_embodiment = target.scene.embodiment;
    let changed = source != target_embodiment;
    let tier = if changed || source == Embodiment::Vacuum || target_embodiment == Embodiment::Vacuum {
        Tier::Extended
    } else {
        Tier::Full
    };
    let from_id = demo
        .demo
        .metadata
        .scenario_id
        .as_deref()
        .and_then(parse_scenario_id);
    let factor = from_id
        .map(|(f, _)| f)
        .unwrap_or(match (source, target_embodiment) {
            (Embodiment::Finger, Embodiment::Vacuum) => Factor::Grip,
            (Embodiment::Vacuum, Embodiment::Finger) => Factor::Vacu,
            _ => Factor::Obst,
        });
    let complexity = from_id
        .map(|(_, c)| c)
        .unwrap_or(Complexity::of_subtask_count(target.scene.goals.len()));
    let (budget, budget_origin) = match options.budget {
        Some(b) => (b, "flag"),
        None => (iteration_budget(factor, complexity), "scenario"),
    };
    Setting {
        source_embodiment: source,
        target_embodiment,
        tier,
        embodiment_in_state: changed,
        factor,
        complexity,
        budget,
        budget_origin,
    }
}
