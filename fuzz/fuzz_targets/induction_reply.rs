#![no_main]
//! The operator-induction reply parser never panics.
use libfuzzer_sys::fuzz_target;
use nesy_core::text::parse_induction_reply;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = parse_induction_reply(text);
    }
});
