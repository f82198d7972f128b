//! The designer: its pure update driven by key scripts, whole screens on ratatui's TestBackend,
//! the worker's latest-wins rule, and one scripted session on the shipped policies that ends in
//! exported files that load and validate.

use std::path::Path;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use arlpcg::services::generation::{Ask, LevelRequest};
use arlpcg::services::level_files::GltfOptions;
use arlpcg::shells::design::app::{
    self, App, Effect, GoalSetting, LoadedInfo, Loading, Message, Mode, Overlay, Response,
};
use arlpcg::shells::design::layout::Areas;
use arlpcg::shells::design::view;
use arlpcg::shells::design::worker::{self, GamePolicies, Policies, Workers};
use arlpcg_core::level::scene::PhysicsExtensions;
use arlpcg_core::level::{Game, yaml};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyModifiers, MouseButton, MouseEvent, MouseEventKind,
};

/// A designer whose effects run inline, on `policies`.
/// The shipped platform policies' folder.
fn shipped_platform() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform")
}

struct Harness {
    app: App,
    policies: Mutex<GamePolicies>,
    pending: Vec<Effect>,
}

impl Harness {
    /// A designer on the platform game with `policies` (racing: rules and the scripted driver).
    fn new(policies: Policies, info: LoadedInfo, out: &Path) -> Self {
        let mut app = App::new(Game::Platform, info, 1, out.to_path_buf());
        let pending = app.start();
        Self {
            app,
            policies: Mutex::new({
                let mut shelf = GamePolicies::default();
                shelf[Game::Platform] = policies;
                shelf
            }),
            pending,
        }
    }

    /// Rules and the scripted controller: no trained policy, fully deterministic.
    fn rules(out: &Path) -> Self {
        Self::new(Policies::default(), LoadedInfo::default(), out)
    }

    /// Loads (`f`) our platform profile with the jump speed `jump`, written into `dir`, and
    /// waits for its level and statistics.
    fn load_profile_with_jump(&mut self, dir: &Path, jump: &str) {
        let text = arlpcg_core::level::profile::Profile::default_of(Game::Platform)
            .to_yaml()
            .replace("jump_speed: 9.25", &format!("jump_speed: {jump}"));
        let path = dir.join(format!("jump-{jump}.yaml"));
        std::fs::write(&path, text).unwrap();
        self.key(KeyCode::Char('f'));
        self.keys(path.to_str().unwrap());
        self.key(KeyCode::Enter);
        self.settle();
    }

    /// A designer on the shipped platform policies.
    fn shipped(out: &Path) -> Self {
        let (policies, info) = worker::load(&shipped_platform(), Game::Platform).unwrap();
        Self::new(policies, info, out)
    }

    fn send(&mut self, message: Message) {
        let effects = app::update(&mut self.app, message);
        self.pending.extend(effects);
    }

    fn key(&mut self, code: KeyCode) {
        self.send(Message::Key(KeyEvent::new(code, KeyModifiers::NONE)));
    }

    fn keys(&mut self, text: &str) {
        for c in text.chars() {
            self.key(KeyCode::Char(c));
        }
    }

    /// Runs every pending effect (and those their answers ask for) to the end.
    fn settle(&mut self) {
        while !self.pending.is_empty() {
            let effects = std::mem::take(&mut self.pending);
            for effect in effects {
                let answers = Mutex::new(Vec::new());
                worker::perform(effect, &self.policies, &|| false, &|r| {
                    answers.lock().unwrap().push(r)
                });
                for response in answers.into_inner().unwrap() {
                    self.send(Message::Worker(response));
                }
            }
        }
    }

    fn screen(&self, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        terminal.draw(|f| view::render(&self.app, f)).unwrap();
        terminal.backend().to_string()
    }
}

#[test]
fn starts_with_a_level_and_its_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    assert!(matches!(h.pending[..], [Effect::Generate { .. }]));
    h.settle();
    let level = h.app.level.clone().expect("a level is on screen");
    // Without policies the level on screen is the rule level of the designer's seed and λ.
    let expected = arlpcg::services::generation::rules_level(
        arlpcg_core::level::Game::Platform,
        &LevelRequest::new(h.app.seed, Some(h.app.aux)),
    )
    .unwrap();
    assert_eq!(level.track, expected.track);
    assert_eq!(level.goal, expected.goal);
    let trials = h.app.trials.as_ref().expect("trials started");
    assert_eq!(trials.done(), app::DEFAULT_TRIALS);
    let stats = trials.stats.as_ref().expect("final statistics");
    assert_eq!(stats.trials, app::DEFAULT_TRIALS);
    // The live counters agree with the final statistics.
    assert_eq!(trials.successes(), stats.successes);
    assert_eq!(
        trials.failures_by_block(level.piece_count()),
        stats.failures_by_piece
    );
}

