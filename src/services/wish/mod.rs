//! Wish lists: what a designer wants of a level, as constraints on its attributes
//! ([`attributes`]), read from one small language (`pieces 8..12, climb >= 6, hardest
//! 0.66..1, success 0.4..0.6 for scripted-median`) or from plain words ([`words`]).
//! `generate --want` searches until a level meets every constraint
//! ([`crate::services::making`]); `verify --check`, `generate --check` and a campaign's
//! `checks:` check levels with the same constraints. docs/wish.md is the language's manual.

pub mod attributes;
pub mod score;
pub mod words;

use std::fmt;

use arlpcg_core::level::params::show_number;
use arlpcg_core::level::{Game, Level, MeasuredConstraint};

use crate::services::panel::Judge;
pub use attributes::{Attribute, Evidence, Reads};

/// The most constraints one wish list may hold.
pub const MAX_CONSTRAINTS: usize = 32;
/// The longest wish list or sentence read, in bytes.
pub const MAX_TEXT: usize = 2_000;

/// One constraint: an attribute's value within `[low, high]` (`completed`: 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constraint {
    /// What is measured.
    pub attribute: Attribute,
    /// The least value asked (`-inf`: none).
    pub low: f64,
    /// The most value asked (`inf`: none).
    pub high: f64,
}

/// How a measured value is held against a constraint's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strictness {
    /// The value itself lies in the range: what a search keeps.
    Value,
    /// For success and b, the 95% interval meets the range (a level is not failed by the noise
    /// of its own runs): what a check fails.
    Interval,
}

/// A constraint that a level misses: by how much, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Miss {
    /// The value measured, where the level has it.
    pub value: Option<f64>,
    /// How far outside the range, in the attribute's scale (1 where it could not be measured).
    pub distance: f64,
    /// One line: the constraint and what was measured.
    pub why: String,
}

const FORMS: &str = "a constraint is `ATTRIBUTE LO..HI`, `ATTRIBUTE >= X`, `ATTRIBUTE <= X`, `ATTRIBUTE = X` or `completed`; `success` may end with `for JUDGE`";

impl Constraint {
    /// Reads one constraint; the attribute may be of any game (see [`Want::fit`]). The error
    /// names the part that is wrong and the forms.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text.len() > MAX_TEXT {
            return Err(format!(
                "a constraint of {} bytes: at most {MAX_TEXT}",
                text.len()
            ));
        }
        if text == "completed" {
            return Ok(Constraint {
                attribute: Attribute::Completed,
                low: 1.0,
                high: 1.0,
            });
        }
        let (text_range, judge) = match text.split_once(" for ") {
            Some((before, judge)) => (before.trim(), Some(Judge::parse(judge.trim())?)),
            None => (text, None),
        };
        let Some((name, range)) = text_range.split_once(char::is_whitespace) else {
            return Err(format!("`{text}` has no range: {FORMS}"));
        };
        let attribute = match (Attribute::named_in_any(name)?, judge) {
            (Attribute::Success(None), judge) => Attribute::Success(judge),
            (_, Some(_)) => return Err(format!("`{text}`: only `success` is asked for a judge")),
            (attribute, None) => attribute,
        };
        if attribute == Attribute::Completed {
            return Err(format!("`{text}`: `completed` takes no range"));
        }
        let (low, high) = range_of(range.trim()).map_err(|e| format!("`{text}`: {e}"))?;
        let (least, most) = attribute.domain();
        if high < least || low > most {
            return Err(format!(
                "`{text}`: {attribute} lies within {}..{}",
                show_number(least),
                show_number(most)
            ));
        }
        Ok(Constraint {
            attribute,
            low,
            high,
        })
    }

    /// Whether it reads the panel's runs or rating (`b`, `success for JUDGE`).
    pub fn needs_panel(&self) -> bool {
        matches!(self.attribute, Attribute::B | Attribute::Success(Some(_)))
    }

    /// How `level` misses it, or `None` when it meets it, with `evidence` for the runs.
    pub fn miss(&self, level: &Level, evidence: &Evidence, strictness: Strictness) -> Option<Miss> {
        let value = match self.attribute.value(level, evidence) {
            Ok(value) => value,
            Err(why) => {
                return Some(Miss {
                    value: None,
                    distance: 1.0,
                    why: format!("{self}: {why}"),
                });
            }
        };
        let (low, high) = (self.low - 1e-9, self.high + 1e-9);
        let interval = match strictness {
            Strictness::Interval => self.attribute.interval(evidence),
            Strictness::Value => None,
        };
        let [from, to] = interval.unwrap_or([value, value]);
        if to >= low && from <= high {
            return None;
        }
        let off = if value < low {
            low - value
        } else {
            value - high
        };
        let shown = show_value(self.attribute, value);
        let why = match interval {
            Some([a, b]) => format!(
                "{self}: {} {shown} (95% interval {} to {}) lies outside the range",
                self.attribute.name(),
                show_value(self.attribute, a),
                show_value(self.attribute, b)
            ),
            None => format!("{self}: measured {shown}"),
        };
        Some(Miss {
            value: Some(value),
            distance: off.max(0.0) / self.attribute.scale(),
            why,
        })
    }
}

