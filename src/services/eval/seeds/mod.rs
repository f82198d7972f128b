//! Results over training seeds (`eval --runs`): each run folder's Solver on one shared
//! validation set, each adversarial run's own pair on its controllability levels, then per
//! mode the IQM and mean over seeds with stratified-bootstrap intervals, and the probability
//! that the ARLPCG Solver beats each baseline on validation ([`arlpcg_core::statistics::over_seeds`]). With two
//! ARLPCG runs or more, each Solver also plays the hardest levels (λ = -1) of the ARLPCG
//! Generators it did not train with: a Generator's finish aims at its own Solver's failures,
//! so its levels judge every Solver but that one as unseen levels.

use std::collections::BTreeMap;

use rayon::prelude::*;
use serde::Serialize;

use crate::services::generation::GeneratorPolicy;
use crate::services::panel::JudgePanel;
use crate::services::verify::{Solver, SolverPolicy, verify};
use arlpcg_core::level::Level;
use arlpcg_core::seed_ranges::EVAL_SEED_BASE;
use arlpcg_core::statistics::over_seeds::{
    Aggregate, Estimate, estimate, probability_of_improvement,
};

use super::tables::within;
use super::{AUX_VALUES, Budget, generator_levels};

pub mod markdown;
pub use markdown::markdown;

/// How much a judge's success may rise from one λ to the next harder one and still count as
/// falling monotonically (the noise of the default budget).
pub const DROP_TOLERANCE: f64 = 0.05;

/// What one training run scored.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct RunScores {
    /// The run's folder.
    pub run: String,
    /// The run's training mode.
    pub mode: String,
    /// The run's seed.
    pub seed: u64,
    /// Mean success on the validation set's rule levels...
    pub validation_rule_levels: f64,
    /// ...on its Generator levels...
    pub validation_generator_levels: f64,
    /// ...and on all of it.
    pub validation: f64,
    /// An adversarial run's own pair: its Solver on its Generator's levels at each λ of
    /// [`AUX_VALUES`] (null at a λ where the Generator built no level: a fixed-aux Generator
    /// may build only at the λ it trained at).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controllability: Option<Vec<Option<f64>>>,
    /// The same levels played by the outside judges (the rule-pcg Solver of the evaluation's
    /// policies, the scripted player at median and expert skill; the recipe's finish plays the
    /// median player in both games, so for its runs that one is not a stranger).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub controllability_by_judge: Vec<JudgeCurve>,
    /// Mean success on the λ = -1 levels of the ARLPCG runs' Generators other than the run's
    /// own (none when there is no other)...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_generators_hard: Option<f64>,
    /// ...and on each of them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub on_other_generators: Vec<GeneratorScore>,
}

/// A Solver's mean success on the λ = -1 levels of one run's Generator.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct GeneratorScore {
    /// The Generator's run folder.
    pub generator: String,
    /// The Solver's mean success on them.
    pub success_ratio: f64,
}

/// One judge's success at each λ of [`AUX_VALUES`].
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct JudgeCurve {
    /// The judge's name.
    pub judge: String,
    /// Its success at each λ, in order (null where the Generator built no level).
    pub success_ratio: Vec<Option<f64>>,
}

impl RunScores {
    /// The median over the judges of their drop in success from λ = +1 to λ = -1, and whether
    /// every judge's success falls monotonically (within `tolerance`); `None` without judges,
    /// or when the Generator built no level at some λ.
    pub fn judges_drop(&self, tolerance: f64) -> Option<(f64, bool)> {
        let curves: Vec<Vec<f64>> = self
            .controllability_by_judge
            .iter()
            .map(|c| c.success_ratio.iter().copied().collect())
            .collect::<Option<_>>()?;
        let mut drops: Vec<f64> = curves
            .iter()
            .filter_map(|c| Some(c.first()? - c.last()?))
            .collect();
        if drops.is_empty() {
            return None;
        }
        drops.sort_by(f64::total_cmp);
        let n = drops.len();
        let median = if n % 2 == 1 {
            drops[n / 2]
        } else {
            0.5 * (drops[n / 2 - 1] + drops[n / 2])
        };
        let monotone = curves
            .iter()
            .all(|c| c.windows(2).all(|w| w[1] <= w[0] + tolerance));
        Some((median, monotone))
    }
}

