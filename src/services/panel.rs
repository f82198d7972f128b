//! A panel of judges: the players a level's difficulty is measured with, so that it belongs to
//! no single network. A judge is a trained Solver, named by the mode it was trained in
//! (`arlpcg`, `rule-pcg`, `fixed-track`, `fixed-aux`), or the game's scripted player at a skill
//! (`scripted-novice`, `scripted-median`, `scripted-expert`). Each judge's success on a level,
//! and the level's difficulty b from the Rasch fit over judges × levels ([`arlpcg_core::statistics::rating`]), go
//! into the level's statistics as [`PanelStats`].

use crate::services::verify::{Solver, SolverPolicy, Watch, WrongGame, verify_watched};
use arlpcg_core::game::Skill;
use arlpcg_core::level::Level;
use arlpcg_core::level::stats::{JudgeStats, PanelStats, Rating, SolverRef, SolverStats};
use arlpcg_core::rl::checkpoint::TrainMode;
use arlpcg_core::statistics::rating::{Outcomes, fit};

/// One judge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Judge {
    /// The shipped Solver trained in this mode.
    Solver(TrainMode),
    /// The game's scripted player.
    Scripted(Skill),
}

impl Judge {
    /// Every judge, in the order tables list them.
    pub const ALL: [Judge; 7] = [
        Judge::Solver(TrainMode::Arlpcg),
        Judge::Solver(TrainMode::RulePcg),
        Judge::Solver(TrainMode::FixedTrack),
        Judge::Solver(TrainMode::FixedAux),
        Judge::Scripted(Skill::Novice),
        Judge::Scripted(Skill::Median),
        Judge::Scripted(Skill::Expert),
    ];

    /// The judge's name in files and on the command line (`arlpcg`, `scripted-median`, ...).
    pub fn name(self) -> String {
        match self {
            Judge::Solver(mode) => mode.name().to_string(),
            Judge::Scripted(skill) => format!("scripted-{skill}"),
        }
    }

    /// Who plays for the judge: `policy` (its Solver's, where one was loaded), else the
    /// scripted player at its skill (the expert for a Solver judge without a policy, one that
    /// cannot play the profile).
    pub fn player(self, policy: Option<&SolverPolicy>) -> Solver<'_> {
        match (policy, self) {
            (Some(policy), _) => Solver::Policy(policy),
            (None, Judge::Scripted(skill)) => Solver::Scripted(skill),
            (None, Judge::Solver(_)) => Solver::Scripted(Skill::Expert),
        }
    }

    /// The judge called `name`, or an error listing the names.
    pub fn parse(name: &str) -> Result<Judge, String> {
        Judge::ALL
            .into_iter()
            .find(|j| j.name() == name.trim())
            .ok_or_else(|| {
                let names: Vec<String> = Judge::ALL.iter().map(|j| j.name()).collect();
                format!(
                    "`{name}` is not a judge; the judges are {}",
                    names.join(", ")
                )
            })
    }
}

/// The judges of a panel, ready to play.
pub struct JudgePanel {
    /// Each judge with its Solver policy (none for the scripted player), in order.
    pub judges: Vec<(Judge, Option<SolverPolicy>)>,
}

impl JudgePanel {
    /// How judge `k` plays.
    pub fn solver(&self, k: usize) -> Solver<'_> {
        match &self.judges[k] {
            (_, Some(policy)) => Solver::Policy(policy),
            (Judge::Scripted(skill), None) => Solver::Scripted(*skill),
            (Judge::Solver(_), None) => unreachable!("a Solver judge is loaded with its policy"),
        }
    }

    /// The judges' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.judges.iter().map(|(j, _)| j.name()).collect()
    }
}

/// Each judge's statistics on one level, as the level's panel records them (no rating yet).
pub fn panel_stats(
    panel: &JudgePanel,
    seed: u64,
    trials: u32,
    played: &[SolverStats],
) -> PanelStats {
    PanelStats {
        seed,
        trials,
        judges: panel
            .judges
            .iter()
            .zip(played)
            .map(|((judge, _), stats)| JudgeStats {
                judge: judge.name(),
                // The policy that played: under a profile, the ARLPCG judge's may be the
                // ability-aware one.
                policy: match &stats.solver {
                    SolverRef::Policy { policy } => Some(policy.clone()),
                    SolverRef::Scripted { .. } | SolverRef::Random => None,
                },
                successes: stats.successes,
                success_ratio: stats.success_ratio,
                ci95: stats.ci95,
            })
            .collect(),
        rating: None,
    }
}

