//! The command line as a designer uses it: generate, export, verify; reproducible files; bad
//! input gets one clear line and a non-zero exit, never a panic, and nothing is overwritten.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::{arlpcg, arlpcg_ok, fails_with, files_of, stderr, words};

fn generate(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "generate",
        "--game",
        "platform",
        "--rules",
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    arlpcg(&args)
}

#[test]
fn generate_is_reproducible_byte_for_byte_and_files_load_back() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for dir in [&a, &b] {
        let out = generate(
            dir.path(),
            &["--count", "20", "--seed", "1", "--format", "yaml,glb"],
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let (files_a, files_b) = (files_of(a.path()), files_of(b.path()));
    assert_eq!(files_a.len(), 40);
    assert!(files_a == files_b, "two runs with the same seed differ");
    for (name, bytes) in files_a.iter().filter(|(n, _)| n.ends_with(".yaml")) {
        let level = arlpcg_core::level::yaml::load(&a.path().join(name)).unwrap();
        assert_eq!(
            arlpcg_core::level::yaml::to_string(&level).as_bytes(),
            bytes.as_slice(),
            "{name} does not read back to itself"
        );
        assert_eq!(
            level.seed.map(|s| format!("platform_seed{s}.yaml")),
            Some(name.clone())
        );
    }
}

/// The acceptance run for racing: 20 rule tracks twice give the same bytes, and the
/// scripted driver clears them.
#[test]
fn racing_tracks_are_reproducible_and_the_scripted_driver_clears_them() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for dir in [&a, &b] {
        arlpcg_ok(words(
            "generate --game racing --rules --count 20 --seed 1 --format yaml,glb --out {}",
            &[&dir.path()],
        ));
    }
    let files = files_of(a.path());
    assert_eq!(files.len(), 40);
    assert!(
        files == files_of(b.path()),
        "two runs with the same seed differ"
    );
    let mut args = vec!["verify", "--solver", "scripted", "--trials", "10", "--json"];
    let levels: Vec<String> = files
        .iter()
        .filter(|(n, _)| n.ends_with(".yaml"))
        .map(|(n, _)| a.path().join(n).display().to_string())
        .collect();
    args.extend(levels.iter().map(String::as_str));
    let out = arlpcg_ok(&args);
    let ratios: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|line| {
            let value: serde_json::Value = serde_json::from_str(line).unwrap();
            assert!(value["mean_air_steps"].is_number(), "{line}");
            value["success_ratio"].as_f64().unwrap()
        })
        .collect();
    assert_eq!(ratios.len(), 20);
    let mean = ratios.iter().sum::<f64>() / 20.0;
    assert!(mean >= 0.9, "scripted mean success {mean}: {ratios:?}");
}

