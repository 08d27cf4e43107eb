//! Replays the API calls of a recorded policy run (`execution.json` of `nesy adapt --execute`
//! or `nesy run`) on its scene and reports, control step by control step, when one of the
//! watched objects moves while the robot does not hold it: the tool for finding which call
//! (and which part of its motion) knocked an object.
//!
//! ```text
//! cargo run -p nesy-sim --example replay_trace -- SCENE.json EXECUTION.json OBJECT...
//! ```
//!
//! Every call is replayed with its recorded arguments (the policy's own arithmetic is not
//! re-run), so the replay follows the recorded run as long as the simulation is deterministic;
//! a query whose answer differs from the recorded one is flagged.

use std::sync::{Arc, Mutex};

use nesy_sim::api::TraceEntry;
use nesy_sim::world::{Sim, SimHook};

/// Watches objects every few control steps and prints each step at which one moved.
struct Watch {
    objects: Vec<String>,
    last: Vec<[f64; 3]>,
    /// The call being replayed, for the printout.
    current: Arc<Mutex<String>>,
}

impl SimHook for Watch {
    fn step_interval(&self) -> Option<u64> {
        Some(5)
    }

    fn on_step(&mut self, sim: &Sim) {
        let held = sim.held_object().map(str::to_owned);
        let tool = sim.tool_pose().translation.vector;
        for (name, last) in self.objects.iter().zip(self.last.iter_mut()) {
            let Some(aabb) = sim.object_aabb(name) else {
                continue;
            };
            let now = aabb.centre();
            let moved = (0..3).map(|i| (now[i] - last[i]).powi(2)).sum::<f64>().sqrt();
            if moved > 0.003 && held.as_deref() != Some(name.as_str()) {
                println!(
                    "  {:7.3} s  [{}] {name} moved {moved:.3} m to ({:.3}, {:.3}, {:.3}); tool ({:.3}, {:.3}, {:.3}), joints {:?}",
                    sim.time(),
                    self.current.lock().map(|c| c.clone()).unwrap_or_default(),
                    now[0],
                    now[1],
                    now[2],
                    tool.x,
                    tool.y,
                    tool.z,
                    sim.arm_joints()
                        .iter()
                        .map(|q| (q * 100.0).round() / 100.0)
                        .collect::<Vec<_>>()
                );
                *last = now;
            }
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        return Err("usage: replay_trace SCENE.json EXECUTION.json OBJECT...".into());
    }
    let scene = nesy_sim::scene::SceneSpec::from_file(std::path::Path::new(&args[0]))?;
    let text = std::fs::read_to_string(&args[1])?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", args[1]))?;
    let trace = json
        .pointer("/result/trace")
        .ok_or_else(|| format!("{}: no result.trace array", args[1]))?;
    let entries: Vec<TraceEntry> =
        serde_json::from_value(trace.clone()).map_err(|e| format!("{}: result.trace: {e}", args[1]))?;
    let mut sim = Sim::new(&scene)?;
    let objects: Vec<String> = args[2..].to_vec();
    let last = objects
        .iter()
        .map(|name| {
            sim.object_aabb(name)
                .map(|b| b.centre())
                .ok_or(format!("no object {name:?}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let current = Arc::new(Mutex::new(String::new()));
    sim.add_hook(Box::new(Watch {
        objects,
        last,
        current: Arc::clone(&current),
    }));
    for entry in &entries {
        if let Ok(mut c) = current.lock() {
            *c = format!("#{} {}", entry.index, entry.call.name());
        }
        let got = entry.call.perform(&mut sim);
        if entry.call.is_action() {
            let tool = sim.tool_pose().translation.vector;
            println!(
                "#{:3} {:7.2} s  {:?} -> {:?}  tool ({:.3}, {:.3}, {:.3})",
                entry.index,
                sim.time(),
                entry.call,
                got.as_ref().map(|_| ()),
                tool.x,
                tool.y,
                tool.z
            );
        } else if got != entry.result {
            println!(
                "#{:3} {:?}: replay answered {got:?}, recorded {:?}",
                entry.index, entry.call, entry.result
            );
        }
    }
    Ok(())
}
