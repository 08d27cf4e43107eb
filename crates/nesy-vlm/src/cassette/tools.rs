//! Library side of `nesy cassette inspect | prune | verify | resend`.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fs;
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde_json::Value;
use sha2::{Digest, Sha256};

use super::canonical::{BLOB_SCHEME, hex, request_key};
use super::format::{CassetteFile, blobs_dir, write_atomically};
use super::{CassetteError, InteractionRef, UsageReport};
use crate::error::truncate_chars;
use crate::transport::WireRequest;

/// One interaction as `inspect` lists it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InteractionSummary {
    /// Position in the file.
    pub index: usize,
    /// First 12 hex digits of the key.
    pub key: String,
    /// Accounting label.
    pub purpose: Option<String>,
    /// When it was recorded.
    pub recorded_at: String,
    /// The request path.
    pub path: String,
    /// The requested model.
    pub model: Option<String>,
    /// Messages in the request.
    pub messages: usize,
    /// Images in the request.
    pub images: usize,
    /// Response status; 0 when the attempt got no response.
    pub status: u16,
    /// Why the attempt got no response (`timeout`, `connect`, `body`), if it got none.
    pub failure: Option<String>,
    /// `choices[0].finish_reason`, if the body has one.
    pub finish_reason: Option<String>,
    /// Usage from the response body.
    pub prompt_tokens: u64,
    /// Output tokens.
    pub completion_tokens: u64,
    /// Reasoning tokens.
    pub reasoning_tokens: u64,
    /// Recorded latency.
    pub latency_ms: f64,
}

/// What `inspect` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inspection {
    /// The cassette.
    pub cassette: PathBuf,
    /// Format version.
    pub schema_version: u32,
    /// Metadata.
    pub meta: super::CassetteMeta,
    /// Calls per model.
    pub models: BTreeMap<String, usize>,
    /// Totals of the token columns.
    pub prompt_tokens: u64,
    /// Output tokens in total.
    pub completion_tokens: u64,
    /// Reasoning tokens in total.
    pub reasoning_tokens: u64,
    /// Distinct blobs referenced.
    pub distinct_images: usize,
    /// Every interaction.
    pub interactions: Vec<InteractionSummary>,
}

/// Lists a cassette's calls, tokens and models.
pub fn inspect(path: &Path) -> Result<Inspection, CassetteError> {
    let file = CassetteFile::load(path)?;
    let mut models = BTreeMap::new();
    let mut blobs = BTreeSet::new();
    let mut interactions = Vec::new();
    for (index, interaction) in file.interactions.iter().enumerate() {
        let body = &interaction.request.body;
        let model = body.get("model").and_then(Value::as_str).map(str::to_string);
        *models
            .entry(model.clone().unwrap_or_else(|| "(in path)".into()))
            .or_insert(0) += 1;
        let mut refs = Vec::new();
        collect_refs(body, &mut refs);
        blobs.extend(refs.iter().cloned());
        let response: Option<Value> = interaction
            .response
            .as_ref()
            .and_then(|response| response.body.as_ref())
            .and_then(|raw| serde_json::from_str(raw.get()).ok());
        let usage = |pointer: &str| {
            response
                .as_ref()
                .and_then(|r| r.pointer(pointer))
                .and_then(Value::as_u64)
                .unwrap_or(0)
        };
        interactions.push(InteractionSummary {
            index,
            key: interaction.key.chars().take(12).collect(),
            purpose: interaction.purpose.clone(),
            recorded_at: interaction.recorded_at.clone(),
            path: interaction.request.path.clone(),
            model,
            messages: body.get("messages").and_then(Value::as_array).map_or(0, Vec::len),
            images: refs.len(),
            status: interaction
                .response
                .as_ref()
                .map_or(0, |response| response.status),
            failure: interaction
                .failure
                .as_ref()
                .map(|failure| failure.kind().to_string()),
            finish_reason: response
                .as_ref()
                .and_then(|r| r.pointer("/choices/0/finish_reason"))
                .and_then(Value::as_str)
                .map(str::to_string),
            prompt_tokens: usage("/usage/prompt_tokens"),
            completion_tokens: usage("/usage/completion_tokens"),
            reasoning_tokens: usage("/usage/completion_tokens_details/reasoning_tokens"),
            latency_ms: interaction.latency_ms,
        });
    }
    Ok(Inspection {
        cassette: path.to_path_buf(),
        schema_version: file.schema_version,
        meta: file.meta,
        models,
        prompt_tokens: interactions.iter().map(|i| i.prompt_tokens).sum(),
        completion_tokens: interactions.iter().map(|i| i.completion_tokens).sum(),
        reasoning_tokens: interactions.iter().map(|i| i.reasoning_tokens).sum(),
        distinct_images: blobs.len(),
        interactions,
    })
}