/// One mode over its seeds.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ModeSummary {
    /// The training mode.
    pub mode: String,
    /// The seeds of its runs.
    pub seeds: Vec<u64>,
    /// Validation success: IQM and mean over (half, seed), stratified by half.
    pub validation_iqm: Estimate,
    /// Validation success: the mean over (half, seed).
    pub validation_mean: Estimate,
    /// Mean controllability success at each λ (adversarial modes), over the seeds whose
    /// Generator built levels there (null where none did).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controllability: Option<Vec<Option<SeedsEstimate>>>,
    /// The same for each outside judge.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub controllability_by_judge: Vec<JudgeSummary>,
    /// Mean over seeds of [`RunScores::other_generators_hard`], when every seed has it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_generators_hard: Option<Estimate>,
}

/// One judge's mean success at each λ over a mode's seeds.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct JudgeSummary {
    /// The judge's name.
    pub judge: String,
    /// Its mean success at each λ, in order, as [`ModeSummary::controllability`].
    pub success_ratio: Vec<Option<SeedsEstimate>>,
}

/// An estimate over the seeds that have a value (a λ where a seed's Generator built no level
/// has none).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct SeedsEstimate {
    /// The estimate.
    #[serde(flatten)]
    pub estimate: Estimate,
    /// How many of the mode's seeds it is over, when not all of them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seeds: Option<usize>,
}

/// The estimate over seeds of `values` (one per seed; none where a seed has no value),
/// none when no seed has one.
fn over_seeds(values: &[Option<f64>], stream: u64) -> Option<SeedsEstimate> {
    let at: Vec<f64> = values.iter().flatten().copied().collect();
    (!at.is_empty()).then(|| SeedsEstimate {
        seeds: (at.len() < values.len()).then_some(at.len()),
        estimate: estimate(&[at], Aggregate::Mean, stream),
    })
}

/// P(arlpcg's validation success > the baseline's), over seeds.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Improvement {
    /// The baseline's mode.
    pub baseline: String,
    /// The probability, with its interval.
    pub probability: Estimate,
}

/// Everything `eval --runs` reports (`seeds.json`).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct SeedResults {
    /// How much was evaluated.
    pub budget: Budget,
    /// The Generator whose levels make the validation set's other half.
    pub validation_generator: String,
    /// The λ values the success curves are measured at, in order.
    pub aux: Vec<f64>,
    /// Each mode's runs, one entry per seed.
    pub seeds: BTreeMap<String, Vec<RunScores>>,
    /// Each mode over its seeds.
    pub modes: Vec<ModeSummary>,
    /// P(arlpcg's validation success > each baseline's).
    pub arlpcg_beats: Vec<Improvement>,
    /// P(arlpcg's success > the baseline's) on the other Generators' λ = -1 levels.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub arlpcg_beats_on_other_generators: Vec<Improvement>,
}

impl SeedResults {
    /// A seeds.json as `eval --runs` wrote it, refused (`Err` naming the field) when a figure
    /// is not a share within [0, 1], a λ not within [-1, 1], or a curve lacks a value per λ.
    pub fn read(json: &[u8]) -> anyhow::Result<SeedResults> {
        let results: SeedResults = serde_json::from_slice(json)?;
        results.check().map_err(anyhow::Error::msg)?;
        Ok(results)
    }

