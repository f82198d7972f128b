//! Racing levels as data: where the road starts, its segments (each relative to the end of the
//! previous one) and the obstacles the road must avoid, with the checks that need no geometry
//! (ranges, the goal reached). The road's shape, and the rules it must keep (no crossing, no
//! obstacle hit), are resolved and checked by [`super::road`].

use serde::{Deserialize, Serialize};

use super::params::{self, ParamRange, RangeError};

/// The most segments a track may have (a 10 km road).
pub const MAX_SEGMENTS: usize = 400;
/// The style knobs a road level may record, as the Generators name them
/// (`crates/core/src/game/racing/generator.rs`, `KNOBS`).
pub const ROAD_KNOBS: [&str; 2] = ["curviness", "elevation"];
/// The most obstacles a track may have.
pub const MAX_OBSTACLES: usize = 200;
/// The road's end must come this close to the goal, horizontally, m...
pub const GOAL_REACH_HORIZONTAL: f64 = 12.0;
/// ...and vertically, m.
pub const GOAL_REACH_VERTICAL: f64 = 6.0;
/// A run succeeds on the last this many metres of a complete road, within its edges.
pub const FINISH_LENGTH: f64 = 3.0;

/// Width of the road surface, m: the built-in game's.
pub const ROAD_WIDTH: f64 = 9.0;
/// Bank angle per unit of curvature: bank (degrees) = `BANK_GAIN` · curve (degrees) / length (m),
/// the built-in game's.
pub const BANK_GAIN: f64 = 10.0;
/// The road widths a track (and a profile) may have, m.
pub const WIDTH_RANGE: ParamRange = ParamRange::new("road width", 6.0, 14.0, "m");
/// The banking gains a track (and a profile) may have (0: a flat road).
pub const BANKING_RANGE: ParamRange = ParamRange::new("banking", 0.0, 20.0, "° per °/m");
/// How wide a road is and how steeply it banks in its curves: a property of each track (a
/// profile's `segments.road_width` and `segments.banking` set it for the levels made under it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoadShape {
    /// Width of the road surface, m.
    pub width: f64,
    /// Bank angle per unit of curvature: bank (degrees) = banking · curve (degrees) / length
    /// (m), clipped to ±15° (the road's steepest banking).
    pub banking: f64,
}

impl Default for RoadShape {
    fn default() -> Self {
        Self {
            width: ROAD_WIDTH,
            banking: BANK_GAIN,
        }
    }
}

impl RoadShape {
    /// Checks both against their ranges (NaN fails): `Err("field: what it must be")`.
    pub fn check(&self) -> Result<(), String> {
        WIDTH_RANGE
            .check(self.width)
            .map_err(|e| format!("width: {e}"))?;
        BANKING_RANGE
            .check(self.banking)
            .map_err(|e| format!("banking: {e}"))?;
        Ok(())
    }

    /// Whether this is the built-in road (its width and banking).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Two parts of the road further apart along it than this must not come near each other, m.
    pub fn crossing_arc(&self) -> f64 {
        4.0 * self.width
    }

    /// The least horizontal distance between two such parts' centre lines, m.
    pub fn min_self_distance(&self) -> f64 {
        self.width + 3.0
    }

    /// The least horizontal distance from the centre line to an obstacle, m.
    pub fn min_obstacle_distance(&self) -> f64 {
        0.5 * self.width + 1.5
    }
}

/// The Generator's action for one road segment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SegmentParams {
    /// Segment length along the centre line, m.
    pub length: f64,
    /// Heading change over the segment, degrees (positive turns left).
    pub curve: f64,
    /// Height change over the segment, m.
    pub height: f64,
}

impl SegmentParams {
    /// Builds segment parameters, checking each against its range.
    pub fn new(length: f64, curve: f64, height: f64) -> Result<Self, RangeError> {
        Ok(Self {
            length: params::SEGMENT_LENGTH.check(length)?,
            curve: params::SEGMENT_CURVE.check(curve)?,
            height: params::SEGMENT_HEIGHT.check(height)?,
        })
    }
}

/// Something in the scene the road must go around (in plan: the road passes neither over nor
/// under it). `position` is the centre of its base.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Obstacle {
    /// A box of `size` (x, y, z before turning), turned `heading` degrees about +Y.
    Box {
        /// The centre of its base, m.
        position: [f64; 3],
        /// Its full size along x, y, z before turning, m.
        size: [f64; 3],
        /// Its turn about +Y, degrees.
        heading: f64,
    },
    /// An upright cylinder.
    Cylinder {
        /// The centre of its base, m.
        position: [f64; 3],
        /// Its radius, m.
        radius: f64,
        /// Its height, m.
        height: f64,
    },
}

/// The sides of a box and a cylinder's radius and height lie in this range, m.
pub const OBSTACLE_SIZE: params::ParamRange =
    params::ParamRange::new("obstacle size", 0.1, 200.0, "m");

impl Obstacle {
    /// The centre of the obstacle's base, m.
    pub fn position(&self) -> [f64; 3] {
        match *self {
            Obstacle::Box { position, .. } | Obstacle::Cylinder { position, .. } => position,
        }
    }

    /// Horizontal distance from `(x, z)` to the obstacle's footprint (0 inside it).
    pub fn plan_distance(&self, x: f64, z: f64) -> f64 {
        match *self {
            Obstacle::Box {
                position,
                size,
                heading,
            } => {
                let (dx, dz) = (x - position[0], z - position[2]);
                // Into the box's frame: undo the heading's turn about +Y.
                let (s, c) = heading.to_radians().sin_cos();
                let local_x = c * dx - s * dz;
                let local_z = s * dx + c * dz;
                let out_x = (local_x.abs() - 0.5 * size[0]).max(0.0);
                let out_z = (local_z.abs() - 0.5 * size[2]).max(0.0);
                out_x.hypot(out_z)
            }
            Obstacle::Cylinder {
                position, radius, ..
            } => ((x - position[0]).hypot(z - position[2]) - radius).max(0.0),
        }
    }

