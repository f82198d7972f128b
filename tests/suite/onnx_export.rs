//! Policies out as ONNX: every shipped policy, in both profiles, run by a runtime that is not
//! ours (tract) on observations it was not exported with, gives the actions this tool plays.

use std::path::{Path, PathBuf};

use arlpcg::services::onnx::{self, Contract, Exported, example_observations, reference_outputs};
use arlpcg_core::level::Game;
use tract_onnx::prelude::*;

use crate::common::{arlpcg, arlpcg_ok, stderr, words};

const ROWS: usize = 64;

fn shipped_policies() -> Vec<PathBuf> {
    let mut found = Vec::new();
    for game in [Game::Platform, Game::Racing] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("policies")
            .join(game.name());
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
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform/solver.safetensors");
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

#[test]
fn export_policy_writes_the_graph_and_its_sidecar_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("racing.onnx");
    let out_arg = out.to_str().unwrap();
    let policy = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/policies/racing/solver.safetensors"
    );
    arlpcg_ok(words("export-policy {} --out {}", &[&policy, &out_arg]));
    let bytes = std::fs::read(&out).unwrap();
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("racing.onnx.json")).unwrap())
            .unwrap();
    assert_eq!(sidecar["game"], "racing");
    assert_eq!(sidecar["inputs"][0]["name"], "observation");
    assert_eq!(sidecar["outputs"][0]["columns"][1]["name"], "steer");
    // A Solver's sidecar says how its actions are sampled, and holds no Generator's rules.
    assert_eq!(sidecar["sampling"]["std"].as_array().unwrap().len(), 2);
    assert!(sidecar.get("generator").is_none());

    // Existing files stay unless --force; the same policy gives the same bytes.
    let again = arlpcg(words("export-policy {} --out {}", &[&policy, &out_arg]));
    assert!(!again.status.success());
    assert!(stderr(&again).contains("racing.onnx"), "{}", stderr(&again));
    arlpcg_ok(words(
        "export-policy {} --out {} --force",
        &[&policy, &out_arg],
    ));
    assert_eq!(std::fs::read(&out).unwrap(), bytes);

    // Not a policy, or not an .onnx name: a clear error, nothing written.
    let level = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let other = dir.path().join("other.onnx");
    let bad = arlpcg(words("export-policy {} --out {}", &[&level, &other]));
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("Cargo.toml"), "{}", stderr(&bad));
    let wrong_name = arlpcg(words("export-policy {} --out model.pt", &[&policy]));
    assert!(!wrong_name.status.success());
    assert!(
        stderr(&wrong_name).contains(".onnx"),
        "{}",
        stderr(&wrong_name)
    );
    assert!(!other.exists() && !Path::new("model.pt").exists());
}