    fn check(&self) -> Result<(), String> {
        const SHARE: (f64, f64) = (0.0, 1.0);
        if self.aux.is_empty() || self.aux.len() > AUX_VALUES.len() {
            return Err(format!("aux: 1 to {} values of λ", AUX_VALUES.len()));
        }
        for (a, aux) in self.aux.iter().enumerate() {
            within(&format!("aux[{a}]"), *aux, (-1.0, 1.0))?;
        }
        // Every curve has one value per λ.
        let curve = |field: &str, values: &[Option<f64>]| -> Result<(), String> {
            if values.len() != self.aux.len() {
                return Err(format!(
                    "{field}: {} values, one per λ ({}) expected",
                    values.len(),
                    self.aux.len()
                ));
            }
            for (a, value) in values.iter().enumerate() {
                if let Some(value) = value {
                    within(&format!("{field}[{a}]"), *value, SHARE)?;
                }
            }
            Ok(())
        };
        let estimate = |field: &str, e: &Estimate| -> Result<(), String> {
            within(&format!("{field}.value"), e.value, SHARE)?;
            within(&format!("{field}.ci95[0]"), e.ci95[0], SHARE)?;
            within(&format!("{field}.ci95[1]"), e.ci95[1], SHARE)
        };
        for (mode, runs) in &self.seeds {
            for (k, run) in runs.iter().enumerate() {
                let at = |field: &str| format!("seeds.{mode}[{k}].{field}");
                within(&at("validation"), run.validation, SHARE)?;
                within(
                    &at("validation_rule_levels"),
                    run.validation_rule_levels,
                    SHARE,
                )?;
                within(
                    &at("validation_generator_levels"),
                    run.validation_generator_levels,
                    SHARE,
                )?;
                if let Some(values) = &run.controllability {
                    curve(&at("controllability"), values)?;
                }
                for (j, judge) in run.controllability_by_judge.iter().enumerate() {
                    curve(
                        &at(&format!("controllability_by_judge[{j}].success_ratio")),
                        &judge.success_ratio,
                    )?;
                }
                if let Some(hard) = run.other_generators_hard {
                    within(&at("other_generators_hard"), hard, SHARE)?;
                }
                for (g, score) in run.on_other_generators.iter().enumerate() {
                    let field = at(&format!("on_other_generators[{g}].success_ratio"));
                    within(&field, score.success_ratio, SHARE)?;
                }
            }
        }
        for (k, mode) in self.modes.iter().enumerate() {
            let at = |field: &str| format!("modes[{k}].{field}");
            estimate(&at("validation_iqm"), &mode.validation_iqm)?;
            estimate(&at("validation_mean"), &mode.validation_mean)?;
            let curves = mode
                .controllability
                .iter()
                .map(|c| ("controllability".to_string(), c));
            let judges = mode
                .controllability_by_judge
                .iter()
                .enumerate()
                .map(|(j, c)| {
                    (
                        format!("controllability_by_judge[{j}].success_ratio"),
                        &c.success_ratio,
                    )
                });
            for (field, estimates) in curves.chain(judges) {
                if estimates.len() != self.aux.len() {
                    return Err(format!("{}: one value per λ expected", at(&field)));
                }
                for (a, e) in estimates.iter().enumerate() {
                    if let Some(e) = e {
                        estimate(&at(&format!("{field}[{a}]")), &e.estimate)?;
                    }
                }
            }
            if let Some(hard) = &mode.other_generators_hard {
                estimate(&at("other_generators_hard"), hard)?;
            }
        }
        let beats = self.arlpcg_beats.iter().map(|i| ("arlpcg_beats", i));
        let others = (self.arlpcg_beats_on_other_generators.iter())
            .map(|i| ("arlpcg_beats_on_other_generators", i));
        for (k, (field, improvement)) in beats.chain(others).enumerate() {
            estimate(
                &format!("{field}[{k}].probability"),
                &improvement.probability,
            )?;
        }
        Ok(())
    }
}

/// One run to score: its Solver, mode and seed, and its Generator when it has one.
pub struct SeedRun<'a> {
    /// The run's folder.
    pub folder: String,
    /// The run's training mode.
    pub mode: String,
    /// The run's seed.
    pub seed: u64,
    /// The run's Solver.
    pub solver: &'a SolverPolicy,
    /// The run's Generator, when it has one.
    pub generator: Option<&'a GeneratorPolicy>,
}

