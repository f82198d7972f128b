#![allow(clippy::unwrap_used)]

//! Policies out as ONNX, run by a runtime that is not ours: every shipped policy, in both
//! contracts, on observations it was not exported with, gives in tract the actions arlpcg plays;
//! ML-Agents' action masks decide a masked branch.

use std::path::{Path, PathBuf};

use arlpcg::services::onnx::{self, Contract, Exported, example_observations, reference_outputs};
use arlpcg_core::level::Game;
use tract_onnx::prelude::*;

/// The repository's root, two folders above this crate.
fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const ROWS: usize = 64;

fn shipped_policies() -> Vec<PathBuf> {
    let mut found = Vec::new();
    for game in [Game::Platform, Game::Racing] {
        let dir = repository().join("policies").join(game.name());
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "safetensors") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// Runs the graph with tract: the observation rows, and `masks` for `action_masks` if the graph
/// takes it; every output, by name.
fn run_tract(
    exported: &Exported,
    observations: &[f32],
    masks: Option<&[f32]>,
) -> Vec<(String, Vec<f32>)> {
    let sidecar = &exported.sidecar;
    let width = exported.sidecar.inputs[0].shape[1].as_u64().unwrap() as usize;
    let rows = observations.len() / width;
    let mut model = tract_onnx::onnx()
        .model_for_read(&mut std::io::Cursor::new(&exported.onnx))
        .expect("tract reads the graph");
    let mut inputs: TVec<TValue> = tvec![
        tract_ndarray::Array2::from_shape_vec((rows, width), observations.to_vec())
            .unwrap()
            .into_tensor()
            .into()
    ];
    model = model
        .with_input_fact(0, f32::fact([rows, width]).into())
        .unwrap();
    if let Some(port) = sidecar.inputs.get(1) {
        let columns = port.shape[1].as_u64().unwrap() as usize;
        let masks = masks
            .map(<[f32]>::to_vec)
            .unwrap_or(vec![1.0; rows * columns]);
        model = model
            .with_input_fact(1, f32::fact([rows, columns]).into())
            .unwrap();
        inputs.push(
            tract_ndarray::Array2::from_shape_vec((rows, columns), masks)
                .unwrap()
                .into_tensor()
                .into(),
        );
    }
    let plan = model.into_optimized().unwrap().into_runnable().unwrap();
    let outputs = plan.run(inputs).expect("tract runs the graph");
    sidecar
        .outputs
        .iter()
        .zip(outputs.iter())
        .map(|(port, value)| {
            // ML-Agents' discrete actions are integers, as the sidecar says; compared as floats.
            let integers = port.element_type.as_deref() == Some("int64");
            // (tract may carry int64 as its symbolic-dimension integers, TDim)
            let integer = matches!(value.datum_type(), DatumType::I64 | DatumType::TDim);
            assert_eq!(integer, integers, "{}: {:?}", port.name, value.datum_type());
            let value = value.cast_to::<f32>().unwrap();
            let values = value.to_plain_array_view::<f32>().unwrap();
            (port.name.clone(), values.iter().copied().collect())
        })
        .collect()
}

#[test]
fn every_shipped_policy_runs_in_tract_as_it_plays_here() {
    let policies = shipped_policies();
    assert!(
        policies.len() >= 10,
        "expected the shipped policies: {policies:?}"
    );
    for path in &policies {
        let (policy, card, reference) = arlpcg::services::policies::load_any(path).unwrap();
        // Observations the export did not see (its examples use seed 0).
        let observations = example_observations(&card.normalizer, ROWS, 1);
        for profile in [Contract::Plain, Contract::Mlagents] {
            let exported = onnx::export(&policy, &card, reference.clone(), profile).unwrap();
            let expected = reference_outputs(&policy, &card, profile, &observations).unwrap();
            let got = run_tract(&exported, &observations, None);
            for (name, want) in &expected {
                let (_, values) = got.iter().find(|(n, _)| n == name).unwrap_or_else(|| {
                    panic!("{}: no output {name}", path.display());
                });
                let want: Vec<f32> = want.iter().flatten().copied().collect();
                assert_eq!(values.len(), want.len(), "{} {name}", path.display());
                let error = values
                    .iter()
                    .zip(&want)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0f32, f32::max);
                assert!(
                    error < 1e-4,
                    "{} ({}) {name}: max abs error {error}",
                    path.display(),
                    profile.name()
                );
            }
            if profile == Contract::Mlagents {
                let constant = |name: &str| got.iter().find(|(n, _)| n == name).unwrap().1.clone();
                assert_eq!(constant("version_number"), vec![3.0]);
                assert_eq!(constant("memory_size"), vec![0.0]);
                if card.network.continuous > 0 {
                    assert_eq!(
                        constant("continuous_action_output_shape"),
                        vec![card.network.continuous as f32]
                    );
                }
            }
            // The example rows in the sidecar are this tool's own answers too.
            let examples = &exported.sidecar.examples;
            let rows: Vec<f32> = examples.observations.iter().flatten().copied().collect();
            assert_eq!(
                examples.outputs,
                reference_outputs(&policy, &card, profile, &rows).unwrap()
            );
        }
    }
}

#[test]
fn mlagents_action_masks_decide_a_masked_branch() {
    let path = repository().join("policies/platform/solver.safetensors");
    let (policy, card, reference) = arlpcg::services::policies::load_any(&path).unwrap();
    assert_eq!(card.network.binary, 1, "the platform Solver jumps");
    let exported = onnx::export(&policy, &card, reference, Contract::Mlagents).unwrap();
    let observations = example_observations(&card.normalizer, ROWS, 2);
    let jump = |masks: &[f32]| {
        let masks: Vec<f32> = masks.iter().copied().cycle().take(2 * ROWS).collect();
        run_tract(&exported, &observations, Some(&masks))
            .into_iter()
            .find(|(n, _)| n == "discrete_actions")
            .unwrap()
            .1
    };
    let free = jump(&[1.0, 1.0]);
    assert!(
        free.contains(&0.0) && free.contains(&1.0),
        "unmasked, the rows should differ: {free:?}"
    );
    assert!(jump(&[1.0, 0.0]).iter().all(|&a| a == 0.0), "jump masked");
    assert!(
        jump(&[0.0, 1.0]).iter().all(|&a| a == 1.0),
        "staying masked"
    );
}
