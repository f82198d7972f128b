use super::*;

#[test]
fn a_partial_file_takes_its_games_defaults_and_old_names_still_read() {
    let text = "generator:\n  ppo:\n    ent_coef: 0.001\n  generator_phase_steps: 20000\n";
    let racing = TrainConfig::parse_for(text, Game::Racing).unwrap();
    let mut expected = TrainConfig::for_game(Game::Racing);
    expected.generator.ppo.ent_coef = 0.001;
    expected.generator.generator_phase_steps = 20_000;
    assert_eq!(racing, expected);
    assert_eq!(racing.generator.rewards.air_step, 0.05);
    let platform = TrainConfig::parse_for(text, Game::Platform).unwrap();
    assert_eq!(platform.generator.rewards.air_step, 0.0);
    assert_eq!(platform.solver.gamma, 0.99);
    assert_eq!((platform.steps, racing.steps), (12_000_000, 5_000_000));
    let old = "ppo:\n  gamma: 0.95\ngenerator:\n  max_blocks: 12\n";
    let read = TrainConfig::parse_for(old, Game::Racing).unwrap();
    assert_eq!((read.solver.gamma, read.generator.max_pieces), (0.95, 12));
    assert_eq!(
        TrainConfig::parse_for("", Game::Racing).unwrap(),
        TrainConfig::for_game(Game::Racing)
    );
    assert_eq!(
        TrainConfig::for_game(Game::Racing).generator.curve_offset,
        90.0
    );
}

/// A file may name one field of the finish, or of its scripted opponent: the recipe's values
/// fill the rest (docs/training.md).
#[test]
fn a_partial_finish_keeps_the_recipes_other_fields() {
    let text = "generator:\n  finish:\n    scripted_opponent:\n      easy_only: true\n";
    let racing = TrainConfig::parse_for(text, Game::Racing).unwrap();
    let mut expected = TrainConfig::for_game(Game::Racing);
    let opponent = expected
        .generator
        .finish
        .scripted_opponent
        .as_mut()
        .unwrap();
    opponent.easy_only = true;
    assert_eq!(racing, expected);
    let entropy = "generator:\n  finish:\n    generator_entropy: 0.02\n";
    let platform = TrainConfig::parse_for(entropy, Game::Platform).unwrap();
    let mut expected = TrainConfig::for_game(Game::Platform);
    expected.generator.finish.generator_entropy = Some(0.02);
    assert_eq!(platform, expected);
    // The finish's own Generator learning rate reaches its schedule, and no earlier one.
    let rate = "generator:\n  finish: {generator_learning_rate: 0.001}\n";
    let platform = TrainConfig::parse_for(rate, Game::Platform).unwrap();
    assert_eq!(
        platform.schedule_at(platform.steps).generator_learning_rate,
        Some(0.001)
    );
    assert_eq!(
        platform
            .schedule_at(platform.steps - 1)
            .generator_learning_rate,
        None
    );
}

