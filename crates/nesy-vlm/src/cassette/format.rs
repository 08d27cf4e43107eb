//! The cassette file: pretty JSON with a schema version and metadata; requests stored with
//! images as content references; responses stored whole (a JSON body is embedded verbatim,
//! so replay is byte-identical); only allowlisted headers.

use std::collections::{BTreeMap, HashMap};
use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use base64::Engine as _;
use bytes::Bytes;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use super::canonical::request_key;
use super::{CassetteError, InteractionRef};
use crate::constraint::ConstrainMode;
use crate::error::{TimeoutPhase, TransportError};
use crate::secret::SecretString;
use crate::transport::{Origin, WireResponse, is_allowed_header};

/// The cassette format version this crate reads and writes.
pub const SCHEMA_VERSION: u32 = 1;

/// A whole cassette file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CassetteFile {
    /// Format version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// Who recorded it, when, against what.
    pub meta: CassetteMeta,
    /// Recorded calls, in the order they completed (see [`Interaction::send_order`] for the
    /// order they were sent in).
    pub interactions: Vec<Interaction>,
}

/// Cassette metadata.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CassetteMeta {
    /// The recorder, e.g. `nesy-vlm 0.1.0`.
    pub recorder: String,
    /// When the file was first written (RFC 3339, UTC).
    pub created_at: String,
    /// When it was last written.
    pub updated_at: String,
    /// The model of the latest recorded request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// The backend label of the recording transport (e.g. `http openai`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<String>,
    /// What the recorded server announced it can take; a replay sizes its requests by it,
    /// as the recording did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub server: Option<crate::capabilities::ServerCapabilities>,
    /// Whether the recorded requests carried their reply constraints; a replay sends them
    /// the same way, so that its bodies match. Absent means `auto`.
    #[serde(default, skip_serializing_if = "ConstrainMode::is_auto")]
    pub constrain: ConstrainMode,
}

/// One recorded call.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Interaction {
    /// The request key (recomputed on load; a mismatch is reported by `verify`).
    pub key: String,
    /// The call's accounting label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub purpose: Option<String>,
    /// When it was recorded.
    pub recorded_at: String,
    /// How long the live call took.
    pub latency_ms: f64,
    /// Where this call stands in the order the cassette's calls were sent, counted across
    /// every recording that appended to the file. Calls sent concurrently complete, and so
    /// are appended, in whatever order the server finishes them; identical requests replay
    /// by this order so that each caller gets the reply its own call got. Absent in files
    /// recorded before it was kept: such an interaction counts as sent at its position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub send_order: Option<u64>,
    /// The request.
    pub request: StoredRequest,
    /// The response; absent when the attempt got none, and then [`Interaction::failure`]
    /// says why. A file holds exactly one of the two per interaction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub response: Option<StoredResponse>,
    /// Why a sent attempt got no response.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<StoredFailure>,
}

impl Interaction {
    fn sent_at_or(&self, position: usize) -> u64 {
        self.send_order.unwrap_or(position as u64)
    }

    /// What the attempt got: its response, or the failure that took its place. The outer
    /// `Err` says what is wrong when the interaction holds neither or both, which
    /// [`CassetteFile::parse`] refuses in a file.
    pub fn outcome(&self) -> Result<Result<&StoredResponse, &StoredFailure>, &'static str> {
        match (&self.response, &self.failure) {
            (Some(response), None) => Ok(Ok(response)),
            (None, Some(failure)) => Ok(Err(failure)),
            (None, None) => Err("has neither `response` nor `failure`"),
            (Some(_), Some(_)) => Err("has both `response` and `failure`; expected one of them"),
        }
    }
}

/// An attempt that was sent and got no HTTP response: a timeout, a refused or reset
/// connection, a body cut short. Recorded so that a replay fails the same attempt the same
/// way and the retry layer above the cassette retries (or gives up) as it did live; without
/// it a replay would count fewer attempts than the run it reproduces. Failures that never
/// reached the network (a call cap, a shutdown) are not recorded.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StoredFailure {
    /// A timeout fired.
    Timeout {
        /// Which timeout.
        phase: TimeoutPhase,
        /// The transport's message.
        message: String,
    },
    /// The connection could not be established or was lost before a response.
    Connect {
        /// The transport's message.
        message: String,
    },
    /// The response body could not be read to the end.
    Body {
        /// The transport's message.
        message: String,
    },
}

