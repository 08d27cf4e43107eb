#![no_main]
//! The plan parser never panics.
use libfuzzer_sys::fuzz_target;
use nesy_core::pddl::parse_plan;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_plan(text);
    }
});
