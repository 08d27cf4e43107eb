//! `nesy adapt`: adapt a demonstration to a target scene (NeSyCR) and synthesize, and
//! optionally execute, a verified code policy. The work is done by `nesy_pipeline`; this
//! module parses flags, owns the async runtime, shows progress and prints the summary.

use std::fmt::Write as _;
use std::io::IsTerminal as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context as _;
use nesy_core::adapt::AdaptConfig;
use nesy_pipeline::output::{RunDir, induction_counts, proposals, violations};
use nesy_pipeline::states::{StateSource, StatesMode};
use nesy_pipeline::synth::CodegenMode;
use nesy_pipeline::vlm::{VlmSetup, VlmSource};
use nesy_pipeline::{
    self as pipeline, AdaptOptions, AdaptRun, DemoInput, ImagesMode, LogProgress, NoProgress, PipelineError,
    Progress, TargetInput,
};
use nesy_policy::Limits;
use nesy_vlm::ConfigOverrides;

/// Arguments of `nesy adapt`.
#[derive(Debug, clap::Args)]
pub(crate) struct AdaptArgs {
    /// The demonstration: `demo.mcap`, a folder holding it, or a folder with `manifest.json`.
    #[arg(long, value_name = "DIR")]
    pub demo: PathBuf,
    /// The target: a simulated scene (`scene.json`), or a camera target folder (the demo
    /// layout with one keyframe: the camera's frames, the object list, the instruction and
    /// the robot; optionally `scene.json` beside its manifest to execute on). Defaults to the
    /// target scene recorded in the demo.
    #[arg(long, value_name = "SCENE|DIR")]
    pub target: Option<PathBuf>,
    /// The task's predicates and object kinds (a TOML vocabulary file); the default is the
    /// benchmark's fifteen predicates.
    #[arg(long, value_name = "FILE")]
    pub vocabulary: Option<PathBuf>,
    /// A folder of prompt files replacing the bundled ones by name (`nesy prompts export`
    /// writes them); the run's summary.json records the hash of every template used.
    #[arg(long, value_name = "DIR")]
    pub prompts: Option<PathBuf>,
    /// Who answers: `oracle` (offline reference responder), `replay:CASSETTE`, or the URL of
    /// an OpenAI-compatible server. Default: the configured VLM (NESY_VLM_* settings).
    #[arg(long, value_name = "URL|replay:CASSETTE|oracle")]
    pub vlm: Option<String>,
    /// Record every model call to this cassette (replay it later with `--vlm replay:FILE`).
    #[arg(long, value_name = "CASSETTE")]
    pub record: Option<PathBuf>,
    /// Noise for `--vlm oracle`, e.g. `op-drop=0.1,state-inject=0.1,bad-patch=0.2` (`nesy-vlm`'s README lists the knobs).
    #[arg(long, value_name = "SPEC", default_value = "")]
    pub oracle_noise: String,
    /// Symbolic states: ground truth (`observed`), the VLM's state translation (`vlm`), or
    /// ground truth when the demo has it (`auto`).
    #[arg(long, value_enum, default_value_t = StatesMode::Auto)]
    pub states: StatesMode,
    /// Whether model requests carry the keyframes' pictures: `auto` sends them unless the
    /// server announces text input only; `never` needs `--states observed`.
    #[arg(long, value_enum, default_value_t = ImagesMode::Auto)]
    pub vlm_images: ImagesMode,
    /// Code synthesis: the VLM's code-generation prompt, or the deterministic template compiler.
    #[arg(long, value_enum, default_value_t = CodegenMode::Vlm)]
    pub codegen: CodegenMode,
    /// Run the policy in the sandbox against the target scene and score it (a camera target
    /// needs a `scene.json` beside its manifest for this).
    #[arg(long)]
    pub execute: bool,
    /// With `--execute`, record the execution into the output directory: its calls replayed
    /// on a fresh copy of the target scene give `execution.mcap` (a keyframe after every
    /// action) and `rollout.mp4` (a frame every N control steps; N divides 100). 0 records
    /// nothing.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub render_every: u32,
    /// Output directory (default `runs/adapt/<demo name>`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the run summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Patch-proposal budget (default: 10, 15 for combined factors, doubled at high complexity).
    #[arg(long, value_name = "N")]
    pub budget: Option<usize>,
    /// Induction attempts per demonstrated transition.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub induction_tries: usize,
    /// Wall-clock budget of the policy in seconds (with `--execute`).
    #[arg(long, value_name = "SECS", default_value_t = 300.0)]
    pub timeout: f64,
    /// Stop the policy when it makes no robot API call for this many seconds (with
    /// `--execute`).
    #[arg(long, value_name = "SECS", default_value_t = 10.0)]
    pub idle_timeout: f64,
    /// VLM settings (also from the environment and `--vlm-config`).
    #[command(flatten)]
    pub vlm_config: ConfigOverrides,
    /// Running the policy on a robot (with `--execute`; its record goes to `robot/` in the
    /// output directory).
    #[command(flatten)]
    pub robot: super::robot::RobotArgs,
}