/// Every judge of `panel` plays `level` `trials` times from `seed` (each judge's runs are
/// verification's), `on_judge` after each judge; not yet rated. `Ok(None)` when `watch.stop`
/// cut the play short.
pub fn play(
    panel: &JudgePanel,
    level: &Level,
    trials: u32,
    seed: u64,
    watch: &Watch,
    on_judge: &dyn Fn(usize, &SolverStats),
) -> Result<Option<PanelStats>, WrongGame> {
    let mut played = Vec::with_capacity(panel.judges.len());
    for k in 0..panel.judges.len() {
        let Some(stats) = verify_watched(level, &panel.solver(k), trials, seed, watch)? else {
            return Ok(None);
        };
        on_judge(k, &stats);
        played.push(stats);
    }
    Ok(Some(panel_stats(panel, seed, trials, &played)))
}

/// Plays every level of `levels` with every judge of `panel` (each from its verification's
/// seed), several levels at once, and rates them together into their statistics; returns the
/// judges' θ. A level that already has this panel's plays keeps them (it is only rated again).
/// Levels that `watch.stop` left unplayed are dropped from the end.
pub fn play_and_rate(
    panel: &JudgePanel,
    levels: &mut Vec<Level>,
    trials: u32,
    watch: &Watch,
) -> Vec<(String, f64)> {
    use rayon::prelude::*;
    let played: Vec<Option<PanelStats>> = levels
        .par_iter()
        .map(|level| {
            let stats = level.stats.as_ref();
            if let Some(played) = stats.and_then(|s| s.panel.clone()) {
                return Some(played);
            }
            let seed = stats.map_or(0, |s| s.seed);
            play(panel, level, trials, seed, watch, &|_, _| {})
                .expect("judges are loaded for the levels' game")
        })
        .collect();
    let done = played.iter().take_while(|p| p.is_some()).count();
    levels.truncate(done);
    let mut panels: Vec<PanelStats> = played.into_iter().flatten().take(done).collect();
    let abilities = rate(&mut panels.iter_mut().collect::<Vec<_>>());
    for (level, panel) in levels.iter_mut().zip(panels) {
        if let Some(stats) = level.stats.as_mut() {
            stats.panel = Some(panel);
        }
    }
    abilities
}

/// Rates every level of `panels` together: fits the Rasch model over their judges × levels (a
/// judge is matched by name; one a level was not played by says nothing about it) and records
/// each level's b with its interval. Returns each judge's ability θ, by name.
pub fn rate(panels: &mut [&mut PanelStats]) -> Vec<(String, f64)> {
    let mut names: Vec<String> = Vec::new();
    for panel in panels.iter() {
        for j in &panel.judges {
            if !names.contains(&j.judge) {
                names.push(j.judge.clone());
            }
        }
    }
    let mut outcomes = Outcomes::new(names.len(), panels.len());
    for (i, panel) in panels.iter().enumerate() {
        for j in &panel.judges {
            let k = names.iter().position(|n| *n == j.judge).expect("listed");
            outcomes.set(k, i, j.successes, panel.trials);
        }
    }
    let fitted = fit(&outcomes);
    for (i, panel) in panels.iter_mut().enumerate() {
        panel.rating = Some(Rating {
            b: round3(fitted.b[i]),
            ci95: fitted.b_ci95[i].map(round3),
            levels: outcomes.levels as u32,
        });
    }
    names.into_iter().zip(fitted.theta).collect()
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_judge_is_found_by_its_name() {
        for judge in Judge::ALL {
            assert_eq!(Judge::parse(&judge.name()), Ok(judge));
        }
        let err = Judge::parse("scripted").unwrap_err();
        assert!(
            err.contains("scripted-median") && err.contains("fixed-aux"),
            "{err}"
        );
    }

    #[test]
    fn levels_rated_together_order_by_their_judges_success() {
        let judges = |ratios: [u32; 2]| PanelStats {
            seed: 0,
            trials: 50,
            judges: ["arlpcg", "scripted-expert"]
                .iter()
                .zip(ratios)
                .map(|(name, successes)| JudgeStats {
                    judge: name.to_string(),
                    policy: None,
                    successes,
                    success_ratio: successes as f64 / 50.0,
                    ci95: [0.0, 1.0],
                })
                .collect(),
            rating: None,
        };
        let (mut easy, mut hard) = (judges([45, 50]), judges([10, 40]));
        let theta = rate(&mut [&mut easy, &mut hard]);
        let (easy, hard) = (easy.rating.unwrap(), hard.rating.unwrap());
        assert!(easy.b < hard.b, "{easy:?} {hard:?}");
        assert_eq!(easy.levels, 2);
        assert!(
            theta[1].1 > theta[0].1,
            "the expert is the abler judge: {theta:?}"
        );
    }
}
