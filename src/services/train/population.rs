//! The population a Generator plays against while it learns (docs/training.md, "A population
//! of Solvers"): earlier [`Snapshot`]s of the Solver, and how a Generator checkpoint stores them
//! (tensors `population.K.<variable>`, the rest in its training state's `source`).

use serde::{Deserialize, Serialize};

use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::ActorCritic;

/// An earlier Solver that the Generator plays against.
pub struct Snapshot {
    /// The Solver's network.
    pub policy: ActorCritic,
    /// Its observation normalizer.
    pub norm: RunningNorm,
    /// The Solver's steps when it was taken.
    pub solver_steps: u64,
}

impl Snapshot {
    /// A copy of `policy` (new variables, the same values) with its normalizer.
    pub fn of(
        policy: &ActorCritic,
        norm: &RunningNorm,
        solver_steps: u64,
    ) -> candle_core::Result<Self> {
        let copy = ActorCritic::new(policy.shape().clone(), 0)?;
        for ((_, to), (_, from)) in copy.named_vars().iter().zip(policy.named_vars()) {
            to.set(&from.as_tensor().copy()?)?;
        }
        Ok(Self {
            policy: copy,
            norm: norm.clone(),
            solver_steps,
        })
    }
}

/// How a Generator checkpoint records its population: the snapshots' tensors are named
/// `population.K.<variable>`, and this (its training state's `source`) holds the rest.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct PopulationRecord {
    /// Each snapshot, oldest first.
    pub snapshots: Vec<SnapshotRecord>,
}

/// One snapshot as a checkpoint records it (its tensors apart).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SnapshotRecord {
    /// The Solver's steps when it was taken.
    pub solver_steps: u64,
    /// Its observation normalizer.
    pub norm: RunningNorm,
}

/// The population as a checkpoint stores it: its record and its tensors.
pub fn population_record(
    population: &[Snapshot],
) -> (PopulationRecord, Vec<(String, candle_core::Tensor)>) {
    let mut tensors = Vec::new();
    let mut record = PopulationRecord::default();
    for (k, snapshot) in population.iter().enumerate() {
        for (name, var) in snapshot.policy.named_vars() {
            tensors.push((format!("population.{k}.{name}"), var.as_tensor().clone()));
        }
        record.snapshots.push(SnapshotRecord {
            solver_steps: snapshot.solver_steps,
            norm: snapshot.norm.clone(),
        });
    }
    (record, tensors)
}

/// The population a checkpoint stored: Solvers of `shape`, each tensor checked for its shape
/// and for finite values. `Err` names the tensor.
pub fn population_from(
    record: &PopulationRecord,
    tensors: &std::collections::HashMap<String, candle_core::Tensor>,
    shape: &arlpcg_core::rl::policy::PolicyShape,
) -> Result<Vec<Snapshot>, String> {
    let mut population = Vec::with_capacity(record.snapshots.len());
    for (k, entry) in record.snapshots.iter().enumerate() {
        let policy = ActorCritic::new(shape.clone(), 0).map_err(|e| e.to_string())?;
        for (name, var) in policy.named_vars() {
            let key = format!("population.{k}.{name}");
            arlpcg_core::rl::checkpoint::restore_var(tensors, &key, &var)
                .map_err(|e| e.to_string())?;
        }
        let d = shape.observation;
        if entry.norm.mean.len() != d || entry.norm.var.len() != d {
            return Err(format!(
                "snapshot {k}: its normalizer does not observe {d} values"
            ));
        }
        population.push(Snapshot {
            policy,
            norm: entry.norm.clone(),
            solver_steps: entry.solver_steps,
        });
    }
    Ok(population)
}