/// A run that stopped before it had an outcome of its own. The model's side ending it (no
/// usable reply, a refused request, an unreachable server) is an outcome of the episode:
/// it is printed, recorded in `failure.json` and exits 1. Anything else is an error (exit
/// 2); it too leaves its record behind, except bad input, which stops before the run.
fn stopped(
    error: &PipelineError,
    target: &TargetInput,
    options: &AdaptOptions,
    calls: &nesy_vlm::RunUsage,
    elapsed: Duration,
) -> anyhow::Result<ExitCode> {
    let reason = error.stop_reason();
    let recorded =
        RunDir::create(&options.out_dir).and_then(|dir| dir.write_failure(target, error, calls, elapsed));
    let record = match recorded {
        Ok(Some(path)) => format!("; {} records why", path.display()),
        Ok(None) => String::new(),
        Err(write_error) => format!("; the failure could not be recorded: {write_error}"),
    };
    if reason.is_model_side() {
        outln!(
            "nesy adapt: {}\n  reason    {error}\n  calls     {} model call(s) in {:.1} s{record}",
            reason.as_str().to_uppercase(),
            calls.total.calls,
            elapsed.as_secs_f64()
        )?;
        return Ok(ExitCode::from(1));
    }
    if !record.is_empty() {
        eprintln!("nesy adapt: the run stopped before an outcome{record}");
    }
    Err(anyhow::anyhow!("{error}"))
}

/// Runs `nesy adapt`: exit 0 when the procedure was adapted, compiled and (with `--execute`)
/// succeeded; 1 when the adaptation is unresolved, code generation failed, the policy
/// failed, or the model gave no usable reply, refused the request or could not be reached;
/// 2 on bad input.
pub(crate) fn run(args: AdaptArgs) -> anyhow::Result<ExitCode> {
    let options = options(&args)?;
    anyhow::ensure!(
        args.robot.robot.is_none() || args.execute,
        "--robot runs the adapted policy on a robot: it needs --execute"
    );
    if args.render_every != 0 {
        anyhow::ensure!(
            args.execute,
            "--render-every records an execution: it needs --execute"
        );
        super::rollout::rollout_fps(args.render_every)?;
    }
    let setup = VlmSetup {
        source: match &args.vlm {
            Some(text) => VlmSource::parse(text, args.vlm_config.clone(), args.oracle_noise.clone())?,
            None => VlmSource::Configured(Box::new(args.vlm_config.clone())),
        },
        record: args.record.clone(),
    };
    if !args.oracle_noise.is_empty() && !matches!(setup.source, VlmSource::Oracle { .. }) {
        anyhow::bail!("--oracle-noise only applies to --vlm oracle");
    }
    let progress = make_progress(args.json);
    progress.stage("reading the demo");
    let demo = DemoInput::load(&args.demo, &options.vocabulary)?;
    progress.stage("building the target scene");
    let target = TargetInput::load(args.target.as_deref(), &demo)?;
    progress.stage("connecting the VLM");
    let client = pipeline::vlm::build_client(&setup, &demo)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    let started = std::time::Instant::now();
    // The clone shares the client's accounting, so the calls made before a stop are known.
    let calls = client.clone();
    let run = match runtime.block_on(pipeline::run(&demo, &target, client, &options, progress.clone())) {
        Ok(run) => run,
        Err(error) => {
            progress.stage("");
            return stopped(&error, &target, &options, &calls.usage(), started.elapsed());
        }
    };
    progress.stage("writing the outputs");
    let out_dir = RunDir::create(&run.out_dir)?;
    out_dir.write_all(&run, &target)?;
    progress.stage("");
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&run)?)?;
    } else {
        out!("{}", summary(&run))?;
    }
    let mut rollout_files = None;
    if let Some(execution) = run.execution.as_ref().filter(|_| args.render_every != 0) {
        let rollout = super::rollout::record_rollout(
            &execution.scene_path,
            None,
            &execution.result.trace,
            &run.out_dir,
            args.render_every,
        )?;
        super::rollout::announce(&rollout, "  recording ", args.json)?;
        rollout_files = Some(pipeline::RolloutFiles {
            video: pipeline::output::ROLLOUT_VIDEO_FILE.to_owned(),
            recording: pipeline::output::EXECUTION_RECORDING_FILE.to_owned(),
            summary: super::rollout::describe(&rollout),
        });
    }
    // Written last, so that it can show the rollout.
    let html = pipeline::report_html(&run, &demo, &target, rollout_files.as_ref());
    out_dir.write_text(pipeline::HTML_REPORT_FILE, &html)?;
    if let Some(error @ pipeline::synth::SynthError::Call { .. }) = &run.codegen_error {
        eprintln!("error: {error} (outputs written to {})", run.out_dir.display());
    }
    if let Some(address) = &args.robot.robot {
        return execute_on_robot(&args, address, &run, &target, &options);
    }
    Ok(ExitCode::from(run.exit_code()))
}