    /// Checks the sizes and that the numbers are finite: `Err("field: what it must be")`.
    pub fn check(&self) -> Result<(), String> {
        let coordinate = |p: [f64; 3]| {
            p.iter()
                .try_for_each(|&c| params::COORDINATE.check(c).map(|_| ()))
                .map_err(|e| format!("position: {e}"))
        };
        let size = |field: &str, v: f64| {
            OBSTACLE_SIZE
                .check(v)
                .map(|_| ())
                .map_err(|e| format!("{field}: {e}"))
        };
        match *self {
            Obstacle::Box {
                position,
                size: sides,
                heading,
            } => {
                coordinate(position)?;
                sides.iter().try_for_each(|&v| size("size", v))?;
                params::HEADING
                    .check(heading)
                    .map(|_| ())
                    .map_err(|e| format!("heading: {e}"))
            }
            Obstacle::Cylinder {
                position,
                radius,
                height,
            } => {
                coordinate(position)?;
                size("radius", radius)?;
                size("height", height)
            }
        }
    }
}

/// The settings of the rule-based racing generator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RacingRulesConfig {
    /// Give up on a track (and draw another) after this many segments without reaching the goal.
    pub max_segments: u32,
    /// Curves are drawn within this many degrees either way (the range allows 30).
    pub max_curve: f64,
    /// Height changes are drawn within this many metres either way (the range allows 5).
    pub max_height: f64,
    /// Obstacles placed between the start and the goal, which the road must go around.
    pub obstacles: u32,
}

impl Default for RacingRulesConfig {
    fn default() -> Self {
        Self {
            max_segments: 30,
            max_curve: 24.0,
            max_height: 3.0,
            obstacles: 0,
        }
    }
}

impl RacingRulesConfig {
    /// Checks each setting's range (NaN fails): `Err("field: what it must be")`.
    pub fn check(&self) -> Result<(), String> {
        if !(1..=MAX_SEGMENTS as u32).contains(&self.max_segments) {
            return Err(format!(
                "max_segments {} must be within [1, {MAX_SEGMENTS}]",
                self.max_segments
            ));
        }
        if !(0.0..=params::SEGMENT_CURVE.max).contains(&self.max_curve) {
            return Err(format!(
                "max_curve {} must be a number of degrees within [0, {}]",
                params::show_number(self.max_curve),
                params::SEGMENT_CURVE.max
            ));
        }
        if !(0.0..=params::SEGMENT_HEIGHT.max).contains(&self.max_height) {
            return Err(format!(
                "max_height {} must be a number of metres within [0, {}]",
                params::show_number(self.max_height),
                params::SEGMENT_HEIGHT.max
            ));
        }
        if self.obstacles as usize > MAX_OBSTACLES {
            return Err(format!(
                "obstacles {} must be at most {MAX_OBSTACLES}",
                self.obstacles
            ));
        }
        Ok(())
    }
}

/// A racing track: where the road starts, its segments and the obstacles around it.
#[derive(Debug, Clone, PartialEq)]
pub struct RacingTrack {
    /// Start of the road's centre line.
    pub position: [f64; 3],
    /// Initial road direction, degrees.
    pub heading: f64,
    /// The road's segments, from the start.
    pub segments: Vec<SegmentParams>,
    /// What the road must go around.
    pub obstacles: Vec<Obstacle>,
    /// How wide the road is and how it banks.
    pub road: RoadShape,
}

impl RacingTrack {
    /// An empty track of the built-in road, starting at `position`, heading `heading` degrees.
    pub fn new(position: [f64; 3], heading: f64) -> Self {
        Self {
            position,
            heading,
            segments: Vec::new(),
            obstacles: Vec::new(),
            road: RoadShape::default(),
        }
    }
}

/// Whether the road's end `end` reaches `goal`.
pub fn reaches(end: [f64; 3], goal: [f64; 3]) -> bool {
    (end[0] - goal[0]).hypot(end[2] - goal[2]) <= GOAL_REACH_HORIZONTAL
        && (end[1] - goal[1]).abs() <= GOAL_REACH_VERTICAL
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_distance_to_a_turned_box_and_a_cylinder() {
        let boxed = Obstacle::Box {
            position: [10.0, 0.0, 0.0],
            size: [2.0, 3.0, 4.0],
            heading: 90.0,
        };
        // Turned a quarter, the 4 m side lies along x: the footprint spans x in [8, 12].
        assert!((boxed.plan_distance(15.0, 0.0) - 3.0).abs() < 1e-9);
        assert!((boxed.plan_distance(10.0, 4.0) - 3.0).abs() < 1e-9);
        assert_eq!(boxed.plan_distance(10.5, 0.5), 0.0);
        let cylinder = Obstacle::Cylinder {
            position: [0.0, 5.0, 0.0],
            radius: 2.0,
            height: 1.0,
        };
        assert!((cylinder.plan_distance(3.0, 4.0) - 3.0).abs() < 1e-9);
    }

    #[test]
    fn obstacle_check_names_the_field() {
        let bad = Obstacle::Cylinder {
            position: [0.0, f64::NAN, 0.0],
            radius: 1.0,
            height: 1.0,
        };
        assert!(bad.check().unwrap_err().starts_with("position"));
        let bad = Obstacle::Box {
            position: [0.0; 3],
            size: [1.0, 0.0, 1.0],
            heading: 0.0,
        };
        assert!(bad.check().unwrap_err().starts_with("size"));
    }
}
