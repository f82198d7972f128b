//! The adversarial loop (ARLPCG), written once for both games: many [`Match`]es, each a Generator
//! building a level while a Solver plays it, stepped together. Seen from the Solver's trainer
//! this is a [`VecEnv`]: the Generator lives inside it and places pieces (one batched forward
//! pass for every match that needs one) whenever Solvers come close to their newest piece.
//!
//! Training alternates phases (docs/spec.md §3): while the Solver learns, the Generator only runs
//! inference; while the Generator learns, the Solver only runs inference and the Generator's
//! decisions are recorded per match, to be learned from with PPO once enough have completed.
//! Each match draws its goal, start (and racing obstacles) and λ from its own seed (episode
//! counter from [`TRAINING_SEED_BASE`]), so runs are reproducible and resumable.
//!
//! With a population, each match also draws who plays it while the Generator learns: the
//! current Solver or one of its earlier [`Snapshot`]s, so that the Generator's failure reward
//! comes from several networks and no single one's blind spot pays. In a finish with a scripted
//! opponent, a match may draw the game's scripted player instead, which acts on the world it
//! sees. While the Solver learns it plays every match itself.
//!
//! Each match keeps the log of what it has been through (its seed, then every piece placed and
//! every Solver step, as action rows); a checkpoint stores the logs with the Generator's
//! pending decisions ([`MatchesUnderWay`]) and a resume replays them, so a resumed run goes on
//! with the very matches it stopped in.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::services::train::cards::generator_shape;
use crate::services::train::config::{ScriptedOpponent, TrainConfig};
use crate::services::train::population::Snapshot;
use crate::services::train::solver_envs::SolverEnvs;
use arlpcg_core::game::generator::{
    BuildLimits, GeneratorGame, GeneratorRewards, Match, MatchPacing, TrackBuild,
};
use arlpcg_core::game::{Scripted, SolverEnv, observe_solver};
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::{AbilityRanges, ability_columns};
use arlpcg_core::level::stats::{Outcome, Skill};
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};
use arlpcg_core::rl::ppo::Ppo;
use arlpcg_core::rl::timing::{Clock, InnerTime};
use arlpcg_core::rl::vec_env::{OtherPlayers, Seat, Transition, VecEnv};
use arlpcg_core::seed_ranges::TRAINING_SEED_BASE;

mod batch;
mod replay;
mod state;
pub use replay::{AdversarialRecord, MadeUnder, MatchEvent, MatchLog, MatchesUnderWay};
pub use state::{AdversarialState, MatchStats, Phase};

/// The scripted player of a match, with its skill.
type ScriptedPlayer<G> = (Skill, <G as arlpcg_core::game::GameSpec>::Scripted);

/// What the matches are made of.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchRules {
    /// λ is drawn uniformly from these for each match.
    pub aux_values: Vec<f32>,
    /// Each knob of a Generator with knobs (`rewards.knobs`) is drawn uniformly from these for
    /// each match...
    pub knob_values: Vec<f32>,
    /// ...while this holds; else every knob is 0 (`Finish::knobs_only` before the finish).
    pub draw_knobs: bool,
    /// The Generator's piece budget, curve offset and reach (the finish's, in the finish).
    pub limits: BuildLimits,
    /// Obstacles drawn into each racing match's scene.
    pub obstacles: u32,
    /// The Generator's reward terms.
    pub rewards: GeneratorRewards,
    /// The share of matches a snapshot plays (`None`: uniform over the current Solver and the
    /// snapshots).
    pub snapshot_share: Option<f64>,
    /// The scripted player's share of the matches while the Generator learns (in a finish).
    pub scripted_opponent: Option<ScriptedOpponent>,
    /// The share of matches whose λ changes along the track
    /// ([`GeneratorConfig::paced_share`](super::GeneratorConfig::paced_share)).
    pub paced_share: f64,
    /// Some: each match's player has its main abilities drawn within these ranges, and both
    /// agents observe them ([`TrainConfig::trained_over`](super::TrainConfig::trained_over)).
    pub trained_over: Option<AbilityRanges>,
}

/// The Generator with its optimizer and normalizer.
pub struct Generator {
    /// The Generator's learner.
    pub ppo: Ppo,
    /// Its observation normalizer.
    pub norm: RunningNorm,
}

