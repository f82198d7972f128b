//! `arlpcg train`: the shell around the training core ([`crate::services::train`]). It owns what the core
//! must not touch: the clock, signals (Ctrl-C, and SIGTERM and SIGHUP as schedulers send them:
//! each saves a checkpoint and stops), the progress bar and what is printed.

use std::io::IsTerminal;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};

use crate::services::train::{self, TrainConfig, Training};
use crate::shells::cli::TrainArgs;
use crate::shells::common::{Interrupted, UsageError};

pub fn run(args: &TrainArgs) -> Result<()> {
    if args.print_config {
        // What a new run with these --game, --mode and --config would train with.
        let game = args.game.unwrap_or_default();
        let mode = args
            .mode
            .map_or(arlpcg_core::rl::checkpoint::TrainMode::RulePcg, Into::into);
        let config = match &args.config {
            Some(path) => train::load_config(path, game, mode)?,
            None => TrainConfig::for_run(game, mode),
        };
        crate::shells::common::say(format_args!("{}", serde_yaml::to_string(&config)?));
        return Ok(());
    }
    let usage = |message: &str| anyhow::Error::from(UsageError(message.into()));
    let out = args.out.as_ref().ok_or_else(|| {
        usage("--out DIR is required: where the run's checkpoint, metrics and policy go")
    })?;
    // Ctrl-C and SIGTERM from here on stop the run at its next safe point, with a checkpoint.
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second handler cannot be installed (tests run several runs in one process).
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    if out.exists() && !out.is_dir() {
        return Err(usage(&format!("--out {} is not a folder", out.display())));
    }
    // The profile is read and checked before anything is made: a bad one leaves no folder.
    let profile = args
        .profile
        .as_deref()
        .map(crate::services::profile::load)
        .transpose()?;
    let pool = crate::shells::common::thread_pool(args.threads)?;
    // One session per run folder: two (two new runs, a resume started twice) would interleave
    // or replace each other's files. The folder is made, if need be, and locked before
    // anything is written in it; a run refused after that takes away the folder it made.
    let made = make_run_folder(out)?;
    let lock = RunLock::take(out)?;
    // Temporary files a killed session left (a checkpoint half written) go first.
    let stale = crate::services::fsio::remove_stale_temps(out, std::time::SystemTime::now())?;
    if stale > 0 {
        crate::warn!(
            "removed {stale} temporary files a stopped run left in {}",
            out.display()
        );
    }
    pool.install(|| {
        let opened = train::open(
            args.game,
            args.mode.map(Into::into),
            out,
            train::RunAsk {
                config: args.config.as_deref(),
                seed: args.seed,
                steps: args.steps,
                profile: profile.as_ref(),
                ability_spread: args.ability_spread,
            },
            args.resume,
        );
        let mut run = match opened {
            Ok(run) => run,
            Err(err) => {
                drop(lock);
                if made {
                    let _ = std::fs::remove_dir(out); // only while it is still empty
                }
                return Err(err);
            }
        };
        let _lock = lock;
        run.add_session(
            std::iter::once("arlpcg".to_string())
                .chain(std::env::args().skip(1))
                .collect::<Vec<_>>()
                .join(" "),
            crate::shells::common::code_commit(),
        );
        train_loop(run.as_mut(), args.minutes, args.pause_at, &stop)
    })
}

/// Makes the run folder `out` (and the folders above it) unless it exists; whether it made it.
fn make_run_folder(out: &std::path::Path) -> Result<bool> {
    if out.is_dir() {
        return Ok(false);
    }
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
    }
    match std::fs::create_dir(out) {
        Ok(()) => Ok(true),
        // Another run made it a moment ago: the lock decides which of the two goes on.
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && out.is_dir() => Ok(false),
        Err(e) => Err(e).with_context(|| format!("cannot create {}", out.display())),
    }
}

/// The matrix product (`n × n × n`) whose rate is this machine's peak, measured at the start of
/// each session (about 0.1 s on two threads).
const PEAK_PROBE_SIZE: usize = 1024;

/// Seconds between the progress lines of a run whose standard error is not a terminal.
const PLAIN_LINE_SECONDS: f64 = 60.0;

