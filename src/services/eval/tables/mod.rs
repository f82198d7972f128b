//! The three tables, assembled from the layout and the statistics of every play.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::services::verify::{FailureConcentration, Summary};
use arlpcg_core::game::facts::facts;
use arlpcg_core::level::Game;
use arlpcg_core::level::stats::SolverStats;

use super::{AUX_VALUES, Budget, KNOB_BETWEEN, Play, PlayLayout};

/// One row of the controllability table: the ARLPCG Solver on the Generator's levels at one λ.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ControllabilityRow {
    /// λ.
    pub aux: f64,
    /// Mean over levels of each level's success ratio.
    pub success_ratio: f64,
    /// Standard deviation over levels of the success ratio.
    pub success_std: f64,
    /// Fraction of levels completed by at least one run.
    pub completed_by_any: f64,
    /// The pieces' mean parameters, named by the game's piece columns (`avg_block_distance`, ...).
    #[serde(flatten)]
    pub pieces: BTreeMap<String, f64>,
    /// Racing: mean seconds per run with the car in the air.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub air_time: Option<f64>,
    /// Where the failures are ([`PieceFailures`]; absent from results written before).
    #[serde(default, flatten, skip_serializing_if = "Option::is_none")]
    pub failures: Option<PieceFailures>,
    /// Levels played at this λ.
    pub tracks: usize,
}

/// How long the levels of one λ are and where their failed runs fail: a Generator that makes a
/// level hard by a wall before the goal has most failures on the last piece, one whose
/// difficulty lies along the way spreads them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct PieceFailures {
    /// Mean pieces per level.
    pub pieces_per_level: f64,
    /// Of all failed runs, the share that failed on their level's last piece...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failures_on_last_piece: Option<f64>,
    /// ...and on the piece of their level that fails most (none: no run failed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failures_on_worst_piece: Option<f64>,
}

impl ControllabilityRow {
    /// Pieces per level, and the failures' shares on the last and on the worst piece (none: not
    /// measured, or no run failed).
    pub fn failure_columns(&self) -> [Option<f64>; 3] {
        self.failures.map_or([None; 3], |f| {
            [
                Some(f.pieces_per_level),
                f.failures_on_last_piece,
                f.failures_on_worst_piece,
            ]
        })
    }
}

impl PieceFailures {
    /// From the statistics of each level of one λ (none without levels).
    pub fn of(stats: &[&SolverStats]) -> Option<PieceFailures> {
        if stats.is_empty() {
            return None;
        }
        let mut gathered = FailureConcentration::default();
        for level in stats {
            gathered.add(level);
        }
        let shares = gathered.shares();
        Some(PieceFailures {
            pieces_per_level: gathered.pieces_per_level(),
            failures_on_last_piece: shares.map(|[last, _]| last),
            failures_on_worst_piece: shares.map(|[_, worst]| worst),
        })
    }
}

/// One row of the generalization table: one Solver on the validation set.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct GeneralizationRow {
    /// The Solver's training mode.
    pub mode: String,
    /// Mean over levels of each level's success ratio.
    pub success_ratio: f64,
    /// Mean success on the validation set's rule levels (no Solver trained on these)...
    pub success_rule_levels: f64,
    /// ...and on its Generator levels (the ARLPCG Solver's own training distribution).
    pub success_generator_levels: f64,
    /// Standard deviation over levels of the success ratio.
    pub success_std: f64,
    /// Fraction of levels completed by at least one run.
    pub completed_by_any: f64,
    /// Mean decisions of the successful runs.
    pub avg_steps: f64,
    /// Levels played.
    pub tracks: usize,
}

/// One row of the cross table: one Solver on the Generator's levels at each λ.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct CrossRow {
    /// The Solver's training mode.
    pub mode: String,
    /// Success ratio at each λ of [`AUX_VALUES`], in that order.
    pub success_ratio: Vec<f64>,
}

/// One judge at one λ: its success on the controllability levels (the cross table's plays).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct JudgeRow {
    pub judge: String,
    pub aux: f64,
    pub success_ratio: f64,
    pub completed_by_any: f64,
}

