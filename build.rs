//! Records which code the binary is built from (`ARLPCG_COMMIT`), for the cards of the policies
//! it trains: the last commit that changed the code (src/, crates/, Cargo.toml, Cargo.lock,
//! build.rs), `-dirty` when the code differs from it, "unknown" outside a git checkout.
//!
//! Only the code decides the value, so a commit that touches only docs or results leaves it as
//! it was, and nothing is rebuilt: the script reruns when the code or the branch moves, and
//! cargo recompiles only when what it prints changes.

use std::process::Command;

const CODE: [&str; 5] = ["src", "crates", "Cargo.toml", "Cargo.lock", "build.rs"];

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let mut log = vec!["log", "-1", "--format=%h", "--abbrev=7", "--"];
    log.extend(CODE);
    let commit = git(&log).filter(|c| !c.is_empty());
    let mut status = vec!["status", "--porcelain", "--"];
    status.extend(CODE);
    let dirty = git(&status).is_some_and(|changes| !changes.is_empty());
    let described = match commit {
        Some(c) if dirty => format!("{c}-dirty"),
        Some(c) => c,
        None => "unknown".into(),
    };
    println!("cargo:rustc-env=ARLPCG_COMMIT={described}");
    for path in [".git/HEAD", ".git/refs/heads", ".git/packed-refs"]
        .into_iter()
        .chain(CODE)
    {
        println!("cargo:rerun-if-changed={path}");
    }
}
