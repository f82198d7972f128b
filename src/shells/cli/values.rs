//! The command line's values as text: each option's parser, with the one-line reason a value is
//! refused, and the small types they make.

use std::path::PathBuf;

use crate::services::panel::Judge;
use arlpcg_core::level::Game;
use arlpcg_core::level::params;

/// One of K equal shares of a batch (`--shard I/K`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// The share's index, from 0.
    pub index: u64,
    /// How many shares.
    pub count: u64,
}

impl Shard {
    /// Whether item `i` of the batch belongs to this shard.
    pub fn owns(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

pub(super) fn parse_target(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if p > 0.0 && p < 1.0 => Ok(p),
        _ => Err(format!(
            "`{s}` is not a success ratio strictly between 0 and 1"
        )),
    }
}

/// `--keep LEVEL.yaml:K`: the level file and how many of its pieces to keep.
#[derive(Debug, Clone, PartialEq)]
pub struct KeepArg {
    /// The level file.
    pub level: PathBuf,
    /// How many of its pieces to keep.
    pub pieces: usize,
}

pub(super) fn parse_keep(s: &str) -> Result<KeepArg, String> {
    let (path, pieces) = s.rsplit_once(':').ok_or_else(|| {
        format!("`{s}` is not LEVEL.yaml:K (the level file, then how many of its pieces to keep)")
    })?;
    let pieces = pieces.trim().parse().map_err(|_| {
        format!("`{s}`: after the last `:` comes the number of pieces to keep, not `{pieces}`")
    })?;
    if path.is_empty() {
        return Err(format!("`{s}`: the level file is missing before `:`"));
    }
    Ok(KeepArg {
        level: PathBuf::from(path),
        pieces,
    })
}

pub(super) fn parse_shard(s: &str) -> Result<Shard, String> {
    let bad = || format!("`{s}` is not I/K with 0 <= I < K (e.g. 0/4 .. 3/4)");
    let (i, k) = s.split_once('/').ok_or_else(bad)?;
    let index: u64 = i.trim().parse().map_err(|_| bad())?;
    let count: u64 = k.trim().parse().map_err(|_| bad())?;
    if count == 0 || index >= count {
        return Err(bad());
    }
    Ok(Shard { index, count })
}

pub(super) fn parse_contract(s: &str) -> Result<crate::services::onnx::Contract, String> {
    match s {
        "plain" => Ok(crate::services::onnx::Contract::Plain),
        "mlagents" => Ok(crate::services::onnx::Contract::Mlagents),
        _ => Err(format!("unknown profile {s}: plain or mlagents")),
    }
}

/// The judges a panel is asked for (empty: the default panel).
#[derive(Debug, Clone, PartialEq)]
pub struct Judges(pub Vec<Judge>);

pub(super) fn parse_judges(s: &str) -> Result<Judges, String> {
    let judges = s
        .split(',')
        .filter(|name| !name.trim().is_empty())
        .map(Judge::parse)
        .collect::<Result<Vec<_>, _>>()?;
    for (k, judge) in judges.iter().enumerate() {
        if judges[..k].contains(judge) {
            return Err(format!(
                "{} is named twice: each judge counts once in the rating",
                judge.name()
            ));
        }
    }
    Ok(Judges(judges))
}

pub(super) fn parse_minutes(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(m) if m.is_finite() && m > 0.0 => Ok(m),
        _ => Err(format!("`{s}` is not a positive number of minutes")),
    }
}

pub(super) fn parse_ability_spread(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(share) if (0.0..=0.5).contains(&share) => Ok(share),
        _ => Err(format!("`{s}` is not a share within [0, 0.5] (0.2: ±20%)")),
    }
}

pub(super) fn parse_game(s: &str) -> Result<Game, String> {
    s.parse()
}

pub(super) fn parse_aux(s: &str) -> Result<f64, String> {
    let value: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    // -0 is 0 (`check` returns it so): the same level, file name and YAML.
    params::AUX.check(value).map_err(|e| e.to_string())
}

/// `--aux`: λ alone (`-0.5`), or named values (`difficulty=-0.5,stride=1`), each in [-1, 1];
/// names other than `difficulty` are a Generator's style knobs, checked once the game is known.
#[derive(Debug, Clone, PartialEq)]
pub struct AuxArg {
    /// λ: +1 easy, -1 hard.
    pub difficulty: Option<f64>,
    /// The knobs asked for, by name, in the order given.
    pub knobs: Vec<(String, f64)>,
}

pub(super) fn parse_aux_arg(s: &str) -> Result<AuxArg, String> {
    if !s.contains('=') {
        return parse_aux(s.trim()).map(|difficulty| AuxArg {
            difficulty: Some(difficulty),
            knobs: Vec::new(),
        });
    }
    let mut arg = AuxArg {
        difficulty: None,
        knobs: Vec::new(),
    };
    for part in s.split(',') {
        let (name, value) = part.split_once('=').ok_or_else(|| {
            format!("`{part}`: give name=value pairs (difficulty=-0.5,stride=1) or one number")
        })?;
        let name = name.trim();
        let value = parse_aux(value.trim()).map_err(|e| format!("{name}: {e}"))?;
        let given_twice = format!("`{name}` is given twice");
        match name {
            "" => return Err(format!("`{part}`: a value without a name")),
            "difficulty" if arg.difficulty.is_some() => return Err(given_twice),
            "difficulty" => arg.difficulty = Some(value),
            _ if arg.knobs.iter().any(|(known, _)| known == name) => return Err(given_twice),
            _ => arg.knobs.push((name.to_string(), value)),
        }
    }
    Ok(arg)
}

pub(super) fn parse_point(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!("`{s}` is not x,y,z"));
    };
    let mut point = [0.0; 3];
    for (slot, part) in point.iter_mut().zip([x, y, z]) {
        let value: f64 = part
            .trim()
            .parse()
            .map_err(|_| format!("`{part}` is not a number"))?;
        *slot = params::COORDINATE.check(value).map_err(|e| e.to_string())?;
    }
    Ok(point)
}

/// `--population MEAN,SD`: the players' ability θ, logits.
pub(super) fn parse_population(s: &str) -> Result<(f64, f64), String> {
    let bad = || format!("`{s}` is not MEAN,SD (two numbers, SD ≥ 0: e.g. 0.5,1.2)");
    let (mean, sd) = s.split_once(',').ok_or_else(bad)?;
    let (mean, sd): (f64, f64) = (
        mean.trim().parse().map_err(|_| bad())?,
        sd.trim().parse().map_err(|_| bad())?,
    );
    // The limits a campaign file's population meets too.
    let population = arlpcg_core::statistics::population::Population {
        theta_mean: mean + 0.0,
        theta_sd: sd + 0.0,
        retry: arlpcg_core::statistics::population::DEFAULT_RETRY,
    };
    population
        .check()
        .map(|()| (population.theta_mean, population.theta_sd))
        .map_err(|problem| format!("`{s}`: {problem}"))
}

/// `--retry P`: a chance within [0, 1).
pub(super) fn parse_retry(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..1.0).contains(&p) => Ok(p),
        _ => Err(format!(
            "`{s}` is not a chance within [0, 1) (1 would retry forever)"
        )),
    }
}
