//! Throughput of the racing Solver environment: decisions per second (the car's physics with
//! its four wheel ray casts, the observation with its fan of 20 ray casts), on one thread and
//! with 64 worlds on two threads; and what a decision's time goes to.
//!
//! Run with `cargo bench --bench racing_env`. Target: 50,000 decisions/s, 64 worlds on 2 cores.

use std::time::{Duration, Instant};

use arlpcg_core::game::SolverEnv;
use arlpcg_core::game::racing::car::CarAction;
use arlpcg_core::game::racing::{
    OBSERVATION_SIZE, RacingEnv, RacingRewards, ScriptedDriver, rules,
};
use arlpcg_core::level::Track;
use arlpcg_core::level::racing::RacingRulesConfig;
use rayon::prelude::*;

/// How a worker picks its actions.
#[derive(Clone, Copy, PartialEq)]
enum Driver {
    /// Seeded random actions leaning on the throttle (a policy early in training: short runs,
    /// many resets).
    Random,
    /// The scripted driver (a policy late in training: whole tracks).
    Scripted,
}

struct Worker {
    env: RacingEnv,
    obs: Vec<f32>,
    state: u64,
    episodes: u64,
    driver: Driver,
    scripted: ScriptedDriver,
    observe: bool,
}

impl Worker {
    fn new(seed: u64, driver: Driver, observe: bool) -> Self {
        let config = RacingRulesConfig {
            obstacles: 2,
            ..RacingRulesConfig::default()
        };
        let level = rules::racing_level(seed, None, None, &config, &Default::default())
            .expect("rule track");
        let Track::Racing(track) = &level.track else {
            unreachable!("a racing level")
        };
        Self {
            env: RacingEnv::new(track, level.goal, RacingRewards::default()),
            obs: vec![0.0; OBSERVATION_SIZE],
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
            episodes: 0,
            driver,
            scripted: ScriptedDriver::new(seed, 0.1),
            observe,
        }
    }

    fn next_unit(&mut self) -> f32 {
        // xorshift64*
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        ((self.state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32) * 2.0
            - 1.0
    }

    /// Takes `n` decisions, resetting finished episodes.
    fn run(&mut self, n: u64) {
        for _ in 0..n {
            let action = match self.driver {
                Driver::Random => CarAction {
                    throttle: 0.5 + 0.5 * self.next_unit(),
                    steer: self.next_unit(),
                },
                Driver::Scripted => self.scripted.act(&self.env),
            };
            let step = self.env.step(action);
            if self.observe {
                self.env.observe(&mut self.obs);
            }
            if step.terminated || step.truncated {
                self.episodes += 1;
                self.env.reset(self.episodes);
            }
        }
    }
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

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let budget = Duration::from_secs(3);
    let single = |driver, observe, label: &str| {
        let mut worker = Worker::new(1, driver, observe);
        measure(label, budget, || {
            worker.run(2_000);
            2_000
        })
    };
    let random = single(Driver::Random, true, "1 world, 1 thread, random driver");
    let scripted = single(Driver::Scripted, true, "1 world, 1 thread, scripted driver");
    let physics = single(
        Driver::Scripted,
        false,
        "1 world, 1 thread, scripted, no observation",
    );
    let per_decision = 1e6 / scripted;
    let observation = per_decision - 1e6 / physics;
    println!(
        "of a scripted decision's {per_decision:.1} µs: observation (20-ray fan, centre line) {observation:.1} µs, \
         physics + wheel rays + driver {:.1} µs",
        1e6 / physics
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    let chunk = 256;
    let mut two = f64::INFINITY;
    for (driver, name, one) in [
        (Driver::Random, "random", random),
        (Driver::Scripted, "scripted", scripted),
    ] {
        let mut workers: Vec<Worker> = (0..64).map(|s| Worker::new(s, driver, true)).collect();
        let rate = pool.install(|| {
            measure(
                &format!("64 worlds, 2 threads, {name} driver"),
                budget,
                || {
                    workers.par_iter_mut().for_each(|w| w.run(chunk));
                    64 * chunk
                },
            )
        });
        println!("  parallel speed-up on 2 threads: {:.2}x", rate / one);
        two = two.min(rate);
    }
    let target = 50_000.0;
    let verdict = if two >= target { "reached" } else { "MISSED" };
    println!(
        "target {target:.0} decisions/s on 2 cores (the slower driver): {verdict} ({:.1}x the target)",
        two / target
    );
}
