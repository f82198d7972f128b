use super::*;

fn some(values: &[f64]) -> Vec<Option<f64>> {
    values.iter().copied().map(Some).collect()
}

fn run(mode: &str, seed: u64, rules: f64, generated: f64) -> RunScores {
    RunScores {
        run: format!("runs/{mode}-{seed}"),
        mode: mode.into(),
        seed,
        validation_rule_levels: rules,
        validation_generator_levels: generated,
        validation: 0.5 * (rules + generated),
        controllability: (mode == "arlpcg").then(|| some(&[1.0, 0.9, 0.8, 0.6, 0.5])),
        controllability_by_judge: match mode {
            "arlpcg" => vec![
                JudgeCurve {
                    judge: "scripted-median".into(),
                    success_ratio: some(&[1.0, 0.95, 0.9, 0.8, 0.7]),
                },
                JudgeCurve {
                    judge: "scripted-expert".into(),
                    success_ratio: some(&[1.0, 1.0, 1.0, 0.98, 0.9 - 0.1 * seed as f64]),
                },
            ],
            _ => Vec::new(),
        },
        other_generators_hard: None,
        on_other_generators: Vec::new(),
    }
}

#[test]
fn modes_are_summarized_over_their_seeds() {
    let runs = vec![
        run("arlpcg", 0, 0.9, 0.8),
        run("rule-pcg", 0, 0.8, 0.6),
        run("arlpcg", 1, 0.92, 0.82),
        run("rule-pcg", 1, 0.9, 0.7),
        run("arlpcg", 2, 0.88, 0.78),
    ];
    let results = summarize(Budget::QUICK, "g", runs);
    let names: Vec<&str> = results.modes.iter().map(|m| m.mode.as_str()).collect();
    assert_eq!(names, ["arlpcg", "rule-pcg"]);
    assert_eq!(results.modes[0].seeds, [0, 1, 2]);
    let mean = results.modes[0].validation_mean;
    assert!((mean.value - 0.85).abs() < 1e-12, "{mean:?}");
    assert!(mean.ci95[0] <= mean.value && mean.value <= mean.ci95[1]);
    let control = results.modes[0].controllability.as_ref().unwrap();
    assert_eq!(control[4].as_ref().unwrap().estimate.value, 0.5);
    assert!(results.modes[1].controllability.is_none());
    // On the rule half arlpcg's seeds (0.9, 0.92, 0.88) against rule-pcg's (0.8, 0.9) win
    // 4 pairs, tie 1 and lose 1 (0.75); on the Generator half they win all 6.
    let p = &results.arlpcg_beats[0];
    assert_eq!(p.baseline, "rule-pcg");
    assert!(
        (p.probability.value - (0.75 + 1.0) / 2.0).abs() < 1e-12,
        "{p:?}"
    );
    // Each judge over the seeds, and each run's median drop over its judges.
    let judges = &results.modes[0].controllability_by_judge;
    assert_eq!(judges[0].judge, "scripted-median");
    let at = |j: usize, a: usize| judges[j].success_ratio[a].as_ref().unwrap().estimate.value;
    assert!((at(0, 4) - 0.7).abs() < 1e-12);
    assert!((at(1, 4) - 0.8).abs() < 1e-12);
    assert!(results.modes[1].controllability_by_judge.is_empty());
    assert_eq!(results.seeds["arlpcg"].len(), 3);
    assert_eq!(results.seeds["rule-pcg"][1].seed, 1);
    let (median, monotone) = results.seeds["arlpcg"][0].judges_drop(0.05).unwrap();
    assert!((median - 0.2).abs() < 1e-12 && monotone, "{median}");
    assert_eq!(results.seeds["rule-pcg"][0].judges_drop(0.05), None);
    let md = markdown(&results);
    assert!(
        md.contains("| arlpcg | 0, 1, 2 |") && md.contains("| rule-pcg |"),
        "{md}"
    );
    assert!(md.contains("| arlpcg | scripted-expert |"), "{md}");
    assert!(md.contains("| 0.20, yes | — |"), "{md}");
    assert!(results.arlpcg_beats_on_other_generators.is_empty());
    assert!(!md.contains("other runs' Generators"), "{md}");
}

