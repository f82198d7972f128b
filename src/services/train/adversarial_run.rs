//! An adversarial run: the Solver's run, whose environments hold the Generator, and the
//! Generator's own phases, counters, metrics and checkpoint.

use std::io::Write;
use std::path::Path;

use super::arlpcg::{AdversarialEnvs, AdversarialRecord, Generator, MatchRules, MatchStats, Phase};
use super::cards::{card, read_checkpoint, record_commands, save_policy_files, solver_shape};
use super::config::{Schedule, TrainConfig};
use super::metrics::{
    check_metrics_header, generator_metrics_header, generator_row, open_append, scripted_columns,
    time_columns, truncate_metrics, update_columns,
};
use super::own_check;
use super::population::{PopulationRecord, Snapshot, population_from, population_record};
use super::solver_envs::{SolverEnvs, SolverMode, SourceRecord};
use super::solver_run::SolverRun;
use super::{
    CHECKPOINT, ConfigChange, GENERATOR_CHECKPOINT, GENERATOR_METRICS, Progress, Training,
};
use crate::services::fsio;
use crate::services::fsio::Overwrite;
use anyhow::{Context, Result};
use arlpcg_core::game::generator::{BuildLimits, GeneratorGame};
use arlpcg_core::rl::checkpoint;
use arlpcg_core::rl::checkpoint::{PolicyCard, Role, TrainMode, TrainingState};
use arlpcg_core::rl::ppo::Ppo;
use arlpcg_core::rl::timing::{Stretch, TimeSplit};
use arlpcg_core::seed_ranges::EVAL_SEED_BASE;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// An adversarial run: the Solver's run, whose environments hold the Generator, and the
/// Generator's own counters and metrics.
pub(super) struct AdversarialRun<G: GeneratorGame> {
    pub(super) solver: SolverRun<AdversarialEnvs<G>>,
    pub(super) generator_iteration: u64,
    pub(super) generator_metrics: std::fs::File,
}

impl<G: GeneratorGame> AdversarialRun<G> {
    /// The rules of the matches at `solver_steps`: what the schedule there says of the
    /// Generator's reach and knobs holds from the first match (a resumed run replays its
    /// matches under way by them); each iteration sets them again.
    pub(super) fn rules(mode: TrainMode, config: &TrainConfig, solver_steps: u64) -> MatchRules {
        let schedule = config.schedule_at(solver_steps);
        MatchRules {
            aux_values: match mode {
                TrainMode::FixedAux => vec![1.0],
                _ => config.generator.aux_values.clone(),
            },
            limits: BuildLimits {
                max_pieces: config.generator.max_pieces,
                curve_offset: config.generator.curve_offset,
                player: config.player(G::GAME),
                reach_runs: schedule.reach_runs,
            },
            knob_values: config
                .generator
                .knob_values
                .clone()
                .unwrap_or(super::config::DEFAULT_KNOB_VALUES.to_vec()),
            draw_knobs: schedule.draw_knobs,
            obstacles: config.generator.obstacles,
            rewards: config.generator.rewards.clone(),
            snapshot_share: config.generator.snapshot_share,
            scripted_opponent: None,
            paced_share: match mode {
                TrainMode::FixedAux => 0.0,
                _ => schedule.paced_share.unwrap_or(config.generator.paced_share),
            },
            trained_over: config
                .trained_over(G::GAME)
                .expect("the ability ranges were checked with the configuration"),
        }
    }

    pub(super) fn start(out: &Path, mode: TrainMode, config: TrainConfig) -> Result<Self> {
        let build = |config: &TrainConfig, _: Option<serde_json::Value>, _: u64| {
            let generator = Generator::fresh(config, G::GAME)?;
            let rng = ChaCha8Rng::seed_from_u64(config.seed.wrapping_add(1));
            let envs = AdversarialEnvs::new(
                config.solver.num_envs - config.rule_level_envs(),
                generator,
                rng,
                Self::rules(mode, config, 0),
                AdversarialRecord::default(),
                Vec::new(),
                solver_shape(config, G::GAME).action_size(),
            )?;
            Ok(envs.with_rule_levels(rule_levels::<G>(config, SourceRecord::default())?))
        };
        let solver = SolverRun::start(out, mode, config, build)?;
        fsio::write_atomic(
            &out.join(GENERATOR_METRICS),
            format!("{}\n", generator_metrics_header::<G>()).as_bytes(),
            Overwrite::Allowed,
        )?;
        Ok(Self {
            solver,
            generator_iteration: 0,
            generator_metrics: open_append(&out.join(GENERATOR_METRICS))?,
        })
    }

