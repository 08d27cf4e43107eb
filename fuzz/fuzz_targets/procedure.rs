#![no_main]
//! Action blocks and procedures: never panic; what parses round-trips through printing.
use libfuzzer_sys::fuzz_target;
use nesy_core::format_procedure;
use nesy_core::text::{parse_action_block, parse_procedure};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_action_block(text);
        if let Ok(ops) = parse_procedure(text) {
            assert_eq!(parse_procedure(&format_procedure(&ops)).unwrap(), ops);
        }
    }
});
