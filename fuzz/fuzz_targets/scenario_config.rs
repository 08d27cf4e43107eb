#![no_main]
//! The scenario-configuration reader never panics; what it accepts round-trips.
use libfuzzer_sys::fuzz_target;
use nesy_sim::tasks::scenario::ConfigFile;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(config) = ConfigFile::from_json_str(text, "fuzz.json") {
            ConfigFile::from_json_str(&config.to_json_pretty(), "fuzz-again.json").unwrap();
        }
    }
});
