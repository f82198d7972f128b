//! Verification: play a level many times with a Solver and aggregate the statistics. Runs are
//! seeded from `seed` and the trial index, so the same level, Solver, seed and trial count give
//! the same statistics whatever the number of threads.
//!
//! A trained policy plays trials in lockstep, up to [`LOCKSTEP`] at a time: all their worlds step
//! in parallel and one batched forward pass picks every action. It samples its actions (the
//! stochastic policy it was trained as).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::game::platform::reach::play_scripted;
use crate::game::platform::{OBSERVATION_SIZE, PlatformAction, PlatformEnv, SolverRewards};
use crate::level::scene::UnsupportedGame;
use crate::level::stats::{SolverRef, SolverStats, TrialResult};
use crate::level::{Level, PlatformTrack, PolicyRef, Track};
use crate::rl::normalizer::RunningNorm;
use crate::rl::policy::{ActMode, ActorCritic};

/// Take-off jitter of the scripted controller when it verifies levels, m.
pub const SCRIPTED_JITTER: f32 = 0.3;
/// Trials a policy plays at once.
pub const LOCKSTEP: usize = 64;

/// A trained Solver, ready to play.
pub struct SolverPolicy {
    pub policy: ActorCritic,
    pub normalizer: RunningNorm,
    pub reference: PolicyRef,
}

/// Who plays the trials.
pub enum Solver<'a> {
    /// The scripted (non-learning) controller.
    Scripted,
    /// Uniformly random actions (a baseline).
    Random,
    /// A trained Solver policy.
    Policy(&'a SolverPolicy),
}

impl Solver<'_> {
    fn reference(&self) -> SolverRef {
        match self {
            Solver::Scripted => SolverRef::Scripted,
            Solver::Random => SolverRef::Random,
            Solver::Policy(p) => SolverRef::Policy {
                policy: p.reference.clone(),
            },
        }
    }
}

/// Plays `trials` runs of the level and returns their statistics. `on_trial` is called after
/// each finished trial (possibly from worker threads), for progress reporting.
pub fn verify(
    level: &Level,
    solver: &Solver,
    trials: u32,
    seed: u64,
    on_trial: &(dyn Fn() + Sync),
) -> Result<SolverStats, UnsupportedGame> {
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
) -> Result<Option<SolverStats>, UnsupportedGame> {
    let Track::Platform(track) = &level.track else {
        return Err(UnsupportedGame("racing"));
    };
    let new_env = || PlatformEnv::new(track, level.goal, SolverRewards::default());
    let reported = |result: TrialResult| {
        (watch.on_trial)(&result);
        result
    };
    let results: Option<Vec<TrialResult>> = match solver {
        Solver::Scripted => (0..trials as u64)
            .into_par_iter()
            .map_init(new_env, |env, i| {
                (!(watch.stop)())
                    .then(|| reported(play_scripted(env, seed.wrapping_add(i), SCRIPTED_JITTER)))
            })
            .collect(),
        Solver::Random => (0..trials as u64)
            .into_par_iter()
            .map_init(new_env, |env, i| {
                (!(watch.stop)()).then(|| reported(play_random(env, seed.wrapping_add(i))))
            })
            .collect(),
        Solver::Policy(policy) => (0..trials as u64)
            .collect::<Vec<_>>()
            .chunks(LOCKSTEP)
            .map(|chunk| play_policy(track, level.goal, policy, seed, chunk, watch))
            .collect::<Option<Vec<Vec<TrialResult>>>>()
            .map(|chunks| chunks.concat()),
    };
    Ok(results.map(|results| {
        SolverStats::from_trials(solver.reference(), seed, track.block_count(), &results)
    }))
}

/// One run recorded for display: where the character's feet were at every step.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    pub path: Vec<[f32; 3]>,
    pub result: TrialResult,
}

