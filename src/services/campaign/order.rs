//! A campaign's levels in order: each searched to its ramp point, played and rated by the panel,
//! put in order of the panel's difficulty where the ramp allows, and mended where that
//! difficulty still steps down (a level drawn anew); a level of a campaign on disk regenerated.

use std::path::{Path, PathBuf};

use super::{Campaign, CampaignAsk, campaign_files, level_stem, open};
use crate::services::difficulty;
use crate::services::generation::GeneratorPolicy;
use crate::services::level_files::Format;
use crate::services::making::{self, LevelSource, Proof};
use crate::services::panel::{Judge, JudgePanel, play_and_rate};
use crate::services::verify::{Solver, Watch};
use arlpcg_core::level::Level;
use arlpcg_core::level::stats::Rating;

/// Puts the levels in order of the panel's difficulty b wherever the ramp allows it: two
/// neighbours trade places when the later is rated easier and each still measures within
/// `band` of the other's ramp point, until no such pair is left. The judge's ramp holds; the
/// other judges, whom b also counts, see fewer steps down.
pub fn order_by_difficulty(levels: &mut [Level], targets: &[f64], band: f64) {
    let measured = |l: &Level| l.stats.as_ref().map_or(f64::NAN, |s| s.success_ratio);
    let b = |l: &Level| rating(l).map_or(f64::NAN, |r| r.b);
    let fits = |l: &Level, k: usize| (measured(l) - targets[k]).abs() <= band + 1e-9;
    let mut swapped = true;
    while swapped {
        swapped = false;
        for k in 0..levels.len().saturating_sub(1) {
            let (earlier, later) = (&levels[k], &levels[k + 1]);
            if b(earlier) > b(later) && fits(later, k) && fits(earlier, k + 1) {
                levels.swap(k, k + 1);
                swapped = true;
            }
        }
    }
}

/// The search of level `seed` of the campaign `ask` ([`CampaignAsk::request`]): a level whose
/// success for `solver`, over the campaign's runs, is within [`difficulty::BAND`] of `target`
/// ([`difficulty::level_for`]; with a curve of λ, that curve moved as a whole) and whose pieces
/// meet the campaign's checks on pieces, with its certificate. `stopped` ends the search
/// ([`difficulty::TargetError::SearchStopped`]).
pub fn search_level(
    (generator, solver): (&GeneratorPolicy, &Solver),
    curve: &difficulty::Curve,
    ask: &CampaignAsk,
    (seed, target): (u64, f64),
    stopped: &(dyn Fn() -> bool + Sync),
) -> anyhow::Result<Level> {
    let proof = Proof::Target {
        solver,
        curve,
        target,
        trials: ask.trials,
        checks: &ask.checks,
    };
    let asked = &ask.request(seed);
    let watch = Watch {
        on_trial: &|_| {},
        stop: stopped,
    };
    let source = LevelSource::Generator(generator);
    making::verified_level(source, asked, &proof, &watch, &|_| {})?
        .ok_or_else(|| difficulty::TargetError::SearchStopped.into())
}

/// The panel plays `levels` (each verified by the judge; those it has played keep their plays)
/// and rates them together; then the record, the levels named `levelNN.yaml` in their order.
/// `Ok(None)` when `watch.stop` cut the panel short (the levels are then as they came).
pub fn rate(
    ask: &CampaignAsk,
    panel: &JudgePanel,
    levels: &mut Vec<Level>,
    watch: &Watch,
) -> anyhow::Result<Option<Campaign>> {
    let Some(thetas) = play_all(panel, levels, ask.trials, watch) else {
        return Ok(None);
    };
    ask.named_record(levels, &thetas).map(Some)
}

/// How many levels a campaign may draw anew where the panel's b steps down.
pub const REDRAWS: usize = 4;

/// How far b steps down along `levels`: over neighbours, the sum of the gaps by which a level's
/// 95% interval of b lies wholly below the one before it (0 when b rises within its intervals).
pub fn descent(levels: &[Level]) -> f64 {
    let intervals: Vec<[f64; 2]> = levels
        .iter()
        .map(|l| rating(l).map_or([f64::NAN; 2], |r| r.ci95))
        .collect();
    intervals
        .windows(2)
        .map(|pair| (pair[0][0] - pair[1][1]).max(0.0))
        .sum()
}