/// Plays the validation set (rule levels first, `rule_levels` of them) with every run's Solver,
/// each adversarial run's own pair and the `judges` on its controllability levels, and every
/// Solver on the λ = -1 levels of the ARLPCG Generators other than its run's own
/// ([`other_generators_plays`] of them); `on_level` after each level played. Levels are of the
/// built-in game, as the runs' are.
pub fn score_runs(
    runs: &[SeedRun],
    judges: &JudgePanel,
    validation: &[Level],
    rule_levels: usize,
    budget: Budget,
    on_level: &(dyn Fn() + Sync),
) -> Result<Vec<RunScores>, candle_core::Error> {
    // Each level's success ratio with `solver`.
    let play = |solver: &Solver, levels: &[Level], trials: u32| -> Vec<f64> {
        levels
            .par_iter()
            .map(|level| {
                let stats = verify(level, solver, trials, level.seed.unwrap_or(0), &|| {})
                    .expect("runs are loaded for the evaluation's game");
                on_level();
                stats.success_ratio
            })
            .collect()
    };
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len().max(1) as f64;
    // At a λ where the Generator built no level there is no success to measure.
    let mean_of_any = |xs: &[f64]| (!xs.is_empty()).then(|| mean(xs));
    // Each adversarial run's controllability levels, at every λ of AUX_VALUES, built once:
    // its own pair and the judges play them, and every other run its λ = -1 ones.
    let controllability_levels: Vec<Option<Vec<Vec<Level>>>> = runs
        .iter()
        .map(|run| {
            run.generator
                .map(|generator| {
                    AUX_VALUES
                        .iter()
                        .map(|&aux| {
                            generator_levels(generator, aux, EVAL_SEED_BASE, budget.tracks, None)
                        })
                        .collect::<Result<Vec<_>, _>>()
                })
                .transpose()
        })
        .collect::<Result<_, _>>()?;
    let mut hard_levels: Vec<(&str, &[Level])> = runs
        .iter()
        .zip(&controllability_levels)
        .filter(|(run, _)| run.mode == "arlpcg")
        .filter_map(|(run, levels)| {
            Some((run.folder.as_str(), levels.as_ref()?.last()?.as_slice()))
        })
        .collect();
    // With one ARLPCG Generator there is no other to compare its own Solver on.
    if hard_levels.len() < 2 {
        hard_levels.clear();
    }
    runs.iter()
        .zip(&controllability_levels)
        .map(|(run, levels)| {
            let own = Solver::Policy(run.solver);
            let success = play(&own, validation, budget.validation_trials);
            let (rules, generated) = success.split_at(rule_levels.min(success.len()));
            let (controllability, controllability_by_judge) = match levels {
                Some(levels) => {
                    let own_curve = levels
                        .iter()
                        .map(|at| mean_of_any(&play(&own, at, budget.trials)))
                        .collect();
                    let curves = judges
                        .names()
                        .into_iter()
                        .enumerate()
                        .map(|(k, judge)| JudgeCurve {
                            judge,
                            success_ratio: levels
                                .iter()
                                .map(|at| mean_of_any(&play(&judges.solver(k), at, budget.trials)))
                                .collect(),
                        })
                        .collect();
                    (Some(own_curve), curves)
                }
                None => (None, Vec::new()),
            };
            let on_other_generators: Vec<GeneratorScore> = hard_levels
                .iter()
                .filter(|(folder, _)| *folder != run.folder)
                .map(|(folder, levels)| GeneratorScore {
                    generator: folder.to_string(),
                    success_ratio: mean(&play(&own, levels, budget.trials)),
                })
                .collect();
            Ok(RunScores {
                run: run.folder.clone(),
                mode: run.mode.clone(),
                seed: run.seed,
                validation_rule_levels: mean(rules),
                validation_generator_levels: mean(generated),
                validation: mean(&success),
                controllability,
                controllability_by_judge,
                other_generators_hard: (!on_other_generators.is_empty()).then(|| {
                    mean(
                        &on_other_generators
                            .iter()
                            .map(|g| g.success_ratio)
                            .collect::<Vec<_>>(),
                    )
                }),
                on_other_generators,
            })
        })
        .collect()
}

/// The levels [`score_runs`] plays on other Generators' λ = -1 levels for a run: `tracks` per
/// ARLPCG Generator of `runs` but its own (`own`: the run is one of those), when there are at
/// least two.
pub fn other_generators_plays(arlpcg_generators: usize, own: bool, tracks: u32) -> u64 {
    if arlpcg_generators < 2 {
        return 0;
    }
    (arlpcg_generators - usize::from(own)) as u64 * tracks as u64
}

