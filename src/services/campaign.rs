//! Campaigns (`arlpcg campaign`): a sequence of levels on a difficulty ramp, each searched to
//! its ramp point ([`crate::services::difficulty::level_for`]) and verified, rated together by
//! the panel of judges, and a player population ([`Population`]) sent through them: who reaches
//! each level, who quits on it, how many attempts a success takes. The campaign's record is
//! `campaign.yaml`; `campaign.md` and `campaign.png` report it.
//!
//! A ramp asks a success ratio per position in the campaign, written like an aux curve:
//! `position:success` points, position 0 the first level and 1 the last, linear between them
//! (`0:0.95, 1:0.5`).

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::services::chart::{LineChart, Series, stacked_png};
use crate::services::checks::Check;
use crate::services::difficulty;
use crate::services::generation::{AuxAsk, GeneratorPolicy, LevelRequest};
use crate::services::level_files::{Format, LevelFiles, render};
use crate::services::panel::{Judge, JudgePanel, play_and_rate};
use crate::services::verify::{self, Solver, Watch};
use arlpcg_core::level::pacing::{AuxCurve, CurveWords, parse_points, show_points, value_at};
use arlpcg_core::level::profile::{Profile, ProfileRecord};
use arlpcg_core::level::stats::Rating;
use arlpcg_core::level::{Game, Level};
use arlpcg_core::statistics::population::{LevelFlow, Population};

/// The record's file name, beside the levels.
pub const CAMPAIGN_FILE: &str = "campaign.yaml";

/// The `format:` of a campaign file.
pub const FORMAT: &str = "arlpcg-campaign";
/// The campaign file's version.
pub const VERSION: u32 = 1;

const RAMP_WORDS: CurveWords = CurveWords {
    curve: "a ramp",
    x: "position",
    x_meaning: "the position in the campaign (0 the first level, 1 the last)",
    y: "success",
    examples: ["0:0.95, 1:0.5", "0.5:0.7", "0.5:0.9, 0.5:0.6"],
};

/// The success ratio asked for along a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Ramp {
    points: Vec<(f64, f64)>,
}

impl Ramp {
    /// Parses `position:success, ...`; each success strictly between 0 and 1 (a level that no
    /// run completes is never kept, and 1 cannot be measured within a band).
    pub fn parse(text: &str) -> Result<Self, String> {
        parse_points(text, &RAMP_WORDS, |success| {
            match success > 0.0 && success < 1.0 {
                true => Ok(()),
                false => Err("a success ratio strictly between 0 and 1".into()),
            }
        })
        .map(|points| Self { points })
    }

    /// The success asked for at `position` (0 first level, 1 last).
    pub fn at(&self, position: f64) -> f64 {
        value_at(&self.points, position)
    }
}

impl fmt::Display for Ramp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&show_points(&self.points))
    }
}

arlpcg_core::as_text!(Ramp);

/// Level `k`'s position in a campaign of `n` levels: 0 for the first, 1 for the last.
pub fn position(k: usize, n: usize) -> f64 {
    match n {
        0 | 1 => 0.0,
        _ => k as f64 / (n - 1) as f64,
    }
}

/// The name of level `k` (from 0) of a campaign of `n` levels: `level01`, wide enough that
/// the names sort in order.
pub fn level_stem(k: usize, n: usize) -> String {
    let width = n.to_string().len().max(2);
    format!("level{:0width$}", k + 1)
}

