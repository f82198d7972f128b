//! Verification: play a level many times with a Solver and aggregate the statistics. Runs are
//! seeded from `seed` and the trial index, so the same level, Solver, seed and trial count give
//! the same statistics whatever the number of threads.
//!
//! A trained policy plays trials in lockstep, up to [`LOCKSTEP`] at a time: all their worlds step
//! in parallel and one batched forward pass picks every action. It samples its actions (the
//! stochastic policy it was trained as), each trial from its own random stream, so a trial played
//! in the pool is the run [`record`] plays alone from the same seed.

use std::ops::Range;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame, Scripted, Skill, SolverEnv};
use arlpcg_core::level::profile::{Abilities, Profile, main_abilities};
use arlpcg_core::level::stats::{SolverRef, SolverStats, TrialResult};
use arlpcg_core::level::{Game, Level, PolicyRef};
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};

/// Trials a policy plays at once.
pub const LOCKSTEP: usize = 64;

/// Trials a policy plays at once until the first one ends (the designer's first statistics).
pub const FIRST_POOL: usize = 4;

/// A trained Solver, ready to play.
pub struct SolverPolicy {
    /// The game it was trained for.
    pub game: Game,
    pub policy: ActorCritic,
    pub normalizer: RunningNorm,
    pub reference: PolicyRef,
    /// The game profile it trained for (none: the built-in game).
    pub profile: Option<Profile>,
    /// An ability-aware Solver: it trained with each main ability within this share of its
    /// profile's, and observes them (none: it trained with one character or car).
    pub ability_spread: Option<f64>,
}

/// How a Solver policy stands to the abilities of a profile it is to play under.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileFit {
    /// It trained with them, or over a range that holds them.
    Fits,
    /// A policy of one character or car, trained with others: its statistics are not those of
    /// a player who trained with them (the message says so).
    Untrained(String),
    /// Beyond the range an ability-aware policy trained over: refused (the message says how to
    /// train for it).
    Beyond(String),
}

impl SolverPolicy {
    /// How it stands to playing under `played` (none: the built-in abilities).
    pub fn fit(&self, played: Option<&Profile>) -> ProfileFit {
        let abilities = |profile: Option<&Profile>| Abilities::of(profile, self.game);
        let name = |profile: Option<&Profile>| {
            profile.map_or("the built-in abilities".to_string(), |p| {
                format!("profile `{}`", p.name)
            })
        };
        let trained = self.profile.as_ref();
        match self.ability_spread {
            Some(spread) if !abilities(played).within(&abilities(trained), spread) => {
                ProfileFit::Beyond(format!(
                    "{} lies beyond the abilities the Solver policy {} trained over (each of {} within ±{:.0}% of {}): train a Solver for it (arlpcg train --profile FILE)",
                    name(played),
                    self.reference.path,
                    main_abilities(self.game).join(", "),
                    100.0 * spread,
                    name(trained)
                ))
            }
            None if abilities(played) != abilities(trained) => ProfileFit::Untrained(format!(
                "the Solver policy trained for {} plays under {}: its statistics are of a player who never trained with them (the scripted player, --solver scripted, plays with them)",
                name(trained),
                name(played)
            )),
            _ => ProfileFit::Fits,
        }
    }

    /// Of this Solver and a folder's ability-aware one, the one that plays under `played`: the
    /// ability-aware one when this one did not train with those abilities and its range holds
    /// them; else this one (its [`fit`](Self::fit) says why it may not).
    pub fn or_aware<'a>(
        &'a self,
        aware: Option<&'a SolverPolicy>,
        played: Option<&Profile>,
    ) -> &'a SolverPolicy {
        match aware {
            Some(aware) if self.yields_to(aware, played) => aware,
            _ => self,
        }
    }

    /// Whether `aware` plays under `played` in place of this Solver ([`Self::or_aware`]).
    pub fn yields_to(&self, aware: &SolverPolicy, played: Option<&Profile>) -> bool {
        self.fit(played) != ProfileFit::Fits && aware.fit(played) == ProfileFit::Fits
    }

    /// What it observes after the game's observation on `level`: for an ability-aware Solver
    /// the level's main abilities relative to ours, else nothing.
    fn ability_row(&self, level: &Level) -> Vec<f32> {
        if self.ability_spread.is_none() {
            return Vec::new();
        }
        let played = Abilities::of(level.profile.as_ref(), level.game());
        played.relative_main().to_vec()
    }
}

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
    pub policy: String,
    pub plays: Game,
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
    Ok(match level.game() {
        Game::Platform => play_all::<PlatformGame>(level, solver, range, seed, watch),
        Game::Racing => play_all::<RacingGame>(level, solver, range, seed, watch),
    })
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
    pub path: Vec<[f32; 3]>,
    pub result: TrialResult,
}

