//! The Solver's trials on the level on screen, as they come in: counts, the success ratio with
//! its interval, progress, air time and the failures per piece.

use arlpcg_core::level::Game;
use arlpcg_core::level::stats::{Outcome, SolverStats, TrialResult, wilson_interval};

/// The Solver's trials on the level on screen, as they come in.
#[derive(Debug, Clone, PartialEq)]
pub struct Trials {
    pub id: u64,
    pub wanted: u32,
    pub results: Vec<TrialResult>,
    /// The final statistics (the same as `arlpcg verify` gives), once all trials are in.
    pub stats: Option<SolverStats>,
    /// Why the trials stopped before they were all in, if they could not be played.
    pub error: Option<String>,
}

impl Trials {
    pub fn done(&self) -> u32 {
        self.results.len() as u32
    }

    pub fn successes(&self) -> u32 {
        self.results
            .iter()
            .filter(|r| r.outcome == Outcome::Success)
            .count() as u32
    }

    /// Success ratio and its 95% interval so far (`None` before the first trial).
    pub fn success(&self) -> Option<(f64, [f64; 2])> {
        let n = self.done();
        (n > 0).then(|| {
            let s = self.successes();
            (s as f64 / n as f64, wilson_interval(s, n))
        })
    }

    pub fn mean_progress(&self) -> Option<f64> {
        let n = self.results.len();
        (n > 0).then(|| self.results.iter().map(|r| r.progress).sum::<f64>() / n as f64)
    }

    /// Racing: mean seconds per run with the car in the air so far (`None` on platform levels
    /// and before the first trial).
    pub fn mean_air_seconds(&self, game: Game) -> Option<f64> {
        let dt = arlpcg_core::game::facts::facts(game).air_time_step?;
        let air: Vec<u32> = self.results.iter().filter_map(|r| r.air_steps).collect();
        (!air.is_empty())
            .then(|| dt * air.iter().map(|&a| f64::from(a)).sum::<f64>() / air.len() as f64)
    }

    pub fn count(&self, outcome: Outcome) -> u32 {
        self.results.iter().filter(|r| r.outcome == outcome).count() as u32
    }

    /// Failed runs per block so far (`blocks` blocks), as `SolverStats::failures_by_piece`.
    pub fn failures_by_block(&self, blocks: usize) -> Vec<u32> {
        let mut failures = vec![0; blocks];
        for r in self
            .results
            .iter()
            .filter(|r| r.outcome != Outcome::Success)
        {
            if blocks > 0 {
                failures[r.target_piece.min(blocks - 1)] += 1;
            }
        }
        failures
    }
}
