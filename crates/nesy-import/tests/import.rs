//! Imports of real-world layouts, built from the quick-start demo's own pictures: a frames
//! folder in which each keyframe is held still for a while (as a person pauses between
//! steps), and the same demo in the authors' format. The imported demos read back as nesy
//! demos with the original views, states and objects.

use std::path::{Path, PathBuf};

use nesy_import::{CONTACT_SHEET_FILE, ImportError, ImportOptions, KeyframeMode, SourceKind, import};
use nesy_sim::demo::{Demo, Demonstrator, read, read_folder};

fn quickstart() -> Demo {
    read(nesy_testkit::workspace_root().join("fixtures/demos/adapt-realstyle")).unwrap()
}

/// The demo's keyframes as a frames folder at `fps`, each held for `hold` frames, with the
/// given views (`DIR/<view>/frame_<i>.png`).
fn held_frames(demo: &Demo, views: &[&str], hold: usize, dir: &Path) {
    for view in views {
        std::fs::create_dir_all(dir.join(view)).unwrap();
    }
    let mut i = 0;
    for keyframe in &demo.keyframes {
        for _ in 0..hold {
            for view in views {
                let bytes = &keyframe.views.get(view).unwrap().raw;
                std::fs::write(dir.join(view).join(format!("frame_{i}.png")), bytes).unwrap();
            }
            i += 1;
        }
    }
}

fn options(keyframes: KeyframeMode, fps: Option<f64>) -> ImportOptions {
    ImportOptions {
        keyframes,
        fps,
        instruction: Some("Put the cylinder in the drawer.".into()),
        objects: Some(vec!["red_cylinder".into(), "drawer".into()]),
        ..ImportOptions::default()
    }
}

#[test]
fn auto_finds_every_held_keyframe_of_a_frames_folder() {
    let demo = quickstart();
    let scratch = tempfile::tempdir().unwrap();
    let frames = scratch.path().join("frames");
    held_frames(&demo, &["top", "front"], 6, &frames);
    let out = scratch.path().join("imported");
    let report = import(&frames, &out, &options(KeyframeMode::Auto, Some(10.0))).unwrap();
    assert_eq!(report.kind, SourceKind::Frames);
    assert_eq!(report.views, ["top", "front"]);
    assert_eq!(report.frames, 6 * demo.keyframes.len());
    let frames_found: Vec<usize> = report.keyframes.iter().map(|k| k.frame).collect();
    let expected: Vec<usize> = (0..demo.keyframes.len()).map(|k| 6 * k).collect();
    assert_eq!(
        frames_found, expected,
        "one keyframe where each held picture begins"
    );

    let imported = read_folder(&out).unwrap();
    assert_eq!(imported.metadata.demonstrator, Demonstrator::Human);
    assert_eq!(imported.keyframes.len(), demo.keyframes.len());
    for (k, (mine, theirs)) in imported.keyframes.iter().zip(&demo.keyframes).enumerate() {
        assert_eq!(
            mine.views.get("top").unwrap().raw,
            theirs.views.get("top").unwrap().raw,
            "keyframe {k}"
        );
        assert!((mine.time - 0.6 * k as f64).abs() < 1e-9);
        assert!(mine.state.is_none());
    }
    let record = imported.metadata.imported_from.unwrap();
    assert_eq!(record["keyframes"], "auto");
    assert_eq!(record["chosen"].as_array().unwrap().len(), demo.keyframes.len());
    let sheet = std::fs::read(out.join(CONTACT_SHEET_FILE)).unwrap();
    assert_eq!(
        nesy_sim::demo::image_size(&sheet).map(|(w, _)| w),
        Some(4 * 246 + 6)
    );
}

