use super::*;
use crate::services::verify::ProfileFit;

/// A Generator's reach is read from its card: none, or a count of runs within its game's
/// range; a card out of range, or one of a game without a reach, names the file and field.
#[test]
fn a_generators_reach_runs_come_from_its_card_within_its_games_range() {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    let card = load_generator(&shipped.join(GENERATOR_FILE), Game::Platform)
        .unwrap()
        .1;
    let path = Path::new("g.safetensors");
    assert_eq!(generator_limits(path, &card).unwrap().reach_runs, Some(4));
    let uncut = PolicyCard {
        reach_runs: None,
        ..card.clone()
    };
    assert_eq!(generator_limits(path, &uncut).unwrap().reach_runs, None);
    let with = |game, runs| PolicyCard {
        game,
        reach_runs: Some(runs),
        ..card.clone()
    };
    let four = generator_limits(path, &with(Game::Platform, 4)).unwrap();
    assert_eq!(four.reach_runs, Some(4));
    for (game, runs, says) in [
        (
            Game::Platform,
            0,
            "card field reach_runs is 0, outside [1, 8]",
        ),
        (
            Game::Platform,
            9,
            "card field reach_runs is 9, outside [1, 8]",
        ),
        (
            Game::Racing,
            4,
            "the racing Generator's pieces are not cut to a reach",
        ),
    ] {
        let error = generator_limits(path, &with(game, runs))
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("g.safetensors: ") && error.contains(says),
            "{error}"
        );
    }
}

/// A profile's λ→success curve is kept in its own file: the built-in game's curve is never
/// used for a profile's levels, nor the profile's for the built-in game's.
#[test]
fn a_profiles_curve_is_kept_apart_from_the_built_in_games() {
    use crate::services::difficulty::{Curve, TargetError};
    use crate::services::verify::Solver;
    let dir = tempfile::tempdir().unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    let generator = load_generator(&shipped.join(GENERATOR_FILE), Game::Platform)
        .unwrap()
        .0;
    let solver = Solver::Scripted(arlpcg_core::game::Skill::Median);
    let profile = Profile::default_of(Game::Platform)
        .with_value("character.jump_speed", 7.5)
        .unwrap();
    let built_in = Curve {
        generator_sha256: generator.reference.sha256.clone(),
        solver_sha256: "scripted-median".into(),
        profile_sha256: None,
        points: vec![(1.0, 0.9)],
    };
    let for_profile = Curve {
        profile_sha256: Some(profile.sha256()),
        points: vec![(1.0, 0.4)],
        ..built_in.clone()
    };
    let stem = dir.path().join("difficulty-curve-scripted-median");
    let profile_file = stem.with_extension(format!("profile-{}.yaml", &profile.sha256()[..12]));
    for (curve, path) in [
        (&built_in, stem.with_extension("yaml")),
        (&for_profile, profile_file.clone()),
    ] {
        std::fs::write(path, serde_yaml::to_string(curve).unwrap()).unwrap();
    }
    let read = |profile: Option<&Profile>| {
        let measured = std::cell::Cell::new(false);
        let curve = difficulty_curve(
            (dir.path(), None),
            &generator,
            &solver,
            profile,
            || measured.set(true),
            &|| true,
        );
        (curve, measured.get())
    };
    assert_eq!(read(None).0.unwrap(), built_in);
    assert_eq!(read(Some(&profile)).0.unwrap(), for_profile);
    // Without its own file, the profile's curve is measured (here stopped at once).
    std::fs::remove_file(&profile_file).unwrap();
    let (curve, measured) = read(Some(&profile));
    assert!(measured);
    assert!(matches!(
        curve.unwrap_err().downcast_ref(),
        Some(TargetError::Stopped)
    ));
}

#[test]
fn only_the_folders_own_solver_uses_the_folders_curve_file() {
    let dir = tempfile::tempdir().unwrap();
    let other = tempfile::tempdir().unwrap();
    for path in [
        dir.path().join(SOLVER_FILE),
        dir.path().join("solver-rule-pcg.safetensors"),
        other.path().join(SOLVER_FILE),
    ] {
        std::fs::write(path, b"weights").unwrap();
    }
    let own = curve_path(dir.path(), &dir.path().join(SOLVER_FILE), "ab12");
    assert_eq!(own, dir.path().join(CURVE_FILE));
    let spelled_otherwise = dir.path().join(".").join(SOLVER_FILE);
    assert_eq!(
        curve_path(dir.path(), &spelled_otherwise, "ab12"),
        dir.path().join(CURVE_FILE)
    );
    let baseline = curve_path(
        dir.path(),
        &dir.path().join("solver-rule-pcg.safetensors"),
        "0123456789abcdef",
    );
    assert_eq!(
        baseline,
        dir.path()
            .join("difficulty-curve-solver-rule-pcg-0123456789ab.yaml")
    );
    // Another folder's Solver of the same file name: its own curve file, told apart by hash.
    let foreign = curve_path(
        dir.path(),
        &other.path().join(SOLVER_FILE),
        "fedcba9876543210",
    );
    assert_eq!(
        foreign,
        dir.path().join("difficulty-curve-solver-fedcba987654.yaml")
    );
}

/// The shipped platform Solver plays every character within the ranges it trained over and
/// refuses one beyond them, naming the range.
#[test]
fn the_shipped_platform_solver_plays_the_characters_within_its_ranges() {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/platform");
    let jumping = |jump_speed: f64| {
        Profile::default_of(Game::Platform)
            .with_value("character.jump_speed", jump_speed)
            .unwrap()
    };
    let solver = load_solver(&shipped.join(SOLVER_FILE), Game::Platform)
        .unwrap()
        .0;
    for profile in [None, Some(jumping(4.5)), Some(jumping(10.5))] {
        assert_eq!(solver.fit(profile.as_ref()), ProfileFit::Fits);
    }
    match solver.fit(Some(&jumping(12.0))) {
        ProfileFit::Beyond(problem) => assert!(problem.contains("jump_speed"), "{problem}"),
        other => panic!("{other:?}"),
    }
}
