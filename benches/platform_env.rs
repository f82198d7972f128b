//! Throughput of the platform Solver environment: decisions per second (physics, height-map ray
//! casts and observation included), on one thread and with many worlds on two threads.
//!
//! Run with `cargo bench --bench platform_env`. Target: 100,000 decisions/s on 2 cores.

use std::time::{Duration, Instant};

use arlpcg_core::game::SolverEnv;
use arlpcg_core::game::platform::rules;
use arlpcg_core::game::platform::{OBSERVATION_SIZE, PlatformAction, PlatformEnv, PlatformRewards};
use rayon::prelude::*;

/// A world with a cheap, seeded action source (a random policy, as early in training).
struct Worker {
    env: PlatformEnv,
    obs: Vec<f32>,
    state: u64,
    episodes: u64,
}

impl Worker {
    fn new(seed: u64) -> Self {
        let level =
            rules::platform_level(seed, None, None, &Default::default(), &Default::default())
                .expect("rule level");
        let track = level.platform().expect("platform level");
        Self {
            env: PlatformEnv::new(track, level.goal, PlatformRewards::default()),
            obs: vec![0.0; OBSERVATION_SIZE],
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
            episodes: 0,
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
            let action = PlatformAction {
                forward: 0.5 + 0.5 * self.next_unit(),
                turn: self.next_unit(),
                jump: self.next_unit() > 0.8,
            };
            let step = self.env.step(action);
            self.env.observe(&mut self.obs);
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
        "{label:<44} {:>10.0} decisions/s  ({:.2} µs each)",
        rate,
        1e6 / rate
    );
    rate
}

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let budget = Duration::from_secs(3);
    let mut single = Worker::new(1);
    let one = measure("1 world, 1 thread", budget, || {
        single.run(2_000);
        2_000
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    let mut workers: Vec<Worker> = (0..64).map(Worker::new).collect();
    let chunk = 256;
    let two = pool.install(|| {
        measure("64 worlds, 2 threads", budget, || {
            workers.par_iter_mut().for_each(|w| w.run(chunk));
            64 * chunk
        })
    });
    println!("parallel speed-up on 2 threads: {:.2}x", two / one);
    let target = 100_000.0;
    let verdict = if two >= target { "reached" } else { "MISSED" };
    println!(
        "target {target:.0} decisions/s on 2 cores: {verdict} ({:.1}x the target)",
        two / target
    );
}
