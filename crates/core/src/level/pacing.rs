//! Pacing: λ along a level. An [`AuxCurve`] gives λ as a piecewise-linear function of how far
//! the level has come, as a fraction of the start-to-goal distance (0 at the start, 1 at the
//! goal); the Generator builds each piece at the curve's value where that piece begins.
//!
//! Written as control points `fraction:λ`, separated by commas: `0:1, 0.5:1, 0.6:-1, 1:-1` is
//! easy up to halfway, then hard. Two points at one fraction make a step: `0:1, 0.5:1, 0.5:-1,
//! 1:-1` is easy up to halfway (the first point's λ holds at the step itself), hard after it.
//! Before the first point and after the last, λ stays at that point's value.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::params::{AUX, show_number};

/// Control points of a curve, at most (a designer's curve has a handful).
pub const MAX_POINTS: usize = 32;

/// λ as a function of the fraction of the way to the goal.
#[derive(Debug, Clone, PartialEq)]
pub struct AuxCurve {
    /// `(fraction, λ)`, fractions increasing within [0, 1] (two equal ones at most: a step),
    /// λ within [-1, 1].
    points: Vec<(f64, f64)>,
}

impl AuxCurve {
    /// Parses `fraction:λ, fraction:λ, ...`; the error says which point is wrong and why.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text.is_empty() {
            return Err(
                "an aux curve needs at least one point `fraction:λ`, e.g. `0:1, 1:-1`".into(),
            );
        }
        let mut points = Vec::new();
        for (i, item) in text.split(',').enumerate() {
            let item = item.trim();
            let number = |s: &str, what: &str| {
                s.trim().parse::<f64>().map_err(|_| {
                    format!(
                        "point {} (`{item}`): its {what} `{}` is not a number",
                        i + 1,
                        s.trim()
                    )
                })
            };
            let Some((fraction, aux)) = item.split_once(':') else {
                return Err(format!(
                    "point {} (`{item}`) is not `fraction:λ` (e.g. `0.5:-1`)",
                    i + 1
                ));
            };
            let (fraction, aux) = (number(fraction, "fraction")?, number(aux, "λ")?);
            points.push((fraction, aux));
        }
        Self::new(points)
    }

    /// A curve through `points`, checked: 1 to [`MAX_POINTS`] points, fractions increasing
    /// within [0, 1] (at most two points at one fraction: a step), every λ within [-1, 1] (NaN
    /// fails).
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, String> {
        if points.is_empty() || points.len() > MAX_POINTS {
            return Err(format!(
                "an aux curve has 1 to {MAX_POINTS} points, not {}",
                points.len()
            ));
        }
        for (i, &(fraction, aux)) in points.iter().enumerate() {
            let at = format!(
                "point {} ({}:{})",
                i + 1,
                show_number(fraction),
                show_number(aux)
            );
            if !(0.0..=1.0).contains(&fraction) {
                return Err(format!(
                    "{at}: the fraction of the way to the goal must be within [0, 1]"
                ));
            }
            AUX.check(aux).map_err(|e| format!("{at}: {e}"))?;
            if i > 0 && fraction < points[i - 1].0 {
                return Err(format!(
                    "{at}: fractions must increase from point to point (the previous is {})",
                    show_number(points[i - 1].0)
                ));
            }
            if i > 1 && fraction == points[i - 2].0 {
                return Err(format!(
                    "{at}: three points at one fraction; a step takes two (`0.5:1, 0.5:-1`)"
                ));
            }
        }
        Ok(Self { points })
    }

    /// λ at `fraction` of the way to the goal (clamped to [0, 1]).
    pub fn at(&self, fraction: f64) -> f64 {
        let fraction = if fraction.is_nan() {
            0.0
        } else {
            fraction.clamp(0.0, 1.0)
        };
        let first = self.points[0];
        if fraction <= first.0 {
            return first.1;
        }
        for pair in self.points.windows(2) {
            let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
            if fraction <= x1 && x1 > x0 {
                return y0 + (y1 - y0) * (fraction - x0) / (x1 - x0);
            }
        }
        self.points[self.points.len() - 1].1
    }

    /// The control points, `(fraction, λ)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }
}

impl fmt::Display for AuxCurve {
    /// The form [`AuxCurve::parse`] reads: `0:1, 0.5:1, 0.6:-1, 1:-1`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (fraction, aux)) in self.points.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{}:{}", show_number(*fraction), show_number(*aux))?;
        }
        Ok(())
    }
}

impl std::str::FromStr for AuxCurve {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::parse(s)
    }
}

impl Serialize for AuxCurve {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for AuxCurve {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        Self::parse(&text).map_err(serde::de::Error::custom)
    }
}

/// λ along a built level: the curve it was built with and the λ each piece was built at.
#[derive(Debug, Clone, PartialEq)]
pub struct Pacing {
    /// The curve the Generator followed (after a kept prefix: the curve of the rest).
    pub curve: AuxCurve,
    /// `piece_aux[i]`: the λ piece `i` was placed at (the curve's value where it begins); none
    /// only for a kept piece whose level recorded none.
    pub piece_aux: Vec<Option<f64>>,
}

