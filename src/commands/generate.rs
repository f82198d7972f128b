//! `arlpcg generate`: levels from the rules, written as files named after game, seed and aux.

use anyhow::{Context, Result, bail};

use super::export::{LevelFiles, write_level_files};
use crate::cli::GenerateArgs;
use crate::fsio::Overwrite;
use crate::game::rules;
use crate::level::{Game, RulesConfig};

pub fn run(args: &GenerateArgs) -> Result<()> {
    if args.game != Game::Platform {
        bail!(
            "--game {}: only the platform game is implemented so far",
            args.game
        );
    }
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
    let config = RulesConfig::default();
    let bar = super::progress_bar(plans.len() as u64, "generating");
    for (seed, files) in &plans {
        let level = rules::platform_level(*seed, args.aux, args.goal, &config)
            .with_context(|| format!("seed {seed}"))?;
        write_level_files(&level, files, overwrite)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let files: usize = plans.iter().map(|(_, f)| f.paths().len()).sum();
    println!(
        "wrote {} levels ({files} files) to {}",
        plans.len(),
        args.out.display()
    );
    Ok(())
}

/// `platform_seed7` or, with an aux value, `platform_seed7_aux-0.50`.
pub fn file_stem(game: Game, seed: u64, aux: Option<f64>) -> String {
    match aux {
        Some(aux) => format!("{game}_seed{seed}_aux{aux:+.2}"),
        None => format!("{game}_seed{seed}"),
    }
}
