//! End-to-end training speed of the platform Solver: rollouts over 64 parallel worlds plus PPO
//! updates, in environment steps per second, with where the time goes (the buckets `train`
//! logs) and the update's share of this machine's matmul peak. The recipe (`TrainConfig`'s
//! defaults) runs beside the first prototype's settings (the paper's 2 × 512 actor-critic, four
//! update epochs) on today's code, alternating, so that the ratio is measured in one run on one
//! machine; the prototype itself measured 3,500-4,600 env steps/s (2026-11-22).
//!
//! Then a Generator phase's playing tick at the recipe's width: the current Solver and four
//! snapshots share 64 matches; the Solver run on every row and the snapshots one after another
//! (as before 2026-11-29), beside the Solver run on its own rows and the actors side by side
//! (now).
//!
//! Run with `cargo bench --bench train_e2e`. Target: the recipe at 4.5x the prototype's
//! 4,600 env steps/s (20,700).
#![allow(clippy::unwrap_used)] // a measurement or a test may unwrap (Cargo.toml, [lints])

use std::time::Instant;

use arlpcg::services::train::solver_envs::{SolverEnvs, SolverMode, SourceRecord};
use arlpcg::services::train::{SOLO_SOLVER_UPDATE_EPOCHS, TrainConfig};
use arlpcg_core::game::PlatformGame;
use arlpcg_core::rl::fused::matmul_peak_flops;
use arlpcg_core::rl::policy::{ActMode, ActorCritic, PolicyShape};
use arlpcg_core::rl::ppo::{Ppo, PpoConfig};
use arlpcg_core::rl::timing::TimeSplit;
use arlpcg_core::rl::vec_env::Trainer;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A trainer of the platform Solver on rule levels with these PPO settings.
fn trainer(shape: &PolicyShape, ppo: PpoConfig) -> Trainer<SolverEnvs<PlatformGame>> {
    let envs = SolverEnvs::<PlatformGame>::new(
        SolverMode::RulePcg,
        ppo.num_envs,
        SourceRecord::default(),
        shape.action_size(),
        (Default::default(), None),
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

/// The platform Solver's network with `hidden` layers.
fn shape(hidden: Vec<usize>) -> PolicyShape {
    PolicyShape {
        observation: arlpcg_core::game::platform::OBSERVATION_SIZE,
        hidden,
        continuous: 2,
        binary: 1,
    }
}

/// The first prototype's end-to-end figure, env steps per second (README of 2026-11-22: 3,500-4,600).
const PROTOTYPE_STEPS_PER_S: f64 = 4_600.0;

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let recipe = TrainConfig::default();
    let prototype = PpoConfig {
        update_epochs: SOLO_SOLVER_UPDATE_EPOCHS,
        ..recipe.solver.clone()
    };
    let settings = [
        (
            "the prototype's 2 x 512, 4 epochs",
            shape(vec![512, 512]),
            prototype,
        ),
        (
            "the recipe",
            shape(recipe.hidden.clone()),
            recipe.solver.clone(),
        ),
    ];
    let mut trainers: Vec<_> = settings
        .iter()
        .map(|(_, shape, ppo)| trainer(shape, ppo.clone()))
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
    println!("end-to-end training, 64 worlds x 128 steps, platform rule levels");
    let mut rates = Vec::new();
    for ((name, shape, ppo), split) in settings.iter().zip(&splits) {
        let steps = 6.0 * ppo.batch_size() as f64;
        let rate = steps / split.total();
        rates.push(rate);
        println!(
            "  {name} (hidden {:?}, {} epochs x {} minibatches of {}): {rate:.0} env steps/s; {}; update at {:.0}% of the {:.0} GFLOP/s matmul peak",
            shape.hidden,
            ppo.update_epochs,
            ppo.num_minibatches,
            ppo.minibatch_size(),
            split.shares(),
            100.0 * split.update_mfu(peak),
            peak / 1e9
        );
    }
    let target = 4.5 * PROTOTYPE_STEPS_PER_S;
    println!(
        "  the recipe runs {:.2}x the prototype's settings here and {:.1}x the prototype's {PROTOTYPE_STEPS_PER_S:.0} env steps/s; the target, 4.5x ({target:.0}): {}",
        rates[1] / rates[0],
        rates[1] / PROTOTYPE_STEPS_PER_S,
        if rates[1] >= target {
            "reached"
        } else {
            "MISSED"
        }
    );
    playing_tick(&settings[1].1);
}

/// Seconds per playing tick of a Generator phase, played both ways, alternating.
fn playing_tick(shape: &PolicyShape) {
    let policies: Vec<ActorCritic> = (0..5)
        .map(|seed| ActorCritic::new(shape.clone(), seed).unwrap())
        .collect();
    let d = shape.observation;
    let observations: Vec<f32> = (0..64 * d).map(|i| (i as f32 * 0.37).sin()).collect();
    // Match i is played by policy i % 5 (0: the current Solver).
    let played: Vec<bool> = (0..64).map(|i| i % 5 == 0).collect();
    let rows_of = |k: usize| -> Vec<f32> {
        (0..64)
            .filter(|i| i % 5 == k)
            .flat_map(|i| observations[i * d..(i + 1) * d].to_vec())
            .collect()
    };
    let snapshot_rows: Vec<Vec<f32>> = (1..5).map(rows_of).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let (mut before, mut now) = (0.0, 0.0);
    for _ in 0..10 {
        let start = Instant::now();
        for _ in 0..100 {
            policies[0]
                .choose(&observations, ActMode::Sample, &mut rng)
                .unwrap();
            for (policy, rows) in policies[1..].iter().zip(&snapshot_rows) {
                policy.choose(rows, ActMode::Sample, &mut rng).unwrap();
            }
        }
        before += start.elapsed().as_secs_f64() / 100.0;
        let start = Instant::now();
        for _ in 0..100 {
            let learner_rows = rows_of(0);
            let players: Vec<(&ActorCritic, &[f32])> = std::iter::once(&learner_rows)
                .chain(&snapshot_rows)
                .zip(&policies)
                .map(|(rows, policy)| (policy, &rows[..]))
                .collect();
            let mut heads = ActorCritic::heads(&players).unwrap().into_iter();
            policies[0]
                .draw_rows(heads.next().unwrap(), &played, ActMode::Sample, &mut rng)
                .unwrap();
            for ((policy, rows), head) in players[1..].iter().zip(heads) {
                let every_row = vec![true; rows.len() / d];
                policy
                    .draw_rows(head, &every_row, ActMode::Sample, &mut rng)
                    .unwrap();
            }
        }
        now += start.elapsed().as_secs_f64() / 100.0;
    }
    println!(
        "a Generator phase's playing tick (the Solver and 4 snapshots over 64 matches): {:.0} us before, {:.0} us now ({:.2}x)",
        before * 1e5,
        now * 1e5,
        before / now
    );
}
