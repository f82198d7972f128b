//! The level file's shape for serde (`LevelFile` and its pieces, numbers bounded while they
//! are parsed) and its conversion to and from a [`Level`], with the checks serde cannot make.

use std::collections::BTreeMap;
use std::marker::PhantomData;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{
    FORMAT_NAME, FORMAT_VERSION, Problem, TRANSFORM_TOLERANCE, invalid, line_of_item, line_of_key,
};
use crate::level::heading;
use crate::level::pacing::{AuxCurve, Pacing};
use crate::level::params::{self, ParamRange};
use crate::level::platform::{BlockParams, PlatformTrack, Start, headroom_of};
use crate::level::profile::ProfileRecord;
use crate::level::racing::{self, Obstacle, RacingTrack, RoadShape, SegmentParams};
use crate::level::{Game, Level, Shape, ShapeKind, SolverStats, Source, Track, WantRecord};

/// A number that must lie in the range `B` names; checked while parsing, so serde_yaml's error
/// carries the field path and line.
#[derive(Debug, Clone, Copy)]
struct Bounded<B>(f64, PhantomData<B>);

trait Bound {
    const RANGE: ParamRange;
}

macro_rules! bounds {
    ($($marker:ident => $range:expr),* $(,)?) => {
        $(
            #[derive(Debug, Clone, Copy)]
            struct $marker;
            impl Bound for $marker {
                const RANGE: ParamRange = $range;
            }
        )*
    };
}

bounds! {
    Distance => params::BLOCK_DISTANCE,
    Angle => params::BLOCK_ANGLE,
    Size => params::BLOCK_SIZE,
    BlockHeight => params::BLOCK_HEIGHT,
    Length => params::SEGMENT_LENGTH,
    Curve => params::SEGMENT_CURVE,
    SegmentHeight => params::SEGMENT_HEIGHT,
    Aux => params::AUX,
    Heading => params::HEADING,
    Coordinate => params::COORDINATE,
    RoadWidth => racing::WIDTH_RANGE,
    Banking => racing::BANKING_RANGE,
}

impl<B> Bounded<B> {
    fn new(value: f64) -> Self {
        Self(value, PhantomData)
    }
}

impl<B> Serialize for Bounded<B> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_f64(self.0)
    }
}

impl<'de, B: Bound> Deserialize<'de> for Bounded<B> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        // The message names the parameter too: in flow style (`{size: 12}`) serde_yaml's path
        // stops at the enclosing mapping.
        let value = f64::deserialize(deserializer)?;
        B::RANGE
            .check(value)
            .map(Self::new)
            .map_err(serde::de::Error::custom)
    }
}

type Point = [Bounded<Coordinate>; 3];

fn point(p: &Point) -> [f64; 3] {
    p.map(|c| c.0)
}