/// Blob file names (`<hex>.<ext>`) referenced by a body.
fn collect_refs(value: &Value, out: &mut Vec<String>) {
    match value {
        Value::String(text) => {
            if let Some(name) = text.strip_prefix(BLOB_SCHEME) {
                out.push(name.to_string());
            }
        }
        Value::Array(items) => items.iter().for_each(|item| collect_refs(item, out)),
        Value::Object(map) => map.values().for_each(|item| collect_refs(item, out)),
        _ => {}
    }
}

/// A problem `verify` found.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Problem {
    /// The interaction, if the problem is in one.
    pub interaction: Option<usize>,
    /// What is wrong.
    pub message: String,
}

/// Checks a cassette: every referenced blob exists and hashes to its name, every stored key
/// matches its request, every response body decodes. An unreadable file is an `Err`.
pub fn verify(path: &Path) -> Result<Vec<Problem>, CassetteError> {
    let file = CassetteFile::load(path)?;
    let blobs = blobs_dir(path);
    let mut problems = Vec::new();
    let mut checked: HashMap<String, bool> = HashMap::new();
    for (index, interaction) in file.interactions.iter().enumerate() {
        let at = Some(index);
        let key = request_key(&interaction.request.path, &interaction.request.body);
        if key != interaction.key {
            problems.push(Problem {
                interaction: at,
                message: format!(
                    "stored key {} does not match the request (recomputed {key}); was it edited?",
                    interaction.key
                ),
            });
        }
        // A recorded failure has no response to decode; `CassetteFile::parse` checked its shape.
        if let Some(response) = &interaction.response {
            match response.to_wire(crate::transport::Origin::Replayed) {
                Err(message) => problems.push(Problem {
                    interaction: at,
                    message: format!("response: {message}"),
                }),
                // A replayed success must be a completion; an empty one fails every replay.
                Ok(wire) if wire.is_success() && wire.body.is_empty() => problems.push(Problem {
                    interaction: at,
                    message: format!("response: status {} with no body", wire.status),
                }),
                Ok(_) => {}
            }
            for name in response.headers.keys() {
                if !crate::transport::is_allowed_header(name) {
                    problems.push(Problem {
                        interaction: at,
                        message: format!(
                            "response header `{name}` is not on the allowlist (a recorder never stores it; it may hold a credential)"
                        ),
                    });
                }
            }
        }
        let mut refs = Vec::new();
        collect_refs(&interaction.request.body, &mut refs);
        for name in refs {
            if let Some(ok) = checked.get(&name) {
                if !ok {
                    problems.push(Problem {
                        interaction: at,
                        message: format!("blob {name} is missing or corrupt"),
                    });
                }
                continue;
            }
            let result = if is_blob_name(&name) {
                check_blob(&blobs.join(&name), name.split('.').next().unwrap_or_default())
            } else {
                // Never a path: `../`, `/dev/zero` or a pipe must not be opened.
                Err(format!(
                    "blob reference {:?} is not a content address (expected {BLOB_SCHEME}<64 hex digits>.<extension>)",
                    truncate_chars(&name, 80)
                ))
            };
            checked.insert(name, result.is_ok());
            if let Err(message) = result {
                problems.push(Problem {
                    interaction: at,
                    message,
                });
            }
        }
    }
    Ok(problems)
}

/// Whether a blob reference is a bare content address, `<64 lowercase hex>.<1–8 [a-z0-9]>`.
fn is_blob_name(name: &str) -> bool {
    let Some((digest, ext)) = name.split_once('.') else {
        return false;
    };
    digest.len() == 64
        && digest.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
        && (1..=8).contains(&ext.len())
        && ext.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit())
}

