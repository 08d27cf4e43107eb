//! `demo.mcap`: a demo as an MCAP file that Foxglove opens and any MCAP reader can parse.
//!
//! All messages are JSON (`message_encoding = "json"`) with a JSON Schema
//! (`schema encoding = "jsonschema"`); chunks are zstd-compressed. Every keyframe `k`
//! publishes one message on each topic below, all with `sequence = k` and
//! `log_time = publish_time =` the keyframe's simulated time in nanoseconds:
//!
//! | topic | schema | payload |
//! |---|---|---|
//! | `/camera/top`, `/camera/front`, `/camera/back` | `foxglove.CompressedImage` | the plain view, PNG |
//! | `/camera/{top,front,back}/marked` | `foxglove.CompressedImage` | the labelled view, PNG (may be absent for a keyframe) |
//! | `/nesy/state` | `nesy.KeyframeState` | `{keyframe, timestamp, atoms}`: ground-truth atoms, or `null` if unknown |
//! | `/nesy/action` | `nesy.KeyframeAction` | `{keyframe, timestamp, entry}`: the API call and result that led here (`null` for keyframe 0) |
//!
//! One metadata record named [`METADATA_NAME`] holds the demo's metadata as strings
//! (see [`MetadataKey`]).

use std::collections::{BTreeMap, HashMap};
use std::io::{Seek, Write};
use std::path::Path;
use std::sync::Arc;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD as BASE64;
use mcap::records::{MessageHeader, Metadata, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{
    CameraImages, CameraName, Demo, DemoError, DemoMetadata, Demonstrator, Keyframe, KeyframeViews,
    NESY_VERSION, check_png,
};
use crate::api::{Embodiment, TraceEntry};
use crate::scene::SceneSpec;

/// Name of the metadata record.
pub const METADATA_NAME: &str = "nesy.demo";

/// Name of the metadata record an execution recording adds: `outcome` (the goal checker's
/// verdict as JSON, `null` for a scene without goals) and, when the replay parted from the
/// recorded run, `divergence` (JSON).
pub const EXECUTION_METADATA_NAME: &str = "nesy.execution";
/// Version of this layout, stored under `format_version` in the metadata.
pub const FORMAT_VERSION: u32 = 1;
/// Topic of the ground-truth states.
pub const STATE_TOPIC: &str = "/nesy/state";
/// Topic of the API calls.
pub const ACTION_TOPIC: &str = "/nesy/action";
/// Schema name of image messages (Foxglove's well-known image type).
pub const IMAGE_SCHEMA_NAME: &str = "foxglove.CompressedImage";
/// Schema name of state messages.
pub const STATE_SCHEMA_NAME: &str = "nesy.KeyframeState";
/// Schema name of action messages.
pub const ACTION_SCHEMA_NAME: &str = "nesy.KeyframeAction";

/// The topic of a filmed camera's frames: `/film/<camera>` (a recording of an execution
/// carries them beside its keyframes; the demo reader skips it).
pub fn film_topic(camera: &str) -> String {
    format!("/film/{camera}")
}

/// Frames filmed at a fixed rate by one camera, for an execution recording's `/film/<camera>`
/// topic.
#[derive(Clone, Debug, Default)]
pub struct Film {
    /// The camera's name (`corner`).
    pub camera: String,
    /// The frames in order.
    pub frames: Vec<FilmFrame>,
}

/// One filmed frame.
#[derive(Clone, Debug)]
pub struct FilmFrame {
    /// Simulated time in seconds, on the keyframes' clock.
    pub time: f64,
    /// The picture, JPEG.
    pub jpeg: Vec<u8>,
}

/// The image topic of a camera: `/camera/<name>` or `/camera/<name>/marked`.
pub fn image_topic(camera: CameraName, marked: bool) -> String {
    if marked {
        format!("/camera/{}/marked", camera.as_str())
    } else {
        format!("/camera/{}", camera.as_str())
    }
}

/// Every topic a nesy demo has, in channel order.
pub fn topics() -> Vec<String> {
    let mut all: Vec<String> = CameraName::ALL.iter().map(|&c| image_topic(c, false)).collect();
    all.extend(CameraName::ALL.iter().map(|&c| image_topic(c, true)));
    all.push(STATE_TOPIC.to_owned());
    all.push(ACTION_TOPIC.to_owned());
    all
}

/// Keys of the metadata record. Values are strings; lists and scenes are JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetadataKey {
    /// `format_version`: [`FORMAT_VERSION`].
    FormatVersion,
    /// `instruction`.
    Instruction,
    /// `objects`: JSON array of names.
    Objects,
    /// `embodiment`: `finger` or `vacuum`.
    Embodiment,
    /// `keyframes`: the keyframe count, decimal.
    Keyframes,
    /// `scenario_id` (optional).
    ScenarioId,
    /// `side` (optional): `source` or `target`.
    Side,
    /// `nesy_version` (optional).
    NesyVersion,
    /// `target_scene` (optional): a `scene.json` document.
    TargetScene,
}