/// Of the neighbours `k - 1` and `k`, the one whose b lies farther from the campaign's trend
/// (the least-squares line of b over position): the one to draw anew.
fn off_trend(levels: &[Level], k: usize) -> usize {
    let b: Vec<f64> = levels
        .iter()
        .map(|l| rating(l).map_or(f64::NAN, |r| r.b))
        .collect();
    let n = b.len() as f64;
    let x_mean = (n - 1.0) / 2.0;
    let b_mean = b.iter().sum::<f64>() / n;
    let (sxy, sxx) = b
        .iter()
        .enumerate()
        .fold((0.0, 0.0), |(sxy, sxx), (i, bi)| {
            let dx = i as f64 - x_mean;
            (sxy + dx * (bi - b_mean), sxx + dx * dx)
        });
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let residual = |i: usize| (b[i] - (b_mean + slope * (i as f64 - x_mean))).abs();
    if residual(k - 1) > residual(k) {
        k - 1
    } else {
        k
    }
}

/// [`rate`] with the levels reordered, then mended where b still steps down: up to [`REDRAWS`]
/// times, the level of the first step down that lies off the trend is drawn anew by `draw`
/// (from seed `ask.seed + n + d` for the d-th draw, at its ramp point), the panel plays it and
/// the campaign is rated again; the new draw is kept when the campaign then steps down less
/// ([`descent`]). Returns the campaign and the seeds of the draws kept; `Ok(None)` after a stop.
pub fn rate_and_mend(
    ask: &CampaignAsk,
    panel: &JudgePanel,
    levels: &mut Vec<Level>,
    watch: &Watch,
    draw: &dyn Fn(u64, f64) -> anyhow::Result<Level>,
) -> anyhow::Result<Option<(Campaign, Vec<u64>)>> {
    let n = levels.len();
    let targets: Vec<f64> = (0..n).map(|k| ask.target(k, n)).collect();
    let in_order = |levels: &mut Vec<Level>| {
        let thetas = play_all(panel, levels, ask.trials, watch)?;
        order_by_difficulty(levels, &targets, difficulty::BAND);
        Some(thetas)
    };
    let Some(mut thetas) = in_order(levels) else {
        return Ok(None);
    };
    let mut kept = Vec::new();
    for d in 0..REDRAWS {
        let Some(k) = (1..n).find(|&k| descent(&levels[k - 1..=k]) > 0.0) else {
            break;
        };
        let k = off_trend(levels, k);
        let seed = ask.seed.checked_add((n + d) as u64).ok_or_else(|| {
            anyhow::anyhow!("the campaign's seed plus its redraws overflows a 64-bit seed")
        })?;
        let mut candidate = levels.clone();
        candidate[k] = draw(seed, targets[k])?;
        let Some(candidate_thetas) = in_order(&mut candidate) else {
            return Ok(None);
        };
        if descent(&candidate) < descent(levels) {
            *levels = candidate;
            thetas = candidate_thetas;
            kept.push(seed);
        }
    }
    Ok(Some((ask.named_record(levels, &thetas)?, kept)))
}

/// The panel plays the levels not yet played and all are rated together: the judges' θ, or
/// `None` after a stop (the levels then as they came).
fn play_all(
    panel: &JudgePanel,
    levels: &mut Vec<Level>,
    trials: u32,
    watch: &Watch,
) -> Option<Vec<(String, f64)>> {
    let before = levels.clone();
    let thetas = play_and_rate(panel, levels, trials, watch);
    if levels.len() < before.len() {
        *levels = before;
        return None;
    }
    Some(thetas)
}