/// `--execute --robot`: the adapted policy on the robot, after its execution in the target
/// scene (the dry run) reached the goal; exit 0 only if the adaptation succeeded and the
/// policy ran to its end on the robot.
fn execute_on_robot(
    args: &AdaptArgs,
    address: &nesy_robot::RobotAddress,
    run: &pipeline::AdaptRun,
    target: &TargetInput,
    options: &AdaptOptions,
) -> anyhow::Result<ExitCode> {
    use super::robot::{DryRun, dry_run_verdict};
    let Some(policy) = &run.policy else {
        eprintln!("robot not contacted: no policy was synthesized");
        return Ok(ExitCode::from(run.exit_code().max(1)));
    };
    let dry_run = match (&run.execution, args.robot.skip_dry_run) {
        (_, true) => DryRun::Skipped,
        (Some(execution), false) => {
            if let Some(why) = dry_run_verdict(&execution.result) {
                if args.json {
                    eprintln!("robot not contacted: {why}");
                } else {
                    outln!("  robot     not contacted: {why}")?;
                }
                return Ok(ExitCode::from(run.exit_code().max(1)));
            }
            DryRun::Passed {
                scene: &execution.scene_path,
                result: &execution.result,
            }
        }
        (None, false) => anyhow::bail!(
            "--robot needs the dry run in simulation, and this target has no scene to run it on ({}); \
             give the camera target a scene.json, or pass --skip-dry-run",
            run.not_executed.as_deref().unwrap_or("not executed")
        ),
    };
    let run_dir = run.out_dir.join("robot");
    let policy_file = run.out_dir.join("policy.py").display().to_string();
    let robot_run = super::robot::RobotRun {
        source: &policy.code,
        policy_file: &policy_file,
        limits: &options.limits,
        dry_run,
        run_dir: &run_dir,
        expected: Some(target.embodiment),
    };
    let (result, _record) = super::robot::run_on_robot(&args.robot, address, robot_run)?;
    let stop = super::robot::describe_stop(&result.outcome)
        .map(|s| format!(", {s}"))
        .unwrap_or_default();
    let line = format!(
        "  robot     {} at {address} ({} API calls{stop}); record {}",
        result.outcome.kind(),
        result.trace.len(),
        run_dir.display()
    );
    // With --json, stdout holds the run summary alone; the record is in robot/robot-run.json.
    if args.json {
        eprintln!("{}", line.trim_start());
    } else {
        outln!("{line}")?;
    }
    Ok(ExitCode::from(if result.is_ok() { run.exit_code() } else { 1 }))
}