impl MetadataKey {
    /// The key string.
    pub fn as_str(self) -> &'static str {
        match self {
            MetadataKey::FormatVersion => "format_version",
            MetadataKey::Instruction => "instruction",
            MetadataKey::Objects => "objects",
            MetadataKey::Embodiment => "embodiment",
            MetadataKey::Keyframes => "keyframes",
            MetadataKey::ScenarioId => "scenario_id",
            MetadataKey::Side => "side",
            MetadataKey::NesyVersion => "nesy_version",
            MetadataKey::TargetScene => "target_scene",
        }
    }
}

/// A timestamp as Foxglove writes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Timestamp {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds within the second.
    pub nsec: u32,
}

impl Timestamp {
    fn from_nanos(ns: u64) -> Timestamp {
        Timestamp {
            sec: u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX),
            nsec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// `foxglove.CompressedImage` in its JSON encoding.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct ImageMessage {
    timestamp: Timestamp,
    frame_id: String,
    /// Base64 of the PNG bytes.
    data: String,
    format: String,
}

/// A keyframe's ground-truth symbolic state (`/nesy/state`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(rename = "nesy.KeyframeState")]
pub struct StateMessage {
    /// Keyframe index, from 0.
    pub keyframe: usize,
    /// Simulated time of the keyframe.
    pub timestamp: Timestamp,
    /// The true atoms in the authors' notation, e.g. `(OnTopOf red_cube floor)`, sorted;
    /// `null` when the demo has no ground truth.
    #[schemars(with = "Option<Vec<String>>")]
    pub atoms: Option<nesy_core::State>,
}

/// The API call that led to a keyframe (`/nesy/action`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(rename = "nesy.KeyframeAction")]
pub struct ActionMessage {
    /// Keyframe index, from 0.
    pub keyframe: usize,
    /// Simulated time of the keyframe.
    pub timestamp: Timestamp,
    /// The call as a nesy-sim trace entry: `index` (position in the robot's full call
    /// trace), `call` (the API function name) with its arguments, `result` (`{"Ok": ...}`
    /// or `{"Err": ...}`) and `sim_time`; `null` for keyframe 0.
    #[schemars(with = "Option<serde_json::Map<String, serde_json::Value>>")]
    pub entry: Option<TraceEntry>,
}

/// JSON Schema of `foxglove.CompressedImage` (JSON encoding), as the channel carries it.
pub fn image_schema() -> String {
    let schema = serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": IMAGE_SCHEMA_NAME,
        "description": "A compressed image (Foxglove's well-known schema); nesy writes PNG.",
        "type": "object",
        "properties": {
            "timestamp": {
                "type": "object",
                "description": "Time of the image",
                "properties": {
                    "sec": {"type": "integer", "minimum": 0},
                    "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}
                },
                "required": ["sec", "nsec"]
            },
            "frame_id": {"type": "string", "description": "Camera name"},
            "data": {"type": "string", "contentEncoding": "base64", "description": "Compressed image data"},
            "format": {"type": "string", "description": "Image format: png"}
        },
        "required": ["timestamp", "frame_id", "data", "format"]
    });
    pretty(&schema)
}

/// JSON Schema of `/nesy/state` messages.
pub fn state_schema() -> String {
    pretty(&schemars::schema_for!(StateMessage))
}