/// With a profile (`design --profile`, `f`), levels are made and played for it and the header
/// says so: a low jumper fails the rule level the built-in character completes. `[ ]` change the
/// chosen ability (`e` picks it) by 5% and make the level again.
#[test]
fn a_profile_makes_the_levels_and_its_keys_change_the_abilities() {
    let dir = tempfile::tempdir().unwrap();
    let low = arlpcg_core::level::profile::Profile::default_of(Game::Platform)
        .to_yaml()
        .replace("name: default", "name: low-jumper")
        .replace("jump_speed: 9.25", "jump_speed: 8.0");
    let file = dir.path().join("low.yaml");
    std::fs::write(&file, low).unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    h.key(KeyCode::Char('f'));
    h.keys(file.to_str().unwrap());
    h.key(KeyCode::Enter);
    assert!(matches!(h.pending[..], [Effect::LoadProfile { .. }]));
    h.settle();
    let level = h.app.level.clone().expect("a level is on screen");
    assert_eq!(
        level.profile.as_ref().map(|p| p.name.as_str()),
        Some("low-jumper")
    );
    // Made within the low jumper's reach: no block more than 1 m above the last.
    for pair in level.platform().unwrap().platforms().windows(2) {
        assert!(pair[1].position[1] - pair[0].position[1] <= 1.0 + 1e-9);
    }
    assert!(h.screen(120, 36).contains("profile: low-jumper"));

    // `]` raises the jump speed 5%; `e` then `[` lowers the run speed 5%.
    h.key(KeyCode::Char(']'));
    h.settle();
    h.key(KeyCode::Char('e'));
    h.key(KeyCode::Char('['));
    h.settle();
    let edited = h.app.level.as_ref().unwrap().profile.clone().unwrap();
    assert_eq!(edited.name, "low-jumper (edited)");
    assert_eq!(edited.value("character.jump_speed").unwrap().0, 8.4);
    assert_eq!(edited.value("character.run_speed").unwrap().0, 7.6);
    // A file that is not a profile is a message, not a crash.
    h.key(KeyCode::Char('f'));
    h.keys(dir.path().join("missing.yaml").to_str().unwrap());
    h.key(KeyCode::Enter);
    h.settle();
    assert!(
        h.app
            .status
            .as_ref()
            .is_some_and(|(text, problem)| *problem && text.contains("missing.yaml"))
    );
}

/// On the shipped platform policies, the Solver plays a loaded profile within the ranges it
/// trained over, as it plays ours.
#[test]
fn a_profile_within_the_shipped_solvers_ranges_is_played_by_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::shipped(dir.path());
    h.settle();
    for jump in ["8.5", "9.25"] {
        h.load_profile_with_jump(dir.path(), jump);
        let trials = h.app.trials.as_ref().expect("trials of the new level");
        let stats = trials.stats.as_ref().expect("statistics");
        let played = stats.solver.describe();
        assert!(
            played.ends_with("policies/platform/solver.safetensors"),
            "{played}"
        );
    }
}

/// Beyond the range an ability-aware Solver trained over, the scripted expert plays the trials in
/// its place, and the status line and the statistics panel say so; within it, the Solver plays.
#[test]
fn the_scripted_expert_plays_beyond_an_ability_aware_solvers_range() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = crate::common::five_jumpers_pair();
    let (policies, info) = worker::load(run, Game::Platform).unwrap();
    let mut h = Harness::new(policies, info, dir.path());
    h.settle();
    for (jump, stood_in) in [("8.5", false), ("7.0", true)] {
        h.load_profile_with_jump(dir.path(), jump);
        let trials = h.app.trials.as_ref().expect("trials of the new level");
        let said = trials.stand_in.clone().unwrap_or_default();
        assert_eq!(
            said.contains("lies beyond the abilities"),
            stood_in,
            "{said}"
        );
        let stats = trials.stats.as_ref().expect("the trials are played");
        assert_eq!(
            matches!(
                stats.solver,
                arlpcg_core::level::SolverRef::Scripted {
                    skill: arlpcg_core::game::Skill::Expert
                }
            ),
            stood_in
        );
        assert_eq!(
            h.screen(120, 40).contains("scripted-expert in its place"),
            stood_in
        );
    }
}

/// With a Generator trained with style knobs, `m` picks the slider the arrows move: a knob's
/// value reaches the level (its file records it) and the screen shows it beside the style the
/// level measures; without knobs, `m` says there are none and λ stays on the arrows.
#[test]
fn the_arrows_move_a_style_knob_that_m_picks() {
    let dir = tempfile::tempdir().unwrap();
    let mut rules = Harness::rules(dir.path());
    rules.settle();
    rules.key(KeyCode::Char('m'));
    assert!(rules.pending.is_empty() && rules.app.slider == 0);
    let (said, problem) = rules.app.status.clone().unwrap();
    assert!(problem && said.contains("no style knobs"), "{said}");

    let (run, _) = crate::common::knob_pair();
    let (policies, info) = worker::load(run, Game::Platform).unwrap();
    let mut h = Harness::new(policies, info, dir.path());
    h.settle();
    assert_eq!(h.app.knobs, vec![0.0, 0.0]);
    let screen = h.screen(120, 40);
    assert!(
        screen.contains("λ +1.00  stride +0.00  steps +0.00"),
        "{screen}"
    );
    assert!(screen.contains("measured stride"), "{screen}");
    h.key(KeyCode::Char('m'));
    assert_eq!(h.app.slider, 1);
    h.key(KeyCode::End);
    assert!(
        matches!(&h.pending[..], [Effect::Generate { knobs, ask: Ask::Aux(aux), .. }]
            if knobs == &[1.0, 0.0] && *aux == 1.0)
    );
    h.settle();
    let level = h.app.level.clone().unwrap();
    assert_eq!(level.knobs.get("stride"), Some(&1.0));
    assert!(h.screen(120, 40).contains("stride +1.00"));
    // Round to λ again: the arrows move λ, the knob keeps its value.
    h.key(KeyCode::Char('m'));
    h.key(KeyCode::Char('m'));
    assert_eq!(h.app.slider, 0);
    h.key(KeyCode::Left);
    assert!(
        matches!(&h.pending[..], [Effect::Generate { knobs, ask: Ask::Aux(aux), .. }]
            if knobs == &[1.0, 0.0] && (*aux - 0.9).abs() < 1e-9)
    );
}

