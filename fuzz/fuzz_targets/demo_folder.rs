#![no_main]
//! The demo-folder reader never panics on any `manifest.json`: the frames are a real demo's
//! (the bundled MCAP fixture, written out once as a folder), the manifest is the input.
use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use nesy_sim::demo::{read_folder, read_mcap, write_folder};

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/demos/adapt-realstyle/demo.mcap");

fn folder() -> &'static PathBuf {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("nesy-fuzz-demo-folder-{}", std::process::id()));
        let demo = read_mcap(std::path::Path::new(FIXTURE)).unwrap();
        write_folder(&demo, &dir).unwrap();
        // The real manifest, kept beside the one each input overwrites: a seed for the corpus.
        std::fs::copy(dir.join("manifest.json"), dir.join("manifest.orig.json")).unwrap();
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let dir = folder();
    std::fs::write(dir.join("manifest.json"), data).unwrap();
    let _ = read_folder(dir);
});
