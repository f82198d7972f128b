//! The paper's evaluation on either game (docs/spec.md §4), as pure functions of the policies
//! and the budget: the same policies and budget give the same tables.
//!
//! - **Controllability**: Generator levels at λ ∈ {1, 0.5, 0, -0.5, -1} (the same goals at every
//!   λ), played by the ARLPCG Solver: success ratio ± std over levels, the fraction completed by
//!   at least one run, the pieces' mean parameters (platform: block distance and size; racing:
//!   segment curve, length and height change), racing, the car's time in the air per run, and
//!   where the runs fail: pieces per level and the failures' shares on each level's last piece
//!   and on its most-failed one (`tables::PieceFailures`).
//! - **Generalization**: every Solver on one held-out validation set (half rule levels, half
//!   Generator levels cycling through the λ values), success ± std, completed by any, mean steps
//!   of successful runs.
//! - **Cross**: every Solver on the controllability levels, success ratio at each λ.
//! - **Knob**: the ARLPCG Solver on the same goals every 0.25 of λ, how far success moves a step.
//! - **Style knobs** (a Generator trained with them): each knob at nine settings, the others and
//!   λ at 0, the style its levels measure and the ARLPCG Solver's success ([`styles`]).
//!
//! In parts, as an evaluation flows: [`levels`] builds every level and the [`PlayLayout`] of the
//! tables; [`plays`] numbers the plays (one Solver on one level) and plays any subset of them,
//! which is what a shard does; [`merge`] checks and joins shards' parts; [`tables`] assembles
//! the tables from every play's statistics; [`report`] writes them as markdown, CSV and a chart.
//! Levels use seeds from [`arlpcg_core::seed_ranges::EVAL_SEED_BASE`] up: no evaluation level was trained on.

mod levels;
mod merge;
pub mod page;
mod plays;
mod report;
pub mod seeds;
pub mod styles;
pub(crate) mod tables;

pub use levels::{Levels, generator_levels, is_rule_level, levels, validation_levels};
pub use merge::{PART_FILE, Part, merge};
pub use plays::{Play, PlayLayout, play};
pub use report::{chart, csv_tables, markdown};
pub use tables::{ControllabilityRow, CrossRow, GeneralizationRow, Knob, Results, assemble};

use serde::Serialize;

use crate::services::generation::GeneratorPolicy;
use crate::services::verify::Solver;

/// The λ values of the tables, easy to hard.
pub const AUX_VALUES: [f64; 5] = [1.0, 0.5, 0.0, -0.5, -1.0];

/// The λ values between the tables' own: with them the ARLPCG Solver plays the same goals every
/// 0.25 from 1 to -1, to show how smoothly the knob turns ([`tables::Knob`]).
pub const KNOB_BETWEEN: [f64; 4] = [0.75, 0.25, -0.25, -0.75];

/// How much to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Budget {
    /// Levels per λ (controllability and cross tables).
    pub tracks: u32,
    /// Runs per level in those tables.
    pub trials: u32,
    /// Levels in the validation set.
    pub validation_tracks: u32,
    /// Runs per validation level.
    pub validation_trials: u32,
}

impl Budget {
    /// Minutes on 2 cores.
    pub const QUICK: Budget = Budget {
        tracks: 20,
        trials: 20,
        validation_tracks: 40,
        validation_trials: 20,
    };
    /// The paper's scale: 50 tracks × 1000 runs per λ, 1000 validation tracks × 20 runs.
    pub const FULL: Budget = Budget {
        tracks: 50,
        trials: 1000,
        validation_tracks: 1000,
        validation_trials: 20,
    };
}

/// A Solver under evaluation, named by its training mode.
pub struct NamedSolver<'a> {
    /// The judge's name: a trained Solver's mode, or `scripted-<skill>`.
    pub mode: String,
    /// The player.
    pub solver: Solver<'a>,
}

/// Runs the whole evaluation, on levels made for `profile` (none: the built-in game). `solvers`
/// must include the `arlpcg` one (it plays the
/// controllability table); `on_level` is called after each level played (progress).
pub fn evaluate(
    generator: &GeneratorPolicy,
    solvers: &[NamedSolver],
    budget: Budget,
    profile: Option<&arlpcg_core::level::profile::Profile>,
    on_level: &(dyn Fn() + Sync),
) -> Result<Results, candle_core::Error> {
    let levels = levels(generator, solvers, budget, profile)?;
    let all: Vec<usize> = (0..levels.layout.plays().len()).collect();
    let stats = play(&levels, solvers, budget, &all, on_level);
    Ok(Results {
        profile: profile.map(|p| p.record()),
        ..assemble(budget, &generator.reference.path, &levels.layout, &stats)
    })
}

/// Levels `evaluate` plays in all (for a progress bar), for a Generator of `knobs` style knobs.
pub fn levels_to_play(budget: Budget, solvers: usize, knobs: usize) -> u64 {
    let per_table = AUX_VALUES.len() as u64 * budget.tracks as u64;
    let between = KNOB_BETWEEN.len() as u64 * budget.tracks as u64;
    let styles = (knobs * styles::KNOB_SETTINGS.len()) as u64 * budget.tracks as u64;
    per_table + between + styles + solvers as u64 * (budget.validation_tracks as u64 + per_table)
}
