//! Computes the simulator's fingerprint: a hash of every source file of the crate and of the
//! robot models it embeds. Recorded demonstrations are keyed by it, so a changed simulator
//! never silently reuses demos recorded by an older one.

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// FNV-1a over 64 bits, run twice with different offsets for 128 bits of key: enough to
/// tell builds apart (this is a cache key, not a security boundary).
fn fnv(seed: u64, bytes: &[u8], mut h: u64) -> u64 {
    h ^= seed;
    for b in bytes {
        h = (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01B3);
    }
    h
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let mut list = Vec::new();
    for dir in [root.join("src"), root.join("../../assets/robots")] {
        println!("cargo:rerun-if-changed={}", dir.display());
        files(&dir, &mut list);
    }
    list.sort();
    let (mut a, mut b) = (0xCBF2_9CE4_8422_2325_u64, 0x8422_2325_CBF2_9CE4_u64);
    for path in &list {
        let rel = path
            .strip_prefix(&root)
            .unwrap_or(path)
            .to_string_lossy()
            .replace('\\', "/");
        let bytes = std::fs::read(path).unwrap_or_default();
        a = fnv(1, rel.as_bytes(), a);
        a = fnv(2, &bytes, a);
        b = fnv(3, &bytes, b);
        b = fnv(4, rel.as_bytes(), b);
    }
    println!(
        "cargo:rustc-env=NESY_SIM_FINGERPRINT={}-{a:016x}{b:016x}",
        std::env::var("CARGO_PKG_VERSION").unwrap_or_default()
    );
}
