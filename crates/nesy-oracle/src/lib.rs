//! The offline reference responder (`--vlm oracle`): a [`Transport`] that answers every
//! NeSyCR call from simulator ground truth and nesy's true domain
//! (`assets/pddl/nesy-world.pddl`), in the text format the prompt asks for. It sits where
//! HTTP would, under the retry layer and any cassette, so the replies go through the same
//! parsers, verification and cassette recording as a real model's.
//!
//! - **Operator induction** ([`induce`]): the transition's recorded API call (given to
//!   the responder with [`OracleTransport::with_demo_calls`]) selects the domain's schemas
//!   for that call; the binding whose grounded effects reproduce s_{t+1} is printed as the
//!   Action Prediction reply.
//! - **Patches** ([`propose`]): nesy-core's planner over the true domain, from the violation
//!   state to the unmet preconditions (or a removal of redundant actions, or a conversion to
//!   the target end effector), printed as a SEARCH/REPLACE reply.
//! - **State translation**: the ground-truth state the request carries, minus the atoms
//!   already known.
//! - **Code generation**: the procedure compiled by nesy-sim's template compiler, in a
//!   fenced code block.
//!
//! [`OracleNoise`] degrades the answers on purpose for the robustness study.
//!
//! The responder plugs in where HTTP would, behind nesy-vlm's client; its answers are an
//! upper bound on a model's, never a model's:
//!
//! ```
//! use std::sync::Arc;
//! use nesy_oracle::{OracleNoise, OracleTransport};
//! use nesy_vlm::{BackendKind, VlmClient, VlmConfig};
//!
//! let noise: OracleNoise = "op-drop=0.1,bad-patch=0.2".parse().unwrap();
//! let oracle = Arc::new(OracleTransport::new().unwrap().with_noise(noise, 7));
//! let client = VlmClient::with_transport(&VlmConfig::new(BackendKind::Vllm, "nesy-oracle"), oracle.clone());
//! assert_eq!(oracle.stats().inductions, 0);
//! # drop(client);
//! ```

mod induce;
mod noise;
mod patch;

use std::fmt;
use std::sync::Mutex;

use nesy_core::Atom;
use nesy_core::Symbol;
use nesy_core::planner::PlannerConfig;
use serde::{Deserialize, Serialize};

pub use induce::{InduceError, InducedAction, api_function, induce};
pub use noise::{NoiseError, NoiseRng, OracleNoise, Relations, StateScope};
pub use patch::{OraclePatchError, ProposedPatch, Strategy, misplaced, propose, propose_for_guess};

use nesy_reasoner::{CodeGenerationContext, StateTranslationContext, VlmTask};
use nesy_sim::api::ApiCall;
use nesy_sim::codegen::compile_policy;
use nesy_sim::domain::{DomainError, WorldDomain};
use nesy_vlm::{BoxFuture, Origin, Transport, TransportError, WireRequest, WireResponse};

/// Counts of what the oracle answered, for reports and tests.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct OracleStats {
    /// Induction replies.
    pub inductions: usize,
    /// Induction replies whose schema reproduced the transition exactly.
    pub exact_inductions: usize,
    /// Patch replies, by strategy.
    pub patches: usize,
    /// Patch replies corrupted by `bad_patch`.
    pub corrupted_patches: usize,
    /// Operator literals and state atoms changed by the operator and state knobs.
    pub perturbed_literals: usize,
    /// Patch requests without identification whose failing step the oracle guessed
    /// (`localize_miss`).
    pub localize_misses: usize,
    /// State translations.
    pub translations: usize,
    /// Programs compiled.
    pub programs: usize,
}

/// The reference responder as a transport.
pub struct OracleTransport {
    world: &'static WorldDomain,
    noise: OracleNoise,
    seed: u64,
    planner: PlannerConfig,
    demo_calls: Vec<Option<ApiCall>>,
    stats: Mutex<OracleStats>,
}

impl fmt::Debug for OracleTransport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("OracleTransport")
            .field("noise", &self.noise)
            .field("seed", &self.seed)
            .field("demo_calls", &self.demo_calls.len())
            .finish_non_exhaustive()
    }
}

impl OracleTransport {
    /// An oracle over the built-in true domain, without noise and without recorded calls.
    pub fn new() -> Result<OracleTransport, DomainError> {
        Ok(OracleTransport {
            world: WorldDomain::builtin()?,
            noise: OracleNoise::NONE,
            seed: 0,
            planner: PlannerConfig::default(),
            demo_calls: Vec::new(),
            stats: Mutex::new(OracleStats::default()),
        })
    }

    /// Degrades answers with `noise`, drawing from `seed`.
    pub fn with_noise(mut self, noise: OracleNoise, seed: u64) -> Self {
        self.noise = noise;
        self.seed = seed;
        self
    }

