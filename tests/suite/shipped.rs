//! What ships loads: every level under `levels/` (and its `.glb` is exactly what export makes
//! of it today), and every policy under `policies/` with the card beside it.

use std::path::{Path, PathBuf};

use arlpcg_core::game::GameSpec;
use arlpcg_core::level::scene::Scene;
use arlpcg_core::level::{gltf, yaml};

fn yaml_files(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            yaml_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "yaml") {
            found.push(path);
        }
    }
}

#[test]
fn every_shipped_level_loads_and_its_glb_is_current() {
    let mut files = Vec::new();
    yaml_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("levels"),
        &mut files,
    );
    assert!(
        files.len() >= 4,
        "expected the shipped example levels, found {files:?}"
    );
    for path in files {
        let level = yaml::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let glb = path.with_extension("glb");
        if glb.exists() {
            let current = gltf::to_glb(&Scene::of_level(&level));
            assert!(
                std::fs::read(&glb).unwrap() == current,
                "{} is stale: re-export it",
                glb.display()
            );
        }
    }
}

#[test]
fn every_shipped_platform_policy_loads_and_its_card_matches() {
    use arlpcg_core::game::platform::OBSERVATION_SIZE;
    use arlpcg_core::game::platform::generator::GENERATOR_OBSERVATION_SIZE;
    use arlpcg_core::level::Game;
    use arlpcg_core::rl::checkpoint::{PolicyCard, Role, load_policy};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    let shipped = [
        (
            "generator",
            Role::Generator,
            GENERATOR_OBSERVATION_SIZE,
            "arlpcg",
        ),
        ("solver", Role::Solver, OBSERVATION_SIZE, "arlpcg"),
        (
            "solver-rule-pcg",
            Role::Solver,
            OBSERVATION_SIZE,
            "rule-pcg",
        ),
        (
            "solver-fixed-track",
            Role::Solver,
            OBSERVATION_SIZE,
            "fixed-track",
        ),
        (
            "solver-fixed-aux",
            Role::Solver,
            OBSERVATION_SIZE,
            "fixed-aux",
        ),
    ];
    for (name, role, observation, mode) in shipped {
        let bytes = std::fs::read(dir.join(format!("{name}.safetensors")))
            .unwrap_or_else(|e| panic!("{name}.safetensors ships: {e}"));
        let loaded = load_policy(&bytes, Game::Platform, role, observation)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let card: PolicyCard = serde_yaml::from_str(
            &std::fs::read_to_string(dir.join(format!("{name}.yaml"))).unwrap(),
        )
        .unwrap();
        // serde_yaml parses floats to within an ulp, not exactly: the normalizer is compared closely.
        let close = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + y.abs()))
        };
        assert!(
            close(&card.normalizer.mean, &loaded.card.normalizer.mean)
                && close(&card.normalizer.var, &loaded.card.normalizer.var),
            "{name}"
        );
        let mut card = card;
        card.normalizer = loaded.card.normalizer.clone();
        assert_eq!(
            card, loaded.card,
            "{name}.yaml differs from the card inside {name}.safetensors"
        );
        assert_eq!(card.training.mode.name(), mode, "{name}");
        // A policy trained from uncommitted code cannot be reproduced: none ships.
        assert!(
            !card.training.commit.ends_with("-dirty"),
            "{name} was trained on a working tree with uncommitted changes ({})",
            card.training.commit
        );
        assert_eq!(card.network.hidden, vec![256, 256]);
        // All four Solvers learn for one budget, 12M Solver steps (the last 8k-step update may
        // overshoot it); the ARLPCG one then plays 40,000 more at learning rate 0 while its
        // Generator trains on against it.
        if role == Role::Solver {
            assert!(
                (12_000_000..12_110_000).contains(&card.training.steps),
                "{name} is trained to the budget, not {}",
                card.training.steps
            );
        }
    }
}

/// The four shipped racing Solvers load as racing Solvers, their cards match the files, they are
/// trained to the budget from committed code, and each drives a held-out rule track to the end.
#[test]
fn the_shipped_racing_solvers_load_and_drive() {
    use arlpcg::services::verify::{Solver, verify};
    use arlpcg_core::game::racing::OBSERVATION_SIZE;
    use arlpcg_core::level::Game;
    let level = arlpcg_core::game::RacingGame::rule_level(3, &Default::default()).unwrap();
    for (file, mode) in [
        ("solver.safetensors", "arlpcg"),
        ("solver-rule-pcg.safetensors", "rule-pcg"),
        ("solver-fixed-track.safetensors", "fixed-track"),
        ("solver-fixed-aux.safetensors", "fixed-aux"),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("policies/racing")
            .join(file);
        let (solver, card) = arlpcg::services::policies::load_solver(&path, Game::Racing).unwrap();
        assert_eq!(card.training.mode.name(), mode);
        assert_eq!(
            card.observation.iter().map(|(_, k)| k).sum::<usize>(),
            OBSERVATION_SIZE
        );
        // The recipe's budget is 5M Solver steps (the last 8k-step update may pass it); the
        // ARLPCG Solver then plays 16,384 more in the finish.
        let budget = match mode {
            "arlpcg" => 5_016_384..5_030_000,
            _ => 5_000_000..5_010_000,
        };
        assert!(
            budget.contains(&card.training.steps),
            "{file}: {} steps",
            card.training.steps
        );
        // A policy trained from uncommitted code cannot be reproduced: none ships.
        assert!(
            !card.training.commit.ends_with("-dirty"),
            "{file} trained on uncommitted code ({})",
            card.training.commit
        );
        // The card inside the file and the card beside it agree.
        let beside: arlpcg_core::rl::checkpoint::PolicyCard =
            serde_yaml::from_str(&std::fs::read_to_string(path.with_extension("yaml")).unwrap())
                .unwrap();
        let record = |c: &arlpcg_core::rl::checkpoint::PolicyCard| {
            let t = &c.training;
            (t.mode, t.steps, t.commit.clone(), t.command.clone())
        };
        assert_eq!(record(&beside), record(&card));
        let stats = verify(&level, &Solver::Policy(&solver), 8, 0, &|| {}).unwrap();
        assert!(stats.success_ratio >= 0.75, "{file}: {stats:?}");
    }
}

