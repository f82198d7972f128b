//! `arlpcg eval`: loads the Generator and the Solvers, runs [`crate::eval::evaluate`], writes
//! results.md, the CSV tables, results.json and results.png.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use crate::cli::EvalArgs;
use crate::eval::{self, Budget, NamedSolver};
use crate::fsio::{self, Overwrite};
use crate::level::Game;
use crate::policies::{GENERATOR_FILE, load_generator, load_solver};
use crate::verify::SolverPolicy;

pub fn run(args: &EvalArgs) -> Result<()> {
    if args.game != Game::Platform {
        bail!(
            "--game {}: only the platform game can be evaluated so far",
            args.game
        );
    }
    if let Some(missing) = args.policies.iter().find(|dir| !dir.is_dir()) {
        bail!("--policies {}: no such folder", missing.display());
    }
    let generator_path = args
        .policies
        .iter()
        .map(|dir| dir.join(GENERATOR_FILE))
        .find(|p| p.exists())
        .with_context(|| format!("no {GENERATOR_FILE} in any --policies folder"))?;
    let (generator, _) = load_generator(&generator_path)?;
    let mut solvers: Vec<(String, SolverPolicy)> = Vec::new();
    for dir in &args.policies {
        let entries = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read the policies folder {}", dir.display()))?;
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("solver") && n.ends_with(".safetensors"))
            })
            .collect();
        files.sort();
        for path in files {
            let (solver, card) = load_solver(&path, Game::Platform)?;
            if let Some((mode, _)) = solvers.iter().find(|(m, _)| *m == card.training.mode) {
                eprintln!(
                    "note: {} skipped: a {mode} Solver is already loaded",
                    path.display()
                );
                continue;
            }
            solvers.push((card.training.mode.clone(), solver));
        }
    }
    if !solvers.iter().any(|(mode, _)| mode == "arlpcg") {
        bail!(
            "no arlpcg Solver (a solver*.safetensors whose card says mode arlpcg) in the --policies folders: it plays the controllability table"
        );
    }
    let base = if args.full {
        Budget::FULL
    } else {
        Budget::QUICK
    };
    let budget = Budget {
        tracks: args.tracks.unwrap_or(base.tracks),
        trials: args.trials.unwrap_or(base.trials),
        validation_tracks: args.validation_tracks.unwrap_or(base.validation_tracks),
        validation_trials: args.trials.unwrap_or(base.validation_trials),
    };
    let overwrite = if args.force {
        Overwrite::Allowed
    } else {
        Overwrite::Never
    };
    let names = [
        "results.md",
        "results.json",
        "results.png",
        "controllability.csv",
        "generalization.csv",
        "cross.csv",
    ];
    if overwrite == Overwrite::Never {
        for name in names {
            let path = args.out.join(name);
            if path.exists() {
                bail!(
                    "{} exists: add --force to replace the results, or choose another --out",
                    path.display()
                );
            }
        }
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let pool = crate::shell::thread_pool(args.threads)?;
    let named: Vec<NamedSolver> = solvers
        .iter()
        .map(|(mode, policy)| NamedSolver {
            mode: mode.clone(),
            policy,
        })
        .collect();
    eprintln!(
        "generator {}; solvers: {}",
        generator_path.display(),
        named
            .iter()
            .map(|s| s.mode.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let bar =
        crate::shell::progress_bar(eval::levels_to_play(budget, named.len()), "levels played");
    let results = pool.install(|| eval::evaluate(&generator, &named, budget, &|| bar.inc(1)))?;
    bar.finish_and_clear();
    let markdown = eval::markdown(&results);
    let mut files: Vec<(String, Vec<u8>)> = vec![
        ("results.md".into(), markdown.clone().into_bytes()),
        ("results.json".into(), serde_json::to_vec_pretty(&results)?),
        ("results.png".into(), eval::chart(&results).to_png()),
    ];
    for (name, text) in eval::csv_tables(&results) {
        files.push((name.into(), text.into_bytes()));
    }
    for (name, bytes) in &files {
        fsio::write_atomic(&args.out.join(name), bytes, overwrite)?;
    }
    println!("{markdown}");
    println!("wrote {} files to {}", files.len(), args.out.display());
    Ok(())
}