impl Generator {
    /// A Generator that has learned nothing yet: `config`'s networks for `game`, its weights
    /// seeded by the run's seed + 1, its exploration at `initial_log_std`.
    pub fn fresh(config: &TrainConfig, game: Game) -> anyhow::Result<Self> {
        let shape = generator_shape(config, game);
        let policy = ActorCritic::new(shape.clone(), config.seed.wrapping_add(1))?;
        policy.set_log_std(config.generator.initial_log_std)?;
        Ok(Generator {
            ppo: Ppo::new(config.generator.ppo.clone(), policy)?,
            norm: RunningNorm::new(shape.observation),
        })
    }
}

/// One recorded Generator decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Decision {
    observation: Vec<f32>,
    action: Vec<f32>,
    log_prob: f32,
    value: f32,
    /// Reward from this decision until the next one (still growing while it is the newest).
    reward: f32,
    /// The match ended before the next decision.
    ended: bool,
}

/// Many matches of the Generator against the Solver, as the Solver's environments.
pub struct AdversarialEnvs<G: GeneratorGame> {
    matches: Vec<Match<G>>,
    /// Per match, what it has been through.
    logs: Vec<MatchLog>,
    /// The Generator, with its optimizer and normalizer.
    pub generator: Generator,
    /// Samples the Generator's actions and shuffles its minibatches.
    pub rng: ChaCha8Rng,
    /// How matches are set up.
    pub rules: MatchRules,
    /// Where the run stands: phase and counters.
    pub state: AdversarialState,
    /// Per match, the Generator decisions recorded while it learns (oldest first).
    recorded: Vec<Vec<Decision>>,
    generator_returns: Vec<f32>,
    /// Match statistics since they were last taken.
    pub stats: MatchStats,
    /// Earlier Solvers, oldest first.
    pub population: Vec<Snapshot>,
    /// Per match, the snapshot that plays it while the Generator learns (`None`: the current
    /// Solver).
    opponents: Vec<Option<usize>>,
    /// Per match, the scripted player (and its skill) that plays it while the Generator
    /// learns, if one does.
    scripted: Vec<Option<ScriptedPlayer<G>>>,
    /// The Solver's environments on rule levels, after the matches
    /// ([`GeneratorConfig::rule_level_share`](super::GeneratorConfig::rule_level_share)):
    /// they step while the Solver learns and wait while the Generator does.
    rule_levels: Option<SolverEnvs<G>>,
}

impl<G: GeneratorGame> AdversarialEnvs<G> {
    /// `num_matches` matches, continuing from `record`: its matches under way are replayed
    /// (Solver action rows of `solver_action_size`); without them, fresh matches start and
    /// each gets its first piece. `Err` says why a record's matches cannot be replayed.
    pub fn new(
        num_matches: usize,
        generator: Generator,
        rng: ChaCha8Rng,
        rules: MatchRules,
        record: AdversarialRecord,
        population: Vec<Snapshot>,
        solver_action_size: usize,
    ) -> anyhow::Result<Self> {
        let mut this = Self {
            matches: Vec::with_capacity(num_matches),
            logs: Vec::with_capacity(num_matches),
            generator,
            rng,
            rules,
            state: record.state,
            recorded: vec![Vec::new(); num_matches],
            generator_returns: vec![0.0; num_matches],
            stats: MatchStats::default(),
            population,
            opponents: Vec::with_capacity(num_matches),
            scripted: Vec::with_capacity(num_matches),
            rule_levels: None,
        };
        if let Some(under_way) = record.under_way {
            this.replay(num_matches, under_way, solver_action_size)
                .map_err(|problem| anyhow::anyhow!("matches under way: {problem}"))?;
            return Ok(this);
        }
        for _ in 0..num_matches {
            let (fresh, opponent, scripted) = this.next_match();
            this.logs
                .push(MatchLog::new(fresh.seed(), this.made_under()));
            this.matches.push(fresh);
            this.opponents.push(opponent);
            this.scripted.push(scripted);
        }
        this.first_pieces((0..num_matches).collect())?;
        Ok(this)
    }

    /// The same environments with `rule_levels` after the matches (none: matches only).
    pub fn with_rule_levels(mut self, rule_levels: Option<SolverEnvs<G>>) -> Self {
        self.rule_levels = rule_levels;
        self
    }

