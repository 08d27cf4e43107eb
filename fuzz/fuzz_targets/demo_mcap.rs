#![no_main]
//! The MCAP demonstration reader never panics on any bytes.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = nesy_sim::demo::read_mcap_bytes(data, std::path::Path::new("fuzz.mcap"));
});
