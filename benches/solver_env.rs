//! Throughput of each game's Solver environment: decisions per second (physics, ray casts and
//! the observation included), on one thread and with 64 worlds on two threads; for racing, what
//! a decision's time goes to (its car has four wheel ray casts, its observation a fan of 20).
//!
//! Run with `cargo bench --bench solver_env`. Targets on 2 cores, 64 worlds: platform 100,000
//! decisions/s, racing 50,000 (the slower of its two drivers).
#![allow(clippy::unwrap_used)] // a measurement or a test may unwrap (Cargo.toml, [lints])

use std::time::{Duration, Instant};

use arlpcg_core::game::platform::{PlatformAction, PlatformEnv, PlatformRewards};
use arlpcg_core::game::racing::car::CarAction;
use arlpcg_core::game::racing::{RacingEnv, RacingRewards, ScriptedDriver};
use arlpcg_core::game::{GameSpec, PlatformGame, SolverEnv};
use arlpcg_core::level::racing::RacingRulesConfig;
use rayon::prelude::*;

/// A cheap, seeded source of numbers in [-1, 1] (xorshift64*).
struct Units(u64);

impl Units {
    fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32) * 2.0
            - 1.0
    }
}

/// How a worker picks its actions.
type Driver<E> = Box<dyn FnMut(&E, &mut Units) -> <E as SolverEnv>::Action + Send>;

/// A world and its driver.
struct Worker<E: SolverEnv> {
    env: E,
    obs: Vec<f32>,
    units: Units,
    episodes: u64,
    driver: Driver<E>,
    observe: bool,
}

impl<E: SolverEnv> Worker<E> {
    fn new(env: E, seed: u64, driver: Driver<E>, observe: bool) -> Self {
        Self {
            env,
            obs: vec![0.0; E::OBSERVATION_SIZE],
            units: Units::new(seed),
            episodes: 0,
            driver,
            observe,
        }
    }

    /// Takes `n` decisions, resetting finished episodes.
    fn run(&mut self, n: u64) {
        for _ in 0..n {
            let action = (self.driver)(&self.env, &mut self.units);
            let step = self.env.step(action);
            if self.observe {
                self.env.observe(&mut self.obs);
            }
            if step.outcome.is_some() {
                self.episodes += 1;
                self.env.reset(self.episodes);
            }
        }
    }
}

/// A platform rule level's world with random actions leaning forward (a policy early in
/// training).
fn platform_worker(seed: u64) -> Worker<PlatformEnv> {
    let level = PlatformGame::rule_level(seed, &Default::default()).expect("rule level");
    let track = level.platform().expect("platform level");
    let env = PlatformEnv::new(track, level.goal, PlatformRewards::default());
    let driver: Driver<PlatformEnv> = Box::new(|_, units| PlatformAction {
        forward: 0.5 + 0.5 * units.next(),
        turn: units.next(),
        jump: units.next() > 0.8,
    });
    Worker::new(env, seed, driver, true)
}

/// A racing rule track's world (two obstacles), driven by seeded random actions leaning on the
/// throttle (a policy early in training: short runs, many resets) or by the scripted driver (a
/// policy late in training: whole tracks).
fn racing_worker(seed: u64, scripted: bool, observe: bool) -> Worker<RacingEnv> {
    let config = RacingRulesConfig {
        obstacles: 2,
        ..RacingRulesConfig::default()
    };
    let level = arlpcg_core::game::racing::rules::racing_level(
        seed,
        None,
        None,
        &config,
        &Default::default(),
    )
    .expect("rule track");
    let track = level.racing().expect("racing level");
    let env = RacingEnv::new(track, level.goal, RacingRewards::default());
    let driver: Driver<RacingEnv> = if scripted {
        let mut driver = ScriptedDriver::new(seed, 0.1);
        Box::new(move |env, _| driver.act(env))
    } else {
        Box::new(|_, units| CarAction {
            throttle: 0.5 + 0.5 * units.next(),
            steer: units.next(),
        })
    };
    Worker::new(env, seed, driver, observe)
}

fn measure(label: &str, budget: Duration, mut round: impl FnMut() -> u64) -> f64 {
    round(); // warm up
    let start = Instant::now();
    let mut decisions = 0;
    while start.elapsed() < budget {
        decisions += round();
    }
    let rate = decisions as f64 / start.elapsed().as_secs_f64();
    println!(
        "{label:<52} {:>10.0} decisions/s  ({:.2} µs each)",
        rate,
        1e6 / rate
    );
    rate
}

/// One world on one thread.
fn single<E: SolverEnv>(label: &str, budget: Duration, mut worker: Worker<E>) -> f64 {
    measure(label, budget, || {
        worker.run(2_000);
        2_000
    })
}

/// 64 worlds on the two threads of `pool`, beside `one`, the rate of one world on one thread.
fn parallel<E: SolverEnv>(
    label: &str,
    budget: Duration,
    pool: &rayon::ThreadPool,
    mut workers: Vec<Worker<E>>,
    one: f64,
) -> f64 {
    let chunk = 256;
    let rate = pool.install(|| {
        measure(label, budget, || {
            workers.par_iter_mut().for_each(|w| w.run(chunk));
            workers.len() as u64 * chunk
        })
    });
    println!("  parallel speed-up on 2 threads: {:.2}x", rate / one);
    rate
}

fn verdict(what: &str, rate: f64, target: f64) {
    let verdict = if rate >= target { "reached" } else { "MISSED" };
    println!(
        "{what}: target {target:.0} decisions/s on 2 cores: {verdict} ({:.1}x the target)",
        rate / target
    );
}

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let budget = Duration::from_secs(3);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");

    println!("== platform");
    let one = single("1 world, 1 thread", budget, platform_worker(1));
    let workers = (0..64).map(platform_worker).collect();
    let two = parallel("64 worlds, 2 threads", budget, &pool, workers, one);
    verdict("platform", two, 100_000.0);

    println!("== racing");
    let random = single(
        "1 world, 1 thread, random driver",
        budget,
        racing_worker(1, false, true),
    );
    let scripted = single(
        "1 world, 1 thread, scripted driver",
        budget,
        racing_worker(1, true, true),
    );
    let physics = single(
        "1 world, 1 thread, scripted, no observation",
        budget,
        racing_worker(1, true, false),
    );
    let per_decision = 1e6 / scripted;
    let observation = per_decision - 1e6 / physics;
    println!(
        "of a scripted decision's {per_decision:.1} µs: observation (20-ray fan, centre line) \
         {observation:.1} µs, physics + wheel rays + driver {:.1} µs",
        1e6 / physics
    );
    let mut slower = f64::INFINITY;
    for (scripted, name, one) in [(false, "random", random), (true, "scripted", scripted)] {
        let workers = (0..64).map(|s| racing_worker(s, scripted, true)).collect();
        let label = format!("64 worlds, 2 threads, {name} driver");
        slower = slower.min(parallel(&label, budget, &pool, workers, one));
    }
    verdict("racing (the slower driver)", slower, 50_000.0);
}