#[test]
fn the_platform_finish_follows_the_budget_and_stages_apply_from_their_step() {
    // The platform recipe's finish starts where its Solver's 12M end (its fields and racing's:
    // recipe.rs).
    assert_eq!(TrainConfig::default().generator.finish, PLATFORM_FINISH);
    let platform = TrainConfig::for_game(Game::Platform);
    assert_eq!(platform.adversarial_budget(), 12_040_000);
    let finish = platform.schedule_at(12_000_000);
    assert_eq!(
        (finish.solver_learning_rate, finish.snapshot_share),
        (Some(0.0), Some(0.0))
    );
    assert_eq!(platform.schedule_at(11_999_999).solver_learning_rate, None);
    assert_eq!(platform.lr_scale(12_010_000), 0.0);
    // A finish in which the Solver keeps learning, with its own phases.
    let learning = "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, solver_learning_rate: 1.0e-4, solver_phase_steps: 16}\n";
    let learning = TrainConfig::parse_for(learning, Game::Platform).unwrap();
    let finish = learning.schedule_at(learning.steps);
    assert_eq!(
        (
            finish.solver_learning_rate, finish.solver_phase_steps, finish.generator_phase_steps
        ),
        (Some(1.0e-4), 16, 9)
    );
    let staged = "generator:\n  snapshot_share: 0.5\n  stages:\n  - {from_steps: 100, solver_learning_rate: 0, solver_phase_steps: 8, generator_phase_steps: 9}\n  - {from_steps: 200, solver_learning_rate: 0, solver_phase_steps: 8, generator_phase_steps: 9, snapshot_share: 0}\n";
    let staged = TrainConfig::parse_for(staged, Game::Platform)
        .unwrap()
        .generator;
    assert_eq!(staged.schedule_at(99).generator_phase_steps, 5_000);
    let last = staged.schedule_at(100);
    assert_eq!(
        (
            last.solver_learning_rate, last.solver_phase_steps, last.generator_phase_steps
        ),
        (Some(0.0), 8, 9)
    );
    assert_eq!(
        [99, 100, 200].map(|steps| staged.schedule_at(steps).snapshot_share),
        [Some(0.5), Some(0.5), Some(0.0)]
    );
    let narrow = TrainConfig::parse_for("generator:\n  curve_offset: 30\n", Game::Racing).unwrap();
    assert_eq!(narrow.generator.curve_offset, 30.0);
    // A finish's reach holds in the finish only.
    let cut = TrainConfig::parse_for(
        "steps: 100\ngenerator:\n  finish: {reach_runs: 4}\n",
        Game::Platform,
    )
    .unwrap();
    assert_eq!(
        [99, 100].map(|steps| cut.schedule_at(steps).reach_runs),
        [None, Some(4)]
    );
    // Knobs drawn in the finish only: all 0 before it.
    let knobs =
        "steps: 100\ngenerator:\n  rewards: {knobs: [0.1, 0.1]}\n  finish: {knobs_only: true}\n";
    let knobs = TrainConfig::parse_for(knobs, Game::Platform).unwrap();
    assert_eq!(
        [99, 100].map(|steps| knobs.schedule_at(steps).draw_knobs),
        [false, true]
    );
}

/// The finish's reach and knobs: a count of runs outside the reach measurement's, a reach for
/// a game whose pieces have none, knobs in the finish of a Generator without knobs.
#[test]
fn finish_reach_and_knob_fields_that_cannot_hold_are_named() {
    for (text, game, says) in [
        (
            "generator:\n  finish: {reach_runs: 0}\n",
            Game::Platform,
            "finish.reach_runs must be within [1, 8] runs",
        ),
        (
            "generator:\n  finish: {reach_runs: 9}\n",
            Game::Platform,
            "finish.reach_runs must be within [1, 8] runs",
        ),
        (
            "generator:\n  finish: {reach_runs: 4}\n",
            Game::Racing,
            "the racing Generator's pieces are not cut to a reach",
        ),
        (
            "generator:\n  rewards: {knobs: []}\n  finish: {knobs_only: true}\n",
            Game::Platform,
            "finish.knobs_only needs knobs (rewards.knobs)",
        ),
        (
            "generator:\n  hard_success_floor: 1.5\n",
            Game::Platform,
            "generator.hard_success_floor must be a ratio in [0, 1]",
        ),
    ] {
        let error = TrainConfig::parse_for(text, game).unwrap_err();
        assert!(error.contains(says), "{text}: {error}");
    }
}

