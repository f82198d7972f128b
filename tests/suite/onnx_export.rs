//! Policies out as ONNX: `export-policy` writes the graph and its sidecar once, and each policy's
//! golden episode replays from its level and actions. That the graphs run elsewhere as they play
//! here is checked by tract (crates/tract-check) and, in CI, by onnxruntime.

use std::path::Path;

use crate::common::{arlpcg, arlpcg_ok, stderr, words};

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

#[test]
fn a_generators_numbers_for_a_web_page_follow_its_graph() {
    let dir = tempfile::tempdir().unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let generator = format!("{root}/policies/platform/generator.safetensors");
    let (numbers, graph) = (dir.path().join("g.json"), dir.path().join("g.onnx"));
    arlpcg_ok(words(
        "export-policy {} --out {}",
        &[&generator, &numbers.to_str().unwrap()],
    ));
    arlpcg_ok(words(
        "export-policy {} --out {}",
        &[&generator, &graph.to_str().unwrap()],
    ));
    let read = |path: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
    };
    let (kit, sidecar) = (read(&numbers), read(&dir.path().join("g.onnx.json")));
    // The graph's sidecar, build rules included, and the actor layer by layer.
    assert_eq!(kit["sidecar"], sidecar);
    let observation = sidecar["inputs"][0]["shape"][1].as_u64().unwrap();
    let layers = kit["network"]["layers"].as_array().unwrap();
    assert_eq!(layers[0]["inputs"].as_u64(), Some(observation));
    let actions = sidecar["sampling"]["std"].as_array().unwrap().len() as u64;
    assert!(layers.last().unwrap()["outputs"].as_u64().unwrap() >= actions);
    for pair in layers.windows(2) {
        assert_eq!(pair[0]["outputs"], pair[1]["inputs"]);
    }
    for layer in layers {
        let (inputs, outputs) = (
            layer["inputs"].as_u64().unwrap(),
            layer["outputs"].as_u64().unwrap(),
        );
        assert_eq!(
            layer["weight"].as_array().unwrap().len() as u64,
            inputs * outputs
        );
    }
    // A Solver has no levels to build: refused, nothing written.
    let solver = format!("{root}/policies/platform/solver.safetensors");
    let refused = dir.path().join("s.json");
    let out = arlpcg(words(
        "export-policy {} --out {}",
        &[&solver, &refused.to_str().unwrap()],
    ));
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("for a Generator"), "{}", stderr(&out));
    assert!(!refused.exists());
}

/// Plays a Solver's golden episode again from its level and recorded actions: each frame's
/// observation and state are the game's, with the abilities an ability-aware Solver observes.
fn replay_golden<G: arlpcg_core::game::GameSpec>(
    episode: &serde_json::Value,
    state_names: &[&str],
) {
    use arlpcg_core::game::SolverEnv;
    let level = arlpcg_core::level::yaml::parse(episode["level"].as_str().unwrap()).unwrap();
    let mut env = G::solver_env(&level).unwrap();
    env.reset(episode["run_seed"].as_u64().unwrap());
    let frames = episode["frames"].as_array().unwrap();
    assert!(frames.len() > 50, "{} frames", frames.len());
    for frame in frames {
        let mut observation = vec![0.0f32; G::Env::OBSERVATION_SIZE];
        env.observe(&mut observation);
        let recorded: Vec<f32> = serde_json::from_value(frame["observation"].clone()).unwrap();
        let (game_part, ability_part) = recorded.split_at(G::Env::OBSERVATION_SIZE);
        assert_eq!(observation, game_part);
        let mut names: Vec<&str> = frame["state"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        // An ability-aware Solver observes `value/ours - 1` of each main ability after the
        // game's values, and its state holds both (a golden episode plays with ours: 0).
        if !ability_part.is_empty() {
            let read = |key: &str| -> Vec<f64> {
                serde_json::from_value(frame["state"][key].clone()).unwrap()
            };
            let (played, ours) = (read("abilities"), read("abilities_built_in"));
            let expected: Vec<f32> = played
                .iter()
                .zip(&ours)
                .map(|(p, o)| (p / o - 1.0) as f32)
                .collect();
            assert_eq!(ability_part, expected);
            names.retain(|name| !name.starts_with("abilities"));
        }
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

/// A policy's export has its golden episode beside it. A Solver's is a real run on the level
/// it carries, which plays again to the same observations from the recorded actions (so a port
/// checks itself against a run the game really has), each frame's state holding every group a
/// port reads; a Generator's has one frame per piece of the level it built.
#[test]
fn a_policys_golden_episode_replays_from_its_level_and_actions() {
    use arlpcg_core::game::{PlatformGame, RacingGame};
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
            "platform" => replay_golden::<PlatformGame>(&episode, names),
            _ => replay_golden::<RacingGame>(&episode, names),
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