fn write_point(p: [f64; 3]) -> Point {
    p.map(|c| Bounded::new((c * 10_000.0).round() / 10_000.0))
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LevelFile {
    format: String,
    version: u32,
    game: Game,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    seed: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    aux: Option<Bounded<Aux>>,
    /// λ along the level (then each block or segment carries its own `aux`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    aux_curve: Option<AuxCurve>,
    /// The style knobs it was built with, by name (none: no preference).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    knobs: BTreeMap<String, Bounded<Aux>>,
    start: StartFile,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    goal: Option<Point>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    blocks: Option<Vec<BlockFile>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    segments: Option<Vec<SegmentFile>>,
    /// Racing levels: what the road goes around.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    obstacles: Vec<Obstacle>,
    /// Racing levels: the road's width and banking (none: the built-in road's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    road: Option<RoadFile>,
    #[serde(default)]
    source: Source,
    /// The game profile it was made under (none: the built-in one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    profile: Option<ProfileRecord>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stats: Option<SolverStats>,
    /// The wish list it was searched to meet, with each constraint's measured value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    want: Option<WantRecord>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RoadFile {
    width: Bounded<RoadWidth>,
    banking: Bounded<Banking>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StartFile {
    position: Point,
    heading: Bounded<Heading>,
    /// Side of the start block (platform levels; default 6 m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    size: Option<Bounded<Size>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BlockFile {
    distance: Bounded<Distance>,
    angle: Bounded<Angle>,
    size: Bounded<Size>,
    height: Bounded<BlockHeight>,
    /// The λ the block was placed at (levels built with an `aux_curve`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    aux: Option<Bounded<Aux>>,
    /// Resolved top centre (written by arlpcg; optional and checked when read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    position: Option<Point>,
    /// Resolved heading, degrees (written by arlpcg; optional and checked when read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    heading: Option<Bounded<Heading>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentFile {
    length: Bounded<Length>,
    curve: Bounded<Curve>,
    height: Bounded<SegmentHeight>,
    /// The λ the segment was placed at (levels built with an `aux_curve`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    aux: Option<Bounded<Aux>>,
}

impl LevelFile {
    pub(super) fn from_level(level: &Level) -> Self {
        let piece_aux = |i: usize| {
            level
                .pacing
                .as_ref()
                .and_then(|p| p.piece_aux.get(i).copied().flatten())
                .map(Bounded::new)
        };
        let road = match level.shape() {
            Shape::Road(track) if !track.road.is_default() => Some(RoadFile {
                width: Bounded::new(track.road.width),
                banking: Bounded::new(track.road.banking),
            }),
            _ => None,
        };
        let (start, blocks, segments, obstacles) = match level.shape() {
            Shape::Blocks(track) => {
                let s = track.start();
                let start = StartFile {
                    position: write_point(s.position),
                    heading: Bounded::new(s.heading),
                    size: Some(Bounded::new(s.size)),
                };
                let blocks = track
                    .block_params()
                    .iter()
                    .zip(&track.platforms()[1..])
                    .enumerate()
                    .map(|(i, (p, placed))| BlockFile {
                        distance: Bounded::new(p.distance),
                        angle: Bounded::new(p.angle),
                        size: Bounded::new(p.size),
                        height: Bounded::new(p.height),
                        aux: piece_aux(i),
                        position: Some(write_point(placed.position)),
                        heading: Some(Bounded::new((placed.heading * 1000.0).round() / 1000.0)),
                    })
                    .collect();
                (start, Some(blocks), None, Vec::new())
            }
            Shape::Road(track) => {
                let start = StartFile {
                    position: write_point(track.position),
                    heading: Bounded::new(track.heading),
                    size: None,
                };
                let segments = track
                    .segments
                    .iter()
                    .enumerate()
                    .map(|(i, s)| SegmentFile {
                        length: Bounded::new(s.length),
                        curve: Bounded::new(s.curve),
                        height: Bounded::new(s.height),
                        aux: piece_aux(i),
                    })
                    .collect();
                (start, None, Some(segments), track.obstacles.clone())
            }
        };
        Self {
            format: FORMAT_NAME.to_string(),
            version: FORMAT_VERSION,
            game: level.game(),
            seed: level.seed,
            aux: level.aux.map(Bounded::new),
            aux_curve: level.pacing.as_ref().map(|p| p.curve.clone()),
            knobs: level
                .knobs
                .iter()
                .map(|(name, value)| (name.clone(), Bounded::new(*value)))
                .collect(),
            start,
            goal: Some(level.goal.map(Bounded::new)),
            blocks,
            segments,
            obstacles,
            road,
            source: level.source.clone(),
            profile: level.profile.as_ref().map(|p| p.record()),
            stats: level.stats.clone(),
            want: level.want.clone(),
        }
    }

    pub(super) fn into_level(self, text: &str) -> Result<Level, Problem> {
        let pacing = self.pacing(text)?;
        let profile = match &self.profile {
            Some(record) => Some(
                record
                    .profile(self.game)
                    .map_err(|e| invalid("profile".into(), line_of_key(text, "profile"), e))?,
            ),
            None => None,
        };
        let (track, default_goal) = match self.game.shape() {
            ShapeKind::Blocks => {
                let headroom = headroom_of(profile.as_ref().map(|p| &p.abilities));
                let (blocks, end) = self.platform_track(text, headroom)?;
                (Track::of_blocks(self.game, blocks), end)
            }
            ShapeKind::Road => {
                let (road, end) = self.racing_track(text)?;
                (Track::of_road(self.game, road), end)
            }
        };
        let track = track.ok_or_else(|| {
            invalid(
                "game".into(),
                line_of_key(text, "game"),
                format!("a {} level cannot hold these pieces", self.game),
            )
        })?;
        let level = Level {
            seed: self.seed,
            aux: self.aux.map(|a| a.0),
            goal: self
                .goal
                .as_ref()
                .map_or(default_goal.map(params::quantize), point),
            track,
            source: self.source,
            stats: self.stats,
            pacing,
            profile,
            knobs: self.knobs.iter().map(|(k, v)| (k.clone(), v.0)).collect(),
            want: self.want,
        };
        level.validate().map_err(|e| {
            let key = |key: &str| (key.to_string(), line_of_key(text, key));
            let (field, line) = match &e {
                crate::level::InvalidLevel::Stats(_) => key("stats"),
                crate::level::InvalidLevel::Want(_) => key("want"),
                crate::level::InvalidLevel::Source(_) => key("source"),
                crate::level::InvalidLevel::NoPieces(what)
                | crate::level::InvalidLevel::TooMany { what, .. } => key(what),
                crate::level::InvalidLevel::GoalNotReached { .. }
                | crate::level::InvalidLevel::RoadShort { .. } => key("goal"),
                crate::level::InvalidLevel::Road(_) => key("segments"),
                crate::level::InvalidLevel::Pacing(_) => key("aux_curve"),
                crate::level::InvalidLevel::UnknownKnob { .. } => key("knobs"),
                crate::level::InvalidLevel::Obstacle { index, problem } => {
                    return invalid(
                        format!("obstacles[{index}]"),
                        line_of_item(text, "obstacles", *index),
                        problem.clone(),
                    );
                }
            };
            invalid(field, line, e.to_string())
        })?;
        Ok(level)
    }

    /// The platform track the file describes, and where its last block ends (the goal when the
    /// file gives none); each block checked with its line and placed with `headroom`
    /// ([`headroom_of`] its character).
    fn platform_track(
        &self,
        text: &str,
        headroom: f64,
    ) -> Result<(PlatformTrack, [f64; 3]), Problem> {
        if self.segments.is_some() {
            return Err(invalid(
                "segments".into(),
                line_of_key(text, "segments"),
                format!("a {} level has `blocks`, not `segments`", self.game),
            ));
        }
        if !self.obstacles.is_empty() {
            return Err(invalid(
                "obstacles".into(),
                line_of_key(text, "obstacles"),
                format!("a {} level has no obstacles", self.game),
            ));
        }
        if self.road.is_some() {
            return Err(invalid(
                "road".into(),
                line_of_key(text, "road"),
                format!("a {} level has no road", self.game),
            ));
        }
        let blocks = self.blocks.as_ref().ok_or_else(|| {
            invalid(
                "blocks".into(),
                None,
                format!("missing: a {} level needs its blocks", self.game),
            )
        })?;
        let start = Start {
            position: point(&self.start.position),
            heading: self.start.heading.0,
            size: self.start.size.map_or(Start::default().size, |s| s.0),
        };
        let mut track = PlatformTrack::new(start).with_headroom(headroom);
        for (i, block) in blocks.iter().enumerate() {
            let field = format!("blocks[{i}]");
            let line = || line_of_item(text, "blocks", i);
            let params = BlockParams {
                distance: block.distance.0,
                angle: block.angle.0,
                size: block.size.0,
                height: block.height.0,
            };
            track
                .push(params)
                .map_err(|e| invalid(field.clone(), line(), e.to_string()))?;
            let placed = track.last();
            if let Some(position) = &block.position {
                let written = point(position);
                let off =
                    (0..3).any(|k| (written[k] - placed.position[k]).abs() > TRANSFORM_TOLERANCE);
                if off {
                    return Err(invalid(
                        format!("{field}.position"),
                        line(),
                        format!(
                            "{written:?} is not where the block's parameters put it ({:?}); delete `position` and `heading` to recompute them",
                            placed.position.map(|c| (c * 1000.0).round() / 1000.0)
                        ),
                    ));
                }
            }
            if let Some(heading) = block.heading {
                let off = heading::wrap_degrees(heading.0 - placed.heading).abs();
                if off > TRANSFORM_TOLERANCE {
                    return Err(invalid(
                        format!("{field}.heading"),
                        line(),
                        format!(
                            "{} is not the heading the block's parameters give ({:.3}); delete `position` and `heading` to recompute them",
                            heading.0, placed.heading
                        ),
                    ));
                }
            }
        }
        let last = track.last().position;
        Ok((track, last))
    }

    /// The racing track the file describes, and where its road ends (the goal when the file
    /// gives none); counts and obstacles checked before any road geometry.
    fn racing_track(&self, text: &str) -> Result<(RacingTrack, [f64; 3]), Problem> {
        if self.blocks.is_some() {
            return Err(invalid(
                "blocks".into(),
                line_of_key(text, "blocks"),
                format!("a {} level has `segments`, not `blocks`", self.game),
            ));
        }
        if self.start.size.is_some() {
            return Err(invalid(
                "start.size".into(),
                None,
                format!("a {} level's start has no size", self.game),
            ));
        }
        let segments = self.segments.as_ref().ok_or_else(|| {
            invalid(
                "segments".into(),
                None,
                format!("missing: a {} level needs its segments", self.game),
            )
        })?;
        let segments: Vec<SegmentParams> = segments
            .iter()
            .map(|s| SegmentParams {
                length: s.length.0,
                curve: s.curve.0,
                height: s.height.0,
            })
            .collect();
        // Each obstacle before the geometry, which is meaningless around a NaN one (the counts
        // were refused from the first parse, in `check_counts`).
        for (index, obstacle) in self.obstacles.iter().enumerate() {
            obstacle.check().map_err(|problem| {
                let (field, message) = problem.split_once(": ").unwrap_or(("", &problem));
                invalid(
                    format!("obstacles[{index}].{field}"),
                    line_of_item(text, "obstacles", index),
                    message.to_string(),
                )
            })?;
        }
        let track = RacingTrack {
            position: point(&self.start.position),
            heading: self.start.heading.0,
            segments,
            obstacles: self.obstacles.clone(),
            road: self
                .road
                .as_ref()
                .map_or_else(RoadShape::default, |r| RoadShape {
                    width: r.width.0,
                    banking: r.banking.0,
                }),
        };
        // Checked here (not only in `validate`) to name the segment's line.
        track.check_geometry().map_err(|e| {
            let index = match e {
                crate::level::road::TrackError::Crosses { later, .. } => later,
                crate::level::road::TrackError::HitsObstacle { segment, .. } => segment,
            };
            invalid(
                format!("segments[{index}]"),
                line_of_item(text, "segments", index),
                e.to_string(),
            )
        })?;
        let (end, _) = track.road().end();
        Ok((track, end))
    }
}

impl LevelFile {
    /// λ along the level: with `aux_curve`, every piece carries its `aux` (but pieces kept
    /// from a level that recorded none); without, none does.
    fn pacing(&self, text: &str) -> Result<Option<Pacing>, Problem> {
        let (key, piece_aux): (&str, Vec<Option<f64>>) = match (&self.blocks, &self.segments) {
            (Some(blocks), _) => (
                "blocks",
                blocks.iter().map(|b| b.aux.map(|a| a.0)).collect(),
            ),
            (None, Some(segments)) => (
                "segments",
                segments.iter().map(|s| s.aux.map(|a| a.0)).collect(),
            ),
            (None, None) => ("blocks", Vec::new()),
        };
        let invalid = |index: usize, message: String| Problem::Invalid {
            field: format!("{key}[{index}].aux"),
            line: line_of_item(text, key, index),
            message,
        };
        let Some(curve) = &self.aux_curve else {
            return match piece_aux.iter().position(Option::is_some) {
                Some(i) => Err(invalid(
                    i,
                    "a piece's own λ needs `aux_curve` at the top of the file (the curve it was placed along)".into(),
                )),
                None => Ok(None),
            };
        };
        if self.aux.is_some() {
            return Err(Problem::Invalid {
                field: "aux".into(),
                line: line_of_key(text, "aux"),
                message: "a level has one λ (`aux`) or a curve (`aux_curve`), not both".into(),
            });
        }
        // Pieces kept from a level that recorded no λ have none.
        let kept = self.source.kept_pieces();
        if let Some(i) = piece_aux.iter().skip(kept).position(Option::is_none) {
            return Err(invalid(
                kept + i,
                "missing: with `aux_curve` every piece the Generator placed has its λ".into(),
            ));
        }
        Ok(Some(Pacing {
            curve: curve.clone(),
            piece_aux,
        }))
    }
}
