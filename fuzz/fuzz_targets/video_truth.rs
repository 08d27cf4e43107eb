#![no_main]
//! The reader of a demonstration video's ground truth (`demo.video.json`) never panics.
use libfuzzer_sys::fuzz_target;
use nesy_sim::demo::VideoTruth;

fuzz_target!(|data: &[u8]| {
    let _ = VideoTruth::parse(std::path::Path::new("demo.video.json"), data);
});
