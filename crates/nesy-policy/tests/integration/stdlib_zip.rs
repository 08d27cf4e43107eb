//! The standard-library zip of static builds covers the runtime. The check script
//! (`scripts/static/check_stdlib_zip.py`) builds the zip the way `scripts/build-static.sh`
//! does and runs the static checker and the numpy subset with nothing but that zip on
//! `sys.path`. A module the runtime's Python starts to import and the zip lacks would
//! otherwise only show up as a `ModuleNotFoundError` in a static binary; this catches it in a
//! normal `cargo test`.

use std::path::PathBuf;
use std::process::Command;

/// The workspace root, where the scripts live.
fn root() -> PathBuf {
    nesy_testkit::workspace_root()
}

/// The interpreter the build embeds: `PYO3_PYTHON` (which `.cargo/config.toml` points at
/// `scripts/system-python` for every process cargo runs), else that script itself, so the
/// zip is built and used by the same CPython version these tests link.
fn python() -> PathBuf {
    std::env::var_os("PYO3_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("scripts/system-python"))
}

/// Runs the check script (a second or so) and fails with its report when the zip misses
/// something the runtime imports.
#[test]
fn stdlib_zip_covers_the_runtime() {
    let script = root().join("scripts/static/check_stdlib_zip.py");
    let output = Command::new(python())
        .arg(&script)
        .current_dir(root())
        .output()
        .expect("run scripts/static/check_stdlib_zip.py");
    assert!(
        output.status.success(),
        "{} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        script.display(),
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}