#[test]
fn generate_names_files_by_game_seed_and_aux_and_never_overwrites() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(
        dir.path(),
        &[
            "--count", "2", "--seed", "5", "--aux", "-0.5", "--format", "yaml",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let names: Vec<String> = files_of(dir.path()).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "platform_seed5_aux-0.50.yaml", "platform_seed6_aux-0.50.yaml"
        ]
    );
    let before = files_of(dir.path());
    // Run again: the files are there and identical, so nothing is rewritten.
    let out = generate(
        dir.path(),
        &[
            "--count", "2", "--seed", "5", "--aux", "-0.5", "--format", "yaml",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("2 of them already there and identical"),
        "{said}"
    );
    assert_eq!(files_of(dir.path()), before);
    // Seed 6 exists with other contents: the run refuses before writing anything, seed 7
    // included.
    let seed6 = dir.path().join("platform_seed6_aux-0.50.yaml");
    let mut edited = std::fs::read_to_string(&seed6).unwrap();
    edited.push_str("# edited by hand\n");
    std::fs::write(&seed6, edited).unwrap();
    let before = files_of(dir.path());
    let out = generate(
        dir.path(),
        &[
            "--count", "2", "--seed", "6", "--aux", "-0.5", "--format", "yaml",
        ],
    );
    fails_with(&out, 1, "already exists with other contents (use --force");
    assert_eq!(files_of(dir.path()), before);
    let out = generate(
        dir.path(),
        &[
            "--count", "2", "--seed", "6", "--aux", "-0.5", "--format", "yaml", "--force",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(files_of(dir.path()).len(), 3);
}

/// K shards together write exactly the unsharded batch, and a shard re-run rewrites nothing.
#[test]
fn shards_of_a_batch_write_exactly_the_batch() {
    let (whole, parts) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let batch = [
        "--count", "10", "--seed", "1", "--format", "yaml,glb", "--verify", "4",
    ];
    let out = generate(whole.path(), &batch);
    assert!(out.status.success(), "{}", stderr(&out));
    for shard in ["0/4", "1/4", "2/4", "3/4"] {
        let mut args = batch.to_vec();
        args.extend(["--shard", shard]);
        let out = generate(parts.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    assert!(files_of(whole.path()) == files_of(parts.path()));
    let mut args = batch.to_vec();
    args.extend(["--shard", "1/4"]);
    let out = generate(parts.path(), &args);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains(
            "wrote 3 levels (shard 1/4 of 10) (6 files, 6 of them already there and identical)"
        ),
        "{said}"
    );
    for bad in ["4/4", "1/0", "x/2", "3"] {
        let mut args = batch.to_vec();
        args.extend(["--shard", bad]);
        assert_eq!(
            generate(parts.path(), &args).status.code(),
            Some(2),
            "{bad}"
        );
    }
}

/// Where tests leave glTF files for `.ci/run` to pass through the Khronos validator.
fn gltf_export_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gltf-exports");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn export_writes_glb_and_gltf_with_bin() {
    let dir = tempfile::tempdir().unwrap();
    let out = generate(dir.path(), &["--seed", "3", "--format", "yaml,glb,gltf"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let names: Vec<String> = files_of(dir.path()).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "platform_seed3.bin", "platform_seed3.glb", "platform_seed3.gltf",
            "platform_seed3.yaml"
        ]
    );
    let level = dir.path().join("platform_seed3.yaml");
    let exports = gltf_export_dir();
    for name in ["cli_export.glb", "cli_export.gltf"] {
        let target = exports.join(name);
        arlpcg_ok(words("export {} --out {} --force", &[&level, &target]));
    }
    assert!(exports.join("cli_export.bin").exists());
    // The exported .glb equals the one generate wrote: one exporter.
    assert_eq!(
        std::fs::read(exports.join("cli_export.glb")).unwrap(),
        std::fs::read(dir.path().join("platform_seed3.glb")).unwrap()
    );
    let existing = exports.join("cli_export.glb");
    let out = arlpcg(words("export {} --out {}", &[&level, &existing]));
    fails_with(&out, 1, "already exists");
    let out = arlpcg(words("export {} --out level.obj", &[&level]));
    assert!(
        stderr(&out).contains("must end in .glb or .gltf"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn verify_reports_json_with_the_documented_keys() {
    let dir = tempfile::tempdir().unwrap();
    assert!(
        generate(dir.path(), &["--seed", "2", "--format", "yaml"])
            .status
            .success()
    );
    let level = dir.path().join("platform_seed2.yaml");
    let out = arlpcg_ok(words(
        "verify {} --trials 20 --json --solver scripted",
        &[&level],
    ));
    let line = String::from_utf8(out.stdout).unwrap();
    let report: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    for key in [
        "level", "trials", "successes", "success_ratio", "mean_progress",
    ] {
        assert!(report.get(key).is_some(), "missing {key} in {report}");
    }
    assert_eq!(report["trials"], 20);
    // Rule levels keep every jump within reach: the scripted controller gets through.
    assert_eq!(report["successes"], 20, "{report}");
}

/// Writes a broken level file and checks the one-line error it gets.
fn assert_rejected(name: &str, contents: &[u8], expected: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, contents).unwrap();
    for command in [
        vec![
            "verify",
            path.to_str().unwrap(),
            "--trials",
            "1",
            "--solver",
            "scripted",
        ],
        vec![
            "export",
            path.to_str().unwrap(),
            "--out",
            dir.path().join("x.glb").to_str().unwrap(),
        ],
    ] {
        let out = arlpcg(&command);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name} panicked: {err}");
        let error_lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        assert!(
            !error_lines.is_empty() && error_lines[0].contains(name),
            "{name}: the error must name the file: {err}"
        );
        assert!(
            error_lines[0].contains(expected),
            "{name}: expected `{expected}` in: {err}"
        );
    }
    assert!(!dir.path().join("x.glb").exists());
}

const GOOD: &str = "format: arlpcg-level\nversion: 1\ngame: platform\nstart: {position: [0, 0, 0], heading: 0}\nblocks:\n- {distance: 7, angle: 0, size: 5, height: 1}\n";

#[test]
fn hand_broken_level_files_get_one_clear_line_and_a_non_zero_exit() {
    let edited = |from: &str, to: &str| GOOD.replace(from, to).into_bytes();
    // Statistics and the source are checked like the track: NaN and absurd values were accepted.
    let rules = |spread: &str, margin: &str, max: &str| {
        format!(
            "{GOOD}source: {{kind: rules, rules: {{max_blocks: {max}, angle_spread: {spread}, reach_margin: {margin}}}}}\n"
        )
        .into_bytes()
    };
    let stats = |ratio: &str, ci: &str| {
        format!(
            "{GOOD}stats: {{solver: {{kind: scripted}}, seed: 3, trials: 3, successes: 3, fell: 0, timed_out: 0, \
             success_ratio: {ratio}, ci95: [0.4385, {ci}], mean_progress: 1.0, mean_success_steps: 297.3, \
             failures_by_piece: [0]}}\n"
        )
        .into_bytes()
    };
    let good = dir_with_level(&stats("1.0", "1.0"));
    arlpcg_ok(words("verify {} --solver scripted", &[&good.1]));
    good.0.close().unwrap();
    let random: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let cases: [(&str, Vec<u8>, &str); 17] = [
        ("empty.yaml", Vec::new(), "the file is empty"),
        (
            "truncated.yaml",
            GOOD.as_bytes()[..GOOD.len() - 20].to_vec(),
            "invalid YAML: did not find expected node content at line 7",
        ),
        (
            "cut.yaml",
            GOOD.as_bytes()[..GOOD.len() - 46].to_vec(),
            "blocks: missing: a platform level needs its blocks",
        ),
        (
            "version.yaml",
            edited("version: 1", "version: 7"),
            "format version 7 is not supported",
        ),
        (
            "range.yaml",
            edited("size: 5", "size: 12"),
            "size 12 is out of range [4, 6] m",
        ),
        (
            "nan.yaml",
            edited("height: 1", "height: .nan"),
            "height must be a number, not NaN",
        ),
        (
            "game.yaml",
            edited("game: platform", "game: tetris"),
            "unknown variant `tetris`",
        ),
        (
            "racing.yaml",
            edited("game: platform", "game: racing"),
            "a racing level has `segments`, not `blocks`",
        ),
        ("random.yaml", random, "not a text file"),
        (
            "large.yaml",
            format!("{GOOD}# {}\n", "x".repeat(5 << 20)).into_bytes(),
            "larger than 4 MiB",
        ),
        (
            "unknown.yaml",
            format!("{GOOD}colour: red\n").into_bytes(),
            "unknown field `colour`",
        ),
        (
            "spread.yaml",
            rules(".nan", "0.5", "40"),
            "source: rules.angle_spread NaN must be a number of degrees within [0, 180] (line 7)",
        ),
        (
            "margin.yaml",
            rules("60", "-4", "40"),
            "source: rules.reach_margin -4 must be",
        ),
        (
            "max.yaml",
            rules("60", "0.5", "0"),
            "source: rules.max_blocks 0 must be within [1, 400]",
        ),
        (
            "ratio.yaml",
            stats(".nan", "1.0"),
            "stats: success_ratio NaN does not match successes / trials = 1 (line 7)",
        ),
        (
            "huge.yaml",
            edited("distance: 7", "distance: 1e308"),
            "distance 1e308 is out of range [5, 10] m",
        ),
        (
            "ci.yaml",
            stats("1.0", ".inf"),
            "stats: ci95 [0.4385, inf] does not match",
        ),
    ];
    for (name, contents, expected) in &cases {
        assert_rejected(name, contents, expected);
    }
}

/// A temporary folder holding `level.yaml` with these bytes.
fn dir_with_level(bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("level.yaml");
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

/// A level that cannot be read is named once, in `verify` as in `--replay`.
#[test]
fn a_missing_level_file_is_named() {
    for mode in ["--solver scripted", "--replay"] {
        let out = arlpcg(words(&format!("verify /no/such/level.yaml {mode}"), &[]));
        fails_with(&out, 1, "error: /no/such/level.yaml: cannot read the file");
        assert_eq!(stderr(&out).matches("/no/such/level.yaml").count(), 1);
    }
}

#[test]
fn a_generator_of_the_other_game_is_refused_by_name() {
    let out = arlpcg(words(
        "generate --game racing --policies policies/platform --aux 0 --out x",
        &[],
    ));
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out)
            .contains("this is a platform generator policy, expected a racing generator one"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn bad_arguments_are_usage_errors() {
    let out = arlpcg(words("generate --rules --out x --aux 3", &[]));
    fails_with(&out, 2, "aux 3 is out of range [-1, 1]");
    let out = arlpcg(words("generate --rules --obstacles 3 --out x", &[]));
    fails_with(&out, 2, "--obstacles is for racing levels");
}

/// Arguments that cannot go together are usage errors (exit 2) as clap's own are; a missing
/// folder is named as such.
#[test]
fn arguments_that_do_not_fit_together_exit_2() {
    for (args, expected) in [
        (
            vec!["generate", "--policies", "policies/platform", "--out", "x"],
            "--policies needs --aux",
        ),
        (vec!["train", "--steps", "10"], "--out <OUT>"),
        (
            vec![
                "generate", "--rules", "--seed", "99999999999999999999999", "--out", "x",
            ],
            "number too large",
        ),
    ] {
        let out = arlpcg(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(expected),
            "{args:?}: {}",
            stderr(&out)
        );
    }
    let out = arlpcg(words("eval --policies /nonexistent --out x", &[]));
    fails_with(&out, 1, "--policies /nonexistent: no such folder");
}

/// `--aux=-0` is λ = 0: the same file name and the same bytes as `--aux 0`.
#[test]
fn minus_zero_aux_is_zero() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for (out, aux) in [(&a, "--aux=-0"), (&b, "--aux=0")] {
        let run = generate(out, &["--count", "1", "--format", "yaml", aux]);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    assert_eq!(files_of(&a), files_of(&b));
    assert_eq!(files_of(&a)[0].0, "platform_seed0_aux+0.00.yaml");
}

#[test]
fn running_without_a_command_prints_usage() {
    let out = arlpcg_ok::<&str>([]);
    let text = String::from_utf8(out.stdout).unwrap();
    for word in ["generate", "export", "verify", "Examples"] {
        assert!(text.contains(word), "usage lacks {word}: {text}");
    }
}

/// A policy path that is a device, a folder or a file far larger than any policy is refused
/// before it is read (`/dev/zero` read GBs).
#[test]
fn policy_paths_that_are_not_policy_files_are_refused_unread() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.safetensors");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len(300 * 1024 * 1024).unwrap(); // sparse: takes no disk
    let cases = [
        ("/dev/zero", "is not a regular file"),
        ("/", "is not a regular file"),
        (big.to_str().unwrap(), "more than the 268435456"),
    ];
    for (path, expected) in cases {
        let out = arlpcg(words(
            "verify levels/platform/platform_seed7_aux+1.00.yaml --solver policy --policy {}",
            &[&path],
        ));
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{path}: {err}");
        assert!(
            err.contains(path) && err.contains(expected),
            "{path}: {err}"
        );
    }
}

/// Nesting and alias bombs are refused before serde_yaml builds anything: a 100,000-deep level
/// took 45 s to fail, a file of repeated aliases grew to gigabytes and aborted.
#[test]
fn yaml_nesting_and_alias_bombs_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let header = "format: arlpcg-level\nversion: 1\ngame: platform\n";
    let deep = format!(
        "{header}x: {}1{}\n",
        "[".repeat(100_000),
        "]".repeat(100_000)
    );
    let blocks = "  - {distance: 6, angle: 0, size: 5, height: 0}\n".repeat(50);
    let aliases = vec!["*b"; 100_000].join(", ");
    let bomb = format!("{header}b: &b\n{blocks}c: [{aliases}]\n");
    for (name, text, expected) in [
        (
            "deep.yaml",
            deep,
            "nested more than 32 levels deep (line 4)",
        ),
        ("bomb.yaml", bomb, "aliases (*name) are not allowed"),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let out = arlpcg(words("verify {} --solver scripted", &[&path]));
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(name) && err.contains(expected), "{err}");
    }
}

/// A batch that cannot finish writes nothing: with --force, the files of an earlier batch keep
/// their bytes (an unreachable --goal failed after the first levels were written, or rewritten).
#[test]
fn a_batch_that_fails_writes_nothing_and_overwrites_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let first = generate(dir.path(), &["--count", "3", "--format", "yaml"]);
    assert!(first.status.success(), "{}", stderr(&first));
    let before = files_of(dir.path());
    let failed = generate(
        dir.path(),
        &[
            "--count", "3", "--format", "yaml", "--force", "--goal", "0,300,5",
        ],
    );
    fails_with(&failed, 1, "nothing was written");
    assert_eq!(files_of(dir.path()), before);
    // A verified batch whose level cannot be built fails before any level is played.
    let unbuildable = generate(
        dir.path(),
        &[
            "--count", "1", "--format", "yaml", "--force", "--goal", "0,300,5", "--verify", "20",
        ],
    );
    fails_with(&unbuildable, 1, "seed 0 (nothing was played or written)");
    assert_eq!(files_of(dir.path()), before);
}

/// Ctrl-C in a batch writes the levels finished so far, complete, leaves no temporary file,
/// says how many and exits 130.
#[test]
fn ctrl_c_in_a_batch_keeps_finished_levels_and_no_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args([
            "generate", "--game", "platform", "--rules", "--count", "5000",
        ])
        .args(["--verify", "20", "--format", "yaml,glb", "--out"])
        .arg(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let output = child.wait_with_output().unwrap();
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(130), "{err}");
    let files = files_of(dir.path());
    assert!(
        files.iter().all(|(name, _)| !name.starts_with('.')),
        "temporary files left: {:?}",
        files.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert_eq!(files.len() % 2, 0, "a level with only some of its files");
    let levels = files.len() / 2;
    assert!(
        err.contains(&format!("wrote the {levels} of 5000 levels")),
        "{err}"
    );
    for (name, _) in files.iter().filter(|(n, _)| n.ends_with(".yaml")) {
        let path = dir.path().join(name);
        arlpcg_ok(words("verify {} --solver scripted --trials 1", &[&path]));
    }
}

/// `eval --shard I/K` then `--merge` gives the unsharded results byte for byte; a missing
/// shard is named, and parts of different evaluations are refused.
#[test]
fn sharded_eval_merges_into_the_unsharded_results() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).display().to_string();
    let budget = [
        "--policies", "policies/platform", "--tracks", "2", "--trials", "3", "--validation-tracks",
        "4",
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["eval"];
        args.extend_from_slice(&budget);
        args.extend_from_slice(extra);
        arlpcg(&args)
    };
    // One thread for the whole run, all cores for the shards: the figures must not depend on it.
    let out = run(&["--threads", "1", "--out", &at("whole")]);
    assert!(out.status.success(), "{}", stderr(&out));
    for i in 0..3 {
        let shard = format!("{i}/3");
        let out = run(&["--shard", &shard, "--out", &at(&format!("part{i}"))]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let merge = |parts: &[&str], out_dir: &str| {
        let mut args = vec!["eval", "--merge"];
        let paths: Vec<String> = parts.iter().map(|p| at(p)).collect();
        args.extend(paths.iter().map(String::as_str));
        let out_path = at(out_dir);
        args.extend(["--out", out_path.as_str()]);
        arlpcg(&args)
    };
    let out = merge(&["part2", "part0", "part1"], "merged");
    assert!(out.status.success(), "{}", stderr(&out));
    for file in [
        "results.json", "results.md", "controllability.csv", "cross.csv",
    ] {
        assert_eq!(
            std::fs::read(dir.path().join("whole").join(file)).unwrap(),
            std::fs::read(dir.path().join("merged").join(file)).unwrap(),
            "{file} differs"
        );
    }
    let out = merge(&["part0", "part2"], "short");
    fails_with(&out, 1, "shard 1/3 is missing");
    let other_dir = at("other");
    arlpcg_ok(words(
        "eval --policies policies/platform --tracks 2 --trials 2 --validation-tracks 4 --shard 1/3 --out {}",
        &[&other_dir],
    ));
    let out = merge(&["part0", "other", "part2"], "mixed");
    fails_with(&out, 1, "their budget differ");
}

/// With --verify no level that no run completed is handed out: such draws are replaced by the
/// seed's next draw, and every level carries a certificate that `verify --replay` re-runs.
#[test]
fn verified_levels_are_completable_and_their_certificates_replay() {
    let dir = tempfile::tempdir().unwrap();
    let out = arlpcg_ok(words(
        "generate --policies policies/platform --aux -1 --count 12 --verify 1 --format yaml --out {}",
        &[&dir.path()],
    ));
    let said = String::from_utf8_lossy(&out.stdout);
    let mut levels = Vec::new();
    let mut redraws = 0;
    for (name, _) in files_of(dir.path()) {
        let path = dir.path().join(&name);
        let level = arlpcg_core::level::yaml::load(&path).unwrap();
        let stats = level.stats.clone().unwrap();
        assert!(stats.successes > 0, "{name}: no run completed it");
        assert!(stats.certificate.is_some(), "{name} has no certificate");
        redraws += stats.redraws;
        levels.push(path.display().to_string());
    }
    // At λ = -1 (success about 0.7) a level verified with one run is often completed by none.
    assert!(redraws > 0, "nothing was redrawn: {said}");
    assert!(said.contains("redrew"), "{said}");
    let mut args = vec!["verify", "--replay"];
    args.extend(levels.iter().map(String::as_str));
    let out = arlpcg_ok(&args);
    let replayed = String::from_utf8_lossy(&out.stdout);
    assert_eq!(replayed.matches("succeeds again").count(), 12, "{replayed}");
    // A certificate recorded by another policy is refused by name.
    let first = &levels[0];
    let text = std::fs::read_to_string(first).unwrap();
    let at = text.rfind("sha256: ").unwrap() + "sha256: ".len();
    let forged = format!("{}{}{}", &text[..at], "0".repeat(64), &text[at + 64..]);
    std::fs::write(first, forged).unwrap();
    let out = arlpcg(words("verify --replay {}", &[&first]));
    fails_with(&out, 1, "is not the policy that verified the level");
    let out = arlpcg(words("verify --replay levels/hand/staircase.yaml", &[]));
    fails_with(&out, 1, "no statistics");
    let out = arlpcg(words("generate --rules --allow-unsolved --out x", &[]));
    assert_eq!(out.status.code(), Some(2));
}

/// `--target-success P` hands out levels whose measured success is within ±0.1 of P, recording
/// the λ it used; the curve it starts from is the one kept beside the shipped policies.
/// A seed whose goal rules the band out (seed 3's scene: no λ or draw of the shipped Generator
/// measures under 0.55) gets a level of another seed's scene, which it records.
#[test]
fn target_success_borrows_another_seeds_scene_when_its_own_cannot_meet_the_band() {
    let dir = tempfile::tempdir().unwrap();
    arlpcg_ok(words(
        "generate --policies policies/platform --target-success 0.2 --seed 3 --verify 100 --format yaml --out {}",
        &[&dir.path()],
    ));
    let files = files_of(dir.path());
    assert_eq!(files.len(), 1);
    let (name, _) = &files[0];
    assert!(name.starts_with("platform_seed3_"), "{name}");
    let level = arlpcg_core::level::yaml::load(&dir.path().join(name)).unwrap();
    assert_ne!(
        level.seed,
        Some(3),
        "{name} was built from seed 3's own scene"
    );
    let stats = level.stats.unwrap();
    assert!(
        (stats.success_ratio - 0.2).abs() <= 0.1 + 1e-9,
        "{}",
        stats.success_ratio
    );
    // Given the goal, the search keeps to it, and seed 3's goal rules 0.2 out (closest 0.55).
    let own = dir.path().join("own");
    arlpcg_ok(words(
        "generate --policies policies/platform --aux -1 --seed 3 --format yaml --out {}",
        &[&own],
    ));
    let goal = arlpcg_core::level::yaml::load(&own.join("platform_seed3_aux-1.00.yaml"))
        .unwrap()
        .goal;
    let goal = format!("{},{},{}", goal[0], goal[1], goal[2]);
    let out = arlpcg(words(
        "generate --policies policies/platform --target-success 0.2 --seed 3 {} --out {}",
        &[&format!("--goal={goal}"), &dir.path().join("given")],
    ));
    fails_with(&out, 1, "no level within ±0.1 of success 0.2");
}

#[test]
fn target_success_levels_measure_within_the_band() {
    let dir = tempfile::tempdir().unwrap();
    let out = arlpcg_ok(words(
        "generate --policies policies/platform --target-success 0.6 --count 3 --verify 50 --format yaml --out {}",
        &[&dir.path()],
    ));
    assert!(
        !stderr(&out).contains("measuring"),
        "the shipped policies' curve is current: {}",
        stderr(&out)
    );
    let files = files_of(dir.path());
    assert_eq!(files.len(), 3);
    let mut auxes = Vec::new();
    for (name, _) in &files {
        assert!(name.ends_with("_success0.60.yaml"), "{name}");
        let level = arlpcg_core::level::yaml::load(&dir.path().join(name)).unwrap();
        let stats = level.stats.unwrap();
        assert!(
            (stats.success_ratio - 0.6).abs() <= 0.1 + 1e-9,
            "{name}: success {}",
            stats.success_ratio
        );
        assert!(stats.certificate.is_some());
        auxes.push(level.aux.unwrap());
    }
    // The λ used is recorded; the shipped policies' curve is 0.98 at λ = 0.5, so on average a
    // 0.6 level comes from well below it.
    assert!(auxes.iter().sum::<f64>() / 3.0 < 0.25, "{auxes:?}");
    for bad in ["0", "1", "1.5", "nan"] {
        let out = arlpcg(words(
            "generate --policies policies/platform --target-success {} --out x",
            &[&bad],
        ));
        assert_eq!(out.status.code(), Some(2), "{bad}");
    }
    let out = arlpcg(words("generate --rules --target-success 0.5 --out x", &[]));
    assert_eq!(
        out.status.code(),
        Some(2),
        "--target-success needs --policies"
    );
}

/// `--solver-policy` verifies a Generator's levels with another Solver than the one beside it,
/// and the level records which; without --verify it is refused.
#[test]
fn generate_verifies_with_the_solver_policy_it_is_given() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let policies = root.join("policies/platform");
    let other = policies.join("solver-rule-pcg.safetensors");
    arlpcg_ok(words(
        "generate --policies {} --aux 1 --verify 4 --solver-policy {} --format yaml --out {}",
        &[&policies, &other, &out],
    ));
    let yaml = std::fs::read_to_string(dir.path().join("platform_seed0_aux+1.00.yaml")).unwrap();
    let stats = &yaml[yaml.find("stats:").expect("verified")..];
    assert!(stats.contains("solver-rule-pcg.safetensors"), "{stats}");
    assert!(!stats.contains("solver.safetensors"), "{stats}");

    let refused = arlpcg(words(
        "generate --policies {} --aux 1 --solver-policy {} --out {}",
        &[&policies, &other, &out],
    ));
    fails_with(&refused, 2, "--solver-policy");
}

