//! `arlpcg train` with tiny budgets: a killed run resumes from its checkpoint and its learning
//! curve continues (no restart, no gap, no repeat); runs refuse to clobber each other; the
//! trained policy loads with its card.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use arlpcg_core::game::platform::OBSERVATION_SIZE;
use arlpcg_core::game::platform::generator::GENERATOR_OBSERVATION_SIZE;
use arlpcg_core::level::Game;
use arlpcg_core::rl::checkpoint::{LoadedPolicy, Role, load_policy};

use crate::common::{arlpcg, arlpcg_ok, fails_with, stderr, words};

const TINY: &str = "\
seed: 3
hidden: [16, 16]
ability_ranges: null
checkpoint_minutes: 0.0
ppo:
  num_envs: 4
  num_steps: 32
  update_epochs: 2
  num_minibatches: 2
";

/// The columns the clock writes into a metrics file (two runs of the same bytes differ there):
/// wall time, steps/s, rollout and update seconds, and the time split.
const CLOCK_COLUMNS: [&str; 11] = [
    "wall_time_s", "steps_per_s", "rollout_s", "update_s", "env_s", "forward_s", "generator_s",
    "gae_s", "copies_s", "iteration_s", "update_mfu",
];

/// The rows of a metrics file (header included) without the clock's columns; none without
/// the file.
fn without_clock(path: &Path) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next()?.split(',').collect();
    let kept: Vec<usize> = (0..header.len())
        .filter(|&k| !CLOCK_COLUMNS.contains(&header[k]))
        .collect();
    let pick = |cells: Vec<&str>| kept.iter().map(|&k| cells[k]).collect::<Vec<_>>().join(",");
    Some(
        std::iter::once(pick(header.clone()))
            .chain(lines.map(|row| pick(row.split(',').collect())))
            .collect(),
    )
}

/// (iteration, global_step) of every metrics row.
fn curve(dir: &Path) -> Vec<(u64, u64)> {
    let text = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            let mut fields = line.split(',');
            (
                fields.next().unwrap().parse().unwrap(),
                fields.next().unwrap().parse().unwrap(),
            )
        })
        .collect()
}

/// A scratch folder holding the training configuration `config` (`tiny.yaml`), the folder
/// itself, and the path of a run folder in it (`run`, not made yet).
fn scratch(config: &str) -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tiny.yaml");
    std::fs::write(&path, config).unwrap();
    let out = dir.path().join("run");
    (dir, path, out)
}

#[test]
fn a_killed_run_resumes_where_its_checkpoint_stopped() {
    let (_dir, config, out) = scratch(TINY);
    let out_s = out.to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args([
            "train",
            "--mode",
            "fixed-track",
            "--steps",
            "100000000",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out_s,
            "--threads",
            "2",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Let it checkpoint a few iterations (every iteration with checkpoint_minutes 0), then kill it.
    let start = Instant::now();
    let rows = |out: &Path| {
        if out.join("metrics.csv").exists() {
            curve(out).len()
        } else {
            0
        }
    };
    while rows(&out) < 4 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the run made no progress"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let killed = child.id();
    child.kill().unwrap();
    child.wait().unwrap();
    let before = curve(&out);
    // The killed session leaves its lock, naming a process that is gone.
    let lock = out.join("train.lock");
    assert_eq!(
        std::fs::read_to_string(&lock).unwrap().trim(),
        killed.to_string()
    );
    a_live_lock_refuses_a_second_session(&out);
    // A stale lock does not hold (the sessions below take it over): its process is gone, or
    // its number now belongs to another program (this test's own).
    std::fs::write(&lock, format!("{}\n", std::process::id())).unwrap();
    let checkpoint = std::fs::read(out.join("checkpoint.safetensors")).unwrap();
    let saved = load_policy(&checkpoint, Game::Platform, Role::Solver, OBSERVATION_SIZE).unwrap();
    let state = saved.training_state().unwrap();
    assert!(
        state.iteration >= 3 && state.global_step == state.iteration * 128,
        "{:?}",
        (state.iteration, state.global_step)
    );

    wrong_resumes_are_refused(out_s);

    let target = state.global_step + 3 * 128;
    arlpcg_ok(words(
        "train --mode fixed-track --steps {} --out {} --resume --threads 2",
        &[&target.to_string(), &out_s],
    ));
    assert!(!lock.exists(), "a finished session removes its lock");
    let after = curve(&out);
    // The rows up to the checkpoint are kept, later ones (written after it) dropped and redone.
    assert_eq!(
        &after[..state.iteration as usize],
        &before[..state.iteration as usize]
    );
    for (k, (iteration, step)) in after.iter().enumerate() {
        assert_eq!(
            (*iteration, *step),
            (k as u64 + 1, (k as u64 + 1) * 128),
            "the curve restarted or skipped: {after:?}"
        );
    }
    assert_eq!(after.last().unwrap().1, target);
    // The budget is stored with the run: the first command plus --resume (no --steps) stops
    // at it at once.
    arlpcg_ok(words(
        "train --mode fixed-track --seed 3 --out {} --resume",
        &[&out_s],
    ));
    assert_eq!(curve(&out), after);
    the_card_records_the_whole_run(&out, target);
}

/// The finished policy loads with its card, which records the whole run: its budget, mode,
/// network, and the command of every session.
fn the_card_records_the_whole_run(out: &Path, target: u64) {
    let out_s = out.to_str().unwrap();
    let policy = std::fs::read(out.join("solver.safetensors")).unwrap();
    let loaded = load_policy(&policy, Game::Platform, Role::Solver, OBSERVATION_SIZE).unwrap();
    assert_eq!(loaded.card.training.steps, target);
    assert_eq!(loaded.card.training.mode.name(), "fixed-track");
    // The card names the command that started the run and each session that resumed it.
    assert!(
        loaded
            .card
            .training
            .command
            .starts_with("arlpcg train --mode fixed-track --steps 100000000"),
        "{}",
        loaded.card.training.command
    );
    let resumes = &loaded.card.training.resumed_with;
    assert_eq!(resumes.len(), 2, "{resumes:?}");
    assert!(resumes.iter().all(|command| command.contains("--resume")));
    assert!(resumes[1].ends_with(&format!("--seed 3 --out {out_s} --resume")));
    assert_eq!(loaded.card.network.hidden, vec![16, 16]);
    let card: serde_yaml::Value =
        serde_yaml::from_str(&std::fs::read_to_string(out.join("solver.yaml")).unwrap()).unwrap();
    assert_eq!(card["role"], "solver");
}

/// A lock held by a live process refuses a second session, naming the lock file, and changes
/// nothing. The holder is util-linux's `flock`, which takes the lock a session takes.
fn a_live_lock_refuses_a_second_session(out: &Path) {
    let lock = out.join("train.lock");
    let before = curve(out);
    let out_s = out.to_str().unwrap();
    // `-o`: the lock stays with `flock` itself (not its `sleep`), so killing it lets go.
    let mut holder = Command::new("flock")
        .arg("-o")
        .arg(&lock)
        .args(["sleep", "60"])
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let busy = arlpcg(words(
        "train --mode fixed-track --steps 100000 --out {} --resume",
        &[&out_s],
    ));
    holder.kill().unwrap();
    holder.wait().unwrap();
    fails_with(&busy, 1, "in use by another training session");
    assert!(stderr(&busy).contains("train.lock"), "{}", stderr(&busy));
    assert_eq!(curve(out), before);
}

/// Resuming without --resume, or with another mode or seed, is refused.
fn wrong_resumes_are_refused(out_s: &str) {
    let refused = arlpcg(words(
        "train --mode fixed-track --steps 100 --out {}",
        &[&out_s],
    ));
    fails_with(&refused, 1, "add --resume");
    // A resume with another mode or game is refused, naming the run's own.
    for other in [["--mode", "rule-pcg"], ["--game", "racing"]] {
        let refused = arlpcg(words(
            "train {} {} --steps 100 --out {} --resume",
            &[&other[0], &other[1], &out_s],
        ));
        fails_with(&refused, 1, "is a platform fixed-track run");
    }
    // A resume with another seed is refused by name; the run's own seed may be given again.
    let refused = arlpcg(words(
        "train --mode fixed-track --seed 5 --out {} --resume",
        &[&out_s],
    ));
    fails_with(&refused, 1, "seed cannot change");
    files_of_another_run_are_refused(Path::new(out_s));
}

/// A run folder holding another run's files (another game's `config.yaml`, metrics of other
/// columns) is refused by the file's name, and resumes once its own files are back.
fn files_of_another_run_are_refused(out: &Path) {
    let resume = [
        "train",
        "--steps",
        "100",
        "--out",
        out.to_str().unwrap(),
        "--resume",
    ];
    let racing = arlpcg_ok(words("train --game racing --print-config", &[])).stdout;
    let metrics = "racing,columns\n1,2\n";
    for (name, foreign) in [
        ("config.yaml", &racing[..]),
        ("metrics.csv", metrics.as_bytes()),
    ] {
        let path = out.join(name);
        let own = std::fs::read(&path).unwrap();
        std::fs::write(&path, foreign).unwrap();
        let refused = arlpcg(resume);
        fails_with(&refused, 1, "holds files of two different runs");
        assert!(stderr(&refused).contains(name), "{}", stderr(&refused));
        assert_eq!(
            std::fs::read(&path).unwrap(),
            foreign,
            "{name} was rewritten"
        );
        std::fs::write(&path, own).unwrap();
    }
}

#[test]
fn bad_training_configs_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("bad.yaml");
    std::fs::write(&config, "ppo:\n  learning_rat: 0.1\n").unwrap();
    let out = arlpcg(words(
        "train --steps 10 --config {} --out {}",
        &[&config, &dir.path().join("r")],
    ));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("bad.yaml") && err.contains("unknown field `learning_rat`"),
        "{err}"
    );
}