    /// The demonstration's recorded robot calls, one per transition (keyframe `t` to
    /// `t + 1`), `None` where a transition has none. Induction answers for a transition
    /// with a call choose among the schemas that stand for it; without one, among all.
    pub fn with_demo_calls(mut self, calls: Vec<Option<ApiCall>>) -> Self {
        self.demo_calls = calls;
        self
    }

    /// Planner settings for patches.
    pub fn with_planner(mut self, planner: PlannerConfig) -> Self {
        self.planner = planner;
        self
    }

    /// What has been answered so far.
    pub fn stats(&self) -> OracleStats {
        self.stats.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    fn bump(&self, f: impl FnOnce(&mut OracleStats)) {
        f(&mut self.stats.lock().unwrap_or_else(|e| e.into_inner()));
    }

    /// The reply text for a request (what the transport wraps in a completion body).
    pub fn answer(&self, request: &WireRequest) -> Result<String, TransportError> {
        let context = request.task.as_ref().ok_or_else(|| {
            fail("the oracle needs the task context every nesy prompt attaches; this request has none".into())
        })?;
        let task = VlmTask::from_task_context(context).map_err(|e| fail(e.to_string()))?;
        let mut rng = NoiseRng::for_request(self.seed, &request.body);
        match task {
            VlmTask::Induction(ctx) => {
                let call = self.demo_calls.get(ctx.request.step).and_then(Option::as_ref);
                let mut action = induce(self.world, &ctx, call).map_err(|e| fail(e.to_string()))?;
                let changed = noise::perturb_operator(&mut action.operator, &self.noise, &mut rng);
                self.bump(|s| {
                    s.inductions += 1;
                    s.exact_inductions += usize::from(action.exact);
                    s.perturbed_literals += changed;
                });
                Ok(induce::format_reply(&action, call))
            }
            VlmTask::Patch(ctx) => {
                // Without identification, a model may patch the wrong step: the guess
                // replaces the request before the planner sees it.
                // When nothing can be planned for the guessed step, the answer is the
                // correctly localised one.
                let guessed = if rng.chance(self.noise.localize_miss) {
                    patch::misplaced(&ctx, &mut |n| rng.below(n))
                        .and_then(|g| patch::propose_for_guess(self.world, &g, &self.planner).ok())
                } else {
                    None
                };
                if guessed.is_some() {
                    self.bump(|s| s.localize_misses += 1);
                }
                let answer = match guessed {
                    Some(p) => Ok(p),
                    None => propose(self.world, &ctx, &self.planner),
                };
                let mut proposed = match answer {
                    Ok(p) => p,
                    Err(e) => {
                        // An honest non-answer, said in a typed way: the same request would get
                        // the same answer, so the loop stops instead of asking again.
                        self.bump(|s| s.patches += 1);
                        return Err(TransportError::Declined(format!("oracle: no patch: {e}")));
                    }
                };
                let corrupted = rng.chance(self.noise.bad_patch);
                if corrupted {
                    corrupt_patch(&mut proposed, &mut rng);
                }
                self.bump(|s| {
                    s.patches += 1;
                    s.corrupted_patches += usize::from(corrupted);
                });
                Ok(patch::format_reply(&proposed))
            }
            VlmTask::StateTranslation(ctx) => {
                let (text, changed) = translate(&ctx, &self.noise, &mut rng)?;
                self.bump(|s| {
                    s.translations += 1;
                    s.perturbed_literals += changed;
                });
                Ok(text)
            }
            VlmTask::CodeGeneration(ctx) => {
                let code = compile(&ctx)?;
                self.bump(|s| s.programs += 1);
                Ok(format!(
                    "The program below is nesy's template compilation of the {} verified actions for the {}.\n\n```python\n{}```\n",
                    ctx.procedure.len(),
                    ctx.embodiment.description(),
                    if code.ends_with('\n') { code } else { code + "\n" }
                ))
            }
        }
    }
}

/// The template compiler's program for a code-generation request.
fn compile(ctx: &CodeGenerationContext) -> Result<String, TransportError> {
    compile_policy(&ctx.procedure, &ctx.objects, ctx.embodiment, ctx.protective_stop)
        .map(|compiled| compiled.code)
        .map_err(|e| fail(e.to_string()))
}

fn fail(message: String) -> TransportError {
    TransportError::Failed {
        message: format!("oracle: {message}"),
        retryable: false,
    }
}

/// Corrupts a patch: half the time its SEARCH names an action the plan does not have (the
/// loop reports a non-matching SEARCH), otherwise the first inserted action is lost (the
/// loop reports that the violation is not resolved) when there is one to lose.
fn corrupt_patch(p: &mut ProposedPatch, rng: &mut NoiseRng) {
    let inserted = p
        .replace
        .len()
        .saturating_sub(usize::from(p.strategy == Strategy::Insert));
    if rng.chance(0.5) || inserted == 0 {
        if let Some(first) = p.search.first_mut() {
            first.name.push_str("Again");
        }
    } else {
        p.replace.remove(0);
    }
}

fn translate(
    ctx: &StateTranslationContext,
    noise: &OracleNoise,
    rng: &mut NoiseRng,
) -> Result<(String, usize), TransportError> {
    let truth = ctx.ground_truth.as_ref().ok_or_else(|| {
        fail(format!(
            "state translation of {} carries no ground-truth state",
            ctx.view_set
        ))
    })?;
    let objects: Vec<Symbol> = ctx.objects.iter().map(|o| Symbol::new(o)).collect();
    let mut atoms: Vec<Atom> = truth
        .sorted_by_text()
        .into_iter()
        .filter(|a| !ctx.known.contains(a))
        .copied()
        .collect();
    let mut changed = 0;
    if noise.perturbs_states() && noise.state_scope.covers(&ctx.view_set) {
        let (perturbed, report) = noise::perturb_state(&atoms, &objects, noise, rng);
        atoms = perturbed;
        changed = report.changed();
    }
    let mut lines: Vec<String> = atoms.iter().map(|a| format!("- {a}")).collect();
    if lines.is_empty() {
        lines.push("None".into());
    }
    Ok((lines.join("\n") + "\n", changed))
}

/// An OpenAI chat-completion body around a reply text.
pub fn completion_body(text: &str) -> serde_json::Value {
    serde_json::json!({
        "id": "oracle",
        "object": "chat.completion",
        "model": "nesy-oracle",
        "choices": [{
            "index": 0,
            "message": {"role": "assistant", "content": text},
            "finish_reason": "stop"
        }],
        "usage": {"prompt_tokens": 0, "completion_tokens": 0, "total_tokens": 0}
    })
}

impl Transport for OracleTransport {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            let text = self.answer(request)?;
            let mut response = WireResponse::new(200, completion_body(&text).to_string(), Origin::Offline);
            response
                .headers
                .push(("content-type".into(), "application/json".into()));
            Ok(response)
        })
    }

    fn label(&self) -> String {
        if self.noise.is_none() {
            "oracle".into()
        } else {
            format!("oracle noise {}", self.noise)
        }
    }
}