/// `V` serves the level on screen in 3D (the page of `arlpcg view`), and the page follows the
/// designer: a new level is a new version of the scene, with its own pieces.
#[test]
fn v_serves_the_level_on_screen_in_3d_and_follows_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.key(KeyCode::Char('V'));
    assert!(
        !h.pending.iter().any(|e| matches!(e, Effect::OpenView)),
        "no level yet"
    );
    h.settle();
    h.key(KeyCode::Char('V'));
    assert!(matches!(h.pending.as_slice(), [Effect::OpenView]));
    h.pending.clear();

    let mut browser = arlpcg::shells::design::browser::Browser::default();
    let url = browser.serve(&h.app).unwrap();
    let address = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let scene = |address: &str| {
        let (status, body) = crate::view::get(address, "/scene.json");
        assert_eq!(status, 200, "{body}");
        let json: serde_json::Value = serde_json::from_str(&body).unwrap();
        let pieces = json["scene"]["pieces"].as_u64().unwrap() as usize;
        (json["version"].as_str().unwrap().to_string(), pieces)
    };
    let first_level = h.app.level.clone().unwrap();
    let (first, pieces) = scene(&address);
    assert_eq!(pieces, first_level.piece_count());
    browser.follow(&h.app);
    assert_eq!(scene(&address).0, first, "nothing changed, nothing new");
    assert_eq!(browser.serve(&h.app).unwrap(), url, "one server");

    h.key(KeyCode::Char('n'));
    h.settle();
    let second_level = h.app.level.clone().unwrap();
    assert_ne!(second_level.seed, first_level.seed);
    browser.follow(&h.app);
    let (second, pieces) = scene(&address);
    assert_ne!(second, first);
    assert_eq!(pieces, second_level.piece_count());
    assert_eq!(crate::view::get(&address, "/version").1, second);
}

#[test]
fn whole_screen_at_80x24() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    insta::assert_snapshot!("start_80x24", h.screen(80, 24));
    h.key(KeyCode::Char('?'));
    insta::assert_snapshot!("help_80x24", h.screen(80, 24));
}

#[test]
fn whole_screen_larger_and_too_small() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    h.key(KeyCode::Down);
    h.key(KeyCode::Down);
    insta::assert_snapshot!("selected_block_120x36", h.screen(120, 36));
    assert!(h.screen(60, 20).contains("at least 80×24"));
}

#[test]
fn slider_keys_and_mouse_change_lambda_and_regenerate() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    h.key(KeyCode::Left);
    assert_eq!(h.app.aux, 0.9);
    assert!(matches!(h.pending[..], [Effect::Generate { ask: Ask::Aux(aux), .. }] if aux == 0.9));
    h.key(KeyCode::Right);
    h.key(KeyCode::Right);
    assert_eq!(h.app.aux, 1.0, "clamped at +1");
    h.key(KeyCode::Home);
    assert_eq!(h.app.aux, -1.0);
    // Only the newest generation's level is shown.
    assert!(h.app.generating());
    h.settle();
    assert_eq!(h.app.loading, Loading::Idle);
    assert_eq!(h.app.level.as_ref().unwrap().aux, Some(-1.0));

    h.send(Message::Resize {
        width: 100,
        height: 30,
    });
    let slider = Areas::of(h.app.size).slider;
    let mouse = |kind, column| {
        Message::Mouse(MouseEvent {
            kind,
            column,
            row: slider.y,
            modifiers: KeyModifiers::NONE,
        })
    };
    h.send(mouse(
        MouseEventKind::Down(MouseButton::Left),
        slider.right() - 1,
    ));
    assert_eq!(h.app.aux, 1.0, "the right end is +1");
    h.send(mouse(
        MouseEventKind::Drag(MouseButton::Left),
        slider.x + slider.width / 2,
    ));
    assert!(h.app.aux.abs() < 0.06, "the middle is 0, got {}", h.app.aux);
    h.send(mouse(MouseEventKind::Up(MouseButton::Left), slider.x));
    h.send(mouse(MouseEventKind::Drag(MouseButton::Left), slider.x));
    assert!(h.app.aux.abs() < 0.06, "no drag after release");
}

#[test]
fn seed_and_goal_settings() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    let first = h.app.level.clone().unwrap();

    h.key(KeyCode::Char('s'));
    h.key(KeyCode::Backspace);
    h.keys("x");
    h.key(KeyCode::Enter);
    let (text, is_error) = h.app.status.clone().unwrap();
    assert!(is_error && text.contains("seed `x`"), "{text}");
    assert_eq!(h.app.seed, 1);

    h.key(KeyCode::Char('s'));
    h.key(KeyCode::Backspace);
    h.keys("42");
    h.key(KeyCode::Enter);
    assert_eq!(h.app.seed, 42);
    h.settle();
    assert_ne!(h.app.level.as_ref().unwrap().goal, first.goal);

    h.key(KeyCode::Char('n'));
    assert_ne!(h.app.seed, 42);

    // By hand: starts from the goal on screen, then moves with d/D, h/H, a/A.
    h.settle();
    let drawn = h.app.level.as_ref().unwrap().goal;
    h.key(KeyCode::Char('g'));
    let GoalSetting::Custom { distance, .. } = h.app.goal else {
        panic!("goal set by hand");
    };
    assert!((distance - drawn[0].hypot(drawn[2])).abs() < 0.6);
    h.keys("DDHa");
    h.settle();
    let goal = h.app.level.as_ref().unwrap().goal;
    assert!((goal[0].hypot(goal[2]) - (distance + 10.0).min(70.0)).abs() < 0.6);
    h.key(KeyCode::Char('g'));
    assert_eq!(h.app.goal, GoalSetting::FromSeed);
}