fn options(args: &AdaptArgs) -> anyhow::Result<AdaptOptions> {
    let wall_time_ms = super::seconds_to_ms("--timeout", args.timeout)?;
    let idle_ms = super::seconds_to_ms("--idle-timeout", args.idle_timeout)?;
    if args.induction_tries == 0 {
        anyhow::bail!("--induction-tries must be at least 1");
    }
    if args.budget == Some(0) {
        anyhow::bail!("--budget must be at least 1");
    }
    let out_dir = match &args.out {
        Some(dir) => dir.clone(),
        None => {
            let name = args
                .demo
                .file_stem()
                .filter(|n| *n != "demo")
                .or_else(|| args.demo.parent().and_then(|p| p.file_name()))
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "demo".into());
            PathBuf::from("runs/adapt").join(name)
        }
    };
    let vocabulary = match &args.vocabulary {
        Some(path) => pipeline::load_vocabulary(path)?,
        None => nesy_core::Vocabulary::new(),
    };
    let prompts = match &args.prompts {
        Some(dir) => Some(Arc::new(nesy_reasoner::prompts::Prompts::with_overrides(dir)?)),
        None => None,
    };
    Ok(AdaptOptions {
        vocabulary,
        prompts,
        states: args.states,
        codegen: args.codegen,
        execute: args.execute,
        images: args.vlm_images,
        budget: args.budget,
        adapt: AdaptConfig {
            induction_tries: args.induction_tries,
            ..AdaptConfig::default()
        },
        limits: Limits {
            wall_time_ms,
            idle_ms,
            ..Limits::default()
        },
        worker: None,
        out_dir,
    })
}

/// A spinner on a terminal; log events otherwise; nothing with `--json`.
fn make_progress(json: bool) -> Arc<dyn Progress> {
    if json {
        Arc::new(NoProgress)
    } else if std::io::stderr().is_terminal() {
        Arc::new(Spinner::new())
    } else {
        Arc::new(LogProgress)
    }
}

struct Spinner {
    bar: indicatif::ProgressBar,
}

impl Spinner {
    fn new() -> Spinner {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {prefix}: {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        bar.enable_steady_tick(Duration::from_millis(120));
        Spinner { bar }
    }
}

impl Progress for Spinner {
    fn stage(&self, name: &str) {
        if name.is_empty() {
            self.bar.finish_and_clear();
        } else {
            self.bar.set_prefix(name.to_owned());
            self.bar.set_message("");
        }
    }

