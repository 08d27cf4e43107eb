//! How a unit ended: a leaf type that the methods, the harness, the JSONL rows and the
//! reports all name.

use serde::{Deserialize, Serialize};

/// How a unit ended. Every unit ends in exactly one status; none is dropped from a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitStatus {
    /// Specified, compiled and executed, every subtask successful (strict scoring).
    Succeeded,
    /// The method's adaptation ran out of budget without a verified specification.
    Unresolved,
    /// A specification, but no program could be obtained from it.
    CodegenFailed,
    /// A program ran (or could not run) and did not succeed.
    ExecutionFailed,
    /// The method could not produce a specification: a reply it cannot read, a parse or
    /// planner failure that ends it, a call cap reached.
    MethodError,
    /// The scenario's demonstration is unusable (the expert failed, or its final state lacks
    /// part of the goal); no method runs on it.
    DemoUnusable,
    /// The endpoint refused a request as built (too many images, too long): retrying the
    /// same request cannot help, and it says nothing about the method.
    RequestRefused,
    /// A model call did not complete (network, rate limit, server error, a missing
    /// recording): retried on resume.
    TransportError,
    /// The run was stopped while the unit was in flight: retried on resume.
    Interrupted,
}

impl UnitStatus {
    /// Every status, in report order.
    pub const ALL: [UnitStatus; 9] = [
        UnitStatus::Succeeded,
        UnitStatus::Unresolved,
        UnitStatus::CodegenFailed,
        UnitStatus::ExecutionFailed,
        UnitStatus::MethodError,
        UnitStatus::DemoUnusable,
        UnitStatus::RequestRefused,
        UnitStatus::TransportError,
        UnitStatus::Interrupted,
    ];

    /// `succeeded`, `unresolved`, …
    pub fn as_str(self) -> &'static str {
        match self {
            UnitStatus::Succeeded => "succeeded",
            UnitStatus::Unresolved => "unresolved",
            UnitStatus::CodegenFailed => "codegen_failed",
            UnitStatus::ExecutionFailed => "execution_failed",
            UnitStatus::MethodError => "method_error",
            UnitStatus::DemoUnusable => "demo_unusable",
            UnitStatus::RequestRefused => "request_refused",
            UnitStatus::TransportError => "transport_error",
            UnitStatus::Interrupted => "interrupted",
        }
    }

    /// Final statuses are kept on resume; the others (transport errors, interrupted units)
    /// are run again.
    pub fn is_final(self) -> bool {
        !matches!(self, UnitStatus::TransportError | UnitStatus::Interrupted)
    }

    /// True when the unit is scored as an episode of the method: everything but unusable
    /// demos (excluded from every method alike) and units that are retried.
    pub fn is_scored(self) -> bool {
        self.is_final() && self != UnitStatus::DemoUnusable
    }
}

impl std::fmt::Display for UnitStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}