#[test]
fn replay_sweep_and_trial_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    h.key(KeyCode::Char('r'));
    h.settle();
    let replay = h.app.replay.clone().expect("a recorded run");
    assert!(replay.recording.path.len() > 10);
    for _ in 0..5 {
        h.send(Message::Tick);
    }
    assert_eq!(
        h.app.replay.as_ref().unwrap().frame,
        5 * app::REPLAY_STEPS_PER_TICK
    );
    assert!(h.screen(80, 24).contains('@'), "the runner is drawn");

    h.key(KeyCode::Char('w'));
    h.settle();
    let sweep = h.app.sweep.clone().expect("a sweep");
    assert_eq!(
        sweep.points.len(),
        arlpcg::shells::design::app::sweep::SWEEP_AUX.len()
    );
    // Rule levels do not depend on λ, so every point of their sweep measures the same level
    // with the same trials: one success ratio, whatever λ says.
    let ratios: Vec<f64> = sweep
        .points
        .iter()
        .map(|(_, p)| match p {
            app::SweepPoint::Success(s) => *s,
            other => panic!("a sweep point is {other:?}"),
        })
        .collect();
    assert!(ratios.windows(2).all(|w| w[0] == w[1]), "{ratios:?}");

    h.key(KeyCode::Char('t'));
    for _ in 0..3 {
        h.key(KeyCode::Backspace);
    }
    h.keys("20");
    h.key(KeyCode::Enter);
    h.settle();
    assert_eq!(
        h.app
            .trials
            .as_ref()
            .unwrap()
            .stats
            .as_ref()
            .unwrap()
            .trials,
        20
    );
    h.key(KeyCode::Char('t'));
    h.key(KeyCode::Backspace);
    h.key(KeyCode::Backspace);
    h.keys("0");
    h.key(KeyCode::Enter);
    let (text, is_error) = h.app.status.clone().unwrap();
    assert!(is_error && text.contains("trials `0`"), "{text}");
    assert_eq!(h.app.trials_wanted, 20);
}

#[test]
fn export_asks_before_overwriting() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    h.key(KeyCode::Char('x'));
    let Some(Effect::Export { stem, .. }) = h.pending.first().cloned() else {
        panic!("an export effect");
    };
    assert_eq!(stem, "platform_seed1_aux+1.00");
    h.settle();
    let yaml_path = dir.path().join("platform").join(format!("{stem}.yaml"));
    let glb_path = dir.path().join("platform").join(format!("{stem}.glb"));
    let level = yaml::load(&yaml_path).expect("the export loads");
    assert_eq!(
        level.stats.as_ref().map(|s| s.trials),
        Some(app::DEFAULT_TRIALS)
    );
    assert!(h.app.status.as_ref().unwrap().0.contains("exported"));
    gltf::Gltf::open(&glb_path).expect("a valid glb");

    let before = std::fs::read(&yaml_path).unwrap();
    h.key(KeyCode::Right); // nothing changes at +1: same level, same name
    h.key(KeyCode::Char('x'));
    h.settle();
    assert!(matches!(h.app.overlay, Overlay::ConfirmOverwrite { ref paths } if paths.len() == 2));
    h.key(KeyCode::Char('n'));
    h.settle();
    assert_eq!(h.app.overlay, Overlay::None);
    assert!(h.app.status.as_ref().unwrap().0.contains("nothing written"));
    assert_eq!(std::fs::read(&yaml_path).unwrap(), before);

    h.key(KeyCode::Char('x'));
    h.settle();
    h.key(KeyCode::Char('y'));
    let Some(Effect::Export { overwrite, .. }) = h.pending.first().cloned() else {
        panic!("an export effect");
    };
    assert!(overwrite);
    h.settle();
    assert!(h.app.status.as_ref().unwrap().0.contains("exported"));
}

/// `design --physics both --collision-names`: the designer's export writes its glTF so.
#[test]
fn export_writes_the_gltf_physics_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.app.gltf = GltfOptions {
        collision_names: true,
        physics: PhysicsExtensions::Both,
    };
    h.settle();
    h.key(KeyCode::Char('x'));
    h.settle();
    let glb = dir.path().join("platform/platform_seed1_aux+1.00.glb");
    let bytes = String::from_utf8_lossy(&std::fs::read(glb).unwrap()).into_owned();
    for name in ["OMI_physics_body", "KHR_physics_rigid_bodies", "-col"] {
        assert!(bytes.contains(name), "{name}");
    }
}

#[test]
fn loading_a_wrong_file_is_a_message_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    let bad = dir.path().join("bad.safetensors");
    std::fs::write(&bad, b"not a policy").unwrap();
    for path in [bad.display().to_string(), "no/such/folder".to_string()] {
        h.key(KeyCode::Char('p'));
        h.keys(&path);
        h.key(KeyCode::Enter);
        h.settle();
        let (text, is_error) = h.app.status.clone().unwrap();
        assert!(is_error, "{text}");
        assert!(text.contains(&path), "the message names the file: {text}");
    }
    assert_eq!(*h.app.policies(), LoadedInfo::default());
}