    /// Lets the Generator place the first piece of the fresh matches `indices`; a match whose
    /// first piece is invalid (a racing segment into an obstacle) is replaced by the next.
    fn first_pieces(&mut self, mut indices: Vec<usize>) -> candle_core::Result<()> {
        while !indices.is_empty() {
            let invalid = self.place_while_needed(indices)?;
            for &i in &invalid {
                self.restart(i, None);
            }
            indices = invalid;
        }
        Ok(())
    }

    /// Lets the Generator place pieces in the matches `indices` until none wants another (a
    /// racing road is built [`arlpcg_core::game::racing::generator::REQUEST_DISTANCE`] ahead of the
    /// car, which can take more than one segment at the start); returns the matches that ended
    /// because a placement was invalid.
    fn place_while_needed(&mut self, mut indices: Vec<usize>) -> candle_core::Result<Vec<usize>> {
        let mut ended = Vec::new();
        while !indices.is_empty() {
            let invalid = self.decide(&indices)?;
            indices.retain(|i| !invalid.contains(i) && self.matches[*i].needs_piece());
            ended.extend(invalid);
        }
        Ok(ended)
    }

    /// Whether the Generator is the one learning.
    pub fn learning(&self) -> bool {
        self.state.phase == Phase::Generator
    }

    /// Switches phase; recordings of the Generator start afresh when it starts learning.
    pub fn set_phase(&mut self, phase: Phase) {
        self.state.phase = phase;
        self.state.phase_steps = 0;
        self.state.hard_block = [0, 0];
        for recorded in &mut self.recorded {
            recorded.clear();
        }
    }

    /// The next match, and the snapshot or scripted player that plays it while the Generator
    /// learns.
    fn next_match(&mut self) -> (Match<G>, Option<usize>, Option<ScriptedPlayer<G>>) {
        let seed = TRAINING_SEED_BASE + self.state.episodes_started;
        self.state.episodes_started += 1;
        let (fresh, mut rng) = self.match_of(seed, self.made_under());
        let snapshots = self.population.len();
        let opponent = match (snapshots, self.rules.snapshot_share) {
            (0, _) => None,
            (n, None) => Some(rng.random_range(0..=n)).filter(|&k| k < n),
            (n, Some(share)) => rng.random_bool(share).then(|| rng.random_range(0..n)),
        };
        // Drawn only with a scripted opponent, so that runs without one keep their bytes.
        let scripted = match self.rules.scripted_opponent {
            Some(o)
                if opponent.is_none()
                    && (!o.easy_only || fresh.aux[0] > 0.0)
                    && rng.random_bool(o.share) =>
            {
                Some((o.skill, G::scripted(seed, o.skill)))
            }
            _ => None,
        };
        (fresh, opponent, scripted)
    }

    /// The rules a match made now follows that change with the schedule.
    fn made_under(&self) -> MadeUnder {
        MadeUnder {
            reach_runs: self.rules.limits.reach_runs,
            draw_knobs: self.rules.draw_knobs,
            paced_share: Some(self.rules.paced_share),
        }
    }

    /// The match of `seed` made `under` those rules, before its first piece (its build and λ
    /// drawn from the seed), and the seed's generator, to draw on from.
    fn match_of(&self, seed: u64, under: MadeUnder) -> (Match<G>, ChaCha8Rng) {
        let mut limits = self.rules.limits;
        limits.reach_runs = under.reach_runs;
        limits.player = limits
            .player
            .drawn(G::GAME, self.rules.trained_over.as_ref(), seed);
        let (build, mut rng) = G::new_build(seed, None, limits, self.rules.obstacles);
        let values = &self.rules.aux_values;
        let aux = values[rng.random_range(0..values.len())];
        // Drawn only for a Generator with knobs, so that runs without them keep their bytes.
        let knobs = (0..self.rules.rewards.knobs.len())
            .map(|_| match under.draw_knobs {
                true => self.rules.knob_values[rng.random_range(0..self.rules.knob_values.len())],
                false => 0.0,
            })
            .collect();
        let fresh = Match::new(build, vec![aux], seed).with_knobs(knobs);
        // Drawn only when pacing is on, so that runs without it keep their bytes.
        let paced_share = under.paced_share.unwrap_or(self.rules.paced_share);
        if paced_share > 0.0 && rng.random_bool(paced_share) {
            let pacing = MatchPacing {
                before: aux,
                after: values[rng.random_range(0..values.len())],
                switch: rng.random_range(0.25..=0.75),
            };
            return (fresh.paced(pacing), rng);
        }
        (fresh, rng)
    }