/// A policy's export has its golden episode beside it. A Solver's is a real run on the level
/// it carries, which plays again to the same observations from the recorded actions (so a port
/// checks itself against a run the game really has), each frame's state holding every group a
/// port reads; a Generator's has one frame per piece of the level it built.
#[test]
fn a_policys_golden_episode_replays_from_its_level_and_actions() {
    use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame, SolverEnv};
    fn replay<G: GameSpec>(episode: &serde_json::Value, state_names: &[&str]) {
        let level = arlpcg_core::level::yaml::parse(episode["level"].as_str().unwrap()).unwrap();
        let mut env = G::solver_env(&level).unwrap();
        env.reset(episode["run_seed"].as_u64().unwrap());
        let frames = episode["frames"].as_array().unwrap();
        assert!(frames.len() > 50, "{} frames", frames.len());
        for frame in frames {
            let mut observation = vec![0.0f32; G::Env::OBSERVATION_SIZE];
            env.observe(&mut observation);
            let recorded: Vec<f32> = serde_json::from_value(frame["observation"].clone()).unwrap();
            assert_eq!(observation, recorded);
            let names: Vec<&str> = frame["state"]
                .as_object()
                .unwrap()
                .keys()
                .map(String::as_str)
                .collect();
            assert_eq!(names, state_names);
            let action: Vec<f32> = serde_json::from_value(frame["action"].clone()).unwrap();
            assert!(action.iter().all(|a| (-1.0..=1.0).contains(a)));
            env.step(G::Env::action_from_policy_row(&action));
        }
        assert_eq!(
            episode["outcome"], "Success",
            "the shipped Solver completes its level"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    for (game, names) in [
        (
            "platform",
            &[
                "feet", "goal", "grounded", "height_map_hits", "max_steps", "next_block_size",
                "next_block_top", "steps", "velocity", "yaw",
            ][..],
        ),
        (
            "racing",
            &[
                "angular_velocity", "centre_line_ahead", "fan_hits", "goal", "position",
                "road_heading", "road_point", "rotation_xyzw", "velocity",
            ][..],
        ),
    ] {
        let out = dir.path().join(format!("{game}.onnx"));
        let policy = format!(
            "{}/policies/{game}/solver.safetensors",
            env!("CARGO_MANIFEST_DIR")
        );
        arlpcg_ok(words("export-policy {} --out {}", &[&policy, &out]));
        every_observation_part_says_what_it_holds(&dir.path().join(format!("{game}.onnx.json")));
        let golden = dir.path().join(format!("{game}.onnx.golden.json"));
        let episode: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&golden).unwrap()).unwrap();
        assert_eq!(episode["format"], "arlpcg-golden-episode");
        match game {
            "platform" => replay::<PlatformGame>(&episode, names),
            _ => replay::<RacingGame>(&episode, names),
        }
    }
    // A Generator's: each piece it placed at λ = -1, the level it built loading as a level.
    for game in ["platform", "racing"] {
        let generator = format!(
            "{}/policies/{game}/generator.safetensors",
            env!("CARGO_MANIFEST_DIR")
        );
        let out = dir.path().join(format!("{game}-generator.onnx"));
        arlpcg_ok(words("export-policy {} --out {}", &[&generator, &out]));
        every_observation_part_says_what_it_holds(
            &dir.path().join(format!("{game}-generator.onnx.json")),
        );
        let golden = dir
            .path()
            .join(format!("{game}-generator.onnx.golden.json"));
        let episode: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&golden).unwrap()).unwrap();
        assert_eq!(episode["aux"], -1.0);
        assert_eq!(episode["outcome"], "Completed");
        let level = arlpcg_core::level::yaml::parse(episode["level"].as_str().unwrap()).unwrap();
        let frames = episode["frames"].as_array().unwrap();
        assert_eq!(
            frames.len(),
            level.piece_count(),
            "one frame per piece placed"
        );
        // The sidecar holds what `generate` reads besides the graph: the sampling's standard
        // deviations, the piece budget and attempts, and the golden's piece rules.
        let sidecar: serde_json::Value = serde_json::from_slice(
            &std::fs::read(dir.path().join(format!("{game}-generator.onnx.json"))).unwrap(),
        )
        .unwrap();
        let rules = &sidecar["generator"];
        assert_eq!(rules["piece_rules"], episode["piece_rules"], "{game}");
        assert_eq!(rules["attempts"], 64);
        let budget = frames[0]["state"]
            .get("max_blocks")
            .or(frames[0]["state"].get("max_segments"))
            .unwrap_or_else(|| panic!("{game}: no piece budget in the state"));
        assert_eq!(rules["max_pieces"].as_f64(), budget[0].as_f64(), "{game}");
        let log_std: Vec<f32> =
            serde_json::from_value(sidecar["sampling"]["log_std"].clone()).unwrap();
        let std: Vec<f32> = serde_json::from_value(sidecar["sampling"]["std"].clone()).unwrap();
        let actions = sidecar["outputs"][0]["columns"].as_array().unwrap().len();
        assert_eq!((log_std.len(), std.len()), (actions, actions), "{game}");
        for (l, s) in log_std.iter().zip(&std) {
            assert_eq!(l.exp(), *s, "{game}");
            assert!(*s > 0.0 && *s < 2.0, "{game}: a trained std, {s}");
        }
    }
}

/// The sidecar at `path` says, for every part of the observation, how it is computed.
fn every_observation_part_says_what_it_holds(path: &Path) {
    let sidecar: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    for column in sidecar["inputs"][0]["columns"].as_array().unwrap() {
        let meaning = column["meaning"].as_str().unwrap_or_default();
        assert!(meaning.len() > 10, "{}: {column}", path.display());
    }
}
