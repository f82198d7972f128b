//! Campaigns (`arlpcg campaign`): a sequence of levels on a difficulty ramp, each searched to
//! its ramp point ([`crate::services::difficulty::level_for`]) and verified, rated together by
//! the panel of judges, and a player population ([`Population`]) sent through them: who reaches
//! each level, who quits on it, how many attempts a success takes. The campaign's record is
//! `campaign.yaml`; `campaign.md` and `campaign.png` report it.
//!
//! Here: the ramp, the record and its files. `order.rs` searches, plays, orders and mends the
//! levels; `report.rs` writes the page and the charts.
//!
//! A ramp asks a success ratio per position in the campaign, written like an aux curve:
//! `position:success` points, position 0 the first level and 1 the last, linear between them
//! (`0:0.95, 1:0.5`).

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::services::chart::stacked_png;
use crate::services::generation::{AuxAsk, LevelRequest};
use crate::services::level_files::{Format, GltfOptions, LevelFiles, render};
use crate::services::wish::Constraint;
use arlpcg_core::level::pacing::{AuxCurve, CurveWords, parse_points, show_points, value_at};
use arlpcg_core::level::profile::{Profile, ProfileRecord};
use arlpcg_core::level::{Game, Level};
use arlpcg_core::statistics::population::{LevelFlow, Population};

mod order;
mod report;
use order::rating;
pub use order::{
    REDRAWS, descent, order_by_difficulty, rate, rate_and_mend, regenerate_level, search_level,
};

/// The record's file name, beside the levels.
pub const CAMPAIGN_FILE: &str = "campaign.yaml";

/// Runs per level a campaign may ask for, least and most (`campaign --trials`); a campaign
/// file is held to the same.
pub const TRIALS: (u32, u32) = (10, 100_000);
/// The most levels a campaign may have (`campaign --levels`, and a campaign file).
pub const MOST_LEVELS: u32 = 1000;

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
    /// Always [`FORMAT`].
    pub format: String,
    /// The record's format version.
    pub version: u32,
    /// The game.
    pub game: Game,
    /// Level `k` is searched from seed `seed + k`.
    pub seed: u64,
    /// The judge whose success the ramp asks for.
    pub judge: String,
    /// Runs per level, for the judge and for each judge of the panel.
    pub trials: u32,
    /// The judge's success asked for along the campaign.
    pub ramp: Ramp,
    /// The shape of λ along each level (pacing), moved as a whole by each level's search.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pacing: Option<AuxCurve>,
    /// The game profile every level is made for (none: the built-in one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileRecord>,
    /// Acceptance checks every level must pass (`verify --campaign` applies them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub checks: Vec<Constraint>,
    /// How the levels' glTF files carry their colliders (absent: OMI, no import hints); a
    /// level searched anew is written the same way.
    #[serde(default, skip_serializing_if = "GltfOptions::is_default")]
    pub gltf: GltfOptions,
    /// The player population the levels are judged for.
    pub population: Population,
    /// `scripted judges`: the population's 10th, 50th and 90th percentiles of θ are the
    /// scripted novice's, median's and expert's; `given`: as asked for.
    pub population_from: String,
    /// Each judge's ability θ from the panel's rating of these levels, logits.
    pub judges_theta: Vec<JudgeTheta>,
    /// The levels, in campaign order.
    pub levels: Vec<CampaignLevel>,
}

/// A judge's ability on the campaign's levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JudgeTheta {
    /// The judge's name.
    pub judge: String,
    /// Its ability θ, logits.
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
    /// Its place in the campaign: 0 the first level, 1 the last.
    pub position: f64,
    /// The judge's success asked for by the ramp.
    pub asked: f64,
    /// The judge's success measured, with its 95% interval.
    pub measured: f64,
    /// The 95% interval of `measured`.
    pub ci95: [f64; 2],
    /// The λ the level was built at, or its curve of λ (with `pacing`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aux: Option<f64>,
    /// The curve of λ the level was built along (with `pacing`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aux_curve: Option<AuxCurve>,
    /// Difficulty on the panel's scale, logits, with its 95% interval.
    pub b: f64,
    /// The 95% interval of `b`.
    pub b_ci95: [f64; 2],
    /// How the population fares on it.
    pub players: LevelFlow,
}

/// How the population is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PopulationAsk {
    /// From the scripted judges' θ (10th, 50th, 90th percentiles), with this retry chance.
    ScriptedJudges {
        /// The chance a player tries a failed level again (else quits).
        retry: f64,
    },
    /// As given.
    Given(Population),
}