    /// Adds a snapshot of the Solver, the oldest leaving beyond `keep`; the matches it played
    /// go to the current Solver.
    pub fn add_snapshot(&mut self, snapshot: Snapshot, keep: usize) {
        self.population.push(snapshot);
        while self.population.len() > keep {
            self.population.remove(0);
            for opponent in &mut self.opponents {
                *opponent = opponent.and_then(|k| k.checked_sub(1));
            }
        }
    }

    /// Lets the Generator place a piece in each of the matches `indices`; returns the matches
    /// that ended because the placement was invalid.
    fn decide(&mut self, indices: &[usize]) -> candle_core::Result<Vec<usize>> {
        if indices.is_empty() {
            return Ok(Vec::new());
        }
        let d = self.generator.norm.mean.len();
        let mut observations = vec![0.0; indices.len() * d];
        for (&i, row) in indices.iter().zip(observations.chunks_mut(d)) {
            self.matches[i].observe_generator(row);
        }
        let learning = self.learning();
        if learning {
            self.generator.norm.update(&observations);
        }
        self.generator.norm.normalize(&mut observations);
        let acted = self
            .generator
            .ppo
            .policy
            .act(&observations, ActMode::Sample, &mut self.rng)?;
        let width = acted.actions.len() / indices.len();
        let mut ended = Vec::new();
        for (k, &i) in indices.iter().enumerate() {
            let action = &acted.actions[k * width..(k + 1) * width];
            let game = &mut self.matches[i];
            let invalid = game.place(action).is_invalid();
            self.logs[i].events.push(MatchEvent::Place(action.to_vec()));
            let mut reward = self.rules.rewards.per_piece(game.placed_aux());
            if invalid {
                reward += self.rules.rewards.invalid;
                ended.push(i);
            } else {
                reward += game.placed_style_reward(&self.rules.rewards);
            }
            self.generator_returns[i] += reward;
            if learning {
                self.recorded[i].push(Decision {
                    observation: observations[k * d..(k + 1) * d].to_vec(),
                    action: action.to_vec(),
                    log_prob: acted.log_probs[k],
                    value: acted.values[k],
                    reward,
                    ended: invalid,
                });
            }
        }
        Ok(ended)
    }

    /// Ends match `i` (recording its statistics) and starts the next one in its place.
    fn restart(&mut self, i: usize, solver_outcome: Option<Outcome>) {
        let game = &self.matches[i];
        let aux = game.aux[0];
        let by_scripted = self.learning() && self.scripted[i].is_some();
        let stats = &mut self.stats;
        stats.episodes += 1;
        stats.generator_return_sum += self.generator_returns[i] as f64;
        self.generator_returns[i] = 0.0;
        match solver_outcome {
            None => stats.invalid += 1,
            Some(outcome) if by_scripted && aux != 0.0 && game.pacing().is_none() => {
                let side = usize::from(aux < 0.0);
                stats.scripted_judged[side] += 1;
                stats.scripted_successes[side] += u32::from(outcome == Outcome::Success);
            }
            Some(outcome) if aux != 0.0 && game.pacing().is_none() => {
                let side = usize::from(aux < 0.0);
                stats.judged[side] += 1;
                stats.successes[side] += u32::from(outcome == Outcome::Success);
                for features in game.build().piece_features() {
                    stats.pieces[side] += 1;
                    stats.feature_sums[side][0] += features[0];
                    stats.feature_sums[side][1] += features[1];
                }
                stats.air_steps[side] += u64::from(G::air_steps(game.env()));
            }
            Some(_) => {}
        }
        if let Some(last) = self.recorded[i].last_mut() {
            last.ended = true;
        }
        let (fresh, opponent, scripted) = self.next_match();
        self.logs[i] = MatchLog::new(fresh.seed(), self.made_under());
        self.matches[i] = fresh;
        self.opponents[i] = opponent;
        self.scripted[i] = scripted;
    }
}

impl<G: GeneratorGame> VecEnv for AdversarialEnvs<G> {
    fn num_envs(&self) -> usize {
        self.matches.len() + self.rule_levels.as_ref().map_or(0, VecEnv::num_envs)
    }

    fn observation_size(&self) -> usize {
        G::Env::OBSERVATION_SIZE + ability_columns(self.rules.trained_over.is_some())
    }