/// Reads one blob through [`nesy_input::read_bytes`] (a regular file of at most
/// [`nesy_input::MAX_IMAGE_BYTES`]: blobs are the requests' images) and checks it hashes to
/// `expected`.
fn check_blob(blob: &Path, expected: &str) -> Result<(), String> {
    let shown = blob.display();
    let bytes =
        nesy_input::read_bytes(blob, nesy_input::MAX_IMAGE_BYTES).map_err(|err| match err.kind() {
            std::io::ErrorKind::NotFound => format!("blob {shown} is missing: {err}"),
            _ => format!("blob {shown} cannot be read: {err}"),
        })?;
    if hex(&Sha256::digest(&bytes)) != expected {
        return Err(format!("blob {shown} does not hash to its name"));
    }
    Ok(())
}

/// What `prune` did (or would do, in a dry run).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PruneOutcome {
    /// Interactions kept.
    pub kept: usize,
    /// Indices (in the old file) of interactions dropped.
    pub dropped: Vec<usize>,
    /// Blob files removed (or that would be) because no cassette in the directory refers
    /// to them any more.
    pub removed_blobs: Vec<PathBuf>,
}

/// Drops interactions that the usage report does not list as used, then (with
/// `remove_orphan_blobs`) deletes blobs no cassette beside it references.
pub fn prune(
    path: &Path,
    usage: &UsageReport,
    remove_orphan_blobs: bool,
    dry_run: bool,
) -> Result<PruneOutcome, CassetteError> {
    let mut file = CassetteFile::load(path)?;
    let used: BTreeSet<&InteractionRef> = usage.used.iter().collect();
    // Occurrences count in send order, as the replay that wrote the usage report did.
    let references = file.references(&file.send_sequence());
    let mut dropped = Vec::new();
    let mut kept = Vec::new();
    for ((index, interaction), reference) in std::mem::take(&mut file.interactions)
        .into_iter()
        .enumerate()
        .zip(references)
    {
        if used.contains(&reference) {
            kept.push(interaction)
        } else {
            dropped.push(index)
        }
    }
    file.interactions = kept;
    if !dry_run && !dropped.is_empty() {
        file.meta.updated_at = crate::timefmt::now_rfc3339();
        write_atomically(path, file.to_pretty_json(&[]).as_bytes())?;
    }
    let mut removed_blobs = Vec::new();
    if remove_orphan_blobs {
        removed_blobs = orphan_blobs(path, if dry_run { Some(&file) } else { None })?;
        if !dry_run {
            for blob in &removed_blobs {
                fs::remove_file(blob).map_err(|source| CassetteError::Io {
                    path: blob.clone(),
                    error: source,
                })?;
            }
        }
    }
    Ok(PruneOutcome {
        kept: file.interactions.len(),
        dropped,
        removed_blobs,
    })
}

/// Blobs under `blobs/` beside `cassette` that no `*.json` cassette in that directory
/// references. `pending` stands in for the cassette's own content (for a dry run).
fn orphan_blobs(cassette: &Path, pending: Option<&CassetteFile>) -> Result<Vec<PathBuf>, CassetteError> {
    let dir = super::format::parent_dir(cassette);
    let blobs = blobs_dir(cassette);
    if !blobs.is_dir() {
        return Ok(Vec::new());
    }
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| CassetteError::Io { path, error: source }
    };
    let mut referenced = BTreeSet::new();
    for entry in fs::read_dir(&dir).map_err(io(&dir))? {
        let other = entry.map_err(io(&dir))?.path();
        if other.extension().is_none_or(|ext| ext != "json") {
            continue;
        }
        let file = match pending {
            Some(pending) if other == cassette => pending.clone(),
            _ => match CassetteFile::load(&other) {
                Ok(file) => file,
                // Not a cassette (e.g. a usage report): it references nothing.
                Err(CassetteError::Schema { .. }) | Err(CassetteError::Parse { .. }) => continue,
                Err(err) => return Err(err),
            },
        };
        let mut refs = Vec::new();
        for interaction in &file.interactions {
            collect_refs(&interaction.request.body, &mut refs);
        }
        referenced.extend(refs);
    }
    let mut orphans = Vec::new();
    for entry in fs::read_dir(&blobs).map_err(io(&blobs))? {
        let blob = entry.map_err(io(&blobs))?.path();
        let name = blob
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
            .to_string();
        if blob.is_file() && !referenced.contains(&name) {
            orphans.push(blob);
        }
    }
    orphans.sort();
    Ok(orphans)
}

