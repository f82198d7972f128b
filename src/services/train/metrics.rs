//! The run's metrics files (`metrics.csv`, `generator-metrics.csv`): rows, resume truncation,
//! and the learning-curve chart drawn from them.

use std::path::Path;

use super::arlpcg::MatchStats;
use super::{GENERATOR_METRICS, METRICS};
use crate::services::fsio;
use crate::services::fsio::Overwrite;
use anyhow::{Context, Result};
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::rl::ppo::UpdateStats;
use arlpcg_core::rl::timing::TimeSplit;

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
/// adversarial modes, its success on easy and hard Generator levels, and the scripted
/// opponent's on hard ones in a finish that has one), smoothed over 10 updates.
pub fn write_learning_curve(out: &Path) -> Result<()> {
    let read = |name: &str| read_text(&out.join(name)).unwrap_or_default();
    let solver = read(METRICS);
    let generator = read(GENERATOR_METRICS);
    let mut series = vec![crate::services::chart::Series {
        name: "Solver, training".into(),
        points: metric_series(&solver, "global_step", "success_ratio", 10),
    }];
    for (column, name) in [
        ("success_easy", "λ > 0"),
        ("success_hard", "λ < 0"),
        ("scripted_success_hard", "scripted opponent, λ < 0"),
    ] {
        let points = metric_series(&generator, "solver_step", column, 10);
        // The scripted opponent's column is NaN outside a finish that has one.
        if points.iter().any(|p| p.1.is_finite()) {
            series.push(crate::services::chart::Series {
                name: name.into(),
                points,
            });
        }
    }
    let chart = crate::services::chart::LineChart {
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

/// `a / b` for a metrics row: NaN when nothing was counted.
fn ratio(a: f64, b: u32) -> f64 {
    if b == 0 { f64::NAN } else { a / b as f64 }
}

/// The match columns of a Generator metrics row.
pub(super) fn generator_row(s: &MatchStats) -> String {
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

/// The scripted opponent's columns of a Generator metrics row: its success at λ > 0 and λ < 0.
pub(super) fn scripted_columns(s: &MatchStats) -> String {
    format!(
        "{:.4},{:.4}",
        ratio(s.scripted_successes[0] as f64, s.scripted_judged[0]),
        ratio(s.scripted_successes[1] as f64, s.scripted_judged[1])
    )
}

/// The header of `generator-metrics.csv` for game `G`: its piece features by name, the
/// Solver's mean steps in the air per match (0 on the platform game), and last the scripted
/// opponent's success (NaN where it played no match: outside a finish that has one).
pub(super) fn generator_metrics_header<G: GeneratorGame>() -> String {
    let [a, b] = G::PIECE_FEATURES;
    format!(
        "iteration,solver_step,generator_step,wall_time_s,rollout_s,update_s,learning_rate,episodes,mean_return,invalid_ratio,success_easy,success_hard,{a}_easy,{a}_hard,{b}_easy,{b}_hard,air_steps_easy,air_steps_hard,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance,scripted_success_easy,scripted_success_hard,env_s,forward_s,generator_s,gae_s,copies_s,iteration_s,update_mfu"
    )
}

/// A metrics file's text, if it is a regular file that reads as text (never blocks on a FIFO).
fn read_text(path: &Path) -> Option<String> {
    crate::services::fsio::check_regular(path, "metrics file").ok()?;
    std::fs::read_to_string(path).ok()
}

/// The columns of a metrics row that say where its time went: seconds per bucket.
pub(super) fn time_columns(time: &TimeSplit) -> String {
    time.buckets()
        .iter()
        .filter(|(name, _)| *name != "update")
        .map(|(_, s)| format!("{s:.6}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// Refuses a metrics file whose columns are not `header`'s (or its first columns, from before
/// later ones were added): a run folder that holds another run's metrics (another game's, or a
/// Solver-only run's) is named before anything is written in it.
pub(super) fn check_metrics_header(path: &Path, header: &str, checkpoint: &Path) -> Result<()> {
    let Some(text) = read_text(path) else {
        return Ok(()); // missing: the resume writes it afresh
    };
    let written = text.lines().next().unwrap_or_default();
    let extends = header
        .strip_prefix(written)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with(','));
    if !extends {
        anyhow::bail!(
            "{}: its columns are not those of the run in {} (it begins \"{}\"): the folder \
             holds files of two different runs; resume a folder that one run wrote",
            path.display(),
            checkpoint.display(),
            written.chars().take(60).collect::<String>()
        );
    }
    Ok(())
}

/// Drops metric rows written after the checkpoint a run resumes from, so the curve continues
/// without a gap or a repeat.
/// A file written before columns were appended to `header` gains them, empty in its rows.
pub(super) fn truncate_metrics(path: &Path, header: &str, last_iteration: u64) -> Result<()> {
    let text = read_text(path).unwrap_or_else(|| format!("{header}\n"));
    let mut lines = text.lines();
    let written = lines.next().unwrap_or(header);
    let added = header
        .strip_prefix(written)
        .filter(|rest| rest.starts_with(','))
        .map_or(0, |rest| rest.matches(',').count());
    let mut kept = vec![if added > 0 { header } else { written }.to_string()];
    kept.extend(
        lines
            .filter(|line| {
                line.split(',')
                    .next()
                    .and_then(|it| it.parse::<u64>().ok())
                    .is_some_and(|it| it <= last_iteration)
            })
            .map(|line| format!("{line}{}", ",".repeat(added))),
    );
    fsio::write_atomic(
        path,
        format!("{}\n", kept.join("\n")).as_bytes(),
        Overwrite::Allowed,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A resume keeps the rows up to its checkpoint; a file from before the scripted
    /// opponent's columns gains them, empty in the rows it keeps.
    #[test]
    fn truncation_keeps_rows_to_the_checkpoint_and_appends_new_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("generator-metrics.csv");
        std::fs::write(&path, "iteration,a\n1,0.5\n2,0.6\n3,0.7\n").unwrap();
        truncate_metrics(&path, "iteration,a,b,c", 2).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "iteration,a,b,c\n1,0.5,,\n2,0.6,,\n"
        );
        // A file of today's header stays as it was, less the rows after the checkpoint.
        truncate_metrics(&path, "iteration,a,b,c", 1).unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "iteration,a,b,c\n1,0.5,,\n"
        );
    }

    /// A resume accepts a metrics file of its own columns, or of their first ones, and refuses
    /// another run's by name.
    #[test]
    fn a_metrics_file_of_other_columns_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("generator-metrics.csv");
        let checkpoint = dir.path().join("checkpoint.safetensors");
        check_metrics_header(&path, "iteration,a,b", &checkpoint).unwrap();
        for own in ["iteration,a,b", "iteration,a"] {
            std::fs::write(&path, format!("{own}\n1,0.5\n")).unwrap();
            check_metrics_header(&path, "iteration,a,b", &checkpoint).unwrap();
        }
        for other in ["iteration,z", "iteration,a,bb", "iteration,a,b,c", ""] {
            std::fs::write(&path, format!("{other}\n")).unwrap();
            let err = check_metrics_header(&path, "iteration,a,b", &checkpoint)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("generator-metrics.csv") && err.contains("two different runs"),
                "{other}: {err}"
            );
        }
    }
}
