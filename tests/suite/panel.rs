//! The panel of judges: the scripted player's skills apart on rule levels, `verify --panel`,
//! `generate --panel` and `--judge`.

use arlpcg::services::verify::{Solver, verify};
use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame, Skill};

use crate::common::{arlpcg, arlpcg_ok, fails_with};

/// Mean success of each skill, weakest first, on `levels` rule levels of `G`, `trials` runs each.
fn skill_success<G: GameSpec>(levels: u64, trials: u32) -> Vec<f64> {
    let levels: Vec<_> = (0..levels)
        .filter_map(|k| G::rule_level(9_000 + k))
        .collect();
    assert!(levels.len() >= 4, "the rules build most seeds");
    Skill::ALL
        .iter()
        .map(|&skill| {
            let total: f64 = levels
                .iter()
                .map(|level| {
                    verify(level, &Solver::Scripted(skill), trials, 0, &|| {})
                        .unwrap()
                        .success_ratio
                })
                .sum();
            total / levels.len() as f64
        })
        .collect()
}

#[test]
fn scripted_skills_are_clearly_apart_on_rule_levels() {
    // Calibrated on 40 rule levels × 20 runs (measured at 93fa40a): platform 0.46 / 0.91 / 1.00,
    // racing 0.59 / 0.87 / 1.00.
    for (game, success) in [
        ("platform", skill_success::<PlatformGame>(6, 16)),
        ("racing", skill_success::<RacingGame>(5, 8)),
    ] {
        let [novice, median, expert] = success[..] else {
            unreachable!()
        };
        assert!(expert >= 0.95, "{game}: expert {expert:.2}");
        assert!(
            novice + 0.15 < median && median < expert,
            "{game}: novice {novice:.2}, median {median:.2}, expert {expert:.2}"
        );
        assert!(
            novice < 0.8,
            "{game}: a novice below the trained Solvers, {novice:.2}"
        );
    }
}

#[test]
fn verify_panel_reports_every_judge_and_rates_the_levels_together() {
    let levels = [
        "levels/platform/platform_seed7_aux+1.00.yaml",
        "levels/platform/platform_seed7_aux-1.00.yaml",
    ];
    let mut args = vec!["verify", "--panel", "--trials", "12", "--json"];
    args.extend(levels);
    let out = arlpcg_ok(&args);
    let rows: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 2);
    for row in &rows {
        let panel = row["panel"].as_object().unwrap();
        assert_eq!(
            panel.len(),
            7,
            "every shipped Solver and three skills: {panel:?}"
        );
        assert!(panel.contains_key("rule-pcg") && panel.contains_key("scripted-novice"));
        assert_eq!(row["rating"]["levels"], 2);
        let ci = row["rating"]["ci95"].as_array().unwrap();
        let b = row["rating"]["b"].as_f64().unwrap();
        assert!(
            ci[0].as_f64().unwrap() < b && b < ci[1].as_f64().unwrap(),
            "{row}"
        );
    }
    let b = |k: usize| rows[k]["rating"]["b"].as_f64().unwrap();
    assert!(
        b(0) < b(1),
        "the λ = 1 level rates easier than the λ = -1 one"
    );

    let some = arlpcg_ok(&[
        "verify", levels[0], "--panel", "scripted-median,arlpcg", "--trials", "4", "--json",
    ]);
    let row: serde_json::Value = serde_json::from_slice(&some.stdout).unwrap();
    let names: Vec<&String> = row["panel"].as_object().unwrap().keys().collect();
    assert_eq!(names, ["arlpcg", "scripted-median"]);

    let bad = arlpcg(&["verify", levels[0], "--panel", "scripted-wizard"]);
    fails_with(&bad, 2, "scripted-expert");
}

#[test]
fn generate_records_the_panel_and_the_rating_and_verifies_with_a_judge() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("rated");
    arlpcg_ok(&[
        "generate",
        "--game",
        "platform",
        "--policies",
        "policies/platform",
        "--aux=-1",
        "--seed",
        "100",
        "--count",
        "2",
        "--verify",
        "6",
        "--panel",
        "--judge",
        "scripted-median",
        "--format",
        "yaml",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let path = out_dir.join("platform_seed100_aux-1.00.yaml");
    let level = arlpcg_core::level::yaml::load(&path).unwrap();
    let stats = level.stats.unwrap();
    assert_eq!(
        stats.solver,
        arlpcg_core::level::SolverRef::Scripted {
            skill: Skill::Median
        }
    );
    let panel = stats.panel.expect("--panel records the panel");
    assert_eq!(panel.judges.len(), 7);
    assert_eq!(panel.trials, 6);
    let rating = panel.rating.expect("and the rating");
    assert_eq!(rating.levels, 2);
    assert!(rating.ci95[0] < rating.b && rating.b < rating.ci95[1]);
}
