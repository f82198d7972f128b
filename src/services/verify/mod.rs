//! Verification: play a level many times with a Solver and aggregate the statistics. Runs are
//! seeded from `seed` and the trial index, so the same level, Solver, seed and trial count give
//! the same statistics whatever the number of threads.
//!
//! A trained policy plays trials in lockstep, up to [`LOCKSTEP`] at a time: all their worlds step
//! in parallel and one batched forward pass picks every action. It samples its actions (the
//! stochastic policy it was trained as), each trial from its own random stream, so a trial played
//! in the pool is the run [`record`] plays alone from the same seed.
//!
//! Here: who plays and how trials are played, recorded and certified. `policy.rs` holds a
//! trained Solver and how it fits a profile; `summary.rs` what many levels' statistics say.

use std::ops::Range;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use arlpcg_core::game::{GameSpec, Scripted, Skill, SolverEnv};
use arlpcg_core::level::stats::{SolverRef, SolverStats, TrialResult};
use arlpcg_core::level::{Game, Level, PolicyRef};
use arlpcg_core::rl::policy::ActMode;

/// Trials a policy plays at once.
pub const LOCKSTEP: usize = 64;

/// Trials a policy plays at once until the first one ends (the designer's first statistics).
pub const FIRST_POOL: usize = 4;

mod policy;
mod summary;
pub use policy::{ProfileFit, SolverPolicy, default_player};
pub use summary::{FailureConcentration, HalfwaySplit, Summary, pacing_chart, passed_by_piece};

/// Who plays the trials.
pub enum Solver<'a> {
    /// The scripted (non-learning) player of the level's game, at a skill.
    Scripted(Skill),
    /// Uniformly random actions (a baseline).
    Random,
    /// A trained Solver policy.
    Policy(&'a SolverPolicy),
}

impl Solver<'_> {
    /// How a level's statistics name this Solver.
    pub fn reference(&self) -> SolverRef {
        match self {
            Solver::Scripted(skill) => SolverRef::Scripted { skill: *skill },
            Solver::Random => SolverRef::Random,
            Solver::Policy(p) => SolverRef::Policy {
                policy: p.reference.clone(),
            },
        }
    }

    /// The policy file, for a trained Solver.
    pub fn policy_reference(&self) -> Option<PolicyRef> {
        match self {
            Solver::Policy(p) => Some(p.reference.clone()),
            Solver::Scripted(_) | Solver::Random => None,
        }
    }

    /// Checks that a policy plays the level's game.
    fn check_game(&self, level: Game) -> Result<(), WrongGame> {
        match self {
            Solver::Policy(p) if p.game != level => Err(WrongGame {
                policy: p.reference.path.clone(),
                plays: p.game,
                level,
            }),
            _ => Ok(()),
        }
    }
}

/// A Solver policy asked to play a level of another game.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the Solver policy {policy} plays the {plays} game, but this is a {level} level")]
pub struct WrongGame {
    /// The policy file.
    pub policy: String,
    /// The game it plays.
    pub plays: Game,
    /// The level's game.
    pub level: Game,
}

/// Plays `trials` runs of the level and returns their statistics. `on_trial` is called after
/// each finished trial (possibly from worker threads), for progress reporting.
pub fn verify(
    level: &Level,
    solver: &Solver,
    trials: u32,
    seed: u64,
    on_trial: &(dyn Fn() + Sync),
) -> Result<SolverStats, WrongGame> {
    let watch = Watch {
        on_trial: &|_| on_trial(),
        stop: &|| false,
    };
    let stats = verify_watched(level, solver, trials, seed, &watch)?;
    Ok(stats.expect("verification without a stop condition runs to the end"))
}

/// Who watches a verification: told of each finished trial, asked whether to stop.
pub struct Watch<'a> {
    /// Called with each finished trial, possibly from worker threads, in any order.
    pub on_trial: &'a (dyn Fn(&TrialResult) + Sync),
    /// Checked between ticks (policy) or trials (scripted, random); true abandons the work.
    pub stop: &'a (dyn Fn() -> bool + Sync),
}

/// [`verify`], watched: the same trials with the same statistics, unless `watch.stop` says to
/// stop, which returns `Ok(None)` soon after.
pub fn verify_watched(
    level: &Level,
    solver: &Solver,
    trials: u32,
    seed: u64,
    watch: &Watch,
) -> Result<Option<SolverStats>, WrongGame> {
    let results = trial_results(level, solver, 0..trials as u64, seed, watch)?;
    Ok(results.map(|results| stats_of(level, solver, seed, &results)))
}

