//! A person's demonstration seen by one camera (JPEG frames, `"embodiment": "human"`, no
//! states, no robot calls) adapted to a target seen only by a camera (one JPEG frame, the
//! object list, the robot), with the model's answers replayed from a cassette: the run ends
//! with a verified procedure and `policy.py`, and `--execute` says there is nothing to
//! execute on.
//!
//! The fixture (`fixtures/demos/camera-target/`) is made from the quick-start demo and its
//! target scene: each keyframe's front view, shrunk and saved as JPEG, stands for the camera.
//! Its cassette was recorded with the offline reference responder, which reads ground truth
//! that only the recording copy carries (the demo's states, the target's `scene.json`); the
//! committed folders hold neither, and the requests are the same. Regenerate with
//! `cargo test -p nesy-cli --test integration camera_target:: -- --ignored`.

use crate::common;

use std::path::Path;

use nesy_sim::demo::{
    CameraImages, Demo, DemoMetadata, Demonstrator, Keyframe, KeyframeViews, NESY_VERSION, NamedView,
};
use serde_json::Value;

const FIXTURE: &str = "fixtures/demos/camera-target";
const CASSETTE: &str = "fixtures/cassettes/adapt-camera-target.json";
const SOURCE: &str = "fixtures/demos/pick_place_obst_0to1_finger";
/// The rendered view that stands for the camera.
const FILMED: &str = "front";
/// The camera's view name in the fixture.
const CAMERA: &str = "camera";

/// One JPEG view named [`CAMERA`], made from `views`' [`FILMED`] view.
fn camera_view(views: &KeyframeViews) -> KeyframeViews {
    let png = &views.get(FILMED).expect("the front view").raw;
    KeyframeViews::new(vec![NamedView {
        name: CAMERA.into(),
        images: CameraImages {
            raw: nesy_testkit::jpeg_from_png(png, 1, 85),
            marked: None,
        },
    }])
}

/// Writes the demo and the target folders under `dir`; `with_truth` keeps the demo's states
/// and puts the target's `scene.json` beside its manifest (the recording copy only).
fn write_fixture(root: &Path, dir: &Path, with_truth: bool) {
    let source = nesy_sim::demo::read(root.join(SOURCE).join("demo.mcap")).unwrap();
    let demo = Demo {
        metadata: DemoMetadata {
            instruction: source.metadata.instruction.clone(),
            objects: source.metadata.objects.clone(),
            embodiment: nesy_core::Embodiment::Finger,
            demonstrator: Demonstrator::Human,
            imported_from: None,
            scenario_id: None,
            side: None,
            nesy_version: Some(NESY_VERSION.to_owned()),
            target_scene: None,
        },
        keyframes: source
            .keyframes
            .iter()
            .map(|k| Keyframe {
                index: k.index,
                time: k.time,
                views: camera_view(&k.views),
                state: if with_truth { k.state.clone() } else { None },
                action: None,
            })
            .collect(),
    };
    nesy_sim::demo::write_folder(&demo, &dir.join("demo")).unwrap();

    let scene_file = root.join(SOURCE).join("target.json");
    let scene = nesy_sim::scene::SceneSpec::from_file(&scene_file).unwrap();
    let rendered =
        nesy_pipeline::TargetInput::from_scene(scene_file.clone(), scene.clone(), scene.embodiment).unwrap();
    let target = Demo {
        metadata: DemoMetadata {
            instruction: scene.instruction.clone(),
            objects: rendered.objects.clone(),
            embodiment: scene.embodiment,
            demonstrator: Demonstrator::Robot,
            imported_from: None,
            scenario_id: None,
            side: None,
            nesy_version: Some(NESY_VERSION.to_owned()),
            target_scene: None,
        },
        keyframes: vec![Keyframe {
            index: 0,
            time: 0.0,
            views: camera_view(&KeyframeViews::new(rendered.views.clone())),
            state: None,
            action: None,
        }],
    };
    let target_dir = dir.join("target");
    nesy_sim::demo::write_folder(&target, &target_dir).unwrap();
    if with_truth {
        std::fs::copy(&scene_file, target_dir.join(nesy_pipeline::TARGET_SCENE_BESIDE)).unwrap();
    }
}

#[test]
#[ignore = "regenerates the committed camera-target fixture and its cassette"]
fn record_camera_target_fixture() {
    let root = common::workspace();
    let scratch = common::scratch();
    write_fixture(&root, scratch.path(), true);
    let cassette = root.join(CASSETTE);
    let _ = std::fs::remove_file(&cassette);
    let cassette_arg = cassette.display().to_string();
    let (code, stdout, stderr) = common::adapt(
        &scratch.path().join("demo"),
        &scratch.path().join("target"),
        "oracle",
        &scratch.path().join("run"),
        &["--states", "vlm", "--record", &cassette_arg],
    );
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    let fixture = root.join(FIXTURE);
    let _ = std::fs::remove_dir_all(&fixture);
    write_fixture(&root, &fixture, false);
}

#[test]
fn a_human_jpeg_demo_adapts_to_a_camera_target_without_a_scene() {
    let scratch = common::scratch();
    let out = scratch.path().join("run");
    let (code, stdout, stderr) = common::adapt(
        &Path::new(FIXTURE).join("demo"),
        &Path::new(FIXTURE).join("target"),
        &format!("replay:{CASSETTE}"),
        &out,
        &["--states", "vlm", "--execute", "--json"],
    );
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    let summary: Value = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}\n{stdout}"));
    assert_eq!(summary["status"], "succeeded", "{summary:#}");
    assert_eq!(summary["states"]["source"], "vlm", "{summary:#}");
    assert!(
        summary["not_executed"]
            .as_str()
            .is_some_and(|reason| reason.contains("nothing to execute on")),
        "{summary:#}"
    );
    // A verified procedure and the policy; no scene, so no execution and no scene file.
    let world: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("world_model.json")).unwrap()).unwrap();
    assert_eq!(world["verified"], true);
    let policy = std::fs::read_to_string(out.join("policy.py")).unwrap();
    assert!(policy.contains("def "), "{policy}");
    assert!(!out.join("execution.json").exists());
    assert!(!out.join("target_scene.json").exists());
    // The camera's frame is kept as it came (JPEG), and the state came from the model.
    assert!(out.join("target_camera.jpg").is_file());
    let adaptation: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("adaptation.json")).unwrap()).unwrap();
    assert!(
        adaptation["target_state"]
            .as_array()
            .is_some_and(|s| !s.is_empty()),
        "{adaptation:#}"
    );
}

#[test]
fn a_camera_target_refuses_a_person_and_observed_states() {
    let scratch = common::scratch();
    nesy_testkit::copy_tree(&common::workspace().join(FIXTURE), scratch.path());
    // Ground-truth states need a simulated scene.
    let (demo, target) = (scratch.path().join("demo"), scratch.path().join("target"));
    let (code, _, stderr) = common::adapt(
        &demo,
        &target,
        "oracle",
        &scratch.path().join("run"),
        &["--states", "observed"],
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("ground-truth"), "{stderr}");
    // A target names the robot, not a person.
    let manifest = scratch.path().join("target/manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"finger\"", "\"human\"")).unwrap();
    let (code, _, stderr) = common::adapt(
        &demo,
        &target,
        &format!("replay:{CASSETTE}"),
        &scratch.path().join("run2"),
        &[],
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("not `human`"), "{stderr}");
}
