//! The run's metrics files (`metrics.csv`, `generator-metrics.csv`): rows, resume truncation,
//! and the learning-curve chart drawn from them.

use std::path::Path;

use anyhow::{Context, Result};

use super::*;

/// Column `name` of a metrics CSV as (x column, value) pairs, smoothed over `window` rows.
pub(super) fn metric_series(text: &str, x: &str, name: &str, window: usize) -> Vec<(f64, f64)> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let (Some(xi), Some(yi)) = (
        header.iter().position(|h| *h == x),
        header.iter().position(|h| *h == name),
    ) else {
        return Vec::new();
    };
    let rows: Vec<(f64, f64)> = lines
        .filter_map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            Some((fields.get(xi)?.parse().ok()?, fields.get(yi)?.parse().ok()?))
        })
        .collect();
    (0..rows.len())
        .map(|i| {
            let recent: Vec<f64> = rows[i.saturating_sub(window - 1)..=i]
                .iter()
                .map(|r| r.1)
                .filter(|v: &f64| v.is_finite())
                .collect();
            // An empty window is NaN (0/0): the chart breaks the line there.
            (rows[i].0, recent.iter().sum::<f64>() / recent.len() as f64)
        })
        .collect()
}

/// `learning-curve.png`: the Solver's training success ratio against its steps (and, in the
/// adversarial modes, its success on easy and hard Generator levels), smoothed over 10 updates.
pub fn write_learning_curve(out: &Path) -> Result<()> {
    let read = |name: &str| read_text(&out.join(name)).unwrap_or_default();
    let solver = read(METRICS);
    let generator = read(GENERATOR_METRICS);
    let mut series = vec![crate::chart::Series {
        name: "Solver, training".into(),
        points: metric_series(&solver, "global_step", "success_ratio", 10),
    }];
    for (column, name) in [("success_easy", "λ > 0"), ("success_hard", "λ < 0")] {
        let points = metric_series(&generator, "solver_step", column, 10);
        if !points.is_empty() {
            series.push(crate::chart::Series {
                name: name.into(),
                points,
            });
        }
    }
    let chart = crate::chart::LineChart {
        title: format!("Solver success ratio ({})", out.display()),
        x_label: "Solver environment steps".into(),
        y_label: "success ratio".into(),
        series,
        y_range: Some((0.0, 1.0)),
    };
    fsio::write_atomic(
        &out.join("learning-curve.png"),
        &chart.to_png(),
        Overwrite::Allowed,
    )
}

/// The loss columns of a metrics row.
pub(super) fn update_columns(u: &UpdateStats) -> String {
    format!(
        "{:.5},{:.5},{:.4},{:.5},{:.4},{:.4}",
        u.policy_loss, u.value_loss, u.entropy, u.approx_kl, u.clip_fraction, u.explained_variance
    )
}

pub(super) fn open_append(path: &Path) -> Result<std::fs::File> {
    std::fs::OpenOptions::new()
        .append(true)
        .open(path)
        .with_context(|| format!("cannot open {}", path.display()))
}

/// The match columns of a Generator metrics row.
pub(super) fn generator_row(s: &MatchStats) -> String {
    let ratio = |a: f64, b: u32| if b == 0 { f64::NAN } else { a / b as f64 };
    format!(
        "{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.2},{:.2}",
        s.episodes,
        ratio(s.generator_return_sum, s.episodes),
        ratio(s.invalid as f64, s.episodes),
        ratio(s.successes[0] as f64, s.judged[0]),
        ratio(s.successes[1] as f64, s.judged[1]),
        ratio(s.feature_sums[0][0], s.pieces[0]),
        ratio(s.feature_sums[1][0], s.pieces[1]),
        ratio(s.feature_sums[0][1], s.pieces[0]),
        ratio(s.feature_sums[1][1], s.pieces[1]),
        ratio(s.air_steps[0] as f64, s.judged[0]),
        ratio(s.air_steps[1] as f64, s.judged[1]),
    )
}

/// The header of `generator-metrics.csv` for game `G`: its piece features by name, and the
/// Solver's mean steps in the air per match (0 on the platform game).
pub(super) fn generator_metrics_header<G: GeneratorGame>() -> String {
    let [a, b] = G::PIECE_FEATURES;
    format!(
        "iteration,solver_step,generator_step,wall_time_s,rollout_s,update_s,learning_rate,episodes,mean_return,invalid_ratio,success_easy,success_hard,{a}_easy,{a}_hard,{b}_easy,{b}_hard,air_steps_easy,air_steps_hard,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance"
    )
}

/// A metrics file's text, if it is a regular file that reads as text (never blocks on a FIFO).
fn read_text(path: &Path) -> Option<String> {
    crate::fsio::check_regular(path, "metrics file").ok()?;
    std::fs::read_to_string(path).ok()
}

/// Drops metric rows written after the checkpoint a run resumes from, so the curve continues
/// without a gap or a repeat.
pub(super) fn truncate_metrics(path: &Path, header: &str, last_iteration: u64) -> Result<()> {
    let text = read_text(path).unwrap_or_else(|| format!("{header}\n"));
    let kept: Vec<&str> = text
        .lines()
        .enumerate()
        .filter(|(i, line)| {
            *i == 0
                || line
                    .split(',')
                    .next()
                    .and_then(|it| it.parse::<u64>().ok())
                    .is_some_and(|it| it <= last_iteration)
        })
        .map(|(_, line)| line)
        .collect();
    fsio::write_atomic(
        path,
        format!("{}\n", kept.join("\n")).as_bytes(),
        Overwrite::Allowed,
    )
}
