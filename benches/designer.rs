//! The designer's latencies, through its real path (pure update, worker threads, drawing on an
//! 80×24 TestBackend), on the shipped policies of each game (rules and the scripted player where
//! a game ships none): from the key that asks for a new level to the level drawn, to the first
//! Solver statistics, and to 100 trials done. Twice per game: a new seed (`n`) each round, and
//! a pacing edit (`P`: the next preset, or back to one λ) each round; on platform also an
//! ability edit (`[` and `]` in turn: jump speed -5% and +5%, statistics from the shipped
//! ability-aware Solver; issue 62: ≤ 2 s).
//!
//! Run with `cargo bench --bench designer`. Targets (issues 5 and 16): level on screen < 100 ms,
//! first statistics < 300 ms, 100 trials < 2 s on 2 cores. Then the campaign view: from the
//! folder typed at `o` to a 10-level platform campaign drawn (issue 63: ≤ 300 ms).
#![allow(clippy::unwrap_used)] // a measurement or a test may unwrap (Cargo.toml, [lints])

use std::path::Path;
use std::sync::mpsc::channel;
use std::time::{Duration, Instant};

use arlpcg::shells::design::app::{self, App, Message, Response};
use arlpcg::shells::design::{view, worker};
use arlpcg_core::level::Game;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// The allocator the binary runs with (src/main.rs), so the figures are the designer's own.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const LEVELS: usize = 20;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    for game in [Game::Platform, Game::Racing] {
        for (keys, what) in [(&['n'][..], "new seed"), (&['P'][..], "pacing edit")] {
            measure(game, keys, what);
        }
    }
    measure(Game::Platform, &['[', ']'], "ability edit");
    campaign_view();
}

/// A 10-level platform campaign (scripted median, 20 runs a level) made once, then opened from
/// the prompt and drawn, 20 times.
fn campaign_view() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let folder = dir.path().join("campaign");
    let made = std::process::Command::new(env!("CARGO_BIN_EXE_arlpcg"))
        .args([
            "campaign", "--levels", "10", "--ramp", "0:0.95, 1:0.5", "--judge",
        ])
        .args([
            "scripted-median", "--trials", "20", "--format", "yaml,glb", "--out",
        ])
        .arg(&folder)
        .output()
        .expect("the binary runs");
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let (tx, rx) = channel();
    let workers = worker::Workers::start(worker::GamePolicies::default(), tx, None).unwrap();
    let mut app = App::new(
        Game::Platform,
        Default::default(),
        1,
        dir.path().to_path_buf(),
    );
    let mut terminal = Terminal::new(TestBackend::new(120, 36)).expect("a test terminal");
    let mut opened = Vec::new();
    for round in 0..=20 {
        let pressed = Instant::now();
        for effect in app.open_campaign(folder.clone()) {
            workers.submit(effect);
        }
        let response = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("the worker answers");
        assert!(matches!(response, Response::Campaign(Ok(_))));
        app::update(&mut app, Message::Worker(response));
        terminal
            .draw(|f| view::render(&app, f))
            .expect("drawing on a test backend");
        if round > 0 {
            opened.push(pressed.elapsed().as_secs_f64());
        }
    }
    println!(
        "campaign view, 10 platform levels: opened and drawn in {:.1} ms median ({:.1} max)",
        median(opened.clone()) * 1e3,
        opened.iter().copied().fold(0.0, f64::max) * 1e3
    );
}

/// Each round presses the next of `keys`, cyclically.
fn measure(game: Game, keys: &[char], what: &str) {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies")
        .join(game.name());
    let (policies, info) = worker::load(&shipped, game).unwrap_or_default();
    println!(
        "{game}, {what} (`{}`): Generator {}, Solver {}",
        keys.iter().collect::<String>(),
        info.generator
            .as_ref()
            .map_or("none (rules)", |p| p.card.training.mode.name()),
        info.solver
            .as_ref()
            .map_or("none (scripted)", |p| p.card.training.mode.name()),
    );
    let (tx, rx) = channel();
    let mut shelf = worker::GamePolicies::default();
    shelf[game] = policies;
    let workers = worker::Workers::start(shelf, tx, None).unwrap();
    let out = tempfile::tempdir().expect("a temporary folder");
    let mut app = App::new(game, info, 1, out.path().to_path_buf());
    let mut terminal = Terminal::new(TestBackend::new(80, 24)).expect("a test terminal");
    let (mut to_screen, mut to_stats, mut to_done) = (Vec::new(), Vec::new(), Vec::new());
    let mut no_level = 0;
    for round in 0..=LEVELS {
        let pressed = Instant::now();
        let key = KeyEvent::new(KeyCode::Char(keys[round % keys.len()]), KeyModifiers::NONE);
        for effect in app::update(&mut app, Message::Key(key)) {
            workers.submit(effect);
        }
        let (mut screen, mut stats) = (None, None);
        loop {
            let response = rx
                .recv_timeout(Duration::from_secs(120))
                .expect("the worker answers");
            // A seed whose level the Generator cannot build is shown as an error: no trials.
            if matches!(response, Response::Level { result: Err(_), .. }) {
                no_level += 1;
                break;
            }
            let done = matches!(response, Response::TrialsDone { .. });
            let level = matches!(response, Response::Level { .. });
            let trial = matches!(response, Response::Trial { .. });
            for effect in app::update(&mut app, Message::Worker(response)) {
                workers.submit(effect);
            }
            if level || (trial && stats.is_none()) || done {
                terminal
                    .draw(|f| view::render(&app, f))
                    .expect("drawing on a test backend");
            }
            let t = pressed.elapsed().as_secs_f64();
            if level {
                screen.get_or_insert(t);
            }
            if trial {
                stats.get_or_insert(t);
            }
            if done {
                // The first round warms caches and threads; it is not counted.
                if round > 0 {
                    to_screen.push(screen.expect("a level before its trials"));
                    to_stats.push(stats.expect("trials before the end"));
                    to_done.push(t);
                }
                break;
            }
        }
    }
    if to_done.is_empty() {
        println!("no level built ({no_level} seeds without one)");
        return;
    }
    println!(
        "{} levels ({no_level} seeds without one), median (max): level on screen {:.1} ms ({:.1}), first statistics {:.0} ms ({:.0}), 100 trials {:.2} s ({:.2})",
        to_done.len(),
        median(to_screen.clone()) * 1e3,
        to_screen.iter().copied().fold(0.0, f64::max) * 1e3,
        median(to_stats.clone()) * 1e3,
        to_stats.iter().copied().fold(0.0, f64::max) * 1e3,
        median(to_done.clone()),
        to_done.iter().copied().fold(0.0, f64::max),
    );
}
