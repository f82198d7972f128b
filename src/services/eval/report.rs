//! The tables as people and tools read them: markdown beside the paper's figures, CSV files,
//! and the chart of success against λ.

use arlpcg_core::game::facts::facts;

use super::{AUX_VALUES, Results};

/// `x` with `decimals`, or "n/a" for NaN (nothing measured).
fn num(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        "n/a".into()
    } else {
        format!("{x:.decimals$}")
    }
}

/// A success ratio and its standard deviation over levels: `0.457 ± 0.211`.
fn ratio_and_std(ratio: f64, std: f64) -> String {
    format!("{} ± {}", num(ratio, 3), num(std, 3))
}

/// The three tables as markdown, beside the paper's figures.
pub fn markdown(results: &Results) -> String {
    let game = facts(results.game);
    let mut md =
        String::from("## Generator controllability (ARLPCG Solver on Generator levels)\n\n");
    md += game.controllability_header;
    for (row, paper) in results
        .controllability
        .iter()
        .zip(game.paper_controllability)
    {
        md += &format!(
            "| {:+.1} | {} | {} |",
            row.aux,
            ratio_and_std(row.success_ratio, row.success_std),
            num(row.completed_by_any, 2),
        );
        if let Some(air) = row.air_time {
            md += &format!(" {} s |", num(air, 2));
        }
        for (name, unit) in game.piece_columns {
            md += &format!(" {}{unit} |", num(row.pieces[*name], 2));
        }
        let [pieces, last, worst] = row.failure_columns().map(|v| v.unwrap_or(f64::NAN));
        md += &format!(
            " {} | {} | {} |",
            num(pieces, 1),
            num(last, 2),
            num(worst, 2)
        );
        md += &format!(" {} | {paper} |\n", row.tracks);
    }
    if let Some(knob) = &results.knob {
        let success: Vec<String> = knob.success.iter().map(|s| num(*s, 2)).collect();
        md += &format!(
            "\nThe knob on the same goals, λ from +1 to -1 every 0.25: success {}; one step moves a goal's success by at most {} in {:.0}% of {} steps.\n",
            success.join(", "),
            super::Knob::SMOOTH_STEP,
            100.0 * knob.smooth_steps,
            knob.steps
        );
    }
    for table in &results.knobs {
        md += &format!(
            "\n### Style knob `{}` (λ and the other knobs 0): measured style and ARLPCG success\n\n| {} | measured (mean ± std over levels) | success | levels |\n|---|---|---|---|\n",
            table.knob, table.knob
        );
        for row in &table.rows {
            md += &format!(
                "| {:+.2} | {} | {} | {} |\n",
                row.value,
                ratio_and_std(row.measured, row.measured_std),
                num(row.success_ratio, 3),
                row.tracks
            );
        }
        md += &format!(
            "\nSpearman's rank correlation of the setting and each level's measure: {}; success moves by at most {} across the settings.\n",
            num(table.spearman, 3),
            num(table.success_spread, 3)
        );
    }
    md += "\n## Solver generalization (held-out validation levels)\n\n";
    md += "| mode | success ratio | on rule levels | on Generator levels | completed by any | avg steps | paper |\n|---|---|---|---|---|---|---|\n";
    for row in &results.generalization {
        let paper = game.paper_generalization(&row.mode);
        md += &format!(
            "| {} | {} | {} | {} | {} | {} | {paper} |\n",
            row.mode,
            ratio_and_std(row.success_ratio, row.success_std),
            num(row.success_rule_levels, 3),
            num(row.success_generator_levels, 3),
            num(row.completed_by_any, 2),
            num(row.avg_steps, 0)
        );
    }
    md += "\n## Each judge (trained Solvers, the scripted player's skills) on Generator levels at each λ\n\n| judge |";
    for aux in AUX_VALUES {
        md += &format!(" λ = {aux:+.1} |");
    }
    md += "\n|---|";
    md += &"---|".repeat(AUX_VALUES.len());
    md += "\n";
    for row in &results.cross {
        md += &format!("| {} |", row.mode);
        for s in &row.success_ratio {
            md += &format!(" {} |", num(*s, 3));
        }
        md += "\n";
    }
    md += &format!(
        "\nBudget: {} levels × {} runs per λ; {} validation levels × {} runs. Generator: {}\n",
        results.budget.tracks,
        results.budget.trials,
        results.budget.validation_tracks,
        results.budget.validation_trials,
        results.generator
    );
    md
}

/// The chart of `eval`: each Solver's success ratio on Generator levels against λ.
pub fn chart(results: &Results) -> crate::services::chart::LineChart {
    crate::services::chart::LineChart {
        title: "Success ratio on Generator levels (λ: +1 easy, -1 hard)".into(),
        x_label: "aux input λ".into(),
        y_label: "success ratio".into(),
        series: results
            .cross
            .iter()
            .map(|row| crate::services::chart::Series {
                name: row.mode.clone(),
                points: AUX_VALUES
                    .iter()
                    .copied()
                    .zip(row.success_ratio.iter().copied())
                    .collect(),
            })
            .collect(),
        y_range: Some((0.0, 1.0)),
    }
}

/// The three tables as CSV files: (file name, contents).
pub fn csv_tables(results: &Results) -> Vec<(&'static str, String)> {
    let columns: Vec<&str> = facts(results.game)
        .piece_columns
        .iter()
        .map(|(name, _)| *name)
        .collect();
    let air = facts(results.game).air_time_step.is_some();
    let mut controllability = format!(
        "aux,success_ratio,success_std,completed_by_any,{}{},pieces_per_level,failures_on_last_piece,failures_on_worst_piece,tracks\n",
        if air { "air_time," } else { "" },
        columns.join(",")
    );
    for r in &results.controllability {
        controllability += &format!(
            "{},{:.4},{:.4},{:.4},",
            r.aux, r.success_ratio, r.success_std, r.completed_by_any,
        );
        if let Some(time) = r.air_time {
            controllability += &format!("{time:.4},");
        }
        for name in &columns {
            controllability += &format!("{:.4},", r.pieces[*name]);
        }
        for value in r.failure_columns() {
            controllability += &value.map_or(",".into(), |v| format!("{v:.4},"));
        }
        controllability += &format!("{}\n", r.tracks);
    }
    let mut generalization = String::from(
        "mode,success_ratio,success_std,success_rule_levels,success_generator_levels,completed_by_any,avg_steps,tracks\n",
    );
    for r in &results.generalization {
        generalization += &format!(
            "{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.1},{}\n",
            r.mode,
            r.success_ratio,
            r.success_std,
            r.success_rule_levels,
            r.success_generator_levels,
            r.completed_by_any,
            r.avg_steps,
            r.tracks
        );
    }
    let mut cross = String::from("mode");
    for aux in AUX_VALUES {
        cross += &format!(",aux_{aux:+.1}");
    }
    cross += "\n";
    for r in &results.cross {
        cross += &r.mode;
        for s in &r.success_ratio {
            cross += &format!(",{s:.4}");
        }
        cross += "\n";
    }
    vec![
        ("controllability.csv", controllability),
        ("generalization.csv", generalization),
        ("cross.csv", cross),
    ]
}