/// A seed whose draws no run completes is asked again easier, λ up by 0.25 after each 10
/// draws, each step said; the batch fails only when λ = 1 fails too (here an untrained Solver
/// completes nothing).
#[test]
fn generate_verify_eases_a_seed_that_no_run_completes_up_to_lambda_one() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.yaml");
    std::fs::write(
        &config,
        "seed: 3\nhidden: [16, 16]\nability_ranges: null\nppo:\n  num_envs: 4\n  num_steps: 32\n",
    )
    .unwrap();
    let run = dir.path().join("run");
    arlpcg_ok(words(
        "train --mode rule-pcg --steps 128 --config {} --out {}",
        &[&config, &run],
    ));
    let policies = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    let out = arlpcg(words(
        "generate --policies {} --aux=-0.5 --count 1 --verify 2 --solver-policy {} --out {}",
        &[
            &policies,
            &run.join("solver.safetensors"),
            &dir.path().join("levels"),
        ],
    ));
    fails_with(
        &out,
        1,
        "none of the 10 levels drawn for this seed at λ = +1.00",
    );
    let err = stderr(&out);
    let asked: Vec<&str> = err
        .lines()
        .filter_map(|line| line.split("; asking ").nth(1))
        .collect();
    assert_eq!(
        asked,
        [
            "λ = -0.25", "λ = +0.00", "λ = +0.25", "λ = +0.50", "λ = +0.75", "λ = +1.00"
        ],
        "{err}"
    );
    assert!(!dir.path().join("levels").exists(), "nothing written");
}

