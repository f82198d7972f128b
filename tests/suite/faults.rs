//! Paths that are not what they seem, and runs that would replace others' files: a FIFO where a
//! level, a policy, a configuration or an output file should be is refused at once (opening it
//! would block forever), and nothing is overwritten without `--force`.

use crate::common::{arlpcg_within, files_of, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Sends Ctrl-C (SIGINT) to `child`; when it was sent.
fn interrupt(child: &std::process::Child) -> Instant {
    let sent = Instant::now();
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    sent
}

/// A FIFO at `path`, or `None` (and a message) where `mkfifo` is not available.
fn fifo(path: &Path) -> Option<PathBuf> {
    let made = Command::new("mkfifo").arg(path).status();
    if made.is_ok_and(|s| s.success()) {
        Some(path.to_path_buf())
    } else {
        eprintln!("skipped: mkfifo is not available here");
        None
    }
}

fn shipped_level() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("levels/platform/platform_seed7_aux+0.50.yaml")
        .display()
        .to_string()
}

#[test]
fn a_fifo_is_refused_wherever_a_file_is_read_or_written() {
    let dir = tempfile::tempdir().unwrap();
    let Some(pipe) = fifo(&dir.path().join("pipe.yaml")) else {
        return;
    };
    let pipe = pipe.to_str().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let level = shipped_level();
    let cases: [(&str, Vec<&str>); 4] = [
        ("level", vec!["verify", "--trials", "1", pipe]),
        (
            "policy",
            vec!["verify", "--trials", "1", "--policy", pipe, &level],
        ),
        (
            "config",
            vec!["train", "--steps", "10", "--config", pipe, "--out", out_s],
        ),
        ("export", vec!["export", &level, "--out", pipe]),
    ];
    for (what, args) in cases {
        let output = arlpcg_within(&args, Duration::from_secs(20));
        let err = stderr(&output);
        assert!(
            matches!(output.status.code(), Some(1 | 2)),
            "{what}: {:?} {err}",
            output.status
        );
        assert!(err.contains("pipe.yaml"), "{what}: names the file: {err}");
    }
}

#[test]
fn generate_leaves_a_fifo_where_its_file_should_go_alone() {
    let dir = tempfile::tempdir().unwrap();
    let Some(_) = fifo(&dir.path().join("platform_seed3.yaml")) else {
        return;
    };
    let out = dir.path().to_str().unwrap();
    let args = [
        "generate", "--rules", "--game", "platform", "--seed", "3", "--out", out,
    ];
    let output = arlpcg_within(&args, Duration::from_secs(20));
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "nothing written beside it");
}

/// Two `generate` runs into one folder write one after the other: while another holds the
/// folder, a run says it waits and writes nothing (its checks, staging and any rollback cannot
/// interleave with the other's), then writes its files when the folder is free.
#[test]
fn a_batch_waits_while_another_run_writes_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let held = std::fs::File::open(dir.path()).unwrap();
    held.lock().unwrap();
    let out = dir.path().to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args([
            "generate", "--rules", "--count", "2", "--format", "yaml", "--out", out,
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let mut stderr_pipe = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    std::io::BufRead::read_line(&mut stderr_pipe, &mut line).unwrap();
    assert!(
        line.contains("waiting for another arlpcg run that is writing into"),
        "{line}"
    );
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "written while held"
    );
    drop(held);
    let status = child.wait().unwrap();
    assert!(status.success());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn a_new_training_run_never_starts_in_a_folder_holding_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("policies");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("solver.safetensors"), b"a designer's policy").unwrap();
    let args = ["train", "--steps", "100", "--out", out.to_str().unwrap()];
    let output = arlpcg_within(&args, Duration::from_secs(20));
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.contains("is not empty (it holds solver.safetensors)"),
        "{err}"
    );
    let names: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
    assert_eq!(names.len(), 1);
    assert_eq!(
        std::fs::read(out.join("solver.safetensors")).unwrap(),
        b"a designer's policy"
    );
}

