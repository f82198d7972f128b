//! What the Solver measured on a level: trials, successes, the success ratio with its 95% Wilson
//! interval, progress, and where the runs failed.

use serde::{Deserialize, Serialize};

use super::PolicyRef;
use super::params::show_number;

/// Who played the trials.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum SolverRef {
    /// The game's scripted (non-learning) player, at a skill (files written before skills
    /// existed name none: the expert).
    Scripted {
        /// How well it plays.
        #[serde(default)]
        skill: Skill,
    },
    /// Uniformly random actions (a baseline).
    Random,
    /// A trained Solver policy.
    Policy {
        /// The Solver policy file.
        policy: PolicyRef,
    },
}

impl SolverRef {
    /// The player in words, for reports (`scripted player (expert)`, `random actions`, ...).
    pub fn describe(&self) -> String {
        match self {
            SolverRef::Scripted { skill } => format!("scripted player ({skill})"),
            SolverRef::Random => "random actions".to_string(),
            SolverRef::Policy { policy } => format!("policy {}", policy.path),
        }
    }
}

/// How one Solver run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// Reached the goal block.
    Success,
    /// Fell off the track (platform).
    Fell,
    /// Ran out of time.
    TimedOut,
    /// Left the road (racing).
    OffRoad,
    /// Turned over (racing).
    Flipped,
}

impl Outcome {
    /// How a run that ended this way is told: "reached the goal", "fell", ...
    pub fn describe(self) -> &'static str {
        match self {
            Outcome::Success => "reached the goal",
            Outcome::Fell => "fell",
            Outcome::TimedOut => "ran out of time",
            Outcome::OffRoad => "left the road",
            Outcome::Flipped => "turned over",
        }
    }

    /// The failure a game's ending key names ([`GameFacts::endings`]); none for another key.
    ///
    /// [`GameFacts::endings`]: crate::game::facts::GameFacts::endings
    pub fn of_ending(key: &str) -> Option<Outcome> {
        match key {
            "fell" => Some(Outcome::Fell),
            "timed_out" => Some(Outcome::TimedOut),
            "off_road" => Some(Outcome::OffRoad),
            "flipped" => Some(Outcome::Flipped),
            _ => None,
        }
    }

    /// The word a tally of runs that ended this way is headed by.
    pub fn tally_word(self) -> &'static str {
        match self {
            Outcome::Success => "success",
            Outcome::Fell => "fell",
            Outcome::TimedOut => "timeout",
            Outcome::OffRoad => "off road",
            Outcome::Flipped => "flipped",
        }
    }
}

/// One finished Solver run, as verification records it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialResult {
    /// How the run ended.
    pub outcome: Outcome,
    /// Fraction of the track covered, in [0, 1].
    pub progress: f64,
    /// The piece the run was heading for when it ended (index into the level's pieces).
    pub target_piece: usize,
    /// Decisions taken.
    pub steps: u32,
    /// Decisions with the car in the air (racing; `None` for games without air time).
    pub air_steps: Option<u32>,
}

/// Aggregate statistics of many Solver runs on one level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverStats {
    /// Who played.
    pub solver: SolverRef,
    /// Seed of the first trial; trial `i` uses `seed + i`.
    pub seed: u64,
    /// Runs played.
    pub trials: u32,
    /// Runs that reached the goal.
    pub successes: u32,
    /// Runs that fell off the track (platform).
    pub fell: u32,
    /// Runs that ran out of time.
    pub timed_out: u32,
    /// Runs that left the road (racing).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub off_road: u32,
    /// Runs that turned over (racing).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub flipped: u32,
    /// `successes / trials`.
    pub success_ratio: f64,
    /// 95% Wilson score interval of the success ratio.
    pub ci95: [f64; 2],
    /// Mean fraction of the track covered.
    pub mean_progress: f64,
    /// Mean decisions taken by the successful runs (0 when none succeeded).
    pub mean_success_steps: f64,
    /// `failures_by_piece[i]`: runs that failed on their way to piece `i`.
    pub failures_by_piece: Vec<u32>,
    /// Mean decisions per run with the car in the air (racing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_air_steps: Option<f64>,
    /// The seed of one successful run played alone (`verify --replay` re-runs it): proof that
    /// the level can be completed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub certificate: Option<u64>,
    /// Earlier draws of this seed that no run completed, replaced by this one.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub redraws: u32,
    /// The level played by a panel of judges, and its difficulty rating (`generate --panel`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub panel: Option<PanelStats>,
}

/// A level played by a panel of judges (src/services/panel.rs): each judge's success, and the level's
/// difficulty b fitted over judges × levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelStats {
    /// Seed of each judge's first trial; trial `i` uses `seed + i`.
    pub seed: u64,
    /// Runs per judge.
    pub trials: u32,
    /// Each judge's runs, in the panel's order.
    pub judges: Vec<JudgeStats>,
    /// The level's difficulty, when it has been fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rating: Option<Rating>,
}

