#![no_main]
//! The run-manifest reader never panics.
use libfuzzer_sys::fuzz_target;
use nesy_bench::manifest::Manifest;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = Manifest::parse(std::path::Path::new("manifest.json"), text);
    }
});
