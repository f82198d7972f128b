//! The style knobs' table, for a Generator trained with them: for each knob, the same goals at
//! nine settings from -1 to +1 (λ and the other knobs at 0), with the style the levels measure
//! ([`Level::style`]) and the ARLPCG Solver's success at each. A knob steers when its levels'
//! measure rises with it (the rank correlation over levels) while success stays put.

use serde::Serialize;

use arlpcg_core::level::Level;
use arlpcg_core::level::stats::SolverStats;

use super::Play;

/// The settings each knob is evaluated at, -1 to +1 in steps of 0.25.
pub const KNOB_SETTINGS: [f64; 9] = [-1.0, -0.75, -0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0];

/// What the plays of one knob's table need besides the statistics: its name and, per setting,
/// each level's measure of the knob's attribute (so shards can be merged into the table).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct KnobLayout {
    /// The knob's name (`stride`, `curviness`, ...).
    pub knob: String,
    /// Per setting of [`KNOB_SETTINGS`], each level's measure of the knob's attribute.
    pub measured: Vec<Vec<f64>>,
}

impl KnobLayout {
    /// The layout of knob number `k` named `knob`, from its levels at each setting.
    pub fn of(knob: &str, k: usize, levels: &[Vec<Level>]) -> Self {
        Self {
            knob: knob.to_string(),
            measured: levels
                .iter()
                .map(|at| at.iter().map(|level| level.style()[k]).collect())
                .collect(),
        }
    }
}

/// One setting of a knob.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct KnobRow {
    /// The knob's value.
    pub value: f64,
    /// Mean over levels of the knob's attribute, measured ([`Level::style`], in [-1, 1])...
    pub measured: f64,
    /// ...and its standard deviation over levels.
    pub measured_std: f64,
    /// Mean over levels of the ARLPCG Solver's success.
    pub success_ratio: f64,
    /// Levels played at this setting.
    pub tracks: usize,
}

/// One knob's table.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct KnobTable {
    /// The knob's name.
    pub knob: String,
    /// A row per setting, -1 to +1.
    pub rows: Vec<KnobRow>,
    /// Spearman's rank correlation between the setting and each level's measure (ties ranked
    /// by their mean rank; 0 when either does not vary).
    pub spearman: f64,
    /// The widest gap between two settings' success: how much the knob moves difficulty.
    pub success_spread: f64,
}

/// The knobs' tables from the plays and their statistics (none: no knob was evaluated).
pub fn knob_tables(knobs: &[KnobLayout], plays: &[Play], stats: &[SolverStats]) -> Vec<KnobTable> {
    knobs
        .iter()
        .enumerate()
        .map(|(k, layout)| {
            let rows: Vec<KnobRow> = KNOB_SETTINGS
                .iter()
                .enumerate()
                .map(|(s, &value)| {
                    let success: Vec<f64> = plays
                        .iter()
                        .zip(stats)
                        .filter(|(p, _)| {
                            matches!(p, Play::Style { knob, setting, .. } if *knob == k && *setting == s)
                        })
                        .map(|(_, st)| st.success_ratio)
                        .collect();
                    let measured = layout.measured.get(s).map_or(&[][..], Vec::as_slice);
                    let (mean, std) = mean_std(measured);
                    KnobRow {
                        value,
                        measured: mean,
                        measured_std: std,
                        success_ratio: mean_std(&success).0,
                        tracks: measured.len(),
                    }
                })
                .collect();
            let pairs: Vec<(f64, f64)> = layout
                .measured
                .iter()
                .zip(KNOB_SETTINGS)
                .flat_map(|(at, value)| at.iter().map(move |&m| (value, m)))
                .collect();
            let success: Vec<f64> = rows.iter().map(|r| r.success_ratio).collect();
            let spread = success.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - success.iter().copied().fold(f64::INFINITY, f64::min);
            KnobTable {
                knob: layout.knob.clone(),
                rows,
                spearman: spearman(&pairs),
                success_spread: if spread.is_finite() { spread } else { 0.0 },
            }
        })
        .collect()
}

fn mean_std(values: &[f64]) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0);
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

/// Ranks from 1, ties at their mean rank.
fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && values[order[j + 1]] == values[order[i]] {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        for &k in &order[i..=j] {
            ranks[k] = rank;
        }
        i = j + 1;
    }
    ranks
}

/// Spearman's rank correlation of the pairs: Pearson's on their ranks (0 without variation).
pub fn spearman(pairs: &[(f64, f64)]) -> f64 {
    let x = ranks(&pairs.iter().map(|p| p.0).collect::<Vec<_>>());
    let y = ranks(&pairs.iter().map(|p| p.1).collect::<Vec<_>>());
    let (mx, sx) = mean_std(&x);
    let (my, sy) = mean_std(&y);
    if sx == 0.0 || sy == 0.0 {
        return 0.0;
    }
    let n = x.len() as f64;
    x.iter()
        .zip(&y)
        .map(|(a, b)| (a - mx) * (b - my))
        .sum::<f64>()
        / (n * sx * sy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spearman_ranks_ties_and_reads_monotone_orders_as_one() {
        let rising: Vec<(f64, f64)> = (0..9).map(|k| (k as f64, (k as f64).powi(3))).collect();
        assert!((spearman(&rising) - 1.0).abs() < 1e-12);
        let falling: Vec<(f64, f64)> = rising.iter().map(|&(a, b)| (a, -b)).collect();
        assert!((spearman(&falling) + 1.0).abs() < 1e-12);
        assert_eq!(spearman(&[(0.0, 1.0), (1.0, 1.0)]), 0.0);
        // Two settings, two levels each: ties share a rank.
        assert_eq!(ranks(&[-1.0, -1.0, 1.0, 1.0]), vec![1.5, 1.5, 3.5, 3.5]);
        let r = spearman(&[(-1.0, 0.1), (-1.0, 0.2), (1.0, 0.3), (1.0, 0.4)]);
        assert!((r - (4.0f64 / 5.0).sqrt()).abs() < 1e-12, "{r}");
    }

    #[test]
    fn a_knobs_table_reads_each_settings_levels_and_plays() {
        let layout = KnobLayout {
            knob: "stride".into(),
            measured: KNOB_SETTINGS
                .iter()
                .map(|&v| vec![v * 0.5, v * 0.5 + 0.1])
                .collect(),
        };
        let mut plays = Vec::new();
        let mut stats = Vec::new();
        for setting in 0..KNOB_SETTINGS.len() {
            for level in 0..2 {
                plays.push(Play::Style {
                    knob: 0,
                    setting,
                    level,
                });
                // 10 + setting of 20 runs: success 0.5 at -1 ... 0.9 at +1.
                stats.push(crate::services::eval::tables::tests::stats(
                    10 + setting as u32,
                    20,
                ));
            }
        }
        let tables = knob_tables(&[layout], &plays, &stats);
        assert_eq!(tables.len(), 1);
        let table = &tables[0];
        assert_eq!(table.rows.len(), 9);
        assert!((table.rows[0].measured + 0.45).abs() < 1e-12);
        assert!((table.rows[8].success_ratio - 0.9).abs() < 1e-12);
        assert!((table.success_spread - 0.4).abs() < 1e-12);
        assert!(table.spearman > 0.95, "{}", table.spearman);
    }
}
