//! Speed of the PPO update of the paper's 2 × 512 actor-critic, beside this machine's own large
//! f32 matmul throughput measured in the same run (so the ratio holds on a noisy shared machine).
//!
//! Run with `cargo bench --bench ppo_update` (`RAYON_NUM_THREADS=T` for T threads). Target:
//! 30,000 samples per second per epoch on 2 threads, what PyTorch's CPU update of the same
//! network and batch reaches on 2 threads (`docs/perf/torch_ppo_update.py`).
#![allow(clippy::unwrap_used)] // a measurement or a test may unwrap (Cargo.toml, [lints])

use std::time::Instant;

use arlpcg_core::rl::policy::{ActorCritic, PolicyShape};
use arlpcg_core::rl::ppo::{Batch, Ppo, PpoConfig};
use candle_core::{Device, Tensor};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// GFLOP/s of an n × n × n f32 matmul in candle (best of a few).
fn matmul_gflops(n: usize) -> f64 {
    let a = Tensor::ones((n, n), candle_core::DType::F32, &Device::Cpu).unwrap();
    let b = Tensor::ones((n, n), candle_core::DType::F32, &Device::Cpu).unwrap();
    let mut best = 0.0f64;
    for _ in 0..5 {
        let start = Instant::now();
        let c = a.matmul(&b).unwrap();
        let _ = c.sum_all().unwrap().to_scalar::<f32>().unwrap();
        best = best.max(2.0 * (n as f64).powi(3) / start.elapsed().as_secs_f64() / 1e9);
    }
    best
}

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    let shape = PolicyShape {
        observation: 40,
        hidden: vec![512, 512],
        continuous: 2,
        binary: 1,
    };
    let config = PpoConfig {
        num_envs: 64,
        num_steps: 128,
        update_epochs: 1,
        num_minibatches: 4,
        ..PpoConfig::default()
    };
    let n = config.batch_size();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut random = |len: usize| {
        (0..len)
            .map(|_| rng.random_range(-1.0f32..1.0))
            .collect::<Vec<f32>>()
    };
    let batch = Batch {
        observations: random(n * shape.observation),
        actions: random(n * 3)
            .chunks(3)
            .flat_map(|a| [a[0], a[1], if a[2] > 0.0 { 1.0 } else { 0.0 }])
            .collect(),
        log_probs: random(n).iter().map(|x| x - 3.0).collect(),
        advantages: random(n),
        returns: random(n),
        values: random(n),
    };
    let mut ppo = Ppo::new(config.clone(), ActorCritic::new(shape.clone(), 0).unwrap()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    ppo.update(&batch, 1e-4, &mut rng).unwrap(); // warm up
    let epochs = 5;
    let start = Instant::now();
    for _ in 0..epochs {
        ppo.update(&batch, 1e-4, &mut rng).unwrap();
    }
    let rate = (epochs * n) as f64 / start.elapsed().as_secs_f64();
    // Forward 2·in·out and backward 4·in·out multiply-adds per layer, actor and critic.
    let layers = |out: usize| {
        let sizes = shape.layer_sizes(out);
        sizes.windows(2).map(|w| w[0] * w[1]).sum::<usize>()
    };
    let flops_per_sample = 6.0 * (layers(shape.action_size()) + layers(1)) as f64;
    let achieved = rate * flops_per_sample / 1e9;
    let peak = matmul_gflops(2048);
    println!(
        "PPO update, 2 x 512 actor-critic, minibatch {}: {rate:.0} samples/s per epoch",
        config.minibatch_size()
    );
    println!(
        "  {:.1} GFLOP/s in the update vs {peak:.1} GFLOP/s for a 2048^3 matmul: {:.0}% of the machine's matmul peak",
        achieved,
        100.0 * achieved / peak
    );
    let threads = rayon::current_num_threads();
    if threads == 2 {
        let verdict = if rate >= 30_000.0 {
            "reached"
        } else {
            "MISSED"
        };
        println!("  2 threads; target 30000 samples/s per epoch: {verdict}");
    } else {
        println!("  {threads} threads (the target, 30000 samples/s per epoch, is for 2)");
    }
}
