//! The ranges a profile's level pieces are drawn from: platform blocks and racing segments, each
//! within the level format's own.

use serde::{Deserialize, Serialize};

use super::{Fields, field, nth, ordered};
use crate::level::params::{self, ParamRange};
use crate::level::racing::{self, RoadShape};
use crate::level::{Game, Shape, ShapeKind};

/// The ranges a platform level's blocks are drawn from, by the rules and the Generator; each
/// within the level format's own (`level::params`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockRanges {
    /// Shortest and longest centre-to-centre distance from the previous block, m.
    pub min_distance: f64,
    /// The longest centre-to-centre distance from the previous block, m.
    pub max_distance: f64,
    /// Smallest and largest side of a block's top, m.
    pub min_size: f64,
    /// The largest side of a block's top, m.
    pub max_size: f64,
    /// Largest drop (negative) and climb from the previous block, m.
    pub min_height: f64,
    /// The largest climb from the previous block, m.
    pub max_height: f64,
    /// Sharpest turn off the last jump's direction, degrees (the Generator keeps within
    /// `game::platform::reach::MAX_TURN` as well).
    pub max_turn: f64,
}

/// The ranges a racing level's segments are drawn from, by the rules and the Generator; each
/// within the level format's own (`level::params`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentRanges {
    /// Shortest and longest segment along the centre line, m.
    pub min_length: f64,
    /// The longest segment along the centre line, m.
    pub max_length: f64,
    /// Sharpest heading change over a segment, either way, degrees.
    pub max_curve: f64,
    /// Largest height change over a segment, either way, m.
    pub max_height: f64,
    /// Width of the road, m (a level made under the profile records it, with the banking).
    #[serde(default = "default_road_width")]
    pub road_width: f64,
    /// Bank angle per unit of curvature, ° per °/m (0: a flat road).
    #[serde(default = "default_banking")]
    pub banking: f64,
}

fn default_road_width() -> f64 {
    racing::ROAD_WIDTH
}

fn default_banking() -> f64 {
    racing::BANK_GAIN
}

/// The ranges a game's pieces are drawn from, of the kind its levels are built from
/// ([`ShapeKind`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pieces {
    /// The blocks' ranges (platform).
    Blocks(BlockRanges),
    /// The road segments' ranges (racing).
    Road(SegmentRanges),
}

impl Default for BlockRanges {
    /// The level format's ranges, and the Generator's sharpest turn.
    fn default() -> Self {
        Self {
            min_distance: params::BLOCK_DISTANCE.min,
            max_distance: params::BLOCK_DISTANCE.max,
            min_size: params::BLOCK_SIZE.min,
            max_size: params::BLOCK_SIZE.max,
            min_height: params::BLOCK_HEIGHT.min,
            max_height: params::BLOCK_HEIGHT.max,
            max_turn: params::BLOCK_ANGLE.max,
        }
    }
}

impl Default for SegmentRanges {
    /// The level format's ranges.
    fn default() -> Self {
        Self {
            min_length: params::SEGMENT_LENGTH.min,
            max_length: params::SEGMENT_LENGTH.max,
            max_curve: params::SEGMENT_CURVE.max,
            max_height: params::SEGMENT_HEIGHT.max,
            road_width: racing::ROAD_WIDTH,
            banking: racing::BANK_GAIN,
        }
    }
}

