//! Running observation normalization (mean and variance over everything seen, merged batch by
//! batch with Chan's parallel algorithm), as in CleanRL's `NormalizeObservation`.

use serde::{Deserialize, Serialize};

/// Normalized observations are clipped to this many standard deviations.
pub const CLIP: f32 = 10.0;

/// Per-feature running mean and variance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunningNorm {
    /// Each feature's running mean.
    pub mean: Vec<f64>,
    /// Each feature's running variance.
    pub var: Vec<f64>,
    /// How many rows the statistics hold (starts at 1e-4).
    pub count: f64,
}

impl RunningNorm {
    /// A normalizer of `size` features that has seen nothing: mean 0, variance 1.
    pub fn new(size: usize) -> Self {
        Self {
            mean: vec![0.0; size],
            var: vec![1.0; size],
            count: 1e-4,
        }
    }

    /// How many features it normalizes.
    pub fn size(&self) -> usize {
        self.mean.len()
    }

    /// Folds a batch of rows (`rows.len()` a multiple of the feature count) into the statistics.
    pub fn update(&mut self, rows: &[f32]) {
        let d = self.size();
        let n = rows.len() / d;
        if n == 0 {
            return;
        }
        for k in 0..d {
            let column = rows.iter().skip(k).step_by(d).map(|&x| x as f64);
            let batch_mean = column.clone().sum::<f64>() / n as f64;
            let batch_var = column.map(|x| (x - batch_mean).powi(2)).sum::<f64>() / n as f64;
            let delta = batch_mean - self.mean[k];
            let total = self.count + n as f64;
            self.mean[k] += delta * n as f64 / total;
            let m2 = self.var[k] * self.count
                + batch_var * n as f64
                + delta * delta * self.count * n as f64 / total;
            self.var[k] = m2 / total;
        }
        self.count += n as f64;
    }

    /// Normalizes rows in place: `(x - mean) / sqrt(var + 1e-8)`, clipped to ±`CLIP`.
    pub fn normalize(&self, rows: &mut [f32]) {
        let d = self.size();
        let scale: Vec<f64> = self.var.iter().map(|v| 1.0 / (v + 1e-8).sqrt()).collect();
        for row in rows.chunks_mut(d) {
            for ((x, m), s) in row.iter_mut().zip(&self.mean).zip(&scale) {
                *x = (((*x as f64 - m) * s) as f32).clamp(-CLIP, CLIP);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_merge_to_the_statistics_of_the_whole() {
        let data: Vec<f32> = (0..200).map(|i| ((i * 37) % 101) as f32 * 0.1).collect();
        let mut batched = RunningNorm::new(2);
        for chunk in data.chunks(20) {
            batched.update(chunk);
        }
        let column: Vec<f64> = data.iter().step_by(2).map(|&x| x as f64).collect();
        let mean = column.iter().sum::<f64>() / 100.0;
        let var = column.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 100.0;
        assert!(
            (batched.mean[0] - mean).abs() < 1e-4,
            "{} vs {mean}",
            batched.mean[0]
        );
        assert!(
            (batched.var[0] - var).abs() / var < 1e-4,
            "{} vs {var}",
            batched.var[0]
        );
        let mut row = [mean as f32, 1e9];
        batched.normalize(&mut row);
        assert!(row[0].abs() < 1e-3 && row[1] == CLIP);
    }
}