#[test]
fn manual_modes_and_bad_folders() {
    let demo = quickstart();
    let scratch = tempfile::tempdir().unwrap();
    let frames = scratch.path().join("frames");
    held_frames(&demo, &["top"], 2, &frames);
    let single = scratch.path().join("single");
    std::fs::create_dir_all(&single).unwrap();
    for entry in std::fs::read_dir(frames.join("top")).unwrap().flatten() {
        std::fs::copy(entry.path(), single.join(entry.file_name())).unwrap();
    }

    // Frames directly in the folder: one view, named `camera`.
    let out = scratch.path().join("every");
    let report = import(&single, &out, &options(KeyframeMode::Every(0.4), Some(5.0))).unwrap();
    assert_eq!(report.views, ["camera"]);
    assert_eq!(report.keyframes.len(), demo.keyframes.len());
    let out = scratch.path().join("at");
    let report = import(&single, &out, &options("at:0,1.2,2".parse().unwrap(), Some(5.0))).unwrap();
    assert_eq!(
        report.keyframes.iter().map(|k| k.frame).collect::<Vec<_>>(),
        [0, 6, 10]
    );

    let refuse = |result: Result<_, ImportError>, expected: &[&str]| {
        let message = result.unwrap_err().to_string();
        for part in expected {
            assert!(message.contains(part), "{message}");
        }
    };
    // Not empty, no frame rate, no instruction.
    refuse(
        import(&single, &out, &options(KeyframeMode::All, None)),
        &["not empty"],
    );
    let fresh = |name: &str| scratch.path().join(name);
    refuse(
        import(&single, &fresh("a"), &options(KeyframeMode::Auto, None)),
        &["--fps"],
    );
    let untold = ImportOptions {
        instruction: None,
        ..options(KeyframeMode::All, None)
    };
    refuse(import(&single, &fresh("b"), &untold), &["--instruction"]);
    // A frame of another size names the file.
    std::fs::write(single.join("frame_3.png"), nesy_testkit::png(8, 1)).unwrap();
    refuse(
        import(&single, &fresh("c"), &options(KeyframeMode::All, None)),
        &["frame_3.png", "8x8"],
    );
    // A view with fewer frames names its folder.
    std::fs::remove_file(frames.join("top/frame_3.png")).unwrap();
    std::fs::create_dir_all(frames.join("front")).unwrap();
    std::fs::copy(frames.join("top/frame_0.png"), frames.join("front/frame_0.png")).unwrap();
    refuse(
        import(&frames, &fresh("d"), &options(KeyframeMode::All, None)),
        &["front", "expected"],
    );
    // Nothing changes: auto finds one keyframe and says what to do.
    let still = fresh("still");
    std::fs::create_dir_all(&still).unwrap();
    for i in 0..10 {
        std::fs::copy(frames.join("top/frame_0.png"), still.join(format!("f{i}.png"))).unwrap();
    }
    refuse(
        import(&still, &fresh("e"), &options(KeyframeMode::Auto, Some(10.0))),
        &["1 keyframe", "every:SECONDS"],
    );
}

/// The bundled demo in the authors' layout (the quick-start demo, written by
/// `regenerate_the_authors_format_fixture`).
const AUTHORS_FIXTURE: &str = "fixtures/demos/authors-format/episode_0";

/// Writes `demo` in the authors' layout: data.json and `frames/<view>[_marked]/frame_<i>.jpg`
/// (their frames are JPEG; these hold the quick-start demo's pictures at a third of their
/// size, re-encoded).
fn authors_folder(demo: &Demo, dir: &Path) -> PathBuf {
    let states: Vec<Vec<String>> = demo
        .keyframes
        .iter()
        .map(|k| k.state.as_ref().unwrap().iter().map(|a| a.to_string()).collect())
        .collect();
    let data = serde_json::json!({
        "instruction": demo.metadata.instruction,
        "objects": demo.metadata.objects,
        "object_states": states,
        "additional_context": "None",
    });
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("data.json"),
        serde_json::to_string_pretty(&data).unwrap(),
    )
    .unwrap();
    for keyframe in &demo.keyframes {
        for view in keyframe.views.iter() {
            for (suffix, bytes) in [
                ("", Some(&view.images.raw)),
                ("_marked", view.images.marked.as_ref()),
            ] {
                let Some(bytes) = bytes else { continue };
                let folder = dir.join("frames").join(format!("{}{suffix}", view.name));
                std::fs::create_dir_all(&folder).unwrap();
                std::fs::write(
                    folder.join(format!("frame_{}.jpg", keyframe.index)),
                    jpeg_of(bytes),
                )
                .unwrap();
            }
        }
    }
    dir.to_owned()
}

fn jpeg_of(png: &[u8]) -> Vec<u8> {
    nesy_testkit::jpeg_from_png(png, 3, 85)
}

/// Rewrites the bundled authors'-format fixture from the quick-start demo:
/// `NESY_UPDATE_FIXTURES=1 cargo test -p nesy-import --test import -- --ignored`.
#[test]
#[ignore = "rewrites a committed fixture"]
fn regenerate_the_authors_format_fixture() {
    if std::env::var_os("NESY_UPDATE_FIXTURES").is_none() {
        return;
    }
    let dir = nesy_testkit::workspace_root().join(AUTHORS_FIXTURE);
    let _ = std::fs::remove_dir_all(&dir);
    authors_folder(&quickstart(), &dir);
}

