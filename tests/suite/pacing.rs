//! Pacing: λ along a level (`generate --aux-curve`). Each piece is built at the curve's value
//! where it begins and records it; the shipped racing Generator follows a λ that changes
//! within a level in a track's second half (the recipe's platform one does so weakly:
//! measured at 93fa40a, whose docs/results.md had a "Pacing" section); bad curves are refused with the reason.

use std::path::Path;

use arlpcg::services::generation::{AuxAsk, LevelRequest, generator_level};
use arlpcg::services::policies::{load_generator, load_solver, policy_paths};
use arlpcg::services::verify::{HalfwaySplit, Solver, verify};
use arlpcg_core::level::pacing::{AuxCurve, round_aux};
use arlpcg_core::level::{Game, yaml};

use crate::common::{arlpcg, arlpcg_ok, stderr, words};
use arlpcg_core::game::GameSpec;

const EASY_THEN_HARD: &str = "0:1, 0.5:1, 0.5:-1, 1:-1";

fn shipped(game: Game) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies")
        .join(game.name())
}

#[test]
fn each_piece_is_built_at_the_curves_value_where_it_begins_and_records_it() {
    let curve = AuxCurve::parse(EASY_THEN_HARD).unwrap();
    for game in [Game::Platform, Game::Racing] {
        let (generator, _) = load_generator(&policy_paths(&shipped(game)).0, game).unwrap();
        let request = LevelRequest::new(3, None)
            .obstacles(arlpcg_core::game::facts::facts(game).scene_obstacles)
            .aux(AuxAsk::Curve(curve.clone()));
        let level = generator_level(&generator, &request).unwrap();
        let pacing = level
            .pacing
            .as_ref()
            .expect("a curve level records its pacing");
        assert_eq!(level.aux, None, "{game}: one λ or a curve, not both");
        let expected: Vec<Option<f64>> = level
            .piece_start_fractions()
            .iter()
            .map(|&f| Some(round_aux(curve.at(f))))
            .collect();
        assert_eq!(pacing.piece_aux, expected, "{game}");
        assert!(
            expected.contains(&Some(1.0)) && expected.contains(&Some(-1.0)),
            "{game}: both halves of the curve are in the level: {expected:?}"
        );
        let text = yaml::to_string(&level);
        assert!(
            text.contains(&format!("aux_curve: {EASY_THEN_HARD}")),
            "{text}"
        );
        assert_eq!(
            yaml::parse(&text).unwrap(),
            level,
            "{game}: reads back equal"
        );
    }
}

/// The shipped racing Generator follows λ early in a track: the first half of a hard-then-easy
/// track fails more often than that of an easy-then-hard one. After an easy first half it does
/// not make the second half hard (docs/decisions.md#d12), so that half is not asked of it here.
#[test]
fn the_shipped_racing_generator_makes_a_tracks_first_half_as_hard_as_the_curve_asks() {
    let game = Game::Racing;
    let dir = shipped(game);
    let (generator, _) = load_generator(&policy_paths(&dir).0, game).unwrap();
    let (solver, _) = load_solver(&policy_paths(&dir).1, game).unwrap();
    let split = |curve: &str| {
        let mut split = HalfwaySplit::default();
        for seed in 100..106 {
            let request = LevelRequest::new(seed, None)
                .obstacles(arlpcg_core::game::facts::facts(game).scene_obstacles)
                .aux(AuxAsk::Curve(AuxCurve::parse(curve).unwrap()));
            let level = generator_level(&generator, &request).unwrap();
            let stats = verify(&level, &Solver::Policy(&solver), 20, seed, &|| {}).unwrap();
            split.add(&level, &stats);
        }
        split
    };
    let easy_then_hard = split(EASY_THEN_HARD);
    let hard_then_easy = split("0:-1, 0.5:-1, 0.5:1, 1:1");
    // Measured with the shipped pair (seed 0 of the recipe with retries, D16): 0.24 failures per
    // piece before halfway (21 on 88 pieces, 20 runs each) against 0.00 (0 on 57); over 20
    // tracks of 50 runs (seed 500 on), 1.10 against 0.01 per piece, 89% of the hard-then-easy
    // failures before halfway.
    let before = [hard_then_easy.per_piece()[0], easy_then_hard.per_piece()[0]];
    assert!(
        before[0] >= 0.1 && before[0] >= 1.5 * before[1],
        "failures per piece before halfway: hard then easy {hard_then_easy:?}, easy then hard {easy_then_hard:?}"
    );
}