/// Every field is range-checked before anything is allocated or written: values that aborted
/// with out-of-memory, trained on NaN or were silently accepted are refused with the field's
/// name, and no run folder is left behind.
#[test]
fn out_of_range_training_configs_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("ppo:\n  num_envs: 100000000\n", "solver.num_envs"),
        ("hidden: [1000000000, 1000000000]\n", "hidden"),
        ("hidden: [1e9, 1e9]\n", "hidden"),
        ("ppo:\n  ent_coef: .nan\n", "solver.ent_coef"),
        ("ppo:\n  clip_coef: .nan\n", "solver.clip_coef"),
        ("ppo:\n  clip_coef: -0.2\n", "solver.clip_coef"),
        ("ppo:\n  learning_rate: .inf\n", "solver.learning_rate"),
        ("ppo:\n  max_grad_norm: 0\n", "solver.max_grad_norm"),
        ("ppo:\n  target_kl: -1\n", "solver.target_kl"),
        ("steps: 0\n", "steps"),
        ("checkpoint_minutes: -1\n", "checkpoint_minutes"),
        ("checkpoint_minutes: .nan\n", "checkpoint_minutes"),
        (
            "ppo:\n  num_envs: 2\n  num_steps: 4\n  num_minibatches: 9\n",
            "solver.num_minibatches",
        ),
        (
            "generator:\n  ppo:\n    gamma: 1.5\n", "generator.ppo.gamma",
        ),
        (
            "generator:\n  solver_phase_steps: 0\n", "solver_phase_steps",
        ),
        (
            "generator:\n  rewards:\n    knobs: [1]\n",
            "generator.rewards.knobs",
        ),
        (
            "generator:\n  rewards:\n    knobs: [1, .nan]\n",
            "generator.rewards",
        ),
        ("generator:\n  knob_values: [2]\n", "generator.knob_values"),
    ];
    let deep = format!("seed: {}1{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let aliases = format!(
        "hidden: &h [8, 8]\ngenerator:\n  aux_values: [{}]\n",
        vec!["*h"; 1000].join(",")
    );
    let cases = cases
        .iter()
        .map(|(text, field)| (text.to_string(), *field))
        .chain([
            (deep, "nested more than 32 levels deep (line 1)"),
            (aliases, "aliases (*name) are not allowed"),
        ]);
    for (k, (text, field)) in cases.enumerate() {
        let config = dir.path().join(format!("bad-{k}.yaml"));
        std::fs::write(&config, &text).unwrap();
        let run = dir.path().join(format!("run-{k}"));
        let out = arlpcg(words(
            "train --steps 10 --config {} --out {}",
            &[&config, &run],
        ));
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{text}: {err}");
        assert!(
            err.contains(&format!("bad-{k}.yaml")) && err.contains(field),
            "{text}: the error should name the file and {field}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            !run.exists(),
            "{text}: a refused config left {}",
            run.display()
        );
    }
}

/// A fixed-aux run plays only λ = 1 matches: a configuration whose finish waits for the Solver
/// to fail hard matches (the racing ARLPCG recipe's) would never end its Generator phase early,
/// so it is refused, naming the file and the field; the mode's own defaults have no finish.
#[test]
fn a_fixed_aux_run_refuses_a_finish_that_waits_for_hard_matches() {
    let dir = tempfile::tempdir().unwrap();
    let recipe = arlpcg(words(
        "train --game racing --mode arlpcg --print-config",
        &[],
    ));
    let config = dir.path().join("racing-arlpcg.yaml");
    std::fs::write(&config, &recipe.stdout).unwrap();
    let run = dir.path().join("run");
    let out = arlpcg(words(
        "train --game racing --mode fixed-aux --config {} --out {}",
        &[&config, &run],
    ));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("racing-arlpcg.yaml") && err.contains("generator_until_hard_success"),
        "{err}"
    );
    assert!(!run.exists(), "a refused run left {}", run.display());
    let defaults = arlpcg(words(
        "train --game racing --mode fixed-aux --print-config",
        &[],
    ));
    // What --print-config prints for fixed-aux reads back as fixed-aux's defaults: the
    // racing finish's stop is not filled in from the game's defaults.
    let text = String::from_utf8(defaults.stdout).unwrap();
    let read_back =
        arlpcg::services::train::TrainConfig::parse_for(&text, arlpcg_core::level::Game::Racing)
            .unwrap();
    assert_eq!(
        read_back,
        arlpcg::services::train::TrainConfig::for_run(
            arlpcg_core::level::Game::Racing,
            arlpcg_core::rl::checkpoint::TrainMode::FixedAux
        )
    );
    let defaults: arlpcg::services::train::TrainConfig = serde_yaml::from_str(&text).unwrap();
    assert_eq!(defaults.adversarial_budget(), defaults.steps);
}

/// A configuration file is laid over its mode's defaults, not arlpcg's: a rule-pcg Solver
/// keeps its four update passes beside the file's width, and `--print-config --config` shows
/// just that.
#[test]
fn a_configuration_file_lies_over_its_modes_defaults() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("wide.yaml");
    std::fs::write(&config, "hidden: [32, 32]\n").unwrap();
    let printed = arlpcg_ok(words(
        "train --game platform --mode rule-pcg --config {} --print-config",
        &[&config],
    ))
    .stdout;
    let printed: arlpcg::services::train::TrainConfig = serde_yaml::from_slice(&printed).unwrap();
    assert_eq!(printed.hidden, vec![32, 32]);
    assert_eq!(
        printed.solver.update_epochs,
        arlpcg::services::train::SOLO_SOLVER_UPDATE_EPOCHS
    );
    let adversarial = arlpcg_ok(words(
        "train --game platform --mode arlpcg --config {} --print-config",
        &[&config],
    ))
    .stdout;
    let adversarial: arlpcg::services::train::TrainConfig =
        serde_yaml::from_slice(&adversarial).unwrap();
    assert_ne!(
        adversarial.solver.update_epochs,
        arlpcg::services::train::SOLO_SOLVER_UPDATE_EPOCHS
    );
}

/// Ctrl-C, and SIGTERM as Slurm and Kubernetes stop a job, save a checkpoint and the policy,
/// then exit 130.
#[test]
fn a_signal_saves_a_checkpoint_and_the_policy_and_exits_130() {
    for signal in ["-INT", "-TERM"] {
        stopped_by(signal);
    }
}

