//! The paper's evaluation on our platform game (docs/spec.md §4), as pure functions of the policies and
//! the budget: the same policies and budget give the same tables.
//!
//! - **Controllability**: Generator levels at λ ∈ {1, 0.5, 0, -0.5, -1} (the same goals at every
//!   λ), played by the ARLPCG Solver: success ratio ± std over levels, the fraction completed by
//!   at least one run, the mean block distance and size.
//! - **Generalization**: every Solver on one held-out validation set (half rule levels, half
//!   Generator levels cycling through the λ values), success ± std, completed by any, mean steps
//!   of successful runs.
//! - **Cross**: every Solver on the controllability levels, success ratio at each λ.
//!
//! Levels use seeds from [`EVAL_SEED_BASE`] up, far below the seeds training draws from
//! ([`crate::train::solver_envs::TRAINING_SEED_BASE`]): no evaluation level was trained on.

use rayon::prelude::*;
use serde::Serialize;

use crate::game::rules;
use crate::generation::{self, GeneratorPolicy};
use crate::level::stats::SolverStats;
use crate::level::{Level, RulesConfig};
use crate::verify::{Solver, SolverPolicy, Summary, verify};

/// The λ values of the tables, easy to hard.
pub const AUX_VALUES: [f64; 5] = [1.0, 0.5, 0.0, -0.5, -1.0];
/// First seed of the controllability levels; the validation set starts at twice this.
pub const EVAL_SEED_BASE: u64 = 1 << 32;
/// Seeds tried per wanted level before the table notes a shortfall (the Generator may fail to
/// reach a goal).
const SEED_TRIES: u64 = 4;

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
    pub mode: String,
    pub policy: &'a SolverPolicy,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ControllabilityRow {
    pub aux: f64,
    pub success_ratio: f64,
    pub success_std: f64,
    pub completed_by_any: f64,
    pub avg_block_distance: f64,
    pub avg_block_size: f64,
    pub tracks: usize,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GeneralizationRow {
    pub mode: String,
    pub success_ratio: f64,
    /// Mean success on the validation set's rule levels (no Solver trained on these)...
    pub success_rule_levels: f64,
    /// ...and on its Generator levels (the ARLPCG Solver's own training distribution).
    pub success_generator_levels: f64,
    pub success_std: f64,
    pub completed_by_any: f64,
    /// Mean decisions of the successful runs.
    pub avg_steps: f64,
    pub tracks: usize,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossRow {
    pub mode: String,
    /// Success ratio at each λ of [`AUX_VALUES`], in that order.
    pub success_ratio: Vec<f64>,
}

/// Everything `eval` measures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Results {
    pub budget: Budget,
    pub generator: String,
    pub controllability: Vec<ControllabilityRow>,
    pub generalization: Vec<GeneralizationRow>,
    pub cross: Vec<CrossRow>,
}

/// Generator levels at `aux`: `count` of them from seeds `base`, `base + 1`, ... (a seed whose
/// level the Generator cannot build is skipped, within `SEED_TRIES` seeds per level).
pub fn generator_levels(
    generator: &GeneratorPolicy,
    aux: f64,
    base: u64,
    count: u32,
) -> Result<Vec<Level>, candle_core::Error> {
    let mut levels = Vec::with_capacity(count as usize);
    for seed in base..base + count as u64 * SEED_TRIES {
        if levels.len() == count as usize {
            break;
        }
        match generation::generator_level(generator, seed, aux, None, 0) {
            Ok(level) => levels.push(level),
            Err(generation::GenerationError::NoLevel { .. }) => {}
            Err(generation::GenerationError::Network(e)) => return Err(e),
        }
    }
    Ok(levels)
}

/// The validation set: rule levels and Generator levels (λ cycling through [`AUX_VALUES`]),
/// half each.
pub fn validation_levels(
    generator: &GeneratorPolicy,
    count: u32,
) -> Result<Vec<Level>, candle_core::Error> {
    let base = 2 * EVAL_SEED_BASE;
    let rule_count = count / 2;
    let mut levels: Vec<Level> = (0..rule_count as u64)
        .filter_map(|k| rules::platform_level(base + k, None, None, &RulesConfig::default()).ok())
        .collect();
    let per_aux = (count - rule_count).div_ceil(AUX_VALUES.len() as u32);
    for (k, &aux) in AUX_VALUES.iter().enumerate() {
        let seeds = base + (1 + k as u64) * (1 << 24);
        let wanted = per_aux.min(count - levels.len() as u32);
        levels.extend(generator_levels(generator, aux, seeds, wanted)?);
    }
    Ok(levels)
}