/// A seed whose goal the Generator cannot build toward at the asked λ (goals 7-8 m up for
/// Godot's 1 m jumper at λ = -1) is eased as an unsolved one is, each step said, instead of
/// failing the batch; the level records the λ it was built at.
#[test]
fn generate_verify_eases_a_seed_the_generator_cannot_build_at_its_lambda() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let policies = root.join("policies/platform");
    let profile = root.join("results/platform/profiles/godot4/profile.yaml");
    // The goals of seeds 4, 32 and 55 (7.4-8.1 m up), where the shipped Generator builds no
    // valid level at λ = -1 for this character; one of them is enough.
    let goal = [
        "4.868,8.056,-32.429", "15.277,7.435,-27.372", "28.818,7.753,-12.616",
    ]
    .into_iter()
    .find(|goal| {
        let plain = arlpcg(words(
            "generate --policies {} --profile {} --aux=-1 --goal {} --count 1 --out {}",
            &[&policies, &profile, goal, &dir.path().join("plain")],
        ));
        !plain.status.success() && stderr(&plain).contains("no valid level")
    })
    .expect("the shipped Generator builds a level toward every goal: pick higher ones");
    let levels = dir.path().join("levels");
    let out = arlpcg(words(
        "generate --policies {} --profile {} --aux=-1 --goal {} --count 1 --verify 5 --format yaml --out {}",
        &[&policies, &profile, &goal, &levels],
    ));
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("the Generator built no valid level at λ = -1.00; asking λ = -0.75"),
        "{err}"
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("over 1 levels; 1 of them built at an eased λ"),
        "{said}"
    );
    let file = std::fs::read_dir(&levels)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let yaml = std::fs::read_to_string(&file).unwrap();
    let aux: f64 = yaml
        .lines()
        .find_map(|line| line.strip_prefix("aux: "))
        .and_then(|aux| aux.parse().ok())
        .unwrap_or_else(|| panic!("no aux in {yaml}"));
    assert!(aux > -1.0, "{aux}");
}

