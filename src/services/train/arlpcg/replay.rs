//! What a checkpoint keeps of the matches under way, and how a resume plays them again: each
//! match's [`MatchLog`] (its seed, then every piece placed and every Solver step as action
//! rows), who plays it, the Generator's return so far and its decisions not yet learned from.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{AdversarialEnvs, AdversarialState, Decision, MatchStats, ScriptedPlayer};
use crate::services::train::solver_envs::{SolverEnvs, SourceRecord};
use arlpcg_core::game::generator::{GeneratorGame, GeneratorRewards, Match};
use arlpcg_core::game::{Scripted, SolverEnv};
use arlpcg_core::level::stats::Skill;

/// What a match has been through since it began: enough to play it again to where it is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MatchLog {
    /// The seed the match was made from.
    pub seed: u64,
    /// The schedule's rules it was made under, which a replay follows whatever the rules at
    /// the resumed step (none: a checkpoint from before they were kept, replayed under those).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub made_under: Option<MadeUnder>,
    /// What happened, in order.
    pub events: Vec<MatchEvent>,
}

impl MatchLog {
    /// The log of a match of `seed` made `under` those rules, before anything happened.
    pub fn new(seed: u64, under: MadeUnder) -> Self {
        Self {
            seed,
            made_under: Some(under),
            events: Vec::new(),
        }
    }
}

/// The rules of a match that change with the schedule: a match made before the finish keeps
/// them into it, so a checkpoint taken there must replay it under them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MadeUnder {
    /// The runs the Generator's reach counts (`Finish::reach_runs`; none: all of them).
    pub reach_runs: Option<u64>,
    /// Whether the match's knobs were drawn (else all 0).
    pub draw_knobs: bool,
    /// The share of paced matches it was drawn under (none, in a checkpoint from before the
    /// field: the share in force when it is replayed).
    #[serde(default)]
    pub paced_share: Option<f64>,
}

/// One thing that happened in a match, as the action row that made it happen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MatchEvent {
    /// The Generator placed a piece.
    Place(Vec<f32>),
    /// The Solver (or the snapshot playing the match) took a step.
    Step(Vec<f32>),
    /// The scripted player took a step: it acts on the world it sees, so a replay asks it
    /// again.
    Scripted,
}

/// The matches under way as a checkpoint stores them: per match its log, who plays it, the
/// Generator's return so far and its decisions still to learn from; and the statistics not
/// yet taken.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MatchesUnderWay {
    logs: Vec<MatchLog>,
    opponents: Vec<Option<usize>>,
    /// Per match, the skill of the scripted player that plays it, if one does (empty: none
    /// does).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    scripted: Vec<Option<Skill>>,
    generator_returns: Vec<f32>,
    recorded: Vec<Vec<Decision>>,
    stats: MatchStats,
}

/// What a checkpoint stores of the matches: the source's progress and, since checkpoints
/// have held them, the matches under way (none: fresh matches start).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct AdversarialRecord {
    /// The source's progress.
    #[serde(flatten)]
    pub state: AdversarialState,
    /// The matches under way, if the checkpoint holds them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub under_way: Option<MatchesUnderWay>,
    /// The rule levels' source and episodes under way (none: the run has no rule levels).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rule_levels: Option<SourceRecord>,
}

impl<G: GeneratorGame> AdversarialEnvs<G> {
    /// The source's progress and the matches under way, as a checkpoint stores them.
    pub fn record(&self) -> AdversarialRecord {
        AdversarialRecord {
            state: self.state,
            under_way: Some(MatchesUnderWay {
                logs: self.logs.clone(),
                opponents: self.opponents.clone(),
                scripted: match self.scripted.iter().any(Option::is_some) {
                    true => self
                        .scripted
                        .iter()
                        .map(|p| p.as_ref().map(|p| p.0))
                        .collect(),
                    false => Vec::new(),
                },
                generator_returns: self.generator_returns.clone(),
                recorded: self.recorded.clone(),
                stats: self.stats.clone(),
            }),
            rule_levels: self.rule_levels.as_ref().map(SolverEnvs::record),
        }
    }