#[test]
fn out_of_range_generator_fields_are_named() {
    for (text, game, says) in [
        (
            "generator:\n  curve_offset: 200\n",
            Game::Racing,
            "in [0, 180]",
        ),
        (
            "generator:\n  curve_offset: .nan\n",
            Game::Racing,
            "in [0, 180]",
        ),
        (
            "generator:\n  curve_offset: 90\n",
            Game::Platform,
            "does not steer the platform Generator",
        ),
        (
            "generator:\n  stages:\n  - {from_steps: 9, solver_learning_rate: 0, solver_phase_steps: 1, generator_phase_steps: 1}\n  - {from_steps: 5, solver_learning_rate: 0, solver_phase_steps: 1, generator_phase_steps: 1}\n",
            Game::Platform,
            "stages[1].from_steps must be after",
        ),
        (
            "generator:\n  stages:\n  - {from_steps: 9, solver_learning_rate: .nan, solver_phase_steps: 1, generator_phase_steps: 1}\n",
            Game::Platform,
            "stages[0].solver_learning_rate",
        ),
        (
            "generator:\n  stages:\n  - {from_steps: 9, solver_learning_rate: 0, solver_phase_steps: 1, generator_phase_steps: 1, snapshot_share: -1}\n",
            Game::Platform,
            "stages[0].snapshot_share",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, solver_learning_rate: -1}\n",
            Game::Platform,
            "finish.solver_learning_rate",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, until_hard_success: .nan}\n",
            Game::Platform,
            "finish.until_hard_success",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, generator_until_hard_success: 2}\n",
            Game::Platform,
            "finish.generator_until_hard_success",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, hard_match_block: 0}\n",
            Game::Platform,
            "finish.hard_match_block",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, generator_entropy: -0.1}\n",
            Game::Platform,
            "finish.generator_entropy",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, generator_learning_rate: .nan}\n",
            Game::Platform,
            "finish.generator_learning_rate",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, generator_learning_rate: 0}\n",
            Game::Racing,
            "finish.generator_learning_rate",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, scripted_opponent: {skill: median, share: 0}}\n",
            Game::Platform,
            "finish.scripted_opponent.share must be a number in (0, 1]",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, scripted_opponent: {skill: master, share: 0.5}}\n",
            Game::Racing,
            "unknown variant `master`",
        ),
        (
            "generator:\n  snapshot_share: 1.5\n",
            Game::Platform,
            "generator.snapshot_share must be a number in [0, 1]",
        ),
        (
            "generator:\n  paced_share: .nan\n",
            Game::Racing,
            "generator.paced_share must be a number in [0, 1]",
        ),
        (
            "generator:\n  finish: {solver_steps: 64, generator_phase_steps: 9, paced_share: 2}\n",
            Game::Platform,
            "finish.paced_share must be a ratio in [0, 1]",
        ),
        (
            "generator:\n  population: 99\n",
            Game::Platform,
            "generator.population must be within [0, 16]",
        ),
    ] {
        let err = TrainConfig::parse_for(text, game).unwrap_err();
        assert!(err.to_string().contains(says), "{text}: {err}");
    }
    let err = TrainConfig::parse_for("generator:\n  max_pieces: 500\n", Game::Racing).unwrap_err();
    assert!(
        err.contains("generator.max_pieces must be within [1, 400]"),
        "{err}"
    );
}

#[test]
fn ability_ranges_are_read_by_name_and_refused_with_the_field() {
    let wide = "ability_ranges:\n  character.jump_speed: [4, 11]\n  character.run_speed: [4, 9]\n  character.gravity: [9, 25]\n";
    let config = TrainConfig::parse_for(wide, Game::Platform).unwrap();
    assert!(config.ability_aware());
    let ranges = config.trained_over(Game::Platform).unwrap().unwrap();
    assert_eq!(ranges.named()["character.gravity"], [9.0, 25.0]);
    // Ranges given under a file are turned off with null over it, and then a share still
    // reads, as ranges around the built-in character.
    let off = TrainConfig::parse_over("ability_ranges: null\n", config.clone(), Game::Platform);
    assert!(!off.unwrap().ability_aware());
    let spread = TrainConfig::parse_for(
        "ability_ranges: null\nability_spread: 0.2\n",
        Game::Platform,
    )
    .unwrap();
    let around = spread.trained_over(Game::Platform).unwrap().unwrap();
    assert_eq!(
        around.named()["character.jump_speed"],
        [9.25 * 0.8, 9.25 * 1.2]
    );
    for (text, game, says) in [
        (
            format!("{wide}ability_spread: 0.2\n"),
            Game::Platform,
            "not both",
        ),
        (
            wide.replace("[9, 25]", "[25, 9]"),
            Game::Platform,
            "character.gravity: [25, 9] runs backwards",
        ),
        (
            wide.replace("[9, 25]", "[9, .nan]"),
            Game::Platform,
            "character.gravity",
        ),
        (
            wide.to_string(),
            Game::Racing,
            "not a main ability of a car",
        ),
        (
            wide.replace("  character.gravity: [9, 25]\n", ""),
            Game::Platform,
            "character.gravity: missing",
        ),
    ] {
        // Over the configuration's defaults, which name no ranges: platform's recipe names all
        // three, so a file laid over it cannot leave one out.
        let problem = TrainConfig::parse_over(&text, TrainConfig::default(), game).unwrap_err();
        assert!(problem.contains(says), "{text}: {problem}");
    }
}
