//! The plays of an evaluation (one Solver on one level), numbered so that shards can play any
//! subset apart, and playing them.

use rayon::prelude::*;
use serde::Serialize;

use crate::services::verify::verify;
use arlpcg_core::level::Game;
use arlpcg_core::level::stats::SolverStats;

use super::styles::KnobLayout;
use super::{Budget, Levels, NamedSolver};

/// What the tables are made of, without the levels themselves: the game, how many levels each
/// table has, the Solvers' names and the piece statistics of the controllability levels. With
/// it, the per-level statistics of every play make the tables ([`assemble`]), so shards of an
/// evaluation can be played apart and merged.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct PlayLayout {
    /// The game.
    pub game: Game,
    /// Levels per λ of [`AUX_VALUES`] (the Generator may build fewer than the budget asks).
    pub levels_per_aux: Vec<usize>,
    /// Levels per λ of [`KNOB_BETWEEN`](super::KNOB_BETWEEN) (none in parts written before).
    #[serde(default)]
    pub levels_between: Vec<usize>,
    /// The pieces' mean parameters (the game's piece columns) at each λ (`None`: no levels).
    pub piece_means: Vec<Option<Vec<f64>>>,
    /// Levels in the validation set: its rule levels first, then the Generator's.
    pub validation_levels: usize,
    /// How many of them are rule levels.
    pub validation_rule_levels: usize,
    /// The Solvers' training modes, in table order.
    pub solvers: Vec<String>,
    /// The style knobs' tables, one per knob of a Generator trained with them (none before).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub knobs: Vec<KnobLayout>,
}

/// One play of one level by one Solver: which table, which Solver and λ, which level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Play {
    /// The ARLPCG Solver on level `level` at λ number `aux`.
    Controllability {
        /// The λ's index.
        aux: usize,
        /// The level's index at that λ.
        level: usize,
    },
    /// The ARLPCG Solver on level `level` at λ number `aux` of the knob's in-between values.
    Knob {
        /// The λ's index among the in-between values.
        aux: usize,
        /// The level's index at that λ.
        level: usize,
    },
    /// Solver `solver` on validation level `level`.
    Generalization {
        /// The Solver's index.
        solver: usize,
        /// The level's index in the validation set.
        level: usize,
    },
    /// The ARLPCG Solver on level `level` of style knob `knob` at its setting number `setting`
    /// ([`KNOB_SETTINGS`](super::styles::KNOB_SETTINGS)).
    Style {
        /// The knob's index.
        knob: usize,
        /// The setting's index.
        setting: usize,
        /// The level's index at that setting.
        level: usize,
    },
    /// Solver `solver` on level `level` at λ number `aux`.
    Cross {
        /// The Solver's index.
        solver: usize,
        /// The λ's index.
        aux: usize,
        /// The level's index at that λ.
        level: usize,
    },
}

impl PlayLayout {
    /// How many plays [`PlayLayout::plays`] lists, without listing them.
    pub fn play_count(&self) -> usize {
        let per_table: usize = self.levels_per_aux.iter().sum();
        let between: usize = self.levels_between.iter().sum();
        let styles: usize = self
            .knobs
            .iter()
            .flat_map(|k| &k.measured)
            .map(Vec::len)
            .sum();
        per_table + between + styles + self.solvers.len() * (self.validation_levels + per_table)
    }

    /// Every play of the evaluation, in a fixed order; shard I of K plays those whose index
    /// modulo K is I.
    pub fn plays(&self) -> Vec<Play> {
        let mut plays = Vec::new();
        for (aux, &n) in self.levels_per_aux.iter().enumerate() {
            plays.extend((0..n).map(|level| Play::Controllability { aux, level }));
        }
        for (aux, &n) in self.levels_between.iter().enumerate() {
            plays.extend((0..n).map(|level| Play::Knob { aux, level }));
        }
        for solver in 0..self.solvers.len() {
            plays.extend(
                (0..self.validation_levels).map(|level| Play::Generalization { solver, level }),
            );
            for (aux, &n) in self.levels_per_aux.iter().enumerate() {
                plays.extend((0..n).map(|level| Play::Cross { solver, aux, level }));
            }
        }
        // Last, so that evaluations without knobs number their plays as before.
        for (knob, layout) in self.knobs.iter().enumerate() {
            for (setting, at) in layout.measured.iter().enumerate() {
                plays.extend((0..at.len()).map(|level| Play::Style {
                    knob,
                    setting,
                    level,
                }));
            }
        }
        plays
    }
}

/// The index of the ARLPCG Solver (it plays the controllability table), else the first.
fn main_solver(solvers: &[String]) -> usize {
    solvers.iter().position(|m| m == "arlpcg").unwrap_or(0)
}

/// Plays the plays numbered `indices` (into [`PlayLayout::plays`]): each level `trials` runs (the
/// validation levels `validation_trials`), run seeds from the level's seed.
pub fn play(
    levels: &Levels,
    solvers: &[NamedSolver],
    budget: Budget,
    indices: &[usize],
    on_level: &(dyn Fn() + Sync),
) -> Vec<SolverStats> {
    let plays = levels.layout.plays();
    let main = main_solver(&levels.layout.solvers);
    // Several plays in flight at once; each depends only on its level and Solver, so the
    // statistics do not depend on the number of threads.
    indices
        .par_iter()
        .map(|&i| {
            let (solver, level, trials) = match plays[i] {
                Play::Controllability { aux, level } => {
                    (main, &levels.by_aux[aux][level], budget.trials)
                }
                Play::Knob { aux, level } => (main, &levels.between[aux][level], budget.trials),
                Play::Style {
                    knob,
                    setting,
                    level,
                } => (main, &levels.by_knob[knob][setting][level], budget.trials),
                Play::Generalization { solver, level } => {
                    (solver, &levels.validation[level], budget.validation_trials)
                }
                Play::Cross { solver, aux, level } => {
                    (solver, &levels.by_aux[aux][level], budget.trials)
                }
            };
            let stats = verify(
                level,
                &solvers[solver].solver,
                trials,
                level.seed.unwrap_or(0),
                &|| {},
            )
            .expect("evaluation Solvers play the evaluation's game");
            on_level();
            stats
        })
        .collect()
}
