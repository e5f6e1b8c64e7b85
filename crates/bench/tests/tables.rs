//! docs/benchmarks.md's tables are the ones `docs/benchmarks/tables.py` makes from the raw
//! results in `docs/benchmarks/data/`.

use std::path::Path;
use std::process::Command;

#[test]
fn the_benchmark_tables_match_their_data() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/benchmarks/tables.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg("--check")
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