/// The results of a verification's trials `range` alone, in order (trial `i` seeded `seed + i`,
/// whatever the range), so a verification can be played in parts: trials `0..20`, then
/// `20..100`, give the results of trials `0..100`. `None` when `watch.stop` says to stop.
pub fn trial_results(
    level: &Level,
    solver: &Solver,
    range: Range<u64>,
    seed: u64,
    watch: &Watch,
) -> Result<Option<Vec<TrialResult>>, WrongGame> {
    solver.check_game(level.game())?;
    Ok(arlpcg_core::for_game!(level.game(), G => {
        play_all::<G>(level, solver, range, seed, watch)
    }))
}

/// The statistics of a verification from `seed` whose trials gave `results` (trials `0..n`).
pub fn stats_of(level: &Level, solver: &Solver, seed: u64, results: &[TrialResult]) -> SolverStats {
    SolverStats::from_trials(solver.reference(), seed, level.piece_count(), results)
}

/// Plays the trials `range` of a level of game `G`; `None` when told to stop.
fn play_all<G: GameSpec>(
    level: &Level,
    solver: &Solver,
    range: Range<u64>,
    seed: u64,
    watch: &Watch,
) -> Option<Vec<TrialResult>> {
    let new_env = &|| G::solver_env(level).expect("verification plays a level of its own game");
    let reported = |result: TrialResult| {
        (watch.on_trial)(&result);
        result
    };
    match solver {
        Solver::Scripted(skill) => range
            .into_par_iter()
            .map_init(new_env, |env, i| {
                (!(watch.stop)())
                    .then(|| reported(play_scripted::<G>(env, seed.wrapping_add(i), *skill)))
            })
            .collect(),
        Solver::Random => range
            .into_par_iter()
            .map_init(new_env, |env, i| {
                (!(watch.stop)()).then(|| reported(play_random(env, seed.wrapping_add(i))))
            })
            .collect(),
        Solver::Policy(policy) => {
            let abilities = policy.ability_row(level);
            play_policy(new_env, policy, &abilities, seed, range, watch)
        }
    }
}

/// One run recorded for display: where the player was at every step.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Where the player was at every step.
    pub path: Vec<[f32; 3]>,
    /// How the run ended.
    pub result: TrialResult,
}

/// Plays one run of the level with `seed` and records it: the run that trial `i` of a
/// verification from seed `seed - i` plays in its pool, here alone (one forward pass per step).
pub fn record(level: &Level, solver: &Solver, seed: u64) -> Result<Recording, WrongGame> {
    solver.check_game(level.game())?;
    let unexpected = "a level's environment is of its own game";
    Ok(arlpcg_core::for_game!(level.game(), G => {
        record_env::<G>(G::solver_env(level).expect(unexpected), (solver, level), seed)
    }))
}

