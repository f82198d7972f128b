//! Adam over the policy's flat parameter vector (see [`super::fused`]), one fused pass split
//! across rayon's threads, with its moments exposed as named tensors so that a checkpoint can
//! store and restore them.

use std::collections::HashMap;

use candle_core::{Device, Tensor, Var};
use rayon::prelude::*;

use super::fused::PARAM_CHUNK;

/// Adam's state: step count and first and second moments per parameter.
#[derive(Clone)]
pub struct Adam {
    /// Decay of the first moment.
    pub beta1: f64,
    /// Decay of the second moment.
    pub beta2: f64,
    /// Added to the second moment's root in the denominator.
    pub eps: f64,
    /// Updates taken so far, for the bias correction.
    pub step: u64,
    first: Vec<f32>,
    second: Vec<f32>,
}

impl Adam {
    /// Zeroed moments for `vars` (CleanRL's eps of 1e-5).
    pub fn new(vars: &[(String, Var)]) -> Self {
        let len = vars.iter().map(|(_, v)| v.as_tensor().elem_count()).sum();
        Self {
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-5,
            step: 0,
            first: vec![0.0; len],
            second: vec![0.0; len],
        }
    }

    /// One update of every parameter with its gradient times `grad_scale` (gradient-norm
    /// clipping). Each element is independent of the others: no result depends on the threads.
    pub fn apply(
        &mut self,
        params: &mut [f32],
        gradients: &[f32],
        learning_rate: f64,
        grad_scale: f64,
    ) {
        assert_eq!(params.len(), self.first.len());
        assert_eq!(gradients.len(), self.first.len());
        self.step += 1;
        let (beta1, beta2) = (self.beta1 as f32, self.beta2 as f32);
        let correction1 = (1.0 - self.beta1.powi(self.step as i32)) as f32;
        let correction2 = (1.0 - self.beta2.powi(self.step as i32)) as f32;
        let (rate, scale, eps) = (learning_rate as f32, grad_scale as f32, self.eps as f32);
        params
            .par_chunks_mut(PARAM_CHUNK)
            .zip(gradients.par_chunks(PARAM_CHUNK))
            .zip(self.first.par_chunks_mut(PARAM_CHUNK))
            .zip(self.second.par_chunks_mut(PARAM_CHUNK))
            .for_each(|(((p, g), m), v)| {
                for (((p, g), m), v) in p.iter_mut().zip(g).zip(m).zip(v) {
                    let g = g * scale;
                    *m = beta1 * *m + (1.0 - beta1) * g;
                    *v = beta2 * *v + (1.0 - beta2) * g * g;
                    *p -= rate * (*m / correction1) / ((*v / correction2).sqrt() + eps);
                }
            });
    }

    /// The moments as named tensors (`adam.m.<var>`, `adam.v.<var>`), shaped as their vars.
    pub fn named_state(&self, vars: &[(String, Var)]) -> Vec<(String, Tensor)> {
        let mut offset = 0;
        let mut state = Vec::with_capacity(2 * vars.len());
        for (name, var) in vars {
            let (len, dims) = (var.as_tensor().elem_count(), var.as_tensor().dims());
            for (prefix, moments) in [("m", &self.first), ("v", &self.second)] {
                let tensor = Tensor::from_slice(&moments[offset..offset + len], dims, &Device::Cpu)
                    .expect("moments are laid out as their vars");
                state.push((format!("adam.{prefix}.{name}"), tensor));
            }
            offset += len;
        }
        state
    }

    /// Restores the moments saved by [`Adam::named_state`].
    pub fn restore(
        &mut self,
        vars: &[(String, Var)],
        tensors: &HashMap<String, Tensor>,
        step: u64,
    ) -> Result<(), String> {
        let mut offset = 0;
        for (name, var) in vars {
            let len = var.as_tensor().elem_count();
            for (prefix, moments) in [("m", &mut self.first), ("v", &mut self.second)] {
                let key = format!("adam.{prefix}.{name}");
                let saved = tensors
                    .get(&key)
                    .ok_or_else(|| format!("missing optimizer tensor `{key}`"))?;
                if saved.dims() != var.as_tensor().dims() {
                    return Err(format!(
                        "optimizer tensor `{key}` has shape {:?}, expected {:?}",
                        saved.dims(),
                        var.as_tensor().dims()
                    ));
                }
                let values = saved
                    .flatten_all()
                    .and_then(|t| t.to_vec1::<f32>())
                    .map_err(|e| format!("optimizer tensor `{key}`: {e}"))?;
                moments[offset..offset + len].copy_from_slice(&values);
            }
            offset += len;
        }
        self.step = step;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::DType;

    fn vars() -> Vec<(String, Var)> {
        vec![
            (
                "w".to_string(),
                Var::ones((4, 3), DType::F32, &Device::Cpu).unwrap(),
            ),
            (
                "b".to_string(),
                Var::ones((1, 3), DType::F32, &Device::Cpu).unwrap(),
            ),
        ]
    }

    #[test]
    fn each_step_moves_a_weight_by_about_the_learning_rate_downhill() {
        let mut adam = Adam::new(&vars());
        let mut params = vec![1.0f32; 15];
        for _ in 0..3 {
            // The gradient of Σ p² is 2p; Adam's first steps move by the learning rate.
            let gradients: Vec<f32> = params.iter().map(|p| 2.0 * p).collect();
            adam.apply(&mut params, &gradients, 0.1, 1.0);
        }
        assert!(params.iter().all(|&x| (x - 0.7).abs() < 0.01), "{params:?}");
        assert_eq!(adam.step, 3);
    }

    #[test]
    fn named_state_restores_into_the_same_moments() {
        let vars = vars();
        let mut adam = Adam::new(&vars);
        let mut params: Vec<f32> = (0..15).map(|i| i as f32).collect();
        let gradients: Vec<f32> = (0..15).map(|i| (i as f32).sin()).collect();
        adam.apply(&mut params, &gradients, 0.01, 0.5);
        let saved: HashMap<String, Tensor> = adam.named_state(&vars).into_iter().collect();
        assert_eq!(saved["adam.v.b"].dims(), &[1, 3]);
        let mut restored = Adam::new(&vars);
        restored.restore(&vars, &saved, adam.step).unwrap();
        assert_eq!(
            (restored.first.clone(), restored.second.clone()),
            (adam.first, adam.second)
        );
        let mut wrong = saved.clone();
        wrong.insert(
            "adam.m.w".into(),
            Tensor::zeros((3, 4), DType::F32, &Device::Cpu).unwrap(),
        );
        let error = restored.restore(&vars, &wrong, 1).unwrap_err();
        assert!(
            error.contains("adam.m.w") && error.contains("[3, 4]"),
            "{error}"
        );
    }
}
