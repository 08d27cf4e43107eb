#![no_main]
//! The vocabulary-file reader never panics: any text is a vocabulary or an error naming its
//! line and field.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = nesy_core::parse_vocabulary_file(text);
    }
});
