//! Racing levels as data: road segments, each relative to the end of the previous one. The road
//! geometry (C1 joins, banking) is built by the racing game; here are only the parameters.

use serde::{Deserialize, Serialize};

use super::params::{self, RangeError};

/// The Generator's action for one road segment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SegmentParams {
    /// Segment length along the centre line, m.
    pub length: f64,
    /// Heading change over the segment, degrees.
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

/// A racing track: where the road starts and its segments.
#[derive(Debug, Clone, PartialEq)]
pub struct RacingTrack {
    /// Start of the road's centre line.
    pub position: [f64; 3],
    /// Initial road direction, degrees.
    pub heading: f64,
    pub segments: Vec<SegmentParams>,
}
