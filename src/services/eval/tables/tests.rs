use super::*;
use arlpcg_core::level::SolverRef;
use arlpcg_core::level::stats::{Outcome, TrialResult};

/// Statistics of `successes` successful runs out of `trials` (the rest fell on piece 0).
pub(in crate::services::eval) fn stats(successes: u32, trials: u32) -> SolverStats {
    let run = |outcome| TrialResult {
        outcome,
        progress: if outcome == Outcome::Success {
            1.0
        } else {
            0.5
        },
        target_piece: 0,
        steps: 100,
        air_steps: Some(3),
    };
    let runs: Vec<TrialResult> = (0..trials)
        .map(|i| {
            run(if i < successes {
                Outcome::Success
            } else {
                Outcome::Fell
            })
        })
        .collect();
    SolverStats::from_trials(
        SolverRef::Scripted {
            skill: arlpcg_core::game::Skill::Expert,
        },
        0,
        2,
        &runs,
    )
}

/// Two Solvers (the ARLPCG one second), 1, 2, 0, 1, 1 levels at the five λ, a validation
/// set of one rule level and two Generator levels.
pub(in crate::services::eval) fn layout(game: Game) -> PlayLayout {
    let columns = facts(game).piece_columns.len();
    PlayLayout {
        game,
        levels_per_aux: vec![1, 2, 0, 1, 1],
        levels_between: vec![1, 1, 1, 1],
        piece_means: vec![
            Some(vec![7.0; columns]),
            Some(vec![8.0; columns]),
            None,
            Some(vec![9.0; columns]),
            Some(vec![10.0; columns]),
        ],
        validation_levels: 3,
        validation_rule_levels: 1,
        solvers: vec!["rule-pcg".into(), "arlpcg".into()],
        knobs: Vec::new(),
    }
}

/// Each play's statistics chosen so every table cell is known: plays are numbered as
/// `PlayLayout::plays` lists them.
fn outcomes(layout: &PlayLayout) -> Vec<SolverStats> {
    layout
        .plays()
        .iter()
        .map(|play| match *play {
            // Controllability: success 4/4 at λ = 1, then 2/4 and 0/4 at 0.5, ...
            Play::Controllability { aux, level } => match (aux, level) {
                (0, _) => stats(4, 4),
                (1, 0) => stats(2, 4),
                (1, _) => stats(0, 4),
                _ => stats(1, 4),
            },
            Play::Generalization { solver, level } => {
                stats(if level < 1 { 4 } else { solver as u32 * 2 }, 4)
            }
            Play::Cross { solver, .. } => stats(solver as u32 + 1, 4),
            Play::Knob { .. } => stats(3, 4),
            Play::Style { setting, .. } => stats(setting as u32 % 5, 4),
        })
        .collect()
}

#[test]
fn assemble_puts_every_play_in_its_cell() {
    let layout = layout(Game::Racing);
    let results = assemble(Budget::QUICK, "gen", &layout, &outcomes(&layout));
    let success: Vec<f64> = results
        .controllability
        .iter()
        .map(|r| r.success_ratio)
        .collect();
    assert_eq!(success[0], 1.0);
    assert_eq!(success[1], 0.25, "the mean of 2/4 and 0/4");
    assert!(success[2].is_nan(), "no level at λ = 0: nothing measured");
    assert_eq!(&success[3..], &[0.25, 0.25]);
    let second = &results.controllability[1];
    assert_eq!(second.success_std, 0.25);
    assert_eq!(second.completed_by_any, 0.5);
    assert_eq!(second.tracks, 2);
    assert_eq!(second.pieces["avg_segment_length"], 8.0);
    // 3 air steps a run at 1/30 s a decision.
    let air = second.air_time.expect("racing measures air time");
    assert!((air - 0.1).abs() < 1e-6, "{air}");

    let [rule, arlpcg] = &results.generalization[..] else {
        panic!("one row per Solver")
    };
    assert_eq!(
        (rule.mode.as_str(), arlpcg.mode.as_str()),
        ("rule-pcg", "arlpcg")
    );
    assert_eq!(rule.success_rule_levels, 1.0);
    assert_eq!(rule.success_generator_levels, 0.0);
    assert_eq!(arlpcg.success_generator_levels, 0.5);
    assert!((arlpcg.success_ratio - 2.0 / 3.0).abs() < 1e-12);
    assert!(rule.avg_steps == 100.0 && rule.tracks == 3);

    assert_eq!(results.cross[0].success_ratio[0], 0.25);
    assert_eq!(results.cross[1].success_ratio[0], 0.5);
    assert!(results.cross[1].success_ratio[2].is_nan());
}