/// `LO..HI`, `>= X`, `<= X`, `> X`, `< X`, `= X` or `X`.
fn range_of(text: &str) -> Result<(f64, f64), String> {
    let number = |t: &str| -> Result<f64, String> {
        let t = t.trim();
        match t.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("`{t}` is not a number")),
        }
    };
    if let Some((low, high)) = text.split_once("..") {
        let (low, high) = (number(low)?, number(high)?);
        if low > high {
            return Err(format!(
                "the range {}..{} is empty: LO must not be above HI",
                show_number(low),
                show_number(high)
            ));
        }
        return Ok((low, high));
    }
    for (op, bounds) in [
        (">=", (1, 0)),
        ("<=", (0, 1)),
        (">", (1, 0)),
        ("<", (0, 1)),
        ("=", (1, 1)),
    ] {
        if let Some(rest) = text.strip_prefix(op) {
            let x = number(rest)?;
            let pick = |b, unbounded| if b == 1 { x } else { unbounded };
            return Ok((
                pick(bounds.0, f64::NEG_INFINITY),
                pick(bounds.1, f64::INFINITY),
            ));
        }
    }
    number(text)
        .map(|x| (x, x))
        .map_err(|_| format!("`{text}` is not a range: {FORMS}"))
}

fn show_value(attribute: Attribute, value: f64) -> String {
    let digits = match attribute {
        Attribute::Pieces => 0,
        Attribute::Success(_) | Attribute::Hardest | Attribute::Knob(_) | Attribute::B => 2,
        _ => 1,
    };
    format!("{value:.digits$}{}", attribute.unit())
}

impl fmt::Display for Constraint {
    /// The form [`Constraint::parse`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let judge = match self.attribute {
            Attribute::Success(Some(judge)) => format!(" for {}", judge.name()),
            _ => String::new(),
        };
        let name = self.attribute.name();
        let (low, high) = (show_number(self.low), show_number(self.high));
        match (self.low.is_finite(), self.high.is_finite()) {
            _ if self.attribute == Attribute::Completed => f.write_str("completed"),
            (true, true) if self.low == self.high => write!(f, "{name} = {low}{judge}"),
            (true, true) => write!(f, "{name} {low}..{high}{judge}"),
            (true, false) => write!(f, "{name} >= {low}{judge}"),
            (false, true) => write!(f, "{name} <= {high}{judge}"),
            (false, false) => write!(f, "{name} <= inf{judge}"),
        }
    }
}

arlpcg_core::as_text!(Constraint);

/// A wish list: constraints that a level must all meet.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Want {
    /// The constraints, in the order asked.
    pub constraints: Vec<Constraint>,
}

impl Want {
    /// Reads a wish list: constraints separated by commas (or `and`). Refuses an empty one,
    /// one over [`MAX_CONSTRAINTS`], and two constraints on one attribute whose ranges do not
    /// meet.
    pub fn parse(text: &str) -> Result<Self, String> {
        if text.len() > MAX_TEXT {
            return Err(format!(
                "a wish list of {} bytes: at most {MAX_TEXT}",
                text.len()
            ));
        }
        let parts: Vec<&str> = text
            .split([',', ';'])
            .flat_map(|part| part.split(" and "))
            .map(str::trim)
            .filter(|part| !part.is_empty())
            .collect();
        if parts.is_empty() {
            return Err(format!("the wish list is empty: {FORMS}"));
        }
        if parts.len() > MAX_CONSTRAINTS {
            return Err(format!(
                "{} constraints: a wish list holds at most {MAX_CONSTRAINTS}",
                parts.len()
            ));
        }
        let want = Want {
            constraints: parts
                .into_iter()
                .map(Constraint::parse)
                .collect::<Result<_, _>>()?,
        };
        want.consistent()?;
        Ok(want)
    }