/// On the other Generators' hard levels: the mean over each mode's seeds, and P(arlpcg
/// better) from those seeds alone; a baseline some seed of which lacks the figure is left
/// out.
#[test]
fn other_generators_hard_levels_are_summarized_over_seeds() {
    // Two ARLPCG runs: each plays the other's Generator; rule-pcg's play both.
    let on = |scores: &[(u64, f64)]| -> Vec<GeneratorScore> {
        scores
            .iter()
            .map(|&(g, success_ratio)| GeneratorScore {
                generator: format!("runs/arlpcg-{g}"),
                success_ratio,
            })
            .collect()
    };
    let with = |mode: &str, seed: u64, scores: &[(u64, f64)]| {
        let on_other_generators = on(scores);
        let n = on_other_generators.len();
        RunScores {
            other_generators_hard: (mode != "fixed-track").then(|| {
                on_other_generators
                    .iter()
                    .map(|g| g.success_ratio)
                    .sum::<f64>()
                    / n as f64
            }),
            on_other_generators,
            ..run(mode, seed, 0.9, 0.8)
        }
    };
    let runs = vec![
        with("arlpcg", 0, &[(1, 0.8)]),
        with("arlpcg", 1, &[(0, 0.7)]),
        with("rule-pcg", 0, &[(0, 0.7), (1, 0.8)]),
        with("rule-pcg", 1, &[(0, 0.6), (1, 0.6)]),
        with("fixed-track", 0, &[]),
    ];
    let results = summarize(Budget::QUICK, "g", runs);
    let hard = results.modes[0].other_generators_hard.unwrap();
    assert!((hard.value - 0.75).abs() < 1e-12, "{hard:?}");
    assert!(results.modes[2].other_generators_hard.is_none());
    // arlpcg (0.8, 0.7) against rule-pcg (0.75, 0.6): 3 of 4 pairs won.
    let beats = &results.arlpcg_beats_on_other_generators;
    assert_eq!(beats.len(), 1, "{beats:?}");
    assert_eq!(beats[0].baseline, "rule-pcg");
    assert!(
        (beats[0].probability.value - 0.75).abs() < 1e-12,
        "{beats:?}"
    );
    let md = markdown(&results);
    assert!(md.contains("| arlpcg | 0.750 ["), "{md}");
    assert!(md.contains("| 0.800 |"), "{md}");
    // Generator 0's levels: its own Solver 0.5 (controllability at λ = -1), the other
    // ARLPCG Solver 0.7, the rule-pcg Solvers (0.7 + 0.6) / 2; fixed-track played none.
    assert!(
        md.contains("| runs/arlpcg-0 | 0.500 | 0.700 | 0.650 | — |"),
        "{md}"
    );
    assert!(
        md.contains("| runs/arlpcg-1 | 0.500 | 0.800 | 0.700 | — |"),
        "{md}"
    );
    assert_eq!(other_generators_plays(5, true, 20), 80);
    assert_eq!(other_generators_plays(5, false, 20), 100);
    assert_eq!(other_generators_plays(1, false, 20), 0);
}

/// A λ where a run's Generator built no level has no success: null in the run's curve, "—" in
/// its row and no judges' drop; the mode's estimate there is over the seeds that built levels,
/// and says how many; none built: "—". The file reads back.
#[test]
fn a_lambda_without_levels_has_no_success_rather_than_zero() {
    let unbuilt = |seed: u64| RunScores {
        controllability: Some(vec![Some(0.95), None, None, None, None]),
        controllability_by_judge: vec![JudgeCurve {
            judge: "scripted-median".into(),
            success_ratio: vec![Some(0.9), None, None, None, None],
        }],
        ..run("fixed-aux", seed, 0.9, 0.8)
    };
    let built = RunScores {
        controllability: Some(some(&[0.98, 1.0, 1.0, 1.0, 1.0])),
        controllability_by_judge: vec![JudgeCurve {
            judge: "scripted-median".into(),
            success_ratio: some(&[1.0, 1.0, 1.0, 1.0, 1.0]),
        }],
        ..run("fixed-aux", 1, 0.9, 0.8)
    };
    assert_eq!(unbuilt(0).judges_drop(0.05), None);
    let results = summarize(Budget::QUICK, "g", vec![unbuilt(0), built, unbuilt(2)]);
    let control = results.modes[0].controllability.as_ref().unwrap();
    assert_eq!(control[1].as_ref().unwrap().seeds, Some(1));
    assert!((control[1].as_ref().unwrap().estimate.value - 1.0).abs() < 1e-12);
    assert_eq!(control[0].as_ref().unwrap().seeds, None);
    let md = markdown(&results);
    assert!(md.contains("(seeds that built levels: 1)"), "{md}");
    assert!(md.contains("| 0.95, — (no level), — (no level)"), "{md}");
    assert!(!md.contains("-0.00"), "{md}");
    let alone = summarize(Budget::QUICK, "g", vec![unbuilt(0)]);
    assert!(alone.modes[0].controllability.as_ref().unwrap()[4].is_none());
    assert!(markdown(&alone).contains("— (no level built)"));
    let json = serde_json::to_vec(&results).unwrap();
    assert_eq!(SeedResults::read(&json).unwrap(), results);
}