#[test]
fn the_authors_format_imports_with_its_states() {
    let demo = quickstart();
    let scratch = tempfile::tempdir().unwrap();
    let source = scratch.path().join("episode_0");
    nesy_testkit::copy_tree(&nesy_testkit::workspace_root().join(AUTHORS_FIXTURE), &source);
    let out = scratch.path().join("imported");
    let report = import(&source, &out, &ImportOptions::default()).unwrap();
    assert_eq!(report.kind, SourceKind::Authors);
    assert_eq!(report.views, ["top", "front", "back"]);
    let imported = read_folder(&out).unwrap();
    assert_eq!(imported.metadata.instruction, demo.metadata.instruction);
    assert_eq!(imported.metadata.objects, demo.metadata.objects);
    assert_eq!(imported.states(), demo.states());
    let first = imported.keyframes[0].views.get("top").unwrap();
    assert!(first.marked.is_some());
    assert_eq!(
        nesy_sim::demo::ImageFormat::of(&first.raw),
        Some(nesy_sim::demo::ImageFormat::Jpeg)
    );
    assert_eq!(nesy_sim::demo::image_size(&first.raw), Some((128, 128)));

    // Only `all` fits a format that holds keyframes only; a missing frame is named.
    let message = import(
        &source,
        &scratch.path().join("x"),
        &options(KeyframeMode::Auto, Some(1.0)),
    )
    .unwrap_err()
    .to_string();
    assert!(message.contains("--keyframes all"), "{message}");
    std::fs::remove_file(source.join("frames/front/frame_4.jpg")).unwrap();
    let message = import(&source, &scratch.path().join("y"), &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("frames/front/frame_4.jpg") && message.contains("no such file"),
        "{message}"
    );
}

/// The bundled video: the quick-start demo's front view at 10 fps, each keyframe held for
/// half a second (written by `regenerate_the_video_fixture`).
const VIDEO_FIXTURE: &str = "fixtures/demos/video/held-keyframes.mp4";

/// The quick-start demo's front view, each keyframe held for `hold` frames.
fn held_front_view(demo: &Demo, hold: usize) -> Vec<nesy_sim::perception::render::Image> {
    let mut frames = Vec::new();
    for keyframe in &demo.keyframes {
        let picture = nesy_import::decode(&keyframe.views.get("front").unwrap().raw).unwrap();
        for _ in 0..hold {
            frames.push(picture.clone());
        }
    }
    frames
}

/// Rewrites the bundled video fixture:
/// `NESY_UPDATE_FIXTURES=1 cargo test -p nesy-import --test import -- --ignored`.
#[test]
#[ignore = "rewrites a committed fixture"]
fn regenerate_the_video_fixture() {
    if std::env::var_os("NESY_UPDATE_FIXTURES").is_none() {
        return;
    }
    let path = nesy_testkit::workspace_root().join(VIDEO_FIXTURE);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    nesy_import::write_mp4(&path, &held_front_view(&quickstart(), 5), 10.0).unwrap();
}

/// The bundled H.264 MP4 (the quick-start demo's front view at 10 fps, each keyframe held
/// for half a second), imported with `auto`: every keyframe is found where its picture
/// begins, through the encoder's and the decoder's losses. Written again here, the video
/// imports the same way.
#[test]
fn a_video_imports_with_automatic_keyframes() {
    let demo = quickstart();
    let scratch = tempfile::tempdir().unwrap();
    let frames = held_front_view(&demo, 5);
    let written = scratch.path().join("demo.mp4");
    nesy_import::write_mp4(&written, &frames, 10.0).unwrap();
    let again = import(
        &written,
        &scratch.path().join("again"),
        &options(KeyframeMode::Auto, None),
    )
    .unwrap();
    let video = nesy_testkit::workspace_root().join(VIDEO_FIXTURE);

    let out = scratch.path().join("imported");
    let report = import(&video, &out, &options(KeyframeMode::Auto, None)).unwrap();
    assert_eq!(report.kind, SourceKind::Video);
    assert_eq!(report.frames, frames.len());
    let times: Vec<f64> = report.keyframes.iter().map(|k| k.time).collect();
    let expected: Vec<f64> = (0..demo.keyframes.len()).map(|k| 0.5 * k as f64).collect();
    assert_eq!(times, expected);
    assert_eq!(again.keyframes, report.keyframes);
    let imported = read_folder(&out).unwrap();
    assert_eq!(
        imported.keyframes[0].views.names().collect::<Vec<_>>(),
        ["camera"]
    );
    assert_eq!(
        nesy_sim::demo::image_size(&imported.keyframes[3].views.get("camera").unwrap().raw),
        Some((384, 384))
    );

    // A truncated file and a file that is no video are refused by name, without a panic.
    let bytes = std::fs::read(&video).unwrap();
    for (name, data) in [
        ("cut.mp4", &bytes[..bytes.len() / 2]),
        ("text.mp4", &b"not a video at all"[..]),
    ] {
        let path = scratch.path().join(name);
        std::fs::write(&path, data).unwrap();
        let message = import(
            &path,
            &scratch.path().join(format!("out-{name}")),
            &options(KeyframeMode::All, None),
        )
        .unwrap_err()
        .to_string();
        assert!(message.contains(name), "{message}");
    }
}
