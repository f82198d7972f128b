//! What the statistics of many levels say together: the generalization table's aggregates,
//! where along a level runs fail, and the pacing chart of one level.

use arlpcg_core::level::Level;
use arlpcg_core::level::stats::SolverStats;

/// Aggregates over many levels, as the paper's generalization table does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Levels summarized.
    pub levels: usize,
    /// Mean over levels of each level's success ratio.
    pub mean_success: f64,
    /// Standard deviation over levels of the success ratio.
    pub std_success: f64,
    /// Fraction of levels completed by at least one run.
    pub completed_by_any: f64,
    /// Mean over levels of the fraction of the track covered.
    pub mean_progress: f64,
    /// Mean decisions of successful runs (over levels with a success).
    pub mean_success_steps: f64,
}

impl Summary {
    /// The summary of these levels' statistics.
    pub fn of(stats: &[SolverStats]) -> Self {
        let n = stats.len().max(1) as f64;
        let mean = |f: &dyn Fn(&SolverStats) -> f64| stats.iter().map(f).sum::<f64>() / n;
        let mean_success = mean(&|s| s.success_ratio);
        let variance = mean(&|s| (s.success_ratio - mean_success).powi(2));
        let solved: Vec<&SolverStats> = stats.iter().filter(|s| s.successes > 0).collect();
        Self {
            levels: stats.len(),
            mean_success,
            std_success: variance.sqrt(),
            completed_by_any: solved.len() as f64 / n,
            mean_progress: mean(&|s| s.mean_progress),
            mean_success_steps: solved.iter().map(|s| s.mean_success_steps).sum::<f64>()
                / solved.len().max(1) as f64,
        }
    }
}

/// Where runs fail along levels: failures and pieces before the halfway point (pieces that
/// begin less than half the start-to-goal distance in) and past it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HalfwaySplit {
    /// Failures on pieces before the halfway point, and past it.
    pub failures: [u64; 2],
    /// Pieces before the halfway point, and past it.
    pub pieces: [u64; 2],
}

impl HalfwaySplit {
    /// Adds a level's per-piece failures, each piece on the side where it begins.
    pub fn add(&mut self, level: &Level, stats: &SolverStats) {
        for (fraction, &failures) in level
            .piece_start_fractions()
            .iter()
            .zip(&stats.failures_by_piece)
        {
            let side = usize::from(*fraction >= 0.5);
            self.failures[side] += u64::from(failures);
            self.pieces[side] += 1;
        }
    }

    /// The share of all failures that fall past the halfway point (NaN without failures).
    pub fn share_past(&self) -> f64 {
        self.failures[1] as f64 / (self.failures[0] + self.failures[1]) as f64
    }

    /// Failures per piece before the halfway point and past it (NaN for a side without pieces).
    pub fn per_piece(&self) -> [f64; 2] {
        [0, 1].map(|k| self.failures[k] as f64 / self.pieces[k] as f64)
    }
}

/// Where a batch's failures gather: the share of all failures on each level's last piece and on
/// each level's most-failed piece (so weighted by failures), and the pieces per level. A knob
/// that builds a wall before the goal shows as a last-piece share near 1; one that makes every
/// stretch harder, as small shares of both.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct FailureConcentration {
    /// Failed runs, over all levels.
    pub failures: u64,
    /// Of them, those on their level's last piece.
    pub on_last_piece: u64,
    /// Of them, those on their level's most-failed piece.
    pub on_worst_piece: u64,
    /// Levels added.
    pub levels: u64,
    /// Pieces of those levels.
    pub pieces: u64,
}

impl FailureConcentration {
    /// Adds one level's failures.
    pub fn add(&mut self, stats: &SolverStats) {
        let by_piece = &stats.failures_by_piece;
        self.failures += by_piece.iter().map(|&f| u64::from(f)).sum::<u64>();
        self.on_last_piece += by_piece.last().map_or(0, |&f| u64::from(f));
        self.on_worst_piece += by_piece.iter().max().map_or(0, |&f| u64::from(f));
        self.levels += 1;
        self.pieces += by_piece.len() as u64;
    }

    /// The shares on the last and on the most-failed piece (none without failures).
    pub fn shares(&self) -> Option<[f64; 2]> {
        (self.failures > 0).then(|| {
            [self.on_last_piece, self.on_worst_piece].map(|n| n as f64 / self.failures as f64)
        })
    }

    /// Mean pieces per level.
    pub fn pieces_per_level(&self) -> f64 {
        self.pieces as f64 / self.levels.max(1) as f64
    }
}

