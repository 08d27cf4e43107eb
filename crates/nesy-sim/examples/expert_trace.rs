//! Runs the scripted expert on one generated single-subtask task and prints every action
//! call with its result, the final symbolic state and the goal checks' verdict: the tool
//! for finding out why the expert sweep reports a failure.
//!
//! ```text
//! cargo run -p nesy-sim --example expert_trace -- KIND OBST MULTI VARIANT finger|vacuum [SCENE_OUT.json]
//! cargo run -p nesy-sim --example expert_trace -- --task TASK_CONFIG.json [SCENE_OUT.json]
//! cargo run -p nesy-sim --example expert_trace -- --scene SCENE.json
//! cargo run -p nesy-sim --example expert_trace -- --scenario ID source|target
//! ```
//!
//! The second form takes any `TaskConfig` (e.g. a composite), as JSON; the third a
//! `scene.json` with goals, e.g. from `nesy scenarios show ID --side source`. After each call
//! the loose objects that moved more than 2 cm during it are listed, so an object knocked by
//! the arm shows at the call that knocked it.

use nesy_core::Embodiment;
use nesy_sim::api::TraceEntry;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::TaskConfig;
use nesy_sim::tasks::goal::GoalMonitor;
use nesy_sim::world::Sim;
use nesy_sim::world::SimHook;

/// Prints every action call with its result and the articulations' joint positions after it.
struct PrintActions {
    articulations: Vec<String>,
    /// Loose objects and where they were after the previous action.
    tracked: Vec<(String, [f64; 3])>,
}

impl SimHook for PrintActions {
    fn on_call(&mut self, sim: &Sim, entry: &TraceEntry) {
        if !entry.call.is_action() {
            return;
        }
        let verdict = match &entry.result {
            Ok(_) => "ok".to_owned(),
            Err(e) => format!("refused: {e}"),
        };
        let joints: Vec<String> = self
            .articulations
            .iter()
            .map(|name| format!("{name} {:.3}", sim.articulation_q(name).unwrap_or(f64::NAN)))
            .collect();
        let tool = sim.tool_pose().translation.vector;
        println!(
            "{:7.2} s  {:?} -> {verdict}  [{}; tool ({:.3}, {:.3}, {:.3})]",
            entry.sim_time,
            entry.call,
            joints.join(", "),
            tool.x,
            tool.y,
            tool.z
        );
        let held = sim.held_object().map(str::to_owned);
        for (name, last) in &mut self.tracked {
            let Some(aabb) = sim.object_aabb(name) else {
                continue;
            };
            let now = aabb.centre();
            let moved = (0..3).map(|i| (now[i] - last[i]).powi(2)).sum::<f64>().sqrt();
            if moved > 0.02 && held.as_deref() != Some(name.as_str()) {
                println!(
                    "           {name} moved {moved:.3} m to ({:.3}, {:.3}, {:.3})",
                    now[0], now[1], now[2]
                );
            }
            *last = now;
        }
    }
}

const USAGE: &str = "usage: expert_trace KIND OBST MULTI VARIANT finger|vacuum [SCENE_OUT.json] \
                     | expert_trace --task TASK_CONFIG.json [SCENE_OUT.json] \
                     | expert_trace --scene SCENE.json \
                     | expert_trace --scenario ID source|target";

/// The task of the first form's arguments.
fn single_config(args: &[String]) -> Result<TaskConfig, Box<dyn std::error::Error>> {
    if args.len() < 5 {
        return Err(USAGE.into());
    }
    let kind =
        SubtaskKind::from_name(&args[0]).ok_or_else(|| format!("unknown subtask {:?}; {USAGE}", args[0]))?;
    let embodiment = match args[4].as_str() {
        "finger" => Embodiment::Finger,
        "vacuum" => Embodiment::Vacuum,
        other => return Err(format!("unknown embodiment {other:?}; {USAGE}").into()),
    };
    let variant: u64 = args[3].parse()?;
    Ok(TaskConfig::single(
        kind,
        variant,
        args[1].parse()?,
        args[2].parse()?,
        embodiment,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = if args.first().map(String::as_str) == Some("--scene") {
        let path = args.get(1).ok_or(USAGE)?;
        nesy_sim::scene::SceneSpec::from_file(std::path::Path::new(path))?
    } else if args.first().map(String::as_str) == Some("--scenario") {
        // The scene exactly as the sweep builds it (a scene written as JSON and read back can
        // differ in the last bits of a coordinate, and some episodes are sensitive to that).
        use nesy_sim::tasks::scenario::{self, Side};
        let id = args.get(1).ok_or(USAGE)?;
        let side = match args.get(2).map(String::as_str) {
            Some("target") => Side::Target,
            Some("source") | None => Side::Source,
            Some(_) => return Err(USAGE.into()),
        };
        scenario::find(&scenario::generate_suite(), id)?
            .generate(side)?
            .scene
    } else {
        generated_scene(&args)?
    };
    trace(&scene)
}

/// The scene of the first two forms (written to SCENE_OUT.json when given).
fn generated_scene(args: &[String]) -> Result<nesy_sim::scene::SceneSpec, Box<dyn std::error::Error>> {
    let (config, scene_out) = if args.first().map(String::as_str) == Some("--task") {
        let path = args.get(1).ok_or(USAGE)?;
        let text = std::fs::read_to_string(path)?;
        let config: TaskConfig = serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
        (config, args.get(2))
    } else {
        (single_config(args)?, args.get(5))
    };
    let task = config.generate()?;
    if let Some(path) = scene_out {
        std::fs::write(path, task.scene.to_json_pretty())?;
    }
    Ok(task.scene)
}

fn trace(scene: &nesy_sim::scene::SceneSpec) -> Result<(), Box<dyn std::error::Error>> {
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    let tracked = scene
        .goals
        .iter()
        .flat_map(|g| g.objects())
        .filter_map(|name| Some((name.to_owned(), sim.object_aabb(name)?.centre())))
        .collect();
    sim.add_hook(Box::new(PrintActions {
        articulations: scene.articulations.keys().cloned().collect(),
        tracked,
    }));
    let result = nesy_sim::tasks::experts::run(&mut sim, scene);
    println!("\n{}", nesy_sim::perception::observer::observe(&sim));
    let outcome = monitor.finish(&mut sim);
    // After the final settle, as the goal checks saw them: the displaced list is decided here.
    let containers = [
        "toy_box",
        "hinge_body",
        "bottom_drawer",
        "left_chess_box",
        "right_chess_box",
    ];
    for name in scene.goals.iter().flat_map(|g| g.objects()).chain(containers) {
        println!(
            "{name}: {:?} speed {:.4}",
            sim.object_aabb(name),
            sim.object_velocity(name)
                .map_or(0.0, |v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
        );
    }
    println!(
        "\nexpert: {}\ngoal checks: {}; displaced: {:?}\nachieved: {:?}",
        result.map_or_else(|e| e.to_string(), |()| "finished".to_owned()),
        outcome.summary(),
        outcome.displaced,
        outcome.achieved_sequence
    );
    Ok(())
}
