//! The layering docs/architecture.md describes, checked where the compiler cannot check it.
//! The crate boundary already refuses every import from `arlpcg_core` up into the services or
//! the shells; these tests refuse the other "never"s: the pure parts read no clock, print
//! nothing and use no global random generator (the same inputs give the same bytes); the
//! services never reach up into the shells; the shells meet a game only through the game
//! abstraction; inside the core, `level` stands alone and `game` and `rl` never meet; only the
//! `train` command drives training; no two modules import each other; no function grows past
//! 120 lines; and docs/architecture.md names every module there is.

use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The pure parts, from the repository's root: the core crate and the services that compute.
const PURE: &[&str] = &[
    "crates/core/src", "src/services/train", "src/services/eval", "src/services/onnx",
    "src/services/verify", "src/services/generation.rs", "src/services/making",
    "src/services/difficulty.rs", "src/services/panel.rs", "src/services/wish",
];

/// What the pure parts may not name, and why.
const IMPURE: &[(&str, &str)] = &[
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
    ("ratatui", "draws on a terminal"),
];

/// The layering's "never"s: in these files, none of these paths may be named (`except` the files
/// whose path, from the repository's root, starts with one of these).
struct Never {
    within: &'static str,
    names: &'static [&'static str],
    why: &'static str,
    except: &'static [&'static str],
}

const NEVER: &[Never] = &[
    Never {
        within: "src/services",
        names: &["crate::shells"],
        why: "a service reaches up into the shells",
        except: &[],
    },
    Never {
        within: "src/shells",
        names: &["arlpcg_core::game::platform", "arlpcg_core::game::racing"],
        why: "the shells meet a game through `GameSpec` and `game::facts`, not its own module \
              (nor its rules)",
        except: &[],
    },
    Never {
        within: "src",
        names: &["services::train"],
        why: "training is driven by the `train` command alone (the card's types live in `rl`; \
              `report` draws a run's curve from its metrics)",
        except: &[
            "src/services/train", "src/shells/commands/train.rs", "src/shells/commands/report.rs",
        ],
    },
    Never {
        within: "src/services/train",
        names: &["use super::*"],
        why: "train/ imports by name: one namespace over its files hides who needs what",
        except: &["src/services/train/config/tests.rs"],
    },
    Never {
        within: "crates/core/src/level",
        names: &["crate::game", "crate::rl"],
        why: "levels are data: the games and learning build on them, not the other way",
        except: &[],
    },
    Never {
        within: "crates/core/src/rl",
        names: &["crate::game"],
        why: "learning knows no game: `game` and `rl` sit side by side on `level`",
        except: &[],
    },
    Never {
        within: "crates/core/src/game",
        names: &["crate::rl"],
        why: "a game knows no learner: `game` and `rl` sit side by side on `level`",
        except: &[],
    },
    Never {
        within: "crates/core/src/statistics",
        names: &["crate::"],
        why: "statistics are numbers in, numbers out",
        except: &[],
    },
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

/// The code lines of a file, numbered from 1: unit tests (which may print what they measure
/// and build what they need) and comment lines left out.
fn code_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let code = text.split("#[cfg(test)]").next().unwrap();
    code.lines()
        .enumerate()
        .map(|(i, line)| (i + 1, line))
        .filter(|(_, line)| !line.trim_start().starts_with("//"))
}