#[test]
fn platform_tables_have_no_air_time() {
    let layout = layout(Game::Platform);
    let results = assemble(Budget::QUICK, "gen", &layout, &outcomes(&layout));
    assert!(results.controllability.iter().all(|r| r.air_time.is_none()));
    assert_eq!(results.controllability[0].pieces["avg_block_size"], 7.0);
}

/// Failures on the last piece and on each level's worst piece, as shares of all failures.
#[test]
fn piece_failures_say_where_the_runs_fail() {
    let level = |by_piece: &[u32]| SolverStats {
        failures_by_piece: by_piece.to_vec(),
        ..stats(0, 0)
    };
    let (wall, spread) = (level(&[0, 1, 3]), level(&[2, 0, 0, 0]));
    let failures = PieceFailures::of(&[&wall, &spread]).unwrap();
    assert_eq!(failures.pieces_per_level, 3.5);
    assert_eq!(failures.failures_on_last_piece, Some(3.0 / 6.0));
    assert_eq!(failures.failures_on_worst_piece, Some(5.0 / 6.0));
    let clean = PieceFailures::of(&[&level(&[0, 0])]).unwrap();
    assert_eq!(clean.failures_on_last_piece, None, "no failure, no share");
    assert_eq!(PieceFailures::of(&[]), None);
}

/// The knob reads each goal's success at the nine λ in order, 1 to -1, and counts the steps
/// where it moved by more than half.
#[test]
fn the_knob_follows_each_goal_from_one_lambda_to_the_next() {
    // Goal 7 falls evenly from 1 to 0.2 (0.1 a step); goal 8 drops from 1 to 0 between λ = 0
    // and -0.25 (the first play of the knob's third in-between λ).
    let success = |goal: u64, k: usize| match goal {
        7 => 1.0 - 0.1 * k as f64,
        _ => f64::from(u8::from(k < 5)),
    };
    let mut plays = Vec::new();
    let mut all = Vec::new();
    for k in 0..9 {
        for (level, goal) in [7u64, 8].into_iter().enumerate() {
            plays.push(match k % 2 {
                0 => Play::Controllability { aux: k / 2, level },
                _ => Play::Knob { aux: k / 2, level },
            });
            let mut s = stats((20.0 * success(goal, k)).round() as u32, 20);
            s.seed = goal;
            all.push(s);
        }
    }
    plays.push(Play::Generalization {
        solver: 0,
        level: 0,
    });
    all.push(stats(0, 20));
    let knob = Knob::of(&plays, &all).unwrap();
    assert_eq!(
        knob.aux,
        [1.0, 0.75, 0.5, 0.25, 0.0, -0.25, -0.5, -0.75, -1.0]
    );
    assert!((knob.success[0] - 1.0).abs() < 1e-9 && (knob.success[8] - 0.1).abs() < 1e-9);
    assert_eq!(knob.steps, 16);
    assert_eq!(knob.smooth_steps, 15.0 / 16.0);
    let tables_only: Vec<Play> = plays
        .iter()
        .map(|p| match *p {
            Play::Knob { level, .. } => Play::Generalization { solver: 0, level },
            p => p,
        })
        .collect();
    assert_eq!(Knob::of(&tables_only, &all), None, "no knob levels played");
}