/// Reads a usage report written by a cassette run.
pub fn load_usage_report(path: &Path) -> Result<UsageReport, CassetteError> {
    let text =
        nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES).map_err(|source| CassetteError::Io {
            path: path.to_path_buf(),
            error: source,
        })?;
    serde_json::from_str(&text).map_err(|err| CassetteError::Parse {
        path: path.to_path_buf(),
        line: err.line(),
        column: err.column(),
        message: err.to_string(),
    })
}

/// How many user turns a chat request body holds: 1 for a conversation's first request
/// (the model's first try), more for a re-ask.
///
/// ```
/// let ask = serde_json::json!({"messages": [{"role": "system"}, {"role": "user"}]});
/// assert_eq!(nesy_vlm::cassette_tools::user_turns(&ask), 1);
/// ```
pub fn user_turns(body: &Value) -> usize {
    body["messages"]
        .as_array()
        .map_or(0, |m| m.iter().filter(|m| m["role"] == "user").count())
}

/// Which recorded requests [`resend_selection`] picks to send again.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResendPlan {
    /// The purposes to pick (e.g. `induce`, `patch`); empty picks every purpose.
    pub purposes: Vec<String>,
    /// Only the first request of each conversation (one user turn): the model's first try.
    pub first_tries_only: bool,
    /// At most this many requests of each purpose, the first found in path order.
    pub per_purpose: Option<usize>,
    /// Remove the reply constraint from each body ([`crate::CONSTRAINT_FIELDS`]), so that
    /// the same prompt is answered freely.
    pub strip_constraints: bool,
}

/// What [`resend_selection`] picked.
#[derive(Debug, Clone)]
pub struct ResendSelection {
    /// The requests to send, each distinct.
    pub requests: Vec<WireRequest>,
    /// Picked requests left out because an earlier pick was the same request (same path and
    /// body as it would be sent): two runs that reached the same prompt ask it once.
    pub duplicates: usize,
}

/// The requests of `cassettes` (in the order given, each in recording order) that `plan`
/// picks, ready to send: their recorded path, purpose and body, without the constraint when
/// asked. A body holding an image reference is refused (its picture lives in the source's
/// `blobs/`; resending covers text requests).
///
/// Each distinct request is picked once, so that a share of replies read counts prompts,
/// not how often runs happened to reach the same prompt; the limit per purpose counts
/// distinct requests.
///
/// Sending each again, through a recording cassette, answers "what would the model have
/// said to the same prompt without its grammar": a paired comparison on identical prompts.
pub fn resend_selection(cassettes: &[PathBuf], plan: &ResendPlan) -> Result<ResendSelection, CassetteError> {
    let mut picked: Vec<WireRequest> = Vec::new();
    let mut seen: HashSet<String> = HashSet::new();
    let mut duplicates = 0;
    let mut counts: HashMap<String, usize> = HashMap::new();
    for path in cassettes {
        let file = CassetteFile::load(path)?;
        for (index, interaction) in file.interactions.iter().enumerate() {
            let purpose = interaction.purpose.clone().unwrap_or_default();
            if !plan.purposes.is_empty() && !plan.purposes.contains(&purpose) {
                continue;
            }
            let body = &interaction.request.body;
            if plan.first_tries_only && user_turns(body) > 1 {
                continue;
            }
            let count = counts.entry(purpose.clone()).or_default();
            if plan.per_purpose.is_some_and(|limit| *count >= limit) {
                continue;
            }
            if body.to_string().contains(BLOB_SCHEME) {
                return Err(CassetteError::Schema {
                    path: path.clone(),
                    message: format!(
                        "interaction #{index} carries an image; resend covers requests of text only"
                    ),
                });
            }
            let mut body = body.clone();
            if plan.strip_constraints
                && let Some(fields) = body.as_object_mut()
            {
                for field in crate::CONSTRAINT_FIELDS {
                    fields.remove(field);
                }
            }
            if !seen.insert(request_key(&interaction.request.path, &body)) {
                duplicates += 1;
                continue;
            }
            *count += 1;
            picked.push(WireRequest {
                path: interaction.request.path.clone(),
                body,
                task: None,
                purpose: interaction.purpose.clone(),
            });
        }
    }
    Ok(ResendSelection {
        requests: picked,
        duplicates,
    })
}