#[test]
fn the_pure_parts_read_no_clock_print_nothing_and_use_no_global_rng() {
    let mut files = Vec::new();
    for part in PURE {
        rust_files(&root().join(part), &mut files);
    }
    assert!(
        files.len() > 60,
        "the pure files are found ({})",
        files.len()
    );
    let mut problems = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (number, line) in code_lines(&text) {
            for (name, why) in IMPURE {
                if line.contains(name) {
                    let file = file.strip_prefix(root()).unwrap().display();
                    problems.push(format!("{file}:{number}: `{name}` {why}"));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "the pure parts must stay pure:\n{}",
        problems.join("\n")
    );
}

/// Where `rule` is broken in the files under `dir` (paths from the repository's root).
fn broken(rule: &Never, files: &[PathBuf]) -> Vec<String> {
    let mut found = Vec::new();
    for file in files {
        let relative = file
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .into_owned();
        if rule.except.iter().any(|e| relative.starts_with(e)) {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for (number, line) in code_lines(&text) {
            for name in rule.names.iter().filter(|name| line.contains(*name)) {
                found.push(format!("{relative}:{number}: names `{name}`: {}", rule.why));
            }
        }
    }
    found
}

#[test]
fn every_never_of_the_layering_holds() {
    let mut problems = Vec::new();
    for rule in NEVER {
        let mut files = Vec::new();
        rust_files(&root().join(rule.within), &mut files);
        assert!(!files.is_empty(), "{} holds code", rule.within);
        problems.extend(broken(rule, &files));
    }
    assert!(
        problems.is_empty(),
        "the layering is broken:\n{}",
        problems.join("\n")
    );
    // The check sees imports: the `train` command names the training service, and a rule
    // without its exception would catch it.
    let command = [root().join("src/shells/commands/train.rs")];
    let training = NEVER
        .iter()
        .find(|r| r.names == ["services::train"])
        .unwrap();
    let strict = Never {
        except: &[],
        ..*training
    };
    assert!(!broken(&strict, &command).is_empty());
}

/// The modules of a layer: each file and folder directly under it (`mod.rs` and `lib.rs`
/// aside), by name without `.rs`.
fn modules_under(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir() || p.extension().is_some_and(|e| e == "rs"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .filter(|n| n != "mod" && n != "lib" && n != "main")
        .collect();
    names.sort();
    names
}

#[test]
fn docs_architecture_names_every_module_of_every_layer() {
    let doc = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let mut missing = Vec::new();
    for (layer, prefix) in [
        ("crates/core/src", "crates/core/src/"),
        ("src/services", "src/services/"),
        ("src/shells", "src/shells/"),
    ] {
        let modules = modules_under(&root().join(layer));
        assert!(modules.len() >= 4, "{layer}: {modules:?}");
        for module in modules {
            if !doc.contains(&format!("`{module}")) {
                missing.push(format!("{prefix}{module}"));
            }
        }
    }
    // src/ itself holds the two layers and the two crate roots, nothing else.
    let top: Vec<String> = modules_under(&root().join("src"));
    assert_eq!(
        top,
        ["services", "shells"],
        "src/ holds only lib.rs, main.rs and the layers"
    );
    assert!(
        missing.is_empty(),
        "docs/architecture.md does not name these modules:\n{}",
        missing.join("\n")
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
            "pub(crate) ", "pub(super) ", "pub ", "const ", "async ", "unsafe ",
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
    let root = root();
    let mut files = Vec::new();
    for part in ["src", "crates/core/src", "tests", "benches"] {
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

/// Module pairs of the crate whose sources are `src` that import each other.
fn import_loops(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: Vec<(String, String)> = files
        .iter()
        .map(|f| (module_of(src, f), std::fs::read_to_string(f).unwrap()))
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
    loops
}

#[test]
fn no_two_modules_import_each_other() {
    let mut loops = import_loops(&root().join("src"));
    loops.extend(import_loops(&root().join("crates/core/src")));
    assert!(
        loops.is_empty(),
        "modules that import each other (one should own what both need):\n{}",
        loops.join("\n")
    );
    // The check sees imports: level::road names level::racing.
    let road = std::fs::read_to_string(root().join("crates/core/src/level/road.rs")).unwrap();
    assert!(names_module(&road, "level::road", "level::racing"));
}

/// A game's names (its `Game` and `Track` variants, its module, its `GameSpec` type)...
const GAME_NAMES: &[&str] = &[
    "Game::Platform", "Game::Racing", "Game::Ball", "Track::Platform", "Track::Racing",
    "Track::Ball", "game::platform", "game::racing", "game::ball", "PlatformGame", "RacingGame",
    "BallGame",
];

/// ...may appear only in these files and folders (tests and benches aside, which pick games to
/// try): the dispatch of games to their types, the one of games and tracks to what their levels
/// are built from and who plays them (`level/mod.rs`: `Shape`, `ShapeKind`, `PlayerKind`), and
/// each game's folder. Everything else meets a game through `GameSpec`, `GameFacts`,
/// `for_game!` and a level's `Shape`, so that a new game touches only these (the tests' ball
/// game, crates/core/src/game/ball, is the proof).
const GAME_PLACES: &[&str] = &[
    "crates/core/src/game/mod.rs", "crates/core/src/level/mod.rs",
    "crates/core/src/game/platform/", "crates/core/src/game/racing/", "crates/core/src/game/ball/",
];

#[test]
fn a_game_is_named_only_in_its_folder_and_the_dispatch() {
    let rule = Never {
        within: "",
        names: GAME_NAMES,
        why: "a game is met through `GameSpec`, `GameFacts` and `for_game!` outside its own places",
        except: GAME_PLACES,
    };
    let mut files = Vec::new();
    for part in ["src", "crates/core/src"] {
        rust_files(&root().join(part), &mut files);
    }
    // A module's tests in their own file (`tests.rs`) pick games as any test does.
    files.retain(|f| f.file_name().is_none_or(|n| n != "tests.rs"));
    let problems = broken(&rule, &files);
    assert!(
        problems.is_empty(),
        "a game is named outside its places:\n{}",
        problems.join("\n")
    );
    // The check sees names: the dispatch names both games.
    let strict = Never {
        except: &[],
        ..rule
    };
    let dispatch = [root().join("crates/core/src/game/mod.rs")];
    assert!(broken(&strict, &dispatch).len() >= 2);
}
