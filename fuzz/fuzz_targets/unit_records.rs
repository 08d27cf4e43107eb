#![no_main]
//! The unit-record (JSONL) reader never panics, whatever the lines hold.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = nesy_bench::store::parse_records(std::path::Path::new("shard.jsonl"), text);
    }
});
