#![no_main]
//! Formula and effect parsers: never panic; formulas round-trip through `Display`.
use libfuzzer_sys::fuzz_target;
use nesy_core::text::{parse_effects, parse_formula};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_effects(text);
        if let Ok(f) = parse_formula(text) {
            assert_eq!(parse_formula(&f.to_string()).unwrap(), f);
        }
    }
});
