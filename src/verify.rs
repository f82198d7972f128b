//! Verification: play a level many times with a Solver and aggregate the statistics. Trials run
//! in parallel on the rayon pool; trial `i` is seeded with `seed + i`, so the result does not
//! depend on the number of threads.

use rayon::prelude::*;

use crate::game::platform::reach::play_scripted;
use crate::game::platform::{PlatformEnv, SolverRewards};
use crate::level::scene::UnsupportedGame;
use crate::level::stats::{SolverRef, SolverStats, TrialResult};
use crate::level::{Level, Track};

/// Take-off jitter of the scripted controller when it verifies levels, m.
pub const SCRIPTED_JITTER: f32 = 0.3;

/// Who plays the trials.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// The scripted (non-learning) controller.
    Scripted,
}

impl Solver {
    fn reference(self) -> SolverRef {
        match self {
            Solver::Scripted => SolverRef::Scripted,
        }
    }
}

/// Plays `trials` runs of the level and returns their statistics. `on_trial` is called after
/// each finished trial (from worker threads), for progress reporting.
pub fn verify(
    level: &Level,
    solver: Solver,
    trials: u32,
    seed: u64,
    on_trial: &(dyn Fn() + Sync),
) -> Result<SolverStats, UnsupportedGame> {
    let Track::Platform(track) = &level.track else {
        return Err(UnsupportedGame("racing"));
    };
    let results: Vec<TrialResult> = (0..trials as u64)
        .into_par_iter()
        .map_init(
            || PlatformEnv::new(track, level.goal, SolverRewards::default()),
            |env, i| {
                let result = match solver {
                    Solver::Scripted => play_scripted(env, seed.wrapping_add(i), SCRIPTED_JITTER),
                };
                on_trial();
                result
            },
        )
        .collect();
    Ok(SolverStats::from_trials(
        solver.reference(),
        seed,
        track.block_count(),
        &results,
    ))
}