/// JSON Schema of `/nesy/action` messages.
pub fn action_schema() -> String {
    pretty(&schemars::schema_for!(ActionMessage))
}

fn pretty<T: Serialize>(value: &T) -> String {
    let mut text = serde_json::to_string_pretty(value).unwrap_or_default();
    text.push('\n');
    text
}

/// A keyframe time as the file stores it (whole nanoseconds), so that recorded demos and
/// demos read back compare equal.
pub fn stored_time(seconds: f64) -> f64 {
    time_ns(seconds) as f64 / 1e9
}

fn time_ns(seconds: f64) -> u64 {
    if seconds.is_finite() && seconds > 0.0 {
        (seconds * 1e9).round() as u64
    } else {
        0
    }
}

/// Writes `demo` as MCAP into `w` and returns the writer.
pub fn write_mcap<W: Write + Seek>(demo: &Demo, w: W) -> Result<W, mcap::McapError> {
    write_mcap_with(demo, &[], None, w)
}

/// [`write_mcap`] with further metadata records after the demo's own (readers of the demo
/// format skip them).
pub(crate) fn write_mcap_with<W: Write + Seek>(
    demo: &Demo,
    extra: &[Metadata],
    film: Option<&Film>,
    w: W,
) -> Result<W, mcap::McapError> {
    let options = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .profile("")
        .library(format!("nesy {NESY_VERSION}"));
    let mut out = options.create(w)?;
    let no_meta = BTreeMap::new();
    let image_schema_id = out.add_schema(IMAGE_SCHEMA_NAME, "jsonschema", image_schema().as_bytes())?;
    let state_schema_id = out.add_schema(STATE_SCHEMA_NAME, "jsonschema", state_schema().as_bytes())?;
    let action_schema_id = out.add_schema(ACTION_SCHEMA_NAME, "jsonschema", action_schema().as_bytes())?;
    let mut image_channels = Vec::new();
    for marked in [false, true] {
        for camera in CameraName::ALL {
            let id = out.add_channel(image_schema_id, &image_topic(camera, marked), "json", &no_meta)?;
            image_channels.push((camera, marked, id));
        }
    }
    let state_channel = out.add_channel(state_schema_id, STATE_TOPIC, "json", &no_meta)?;
    let action_channel = out.add_channel(action_schema_id, ACTION_TOPIC, "json", &no_meta)?;

    for keyframe in &demo.keyframes {
        let ns = time_ns(keyframe.time);
        let header = |channel_id| MessageHeader {
            channel_id,
            sequence: u32::try_from(keyframe.index).unwrap_or(u32::MAX),
            log_time: ns,
            publish_time: ns,
        };
        let timestamp = Timestamp::from_nanos(ns);
        for &(camera, marked, channel) in &image_channels {
            // MCAP demos carry the simulator's three cameras; other views are not written.
            let Some(images) = keyframe.views.get(camera.as_str()) else {
                continue;
            };
            let png = if marked {
                images.marked.as_deref()
            } else {
                Some(&images.raw[..])
            };
            let Some(png) = png else { continue };
            let message = ImageMessage {
                timestamp,
                frame_id: camera.as_str().to_owned(),
                data: BASE64.encode(png),
                format: "png".to_owned(),
            };
            out.write_to_known_channel(&header(channel), &json_bytes(&message))?;
        }
        let state = StateMessage {
            keyframe: keyframe.index,
            timestamp,
            atoms: keyframe.state.clone(),
        };
        out.write_to_known_channel(&header(state_channel), &json_bytes(&state))?;
        let action = ActionMessage {
            keyframe: keyframe.index,
            timestamp,
            entry: keyframe.action.clone(),
        };
        out.write_to_known_channel(&header(action_channel), &json_bytes(&action))?;
    }

    if let Some(film) = film {
        let channel = out.add_channel(image_schema_id, &film_topic(&film.camera), "json", &no_meta)?;
        for (index, frame) in film.frames.iter().enumerate() {
            let ns = time_ns(frame.time);
            let header = MessageHeader {
                channel_id: channel,
                sequence: u32::try_from(index).unwrap_or(u32::MAX),
                log_time: ns,
                publish_time: ns,
            };
            let message = ImageMessage {
                timestamp: Timestamp::from_nanos(ns),
                frame_id: film.camera.clone(),
                data: BASE64.encode(&frame.jpeg),
                format: "jpeg".to_owned(),
            };
            out.write_to_known_channel(&header, &json_bytes(&message))?;
        }
    }
    out.write_metadata(&Metadata {
        name: METADATA_NAME.to_owned(),
        metadata: metadata_map(&demo.metadata, demo.keyframes.len()),
    })?;
    for record in extra {
        out.write_metadata(record)?;
    }
    out.finish()?;
    Ok(out.into_inner())
}

