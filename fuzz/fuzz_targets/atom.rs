#![no_main]
//! `Atom::from_str`: never panics; what parses prints back to the same atom.
use libfuzzer_sys::fuzz_target;
use nesy_core::Atom;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(atom) = text.parse::<Atom>()
    {
        assert_eq!(atom.to_string().parse::<Atom>().unwrap(), atom);
    }
});