/// How smoothly λ turns difficulty: the ARLPCG Solver on the same goals at every λ from 1 to -1,
/// 0.25 apart ([`AUX_VALUES`] and [`KNOB_BETWEEN`]).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Knob {
    /// λ, easy to hard.
    pub aux: Vec<f64>,
    /// Mean success at each.
    pub success: Vec<f64>,
    /// Steps from one λ to the next on the same goal...
    pub steps: usize,
    /// ...and the share of them in which success moved by at most [`Knob::SMOOTH_STEP`].
    pub smooth_steps: f64,
}

impl Knob {
    /// The most a step of 0.25 in λ may move one goal's success and still count as smooth.
    pub const SMOOTH_STEP: f64 = 0.5;

    /// From the ARLPCG Solver's plays at every λ (none when the knob's levels were not played).
    fn of(plays: &[Play], stats: &[SolverStats]) -> Option<Knob> {
        let aux: Vec<f64> = (0..AUX_VALUES.len() + KNOB_BETWEEN.len())
            .map(|k| match k % 2 {
                0 => AUX_VALUES[k / 2],
                _ => KNOB_BETWEEN[k / 2],
            })
            .collect();
        // Each λ's success by goal (the level's seed, the same at every λ).
        let mut by_aux = vec![BTreeMap::new(); aux.len()];
        for (play, s) in plays.iter().zip(stats) {
            let k = match *play {
                Play::Controllability { aux, .. } => 2 * aux,
                Play::Knob { aux, .. } => 2 * aux + 1,
                _ => continue,
            };
            by_aux[k].insert(s.seed, s.success_ratio);
        }
        if by_aux.iter().any(BTreeMap::is_empty) {
            return None;
        }
        let success = by_aux
            .iter()
            .map(|goals| goals.values().sum::<f64>() / goals.len() as f64)
            .collect();
        let moves: Vec<f64> = by_aux
            .windows(2)
            .flat_map(|pair| {
                let next = &pair[1];
                pair[0]
                    .iter()
                    .filter_map(|(seed, a)| next.get(seed).map(|b| (a - b).abs()))
            })
            .collect();
        let smooth = moves.iter().filter(|&&m| m <= Self::SMOOTH_STEP).count();
        Some(Knob {
            aux,
            success,
            steps: moves.len(),
            smooth_steps: smooth as f64 / moves.len().max(1) as f64,
        })
    }
}

/// Everything `eval` measures.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Results {
    /// The game evaluated (the tables' columns and the paper's figures depend on it). Not in
    /// results.json, whose folder names the game: [`Results::read`] sets it.
    #[serde(skip, default = "unread_game")]
    pub game: Game,
    /// How much was evaluated.
    pub budget: Budget,
    /// The Generator's policy file.
    pub generator: String,
    /// The controllability table, a row per λ.
    pub controllability: Vec<ControllabilityRow>,
    /// The generalization table, a row per Solver.
    pub generalization: Vec<GeneralizationRow>,
    /// The cross table, a row per Solver.
    pub cross: Vec<CrossRow>,
    /// Every judge (trained Solvers and the scripted player's skills) at every λ.
    pub controllability_by_judge: Vec<JudgeRow>,
    /// The knob every 0.25 of λ (absent from results written before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knob: Option<Knob>,
    /// The game profile every level was made and played for (`eval --profile`; absent: the
    /// built-in game).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<arlpcg_core::level::profile::ProfileRecord>,
    /// Each style knob's table (a Generator trained with knobs; absent otherwise).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub knobs: Vec<super::styles::KnobTable>,
}

/// What a [`Results`] read from JSON holds until [`Results::read`] sets the game.
fn unread_game() -> Game {
    Game::default()
}

impl Results {
    /// A game's results.json, as `eval` wrote it: refused when its tables are another game's,
    /// or when a number is not finite and within its range (`Err` names the field).
    pub fn read(game: Game, json: &[u8]) -> anyhow::Result<Results> {
        let mut results: Results = serde_json::from_slice(json)?;
        results.game = game;
        results.check().map_err(anyhow::Error::msg)?;
        Ok(results)
    }