/// Tab switches to racing: a track of the same seed, its Solver statistics with the racing
/// outcomes and air time, the top-down road and its elevation, a selected segment, a replayed
/// run, the λ sweep, and an export that loads; Tab goes back to the platform level.
#[test]
fn racing_tracks_are_designed_like_platform_levels() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    let platform_level = h.app.level.clone();
    h.key(KeyCode::Tab);
    assert_eq!(h.app.game, Game::Racing);
    h.settle();
    let level = h.app.level.clone().expect("a racing track at once");
    let request = LevelRequest::new(1, Some(1.0))
        .obstacles(arlpcg_core::game::facts::facts(Game::Racing).scene_obstacles);
    let expected = arlpcg::services::generation::rules_level(Game::Racing, &request).unwrap();
    assert_eq!(*level, expected, "the rules' track of the seed");
    let trials = h.app.trials.as_ref().unwrap();
    assert_eq!(trials.stats.as_ref().unwrap().trials, app::DEFAULT_TRIALS);
    let screen = h.screen(100, 32);
    for part in [
        "top-down: ", " segments, ", "elevation: ", "off road ", "flipped ", "air time ",
        "Solver: scripted-expert", "failures per segment",
    ] {
        assert!(screen.contains(part), "{part} missing from\n{screen}");
    }
    h.key(KeyCode::Down);
    assert_eq!(h.app.selected, Some(0));
    assert!(h.screen(100, 32).contains("segment 0: "));
    h.key(KeyCode::Char('r'));
    h.settle();
    let replay = h.app.replay.as_ref().expect("a recorded run");
    assert!(replay.recording.path.len() > 10);
    h.key(KeyCode::Char('w'));
    h.settle();
    let sweep = h.app.sweep.as_ref().unwrap();
    assert!(
        sweep
            .points
            .iter()
            .all(|(_, p)| matches!(p, app::SweepPoint::Success(_))),
        "{:?}",
        sweep.points
    );
    h.key(KeyCode::Char('x'));
    h.settle();
    let exported = yaml::load(&dir.path().join("racing/racing_seed1_aux+1.00.yaml")).unwrap();
    assert_eq!(exported.racing(), level.racing());
    gltf::Gltf::open(dir.path().join("racing/racing_seed1_aux+1.00.glb")).expect("a valid glb");
    h.key(KeyCode::Tab);
    h.settle();
    assert_eq!(h.app.game, Game::Platform);
    assert_eq!(
        h.app.level, platform_level,
        "the same platform level as before"
    );
    h.key(KeyCode::Char('q'));
    assert_eq!(h.app.mode, Mode::Quitting);
}

/// The workers answer the newest request of a kind: trials of a level the slider has moved
/// away from stop, and never report final statistics or another trial after the newer answer.
#[test]
fn newer_requests_supersede_older_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    let level = h.app.level.clone().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let workers = Workers::start(GamePolicies::default(), tx, None).unwrap();
    let deadline = Instant::now() + Duration::from_secs(60);
    let next = || {
        rx.recv_timeout(deadline.saturating_duration_since(Instant::now()))
            .expect("an answer within a minute")
    };
    workers.submit(Effect::Trials {
        id: 100,
        level,
        trials: 100_000,
        seed: 1,
    });
    // The first trial's answer: the long run of trials is under way.
    match next() {
        Response::Trial { id: 100, .. } => {}
        other => panic!("expected a trial of request 100, got {other:?}"),
    }
    let generate = |id| Effect::Generate {
        id,
        game: Game::Platform,
        seed: id,
        goal: None,
        ask: Ask::Aux(0.0),
        keep: None,
        trials: 100,
        profile: None,
        knobs: Vec::new(),
        want: None,
    };
    workers.submit(generate(101));
    loop {
        match next() {
            Response::Level { id: 101, result } => {
                assert!(result.is_ok());
                break;
            }
            Response::Trial { id: 100, .. } => {}
            Response::TrialsDone { id: 100, .. } => panic!("superseded trials finished"),
            other => panic!("unexpected {other:?}"),
        }
    }
    // Once the newer level is answered, the superseded trials say nothing more: the next
    // answer is the one asked for after it.
    workers.submit(generate(102));
    match next() {
        Response::Level { id: 102, result } => assert!(result.is_ok()),
        other => panic!("after the superseding answer, expected level 102, got {other:?}"),
    }
}

/// The newcomer's session on the shipped policies: start, move λ, generate, trials, export;
/// the files load and the .glb validates.
#[test]
fn scripted_session_on_the_shipped_policies() {
    let shipped = shipped_platform();
    let (policies, info) =
        worker::load(&shipped, Game::Platform).expect("the shipped policies load");
    assert!(info.solver.is_some(), "a Solver is shipped");
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::new(policies, info, dir.path());
    h.settle();
    assert!(h.app.level.is_some(), "a level at once");
    // Training budgets in the header where they fit, each in its policy's unit.
    let wide = h.screen(120, 36);
    assert!(wide.contains("Generator: arlpcg ") && wide.contains("M blocks  Solver: arlpcg "));
    assert!(wide.contains("M steps"));
    assert!(
        h.screen(80, 24)
            .contains("Generator: arlpcg  Solver: arlpcg ")
    );
    h.key(KeyCode::Left);
    h.key(KeyCode::Left);
    h.key(KeyCode::Enter);
    h.settle();
    let trials = h.app.trials.as_ref().unwrap();
    assert_eq!(trials.stats.as_ref().unwrap().trials, app::DEFAULT_TRIALS);
    assert!(h.screen(80, 24).contains("trials 100/100  successes"));
    h.key(KeyCode::Char('x'));
    h.settle();
    let yaml_path = dir.path().join("platform/platform_seed1_aux+0.80.yaml");
    let level = yaml::load(&yaml_path).expect("the export loads");
    assert_eq!(level.aux, Some(0.8));
    // The exported statistics are the ones on screen.
    assert_eq!(
        level.stats.as_ref(),
        h.app.trials.as_ref().and_then(|t| t.stats.as_ref())
    );
    let glb = dir.path().join("platform/platform_seed1_aux+0.80.glb");
    gltf::Gltf::open(&glb).expect("a valid glb");
    // Left for `.ci/run` to pass through the Khronos validator.
    let exports = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gltf-exports");
    std::fs::create_dir_all(&exports).unwrap();
    std::fs::copy(&glb, exports.join("designer-session.glb")).unwrap();
    assert_eq!(level.seed, Some(1));
    assert!(matches!(h.app.status, Some((ref t, false)) if t.contains("exported")));
}