/// A campaign's record (`campaign.yaml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Campaign {
    pub format: String,
    pub version: u32,
    pub game: Game,
    /// Level `k` is searched from seed `seed + k`.
    pub seed: u64,
    /// The judge whose success the ramp asks for.
    pub judge: String,
    /// Runs per level, for the judge and for each judge of the panel.
    pub trials: u32,
    pub ramp: Ramp,
    /// The shape of λ along each level (pacing), moved as a whole by each level's search.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pacing: Option<AuxCurve>,
    /// The game profile every level is made for (none: the built-in one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileRecord>,
    /// Acceptance checks every level must pass (`verify --campaign` applies them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub checks: Vec<Check>,
    pub population: Population,
    /// `scripted judges`: the population's 10th, 50th and 90th percentiles of θ are the
    /// scripted novice's, median's and expert's; `given`: as asked for.
    pub population_from: String,
    /// Each judge's ability θ from the panel's rating of these levels, logits.
    pub judges_theta: Vec<JudgeTheta>,
    pub levels: Vec<CampaignLevel>,
}

/// A judge's ability on the campaign's levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JudgeTheta {
    pub judge: String,
    pub theta: f64,
}

/// One level of a campaign: what was asked, what was measured, and how the population fares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignLevel {
    /// The level file, beside campaign.yaml.
    pub file: String,
    /// The seed its search and its runs started from (campaign seed + the level's place in the
    /// search, before [`order_by_difficulty`]; seed + n + d for the d-th level drawn anew).
    pub seed: u64,
    pub position: f64,
    /// The judge's success asked for by the ramp.
    pub asked: f64,
    /// The judge's success measured, with its 95% interval.
    pub measured: f64,
    pub ci95: [f64; 2],
    /// The λ the level was built at, or its curve of λ (with `pacing`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aux: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aux_curve: Option<AuxCurve>,
    /// Difficulty on the panel's scale, logits, with its 95% interval.
    pub b: f64,
    pub b_ci95: [f64; 2],
    /// How the population fares on it.
    pub players: LevelFlow,
}

/// How the population is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PopulationAsk {
    /// From the scripted judges' θ (10th, 50th, 90th percentiles), with this retry chance.
    ScriptedJudges { retry: f64 },
    /// As given.
    Given(Population),
}

/// What a campaign was asked for.
#[derive(Debug, Clone)]
pub struct CampaignAsk {
    pub game: Game,
    pub seed: u64,
    pub judge: String,
    pub trials: u32,
    pub ramp: Ramp,
    pub pacing: Option<AuxCurve>,
    pub profile: Option<Profile>,
    pub checks: Vec<Check>,
    pub population: PopulationAsk,
}

impl CampaignAsk {
    /// What level `seed`'s search asks (its λ curve's shape, its profile).
    pub fn request(&self, seed: u64) -> LevelRequest {
        let asked = LevelRequest::new(seed, None).profile(self.profile.clone());
        match &self.pacing {
            Some(shape) => asked.aux(AuxAsk::Curve(shape.clone())),
            None => asked,
        }
    }

    /// The success asked of level `k` of `n`.
    pub fn target(&self, k: usize, n: usize) -> f64 {
        self.ramp.at(position(k, n))
    }

    /// [`Self::record`] of `levels` in their order, named `levelNN.yaml`.
    pub fn named_record(
        &self,
        levels: &[Level],
        judges_theta: &[(String, f64)],
    ) -> anyhow::Result<Campaign> {
        let n = levels.len();
        let named: Vec<(String, &Level)> = levels
            .iter()
            .enumerate()
            .map(|(k, l)| (format!("{}.yaml", level_stem(k, n)), l))
            .collect();
        self.record(&named, judges_theta)
            .map_err(anyhow::Error::msg)
    }

