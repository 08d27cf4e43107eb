#![no_main]
//! Decoding a policy file's bytes never panics; what decodes as UTF-8 without a coding line
//! comes back unchanged.
use libfuzzer_sys::fuzz_target;
use nesy_policy::decode_policy_source;

fuzz_target!(|data: &[u8]| {
    let decoded = decode_policy_source(data);
    if let (Ok(text), Ok(original)) = (&decoded, std::str::from_utf8(data)) {
        if !original.starts_with('\u{feff}') && !original.contains("coding") {
            assert_eq!(text, original);
        }
    }
});