#[test]
fn options_that_would_do_nothing_or_count_twice_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let level = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/levels/platform/platform_seed7_aux+0.50.yaml"
    );
    let keep = format!("{level}:2");
    let chart = dir.path().join("chart.png");
    std::fs::write(&chart, b"a chart already").unwrap();
    let chart = chart.to_str().unwrap();
    let nowhere = dir.path().join("nowhere");
    let nowhere = nowhere.to_str().unwrap();
    let cases: [(Vec<&str>, i32, &str); 6] = [
        (
            vec!["generate", "--rules", "--keep", &keep, "--out", out],
            2,
            "--keep needs --policies",
        ),
        (
            vec![
                "generate", "--rules", "--judge", "scripted-median", "--out", out,
            ],
            2,
            "--judge plays --verify",
        ),
        (
            vec![
                "verify", "--panel", "scripted-median,scripted-median", level,
            ],
            2,
            "scripted-median is named twice",
        ),
        (
            vec![
                "verify", "--panel", "--policies", nowhere, "--trials", "1", level,
            ],
            1,
            "no such policies folder",
        ),
        (
            vec![
                "generate", "--policies", "policies/platform", "--target-success", "-0.5", "--out",
                out,
            ],
            2,
            "`-0.5` is not a success ratio",
        ),
        (
            vec!["verify", "--chart", chart, level],
            1,
            "already exists: verify writes a new chart",
        ),
    ];
    for (args, code, message) in cases {
        let output = arlpcg(&args);
        fails_with(&output, code, message);
        assert!(!stderr(&output).contains("--force"), "{args:?}");
    }
    assert!(!dir.path().join("out").exists(), "nothing written");
    assert_eq!(std::fs::read(chart).unwrap(), b"a chart already");
}

/// A usage error quotes the argument it refuses; a huge one (a 25,000-point curve, 125 KB) is
/// cut down to its ends, and the reason still shows.
#[test]
fn a_huge_refused_argument_is_not_echoed_whole() {
    let curve = vec!["0:0"; 25_000].join(", ");
    let output = arlpcg(words(
        "generate --policies policies/platform --aux-curve {} --out never-written",
        &[&curve],
    ));
    fails_with(&output, 2, "an aux curve has 1 to 32 points, not 25000");
    assert!(
        stderr(&output).len() < 1_000,
        "{} bytes",
        stderr(&output).len()
    );
    assert!(!Path::new("never-written").exists());
}