/// Each block range field.
pub const BLOCK_FIELDS: [(ParamRange, &str); 7] = [
    field(
        "blocks.min_distance",
        params::BLOCK_DISTANCE.min,
        params::BLOCK_DISTANCE.max,
        "m",
        "shortest distance between block centres",
    ),
    field(
        "blocks.max_distance",
        params::BLOCK_DISTANCE.min,
        params::BLOCK_DISTANCE.max,
        "m",
        "longest distance between block centres",
    ),
    field(
        "blocks.min_size",
        params::BLOCK_SIZE.min,
        params::BLOCK_SIZE.max,
        "m",
        "smallest block side",
    ),
    field(
        "blocks.max_size",
        params::BLOCK_SIZE.min,
        params::BLOCK_SIZE.max,
        "m",
        "largest block side",
    ),
    field(
        "blocks.min_height",
        params::BLOCK_HEIGHT.min,
        params::BLOCK_HEIGHT.max,
        "m",
        "largest drop from block to block (negative)",
    ),
    field(
        "blocks.max_height",
        params::BLOCK_HEIGHT.min,
        params::BLOCK_HEIGHT.max,
        "m",
        "largest climb from block to block",
    ),
    field(
        "blocks.max_turn",
        0.0,
        params::BLOCK_ANGLE.max,
        "°",
        "sharpest turn off the last jump (the Generator keeps within 90)",
    ),
];

/// Each segment range field.
pub const SEGMENT_FIELDS: [(ParamRange, &str); 6] = [
    field(
        "segments.min_length",
        params::SEGMENT_LENGTH.min,
        params::SEGMENT_LENGTH.max,
        "m",
        "shortest segment",
    ),
    field(
        "segments.max_length",
        params::SEGMENT_LENGTH.min,
        params::SEGMENT_LENGTH.max,
        "m",
        "longest segment",
    ),
    field(
        "segments.max_curve",
        0.0,
        params::SEGMENT_CURVE.max,
        "°",
        "sharpest curve of a segment, either way",
    ),
    field(
        "segments.max_height",
        0.0,
        params::SEGMENT_HEIGHT.max,
        "m",
        "largest climb or drop of a segment",
    ),
    field(
        "segments.road_width",
        racing::WIDTH_RANGE.min,
        racing::WIDTH_RANGE.max,
        "m",
        "width of the road",
    ),
    field(
        "segments.banking",
        racing::BANKING_RANGE.min,
        racing::BANKING_RANGE.max,
        "° per °/m",
        "bank angle per unit of curvature (0: flat)",
    ),
];

impl Fields for BlockRanges {
    const FIELDS: &'static [(ParamRange, &'static str)] = &BLOCK_FIELDS;
    fn slot(&mut self, k: usize) -> &mut f64 {
        nth(
            [
                &mut self.min_distance, &mut self.max_distance, &mut self.min_size,
                &mut self.max_size, &mut self.min_height, &mut self.max_height, &mut self.max_turn,
            ],
            k,
        )
    }
}

impl BlockRanges {
    /// Checks every field's range, and that each least is not above its most.
    pub fn check(&self) -> Result<(), String> {
        self.check_each().map_err(|e| e.to_string())?;
        for k in [0, 2, 4] {
            let name = |k: usize| BLOCK_FIELDS[k].0.name;
            ordered((name(k), self.get(k)), (name(k + 1), self.get(k + 1)))?;
        }
        Ok(())
    }

    /// A block's distance from the previous one, m.
    pub fn distance(&self) -> ParamRange {
        ParamRange::new("distance", self.min_distance, self.max_distance, "m")
    }

    /// A block's side, m.
    pub fn size(&self) -> ParamRange {
        ParamRange::new("size", self.min_size, self.max_size, "m")
    }

    /// A block's height over the previous one, m.
    pub fn height(&self) -> ParamRange {
        ParamRange::new("height", self.min_height, self.max_height, "m")
    }

    /// A block's turn off the last jump's direction, either way, degrees (named `angle`).
    pub fn turn(&self) -> ParamRange {
        ParamRange::new("angle", -self.max_turn, self.max_turn, "degrees")
    }

    /// A block's style, one measure in [-1, 1] per knob of a blocks level
    /// ([`crate::level::platform::BLOCK_KNOBS`]): its distance within these ranges' (-1 the
    /// shortest), and the size of its height change, either way, within the largest they allow
    /// (-1 level, +1 the largest); 0 where a range is a single value. What a Generator's
    /// knob pays and a level's style measures.
    pub fn style(&self, block: &crate::level::platform::BlockParams) -> [f32; 2] {
        let distance = self.distance();
        let stride = match distance.max > distance.min {
            true => distance.to_unit(block.distance.clamp(distance.min, distance.max)),
            false => 0.0,
        };
        let largest = self.min_height.abs().max(self.max_height.abs());
        [stride as f32, within_largest(block.height, largest)]
    }