    /// The campaign record of `levels` (named by file, in order), each verified by the judge
    /// and played by the panel, rated together into `judges_theta`. `Err` when the population
    /// is fitted but a scripted judge is missing from the panel.
    pub fn record(
        &self,
        levels: &[(String, &Level)],
        judges_theta: &[(String, f64)],
    ) -> Result<Campaign, String> {
        let population = match self.population {
            PopulationAsk::Given(population) => population,
            PopulationAsk::ScriptedJudges { retry } => {
                let theta = |name: &str| {
                    judges_theta
                        .iter()
                        .find(|(n, _)| n == name)
                        .map(|(_, t)| *t)
                        .ok_or_else(|| {
                            format!("the panel has no {name}, whose θ the population is fitted to")
                        })
                };
                Population::from_percentiles(
                    theta("scripted-novice")?,
                    theta("scripted-median")?,
                    theta("scripted-expert")?,
                    retry,
                )
            }
        };
        let b: Vec<f64> = levels
            .iter()
            .map(|(_, l)| rating(l).map_or(f64::NAN, |r| r.b))
            .collect();
        let flows = population.funnel(&b);
        let n = levels.len();
        let records = levels
            .iter()
            .zip(flows)
            .enumerate()
            .map(|(k, ((file, level), flow))| {
                let stats = level.stats.as_ref();
                let rating = rating(level);
                CampaignLevel {
                    file: file.clone(),
                    seed: stats.map_or(0, |s| s.seed),
                    position: round4(position(k, n)),
                    asked: round4(self.target(k, n)),
                    measured: stats.map_or(f64::NAN, |s| s.success_ratio),
                    ci95: stats.map_or([f64::NAN; 2], |s| s.ci95),
                    aux: level.aux,
                    aux_curve: level.pacing.as_ref().map(|p| p.curve.clone()),
                    b: rating.map_or(f64::NAN, |r| r.b),
                    b_ci95: rating.map_or([f64::NAN; 2], |r| r.ci95),
                    players: LevelFlow {
                        reach: round4(flow.reach),
                        quit: round4(flow.quit),
                        pass: round4(flow.pass),
                        attempts_per_success: round4(flow.attempts_per_success),
                    },
                }
            })
            .collect();
        Ok(Campaign {
            format: FORMAT.into(),
            version: VERSION,
            game: self.game,
            seed: self.seed,
            judge: self.judge.clone(),
            trials: self.trials,
            ramp: self.ramp.clone(),
            pacing: self.pacing.clone(),
            profile: self.profile.as_ref().map(Profile::record),
            checks: self.checks.clone(),
            population: Population {
                theta_mean: round4(population.theta_mean),
                theta_sd: round4(population.theta_sd),
                retry: population.retry,
            },
            population_from: match self.population {
                PopulationAsk::Given(_) => "given".into(),
                PopulationAsk::ScriptedJudges { .. } => "scripted judges".into(),
            },
            judges_theta: judges_theta
                .iter()
                .map(|(judge, theta)| JudgeTheta {
                    judge: judge.clone(),
                    theta: round4(*theta),
                })
                .collect(),
            levels: records,
        })
    }
}

impl Campaign {
    /// What the campaign was asked for, as its record says (to play or extend it again).
    pub fn ask(&self) -> CampaignAsk {
        CampaignAsk {
            game: self.game,
            seed: self.seed,
            judge: self.judge.clone(),
            trials: self.trials,
            ramp: self.ramp.clone(),
            pacing: self.pacing.clone(),
            // A record read back was checked ([`Campaign::check`]).
            profile: self
                .profile
                .as_ref()
                .and_then(|record| record.profile(self.game).ok()),
            checks: self.checks.clone(),
            population: match self.population_from.as_str() {
                "given" => PopulationAsk::Given(self.population),
                _ => PopulationAsk::ScriptedJudges {
                    retry: self.population.retry,
                },
            },
        }
    }

    /// Checks a campaign read back from a file; `Err` names the field.
    pub fn check(&self) -> Result<(), String> {
        if self.format != FORMAT {
            return Err(format!("format: `{}`, not `{FORMAT}`", self.format));
        }
        if self.version != VERSION {
            return Err(format!(
                "version: {} is not a version this tool reads ({VERSION})",
                self.version
            ));
        }
        if self.trials == 0 {
            return Err("trials: at least 1".into());
        }
        self.population
            .check()
            .map_err(|e| format!("population.{e}"))?;
        if let Some(record) = &self.profile {
            record
                .profile(self.game)
                .map_err(|e| format!("profile: {e}"))?;
        }
        if self.levels.is_empty() {
            return Err("levels: none; a campaign has at least one level".into());
        }
        for (k, level) in self.levels.iter().enumerate() {
            let plain = Path::new(&level.file)
                .file_name()
                .is_some_and(|name| name == level.file.as_str());
            if !plain || !level.file.ends_with(".yaml") {
                return Err(format!(
                    "levels[{k}].file: `{}` must be a .yaml file name beside campaign.yaml",
                    level.file
                ));
            }
        }
        Ok(())
    }

