//! End-to-end training speed of the platform Solver: rollouts over 64 parallel worlds plus PPO
//! updates of the paper's 2 × 512 actor-critic, in environment steps per second, with where the
//! time goes (the buckets `train` logs) and the update's share of this machine's matmul peak.
//! The recipe's PPO settings run beside one update epoch (the trial of docs/trials.md,
//! 2026-11-28), alternating, so that the ratio is measured in one run on one machine.
//!
//! Run with `cargo bench --bench train_e2e`. Target: 20,000 environment steps per second.

use std::time::Instant;

use arlpcg::services::train::TrainConfig;
use arlpcg::services::train::solver_envs::{SolverEnvs, SolverMode, SourceRecord};
use arlpcg_core::game::PlatformGame;
use arlpcg_core::rl::fused::matmul_peak_flops;
use arlpcg_core::rl::policy::{ActorCritic, PolicyShape};
use arlpcg_core::rl::ppo::{Ppo, PpoConfig};
use arlpcg_core::rl::timing::TimeSplit;
use arlpcg_core::rl::vec_env::Trainer;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A trainer of the platform Solver on rule levels with these PPO settings.
fn trainer(shape: &PolicyShape, ppo: PpoConfig) -> Trainer<SolverEnvs<PlatformGame>> {
    let envs = SolverEnvs::<PlatformGame>::new(
        SolverMode::RulePcg,
        ppo.num_envs,
        SourceRecord::default(),
        shape.action_size(),
        (Default::default(), 0.0),
    )
    .unwrap();
    let ppo = Ppo::new(ppo, ActorCritic::new(shape.clone(), 0).unwrap()).unwrap();
    Trainer::new(ppo, envs, 0)
}

/// One iteration (a rollout and an update), its time split.
fn iteration(
    trainer: &mut Trainer<SolverEnvs<PlatformGame>>,
    clock: &dyn Fn() -> f64,
) -> TimeSplit {
    let (batch, _, mut time) = trainer.collect(clock).unwrap();
    let start = clock();
    let update = trainer.learn(&batch, 1e-4).unwrap();
    time.update_s = clock() - start;
    time.update_flops = trainer.ppo.update_flops(&update);
    time
}

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let recipe = TrainConfig::default();
    let shape = PolicyShape {
        observation: arlpcg_core::game::platform::OBSERVATION_SIZE,
        hidden: recipe.hidden.clone(),
        continuous: 2,
        binary: 1,
    };
    let one_epoch = PpoConfig {
        update_epochs: 1,
        learning_rate: 6e-4,
        ..recipe.solver.clone()
    };
    let settings = [
        ("the recipe", recipe.solver.clone()),
        ("one epoch", one_epoch),
    ];
    let mut trainers: Vec<_> = settings
        .iter()
        .map(|(_, ppo)| trainer(&shape, ppo.clone()))
        .collect();
    let start = Instant::now();
    let clock = || start.elapsed().as_secs_f64();
    let mut splits = vec![TimeSplit::default(); settings.len()];
    for round in 0..=6 {
        for (trainer, split) in trainers.iter_mut().zip(&mut splits) {
            let time = iteration(trainer, &clock);
            // The first round warms up.
            if round > 0 {
                split.add(&time);
            }
        }
    }
    let peak = matmul_peak_flops(1024, 5, &clock);
    println!("end-to-end training, 64 worlds x 128 steps, 2 x 512, platform rule levels");
    let mut rates = Vec::new();
    for ((name, ppo), split) in settings.iter().zip(&splits) {
        let steps = 6.0 * ppo.batch_size() as f64;
        let rate = steps / split.total();
        rates.push(rate);
        println!(
            "  {name} ({} epochs x {} minibatches of {}): {rate:.0} env steps/s; {}; update at {:.0}% of the {:.0} GFLOP/s matmul peak",
            ppo.update_epochs,
            ppo.num_minibatches,
            ppo.minibatch_size(),
            split.shares(),
            100.0 * split.update_mfu(peak),
            peak / 1e9
        );
    }
    let verdict = if rates[0] >= 20_000.0 {
        "reached"
    } else {
        "MISSED"
    };
    println!(
        "  one epoch runs {:.2}x the recipe; the recipe's target, 20000 env steps/s: {verdict}",
        rates[1] / rates[0]
    );
}