impl Pacing {
    /// Checks that a level of `pieces` pieces, the first `kept` kept from another level, has
    /// a λ within [-1, 1] for each piece (kept pieces may have none).
    pub fn check(&self, pieces: usize, kept: usize) -> Result<(), String> {
        if self.piece_aux.len() != pieces {
            return Err(format!(
                "{} λ values for {pieces} pieces: with `aux_curve` every piece has one",
                self.piece_aux.len()
            ));
        }
        for (i, aux) in self.piece_aux.iter().enumerate() {
            match aux {
                Some(aux) => AUX
                    .check(*aux)
                    .map(drop)
                    .map_err(|e| format!("piece {i}: {e}"))?,
                None if i < kept => {}
                None => {
                    return Err(format!(
                        "piece {i}: missing: with `aux_curve` every piece the Generator placed has its λ"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The fraction of the way covered with `left` of `whole` metres to go, within [0, 1].
pub fn covered(whole: f64, left: f64) -> f64 {
    if whole > 0.0 {
        (1.0 - left / whole).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// λ rounded as level files write it (3 decimals), so that a level read back equals the level
/// built.
pub fn round_aux(aux: f64) -> f64 {
    (aux * 1000.0).round() / 1000.0 + 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_curve_is_piecewise_linear_and_flat_outside_its_points() {
        let curve = AuxCurve::parse("0.2:1, 0.5:1, 0.6:-1, 0.9:-1").unwrap();
        assert_eq!(curve.at(0.0), 1.0);
        assert_eq!(curve.at(0.4), 1.0);
        assert!((curve.at(0.55) - 0.0).abs() < 1e-12);
        assert_eq!(curve.at(0.75), -1.0);
        assert_eq!(curve.at(1.0), -1.0);
        assert_eq!(curve.at(7.0), -1.0);
        assert_eq!(curve.at(f64::NAN), 1.0);
        let flat = AuxCurve::parse("0.3:-0.5").unwrap();
        assert_eq!((flat.at(0.0), flat.at(1.0)), (-0.5, -0.5));
    }

    #[test]
    fn two_points_at_one_fraction_make_a_step() {
        let step = AuxCurve::parse("0:1, 0.5:1, 0.5:-1, 1:-1").unwrap();
        assert_eq!(step.at(0.25), 1.0);
        assert_eq!(step.at(0.5), 1.0, "the first point's λ holds at the step");
        assert_eq!(step.at(0.5 + 1e-9), -1.0);
        assert_eq!(step.at(0.75), -1.0);
        let at_start = AuxCurve::parse("0:1, 0:-1").unwrap();
        assert_eq!((at_start.at(0.0), at_start.at(0.1)), (1.0, -1.0));
        assert_eq!(AuxCurve::parse(&step.to_string()).unwrap(), step);
    }

    #[test]
    fn a_curve_reads_back_what_it_writes() {
        let curve = AuxCurve::parse(" 0:1,0.5:1 , 0.6:-1, 1:-1").unwrap();
        assert_eq!(curve.to_string(), "0:1, 0.5:1, 0.6:-1, 1:-1");
        assert_eq!(AuxCurve::parse(&curve.to_string()).unwrap(), curve);
    }

    #[test]
    fn bad_curves_say_what_is_wrong() {
        let cases = [
            ("", "at least one point"),
            ("0.5", "not `fraction:λ`"),
            ("0:1, x:1", "fraction `x` is not a number"),
            ("0:1, 1:", "λ `` is not a number"),
            ("0:NaN", "NaN"),
            ("0:1, 1:2", "out of range"),
            ("-0.1:1", "within [0, 1]"),
            ("0:1, 1.5:1", "within [0, 1]"),
            ("0:1, 0.5:0, 0.5:-1, 0.5:1", "three points at one fraction"),
            ("0.6:1, 0.4:-1", "must increase"),
        ];
        for (text, expected) in cases {
            let err = AuxCurve::parse(text).unwrap_err();
            assert!(err.contains(expected), "`{text}`: {err}");
        }
        let many = vec!["0:0"; MAX_POINTS + 1].join(",");
        assert!(
            AuxCurve::parse(&many)
                .unwrap_err()
                .contains("1 to 32 points")
        );
    }

    #[test]
    fn pacing_needs_one_aux_value_per_piece_in_range() {
        let pacing = Pacing {
            curve: AuxCurve::parse("0:1").unwrap(),
            piece_aux: vec![Some(1.0), Some(0.5)],
        };
        pacing.check(2, 0).unwrap();
        assert!(
            pacing
                .check(3, 0)
                .unwrap_err()
                .contains("2 λ values for 3 pieces")
        );
        let bad = Pacing {
            piece_aux: vec![Some(1.0), Some(f64::NAN)],
            ..pacing.clone()
        };
        assert!(bad.check(2, 0).unwrap_err().starts_with("piece 1:"));
        let kept = Pacing {
            piece_aux: vec![None, Some(0.5)],
            ..pacing
        };
        kept.check(2, 1).unwrap();
        assert!(
            kept.check(2, 0)
                .unwrap_err()
                .starts_with("piece 0: missing")
        );
    }
}