    fn observe(&mut self, out: &mut [f32]) {
        let (matches, rule_levels) = out.split_at_mut(self.matches.len() * self.observation_size());
        self.matches
            .par_iter()
            .zip(matches.par_chunks_mut(self.observation_size()))
            .for_each(|(game, row)| {
                observe_solver::<G>(game.env(), game.build().player().abilities.as_ref(), row)
            });
        if let Some(envs) = &mut self.rule_levels {
            envs.observe(rule_levels);
        }
    }

    fn step(&mut self, actions: &[f32], out: &mut [Transition]) {
        self.step_timed(actions, out, &|| 0.0);
    }

    /// While the Generator learns, the snapshots and scripted players that play some matches.
    fn other_players(&mut self) -> Option<OtherPlayers<'_>> {
        let seats: Vec<Seat> = self
            .opponents
            .iter()
            .zip(&self.scripted)
            .map(|(opponent, scripted)| match (opponent, scripted) {
                (Some(k), _) => Seat::Other(*k),
                (None, Some(_)) => Seat::Scripted,
                (None, None) => Seat::Learner,
            })
            .chain(std::iter::repeat_n(
                Seat::Learner,
                self.rule_levels.as_ref().map_or(0, VecEnv::num_envs),
            ))
            .collect();
        if !self.learning() || seats.iter().all(|&s| s == Seat::Learner) {
            return None;
        }
        Some(OtherPlayers {
            seats,
            policies: self
                .population
                .iter()
                .map(|snapshot| (&snapshot.policy, &snapshot.norm))
                .collect(),
            rng: &mut self.rng,
        })
    }

    fn step_timed(&mut self, actions: &[f32], out: &mut [Transition], clock: Clock) -> InnerTime {
        let width = actions.len() / self.num_envs();
        let learning = self.learning();
        let (actions, rule_actions) = actions.split_at(self.matches.len() * width);
        let (out, rule_out) = out.split_at_mut(self.matches.len());
        // The rule levels wait while the Generator learns (their rows then go unread).
        if let Some(envs) = self.rule_levels.as_mut().filter(|_| !learning) {
            envs.step(rule_actions, rule_out);
        }
        let rewards = &self.rules.rewards;
        let steps: Vec<(arlpcg_core::game::Step, f32)> = self
            .matches
            .par_iter_mut()
            .zip(self.logs.par_iter_mut())
            .zip(self.scripted.par_iter_mut())
            .zip(actions.par_chunks(width))
            .map(|(((game, log), scripted), row)| {
                let action = match scripted.as_mut().filter(|_| learning) {
                    Some((_, player)) => {
                        log.events.push(MatchEvent::Scripted);
                        player.act(game.env())
                    }
                    None => {
                        log.events.push(MatchEvent::Step(row.to_vec()));
                        G::Env::action_from_policy_row(row)
                    }
                };
                game.step_solver(action, rewards)
            })
            .collect();
        let mut finished = Vec::new();
        let mut turns = Vec::new();
        for (i, (step, generator_reward)) in steps.into_iter().enumerate() {
            self.generator_returns[i] += generator_reward;
            if let Some(last) = self.recorded[i].last_mut().filter(|d| !d.ended) {
                last.reward += generator_reward;
            }
            out[i] = Transition {
                reward: step.reward,
                ended: step.outcome.is_some(),
                success: step.outcome.map(|o| o == Outcome::Success),
            };
            // A Solver run that failed with a retry left starts again: its match goes on.
            if self.matches[i].over() {
                finished.push((i, Some(self.matches[i].solver_outcome())));
            } else if step.outcome.is_none() && self.matches[i].needs_piece() {
                turns.push(i);
            }
        }
        // A failed placement ends the match: the Solver's run is cut, not failed.
        let generator_start = clock();
        let invalid = self
            .place_while_needed(turns)
            .expect("the Generator's forward pass runs on the CPU");
        for i in invalid {
            out[i] = Transition {
                reward: out[i].reward,
                ended: true,
                success: None,
            };
            finished.push((i, None));
        }
        let restarted: Vec<usize> = finished.iter().map(|&(i, _)| i).collect();
        for (i, outcome) in finished {
            self.restart(i, outcome);
        }
        self.first_pieces(restarted)
            .expect("the Generator's forward pass runs on the CPU");
        InnerTime {
            generator_s: clock() - generator_start,
        }
    }
}
