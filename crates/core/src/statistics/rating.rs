//! A difficulty rating that belongs to no single player: the one-parameter logistic (Rasch, item
//! response) model over judges × levels, P(judge j completes level i) = σ(θ_j − b_i), fitted to
//! how many of each judge's runs succeeded on each level. θ is a judge's ability, b a level's
//! difficulty, both in logits: a level with b one higher halves the odds of every judge.
//!
//! The fit is the posterior mode under a weak normal prior (mean 0, sd [`PRIOR_SD`]) on every θ
//! and b, found by alternating one-dimensional Newton steps; the prior keeps a judge that never
//! fails, or a level nobody completes, at a finite value. Only differences θ − b are measured, so
//! the prior's centre sets where 0 lies. A level's interval is b ± 1.96 standard errors from
//! the curvature of its log-posterior, the judges' θ held at their estimates.

/// Standard deviation of the prior on every θ and b, logits.
pub const PRIOR_SD: f64 = 3.0;

/// Successes out of trials for every judge on every level.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcomes {
    /// How many judges.
    pub judges: usize,
    /// How many levels.
    pub levels: usize,
    /// `[judge * levels + level]`: runs that succeeded...
    pub successes: Vec<u32>,
    /// ...out of these (0: the judge did not play the level).
    pub trials: Vec<u32>,
}

impl Outcomes {
    /// No runs yet: every judge has 0 trials on every level.
    pub fn new(judges: usize, levels: usize) -> Self {
        Self {
            judges,
            levels,
            successes: vec![0; judges * levels],
            trials: vec![0; judges * levels],
        }
    }

    /// Records a judge's runs on a level (successes capped at trials).
    pub fn set(&mut self, judge: usize, level: usize, successes: u32, trials: u32) {
        let k = judge * self.levels + level;
        self.successes[k] = successes.min(trials);
        self.trials[k] = trials;
    }

    fn cell(&self, judge: usize, level: usize) -> (f64, f64) {
        let k = judge * self.levels + level;
        (self.successes[k] as f64, self.trials[k] as f64)
    }
}

/// A fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// Each judge's ability, logits.
    pub theta: Vec<f64>,
    /// Each level's difficulty, logits...
    pub b: Vec<f64>,
    /// ...and its 95% interval.
    pub b_ci95: Vec<[f64; 2]>,
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// Fits θ and b to `outcomes` (sweeps until no value moves by more than 1e-9, at most 500).
pub fn fit(outcomes: &Outcomes) -> Fit {
    let precision = 1.0 / (PRIOR_SD * PRIOR_SD);
    let mut theta = vec![0.0; outcomes.judges];
    let mut b = vec![0.0; outcomes.levels];
    for _ in 0..500 {
        let mut moved: f64 = 0.0;
        for (j, t) in theta.iter_mut().enumerate() {
            // d/dθ log-posterior = Σ (s − n p) − θ/σ²; d² = −Σ n p (1 − p) − 1/σ².
            let (mut gradient, mut curvature) = (-*t * precision, precision);
            for (i, bi) in b.iter().enumerate() {
                let (s, n) = outcomes.cell(j, i);
                let p = sigmoid(*t - bi);
                gradient += s - n * p;
                curvature += n * p * (1.0 - p);
            }
            let step = (gradient / curvature).clamp(-2.0, 2.0);
            *t += step;
            moved = moved.max(step.abs());
        }
        for (i, bi) in b.iter_mut().enumerate() {
            let (gradient, curvature) = level_slope(outcomes, &theta, i, *bi, precision);
            let step = (gradient / curvature).clamp(-2.0, 2.0);
            *bi += step;
            moved = moved.max(step.abs());
        }
        if moved < 1e-9 {
            break;
        }
    }
    let b_ci95 = b
        .iter()
        .enumerate()
        .map(|(i, &bi)| {
            let (_, curvature) = level_slope(outcomes, &theta, i, bi, precision);
            let half = 1.96 / curvature.sqrt();
            [bi - half, bi + half]
        })
        .collect();
    Fit { theta, b, b_ci95 }
}

