//! The layering docs/architecture.md describes, checked on the source: the core (levels, games,
//! learning, training, evaluation, verification, generation) reads no clock, prints nothing,
//! uses no global random generator and knows nothing of the shells above it, so the same inputs
//! give the same bytes; and no function grows past 120 lines.

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
    ("std::env::args", "reads the command line (the shell's job)"),
    ("std::env::var", "reads the environment (the shell's job)"),
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

/// The longest a function may be, in lines (signature to closing brace).
const MAX_FUNCTION_LINES: usize = 120;

/// Lines from each `fn` to its closing brace; braces inside strings count too, which in this
/// code always pair up.
fn function_lengths(text: &str) -> Vec<(usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let is_fn = |line: &str| {
        let mut rest = line.trim_start();
        for prefix in [
            "pub(crate) ",
            "pub(super) ",
            "pub ",
            "const ",
            "async ",
            "unsafe ",
        ] {
            rest = rest.strip_prefix(prefix).unwrap_or(rest);
        }
        rest.starts_with("fn ")
    };
    let mut found = Vec::new();
    for start in (0..lines.len()).filter(|&i| is_fn(lines[i])) {
        let (mut depth, mut opened) = (0i64, false);
        for (k, line) in lines[start..].iter().enumerate() {
            opened |= line.contains('{');
            depth += line.matches('{').count() as i64 - line.matches('}').count() as i64;
            if opened && depth <= 0 {
                found.push((start + 1, k + 1));
                break;
            }
            if !opened && line.trim_end().ends_with(';') {
                break; // a declaration without a body
            }
        }
    }
    found
}

#[test]
fn no_function_is_longer_than_120_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for part in ["src", "tests", "benches"] {
        rust_files(&root.join(part), &mut files);
    }
    let long: Vec<String> = files
        .iter()
        .flat_map(|file| {
            let text = std::fs::read_to_string(file).unwrap();
            function_lengths(&text)
                .into_iter()
                .filter(|&(_, lines)| lines > MAX_FUNCTION_LINES)
                .map(|(line, lines)| {
                    format!(
                        "{}:{line}: {lines} lines",
                        file.strip_prefix(root).unwrap().display()
                    )
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        long.is_empty(),
        "functions longer than {MAX_FUNCTION_LINES} lines (split them):\n{}",
        long.join("\n")
    );
    // The count is real: this file's own longest function is found with its length.
    let own = function_lengths(include_str!("architecture.rs"));
    assert!(own.iter().any(|&(_, lines)| lines > 20), "{own:?}");
}

/// The module path of a file under `src/` (`level/racing.rs` → `level::racing`; a `mod.rs` is
/// its folder).
fn module_of(src: &Path, file: &Path) -> String {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let parts: Vec<String> = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .filter(|p| p != "mod")
        .collect();
    parts.join("::")
}

/// Whether the code of `text` (tests and comments aside), in module `from`, names module `to`:
/// by its `crate::` path, or as a sibling through `super::`.
fn names_module(text: &str, from: &str, to: &str) -> bool {
    let code = text.split("#[cfg(test)]").next().unwrap();
    let (from_parent, to_parent) = (
        from.rsplit_once("::").map_or("", |(p, _)| p),
        to.rsplit_once("::").map_or("", |(p, _)| p),
    );
    let to_name = to.rsplit("::").next().unwrap();
    let mut paths = vec![format!("crate::{to}::"), format!("crate::{to}}}")];
    if from_parent == to_parent {
        paths.extend([
            format!("super::{to_name}::"),
            format!("super::{to_name}}}"),
            format!("super::{to_name};"),
        ]);
    }
    code.lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .any(|line| paths.iter().any(|p| line.contains(p.as_str())))
}

#[test]
fn no_two_modules_import_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: Vec<(String, String)> = files
        .iter()
        .map(|f| (module_of(&src, f), std::fs::read_to_string(f).unwrap()))
        .collect();
    let mut loops = Vec::new();
    for (i, (a, a_text)) in modules.iter().enumerate() {
        for (b, b_text) in &modules[i + 1..] {
            // A folder's mod.rs and the files in it belong together.
            let nested = |outer: &str, inner: &str| inner.starts_with(&format!("{outer}::"));
            if nested(a, b) || nested(b, a) {
                continue;
            }
            if names_module(a_text, a, b) && names_module(b_text, b, a) {
                loops.push(format!("{a} <-> {b}"));
            }
        }
    }
    assert!(
        loops.is_empty(),
        "modules that import each other (one should own what both need):\n{}",
        loops.join("\n")
    );
    // The check sees imports: level::road names level::racing.
    let road = modules.iter().find(|(m, _)| m == "level::road").unwrap();
    assert!(names_module(&road.1, "level::road", "level::racing"));
}
