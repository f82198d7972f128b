//! Pacing: λ along a level. An [`AuxCurve`] gives λ as a piecewise-linear function of how far
//! the level has come, as a fraction of the start-to-goal distance (0 at the start, 1 at the
//! goal); the Generator builds each piece at the curve's value where that piece begins.
//!
//! Written as control points `fraction:λ`, separated by commas: `0:1, 0.5:1, 0.6:-1, 1:-1` is
//! easy up to halfway, then hard. Two points at one fraction make a step: `0:1, 0.5:1, 0.5:-1,
//! 1:-1` is easy up to halfway (the first point's λ holds at the step itself), hard after it.
//! Before the first point and after the last, λ stays at that point's value.

use std::fmt;

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

/// The words a curve's messages use: what the curve is, its x and y, and examples of a whole
/// curve, of one point and of a step.
pub struct CurveWords {
    /// What the curve is, with its article ("an aux curve").
    pub curve: &'static str,
    /// The name of a point's x ("fraction").
    pub x: &'static str,
    /// What x is, for the range message: "the fraction of the way to the goal".
    pub x_meaning: &'static str,
    /// The name of a point's y ("λ").
    pub y: &'static str,
    /// Examples: a whole curve, one point, a step.
    pub examples: [&'static str; 3],
}

const AUX_CURVE_WORDS: CurveWords = CurveWords {
    curve: "an aux curve",
    x: "fraction",
    x_meaning: "the fraction of the way to the goal",
    y: "λ",
    examples: ["0:1, 1:-1", "0.5:-1", "0.5:1, 0.5:-1"],
};

/// Parses control points `x:y, x:y, ...` and checks them ([`check_points`], each y by
/// `check_y`); the error says which point is wrong and why.
pub fn parse_points(
    text: &str,
    words: &CurveWords,
    check_y: impl Fn(f64) -> Result<(), String>,
) -> Result<Vec<(f64, f64)>, String> {
    let text = text.trim();
    if text.is_empty() {
        return Err(format!(
            "{} needs at least one point `{}:{}`, e.g. `{}`",
            words.curve, words.x, words.y, words.examples[0]
        ));
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
        let Some((x, y)) = item.split_once(':') else {
            return Err(format!(
                "point {} (`{item}`) is not `{}:{}` (e.g. `{}`)",
                i + 1,
                words.x,
                words.y,
                words.examples[1]
            ));
        };
        // -0 is 0: the same curve, written and hashed the same.
        points.push((number(x, words.x)? + 0.0, number(y, words.y)? + 0.0));
    }
    check_points(&points, words, check_y)?;
    Ok(points)
}

/// Checks control points: 1 to [`MAX_POINTS`], x increasing within [0, 1] (at most two points
/// at one x: a step), each y by `check_y` (NaN fails).
pub fn check_points(
    points: &[(f64, f64)],
    words: &CurveWords,
    check_y: impl Fn(f64) -> Result<(), String>,
) -> Result<(), String> {
    if points.is_empty() || points.len() > MAX_POINTS {
        return Err(format!(
            "{} has 1 to {MAX_POINTS} points, not {}",
            words.curve,
            points.len()
        ));
    }
    for (i, &(x, y)) in points.iter().enumerate() {
        let at = format!("point {} ({}:{})", i + 1, show_number(x), show_number(y));
        if !(0.0..=1.0).contains(&x) {
            return Err(format!("{at}: {} must be within [0, 1]", words.x_meaning));
        }
        check_y(y).map_err(|e| format!("{at}: {e}"))?;
        if i > 0 && x < points[i - 1].0 {
            return Err(format!(
                "{at}: {}s must increase from point to point (the previous is {})",
                words.x,
                show_number(points[i - 1].0)
            ));
        }
        if i > 1 && x == points[i - 2].0 {
            return Err(format!(
                "{at}: three points at one {}; a step takes two (`{}`)",
                words.x, words.examples[2]
            ));
        }
    }
    Ok(())
}

/// The piecewise-linear value of control points at `x` (clamped to [0, 1]; NaN reads 0): the
/// first point's y before it, the last's after it, and at a step the first of its two.
pub fn value_at(points: &[(f64, f64)], x: f64) -> f64 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let first = points[0];
    if x <= first.0 {
        return first.1;
    }
    for pair in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
        if x <= x1 && x1 > x0 {
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
        }
    }
    points[points.len() - 1].1
}

/// Control points in the form [`parse_points`] reads: `0:1, 0.5:1, 0.6:-1, 1:-1`.
pub fn show_points(points: &[(f64, f64)]) -> String {
    points
        .iter()
        .map(|(x, y)| format!("{}:{}", show_number(*x), show_number(*y)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn check_aux(aux: f64) -> Result<(), String> {
    AUX.check(aux).map(|_| ()).map_err(|e| e.to_string())
}

impl AuxCurve {
    /// Parses `fraction:λ, fraction:λ, ...`; the error says which point is wrong and why.
    pub fn parse(text: &str) -> Result<Self, String> {
        parse_points(text, &AUX_CURVE_WORDS, check_aux).map(|points| Self { points })
    }

    /// A curve through `points`, checked: 1 to [`MAX_POINTS`] points, fractions increasing
    /// within [0, 1] (at most two points at one fraction: a step), every λ within [-1, 1] (NaN
    /// fails).
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, String> {
        check_points(&points, &AUX_CURVE_WORDS, check_aux)?;
        Ok(Self { points })
    }

    /// λ at `fraction` of the way to the goal (clamped to [0, 1]).
    pub fn at(&self, fraction: f64) -> f64 {
        value_at(&self.points, fraction)
    }

    /// The control points, `(fraction, λ)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The mean λ over the way to the goal (the curve is flat before its first point and after
    /// its last).
    pub fn mean(&self) -> f64 {
        let (first, last) = (self.points[0], self.points[self.points.len() - 1]);
        let inside: f64 = self
            .points
            .windows(2)
            .map(|p| (p[1].0 - p[0].0) * (p[0].1 + p[1].1) / 2.0)
            .sum();
        first.0 * first.1 + inside + (1.0 - last.0) * last.1
    }

    /// The same shape moved up by `delta`, each point's λ clamped to [-1, 1] and rounded as
    /// level files write it.
    pub fn shifted(&self, delta: f64) -> Self {
        Self {
            points: self
                .points
                .iter()
                .map(|&(x, y)| (x, round_aux((y + delta).clamp(-1.0, 1.0))))
                .collect(),
        }
    }
}

impl fmt::Display for AuxCurve {
    /// The form [`AuxCurve::parse`] reads: `0:1, 0.5:1, 0.6:-1, 1:-1`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&show_points(&self.points))
    }
}

crate::as_text!(AuxCurve);

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
    #[test]
    fn a_curve_has_a_mean_and_moves_as_a_whole() {
        let ramp = super::AuxCurve::parse("0.25:1, 0.75:-1").unwrap();
        assert!(ramp.mean().abs() < 1e-12, "{}", ramp.mean());
        let step = super::AuxCurve::parse("0.5:1, 0.5:-0.5").unwrap();
        assert!((step.mean() - 0.25).abs() < 1e-12);
        assert!((super::AuxCurve::parse("0.3:0.4").unwrap().mean() - 0.4).abs() < 1e-12);
        assert_eq!(ramp.shifted(0.5).to_string(), "0.25:1, 0.75:-0.5");
        assert_eq!(step.shifted(-0.25).to_string(), "0.5:0.75, 0.5:-0.75");
    }

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