/// The log-posterior's slope in `b` of level `i` (toward higher b) and its curvature (positive).
fn level_slope(outcomes: &Outcomes, theta: &[f64], i: usize, b: f64, precision: f64) -> (f64, f64) {
    let (mut gradient, mut curvature) = (-b * precision, precision);
    for (j, t) in theta.iter().enumerate() {
        let (s, n) = outcomes.cell(j, i);
        let p = sigmoid(t - b);
        gradient += n * p - s;
        curvature += n * p * (1.0 - p);
    }
    (gradient, curvature)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Outcomes drawn from known θ and b, `trials` runs per cell.
    fn draw(theta: &[f64], b: &[f64], trials: u32, seed: u64) -> Outcomes {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut outcomes = Outcomes::new(theta.len(), b.len());
        for (j, t) in theta.iter().enumerate() {
            for (i, bi) in b.iter().enumerate() {
                let p = sigmoid(t - bi);
                let s = (0..trials).filter(|_| rng.random_bool(p)).count() as u32;
                outcomes.set(j, i, s, trials);
            }
        }
        outcomes
    }

    #[test]
    fn recovers_known_abilities_and_difficulties() {
        let theta = [-1.5, -0.5, 0.0, 0.8, 2.0];
        let b: Vec<f64> = (0..40).map(|i| -2.0 + 4.0 * i as f64 / 39.0).collect();
        let fit = fit(&draw(&theta, &b, 200, 7));
        // Only θ − b is measured: compare with both shifted so the judges' mean is 0.
        let shift = |v: &[f64], by: f64| v.iter().map(|x| x - by).collect::<Vec<_>>();
        let truth_mean = theta.iter().sum::<f64>() / theta.len() as f64;
        let fit_mean = fit.theta.iter().sum::<f64>() / theta.len() as f64;
        for (got, want) in shift(&fit.theta, fit_mean)
            .iter()
            .zip(shift(&theta, truth_mean))
        {
            assert!((got - want).abs() < 0.1, "θ {got:.3} vs {want:.3}");
        }
        let mut covered = 0;
        for ((got, ci), want) in shift(&fit.b, fit_mean)
            .iter()
            .zip(&fit.b_ci95)
            .zip(shift(&b, truth_mean))
        {
            assert!((got - want).abs() < 0.3, "b {got:.3} vs {want:.3}");
            covered += usize::from(ci[0] - fit_mean <= want && want <= ci[1] - fit_mean);
        }
        // A 95% interval covers the truth for most of the 40 levels.
        assert!(covered >= 34, "{covered} of 40 intervals cover the true b");
    }

    #[test]
    fn harder_levels_rate_higher_and_perfect_scores_stay_finite() {
        let mut outcomes = Outcomes::new(2, 3);
        for j in 0..2 {
            outcomes.set(j, 0, 50, 50);
            outcomes.set(j, 1, 25, 50);
            outcomes.set(j, 2, 0, 50);
        }
        let fit = fit(&outcomes);
        assert!(fit.b[0] < fit.b[1] && fit.b[1] < fit.b[2], "{:?}", fit.b);
        assert!(
            fit.b
                .iter()
                .chain(&fit.theta)
                .all(|x| x.is_finite() && x.abs() < 15.0)
        );
        for (b, ci) in fit.b.iter().zip(&fit.b_ci95) {
            assert!(ci[0] < *b && *b < ci[1]);
        }
    }

    #[test]
    fn a_judge_that_played_nothing_changes_no_difficulty() {
        let mut two = Outcomes::new(2, 2);
        let mut three = Outcomes::new(3, 2);
        for (j, i, s) in [(0, 0, 30), (0, 1, 10), (1, 0, 35), (1, 1, 20)] {
            two.set(j, i, s, 40);
            three.set(j, i, s, 40);
        }
        let (a, b) = (fit(&two), fit(&three));
        for (x, y) in a.b.iter().zip(&b.b) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
        assert_eq!(b.theta[2], 0.0, "the prior's centre");
    }
}
