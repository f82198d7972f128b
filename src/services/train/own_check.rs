//! The check a finished adversarial run makes of its own knob: its Generator's levels at
//! λ = +1 and at λ = -1, played by its own Solver. A knob that works leaves easy levels easy
//! (success at least [`EASY_BAR`]), makes hard ones hard (at most [`HARD_BAR`]) and builds no
//! level that none of the runs completes (at least [`COMPLETED_BAR`] of them completed at each
//! end); a run that misses any says so on its cards (`results`) and in `train`'s last line, so that a seed
//! whose Generator never learned to make hard levels does not pass for a pair. The finished
//! run's check also plays its Solver on as many rule levels, and says whether it plays beyond
//! its own Generator's levels (at least [`RULES_BAR`]): a Solver that learned only those
//! passes the knob's bars and still plays nothing else.

use std::collections::HashMap;
use std::path::Path;

use anyhow::Result;

use super::config::OwnCheck;
use crate::services::eval::generator_levels;
use crate::services::generation::{self, LevelRequest};
use crate::services::policies::{load_generator, load_solver};
use crate::services::verify::{self, Solver};
use arlpcg_core::game::facts::facts;
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::Profile;

/// Own success at λ = +1 at or above this: easy levels stay easy.
pub const EASY_BAR: f64 = 0.95;
/// Own success at λ = -1 at or below this: hard levels are hard.
pub const HARD_BAR: f64 = 0.70;
/// The share of levels that some run completes, at each end, at or above this: hard, not
/// impossible.
pub const COMPLETED_BAR: f64 = 0.95;
/// The margin under [`HARD_BAR`] at which a finish stops on its own check
/// (`generator.finish.own_check_every`, on twice the check's levels): with 0.1 a run stopped
/// at 0.6 showed 0.74 on the levels of its last check; with 0.15 both seeds tried passed
/// (docs/trials.md).
pub const FINISH_HARD_MARGIN: f64 = 0.15;
/// The finished run's Solver's success on rule levels at or above this: it plays beyond its
/// own Generator's levels. The recipe's Solvers that learned play them at 0.90-0.97; one that
/// learned only its Generator's levels (the 2026-12-04 floor trial's seed 4, docs/trials.md)
/// at 0.03.
pub const RULES_BAR: f64 = 0.80;

/// What the check measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwnControl {
    /// Mean success of the run's Solver on its Generator's λ = +1 levels...
    pub easy: f64,
    /// ...and on its λ = -1 levels.
    pub hard: f64,
    /// The smaller of the two ends' shares of levels that at least one run completed.
    pub completed: f64,
    /// The Solver's mean success on as many rule levels (none: not played; the finish's
    /// checks, whose Solver is frozen, leave them out).
    pub rules: Option<f64>,
    /// What was played.
    pub check: OwnCheck,
}

impl OwnControl {
    /// Whether the knob works by both bars.
    pub fn meets(&self) -> bool {
        self.meets_with_margin(0.0)
    }

    /// Whether it meets the bars with `margin` to spare at the hard end: a stop on a check
    /// of 20 levels needs one, since the first check that passes is often a lucky set.
    pub fn meets_with_margin(&self, margin: f64) -> bool {
        self.easy >= EASY_BAR && self.hard <= HARD_BAR - margin && self.completed >= COMPLETED_BAR
    }

    /// How far it is from missing a bar (with `margin` at the hard end): the least of the
    /// three distances, negative by the largest miss when it misses one. A finish keeps the
    /// Generator whose check left the most.
    pub fn slack(&self, margin: f64) -> f64 {
        (self.easy - EASY_BAR)
            .min(HARD_BAR - margin - self.hard)
            .min(self.completed - COMPLETED_BAR)
    }

    /// The figures as a card's `results`.
    pub fn results(&self) -> HashMap<String, f64> {
        let mut results = HashMap::from([
            ("own_success_at_+1".to_string(), round3(self.easy)),
            ("own_success_at_-1".to_string(), round3(self.hard)),
            ("own_completed_least".to_string(), round3(self.completed)),
        ]);
        if let Some(rules) = self.rules {
            results.insert("own_success_on_rule_levels".to_string(), round3(rules));
        }
        results
    }

