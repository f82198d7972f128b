//! Acceptance checks on verified levels (`--check` of `verify`, `generate` and `campaign`, and
//! a campaign's `checks:`): a batch in CI fails when a level misses its spec. A check fails a
//! level only when the level's 95% interval lies wholly outside the range asked for, so that a
//! level is not failed by the noise of its own runs.
//!
//! Written `success LO..HI` (the Solver's success ratio), `b LO..HI` (the panel's difficulty
//! rating, logits) or `completed` (some run completed the level).

use std::fmt;

use arlpcg_core::level::Level;
use arlpcg_core::level::params::show_number;
use arlpcg_core::level::stats::{Rating, SolverStats};

/// One acceptance check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Check {
    /// The success ratio's 95% interval meets [lo, hi].
    Success {
        /// The interval's low end.
        low: f64,
        /// The interval's high end.
        high: f64,
    },
    /// The panel rating's 95% interval of b meets [lo, hi].
    B {
        /// The interval's low end.
        low: f64,
        /// The interval's high end.
        high: f64,
    },
    /// Some run completed the level.
    Completed,
}

const SYNTAX: &str = "`success LO..HI`, `b LO..HI` or `completed`";

impl Check {
    /// Parses a check; the error says what is wrong and what the forms are.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text == "completed" {
            return Ok(Check::Completed);
        }
        let Some((kind, range)) = text.split_once(char::is_whitespace) else {
            return Err(format!("`{text}` is not a check; a check is {SYNTAX}"));
        };
        let (low, high) = range
            .trim()
            .split_once("..")
            .and_then(|(l, h)| Some((l.trim().parse::<f64>().ok()?, h.trim().parse::<f64>().ok()?)))
            .ok_or_else(|| {
                format!(
                    "`{text}`: `{}` is not a range LO..HI (e.g. 0.4..0.6)",
                    range.trim()
                )
            })?;
        if !(low.is_finite() && high.is_finite() && low <= high) {
            return Err(format!(
                "`{text}`: a range LO..HI needs two numbers with LO ≤ HI"
            ));
        }
        match kind {
            "success" if low >= 0.0 && high <= 1.0 => Ok(Check::Success { low, high }),
            "success" => Err(format!("`{text}`: a success ratio lies within 0..1")),
            "b" => Ok(Check::B { low, high }),
            _ => Err(format!(
                "`{text}`: `{kind}` is not a check; a check is {SYNTAX}"
            )),
        }
    }

    /// Whether the check reads the panel's rating (which `--panel` adds).
    pub fn needs_panel(&self) -> bool {
        matches!(self, Check::B { .. })
    }

    /// Why a level fails the check, or `None` when it passes, from the level's statistics
    /// (`stats`: one Solver's runs) and its panel rating. A level without what the check
    /// reads fails it, saying so.
    pub fn failure(&self, stats: Option<&SolverStats>, rating: Option<Rating>) -> Option<String> {
        let outside =
            |interval: [f64; 2], low: f64, high: f64| interval[1] < low || interval[0] > high;
        if let Check::B { low, high } = *self {
            return match rating {
                None => Some(format!(
                    "{self}: the level has no panel rating (play it with --panel)"
                )),
                Some(rating) => outside(rating.ci95, low, high).then(|| {
                    format!(
                        "{self}: b {:+.2} (95% interval {:+.2} to {:+.2}) lies outside the range",
                        rating.b, rating.ci95[0], rating.ci95[1]
                    )
                }),
            };
        }
        let Some(stats) = stats else {
            return Some(format!("{self}: the level was not verified"));
        };
        match *self {
            Check::Completed => (stats.successes == 0)
                .then(|| format!("{self}: none of its {} runs completed it", stats.trials)),
            Check::Success { low, high } => outside(stats.ci95, low, high).then(|| {
                format!(
                    "{self}: success {:.2} (95% interval {:.2} to {:.2}) lies outside the range",
                    stats.success_ratio, stats.ci95[0], stats.ci95[1]
                )
            }),
            Check::B { .. } => unreachable!("answered above"),
        }
    }
}

/// What the checks read of a level: its statistics and their panel rating.
pub fn evidence(level: &Level) -> (Option<&SolverStats>, Option<Rating>) {
    let stats = level.stats.as_ref();
    let rating = stats.and_then(|s| s.panel.as_ref()).and_then(|p| p.rating);
    (stats, rating)
}

impl fmt::Display for Check {
    /// The form [`Check::parse`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Check::Completed => f.write_str("completed"),
            Check::Success { low, high } => {
                write!(f, "success {}..{}", show_number(low), show_number(high))
            }
            Check::B { low, high } => write!(f, "b {}..{}", show_number(low), show_number(high)),
        }
    }
}

arlpcg_core::as_text!(Check);

/// Every failure of `checks` over named levels' evidence ([`evidence`]): (level name, why),
/// in order.
pub fn failures<'a>(
    checks: &[Check],
    levels: impl IntoIterator<Item = (String, Option<&'a SolverStats>, Option<Rating>)>,
) -> Vec<(String, String)> {
    let mut failed = Vec::new();
    for (name, stats, rating) in levels {
        for check in checks {
            if let Some(why) = check.failure(stats, rating) {
                failed.push((name.clone(), why));
            }
        }
    }
    failed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_read_back_what_they_write_and_refuse_bad_syntax() {
        for text in ["success 0.4..0.6", "b -1..1", "completed", "b -2.5..-0.5"] {
            assert_eq!(Check::parse(text).unwrap().to_string(), text);
        }
        assert_eq!(
            Check::parse(" success  0.4 .. 0.6 ").unwrap(),
            Check::Success {
                low: 0.4,
                high: 0.6
            }
        );
        for (text, expected) in [
            ("speed 1..2", "`speed` is not a check"),
            ("success 0.6..0.4", "LO ≤ HI"),
            ("success 0.5", "is not a range"),
            ("success 0..1.5", "within 0..1"),
            ("b NaN..1", "LO ≤ HI"),
            ("done", "is not a check"),
        ] {
            let err = Check::parse(text).unwrap_err();
            assert!(err.contains(expected), "{text}: {err}");
        }
    }
}