fn json_bytes<T: Serialize>(value: &T) -> Vec<u8> {
    // The message types hold only strings, numbers and finite floats: serialisation cannot fail.
    serde_json::to_vec(value).unwrap_or_default()
}

fn metadata_map(meta: &DemoMetadata, keyframes: usize) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    let mut put = |key: MetadataKey, value: String| {
        map.insert(key.as_str().to_owned(), value);
    };
    put(MetadataKey::FormatVersion, FORMAT_VERSION.to_string());
    put(MetadataKey::Instruction, meta.instruction.clone());
    put(
        MetadataKey::Objects,
        serde_json::to_string(&meta.objects).unwrap_or_default(),
    );
    put(MetadataKey::Embodiment, meta.embodiment.as_str().to_owned());
    put(MetadataKey::Keyframes, keyframes.to_string());
    if let Some(id) = &meta.scenario_id {
        put(MetadataKey::ScenarioId, id.clone());
    }
    if let Some(side) = &meta.side {
        put(MetadataKey::Side, side.clone());
    }
    if let Some(version) = &meta.nesy_version {
        put(MetadataKey::NesyVersion, version.clone());
    }
    if let Some(scene) = &meta.target_scene {
        put(
            MetadataKey::TargetScene,
            serde_json::to_string(scene).unwrap_or_default(),
        );
    }
    map
}

/// Writes `demo` to `path` (creating parent folders).
pub fn write_mcap_file(demo: &Demo, path: &Path) -> Result<(), DemoError> {
    write_mcap_file_with(demo, &[], None, path)
}

/// [`write_mcap_file`] with further metadata records.
pub(crate) fn write_mcap_file_with(
    demo: &Demo,
    extra: &[Metadata],
    film: Option<&Film>,
    path: &Path,
) -> Result<(), DemoError> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| DemoError::io(parent, e))?;
    }
    let buffer = write_mcap_with(demo, extra, film, std::io::Cursor::new(Vec::new())).map_err(|source| {
        DemoError::Mcap {
            path: path.to_owned(),
            source,
        }
    })?;
    std::fs::write(path, buffer.into_inner()).map_err(|e| DemoError::io(path, e))
}

/// Reads a `demo.mcap` file.
pub fn read_mcap(path: &Path) -> Result<Demo, DemoError> {
    let bytes =
        nesy_input::read_bytes(path, nesy_input::MAX_DEMO_BYTES).map_err(|e| DemoError::io(path, e))?;
    read_mcap_bytes(&bytes, path)
}

/// A message's log time and payload.
type Stamped = (u64, Vec<u8>);

/// The records of an MCAP file that a demo is made of.
#[derive(Default)]
struct Records {
    schemas: HashMap<u16, String>,
    /// Channel id → (topic, schema id, encoding).
    channels: HashMap<u16, (String, u16, String)>,
    messages: Vec<(MessageHeader, Vec<u8>)>,
    metadata: Option<BTreeMap<String, String>>,
}

/// Decompressed chunks may be larger than the file, but not absurdly so: a corrupt length
/// field must give an error, not a giant allocation.
fn record_limit(file_len: usize) -> usize {
    file_len.saturating_mul(16).max(64 << 20)
}

/// MCAP opcodes of the records a demo is read from: Schema, Channel, Message, Metadata.
const RECORDS_READ: [u8; 4] = [0x03, 0x04, 0x05, 0x0c];

