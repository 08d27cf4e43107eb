//! Demo files: MCAP and folder round trips, damaged and incomplete files, recording
//! determinism, and the independent Python `mcap` reader.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

use nesy_core::Embodiment;
use nesy_core::State;
use nesy_sim::api::{ApiCall, ApiValue, Direction, TraceEntry};
use nesy_sim::demo::mcap_format::{self, ACTION_TOPIC, STATE_TOPIC, image_topic, topics};
use nesy_sim::demo::{
    CameraImages, CameraName, Demo, DemoError, DemoMetadata, Demonstrator, ImageFormat, Keyframe,
    KeyframeViews, RecordOptions,
};
use nesy_sim::perception::render::Image;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::TaskConfig;
use sha2::Digest;

fn png(seed: u8) -> Vec<u8> {
    Image {
        width: 4,
        height: 3,
        rgb: (0..36).map(|i| seed.wrapping_mul(31).wrapping_add(i)).collect(),
    }
    .to_png()
}

fn jpeg(width: u16, height: u16, seed: u8) -> Vec<u8> {
    let rgb: Vec<u8> = (0..usize::from(width) * usize::from(height) * 3)
        .map(|i| seed.wrapping_mul(17).wrapping_add(i as u8))
        .collect();
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, 85)
        .encode(&rgb, width, height, jpeg_encoder::ColorType::Rgb)
        .unwrap();
    out
}

/// A folder demo with `views` (name, width, height) at `keyframes` keyframes, as JPEG.
fn jpeg_folder(manifest: &str, views: &[(&str, u16, u16)], keyframes: usize) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("frames")).unwrap();
    std::fs::write(dir.path().join("manifest.json"), manifest).unwrap();
    for k in 0..keyframes {
        for &(view, width, height) in views {
            let name = nesy_sim::demo::frame_file_name(k, view, false, ImageFormat::Jpeg);
            std::fs::write(dir.path().join("frames").join(name), jpeg(width, height, k as u8)).unwrap();
        }
    }
    dir
}

const HUMAN: &str = r#"{"format_version": 1, "instruction": "Gather the screws on the tray.",
    "objects": ["black_screws", "tray"], "embodiment": "human"}"#;

#[test]
fn a_one_view_jpeg_folder_of_a_human_demonstration_reads() {
    let dir = jpeg_folder(HUMAN, &[("realsense", 64, 48)], 3);
    let demo = nesy_sim::demo::read(dir.path()).unwrap();
    assert_eq!(demo.keyframes.len(), 3);
    assert_eq!(demo.metadata.demonstrator, Demonstrator::Human);
    assert_eq!(
        demo.metadata.embodiment,
        Embodiment::Finger,
        "a hand reads as a finger gripper"
    );
    let views = &demo.keyframes[2].views;
    assert_eq!(views.names().collect::<Vec<_>>(), ["realsense"]);
    assert_eq!(
        nesy_sim::demo::image_size(&views.get("realsense").unwrap().raw),
        Some((64, 48))
    );

    // Written back, it reads the same (JPEG stays JPEG, `human` stays human).
    let copy = tempfile::tempdir().unwrap();
    nesy_sim::demo::write_folder(&demo, copy.path()).unwrap();
    assert!(copy.path().join("frames/0002_realsense.jpg").is_file());
    assert_eq!(nesy_sim::demo::read(copy.path()).unwrap(), demo);
}