#[cfg(test)]
mod tests {
    use nesy_core::State;
    use nesy_core::Tier;

    use super::*;

    fn translation(view_set: &str, truth: &State) -> WireRequest {
        let ctx = StateTranslationContext {
            view_set: view_set.into(),
            instruction: "put the cubes in the box".into(),
            objects: ["red_cube", "green_cube", "blue_cube", "toy_box", "floor"]
                .map(String::from)
                .to_vec(),
            tier: Tier::Full,
            known: State::new(),
            ground_truth: Some(truth.clone()),
        };
        WireRequest {
            path: "/chat/completions".into(),
            body: serde_json::json!({"view": view_set}),
            task: Some(VlmTask::StateTranslation(ctx).to_task_context()),
            purpose: None,
        }
    }

    fn atoms_of(reply: &str) -> Vec<Atom> {
        reply
            .lines()
            .filter_map(|l| l.strip_prefix("- "))
            .map(|a| a.parse().unwrap())
            .collect()
    }

    fn truth() -> State {
        [
            "(OnTopOf red_cube floor)",
            "(OnTopOf green_cube red_cube)",
            "(OnTopOf blue_cube floor)",
            "(InsideOf blue_cube toy_box)",
            "(OnTopOf toy_box floor)",
            "(GripperOpen)",
        ]
        .iter()
        .map(|a| a.parse::<Atom>().unwrap())
        .collect()
    }

    #[test]
    fn demo_scope_perturbs_keyframes_and_leaves_the_target_untouched() {
        let noise: OracleNoise = "state-drop=0.4,state-inject=0.4".parse().unwrap();
        let oracle = OracleTransport::new().unwrap().with_noise(noise, 3);
        let truth = truth();
        let mut sorted: Vec<Atom> = truth.sorted_by_text().into_iter().copied().collect();
        sorted.sort_by_key(|a| a.to_string());
        let target = atoms_of(&oracle.answer(&translation("target/initial", &truth)).unwrap());
        assert_eq!(target, sorted, "the target is out of scope");
        let demo = atoms_of(&oracle.answer(&translation("demo/keyframe/2", &truth)).unwrap());
        assert_ne!(demo, sorted, "a demo keyframe is in scope");
        // 0.4 of 5 binary relations: 2 dropped, 2 injected.
        assert_eq!(demo.iter().filter(|a| !truth.contains(a)).count(), 2, "{demo:?}");
        assert_eq!(truth.iter().filter(|a| !demo.contains(a)).count(), 2, "{demo:?}");
        assert_eq!(oracle.stats().perturbed_literals, 4);

        let both = OracleTransport::new()
            .unwrap()
            .with_noise("state-drop=0.4,state-scope=target".parse().unwrap(), 3);
        let target = atoms_of(&both.answer(&translation("target/initial", &truth)).unwrap());
        assert_eq!(target.len(), sorted.len() - 2);
        let demo = atoms_of(&both.answer(&translation("demo/keyframe/2", &truth)).unwrap());
        assert_eq!(demo, sorted);
    }
}
