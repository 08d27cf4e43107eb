#![no_main]
//! PDDL domain and problem parsers never panic; parsed domains round-trip.
use libfuzzer_sys::fuzz_target;
use nesy_core::pddl::{parse_domain, parse_problem};

const BLOCKSWORLD: &str = include_str!("../../fixtures/pddl/blocksworld/domain.pddl");

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(d) = parse_domain(text) {
            assert_eq!(parse_domain(&d.to_string()).unwrap(), d);
        }
        let domain = parse_domain(BLOCKSWORLD).unwrap();
        let _ = parse_problem(text, &domain);
    }
});
