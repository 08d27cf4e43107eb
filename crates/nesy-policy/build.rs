//! Precompiles the runtime's own Python sources (the static checker and the numpy subset)
//! to marshalled code objects with the interpreter pyo3 builds against, so a worker does not
//! spend its start-up compiling them. If no interpreter can be run, the runtime compiles the
//! sources at start-up instead (same behaviour, slower).

use std::path::PathBuf;
use std::process::Command;

const SOURCES: [&str; 2] = ["checker", "numpy_shim"];

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    println!("cargo:rerun-if-env-changed=PYO3_PYTHON");
    println!("cargo:rerun-if-env-changed=PYO3_CONFIG_FILE");
    let python = std::env::var("PYO3_PYTHON").unwrap_or_else(|_| "python3".to_owned());
    for name in SOURCES {
        let source = PathBuf::from(format!("src/python/{name}.py"));
        println!("cargo:rerun-if-changed={}", source.display());
        let target = out.join(format!("{name}.marshal"));
        let script = "import marshal, sys; src = open(sys.argv[1], encoding='utf-8').read(); \
                      open(sys.argv[2], 'wb').write(marshal.dumps(compile(src, sys.argv[3], 'exec', dont_inherit=True)))";
        let label = if name == "checker" {
            "<nesy-checker>"
        } else {
            "<numpy-subset>"
        };
        let ok = Command::new(&python)
            .args(["-I", "-S", "-c", script])
            .arg(&source)
            .arg(&target)
            .arg(label)
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            // An empty file tells the runtime to compile from source.
            std::fs::write(&target, b"").expect("write to OUT_DIR");
            println!(
                "cargo:warning=could not precompile {name}.py with {python}; it will be compiled at start-up"
            );
        }
    }
}