/// What the tables are made of, without the levels themselves: how many levels each table
/// has, the Solvers' names and the block statistics of the controllability levels. With it,
/// the per-level statistics of every play make the tables ([`assemble`]), so shards of an
/// evaluation can be played apart and merged.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Layout {
    /// Levels per λ of [`AUX_VALUES`] (the Generator may build fewer than the budget asks).
    pub levels_per_aux: Vec<usize>,
    /// (mean block distance, mean block size) of the levels at each λ (`None`: no levels).
    pub block_means: Vec<Option<(f64, f64)>>,
    /// Levels in the validation set: its rule levels first, then the Generator's.
    pub validation_levels: usize,
    /// How many of them are rule levels.
    pub validation_rule_levels: usize,
    /// The Solvers' training modes, in table order.
    pub solvers: Vec<String>,
}

/// One play of one level by one Solver: which table, which Solver and λ, which level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Play {
    /// The ARLPCG Solver on level `level` at λ number `aux`.
    Controllability { aux: usize, level: usize },
    /// Solver `solver` on validation level `level`.
    Generalization { solver: usize, level: usize },
    /// Solver `solver` on level `level` at λ number `aux`.
    Cross {
        solver: usize,
        aux: usize,
        level: usize,
    },
}

impl Layout {
    /// Every play of the evaluation, in a fixed order; shard I of K plays those whose index
    /// modulo K is I.
    pub fn plays(&self) -> Vec<Play> {
        let mut plays = Vec::new();
        for (aux, &n) in self.levels_per_aux.iter().enumerate() {
            plays.extend((0..n).map(|level| Play::Controllability { aux, level }));
        }
        for solver in 0..self.solvers.len() {
            plays.extend(
                (0..self.validation_levels).map(|level| Play::Generalization { solver, level }),
            );
            for (aux, &n) in self.levels_per_aux.iter().enumerate() {
                plays.extend((0..n).map(|level| Play::Cross { solver, aux, level }));
            }
        }
        plays
    }
}

/// The levels of an evaluation and its layout.
pub struct Levels {
    pub by_aux: Vec<Vec<Level>>,
    pub validation: Vec<Level>,
    pub layout: Layout,
}

/// Builds every level the evaluation plays (deterministic: the same Generator and budget give
/// the same levels on every machine).
pub fn levels(
    generator: &GeneratorPolicy,
    solvers: &[NamedSolver],
    budget: Budget,
) -> Result<Levels, candle_core::Error> {
    let by_aux: Vec<Vec<Level>> = AUX_VALUES
        .iter()
        .map(|&aux| generator_levels(generator, aux, EVAL_SEED_BASE, budget.tracks))
        .collect::<Result<_, _>>()?;
    let validation = validation_levels(generator, budget.validation_tracks)?;
    let block_means = by_aux
        .iter()
        .map(|levels| {
            let blocks: Vec<_> = levels
                .iter()
                .filter_map(|l| l.platform())
                .flat_map(|t| t.block_params().iter().copied())
                .collect();
            match blocks.len() {
                0 => None,
                n => Some((
                    blocks.iter().map(|b| b.distance).sum::<f64>() / n as f64,
                    blocks.iter().map(|b| b.size).sum::<f64>() / n as f64,
                )),
            }
        })
        .collect();
    let layout = Layout {
        levels_per_aux: by_aux.iter().map(Vec::len).collect(),
        block_means,
        validation_levels: validation.len(),
        validation_rule_levels: validation
            .iter()
            .filter(|l| matches!(l.source, crate::level::Source::Rules { .. }))
            .count(),
        solvers: solvers.iter().map(|s| s.mode.clone()).collect(),
    };
    Ok(Levels {
        by_aux,
        validation,
        layout,
    })
}

/// The index of the ARLPCG Solver (it plays the controllability table), else the first.
fn main_solver(solvers: &[String]) -> usize {
    solvers.iter().position(|m| m == "arlpcg").unwrap_or(0)
}