    pub(super) fn resume(out: &Path, mode: TrainMode, change: ConfigChange) -> Result<Self> {
        let path = out.join(GENERATOR_CHECKPOINT);
        if !path.exists() && out.join(CHECKPOINT).exists() {
            // A Solver-only run: its checkpoint says which mode it was trained in.
            read_checkpoint(&out.join(CHECKPOINT), G::GAME, Role::Solver, mode)?;
        }
        let (loaded, generator_state) = read_checkpoint(&path, G::GAME, Role::Generator, mode)?;
        check_metrics_header(
            &out.join(GENERATOR_METRICS),
            &generator_metrics_header::<G>(),
            &path,
        )?;
        let generator_iteration = generator_state.iteration;
        let record: PopulationRecord = match &generator_state.source {
            serde_json::Value::Null => PopulationRecord::default(),
            source => serde_json::from_value(source.clone())
                .with_context(|| format!("{}: population", path.display()))?,
        };
        let build =
            move |config: &TrainConfig, source: Option<serde_json::Value>, solver_steps: u64| {
                if let Some(trained) = loaded.card.curve_offset
                    && trained != config.generator.curve_offset
                {
                    anyhow::bail!(
                        "{}: this Generator was trained with generator.curve_offset {trained}, the \
                     configuration says {}; it maps its actions to curves by that offset, so it \
                     cannot change",
                        path.display(),
                        config.generator.curve_offset
                    );
                }
                let mut matches: AdversarialRecord =
                    serde_json::from_value(source.unwrap_or_default()).context("match source")?;
                // Episodes under way on rule levels go on only beside the matches under way.
                let mut rule_record = matches.rule_levels.take().unwrap_or_default();
                if matches.under_way.is_none() {
                    rule_record.under_way.clear();
                }
                let mut population =
                    population_from(&record, &loaded.tensors, &solver_shape(config, G::GAME))
                        .map_err(|e| anyhow::anyhow!("{}: population: {e}", path.display()))?;
                // A configuration that keeps fewer snapshots drops the oldest.
                let surplus = population.len().saturating_sub(config.generator.population);
                population.drain(..surplus);
                let vars = loaded.policy.named_vars();
                let mut ppo = Ppo::new(config.generator.ppo.clone(), loaded.policy)?;
                ppo.adam
                    .restore(&vars, &loaded.tensors, generator_state.adam_step)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
                let generator = Generator {
                    ppo,
                    norm: loaded.card.normalizer.clone(),
                };
                // The matches under way are replayed (none if the rules changed: fresh ones start).
                let envs = AdversarialEnvs::new(
                    config.solver.num_envs - config.rule_level_envs(),
                    generator,
                    generator_state.rng,
                    Self::rules(mode, config, solver_steps),
                    matches,
                    population,
                    solver_shape(config, G::GAME).action_size(),
                )?;
                Ok(envs.with_rule_levels(rule_levels::<G>(config, rule_record)?))
            };
        let solver = SolverRun::resume(out, mode, change, build)?;
        truncate_metrics(
            &out.join(GENERATOR_METRICS),
            &generator_metrics_header::<G>(),
            generator_iteration,
        )?;
        Ok(Self {
            solver,
            generator_iteration,
            generator_metrics: open_append(&out.join(GENERATOR_METRICS))?,
        })
    }

    pub(super) fn envs(&mut self) -> &mut AdversarialEnvs<G> {
        &mut self.solver.trainer.env
    }

    pub(super) fn generator_card(&self, wall_time_s: f64) -> PolicyCard {
        let envs = &self.solver.trainer.env;
        let mut card = card(
            G::GAME,
            Role::Generator,
            self.solver.mode,
            &self.solver.config,
            &envs.generator.norm,
            envs.state.generator_steps,
            wall_time_s,
        );
        card.training.population = envs.population.iter().map(|s| s.solver_steps).collect();
        // The reach it cuts its jumps to from here on (the finish's, once the finish begins).
        let solver_steps = self.solver.trainer.global_step;
        card.reach_runs = self.solver.config.schedule_at(solver_steps).reach_runs;
        record_commands(&mut card, &self.solver.commands, &self.solver.commit);
        self.solver.record_time(&mut card);
        card.results = self.solver.results.clone();
        card
    }

