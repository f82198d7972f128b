//! A population of players going through a sequence of levels (a campaign), from the levels'
//! difficulty b on the panel's Rasch scale ([`super::rating`]).
//!
//! A player has an ability θ, drawn from Normal(mean, sd) on the same logit scale as the
//! judges' θ, and completes an attempt at a level of difficulty b with chance s = σ(θ − b).
//! After each failed attempt the player tries again with chance `retry`, else quits the
//! campaign. So a player passes a level with chance s / (1 − retry·(1 − s)) and makes
//! 1 / (1 − retry·(1 − s)) attempts on it in expectation. The share of players who reach level
//! k is the population's mean of the product of the earlier levels' pass chances, integrated
//! over θ on a fine grid.

/// Abilities and persistence of a player population.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Population {
    /// Mean ability θ, logits.
    pub theta_mean: f64,
    /// Standard deviation of θ, logits (0: every player alike).
    pub theta_sd: f64,
    /// The chance that a player tries a level again after failing it (else quits).
    pub retry: f64,
}

/// The standard normal's 90th percentile.
const Z90: f64 = 1.281_551_565_545;

/// The chance to try again after a failure when none is given: a player quits after about
/// one failure in four.
pub const DEFAULT_RETRY: f64 = 0.75;

/// The largest mean ability (either sign) and spread of a population, logits: far beyond any
/// judge's θ or level's b (the rating's prior has sd 3), where every player passes or fails
/// every level alike.
pub const MOST_LOGITS: f64 = 50.0;

/// Grid points over θ (±8 sd) for the population's integrals.
const GRID: usize = 2001;

/// How the population fares on one level of the campaign.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelFlow {
    /// The share of all players who reach the level.
    pub reach: f64,
    /// The share of all players who quit on it.
    pub quit: f64,
    /// Of the players who reach it, the share who pass it.
    pub pass: f64,
    /// Attempts made on the level per success on it (by the players who reach it).
    pub attempts_per_success: f64,
}

impl Population {
    /// The population whose 10th, 50th and 90th percentiles of θ are `low`, `middle` and
    /// `high` (e.g. the scripted novice, median and expert): mean `middle`, sd the mean of the
    /// two half-spreads over the normal's 90th percentile.
    pub fn from_percentiles(low: f64, middle: f64, high: f64, retry: f64) -> Self {
        Self {
            theta_mean: middle,
            theta_sd: (((high - middle) + (middle - low)) / 2.0 / Z90).max(0.0),
            retry,
        }
    }

    /// Checks the numbers: the mean within ±[`MOST_LOGITS`], the sd within [0, MOST_LOGITS],
    /// retry within [0, 1). `Err` names the field. `--population` and a campaign file meet
    /// the same limits.
    pub fn check(&self) -> Result<(), String> {
        if !(-MOST_LOGITS..=MOST_LOGITS).contains(&self.theta_mean) {
            return Err(format!(
                "theta_mean {} must be a number within [-{MOST_LOGITS}, {MOST_LOGITS}] (logits)",
                shown(self.theta_mean)
            ));
        }
        if !(0.0..=MOST_LOGITS).contains(&self.theta_sd) {
            return Err(format!(
                "theta_sd {} must be a number within [0, {MOST_LOGITS}] (logits)",
                shown(self.theta_sd)
            ));
        }
        if !(0.0..1.0).contains(&self.retry) {
            return Err(format!(
                "retry {} must be within [0, 1) (1 would retry forever)",
                shown(self.retry)
            ));
        }
        Ok(())
    }

    /// The flow through levels of difficulty `b`, in order.
    pub fn funnel(&self, b: &[f64]) -> Vec<LevelFlow> {
        let grid = self.grid();
        // Each grid point's share of players still playing, level by level.
        let mut playing: Vec<f64> = grid.iter().map(|&(_, w)| w).collect();
        let mut flows = Vec::with_capacity(b.len());
        for &difficulty in b {
            let (mut reach, mut passed, mut attempts) = (0.0, 0.0, 0.0);
            for (share, &(theta, _)) in playing.iter_mut().zip(&grid) {
                let s = sigmoid(theta - difficulty);
                let keep_trying = 1.0 - self.retry * (1.0 - s);
                reach += *share;
                attempts += *share / keep_trying;
                *share *= s / keep_trying;
                passed += *share;
            }
            flows.push(LevelFlow {
                reach,
                quit: reach - passed,
                pass: if reach > 0.0 { passed / reach } else { 0.0 },
                attempts_per_success: if passed > 0.0 {
                    attempts / passed
                } else {
                    f64::INFINITY
                },
            });
        }
        flows
    }

    /// (θ, weight) points whose weights sum to 1: one point when every player is alike.
    fn grid(&self) -> Vec<(f64, f64)> {
        if self.theta_sd == 0.0 {
            return vec![(self.theta_mean, 1.0)];
        }
        let step = 16.0 / (GRID - 1) as f64;
        let points: Vec<(f64, f64)> = (0..GRID)
            .map(|i| {
                let z = -8.0 + i as f64 * step;
                (self.theta_mean + z * self.theta_sd, (-0.5 * z * z).exp())
            })
            .collect();
        let total: f64 = points.iter().map(|p| p.1).sum();
        points.into_iter().map(|(t, w)| (t, w / total)).collect()
    }
}

