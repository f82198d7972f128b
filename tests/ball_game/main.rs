//! The third game: a ball pushed across blocks (crates/core/src/game/ball, built with the
//! `test-game` feature, `cargo test --features test-game --test ball_game`). It plugs in through
//! `GameSpec`, its folder, its `Track` variant and the dispatch, and every command plays it as
//! it plays the paper's two games: rules, generate, verify, a tiny train, the trained pair's
//! levels, eval, the glTF and ONNX exports, and the designer's screen.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::process::Output;

use arlpcg::shells::design::app::{self, App, Message};
use arlpcg::shells::design::{view, worker};
use arlpcg_core::game::ball::env::{BallAction, BallEnv};
use arlpcg_core::game::ball::{BallGame, FACTS};
use arlpcg_core::game::{GameSpec, Scripted, SolverEnv};
use arlpcg_core::level::{Game, Track, yaml};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

fn arlpcg(args: &[&str]) -> Output {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args(args)
        .env(
            "ARLPCG_CACHE",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("ball-cache"),
        )
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "arlpcg {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn text(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// A training run small enough for a test: both agents learn, in turn, then the finish.
const TINY: &str = "\
seed: 3
hidden: [16, 16]
checkpoint_minutes: 0.0
solver:
  num_envs: 4
  num_steps: 32
  update_epochs: 1
  num_minibatches: 2
generator:
  ppo:
    num_envs: 4
    num_steps: 4
    update_epochs: 1
    num_minibatches: 2
  solver_warmup_steps: 128
  solver_phase_steps: 128
  generator_phase_steps: 8
  own_check: {levels: 1, trials: 2}
  finish:
    solver_steps: 128
    generator_phase_steps: 8
";

/// The scripted expert pushes the ball onto the goal block of a rule level: the game can be
/// played, and it is played in rapier (the ball falls when pushed off the start block).
#[test]
fn the_scripted_pusher_rolls_the_ball_to_the_goal_and_a_wrong_push_falls() {
    let level = (0..20)
        .find_map(|seed| BallGame::rule_level(seed, &Default::default()))
        .unwrap();
    assert!(matches!(level.track, Track::Ball(_)));
    let finish = |mut act: Box<dyn FnMut(&BallEnv) -> BallAction>| {
        let mut env = BallGame::solver_env(&level).unwrap();
        env.reset(1);
        loop {
            let action = act(&env);
            if let Some(outcome) = env.step(action).outcome {
                return outcome;
            }
        }
    };
    let successes = (0..4)
        .filter(|&run| {
            let mut pusher = BallGame::scripted(run, arlpcg_core::game::Skill::Expert);
            finish(Box::new(move |env| pusher.act(env)))
                == arlpcg_core::level::stats::Outcome::Success
        })
        .count();
    assert_eq!(successes, 4, "the expert rolls to the goal");
    let back = |_: &BallEnv| <BallEnv as SolverEnv>::action_from_policy_row(&[-1.0, -1.0, 0.0]);
    assert_ne!(
        finish(Box::new(back)),
        arlpcg_core::level::stats::Outcome::Success
    );
}

#[test]
fn every_command_plays_the_ball_game() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();

    // Rules, files and their glTF: the level file names the game and reads back.
    let rules = path("rules");
    arlpcg(&[
        "generate", "--game", "ball", "--rules", "--count", "2", "--seed", "3", "--out", &rules,
        "--format", "yaml,glb", "--verify", "4", "--judge", "scripted-expert",
    ]);
    let first = std::fs::read_dir(&rules)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .min()
        .unwrap();
    let level = yaml::load(&first).unwrap();
    assert_eq!(level.game(), Game::Ball);
    assert!(level.stats.is_some(), "verified");
    assert!(first.with_extension("glb").is_file());

    // Verify, by the scripted pusher, in JSON with the game's own endings.
    let json = text(&arlpcg(&[
        "verify",
        first.to_str().unwrap(),
        "--solver",
        "scripted-expert",
        "--trials",
        "4",
        "--json",
    ]));
    let verdict: serde_json::Value = serde_json::from_str(json.lines().next().unwrap()).unwrap();
    assert!(verdict["fell"].is_u64(), "{verdict}");

    // A tiny adversarial run: a Generator and a Solver of the ball game.
    let config = path("tiny.yaml");
    std::fs::write(&config, TINY).unwrap();
    let run = path("run");
    arlpcg(&[
        "train", "--game", "ball", "--mode", "arlpcg", "--steps", "256", "--config", &config,
        "--out", &run,
    ]);
    let card = std::fs::read_to_string(Path::new(&run).join("generator.yaml")).unwrap();
    assert!(card.contains("game: ball"), "{card}");

    // Its Generator's levels, verified by its Solver; eval; the ONNX export of its Solver.
    let made = path("made");
    arlpcg(&[
        "generate", "--game", "ball", "--policies", &run, "--count", "1", "--seed", "4",
        "--aux=-1", "--verify", "2", "--allow-unsolved", "--out", &made,
    ]);
    let eval = path("eval");
    arlpcg(&[
        "eval", "--game", "ball", "--policies", &run, "--tracks", "2", "--trials", "2",
        "--validation-tracks", "2", "--out", &eval,
    ]);
    assert!(Path::new(&eval).read_dir().unwrap().next().is_some());
    let onnx = path("solver.onnx");
    arlpcg(&[
        "export-policy",
        &format!("{run}/solver.safetensors"),
        "--out",
        &onnx,
    ]);
    assert!(std::fs::metadata(&onnx).unwrap().len() > 0);

    // The designer on the trained pair: the ball's level on screen, with its statistics.
    let (policies, info) = worker::load(Path::new(&run), Game::Ball).unwrap();
    let mut app = App::new(Game::Ball, info, 1, dir.path().to_path_buf());
    let mut pending = app.start();
    let shelf = std::sync::Mutex::new({
        let mut shelf = worker::GamePolicies::default();
        shelf[Game::Ball] = policies;
        shelf
    });
    while let Some(effect) = pending.pop() {
        let answers = std::sync::Mutex::new(Vec::new());
        worker::perform(effect, &shelf, &|| false, &|r| {
            answers.lock().unwrap().push(r)
        });
        for response in answers.into_inner().unwrap() {
            pending.extend(app::update(&mut app, Message::Worker(response)));
        }
    }
    let mut terminal = Terminal::new(TestBackend::new(120, 36)).unwrap();
    terminal.draw(|f| view::render(&app, f)).unwrap();
    let screen = terminal.backend().to_string();
    assert!(screen.contains(" ball "), "{screen}");
    assert!(screen.contains(FACTS.pieces), "{screen}");
    assert!(screen.contains("success"), "{screen}");
}
