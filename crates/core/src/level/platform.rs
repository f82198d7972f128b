//! Platform levels as data: blocks placed turtle-style, each relative to the previous one by the
//! Generator's four parameters, and the world transforms those parameters resolve to.
//!
//! World frame: right-handed, Y up, metres. A heading is an angle in degrees about +Y, 0 along +X,
//! so heading `h` points along `(cos h, 0, -sin h)` (the same rotation glTF applies to a node).

use serde::{Deserialize, Serialize};

use super::heading::{heading_direction, wrap_degrees};
use super::params::{self, RangeError};

/// Vertical thickness of every block; a block's `position` is the centre of its top face.
pub const BLOCK_THICKNESS: f64 = 1.0;
/// The last block reaches the goal when the goal is this close to its top centre, horizontally...
pub const GOAL_REACH_HORIZONTAL: f64 = 3.0;
/// ...and this close vertically.
pub const GOAL_REACH_VERTICAL: f64 = 2.0;
/// Two blocks whose footprints overlap must have tops at least this far apart vertically, so that
/// the built-in character (1.8 m tall) fits between them: [`headroom_for`] its height.
/// Consecutive blocks are exempt.
pub const HEADROOM: f64 = 3.0;
/// The clearance above a character's head that [`headroom_for`] leaves, m.
pub const HEAD_CLEARANCE: f64 = 0.2;
/// The most blocks a level may hold (a guard against absurd files, far above any real level).
pub const MAX_BLOCKS: usize = 400;

/// How far apart, vertically, the tops of two overlapping blocks must be for a character whose
/// capsule is `height` tall to fit between them: the upper block's thickness, the character and
/// [`HEAD_CLEARANCE`] ([`HEADROOM`] for the built-in 1.8 m).
pub fn headroom_for(height: f64) -> f64 {
    BLOCK_THICKNESS + height + HEAD_CLEARANCE
}

/// The headroom of a level made for `abilities` (none, or a car's: the built-in character's).
pub fn headroom_of(abilities: Option<&crate::level::profile::Abilities>) -> f64 {
    match abilities {
        Some(crate::level::profile::Abilities::Character(c)) => headroom_for(c.height),
        _ => HEADROOM,
    }
}

/// The style knobs a blocks level may record, as the Generators name them
/// (`crates/core/src/game/platform/generator.rs`, `KNOBS`).
pub const BLOCK_KNOBS: [&str; 2] = ["stride", "steps"];

/// The Generator's action for one block, relative to the previous block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BlockParams {
    /// Horizontal centre-to-centre distance from the previous block, m.
    pub distance: f64,
    /// Heading change relative to the direction of the last two blocks, degrees.
    pub angle: f64,
    /// Side of the square block top, m.
    pub size: f64,
    /// Height change from the previous block, m.
    pub height: f64,
}

impl BlockParams {
    /// Builds block parameters, checking each against its range.
    pub fn new(distance: f64, angle: f64, size: f64, height: f64) -> Result<Self, RangeError> {
        Ok(Self {
            distance: params::BLOCK_DISTANCE.check(distance)?,
            angle: params::BLOCK_ANGLE.check(angle)?,
            size: params::BLOCK_SIZE.check(size)?,
            height: params::BLOCK_HEIGHT.check(height)?,
        })
    }

    /// Maps four values in [-1, 1] (a policy's squashed action) onto the parameter ranges,
    /// quantized to the precision files store.
    pub fn from_unit(action: [f64; 4]) -> Self {
        Self {
            distance: params::quantize(params::BLOCK_DISTANCE.from_unit(action[0])),
            angle: params::quantize(params::BLOCK_ANGLE.from_unit(action[1])),
            size: params::quantize(params::BLOCK_SIZE.from_unit(action[2])),
            height: params::quantize(params::BLOCK_HEIGHT.from_unit(action[3])),
        }
    }
}

/// Where a level starts: the start block, on which the character spawns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// Centre of the start block's top face.
    pub position: [f64; 3],
    /// Direction the track sets off in, degrees (the "previous direction" of the first block).
    pub heading: f64,
    /// Side of the start block, m.
    pub size: f64,
}

impl Default for Start {
    fn default() -> Self {
        Self {
            position: [0.0; 3],
            heading: 0.0,
            size: 6.0,
        }
    }
}

/// A square block in the world: the start block or a placed one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Platform {
    /// Centre of the top face.
    pub position: [f64; 3],
    /// Heading (yaw about +Y), degrees in (-180, 180].
    pub heading: f64,
    /// Side of the square top, m.
    pub size: f64,
}

impl Platform {
    /// The platform placed relative to this one by `params`.
    pub fn place(&self, params: &BlockParams) -> Platform {
        let heading = wrap_degrees(self.heading + params.angle);
        let [dx, dz] = heading_direction(heading);
        Platform {
            position: [
                self.position[0] + params.distance * dx,
                self.position[1] + params.height,
                self.position[2] + params.distance * dz,
            ],
            heading,
            size: params.size,
        }
    }