/// `x` for a message: a huge or tiny number in scientific notation (`1e308`, not 309 digits).
fn shown(x: f64) -> String {
    match x.is_finite() && (x == 0.0 || (1e-6..1e9).contains(&x.abs())) {
        true => format!("{x}"),
        false => format!("{x:e}"),
    }
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_distr::{Distribution, Normal};

    fn close(a: f64, b: f64, tolerance: f64) -> bool {
        (a - b).abs() <= tolerance
    }

    /// Players all alike: a level passed with chance s/(1 − r(1 − s)), 1/s attempts per
    /// success, and the next level reached by exactly the players who passed.
    #[test]
    fn players_alike_follow_the_closed_forms() {
        let population = Population {
            theta_mean: 0.5,
            theta_sd: 0.0,
            retry: 0.6,
        };
        let flows = population.funnel(&[0.0, 1.5]);
        let s = sigmoid(0.5);
        let pass = s / (1.0 - 0.6 * (1.0 - s));
        assert!(close(flows[0].reach, 1.0, 1e-12));
        assert!(close(flows[0].pass, pass, 1e-12), "{flows:?}");
        assert!(close(flows[0].quit, 1.0 - pass, 1e-12));
        assert!(close(flows[0].attempts_per_success, 1.0 / s, 1e-12));
        assert!(close(flows[1].reach, pass, 1e-12));
        let s2 = sigmoid(-1.0);
        assert!(close(flows[1].pass, s2 / (1.0 - 0.6 * (1.0 - s2)), 1e-12));
    }

    /// Without retries, a level as hard as the population's mean ability is passed by half of
    /// it, whatever the spread (σ(θ − b) is odd around b); and the percentiles come back.
    #[test]
    fn a_level_at_the_mean_ability_passes_half_without_retries() {
        for sd in [0.5, 1.0, 3.0] {
            let population = Population {
                theta_mean: -0.7,
                theta_sd: sd,
                retry: 0.0,
            };
            let flow = population.funnel(&[-0.7])[0];
            assert!(close(flow.pass, 0.5, 1e-9), "sd {sd}: {flow:?}");
        }
        let fitted = Population::from_percentiles(-2.0, 0.0, 2.0, 0.5);
        assert!(close(fitted.theta_mean, 0.0, 1e-12));
        assert!(close(fitted.theta_sd * Z90, 2.0, 1e-12));
    }

    /// 10,000 simulated players, each attempt a draw of the level's success for the player's θ,
    /// reach each level of a campaign within 0.02 of the model, and make its attempts per success
    /// within 3%.
    #[test]
    fn simulated_players_agree_with_the_model() {
        let population = Population {
            theta_mean: 1.0,
            theta_sd: 1.5,
            retry: 0.7,
        };
        let b = [-1.0, 0.0, 0.5, 1.0, 1.5, 2.5];
        let model = population.funnel(&b);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let normal = Normal::new(population.theta_mean, population.theta_sd).unwrap();
        let players = 10_000;
        let mut reached = vec![0u32; b.len()];
        let mut attempts = vec![0u32; b.len()];
        let mut successes = vec![0u32; b.len()];
        for _ in 0..players {
            let theta: f64 = normal.sample(&mut rng);
            'levels: for (k, &difficulty) in b.iter().enumerate() {
                reached[k] += 1;
                loop {
                    attempts[k] += 1;
                    if rng.random::<f64>() < sigmoid(theta - difficulty) {
                        successes[k] += 1;
                        break;
                    }
                    if rng.random::<f64>() >= population.retry {
                        break 'levels;
                    }
                }
            }
        }
        for k in 0..b.len() {
            let reach = reached[k] as f64 / players as f64;
            assert!(
                close(reach, model[k].reach, 0.02),
                "level {k}: simulated {reach}, model {}",
                model[k].reach
            );
            let per_success = attempts[k] as f64 / successes[k] as f64;
            assert!(
                close(per_success / model[k].attempts_per_success, 1.0, 0.03),
                "level {k}: simulated {per_success} attempts per success, model {}",
                model[k].attempts_per_success
            );
        }
    }

    #[test]
    fn a_population_out_of_range_is_named_by_its_field() {
        let ok = Population {
            theta_mean: 0.0,
            theta_sd: 1.0,
            retry: 0.5,
        };
        ok.check().unwrap();
        for (population, field) in [
            (Population { retry: 1.0, ..ok }, "retry"),
            (
                Population {
                    theta_sd: -1.0,
                    ..ok
                },
                "theta_sd",
            ),
            (
                Population {
                    theta_mean: f64::NAN,
                    ..ok
                },
                "theta_mean",
            ),
        ] {
            assert!(population.check().unwrap_err().starts_with(field));
        }
    }
}