fn stopped_by(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.yaml");
    // Checkpoints only at the end: Ctrl-C must write one itself.
    std::fs::write(
        &config,
        TINY.replace("checkpoint_minutes: 0.0", "checkpoint_minutes: 600.0"),
    )
    .unwrap();
    let out = dir.path().join("run");
    let child = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args([
            "train",
            "--steps",
            "100000000",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    // Counted in whole lines: the run may be writing the next row while it is read.
    let rows = || {
        std::fs::read_to_string(out.join("metrics.csv"))
            .map_or(0, |text| text.matches('\n').count().saturating_sub(1))
    };
    while rows() < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the run made no progress"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(!out.join("checkpoint.safetensors").exists());
    let interrupted = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(interrupted.success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(
        output.status.code(),
        Some(130),
        "{signal}: interrupted, after saving"
    );
    assert!(String::from_utf8_lossy(&output.stdout).contains("stopped (Ctrl-C"));
    let checkpoint = std::fs::read(out.join("checkpoint.safetensors")).unwrap();
    let state = load_policy(&checkpoint, Game::Platform, Role::Solver, OBSERVATION_SIZE)
        .unwrap()
        .training_state()
        .unwrap();
    assert_eq!(
        state.iteration as usize,
        curve(&out).len(),
        "the checkpoint holds every iteration the metrics show"
    );
    assert!(out.join("solver.safetensors").exists() && out.join("solver.yaml").exists());
}

const TINY_ADVERSARIAL: &str = "\
seed: 5
hidden: [16, 16]
ability_ranges: null
checkpoint_minutes: 0.0
solver:
  num_envs: 4
  num_steps: 32
  update_epochs: 1
  num_minibatches: 2
generator:
  ppo:
    num_envs: 4
    num_steps: 4
    update_epochs: 1
    num_minibatches: 2
  solver_warmup_steps: 128
  solver_phase_steps: 128
  generator_phase_steps: 16
  population: 2
  population_every_steps: 256
  own_check: {levels: 1, trials: 2}
  stages:
  - from_steps: 768
    solver_learning_rate: 0.0
    solver_phase_steps: 128
    generator_phase_steps: 8
  finish:
    solver_steps: 128
    generator_phase_steps: 8
";

/// The Solver steps of the snapshots a run's Generator card says it played against.
fn population(dir: &Path) -> Vec<u64> {
    load_network(dir, GENERATOR).card.training.population
}

/// A platform run's two networks: file, role and observation size.
const SOLVER: (&str, Role, usize) = ("solver.safetensors", Role::Solver, OBSERVATION_SIZE);
const GENERATOR: (&str, Role, usize) = (
    "generator.safetensors",
    Role::Generator,
    GENERATOR_OBSERVATION_SIZE,
);

/// One of a platform run's networks, loaded as the commands load it.
fn load_network(run: &Path, (file, role, size): (&str, Role, usize)) -> LoadedPolicy {
    load_policy(
        &std::fs::read(run.join(file)).unwrap(),
        Game::Platform,
        role,
        size,
    )
    .unwrap()
}

/// Generator iterations logged so far (rows of generator-metrics.csv).
fn generator_rows(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("generator-metrics.csv"))
        .unwrap()
        .lines()
        .count()
        - 1
}

#[test]
fn an_adversarial_run_alternates_phases_resumes_and_its_generator_builds_levels() {
    let (dir, config, out) = scratch(TINY_ADVERSARIAL);
    let out_s = out.to_str().unwrap();
    let config_s = config.to_str().unwrap();
    let first = arlpcg_ok(words(
        "train --mode arlpcg --steps 512 --config {} --out {}",
        &[&config_s, &out_s],
    ));
    // Its standard error is a pipe, where no bar is drawn: each phase change has its line.
    let log = String::from_utf8_lossy(&first.stderr);
    for phase_ends in ["Solver steps: solver: ", "Solver steps: generator: "] {
        assert!(
            log.contains(phase_ends),
            "no line for {phase_ends:?} in {log}"
        );
    }
    // 512 Solver steps in phases of 128: both agents learned, in turn; then the finish's 128.
    assert_eq!(curve(&out).last().unwrap().1, 512 + 128);
    let generator_before = generator_rows(&out);
    assert!(
        generator_before >= 3,
        "{generator_before} Generator iterations"
    );
    // Snapshots when a Solver phase ends at least 256 steps after the last one.
    let first_population = population(&out);
    assert!(
        !first_population.is_empty() && first_population.len() <= 2,
        "{first_population:?}"
    );
    arlpcg_ok(words(
        "train --mode arlpcg --steps 1024 --out {} --resume",
        &[&out_s],
    ));
    assert_eq!(curve(&out).last().unwrap().1, 1024 + 128);
    assert!(
        generator_rows(&out) > generator_before,
        "the Generator went on learning"
    );
    // The Solver is frozen (learning rate 0) in the first session's finish (past 512), and
    // from 768 Solver steps on: the last stage, then the finish past the new budget.
    for (step, rate) in learning_rates(&out) {
        let frozen = (512 < step && step <= 640) || step > 768;
        assert_eq!(frozen, rate == 0.0, "step {step}: learning rate {rate}");
    }
    // The population came back from the checkpoint and grew, keeping the newest two.
    let resumed_population = population(&out);
    assert_eq!(resumed_population.len(), 2, "{resumed_population:?}");
    assert!(resumed_population.last() > first_population.last());
    assert!(resumed_population.windows(2).all(|w| w[1] - w[0] >= 256));
    for network in [SOLVER, GENERATOR] {
        assert_eq!(
            load_network(&out, network).card.training.mode.name(),
            "arlpcg"
        );
    }
    // The run's folder is a policies folder for every command that takes one.
    generate_and_verify_with_a_run(dir.path(), out_s);
    evaluate_a_run(dir.path(), out_s);
    score_a_run_as_one_seed(dir.path(), out_s);
    // Another game's Generator metrics (racing names other piece features) are refused.
    let metrics = out.join("generator-metrics.csv");
    let own = std::fs::read_to_string(&metrics).unwrap();
    std::fs::write(&metrics, own.replacen("distance_easy", "curve_easy", 1)).unwrap();
    let refused = arlpcg(words("train --steps 2048 --out {} --resume", &[&out_s]));
    fails_with(
        &refused,
        1,
        "generator-metrics.csv: its columns are not those",
    );
}

/// A staged run with a finish, resumed with a larger budget (through its last stage and a
/// second finish), gives the same bytes every time, on one thread or two: the weights of both
/// networks and every metrics column but the clock's.
#[test]
fn a_staged_run_with_a_finish_resumes_to_the_same_bytes_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.yaml");
    std::fs::write(&config, TINY_ADVERSARIAL).unwrap();
    let config_s = config.to_str().unwrap();
    let train = |threads: &str| {
        let out = dir.path().join(format!("run-{threads}"));
        let out_s = out.to_str().unwrap();
        let first = [
            "train", "--mode", "arlpcg", "--config", config_s, "--out", out_s,
        ];
        // 640 Solver steps and the finish's 128 (the stage begins at 768)...
        arlpcg_ok([&first[..], &["--steps", "640", "--threads", threads]].concat());
        // ...then resumed to a budget of 1024, inside the stage, and the finish after it.
        arlpcg_ok(words(
            "train --mode arlpcg --steps 1024 --out {} --resume --threads {}",
            &[&out_s, &threads],
        ));
        out
    };
    let (one, two) = (train("1"), train("2"));
    assert_same_training(&one, &two, &[SOLVER, GENERATOR]);
    assert_eq!(curve(&one).last().unwrap().1, 1024 + 128);
}

/// The weights of `networks` and every metrics column but the clock's are the same in the two
/// runs.
fn assert_same_training(one: &Path, two: &Path, networks: &[(&str, Role, usize)]) {
    for &network in networks {
        let weights = |run: &Path| {
            let loaded = load_network(run, network);
            let mut tensors: Vec<(String, Vec<f32>)> = loaded
                .tensors
                .iter()
                .map(|(name, t)| (name.clone(), t.flatten_all().unwrap().to_vec1().unwrap()))
                .collect();
            tensors.sort_by(|a, b| a.0.cmp(&b.0));
            tensors
        };
        assert_eq!(weights(one), weights(two), "{}", network.0);
    }
    // Metrics without the clock's columns.
    for file in ["metrics.csv", "generator-metrics.csv"] {
        let rows = |run: &Path| without_clock(&run.join(file));
        assert_eq!(rows(one), rows(two), "{file}");
    }
}

/// A run paused (`--pause-at`) and resumed gives the bytes of the run never paused: the
/// episodes and matches under way go on where they were. An adversarial run with a stage and
/// a finish, paused inside its stage, and a Solver-only run.
#[test]
fn a_run_paused_mid_stage_resumes_to_the_bytes_of_one_never_paused() {
    let dir = tempfile::tempdir().unwrap();
    let train = |mode: &str, config: &str, steps: &str, pause_at: Option<&str>| {
        let name = format!("{mode}-{}", pause_at.unwrap_or("whole"));
        let path = dir.path().join(format!("{name}.yaml"));
        std::fs::write(&path, config).unwrap();
        let out = dir.path().join(name);
        let out_s = out.to_str().unwrap();
        let start = [
            "train",
            "--mode",
            mode,
            "--config",
            path.to_str().unwrap(),
            "--steps",
            steps,
            "--out",
            out_s,
        ];
        match pause_at {
            None => {
                arlpcg_ok(start);
            }
            Some(at) => {
                arlpcg_ok([&start[..], &["--pause-at", at]].concat());
                let paused = curve(&out).last().unwrap().1;
                let (at, steps): (u64, u64) = (at.parse().unwrap(), steps.parse().unwrap());
                assert!((at..steps).contains(&paused), "paused at {paused}");
                arlpcg_ok(words("train --mode {} --out {} --resume", &[&mode, &out_s]));
            }
        }
        out
    };
    // The stage begins at 768: paused at 896, inside it, with matches under way.
    let whole = train("arlpcg", TINY_ADVERSARIAL, "1024", None);
    let paused = train("arlpcg", TINY_ADVERSARIAL, "1024", Some("800"));
    assert_same_training(&whole, &paused, &[SOLVER, GENERATOR]);
    assert_eq!(curve(&paused).last().unwrap().1, 1024 + 128);
    // With retries a failed Solver starts again on the piece it failed, and the match goes on.
    let retries =
        TINY_ADVERSARIAL.replace("generator:\n", "generator:\n  rewards:\n    retries: 2\n");
    assert_ne!(retries, TINY_ADVERSARIAL);
    for run in [&whole, &paused] {
        std::fs::remove_dir_all(run).unwrap();
    }
    let whole = train("arlpcg", &retries, "1024", None);
    let paused = train("arlpcg", &retries, "1024", Some("800"));
    assert_same_training(&whole, &paused, &[SOLVER, GENERATOR]);
    let whole = train("rule-pcg", TINY, "640", None);
    let paused = train("rule-pcg", TINY, "640", Some("300"));
    assert_same_training(&whole, &paused, &[SOLVER]);
}

/// A run killed while its Generator learns (phases of six iterations here) resumes from its
/// last checkpoint to the bytes of one never stopped: the Generator's decisions not yet
/// learned from are in the checkpoint with the matches under way, half of them paced (λ
/// changing along the track).
#[test]
fn a_run_killed_while_its_generator_learns_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.yaml");
    let long_phases = TINY_ADVERSARIAL.replace(
        "  solver_phase_steps: 128\n  generator_phase_steps: 16",
        "  solver_phase_steps: 128\n  generator_phase_steps: 96\n  paced_share: 0.5",
    );
    assert_ne!(long_phases, TINY_ADVERSARIAL);
    std::fs::write(&config, &long_phases).unwrap();
    let args = |out: &Path| -> Vec<String> {
        let config = config.to_str().unwrap();
        let out = out.to_str().unwrap();
        [
            "train", "--mode", "arlpcg", "--config", config, "--steps", "768", "--out", out,
        ]
        .map(String::from)
        .to_vec()
    };
    let whole = dir.path().join("whole");
    arlpcg_ok(args(&whole));
    let killed = dir.path().join("killed");
    // The first Generator phase runs iterations 1 to 6: kill it after its third.
    kill_after_generator_rows(&args(&killed), &killed, 3);
    let killed_s = killed.to_str().unwrap();
    arlpcg_ok(words("train --mode arlpcg --out {} --resume", &[&killed_s]));
    assert_same_training(&whole, &killed, &[SOLVER, GENERATOR]);
}