    fn detail(&self, message: &str) {
        self.bar.set_message(message.to_owned());
    }
}

/// The terminal summary.
pub(crate) fn summary(run: &AdaptRun) -> String {
    let mut out = String::new();
    summarize_inputs(&mut out, run);
    summarize_world_model(&mut out, run);
    summarize_adaptation(&mut out, run);
    summarize_policy(&mut out, run);
    summarize_execution(&mut out, run);
    summarize_time(&mut out, run);
    out
}

/// The status, the demo, the target and where the states came from.
fn summarize_inputs(out: &mut String, run: &AdaptRun) {
    let s = &run.setting;
    let _ = writeln!(out, "nesy adapt: {}", run.status.as_str().to_uppercase());
    let _ = writeln!(
        out,
        "  demo      {} ({} keyframes, {})",
        run.demo_path.display(),
        run.demo_states.len(),
        s.source_embodiment
    );
    let _ = writeln!(
        out,
        "  target    {} ({}{})",
        run.target_path.display(),
        s.target_embodiment,
        if s.source_embodiment != s.target_embodiment {
            ", embodiment changed"
        } else {
            ""
        }
    );
    let states = match &run.states {
        StateSource::Observed => "observed (ground truth)".to_owned(),
        StateSource::Vlm { agreement, .. } => format!(
            "VLM state translation{}",
            agreement
                .map(|a| format!(" (F1 {:.2} vs ground truth)", a.f1))
                .unwrap_or_default()
        ),
    };
    let _ = writeln!(out, "  states    {states}");
}

/// How many operators were induced and whether all verified.
fn summarize_world_model(out: &mut String, run: &AdaptRun) {
    let wm = &run.adaptation.world_model;
    let counts = induction_counts(&run.adaptation);
    let _ = writeln!(
        out,
        "  world     {} operators, {} ({})",
        wm.procedure.len(),
        if wm.is_verified() {
            "all verified".to_owned()
        } else {
            format!("UNVERIFIED steps {:?}", wm.unverified_steps)
        },
        counts.summary()
    );
}

/// The violations found and the proposals' verdicts, then the procedure.
fn summarize_adaptation(out: &mut String, run: &AdaptRun) {
    let found = violations(&run.adaptation);
    let props = proposals(&run.adaptation);
    let accepted = props.iter().filter(|p| p.verdict == "accepted").count();
    let _ = writeln!(
        out,
        "  adapt     {} violation(s), {} proposal(s) ({} accepted, {} rejected), budget {}",
        found.len(),
        props.len(),
        accepted,
        props.len() - accepted,
        run.setting.budget
    );
    for v in &found {
        let _ = match v.kind {
            "precondition" => writeln!(
                out,
                "            step {} {}: unmet {}",
                v.step.map(|s| s + 1).unwrap_or_default(),
                v.action.as_deref().unwrap_or(""),
                v.unmet.join(" ")
            ),
            _ => writeln!(out, "            goal: unmet {}", v.unmet.join(" ")),
        };
    }
    match run.adapted() {
        Some(p) => {
            let _ = writeln!(
                out,
                "  procedure {} -> {} actions, verified",
                run.demonstrated().len(),
                p.len()
            );
        }
        None => {
            let _ = writeln!(
                out,
                "  procedure UNRESOLVED: no verified procedure; no policy was produced"
            );
        }
    }
}

/// Where the program came from, or why there is none.
fn summarize_policy(out: &mut String, run: &AdaptRun) {
    if let Some(p) = &run.policy {
        let mode = match p.mode {
            CodegenMode::Vlm => "VLM code generation",
            CodegenMode::Template => "template compiler",
        };
        let _ = writeln!(
            out,
            "  policy    policy.py ({mode}, {} lines)",
            p.code.lines().count()
        );
        for (i, rejected) in p.rejected.iter().enumerate() {
            let _ = writeln!(out, "            reply {} re-asked: {}", i + 1, rejected.problem);
        }
    }
    if let Some(e) = &run.codegen_error {
        let first = e.to_string();
        let _ = writeln!(
            out,
            "  policy    FAILED: {}",
            first.lines().next().unwrap_or_default()
        );
    }
}

/// The episode's outcome and goal checks, when the policy ran.
fn summarize_execution(out: &mut String, run: &AdaptRun) {
    if let Some(reason) = &run.not_executed {
        let _ = writeln!(out, "  execute   {reason}");
    }
    if let Some(x) = &run.execution {
        let r = &x.result;
        let _ = writeln!(
            out,
            "  execute   {} ({} API calls, {:.1} s)",
            r.outcome.kind(),
            r.trace.len(),
            r.wall_time_s
        );
        match &x.metrics {
            Some(m) => {
                let results: Vec<String> = m
                    .subtasks
                    .iter()
                    .map(|s| {
                        format!(
                            "{} {}",
                            s.subtask,
                            serde_json::to_value(s.status)
                                .ok()
                                .and_then(|v| v.as_str().map(str::to_owned))
                                .unwrap_or_default()
                        )
                    })
                    .collect();
                let _ = writeln!(out, "            {}", results.join(", "));
                let _ = writeln!(
                    out,
                    "            SR {:.0}  GC {:.2}  PD {}",
                    m.sr,
                    m.gc,
                    m.pd.map(|p| format!("{p:.2}")).unwrap_or_else(|| "n/a".into())
                );
            }
            None => {
                let _ = writeln!(out, "            no goal checks reported");
            }
        }
    }
}

/// The time breakdown and where the outputs are.
fn summarize_time(out: &mut String, run: &AdaptRun) {
    let t = &run.timing;
    let _ = writeln!(
        out,
        "  time      VLM {:.3} s, symbolic {:.2} ms (world model {:.2}, adaptation {:.2}), template compiler {:.2} ms, sim {:.2} s, total {:.2} s",
        t.vlm_s,
        t.symbolic_s * 1e3,
        t.symbolic_world_model_s * 1e3,
        t.symbolic_adaptation_s * 1e3,
        t.codegen_template_s * 1e3,
        t.sim_s,
        t.total_s
    );
    let _ = writeln!(
        out,
        "  outputs   {}/ (report.md, adaptation.json, ...)",
        run.out_dir.display()
    );
}