impl StoredFailure {
    /// Its kind as the file names it: `timeout`, `connect` or `body`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Timeout { .. } => "timeout",
            Self::Connect { .. } => "connect",
            Self::Body { .. } => "body",
        }
    }

    /// The failure as a cassette stores it, for the transport errors that mean a sent
    /// attempt got no response; `None` for the others.
    pub fn from_transport(error: &TransportError) -> Option<Self> {
        match error {
            TransportError::Timeout { phase, message } => Some(Self::Timeout {
                phase: *phase,
                message: message.clone(),
            }),
            TransportError::Connect(message) => Some(Self::Connect {
                message: message.clone(),
            }),
            TransportError::Body(message) => Some(Self::Body {
                message: message.clone(),
            }),
            TransportError::Cassette(_) | TransportError::Declined(_) | TransportError::Failed { .. } => None,
        }
    }

    /// The transport error a replay returns for it.
    pub fn to_transport(&self) -> TransportError {
        match self.clone() {
            Self::Timeout { phase, message } => TransportError::Timeout { phase, message },
            Self::Connect { message } => TransportError::Connect(message),
            Self::Body { message } => TransportError::Body(message),
        }
    }
}

/// A recorded request: images replaced by `blob:sha256:<hex>.<ext>` references.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoredRequest {
    /// Always `POST`.
    pub method: String,
    /// Path and query relative to the base URL.
    pub path: String,
    /// The canonical body.
    pub body: serde_json::Value,
}

/// A recorded response. Exactly one of the body fields is present: `body` (JSON, embedded
/// verbatim), `body_text` (other UTF-8) or `body_base64` (anything else).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoredResponse {
    /// HTTP status.
    pub status: u16,
    /// Allowlisted headers.
    #[serde(default)]
    pub headers: BTreeMap<String, String>,
    /// A JSON body, byte for byte.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Box<RawValue>>,
    /// A non-JSON UTF-8 body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_text: Option<String>,
    /// A binary body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_base64: Option<String>,
}

impl StoredResponse {
    /// Stores a wire response: headers filtered again (defence in depth), body kept whole.
    pub fn from_wire(response: &WireResponse) -> Self {
        let headers = response
            .headers
            .iter()
            .filter(|(name, _)| is_allowed_header(name))
            .map(|(name, value)| (name.to_ascii_lowercase(), value.clone()))
            .collect();
        let mut stored = Self {
            status: response.status,
            headers,
            body: None,
            body_text: None,
            body_base64: None,
        };
        match std::str::from_utf8(&response.body) {
            Ok(text) => match RawValue::from_string(text.to_string()) {
                // Only when the raw value is the whole text (no surrounding whitespace), and
                // not `null`, which would read back as an absent body.
                Ok(raw) if raw.get().len() == text.len() && text != "null" => stored.body = Some(raw),
                _ => stored.body_text = Some(text.to_string()),
            },
            Err(_) => {
                stored.body_base64 = Some(base64::engine::general_purpose::STANDARD.encode(&response.body))
            }
        }
        stored
    }

    /// The response as a transport returns it.
    pub fn to_wire(&self, origin: Origin) -> Result<WireResponse, String> {
        let body = match (&self.body, &self.body_text, &self.body_base64) {
            (Some(raw), None, None) => Bytes::copy_from_slice(raw.get().as_bytes()),
            (None, Some(text), None) => Bytes::copy_from_slice(text.as_bytes()),
            (None, None, Some(b64)) => Bytes::from(
                base64::engine::general_purpose::STANDARD
                    .decode(b64)
                    .map_err(|err| format!("body_base64: {err}"))?,
            ),
            (None, None, None) => Bytes::new(),
            _ => return Err("more than one of body, body_text, body_base64".to_string()),
        };
        let headers = self
            .headers
            .iter()
            .map(|(name, value)| (name.clone(), value.clone()))
            .collect();
        Ok(WireResponse {
            status: self.status,
            headers,
            body,
            origin,
        })
    }
}

impl CassetteFile {
    /// An empty cassette.
    pub fn new(model: Option<String>, backend: Option<String>) -> Self {
        let now = crate::timefmt::now_rfc3339();
        Self {
            schema_version: SCHEMA_VERSION,
            meta: CassetteMeta {
                recorder: recorder(),
                created_at: now.clone(),
                updated_at: now,
                model,
                backend,
                server: None,
                constrain: ConstrainMode::Auto,
            },
            interactions: Vec::new(),
        }
    }

    /// Reads a cassette; errors name the file, line and column.
    pub fn load(path: &Path) -> Result<Self, CassetteError> {
        let text = nesy_input::read_text(path, nesy_input::MAX_CASSETTE_BYTES).map_err(|source| {
            CassetteError::Io {
                path: path.to_path_buf(),
                error: source,
            }
        })?;
        Self::parse(path, &text)
    }