/// The first length-prefixed field of a Schema, Channel or Metadata record (the MCAP layout)
/// whose length runs past the end of the record, named for the error; `None` if all fit.
fn oversized_length(opcode: u8, data: &[u8]) -> Option<&'static str> {
    /// Reads a little-endian u32 length at `at` and skips that many bytes; `None` if either
    /// runs past `end`.
    fn skip_prefixed(data: &[u8], at: usize, end: usize) -> Option<usize> {
        let len = u32::from_le_bytes(data.get(at..at + 4)?.try_into().ok()?) as usize;
        let next = (at + 4).checked_add(len)?;
        (next <= end).then_some(next)
    }
    /// A map: a u32 byte length, then string key/value pairs inside it.
    fn skip_string_map(data: &[u8], at: usize, end: usize) -> Option<usize> {
        let map_end = skip_prefixed(data, at, end)?;
        let mut entry = at + 4;
        while entry < map_end {
            entry = skip_prefixed(data, entry, map_end)?;
            entry = skip_prefixed(data, entry, map_end)?;
        }
        Some(map_end)
    }
    let end = data.len();
    let ok = match opcode {
        // id u16, name, encoding, data.
        0x03 => skip_prefixed(data, 2, end)
            .and_then(|at| skip_prefixed(data, at, end))
            .and_then(|at| skip_prefixed(data, at, end))
            .is_some(),
        // id u16, schema id u16, topic, message encoding, metadata map.
        0x04 => skip_prefixed(data, 4, end)
            .and_then(|at| skip_prefixed(data, at, end))
            .and_then(|at| skip_string_map(data, at, end))
            .is_some(),
        // name, metadata map.
        0x0c => skip_prefixed(data, 0, end)
            .and_then(|at| skip_string_map(data, at, end))
            .is_some(),
        // Message: fixed header, then the payload to the end.
        _ => true,
    };
    (!ok).then_some(match opcode {
        0x03 => "a Schema record",
        0x04 => "a Channel record",
        _ => "a Metadata record",
    })
}

fn scan(bytes: &[u8], path: &Path) -> Result<Records, DemoError> {
    let mcap_err = |source| DemoError::Mcap {
        path: path.to_owned(),
        source,
    };
    let options = LinearReaderOptions::default()
        .with_record_length_limit(record_limit(bytes.len()))
        .with_validate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true);
    let mut reader = LinearReader::new_with_options(options);
    let mut rest = bytes;
    let mut records = Records::default();
    while let Some(event) = reader.next_event() {
        match event.map_err(mcap_err)? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            LinearReadEvent::Record { data, opcode } => {
                // Only the records a demo is read from are parsed, and only once every length
                // inside them fits the record: the mcap crate reserves a string's claimed
                // length before reading it, so a corrupt 4 GB length was a 4 GB allocation.
                if !RECORDS_READ.contains(&opcode) {
                    continue;
                }
                if let Some(field) = oversized_length(opcode, data) {
                    return Err(DemoError::invalid(
                        path,
                        field,
                        "a length that fits inside its record",
                        "a length past the record's end",
                    ));
                }
                match mcap::parse_record(opcode, data).map_err(mcap_err)? {
                    Record::Schema { header, data: _ } => {
                        records.schemas.insert(header.id, header.name);
                    }
                    Record::Channel(c) => {
                        records
                            .channels
                            .insert(c.id, (c.topic, c.schema_id, c.message_encoding));
                    }
                    Record::Message { header, data } => records.messages.push((header, data.into_owned())),
                    Record::Metadata(m) if m.name == METADATA_NAME => records.metadata = Some(m.metadata),
                    _ => {}
                }
            }
        }
    }
    Ok(records)
}

/// Reads a demo from the bytes of a `demo.mcap`; `path` names it in errors.
pub fn read_mcap_bytes(bytes: &[u8], path: &Path) -> Result<Demo, DemoError> {
    let records = scan(bytes, path)?;
    let meta_map = records.metadata.ok_or_else(|| DemoError::MissingMetadata {
        path: path.to_owned(),
        name: METADATA_NAME.to_owned(),
    })?;
    let (metadata, count) = parse_metadata(&meta_map, path)?;
    let all_topics = topics();
    check_channels(&records.channels, &records.schemas, &all_topics, path)?;
    let mut slots = slot_messages(records.messages, &records.channels, &all_topics, count, path)?;
    let mut keyframes = Vec::with_capacity(count);
    for k in 0..count {
        keyframes.push(take_keyframe(&mut slots, k, count, path)?);
    }
    Ok(Demo { metadata, keyframes })
}