    /// Checks tables read from a file: the piece columns of its game, each share within [0, 1],
    /// each λ within [-1, 1], every other figure finite and not negative.
    fn check(&self) -> Result<(), String> {
        let game = facts(self.game);
        let columns: Vec<&str> = game.piece_columns.iter().map(|(name, _)| *name).collect();
        if let Some(record) = &self.profile {
            record
                .profile(self.game)
                .map_err(|e| format!("profile: {e}"))?;
        }
        // The other game's piece columns: none may stand where this game's do.
        let foreign: Vec<&str> = Game::ALL
            .into_iter()
            .filter(|&g| g != self.game)
            .flat_map(|g| facts(g).piece_columns.iter().map(|(name, _)| *name))
            .filter(|name| !columns.contains(name))
            .collect();
        for (k, row) in self.controllability.iter().enumerate() {
            let at = |field: &str| format!("controllability[{k}].{field}");
            let has = |name: &&str| row.pieces.contains_key(*name);
            let theirs = foreign.iter().any(has);
            if theirs
                || !columns.iter().all(has)
                || row.air_time.is_some() != game.air_time_step.is_some()
            {
                return Err(format!(
                    "controllability[{k}]: its columns are not the {} game's ({}): another game's results?",
                    self.game,
                    columns.join(", ")
                ));
            }
            within(&at("aux"), row.aux, AUX)?;
            within(&at("success_ratio"), row.success_ratio, SHARE)?;
            within(&at("success_std"), row.success_std, SHARE)?;
            within(&at("completed_by_any"), row.completed_by_any, SHARE)?;
            for name in &columns {
                within(&at(name), row.pieces[*name], SIZE)?;
            }
            if let Some(air) = row.air_time {
                within(&at("air_time"), air, COUNT)?;
            }
            if let Some(f) = row.failures {
                within(&at("pieces_per_level"), f.pieces_per_level, COUNT)?;
                for (name, share) in [
                    ("failures_on_last_piece", f.failures_on_last_piece),
                    ("failures_on_worst_piece", f.failures_on_worst_piece),
                ] {
                    if let Some(share) = share {
                        within(&at(name), share, SHARE)?;
                    }
                }
            }
        }
        for (k, row) in self.generalization.iter().enumerate() {
            let at = |field: &str| format!("generalization[{k}].{field}");
            for (name, value) in [
                ("success_ratio", row.success_ratio),
                ("success_rule_levels", row.success_rule_levels),
                ("success_generator_levels", row.success_generator_levels),
                ("success_std", row.success_std),
                ("completed_by_any", row.completed_by_any),
            ] {
                within(&at(name), value, SHARE)?;
            }
            within(&at("avg_steps"), row.avg_steps, COUNT)?;
        }
        for (k, row) in self.cross.iter().enumerate() {
            if row.success_ratio.len() != AUX_VALUES.len() {
                return Err(format!(
                    "cross[{k}].success_ratio: {} values, one per λ ({}) expected",
                    row.success_ratio.len(),
                    AUX_VALUES.len()
                ));
            }
            for (a, value) in row.success_ratio.iter().enumerate() {
                within(&format!("cross[{k}].success_ratio[{a}]"), *value, SHARE)?;
            }
        }
        for (k, row) in self.controllability_by_judge.iter().enumerate() {
            let at = |field: &str| format!("controllability_by_judge[{k}].{field}");
            within(&at("aux"), row.aux, AUX)?;
            within(&at("success_ratio"), row.success_ratio, SHARE)?;
            within(&at("completed_by_any"), row.completed_by_any, SHARE)?;
        }
        if let Some(knob) = &self.knob {
            if knob.aux.len() != knob.success.len() {
                return Err("knob: aux and success differ in length".into());
            }
            for (a, (aux, success)) in knob.aux.iter().zip(&knob.success).enumerate() {
                within(&format!("knob.aux[{a}]"), *aux, AUX)?;
                within(&format!("knob.success[{a}]"), *success, SHARE)?;
            }
            within("knob.smooth_steps", knob.smooth_steps, SHARE)?;
        }
        for (k, table) in self.knobs.iter().enumerate() {
            let at = |field: &str| format!("knobs[{k}].{field}");
            within(&at("spearman"), table.spearman, AUX)?;
            within(&at("success_spread"), table.success_spread, SHARE)?;
            for (r, row) in table.rows.iter().enumerate() {
                let at = |field: &str| format!("knobs[{k}].rows[{r}].{field}");
                within(&at("value"), row.value, AUX)?;
                within(&at("measured"), row.measured, AUX)?;
                within(&at("measured_std"), row.measured_std, SHARE)?;
                within(&at("success_ratio"), row.success_ratio, SHARE)?;
            }
        }
        Ok(())
    }
}

