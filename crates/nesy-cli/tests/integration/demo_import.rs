//! `nesy demo import` driven as a user would: the authors' demo format imported and adapted
//! end to end, and a frames folder imported with automatic keyframes.

use crate::common;

use serde_json::Value;

#[test]
fn an_authors_format_demo_imports_and_adapts() {
    let scratch = common::scratch();
    let demo = scratch.path().join("imported").display().to_string();
    let (code, stdout, stderr) = common::run(&[
        "demo",
        "import",
        "fixtures/demos/authors-format/episode_0",
        "--out",
        &demo,
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stdout.contains("imported 9 keyframe(s) of 9 frame(s), views top, front, back"),
        "{stdout}"
    );
    assert!(stdout.contains("contact_sheet.png"), "{stdout}");

    let out = scratch.path().join("run").display().to_string();
    let (code, stdout, stderr) = common::run(&[
        "adapt",
        "--demo",
        &demo,
        "--target",
        "fixtures/demos/adapt-realstyle/target.json",
        "--vlm",
        "oracle",
        "--states",
        "observed",
        "--codegen",
        "template",
        "--execute",
        "--out",
        &out,
        "--json",
    ]);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    let summary: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["status"], "succeeded", "{stdout}");
}

#[test]
fn a_frames_folder_imports_with_automatic_keyframes() {
    let scratch = common::scratch();
    let frames = scratch.path().join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    // The quick-start demo's front view (the top one hides the fingers under the arm), each
    // keyframe held for half a second at 10 fps.
    let source = nesy_sim::demo::read(common::workspace().join("fixtures/demos/adapt-realstyle")).unwrap();
    let mut i = 0;
    for keyframe in &source.keyframes {
        for _ in 0..5 {
            std::fs::write(
                frames.join(format!("{i:05}.png")),
                &keyframe.views.get("front").unwrap().raw,
            )
            .unwrap();
            i += 1;
        }
    }
    let out = scratch.path().join("imported").display().to_string();
    let frames = frames.display().to_string();
    let base = [
        "demo",
        "import",
        &frames,
        "--out",
        &out,
        "--keyframes",
        "auto",
        "--instruction",
        "Put the cylinder away.",
        "--objects",
        "red_cylinder, drawer_body",
    ];
    let (code, _, stderr) = common::run(&base);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("--fps"), "{stderr}");

    let mut args = base.to_vec();
    args.extend(["--fps", "10", "--json"]);
    let (code, stdout, stderr) = common::run(&args);
    assert_eq!(code, Some(0), "{stderr}");
    let report: Value = serde_json::from_str(&stdout).unwrap();
    let times: Vec<f64> = report["keyframes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k["time"].as_f64().unwrap())
        .collect();
    let expected: Vec<f64> = (0..source.keyframes.len()).map(|k| 0.5 * k as f64).collect();
    assert_eq!(times, expected);
    let manifest: Value = serde_json::from_str(
        &std::fs::read_to_string(scratch.path().join("imported/manifest.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(manifest["embodiment"], "human");
    assert_eq!(
        manifest["objects"],
        serde_json::json!(["red_cylinder", "drawer_body"])
    );
    assert_eq!(manifest["imported_from"]["keyframes"], "auto");
}

#[test]
fn a_video_imports_with_automatic_keyframes_by_default() {
    let scratch = common::scratch();
    let out = scratch.path().join("imported").display().to_string();
    let (code, stdout, stderr) = common::run(&[
        "demo",
        "import",
        "fixtures/demos/video/held-keyframes.mp4",
        "--out",
        &out,
        "--instruction",
        "Place all cylinder blocks in the prismatic drawer.",
        "--objects",
        "red_cylinder,drawer_body",
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stdout.contains("imported 9 keyframe(s) of 45 frame(s), views camera"),
        "{stdout}"
    );
    assert!(
        stdout.contains("0.00 0.50 1.00 1.50 2.00 2.50 3.00 3.50 4.00"),
        "{stdout}"
    );
}