/// Target-success mode: the designer asks for 60%, the search finds a level, the slider shows
/// the λ it used, and the Solver's measured success on screen is within ±0.1 of the target;
/// moving the slider leaves the mode. Without a Generator the mode is refused with a reason.
#[test]
fn target_success_mode_finds_a_level_in_band() {
    let dir = tempfile::tempdir().unwrap();
    let mut rules = Harness::rules(dir.path());
    rules.settle();
    rules.key(KeyCode::Char('T'));
    rules.keys("0.6");
    rules.key(KeyCode::Enter);
    assert!(rules.pending.is_empty());
    let (text, is_error) = rules.app.status.clone().unwrap();
    assert!(is_error && text.contains("needs a Generator"), "{text}");

    let mut h = Harness::shipped(dir.path());
    h.settle();
    h.key(KeyCode::Char('T'));
    h.keys("0.6");
    h.key(KeyCode::Enter);
    assert!(
        matches!(h.pending[..], [Effect::Generate { ask: Ask::Success(target), .. }] if target == 0.6)
    );
    h.settle();
    let level = h.app.level.clone().expect("a level in the band");
    assert_eq!(
        h.app.aux,
        level.aux.unwrap(),
        "the slider shows the λ found"
    );
    let trials = h.app.trials.as_ref().unwrap();
    let (success, _) = trials.success().unwrap();
    assert!((success - 0.6).abs() <= 0.1 + 1e-9, "measured {success}");
    assert!(h.screen(80, 24).contains("for success 0.60"));
    h.key(KeyCode::Right);
    assert_eq!(h.app.ask.success(), None, "the slider leaves target mode");
    assert!(matches!(h.pending[..], [Effect::Generate { .. }]));
}

/// `W` takes a wish list or a sentence: each level is searched to meet it, the slider shows
/// the λ found, and the statistics show each constraint ✓ or ✗ with its value; a constraint the
/// game does not have is a message; empty lets it go.
#[test]
fn a_typed_wish_list_is_searched_for_and_checked_on_screen() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::shipped(dir.path());
    h.settle();
    h.key(KeyCode::Char('W'));
    h.keys("a short level that climbs, purple");
    h.key(KeyCode::Enter);
    let (said, _) = h.app.status.clone().unwrap();
    assert!(
        said.contains("wish list: pieces <= 7, climb >= 5") && said.contains("not used: purple"),
        "{said}"
    );
    assert!(matches!(
        &h.pending[..],
        [Effect::Generate { want: Some(_), .. }]
    ));
    h.settle();
    let level = h
        .app
        .level
        .clone()
        .expect("a level that meets the wish list");
    assert!(level.piece_count() <= 7);
    let record = level.want.as_ref().expect("the level records its want");
    assert_eq!(record.asked, "pieces <= 7, climb >= 5");
    assert_eq!(
        h.app.aux,
        level.aux.unwrap(),
        "the slider shows the λ found"
    );
    let screen = h.screen(100, 40);
    assert!(
        screen.contains("✓ pieces <= 7") && screen.contains("✓ climb >= 5"),
        "{screen}"
    );
    h.key(KeyCode::Char('W'));
    for _ in 0..40 {
        h.key(KeyCode::Backspace);
    }
    h.keys("curviness >= 0.5");
    h.key(KeyCode::Enter);
    let (said, is_error) = h.app.status.clone().unwrap();
    assert!(is_error && said.contains("`curviness`"), "{said}");
    // Each game keeps its own wish list: Tab to racing finds none (`stride` racing levels do not
    // have), and Tab back finds platform's as it was left.
    h.key(KeyCode::Char('W'));
    for _ in 0..40 {
        h.key(KeyCode::Backspace);
    }
    h.keys("stride >= 0");
    h.key(KeyCode::Enter);
    assert_eq!(
        h.app.want().map(ToString::to_string).as_deref(),
        Some("stride >= 0")
    );
    h.key(KeyCode::Tab);
    assert_eq!(h.app.game, Game::Racing);
    assert!(h.app.want().is_none());
    h.key(KeyCode::Tab);
    let (said, _) = h.app.status.clone().unwrap();
    assert!(said.contains("platform's wish list: stride >= 0"), "{said}");
    assert_eq!(
        h.app.want().map(ToString::to_string).as_deref(),
        Some("stride >= 0")
    );
    h.key(KeyCode::Char('W'));
    for _ in 0..40 {
        h.key(KeyCode::Backspace);
    }
    h.key(KeyCode::Enter);
    assert!(h.app.want().is_none());
}

/// Trials that cannot be played (here a racing Solver put on the platform game) say why, on the
/// stats panel and the status line, instead of vanishing.
#[test]
fn trials_that_fail_say_why() {
    let dir = tempfile::tempdir().unwrap();
    let racing = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/racing");
    let (racing, _) =
        worker::load(&racing, Game::Racing).expect("the shipped racing policies load");
    let wrong = Policies {
        generator: None,
        solver: racing.solver.clone(),
        ..Policies::default()
    };
    let mut h = Harness::new(wrong, LoadedInfo::default(), dir.path());
    h.settle();
    assert!(h.app.level.is_some(), "the rule level is on screen");
    let trials = h.app.trials.as_ref().expect("trials were started");
    let problem = trials
        .error
        .as_deref()
        .expect("the trials' failure is kept");
    assert!(problem.contains("racing"), "{problem}");
    let screen = h.screen(100, 30);
    assert!(screen.contains("stopped:"), "{screen}");
}

