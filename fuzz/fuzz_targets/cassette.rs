#![no_main]
//! The cassette reader never panics.
use libfuzzer_sys::fuzz_target;
use nesy_vlm::CassetteFile;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = CassetteFile::parse(std::path::Path::new("fuzz.json"), text);
    }
});