/// Messages of each topic, indexed by keyframe (a `None` until its message is read).
type Slots<'a> = HashMap<&'a str, Vec<Option<Stamped>>>;

/// Checks the schema and encoding of every channel a demo topic is on, and that each of
/// `all_topics` has a channel.
fn check_channels(
    channels: &HashMap<u16, (String, u16, String)>,
    schemas: &HashMap<u16, String>,
    all_topics: &[String],
    path: &Path,
) -> Result<(), DemoError> {
    let mut by_topic: HashMap<&str, u16> = HashMap::new();
    for (id, (topic, schema_id, encoding)) in channels {
        by_topic.insert(topic.as_str(), *id);
        let expected_schema = if topic.starts_with("/camera/") {
            Some(IMAGE_SCHEMA_NAME)
        } else if topic == STATE_TOPIC {
            Some(STATE_SCHEMA_NAME)
        } else if topic == ACTION_TOPIC {
            Some(ACTION_SCHEMA_NAME)
        } else {
            None
        };
        let Some(expected_schema) = expected_schema else {
            continue;
        };
        if encoding != "json" {
            return Err(DemoError::invalid(
                path,
                format!("channel {topic}"),
                "message encoding \"json\"",
                format!("{encoding:?}"),
            ));
        }
        let schema = schemas.get(schema_id).map(String::as_str).unwrap_or("");
        if schema != expected_schema {
            return Err(DemoError::invalid(
                path,
                format!("channel {topic}"),
                format!("schema {expected_schema:?}"),
                format!("{schema:?}"),
            ));
        }
    }
    for topic in all_topics {
        if !by_topic.contains_key(topic.as_str()) {
            return Err(DemoError::MissingTopic {
                path: path.to_owned(),
                topic: topic.clone(),
                expected: all_topics.join(", "),
            });
        }
    }
    Ok(())
}

/// Files each message of a demo topic under its keyframe (the message sequence), rejecting
/// unknown channels, sequences past `count` and second messages for one keyframe.
fn slot_messages<'a>(
    messages: Vec<(MessageHeader, Vec<u8>)>,
    channels: &HashMap<u16, (String, u16, String)>,
    all_topics: &'a [String],
    count: usize,
    path: &Path,
) -> Result<Slots<'a>, DemoError> {
    let topic_of: HashMap<u16, &str> = channels
        .iter()
        .map(|(id, (topic, _, _))| (*id, topic.as_str()))
        .collect();
    let mut slots: Slots<'a> = all_topics
        .iter()
        .map(|t| (t.as_str(), vec![None; count]))
        .collect();
    for (header, data) in messages {
        let Some(topic) = topic_of.get(&header.channel_id).copied() else {
            return Err(DemoError::invalid(
                path,
                format!("message {} ", header.sequence),
                "a channel defined before the message",
                format!("unknown channel id {}", header.channel_id),
            ));
        };
        let Some(slot) = slots.get_mut(topic) else {
            continue;
        };
        let k = header.sequence as usize;
        if k >= count {
            return Err(DemoError::invalid(
                path,
                format!("{topic} message"),
                format!("keyframe sequence below the metadata's keyframe count {count}"),
                format!("sequence {k}"),
            ));
        }
        if slot[k].is_some() {
            return Err(DemoError::invalid(
                path,
                format!("{topic} keyframe {k}"),
                "one message per keyframe",
                "a second message",
            ));
        }
        slot[k] = Some((header.log_time, data));
    }
    Ok(slots)
}