    /// Checks that each of `block`'s parameters lies within these ranges.
    #[cfg(test)]
    pub(crate) fn check_block(
        &self,
        block: &crate::level::platform::BlockParams,
    ) -> Result<(), params::RangeError> {
        self.distance().check(block.distance)?;
        self.size().check(block.size)?;
        self.height().check(block.height)?;
        self.turn().check(block.angle).map(drop)
    }
}

impl Fields for SegmentRanges {
    const FIELDS: &'static [(ParamRange, &'static str)] = &SEGMENT_FIELDS;
    fn slot(&mut self, k: usize) -> &mut f64 {
        nth(
            [
                &mut self.min_length, &mut self.max_length, &mut self.max_curve,
                &mut self.max_height, &mut self.road_width, &mut self.banking,
            ],
            k,
        )
    }
}

impl SegmentRanges {
    /// Checks every field's range, and that the shortest length is not above the longest.
    pub fn check(&self) -> Result<(), String> {
        self.check_each().map_err(|e| e.to_string())?;
        ordered(
            (SEGMENT_FIELDS[0].0.name, self.min_length),
            (SEGMENT_FIELDS[1].0.name, self.max_length),
        )
    }

    /// A segment's style, one measure in [-1, 1] per knob of a road level
    /// ([`crate::level::racing::ROAD_KNOBS`]): the size of its heading change and of its
    /// height change, either way, within the largest these ranges allow (-1 none, +1 the
    /// largest); 0 where a range allows none.
    pub fn style(&self, segment: &crate::level::racing::SegmentParams) -> [f32; 2] {
        [
            within_largest(segment.curve, self.max_curve),
            within_largest(segment.height, self.max_height),
        ]
    }

    /// A segment's length, m.
    pub fn length(&self) -> ParamRange {
        ParamRange::new("length", self.min_length, self.max_length, "m")
    }

    /// A segment's heading change, either way, degrees.
    pub fn curve(&self) -> ParamRange {
        ParamRange::new("curve", -self.max_curve, self.max_curve, "degrees")
    }

    /// A segment's height change, either way, m.
    pub fn height(&self) -> ParamRange {
        ParamRange::new("height", -self.max_height, self.max_height, "m")
    }

    /// The road of the levels made with these ranges.
    pub fn road(&self) -> RoadShape {
        RoadShape {
            width: self.road_width,
            banking: self.banking,
        }
    }
}

impl Pieces {
    /// `game`'s piece ranges from a file's `blocks:` and `segments:` (the one of its game, the
    /// built-in ranges when it has none, and not the other's), checked.
    pub(super) fn checked(
        game: Game,
        blocks: Option<BlockRanges>,
        segments: Option<SegmentRanges>,
    ) -> Result<Self, String> {
        match (game.shape(), blocks, segments) {
            (ShapeKind::Blocks, blocks, None) => Self::of_blocks(blocks),
            (ShapeKind::Road, None, segments) => Self::of_road(segments),
            (ShapeKind::Blocks, _, _) => {
                Err(format!("a {game} profile has `blocks:`, not `segments:`"))
            }
            (ShapeKind::Road, _, _) => {
                Err(format!("a {game} profile has `segments:`, not `blocks:`"))
            }
        }
    }

    fn of_blocks(blocks: Option<BlockRanges>) -> Result<Self, String> {
        let blocks = blocks.unwrap_or_default().normalized();
        blocks.check()?;
        Ok(Pieces::Blocks(blocks))
    }

    fn of_road(segments: Option<SegmentRanges>) -> Result<Self, String> {
        let segments = segments.unwrap_or_default().normalized();
        segments.check()?;
        Ok(Pieces::Road(segments))
    }

