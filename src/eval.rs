//! The paper's evaluation on either game (docs/spec.md §4), as pure functions of the policies
//! and the budget: the same policies and budget give the same tables.
//!
//! - **Controllability**: Generator levels at λ ∈ {1, 0.5, 0, -0.5, -1} (the same goals at every
//!   λ), played by the ARLPCG Solver: success ratio ± std over levels, the fraction completed by
//!   at least one run, the pieces' mean parameters (platform: block distance and size; racing:
//!   segment curve, length and height change) and, racing, the car's time in the air per run.
//! - **Generalization**: every Solver on one held-out validation set (half rule levels, half
//!   Generator levels cycling through the λ values), success ± std, completed by any, mean steps
//!   of successful runs.
//! - **Cross**: every Solver on the controllability levels, success ratio at each λ.
//!
//! Levels use seeds from [`EVAL_SEED_BASE`] up, far below the seeds training draws from
//! ([`crate::train::solver_envs::TRAINING_SEED_BASE`]): no evaluation level was trained on.

use rayon::prelude::*;
use serde::Serialize;

use std::collections::BTreeMap;

use crate::generation::{self, GeneratorPolicy};
use crate::level::stats::SolverStats;
use crate::level::{Game, Level, Track};
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
    /// The pieces' mean parameters, named by [`piece_columns`] (`avg_block_distance`, ...).
    #[serde(flatten)]
    pub pieces: BTreeMap<String, f64>,
    /// Racing: mean seconds per run with the car in the air.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_time: Option<f64>,
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
    /// The game evaluated (the tables' columns and the paper's figures depend on it).
    #[serde(skip)]
    pub game: Game,
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
        match generation::generator_level(
            generator,
            seed,
            aux,
            None,
            scene_obstacles(generator.game),
        ) {
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
    let game = generator.game;
    let mut levels: Vec<Level> = (0..rule_count as u64)
        .filter_map(|k| {
            generation::rules_level(game, base + k, None, None, scene_obstacles(game)).ok()
        })
        .collect();
    let per_aux = (count - rule_count).div_ceil(AUX_VALUES.len() as u32);
    for (k, &aux) in AUX_VALUES.iter().enumerate() {
        let seeds = base + (1 + k as u64) * (1 << 24);
        let wanted = per_aux.min(count - levels.len() as u32);
        levels.extend(generator_levels(generator, aux, seeds, wanted)?);
    }
    Ok(levels)
}

/// Obstacles in each evaluation scene: racing tracks are built around as many as the racing
/// Generator trained with (some draws are dropped near the start or goal).
pub fn scene_obstacles(game: Game) -> u32 {
    match game {
        Game::Platform => 0,
        Game::Racing => crate::game::racing::generator::MATCH_OBSTACLES,
    }
}

/// The names of the controllability table's piece columns of `game`, in the order
/// [`piece_values`] gives them.
pub fn piece_columns(game: Game) -> &'static [&'static str] {
    match game {
        Game::Platform => &["avg_block_distance", "avg_block_size"],
        Game::Racing => &[
            "avg_segment_curve",
            "avg_segment_length",
            "avg_segment_height",
        ],
    }
}

/// Each piece's parameters, as [`piece_columns`] names them (racing: the curve's and the
/// height change's size, whatever their sign).
fn piece_values(level: &Level) -> Vec<Vec<f64>> {
    match &level.track {
        Track::Platform(track) => track
            .block_params()
            .iter()
            .map(|b| vec![b.distance, b.size])
            .collect(),
        Track::Racing(track) => track
            .segments
            .iter()
            .map(|s| vec![s.curve.abs(), s.length, s.height.abs()])
            .collect(),
    }
}