/// A game profile: `init` prints one that `check` accepts; a bad one names its field; one under
/// which no level can be completed is refused; levels made for one record it and are played
/// under it, and a weaker jumper fails the staircase the built-in character climbs.
#[test]
fn a_game_profile_is_checked_recorded_and_played_under() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let init = arlpcg_ok(words("profile init --game platform", &[]));
    let text = String::from_utf8(init.stdout).unwrap();
    let write = |name: &str, text: &str| std::fs::write(path(name), text).unwrap();
    write("default.yaml", &text);
    let checked = arlpcg_ok(words("profile check {}", &[&path("default.yaml")]));
    let report = String::from_utf8_lossy(&checked.stdout);
    assert!(
        report.contains("reach table") && report.contains("+0 m: 6 m"),
        "{report}"
    );
    let low = text
        .replace("name: default", "name: low-jumper")
        .replace("jump_speed: 9.25", "jump_speed: 7.5");
    write("low.yaml", &low);
    write("nan.yaml", &text.replace("gravity: 20.0", "gravity: .nan"));
    fails_with(
        &arlpcg(words("profile check {}", &[&path("nan.yaml")])),
        1,
        "character.gravity must be a number",
    );
    write(
        "flat.yaml",
        &text.replace("jump_speed: 9.25", "jump_speed: 3.0"),
    );
    fails_with(
        &arlpcg(words("profile check {}", &[&path("flat.yaml")])),
        1,
        "most of the game's goals cannot be reached",
    );
    fails_with(
        &arlpcg(words(
            "generate --game racing --rules --profile {} --out {}",
            &[&path("low.yaml"), &path("x")],
        )),
        1,
        "a platform profile, not a racing one",
    );

    // Made for the low jumper: the level records it and is verified under it.
    let out = path("levels");
    arlpcg_ok(words(
        "generate --rules --count 1 --seed 3 --profile {} --verify 10 --format yaml --out {}",
        &[&path("low.yaml"), &out],
    ));
    let level = std::fs::read_to_string(dir.path().join("levels/platform_seed3.yaml")).unwrap();
    assert!(
        level.contains("profile:\n  name: low-jumper\n  sha256: "),
        "{level}"
    );
    let again = arlpcg_ok(words(
        "verify {} --solver scripted --trials 5",
        &[&format!("{out}/platform_seed3.yaml")],
    ));
    assert!(String::from_utf8_lossy(&again.stdout).contains("under profile `low-jumper`"));
    // Its export carries the abilities in the scene's extras.
    let gltf = path("level.gltf");
    arlpcg_ok(words(
        "export {} --out {}",
        &[&format!("{out}/platform_seed3.yaml"), &gltf],
    ));
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    let extras = &doc["scenes"][0]["extras"]["profile"];
    assert_eq!(extras["name"], "low-jumper", "{doc}");
    assert_eq!(extras["character"]["jump_speed"], 7.5);

    // The staircase: the built-in character climbs it, the low jumper does not.
    let staircase = concat!(env!("CARGO_MANIFEST_DIR"), "/levels/hand/staircase.yaml");
    let success = |extra: &[&str]| {
        let mut args = vec![
            "verify", staircase, "--solver", "scripted", "--trials", "10", "--json",
        ];
        args.extend_from_slice(extra);
        let out = arlpcg_ok(&args);
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (json["success_ratio"].as_f64().unwrap(), stderr(&out))
    };
    assert_eq!(success(&[]).0, 1.0);
    let (low_success, said) = success(&["--profile", &path("low.yaml")]);
    assert_eq!(low_success, 0.0);
    assert!(
        said.contains("made under the built-in profile; playing it under `low-jumper`"),
        "{said}"
    );
}

/// The shipped platform Solver trained over the characters within its ranges (jump speed 4-11
/// m/s): it plays a low jumper's levels, verifying or as the ARLPCG judge on the panel. Beyond
/// its range the scripted expert plays in its place and a line says why; `--solver policy`,
/// which names it, is refused there; without a profile it plays as before.
#[test]
fn the_shipped_solver_plays_a_profile_within_its_range() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    write_platform_profile(&path("low.yaml"), "low-jumper", "7.5");
    let staircase = concat!(env!("CARGO_MANIFEST_DIR"), "/levels/hand/staircase.yaml");
    write_platform_profile(&path("high.yaml"), "high-jumper", "11.5");
    let verify = |profile: &[&str]| {
        let mut args = vec!["verify", staircase, "--trials", "2", "--json"];
        args.extend_from_slice(profile);
        arlpcg(&args)
    };
    let played = |profile: &[&str]| {
        let out = verify(profile);
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (json["solver"].as_str().unwrap().to_string(), stderr(&out))
    };
    for profile in [&["--profile", &path("low.yaml")][..], &[]] {
        let (shipped, said) = played(profile);
        assert!(
            shipped.ends_with("policies/platform/solver.safetensors"),
            "{shipped}"
        );
        assert!(!said.contains("never trained"), "{said}");
    }
    let (stand_in, said) = played(&["--profile", &path("high.yaml")]);
    assert_eq!(stand_in, "scripted player (expert)");
    assert!(
        said.contains("profile `high-jumper` lies beyond the abilities the Solver policy")
            && said.contains("trained over (character.jump_speed")
            && said.contains(
                "): the scripted expert, who plays with any abilities, plays in its place"
            ),
        "{said}"
    );
    fails_with(
        &verify(&["--profile", &path("high.yaml"), "--solver", "policy"]),
        1,
        "profile `high-jumper` lies beyond the abilities the Solver policy",
    );
    // The ARLPCG judge, verifying and on the panel, plays the low jumper's level.
    let rated = path("rated");
    arlpcg_ok(words(
        "generate --policies policies/platform --aux 1 --profile {} --count 1 --verify 2 --judge arlpcg --panel --format yaml --out {}",
        &[&path("low.yaml"), &rated],
    ));
    let (_, yaml) = files_of(Path::new(&rated)).remove(0);
    let level = arlpcg_core::level::yaml::parse(std::str::from_utf8(&yaml).unwrap()).unwrap();
    let stats = level.stats.unwrap();
    let arlpcg_core::level::SolverRef::Policy { policy } = &stats.solver else {
        panic!("the ARLPCG judge verifies: {:?}", stats.solver)
    };
    assert!(
        policy.path.ends_with("platform/solver.safetensors"),
        "{}",
        policy.path
    );
    let panel = stats.panel.expect("--panel records the panel");
    let arlpcg = panel.judges.iter().find(|j| j.judge == "arlpcg").unwrap();
    assert_eq!(arlpcg.policy.as_ref(), Some(policy));
    // Beyond its abilities, the scripted expert verifies what is generated, and says so.
    let stood_in = path("stood-in");
    let out = arlpcg_ok(words(
        "generate --policies policies/platform --aux 1 --profile {} --count 1 --verify 2 --format yaml --out {}",
        &[&path("high.yaml"), &stood_in],
    ));
    assert!(
        stderr(&out)
            .contains("the scripted expert, who plays with any abilities, plays in its place"),
        "{}",
        stderr(&out)
    );
    let (_, yaml) = files_of(Path::new(&stood_in)).remove(0);
    let level = arlpcg_core::level::yaml::parse(std::str::from_utf8(&yaml).unwrap()).unwrap();
    assert!(
        matches!(
            level.stats.unwrap().solver,
            arlpcg_core::level::SolverRef::Scripted {
                skill: arlpcg_core::game::Skill::Expert
            }
        ),
        "the scripted expert verifies"
    );
}

