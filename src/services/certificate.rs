//! A level's certificate: the seed its statistics record for a run that reached the goal,
//! played again with the Solver that recorded it. `verify --replay` checks it still succeeds;
//! `view` draws it as a trail.

use arlpcg_core::level::Level;
use arlpcg_core::level::stats::SolverRef;

use crate::services::policies;
use crate::services::verify::{self, Recording, Solver};

/// The certificate run `level`'s statistics record, played again with the Solver that recorded
/// it (its policy file checked by SHA-256): its seed and the run. `Err` says why it cannot be
/// (no statistics, no certificate, the policy missing or changed); whether the run succeeds
/// again is the caller's to read.
pub fn run(level: &Level) -> anyhow::Result<(u64, Recording)> {
    use anyhow::Context;
    let stats = level
        .stats
        .as_ref()
        .context("no statistics: verify the level first (generate --verify N)")?;
    let seed = stats
        .certificate
        .context("its statistics record no certificate (no successful run was found)")?;
    let loaded;
    let solver = match &stats.solver {
        SolverRef::Scripted { skill } => Solver::Scripted(*skill),
        SolverRef::Random => Solver::Random,
        SolverRef::Policy { policy } => {
            let path = std::path::Path::new(&policy.path);
            loaded = policies::load_solver(path, level.game())?.0;
            if loaded.reference.sha256 != policy.sha256 {
                anyhow::bail!(
                    "{} is not the policy that recorded the certificate (its SHA-256 differs)",
                    policy.path
                );
            }
            Solver::Policy(&loaded)
        }
    };
    Ok((seed, verify::record(level, &solver, seed)?))
}
