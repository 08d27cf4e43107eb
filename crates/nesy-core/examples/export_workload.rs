//! Writes the benchmark workloads as JSON for `scripts/bench_py_executor.py`, so that the
//! Python executor measures exactly the inputs the criterion benches measure.
//!
//! Usage: `cargo run -p nesy-core --example export_workload -- workload.json`

#[path = "../benches/workload/mod.rs"]
mod workload;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: export_workload OUT.json")?;
    let json = serde_json::json!({
        "state_200": workload::state_200(),
        "operator_20": workload::operator_20(),
        "procedure_116": workload::procedure_116(),
        "goal_116": workload::goal_116(),
    });
    std::fs::write(&path, serde_json::to_string_pretty(&json)?)?;
    eprintln!("wrote {path}");
    Ok(())
}