/// Each trial of a verification is the run `record` plays alone from the same seed: its own
/// world, its own random stream, whatever else shares the pool (a small first pool, then up
/// to 64 worlds, each starting the next trial when its own ends). So verification's statistics
/// and a level's certificate replay agree run for run, and a verification played in parts
/// (`generate --target-success` screens each candidate with its first 20 runs) is the whole.
#[test]
fn each_verification_trial_is_the_run_recorded_from_its_seed() {
    use arlpcg::services::verify::{
        Solver, Watch, record, stats_of, trial_results, verify_watched,
    };
    use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame};
    use arlpcg_core::level::Game;
    use arlpcg_core::level::stats::TrialResult;
    use std::sync::Mutex;
    for (game, level) in [
        (
            Game::Platform,
            PlatformGame::rule_level(7, &Default::default()).unwrap(),
        ),
        (
            Game::Racing,
            RacingGame::rule_level(7, &Default::default()).unwrap(),
        ),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("policies")
            .join(game.name())
            .join("solver.safetensors");
        let (policy, _) = arlpcg::services::policies::load_solver(&path, game).unwrap();
        let solver = Solver::Policy(&policy);
        let (trials, seed) = (12, 40);
        let played = Mutex::new(Vec::<TrialResult>::new());
        let on_trial = |r: &TrialResult| played.lock().unwrap().push(*r);
        let watch = Watch {
            on_trial: &on_trial,
            stop: &|| false,
        };
        let stats = verify_watched(&level, &solver, trials, seed, &watch)
            .unwrap()
            .unwrap();
        let mut played = played.into_inner().unwrap();
        assert_eq!(played.len(), trials as usize);
        let mut successes = 0;
        for i in 0..trials as u64 {
            let alone = record(&level, &solver, seed + i).unwrap().result;
            successes += u32::from(alone.outcome == arlpcg_core::level::stats::Outcome::Success);
            let at = played.iter().position(|r| *r == alone).unwrap_or_else(|| {
                panic!("{game}: trial {i} played alone ({alone:?}) is none of the pool's runs")
            });
            played.swap_remove(at);
        }
        assert_eq!(stats.successes, successes, "{game}");
        // Played in parts, the trials give the same results in the same order.
        let quiet = Watch {
            on_trial: &|_| {},
            stop: &|| false,
        };
        let part = |range| {
            trial_results(&level, &solver, range, seed, &quiet)
                .unwrap()
                .unwrap()
        };
        let mut parts = part(0..5);
        parts.extend(part(5..trials as u64));
        assert_eq!(parts, part(0..trials as u64), "{game}");
        assert_eq!(stats_of(&level, &solver, seed, &parts), stats, "{game}");
    }
}

/// Every shipped policy of each game is seed 0 of the recipe: the configuration a run folder
/// records (the folder `--out` names in the card's command) is what `train --game G --mode M
/// --seed 0` uses today.
#[test]
fn the_shipped_policies_were_trained_by_the_recipe() {
    use arlpcg::services::train::TrainConfig;
    use arlpcg_core::level::Game;
    use arlpcg_core::rl::checkpoint::TrainMode;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for game in [Game::Platform, Game::Racing] {
        let dir = root.join("policies").join(game.name());
        for file in [
            "generator.yaml", "solver.yaml", "solver-rule-pcg.yaml", "solver-fixed-track.yaml",
            "solver-fixed-aux.yaml",
        ] {
            let card: arlpcg_core::rl::checkpoint::PolicyCard =
                serde_yaml::from_str(&std::fs::read_to_string(dir.join(file)).unwrap()).unwrap();
            let words: Vec<&str> = card.training.command.split_whitespace().collect();
            let out = words
                .iter()
                .position(|w| *w == "--out")
                .map(|i| words[i + 1])
                .expect("the card's command names its run folder");
            let text = std::fs::read_to_string(root.join(out).join("config.yaml")).unwrap();
            let mode = file
                .strip_prefix("solver-")
                .map_or("arlpcg", |f| f.trim_end_matches(".yaml"));
            let mut recipe = TrainConfig::for_run(game, TrainMode::from_name(mode).unwrap());
            recipe.seed = 0;
            let recorded = TrainConfig::parse_for(&text, game).unwrap();
            // A run that plays no finish (a Solver trained alone, or fixed-aux, whose recipe
            // has none) is compared without it: its folder keeps the finish fields of the day
            // it was trained, which changed nothing it did.
            let plays_no_finish = match mode {
                "rule-pcg" | "fixed-track" => true,
                "fixed-aux" => recorded.generator.finish.solver_steps == 0,
                _ => false,
            };
            if plays_no_finish {
                recipe.generator.finish = recorded.generator.finish;
            }
            assert_eq!(
                recorded,
                recipe,
                "{}/{file}: its run's configuration is not the recipe's",
                game.name()
            );
            assert_eq!(
                (card.training.mode.name(), card.training.seed),
                (mode, 0),
                "{}/{file}",
                game.name()
            );
        }
    }
}