/// Plays one run of the level with `seed` and records it. A policy plays it alone (one forward
/// pass per step), so the run is not one of [`verify`]'s lockstep trials of the same seed.
pub fn record(level: &Level, solver: &Solver, seed: u64) -> Result<Recording, UnsupportedGame> {
    let Track::Platform(track) = &level.track else {
        return Err(UnsupportedGame("racing"));
    };
    let mut env = PlatformEnv::new(track, level.goal, SolverRewards::default());
    env.reset(seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut scripted =
        crate::game::platform::scripted::ScriptedController::new(seed, SCRIPTED_JITTER);
    let mut observation = vec![0.0; OBSERVATION_SIZE];
    let feet = |env: &PlatformEnv| {
        let f = env.character().feet;
        [f.x, f.y, f.z]
    };
    let mut path = vec![feet(&env)];
    loop {
        let action = match solver {
            Solver::Scripted => scripted.act(&env),
            Solver::Random => random_action(&mut rng),
            Solver::Policy(policy) => {
                env.observe(&mut observation);
                policy.normalizer.normalize(&mut observation);
                let action = policy
                    .policy
                    .choose(&observation, ActMode::Sample, &mut rng)
                    .expect("a loaded policy acts on observations of its size");
                PlatformAction::from_policy_row(&action)
            }
        };
        let outcome = env.step(action).outcome;
        path.push(feet(&env));
        if let Some(outcome) = outcome {
            return Ok(Recording {
                path,
                result: finish(&env, outcome),
            });
        }
    }
}

fn finish(env: &PlatformEnv, outcome: crate::level::stats::Outcome) -> TrialResult {
    TrialResult {
        outcome,
        progress: env.progress(),
        target_piece: env.furthest(),
        steps: env.steps(),
        air_steps: None,
    }
}

/// Uniformly random actions: the random baseline.
fn random_action(rng: &mut ChaCha8Rng) -> PlatformAction {
    PlatformAction {
        forward: rng.random_range(-1.0..=1.0),
        turn: rng.random_range(-1.0..=1.0),
        jump: rng.random_bool(0.5),
    }
}

fn play_random(env: &mut PlatformEnv, seed: u64) -> TrialResult {
    env.reset(seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    loop {
        if let Some(outcome) = env.step(random_action(&mut rng)).outcome {
            return finish(env, outcome);
        }
    }
}

/// Plays the trials `indices` together: parallel worlds, one forward pass per tick.
fn play_policy(
    track: &PlatformTrack,
    goal: [f64; 3],
    solver: &SolverPolicy,
    seed: u64,
    indices: &[u64],
    watch: &Watch,
) -> Option<Vec<TrialResult>> {
    let mut envs: Vec<PlatformEnv> = indices
        .par_iter()
        .map(|&i| {
            let mut env = PlatformEnv::new(track, goal, SolverRewards::default());
            env.reset(seed.wrapping_add(i));
            env
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(indices[0]).rotate_left(17));
    let mut results: Vec<Option<TrialResult>> = vec![None; envs.len()];
    let mut observations = vec![0.0; envs.len() * OBSERVATION_SIZE];
    loop {
        let active: Vec<usize> = (0..envs.len()).filter(|&k| results[k].is_none()).collect();
        if active.is_empty() {
            break;
        }
        if (watch.stop)() {
            return None;
        }
        let rows = &mut observations[..active.len() * OBSERVATION_SIZE];
        rows.par_chunks_mut(OBSERVATION_SIZE)
            .zip(&active)
            .for_each(|(row, &k)| envs[k].observe(row));
        solver.normalizer.normalize(rows);
        let actions = solver
            .policy
            .choose(rows, ActMode::Sample, &mut rng)
            .expect("a loaded policy acts on observations of its size");
        let width = solver.policy.shape().action_size();
        let mut stepping: Vec<(usize, &mut PlatformEnv)> = envs
            .iter_mut()
            .enumerate()
            .filter(|(k, _)| results[*k].is_none())
            .collect();
        let finished: Vec<(usize, TrialResult)> = stepping
            .par_iter_mut()
            .zip(actions.par_chunks(width))
            .filter_map(|((k, env), row)| {
                env.step(PlatformAction::from_policy_row(row))
                    .outcome
                    .map(|o| (*k, finish(env, o)))
            })
            .collect();
        for (k, result) in finished {
            (watch.on_trial)(&result);
            results[k] = Some(result);
        }
    }
    Some(
        results
            .into_iter()
            .map(|r| r.expect("every trial finished"))
            .collect(),
    )
}

/// Aggregates over many levels, as the paper's generalization table does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    pub levels: usize,
    /// Mean over levels of each level's success ratio.
    pub mean_success: f64,
    /// Standard deviation over levels of the success ratio.
    pub std_success: f64,
    /// Fraction of levels completed by at least one run.
    pub completed_by_any: f64,
    pub mean_progress: f64,
    /// Mean decisions of successful runs (over levels with a success).
    pub mean_success_steps: f64,
}

impl Summary {
    pub fn of(stats: &[SolverStats]) -> Self {
        let n = stats.len().max(1) as f64;
        let mean = |f: &dyn Fn(&SolverStats) -> f64| stats.iter().map(f).sum::<f64>() / n;
        let mean_success = mean(&|s| s.success_ratio);
        let variance = mean(&|s| (s.success_ratio - mean_success).powi(2));
        let solved: Vec<&SolverStats> = stats.iter().filter(|s| s.successes > 0).collect();
        Self {
            levels: stats.len(),
            mean_success,
            std_success: variance.sqrt(),
            completed_by_any: solved.len() as f64 / n,
            mean_progress: mean(&|s| s.mean_progress),
            mean_success_steps: solved.iter().map(|s| s.mean_success_steps).sum::<f64>()
                / solved.len().max(1) as f64,
        }
    }
}