    /// In words, with the verdict.
    pub fn describe(&self) -> String {
        let verdict = if self.meets() {
            "its knob works"
        } else {
            "its knob does NOT work"
        };
        let rules = match self.rules {
            Some(r) if r >= RULES_BAR => {
                format!("; on rule levels it succeeds {r:.3}: it plays beyond its own Generator's")
            }
            Some(r) => format!(
                "; on rule levels it succeeds only {r:.3} (bar ≥ {RULES_BAR}): it learned \
                 its own Generator's levels and little else"
            ),
            None => String::new(),
        };
        format!(
            "own check ({} levels × {} runs at each end): its Solver succeeds {:.3} at λ = +1 \
             and {:.3} at λ = -1, and completes at least {:.3} of the levels at each end: \
             {verdict} (bars: ≥ {EASY_BAR}, ≤ {HARD_BAR}, ≥ {COMPLETED_BAR}){rules}",
            self.check.levels, self.check.trials, self.easy, self.hard, self.completed
        )
    }
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// Plays the check on the policies of the run folder `out` (its `generator.safetensors` and
/// `solver.safetensors`), for `profile` (the run's own; none: ours), on levels of the seeds
/// from `seed_base` (a finished run's: `EVAL_SEED_BASE`), and with `rules` as many rule levels
/// of those seeds. None when `check` plays nothing. Seeded: the same policies give the same
/// figures on any number of threads.
pub fn own_control(
    out: &Path,
    game: Game,
    profile: Option<&Profile>,
    (check, rules): (OwnCheck, bool),
    seed_base: u64,
) -> Result<Option<OwnControl>> {
    if !check.plays() {
        return Ok(None);
    }
    let (generator, _) = load_generator(&out.join("generator.safetensors"), game)?;
    let (solver, _) = load_solver(&out.join("solver.safetensors"), game)?;
    let solver = Solver::Policy(&solver);
    // The mean success and the share of levels some run completed.
    let play = |aux: f64| -> Result<(f64, f64)> {
        let levels = generator_levels(&generator, aux, seed_base, check.levels, profile)?;
        let (mut total, mut completed) = (0.0, 0);
        for level in &levels {
            let seed = level.seed.unwrap_or(seed_base);
            let stats = verify::verify(level, &solver, check.trials, seed, &|| {})?;
            total += stats.success_ratio;
            completed += usize::from(stats.successes > 0);
        }
        // A seed the Generator could not build counts as neither easy nor hard.
        let built = levels.len().max(1) as f64;
        Ok((total / built, completed as f64 / built))
    };
    let (easy, easy_completed) = play(1.0)?;
    let (hard, hard_completed) = play(-1.0)?;
    let rules = match rules {
        true => Some(rule_success(&solver, game, profile, check, seed_base)?),
        false => None,
    };
    Ok(Some(OwnControl {
        easy,
        hard,
        completed: easy_completed.min(hard_completed),
        rules,
        check,
    }))
}

/// The mean success of `solver` on `check.levels` rule levels of the seeds from `seed_base`
/// for `profile`, `check.trials` runs each (a seed the rules cannot build is skipped).
fn rule_success(
    solver: &Solver,
    game: Game,
    profile: Option<&Profile>,
    check: OwnCheck,
    seed_base: u64,
) -> Result<f64> {
    let (mut total, mut played) = (0.0, 0);
    for seed in seed_base..seed_base + u64::from(check.levels) {
        let request = LevelRequest::new(seed, None)
            .obstacles(facts(game).scene_obstacles)
            .profile(profile.cloned());
        let Ok(level) = generation::rules_level(game, &request) else {
            continue;
        };
        total += verify::verify(&level, solver, check.trials, seed, &|| {})?.success_ratio;
        played += 1;
    }
    Ok(total / f64::from(played.max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn control(easy: f64, hard: f64, completed: f64) -> OwnControl {
        let check = OwnCheck {
            levels: 20,
            trials: 20,
        };
        OwnControl {
            easy,
            hard,
            completed,
            rules: None,
            check,
        }
    }

    #[test]
    fn a_knob_works_only_when_easy_is_easy_hard_is_hard_and_hard_is_not_impossible() {
        assert!(control(0.97, 0.55, 1.0).meets());
        assert!(!control(0.90, 0.55, 1.0).meets(), "easy levels too hard");
        assert!(!control(0.97, 0.82, 1.0).meets(), "hard levels too easy");
        assert!(control(0.97, 0.65, 1.0).meets());
        assert!(!control(0.97, 0.6, 1.0).meets_with_margin(FINISH_HARD_MARGIN));
        assert!(control(0.97, 0.5, 1.0).meets_with_margin(FINISH_HARD_MARGIN));
        // The slack: the least distance to a bar, by which the finish ranks its checks.
        let slack = |c: OwnControl| c.slack(FINISH_HARD_MARGIN);
        assert!(
            (slack(control(0.97, 0.5, 1.0)) - 0.02).abs() < 1e-9,
            "easy end closest"
        );
        assert!(
            (slack(control(0.99, 0.6, 1.0)) + 0.05).abs() < 1e-9,
            "hard end missed"
        );
        assert!(slack(control(0.99, 0.6, 1.0)) > slack(control(0.99, 0.7, 1.0)));
        assert!(
            !control(0.98, 0.30, 0.40).meets(),
            "hard by being impossible"
        );
        let said = control(0.98, 0.30, 0.40).describe();
        assert!(
            said.contains("0.300 at λ = -1") && said.contains("does NOT work"),
            "{said}"
        );
        assert_eq!(
            control(0.9876, 0.5, 1.0).results()["own_success_at_+1"],
            0.988
        );
    }

    #[test]
    fn the_finished_checks_rule_levels_say_whether_the_solver_plays_beyond_its_generator() {
        let narrow = OwnControl {
            rules: Some(0.025),
            ..control(0.97, 0.55, 1.0)
        };
        assert!(narrow.meets(), "the knob's verdict is the knob's alone");
        let said = narrow.describe();
        assert!(
            said.contains("its knob works") && said.contains("only 0.025 (bar ≥ 0.8)"),
            "{said}"
        );
        assert_eq!(narrow.results()["own_success_on_rule_levels"], 0.025);
        let broad = OwnControl {
            rules: Some(0.93),
            ..narrow
        };
        assert!(broad.describe().contains("succeeds 0.930: it plays beyond"));
        let unplayed = control(0.97, 0.55, 1.0);
        assert!(!unplayed.describe().contains("rule levels"));
        assert!(
            !unplayed
                .results()
                .contains_key("own_success_on_rule_levels")
        );
    }
}