/// The README's key table is the designer's key map (`view::KEYS`), row for row.
#[test]
fn the_readme_key_table_is_the_key_map() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let start = readme
        .find("<!-- keys:")
        .expect("the README marks its key table");
    let end = readme.find("<!-- /keys -->").expect("the key table ends");
    let table: Vec<&str> = readme[start..end].lines().skip(3).collect();
    let expected: Vec<String> = view::KEYS
        .iter()
        .map(|(keys, what)| format!("| `{keys}` | {what} |"))
        .collect();
    assert_eq!(
        table, expected,
        "README.md's key table differs from view::KEYS"
    );
}

/// Pacing keys on the shipped policies: `P` steps through the presets (the level follows the
/// curve, each piece coloured by its λ), `C` takes a typed curve and names a bad one, `k` keeps
/// the pieces up to the selected one through regenerations, `K` lets go; the slider goes back
/// to one λ.
#[test]
fn pacing_keys_set_a_curve_and_keep_a_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::shipped(dir.path());
    h.settle();
    h.key(KeyCode::Char('P'));
    assert!(
        matches!(&h.pending[..], [Effect::Generate { ask: Ask::Curve(c), .. }] if c.to_string() == "0:1, 1:-1"),
        "{:?}",
        h.pending
    );
    h.settle();
    let level = h.app.level.clone().unwrap();
    let pacing = level.pacing.as_ref().expect("a paced level on screen");
    assert_eq!(
        pacing.piece_aux.first(),
        Some(&Some(1.0)),
        "easy at the start"
    );
    insta::assert_snapshot!("pacing_ramp_up_120x36", h.screen(120, 36));
    // The next preset, then a typed curve, then a bad one.
    h.key(KeyCode::Char('P'));
    assert_eq!(
        arlpcg::shells::design::app::pacing::preset_name(h.app.ask.curve().unwrap()),
        "ramp down"
    );
    h.key(KeyCode::Char('C'));
    for _ in 0..20 {
        h.key(KeyCode::Backspace);
    }
    h.keys("0:-1, 0.5:-1, 0.6:1, 1:1");
    h.key(KeyCode::Enter);
    assert_eq!(
        arlpcg::shells::design::app::pacing::preset_name(h.app.ask.curve().unwrap()),
        "custom"
    );
    h.key(KeyCode::Char('C'));
    h.keys(", 0.2:1");
    h.key(KeyCode::Enter);
    let (status, problem) = h.app.status.clone().unwrap();
    assert!(problem && status.contains("must increase"), "{status}");
    h.settle();
    // Keep the first two blocks; regenerations with new seeds keep them.
    let before = h.app.level.clone().unwrap();
    h.key(KeyCode::Down);
    h.key(KeyCode::Down);
    h.key(KeyCode::Char('k'));
    h.settle();
    assert_eq!(h.app.kept.as_ref().unwrap().pieces, 2);
    h.key(KeyCode::Char('n'));
    h.settle();
    let after = h.app.level.clone().unwrap();
    assert_eq!(
        after.platform().unwrap().block_params()[..2],
        before.platform().unwrap().block_params()[..2]
    );
    assert!(matches!(
        after.source,
        arlpcg_core::level::Source::Kept { pieces: 2, .. }
    ));
    assert!(
        h.app.export_stem().ends_with("_pacing-custom_keep2"),
        "{}",
        h.app.export_stem()
    );
    h.key(KeyCode::Char('K'));
    assert!(h.app.kept.is_none());
    // The slider: one λ again.
    h.key(KeyCode::Left);
    assert!(h.app.ask.curve().is_none());
    h.settle();
    assert!(h.app.level.as_ref().unwrap().pacing.is_none());
}

/// `j` hands the trials to the next judge: the folder's other Solvers in turn, then the scripted
/// player at each skill, then back; the header and the statistics say who plays.
#[test]
fn the_judge_key_cycles_through_the_panel() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::shipped(dir.path());
    h.settle();
    let mut seen = Vec::new();
    for _ in 0..7 {
        h.key(KeyCode::Char('j'));
        h.settle();
        let judge = h.app.policies().judge().name();
        let trials = h
            .app
            .trials
            .as_ref()
            .and_then(|t| t.stats.as_ref())
            .unwrap();
        match &trials.solver {
            arlpcg_core::level::SolverRef::Scripted { skill } => {
                assert_eq!(judge, format!("scripted-{skill}"));
                assert!(
                    h.screen(80, 24)
                        .contains(&format!("Solver: scripted-{skill}"))
                );
            }
            arlpcg_core::level::SolverRef::Policy { policy } => {
                assert!(policy.path.contains("solver"), "{}", policy.path);
            }
            other => panic!("{other:?}"),
        }
        seen.push(judge);
    }
    assert_eq!(
        seen,
        [
            "rule-pcg", "fixed-track", "fixed-aux", "scripted-novice", "scripted-median",
            "scripted-expert", "arlpcg"
        ]
    );
}