    /// Whether the two blocks collide or leave less than `headroom` between their tops.
    pub fn overlaps(&self, other: &Platform, headroom: f64) -> bool {
        (self.position[1] - other.position[1]).abs() < headroom && self.footprint_intersects(other)
    }

    /// Separating-axis test of the two square footprints in the horizontal plane.
    fn footprint_intersects(&self, other: &Platform) -> bool {
        let centre_delta = [
            other.position[0] - self.position[0],
            other.position[2] - self.position[2],
        ];
        let axes_of = |p: &Platform| {
            let [x, z] = heading_direction(p.heading);
            [[x, z], [-z, x]]
        };
        let (mine, theirs) = (axes_of(self), axes_of(other));
        mine.iter().chain(theirs.iter()).all(|axis| {
            let radius = |p: &Platform, axes: &[[f64; 2]; 2]| {
                0.5 * p.size * (dot(axes[0], *axis).abs() + dot(axes[1], *axis).abs())
            };
            dot(centre_delta, *axis).abs() < radius(self, &mine) + radius(other, &theirs)
        })
    }

    /// Whether this block, as the last of a level, reaches `goal`.
    pub fn reaches(&self, goal: [f64; 3]) -> bool {
        let horizontal = (goal[0] - self.position[0]).hypot(goal[2] - self.position[2]);
        horizontal <= GOAL_REACH_HORIZONTAL
            && (goal[1] - self.position[1]).abs() <= GOAL_REACH_VERTICAL
    }

    /// Signed distance between the facing edges of two consecutive blocks along the line joining
    /// their centres, as docs/spec.md §1.1 defines it: distance - (size_a + size_b) / 2.
    pub fn edge_gap(&self, next: &Platform) -> f64 {
        let distance =
            (next.position[0] - self.position[0]).hypot(next.position[2] - self.position[2]);
        distance - 0.5 * (self.size + next.size)
    }
}

/// Why a block cannot be placed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlacementError {
    /// The new block would overlap a platform already placed.
    #[error("block {block} overlaps {}", describe_platform(*other))]
    Overlap {
        /// The new block's index in the level's blocks.
        block: usize,
        /// The platform it overlaps (0 is the start block, `i + 1` is block `i`).
        other: usize,
    },
    /// The level already holds the most blocks allowed.
    #[error("a level holds at most {MAX_BLOCKS} blocks")]
    TooManyBlocks,
}

/// Names platform `index` (0 is the start block, `i + 1` is `blocks[i]`) for messages.
pub fn describe_platform(index: usize) -> String {
    match index {
        0 => "the start block".to_string(),
        i => format!("block {}", i - 1),
    }
}

/// A platform track: the start block and the placed blocks with their resolved transforms.
#[derive(Debug, Clone, PartialEq)]
pub struct PlatformTrack {
    start: Start,
    params: Vec<BlockParams>,
    /// Platform 0 is the start block, platform `i + 1` is `blocks[i]`.
    platforms: Vec<Platform>,
    /// How far apart the tops of overlapping blocks must be ([`headroom_of`] the character).
    headroom: f64,
}

impl PlatformTrack {
    /// An empty track: just the start block.
    pub fn new(start: Start) -> Self {
        let platforms = vec![Platform {
            position: start.position,
            heading: wrap_degrees(start.heading),
            size: start.size,
        }];
        Self {
            start,
            params: Vec::new(),
            platforms,
            headroom: HEADROOM,
        }
    }

    /// This track for a character that needs `headroom` between overlapping blocks
    /// ([`headroom_of`]); built-in: [`HEADROOM`].
    pub fn with_headroom(self, headroom: f64) -> Self {
        Self { headroom, ..self }
    }

    /// The headroom its blocks keep.
    pub fn headroom(&self) -> f64 {
        self.headroom
    }

    /// Places every block in turn, failing on the first invalid placement.
    pub fn from_params(start: Start, blocks: &[BlockParams]) -> Result<Self, PlacementError> {
        let mut track = Self::new(start);
        for params in blocks {
            track.push(*params)?;
        }
        Ok(track)
    }

    /// Where `params` would put the next block, without placing it.
    pub fn preview(&self, params: &BlockParams) -> Platform {
        self.last().place(params)
    }

    /// Places the next block. It may overlap the previous block but no other one.
    pub fn push(&mut self, params: BlockParams) -> Result<(), PlacementError> {
        if self.params.len() >= MAX_BLOCKS {
            return Err(PlacementError::TooManyBlocks);
        }
        let candidate = self.preview(&params);
        let before_previous = self.platforms.len() - 1;
        if let Some(other) = self.platforms[..before_previous]
            .iter()
            .position(|p| p.overlaps(&candidate, self.headroom))
        {
            return Err(PlacementError::Overlap {
                block: self.params.len(),
                other,
            });
        }
        self.params.push(params);
        self.platforms.push(candidate);
        Ok(())
    }