#[test]
fn views_keep_the_manifest_order_and_bad_folders_name_the_file() {
    let ordered = HUMAN.replace("\"human\"", "\"human\", \"views\": [\"wrist\", \"overhead\"]");
    let dir = jpeg_folder(&ordered, &[("overhead", 32, 24), ("wrist", 16, 16)], 2);
    let demo = nesy_sim::demo::read(dir.path()).unwrap();
    assert_eq!(
        demo.keyframes[0].views.names().collect::<Vec<_>>(),
        ["wrist", "overhead"]
    );

    // One frame of another resolution.
    std::fs::write(dir.path().join("frames/0001_wrist.jpg"), jpeg(20, 16, 1)).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("0001_wrist.jpg") && err.contains("16x16") && err.contains("20x16"),
        "{err}"
    );
    std::fs::write(dir.path().join("frames/0001_wrist.jpg"), jpeg(16, 16, 1)).unwrap();

    // A view the manifest does not list.
    std::fs::write(dir.path().join("frames/0001_side.jpg"), jpeg(16, 16, 1)).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("0001_side.jpg") && err.contains("view `side`"),
        "{err}"
    );
    std::fs::remove_file(dir.path().join("frames/0001_side.jpg")).unwrap();

    // The same frame twice, as PNG and JPEG.
    std::fs::write(dir.path().join("frames/0001_wrist.png"), png(1)).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(err.contains("one file per keyframe and view"), "{err}");
    std::fs::remove_file(dir.path().join("frames/0001_wrist.png")).unwrap();

    // A truncated JPEG and a file that is no image.
    let whole = jpeg(16, 16, 1);
    std::fs::write(dir.path().join("frames/0001_wrist.jpg"), &whole[..8]).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("0001_wrist.jpg") && err.contains("truncated or damaged"),
        "{err}"
    );
    std::fs::write(dir.path().join("frames/0001_wrist.jpg"), b"GIF89a").unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("0001_wrist.jpg") && err.contains("JPEG data"),
        "{err}"
    );

    // A person is the only new demonstrator.
    let robot = HUMAN.replace("\"human\"", "\"octopus\"");
    let dir = jpeg_folder(&robot, &[("top", 8, 8)], 2);
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(err.contains("embodiment") && err.contains("human"), "{err}");
}

/// A small hand-made demo: three keyframes, marked views missing on the last one.
fn synthetic_demo() -> Demo {
    let keyframes = (0..3)
        .map(|k| {
            let views = KeyframeViews::from_fn(|camera| {
                let seed = (k * 3 + camera as usize) as u8;
                Ok::<_, ()>(CameraImages {
                    raw: png(seed),
                    marked: (k < 2).then(|| png(seed + 100)),
                })
            })
            .unwrap();
            let state: State = ["(GripperOpen)", "(OnTopOf red_cube floor)"]
                .iter()
                .map(|a| a.parse().unwrap())
                .collect();
            let action = (k > 0).then(|| TraceEntry {
                index: 4 * k,
                call: ApiCall::MoveGripperTo {
                    obj_name: "red_cube".into(),
                    pointing_to: Direction::Down,
                    depth: 0.015,
                },
                result: Ok(ApiValue::None),
                sim_time: 1.5 * k as f64,
            });
            Keyframe {
                index: k,
                time: 1.5 * k as f64,
                views,
                state: Some(state),
                action,
            }
        })
        .collect();
    Demo {
        metadata: DemoMetadata {
            instruction: "Place the cube blocks in to the box.".into(),
            objects: vec![
                "floor".into(),
                "red_cube".into(),
                "toy_box".into(),
                "gripper".into(),
            ],
            embodiment: Embodiment::Finger,
            demonstrator: Demonstrator::Robot,
            imported_from: None,
            scenario_id: Some("obst_low_00_s0".into()),
            side: Some("source".into()),
            nesy_version: Some(nesy_sim::demo::NESY_VERSION.into()),
            target_scene: None,
        },
        keyframes,
    }
}

fn to_bytes(demo: &Demo) -> Vec<u8> {
    mcap_format::write_mcap(demo, Cursor::new(Vec::new()))
        .unwrap()
        .into_inner()
}

fn read_bytes(bytes: &[u8]) -> Result<Demo, DemoError> {
    mcap_format::read_mcap_bytes(bytes, Path::new("demo.mcap"))
}

#[test]
fn mcap_round_trip_is_exact() {
    let demo = synthetic_demo();
    let bytes = to_bytes(&demo);
    let back = read_bytes(&bytes).unwrap();
    assert_eq!(back, demo);
    // Deterministic bytes.
    assert_eq!(to_bytes(&back), bytes);
    let counts = mcap_format::channel_summary(&bytes, Path::new("demo.mcap")).unwrap();
    assert_eq!(counts.len(), 8);
    assert_eq!(counts[STATE_TOPIC], 3);
    assert_eq!(
        counts[&image_topic(CameraName::Top, true)],
        2,
        "no marked view on keyframe 2"
    );
}

