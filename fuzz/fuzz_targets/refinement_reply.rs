#![no_main]
//! The refinement reply parser never panics; parsed patches print and parse back.
use libfuzzer_sys::fuzz_target;
use nesy_core::text::parse_refinement_reply;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(reply) = parse_refinement_reply(text)
    {
        for patch in &reply.patches {
            let again = parse_refinement_reply(&patch.to_string()).unwrap();
            assert_eq!(&again.patches[0], patch);
        }
    }
});
