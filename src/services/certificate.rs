//! A level's certificate: the seed its statistics record for a run that reached the goal,
//! played again with the Solver that recorded it. `verify --replay` checks it still succeeds;
//! `view` draws it as a trail, beside the first trials of the level's verification played
//! again ([`replays`]).

use anyhow::Context;

use arlpcg_core::level::Level;
use arlpcg_core::level::stats::{SolverRef, SolverStats};

use crate::services::policies;
use crate::services::verify::{self, Recording, Solver};

/// The certificate run `level`'s statistics record, played again with the Solver that recorded
/// it (its policy file checked by SHA-256): its seed and the run. `Err` says why it cannot be
/// (no statistics, no certificate, the policy missing or changed); whether the run succeeds
/// again is the caller's to read.
pub fn run(level: &Level) -> anyhow::Result<(u64, Recording)> {
    with_recording_solver(level, |stats, solver| {
        let seed = stats
            .certificate
            .context("its statistics record no certificate (no successful run was found)")?;
        Ok((seed, verify::record(level, solver, seed)?))
    })
}

/// The first `count` trials of `level`'s verification (at most as many as it played), each
/// played again alone from its seed (trial `i`: the verification's seed + `i`) with the Solver
/// that recorded them: seed and run, in order.
pub fn replays(level: &Level, count: u32) -> anyhow::Result<Vec<(u64, Recording)>> {
    with_recording_solver(level, |stats, solver| {
        (0..count.min(stats.trials) as u64)
            .map(|i| {
                let seed = stats.seed.wrapping_add(i);
                Ok((seed, verify::record(level, solver, seed)?))
            })
            .collect()
    })
}

/// `f` with `level`'s statistics and the Solver they name (a policy file checked by SHA-256).
fn with_recording_solver<T>(
    level: &Level,
    f: impl FnOnce(&SolverStats, &Solver) -> anyhow::Result<T>,
) -> anyhow::Result<T> {
    let stats = level
        .stats
        .as_ref()
        .context("no statistics: verify the level first (generate --verify N)")?;
    let loaded;
    let solver = match &stats.solver {
        SolverRef::Scripted { skill } => Solver::Scripted(*skill),
        SolverRef::Random => Solver::Random,
        SolverRef::Policy { policy } => {
            let path = std::path::Path::new(&policy.path);
            loaded = policies::load_solver(path, level.game())?.0;
            if loaded.reference.sha256 != policy.sha256 {
                anyhow::bail!(
                    "{} is not the policy that verified the level (its SHA-256 differs)",
                    policy.path
                );
            }
            Solver::Policy(&loaded)
        }
    };
    f(stats, &solver)
}
