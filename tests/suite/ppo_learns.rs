//! PPO learns tasks whose solutions are known, with fixed seeds: CartPole (Gymnasium's
//! CartPole-v1 dynamics, the binary action head) and a continuous tracking task whose optimum is
//! known exactly (the Gaussian head).

use arlpcg_core::rl::policy::{ActMode, ActorCritic, PolicyShape};
use arlpcg_core::rl::ppo::{Ppo, PpoConfig};
use arlpcg_core::rl::vec_env::{Trainer, Transition, VecEnv};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Gymnasium's CartPole-v1: Euler integration at 50 Hz, ±10 N, fail past 12° or 2.4 m, 500 steps.
struct CartPole {
    state: [f32; 4],
    steps: u32,
    rng: ChaCha8Rng,
}

impl CartPole {
    fn new(seed: u64) -> Self {
        let mut env = Self {
            state: [0.0; 4],
            steps: 0,
            rng: ChaCha8Rng::seed_from_u64(seed),
        };
        env.reset();
        env
    }

    fn reset(&mut self) {
        for s in &mut self.state {
            *s = self.rng.random_range(-0.05..0.05);
        }
        self.steps = 0;
    }

    /// Returns (reward, ended).
    fn step(&mut self, push_right: bool) -> (f32, bool) {
        let (gravity, mass_cart, mass_pole, length, force_mag, tau) =
            (9.8f32, 1.0f32, 0.1f32, 0.5f32, 10.0f32, 0.02f32);
        let total_mass = mass_cart + mass_pole;
        let pole_mass_length = mass_pole * length;
        let [x, x_dot, theta, theta_dot] = self.state;
        let force = if push_right { force_mag } else { -force_mag };
        let (sin, cos) = theta.sin_cos();
        let temp = (force + pole_mass_length * theta_dot * theta_dot * sin) / total_mass;
        let theta_acc = (gravity * sin - cos * temp)
            / (length * (4.0 / 3.0 - mass_pole * cos * cos / total_mass));
        let x_acc = temp - pole_mass_length * theta_acc * cos / total_mass;
        self.state = [
            x + tau * x_dot,
            x_dot + tau * x_acc,
            theta + tau * theta_dot,
            theta_dot + tau * theta_acc,
        ];
        self.steps += 1;
        let fell = self.state[0].abs() > 2.4 || self.state[2].abs() > 12f32.to_radians();
        (1.0, fell || self.steps >= 500)
    }
}

struct CartPoles(Vec<CartPole>);

impl VecEnv for CartPoles {
    fn num_envs(&self) -> usize {
        self.0.len()
    }
    fn observation_size(&self) -> usize {
        4
    }
    fn observe(&mut self, out: &mut [f32]) {
        for (env, row) in self.0.iter().zip(out.chunks_mut(4)) {
            row.copy_from_slice(&env.state);
        }
    }
    fn step(&mut self, actions: &[f32], out: &mut [Transition]) {
        for ((env, action), t) in self.0.iter_mut().zip(actions).zip(out.iter_mut()) {
            let (reward, ended) = env.step(*action > 0.5);
            if ended {
                env.reset();
            }
            *t = Transition {
                reward,
                ended,
                success: None,
            };
        }
    }
}

/// Mean return of the deterministic policy over `episodes` fresh episodes.
fn evaluate_cartpole(trainer: &mut Trainer<CartPoles>, episodes: u64) -> f32 {
    let mut total = 0.0;
    for seed in 0..episodes {
        let mut env = CartPole::new(10_000 + seed);
        loop {
            let mut obs = env.state.to_vec();
            trainer.norm.normalize(&mut obs);
            let acted = trainer
                .ppo
                .policy
                .act(&obs, ActMode::Deterministic, &mut trainer.rng)
                .unwrap();
            let (reward, ended) = env.step(acted.actions[0] > 0.5);
            total += reward;
            if ended {
                break;
            }
        }
    }
    total / episodes as f32
}