/// Runs `arlpcg args` writing to `out` and kills it once its Generator metrics hold `rows`
/// rows (a checkpoint after each iteration in the tiny configurations).
fn kill_after_generator_rows(args: &[String], out: &Path, rows: usize) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let metrics = out.join("generator-metrics.csv");
    let start = Instant::now();
    // The header and `rows` rows.
    while std::fs::read_to_string(&metrics).map_or(0, |text| text.lines().count()) < 1 + rows {
        assert!(start.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// (solver_step, the columns that do not tell time, entropy) of each Generator metrics row.
fn generator_metrics(run: &Path) -> Vec<(u64, String, f64)> {
    let path = run.join("generator-metrics.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let entropy = header.iter().position(|c| *c == "entropy").unwrap();
    let kept = without_clock(&path).unwrap();
    text.lines()
        .zip(kept)
        .skip(1)
        .map(|(row, kept)| {
            let cells: Vec<&str> = row.split(',').collect();
            (
                cells[1].parse().unwrap(),
                kept,
                cells[entropy].parse().unwrap(),
            )
        })
        .collect()
}

/// A policy file's tensors, by name, as their values.
fn tensors(path: &Path) -> std::collections::BTreeMap<String, Vec<f32>> {
    candle_core::safetensors::load(path, &candle_core::Device::Cpu)
        .unwrap()
        .into_iter()
        .map(|(name, t)| (name, t.flatten_all().unwrap().to_vec1::<f32>().unwrap()))
        .collect()
}

/// [`TINY_ADVERSARIAL`] with its finish replaced by `fields` (one `key: value` per line).
fn tiny_with_finish(fields: &str) -> String {
    let finish: String = fields.lines().map(|line| format!("    {line}\n")).collect();
    TINY_ADVERSARIAL.replace(
        "    solver_steps: 128\n    generator_phase_steps: 8\n",
        &finish,
    )
}

/// An arlpcg run of `config` (a variant of [`TINY_ADVERSARIAL`], which it must differ from) to a
/// budget of 640 Solver steps and its finish, in `dir/run`.
fn train_tiny_to_640(dir: &Path, config: &str) -> std::path::PathBuf {
    assert_ne!(
        config, TINY_ADVERSARIAL,
        "the variant changes the tiny configuration"
    );
    let path = dir.join("variant.yaml");
    std::fs::write(&path, config).unwrap();
    let out = dir.join("run");
    arlpcg_ok(words(
        "train --mode arlpcg --steps 640 --config {} --out {}",
        &[&path, &out],
    ));
    out
}

/// An arlpcg run of the configuration file `config` to 640 Solver steps and its finish, in
/// `out`; with `pause_at`, paused there, looked at by `paused`, and resumed to its end.
fn train_640_resumed(
    out: &Path,
    config: &Path,
    pause_at: Option<&str>,
    paused: impl Fn(&Path),
) -> PathBuf {
    let start = words(
        "train --mode arlpcg --steps 640 --config {} --out {}",
        &[&config, &out],
    );
    match pause_at {
        None => arlpcg_ok(start),
        Some(at) => {
            arlpcg_ok(start.into_iter().chain(["--pause-at".into(), at.into()]));
            paused(out);
            arlpcg_ok(words("train --resume --out {}", &[&out]))
        }
    };
    out.to_path_buf()
}

/// A finish in which the Solver learns: it opens with the Generator's phase even when the
/// budget ends inside a Solver phase, and its Solver phase (here longer than what is left)
/// learns at the finish's constant rate to the end, against the Generator frozen.
#[test]
fn a_learning_finish_opens_with_the_generator_and_ends_with_the_solver_catching_up() {
    let dir = tempfile::tempdir().unwrap();
    let catch_up = TINY_ADVERSARIAL
        .replace("  solver_phase_steps: 128\n  generator_phase_steps: 16", "  solver_phase_steps: 384\n  generator_phase_steps: 16")
        .replace(
            "    solver_steps: 128\n    generator_phase_steps: 8\n",
            "    solver_steps: 192\n    generator_phase_steps: 8\n    solver_learning_rate: 1.0e-4\n    solver_phase_steps: 1000000\n",
        );
    let out = train_tiny_to_640(dir.path(), &catch_up);
    // Solver phases of 384 steps (three iterations of 128): the one from 384 is under way at
    // 640, where the finish begins; its first iteration (to 768) ends it...
    let generator_steps: Vec<u64> = std::fs::read_to_string(out.join("generator-metrics.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|row| row.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let in_finish: Vec<u64> = generator_steps.into_iter().filter(|&s| s > 640).collect();
    assert!(!in_finish.is_empty(), "the finish has a Generator phase");
    assert!(in_finish.iter().all(|&s| s == 768), "{in_finish:?}");
    // ...and the Solver learns at 1e-4 from 640 to the budget, 640 + 192.
    let finish_rates: Vec<(u64, f64)> = learning_rates(&out)
        .into_iter()
        .filter(|&(step, _)| step > 640)
        .collect();
    assert_eq!(finish_rates, vec![(768, 1e-4), (896, 1e-4)]);
}

/// A catch-up that ends at a success: with `until_hard_success: 0` the first block of hard
/// matches the Solver finishes in it ends the run, long before the finish's limit. Its matches
/// are unpaced (the recipe paces half of the finish's, which the stops do not count).
#[test]
fn a_catch_up_until_a_success_ends_the_run_early() {
    let dir = tempfile::tempdir().unwrap();
    let until = tiny_with_finish(
        "solver_steps: 64000\ngenerator_phase_steps: 8\nsolver_learning_rate: 1.0e-4\nsolver_phase_steps: 1000000\nuntil_hard_success: 0.0\npaced_share: null",
    );
    let out = train_tiny_to_640(dir.path(), &until);
    let last = curve(&out).last().unwrap().1;
    // The catch-up begins at 768 (after the finish's Generator phase) and ends with the
    // iteration that completes a block of hard matches (64, the platform recipe's, which this
    // finish keeps), before the limit of 640 + 64,000.
    assert!((896..640 + 64_000).contains(&last), "ended at {last}");
}

/// A finish's Generator phase that ends at a success: with `generator_until_hard_success: 1`
/// the first block of 32 hard matches ends it, long before its limit of 4,000 decisions, and
/// the catch-up that follows runs to the budget. With blocks of 96 (`hard_match_block`) the
/// same phase plays on until three times as many hard matches have ended. Unpaced, as above.
#[test]
fn a_finish_generator_phase_until_a_success_ends_early() {
    let finish_decisions = |block: &str| {
        let dir = tempfile::tempdir().unwrap();
        let until = tiny_with_finish(&format!(
            "solver_steps: 256\ngenerator_phase_steps: 4000\nsolver_learning_rate: 1.0e-4\nsolver_phase_steps: 1000000\npaced_share: null\ngenerator_until_hard_success: 1.0{block}"
        ));
        let out = train_tiny_to_640(dir.path(), &until);
        // Generator rows of the finish (its phase opens at the budget, 640), each with the
        // Generator's decisions so far; the batch is 16 decisions.
        let rows: Vec<(u64, u64)> = std::fs::read_to_string(out.join("generator-metrics.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|row| {
                let cells: Vec<&str> = row.split(',').collect();
                (cells[1].parse().unwrap(), cells[2].parse().unwrap())
            })
            .filter(|&(solver_steps, _)| solver_steps >= 640)
            .collect();
        assert!(!rows.is_empty(), "the finish has a Generator phase");
        // Then the Solver catches up to the budget, 640 + 256.
        assert_eq!(curve(&out).last().unwrap().1, 896);
        rows.last().unwrap().1 - rows[0].1 + 16
    };
    // Blocks of 32 (the platform recipe's own are 64).
    let decisions = finish_decisions("\nhard_match_block: 32");
    // 32 hard matches take a few dozen batches of these short levels, not the phase's 4,000
    // decisions.
    assert!((32..2_000).contains(&decisions), "{decisions} decisions");
    let in_blocks_of_96 = finish_decisions("\nhard_match_block: 96");
    assert!(
        in_blocks_of_96 > 2 * decisions && in_blocks_of_96 < 4_000,
        "blocks of 96: {in_blocks_of_96} decisions, of 32: {decisions}"
    );
}

/// `finish.reach_runs`: the finish's Generator cuts its jumps to the reach counted in that many
/// of the eight runs, and its card says so, so `generate` cuts its levels the same way; the
/// Solver's card and the Generator's before the finish name no reach. A run with it and with
/// knobs drawn and matches paced in the finish only, paused before the finish or where it
/// begins, resumes to the bytes of the run never paused: the matches it replays follow the
/// rules they were made under.
#[test]
fn a_finish_with_its_own_reach_writes_it_on_the_card_and_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let config = tiny_with_finish(
        "solver_steps: 384\ngenerator_phase_steps: 64\nreach_runs: 1\nknobs_only: true\npaced_share: 1.0",
    )
    .replace(
        "generator:\n",
        "generator:\n  rewards:\n    knobs: [1.0, 0.5]\n",
    );
    let path = dir.path().join("variant.yaml");
    std::fs::write(&path, &config).unwrap();
    let train = |name: &str, pause_at: Option<&str>| {
        train_640_resumed(&dir.path().join(name), &path, pause_at, |out| {
            let card = std::fs::read_to_string(out.join("generator.yaml")).unwrap();
            let paused_in_finish = curve(out).last().unwrap().1 >= 640;
            assert_eq!(card.contains("reach_runs: 1\n"), paused_in_finish, "{card}");
        })
    };
    let whole = train("whole", None);
    let card = std::fs::read_to_string(whole.join("generator.yaml")).unwrap();
    assert!(card.contains("reach_runs: 1\n"), "{card}");
    let solver_card = std::fs::read_to_string(whole.join("solver.yaml")).unwrap();
    assert!(!solver_card.contains("reach_runs"), "{solver_card}");
    for at in ["512", "640", "700"] {
        let paused = train(&format!("paused-{at}"), Some(at));
        assert_same_training(&whole, &paused, &[SOLVER, GENERATOR]);
    }
    let levels = dir.path().join("levels");
    arlpcg_ok(words(
        "generate --policies {} --aux -1 --count 2 --out {}",
        &[&whole, &levels],
    ));
}

/// `finish.paced_share`: the finish's matches are paced in that share, the matches before it
/// as `generator.paced_share` says (none on platform): every Generator row before the finish is
/// the run's without it, and the finish's differ.
#[test]
fn matches_paced_in_the_finish_only_leave_the_run_before_it_unchanged() {
    let rows = |paced: &str| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_with_finish(&format!(
            "solver_steps: 128\ngenerator_phase_steps: 64{paced}"
        ));
        let out = train_tiny_to_640(dir.path(), &config);
        let rows = without_clock(&out.join("generator-metrics.csv")).unwrap();
        let step = |row: &String| row.split(',').nth(1).unwrap().parse::<u64>().unwrap();
        let (before, finish): (Vec<String>, Vec<String>) =
            rows.into_iter().skip(1).partition(|row| step(row) < 640);
        (before, finish)
    };
    let (before, finish) = rows("");
    let (paced_before, paced_finish) = rows("\npaced_share: 1.0");
    assert!(!before.is_empty() && !finish.is_empty());
    assert_eq!(before, paced_before);
    assert_ne!(finish, paced_finish);
}

/// `finish.knobs_only`: a Generator's style knobs are drawn in the finish only, every knob 0
/// before it. Two such runs whose knobs are drawn from different values learn the same bytes up
/// to the finish and part in it; without the option they part from the start.
#[test]
fn knobs_drawn_in_the_finish_only_leave_the_run_before_it_unchanged() {
    // The Generator's rows (clock columns out) before the finish (Solver step < 640) and in it.
    let generator_rows = |knob_values: &str, knobs_only: bool| {
        let dir = tempfile::tempdir().unwrap();
        let finish =
            format!("solver_steps: 128\ngenerator_phase_steps: 64\nknobs_only: {knobs_only}");
        let knobs = format!(
            "generator:\n  rewards:\n    knobs: [1.0, 0.5]\n  knob_values: {knob_values}\n"
        );
        let config = tiny_with_finish(&finish).replace("generator:\n", &knobs);
        let out = train_tiny_to_640(dir.path(), &config);
        let rows = without_clock(&out.join("generator-metrics.csv")).unwrap();
        let step = |row: &String| row.split(',').nth(1).unwrap().parse::<u64>().unwrap();
        rows.into_iter()
            .skip(1)
            .partition::<Vec<String>, _>(|row| step(row) < 640)
    };
    let (before, finish) = generator_rows("[-1, 1]", true);
    let (ones_before, ones_finish) = generator_rows("[1]", true);
    assert!(!before.is_empty() && !finish.is_empty());
    assert_eq!(before, ones_before);
    assert_ne!(finish, ones_finish);
    let (drawn_before, _) = generator_rows("[-1, 1]", false);
    assert_ne!(before, drawn_before);
}

/// `generator.hard_success_floor`: a Generator phase before the finish whose hard matches the
/// Solver succeeds in less often than the floor leaves the next phase with the hard side unpaid.
/// A tiny Solver never succeeds in every hard match, so at 1 every phase after the first learns
/// from other rewards than without the floor, while the first one, and a floor of 0 that no
/// success falls below, keep the bytes of the run without it.
#[test]
fn a_hard_success_floor_leaves_the_hard_side_unpaid_after_a_phase_below_it() {
    let generator_rows = |floor: &str| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_with_finish("solver_steps: 128\ngenerator_phase_steps: 16")
            .replace("generator:\n", &format!("generator:\n{floor}"));
        let out = train_tiny_to_640(dir.path(), &config);
        let rows = without_clock(&out.join("generator-metrics.csv")).unwrap();
        let step = |row: &String| row.split(',').nth(1).unwrap().parse::<u64>().unwrap();
        // The rows before the finish (Solver step < 640).
        rows.into_iter()
            .skip(1)
            .filter(|row| step(row) < 640)
            .collect::<Vec<_>>()
    };
    // The recipe's own floor is 0.25: `null` turns it off.
    let paid = generator_rows("  hard_success_floor: null\n");
    let never_below = generator_rows("  hard_success_floor: 0.0\n");
    let always_below = generator_rows("  hard_success_floor: 1.0\n");
    assert!(paid.len() >= 3, "{paid:?}");
    assert_eq!(never_below, paid);
    assert_eq!(always_below[0], paid[0], "the first phase is paid");
    assert_ne!(always_below[1..], paid[1..]);
}

/// `generator.rule_level_share`: some of the Solver's environments play rule levels beside the
/// Generator's matches. Their episodes under way are part of the checkpoint: a run paused in a
/// Solver phase or a Generator phase and resumed ends in the bytes of the run never paused;
/// the share cannot change in a resumed run (it fixes how many matches there are), and one that
/// would leave the Generator no match is refused by name.
#[test]
fn rule_levels_beside_the_matches_resume_to_the_same_bytes_and_keep_their_share() {
    let dir = tempfile::tempdir().unwrap();
    let config = TINY_ADVERSARIAL.replace("generator:\n", "generator:\n  rule_level_share: 0.5\n");
    let path = dir.path().join("variant.yaml");
    std::fs::write(&path, &config).unwrap();
    let train = |name: &str, pause_at: Option<&str>| {
        train_640_resumed(&dir.path().join(name), &path, pause_at, |_| {})
    };
    let whole = train("whole", None);
    let plain = dir.path().join("plain");
    let tiny = dir.path().join("tiny.yaml");
    std::fs::write(&tiny, TINY_ADVERSARIAL).unwrap();
    arlpcg_ok(words(
        "train --mode arlpcg --steps 640 --config {} --out {}",
        &[&tiny, &plain],
    ));
    assert_ne!(
        without_clock(&whole.join("metrics.csv")),
        without_clock(&plain.join("metrics.csv"))
    );
    // Paused after the warm-up's first Solver iterations and inside a Generator phase.
    for at in ["300", "400"] {
        let paused = train(&format!("paused-{at}"), Some(at));
        assert_same_training(&whole, &paused, &[SOLVER, GENERATOR]);
    }
    let changed = arlpcg(words(
        "train --resume --steps 700 --config {} --out {}",
        &[&tiny, &whole],
    ));
    fails_with(
        &changed,
        1,
        "generator.rule_level_share cannot change in a resumed run",
    );
    let every = dir.path().join("every.yaml");
    std::fs::write(
        &every,
        TINY_ADVERSARIAL.replace("generator:\n", "generator:\n  rule_level_share: 0.9\n"),
    )
    .unwrap();
    let refused = arlpcg(words(
        "train --mode arlpcg --config {} --out {}",
        &[&every, &dir.path().join("every")],
    ));
    fails_with(
        &refused,
        1,
        "generator.rule_level_share must be a share in [0, 1)",
    );
}

/// `finish.own_check_every`: every so many Generator steps of the finish the pair plays its own
/// check aside, on seeds of its own, writing its policies as at a pause. A tiny pair never
/// passes the bars, so its finish learns to its cap in the bytes of the run without the check,
/// then ends with the Generator of its best check, not the one it learned last; a step count
/// of 0 is refused by name.
#[test]
fn a_finish_own_check_plays_aside_and_a_pair_that_never_passes_ends_with_its_best_checked_generator()
 {
    let run = |check: &str| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_with_finish(&format!(
            "solver_steps: 128\ngenerator_phase_steps: 64{check}"
        ));
        let out = train_tiny_to_640(dir.path(), &config);
        let rows = generator_metrics(&out);
        let card = std::fs::read_to_string(out.join("generator.yaml")).unwrap();
        let weights = |name: &str| tensors(&out.join(name));
        let best = out
            .join("generator-best-check.safetensors")
            .exists()
            .then(|| weights("generator-best-check.safetensors"));
        (
            rows,
            card.contains("own_success_at_-1"),
            weights("generator.safetensors"),
            best,
        )
    };
    let (plain, plain_checked, plain_generator, none) = run("");
    // Checks after 32 and 48 of the finish's 64 Generator steps (batches of 16): it learns on
    // after the last of them.
    let (checked, checked_checked, generator, best) = run("\nown_check_every: 24");
    assert!(
        plain_checked && checked_checked,
        "both end with the own check"
    );
    assert!(
        checked.iter().filter(|r| r.0 >= 640).count() >= 4,
        "{checked:?}"
    );
    let rows = |all: &[(u64, String, f64)]| all.iter().map(|r| r.1.clone()).collect::<Vec<_>>();
    assert_eq!(rows(&plain), rows(&checked));
    assert!(none.is_none(), "no check, no best-checked Generator");
    assert_eq!(
        Some(&generator),
        best.as_ref(),
        "ends with the best-checked Generator"
    );
    assert_ne!(generator, plain_generator, "not the one it learned last");
    let dir = tempfile::tempdir().unwrap();
    let zero = dir.path().join("zero.yaml");
    std::fs::write(
        &zero,
        tiny_with_finish("solver_steps: 128\nown_check_every: 0"),
    )
    .unwrap();
    let refused = arlpcg(words(
        "train --mode arlpcg --steps 640 --config {} --out {}",
        &[&zero, &dir.path().join("run")],
    ));
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    assert!(
        stderr(&refused).contains("finish.own_check_every"),
        "{}",
        stderr(&refused)
    );
}

/// `finish.generator_entropy` is the Generator's entropy bonus in the finish alone: with a large
/// one its policy spreads out there, and every row before the finish is the run without it.
#[test]
fn a_finish_generator_entropy_spreads_the_generator_in_the_finish_only() {
    let run = |entropy: &str| {
        let dir = tempfile::tempdir().unwrap();
        let config = tiny_with_finish(&format!(
            "solver_steps: 128\ngenerator_phase_steps: 400{entropy}"
        ))
        .replace("  ppo:\n", "  ppo:\n    learning_rate: 0.01\n");
        generator_metrics(&train_tiny_to_640(dir.path(), &config))
    };
    let (plain, spread) = (run(""), run("\ngenerator_entropy: 1.0"));
    let before = |rows: &[(u64, String, f64)]| -> Vec<String> {
        rows.iter()
            .filter(|r| r.0 < 640)
            .map(|r| r.1.clone())
            .collect()
    };
    assert!(!before(&plain).is_empty());
    assert_eq!(
        before(&plain),
        before(&spread),
        "the bonus waits for the finish"
    );
    let last = |rows: &[(u64, String, f64)]| rows.last().unwrap().2;
    assert!(
        last(&spread) > last(&plain) + 0.5,
        "entropy at the finish's end: {} with the bonus, {} without",
        last(&spread),
        last(&plain)
    );
}

/// `finish.scripted_opponent`: the scripted player plays a share of the finish's matches while
/// its Generator learns. Every Generator row before the finish is the run without it, the
/// finish's rows are not, and a run killed inside the finish's Generator phase (matches under
/// way that the scripted player was playing) resumes to the bytes of one never stopped.
#[test]
fn a_finish_with_a_scripted_opponent_changes_the_finish_alone_and_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    // The platform recipe's finish has the median controller: the plain run turns it off.
    let finish = "solver_steps: 128\ngenerator_phase_steps: 96";
    let plain = format!("{finish}\nscripted_opponent: null");
    let scripted = format!("{finish}\nscripted_opponent: {{skill: median, share: 0.5}}");
    let rows = |run: &Path| -> Vec<(u64, String)> {
        generator_metrics(run)
            .into_iter()
            .map(|(step, kept, _)| (step, kept))
            .collect()
    };
    let (plain_dir, whole_dir) = (dir.path().join("plain"), dir.path().join("whole"));
    for d in [&plain_dir, &whole_dir] {
        std::fs::create_dir(d).unwrap();
    }
    let plain = rows(&train_tiny_to_640(&plain_dir, &tiny_with_finish(&plain)));
    let whole = train_tiny_to_640(&whole_dir, &tiny_with_finish(&scripted));
    let with_opponent = rows(&whole);
    let split = |rows: &[(u64, String)]| -> (Vec<String>, Vec<String>) {
        let (before, finish): (Vec<_>, Vec<_>) = rows.iter().partition(|r| r.0 < 640);
        let text = |rows: Vec<&(u64, String)>| rows.into_iter().map(|r| r.1.clone()).collect();
        (text(before), text(finish))
    };
    let (plain_before, plain_finish) = split(&plain);
    let (before, in_finish) = split(&with_opponent);
    assert_eq!(plain_before, before, "the opponent waits for the finish");
    assert_eq!(
        in_finish.len(),
        6,
        "the finish's Generator phase: six iterations"
    );
    assert_ne!(
        plain_finish, in_finish,
        "the scripted player changes the finish"
    );
    // Its success on matches at λ > 0 and λ < 0: NaN where it played no match.
    let opponent_success = |run: &Path| -> Vec<(u64, [f64; 2])> {
        let text = std::fs::read_to_string(run.join("generator-metrics.csv")).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = |name: &str| header.iter().position(|c| *c == name).unwrap();
        let (easy, hard) = (at("scripted_success_easy"), at("scripted_success_hard"));
        lines
            .map(|row| {
                let cells: Vec<&str> = row.split(',').collect();
                let cell = |k: usize| cells[k].parse::<f64>().unwrap();
                (cells[1].parse().unwrap(), [cell(easy), cell(hard)])
            })
            .collect()
    };
    let played = |s: &[f64; 2]| s.iter().any(|x| x.is_finite());
    let (opponent_before, opponent_finish): (Vec<_>, Vec<_>) = opponent_success(&whole)
        .into_iter()
        .partition(|r| r.0 < 640);
    assert!(opponent_before.iter().all(|(_, s)| !played(s)));
    assert!(
        opponent_finish.iter().any(|(_, s)| played(s)),
        "{opponent_finish:?}"
    );
    assert!(
        opponent_finish
            .iter()
            .flat_map(|(_, s)| s)
            .all(|x| !x.is_finite() || (0.0..=1.0).contains(x))
    );
    assert!(
        opponent_success(&plain_dir.join("run"))
            .iter()
            .all(|(_, s)| !played(s))
    );
    // `easy_only`: it plays easy matches alone, leaving every hard one to the final Solver.
    let easy_dir = dir.path().join("easy");
    std::fs::create_dir(&easy_dir).unwrap();
    let easy_only =
        format!("{finish}\nscripted_opponent: {{skill: median, share: 0.5, easy_only: true}}");
    let easy = train_tiny_to_640(&easy_dir, &tiny_with_finish(&easy_only));
    let easy_finish: Vec<[f64; 2]> = opponent_success(&easy)
        .into_iter()
        .filter(|r| r.0 >= 640)
        .map(|r| r.1)
        .collect();
    assert!(
        easy_finish.iter().all(|s| !s[1].is_finite())
            && easy_finish.iter().any(|s| s[0].is_finite()),
        "{easy_finish:?}"
    );

    let config = dir.path().join("scripted.yaml");
    std::fs::write(&config, tiny_with_finish(&scripted)).unwrap();
    let killed = dir.path().join("killed");
    let killed_s = killed.to_str().unwrap();
    // Killed after the finish's third Generator iteration.
    let args = ["train", "--mode", "arlpcg", "--steps", "640", "--config"]
        .into_iter()
        .chain([config.to_str().unwrap(), "--out", killed_s])
        .map(String::from)
        .collect::<Vec<_>>();
    kill_after_generator_rows(&args, &killed, before.len() + 3);
    assert!(
        rows(&killed).len() < with_opponent.len(),
        "killed inside the finish"
    );
    arlpcg_ok(words("train --mode arlpcg --out {} --resume", &[&killed_s]));
    assert_same_training(&whole, &killed, &[SOLVER, GENERATOR]);
}