    /// The start block.
    pub fn start(&self) -> &Start {
        &self.start
    }

    /// The Generator parameters of the placed blocks.
    pub fn block_params(&self) -> &[BlockParams] {
        &self.params
    }

    /// All platforms: the start block first, then the placed blocks.
    pub fn platforms(&self) -> &[Platform] {
        &self.platforms
    }

    /// The most recently placed block (the start block while none is placed).
    pub fn last(&self) -> &Platform {
        self.platforms
            .last()
            .expect("a track always has its start block")
    }

    /// How many blocks are placed (the start block not counted).
    pub fn block_count(&self) -> usize {
        self.params.len()
    }
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block(distance: f64, angle: f64, size: f64, height: f64) -> BlockParams {
        BlockParams::new(distance, angle, size, height).unwrap()
    }

    #[test]
    fn blocks_resolve_turtle_style() {
        let track = PlatformTrack::from_params(
            Start::default(),
            &[block(8.0, 0.0, 5.0, 1.0), block(6.0, 90.0, 4.0, -2.0)],
        )
        .unwrap();
        let p = track.platforms();
        assert_eq!(p[1].position, [8.0, 1.0, 0.0]);
        // A 90 degree turn (counter-clockwise seen from above) heads along -Z.
        assert!((p[2].position[0] - 8.0).abs() < 1e-12);
        assert!((p[2].position[2] + 6.0).abs() < 1e-12, "{:?}", p[2]);
        assert_eq!(p[2].position[1], -1.0);
        assert_eq!(p[2].heading, 90.0);
        assert_eq!(p[0].edge_gap(&p[1]), 8.0 - 5.5);
    }

    #[test]
    fn a_block_may_touch_the_previous_one_but_no_other() {
        // Out and straight back: the third block lands on the start block.
        let mut track = PlatformTrack::new(Start::default());
        track.push(block(5.0, 0.0, 6.0, 0.0)).unwrap(); // overlaps the start block by 1 m: allowed
        let err = track.push(block(5.0, 180.0, 6.0, 0.0)).unwrap_err();
        assert_eq!(err, PlacementError::Overlap { block: 1, other: 0 });
        assert_eq!(err.to_string(), "block 1 overlaps the start block");
        // Only 2 m above the start block: too little headroom.
        assert!(track.push(block(5.0, 180.0, 6.0, 2.0)).is_err());
        // A spiral staircase passes 8 m above its own lower turns: allowed.
        let mut stairs = PlatformTrack::new(Start::default());
        for _ in 0..6 {
            stairs.push(block(5.0, 90.0, 4.0, 2.0)).unwrap();
        }
        assert_eq!(stairs.block_count(), 6);
    }

    #[test]
    fn the_headroom_is_the_characters_height() {
        assert_eq!(headroom_for(1.8), HEADROOM, "the built-in character");
        // Out, then back over the start block 3.1 m up: room for a 1.8 m character, not a 2 m one.
        let over_the_start = |headroom: f64| {
            let mut track = PlatformTrack::new(Start::default()).with_headroom(headroom);
            track.push(block(5.0, 0.0, 6.0, 1.5)).unwrap();
            track.push(block(5.0, 180.0, 6.0, 1.6))
        };
        assert!(over_the_start(headroom_for(1.8)).is_ok());
        assert_eq!(
            over_the_start(headroom_for(2.0)),
            Err(PlacementError::Overlap { block: 1, other: 0 })
        );
        assert!(over_the_start(headroom_for(1.2)).is_ok());
    }

    #[test]
    fn rotated_squares_overlap_only_when_they_touch() {
        let a = Platform {
            position: [0.0; 3],
            heading: 0.0,
            size: 4.0,
        };
        let diamond = |x: f64| Platform {
            position: [x, 0.0, 0.0],
            heading: 45.0,
            size: 4.0,
        };
        // The diamond's corner reaches 2*sqrt(2) = 2.83 m from its centre.
        assert!(a.overlaps(&diamond(4.8), HEADROOM));
        assert!(!a.overlaps(&diamond(4.9), HEADROOM));
    }

    #[test]
    fn goal_reach_is_measured_from_the_top_centre() {
        let p = Platform {
            position: [10.0, 2.0, 0.0],
            heading: 0.0,
            size: 5.0,
        };
        assert!(p.reaches([12.0, 3.0, 2.0]));
        assert!(!p.reaches([13.5, 2.0, 0.0]));
        assert!(!p.reaches([10.0, 4.5, 0.0]));
    }
}