#[test]
fn ppo_balances_cartpole() {
    let config = PpoConfig {
        learning_rate: 2.5e-3,
        num_envs: 8,
        num_steps: 128,
        update_epochs: 4,
        num_minibatches: 4,
        ent_coef: 0.01,
        ..PpoConfig::default()
    };
    let shape = PolicyShape {
        observation: 4,
        hidden: vec![64, 64],
        continuous: 0,
        binary: 1,
    };
    let ppo = Ppo::new(config.clone(), ActorCritic::new(shape, 1).unwrap()).unwrap();
    let envs = CartPoles((0..config.num_envs as u64).map(CartPole::new).collect());
    let mut trainer = Trainer::new(ppo, envs, 1);
    let iterations = 120; // 122,880 steps
    let mut best = 0.0f32;
    for i in 0..iterations {
        let (batch, _, _) = trainer.collect(&|| 0.0).unwrap();
        let lr = config.learning_rate * (1.0 - i as f64 / iterations as f64);
        trainer.learn(&batch, lr).unwrap();
        if i >= 40 && i % 10 == 9 {
            best = best.max(evaluate_cartpole(&mut trainer, 10));
            if best >= 475.0 {
                break;
            }
        }
    }
    assert!(
        best >= 475.0,
        "CartPole mean return {best} after {} steps",
        trainer.global_step
    );
}

/// Each step shows a target in [-1, 1]²; the action should equal it. Reward -|a - target|², so
/// the optimum is 0 per step (a random policy scores about -2.7 with actions clipped to ±1).
struct Tracking {
    targets: Vec<[f32; 2]>,
    steps: Vec<u32>,
    rng: ChaCha8Rng,
}

impl VecEnv for Tracking {
    fn num_envs(&self) -> usize {
        self.targets.len()
    }
    fn observation_size(&self) -> usize {
        2
    }
    fn observe(&mut self, out: &mut [f32]) {
        for (t, row) in self.targets.iter().zip(out.chunks_mut(2)) {
            row.copy_from_slice(t);
        }
    }
    fn step(&mut self, actions: &[f32], out: &mut [Transition]) {
        for e in 0..self.targets.len() {
            let a = [
                actions[2 * e].clamp(-1.0, 1.0),
                actions[2 * e + 1].clamp(-1.0, 1.0),
            ];
            let t = self.targets[e];
            let reward = -((a[0] - t[0]).powi(2) + (a[1] - t[1]).powi(2));
            self.steps[e] += 1;
            let ended = self.steps[e] == 8;
            if ended {
                self.steps[e] = 0;
            }
            self.targets[e] = [
                self.rng.random_range(-1.0..1.0),
                self.rng.random_range(-1.0..1.0),
            ];
            out[e] = Transition {
                reward,
                ended,
                success: None,
            };
        }
    }
}

#[test]
fn ppo_learns_a_continuous_task_to_its_known_optimum() {
    let config = PpoConfig {
        learning_rate: 3e-3,
        num_envs: 8,
        num_steps: 64,
        gamma: 0.0,
        ..PpoConfig::default()
    };
    let shape = PolicyShape {
        observation: 2,
        hidden: vec![32, 32],
        continuous: 2,
        binary: 0,
    };
    let ppo = Ppo::new(config.clone(), ActorCritic::new(shape, 2).unwrap()).unwrap();
    let envs = Tracking {
        targets: vec![[0.5, -0.5]; 8],
        steps: vec![0; 8],
        rng: ChaCha8Rng::seed_from_u64(2),
    };
    let mut trainer = Trainer::new(ppo, envs, 2);
    let iterations = 150;
    for i in 0..iterations {
        let (batch, _, _) = trainer.collect(&|| 0.0).unwrap();
        trainer
            .learn(
                &batch,
                config.learning_rate * (1.0 - i as f64 / iterations as f64),
            )
            .unwrap();
    }
    // The deterministic policy's mean squared error on fresh targets.
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let targets: Vec<f32> = (0..400).map(|_| rng.random_range(-0.9..0.9)).collect();
    let mut obs = targets.clone();
    trainer.norm.normalize(&mut obs);
    let acted = trainer
        .ppo
        .policy
        .act(&obs, ActMode::Deterministic, &mut rng)
        .unwrap();
    let mse: f32 = acted
        .actions
        .iter()
        .zip(&targets)
        .map(|(a, t)| (a - t).powi(2))
        .sum::<f32>()
        / 200.0;
    assert!(mse < 0.01, "squared error per step {mse}, optimum 0");
}