fn record_env<G: GameSpec>(
    mut env: G::Env,
    (solver, level): (&Solver, &Level),
    seed: u64,
) -> Recording {
    env.reset(seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut scripted = match solver {
        Solver::Scripted(skill) => Some(G::scripted(seed, *skill)),
        _ => None,
    };
    let abilities = match solver {
        Solver::Policy(policy) => policy.ability_row(level),
        _ => Vec::new(),
    };
    let base = <G::Env as SolverEnv>::OBSERVATION_SIZE;
    let mut observation = vec![0.0; base + abilities.len()];
    let mut path = vec![env.marker()];
    loop {
        let action = match solver {
            Solver::Scripted(_) => scripted.as_mut().expect("made above").act(&env),
            Solver::Random => G::Env::random_action(&mut rng),
            Solver::Policy(policy) => {
                env.observe(&mut observation[..base]);
                observation[base..].copy_from_slice(&abilities);
                policy.normalizer.normalize(&mut observation);
                let action = policy
                    .policy
                    .choose(&observation, ActMode::Sample, &mut rng)
                    .expect("a policy checked for the level's game acts on its observations");
                G::Env::action_from_policy_row(&action)
            }
        };
        let outcome = env.step(action).outcome;
        path.push(env.marker());
        if let Some(outcome) = outcome {
            return Recording {
                path,
                result: env.trial_result(outcome),
            };
        }
    }
}

/// The seed of a successful run played alone ([`record`]), searching `seeds`; `None` when none
/// of them succeeds. With `verify --replay`, the certificate a level file carries.
pub fn certify(
    level: &Level,
    solver: &Solver,
    seeds: impl Iterator<Item = u64>,
) -> Result<Option<u64>, WrongGame> {
    for seed in seeds {
        if record(level, solver, seed)?.result.outcome
            == arlpcg_core::level::stats::Outcome::Success
        {
            return Ok(Some(seed));
        }
    }
    Ok(None)
}

/// `level` with a certificate in its statistics: single runs from the trials' seeds on, so a
/// level some trial completed is certified within a few runs unless its success ratio is tiny.
pub fn certified(mut level: Level, solver: &Solver, seed: u64) -> Result<Level, WrongGame> {
    if let Some(stats) = &level.stats
        && stats.successes > 0
    {
        let seeds = (0..2 * stats.trials as u64).map(|k| seed.wrapping_add(k));
        let certificate = certify(&level, solver, seeds)?;
        if let Some(stats) = &mut level.stats {
            stats.certificate = certificate;
        }
    }
    Ok(level)
}

/// Plays one run with the game's scripted player of `skill`, seeded by `seed`.
pub fn play_scripted<G: GameSpec>(env: &mut G::Env, seed: u64, skill: Skill) -> TrialResult {
    env.reset(seed);
    let mut player = G::scripted(seed, skill);
    loop {
        if let Some(outcome) = env.step(player.act(env)).outcome {
            return env.trial_result(outcome);
        }
    }
}

fn play_random<E: SolverEnv>(env: &mut E, seed: u64) -> TrialResult {
    env.reset(seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    loop {
        if let Some(outcome) = env.step(E::random_action(&mut rng)).outcome {
            return env.trial_result(outcome);
        }
    }
}

/// Plays trials `range` in a pool of parallel worlds, one batched forward pass per tick; a
/// world whose trial ends starts the next one. Trial `i` resets its world with `seed + i` and
/// draws its actions from its own stream seeded `seed + i`, as [`record`] does, so its result
/// does not depend on which trials share the pool. The pool starts with [`FIRST_POOL`] worlds,
/// so the first statistics come soon, and grows to [`LOCKSTEP`] once a trial has ended.
fn play_policy<E: SolverEnv>(
    new_env: &(dyn Fn() -> E + Sync),
    solver: &SolverPolicy,
    abilities: &[f32],
    seed: u64,
    range: Range<u64>,
    watch: &Watch,
) -> Option<Vec<TrialResult>> {
    let size = E::OBSERVATION_SIZE + abilities.len();
    let width = solver.policy.shape().action_size();
    let first = range.start;
    let mut results: Vec<Option<TrialResult>> = vec![None; range.clone().count()];
    let (mut envs, mut playing, mut rngs) = (Vec::<E>::new(), Vec::<u64>::new(), Vec::new());
    let mut idle: Vec<E> = Vec::new();
    let mut pool = FIRST_POOL;
    let mut next = range.start;
    let mut observations = vec![0.0; LOCKSTEP * size];
    loop {
        let starting: Vec<u64> = (next..range.end).take(pool - envs.len()).collect();
        next += starting.len() as u64;
        let mut fresh: Vec<(E, u64)> = starting
            .iter()
            .map(|&i| (idle.pop(), i))
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|(env, i)| {
                let mut env = env.unwrap_or_else(new_env);
                env.reset(seed.wrapping_add(i));
                (env, i)
            })
            .collect();
        for (env, i) in fresh.drain(..) {
            envs.push(env);
            playing.push(i);
            rngs.push(ChaCha8Rng::seed_from_u64(seed.wrapping_add(i)));
        }
        if envs.is_empty() {
            break;
        }
        if (watch.stop)() {
            return None;
        }
        let rows = &mut observations[..envs.len() * size];
        rows.par_chunks_mut(size).zip(&envs).for_each(|(row, env)| {
            let (game, own) = row.split_at_mut(E::OBSERVATION_SIZE);
            env.observe(game);
            own.copy_from_slice(abilities);
        });
        solver.normalizer.normalize(rows);
        let actions = solver
            .policy
            .choose_per_row(rows, ActMode::Sample, &mut rngs)
            .expect("a policy checked for the level's game acts on its observations");
        let mut finished: Vec<(usize, TrialResult)> = envs
            .par_iter_mut()
            .zip(actions.par_chunks(width))
            .enumerate()
            .filter_map(|(k, (env, row))| {
                env.step(E::action_from_policy_row(row))
                    .outcome
                    .map(|o| (k, env.trial_result(o)))
            })
            .collect();
        finished.sort_by_key(|&(k, _)| std::cmp::Reverse(k));
        for (k, result) in finished {
            (watch.on_trial)(&result);
            results[(playing[k] - first) as usize] = Some(result);
            idle.push(envs.swap_remove(k));
            playing.swap_remove(k);
            rngs.swap_remove(k);
            pool = LOCKSTEP;
        }
    }
    Some(
        results
            .into_iter()
            .map(|r| r.expect("every trial finished"))
            .collect(),
    )
}