/// `J`: every judge of the folder plays the level on screen and the level is rated; the panel
/// follows a new level while it is shown, an export records it, and `verify --panel` on the
/// exported file gives the same figures.
#[test]
fn the_whole_panel_plays_the_level_on_screen_and_the_export_records_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::shipped(dir.path());
    h.settle();
    h.key(KeyCode::Char('J'));
    assert_eq!(h.app.panel, app::SidePane::Judges);
    h.settle();
    let judging = h.app.judging.clone().expect("the panel played");
    let names: Vec<&str> = judging.judges.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "arlpcg", "rule-pcg", "fixed-track", "fixed-aux", "scripted-novice", "scripted-median",
            "scripted-expert"
        ]
    );
    let stats = judging.stats.clone().expect("rated once all played");
    assert!(stats.rating.is_some());
    insta::assert_snapshot!("judges_panel_120x36", h.screen(120, 36));
    // A new level is measured afresh while the panel is shown.
    h.key(KeyCode::Left);
    h.settle();
    let again = h.app.judging.clone().unwrap();
    assert_eq!(Some(&again.level), h.app.level.as_ref());
    assert_ne!(again.level, judging.level);
    assert!(again.stats.is_some());

    h.key(KeyCode::Char('x'));
    h.settle();
    let stem = h.app.export_stem();
    let file = dir.path().join("platform").join(format!("{stem}.yaml"));
    let exported = yaml::load(&file).unwrap();
    let recorded = exported
        .stats
        .unwrap()
        .panel
        .expect("the export records the panel");
    assert_eq!(Some(&recorded), again.stats.as_ref());
    let verified = crate::common::arlpcg_ok(crate::common::words(
        "verify {} --panel --trials 40 --json --policies {}",
        &[&file, &shipped_platform()],
    ));
    let row: serde_json::Value = serde_json::from_slice(&verified.stdout).unwrap();
    for judge in &recorded.judges {
        assert_eq!(
            row["panel"][&judge.judge].as_f64(),
            Some(judge.success_ratio),
            "{}",
            judge.judge
        );
    }
    assert_eq!(
        row["rating"]["b"].as_f64(),
        recorded.rating.map(|r| r.b),
        "the same rating"
    );
}

/// Under `NO_COLOR` (the shell sets `App::colour` from it) every cell is drawn in the
/// terminal's own colours, with the same text.
#[test]
fn no_color_draws_the_same_screen_without_colours() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::rules(dir.path());
    h.settle();
    let cells = |h: &Harness| {
        let mut terminal = Terminal::new(TestBackend::new(120, 36)).unwrap();
        terminal.draw(|f| view::render(&h.app, f)).unwrap();
        terminal.backend().buffer().content.clone()
    };
    let coloured = cells(&h);
    let plain_colour = |c: &ratatui::buffer::Cell| {
        c.fg == ratatui::style::Color::Reset && c.bg == ratatui::style::Color::Reset
    };
    assert!(!coloured.iter().all(plain_colour), "colours by default");
    let text = h.screen(120, 36);
    h.app.colour = false;
    assert!(cells(&h).iter().all(plain_colour));
    assert_eq!(h.screen(120, 36), text, "the same text");
}

/// `o`: a campaign folder opens on its view (one column per level under the ramp's bars, the
/// funnel's end); `→` and `Enter` open level 2 on the screen, with its trials; `o` comes back,
/// and `R` searches level 2 anew and rewrites the campaign.
#[test]
fn the_campaign_view_opens_a_campaign_and_its_levels() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("campaign");
    let made = crate::common::small_campaign(&folder, &[]);
    assert!(made.status.success(), "{}", crate::common::stderr(&made));
    let mut h = Harness::shipped(dir.path());
    h.settle();
    h.key(KeyCode::Char('o'));
    h.keys(folder.to_str().unwrap());
    h.key(KeyCode::Enter);
    h.settle();
    assert_eq!(h.app.overlay, Overlay::Campaign);
    h.key(KeyCode::Right);
    insta::assert_snapshot!("campaign_view_120x36", h.screen(120, 36));
    h.key(KeyCode::Enter);
    h.settle();
    assert_eq!(h.app.overlay, Overlay::None);
    let expected = yaml::load(&folder.join("level02.yaml")).unwrap();
    let shown = h.app.level.as_ref().expect("level 2 on screen");
    assert_eq!(shown.track, expected.track);
    assert!(h.app.trials.as_ref().unwrap().stats.is_some());
    h.key(KeyCode::Char('o'));
    assert_eq!(h.app.overlay, Overlay::Campaign);
    // R: level 2 searched anew from an unused seed, the campaign rated again and rewritten.
    h.key(KeyCode::Char('R'));
    h.settle();
    let (status, problem) = h.app.status.clone().unwrap();
    assert!(
        !problem && status.starts_with("level 2 searched anew"),
        "{status}"
    );
    let record: serde_yaml::Value =
        serde_yaml::from_slice(&std::fs::read(folder.join("campaign.yaml")).unwrap()).unwrap();
    let level = &record["levels"][1];
    assert_eq!(level["seed"].as_u64(), Some(43));
    let (asked, measured) = (
        level["asked"].as_f64().unwrap(),
        level["measured"].as_f64().unwrap(),
    );
    assert!((asked - measured).abs() <= 0.1 + 1e-9, "{asked} {measured}");
    assert_ne!(
        yaml::load(&folder.join("level02.yaml")).unwrap().track,
        expected.track
    );
    h.key(KeyCode::Esc);
    assert_eq!(h.app.overlay, Overlay::None);
    // A folder without a campaign is a message.
    h.key(KeyCode::Char('o'));
    h.key(KeyCode::Char('o'));
    h.keys("/nonexistent");
    h.key(KeyCode::Enter);
    h.settle();
    let (status, problem) = h.app.status.clone().unwrap();
    assert!(problem && status.contains("no campaign opened"), "{status}");
}