/// (global_step, learning_rate) of every metrics row.
fn learning_rates(run: &Path) -> Vec<(u64, f64)> {
    let metrics = std::fs::read_to_string(run.join("metrics.csv")).unwrap();
    metrics
        .lines()
        .skip(1)
        .map(|row| {
            let cells: Vec<&str> = row.split(',').collect();
            (cells[1].parse().unwrap(), cells[6].parse().unwrap())
        })
        .collect()
}

/// `generate` with the run's Generator, verified with its Solver; a goal it cannot reach and
/// a folder without a Generator are named.
fn generate_and_verify_with_a_run(dir: &Path, run: &str) {
    let levels = dir.join("levels");
    let levels_s = levels.to_str().unwrap();
    let generate = |goal: &str| {
        arlpcg(words(
            "generate --policies {} --aux -0.5 --seed 3 --verify 4 --goal {} --format yaml --out {}",
            &[&run, &goal, &levels_s],
        ))
    };
    // An untrained Generator may find no way to an arbitrary goal; a goal on the start block's
    // own spot is never reached either (blocks are at least 5 m apart), so expect the clear error.
    let generated = generate("0,0,0");
    assert!(!generated.status.success());
    let said = stderr(&generated);
    assert!(said.contains("no valid level"), "{said}");
    let (_, start, _) = arlpcg_core::game::platform::rules::goal_and_start(3, None);
    let [x, z] = arlpcg_core::level::heading::heading_direction(start.heading);
    let generated = generate(&format!("{},0,{}", 7.5 * x, 7.5 * z));
    assert!(generated.status.success(), "{}", stderr(&generated));
    let level =
        arlpcg_core::level::yaml::load(&levels.join("platform_seed3_aux-0.50.yaml")).unwrap();
    assert_eq!(level.aux, Some(-0.5));
    assert!(matches!(
        level.source,
        arlpcg_core::level::Source::Policy { .. }
    ));
    let stats = level
        .stats
        .expect("--verify stores the Solver's statistics");
    assert_eq!(stats.trials, 4);
    assert!(stats.solver.describe().contains("solver.safetensors"));

    let missing_aux = arlpcg(words("generate --policies {} --out {}", &[&run, &levels_s]));
    assert!(stderr(&missing_aux).contains("--aux"));
    let wrong = arlpcg(words(
        "generate --policies {} --aux 1 --out {}",
        &[&dir, &levels_s],
    ));
    assert!(stderr(&wrong).contains("generator.safetensors"));
}