/// A profile's piece ranges: `init` prints them, levels of both games keep within them, and a
/// range out of the format's or upside down names its field and writes nothing.
#[test]
fn a_profiles_piece_ranges_bound_its_levels_and_a_bad_range_names_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let init = |game: &str| {
        String::from_utf8(arlpcg_ok(words("profile init --game {}", &[&game])).stdout).unwrap()
    };
    let (platform, racing) = (init("platform"), init("racing"));
    assert!(platform.contains("blocks:\n") && platform.contains("max_distance: 10.0"));
    let narrow_blocks = platform
        .replace("max_distance: 10.0", "max_distance: 7.0")
        .replace("min_size: 4.0", "min_size: 5.0")
        .replace("max_turn: 180.0", "max_turn: 45.0");
    let narrow_segments = racing
        .replace("max_curve: 30.0", "max_curve: 10.0")
        .replace("road_width: 9.0", "road_width: 7.0")
        .replace("banking: 10.0", "banking: 0.0");
    for (game, text) in [("platform", &narrow_blocks), ("racing", &narrow_segments)] {
        let (profile, out) = (path(&format!("{game}.yaml")), path(game));
        std::fs::write(&profile, text).unwrap();
        arlpcg_ok(words(
            "generate --game {} --rules --count 4 --profile {} --format yaml --out {}",
            &[&game, &profile, &out],
        ));
        for (_, bytes) in files_of(Path::new(&out)) {
            let level =
                arlpcg_core::level::yaml::parse(std::str::from_utf8(&bytes).unwrap()).unwrap();
            match level.platform() {
                Some(track) => assert!(
                    track
                        .block_params()
                        .iter()
                        .all(|b| { b.distance <= 7.0 && b.size >= 5.0 && b.angle.abs() <= 45.0 })
                ),
                None => {
                    let track = level.racing().unwrap();
                    assert!(track.segments.iter().all(|s| s.curve.abs() <= 10.0));
                    // The road of the profile: 7 m wide and flat, in the file and the export.
                    let road = track.road();
                    assert_eq!((road.shape().width, road.shape().banking), (7.0, 0.0));
                    assert!(road.samples().iter().all(|p| p.bank == 0.0));
                    let scene = arlpcg_core::level::scene::Scene::of_level(&level);
                    assert_eq!(scene.extras["road_width"], 7.0);
                }
            }
        }
    }
    let bad = |from: &str, to: &str, said: &str| {
        let file = path("bad.yaml");
        std::fs::write(&file, narrow_blocks.replace(from, to)).unwrap();
        fails_with(&arlpcg(words("profile check {}", &[&file])), 1, said);
        let out = path("never");
        let made = arlpcg(words(
            "generate --rules --profile {} --out {}",
            &[&file, &out],
        ));
        fails_with(&made, 1, said);
        assert!(!Path::new(&out).exists());
    };
    bad(
        "min_distance: 5.0",
        "min_distance: 8.0",
        "blocks.min_distance 8 is above blocks.max_distance 7",
    );
    bad(
        "max_size: 6.0",
        "max_size: 9.0",
        "blocks.max_size 9 is out of range [4, 6] m",
    );
    let file = path("bad-road.yaml");
    std::fs::write(&file, racing.replace("road_width: 9.0", "road_width: 20.0")).unwrap();
    fails_with(
        &arlpcg(words("profile check {}", &[&file])),
        1,
        "segments.road_width 20 is out of range [6, 14] m",
    );
}

/// Writes to `path` our platform profile as `profile init` prints it, named `name`, with jump
/// speed `jump` (m/s, as written).
fn write_platform_profile(path: &str, name: &str, jump: &str) {
    let init = arlpcg_ok(words("profile init --game platform", &[]));
    let text = String::from_utf8(init.stdout)
        .unwrap()
        .replace("name: default", &format!("name: {name}"))
        .replace("jump_speed: 9.25", &format!("jump_speed: {jump}"));
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_solver_trained_for_a_profile_records_it_and_keeps_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    write_platform_profile(&path("default.yaml"), "default", "9.25");
    let low_path = path("low.yaml");
    write_platform_profile(&low_path, "low-jumper", "7.5");
    // Its configuration and card record the profile, a resume keeps it, and it plays under the
    // low jumper's abilities without a word of warning. One character (`--ability-spread 0`
    // turns off any ranges a recipe names).
    let run = path("run");
    let train = |extra: &[&str]| {
        let mut args = vec![
            "train", "--mode", "rule-pcg", "--threads", "1", "--ability-spread", "0", "--out", &run,
        ];
        args.extend_from_slice(extra);
        arlpcg(&args)
    };
    fails_with(
        &train(&[
            "--game", "racing", "--steps", "8192", "--profile", &low_path,
        ]),
        1,
        "--profile is a platform profile and the run is a racing one",
    );
    assert!(
        train(&["--steps", "8192", "--profile", &low_path])
            .status
            .success()
    );
    let card = std::fs::read_to_string(dir.path().join("run/solver.yaml")).unwrap();
    assert!(card.contains("profile:\n  name: low-jumper"), "{card}");
    fails_with(
        &train(&[
            "--resume",
            "--steps",
            "16384",
            "--profile",
            &path("default.yaml"),
        ]),
        1,
        "profile cannot change in a resumed run",
    );
    let trained = arlpcg_ok(words(
        "verify {} --profile {} --policy {} --trials 2",
        &[
            &concat!(env!("CARGO_MANIFEST_DIR"), "/levels/hand/staircase.yaml"),
            &low_path,
            &format!("{run}/solver.safetensors"),
        ],
    ));
    assert!(
        !stderr(&trained).contains("never trained"),
        "{}",
        stderr(&trained)
    );
}

#[test]
fn an_ability_aware_pair_plays_within_its_range_and_refuses_beyond() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for (name, jump) in [("near", "8.5"), ("far", "7.0")] {
        write_platform_profile(&path(&format!("{name}.yaml")), name, jump);
    }
    let refused = path("refused");
    // A share beyond ±50% is refused before anything is made.
    fails_with(
        &arlpcg(words("train --ability-spread 0.7 --out {}", &[&refused])),
        2,
        "`0.7` is not a share within [0, 0.5]",
    );
    assert!(!Path::new(&refused).exists());
    // Five characters (jumps 8-9.5 m/s, ours otherwise): each one's reach is measured once.
    let (run, trained) = crate::common::five_jumpers_pair();
    let run = run.to_str().unwrap().to_string();
    // The finished pair checks its own knob (2 levels × 2 runs at each end here), says how it
    // fared on its last line...
    let said = String::from_utf8_lossy(&trained.stdout);
    assert!(
        said.contains("own check (2 levels × 2 runs at each end): its Solver succeeds")
            && said.contains("bars: ≥ 0.95, ≤ 0.7, ≥ 0.95")
            && said.contains("on rule levels it succeeds"),
        "{said}"
    );
    // ...and both agents observe the abilities; their cards say over which ranges, and carry
    // the check's figures.
    for card in ["solver.yaml", "generator.yaml"] {
        let card = std::fs::read_to_string(Path::new(&run).join(card)).unwrap();
        assert!(
            card.contains("- - abilities\n  - 3")
                && card.contains("character.jump_speed:\n  - 8.0\n  - 9.5"),
            "{card}"
        );
        assert!(
            card.contains("own_success_at_+1:")
                && card.contains("own_success_at_-1:")
                && card.contains("own_completed_least:")
                && card.contains("own_success_on_rule_levels:"),
            "{card}"
        );
    }
    // Its Generator builds for a profile within the range.
    arlpcg_ok(words(
        "generate --policies {} --aux=-1 --profile {} --count 1 --out {}",
        &[&run, &path("near.yaml"), &path("levels")],
    ));
    let staircase = concat!(env!("CARGO_MANIFEST_DIR"), "/levels/hand/staircase.yaml");
    let policy = format!("{run}/solver.safetensors");
    let verify = |profile: &str| {
        arlpcg(words(
            "verify {} --policy {} --trials 2 --profile {}",
            &[&staircase, &policy, &profile],
        ))
    };
    let near = verify(&path("near.yaml"));
    assert!(near.status.success(), "{}", stderr(&near));
    assert!(
        !stderr(&near).contains("never trained"),
        "{}",
        stderr(&near)
    );
    fails_with(
        &verify(&path("far.yaml")),
        1,
        "profile `far` lies beyond the abilities the Solver policy",
    );
    // A campaign judged by it refuses the same profile before it searches.
    let campaign = arlpcg(words(
        "campaign --policies {} --judge arlpcg --profile {} --levels 1 --ramp {} --out {}",
        &[&run, &path("far.yaml"), &"0:0.5, 1:0.5", &path("campaign")],
    ));
    fails_with(&campaign, 1, "profile `far` lies beyond the abilities");
    assert!(!Path::new(&path("campaign")).exists());
}

