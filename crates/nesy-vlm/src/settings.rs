//! Per-purpose call settings: token cap, reasoning effort and temperature for each kind of
//! call the prompts make.

use serde::{Deserialize, Serialize};

use crate::request::{ChatRequest, ReasoningEffort};

/// Options applied to one kind of call. `None` leaves the client's default.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CallSettings {
    /// Token cap for the reply.
    pub max_output_tokens: Option<u32>,
    /// Reasoning effort (sent to reasoning models only).
    pub reasoning_effort: Option<ReasoningEffort>,
    /// Sampling temperature (dropped for reasoning models).
    pub temperature: Option<f32>,
}

impl CallSettings {
    /// Settings with only a reasoning effort.
    pub fn effort(effort: ReasoningEffort) -> Self {
        CallSettings {
            reasoning_effort: Some(effort),
            ..CallSettings::default()
        }
    }

    /// Applies the settings to a request.
    pub fn apply(&self, mut request: ChatRequest) -> ChatRequest {
        if let Some(tokens) = self.max_output_tokens {
            request = request.max_output_tokens(tokens);
        }
        if let Some(effort) = self.reasoning_effort {
            request = request.reasoning_effort(effort);
        }
        if let Some(t) = self.temperature {
            request = request.temperature(t);
        }
        request
    }
}

/// Settings by purpose. The default follows the authors' runs: low reasoning effort for
/// induction, refinement and state translation, medium for code generation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PurposeSettings {
    /// Operator induction (`induce`).
    pub induce: CallSettings,
    /// Refinement proposals (`patch`).
    pub patch: CallSettings,
    /// State translation (`translate`).
    pub translate: CallSettings,
    /// Code generation (`codegen`).
    pub codegen: CallSettings,
}

impl Default for PurposeSettings {
    fn default() -> Self {
        PurposeSettings {
            induce: CallSettings::effort(ReasoningEffort::Low),
            patch: CallSettings::effort(ReasoningEffort::Low),
            translate: CallSettings::effort(ReasoningEffort::Low),
            codegen: CallSettings::effort(ReasoningEffort::Medium),
        }
    }
}