/// Decodes keyframe `k` of `count` from its messages, taking them out of `slots`: state,
/// action and each camera's raw and (optional) marked image.
fn take_keyframe(slots: &mut Slots<'_>, k: usize, count: usize, path: &Path) -> Result<Keyframe, DemoError> {
    let mut take = |topic: &str| slots.get_mut(topic).and_then(|s| s[k].take());
    let missing = |topic: &str| {
        DemoError::invalid(
            path,
            format!("{topic} keyframe {k}"),
            format!("one message for each of the {count} keyframes"),
            "no message",
        )
    };
    let (log_time, state_bytes) = take(STATE_TOPIC).ok_or_else(|| missing(STATE_TOPIC))?;
    let state: StateMessage =
        DemoError::parse_json(path, &format!("{STATE_TOPIC} keyframe {k}"), &state_bytes)?;
    check_keyframe_field(path, STATE_TOPIC, k, state.keyframe)?;
    let (_, action_bytes) = take(ACTION_TOPIC).ok_or_else(|| missing(ACTION_TOPIC))?;
    let action: ActionMessage =
        DemoError::parse_json(path, &format!("{ACTION_TOPIC} keyframe {k}"), &action_bytes)?;
    check_keyframe_field(path, ACTION_TOPIC, k, action.keyframe)?;
    let views = KeyframeViews::from_fn(|camera| {
        let raw_topic = image_topic(camera, false);
        let (_, raw) = take(&raw_topic).ok_or_else(|| missing(&raw_topic))?;
        let raw = decode_image(path, &raw_topic, k, &raw)?;
        let marked_topic = image_topic(camera, true);
        let marked = match take(&marked_topic) {
            Some((_, bytes)) => Some(decode_image(path, &marked_topic, k, &bytes)?),
            None => None,
        };
        Ok(CameraImages { raw, marked })
    })?;
    Ok(Keyframe {
        index: k,
        time: log_time as f64 / 1e9,
        views,
        state: state.atoms,
        action: action.entry,
    })
}

fn check_keyframe_field(path: &Path, topic: &str, k: usize, found: usize) -> Result<(), DemoError> {
    if found == k {
        Ok(())
    } else {
        Err(DemoError::invalid(
            path,
            format!("{topic} keyframe {k}: field keyframe"),
            format!("{k} (the message sequence)"),
            found.to_string(),
        ))
    }
}

fn decode_image(path: &Path, topic: &str, k: usize, bytes: &[u8]) -> Result<Vec<u8>, DemoError> {
    let location = format!("{topic} keyframe {k}");
    let message: ImageMessage = DemoError::parse_json(path, &location, bytes)?;
    if message.format != "png" {
        return Err(DemoError::invalid(
            path,
            format!("{location}: field format"),
            "\"png\"",
            format!("{:?}", message.format),
        ));
    }
    let png = BASE64.decode(message.data.as_bytes()).map_err(|e| {
        DemoError::invalid(
            path,
            format!("{location}: field data"),
            "base64 text",
            e.to_string(),
        )
    })?;
    check_png(path, &format!("{location}: field data"), &png)?;
    Ok(png)
}

