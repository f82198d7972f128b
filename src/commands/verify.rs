//! `arlpcg verify`: play each level many times and report the Solver's statistics.

use std::path::Path;

use anyhow::Result;
use serde_json::json;

use crate::cli::{SolverChoice, VerifyArgs};
use crate::level::stats::SolverStats;
use crate::level::yaml;
use crate::verify::{Solver, verify};

pub fn run(args: &VerifyArgs) -> Result<()> {
    let solver = match args.solver {
        SolverChoice::Scripted => Solver::Scripted,
    };
    if !args.json {
        eprintln!("solver: scripted controller (no trained Solver ships yet)");
    }
    let mut failed = 0;
    for path in &args.levels {
        let outcome = yaml::load(path)
            .map_err(anyhow::Error::from)
            .and_then(|level| {
                let bar = super::progress_bar(args.trials as u64, &path.display().to_string());
                let stats = verify(&level, solver, args.trials, args.seed, &|| bar.inc(1))?;
                bar.finish_and_clear();
                Ok(stats)
            });
        match outcome {
            Ok(stats) if args.json => println!("{}", to_json(path, &stats)),
            Ok(stats) => println!("{}", describe(path, &stats)),
            Err(err) => {
                failed += 1;
                eprintln!("error: {}", one_line(&format!("{err:#}")));
            }
        }
    }
    if failed > 0 {
        anyhow::bail!(
            "{failed} of {} level files could not be verified",
            args.levels.len()
        );
    }
    Ok(())
}

fn to_json(path: &Path, s: &SolverStats) -> serde_json::Value {
    json!({
        "level": path.display().to_string(),
        "solver": s.solver.describe(),
        "seed": s.seed,
        "trials": s.trials,
        "successes": s.successes,
        "success_ratio": s.success_ratio,
        "ci95": s.ci95,
        "mean_progress": s.mean_progress,
        "fell": s.fell,
        "timed_out": s.timed_out,
        "failures_by_block": s.failures_by_piece,
    })
}

fn describe(path: &Path, s: &SolverStats) -> String {
    let mut text = format!(
        "{}: {}/{} succeeded, success ratio {:.2} (95% CI {:.2}-{:.2}), mean progress {:.2}",
        path.display(),
        s.successes,
        s.trials,
        s.success_ratio,
        s.ci95[0],
        s.ci95[1],
        s.mean_progress
    );
    let failures: Vec<String> = s
        .failures_by_piece
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(i, n)| format!("block {i}: {n}"))
        .collect();
    if !failures.is_empty() {
        text += &format!(
            "\n  failed on the way to {} (fell {}, out of time {})",
            failures.join(", "),
            s.fell,
            s.timed_out
        );
    }
    text
}

/// Folds a multi-line error message onto one line.
pub fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}