/// What the tables are made of, without the levels themselves: the game, how many levels each
/// table has, the Solvers' names and the piece statistics of the controllability levels. With
/// it, the per-level statistics of every play make the tables ([`assemble`]), so shards of an
/// evaluation can be played apart and merged.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Layout {
    pub game: Game,
    /// Levels per λ of [`AUX_VALUES`] (the Generator may build fewer than the budget asks).
    pub levels_per_aux: Vec<usize>,
    /// The pieces' mean parameters ([`piece_columns`]) at each λ (`None`: no levels).
    pub piece_means: Vec<Option<Vec<f64>>>,
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
    let game = generator.game;
    let piece_means = by_aux
        .iter()
        .map(|levels| {
            let pieces: Vec<Vec<f64>> = levels.iter().flat_map(piece_values).collect();
            (!pieces.is_empty()).then(|| {
                (0..piece_columns(game).len())
                    .map(|k| pieces.iter().map(|p| p[k]).sum::<f64>() / pieces.len() as f64)
                    .collect()
            })
        })
        .collect();
    let layout = Layout {
        game,
        levels_per_aux: by_aux.iter().map(Vec::len).collect(),
        piece_means,
        validation_levels: validation.len(),
        validation_rule_levels: validation
            .iter()
            .filter(|l| {
                matches!(
                    l.source,
                    crate::level::Source::Rules { .. } | crate::level::Source::RacingRules { .. }
                )
            })
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
            let pieces = piece_columns(layout.game)
                .iter()
                .enumerate()
                .map(|(k, name)| {
                    let mean = layout.piece_means[a].as_ref().map_or(f64::NAN, |m| m[k]);
                    (name.to_string(), mean)
                })
                .collect();
            let air: Vec<f64> = plays
                .iter()
                .zip(stats)
                .filter(|(p, _)| matches!(p, Play::Controllability { aux, .. } if *aux == a))
                .filter_map(|(_, s)| s.mean_air_steps)
                .collect();
            let air_time = (layout.game == Game::Racing).then(|| {
                let dt = f64::from(crate::game::racing::car::DECISION_DT);
                dt * air.iter().sum::<f64>() / air.len().max(1) as f64
            });
            ControllabilityRow {
                aux,
                success_ratio: s.mean_success,
                success_std: s.std_success,
                completed_by_any: s.completed_by_any,
                pieces,
                air_time,
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
        game: layout.game,
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

/// The paper's controllability figures for `game` at each λ of [`AUX_VALUES`] (docs/spec.md §4).
fn paper_controllability(game: Game) -> [&'static str; 5] {
    match game {
        Game::Platform => [
            "0.97, 6.73 m, 5.95 m",
            "0.92, 6.98 m, 5.77 m",
            "0.88, 7.15 m, 5.42 m",
            "0.74, 7.11 m, 4.52 m",
            "0.69, 7.46 m, 4.01 m",
        ],
        Game::Racing => [
            "0.99, 14.4°, 28.4 m, 1.5 m",
            "0.89, 14.7°, 27.1 m, 2.0 m",
            "0.77, 15.1°, 25.1 m, 2.5 m",
            "0.64, 15.3°, 23.0 m, 3.1 m",
            "0.61, 16.8°, 21.8 m, 3.9 m",
        ],
    }
}

/// The paper's generalization figure for a Solver of `game` trained in `mode` (docs/spec.md §4).
fn paper_generalization(game: Game, mode: &str) -> &'static str {
    match (game, mode) {
        (Game::Platform, "fixed-track") => "0.081 ± 0.205, 0.20 (54 steps)",
        (Game::Platform, "rule-pcg") => "0.233 ± 0.200, 0.95 (451 steps)",
        (Game::Platform, "fixed-aux") => "0.173 ± 0.195, 0.90 (442 steps)",
        (Game::Platform, "arlpcg") => "0.457 ± 0.211, 1.00 (467 steps)",
        (Game::Racing, "fixed-track") => "0.219 ± 0.280, 0.7 (431 m)",
        (Game::Racing, "rule-pcg") => "0.174 ± 0.160, 0.9 (355 m)",
        (Game::Racing, "fixed-aux") => "0.163 ± 0.138, 0.8 (382 m)",
        (Game::Racing, "arlpcg") => "0.331 ± 0.225, 1.0 (507 m)",
        _ => "",
    }
}

/// The three tables as markdown, beside the paper's figures.
pub fn markdown(results: &Results) -> String {
    let game = results.game;
    let mut md =
        String::from("## Generator controllability (ARLPCG Solver on Generator levels)\n\n");
    md += match game {
        Game::Platform => {
            "| λ | success ratio | completed by any | avg block distance | avg block size | levels | paper: success, distance, size |\n|---|---|---|---|---|---|---|\n"
        }
        Game::Racing => {
            "| λ | success ratio | completed by any | air time per run | avg segment curve | avg segment length | avg segment height change | tracks | paper: success, angle, length, height |\n|---|---|---|---|---|---|---|---|---|\n"
        }
    };
    let units: &[&str] = match game {
        Game::Platform => &[" m", " m"],
        Game::Racing => &["°", " m", " m"],
    };
    for (row, paper) in results
        .controllability
        .iter()
        .zip(paper_controllability(game))
    {
        md += &format!(
            "| {:+.1} | {} ± {} | {} |",
            row.aux,
            num(row.success_ratio, 3),
            num(row.success_std, 3),
            num(row.completed_by_any, 2),
        );
        if let Some(air) = row.air_time {
            md += &format!(" {} s |", num(air, 2));
        }
        for (name, unit) in piece_columns(game).iter().zip(units) {
            md += &format!(" {}{unit} |", num(row.pieces[*name], 2));
        }
        md += &format!(" {} | {paper} |\n", row.tracks);
    }
    md += "\n## Solver generalization (held-out validation levels)\n\n";
    md += "| mode | success ratio | on rule levels | on Generator levels | completed by any | avg steps | paper |\n|---|---|---|---|---|---|---|\n";
    for row in &results.generalization {
        let paper = paper_generalization(game, &row.mode);
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
    let columns = piece_columns(results.game);
    let air = results.game == Game::Racing;
    let mut controllability = format!(
        "aux,success_ratio,success_std,completed_by_any,{}{},tracks\n",
        if air { "air_time," } else { "" },
        columns.join(",")
    );
    for r in &results.controllability {
        controllability += &format!(
            "{},{:.4},{:.4},{:.4},",
            r.aux, r.success_ratio, r.success_std, r.completed_by_any,
        );
        if let Some(time) = r.air_time {
            controllability += &format!("{time:.4},");
        }
        for name in columns {
            controllability += &format!("{:.4},", r.pieces[*name]);
        }
        controllability += &format!("{}\n", r.tracks);
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
