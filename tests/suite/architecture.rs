//! The layering docs/architecture.md describes, checked on the source: the core (levels, games,
//! learning, training, evaluation, verification, generation) reads no clock, prints nothing,
//! uses no global random generator and knows nothing of the shells above it, so the same inputs
//! give the same bytes.

use std::path::{Path, PathBuf};

/// The core's files and folders, under `src/`.
const CORE: &[&str] = &[
    "level",
    "game",
    "rl",
    "train",
    "eval",
    "verify.rs",
    "generation.rs",
    "difficulty.rs",
    "seeds.rs",
    "onnx",
    "panel.rs",
    "rating.rs",
    "bootstrap.rs",
];

/// What the core may not name, and why.
const FORBIDDEN: &[(&str, &str)] = &[
    ("Instant", "reads the clock"),
    ("SystemTime", "reads the clock"),
    ("println!", "prints"),
    ("print!", "prints"),
    ("eprint", "prints"),
    ("stdout()", "prints"),
    ("stderr()", "prints"),
    ("thread_rng", "uses a global RNG"),
    ("rand::rng()", "uses a global RNG"),
    ("ctrlc", "handles signals (the shell's job)"),
    ("indicatif", "draws progress (the shell's job)"),
    ("crate::shell", "reaches up into the shells"),
    ("crate::cli", "reaches up into the shells"),
    ("crate::commands", "reaches up into the shells"),
    ("crate::design", "reaches up into the designer"),
    ("ratatui", "draws on a terminal"),
];

fn rust_files(path: &Path, into: &mut Vec<PathBuf>) {
    if path.is_dir() {
        for entry in std::fs::read_dir(path).unwrap() {
            rust_files(&entry.unwrap().path(), into);
        }
    } else if path.extension().is_some_and(|e| e == "rs") {
        into.push(path.to_path_buf());
    }
}

#[test]
fn the_core_reads_no_clock_prints_nothing_and_knows_no_shell() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    for part in CORE {
        rust_files(&src.join(part), &mut files);
    }
    assert!(
        files.len() > 40,
        "the core's files are found ({})",
        files.len()
    );
    let mut problems = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        // Unit tests may print what they measure.
        let code = text.split("#[cfg(test)]").next().unwrap();
        for (number, line) in code.lines().enumerate() {
            let line = line.trim_start();
            if line.starts_with("//") {
                continue;
            }
            for (name, why) in FORBIDDEN {
                if line.contains(name) {
                    problems.push(format!(
                        "{}:{}: `{name}` {why}",
                        file.strip_prefix(&src).unwrap().display(),
                        number + 1
                    ));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "the core must stay pure:\n{}",
        problems.join("\n")
    );
}