    /// Plays the matches of `under_way` again to where they were, checking what a tampered
    /// checkpoint could get wrong.
    pub(super) fn replay(
        &mut self,
        num_matches: usize,
        under_way: MatchesUnderWay,
        solver_action_size: usize,
    ) -> Result<(), String> {
        let n = num_matches;
        if [
            under_way.logs.len(),
            under_way.opponents.len(),
            under_way.generator_returns.len(),
            under_way.recorded.len(),
        ] != [n; 4]
        {
            return Err(format!("they are not {n}, one per match"));
        }
        let snapshots = self.population.len();
        if under_way
            .opponents
            .iter()
            .flatten()
            .any(|&k| k >= snapshots)
        {
            return Err(format!(
                "a match is played by a snapshot beyond the {snapshots} kept"
            ));
        }
        let scripted = match under_way.scripted.len() {
            0 => vec![None; n],
            len if len == n => under_way.scripted,
            _ => return Err(format!("they are not {n}, one per match")),
        };
        let shape = self.generator.ppo.policy.shape();
        let (d, width) = (shape.observation, shape.action_size());
        let decision_fits = |decision: &Decision| {
            decision.observation.len() == d
                && decision.action.len() == width
                && decision
                    .observation
                    .iter()
                    .chain(&decision.action)
                    .all(|v| v.is_finite())
        };
        if !under_way.recorded.iter().flatten().all(decision_fits) {
            return Err(format!(
                "a recorded Generator decision is not {d} observed and {width} acted finite numbers"
            ));
        }
        let rewards = &self.rules.rewards;
        let replayed: Vec<(Match<G>, Option<ScriptedPlayer<G>>)> = under_way
            .logs
            .par_iter()
            .zip(scripted)
            .map(|(log, skill)| {
                let player = skill.map(|skill| (skill, G::scripted(log.seed, skill)));
                self.replayed(log, player, width, solver_action_size, rewards)
            })
            .collect::<Result<_, String>>()?;
        (self.matches, self.scripted) = replayed.into_iter().unzip();
        self.logs = under_way.logs;
        self.opponents = under_way.opponents;
        self.generator_returns = under_way.generator_returns;
        self.recorded = under_way.recorded;
        self.stats = under_way.stats;
        Ok(())
    }

    /// The match of `log` played again, with the scripted `player` that plays it if one does:
    /// built from its seed, then every event of it.
    fn replayed(
        &self,
        log: &MatchLog,
        mut player: Option<ScriptedPlayer<G>>,
        generator_width: usize,
        solver_width: usize,
        rewards: &GeneratorRewards,
    ) -> Result<(Match<G>, Option<ScriptedPlayer<G>>), String> {
        let under = log.made_under.unwrap_or_else(|| self.made_under());
        let (mut game, _) = self.match_of(log.seed, under);
        let fits =
            |row: &[f32], width: usize| row.len() == width && row.iter().all(|v| v.is_finite());
        for event in &log.events {
            let action = match event {
                MatchEvent::Place(row) if fits(row, generator_width) => {
                    if game.place(row).is_invalid() {
                        return Err(format!("match {}: a placement is invalid", log.seed));
                    }
                    continue;
                }
                MatchEvent::Step(row) if fits(row, solver_width) && game.started() => {
                    G::Env::action_from_policy_row(row)
                }
                MatchEvent::Scripted if game.started() => match player.as_mut() {
                    Some((_, player)) => player.act(game.env()),
                    None => {
                        return Err(format!(
                            "match {}: a scripted step in a match no scripted player plays",
                            log.seed
                        ));
                    }
                },
                _ => {
                    return Err(format!(
                        "match {}: an action row of the wrong size, not finite, or a step before the first piece",
                        log.seed
                    ));
                }
            };
            game.step_solver(action, rewards);
            if game.over() {
                return Err(format!("match {}: it ends before its last step", log.seed));
            }
        }
        Ok((game, player))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::services::train::TrainConfig;
    use crate::services::train::adversarial_run::AdversarialRun;
    use crate::services::train::arlpcg::{Generator, MatchRules};
    use crate::services::train::cards::{generator_shape, solver_shape};
    use arlpcg_core::game::platform::PlatformGame;
    use arlpcg_core::level::Game;
    use arlpcg_core::rl::checkpoint::TrainMode;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// A match made before the finish and under way in a checkpoint taken in it replays as it
    /// was made: knobs 0 and the cut of before, not the finish's knobs (1) and reach.
    #[test]
    fn a_match_replays_under_the_rules_it_was_made_under() {
        let mut config = TrainConfig::for_game(Game::Platform);
        config.hidden = vec![16, 16];
        config.ability_ranges.clear();
        config.generator.knob_values = Some(vec![1.0]);
        config.generator.rewards.knobs = vec![1.0, 1.0];
        config.generator.finish.knobs_only = true;
        config.generator.finish.reach_runs = Some(1);
        let shape = generator_shape(&config, Game::Platform);
        let solver_actions = solver_shape(&config, Game::Platform).action_size();
        let envs = |rules: MatchRules, record: AdversarialRecord| {
            let generator = Generator::fresh(&config, Game::Platform).unwrap();
            let rng = ChaCha8Rng::seed_from_u64(1);
            AdversarialEnvs::<PlatformGame>::new(
                8,
                generator,
                rng,
                rules,
                record,
                Vec::new(),
                solver_actions,
            )
            .unwrap()
        };
        let rules_at =
            |step| AdversarialRun::<PlatformGame>::rules(TrainMode::Arlpcg, &config, step);
        let before = envs(rules_at(0), AdversarialRecord::default());
        let finish = rules_at(config.steps);
        assert!(finish.draw_knobs && finish.limits.reach_runs == Some(1));
        let replayed = envs(finish, before.record());
        // What the Generator sees of each match: its pieces so far, λ and the knobs.
        let made = |envs: &AdversarialEnvs<PlatformGame>| -> Vec<Vec<f32>> {
            envs.matches
                .iter()
                .map(|m| {
                    let mut seen = vec![0.0; shape.observation];
                    m.observe_generator(&mut seen);
                    seen
                })
                .collect()
        };
        assert!(before.matches.iter().all(|m| m.knobs == [0.0, 0.0]));
        assert_eq!(made(&replayed), made(&before));
    }
}
