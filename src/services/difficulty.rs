//! Difficulty a designer can trust: a Generator's λ → success curve with a given Solver, and
//! the search that turns a wanted success rate into a level (`generate --target-success P`).
//!
//! One level's success at a λ varies a lot from seed to seed (the curve is an average), so the
//! search starts at the λ the curve gives for `P` and then moves λ by how far each verified
//! candidate missed, drawing a new level of the same seed and goal each time, until one
//! measures within [`BAND`] of `P`. A seed's scene can rule a band out (seed 3's goal: no level
//! of the shipped platform policies under 0.55), so after [`OWN_SCENE_CANDIDATES`] misses,
//! unless the goal was given, each candidate is built from another seed's scene (the level
//! records that seed). Each candidate plays [`SCREEN_TRIALS`] runs first and the rest only if
//! their 95% interval still meets the band: a kept level's statistics are those of all its
//! runs, the same as one verification of them all.

use serde::{Deserialize, Serialize};

use crate::services::generation::{self, AuxAsk, GenerationError, GeneratorPolicy, LevelRequest};
use crate::services::verify::{Solver, Watch, WrongGame, stats_of, trial_results, verify};
use crate::services::wish::{Constraint, Evidence, Reads, Strictness};
use arlpcg_core::level::Level;
#[cfg(doc)]
use arlpcg_core::level::pacing::AuxCurve;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::stats::{Outcome, wilson_interval};

/// A kept level measures within this of the wanted success ratio.
pub const BAND: f64 = 0.1;
/// Candidates tried per level before giving up.
pub const MAX_CANDIDATES: u32 = 48;
/// Candidates from the seed's own scene before the search tries other seeds' scenes.
pub const OWN_SCENE_CANDIDATES: u32 = 24;
/// Runs a candidate plays before the search decides whether to play the rest.
pub const SCREEN_TRIALS: u32 = 20;
/// The λ values the curve is measured at, easy to hard.
pub const CURVE_AUX: [f64; 9] = [1.0, 0.75, 0.5, 0.25, 0.0, -0.25, -0.5, -0.75, -1.0];
/// Levels per λ and runs per level when measuring the curve.
pub const CURVE_LEVELS: u32 = 8;
/// Runs per level when measuring the curve.
pub const CURVE_TRIALS: u32 = 20;

/// Mean success ratio of a Solver on a Generator's levels at each λ of [`CURVE_AUX`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Curve {
    /// SHA-256 of the Generator.
    pub generator_sha256: String,
    /// SHA-256 of the Solver it was measured with (for the scripted player, its judge name:
    /// `scripted-median`).
    pub solver_sha256: String,
    /// SHA-256 of the profile its levels were made for (none: the built-in game).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile_sha256: Option<String>,
    /// (λ, mean success ratio), easy to hard.
    pub points: Vec<(f64, f64)>,
}

impl Curve {
    /// Checks a curve read back from a file: at least one point, their λ among [`CURVE_AUX`]
    /// in its order (a λ where no level was built has none), each success a number within
    /// [0, 1]. `Err("points[i]: ...")`.
    pub fn check(&self) -> Result<(), String> {
        if self.points.is_empty() {
            return Err("points: none; a curve has a point per λ it was measured at".into());
        }
        let mut allowed = CURVE_AUX.iter();
        for (i, &(aux, success)) in self.points.iter().enumerate() {
            if !allowed.any(|&a| a == aux) {
                return Err(format!(
                    "points[{i}]: λ {} is not the next of {CURVE_AUX:?}",
                    arlpcg_core::level::params::show_number(aux)
                ));
            }
            if !(0.0..=1.0).contains(&success) {
                return Err(format!(
                    "points[{i}]: success {} must be a number within [0, 1]",
                    arlpcg_core::level::params::show_number(success)
                ));
            }
        }
        Ok(())
    }
}