#[test]
fn folder_round_trip_and_read_dispatch() {
    let dir = tempfile::tempdir().unwrap();
    let demo = synthetic_demo();
    nesy_sim::demo::write_folder(&demo, &dir.path().join("f")).unwrap();
    assert_eq!(nesy_sim::demo::read(dir.path().join("f")).unwrap(), demo);
    assert_eq!(
        nesy_sim::demo::read(dir.path().join("f/manifest.json")).unwrap(),
        demo
    );
    mcap_format::write_mcap_file(&demo, &dir.path().join("m/demo.mcap")).unwrap();
    assert_eq!(nesy_sim::demo::read(dir.path().join("m")).unwrap(), demo);
    assert_eq!(
        nesy_sim::demo::read(dir.path().join("m/demo.mcap")).unwrap(),
        demo
    );
    let err = nesy_sim::demo::read(dir.path()).unwrap_err();
    assert!(matches!(err, DemoError::NotADemo { .. }), "{err}");
}

#[test]
fn minimal_real_world_folder_reads_without_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("frames")).unwrap();
    std::fs::write(
        dir.path().join("manifest.json"),
        r#"{"format_version": 1, "instruction": "Put the fruits in the hinge box.",
            "objects": ["apple", "hinge_body", "hinge_lid"], "embodiment": "vacuum"}"#,
    )
    .unwrap();
    for k in 0..2 {
        for camera in CameraName::ALL {
            let name = nesy_sim::demo::frame_file_name(k, camera.as_str(), false, ImageFormat::Png);
            std::fs::write(dir.path().join("frames").join(name), png(k as u8)).unwrap();
        }
    }
    let demo = nesy_sim::demo::read(dir.path()).unwrap();
    assert_eq!(demo.keyframes.len(), 2);
    assert_eq!(demo.metadata.embodiment, Embodiment::Vacuum);
    let back = demo.keyframes[1].views.get("back").unwrap();
    assert!(demo.states().is_none() && back.marked.is_none());
    assert_eq!(back.marked_or_raw(), &png(1)[..]);
    assert_eq!(
        demo.keyframes[1].views.names().collect::<Vec<_>>(),
        ["top", "front", "back"]
    );

    // A missing view names the file.
    std::fs::remove_file(dir.path().join("frames/0001_front.png")).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("0001_front.png") && err.contains("no such file"),
        "{err}"
    );
    std::fs::write(dir.path().join("frames/0001_front.png"), b"GIF89a").unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(err.contains("0001_front.png") && err.contains("PNG"), "{err}");

    // A bad manifest field names the field.
    std::fs::write(
        dir.path().join("manifest.json"),
        r#"{"format_version": 1, "instruction": "x", "objects": ["a"], "embodiment": "tentacle"}"#,
    )
    .unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("manifest.json") && err.contains("embodiment"),
        "{err}"
    );
    // More manifest keyframes than frames: the missing frame is named.
    std::fs::write(
        dir.path().join("manifest.json"),
        r#"{"format_version": 1, "instruction": "x", "objects": ["a"], "embodiment": "finger",
            "keyframes": [{}, {}, {"state": ["(GripperOpen)"]}]}"#,
    )
    .unwrap();
    std::fs::write(dir.path().join("frames/0001_front.png"), png(1)).unwrap();
    let err = nesy_sim::demo::read(dir.path()).unwrap_err().to_string();
    assert!(err.contains("0002_top.png"), "{err}");
}

#[test]
fn truncated_files_give_errors_not_panics() {
    let bytes = to_bytes(&synthetic_demo());
    let mut cuts: Vec<usize> = (0..bytes.len()).step_by(37).collect();
    cuts.extend([1, 7, 8, 9, bytes.len() - 9, bytes.len() - 8, bytes.len() - 1]);
    for cut in cuts {
        let err = read_bytes(&bytes[..cut]).expect_err("a truncated file must not read");
        assert!(err.to_string().contains("demo.mcap"), "{err}");
    }
}