    /// Parses cassette text (`path` is for messages).
    pub fn parse(path: &Path, text: &str) -> Result<Self, CassetteError> {
        #[derive(Deserialize)]
        struct VersionOnly {
            schema_version: Option<u32>,
        }
        let parse_error = |err: serde_json::Error| CassetteError::Parse {
            path: path.to_path_buf(),
            line: err.line(),
            column: err.column(),
            message: err.to_string(),
        };
        // Check the version first, so a newer file gets a clear message rather than an
        // unknown-field error.
        let version = serde_json::from_str::<VersionOnly>(text)
            .map_err(parse_error)?
            .schema_version;
        match version {
            Some(SCHEMA_VERSION) => {}
            Some(other) => {
                return Err(CassetteError::Schema {
                    path: path.to_path_buf(),
                    message: format!(
                        "schema_version {other} is not supported (this nesy reads version {SCHEMA_VERSION})"
                    ),
                });
            }
            None => {
                return Err(CassetteError::Schema {
                    path: path.to_path_buf(),
                    message: "missing `schema_version`: not a nesy cassette".to_string(),
                });
            }
        }
        let file: Self = serde_json::from_str(text).map_err(parse_error)?;
        for (index, interaction) in file.interactions.iter().enumerate() {
            if let Err(problem) = interaction.outcome() {
                return Err(CassetteError::Schema {
                    path: path.to_path_buf(),
                    message: format!("interaction #{index} {problem}"),
                });
            }
        }
        Ok(file)
    }

    /// The interactions' indices in the order their calls were sent: by
    /// [`Interaction::send_order`], an interaction without one counting as sent at its
    /// position, and ties kept in file order. Replay serves identical requests in this order.
    pub fn send_sequence(&self) -> Vec<usize> {
        let mut indices: Vec<usize> = (0..self.interactions.len()).collect();
        indices.sort_by_key(|&index| (self.interactions[index].sent_at_or(index), index));
        indices
    }

    /// Each interaction's reference, in file order: its request key, and which recording of
    /// that key it is, counted in `sequence` (the [`Self::send_sequence`]), the order a
    /// replay serves identical requests in.
    pub(crate) fn references(&self, sequence: &[usize]) -> Vec<InteractionRef> {
        let keys: Vec<String> = self
            .interactions
            .iter()
            .map(|interaction| request_key(&interaction.request.path, &interaction.request.body))
            .collect();
        let mut occurrences = vec![0; keys.len()];
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for &index in sequence {
            let count = seen.entry(keys[index].as_str()).or_default();
            occurrences[index] = *count;
            *count += 1;
        }
        keys.into_iter()
            .zip(occurrences)
            .map(|(key, occurrence)| InteractionRef { key, occurrence })
            .collect()
    }

    /// The send-order number the next call recorded into this file gets: one past the
    /// largest already used, so that a resumed recording sorts after everything before it.
    pub fn next_send_order(&self) -> u64 {
        self.interactions
            .iter()
            .enumerate()
            .map(|(index, interaction)| interaction.sent_at_or(index) + 1)
            .max()
            .unwrap_or(0)
    }

    /// Pretty JSON, with every occurrence of a secret replaced.
    pub fn to_pretty_json(&self, redactions: &[SecretString]) -> String {
        // Serialising plain data to a String cannot fail.
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        for secret in redactions {
            text = secret.redact_in(&text);
        }
        text.push('\n');
        text
    }

    /// Writes the file atomically: a temporary file beside it, flushed, then renamed over.
    pub fn save(&self, path: &Path, redactions: &[SecretString]) -> Result<(), CassetteError> {
        write_atomically(path, self.to_pretty_json(redactions).as_bytes())
    }
}

/// `nesy-vlm <version>`.
pub(crate) fn recorder() -> String {
    concat!("nesy-vlm ", env!("CARGO_PKG_VERSION")).to_string()
}