/// Iterates `run` until its budget of Solver steps, `minutes` of this session, `pause_at` Solver
/// steps, or a signal (`stop`); checkpoints on the run's interval and at the end, then writes the
/// policies.
fn train_loop(
    run: &mut dyn Training,
    minutes: Option<f64>,
    pause_at: Option<u64>,
    stop: &AtomicBool,
) -> Result<()> {
    let session = Instant::now();
    let seconds = || session.elapsed().as_secs_f64();
    let peak = arlpcg_core::rl::fused::matmul_peak_flops(PEAK_PROBE_SIZE, 3, &seconds);
    run.set_matmul_peak(peak);
    let wall_before = run.wall_before();
    let wall = || wall_before + session.elapsed().as_secs_f64();
    let mut last_checkpoint = Instant::now();
    let total = run.budget();
    let bar = crate::shells::common::progress_bar(total, "training");
    bar.set_position(run.solver_steps());
    let drawn = std::io::stderr().is_terminal();
    let mut last_line = Instant::now();
    loop {
        // The budget may end early (a finish whose catch-up reached its success).
        let done_by_steps = run.solver_steps() >= run.budget();
        let done_by_time = minutes.is_some_and(|m| session.elapsed().as_secs_f64() >= m * 60.0);
        let paused = pause_at.is_some_and(|at| run.solver_steps() >= at);
        if done_by_steps || done_by_time || paused || stop.load(Ordering::SeqCst) {
            break;
        }
        let progress = run.iterate(&wall).with_context(|| {
            format!(
                "training stopped at {} Solver steps; the last checkpoint in {} is kept \
                 (--resume, with --config for a smaller learning rate, continues from it)",
                run.solver_steps(),
                run.out().display()
            )
        })?;
        let message = format!(
            "{}, update at {:.0}% of peak",
            progress.message,
            100.0 * run.time_split().1
        );
        // Without a terminal the bar draws nothing: a log gets a line a minute, and every
        // phase change and finish check.
        if !drawn && (progress.notable || last_line.elapsed().as_secs_f64() >= PLAIN_LINE_SECONDS) {
            crate::warn!(
                "{:.1} min, {} of {} Solver steps: {message}",
                wall() / 60.0,
                run.solver_steps(),
                total
            );
            last_line = Instant::now();
        }
        bar.set_message(message);
        bar.set_position(run.solver_steps());
        if last_checkpoint.elapsed().as_secs_f64() >= run.checkpoint_minutes() * 60.0 {
            run.save_checkpoint(wall())?;
            train::write_learning_curve(run.out())?;
            last_checkpoint = Instant::now();
        }
    }
    bar.finish_and_clear();
    // Measured again at the end: a probe that met a busy machine reads a peak too low.
    let peak = peak.max(arlpcg_core::rl::fused::matmul_peak_flops(
        PEAK_PROBE_SIZE, 3, &seconds,
    ));
    run.set_matmul_peak(peak);
    let trained = wall();
    run.save_checkpoint(trained)?;
    run.save_policies(trained)?;
    train::write_learning_curve(run.out())?;
    let summary = format!(
        "at {} Solver steps after {:.1} min in all; checkpoints and policies in {}",
        run.solver_steps(),
        trained / 60.0,
        run.out().display()
    );
    let (time, mfu) = run.time_split();
    crate::say!(
        "time, all sessions: {}; {} (update at {:.0}% of this machine's {:.0} GFLOP/s matmul \
         peak, the best of its probes at the session's start and end)",
        time.shares(),
        time.stretches.minutes(),
        100.0 * mfu,
        peak / 1e9
    );
    if stop.load(Ordering::SeqCst) {
        crate::say!("stopped (Ctrl-C or a termination signal) {summary}");
        return Err(Interrupted(format!(
            "training interrupted; its checkpoint is saved: --resume continues it ({})",
            run.out().display()
        ))
        .into());
    }
    if run.solver_steps() < run.budget() {
        crate::say!("paused {summary} (--resume goes on)");
        return Ok(());
    }
    // A finished run with a Generator checks its own knob; its cards carry the figures.
    let starting = || {
        crate::say!("checking the finished pair's knob (its own Solver on its λ = ±1 levels)...")
    };
    match run.check_own_control(&wall, &starting)? {
        Some(control) => crate::say!(
            "finished {summary}; {control} (the check took {:.0} s)",
            run.time_split().0.stretches.own_check_s
        ),
        None => crate::say!("finished {summary}"),
    }
    Ok(())
}

/// The run folder's lock: [`train::LOCK_FILE`], locked (`flock`) while the session runs and
/// holding its process id for messages; removed when the session ends. The operating system
/// lets go of the lock when the process ends however it ends, so a killed session's file does
/// not hold, whatever process now has its number.
struct RunLock {
    path: std::path::PathBuf,
    /// Holds the lock while it is open.
    _file: std::fs::File,
}

impl RunLock {
    fn take(out: &std::path::Path) -> Result<Self> {
        use std::io::{Read, Seek, Write};
        let path = out.join(train::LOCK_FILE);
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = match holder.trim() {
                    "" => String::new(),
                    pid => format!(" (process {pid})"),
                };
                anyhow::bail!(
                    "{} is in use by another training session{holder}, which holds {}; wait for \
                     it to finish or stop it (Ctrl-C saves its checkpoint)",
                    out.display(),
                    path.display()
                );
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(e).with_context(|| format!("cannot lock {}", path.display()));
            }
        }
        file.set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| writeln!(file, "{}", std::process::id()))
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Self { path, _file: file })
    }
}

impl Drop for RunLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}