#[test]
fn corrupt_bytes_give_errors_not_panics() {
    let bytes = to_bytes(&synthetic_demo());
    let mut failed = 0;
    let mut tried = 0;
    for pos in (0..bytes.len()).step_by(13) {
        for flip in [0x01u8, 0x80, 0xFF] {
            let mut damaged = bytes.clone();
            damaged[pos] ^= flip;
            tried += 1;
            if read_bytes(&damaged).is_err() {
                failed += 1;
            }
        }
    }
    // Flips inside unchecked fields (e.g. summary offsets the linear reader does not use)
    // may go unnoticed; everything in the data section is covered by CRCs or by parsing.
    assert!(
        failed * 10 >= tried * 9,
        "only {failed} of {tried} corruptions detected"
    );
}

/// Copies a demo file, leaving out the channel of `skip_topic` (and its messages) or the
/// metadata record.
fn copy_without(bytes: &[u8], skip_topic: Option<&str>, skip_metadata: bool) -> Vec<u8> {
    let mut out = mcap::WriteOptions::new().create(Cursor::new(Vec::new())).unwrap();
    let mut channels = BTreeMap::new();
    for message in mcap::MessageStream::new(bytes).unwrap() {
        let message = message.unwrap();
        if Some(message.channel.topic.as_str()) == skip_topic {
            continue;
        }
        let id = *channels.entry(message.channel.topic.clone()).or_insert_with(|| {
            let schema = message.channel.schema.as_ref().unwrap();
            let sid = out
                .add_schema(&schema.name, &schema.encoding, &schema.data)
                .unwrap();
            out.add_channel(sid, &message.channel.topic, "json", &BTreeMap::new())
                .unwrap()
        });
        out.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: id,
                sequence: message.sequence,
                log_time: message.log_time,
                publish_time: message.publish_time,
            },
            &message.data,
        )
        .unwrap();
    }
    if !skip_metadata {
        let summary = mcap::read::Summary::read(bytes).unwrap().unwrap();
        let index = &summary.metadata_indexes[0];
        out.write_metadata(&mcap::read::metadata(bytes, index).unwrap())
            .unwrap();
    }
    out.finish().unwrap();
    out.into_inner().into_inner()
}

#[test]
fn missing_topics_and_metadata_are_named() {
    let bytes = to_bytes(&synthetic_demo());
    assert_eq!(
        read_bytes(&copy_without(&bytes, None, false)).unwrap(),
        synthetic_demo()
    );
    for topic in topics() {
        let err = read_bytes(&copy_without(&bytes, Some(&topic), false)).unwrap_err();
        match &err {
            DemoError::MissingTopic { topic: t, .. } => assert_eq!(t, &topic),
            other => panic!("{topic}: expected MissingTopic, got {other}"),
        }
        assert!(err.to_string().contains(&topic), "{err}");
    }
    let err = read_bytes(&copy_without(&bytes, None, true)).unwrap_err();
    assert!(matches!(err, DemoError::MissingMetadata { .. }), "{err}");
}

#[test]
fn bad_message_payloads_name_topic_keyframe_and_field() {
    let mut demo = synthetic_demo();
    demo.keyframes[1].views.get_mut("front").unwrap().raw = b"not a png".to_vec();
    let err = read_bytes(&to_bytes(&demo)).unwrap_err().to_string();
    assert!(
        err.contains("/camera/front keyframe 1") && err.contains("field data") && err.contains("PNG"),
        "{err}"
    );
}

fn small_task(kind: SubtaskKind, obst: u8, embodiment: Embodiment) -> TaskConfig {
    TaskConfig::single(kind, 3, obst, 0, embodiment)
}

fn record_bytes(config: &TaskConfig) -> (Vec<u8>, nesy_sim::demo::Recording) {
    let scene = config.generate().unwrap().scene;
    let options = RecordOptions {
        image_size: 48,
        render_threads: 1,
        scenario_id: Some("test".into()),
        side: Some("source".into()),
        target_scene: Some(scene.clone()),
    };
    let recording = nesy_sim::demo::record_scene(&scene, &options).unwrap();
    (to_bytes(&recording.demo), recording)
}

