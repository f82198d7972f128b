//! The ranges of every number a level holds, in one place, shared by generators, the YAML
//! loader (which rejects values outside them) and the docs.

use std::fmt;

/// A closed interval a parameter must lie in, with the name and unit used in error messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamRange {
    /// The parameter's name.
    pub name: &'static str,
    /// The least value allowed.
    pub min: f64,
    /// The largest value allowed.
    pub max: f64,
    /// The unit (`m`, `degrees`), or empty.
    pub unit: &'static str,
}

impl ParamRange {
    /// The range `[min, max]` of `name`, in `unit`.
    pub const fn new(name: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            name,
            min,
            max,
            unit,
        }
    }

    /// Checks that `value` is a number inside the range; returns it, -0 as 0.
    pub fn check(&self, value: f64) -> Result<f64, RangeError> {
        if value.is_nan() {
            return Err(RangeError::NotANumber { range: *self });
        }
        if value < self.min || value > self.max {
            return Err(RangeError::OutOfRange {
                range: *self,
                value,
            });
        }
        Ok(value + 0.0)
    }

    /// Maps `t` in [-1, 1] linearly onto the range (how squashed policy outputs become values).
    pub fn from_unit(&self, t: f64) -> f64 {
        let t = t.clamp(-1.0, 1.0);
        self.min + (t + 1.0) * 0.5 * (self.max - self.min)
    }

    /// The nearest value inside the range.
    pub fn clamp(&self, value: f64) -> f64 {
        value.clamp(self.min, self.max)
    }

    /// Maps a value of the range onto [-1, 1] (the inverse of [`ParamRange::from_unit`]).
    pub fn to_unit(&self, value: f64) -> f64 {
        (value - self.min) / (self.max - self.min) * 2.0 - 1.0
    }
}

impl fmt::Display for ParamRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", self.min, self.max)?;
        if !self.unit.is_empty() {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
}

/// A number as a message shows it: `12`, `0.5`, `NaN`, and `1e308` rather than its 309 digits.
pub fn show_number(value: f64) -> String {
    let magnitude = value.abs();
    if value.is_finite() && (magnitude >= 1e9 || (magnitude != 0.0 && magnitude < 1e-6)) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// A parameter outside its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeError {
    /// The value is NaN.
    #[error("{} must be a number, not NaN", range.name)]
    NotANumber {
        /// The range the value had to lie in.
        range: ParamRange,
    },
    /// The value is outside the range.
    #[error("{} {} is out of range {range}", range.name, show_number(*value))]
    OutOfRange {
        /// The range the value had to lie in.
        range: ParamRange,
        /// The value.
        value: f64,
    },
}

/// Platform game: horizontal centre-to-centre distance from the previous block.
pub const BLOCK_DISTANCE: ParamRange = ParamRange::new("distance", 5.0, 10.0, "m");
/// Platform game: heading change relative to the direction of the last two blocks.
pub const BLOCK_ANGLE: ParamRange = ParamRange::new("angle", -180.0, 180.0, "degrees");
/// Platform game: side of the square block top.
pub const BLOCK_SIZE: ParamRange = ParamRange::new("size", 4.0, 6.0, "m");
/// Platform game: height change from the previous block.
pub const BLOCK_HEIGHT: ParamRange = ParamRange::new("height", -2.0, 2.0, "m");

/// Racing game: segment length along the centre line.
pub const SEGMENT_LENGTH: ParamRange = ParamRange::new("length", 20.0, 30.0, "m");
/// Racing game: heading change over the segment.
pub const SEGMENT_CURVE: ParamRange = ParamRange::new("curve", -30.0, 30.0, "degrees");
/// Racing game: height change over the segment.
pub const SEGMENT_HEIGHT: ParamRange = ParamRange::new("height", -5.0, 5.0, "m");

/// The Generator's aux input λ: +1 easy, -1 hard.
pub const AUX: ParamRange = ParamRange::new("aux", -1.0, 1.0, "");
/// A heading in the horizontal plane.
pub const HEADING: ParamRange = ParamRange::new("heading", -180.0, 180.0, "degrees");
/// Any world coordinate: levels live within 10 km of the origin.
pub const COORDINATE: ParamRange = ParamRange::new("coordinate", -10_000.0, 10_000.0, "m");

/// Rounds a generated value to the precision levels are stored with (1 mm, 0.001 degree), so
/// files stay readable and a value reads back exactly as it was written.
pub fn quantize(value: f64) -> f64 {
    (value * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_rejects_nan_and_out_of_range_and_names_the_parameter() {
        assert!(BLOCK_SIZE.check(5.0).is_ok());
        let err = BLOCK_SIZE.check(12.0).unwrap_err();
        assert_eq!(err.to_string(), "size 12 is out of range [4, 6] m");
        let err = BLOCK_SIZE.check(f64::NAN).unwrap_err();
        assert_eq!(err.to_string(), "size must be a number, not NaN");
        assert!(AUX.check(f64::INFINITY).is_err());
        let err = BLOCK_SIZE.check(-1e300).unwrap_err();
        assert_eq!(err.to_string(), "size -1e300 is out of range [4, 6] m");
    }

    #[test]
    fn unit_mapping_round_trips_and_clamps() {
        for t in [-1.0, -0.3, 0.0, 0.7, 1.0] {
            let v = BLOCK_DISTANCE.from_unit(t);
            assert!((BLOCK_DISTANCE.to_unit(v) - t).abs() < 1e-12, "t={t} v={v}");
        }
        assert_eq!(BLOCK_DISTANCE.from_unit(5.0), 10.0);
        assert_eq!(BLOCK_DISTANCE.from_unit(-5.0), 5.0);
    }

    #[test]
    fn quantize_keeps_three_decimals() {
        assert_eq!(quantize(7.234_567), 7.235);
        assert_eq!(quantize(-1.0004), -1.0);
    }
}