/// The summaries over seeds (pure: the same scores give the same bytes).
pub fn summarize(budget: Budget, validation_generator: &str, runs: Vec<RunScores>) -> SeedResults {
    let mut modes: Vec<String> = Vec::new();
    for run in &runs {
        if !modes.contains(&run.mode) {
            modes.push(run.mode.clone());
        }
    }
    fn of<'a>(runs: &'a [RunScores], mode: &'a str) -> impl Iterator<Item = &'a RunScores> {
        runs.iter().filter(move |r| r.mode == mode)
    }
    let halves = |mode: &str| -> Vec<Vec<f64>> {
        vec![
            of(&runs, mode).map(|r| r.validation_rule_levels).collect(),
            of(&runs, mode)
                .map(|r| r.validation_generator_levels)
                .collect(),
        ]
    };
    // Every seed's success on the other Generators' hard levels, if every seed has one.
    let hard = |mode: &str| -> Option<Vec<f64>> {
        of(&runs, mode).map(|r| r.other_generators_hard).collect()
    };
    let summaries = modes
        .iter()
        .map(|mode| {
            let controllability = of(&runs, mode)
                .all(|r| r.controllability.is_some())
                .then(|| {
                    (0..AUX_VALUES.len())
                        .map(|a| {
                            let at: Vec<Option<f64>> = of(&runs, mode)
                                .map(|r| r.controllability.as_ref().expect("checked")[a])
                                .collect();
                            over_seeds(&at, a as u64)
                        })
                        .collect()
                });
            ModeSummary {
                mode: mode.clone(),
                seeds: of(&runs, mode).map(|r| r.seed).collect(),
                validation_iqm: estimate(&halves(mode), Aggregate::Iqm, 0),
                validation_mean: estimate(&halves(mode), Aggregate::Mean, 0),
                controllability,
                controllability_by_judge: judge_summaries(of(&runs, mode).collect()),
                other_generators_hard: hard(mode)
                    .map(|at| estimate(&[at], Aggregate::Mean, AUX_VALUES.len() as u64)),
            }
        })
        .collect();
    let arlpcg_beats = match modes.iter().any(|m| m == "arlpcg") {
        true => modes
            .iter()
            .filter(|m| *m != "arlpcg")
            .map(|baseline| Improvement {
                baseline: baseline.clone(),
                probability: probability_of_improvement(&halves("arlpcg"), &halves(baseline), 0),
            })
            .collect(),
        false => Vec::new(),
    };
    let arlpcg_beats_on_other_generators = match hard("arlpcg") {
        Some(arlpcg) => modes
            .iter()
            .filter(|m| *m != "arlpcg")
            .filter_map(|baseline| {
                Some(Improvement {
                    baseline: baseline.clone(),
                    probability: probability_of_improvement(
                        std::slice::from_ref(&arlpcg),
                        &[hard(baseline)?],
                        0,
                    ),
                })
            })
            .collect(),
        None => Vec::new(),
    };
    let mut seeds: BTreeMap<String, Vec<RunScores>> = BTreeMap::new();
    for run in runs {
        seeds.entry(run.mode.clone()).or_default().push(run);
    }
    SeedResults {
        budget,
        validation_generator: validation_generator.to_string(),
        aux: AUX_VALUES.to_vec(),
        seeds,
        modes: summaries,
        arlpcg_beats,
        arlpcg_beats_on_other_generators,
    }
}

/// Each judge's mean success at each λ over `runs` (the judges every run was played by).
fn judge_summaries(runs: Vec<&RunScores>) -> Vec<JudgeSummary> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    first
        .controllability_by_judge
        .iter()
        .filter_map(|curve| {
            let of_judge: Vec<&JudgeCurve> = runs
                .iter()
                .map(|r| {
                    r.controllability_by_judge
                        .iter()
                        .find(|c| c.judge == curve.judge)
                })
                .collect::<Option<_>>()?;
            let success_ratio = (0..curve.success_ratio.len())
                .map(|a| {
                    let at: Vec<Option<f64>> =
                        of_judge.iter().map(|c| c.success_ratio[a]).collect();
                    over_seeds(&at, a as u64)
                })
                .collect();
            Some(JudgeSummary {
                judge: curve.judge.clone(),
                success_ratio,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests;