#[test]
fn bad_curves_are_refused_with_the_reason() {
    let out_dir = tempfile::tempdir().unwrap();
    let out = out_dir.path().to_str().unwrap();
    let policies = shipped(Game::Platform);
    let policies = policies.to_str().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (
            &["--policies", policies, "--aux-curve", "0:1, 0.5"],
            "not `fraction:λ`",
        ),
        (
            &["--policies", policies, "--aux-curve", "0:1, 0.5:3"],
            "out of range",
        ),
        (
            &["--policies", policies, "--aux-curve=0:1", "--aux", "1"],
            "cannot be used with",
        ),
        (
            &["--rules", "--aux-curve", "0:1"],
            "--aux-curve needs --policies",
        ),
    ];
    for (args, expected) in cases {
        let mut all = vec!["generate", "--game", "platform", "--out", out];
        all.extend_from_slice(args);
        let output = arlpcg(&all);
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    assert_eq!(
        std::fs::read_dir(out).unwrap().count(),
        0,
        "nothing written"
    );
}

#[test]
fn a_piece_aux_without_a_curve_names_the_field() {
    let level = arlpcg_core::game::PlatformGame::rule_level(5, &Default::default()).unwrap();
    let text = yaml::to_string(&level).replacen("  height:", "  aux: -1.0\n  height:", 1);
    let err = yaml::parse(&text).unwrap_err().to_string();
    assert!(
        err.starts_with("blocks[0].aux: a piece's own λ needs `aux_curve`"),
        "{err}"
    );
    let with_curve = text.replacen("start:", "aux_curve: 0:1\nstart:", 1);
    let err = yaml::parse(&with_curve).unwrap_err().to_string();
    assert!(err.starts_with("blocks[1].aux: missing"), "{err}");
}

/// The one file `generate` wrote into `dir`.
fn only_file(dir: &Path) -> std::path::PathBuf {
    std::fs::read_dir(dir)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path()
}

/// The text of each item of the top-level list `key` of a level file, as written.
fn items(text: &str, key: &str) -> Vec<String> {
    let body = text.split(&format!("\n{key}:\n")).nth(1).unwrap();
    let mut items: Vec<String> = Vec::new();
    for line in body.lines() {
        if line.starts_with("- ") {
            items.push(String::new());
        } else if !line.starts_with("  ") {
            break;
        }
        items.last_mut().unwrap().push_str(line);
        items.last_mut().unwrap().push('\n');
    }
    items
}