/// Why no level was found.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// No candidate came within the band of the target.
    #[error(
        "no level within ±{BAND} of success {target} in {MAX_CANDIDATES} candidates (closest: {closest:.2} at λ {aux:+.2}){}",
        set_aside(*.uncompleted, *.unbuilt, *.off_checks)
    )]
    Missed {
        /// The success asked for.
        target: f64,
        /// The closest success measured.
        closest: f64,
        /// The λ of that closest candidate.
        aux: f64,
        /// Candidates within the band that no run completed: never kept.
        uncompleted: u32,
        /// Draws that did not reach the goal within the piece budget.
        unbuilt: u32,
        /// Draws whose pieces missed a check, never played.
        off_checks: u32,
    },
    /// Stopped while the curve was measured.
    #[error("stopped while the λ→success curve was measured")]
    Stopped,
    /// Stopped while a level was searched.
    #[error("stopped while a level was searched")]
    SearchStopped,
    /// The Generator built no level.
    #[error(transparent)]
    Generation(#[from] GenerationError),
    /// A Solver policy of another game than the level's.
    #[error(transparent)]
    WrongGame(#[from] WrongGame),
}

/// What a missed search set aside, for its message: a target near 0 is missed because a level
/// that no run completes is never kept.
fn set_aside(uncompleted: u32, unbuilt: u32, off_checks: u32) -> String {
    let mut parts = Vec::new();
    if uncompleted > 0 {
        parts.push(format!(
            "{uncompleted} candidates within it were set aside because no run completed them (a \
             level is kept only if the Solver completes it; ask for a higher success)"
        ));
    }
    if unbuilt > 0 {
        parts.push(format!(
            "{unbuilt} draws did not reach the goal within the piece budget"
        ));
    }
    if off_checks > 0 {
        parts.push(format!(
            "{off_checks} draws missed a check on their pieces and were not played"
        ));
    }
    match parts.is_empty() {
        true => String::new(),
        false => format!("; {}", parts.join("; ")),
    }
}

/// Measures the curve: [`CURVE_LEVELS`] levels at each λ, made for `profile` (none: the
/// built-in game), [`CURVE_TRIALS`] runs each;
/// `stopped` is asked before each level (a Ctrl-C ends the measurement with
/// [`TargetError::Stopped`]).
pub fn measure(
    generator: &GeneratorPolicy,
    solver: &Solver,
    solver_sha256: &str,
    profile: Option<&Profile>,
    stopped: &dyn Fn() -> bool,
) -> Result<Curve, TargetError> {
    let mut points = Vec::with_capacity(CURVE_AUX.len());
    for aux in CURVE_AUX {
        let mut total = 0.0;
        let mut count = 0;
        for k in 0..CURVE_LEVELS as u64 {
            if stopped() {
                return Err(TargetError::Stopped);
            }
            let seed = arlpcg_core::seed_ranges::CURVE_SEED_BASE + k;
            let obstacles = arlpcg_core::game::facts::facts(generator.game).scene_obstacles;
            let request = LevelRequest::new(seed, Some(aux))
                .obstacles(obstacles)
                .profile(profile.cloned());
            match generation::generator_level(generator, &request) {
                Ok(level) => {
                    total += verify(&level, solver, CURVE_TRIALS, seed, &|| {})?.success_ratio;
                    count += 1;
                }
                Err(GenerationError::NoLevel { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
        if count > 0 {
            points.push((aux, (total / count as f64 * 1e4).round() / 1e4));
        }
    }
    Ok(Curve {
        generator_sha256: generator.reference.sha256.clone(),
        solver_sha256: solver_sha256.to_string(),
        profile_sha256: profile.map(Profile::sha256),
        points,
    })
}

impl Curve {
    /// The curve's span, in words, when `target` lies more than [`BAND`] beyond the success
    /// it measured at every λ (a search then meets it only on seeds far from the mean).
    pub fn beyond(&self, target: f64) -> Option<String> {
        let (least, most) = self
            .points
            .iter()
            .fold((None, None), |(least, most), &point| {
                let pick = |old: Option<(f64, f64)>, better: fn(f64, f64) -> bool| match old {
                    Some(old) if !better(point.1, old.1) => Some(old),
                    _ => Some(point),
                };
                (pick(least, |a, b| a < b), pick(most, |a, b| a > b))
            });
        let ((hard_aux, hard), (easy_aux, easy)) = (least?, most?);
        (target < hard - BAND || target > easy + BAND)
            .then(|| format!("{hard:.2} at λ {hard_aux:+.2} … {easy:.2} at λ {easy_aux:+.2}"))
    }

    /// The λ at which the curve passes `target` (linear between its points; the end λ when the
    /// target is beyond what the curve spans). Where the curve is not monotone, the easiest
    /// crossing wins.
    pub fn aux_for(&self, target: f64) -> f64 {
        let p = &self.points;
        match p.len() {
            0 => 0.0,
            1 => p[0].0,
            _ => {
                for pair in p.windows(2) {
                    let [(a0, s0), (a1, s1)] = [pair[0], pair[1]];
                    let (lo, hi) = (s0.min(s1), s0.max(s1));
                    if (lo..=hi).contains(&target) && hi > lo {
                        return a0 + (target - s0) / (s1 - s0) * (a1 - a0);
                    }
                }
                // Beyond the curve: the nearer end.
                let first = p[0];
                let last = p[p.len() - 1];
                if (target - first.1).abs() <= (target - last.1).abs() {
                    first.0
                } else {
                    last.0
                }
            }
        }
    }
}

/// A level of `asked.seed` whose success, verified with `trials` runs, is within [`BAND`] of
/// `target`: the search starts at the curve's λ and moves λ against each miss, each candidate
/// a new draw of the seed, or of another seed after [`OWN_SCENE_CANDIDATES`] (unless
/// `asked.goal` is given). When `asked` has a curve of λ (pacing), the search moves the whole
/// curve, its mean at the λ searched ([`AuxCurve::shifted`]). A candidate that no run completed
/// is never kept, nor one whose pieces miss a constraint of `checks` on the pieces alone (it is
/// not played: those constraints are met by search, the others checked afterwards). The level
/// is made for `asked.profile`. `stopped` is asked before each
/// candidate and between the runs it plays (a Ctrl-C ends the search with
/// [`TargetError::SearchStopped`]).
pub fn level_for(
    generator: &GeneratorPolicy,
    solver: &Solver,
    curve: &Curve,
    asked: &LevelRequest,
    (target, trials): (f64, u32),
    checks: &[Constraint],
    stopped: &(dyn Fn() -> bool + Sync),
) -> Result<Level, TargetError> {
    let (seed, goal) = (asked.seed, asked.goal);
    let shape = match &asked.aux {
        Some(AuxAsk::Curve(shape)) => Some(shape),
        _ => None,
    };
    let mut aux = curve.aux_for(target);
    let mut closest = (f64::INFINITY, f64::NAN, aux);
    let (mut uncompleted, mut unbuilt, mut off_checks) = (0, 0, 0);
    let on_pieces: Vec<&Constraint> = checks
        .iter()
        .filter(|c| c.attribute.reads() <= Reads::Pieces)
        .collect();
    let obstacles = arlpcg_core::game::facts::facts(generator.game).scene_obstacles;
    for draw in 0..MAX_CANDIDATES {
        if stopped() {
            return Err(TargetError::SearchStopped);
        }
        let quantized = (aux * 1000.0).round() / 1000.0;
        // Another seed supplies the whole scene (start, goal, obstacles), so it stays one the
        // Generator was trained on; the level records that seed.
        let candidate_seed = if goal.is_none() && draw >= OWN_SCENE_CANDIDATES {
            seed ^ (u64::from(draw) << 48)
        } else {
            seed
        };
        let request = LevelRequest::new(candidate_seed, Some(quantized))
            .goal(goal)
            .obstacles(obstacles)
            .draw(draw)
            .profile(asked.profile.clone());
        let request = match shape {
            Some(shape) => request.aux(AuxAsk::Curve(shape.shifted(quantized - shape.mean()))),
            None => request,
        };
        let mut level = match generation::generator_level(generator, &request) {
            Ok(level) => level,
            Err(GenerationError::NoLevel { .. }) => {
                unbuilt += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        let unplayed = Evidence::default();
        if on_pieces
            .iter()
            .any(|c| c.miss(&level, &unplayed, Strictness::Value).is_some())
        {
            off_checks += 1;
            continue;
        }
        let stats = screened_stats(&level, solver, (trials, seed), target, stopped)?
            .ok_or(TargetError::SearchStopped)?;
        let miss = stats.success_ratio - target;
        if miss.abs() < closest.0 {
            closest = (miss.abs(), stats.success_ratio, quantized);
        }
        if miss.abs() <= BAND + 1e-9 {
            if stats.successes > 0 {
                level.stats = Some(stats);
                return Ok(level);
            }
            uncompleted += 1;
        }
        // Too easy (success above the target): lower λ; too hard: raise it.
        aux = (aux - 1.2 * miss).clamp(-1.0, 1.0);
    }
    Err(TargetError::Missed {
        target,
        closest: closest.1,
        aux: closest.2,
        uncompleted,
        unbuilt,
        off_checks,
    })
}

/// The statistics of `trials` runs of a candidate, or of its first [`SCREEN_TRIALS`] alone when
/// their 95% interval lies outside [`BAND`] of `target` (the rest cannot bring it in, bar a
/// 1-in-40 chance); `None` when `stopped` ended the runs.
fn screened_stats(
    level: &Level,
    solver: &Solver,
    (trials, seed): (u32, u64),
    target: f64,
    stopped: &(dyn Fn() -> bool + Sync),
) -> Result<Option<arlpcg_core::level::stats::SolverStats>, WrongGame> {
    let watch = Watch {
        on_trial: &|_| {},
        stop: stopped,
    };
    let screen = SCREEN_TRIALS.min(trials);
    let Some(mut results) = trial_results(level, solver, 0..screen as u64, seed, &watch)? else {
        return Ok(None);
    };
    let successes = results
        .iter()
        .filter(|r| r.outcome == Outcome::Success)
        .count() as u32;
    let [low, high] = wilson_interval(successes, screen);
    if high >= target - BAND && low <= target + BAND {
        let rest = trial_results(level, solver, screen as u64..trials as u64, seed, &watch)?;
        let Some(rest) = rest else {
            return Ok(None);
        };
        results.extend(rest);
    }
    Ok(Some(stats_of(level, solver, seed, &results)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A missed target names the candidates set aside because no run completed them (why a
    /// target near 0 is missed), and says nothing of them when there were none.
    #[test]
    fn a_missed_target_names_the_candidates_no_run_completed() {
        let missed = |uncompleted, unbuilt, off_checks| {
            TargetError::Missed {
                target: 0.02,
                closest: 0.0,
                aux: -1.0,
                uncompleted,
                unbuilt,
                off_checks,
            }
            .to_string()
        };
        let plain = missed(0, 0, 0);
        assert!(plain.ends_with("(closest: 0.00 at λ -1.00)"), "{plain}");
        let checked = missed(0, 0, 3);
        assert!(
            checked.ends_with("; 3 draws missed a check on their pieces and were not played"),
            "{checked}"
        );
        let redrawn = missed(7, 2, 0);
        assert!(
            redrawn.contains("7 candidates within it were set aside because no run completed them")
                && redrawn.contains("ask for a higher success")
                && redrawn.contains("2 draws did not reach the goal"),
            "{redrawn}"
        );
    }

    #[test]
    fn a_damaged_curve_is_named_by_its_point() {
        curve(&[(1.0, 1.0), (0.0, 0.8), (-1.0, 0.3)])
            .check()
            .unwrap();
        let cases = [
            (vec![], "points: none"),
            (vec![(1.0, 1.0), (0.5, f64::NAN)], "points[1]: success NaN"),
            (vec![(1.0, 1.0), (0.5, 7.5)], "points[1]: success 7.5"),
            (
                vec![(0.0, 1.0), (0.5, 0.5)],
                "points[1]: λ 0.5 is not the next",
            ),
            (vec![(f64::NAN, 1.0)], "points[0]: λ NaN"),
        ];
        for (points, expected) in cases {
            let err = curve(&points).check().unwrap_err();
            assert!(err.starts_with(expected), "{err}");
        }
    }

    fn curve(points: &[(f64, f64)]) -> Curve {
        Curve {
            generator_sha256: String::new(),
            solver_sha256: String::new(),
            profile_sha256: None,
            points: points.to_vec(),
        }
    }

    #[test]
    fn aux_for_inverts_the_curve_and_clamps_beyond_it() {
        let c = curve(&[(1.0, 0.95), (0.0, 0.75), (-1.0, 0.35)]);
        assert!((c.aux_for(0.85) - 0.5).abs() < 1e-9);
        assert!((c.aux_for(0.55) + 0.5).abs() < 1e-9);
        assert_eq!(c.aux_for(0.99), 1.0);
        assert_eq!(c.aux_for(0.1), -1.0);
        // Not monotone: the easiest crossing.
        let zigzag = curve(&[(1.0, 0.9), (0.0, 0.5), (-1.0, 0.7)]);
        assert!((zigzag.aux_for(0.6) - 0.25).abs() < 1e-9);
    }

    /// A target more than the band beyond the curve's least and most success is said, with
    /// the span; within the band of either end it is not.
    #[test]
    fn a_target_beyond_the_curve_is_said_with_its_span() {
        let zigzag = curve(&[(1.0, 0.9), (0.0, 0.5), (-1.0, 0.7)]);
        assert_eq!(
            zigzag.beyond(0.3).as_deref(),
            Some("0.50 at λ +0.00 … 0.90 at λ +1.00")
        );
        assert!(zigzag.beyond(0.41).is_none());
        assert!(zigzag.beyond(0.99).is_none());
        assert!(curve(&[(1.0, 0.85), (-1.0, 0.6)]).beyond(0.96).is_some());
        assert!(curve(&[]).beyond(0.5).is_none());
    }
}
