//! What the integration tests share: running the binary, reading its output and its files.

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `arlpcg` binary with `args` and waits for it.
pub fn arlpcg(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// What a run printed on stderr.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `arlpcg args`, which must succeed (the failure shows its stderr).
pub fn arlpcg_ok(args: &[&str]) -> Output {
    let output = arlpcg(args);
    assert!(
        output.status.success(),
        "arlpcg {}: {}",
        args.join(" "),
        stderr(&output)
    );
    output
}

/// The `results.json` an `eval` wrote into `dir`.
pub fn results_json(dir: &Path) -> serde_json::Value {
    let path = dir.join("results.json");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