    /// Takes a snapshot of the Solver for the population when the last is
    /// `population_every_steps` old (or there is none).
    fn snapshot_if_due(&mut self) -> Result<()> {
        let generator = &self.solver.config.generator;
        let (keep, every) = (generator.population, generator.population_every_steps);
        let trainer = &mut self.solver.trainer;
        let now = trainer.global_step;
        let due = trainer
            .env
            .population
            .last()
            .is_none_or(|last| now.saturating_sub(last.solver_steps) >= every);
        if keep > 0 && due {
            let snapshot = Snapshot::of(&trainer.ppo.policy, &trainer.norm, now)?;
            trainer.env.add_snapshot(snapshot, keep);
        }
        Ok(())
    }

    /// Plays until a batch of Generator decisions is complete, and learns from it (with the
    /// schedule's entropy bonus, if it sets one); returns its progress line and the statistics
    /// of the matches that ended meanwhile.
    pub(super) fn generator_iteration(
        &mut self,
        lr_scale: f64,
        schedule: Schedule,
        wall: &dyn Fn() -> f64,
    ) -> Result<(String, MatchStats)> {
        let config = self.solver.config.generator.ppo.clone();
        let learning_rate = match schedule.generator_learning_rate {
            Some(rate) => rate,
            None if config.anneal_lr => config.learning_rate * lr_scale,
            None => config.learning_rate,
        };
        let t0 = wall();
        let mut time = TimeSplit::default();
        self.envs().take_stats();
        while self.envs().completed_decisions() < config.batch_size() {
            time.add(&self.solver.trainer.play_tick(wall)?);
        }
        let before_batch = wall();
        let batch = self.envs().take_generator_batch();
        let stats = self.envs().take_stats();
        let t1 = wall();
        time.copies_s += t1 - before_batch;
        let envs = self.envs();
        envs.generator.ppo.config.ent_coef = schedule.generator_entropy.unwrap_or(config.ent_coef);
        let update = envs
            .generator
            .ppo
            .update(&batch, learning_rate, &mut envs.rng)?;
        let t2 = wall();
        time.update_s = t2 - t1;
        time.update_flops = envs.generator.ppo.update_flops(&update);
        let decisions = batch.log_probs.len() as u64;
        envs.state.generator_steps += decisions;
        envs.state.phase_steps += decisions;
        self.generator_iteration += 1;
        let row = generator_row(&stats);
        time.copies_s += wall() - t2;
        let iteration_s = wall() - t0;
        self.solver.time.add(&time);
        writeln!(
            self.generator_metrics,
            "{},{},{},{:.2},{:.6},{:.6},{:.3e},{row},{},{},{},{iteration_s:.6},{:.3}",
            self.generator_iteration,
            self.solver.trainer.global_step,
            self.solver.trainer.env.state.generator_steps,
            wall(),
            t1 - t0,
            t2 - t1,
            learning_rate,
            update_columns(&update),
            scripted_columns(&stats),
            time_columns(&time),
            time.update_mfu(self.solver.matmul_peak),
        )?;
        // A side no match was judged on (the scripted opponent's hard side when it plays
        // easy matches only) reads "—", not a success of 0.
        let ratio = |a: u32, b: u32| match b {
            0 => "—".to_string(),
            b => format!("{:.2}", f64::from(a) / f64::from(b)),
        };
        let mut message = format!(
            "generator: success easy {} / hard {}, invalid {}",
            ratio(stats.successes[0], stats.judged[0]),
            ratio(stats.successes[1], stats.judged[1]),
            ratio(stats.invalid, stats.episodes)
        );
        if stats.scripted_judged != [0, 0] {
            message += &format!(
                ", scripted opponent easy {} / hard {}",
                ratio(stats.scripted_successes[0], stats.scripted_judged[0]),
                ratio(stats.scripted_successes[1], stats.scripted_judged[1])
            );
        }
        Ok((message, stats))
    }