    /// Refuses two constraints on one attribute whose ranges do not meet.
    fn consistent(&self) -> Result<(), String> {
        for (i, a) in self.constraints.iter().enumerate() {
            for b in &self.constraints[i + 1..] {
                if a.attribute == b.attribute && (a.low > b.high || b.low > a.high) {
                    return Err(format!("`{a}` and `{b}` cannot both hold"));
                }
            }
        }
        Ok(())
    }

    /// Refuses an attribute that `game`'s levels do not have, naming theirs.
    pub fn fit(&self, game: Game) -> Result<(), String> {
        for constraint in &self.constraints {
            if let Attribute::Success(_) = constraint.attribute {
                continue;
            }
            Attribute::named(constraint.attribute.name(), game.shape())
                .map_err(|e| format!("`{constraint}`: {e} ({game} levels)"))?;
        }
        Ok(())
    }

    /// Refuses what [`Want::fit`] refuses, and a constraint no search can meet: `b`, the
    /// panel's rating, fitted over a batch of levels together (`--panel`), is a check of made
    /// levels (`--check`, campaigns), not something one candidate can be measured on.
    pub fn fit_search(&self, game: Game) -> Result<(), String> {
        self.fit(game)?;
        match self
            .constraints
            .iter()
            .find(|c| c.attribute == Attribute::B)
        {
            Some(b) => Err(format!(
                "`{b}`: b is the panel's rating of levels fitted together, which one candidate of a search cannot be measured on; check it on made levels instead (`--check \"{b}\"` with --panel)"
            )),
            None => Ok(()),
        }
    }

    /// The most any constraint reads: the pieces alone, runs, or the panel.
    pub fn reads(&self) -> Reads {
        self.constraints
            .iter()
            .map(|c| c.attribute.reads())
            .max()
            .unwrap_or(Reads::Pieces)
    }

    /// The judges whose success it asks for.
    pub fn judges(&self) -> Vec<Judge> {
        let mut judges = Vec::new();
        for c in &self.constraints {
            if let Attribute::Success(Some(judge)) = c.attribute
                && !judges.contains(&judge)
            {
                judges.push(judge);
            }
        }
        judges
    }

    /// Every constraint `level` misses, in order.
    pub fn misses(&self, level: &Level, evidence: &Evidence, strictness: Strictness) -> Vec<Miss> {
        self.constraints
            .iter()
            .filter_map(|c| c.miss(level, evidence, strictness))
            .collect()
    }

    /// Each constraint with its value on `level` (a constraint the level cannot measure is
    /// left out).
    pub fn measured(&self, level: &Level, evidence: &Evidence) -> Vec<MeasuredConstraint> {
        self.constraints
            .iter()
            .filter_map(|c| {
                let value = c.attribute.value(level, evidence).ok()?;
                Some(MeasuredConstraint {
                    constraint: c.to_string(),
                    value: (value * 10_000.0).round() / 10_000.0,
                })
            })
            .collect()
    }
}

impl fmt::Display for Want {
    /// The form [`Want::parse`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = self.constraints.iter().map(|c| c.to_string()).collect();
        f.write_str(&parts.join(", "))
    }
}

arlpcg_core::as_text!(Want);

/// Reads a wish-list file (`--want-file`): YAML, `want:` a wish list or a list of
/// constraints. The error names the file and the field.
pub fn load(path: &std::path::Path) -> Result<Want, String> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct WantFile {
        want: OneOrMany,
    }
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(String),
        Many(Vec<String>),
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let file: WantFile = serde_yaml::from_str(&text).map_err(|e| {
        format!(
            "{}: {e} (a wish-list file holds `want:` a wish list or a list of constraints)",
            path.display()
        )
    })?;
    let text = match file.want {
        OneOrMany::One(text) => text,
        OneOrMany::Many(list) => list.join(", "),
    };
    Want::parse(&text).map_err(|e| format!("{}: want: {e}", path.display()))
}

/// Refuses a check on an attribute `game`'s levels do not have.
pub fn fit_checks(checks: &[Constraint], game: Game) -> Result<(), String> {
    Want {
        constraints: checks.to_vec(),
    }
    .fit(game)
}

/// Every constraint of `checks` that named levels miss, as a check fails them
/// ([`Strictness::Interval`]): (level name, why), in order.
pub fn failures<'a>(
    checks: &[Constraint],
    levels: impl IntoIterator<Item = (String, &'a Level, Evidence<'a>)>,
) -> Vec<(String, String)> {
    let mut failed = Vec::new();
    for (name, level, evidence) in levels {
        for check in checks {
            if let Some(miss) = check.miss(level, &evidence, Strictness::Interval) {
                failed.push((name.clone(), miss.why));
            }
        }
    }
    failed
}

#[cfg(test)]
mod tests;