/// One judge's runs on a level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JudgeStats {
    /// `arlpcg`, `rule-pcg`, `fixed-track`, `fixed-aux`, `scripted-novice`, `scripted-median`
    /// or `scripted-expert`.
    pub judge: String,
    /// The Solver policy this judge was (none for the scripted player).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub policy: Option<PolicyRef>,
    /// Runs that reached the goal.
    pub successes: u32,
    /// `successes / trials`.
    pub success_ratio: f64,
    /// 95% Wilson score interval of the success ratio.
    pub ci95: [f64; 2],
}

/// A level's difficulty on the Rasch scale (crates/core/src/statistics/rating.rs): P(judge completes it) =
/// σ(θ_judge − b), in logits; one more means half the odds for every judge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rating {
    /// The level's difficulty b, logits (higher: harder).
    pub b: f64,
    /// 95% interval of b.
    pub ci95: [f64; 2],
    /// Levels fitted together (the judges' abilities come from all of them).
    pub levels: u32,
}

fn is_zero(count: &u32) -> bool {
    *count == 0
}

impl SolverStats {
    /// How many runs ended as `ending` (`fell`, `timed_out`, `off_road`, `flipped`: the keys
    /// a game's facts list its endings by); none for a key that is no ending.
    pub fn ending_count(&self, ending: &str) -> Option<u32> {
        match ending {
            "fell" => Some(self.fell),
            "timed_out" => Some(self.timed_out),
            "off_road" => Some(self.off_road),
            "flipped" => Some(self.flipped),
            _ => None,
        }
    }

    /// Aggregates trial results over a level with `pieces` pieces.
    pub fn from_trials(
        solver: SolverRef,
        seed: u64,
        pieces: usize,
        trials: &[TrialResult],
    ) -> Self {
        let count = |o: Outcome| trials.iter().filter(|t| t.outcome == o).count() as u32;
        let n = trials.len() as u32;
        let successes = count(Outcome::Success);
        let mut failures_by_piece = vec![0; pieces];
        for t in trials.iter().filter(|t| t.outcome != Outcome::Success) {
            failures_by_piece[t.target_piece.min(pieces.saturating_sub(1))] += 1;
        }
        let mean = |values: &mut dyn Iterator<Item = f64>| {
            let (sum, k) = values.fold((0.0, 0u32), |(s, k), v| (s + v, k + 1));
            if k == 0 { 0.0 } else { round4(sum / k as f64) }
        };
        Self {
            solver,
            seed,
            trials: n,
            successes,
            fell: count(Outcome::Fell),
            timed_out: count(Outcome::TimedOut),
            off_road: count(Outcome::OffRoad),
            flipped: count(Outcome::Flipped),
            success_ratio: round4(ratio(successes, n)),
            ci95: wilson_interval(successes, n).map(round4),
            mean_progress: mean(&mut trials.iter().map(|t| t.progress)),
            mean_success_steps: mean(
                &mut trials
                    .iter()
                    .filter(|t| t.outcome == Outcome::Success)
                    .map(|t| t.steps as f64),
            ),
            failures_by_piece,
            mean_air_steps: trials
                .iter()
                .map(|t| t.air_steps.map(f64::from))
                .sum::<Option<f64>>()
                .filter(|_| !trials.is_empty())
                .map(|sum| round4(sum / n as f64)),
            certificate: None,
            redraws: 0,
            panel: None,
        }
    }

    /// Runs that did not succeed.
    pub fn failures(&self) -> u64 {
        [self.fell, self.timed_out, self.off_road, self.flipped]
            .iter()
            .map(|&c| c as u64)
            .sum()
    }

    /// Checks that the counts add up, the derived numbers match them, and the per-piece
    /// failures fit a level of `pieces` pieces.
    pub fn check(&self, pieces: usize) -> Result<(), String> {
        if self.trials == 0 {
            return Err("trials must be at least 1".into());
        }
        let ended = self.successes as u64 + self.failures();
        if ended != self.trials as u64 {
            return Err(format!(
                "successes + fell + timed_out + off_road + flipped = {ended}, but trials = {}",
                self.trials
            ));
        }
        let expected_ratio = round4(ratio(self.successes, self.trials));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-3; // false for NaN
        if !close(self.success_ratio, expected_ratio) {
            return Err(format!(
                "success_ratio {} does not match successes / trials = {expected_ratio}",
                show_number(self.success_ratio)
            ));
        }
        let expected_ci = wilson_interval(self.successes, self.trials).map(round4);
        if !(close(self.ci95[0], expected_ci[0]) && close(self.ci95[1], expected_ci[1])) {
            return Err(format!(
                "ci95 {:?} does not match the Wilson interval {expected_ci:?}",
                self.ci95
            ));
        }
        if !(0.0..=1.0).contains(&self.mean_progress) {
            return Err(format!(
                "mean_progress {} is out of range [0, 1]",
                show_number(self.mean_progress)
            ));
        }
        if !self.mean_success_steps.is_finite() || self.mean_success_steps < 0.0 {
            return Err(format!(
                "mean_success_steps {} must be a number >= 0",
                show_number(self.mean_success_steps)
            ));
        }
        if self.failures_by_piece.len() != pieces {
            return Err(format!(
                "failures_by_piece has {} entries but the level has {pieces} pieces",
                self.failures_by_piece.len()
            ));
        }
        let failures: u64 = self.failures_by_piece.iter().map(|&f| f as u64).sum();
        if failures != self.failures() {
            return Err(format!(
                "failures_by_piece adds up to {failures}, but the failed runs (fell + timed_out + off_road + flipped) are {}",
                self.failures()
            ));
        }
        if let Some(air) = self.mean_air_steps
            && !(air.is_finite() && air >= 0.0)
        {
            return Err(format!(
                "mean_air_steps {} must be a number >= 0",
                show_number(air)
            ));
        }
        Ok(())
    }
}

