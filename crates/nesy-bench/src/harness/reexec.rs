//! Re-execution: phase B again on the code an earlier run wrote, with no model call.

use std::path::Path;

use nesy_pipeline::output;

use super::shared::{PhaseA, PhaseAFailure, final_records};
use crate::status::UnitStatus;
use crate::unit::Unit;
use crate::variant::hex;

/// Phase A of an earlier run: its stored program, or its failure carried over.
pub(super) fn reexecuted(source: &Path, unit: &Unit) -> Result<(String, PhaseA), PhaseAFailure> {
    let records =
        final_records(source).map_err(|e| PhaseAFailure::new(UnitStatus::MethodError, e.to_string()))?;
    let old = records.get(&unit.key.name()).ok_or_else(|| {
        PhaseAFailure::new(
            UnitStatus::MethodError,
            format!(
                "{}: has no final record of this unit to re-execute",
                source.display()
            ),
        )
    })?;
    let policy = source.join(&old.artifacts).join(output::POLICY_FILE);
    match std::fs::read_to_string(&policy) {
        Ok(code)
            if !matches!(
                old.status,
                UnitStatus::Unresolved
                    | UnitStatus::CodegenFailed
                    | UnitStatus::MethodError
                    | UnitStatus::DemoUnusable
                    | UnitStatus::RequestRefused
            ) =>
        {
            Ok((
                code,
                PhaseA {
                    spec: old.spec.clone(),
                    states: old.states,
                    vlm_s: old.effort.time.vlm_s,
                    symbolic_s: (old.effort.time.symbolic_s, old.effort.time.symbolic_world_model_s),
                    template_s: old.effort.time.codegen_template_s,
                },
            ))
        }
        _ => Err(PhaseAFailure {
            status: old.status,
            message: old
                .error
                .clone()
                .unwrap_or_else(|| "no program in the re-executed run".into()),
            spec: old.spec.clone().map(Box::new),
            symbolic_s: Some((old.effort.time.symbolic_s, old.effort.time.symbolic_world_model_s)),
        }),
    }
}

/// A digest of a file's bytes, for artifacts named in reports.
pub fn file_digest(path: &Path) -> Option<String> {
    use sha2::Digest as _;
    std::fs::read(path).ok().map(|b| hex(&sha2::Sha256::digest(&b)))
}