/// What a campaign was asked for.
#[derive(Debug, Clone)]
pub struct CampaignAsk {
    /// The game.
    pub game: Game,
    /// Level `k` is searched from seed `seed + k`.
    pub seed: u64,
    /// The judge whose success the ramp asks for.
    pub judge: String,
    /// Runs per level, for the judge and for each judge of the panel.
    pub trials: u32,
    /// The judge's success asked for along the campaign.
    pub ramp: Ramp,
    /// The shape of λ along each level, if any.
    pub pacing: Option<AuxCurve>,
    /// The game profile the levels are made for (none: the built-in one).
    pub profile: Option<Profile>,
    /// Acceptance checks every level must pass.
    pub checks: Vec<Constraint>,
    /// How the levels' glTF files carry their colliders.
    pub gltf: GltfOptions,
    /// How the player population is set.
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
            gltf: self.gltf,
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
            gltf: self.gltf,
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
        // The limits of `campaign --trials` and `--levels`: a file asks no more than they do.
        if !(TRIALS.0..=TRIALS.1).contains(&self.trials) {
            return Err(format!(
                "trials: {} is not within [{}, {}] (campaign --trials)",
                self.trials, TRIALS.0, TRIALS.1
            ));
        }
        self.population
            .check()
            .map_err(|e| format!("population.{e}"))?;
        if let Some(record) = &self.profile {
            record
                .profile(self.game)
                .map_err(|e| format!("profile: {e}"))?;
        }
        if self.levels.is_empty() || self.levels.len() > MOST_LEVELS as usize {
            return Err(format!(
                "levels: {}; a campaign has 1 to {MOST_LEVELS} levels (campaign --levels)",
                self.levels.len()
            ));
        }
        for (k, judge) in self.judges_theta.iter().enumerate() {
            within(&format!("judges_theta[{k}].theta"), judge.theta, LOGITS)?;
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
            level.check().map_err(|e| format!("levels[{k}].{e}"))?;
        }
        Ok(())
    }
}

/// The range of an ability or a difficulty on the panel's logit scale.
const LOGITS: (f64, f64) = (
    -arlpcg_core::statistics::population::MOST_LOGITS,
    arlpcg_core::statistics::population::MOST_LOGITS,
);
/// The range of a share or a success ratio.
const SHARE: (f64, f64) = (0.0, 1.0);

/// `Err` naming `field` unless `value` is a number within `range`.
fn within(field: &str, value: f64, (least, most): (f64, f64)) -> Result<(), String> {
    match (least..=most).contains(&value) {
        true => Ok(()),
        false => Err(format!(
            "{field}: {} is not a number within [{least}, {most}]",
            arlpcg_core::level::params::show_number(value)
        )),
    }
}

impl CampaignLevel {
    /// Checks the numbers a campaign file gives a level: shares within [0, 1], b within the
    /// logit scale's range, λ within [-1, 1]. `Err` names the field.
    fn check(&self) -> Result<(), String> {
        within("position", self.position, SHARE)?;
        within("asked", self.asked, SHARE)?;
        within("measured", self.measured, SHARE)?;
        within("ci95[0]", self.ci95[0], SHARE)?;
        within("ci95[1]", self.ci95[1], SHARE)?;
        within("b", self.b, LOGITS)?;
        within("b_ci95[0]", self.b_ci95[0], LOGITS)?;
        within("b_ci95[1]", self.b_ci95[1], LOGITS)?;
        if let Some(aux) = self.aux {
            within("aux", aux, (-1.0, 1.0))?;
        }
        let players = &self.players;
        within("players.reach", players.reach, SHARE)?;
        within("players.quit", players.quit, SHARE)?;
        within("players.pass", players.pass, SHARE)?;
        // Infinite where no player passes the level.
        if !(1.0..=f64::INFINITY).contains(&players.attempts_per_success) {
            return Err(format!(
                "players.attempts_per_success: {} is not a number of at least 1",
                arlpcg_core::level::params::show_number(players.attempts_per_success)
            ));
        }
        Ok(())
    }
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
            let names = LevelFiles::new(dir, &level_stem(k, n), formats).with_gltf(campaign.gltf);
            render(level, &names).into_iter().rev()
        })
        .collect();
    let record = serde_yaml::to_string(campaign)?;
    files.push((dir.join(CAMPAIGN_FILE), record.into_bytes()));
    files.push((dir.join("campaign.md"), campaign.to_markdown().into_bytes()));
    files.push((dir.join("campaign.png"), stacked_png(&campaign.charts())));
    Ok(files)
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

    #[test]
    fn level_names_sort_in_order() {
        assert_eq!(level_stem(0, 10), "level01");
        assert_eq!(level_stem(9, 10), "level10");
        assert_eq!(level_stem(99, 120), "level100");
        assert_eq!(level_stem(4, 120), "level005");
    }
}
