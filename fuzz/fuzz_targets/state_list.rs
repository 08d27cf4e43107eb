#![no_main]
//! The state-list parser: never panics; what parses round-trips through `Display`.
use libfuzzer_sys::fuzz_target;
use nesy_core::text::parse_state_list;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(state) = parse_state_list(text)
    {
        assert_eq!(parse_state_list(&state.to_string()).unwrap(), state);
    }
});
