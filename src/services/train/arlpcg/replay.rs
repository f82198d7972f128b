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
    /// What happened, in order.
    pub events: Vec<MatchEvent>,
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
        let (mut game, _) = self.match_of(log.seed);
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