/// Plays one run of the level with `seed` and records it: the run that trial `i` of a
/// verification from seed `seed - i` plays in its pool, here alone (one forward pass per step).
pub fn record(level: &Level, solver: &Solver, seed: u64) -> Result<Recording, WrongGame> {
    solver.check_game(level.game())?;
    let unexpected = "a level's environment is of its own game";
    Ok(match level.game() {
        Game::Platform => record_env::<PlatformGame>(
            PlatformGame::solver_env(level).expect(unexpected),
            (solver, level),
            seed,
        ),
        Game::Racing => record_env::<RacingGame>(
            RacingGame::solver_env(level).expect(unexpected),
            (solver, level),
            seed,
        ),
    })
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

/// Where runs fail along levels: failures and pieces before the halfway point (pieces that
/// begin less than half the start-to-goal distance in) and past it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HalfwaySplit {
    /// Failures on pieces before the halfway point, and past it.
    pub failures: [u64; 2],
    /// Pieces before the halfway point, and past it.
    pub pieces: [u64; 2],
}

impl HalfwaySplit {
    /// Adds a level's per-piece failures, each piece on the side where it begins.
    pub fn add(&mut self, level: &Level, stats: &SolverStats) {
        for (fraction, &failures) in level
            .piece_start_fractions()
            .iter()
            .zip(&stats.failures_by_piece)
        {
            let side = usize::from(*fraction >= 0.5);
            self.failures[side] += u64::from(failures);
            self.pieces[side] += 1;
        }
    }

    /// The share of all failures that fall past the halfway point (NaN without failures).
    pub fn share_past(&self) -> f64 {
        self.failures[1] as f64 / (self.failures[0] + self.failures[1]) as f64
    }

    /// Failures per piece before the halfway point and past it (NaN for a side without pieces).
    pub fn per_piece(&self) -> [f64; 2] {
        [0, 1].map(|k| self.failures[k] as f64 / self.pieces[k] as f64)
    }
}

/// Where a batch's failures gather: the share of all failures on each level's last piece and on
/// each level's most-failed piece (so weighted by failures), and the pieces per level. A knob
/// that builds a wall before the goal shows as a last-piece share near 1; one that makes every
/// stretch harder, as small shares of both.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct FailureConcentration {
    pub failures: u64,
    pub on_last_piece: u64,
    pub on_worst_piece: u64,
    pub levels: u64,
    pub pieces: u64,
}

impl FailureConcentration {
    pub fn add(&mut self, stats: &SolverStats) {
        let by_piece = &stats.failures_by_piece;
        self.failures += by_piece.iter().map(|&f| u64::from(f)).sum::<u64>();
        self.on_last_piece += by_piece.last().map_or(0, |&f| u64::from(f));
        self.on_worst_piece += by_piece.iter().max().map_or(0, |&f| u64::from(f));
        self.levels += 1;
        self.pieces += by_piece.len() as u64;
    }

    /// The shares on the last and on the most-failed piece (none without failures).
    pub fn shares(&self) -> Option<[f64; 2]> {
        (self.failures > 0).then(|| {
            [self.on_last_piece, self.on_worst_piece].map(|n| n as f64 / self.failures as f64)
        })
    }

    pub fn pieces_per_level(&self) -> f64 {
        self.pieces as f64 / self.levels.max(1) as f64
    }
}