    /// The share of the population that finishes the campaign.
    pub fn finishers(&self) -> f64 {
        self.levels
            .last()
            .map_or(1.0, |l| l.players.reach - l.players.quit)
    }

    /// The campaign as a Markdown page: what was asked, a table per level, the funnel.
    pub fn to_markdown(&self) -> String {
        let p = &self.population;
        let mut page = format!(
            "# Campaign: {} {} levels, seed {}\n\n\
             Ramp asked for `{}` (success of `{}`, {} runs per level){}. Population: θ ~ \
             Normal({:+.2}, {:.2}) logits ({}), retries after a failure with chance {:.2}; \
             {:.1}% of players finish the campaign.\n\n\
             | level | file | asked | measured (95% CI) | λ | b (95% CI) | reach | quit here | attempts per success |\n\
             |---|---|---|---|---|---|---|---|---|\n",
            self.levels.len(),
            self.game,
            self.seed,
            self.ramp,
            self.judge,
            self.trials,
            self.pacing.as_ref().map_or(String::new(), |c| format!(
                ", each level paced by `{c}` moved as a whole"
            )) + &self.profile.as_ref().map_or(String::new(), |p| format!(
                ", made for profile `{}`",
                p.name
            )),
            p.theta_mean,
            p.theta_sd,
            self.population_from,
            p.retry,
            100.0 * self.finishers(),
        );
        for (k, l) in self.levels.iter().enumerate() {
            let aux = match (l.aux, &l.aux_curve) {
                (Some(aux), _) => format!("{aux:+.2}"),
                (None, Some(curve)) => format!("`{curve}`"),
                (None, None) => String::new(),
            };
            page += &format!(
                "| {} | {} | {:.2} | {:.2} ({:.2}–{:.2}) | {aux} | {:+.2} ({:+.2} to {:+.2}) | {:.3} | {:.3} | {:.2} |\n",
                k + 1,
                l.file,
                l.asked,
                l.measured,
                l.ci95[0],
                l.ci95[1],
                l.b,
                l.b_ci95[0],
                l.b_ci95[1],
                l.players.reach,
                l.players.quit,
                l.players.attempts_per_success,
            );
        }
        let thetas: Vec<String> = self
            .judges_theta
            .iter()
            .map(|j| format!("{} {:+.2}", j.judge, j.theta))
            .collect();
        page += &format!("\nJudges' ability θ (logits): {}.\n", thetas.join(", "));
        page += &format!("\n{}.\n", self.b_trend());
        if !self.checks.is_empty() {
            let checks: Vec<String> = self.checks.iter().map(|c| format!("`{c}`")).collect();
            page += &format!("\nChecks every level must pass: {}.\n", checks.join(", "));
        }
        page
    }

