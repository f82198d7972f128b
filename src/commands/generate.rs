//! `arlpcg generate`: levels from a trained Generator or from the rules, optionally verified by
//! the Solver, written as files named after game, seed and aux.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};

use crate::cli::{GenerateArgs, default_solver};
use crate::fsio::Overwrite;
use crate::generation::{self, GeneratorPolicy};
use crate::level::{Game, Level};
use crate::level_files::{Format, LevelFiles, write_level_files};
use crate::policies::{load_generator, load_solver, policy_paths};
use crate::verify::{Solver, SolverPolicy, verify};

pub fn run(args: &GenerateArgs) -> Result<()> {
    if args.game == Game::Racing && args.policies.is_some() {
        return Err(crate::shell::UsageError(
            "--game racing --policies: no racing Generator is trained yet; use --rules".into(),
        )
        .into());
    }
    if args.obstacles > 0 && (args.game != Game::Racing || !args.rules) {
        return Err(crate::shell::UsageError(
            "--obstacles is for racing tracks from the rules (--game racing --rules)".into(),
        )
        .into());
    }
    let generator = match &args.policies {
        Some(dir) => {
            if args.aux.is_none() {
                return Err(crate::shell::UsageError(
                    "--policies needs --aux λ in [-1, 1] (+1 easy, -1 hard)".into(),
                )
                .into());
            }
            Some(load_generator(&policy_paths(dir).0)?.0)
        }
        None => None,
    };
    let shipped = default_solver(args.game);
    let solver: Option<SolverPolicy> = match (args.verify, &args.policies) {
        (None, _) => None,
        (Some(_), Some(dir)) => Some(load_solver(&policy_paths(dir).1, args.game)?.0),
        (Some(_), None) if shipped.exists() => Some(load_solver(&shipped, args.game)?.0),
        (Some(_), None) => None,
    };
    let seeds: Vec<u64> = (0..args.count as u64)
        .map(|i| args.seed.checked_add(i))
        .collect::<Option<_>>()
        .context("--seed plus --count overflows a 64-bit seed")?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let formats: Vec<Format> = args.format.iter().map(|&f| f.into()).collect();
    let plans: Vec<(u64, LevelFiles)> = seeds
        .iter()
        .map(|&seed| {
            (
                seed,
                LevelFiles::new(&args.out, &file_stem(args.game, seed, args.aux), &formats),
            )
        })
        .collect();
    // Refuse before writing anything, so that a refused run leaves the folder as it was.
    for (_, files) in &plans {
        files.check_writable(overwrite)?;
    }
    // Ctrl-C stops generating; the levels finished so far are still written.
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    // Every level is built (and verified) before the first file is written: a level that
    // cannot be built leaves the folder as it was, and --force replaces nothing.
    let bar = crate::shell::progress_bar(plans.len() as u64, "generating");
    let mut levels = Vec::with_capacity(plans.len());
    for (seed, _) in &plans {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let mut level = build(args, generator.as_ref(), *seed)
            .with_context(|| format!("seed {seed} (nothing was written)"))?;
        if let Some(trials) = args.verify {
            let who = solver.as_ref().map_or(Solver::Scripted, Solver::Policy);
            level.stats = Some(verify(&level, &who, trials, *seed, &|| {})?);
        }
        levels.push(level);
        bar.inc(1);
    }
    bar.finish_and_clear();
    for (written, (level, (_, files))) in levels.iter().zip(&plans).enumerate() {
        write_level_files(level, files, overwrite)
            .with_context(|| format!("after writing {written} of {} levels", plans.len()))?;
    }
    let files: usize = plans[..levels.len()]
        .iter()
        .map(|(_, f)| f.paths().len())
        .sum();
    if levels.len() < plans.len() {
        return Err(crate::shell::Interrupted(format!(
            "interrupted (Ctrl-C): wrote the {} of {} levels finished before it ({files} files) to {}",
            levels.len(),
            plans.len(),
            args.out.display()
        ))
        .into());
    }
    println!(
        "wrote {} levels ({files} files) to {}",
        plans.len(),
        args.out.display()
    );
    Ok(())
}

/// Level `seed` from the Generator when there is one, else from the rules.
fn build(args: &GenerateArgs, generator: Option<&GeneratorPolicy>, seed: u64) -> Result<Level> {
    let (aux, goal) = (args.aux, args.goal);
    Ok(match (args.game, generator) {
        (Game::Platform, Some(generator)) => {
            generation::platform_level(generator, seed, aux.unwrap_or_default(), goal)?
        }
        (game, _) => generation::rules_level(game, seed, aux, goal, args.obstacles)?,
    })
}

/// `platform_seed7` or, with an aux value, `platform_seed7_aux-0.50`.
pub fn file_stem(game: Game, seed: u64, aux: Option<f64>) -> String {
    match aux {
        // `+ 0.0` turns -0 into +0: `--aux=-0` names its files as `--aux 0` does.
        Some(aux) => format!("{game}_seed{seed}_aux{:+.2}", aux + 0.0),
        None => format!("{game}_seed{seed}"),
    }
}