/// The range of a share or a success ratio.
const SHARE: (f64, f64) = (0.0, 1.0);
/// The range of λ.
const AUX: (f64, f64) = (-1.0, 1.0);
/// The range of a piece's mean parameter (metres, degrees), of a size a level has...
const SIZE: (f64, f64) = (-1e6, 1e6);
/// ...and of a count or a duration (pieces per level, steps, seconds).
const COUNT: (f64, f64) = (0.0, 1e9);

/// `Err` naming `field` unless `value` is a number within `range`.
pub(super) fn within(field: &str, value: f64, (least, most): (f64, f64)) -> Result<(), String> {
    match (least..=most).contains(&value) {
        true => Ok(()),
        false => Err(format!(
            "{field}: {} is not a number within [{least}, {most}]",
            arlpcg_core::level::params::show_number(value)
        )),
    }
}

/// The summary of some plays' statistics (NaN figures for none).
fn summarized(chosen: Vec<SolverStats>) -> Summary {
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
}

/// The controllability row of λ number `a` of [`AUX_VALUES`], from the ARLPCG Solver's
/// statistics on its levels.
fn controllability_row(
    layout: &PlayLayout,
    a: usize,
    at_aux: &[&SolverStats],
) -> ControllabilityRow {
    let s = summarized(at_aux.iter().map(|&s| s.clone()).collect());
    let game = facts(layout.game);
    let pieces = game
        .piece_columns
        .iter()
        .enumerate()
        .map(|(k, (name, _))| {
            let mean = layout.piece_means[a].as_ref().map_or(f64::NAN, |m| m[k]);
            (name.to_string(), mean)
        })
        .collect();
    let air: Vec<f64> = at_aux.iter().filter_map(|s| s.mean_air_steps).collect();
    let air_time = game
        .air_time_step
        .map(|dt| dt * air.iter().sum::<f64>() / air.len().max(1) as f64);
    ControllabilityRow {
        aux: AUX_VALUES[a],
        success_ratio: s.mean_success,
        success_std: s.std_success,
        completed_by_any: s.completed_by_any,
        pieces,
        air_time,
        failures: PieceFailures::of(at_aux),
        tracks: layout.levels_per_aux[a],
    }
}

/// The tables from the layout and the statistics of every play (`stats[i]` of play `i`).
pub fn assemble(
    budget: Budget,
    generator: &str,
    layout: &PlayLayout,
    stats: &[SolverStats],
) -> Results {
    let plays = layout.plays();
    assert_eq!(plays.len(), stats.len(), "one statistics entry per play");
    let summary = |wanted: &dyn Fn(&Play) -> bool| {
        summarized(
            plays
                .iter()
                .zip(stats)
                .filter(|(p, _)| wanted(p))
                .map(|(_, s)| s.clone())
                .collect(),
        )
    };
    let controllability = (0..AUX_VALUES.len())
        .map(|a| {
            let at_aux: Vec<&SolverStats> = plays
                .iter()
                .zip(stats)
                .filter(|(p, _)| matches!(p, Play::Controllability { aux, .. } if *aux == a))
                .map(|(_, s)| s)
                .collect();
            controllability_row(layout, a, &at_aux)
        })
        .collect();
    let mut generalization = Vec::new();
    let mut cross = Vec::new();
    let mut controllability_by_judge = Vec::new();
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
        let by_aux: Vec<Summary> = (0..AUX_VALUES.len())
            .map(|a| {
                summary(
                    &|p| matches!(p, Play::Cross { solver, aux, .. } if *solver == k && *aux == a),
                )
            })
            .collect();
        for (s, &aux) in by_aux.iter().zip(&AUX_VALUES) {
            controllability_by_judge.push(JudgeRow {
                judge: mode.clone(),
                aux,
                success_ratio: s.mean_success,
                completed_by_any: s.completed_by_any,
            });
        }
        let success_ratio = by_aux.iter().map(|s| s.mean_success).collect();
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
        controllability_by_judge,
        knob: Knob::of(&plays, stats),
        profile: None,
        knobs: super::styles::knob_tables(&layout.knobs, &plays, stats),
    }
}

#[cfg(test)]
pub(super) mod tests;