    /// The campaign's charts, one above the other: success asked and measured with the share
    /// of players who reach each level; and b per level with its interval.
    pub fn charts(&self) -> Vec<LineChart> {
        let per_level = |f: &dyn Fn(&CampaignLevel) -> f64| -> Vec<(f64, f64)> {
            self.levels
                .iter()
                .enumerate()
                .map(|(k, l)| ((k + 1) as f64, f(l)))
                .collect()
        };
        let series = |name: &str, f: &dyn Fn(&CampaignLevel) -> f64| Series {
            name: name.into(),
            points: per_level(f),
        };
        vec![
            LineChart {
                title: format!(
                    "{} campaign: success of {} and players who reach each level",
                    self.game, self.judge
                ),
                x_label: "level".into(),
                y_label: "share".into(),
                series: vec![
                    series("asked", &|l| l.asked),
                    series("measured", &|l| l.measured),
                    series("players reaching", &|l| l.players.reach),
                ],
                y_range: Some((0.0, 1.0)),
            },
            LineChart {
                title: "difficulty b on the panel's scale (95% interval)".into(),
                x_label: "level".into(),
                y_label: "b (logits)".into(),
                series: vec![
                    series("b", &|l| l.b),
                    series("low", &|l| l.b_ci95[0]),
                    series("high", &|l| l.b_ci95[1]),
                ],
                y_range: None,
            },
        ]
    }
}

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