    /// One iteration of the agent whose phase it is: the progress message, and whether the
    /// iteration played a finish check (a line a log without a progress bar keeps).
    fn phase_iteration(&mut self, wall: &dyn Fn() -> f64) -> Result<(String, bool)> {
        let config = &self.solver.config;
        let steps = self.solver.trainer.global_step;
        // The stage in force where this iteration starts (a stage begins at a phase's end).
        let schedule = config.schedule_at(steps);
        let lr_scale = config.lr_scale(steps);
        let warmup_steps = config.generator.solver_warmup_steps;
        let in_finish = config.in_finish(steps);
        let finish = config.generator.finish;
        // Before the finish, the hard side goes unpaid while the Solver is below the floor.
        let floor = config.generator.hard_success_floor.filter(|_| !in_finish);
        let unpaid = floor.is_some() && self.envs().state.hard_side_unpaid;
        self.envs().rules.rewards.hard_side_unpaid = unpaid;
        self.envs().rules.snapshot_share = schedule.snapshot_share;
        self.envs().rules.scripted_opponent = schedule.scripted_opponent;
        self.envs().rules.limits.reach_runs = schedule.reach_runs;
        self.envs().rules.draw_knobs = schedule.draw_knobs;
        if let Some(share) = schedule.paced_share {
            self.envs().rules.paced_share = share;
        }
        match self.envs().state.phase {
            Phase::Solver => {
                let rollout = self
                    .solver
                    .solver_iteration(lr_scale, schedule.solver_learning_rate, wall)?;
                let phase_began = steps.saturating_sub(self.envs().state.phase_steps);
                let catching_up = self.solver.config.in_finish(phase_began);
                // A Solver phase under way when the finish begins ends with the finish's first
                // iteration, so that the finish opens with the Generator's phase.
                let opens_finish = in_finish && !catching_up;
                let envs = self.envs();
                envs.state.phase_steps += rollout.steps;
                let ends = opens_finish || envs.state.phase_steps >= schedule.solver_phase_steps;
                if let Some(target) = finish.until_hard_success
                    && catching_up
                {
                    let now = self.solver.trainer.global_step;
                    let envs = self.envs();
                    let stats = envs.take_stats();
                    if envs
                        .count_hard_block(&stats, finish.hard_match_block)
                        .is_some_and(|s| s >= target)
                    {
                        envs.state.finish_ended_at = Some(now);
                    }
                }
                let warm = self.solver.trainer.global_step >= warmup_steps;
                if warm && ends {
                    self.snapshot_if_due()?;
                    self.envs().set_phase(Phase::Generator);
                }
                let message = format!(
                    "solver: return {:.2}, success {:.2}, {}",
                    rollout.mean_return,
                    rollout.success_ratio,
                    self.solver.time.largest_two()
                );
                Ok((message, false))
            }
            Phase::Generator => {
                let before = self.envs().state.generator_steps;
                let (mut message, stats) = self.generator_iteration(lr_scale, schedule, wall)?;
                let after = self.envs().state.generator_steps;
                // In the finish, the phase may end once the pair passes its own check...
                let checked = finish
                    .own_check_every
                    .is_some_and(|every| in_finish && after / every != before / every);
                let mut passes = false;
                if checked && let Some(c) = self.finish_check(wall)? {
                    passes = c.meets_with_margin(own_check::FINISH_HARD_MARGIN);
                    message += &format!(", check {:.2} / {:.2}", c.easy, c.hard);
                    if !passes {
                        self.keep_if_best_check(&c)?;
                    }
                }
                let envs = self.envs();
                if floor.is_some() {
                    envs.add_to_hard_block(&stats);
                }
                if unpaid {
                    message += ", hard side unpaid";
                }
                // ...or once the Solver fails enough.
                let hard_enough = match finish.generator_until_hard_success {
                    Some(target) if in_finish => envs
                        .count_hard_block(&stats, finish.hard_match_block)
                        .is_some_and(|s| s <= target),
                    _ => false,
                };
                let capped = envs.state.phase_steps >= schedule.generator_phase_steps;
                if passes || hard_enough || capped {
                    // A finish whose checks never passed ends with its best-checked Generator.
                    if in_finish && !passes && !hard_enough && envs.state.best_check.is_some() {
                        self.restore_best_check()?;
                        message += ", back to the best-checked Generator";
                    }
                    // The phase's hard success says whether the next one pays the hard side.
                    if let Some(floor) = floor
                        && let Some(success) = self.envs().hard_block_success()
                    {
                        self.envs().state.hard_side_unpaid = success < floor;
                    }
                    self.envs().set_phase(Phase::Solver);
                }
                Ok((
                    format!("{message}, {}", self.solver.time.largest_two()),
                    checked,
                ))
            }
        }
    }
}

impl<G: GeneratorGame> Training for AdversarialRun<G> {
    fn solver_steps(&self) -> u64 {
        self.solver.trainer.global_step
    }

    fn budget(&self) -> u64 {
        let config = &self.solver.config;
        let budget = config.adversarial_budget();
        match self.solver.trainer.env.state.finish_ended_at {
            // A finish ended early by its catch-up's success, unless the budget has grown
            // past where it ended (a resume with more steps trains on).
            Some(at) if at > config.steps => at.min(budget),
            _ => budget,
        }
    }