#[test]
fn messages_name_the_field_and_exit_codes_tell_arguments_from_input() {
    let dir = tempfile::tempdir().unwrap();
    let nan_obstacle = dir.path().join("nan-obstacle.yaml");
    std::fs::write(
        &nan_obstacle,
        "format: arlpcg-level\nversion: 1\ngame: racing\nstart: {position: [0, 0, 0], heading: 0}\n\
         segments:\n  - {length: 20, curve: 0, height: 0}\n\
         obstacles:\n  - {kind: box, position: [.nan, 0, 0], size: [2, 2, 2], heading: 0}\n",
    )
    .unwrap();
    let err = yaml_error(&nan_obstacle);
    assert!(
        err.contains("obstacles[0].position: coordinate must be a number, not NaN (line 8)"),
        "{err}"
    );

    let no_rules = dir.path().join("no-rules.yaml");
    std::fs::write(
        &no_rules,
        "format: arlpcg-level\nversion: 1\ngame: platform\nstart: {position: [0, 0, 0], heading: 0}\n\
         blocks:\n  - {distance: 7, angle: 0, size: 5, height: 0}\nsource:\n  kind: rules\n",
    )
    .unwrap();
    let err = yaml_error(&no_rules);
    assert!(
        err.ends_with("no-rules.yaml: source.rules: missing (line 7)"),
        "{err}"
    );

    // A byte-order mark before the first key is read past.
    let staircase = Path::new(env!("CARGO_MANIFEST_DIR")).join("levels/hand/staircase.yaml");
    let mut with_bom = b"\xef\xbb\xbf".to_vec();
    with_bom.extend(std::fs::read(&staircase).unwrap());
    assert_eq!(
        arlpcg_core::level::yaml::parse(std::str::from_utf8(&with_bom).unwrap()).unwrap(),
        arlpcg_core::level::yaml::load(&staircase).unwrap()
    );

    let out = dir.path().join("never-made");
    let out_s = out.to_str().unwrap();
    let staircase = staircase.to_str().unwrap();
    let png = dir.path().join("x.png");
    let cases: [(Vec<&str>, i32, &str); 3] = [
        (
            vec!["export", staircase, "--out", png.to_str().unwrap()],
            2,
            "must end in .glb or .gltf",
        ),
        (
            vec![
                "generate", "--rules", "--seed", "18446744073709551610", "--count", "10", "--out",
                out_s,
            ],
            2,
            "overflows a 64-bit seed",
        ),
        (
            vec!["generate", "--rules", "--goal", "5000,0,0", "--out", out_s],
            1,
            "seed 0",
        ),
    ];
    for (args, code, expected) in cases {
        let output = arlpcg_within(&args, Duration::from_secs(20));
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    assert!(
        !out.exists(),
        "a failed generate leaves no empty folder behind"
    );
    assert!(!png.exists());
}

fn yaml_error(path: &Path) -> String {
    arlpcg_core::level::yaml::load(path)
        .unwrap_err()
        .to_string()
}

/// Runs the binary with files limited to `kib` KiB (writes past it fail with "File too large",
/// as on a full disk), or `None` where bash cannot set the limit.
fn arlpcg_with_file_limit(kib: u32, args: &[&str]) -> Option<Output> {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!(
        "ulimit -f {kib} && trap '' XFSZ && exec '{}' {}",
        env!("CARGO_BIN_EXE_arlpcg"),
        quoted.join(" ")
    );
    let output = Command::new("bash").args(["-c", &script]).output().ok()?;
    if stderr(&output).contains("ulimit") {
        eprintln!("skipped: cannot limit file sizes here");
        return None;
    }
    Some(output)
}

/// A batch whose glTF files do not fit (a full disk) leaves every folder as it was: a new folder
/// is not made, an old batch replaced with --force stays whole, no temporary file stays behind.
#[test]
fn a_batch_that_cannot_be_written_whole_leaves_the_folder_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("fresh");
    let batch = |out: &Path, aux: &str, extra: &[&str]| {
        let mut args = vec![
            "generate",
            "--rules",
            "--game",
            "platform",
            "--count",
            "6",
            "--seed",
            "1",
            "--aux",
            aux,
            "--format",
            "yaml,glb",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        args.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let args = batch(&fresh, "0.5", &[]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    // The .yaml files (about 1 KiB) fit in 4 KiB, the .glb files (about 5.5 KiB) do not.
    let Some(output) = arlpcg_with_file_limit(4, &args) else {
        return;
    };
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.contains("nothing was written") && err.contains("File too large"),
        "{err}"
    );
    assert!(!fresh.exists(), "no folder made");

    let old = dir.path().join("old");
    let args = batch(&old, "1", &[]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = crate::common::arlpcg(&args);
    assert!(output.status.success());
    let before = files_of(&old);
    assert_eq!(before.len(), 12);
    let args = batch(&old, "-1", &["--force"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let output = arlpcg_with_file_limit(4, &args).unwrap();
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert_eq!(
        files_of(&old),
        before,
        "the old batch, whole, and nothing else"
    );
}

/// Ctrl-C while `generate --target-success` measures the policies' λ→success curve (tens of
/// seconds) stops it at once: exit 130, nothing written.
#[test]
fn ctrl_c_stops_the_difficulty_curve_measurement_at_once() {
    use std::io::{BufRead, BufReader};
    let dir = tempfile::tempdir().unwrap();
    let policies = dir.path().join("policies");
    std::fs::create_dir(&policies).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    for name in [
        "generator.safetensors", "generator.yaml", "solver.safetensors", "solver.yaml",
    ] {
        std::fs::copy(shipped.join(name), policies.join(name)).unwrap();
    }
    let out = dir.path().join("out");
    let mut child = crate::common::test_command()
        .args([
            "generate",
            "--policies",
            policies.to_str().unwrap(),
            "--target-success",
            "0.5",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    while !line.contains("measuring") {
        line.clear();
        assert!(
            stderr.read_line(&mut line).unwrap() > 0,
            "ended before measuring"
        );
    }
    std::thread::sleep(Duration::from_millis(300));
    let sent = interrupt(&child);
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut stderr, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert!(
        sent.elapsed() < Duration::from_secs(10),
        "took {:?}",
        sent.elapsed()
    );
    assert_eq!(status.code(), Some(130), "{rest}");
    assert!(
        rest.contains("while the λ→success curve was measured"),
        "{rest}"
    );
    assert!(!out.exists());
    assert!(
        !policies.join("difficulty-curve.yaml").exists(),
        "no partial curve kept"
    );
}

/// Runs the binary with its standard output (or, with `close_stderr`, its standard error)
/// closed before it writes: the pipe's reading end is dropped at once.
fn arlpcg_into_closed_pipe(args: &[&str], close_stderr: bool) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_arlpcg"));
    command.args(args).stdin(Stdio::null());
    command.stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child = command.spawn().expect("the binary runs");
    match close_stderr {
        true => drop(child.stderr.take()),
        false => drop(child.stdout.take()),
    }
    child.wait_with_output().unwrap()
}

#[test]
fn a_closed_pipe_ends_every_command_quietly_with_its_files_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).display().to_string();
    let level = shipped_level();
    let shipped = |file: &str| {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(file)
            .display()
            .to_string()
    };
    let (batch, glb, onnx) = (out("batch"), out("level.glb"), out("solver.onnx"));
    let policy = shipped("policies/platform/solver.safetensors");
    let commands: Vec<Vec<&str>> = vec![
        vec!["verify", "--trials", "2", &level, &level, &level],
        vec!["verify", "--trials", "2", "--json", &level, &level],
        vec!["verify", "--replay", &level, &level],
        vec!["verify", "--panel", "--trials", "2", &level],
        vec![
            "generate", "--rules", "--count", "3", "--seed", "4", "--out", &batch,
        ],
        vec!["export", &level, "--out", &glb],
        vec!["export-policy", &policy, "--out", &onnx],
        vec!["train", "--print-config"],
        vec!["--help"],
    ];
    for args in &commands {
        let output = arlpcg_into_closed_pipe(args, false);
        let code = output.status.code();
        assert!(
            matches!(code, Some(0 | 141)),
            "{args:?} into a closed pipe: exit {code:?}, {}",
            stderr(&output)
        );
        assert!(!stderr(&output).contains("panicked"), "{args:?}");
    }
    // What they wrote is whole: the levels load, the exports are there.
    let levels: Vec<PathBuf> = std::fs::read_dir(&batch)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "yaml"))
        .collect();
    assert_eq!(levels.len(), 3, "three levels");
    for path in levels {
        arlpcg_core::level::yaml::load(&path).expect("a whole level");
    }
    assert!(Path::new(&glb).is_file() && Path::new(&onnx).is_file());
    // An error said to a closed standard error still exits 1, not a panic's 101.
    let missing = out("missing.yaml");
    let output = arlpcg_into_closed_pipe(&["verify", &missing], true);
    assert_eq!(output.status.code(), Some(1));
}

/// Ctrl-C during a long `--verify` stops the trials under way: the command ends at once (exit
/// 130), writing no level it did not finish.
#[test]
fn ctrl_c_stops_a_long_verification_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let child = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args(["generate", "--rules", "--count", "2", "--verify", "1000000"])
        .args(["--out", out.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let sent = interrupt(&child);
    let output = child.wait_with_output().unwrap();
    assert!(
        sent.elapsed() < Duration::from_secs(5),
        "took {:?}",
        sent.elapsed()
    );
    assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
    let written = std::fs::read_dir(&out).map_or(0, |files| files.count());
    assert_eq!(written, 0, "no unfinished level");
}

/// A path that is not UTF-8 could not be recorded as given (levels and cards are UTF-8 text):
/// every command refuses it at the start, naming it, and makes nothing.
#[test]
fn an_argument_that_is_not_utf8_is_refused_before_anything_is_made() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let odd = dir.path().join(std::ffi::OsStr::from_bytes(b"run-\xff"));
    for command in [
        vec!["train", "--steps", "10", "--out"],
        vec!["export", &shipped_level(), "--out"],
        vec!["generate", "--rules", "--out"],
    ] {
        let output = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
            .args(&command)
            .arg(&odd)
            .output()
            .unwrap();
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{command:?}: {err}");
        assert!(
            err.contains("not valid UTF-8") && err.contains("run-"),
            "{err}"
        );
        assert!(!odd.exists(), "{command:?}: nothing made");
    }
}

/// A standard output that cannot be written for another reason than a closed pipe (a full
/// disk: `> /dev/full`) is an error in one line, exit 1, not a panic.
#[test]
fn a_full_disk_on_standard_output_is_an_error_not_a_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("skipped: no /dev/full here");
        return;
    };
    for args in [
        vec!["profile", "init", "--game", "racing"],
        vec!["verify", "--trials", "2", "--json"],
    ] {
        let mut command = crate::common::test_command();
        command.args(&args);
        if args[0] == "verify" {
            command.arg(shipped_level());
        }
        let output = command
            .stdout(full.try_clone().unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("cannot write to standard output") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// Ctrl-C while a campaign searches a level (thousands of runs per candidate) stops the search
/// under way: the campaign ends soon after (exit 130) and writes no level it did not finish.
#[test]
fn ctrl_c_stops_a_campaign_while_it_searches_a_level() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    let mut child = crate::common::test_command()
        .args(["campaign", "--levels", "2", "--ramp", "0:0.6, 1:0.5"])
        .args(["--judge", "scripted-median", "--trials", "100000"])
        .args(["--format", "yaml", "--out", out.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Past loading the policies and reading the shipped curve: into the search.
    std::thread::sleep(Duration::from_secs(5));
    let sent = interrupt(&child);
    while child.try_wait().unwrap().is_none() {
        if sent.elapsed() > Duration::from_secs(10) {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("still searching {:?} after Ctrl-C", sent.elapsed());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
    let written = std::fs::read_dir(&out).map_or(0, |files| files.count());
    assert_eq!(written, 0, "no unfinished level");
}

/// A measured λ→success curve goes to the cache folder (`ARLPCG_CACHE`), keyed by the
/// policies' SHA-256, and is read from there the next time; the policies folder, an input, is
/// never written.
#[test]
fn a_measured_curve_is_cached_apart_from_the_policies_it_was_measured_with() {
    let dir = tempfile::tempdir().unwrap();
    let policies = dir.path().join("policies");
    std::fs::create_dir(&policies).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    for name in ["generator.safetensors", "generator.yaml"] {
        std::fs::copy(shipped.join(name), policies.join(name)).unwrap();
    }
    let before = files_of(&policies);
    let cache = dir.path().join("cache");
    let generate = |out: &str| {
        let output = crate::common::test_command()
            .env("ARLPCG_CACHE", &cache)
            .args(["generate", "--policies", policies.to_str().unwrap()])
            .args(["--target-success", "0.6", "--judge", "scripted-median"])
            .args(["--verify", "20", "--format", "yaml", "--seed", "5"])
            .args(["--out", dir.path().join(out).to_str().unwrap()])
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
        stderr(&output)
    };
    assert!(generate("first").contains("measuring"));
    assert_eq!(
        files_of(&policies),
        before,
        "nothing written beside the policies"
    );
    let curves = files_of(&cache.join("curves"));
    assert_eq!(curves.len(), 1, "{curves:?}");
    assert!(curves[0].0.contains("scripted-median"), "{}", curves[0].0);
    assert!(
        !generate("again").contains("measuring"),
        "read from the cache"
    );
}

/// Arguments that do not fit together exit 2 (`--profile` with `--runs`, or with `--merge`,
/// whose parts record their profile), and a command refused for a file it reads (a profile
/// that is not a number) leaves no folder it would have made.
#[test]
fn misfits_exit_2_and_a_refused_run_leaves_no_folder() {
    let dir = tempfile::tempdir().unwrap();
    let profile = dir.path().join("nan.yaml");
    let init = crate::common::arlpcg_ok(["profile", "init", "--game", "platform"]).stdout;
    let text = String::from_utf8(init).unwrap();
    let nan = text.replacen("jump_speed: ", "jump_speed: .nan #", 1);
    std::fs::write(&profile, nan).unwrap();
    let profile = profile.to_str().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    for args in [
        vec![
            "eval", "--runs", out_s, "--profile", profile, "--out", out_s,
        ],
        vec![
            "eval", "--merge", out_s, "--profile", profile, "--out", out_s,
        ],
    ] {
        let output = crate::common::arlpcg(&args);
        assert_eq!(
            output.status.code(),
            Some(2),
            "{args:?}: {}",
            stderr(&output)
        );
        assert!(stderr(&output).contains("--profile"), "{}", stderr(&output));
    }
    for missing in [profile, "/nonexistent/profile.yaml"] {
        let args = [
            "train", "--steps", "10", "--profile", missing, "--out", out_s,
        ];
        let output = crate::common::arlpcg(args);
        assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
        assert!(stderr(&output).contains(missing), "{}", stderr(&output));
        assert!(!out.exists(), "{args:?} left the folder it made");
    }
}

/// `--json` promises JSON on standard output: with `--check` the verdict goes to standard
/// error, and every line of standard output is a JSON object.
#[test]
fn with_json_standard_output_carries_json_alone() {
    let level = shipped_level();
    for check in ["completed", "success 0..0.01"] {
        let args = [
            "verify", "--trials", "5", "--solver", "scripted-expert", "--json", "--check", check,
            &level,
        ];
        let output = crate::common::arlpcg(args);
        assert!(
            matches!(output.status.code(), Some(0 | 3)),
            "{}",
            stderr(&output)
        );
        let text = String::from_utf8(output.stdout.clone()).unwrap();
        assert_eq!(text.lines().count(), 1, "{text}");
        for line in text.lines() {
            let value: serde_json::Value =
                serde_json::from_str(line).unwrap_or_else(|e| panic!("`{line}` is not JSON: {e}"));
            assert!(value.is_object(), "{line}");
        }
        assert!(stderr(&output).contains("check"), "{}", stderr(&output));
    }
}

/// `campaign --resume` with another `--ramp` (or `--trials`) than the campaign in `--out` was
/// made with is refused, naming a level and what differs: the levels were searched for the
/// other ramp.
#[test]
fn a_campaign_resumed_with_another_ramp_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    let done = crate::common::small_campaign(&out, &[]);
    assert!(done.status.success(), "{}", stderr(&done));
    let before = files_of(&out);
    // small_campaign's command, with another ramp and --resume.
    let other = crate::common::arlpcg(crate::common::words(
        "campaign --game platform --levels 3 --ramp {} --judge scripted-median --trials 20 \
         --seed 40 --format yaml --resume --out {}",
        &[&"0:0.2, 1:0.2", &out],
    ));
    crate::common::fails_with(&other, 1, "it was searched for another ramp");
    assert!(stderr(&other).contains("level0"), "{}", stderr(&other));
    assert_eq!(files_of(&out), before, "nothing rewritten");
}

/// A racing profile whose roads cannot turn (`max_curve: 0`, within its range) leaves most rule
/// goals out of reach: each is refused at once instead of after every attempt, so `profile
/// check` answers in seconds (it took minutes of attempts before).
#[test]
fn a_profile_whose_roads_cannot_turn_is_checked_in_seconds() {
    let dir = tempfile::tempdir().unwrap();
    let init = crate::common::arlpcg_ok(["profile", "init", "--game", "racing"]).stdout;
    let text = String::from_utf8(init).unwrap();
    assert!(text.contains("  max_curve: "), "{text}");
    let straight = dir.path().join("straight.yaml");
    std::fs::write(
        &straight,
        text.replacen("  max_curve: ", "  max_curve: 0 #", 1),
    )
    .unwrap();
    let args = [
        "profile",
        "check",
        straight.to_str().unwrap(),
        "--trials",
        "2",
    ];
    // About 2 s now; 30 s of hopeless attempts before.
    let checked = arlpcg_within(&args, Duration::from_secs(15));
    let said = stderr(&checked);
    assert_eq!(checked.status.code(), Some(1), "{said}");
    assert!(
        said.contains("most of the game's goals cannot be reached"),
        "{said}"
    );
}