/// Plays the plays numbered `indices` (into [`Layout::plays`]): each level `trials` runs (the
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
                Play::Generalization { solver, level } => {
                    (solver, &levels.validation[level], budget.validation_trials)
                }
                Play::Cross { solver, aux, level } => {
                    (solver, &levels.by_aux[aux][level], budget.trials)
                }
            };
            let stats = verify(
                level,
                &Solver::Policy(solvers[solver].policy),
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

/// The tables from the layout and the statistics of every play (`stats[i]` of play `i`).
pub fn assemble(
    budget: Budget,
    generator: &str,
    layout: &Layout,
    stats: &[SolverStats],
) -> Results {
    let plays = layout.plays();
    assert_eq!(plays.len(), stats.len(), "one statistics entry per play");
    let summary = |wanted: &dyn Fn(&Play) -> bool| {
        let chosen: Vec<SolverStats> = plays
            .iter()
            .zip(stats)
            .filter(|(p, _)| wanted(p))
            .map(|(_, s)| s.clone())
            .collect();
        if chosen.is_empty() {
            return Summary {
                levels: 0,
                mean_success: f64::NAN,
                std_success: f64::NAN,
                completed_by_any: f64::NAN,
                mean_progress: f64::NAN,
                mean_success_steps: f64::NAN,
            };
        }
        Summary::of(&chosen)
    };
    let controllability = AUX_VALUES
        .iter()
        .enumerate()
        .map(|(a, &aux)| {
            let s = summary(&|p| matches!(p, Play::Controllability { aux, .. } if *aux == a));
            ControllabilityRow {
                aux,
                success_ratio: s.mean_success,
                success_std: s.std_success,
                completed_by_any: s.completed_by_any,
                avg_block_distance: layout.block_means[a].map_or(f64::NAN, |m| m.0),
                avg_block_size: layout.block_means[a].map_or(f64::NAN, |m| m.1),
                tracks: layout.levels_per_aux[a],
            }
        })
        .collect();
    let mut generalization = Vec::new();
    let mut cross = Vec::new();
    for (k, mode) in layout.solvers.iter().enumerate() {
        let s = summary(&|p| matches!(p, Play::Generalization { solver, .. } if *solver == k));
        let rules = layout.validation_rule_levels;
        let on_rules = summary(
            &|p| matches!(p, Play::Generalization { solver, level } if *solver == k && *level < rules),
        );
        let on_generator = summary(
            &|p| matches!(p, Play::Generalization { solver, level } if *solver == k && *level >= rules),
        );
        generalization.push(GeneralizationRow {
            mode: mode.clone(),
            success_rule_levels: on_rules.mean_success,
            success_generator_levels: on_generator.mean_success,
            success_ratio: s.mean_success,
            success_std: s.std_success,
            completed_by_any: s.completed_by_any,
            avg_steps: if s.completed_by_any > 0.0 {
                s.mean_success_steps
            } else {
                f64::NAN
            },
            tracks: layout.validation_levels,
        });
        let success_ratio = (0..AUX_VALUES.len())
            .map(|a| {
                summary(
                    &|p| matches!(p, Play::Cross { solver, aux, .. } if *solver == k && *aux == a),
                )
                .mean_success
            })
            .collect();
        cross.push(CrossRow {
            mode: mode.clone(),
            success_ratio,
        });
    }
    Results {
        budget,
        generator: generator.to_string(),
        controllability,
        generalization,
        cross,
    }
}

/// Runs the whole evaluation. `solvers` must include the `arlpcg` one (it plays the
/// controllability table); `on_level` is called after each level played (progress).
pub fn evaluate(
    generator: &GeneratorPolicy,
    solvers: &[NamedSolver],
    budget: Budget,
    on_level: &(dyn Fn() + Sync),
) -> Result<Results, candle_core::Error> {
    let levels = levels(generator, solvers, budget)?;
    let all: Vec<usize> = (0..levels.layout.plays().len()).collect();
    let stats = play(&levels, solvers, budget, &all, on_level);
    Ok(assemble(
        budget,
        &generator.reference.path,
        &levels.layout,
        &stats,
    ))
}

/// Levels `evaluate` plays in all (for a progress bar).
pub fn levels_to_play(budget: Budget, solvers: usize) -> u64 {
    let per_table = AUX_VALUES.len() as u64 * budget.tracks as u64;
    per_table + solvers as u64 * (budget.validation_tracks as u64 + per_table)
}

/// `x` with `decimals`, or "n/a" for NaN (nothing measured).
fn num(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        "n/a".into()
    } else {
        format!("{x:.decimals$}")
    }
}