/// `eval` under a profile beyond the shipped Solvers' ranges names the pair's Solver, not the
/// first baseline it loaded, and writes nothing.
#[test]
fn eval_refuses_a_profile_beyond_the_shipped_solvers_naming_the_pairs_solver() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = dir.path().join("eval");
    let refused = arlpcg(words(
        "eval --game platform --policies {} --profile {} --out {}",
        &[
            &root.join("policies/platform"),
            &root.join("results/platform/profiles/threejs-fps/profile.yaml"),
            &out,
        ],
    ));
    fails_with(
        &refused,
        1,
        "profile `threejs-fps` lies beyond the abilities the Solver policy",
    );
    assert!(
        stderr(&refused).contains("platform/solver.safetensors trained over"),
        "{}",
        stderr(&refused)
    );
    assert!(!out.exists());
}

/// `--threads` on the commands that play: one worker or two, the same bytes.
#[test]
fn generate_and_verify_give_the_same_bytes_on_any_thread_count() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for (dir, threads) in [(&a, "1"), (&b, "2")] {
        let out = generate(
            dir.path(),
            &[
                "--count", "2", "--seed", "4", "--verify", "10", "--format", "yaml", "--threads",
                threads,
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let files = files_of(a.path());
    assert_eq!(files.len(), 2);
    assert!(
        files == files_of(b.path()),
        "--threads 1 and 2 made other files"
    );
    let level = a.path().join("platform_seed4.yaml");
    let verify = |threads: &str| {
        arlpcg_ok(words(
            "verify {} --trials 10 --json --threads {}",
            &[&level, &threads],
        ))
        .stdout
    };
    assert_eq!(verify("1"), verify("2"));
    fails_with(
        &arlpcg(words("verify {} --threads 0", &[&level])),
        2,
        "--threads",
    );
}

/// The shipped policies without a checkout as working folder: `$ARLPCG_POLICIES`, else
/// `policies/` beside the binary or above it; else an error that names every place looked at.
/// `--policies` always wins.
#[test]
fn the_shipped_policies_are_found_by_the_variable_or_beside_the_binary_else_named() {
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let at = |p: &str| dir.path().join(p);
    // A copy of the binary, outside the checkout (a link would lead back to it).
    let bin = at("opt/bin/arlpcg");
    std::fs::create_dir_all(at("opt/bin")).unwrap();
    if std::fs::hard_link(env!("CARGO_BIN_EXE_arlpcg"), &bin).is_err() {
        std::fs::copy(env!("CARGO_BIN_EXE_arlpcg"), &bin).unwrap();
    }
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shipped = checkout.join("policies");
    let level = checkout.join("levels/platform/platform_seed7_aux-1.00.yaml");
    let run = |var: Option<&Path>, args: Vec<std::ffi::OsString>| {
        let mut command = Command::new(&bin);
        command
            .current_dir(dir.path())
            .env("ARLPCG_CACHE", at("cache"))
            .env_remove("ARLPCG_POLICIES");
        if let Some(var) = var {
            command.env("ARLPCG_POLICIES", var);
        }
        command.args(args).output().unwrap()
    };
    let verify = || words("verify {} --trials 2", &[&level]);

    // Nowhere: a campaign names every place; verify falls back to the scripted player, saying why.
    let out = at("campaign");
    let nowhere = run(
        None,
        words("campaign --levels 1 --ramp 0:0.5 --out {}", &[&out]),
    );
    fails_with(
        &nowhere,
        1,
        "no shipped policies: looked for policies (in the working folder), ",
    );
    for place in ["opt/bin/policies", "opt/policies", "policies"] {
        assert!(
            stderr(&nowhere).contains(&at(place).display().to_string()),
            "{place}: {}",
            stderr(&nowhere)
        );
    }
    assert!(stderr(&nowhere).contains("set ARLPCG_POLICIES"));
    assert!(!out.exists());
    let scripted = run(None, verify());
    assert!(scripted.status.success(), "{}", stderr(&scripted));
    let rules = run(
        None,
        words("generate --rules --verify 2 --out {}", &[&at("rules")]),
    );
    assert!(rules.status.success(), "{}", stderr(&rules));
    assert!(
        stderr(&rules).contains("no shipped policies: looked for")
            && stderr(&rules).contains("the scripted expert verifies"),
        "{}",
        stderr(&rules)
    );
    assert!(
        stderr(&scripted)
            .contains("platform solver: scripted player (no shipped policies: looked for"),
        "{}",
        stderr(&scripted)
    );

    // The variable.
    let by_var = run(Some(&shipped), verify());
    assert!(by_var.status.success(), "{}", stderr(&by_var));
    let solver = shipped.join("platform/solver.safetensors");
    let said = format!("platform solver: policy {}", solver.display());
    assert!(stderr(&by_var).contains(&said), "{}", stderr(&by_var));
    // A variable naming no folder is an error; --policies wins over it.
    let bad = at("nowhere");
    let panel = |policies: &[&dyn AsRef<std::ffi::OsStr>]| {
        let mut args = verify();
        args.push("--panel".into());
        if let Some(folder) = policies.first() {
            args.extend(["--policies".into(), folder.as_ref().to_owned()]);
        }
        run(Some(&bad), args)
    };
    fails_with(
        &panel(&[]),
        1,
        &format!("ARLPCG_POLICIES={}: no such folder", bad.display()),
    );
    let given = panel(&[&shipped.join("platform")]);
    assert!(given.status.success(), "{}", stderr(&given));

    // Beside the binary, two folders up.
    std::os::unix::fs::symlink(&shipped, at("opt/policies")).unwrap();
    let beside = run(None, verify());
    assert!(beside.status.success(), "{}", stderr(&beside));
    let said = format!(
        "platform solver: policy {}",
        at("opt/policies/platform/solver.safetensors").display()
    );
    assert!(stderr(&beside).contains(&said), "{}", stderr(&beside));
}