#[test]
fn recording_is_deterministic_and_complete() {
    let config = small_task(SubtaskKind::Sweep, 0, Embodiment::Finger);
    let (first, recording) = record_bytes(&config);
    assert!(
        recording.full_success(),
        "{:?} {:?}",
        recording.expert_error,
        recording.outcome
    );
    let demo = &recording.demo;
    // Keyframe 0 plus one per completed action call.
    let actions = demo.keyframes.iter().filter(|k| k.action.is_some()).count();
    assert_eq!(actions + 1, demo.keyframes.len());
    assert!(demo.keyframes[0].action.is_none());
    for (k, frame) in demo.keyframes.iter().enumerate().skip(1) {
        let entry = frame.action.as_ref().unwrap();
        assert!(
            entry.call.is_action() && entry.result.is_ok(),
            "keyframe {k}: {entry:?}"
        );
    }
    assert!(demo.states().is_some());
    assert!(demo.metadata.objects.iter().any(|o| o == "board"));
    let (second, _) = record_bytes(&config);
    let hash = |b: &[u8]| {
        sha2::Sha256::digest(b)
            .iter()
            .map(|x| format!("{x:02x}"))
            .collect::<String>()
    };
    assert_eq!(hash(&first), hash(&second), "same scene, same demo bytes");
    let back = read_bytes(&first).unwrap();
    assert_eq!(back.metadata, demo.metadata);
    for (a, b) in back.keyframes.iter().zip(&demo.keyframes) {
        assert_eq!(
            (a.index, a.time, &a.state, &a.action),
            (b.index, b.time, &b.state, &b.action)
        );
        assert!(a.views == b.views, "keyframe {} views", a.index);
    }
    assert_eq!(back.keyframes.len(), demo.keyframes.len());
}