/// `eval` over the run: every table, in every format, with the keys results.json promises; a
/// second eval into the same folder is refused.
fn evaluate_a_run(dir: &Path, run: &str) {
    let results = dir.join("results");
    let results_s = results.to_str().unwrap();
    arlpcg_ok(words(
        "eval --policies {} --tracks 2 --trials 2 --validation-tracks 4 --out {}",
        &[&run, &results_s],
    ));
    let json: serde_json::Value = crate::common::results_json(&results);
    let rows = json["controllability"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    for key in [
        "aux", "success_ratio", "completed_by_any", "avg_block_distance", "avg_block_size",
    ] {
        assert!(rows[0].get(key).is_some(), "controllability.{key}");
    }
    let by_judge = json["controllability_by_judge"].as_array().unwrap();
    let judges: std::collections::BTreeSet<&str> = by_judge
        .iter()
        .map(|row| row["judge"].as_str().unwrap())
        .collect();
    assert_eq!(
        judges,
        [
            "arlpcg", "scripted-expert", "scripted-median", "scripted-novice"
        ]
        .into(),
        "the run's Solver and the scripted player's skills"
    );
    assert_eq!(by_judge.len(), 4 * 5, "every judge at every λ");
    for key in ["aux", "success_ratio", "completed_by_any"] {
        assert!(
            by_judge[0].get(key).is_some(),
            "controllability_by_judge.{key}"
        );
    }
    let generalization = json["generalization"].as_array().unwrap();
    assert_eq!(generalization[0]["mode"], "arlpcg");
    // Half the validation set is rule levels, so the Solver has something to play.
    assert!(generalization[0]["success_ratio"].is_number());
    for name in [
        "results.md", "results.png", "controllability.csv", "generalization.csv", "cross.csv",
    ] {
        assert!(results.join(name).exists(), "{name}");
    }
    let again = arlpcg(words("eval --policies {} --out {}", &[&run, &results_s]));
    assert!(
        stderr(&again).contains("--force"),
        "results are not clobbered"
    );
}

/// The run scored as one seed of its mode (`eval --runs`): its own pair's controllability and
/// its Solver on the validation set, with (here degenerate) intervals.
fn score_a_run_as_one_seed(dir: &Path, run: &str) {
    let run_dir = run;
    let seeds = dir.join("seeds");
    arlpcg_ok(words(
        "eval --runs {} --policies {} --tracks 2 --trials 2 --validation-tracks 4 --out {}",
        &[&run, &run, &seeds],
    ));
    let seeds_json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(seeds.join("seeds.json")).unwrap()).unwrap();
    assert_eq!(seeds_json["modes"][0]["mode"], "arlpcg");
    assert_eq!(seeds_json["modes"][0]["seeds"], serde_json::json!([5]));
    let run = &seeds_json["seeds"]["arlpcg"][0];
    assert_eq!(run["controllability"].as_array().unwrap().len(), 5);
    // The judges it never trained against: the folder has no rule-pcg Solver, so the scripted
    // player's two skills, on the same levels.
    let judges = run["controllability_by_judge"].as_array().unwrap();
    let names: Vec<&str> = judges
        .iter()
        .map(|j| j["judge"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["scripted-median", "scripted-expert"]);
    assert!(
        judges
            .iter()
            .all(|j| j["success_ratio"].as_array().unwrap().len() == 5)
    );
    assert!(seeds.join("seeds.md").exists());
    // One ARLPCG run has no other run's Generator to be played on.
    assert!(run.get("other_generators_hard").is_none(), "{run}");
    assert!(
        seeds_json["arlpcg_beats_on_other_generators"].is_null(),
        "{seeds_json}"
    );
    // A run named twice is not two seeds.
    let twice = arlpcg(words(
        "eval --runs {} {} --policies {} --out {}",
        &[
            &run_dir,
            &format!("{run_dir}/."),
            &run_dir,
            &dir.join("twice"),
        ],
    ));
    fails_with(&twice, 1, "twice");
    assert!(!dir.join("twice").exists());
    // Nor is a copy of its folder under another name.
    let copy = dir.join("copy");
    std::fs::create_dir(&copy).unwrap();
    for entry in std::fs::read_dir(run_dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_file() {
            std::fs::copy(entry.path(), copy.join(entry.file_name())).unwrap();
        }
    }
    let copied = arlpcg(words(
        "eval --runs {} {} --policies {} --out {}",
        &[&run_dir, &copy, &run_dir, &dir.join("copied")],
    ));
    fails_with(&copied, 1, "one run counted as two seeds");
    assert!(!dir.join("copied").exists());
}

/// `--resume --config` replaces the hyper-parameters (the old file is kept) but refuses the
/// fields that fix the networks, the matches or the seed stream.
#[test]
fn a_resumed_run_takes_new_hyper_parameters_but_not_a_new_shape() {
    let (dir, config, out) = scratch(TINY);
    let (config_s, out_s) = (config.to_str().unwrap(), out.to_str().unwrap());
    let train = |steps: &str, config: &str| {
        arlpcg(words(
            "train --mode rule-pcg --steps {} --config {} --out {} --resume",
            &[&steps, &config, &out_s],
        ))
    };
    arlpcg_ok(words(
        "train --mode rule-pcg --steps 128 --config {} --out {}",
        &[&config_s, &out_s],
    ));

    let reshaped = dir.path().join("reshaped.yaml");
    std::fs::write(
        &reshaped,
        TINY.replace("hidden: [16, 16]", "hidden: [32, 16]"),
    )
    .unwrap();
    let refused = train("256", reshaped.to_str().unwrap());
    assert_eq!(refused.status.code(), Some(1));
    let message = stderr(&refused);
    assert!(message.contains("hidden cannot change"), "{message}");

    let faster = dir.path().join("faster.yaml");
    std::fs::write(&faster, format!("{TINY}  learning_rate: 0.001\n")).unwrap();
    let resumed = train("256", faster.to_str().unwrap());
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    let kept = std::fs::read_to_string(out.join("config-until-step-128.yaml")).unwrap();
    assert!(kept.contains("learning_rate: 0.0003"), "{kept}");
    let now = std::fs::read_to_string(out.join("config.yaml")).unwrap();
    assert!(now.contains("learning_rate: 0.001"), "{now}");
}

/// A racing Solver trains through the same loop as the platform one: its card names the racing
/// game and its observation, γ defaults to the racing value, it resumes, and `verify` plays it
/// on racing tracks and refuses it on a platform level.
#[test]
fn a_racing_solver_trains_resumes_and_plays_racing_tracks_only() {
    let (dir, config, out) = scratch(TINY);
    let out_s = out.to_str().unwrap();
    arlpcg_ok(words(
        "train --game racing --mode rule-pcg --steps 256 --config {} --out {}",
        &[&config, &out_s],
    ));
    // A resume takes the game and mode from the run.
    arlpcg_ok(words("train --steps 512 --out {} --resume", &[&out_s]));
    assert_eq!(curve(&out).last().map(|r| r.1), Some(512));
    a_checkpoint_of_the_other_game_is_refused(dir.path(), &out);
    let stored = std::fs::read_to_string(out.join("config.yaml")).unwrap();
    assert!(stored.contains("gamma: 0.998"), "{stored}");
    let bytes = std::fs::read(out.join("solver.safetensors")).unwrap();
    let loaded = load_policy(
        &bytes,
        Game::Racing,
        Role::Solver,
        arlpcg_core::game::racing::OBSERVATION_SIZE,
    )
    .unwrap();
    assert_eq!(loaded.card.continuous_actions, ["throttle", "steer"]);
    assert!(loaded.card.binary_actions.is_empty());
    assert!(load_policy(&bytes, Game::Platform, Role::Solver, OBSERVATION_SIZE).is_err());

    let tracks = dir.path().join("tracks");
    arlpcg_ok(words("generate --game racing --rules --out {}", &[&tracks]));
    let policy = out.join("solver.safetensors");
    let played = arlpcg_ok(words(
        "verify {} --policy {} --trials 4 --json",
        &[&tracks.join("racing_seed0.yaml"), &policy],
    ));
    let report: serde_json::Value = serde_json::from_slice(&played.stdout).unwrap();
    assert_eq!(report["trials"], 4);
    let refused = arlpcg(words(
        "verify levels/hand/staircase.yaml --policy {}",
        &[&policy],
    ));
    assert_eq!(refused.status.code(), Some(1));
    let said = stderr(&refused);
    assert!(said.contains("racing solver policy"), "{said}");
}

/// A platform run folder (the shipped Solver and its card) whose checkpoint, configuration and
/// metrics are the racing run `racing`'s does not resume: its Solver is another game's, and
/// resuming would replace it. The folder's policy and card are left as they were.
fn a_checkpoint_of_the_other_game_is_refused(dir: &Path, racing: &Path) {
    let platform = dir.join("platform-run");
    std::fs::create_dir(&platform).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    for name in ["solver.safetensors", "solver.yaml"] {
        std::fs::copy(shipped.join(name), platform.join(name)).unwrap();
    }
    for name in ["checkpoint.safetensors", "config.yaml", "metrics.csv"] {
        std::fs::copy(racing.join(name), platform.join(name)).unwrap();
    }
    let before = std::fs::read(platform.join("solver.safetensors")).unwrap();
    let refused = arlpcg(words("train --steps 768 --out {} --resume", &[&platform]));
    fails_with(&refused, 1, "holds files of two different runs");
    let said = stderr(&refused);
    assert!(
        said.contains("solver.yaml: a platform solver") && said.contains("racing run"),
        "{said}"
    );
    assert_eq!(
        std::fs::read(platform.join("solver.safetensors")).unwrap(),
        before
    );
}

/// The racing Generator trains through the adversarial loop written for both games: it
/// alternates phases with its Solver, resumes, its card names the racing Generator's inputs and
/// outputs, `generate --game racing --policies` builds tracks with it, and `eval --game racing`
/// writes the racing tables with air time and segment statistics.
#[test]
fn a_racing_generator_trains_builds_tracks_and_is_evaluated() {
    let (dir, config, out) = scratch(TINY_ADVERSARIAL);
    let out_s = out.to_str().unwrap();
    let train = |steps: &str, resume: bool| {
        let mut args = vec![
            "train", "--game", "racing", "--mode", "arlpcg", "--steps", steps, "--out", out_s,
        ];
        if resume {
            args.push("--resume");
        } else {
            args.extend(["--config", config.to_str().unwrap()]);
        }
        arlpcg_ok(&args);
    };
    train("512", false);
    let generator_before = generator_rows(&out);
    assert!(
        generator_before >= 1,
        "{generator_before} Generator iterations"
    );
    train("1024", true);
    // The budget, then the tiny configuration's finish.
    assert_eq!(curve(&out).last().unwrap().1, 1024 + 128);
    assert!(generator_rows(&out) > generator_before);
    // The curve offset belongs to the Generator's weights: a resumed run cannot change it.
    let narrower = dir.path().join("narrower.yaml");
    std::fs::write(
        &narrower,
        TINY_ADVERSARIAL.replace("generator:\n", "generator:\n  curve_offset: 30\n"),
    )
    .unwrap();
    let refused = arlpcg(words(
        "train --game racing --mode arlpcg --steps 1536 --out {} --resume --config {}",
        &[&out_s, &narrower],
    ));
    assert_eq!(refused.status.code(), Some(1));
    let message = stderr(&refused);
    assert!(
        message.contains("generator-checkpoint.safetensors")
            && message
                .contains("trained with generator.curve_offset 90, the configuration says 30"),
        "{message}"
    );
    assert_eq!(
        curve(&out).last().unwrap().1,
        1024 + 128,
        "the refused run left the run as it was"
    );
    let header = std::fs::read_to_string(out.join("generator-metrics.csv")).unwrap();
    assert!(
        header.starts_with("iteration,")
            && header.contains(
                ",curve_easy,curve_hard,height_easy,height_hard,air_steps_easy,air_steps_hard,"
            ),
        "{}",
        header.lines().next().unwrap()
    );
    let stored = std::fs::read_to_string(out.join("config.yaml")).unwrap();
    assert!(
        stored.contains("air_step: 0.05"),
        "racing Generator rewards: {stored}"
    );
    let loaded = load_policy(
        &std::fs::read(out.join("generator.safetensors")).unwrap(),
        Game::Racing,
        Role::Generator,
        arlpcg_core::game::generator::observation_size::<arlpcg_core::game::RacingGame>(),
    )
    .unwrap();
    assert_eq!(
        loaded.card.continuous_actions,
        [
            "length", "curve_from_goal_bearing", "height_from_goal_slope"
        ]
    );
    assert_eq!(loaded.card.max_pieces, Some(30));

    generate_racing_tracks_with_a_run(dir.path(), out_s);
    evaluate_a_racing_run(dir.path(), out_s);
}

/// Tracks from the run's Generator, verified by its Solver; a goal one segment ahead is
/// within reach of even an untrained Generator.
fn generate_racing_tracks_with_a_run(dir: &Path, run: &str) {
    let tracks = dir.join("tracks");
    let (_, heading, _, _) = arlpcg_core::game::racing::rules::goal_and_start(2, None, 0);
    let [x, z] = arlpcg_core::level::heading::heading_direction(heading);
    let goal = format!("{},0,{}", 50.0 * x, 50.0 * z);
    arlpcg_ok(words(
        "generate --game racing --policies {} --aux -1 --seed 2 --goal {} --verify 2 --allow-unsolved --format yaml,glb --out {}",
        &[&run, &goal, &tracks],
    ));
    let level = arlpcg_core::level::yaml::load(&tracks.join("racing_seed2_aux-1.00.yaml")).unwrap();
    assert!(matches!(
        level.source,
        arlpcg_core::level::Source::Policy { .. }
    ));
    assert!(level.racing().is_some_and(|t| !t.segments.is_empty()));
    assert_eq!(level.stats.unwrap().trials, 2);
}

/// `eval` of a racing run: the racing columns and the paper's racing figures.
fn evaluate_a_racing_run(dir: &Path, run: &str) {
    let results = dir.join("results");
    arlpcg_ok(words(
        "eval --game racing --policies {} --tracks 1 --trials 1 --validation-tracks 2 --out {}",
        &[&run, &results],
    ));
    let json: serde_json::Value = crate::common::results_json(&results);
    let rows = json["controllability"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    for key in [
        "air_time", "avg_segment_curve", "avg_segment_length", "avg_segment_height",
    ] {
        assert!(
            rows[0].get(key).is_some(),
            "controllability.{key}: {}",
            rows[0]
        );
    }
    assert!(rows[0].get("avg_block_size").is_none());
    let markdown = std::fs::read_to_string(results.join("results.md")).unwrap();
    assert!(
        markdown.contains("0.99, 14.4°, 28.4 m, 1.5 m"),
        "the paper's racing figures: {markdown}"
    );
    assert!(
        markdown.contains("0.331 ± 0.225, 1.0 (507 m)"),
        "{markdown}"
    );
}

/// Rewrites the training state stored in a checkpoint's safetensors metadata.
fn tamper_training_state(path: &Path, change: impl Fn(&mut serde_json::Value)) {
    let bytes = std::fs::read(path).unwrap();
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let mut header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    let text = header["__metadata__"]["training_state"].as_str().unwrap();
    let mut state: serde_json::Value = serde_json::from_str(text).unwrap();
    change(&mut state);
    header["__metadata__"]["training_state"] = state.to_string().into();
    let header = serde_json::to_vec(&header).unwrap();
    let mut out = (header.len() as u64).to_le_bytes().to_vec();
    out.extend_from_slice(&header);
    out.extend_from_slice(&bytes[8 + n..]);
    std::fs::write(path, out).unwrap();
}

#[test]
fn a_checkpoint_whose_stored_configuration_is_out_of_range_is_refused_on_resume() {
    let (_dir, config, out) = scratch(TINY);
    let out_s = out.to_str().unwrap();
    arlpcg_ok(words(
        "train --mode fixed-track --steps 128 --config {} --out {}",
        &[&config, &out_s],
    ));
    let checkpoint = out.join("checkpoint.safetensors");
    let cases: [(&str, serde_json::Value, &str); 2] = [
        ("num_envs", serde_json::json!(100_000_000), "num_envs"),
        ("num_minibatches", serde_json::json!(0), "num_minibatches"),
    ];
    let original = std::fs::read(&checkpoint).unwrap();
    let resume = || {
        arlpcg(words(
            "train --mode fixed-track --steps 512 --out {} --resume",
            &[&out_s],
        ))
    };
    for (field, value, expected) in cases {
        std::fs::write(&checkpoint, &original).unwrap();
        tamper_training_state(&checkpoint, |state| {
            state["config"]["solver"][field] = value.clone()
        });
        let tampered = std::fs::read(&checkpoint).unwrap();
        let resumed = resume();
        let err = stderr(&resumed);
        assert_eq!(resumed.status.code(), Some(1), "{field}: {err}");
        assert!(
            err.contains("stored configuration") && err.contains(expected),
            "{field}: {err}"
        );
        assert_eq!(
            std::fs::read(&checkpoint).unwrap(),
            tampered,
            "{field}: left as it was"
        );
    }
    // The numbers a resume carries on are checked too: a wall time that would reach the card
    // as -inf, a negative bucket.
    let numbers: [(&str, &str, serde_json::Value); 2] = [
        ("wall_time_s", "", serde_json::json!(-1e308)),
        ("time_split", "env_s", serde_json::json!(-5.0)),
    ];
    for (field, inner, value) in numbers {
        std::fs::write(&checkpoint, &original).unwrap();
        tamper_training_state(&checkpoint, |state| match inner {
            "" => state[field] = value.clone(),
            inner => state[field][inner] = value.clone(),
        });
        let resumed = resume();
        let named = match inner {
            "" => field.to_string(),
            inner => format!("{field}.{inner}"),
        };
        fails_with(&resumed, 1, &format!("training state: {named} is"));
    }
}

/// Where training time goes: every metrics row of both agents splits its iteration into
/// buckets (env, forward, generator, gae, update, copies) that add up to the iteration's
/// measured time within 5% over the run, none negative; the cards carry the run's split and
/// the update's MFU, and `train` says both when it ends.
#[test]
fn the_time_buckets_add_up_to_each_iteration_and_reach_the_cards() {
    let (_dir, config, out) = scratch(TINY_ADVERSARIAL);
    let trained = arlpcg_ok(words(
        "train --mode arlpcg --steps 512 --config {} --out {}",
        &[&config, &out],
    ));
    let said = String::from_utf8_lossy(&trained.stdout);
    assert!(
        said.contains("time, all sessions: env ")
            && said.contains("; Solver phases ")
            && said.contains("GFLOP/s matmul peak"),
        "{said}"
    );
    let buckets = [
        "env_s", "forward_s", "generator_s", "gae_s", "update_s", "copies_s",
    ];
    let mut run_total = 0.0;
    for file in ["metrics.csv", "generator-metrics.csv"] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = |name: &str| header.iter().position(|c| *c == name).unwrap();
        let (mut split, mut measured) = (0.0, 0.0);
        for row in lines {
            let cells: Vec<f64> = row.split(',').map(|c| c.parse().unwrap()).collect();
            for bucket in buckets {
                assert!(cells[at(bucket)] >= 0.0, "{file}: {bucket} < 0 in {row}");
            }
            split += buckets.iter().map(|b| cells[at(b)]).sum::<f64>();
            measured += cells[at("iteration_s")];
            assert!((0.0..=1.5).contains(&cells[at("update_mfu")]), "{row}");
        }
        assert!(measured > 0.0, "{file}");
        assert!(
            (split - measured).abs() <= 0.05 * measured,
            "{file}: buckets {split:.6} s, iterations {measured:.6} s"
        );
        run_total += measured;
    }
    for card in ["solver.yaml", "generator.yaml"] {
        let text = std::fs::read_to_string(out.join(card)).unwrap();
        let card: serde_yaml::Value = serde_yaml::from_str(&text).unwrap();
        let split = &card["training"]["time_split"];
        let total: f64 = buckets.iter().map(|b| split[*b].as_f64().unwrap()).sum();
        // The card's seconds are rounded to tenths.
        assert!(
            (total - run_total).abs() <= 0.05 * run_total + 0.35,
            "{card:?}"
        );
        assert!(
            card["training"]["update_mfu"].as_f64().unwrap() > 0.0,
            "{text}"
        );
        // The same seconds by stretch: each iteration's whole time, rows and bars included.
        let stretches = &split["stretches"];
        let by_stretch: f64 = ["solver_phases_s", "generator_phases_s", "finish_s"]
            .iter()
            .map(|s| stretches[*s].as_f64().unwrap())
            .sum();
        assert!(
            by_stretch >= run_total - 0.35 && by_stretch <= 1.2 * run_total + 0.35,
            "stretches {by_stretch} s, iterations {run_total} s: {text}"
        );
    }
}

#[test]
fn two_new_runs_into_one_folder_leave_one_run_whole() {
    let (_dir, config, out) = scratch(TINY);
    let start = |seed: &str| {
        Command::new(env!("CARGO_BIN_EXE_arlpcg"))
            .args(["train", "--mode", "fixed-track", "--steps", "2000"])
            .args(["--seed", seed, "--config", config.to_str().unwrap()])
            .args(["--out", out.to_str().unwrap(), "--threads", "1"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (first, second) = (start("1"), start("2"));
    let results = [
        first.wait_with_output().unwrap(),
        second.wait_with_output().unwrap(),
    ];
    let won: Vec<usize> = (0..2).filter(|&k| results[k].status.success()).collect();
    assert_eq!(won.len(), 1, "exactly one run goes on");
    let lost = &results[1 - won[0]];
    assert_eq!(lost.status.code(), Some(1), "{}", stderr(lost));
    let policy = std::fs::read(out.join("solver.safetensors")).unwrap();
    let loaded = load_policy(&policy, Game::Platform, Role::Solver, OBSERVATION_SIZE).unwrap();
    assert_eq!(
        loaded.card.training.seed,
        won[0] as u64 + 1,
        "the folder holds the winner's run"
    );
}

/// A Generator with style knobs: it observes their values after the game's observation (its
/// card says so); `generate` plays it with every knob at 0 (no preference) or as `--aux` names
/// them, and each level records them; a knob the game or the Generator lacks is refused.
#[test]
fn a_generator_with_knobs_records_them_and_generates() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = crate::common::knob_pair();
    let card = std::fs::read_to_string(out.join("generator.yaml")).unwrap();
    assert!(
        card.contains("- - aux\n  - 1\n- - knobs\n  - 2\n"),
        "{card}"
    );
    let solver = std::fs::read_to_string(out.join("solver.yaml")).unwrap();
    assert!(
        !solver.contains("knobs"),
        "the Solver takes no knobs: {solver}"
    );
    let levels = dir.path().join("levels");
    arlpcg_ok(words(
        "generate --policies {} --aux=-1 --count 2 --format yaml --out {}",
        &[&out, &levels],
    ));
    assert_eq!(std::fs::read_dir(&levels).unwrap().count(), 2);
    let zero = std::fs::read_to_string(levels.join("platform_seed0_aux-1.00.yaml")).unwrap();
    assert!(
        zero.contains("knobs:\n  steps: 0.0\n  stride: 0.0\n"),
        "{zero}"
    );
    let named = dir.path().join("named");
    arlpcg_ok(words(
        "generate --policies {} --aux difficulty=-1,stride=1 --format yaml --out {}",
        &[&out, &named],
    ));
    let level =
        std::fs::read_to_string(named.join("platform_seed0_aux-1.00_stride1.00.yaml")).unwrap();
    assert!(
        level.contains("knobs:\n  steps: 0.0\n  stride: 1.0\n"),
        "{level}"
    );
    let refused = |aux: &str, policies: &str| {
        arlpcg(words(
            "generate --policies {} --aux {} --out {}",
            &[&policies, &aux, &dir.path().join("refused")],
        ))
    };
    let without_knobs = concat!(env!("CARGO_MANIFEST_DIR"), "/policies/racing");
    let out_s = out.to_str().unwrap();
    fails_with(
        &refused("difficulty=1,curviness=1", out_s),
        2,
        "knobs are stride, steps",
    );
    fails_with(
        &refused("difficulty=1,stride=1,stride=0", out_s),
        2,
        "`stride` is given twice",
    );
    fails_with(
        &arlpcg(words(
            "generate --game racing --policies {} --aux difficulty=1,curviness=1 --out {}",
            &[&without_knobs, &dir.path().join("refused")],
        )),
        1,
        "was trained without knobs",
    );
    assert!(!dir.path().join("refused").exists());
    // `eval` adds a table per knob: nine settings, the style measured and the Solver's success.
    let evaluated = dir.path().join("eval");
    arlpcg_ok(words(
        "eval --policies {} --tracks 2 --trials 2 --validation-tracks 2 --threads 1 --out {}",
        &[&out, &evaluated],
    ));
    let md = std::fs::read_to_string(evaluated.join("results.md")).unwrap();
    for knob in ["stride", "steps"] {
        assert!(md.contains(&format!("### Style knob `{knob}`")), "{md}");
    }
    assert!(md.contains("| -1.00 |") && md.contains("| +1.00 |"), "{md}");
    let json = std::fs::read_to_string(evaluated.join("results.json")).unwrap();
    assert!(json.contains("\"spearman\""), "{json}");
}