/// The three tables as markdown, beside the paper's figures.
pub fn markdown(results: &Results) -> String {
    let mut md =
        String::from("## Generator controllability (ARLPCG Solver on Generator levels)\n\n");
    md += "| λ | success ratio | completed by any | avg block distance | avg block size | levels | paper: success, distance, size |\n|---|---|---|---|---|---|---|\n";
    let paper = [
        (0.97, 6.73, 5.95),
        (0.92, 6.98, 5.77),
        (0.88, 7.15, 5.42),
        (0.74, 7.11, 4.52),
        (0.69, 7.46, 4.01),
    ];
    for (row, (ps, pd, pz)) in results.controllability.iter().zip(paper) {
        md += &format!(
            "| {:+.1} | {} ± {} | {} | {} m | {} m | {} | {ps}, {pd} m, {pz} m |\n",
            row.aux,
            num(row.success_ratio, 3),
            num(row.success_std, 3),
            num(row.completed_by_any, 2),
            num(row.avg_block_distance, 2),
            num(row.avg_block_size, 2),
            row.tracks
        );
    }
    md += "\n## Solver generalization (held-out validation levels)\n\n";
    md += "| mode | success ratio | on rule levels | on Generator levels | completed by any | avg steps | paper |\n|---|---|---|---|---|---|---|\n";
    for row in &results.generalization {
        let paper = match row.mode.as_str() {
            "fixed-track" => "0.081 ± 0.205, 0.20 (54 steps)",
            "rule-pcg" => "0.233 ± 0.200, 0.95 (451 steps)",
            "fixed-aux" => "0.173 ± 0.195, 0.90 (442 steps)",
            "arlpcg" => "0.457 ± 0.211, 1.00 (467 steps)",
            _ => "",
        };
        md += &format!(
            "| {} | {} ± {} | {} | {} | {} | {} | {paper} |\n",
            row.mode,
            num(row.success_ratio, 3),
            num(row.success_std, 3),
            num(row.success_rule_levels, 3),
            num(row.success_generator_levels, 3),
            num(row.completed_by_any, 2),
            num(row.avg_steps, 0)
        );
    }
    md += "\n## Each Solver on Generator levels at each λ\n\n| mode |";
    for aux in AUX_VALUES {
        md += &format!(" λ = {aux:+.1} |");
    }
    md += "\n|---|";
    md += &"---|".repeat(AUX_VALUES.len());
    md += "\n";
    for row in &results.cross {
        md += &format!("| {} |", row.mode);
        for s in &row.success_ratio {
            md += &format!(" {} |", num(*s, 3));
        }
        md += "\n";
    }
    md += &format!(
        "\nBudget: {} levels × {} runs per λ; {} validation levels × {} runs. Generator: {}\n",
        results.budget.tracks,
        results.budget.trials,
        results.budget.validation_tracks,
        results.budget.validation_trials,
        results.generator
    );
    md
}

/// The chart of `eval`: each Solver's success ratio on Generator levels against λ.
pub fn chart(results: &Results) -> crate::chart::LineChart {
    crate::chart::LineChart {
        title: "Success ratio on Generator levels (λ: +1 easy, -1 hard)".into(),
        x_label: "aux input λ".into(),
        y_label: "success ratio".into(),
        series: results
            .cross
            .iter()
            .map(|row| crate::chart::Series {
                name: row.mode.clone(),
                points: AUX_VALUES
                    .iter()
                    .copied()
                    .zip(row.success_ratio.iter().copied())
                    .collect(),
            })
            .collect(),
        y_range: Some((0.0, 1.0)),
    }
}

/// The three tables as CSV files: (file name, contents).
pub fn csv_tables(results: &Results) -> Vec<(&'static str, String)> {
    let mut controllability = String::from(
        "aux,success_ratio,success_std,completed_by_any,avg_block_distance,avg_block_size,tracks\n",
    );
    for r in &results.controllability {
        controllability += &format!(
            "{},{:.4},{:.4},{:.4},{:.4},{:.4},{}\n",
            r.aux,
            r.success_ratio,
            r.success_std,
            r.completed_by_any,
            r.avg_block_distance,
            r.avg_block_size,
            r.tracks
        );
    }
    let mut generalization = String::from(
        "mode,success_ratio,success_std,success_rule_levels,success_generator_levels,completed_by_any,avg_steps,tracks\n",
    );
    for r in &results.generalization {
        generalization += &format!(
            "{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.1},{}\n",
            r.mode,
            r.success_ratio,
            r.success_std,
            r.success_rule_levels,
            r.success_generator_levels,
            r.completed_by_any,
            r.avg_steps,
            r.tracks
        );
    }
    let mut cross = String::from("mode");
    for aux in AUX_VALUES {
        cross += &format!(",aux_{aux:+.1}");
    }
    cross += "\n";
    for r in &results.cross {
        cross += &r.mode;
        for s in &r.success_ratio {
            cross += &format!(",{s:.4}");
        }
        cross += "\n";
    }
    vec![
        ("controllability.csv", controllability),
        ("generalization.csv", generalization),
        ("cross.csv", cross),
    ]
}