    fn wall_before(&self) -> f64 {
        self.solver.wall_before
    }

    fn add_session(&mut self, command: String, commit: String) {
        self.solver.commands.push(command);
        self.solver.commit = commit;
    }

    fn set_matmul_peak(&mut self, flops: f64) {
        self.solver.matmul_peak = flops;
    }

    fn time_split(&self) -> (TimeSplit, f64) {
        (
            self.solver.time,
            self.solver.time.update_mfu(self.solver.matmul_peak),
        )
    }

    fn iterate(&mut self, wall: &dyn Fn() -> f64) -> Result<Progress> {
        let began = wall();
        let in_finish = self
            .solver
            .config
            .in_finish(self.solver.trainer.global_step);
        let stretch = match self.envs().state.phase {
            _ if in_finish => Stretch::Finish,
            Phase::Solver => Stretch::SolverPhases,
            Phase::Generator => Stretch::GeneratorPhases,
        };
        let phase = self.envs().state.phase;
        let (message, checked) = self.phase_iteration(wall)?;
        self.solver.time.stretches.add(stretch, wall() - began);
        Ok(Progress {
            message: match stretch {
                Stretch::Finish => format!("finish, {message}"),
                _ => message,
            },
            notable: checked || self.envs().state.phase != phase,
        })
    }

    fn checkpoint_minutes(&self) -> f64 {
        self.solver.config.checkpoint_minutes
    }

    fn save_checkpoint(&self, wall: f64) -> Result<()> {
        let envs = &self.solver.trainer.env;
        let (population, tensors) = population_record(&envs.population);
        let state = TrainingState {
            global_step: envs.state.generator_steps,
            iteration: self.generator_iteration,
            adam_step: envs.generator.ppo.adam.step,
            wall_time_s: wall,
            rng: envs.rng.clone(),
            source: serde_json::to_value(population)?,
            config: serde_json::to_value(&self.solver.config)?,
            episode_returns: Vec::new(),
            time_split: self.solver.time,
        };
        let card = self.generator_card(wall);
        let bytes = checkpoint::checkpoint_bytes(&envs.generator.ppo, &card, &state, tensors);
        let out = &self.solver.out;
        // Both or neither: a resume needs the two networks of one iteration.
        let mut batch = fsio::FileBatch::new();
        batch.stage(&out.join(GENERATOR_CHECKPOINT), &bytes, Overwrite::Allowed)?;
        let solver = self.solver.solver_checkpoint_bytes(wall)?;
        batch.stage(&out.join(CHECKPOINT), &solver, Overwrite::Allowed)?;
        batch.commit()
    }

    fn save_policies(&self, wall: f64) -> Result<()> {
        let out = &self.solver.out;
        save_policy_files(
            out,
            "generator",
            &self.solver.trainer.env.generator.ppo.policy,
            &self.generator_card(wall),
        )?;
        save_policy_files(
            out,
            "solver",
            &self.solver.trainer.ppo.policy,
            &self.solver.solver_card(wall),
        )
    }

    fn out(&self) -> &Path {
        &self.solver.out
    }

    fn check_own_control(
        &mut self,
        wall: &dyn Fn() -> f64,
        starting: &dyn Fn(),
    ) -> Result<Option<String>> {
        let began = wall();
        let profile = self.profile()?;
        let check = self.solver.config.generator.own_check;
        let out = self.solver.out.clone();
        if check.plays() {
            starting();
        }
        let Some(control) = own_check::own_control(
            &out,
            G::GAME,
            profile.as_ref(),
            (check, true),
            EVAL_SEED_BASE,
        )?
        else {
            return Ok(None);
        };
        self.solver.results = control.results();
        // The cards' wall time stays the training's; the check's own is a stretch of its own.
        self.solver
            .time
            .stretches
            .add(Stretch::OwnCheck, wall() - began);
        self.save_policies(began)?;
        Ok(Some(control.describe()))
    }
}

/// The Solver's environments on rule levels of an adversarial run, from `record` (none when
/// the configuration gives the rule levels no share).
fn rule_levels<G: GeneratorGame>(
    config: &TrainConfig,
    record: SourceRecord,
) -> Result<Option<SolverEnvs<G>>> {
    match config.rule_level_envs() {
        0 => Ok(None),
        count => super::solver_envs(config, SolverMode::RulePcg, count, record)
            .map(Some)
            .context("rule levels"),
    }
}
