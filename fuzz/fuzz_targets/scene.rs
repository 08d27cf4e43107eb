#![no_main]
//! The scene reader never panics, and a scene it accepts passes its own validation again
//! after a write and re-read.
use libfuzzer_sys::fuzz_target;
use nesy_sim::scene::SceneSpec;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(scene) = SceneSpec::from_json_str(text, "fuzz.json") {
            let again = serde_json::to_string(&scene).unwrap();
            SceneSpec::from_json_str(&again, "fuzz-again.json").unwrap();
        }
    }
});