impl Campaign {
    /// Whether b rises along the campaign, in words: `b rises level to level within its
    /// intervals`, or where it steps down.
    pub fn b_trend(&self) -> String {
        match self.steps_down()[..] {
            [] => "b rises level to level within its intervals".into(),
            ref down => format!(
                "b steps down beyond its intervals at level {}",
                down.iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }

    /// The levels (numbered from 1) whose b falls below the one before it beyond both
    /// intervals: where the campaign steps down for the panel.
    pub fn steps_down(&self) -> Vec<usize> {
        self.levels
            .windows(2)
            .enumerate()
            .filter(|(_, pair)| pair[1].b_ci95[1] < pair[0].b_ci95[0])
            .map(|(k, _)| k + 2)
            .collect()
    }
}

/// The search `asked` ([`CampaignAsk::request`]): a level whose success for `solver`, over
/// `trials` runs, is within [`difficulty::BAND`] of `target` ([`difficulty::level_for`]; with a
/// curve of λ, that curve moved as a whole), with its certificate.
pub fn search_level(
    generator: &GeneratorPolicy,
    solver: &Solver,
    curve: &difficulty::Curve,
    asked: &LevelRequest,
    target: f64,
    trials: u32,
) -> anyhow::Result<Level> {
    let level = difficulty::level_for(generator, solver, curve, asked, target, trials)?;
    Ok(verify::certified(level, solver, asked.seed)?)
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

/// The files of a campaign in folder `dir`: each level's (`levelNN` in `formats`, a .gltf after
/// the .bin it names), then campaign.yaml, campaign.md and campaign.png.
pub fn campaign_files(
    dir: &Path,
    campaign: &Campaign,
    levels: &[Level],
    formats: &[Format],
) -> anyhow::Result<Vec<(PathBuf, Vec<u8>)>> {
    let n = levels.len();
    let mut files: Vec<(PathBuf, Vec<u8>)> = levels
        .iter()
        .enumerate()
        .flat_map(|(k, level)| {
            let names = LevelFiles::new(dir, &level_stem(k, n), formats);
            render(level, &names).into_iter().rev()
        })
        .collect();
    let record = serde_yaml::to_string(campaign)?;
    files.push((dir.join(CAMPAIGN_FILE), record.into_bytes()));
    files.push((dir.join("campaign.md"), campaign.to_markdown().into_bytes()));
    files.push((dir.join("campaign.png"), stacked_png(&campaign.charts())));
    Ok(files)
}

/// Level `k` of the campaign in `folder` searched anew from a seed the campaign has not used
/// (one past its largest), with `generator` and the campaign's judge from the policies folder
/// `dir`, to its ramp point; then the panel of `dir` rates the campaign again (the levels stay
/// in their places) and every file of the campaign is rewritten in the formats it has. Returns
/// the campaign as [`open`] would read it now.
pub fn regenerate_level(
    folder: &Path,
    k: usize,
    generator: &GeneratorPolicy,
    dir: &Path,
    stop: &(dyn Fn() -> bool + Sync),
) -> anyhow::Result<(PathBuf, Campaign, Vec<Level>)> {
    let (folder, record, mut levels) = open(folder)?;
    let judge = Judge::parse(&record.judge).map_err(anyhow::Error::msg)?;
    let judged = crate::services::policies::load_panel(dir, record.game, Some(&[judge]))?;
    let solver = judged.solver(0);
    let curve = crate::services::policies::difficulty_curve(dir, generator, &solver, || {}, stop)?;
    let seed = record
        .levels
        .iter()
        .map(|l| l.seed)
        .max()
        .unwrap_or(record.seed)
        + 1;
    let target = record.levels[k].asked;
    let asked = record.ask().request(seed);
    levels[k] = search_level(generator, &solver, &curve, &asked, target, record.trials)?;
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

/// A campaign's record alone (`campaign.yaml`), read and checked.
pub fn read_record(file: &Path) -> anyhow::Result<Campaign> {
    let bytes = crate::services::fsio::read_limited(file, 1 << 22, "campaign file")?;
    let campaign: Campaign =
        serde_yaml::from_slice(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    campaign
        .check()
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    Ok(campaign)
}

/// A campaign read back: its folder, its record (checked), and its levels in order, each of
/// the campaign's game. `path` is the folder or its campaign.yaml.
pub fn open(path: &Path) -> anyhow::Result<(PathBuf, Campaign, Vec<Level>)> {
    let file = match path.is_dir() {
        true => path.join(CAMPAIGN_FILE),
        false => path.to_path_buf(),
    };
    let folder = file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let campaign = read_record(&file)?;
    let mut levels = Vec::with_capacity(campaign.levels.len());
    for entry in &campaign.levels {
        let level_path = folder.join(&entry.file);
        let level = arlpcg_core::level::yaml::load(&level_path)?;
        if level.game() != campaign.game {
            anyhow::bail!(
                "{}: a {} level in a {} campaign",
                level_path.display(),
                level.game(),
                campaign.game
            );
        }
        levels.push(level);
    }
    Ok((folder, campaign, levels))
}

/// The panel's rating of `level`, when it has one.
fn rating(level: &Level) -> Option<Rating> {
    level
        .stats
        .as_ref()
        .and_then(|s| s.panel.as_ref())
        .and_then(|p| p.rating)
}

fn round4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ramp_reads_back_what_it_writes_and_names_a_bad_point() {
        let ramp = Ramp::parse("0:0.95, 1:0.5").unwrap();
        assert_eq!(ramp.to_string(), "0:0.95, 1:0.5");
        assert!((ramp.at(position(5, 11)) - 0.725).abs() < 1e-12);
        assert_eq!(ramp.at(position(0, 1)), 0.95);
        let step = Ramp::parse("0:0.9, 0.5:0.9, 0.5:0.6, 1:0.6").unwrap();
        assert_eq!(step.at(0.75), 0.6);
        for (text, expected) in [
            ("", "a ramp needs at least one point `position:success`"),
            (
                "0:1",
                "point 1 (0:1): a success ratio strictly between 0 and 1",
            ),
            (
                "0:0.9, 1.5:0.5",
                "point 2 (1.5:0.5): the position in the campaign",
            ),
            ("0.5:0.9, 0:0.5", "positions must increase"),
            ("0:x", "its success `x` is not a number"),
        ] {
            let err = Ramp::parse(text).unwrap_err();
            assert!(err.contains(expected), "{text}: {err}");
        }
    }

    /// A shipped level measuring `success` for the judge, rated `b` ± 0.1 by the panel.
    fn rated(success: f64, b: f64) -> Level {
        let mut level = arlpcg_core::level::yaml::parse(include_str!(
            "../../levels/platform/platform_seed7_aux+1.00.yaml"
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

    #[test]
    fn level_names_sort_in_order() {
        assert_eq!(level_stem(0, 10), "level01");
        assert_eq!(level_stem(9, 10), "level10");
        assert_eq!(level_stem(99, 120), "level100");
        assert_eq!(level_stem(4, 120), "level005");
    }
}