    /// The built-in ranges of `game`.
    pub fn default_of(game: Game) -> Self {
        Self::built_in(game.shape())
    }

    fn built_in(kind: ShapeKind) -> Self {
        match kind {
            ShapeKind::Blocks => Pieces::Blocks(BlockRanges::default()),
            ShapeKind::Road => Pieces::Road(SegmentRanges::default()),
        }
    }

    /// The style of the level `shape`, one value per knob of its shape
    /// ([`ShapeKind::knobs`]): each the mean over its pieces of their measure within these
    /// ranges (`BlockRanges::style`, `SegmentRanges::style`; the ranges of the level's own
    /// shape), 0 for a level of no pieces. The same measure a Generator's knob pays per piece.
    pub fn style(&self, shape: Shape<'_>) -> Vec<f64> {
        let measures: Vec<[f32; 2]> = match shape {
            Shape::Blocks(track) => {
                let ranges = self.blocks();
                track
                    .block_params()
                    .iter()
                    .map(|b| ranges.style(b))
                    .collect()
            }
            Shape::Road(track) => {
                let ranges = self.segments();
                track.segments.iter().map(|s| ranges.style(s)).collect()
            }
        };
        let count = measures.len().max(1) as f64;
        (0..2)
            .map(|k| measures.iter().map(|m| f64::from(m[k])).sum::<f64>() / count)
            .collect()
    }

    /// The block ranges (the built-in ones for a profile of road).
    pub fn blocks(&self) -> BlockRanges {
        match self {
            Pieces::Blocks(b) => *b,
            Pieces::Road(_) => BlockRanges::default(),
        }
    }

    /// The road ranges (the built-in ones for a profile of blocks).
    pub fn segments(&self) -> SegmentRanges {
        match self {
            Pieces::Road(s) => *s,
            Pieces::Blocks(_) => SegmentRanges::default(),
        }
    }

    /// The field named as in [`BLOCK_FIELDS`] or [`SEGMENT_FIELDS`], with its range.
    pub fn value(&self, field: &str) -> Option<(f64, ParamRange)> {
        match self {
            Pieces::Blocks(b) => b.field(field),
            Pieces::Road(s) => s.field(field),
        }
    }

    /// These ranges with `field` at `value`, when they are then valid.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        let changed = match self {
            Pieces::Blocks(b) => Pieces::Blocks(b.set(field, value)?),
            Pieces::Road(s) => Pieces::Road(s.set(field, value)?),
        };
        match changed {
            Pieces::Blocks(b) => Self::of_blocks(Some(b)),
            Pieces::Road(s) => Self::of_road(Some(s)),
        }
        .ok()
    }

    /// What the ranges are of.
    pub fn kind(&self) -> ShapeKind {
        match self {
            Pieces::Blocks(_) => ShapeKind::Blocks,
            Pieces::Road(_) => ShapeKind::Road,
        }
    }

    /// The file's `blocks:` and `segments:`.
    pub(super) fn sections(&self) -> (Option<BlockRanges>, Option<SegmentRanges>) {
        match *self {
            Pieces::Blocks(b) => (Some(b), None),
            Pieces::Road(s) => (None, Some(s)),
        }
    }

    /// The sections a file writes: none for the built-in ranges, so that a profile of
    /// abilities alone keeps its SHA-256.
    pub(super) fn written(&self) -> (Option<BlockRanges>, Option<SegmentRanges>) {
        if *self == Self::built_in(self.kind()) {
            (None, None)
        } else {
            self.sections()
        }
    }
}

/// The size of `value`, either way, within `largest` as a measure in [-1, 1] (-1 none, +1
/// `largest` or more); 0 where `largest` is 0.
fn within_largest(value: f64, largest: f64) -> f32 {
    match largest > 0.0 {
        true => (2.0 * value.abs() / largest - 1.0).min(1.0) as f32,
        false => 0.0,
    }
}