/// The difficulty along a level: the share of runs past each piece, piece by piece from the
/// start, and, on a paced level, the difficulty its λ asked for (`(1 - λ) / 2`: 0 easy, 1 hard).
/// Pieces are counted, not placed by the fraction of the way where they begin: a level that
/// winds back and forth near the goal's distance would draw its line backwards.
pub fn pacing_chart(
    name: &str,
    level: &Level,
    stats: &SolverStats,
) -> crate::services::chart::LineChart {
    let piece_numbers = (1..).map(f64::from);
    let passed = passed_by_piece(stats);
    let mut series = vec![crate::services::chart::Series {
        name: "runs past the piece".into(),
        points: piece_numbers.clone().zip(passed).collect(),
    }];
    if let Some(pacing) = &level.pacing {
        series.push(crate::services::chart::Series {
            name: "asked: (1-λ)/2".into(),
            points: piece_numbers
                .zip(&pacing.piece_aux)
                .map(|(n, aux)| (n, aux.map_or(f64::NAN, |a| (1.0 - a) / 2.0)))
                .collect(),
        });
    }
    crate::services::chart::LineChart {
        title: format!("{name}: {} runs", stats.trials),
        x_label: "piece, from the start".into(),
        y_label: "share".into(),
        series,
        y_range: Some((0.0, 1.0)),
    }
}

/// The share of runs that got past each piece: `1 - failures up to and including it / trials`
/// (what a player feels as the difficulty along the level).
pub fn passed_by_piece(stats: &SolverStats) -> Vec<f64> {
    // Counted in whole runs, so that the last piece's share is the success ratio to the bit.
    let trials = u64::from(stats.trials.max(1));
    let mut failed = 0u64;
    stats
        .failures_by_piece
        .iter()
        .map(|&f| {
            failed += u64::from(f);
            trials.saturating_sub(failed) as f64 / trials as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use arlpcg_core::level::Shape;
    use arlpcg_core::level::stats::SolverRef;

    /// A wall before the goal shows as all failures on the last piece; failures spread over a
    /// level, as small shares of both.
    #[test]
    fn failure_concentration_weighs_each_levels_last_and_worst_piece_by_failures() {
        let stats = |by_piece: Vec<u32>| {
            let mut s = SolverStats::from_trials(SolverRef::Random, 0, by_piece.len(), &[]);
            s.failures_by_piece = by_piece;
            s
        };
        let mut wall = FailureConcentration::default();
        wall.add(&stats(vec![0, 0, 0, 9]));
        wall.add(&stats(vec![0, 0, 1]));
        assert_eq!(wall.shares(), Some([1.0, 1.0]));
        assert_eq!(wall.pieces_per_level(), 3.5);
        let mut spread = FailureConcentration::default();
        spread.add(&stats(vec![2, 1, 2, 1, 0]));
        spread.add(&stats(vec![0, 0, 0]));
        assert_eq!(spread.shares(), Some([0.0, 2.0 / 6.0]));
        assert_eq!(FailureConcentration::default().shares(), None);
    }

    /// With its goal moved onto its third block, the shipped hard example level (platform,
    /// seed 7, λ = -1) winds back away from the goal, so its pieces' fractions of the way are
    /// not in order; the chart still reads left to right.
    #[test]
    fn the_pacing_chart_counts_pieces_in_order_whatever_way_the_level_winds() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("levels/platform/platform_seed7_aux-1.00.yaml");
        let mut level = arlpcg_core::level::yaml::load(&path).unwrap();
        let Shape::Blocks(track) = level.shape() else {
            panic!("a platform level")
        };
        level.goal = track.platforms()[2].position;
        let stats = level.stats.clone().unwrap();
        let fractions = level.piece_start_fractions();
        assert!(
            fractions.windows(2).any(|w| w[1] < w[0]),
            "a level whose pieces go back toward the start: {fractions:?}"
        );
        let chart = pacing_chart("seed7", &level, &stats);
        assert_eq!(
            chart.series.len(),
            1,
            "runs past each piece (one λ asked: no curve)"
        );
        for series in &chart.series {
            assert_eq!(series.points.len(), fractions.len(), "{}", series.name);
            assert!(
                series.points.windows(2).all(|w| w[1].0 > w[0].0),
                "{}: x in order",
                series.name
            );
        }
        let passed: Vec<f64> = chart.series[0].points.iter().map(|p| p.1).collect();
        assert!(passed.windows(2).all(|w| w[1] <= w[0]), "{passed:?}");
        assert_eq!(
            *passed.last().unwrap(),
            stats.success_ratio,
            "the last piece's share is the level's success"
        );
    }
}