/// The Python interpreter that has the PyPI `mcap` package: the one the build embeds
/// (`PYO3_PYTHON`, which `scripts/install-prereqs.sh` installs it into), else one on the path.
fn python_with_mcap() -> Option<String> {
    let build = std::env::var("PYO3_PYTHON").ok();
    build.into_iter().chain(["python3".to_owned()]).find(|py| {
        std::process::Command::new(py)
            .args(["-c", "import mcap.reader"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// What the PyPI `mcap` reader finds in the file at `path`: per topic the message count,
/// the PNG images and the metadata records. `None` (after saying so) where no interpreter
/// has the package outside CI; in CI its absence fails the test.
fn python_mcap_report(path: &Path) -> Option<serde_json::Value> {
    let Some(python) = python_with_mcap() else {
        if std::env::var_os("CI").is_some() || std::env::var_os("NESY_CI").is_some() {
            panic!("CI must provide the PyPI mcap package (scripts/install-prereqs.sh installs it)");
        }
        eprintln!("SKIPPED: no PYO3_PYTHON or python3 with the PyPI `mcap` package");
        return None;
    };
    let script = r#"
import base64, json, sys
from mcap.reader import make_reader
counts, pngs, jpegs = {}, 0, 0
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f)
    meta = [m for m in reader.iter_metadata()]
    for schema, channel, message in reader.iter_messages():
        assert schema.encoding == "jsonschema" and channel.message_encoding == "json"
        body = json.loads(message.data)
        if channel.topic.startswith("/camera/"):
            assert base64.b64decode(body["data"])[:8] == b"\x89PNG\r\n\x1a\n"
            pngs += 1
        if channel.topic.startswith("/film/"):
            assert base64.b64decode(body["data"])[:3] == b"\xff\xd8\xff"
            jpegs += 1
        counts[channel.topic] = counts.get(channel.topic, 0) + 1
print(json.dumps({"counts": counts, "pngs": pngs, "jpegs": jpegs, "metadata": {m.name: m.metadata for m in meta}}))
"#;
    let out = std::process::Command::new(python)
        .args(["-c", script, path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

#[test]
fn python_mcap_reads_every_channel() {
    let config = small_task(SubtaskKind::PickPlace, 0, Embodiment::Vacuum);
    let (bytes, recording) = record_bytes(&config);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("demo.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let Some(report) = python_mcap_report(&path) else {
        return;
    };
    let n = recording.demo.keyframes.len() as u64;
    for topic in topics() {
        assert_eq!(report["counts"][&topic], n, "{topic}: {report}");
    }
    assert_eq!(report["pngs"], 6 * n);
    let meta = &report["metadata"]["nesy.demo"];
    assert_eq!(meta["embodiment"], "vacuum");
    assert_eq!(meta["keyframes"], n.to_string());
    assert!(meta["instruction"].as_str().unwrap().contains("cube"));
    let _ = (ACTION_TOPIC, STATE_TOPIC);
}

/// Runs the expert on `scene` as a policy would run: the goal monitor attached, the episode
/// finished by it. Returns the trace and the verdict.
fn expert_execution(
    scene: &nesy_sim::scene::SceneSpec,
) -> (Vec<TraceEntry>, nesy_sim::tasks::goal::EpisodeOutcome) {
    let mut sim = nesy_sim::world::Sim::new(scene).unwrap();
    let monitor = nesy_sim::tasks::goal::GoalMonitor::attach(&mut sim).unwrap();
    nesy_sim::tasks::experts::run(&mut sim, scene).unwrap();
    let outcome = monitor.finish(&mut sim);
    (nesy_sim::api::RobotApi::trace(&sim).to_vec(), outcome)
}

/// Replays `trace` filming a 64-pixel rollout at 10 fps; returns the recording and the frames.
fn replay(
    scene: &nesy_sim::scene::SceneSpec,
    trace: &[TraceEntry],
) -> (nesy_sim::demo::ExecutionRecording, Vec<Image>) {
    let options = RecordOptions {
        image_size: 48,
        render_threads: 1,
        ..RecordOptions::default()
    };
    let video = nesy_sim::demo::VideoOptions {
        size: 64,
        hold_seconds: 0.0,
        ..nesy_sim::demo::VideoOptions::default()
    };
    let (frames, received) = std::sync::mpsc::sync_channel::<nesy_sim::demo::VideoFrame>(8);
    let collector = std::thread::spawn(move || received.into_iter().map(|f| f.image).collect::<Vec<_>>());
    let recording = nesy_sim::demo::replay_execution(scene, trace, &options, Some((&video, frames))).unwrap();
    (recording, collector.join().unwrap())
}

/// Whether the caption strip along the bottom of a frame holds the caption's red text.
fn captioned(image: &Image) -> bool {
    let rows = image.height.saturating_sub(14)..image.height;
    rows.flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .any(|(x, y)| {
            let i = ((y * image.width + x) * 3) as usize;
            image.rgb[i..i + 3] == [255, 0, 0]
        })
}

#[test]
fn a_replayed_execution_is_the_execution_and_records_like_a_demo() {
    let scene = small_task(SubtaskKind::PickPlace, 0, Embodiment::Finger)
        .generate()
        .unwrap()
        .scene;
    let (trace, outcome) = expert_execution(&scene);
    let (recording, frames) = replay(&scene, &trace);
    assert_eq!(recording.divergence, None);
    let replayed = recording.outcome.as_ref().expect("the scene has goals");
    assert_eq!(replayed.achieved_sequence, outcome.achieved_sequence);
    let results =
        |o: &nesy_sim::tasks::goal::EpisodeOutcome| o.subtasks.iter().map(|s| s.result).collect::<Vec<_>>();
    assert_eq!(results(replayed), results(&outcome));
    let actions = trace
        .iter()
        .filter(|e| e.call.is_action() && e.result.is_ok())
        .count();
    assert_eq!(recording.demo.keyframes.len(), actions + 1);
    assert_eq!(recording.frames, frames.len());
    // Every frame filmed while a call was under way carries its caption; the settle after the
    // last call carries none.
    assert!(frames.len() > 20);
    assert!(captioned(&frames[frames.len() / 2]));
    assert!(!captioned(frames.last().unwrap()));

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("execution.mcap");
    // The filmed frames travel with the keyframes, on a topic of their own that the demo
    // reader skips.
    let film = mcap_format::Film {
        camera: "corner".into(),
        frames: frames
            .iter()
            .enumerate()
            .map(|(i, image)| mcap_format::FilmFrame {
                time: i as f64 / 10.0,
                jpeg: image.to_jpeg(85),
            })
            .collect(),
    };
    recording.write_mcap_file(&path, Some(&film)).unwrap();
    let back = nesy_sim::demo::read_mcap(&path).unwrap();
    assert_eq!(back.keyframes.len(), recording.demo.keyframes.len());
    assert_eq!(back.metadata.side, None);
    if let Some(report) = python_mcap_report(&path) {
        let n = recording.demo.keyframes.len() as u64;
        for topic in topics() {
            assert_eq!(report["counts"][&topic], n, "{topic}: {report}");
        }
        assert_eq!(
            report["counts"][mcap_format::film_topic("corner")],
            frames.len() as u64
        );
        assert_eq!(report["jpegs"], frames.len() as u64);
        let execution = &report["metadata"][mcap_format::EXECUTION_METADATA_NAME];
        let goals: serde_json::Value = serde_json::from_str(execution["outcome"].as_str().unwrap()).unwrap();
        assert_eq!(
            goals["achieved_sequence"],
            serde_json::json!(outcome.achieved_sequence)
        );
        assert!(execution.get("divergence").is_none(), "{execution}");
    }
}

#[test]
fn a_replay_that_gets_another_result_says_where_and_stops() {
    let scene = small_task(SubtaskKind::PickPlace, 0, Embodiment::Finger)
        .generate()
        .unwrap()
        .scene;
    let (mut trace, _) = expert_execution(&scene);
    let at = trace
        .iter()
        .position(|e| e.call.name() == "close_gripper")
        .unwrap();
    trace[at].result = Err(nesy_sim::api::ApiError::InvalidArgument {
        call: "close_gripper".into(),
        message: "recorded as refused".into(),
    });
    let (recording, _) = replay(&scene, &trace);
    let divergence = recording.divergence.expect("the replay differs");
    assert_eq!(
        (divergence.index, divergence.call.as_str()),
        (at, "close_gripper()")
    );
    assert!(
        divergence.recorded.contains("recorded as refused"),
        "{divergence:?}"
    );
    assert_eq!(divergence.replayed, r#"{"type":"none"}"#);
}

/// The committed fixture demos: name, source task, target task (see fixtures/demos/README.md).
fn fixture_tasks() -> Vec<(&'static str, TaskConfig, TaskConfig)> {
    let one = |kind, variant, obst, embodiment, in_state| TaskConfig {
        embodiment_in_state: in_state,
        ..TaskConfig::single(kind, variant, obst, 0, embodiment)
    };
    let files = nesy_sim::tasks::scenario::generate_suite();
    let composite = nesy_sim::tasks::scenario::find(&files, FIXTURE_COMPOSITE).unwrap();
    use nesy_sim::tasks::scenario::Side;
    vec![
        (
            "pick_place_obst_0to1_finger",
            one(SubtaskKind::PickPlace, 11, 0, Embodiment::Finger, false),
            one(SubtaskKind::PickPlace, 11, 1, Embodiment::Finger, false),
        ),
        (
            "put_in_hinge_obst_0to2_finger",
            one(SubtaskKind::PutInHinge, 12, 0, Embodiment::Finger, false),
            one(SubtaskKind::PutInHinge, 12, 2, Embodiment::Finger, false),
        ),
        (
            "pick_place_grip_finger_to_vacuum",
            one(SubtaskKind::PickPlace, 13, 0, Embodiment::Finger, true),
            one(SubtaskKind::PickPlace, 13, 0, Embodiment::Vacuum, true),
        ),
        (
            "composite_medium",
            composite.task(Side::Source),
            composite.task(Side::Target),
        ),
    ]
}

/// The suite scenario the medium composite fixture is recorded from.
const FIXTURE_COMPOSITE: &str = "obst_medium_00_s0";
/// Image side of the fixture demos (reduced from 384 to keep each file small).
const FIXTURE_IMAGE_SIZE: u32 = 256;

/// Re-records the fixture demos (`cargo test -p nesy-sim --test integration demo:: -- --ignored`).
#[test]
#[ignore = "rewrites fixtures/demos (about a minute)"]
fn record_fixture_demos() {
    let root = nesy_testkit::workspace_root().join("fixtures/demos");
    for (name, source, target) in fixture_tasks() {
        let source_scene = source.generate().unwrap().scene;
        let target_scene = target.generate().unwrap().scene;
        let options = RecordOptions {
            image_size: FIXTURE_IMAGE_SIZE,
            render_threads: nesy_sim::perception::render::default_threads(),
            scenario_id: Some(name.to_owned()),
            side: Some("source".into()),
            target_scene: Some(target_scene.clone()),
        };
        let recording = nesy_sim::demo::record_scene(&source_scene, &options).unwrap();
        assert!(
            recording.full_success(),
            "{name}: {:?} {}",
            recording.expert_error,
            recording.outcome.summary()
        );
        // The target must be solvable too: the expert reaches full_success on it.
        let target_run = nesy_sim::demo::run_expert(&target_scene).unwrap();
        assert!(
            target_run.full_success(),
            "{name} target: {:?} {}",
            target_run.expert_error,
            target_run.outcome.summary()
        );
        let dir = root.join(name);
        mcap_format::write_mcap_file(&recording.demo, &dir.join("demo.mcap")).unwrap();
        std::fs::write(dir.join("target.json"), target_scene.to_json_pretty() + "\n").unwrap();
    }
}

/// The committed fixture demos read, carry their target scene, and match their tasks.
#[test]
fn fixture_demos_read_and_match_their_tasks() {
    let root = nesy_testkit::workspace_root().join("fixtures/demos");
    for (name, source, target) in fixture_tasks() {
        let dir = root.join(name);
        let demo = nesy_sim::demo::read(&dir).unwrap_or_else(|e| panic!("{name}: {e}"));
        let target_scene = target.generate().unwrap().scene;
        let on_disk = nesy_sim::scene::SceneSpec::from_file(&dir.join("target.json")).unwrap();
        assert_eq!(on_disk, target_scene, "{name}: target.json is current");
        assert_eq!(demo.metadata.target_scene.as_ref(), Some(&target_scene), "{name}");
        assert_eq!(demo.metadata.instruction, source.instruction());
        assert_eq!(demo.metadata.embodiment, source.embodiment);
        assert!(demo.states().is_some() && demo.calls().is_some(), "{name}");
        assert!(demo.keyframes.len() > 4, "{name}");
        let size = std::fs::metadata(dir.join("demo.mcap")).unwrap().len();
        assert!(size < 4_000_000, "{name}: {size} bytes");
    }
}

/// The Foxglove layouts shipped for `demo.mcap` and `execution.mcap` name only topics the
/// writer publishes (the execution's also its film), so that a renamed topic cannot leave a
/// layout showing empty panels.
#[test]
fn the_foxglove_layouts_name_only_topics_a_recording_has() {
    for (name, panels_expected) in [("demo-layout.json", 5), ("execution-layout.json", 6)] {
        let mut topics = topics();
        if name.starts_with("execution") {
            topics.push(mcap_format::film_topic("corner"));
        }
        let path = nesy_testkit::workspace_root().join("assets/foxglove").join(name);
        let layout: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let panels = layout["configById"].as_object().unwrap();
        let mut named = 0;
        for (id, config) in panels {
            let topic = config["imageMode"]["imageTopic"]
                .as_str()
                .or(config["topicPath"].as_str());
            let topic = topic.unwrap_or_else(|| panic!("{name}: panel {id} shows no topic"));
            assert!(
                topics.iter().any(|t| t == topic),
                "{name}: panel {id} shows {topic}, which no recording has"
            );
            named += 1;
        }
        assert_eq!(
            named, panels_expected,
            "{name}: three views, the call and the state (and the film)"
        );
        // Every panel the mosaic places is configured, and every configured panel is placed.
        fn leaves(node: &serde_json::Value, out: &mut Vec<String>) {
            match node {
                serde_json::Value::String(id) => out.push(id.clone()),
                serde_json::Value::Object(split) => {
                    leaves(&split["first"], out);
                    leaves(&split["second"], out);
                }
                other => panic!("unexpected layout node {other}"),
            }
        }
        let mut placed = Vec::new();
        leaves(&layout["layout"], &mut placed);
        placed.sort();
        let mut configured: Vec<String> = panels.keys().cloned().collect();
        configured.sort();
        assert_eq!(placed, configured, "{name}");
    }
}
