//! What the integration tests share: running the binary, reading its output and its files.

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// A training configuration over five characters: ours with jumps of 8, 8.375, ..., 9.5 m/s.
/// An ability-aware run measures each drawn character's reach once (seconds in a test build),
/// so a test's run draws from few.
const FIVE_JUMPERS: &str = "ability_ranges:
  character.jump_speed: [8.0, 9.5]
  character.run_speed: [8.0, 8.0]
  character.gravity: [20.0, 20.0]
generator:
  own_check: {levels: 2, trials: 2}
";

/// A tiny ability-aware platform pair over [`FIVE_JUMPERS`] (8192 steps), shared ([`shared_pair`]).
pub fn five_jumpers_pair() -> &'static (PathBuf, Output) {
    static PAIR: OnceLock<(PathBuf, Output)> = OnceLock::new();
    PAIR.get_or_init(|| shared_pair("five-jumpers", FIVE_JUMPERS, 8192))
}

/// A tiny platform pair whose Generator takes the two style knobs (rewards 1.0 and 0.5; 4096
/// steps; its own check on 2 levels × 2 runs, as the default's 20 × 20 would take 5 s of its
/// 13 in a test build), shared ([`shared_pair`]).
pub fn knob_pair() -> &'static (PathBuf, Output) {
    static PAIR: OnceLock<(PathBuf, Output)> = OnceLock::new();
    PAIR.get_or_init(|| {
        shared_pair(
            "style-pair",
            "ability_ranges: null\ngenerator:\n  rewards:\n    knobs: [1.0, 0.5]\n  own_check: {levels: 2, trials: 2}\n",
            4096,
        )
    })
}

/// `train --mode arlpcg --config CONFIG --steps STEPS --threads 1` into the build's temporary
/// folder `name/run`, for the tests that play a trained pair and only read it: trained once per
/// test process (each caller keeps it in its own `OnceLock`), its folder and what `train` printed.
fn shared_pair(name: &str, config: &str, steps: u32) -> (PathBuf, Output) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let config_file = dir.join("config.yaml");
    std::fs::write(&config_file, config).unwrap();
    let run = dir.join("run");
    let trained = arlpcg_ok(words(
        "train --mode arlpcg --config {} --steps {} --threads 1 --out {}",
        &[&config_file, &steps.to_string(), &run],
    ));
    (run, trained)
}

/// Runs the `arlpcg` binary with `args` and waits for it.
pub fn arlpcg<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Output {
    test_command().args(args).output().expect("the binary runs")
}

/// Runs the binary, killed after `limit` (so that a hang fails the test instead of stalling it).
pub fn arlpcg_within<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S], limit: Duration) -> Output {
    let mut child = test_command()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("{args:?} still ran after {limit:?}: it hangs");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// The `arlpcg` binary as the tests run it: measured λ→success curves go to a cache folder
/// under the build's target folder (`ARLPCG_CACHE`), never into the user's.
pub fn test_command() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_arlpcg"));
    command.env(
        "ARLPCG_CACHE",
        Path::new(env!("CARGO_TARGET_TMPDIR")).join("arlpcg-cache"),
    );
    command
}

/// A command line's arguments: the words of `line` (split at white space), each `{}` standing
/// for the next of `values`, whole (a path with a space in it stays one argument).
pub fn words(line: &str, values: &[&dyn AsRef<OsStr>]) -> Vec<OsString> {
    let mut values = values.iter();
    let args = line
        .split_whitespace()
        .map(|word| match word {
            "{}" => values
                .next()
                .unwrap_or_else(|| panic!("no value for a {{}} of `{line}`"))
                .as_ref()
                .to_owned(),
            word => word.into(),
        })
        .collect();
    assert!(
        values.next().is_none(),
        "more values than {{}}s in `{line}`"
    );
    args
}

/// What a run printed on stderr.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `arlpcg args`, which must succeed (the failure shows its stderr).
pub fn arlpcg_ok<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Output {
    let args: Vec<OsString> = args.into_iter().map(|a| a.as_ref().to_owned()).collect();
    let output = arlpcg(&args);
    assert!(
        output.status.success(),
        "arlpcg {}: {}",
        args.join(OsStr::new(" ")).to_string_lossy(),
        stderr(&output)
    );
    output
}

/// Every file of folder `dir` (not below it): name and bytes, sorted by name.
pub fn files_of(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

/// A small platform campaign into `out` (3 levels on the ramp `0:0.9, 1:0.5` for the scripted
/// median player, 20 runs each, seed 40, YAML only), with `extra` arguments.
pub fn small_campaign(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "campaign",
        "--game",
        "platform",
        "--levels",
        "3",
        "--ramp",
        "0:0.9, 1:0.5",
        "--judge",
        "scripted-median",
        "--trials",
        "20",
        "--seed",
        "40",
        "--format",
        "yaml",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    arlpcg(&args)
}

/// The `results.json` an `eval` wrote into `dir`.
pub fn results_json(dir: &Path) -> serde_json::Value {
    let path = dir.join("results.json");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A `.glb` read back as an engine's importer reads it: the document parsed and validated, and
/// each buffer's bytes (every buffer must be the file's binary chunk, long enough for it).
/// Our files hold no images, so the `gltf` crate's `import` feature (an image decoder) is not
/// needed.
pub fn import_glb(glb: &[u8]) -> (gltf::Document, Vec<Vec<u8>>) {
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice(glb).expect("the .glb parses and validates");
    let blob = blob.expect("the .glb has a binary chunk");
    let buffers = document
        .buffers()
        .map(|buffer| {
            assert!(
                matches!(buffer.source(), gltf::buffer::Source::Bin),
                "buffer {} is not the .glb's binary chunk",
                buffer.index()
            );
            assert!(
                blob.len() >= buffer.length(),
                "buffer {} needs {} bytes, the binary chunk has {}",
                buffer.index(),
                buffer.length(),
                blob.len()
            );
            blob.clone()
        })
        .collect();
    (document, buffers)
}

/// Asserts that a run exited with `code` and said `message` on stderr (both shown if not).
pub fn fails_with(output: &Output, code: i32, message: &str) {
    let err = stderr(output);
    assert_eq!(output.status.code(), Some(code), "{err}");
    assert!(err.contains(message), "expected `{message}` in:\n{err}");
}
