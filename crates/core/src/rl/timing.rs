//! Where training time goes: each iteration's seconds split into buckets, measured with a clock
//! the caller lends (the core reads none), and the model-FLOPs arithmetic of the PPO update.

use serde::{Deserialize, Serialize};

use super::policy::PolicyShape;

/// A clock in seconds, lent by the shell; `&|| 0.0` measures nothing.
pub type Clock<'a> = &'a dyn Fn() -> f64;

/// Seconds of an iteration (or of a whole run), by what they were spent on.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSplit {
    /// Stepping the environments: physics, ray casts, observations.
    pub env_s: f64,
    /// The learning agent's forward passes while it plays (actions, values), and those of
    /// the policies that play beside it (earlier Solvers, the frozen Solver).
    pub forward_s: f64,
    /// The Generator's work inside the matches: its decisions (their forward passes) and the
    /// pieces and matches they make.
    pub generator_s: f64,
    /// Advantages and returns.
    pub gae_s: f64,
    /// The PPO update (every epoch and minibatch).
    pub update_s: f64,
    /// Copies into the batch, the observation normalizer, episode bookkeeping, metrics.
    pub copies_s: f64,
    /// Floating-point operations of the update's matrix products (forward and backward).
    pub update_flops: f64,
    /// The same seconds by stretch of the run (none in a split written before they were
    /// counted, and in one iteration's).
    #[serde(default, skip_serializing_if = "Stretches::is_empty")]
    pub stretches: Stretches,
}

/// Wall-clock seconds of a run by stretch: its Solver's phases, its Generator's phases before
/// the finish, the finish (docs/training.md), and the finished pair's own check.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stretches {
    /// The Solver's iterations before the finish (a baseline's every iteration).
    pub solver_phases_s: f64,
    /// The Generator's iterations before the finish.
    pub generator_phases_s: f64,
    /// Both agents' iterations in the finish.
    pub finish_s: f64,
    /// The finished pair's check of its own knob.
    pub own_check_s: f64,
}

/// A stretch of a run ([`Stretches`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stretch {
    /// [`Stretches::solver_phases_s`].
    SolverPhases,
    /// [`Stretches::generator_phases_s`].
    GeneratorPhases,
    /// [`Stretches::finish_s`].
    Finish,
    /// [`Stretches::own_check_s`].
    OwnCheck,
}