/// The difficulty along a level: the share of runs past each piece, piece by piece from the
/// start, and, on a paced level, the difficulty its λ asked for (`(1 - λ) / 2`: 0 easy, 1 hard).
/// Pieces are counted, not placed by the fraction of the way where they begin: a level that
/// winds back and forth near the goal's distance would draw its line backwards.
pub fn pacing_chart(
    name: &str,
    level: &Level,
    stats: &SolverStats,
) -> crate::services::chart::LineChart {
    let piece_numbers = (1..).map(f64::from);
    let passed = passed_by_piece(stats);
    let mut series = vec![crate::services::chart::Series {
        name: "runs past the piece".into(),
        points: piece_numbers.clone().zip(passed).collect(),
    }];
    if let Some(pacing) = &level.pacing {
        series.push(crate::services::chart::Series {
            name: "asked: (1-λ)/2".into(),
            points: piece_numbers
                .zip(&pacing.piece_aux)
                .map(|(n, aux)| (n, aux.map_or(f64::NAN, |a| (1.0 - a) / 2.0)))
                .collect(),
        });
    }
    crate::services::chart::LineChart {
        title: format!("{name}: {} runs", stats.trials),
        x_label: "piece, from the start".into(),
        y_label: "share".into(),
        series,
        y_range: Some((0.0, 1.0)),
    }
}

/// The share of runs that got past each piece: `1 - failures up to and including it / trials`
/// (what a player feels as the difficulty along the level).
pub fn passed_by_piece(stats: &SolverStats) -> Vec<f64> {
    let mut failed = 0u64;
    stats
        .failures_by_piece
        .iter()
        .map(|&f| {
            failed += u64::from(f);
            1.0 - failed as f64 / f64::from(stats.trials.max(1))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall before the goal shows as all failures on the last piece; failures spread over a
    /// level, as small shares of both.
    #[test]
    fn failure_concentration_weighs_each_levels_last_and_worst_piece_by_failures() {
        let stats = |by_piece: Vec<u32>| {
            let mut s = SolverStats::from_trials(SolverRef::Random, 0, by_piece.len(), &[]);
            s.failures_by_piece = by_piece;
            s
        };
        let mut wall = FailureConcentration::default();
        wall.add(&stats(vec![0, 0, 0, 9]));
        wall.add(&stats(vec![0, 0, 1]));
        assert_eq!(wall.shares(), Some([1.0, 1.0]));
        assert_eq!(wall.pieces_per_level(), 3.5);
        let mut spread = FailureConcentration::default();
        spread.add(&stats(vec![2, 1, 2, 1, 0]));
        spread.add(&stats(vec![0, 0, 0]));
        assert_eq!(spread.shares(), Some([0.0, 2.0 / 6.0]));
        assert_eq!(FailureConcentration::default().shares(), None);
    }

    /// The shipped hard example level (platform, seed 7, λ = -1) winds back toward its start,
    /// so its pieces' fractions of the way are not in order; the chart still reads left to right.
    #[test]
    fn the_pacing_chart_counts_pieces_in_order_whatever_way_the_level_winds() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("levels/platform/platform_seed7_aux-1.00.yaml");
        let level = arlpcg_core::level::yaml::load(&path).unwrap();
        let stats = level.stats.clone().unwrap();
        let fractions = level.piece_start_fractions();
        assert!(
            fractions.windows(2).any(|w| w[1] < w[0]),
            "a level whose pieces go back toward the start: {fractions:?}"
        );
        let chart = pacing_chart("seed7", &level, &stats);
        assert_eq!(
            chart.series.len(),
            1,
            "runs past each piece (one λ asked: no curve)"
        );
        for series in &chart.series {
            assert_eq!(series.points.len(), fractions.len(), "{}", series.name);
            assert!(
                series.points.windows(2).all(|w| w[1].0 > w[0].0),
                "{}: x in order",
                series.name
            );
        }
        let passed: Vec<f64> = chart.series[0].points.iter().map(|p| p.1).collect();
        assert!(passed.windows(2).all(|w| w[1] <= w[0]), "{passed:?}");
        assert_eq!(
            *passed.last().unwrap(),
            stats.success_ratio,
            "the last piece's share is the level's success"
        );
    }
}