fn parse_metadata(map: &BTreeMap<String, String>, path: &Path) -> Result<(DemoMetadata, usize), DemoError> {
    let location = |key: MetadataKey| format!("metadata {METADATA_NAME} key {}", key.as_str());
    let get = |key: MetadataKey| map.get(key.as_str()).map(String::as_str);
    let require = |key: MetadataKey| {
        get(key).ok_or_else(|| DemoError::invalid(path, location(key), "a value", "no such key"))
    };
    let version = require(MetadataKey::FormatVersion)?;
    if version != FORMAT_VERSION.to_string() {
        return Err(DemoError::invalid(
            path,
            location(MetadataKey::FormatVersion),
            FORMAT_VERSION.to_string(),
            format!("{version:?}"),
        ));
    }
    let instruction = require(MetadataKey::Instruction)?.to_owned();
    let objects: Vec<String> = DemoError::parse_json(
        path,
        &location(MetadataKey::Objects),
        require(MetadataKey::Objects)?.as_bytes(),
    )?;
    let embodiment = match require(MetadataKey::Embodiment)? {
        "finger" => Embodiment::Finger,
        "vacuum" => Embodiment::Vacuum,
        other => {
            return Err(DemoError::invalid(
                path,
                location(MetadataKey::Embodiment),
                "\"finger\" or \"vacuum\"",
                format!("{other:?}"),
            ));
        }
    };
    let count_text = require(MetadataKey::Keyframes)?;
    let count: usize = count_text
        .parse()
        .ok()
        .filter(|n| (1..=100_000).contains(n))
        .ok_or_else(|| {
            DemoError::invalid(
                path,
                location(MetadataKey::Keyframes),
                "a keyframe count from 1 to 100000",
                format!("{count_text:?}"),
            )
        })?;
    let target_scene = match get(MetadataKey::TargetScene) {
        Some(text) => Some(
            SceneSpec::from_json_str(
                text,
                &format!("{}: {}", path.display(), location(MetadataKey::TargetScene)),
            )
            .map_err(|e| {
                DemoError::invalid(
                    path,
                    location(MetadataKey::TargetScene),
                    "a valid scene",
                    e.to_string(),
                )
            })?,
        ),
        None => None,
    };
    let metadata = DemoMetadata {
        instruction,
        objects,
        embodiment,
        demonstrator: Demonstrator::Robot,
        imported_from: None,
        scenario_id: get(MetadataKey::ScenarioId).map(str::to_owned),
        side: get(MetadataKey::Side).map(str::to_owned),
        nesy_version: get(MetadataKey::NesyVersion).map(str::to_owned),
        target_scene,
    };
    Ok((metadata, count))
}

/// The channels of a file by topic, with their message counts (for tools and tests).
pub fn channel_summary(bytes: &[u8], path: &Path) -> Result<BTreeMap<String, usize>, DemoError> {
    let records = scan(bytes, path)?;
    let mut counts: BTreeMap<String, usize> = records
        .channels
        .values()
        .map(|(topic, _, _)| (topic.clone(), 0))
        .collect();
    let topic_of: HashMap<u16, Arc<str>> = records
        .channels
        .iter()
        .map(|(id, (topic, _, _))| (*id, Arc::from(topic.as_str())))
        .collect();
    for (header, _) in &records.messages {
        if let Some(topic) = topic_of.get(&header.channel_id) {
            *counts.entry(topic.to_string()).or_default() += 1;
        }
    }
    Ok(counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `len` as a little-endian u32 length prefix followed by `body`.
    fn prefixed(len: u32, body: &[u8]) -> Vec<u8> {
        let mut out = len.to_le_bytes().to_vec();
        out.extend_from_slice(body);
        out
    }

    #[test]
    fn lengths_past_the_record_are_caught_before_parsing() {
        // Metadata: a name, then an empty map.
        let mut good = prefixed(4, b"demo");
        good.extend(prefixed(0, b""));
        assert_eq!(oversized_length(0x0c, &good), None);
        // A name claiming 4 GB: refused without allocating it.
        let mut bad = prefixed(0xfc00_0000, b"demo");
        bad.extend(prefixed(0, b""));
        assert_eq!(oversized_length(0x0c, &bad), Some("a Metadata record"));
        // A map entry whose value runs past the map.
        let mut entry = prefixed(1, b"k");
        entry.extend(prefixed(99, b"v"));
        let mut map_bad = prefixed(4, b"demo");
        map_bad.extend(prefixed(entry.len() as u32, &entry));
        assert_eq!(oversized_length(0x0c, &map_bad), Some("a Metadata record"));
        // A Channel's topic past the end.
        let mut channel = vec![1, 0, 1, 0];
        channel.extend(prefixed(0xffff_ffff, b""));
        assert_eq!(oversized_length(0x04, &channel), Some("a Channel record"));
    }

    #[test]
    fn a_header_with_a_corrupt_length_is_an_error_not_an_allocation() {
        // Magic, then a Header record whose profile claims 4 GB.
        let mut bytes = b"\x89MCAP0\r\n".to_vec();
        let body = prefixed(0xfc00_0000, b"x");
        bytes.push(0x01);
        bytes.extend((body.len() as u64).to_le_bytes());
        bytes.extend(body);
        assert!(read_mcap_bytes(&bytes, Path::new("bad.mcap")).is_err());
    }
}
