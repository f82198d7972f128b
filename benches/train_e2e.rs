//! End-to-end training speed of the platform Solver: rollouts over 64 parallel worlds plus PPO
//! updates (4 epochs) of the paper's 2 × 512 actor-critic, in environment steps per second, with
//! the split between rollout and update.
//!
//! Run with `cargo bench --bench train_e2e`. Target: 10,000 environment steps per second.

use std::time::Instant;

use arlpcg::services::train::TrainConfig;
use arlpcg::services::train::solver_envs::{SolverEnvs, SolverMode, SourceRecord};
use arlpcg_core::game::PlatformGame;
use arlpcg_core::rl::policy::{ActorCritic, PolicyShape};
use arlpcg_core::rl::ppo::Ppo;
use arlpcg_core::rl::vec_env::Trainer;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let config = TrainConfig::default();
    let shape = PolicyShape {
        observation: arlpcg_core::game::platform::OBSERVATION_SIZE,
        hidden: config.hidden.clone(),
        continuous: 2,
        binary: 1,
    };
    let action_size = shape.action_size();
    let ppo = Ppo::new(config.solver.clone(), ActorCritic::new(shape, 0).unwrap()).unwrap();
    let envs = SolverEnvs::<PlatformGame>::new(
        SolverMode::RulePcg,
        config.solver.num_envs,
        SourceRecord::default(),
        action_size,
    )
    .unwrap();
    let mut trainer = Trainer::new(ppo, envs, 0);
    let (mut rollout_s, mut update_s) = (0.0, 0.0);
    let iterations = 6;
    for i in 0..=iterations {
        let t0 = Instant::now();
        let (batch, _) = trainer.collect().unwrap();
        let t1 = Instant::now();
        trainer.learn(&batch, 1e-4).unwrap();
        if i > 0 {
            // the first iteration warms up
            rollout_s += (t1 - t0).as_secs_f64();
            update_s += t1.elapsed().as_secs_f64();
        }
    }
    let steps = (iterations * config.solver.batch_size()) as f64;
    let rate = steps / (rollout_s + update_s);
    println!(
        "end-to-end training, {} worlds x {} steps, {} epochs, 2 x 512: {rate:.0} env steps/s",
        config.solver.num_envs, config.solver.num_steps, config.solver.update_epochs
    );
    println!(
        "  rollout {:.0} steps/s ({:.0}% of the time), update {:.0} samples/s per epoch",
        steps / rollout_s,
        100.0 * rollout_s / (rollout_s + update_s),
        steps * config.solver.update_epochs as f64 / update_s
    );
    let verdict = if rate >= 10_000.0 {
        "reached"
    } else {
        "MISSED"
    };
    println!("  target 10000 env steps/s: {verdict}");
}