/// Writes bytes to `path` through a temporary file in the same directory and a rename, so a
/// crash leaves either the old or the new file, never a torn one.
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), CassetteError> {
    let io = |source| CassetteError::Io {
        path: path.to_path_buf(),
        error: source,
    };
    let dir = parent_dir(path);
    fs::create_dir_all(&dir).map_err(io)?;
    let mut temp = tempfile::NamedTempFile::new_in(&dir).map_err(io)?;
    temp.write_all(bytes).map_err(io)?;
    temp.as_file().sync_all().map_err(io)?;
    // Temporary files are private (0600); a cassette is ordinary project data.
    let permissions = match fs::metadata(path) {
        Ok(existing) => existing.permissions(),
        Err(_) => readable_permissions(temp.as_file()).map_err(io)?,
    };
    fs::set_permissions(temp.path(), permissions).map_err(io)?;
    temp.persist(path).map_err(|err| io(err.error))?;
    Ok(())
}

#[cfg(unix)]
fn readable_permissions(_file: &fs::File) -> std::io::Result<fs::Permissions> {
    use std::os::unix::fs::PermissionsExt as _;
    Ok(fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn readable_permissions(file: &fs::File) -> std::io::Result<fs::Permissions> {
    Ok(file.metadata()?.permissions())
}

/// Writes a blob unless one with that name exists (content-addressed, so it is the same).
pub(crate) fn write_blob(dir: &Path, name: &str, bytes: &[u8]) -> Result<bool, CassetteError> {
    let path = dir.join(name);
    if path.exists() {
        return Ok(false);
    }
    let io = |source| CassetteError::Io {
        path: path.clone(),
        error: source,
    };
    fs::create_dir_all(dir).map_err(io)?;
    let mut temp = tempfile::NamedTempFile::new_in(dir).map_err(io)?;
    temp.write_all(bytes).map_err(io)?;
    temp.as_file().sync_all().map_err(io)?;
    fs::set_permissions(temp.path(), readable_permissions(temp.as_file()).map_err(io)?).map_err(io)?;
    match temp.persist_noclobber(&path) {
        Ok(_) => Ok(true),
        // Another recorder wrote the same content first.
        Err(_) if path.exists() => Ok(false),
        Err(err) => Err(io(err.error)),
    }
}

/// The directory holding a path (`.` for a bare file name).
pub(crate) fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The `blobs/` directory beside a cassette.
pub fn blobs_dir(cassette: &Path) -> PathBuf {
    parent_dir(cassette).join("blobs")
}

/// An exclusive lock on a cassette across processes: `<cassette>.lock`, created with
/// `O_EXCL`. A lock older than a minute is taken to be left by a crashed recorder.
pub(crate) struct FileLock {
    path: PathBuf,
}

impl FileLock {
    pub(crate) fn acquire(cassette: &Path) -> Result<Self, CassetteError> {
        let mut name = cassette.as_os_str().to_owned();
        name.push(".lock");
        let path = PathBuf::from(name);
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        loop {
            match fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut file) => {
                    let _ = writeln!(file, "{}", std::process::id());
                    return Ok(Self { path });
                }
                Err(err) if err.kind() == std::io::ErrorKind::AlreadyExists => {
                    let stale = fs::metadata(&path)
                        .and_then(|m| m.modified())
                        .map(|modified| SystemTime::now().duration_since(modified).unwrap_or_default())
                        .is_ok_and(|age| age > Duration::from_secs(60));
                    if stale {
                        let _ = fs::remove_file(&path);
                        continue;
                    }
                    if std::time::Instant::now() > deadline {
                        return Err(CassetteError::Locked { path });
                    }
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(source) => return Err(CassetteError::Io { path, error: source }),
            }
        }
    }
}

impl Drop for FileLock {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bodies_round_trip_byte_for_byte() {
        for body in [
            &b"{\"id\":\"x\",  \"choices\":[ ]}"[..],
            b"{\"a\":1}\n",
            b"not json",
            b"null",
            b"",
            b"\xff\xfe binary",
        ] {
            let wire = WireResponse::new(200, body.to_vec(), Origin::Live);
            let stored = StoredResponse::from_wire(&wire);
            let file = CassetteFile {
                schema_version: SCHEMA_VERSION,
                meta: CassetteMeta::default(),
                interactions: vec![Interaction {
                    key: "k".into(),
                    purpose: None,
                    recorded_at: "t".into(),
                    latency_ms: 1.0,
                    send_order: None,
                    request: StoredRequest {
                        method: "POST".into(),
                        path: "/p".into(),
                        body: serde_json::Value::Null,
                    },
                    response: Some(stored),
                    failure: None,
                }],
            };
            let text = file.to_pretty_json(&[]);
            let back = CassetteFile::parse(Path::new("c.json"), &text).unwrap();
            let replayed = back.interactions[0]
                .outcome()
                .unwrap()
                .unwrap()
                .to_wire(Origin::Replayed)
                .unwrap();
            assert_eq!(&replayed.body[..], body, "{text}");
        }
    }

    #[test]
    fn parse_errors_and_versions_are_clear() {
        let err =
            CassetteFile::parse(Path::new("x.json"), "{\n  \"schema_version\": 1,\n  oops").unwrap_err();
        assert!(err.to_string().contains("x.json:3:"), "{err}");
        let err = CassetteFile::parse(Path::new("x.json"), r#"{"schema_version": 9}"#).unwrap_err();
        assert!(
            err.to_string().contains("schema_version 9 is not supported"),
            "{err}"
        );
        let err = CassetteFile::parse(Path::new("x.json"), r#"{"interactions": []}"#).unwrap_err();
        assert!(err.to_string().contains("not a nesy cassette"), "{err}");
    }

    #[test]
    fn an_interaction_holds_exactly_one_of_response_and_failure() {
        let file = |outcome: &str| {
            format!(
                r#"{{"schema_version": 1,
                "meta": {{"recorder": "r", "created_at": "t", "updated_at": "t"}},
                "interactions": [{{"key": "k", "recorded_at": "t", "latency_ms": 1.0,
                    "request": {{"method": "POST", "path": "/p", "body": null}}{outcome}}}]}}"#
            )
        };
        let response = r#""response": {"status": 200, "body": {}}"#;
        let failure =
            r#""failure": {"kind": "timeout", "phase": "response", "message": "no reply in 1800 s"}"#;
        let read = CassetteFile::parse(Path::new("c.json"), &file(&format!(", {failure}"))).unwrap();
        assert_eq!(
            read.interactions[0]
                .outcome()
                .unwrap()
                .unwrap_err()
                .to_transport()
                .to_string(),
            "timed out (Response timeout): no reply in 1800 s"
        );
        for (outcome, expected) in [
            (
                String::new(),
                "interaction #0 has neither `response` nor `failure`",
            ),
            (
                format!(", {response}, {failure}"),
                "interaction #0 has both `response` and `failure`",
            ),
        ] {
            let err = CassetteFile::parse(Path::new("c.json"), &file(&outcome)).unwrap_err();
            assert!(err.to_string().contains(expected), "{err}");
        }
    }

    #[test]
    fn only_failures_that_reached_the_network_are_stored() {
        let timeout = TransportError::Timeout {
            phase: TimeoutPhase::Connect,
            message: "connect".into(),
        };
        let stored = StoredFailure::from_transport(&timeout).unwrap();
        assert_eq!(
            serde_json::to_value(&stored).unwrap(),
            serde_json::json!({"kind": "timeout", "phase": "connect", "message": "connect"})
        );
        assert_eq!(stored.to_transport().to_string(), timeout.to_string());
        for (error, kind) in [
            (TransportError::Connect("refused".into()), "connect"),
            (TransportError::Body("reset".into()), "body"),
        ] {
            let stored = StoredFailure::from_transport(&error).unwrap();
            assert_eq!(serde_json::to_value(&stored).unwrap()["kind"], kind);
            assert!(stored.to_transport().is_retryable());
        }
        let not_sent = TransportError::Failed {
            message: "the unit's cap of 3 model call(s) is reached".into(),
            retryable: false,
        };
        assert_eq!(StoredFailure::from_transport(&not_sent), None);
        assert_eq!(
            StoredFailure::from_transport(&TransportError::Declined("no".into())),
            None
        );
    }

    #[test]
    fn send_order_sorts_replay_and_an_old_file_counts_by_position() {
        let call = |send_order: Option<u64>| Interaction {
            key: "k".into(),
            purpose: None,
            recorded_at: "t".into(),
            latency_ms: 1.0,
            send_order,
            request: StoredRequest {
                method: "POST".into(),
                path: "/p".into(),
                body: serde_json::Value::Null,
            },
            response: Some(StoredResponse::from_wire(&WireResponse::new(
                200,
                b"{}".to_vec(),
                Origin::Live,
            ))),
            failure: None,
        };
        let mut file = CassetteFile::new(None, None);
        assert_eq!(file.next_send_order(), 0);
        // Two calls recorded before the order was kept, then a resumed recording whose
        // second call finished first.
        file.interactions = vec![call(None), call(None), call(Some(3)), call(Some(2))];
        assert_eq!(file.send_sequence(), [0, 1, 3, 2]);
        assert_eq!(file.next_send_order(), 4);
        let text = file.to_pretty_json(&[]);
        assert_eq!(
            text.matches("send_order").count(),
            2,
            "absent stays absent:\n{text}"
        );
    }
}