impl Stretches {
    /// The stretches by name, in the run's order.
    pub fn named(&self) -> [(&'static str, f64); 4] {
        [
            ("Solver phases", self.solver_phases_s),
            ("Generator phases", self.generator_phases_s),
            ("the finish", self.finish_s),
            ("own check", self.own_check_s),
        ]
    }

    /// Whether no stretch took any time (a split written before stretches were counted).
    pub fn is_empty(&self) -> bool {
        self.named().iter().all(|(_, s)| *s == 0.0)
    }

    /// Adds `seconds` to `stretch`.
    pub fn add(&mut self, stretch: Stretch, seconds: f64) {
        *match stretch {
            Stretch::SolverPhases => &mut self.solver_phases_s,
            Stretch::GeneratorPhases => &mut self.generator_phases_s,
            Stretch::Finish => &mut self.finish_s,
            Stretch::OwnCheck => &mut self.own_check_s,
        } += seconds;
    }

    /// The stretches that took any time, in minutes (`Solver phases 3.8 min, the finish
    /// 9.5 min`).
    pub fn minutes(&self) -> String {
        self.named()
            .iter()
            .filter(|(_, s)| *s > 0.0)
            .map(|(name, s)| format!("{name} {:.1} min", s / 60.0))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl TimeSplit {
    /// The buckets by name, in the order metrics and the progress line use.
    pub fn buckets(&self) -> [(&'static str, f64); 6] {
        [
            ("env", self.env_s),
            ("forward", self.forward_s),
            ("generator", self.generator_s),
            ("gae", self.gae_s),
            ("update", self.update_s),
            ("copies", self.copies_s),
        ]
    }

    /// Seconds in all buckets.
    pub fn total(&self) -> f64 {
        self.buckets().iter().map(|(_, s)| s).sum()
    }

    /// Adds `other`'s seconds and FLOPs to these.
    pub fn add(&mut self, other: &TimeSplit) {
        self.env_s += other.env_s;
        self.forward_s += other.forward_s;
        self.generator_s += other.generator_s;
        self.gae_s += other.gae_s;
        self.update_s += other.update_s;
        self.copies_s += other.copies_s;
        self.update_flops += other.update_flops;
        let (mine, theirs) = (&mut self.stretches, &other.stretches);
        mine.solver_phases_s += theirs.solver_phases_s;
        mine.generator_phases_s += theirs.generator_phases_s;
        mine.finish_s += theirs.finish_s;
        mine.own_check_s += theirs.own_check_s;
    }

    /// The same, seconds rounded to tenths (for a card).
    pub fn rounded(&self) -> TimeSplit {
        let tenth = |s: f64| (s * 10.0).round() / 10.0;
        TimeSplit {
            env_s: tenth(self.env_s),
            forward_s: tenth(self.forward_s),
            generator_s: tenth(self.generator_s),
            gae_s: tenth(self.gae_s),
            update_s: tenth(self.update_s),
            copies_s: tenth(self.copies_s),
            update_flops: self.update_flops,
            stretches: Stretches {
                solver_phases_s: tenth(self.stretches.solver_phases_s),
                generator_phases_s: tenth(self.stretches.generator_phases_s),
                finish_s: tenth(self.stretches.finish_s),
                own_check_s: tenth(self.stretches.own_check_s),
            },
        }
    }

    /// Adds a `seconds`-long [`super::vec_env::VecEnv::step`] whose `inner` work was not the
    /// environments' own.
    pub fn add_step(&mut self, seconds: f64, inner: InnerTime) {
        self.env_s += seconds - inner.generator_s;
        self.generator_s += inner.generator_s;
    }

    /// Every bucket's share of the total (`env 23%, forward 45%, ...`).
    pub fn shares(&self) -> String {
        let total = self.total().max(f64::MIN_POSITIVE);
        self.buckets()
            .iter()
            .map(|(name, s)| format!("{name} {:.0}%", 100.0 * s / total))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The two largest buckets with their shares of the total, as the progress line shows
    /// them (`update 62%, env 21%`).
    pub fn largest_two(&self) -> String {
        let total = self.total().max(f64::MIN_POSITIVE);
        let mut buckets = self.buckets();
        buckets.sort_by(|a, b| b.1.total_cmp(&a.1));
        format!(
            "{} {:.0}%, {} {:.0}%",
            buckets[0].0,
            100.0 * buckets[0].1 / total,
            buckets[1].0,
            100.0 * buckets[1].1 / total
        )
    }

    /// The update's model-FLOPs utilisation: its FLOPs per second over `peak_flops`, the
    /// machine's own matrix-product rate ([`super::fused::matmul_peak_flops`]); 0 without an
    /// update or a peak.
    pub fn update_mfu(&self, peak_flops: f64) -> f64 {
        if self.update_s > 0.0 && peak_flops > 0.0 {
            self.update_flops / self.update_s / peak_flops
        } else {
            0.0
        }
    }
}

/// Laps of a lent clock: each [`Stopwatch::lap`] is the time since the one before.
pub struct Stopwatch<'a> {
    clock: Clock<'a>,
    last: f64,
}

impl<'a> Stopwatch<'a> {
    /// A stopwatch on `clock`, its first lap starting now.
    pub fn new(clock: Clock<'a>) -> Self {
        Self {
            clock,
            last: clock(),
        }
    }

    /// Seconds since the last lap (or the start).
    pub fn lap(&mut self) -> f64 {
        let now = (self.clock)();
        let seconds = now - self.last;
        self.last = now;
        seconds
    }
}

/// Seconds spent inside one `VecEnv::step` on work that is not the environments' own.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InnerTime {
    /// A Generator's decisions and the matches it restarts.
    pub generator_s: f64,
}

/// FLOPs of one sample through the update of a network of `shape`: per dense layer of
/// `in × out`, 2·in·out forward, 2·in·out for the weights' gradient and 2·in·out for the
/// input's (none for the first layer, whose input is the observation), actor and critic.
pub fn update_flops_per_sample(shape: &PolicyShape) -> f64 {
    let network = |out: usize| {
        let sizes = shape.layer_sizes(out);
        let products: Vec<f64> = sizes.windows(2).map(|w| (w[0] * w[1]) as f64).collect();
        6.0 * products.iter().sum::<f64>() - 2.0 * products.first().copied().unwrap_or(0.0)
    };
    network(shape.action_size()) + network(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_buckets_and_the_mfu_read_off_the_split() {
        let split = TimeSplit {
            env_s: 2.0,
            forward_s: 1.0,
            update_s: 6.0,
            copies_s: 1.0,
            update_flops: 3e11,
            ..TimeSplit::default()
        };
        assert_eq!(split.total(), 10.0);
        assert_eq!(split.largest_two(), "update 60%, env 20%");
        assert!((split.update_mfu(1e11) - 0.5).abs() < 1e-12);
        assert_eq!(TimeSplit::default().update_mfu(1e11), 0.0);
    }

    #[test]
    fn update_flops_count_every_layer_of_both_networks() {
        let shape = PolicyShape {
            observation: 10,
            hidden: vec![4],
            continuous: 2,
            binary: 0,
        };
        // Actor 10·4 + 4·2 (a log-std takes no product), critic 10·4 + 4·1.
        let actor = 6.0 * (40.0 + 8.0) - 2.0 * 40.0;
        let critic = 6.0 * (40.0 + 4.0) - 2.0 * 40.0;
        assert_eq!(update_flops_per_sample(&shape), actor + critic);
    }
}
