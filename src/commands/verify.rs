//! `arlpcg verify`: play each level many times and report the Solver's statistics, then a
//! summary over all the levels.

use std::path::Path;

use anyhow::Result;
use serde_json::json;

use super::policies::load_solver;
use crate::cli::{DEFAULT_SOLVER, SolverChoice, VerifyArgs};
use crate::level::stats::SolverStats;
use crate::level::yaml;
use crate::verify::{Solver, Summary, verify};

pub fn run(args: &VerifyArgs) -> Result<()> {
    let choice = args.solver.unwrap_or(
        if args.policy.exists() || args.policy != Path::new(DEFAULT_SOLVER) {
            SolverChoice::Policy
        } else {
            SolverChoice::Scripted
        },
    );
    let loaded;
    let solver = match choice {
        SolverChoice::Policy => {
            loaded = load_solver(&args.policy)?.0;
            Solver::Policy(&loaded)
        }
        SolverChoice::Scripted => Solver::Scripted,
        SolverChoice::Random => Solver::Random,
    };
    if !args.json {
        let note = match (&solver, args.solver) {
            (Solver::Scripted, None) => format!(" (no trained Solver at {DEFAULT_SOLVER})"),
            _ => String::new(),
        };
        let who = match &solver {
            Solver::Policy(p) => format!("policy {}", p.reference.path),
            Solver::Scripted => "scripted controller".into(),
            Solver::Random => "random actions".into(),
        };
        eprintln!("solver: {who}{note}");
    }
    let mut failed = 0;
    let mut all = Vec::new();
    for path in &args.levels {
        let outcome = yaml::load(path)
            .map_err(anyhow::Error::from)
            .and_then(|level| {
                let bar = super::progress_bar(args.trials as u64, &path.display().to_string());
                let stats = verify(&level, &solver, args.trials, args.seed, &|| bar.inc(1))?;
                bar.finish_and_clear();
                Ok(stats)
            });
        match outcome {
            Ok(stats) => {
                if args.json {
                    println!("{}", to_json(path, &stats));
                } else {
                    println!("{}", describe(path, &stats));
                }
                all.push(stats);
            }
            Err(err) => {
                failed += 1;
                eprintln!("error: {}", one_line(&format!("{err:#}")));
            }
        }
    }
    if all.len() > 1 && !args.json {
        let s = Summary::of(&all);
        let steps = match s.completed_by_any > 0.0 {
            true => format!("{:.0}", s.mean_success_steps),
            false => "n/a".into(),
        };
        println!(
            "{} levels: success ratio {:.3} ± {:.3} (mean ± std over levels), completed by at least one run {:.2}, mean progress {:.2}, mean steps of successful runs {steps}",
            s.levels, s.mean_success, s.std_success, s.completed_by_any, s.mean_progress
        );
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
        "mean_success_steps": s.mean_success_steps,
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
