//! Adam with its moments kept as named tensors, so that a checkpoint can store and restore them
//! (candle-nn's AdamW keeps its state private).

use std::collections::HashMap;

use candle_core::{Tensor, Var, backprop::GradStore};

/// Adam's state: step count and first and second moments per parameter.
pub struct Adam {
    pub beta1: f64,
    pub beta2: f64,
    pub eps: f64,
    pub step: u64,
    moments: Vec<(Tensor, Tensor)>,
}

impl Adam {
    /// Zeroed moments for `vars` (CleanRL's eps of 1e-5).
    pub fn new(vars: &[(String, Var)]) -> candle_core::Result<Self> {
        let moments = vars
            .iter()
            .map(|(_, v)| Ok((v.as_tensor().zeros_like()?, v.as_tensor().zeros_like()?)))
            .collect::<candle_core::Result<_>>()?;
        Ok(Self {
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-5,
            step: 0,
            moments,
        })
    }

    /// One update of every var with its gradient times `grad_scale` (gradient-norm clipping).
    pub fn apply(
        &mut self,
        vars: &[(String, Var)],
        grads: &GradStore,
        learning_rate: f64,
        grad_scale: f64,
    ) -> candle_core::Result<()> {
        self.step += 1;
        let correction1 = 1.0 - self.beta1.powi(self.step as i32);
        let correction2 = 1.0 - self.beta2.powi(self.step as i32);
        for ((_, var), (m, v)) in vars.iter().zip(self.moments.iter_mut()) {
            let Some(grad) = grads.get(var.as_tensor()) else {
                continue;
            };
            // Detached: a gradient carries its autograd history, and moments built from it would
            // chain every update's graph (activations included) into memory.
            let grad = grad.detach().affine(grad_scale, 0.0)?;
            *m = ((&*m * self.beta1)? + (&grad * (1.0 - self.beta1))?)?;
            *v = ((&*v * self.beta2)? + (grad.sqr()? * (1.0 - self.beta2))?)?;
            let m_hat = (&*m / correction1)?;
            let v_hat = (&*v / correction2)?;
            let delta = (m_hat / (v_hat.sqrt()? + self.eps)?)?;
            var.set(&(var.as_tensor() - (delta * learning_rate)?)?)?;
        }
        Ok(())
    }

    /// The moments as named tensors (`adam.m.<var>`, `adam.v.<var>`).
    pub fn named_state(&self, vars: &[(String, Var)]) -> Vec<(String, Tensor)> {
        vars.iter()
            .zip(&self.moments)
            .flat_map(|((name, _), (m, v))| {
                [
                    (format!("adam.m.{name}"), m.clone()),
                    (format!("adam.v.{name}"), v.clone()),
                ]
            })
            .collect()
    }

    /// Restores the moments saved by [`Adam::named_state`].
    pub fn restore(
        &mut self,
        vars: &[(String, Var)],
        tensors: &HashMap<String, Tensor>,
        step: u64,
    ) -> Result<(), String> {
        for ((name, var), (m, v)) in vars.iter().zip(self.moments.iter_mut()) {
            for (slot, key) in [(m, format!("adam.m.{name}")), (v, format!("adam.v.{name}"))] {
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
                *slot = saved.clone();
            }
        }
        self.step = step;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{DType, Device};

    #[test]
    fn moments_do_not_keep_the_autograd_graph_regression_oom() {
        // Training ran out of memory (24 GB in two minutes): the moments were built from
        // gradients that still tracked their graph, chaining every update into memory.
        let var = Var::ones((4, 3), DType::F32, &Device::Cpu).unwrap();
        let vars = vec![("w".to_string(), var.clone())];
        let mut adam = Adam::new(&vars).unwrap();
        for _ in 0..3 {
            let loss = var.as_tensor().sqr().unwrap().sum_all().unwrap();
            let grads = loss.backward().unwrap();
            adam.apply(&vars, &grads, 0.1, 1.0).unwrap();
        }
        assert!(
            adam.moments
                .iter()
                .all(|(m, v)| !m.track_op() && !v.track_op())
        );
        // Adam moves each weight by about the learning rate per step, toward 0.
        let w = var
            .as_tensor()
            .flatten_all()
            .unwrap()
            .to_vec1::<f32>()
            .unwrap();
        assert!(w.iter().all(|&x| (x - 0.7).abs() < 0.01), "{w:?}");
    }
}