fn ratio(successes: u32, trials: u32) -> f64 {
    if trials == 0 {
        0.0
    } else {
        successes as f64 / trials as f64
    }
}

fn round4(x: f64) -> f64 {
    (x * 10_000.0).round() / 10_000.0
}

/// The 95% Wilson score interval for `successes` out of `trials` (z = 1.96).
pub fn wilson_interval(successes: u32, trials: u32) -> [f64; 2] {
    if trials == 0 {
        return [0.0, 1.0];
    }
    const Z: f64 = 1.959_963_984_540_054;
    let n = trials as f64;
    let p = successes as f64 / n;
    let z2 = Z * Z;
    let denominator = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denominator;
    let half = Z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denominator;
    let low = if successes == 0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let high = if successes == trials {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    [low, high]
}

/// How well a scripted player plays: a Solver-independent yardstick of difficulty, physically
/// grounded and without a network. Each game turns a skill into its own imperfections (take-off
/// timing and run-up speed on the platform game, grip misjudged and steering wobble in racing:
/// docs/platform-physics.md and docs/racing-physics.md); `Expert` is the scripted player that
/// verification used before skills existed.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Default,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Skill {
    /// The weakest scripted player.
    Novice,
    /// Between the novice and the expert.
    Median,
    /// The scripted player as it played before skills existed.
    #[default]
    Expert,
}

impl Skill {
    /// Every skill, weakest first.
    pub const ALL: [Skill; 3] = [Skill::Novice, Skill::Median, Skill::Expert];

    /// The skill's name on the command line and in files (`novice`, `median`, `expert`).
    pub fn name(self) -> &'static str {
        match self {
            Skill::Novice => "novice",
            Skill::Median => "median",
            Skill::Expert => "expert",
        }
    }
}

impl std::fmt::Display for Skill {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_interval_matches_published_values() {
        // 81 of 263 (Wilson 1927, as in Newcombe 1998, method 3): 0.2553 to 0.3662.
        let [lo, hi] = wilson_interval(81, 263);
        assert!(
            (lo - 0.2553).abs() < 1e-4 && (hi - 0.3662).abs() < 1e-4,
            "{lo} {hi}"
        );
        // All successes: the upper bound is 1, the lower bound below it.
        let [lo, hi] = wilson_interval(10, 10);
        assert!((lo - 0.7225).abs() < 1e-4 && hi == 1.0, "{lo} {hi}");
        assert_eq!(wilson_interval(0, 0), [0.0, 1.0]);
    }

    #[test]
    fn from_trials_counts_and_places_failures() {
        let t = |outcome, progress, target_piece| TrialResult {
            outcome,
            progress,
            target_piece,
            steps: 100,
            air_steps: None,
        };
        let trials = [
            t(Outcome::Success, 1.0, 2),
            t(Outcome::Fell, 0.5, 1),
            t(Outcome::Fell, 0.2, 0),
            t(Outcome::TimedOut, 0.5, 1),
        ];
        let stats = SolverStats::from_trials(
            SolverRef::Scripted {
                skill: Skill::Expert,
            },
            7,
            3,
            &trials,
        );
        assert_eq!(
            (stats.trials, stats.successes, stats.fell, stats.timed_out),
            (4, 1, 2, 1)
        );
        assert_eq!(stats.failures_by_piece, vec![1, 2, 0]);
        assert_eq!(stats.success_ratio, 0.25);
        assert_eq!(stats.mean_progress, 0.55);
        assert_eq!(stats.mean_success_steps, 100.0);
        stats.check(3).unwrap();
        assert!(
            stats
                .check(4)
                .unwrap_err()
                .contains("failures_by_piece has 3 entries")
        );
        let mut lying = stats.clone();
        lying.success_ratio = 0.9;
        assert!(lying.check(3).unwrap_err().contains("success_ratio 0.9"));
        for bad in [f64::NAN, f64::INFINITY] {
            let mut lying = stats.clone();
            lying.success_ratio = bad;
            assert!(
                lying.check(3).unwrap_err().contains("success_ratio"),
                "{bad}"
            );
            let mut lying = stats.clone();
            lying.ci95[1] = bad;
            assert!(lying.check(3).unwrap_err().contains("ci95"), "{bad}");
            let mut lying = stats.clone();
            lying.mean_progress = bad;
            assert!(
                lying.check(3).unwrap_err().contains("mean_progress"),
                "{bad}"
            );
        }
    }
}
