//! `arlpcg generate`: levels from a trained Generator or from the rules, optionally verified by
//! the Solver, written as files named after game, seed and aux.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};

use super::export::{LevelFiles, write_level_files};
use super::policies::{load_generator, load_solver, policy_paths};
use crate::cli::{DEFAULT_SOLVER, GenerateArgs};
use crate::fsio::Overwrite;
use crate::game::rules;
use crate::generation::{self, GeneratorPolicy};
use crate::level::{Game, Level, RulesConfig};
use crate::verify::{Solver, SolverPolicy, verify};

pub fn run(args: &GenerateArgs) -> Result<()> {
    if args.game != Game::Platform {
        bail!(
            "--game {}: only the platform game is implemented so far",
            args.game
        );
    }
    let generator = match &args.policies {
        Some(dir) => {
            if args.aux.is_none() {
                return Err(super::UsageError(
                    "--policies needs --aux λ in [-1, 1] (+1 easy, -1 hard)".into(),
                )
                .into());
            }
            Some(load_generator(&policy_paths(dir).0)?.0)
        }
        None => None,
    };
    let solver: Option<SolverPolicy> = match (args.verify, &args.policies) {
        (None, _) => None,
        (Some(_), Some(dir)) => Some(load_solver(&policy_paths(dir).1)?.0),
        (Some(_), None) if Path::new(DEFAULT_SOLVER).exists() => {
            Some(load_solver(Path::new(DEFAULT_SOLVER))?.0)
        }
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
    let plans: Vec<(u64, LevelFiles)> = seeds
        .iter()
        .map(|&seed| {
            (
                seed,
                LevelFiles::new(
                    &args.out,
                    &file_stem(args.game, seed, args.aux),
                    &args.format,
                ),
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
    let bar = super::progress_bar(plans.len() as u64, "generating");
    let mut levels = Vec::with_capacity(plans.len());
    for (seed, _) in &plans {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let mut level = build(generator.as_ref(), *seed, args.aux, args.goal)
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
        return Err(super::Interrupted(format!(
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
fn build(
    generator: Option<&GeneratorPolicy>,
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
) -> Result<Level> {
    Ok(match generator {
        Some(generator) => {
            generation::platform_level(generator, seed, aux.unwrap_or_default(), goal)?
        }
        None => rules::platform_level(seed, aux, goal, &RulesConfig::default())?,
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