#[test]
fn a_kept_prefix_is_written_byte_for_byte_and_the_generator_builds_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    for (game, key, obstacles) in [
        (Game::Platform, "blocks", "0"),
        (Game::Racing, "segments", "3"),
    ] {
        let policies = shipped(game);
        let policies = policies.to_str().unwrap();
        let first = dir.path().join(format!("{game}-first"));
        arlpcg_ok(words(
            "generate --game {} --policies {} --aux-curve {} --obstacles {} --seed 3 --format yaml --out {}",
            &[&game.name(), &policies, &EASY_THEN_HARD, &obstacles, &first],
        ));
        let first_file = only_file(&first);
        let first_text = std::fs::read_to_string(&first_file).unwrap();
        let first_items = items(&first_text, key);
        let keep = first_items.len() / 2;
        assert!(keep >= 1, "{first_text}");
        let second = dir.path().join(format!("{game}-second"));
        arlpcg_ok(words(
            "generate --game {} --policies {} --aux=-1 --keep {} --seed 11 --verify 5 --format yaml --out {}",
            &[
                &game.name(),
                &policies,
                &format!("{}:{keep}", first_file.display()),
                &second,
            ],
        ));
        let second_file = only_file(&second);
        assert!(
            second_file
                .to_str()
                .unwrap()
                .ends_with(&format!("_keep{keep}.yaml"))
        );
        let second_text = std::fs::read_to_string(&second_file).unwrap();
        let second_items = items(&second_text, key);
        assert_eq!(
            second_items[..keep],
            first_items[..keep],
            "{game}: the kept pieces"
        );
        assert_ne!(
            second_items[keep..],
            first_items[keep..],
            "{game}: a new rest"
        );
        let level = yaml::load(&second_file).unwrap();
        assert!(
            matches!(&level.source, arlpcg_core::level::Source::Kept { pieces, .. } if *pieces as usize == keep),
            "{game}: {:?}",
            level.source
        );
        // The kept pieces keep their λ; the rest was built at -1 (a flat λ after a paced prefix
        // is the flat curve `0:-1`).
        let pacing = level.pacing.unwrap();
        assert_eq!(pacing.curve.to_string(), "0:-1");
        assert!(
            pacing.piece_aux[keep..].iter().all(|a| *a == Some(-1.0)),
            "{game}"
        );
        assert!(level.stats.is_some(), "{game}: verified as usual");
    }
}

#[test]
fn a_prefix_that_cannot_be_kept_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let staircase = Path::new(env!("CARGO_MANIFEST_DIR")).join("levels/hand/staircase.yaml");
    let staircase = staircase.to_str().unwrap();
    let policies = shipped(Game::Platform);
    let policies = policies.to_str().unwrap();
    let keep_all = format!("{staircase}:7");
    let keep_many = format!("{staircase}:99");
    let cases: [(&[&str], i32, &str); 4] = [
        (&["--keep", staircase], 2, "is not LEVEL.yaml:K"),
        (
            &["--keep", &keep_many],
            1,
            "asks for 99 pieces, but the level has 7",
        ),
        (&["--keep", &keep_all], 1, "already reach the goal"),
        (
            &["--keep", &keep_all, "--game", "racing"],
            1,
            "a platform level, but this run generates racing",
        ),
    ];
    for (args, code, expected) in cases {
        let mut all = vec![
            "generate", "--policies", policies, "--aux", "1", "--out", out,
        ];
        all.extend_from_slice(args);
        if !args.contains(&"--game") {
            all.extend(["--game", "platform"]);
        } else {
            all[2] = "policies/racing";
        }
        let output = arlpcg(&all);
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    }
    assert!(!Path::new(out).exists(), "nothing written");
}

#[test]
fn verify_draws_the_difficulty_along_one_level() {
    let dir = tempfile::tempdir().unwrap();
    let level = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("levels/pacing/platform_seed102_curve-db82f391.yaml");
    let level = level.to_str().unwrap();
    let chart = dir.path().join("pacing.png");
    let chart_s = chart.to_str().unwrap();
    let policy = shipped(Game::Platform).join("solver.safetensors");
    let policy = policy.to_str().unwrap();
    let output = arlpcg_ok(words(
        "verify {} --trials 20 --policy {} --chart {}",
        &[&level, &policy, &chart_s],
    ));
    assert!(std::fs::read(&chart).unwrap().starts_with(b"\x89PNG"));
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("runs past each block: "), "{stdout}");
    // Not over a file that is there; one level only.
    let again = arlpcg(words(
        "verify {} --trials 5 --policy {} --chart {}",
        &[&level, &policy, &chart_s],
    ));
    assert_eq!(again.status.code(), Some(1), "{}", stderr(&again));
    let two = arlpcg(words(
        "verify {} {} --chart {}",
        &[&level, &level, &chart_s],
    ));
    assert_eq!(two.status.code(), Some(2), "{}", stderr(&two));
}