/// Level `k` of the campaign in `folder` searched anew from a seed the campaign has not used
/// (one past its largest), with `generator` and the campaign's judge from the policies folder
/// `dir`, to its ramp point (the λ→success curve from `dir` or the cache folder `cache`); then
/// the panel of `dir` rates the campaign again (the levels stay in their places) and every file
/// of the campaign is rewritten in the formats it has. Returns the campaign as [`open`] would
/// read it now.
pub fn regenerate_level(
    folder: &Path,
    k: usize,
    generator: &GeneratorPolicy,
    (dir, cache): (&Path, Option<&Path>),
    stop: &(dyn Fn() -> bool + Sync),
) -> anyhow::Result<(PathBuf, Campaign, Vec<Level>)> {
    let (folder, record, mut levels) = open(folder)?;
    let judge = Judge::parse(&record.judge).map_err(anyhow::Error::msg)?;
    let judged = crate::services::policies::load_panel(dir, record.game, Some(&[judge]))?;
    let profile = record.ask().profile;
    let solver = judged.solver(0);
    let curve = crate::services::policies::difficulty_curve(
        (dir, cache),
        generator,
        &solver,
        profile.as_ref(),
        || {},
        stop,
    )?;
    let seed = record
        .levels
        .iter()
        .map(|l| l.seed)
        .max()
        .unwrap_or(record.seed)
        + 1;
    let target = record.levels[k].asked;
    levels[k] = search_level(
        (generator, &solver),
        &curve,
        &record.ask(),
        (seed, target),
        stop,
    )?;
    for level in &mut levels {
        if let Some(stats) = &mut level.stats {
            stats.panel = None;
        }
    }
    let panel = crate::services::policies::load_panel(dir, record.game, None)?;
    let watch = Watch {
        on_trial: &|_| {},
        stop,
    };
    let rated = rate(&record.ask(), &panel, &mut levels, &watch)?
        .ok_or_else(|| anyhow::anyhow!("stopped"))?;
    let n = levels.len();
    let formats: Vec<Format> = [
        (Format::Yaml, "yaml"),
        (Format::Glb, "glb"),
        (Format::Gltf, "gltf"),
    ]
    .into_iter()
    .filter(|(_, ext)| folder.join(format!("{}.{ext}", level_stem(0, n))).exists())
    .map(|(format, _)| format)
    .collect();
    let files = campaign_files(&folder, &rated, &levels, &formats)?;
    crate::services::fsio::write_batch(&folder, files, &|_| true, "", || {})?;
    Ok((folder, rated, levels))
}

/// The panel's rating of `level`, when it has one.
pub(super) fn rating(level: &Level) -> Option<Rating> {
    level
        .stats
        .as_ref()
        .and_then(|s| s.panel.as_ref())
        .and_then(|p| p.rating)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shipped level measuring `success` for the judge, rated `b` ± 0.1 by the panel.
    fn rated(success: f64, b: f64) -> Level {
        let mut level = arlpcg_core::level::yaml::parse(include_str!(
            "../../../levels/platform/platform_seed7_aux+1.00.yaml"
        ))
        .unwrap();
        let stats = level.stats.as_mut().unwrap();
        stats.success_ratio = success;
        stats.panel = Some(arlpcg_core::level::stats::PanelStats {
            seed: 0,
            trials: 10,
            judges: Vec::new(),
            rating: Some(Rating {
                b,
                ci95: [b - 0.1, b + 0.1],
                levels: 4,
            }),
        });
        level
    }

    fn b_of(levels: &[Level]) -> Vec<f64> {
        levels.iter().map(|l| rating(l).unwrap().b).collect()
    }

    /// Neighbours trade places when the later is rated easier and both still fit the other's
    /// ramp point; a pair that does not fit stays as it is.
    #[test]
    fn levels_go_in_order_of_difficulty_where_the_ramp_allows() {
        let targets = [0.9, 0.8, 0.7, 0.2];
        let mut levels = vec![
            rated(0.85, 1.0),
            rated(0.85, -1.0),
            rated(0.7, 2.0),
            rated(0.2, 0.5),
        ];
        order_by_difficulty(&mut levels, &targets, 0.1);
        // 1 and 2 trade places; 3 and 4 do not (0.2 is not within 0.1 of 0.7).
        assert_eq!(b_of(&levels), [-1.0, 1.0, 2.0, 0.5]);
    }

    /// Descent adds the gaps between intervals that step down; overlapping intervals are no
    /// step. Of a pair that steps down, the level off the campaign's trend is drawn anew.
    #[test]
    fn descent_counts_steps_beyond_the_intervals_and_the_outlier_is_redrawn() {
        let levels: Vec<Level> = [-2.0, -1.0, 1.5, 0.0, 1.0, 0.9]
            .into_iter()
            .map(|b| rated(0.5, b))
            .collect();
        // 1.5 → 0.0: [1.4, 1.6] over [-0.1, 0.1], a gap of 1.3; 1.0 → 0.9 overlaps.
        assert!((descent(&levels) - 1.3).abs() < 1e-9);
        assert_eq!(descent(&levels[..3]), 0.0);
        assert_eq!(off_trend(&levels, 3), 2, "1.5 lies above the rising trend");
        let mut low = levels.clone();
        low[2] = rated(0.5, 0.5);
        low[3] = rated(0.5, -2.0);
        assert_eq!(off_trend(&low, 3), 3, "-2.0 lies below it");
    }
}
