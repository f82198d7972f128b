//! The level file, format `arlpcg-level` version 1 (YAML): the source of truth for a level.
//!
//! Loading checks everything and names the file, the field and, where it can, the line of the
//! first problem. A designer may write a level by hand giving only the relative parameters: the
//! resolved transforms (`position`, `heading` of each block) and the goal are then computed.

use std::io::Read;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::pacing::{AuxCurve, Pacing};
use super::params::{self, ParamRange};
use super::platform::{self, BlockParams, PlatformTrack, Start};
use super::racing::{Obstacle, RacingTrack, SegmentParams};
use super::{Game, Level, PolicyRef, SolverStats, Source, Track};

/// The `format` every level file declares.
pub const FORMAT_NAME: &str = "arlpcg-level";
/// The version of the format this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;
/// Level files larger than this are refused before parsing (real ones are a few kB).
pub const MAX_FILE_BYTES: u64 = 4 << 20;
/// Resolved positions and headings in a file must match the parameters this closely.
const TRANSFORM_TOLERANCE: f64 = 1e-3;

/// A level file that could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct LoadError {
    pub path: PathBuf,
    pub problem: Problem,
}

/// What is wrong with a level file.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    #[error("the file is empty")]
    Empty,
    #[error("not a regular file (a folder, FIFO, socket or device)")]
    NotAFile,
    #[error("the file is larger than {} MiB; a level file is a few kB", MAX_FILE_BYTES >> 20)]
    TooLarge,
    #[error("not a text file (invalid UTF-8 at byte {0})")]
    NotText(usize),
    #[error("not an arlpcg level: {0}")]
    NotALevel(String),
    #[error("format version {0} is not supported: this arlpcg reads version {FORMAT_VERSION}")]
    UnsupportedVersion(String),
    /// A syntax, type or range error found while parsing (serde_yaml names field and line).
    #[error("{0}")]
    Parse(String),
    /// A rule of the level broken by otherwise well-formed values.
    #[error("{field}: {message}{}", line.map(|l| format!(" (line {l})")).unwrap_or_default())]
    Invalid {
        field: String,
        line: Option<usize>,
        message: String,
    },
}

/// Reads and validates a level file.
pub fn load(path: &Path) -> Result<Level, LoadError> {
    load_pinned(path).map(|(level, _)| level)
}

/// [`load`], and the file pinned by the hash of the bytes read (what a kept prefix records).
pub fn load_pinned(path: &Path) -> Result<(Level, PolicyRef), LoadError> {
    let fail = |problem| LoadError {
        path: path.to_path_buf(),
        problem,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(e.into()))?;
    if !meta.is_file() {
        return Err(fail(Problem::NotAFile));
    }
    let file = std::fs::File::open(path).map_err(|e| fail(e.into()))?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(e.into()))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(Problem::TooLarge));
    }
    let reference = PolicyRef::pinned(path.display().to_string(), &bytes);
    let text = String::from_utf8(bytes)
        .map_err(|e| fail(Problem::NotText(e.utf8_error().valid_up_to())))?;
    Ok((parse(&text).map_err(fail)?, reference))
}

/// Parses and validates the text of a level file.
pub fn parse(text: &str) -> Result<Level, Problem> {
    // A byte-order mark (some Windows editors write one) is not part of the document.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(Problem::Empty);
    }
    super::yaml_limits::check(text).map_err(Problem::Parse)?;
    check_header(text)?;
    let file: LevelFile = serde_yaml::from_str(text).map_err(|e| Problem::Parse(e.to_string()))?;
    file.into_level(text)
}

/// The level as the text of a level file (deterministic: same level, same bytes).
pub fn to_string(level: &Level) -> String {
    let file = LevelFile::from_level(level);
    serde_yaml::to_string(&file).expect("a level always serializes")
}

/// Checks `format` and `version` before anything else, so that a file of another kind or
/// version gets that error rather than a confusing one about its fields.
fn check_header(text: &str) -> Result<(), Problem> {
    let document: serde_yaml::Value =
        serde_yaml::from_str(text).map_err(|e| Problem::Parse(format!("invalid YAML: {e}")))?;
    let serde_yaml::Value::Mapping(fields) = document else {
        return Err(Problem::NotALevel(format!(
            "expected a YAML mapping starting with `format: {FORMAT_NAME}`, found {}",
            describe_value(&document)
        )));
    };
    match fields.get("format") {
        Some(serde_yaml::Value::String(name)) if name == FORMAT_NAME => {}
        Some(other) => {
            return Err(Problem::NotALevel(format!(
                "format is {}, expected {FORMAT_NAME}",
                describe_value(other)
            )));
        }
        None => {
            return Err(Problem::NotALevel(format!(
                "missing field `format: {FORMAT_NAME}`"
            )));
        }
    }
    match fields.get("version") {
        Some(serde_yaml::Value::Number(n)) if n.as_u64() == Some(FORMAT_VERSION as u64) => {}
        Some(other) => return Err(Problem::UnsupportedVersion(describe_value(other))),
        None => return Err(Problem::NotALevel("missing field `version`".into())),
    }
    check_counts(&fields, text)?;
    check_source_fields(fields.get("source"), text)
}

/// Lists longer than a level may hold are refused before they are parsed into pieces (a huge
/// list would otherwise be read, and for a road, laid out, first).
fn check_counts(fields: &serde_yaml::Mapping, text: &str) -> Result<(), Problem> {
    for (key, max) in [
        ("blocks", platform::MAX_BLOCKS),
        ("segments", super::racing::MAX_SEGMENTS),
        ("obstacles", super::racing::MAX_OBSTACLES),
    ] {
        if let Some(serde_yaml::Value::Sequence(items)) = fields.get(key)
            && items.len() > max
        {
            return Err(Problem::Invalid {
                field: key.into(),
                line: line_of_key(text, key),
                message: format!(
                    "the level has {} {key}: at most {max} are allowed",
                    items.len()
                ),
            });
        }
    }
    Ok(())
}

/// The fields each `source.kind` needs, named with their path and line (serde's message for a
/// tagged variant has neither).
fn check_source_fields(source: Option<&serde_yaml::Value>, text: &str) -> Result<(), Problem> {
    let Some(serde_yaml::Value::Mapping(source)) = source else {
        return Ok(());
    };
    let needed: &[&str] = match source.get("kind").and_then(|k| k.as_str()) {
        Some("rules" | "racing-rules") => &["rules"],
        Some("policy") => &["generator"],
        Some("kept") => &["pieces", "from", "generator"],
        _ => &[],
    };
    match needed.iter().find(|field| !source.contains_key(**field)) {
        Some(field) => Err(Problem::Invalid {
            field: format!("source.{field}"),
            line: line_of_key(text, "source"),
            message: "missing".into(),
        }),
        None => Ok(()),
    }
}

fn describe_value(value: &serde_yaml::Value) -> String {
    let text = serde_yaml::to_string(value).unwrap_or_default();
    let text = text.trim();
    if text.len() > 40 {
        format!("{}...", &text[..text.floor_char_boundary(40)])
    } else {
        text.to_string()
    }
}

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
struct LevelFile {
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
    #[serde(default)]
    source: Source,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stats: Option<SolverStats>,
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
    fn from_level(level: &Level) -> Self {
        let piece_aux = |i: usize| {
            level
                .pacing
                .as_ref()
                .and_then(|p| p.piece_aux.get(i).copied().flatten())
                .map(Bounded::new)
        };
        let (start, blocks, segments, obstacles) = match &level.track {
            Track::Platform(track) => {
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
            Track::Racing(track) => {
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
            start,
            goal: Some(level.goal.map(Bounded::new)),
            blocks,
            segments,
            obstacles,
            source: level.source.clone(),
            stats: level.stats.clone(),
        }
    }

    fn into_level(self, text: &str) -> Result<Level, Problem> {
        let pacing = self.pacing(text)?;
        let (track, default_goal) = match self.game {
            Game::Platform => self.platform_track(text)?,
            Game::Racing => self.racing_track(text)?,
        };
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
        };
        level.validate().map_err(|e| {
            let key = |key: &str| (key.to_string(), line_of_key(text, key));
            let (field, line) = match &e {
                super::InvalidLevel::Stats(_) => key("stats"),
                super::InvalidLevel::Source(_) => key("source"),
                super::InvalidLevel::NoPieces(what) | super::InvalidLevel::TooMany { what, .. } => {
                    key(what)
                }
                super::InvalidLevel::GoalNotReached { .. }
                | super::InvalidLevel::RoadShort { .. } => key("goal"),
                super::InvalidLevel::Road(_) => key("segments"),
                super::InvalidLevel::Pacing(_) => key("aux_curve"),
                super::InvalidLevel::Obstacle { index, problem } => {
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
    /// file gives none); each block checked with its line.
    fn platform_track(&self, text: &str) -> Result<(Track, [f64; 3]), Problem> {
        if self.segments.is_some() {
            return Err(invalid(
                "segments".into(),
                line_of_key(text, "segments"),
                "a platform level has `blocks`, not `segments`".into(),
            ));
        }
        if !self.obstacles.is_empty() {
            return Err(invalid(
                "obstacles".into(),
                line_of_key(text, "obstacles"),
                "a platform level has no obstacles".into(),
            ));
        }
        let blocks = self.blocks.as_ref().ok_or_else(|| {
            invalid(
                "blocks".into(),
                None,
                "missing: a platform level needs its blocks".into(),
            )
        })?;
        let start = Start {
            position: point(&self.start.position),
            heading: self.start.heading.0,
            size: self.start.size.map_or(Start::default().size, |s| s.0),
        };
        let mut track = PlatformTrack::new(start);
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
                let off = platform::wrap_degrees(heading.0 - placed.heading).abs();
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
        Ok((Track::Platform(track), last))
    }

    /// The racing track the file describes, and where its road ends (the goal when the file
    /// gives none); counts and obstacles checked before any road geometry.
    fn racing_track(&self, text: &str) -> Result<(Track, [f64; 3]), Problem> {
        if self.blocks.is_some() {
            return Err(invalid(
                "blocks".into(),
                line_of_key(text, "blocks"),
                "a racing level has `segments`, not `blocks`".into(),
            ));
        }
        if self.start.size.is_some() {
            return Err(invalid(
                "start.size".into(),
                None,
                "a racing level's start has no size".into(),
            ));
        }
        let segments = self.segments.as_ref().ok_or_else(|| {
            invalid(
                "segments".into(),
                None,
                "missing: a racing level needs its segments".into(),
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
        };
        // Checked here (not only in `validate`) to name the segment's line.
        track.check_geometry().map_err(|e| {
            let index = match e {
                super::road::TrackError::Crosses { later, .. } => later,
                super::road::TrackError::HitsObstacle { segment, .. } => segment,
            };
            invalid(
                format!("segments[{index}]"),
                line_of_item(text, "segments", index),
                e.to_string(),
            )
        })?;
        let (end, _) = track.road().end();
        Ok((Track::Racing(track), end))
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

/// A rule of the level broken at `field` (and `line`, where known).
fn invalid(field: String, line: Option<usize>, message: String) -> Problem {
    Problem::Invalid {
        field,
        line,
        message,
    }
}

/// The 1-based line of a top-level `key:`, if written in block style.
fn line_of_key(text: &str, key: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            l.strip_prefix(key)
                .is_some_and(|rest| rest.starts_with(':'))
        })
        .map(|i| i + 1)
}

/// The 1-based line where item `index` of the top-level sequence `key` starts, if the sequence
/// is written in block style (one `- ` per item, as arlpcg writes it).
fn line_of_item(text: &str, key: &str, index: usize) -> Option<usize> {
    let start = line_of_key(text, key)?;
    let mut item_indent = None;
    let mut seen = 0;
    for (i, line) in text.lines().enumerate().skip(start) {
        let content = line.trim_start();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let indent = line.len() - content.len();
        let is_item = content == "-" || content.starts_with("- ");
        let items_at = *item_indent.get_or_insert(indent);
        if indent < items_at || (indent == 0 && !is_item) {
            return None;
        }
        if is_item && indent == items_at {
            if seen == index {
                return Some(i + 1);
            }
            seen += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const HAND_MADE: &str = "\
format: arlpcg-level
version: 1
game: platform
start: {position: [0, 0, 0], heading: 0}
blocks:
- {distance: 7, angle: 0, size: 5, height: 1}
- {distance: 6, angle: 30, size: 4, height: -1}
";

    #[test]
    fn a_hand_made_level_needs_only_relative_parameters() {
        let level = parse(HAND_MADE).unwrap();
        let track = level.platform().unwrap();
        assert_eq!(track.block_count(), 2);
        assert_eq!(
            level.goal,
            track.last().position.map(params::quantize),
            "the goal defaults to the last block"
        );
        assert_eq!(level.source, Source::Hand);
        // Written back, it reads back to the same level, byte for byte on a second round.
        let text = to_string(&level);
        let again = parse(&text).unwrap();
        assert_eq!(again, level);
        assert_eq!(to_string(&again), text);
    }

    fn problem(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn out_of_range_values_name_field_and_line() {
        let msg = problem(&HAND_MADE.replace("size: 4,", "size: 12,"));
        assert!(
            msg.contains("blocks[1]") && msg.contains("size 12 is out of range [4, 6] m"),
            "{msg}"
        );
        assert!(msg.contains("line 7"), "{msg}");
        let msg = problem(&HAND_MADE.replace("height: 1}", "height: .nan}"));
        assert!(
            msg.contains("blocks[0]: height must be a number, not NaN"),
            "{msg}"
        );
        // In block style too, the item and its line are named.
        let block_style =
            to_string(&parse(HAND_MADE).unwrap()).replacen("size: 5.0", "size: 5.5e3", 1);
        let msg = problem(&block_style);
        assert!(
            msg.contains("blocks[0]: size 5500 is out of range") && msg.contains("line 16"),
            "{msg}"
        );
    }

    #[test]
    fn header_problems_come_first() {
        assert!(problem("").contains("empty"));
        assert!(
            problem(&HAND_MADE.replace("version: 1", "version: 2"))
                .contains("format version 2 is not supported")
        );
        assert!(problem(&HAND_MADE.replace("arlpcg-level", "gltf")).contains("format is gltf"));
        assert!(problem("just some words").contains("not an arlpcg level"));
        assert!(problem("- a\n- list").contains("not an arlpcg level"));
    }

    #[test]
    fn unknown_missing_and_misplaced_fields_are_named() {
        let msg = problem(&HAND_MADE.replace("game: platform", "game: platform\ncolour: red"));
        assert!(msg.contains("unknown field `colour`"), "{msg}");
        let msg = problem(&HAND_MADE.replace("game: platform", "game: chess"));
        assert!(msg.contains("unknown variant `chess`"), "{msg}");
        let msg = problem(&HAND_MADE.replace("size: 5, ", ""));
        assert!(msg.contains("blocks[0]: missing field `size`"), "{msg}");
        let msg = problem(&HAND_MADE.replace("blocks:", "segments:"));
        assert!(msg.contains("segments"), "{msg}");
    }

    #[test]
    fn overlaps_moved_transforms_and_unreached_goals_are_caught() {
        let overlap = HAND_MADE.replace(
            "{distance: 6, angle: 30, size: 4, height: -1}",
            "{distance: 7, angle: 180, size: 4, height: -1}",
        );
        let msg = problem(&overlap);
        assert!(
            msg.contains("blocks[1]: block 1 overlaps the start block (line 7)"),
            "{msg}"
        );
        let moved = HAND_MADE.replace("height: 1}", "height: 1, position: [7, 1, 3]}");
        assert!(problem(&moved).contains("blocks[0].position"));
        let far_goal = format!("{HAND_MADE}goal: [100, 0, 0]\n");
        assert!(problem(&far_goal).contains("does not reach the goal"));
    }

    #[test]
    fn line_of_item_finds_block_style_items() {
        let text = "a: 1\nblocks:\n  - x: 1\n    y: 2\n  - x: 3\nsource:\n  kind: hand\n";
        assert_eq!(line_of_item(text, "blocks", 0), Some(3));
        assert_eq!(line_of_item(text, "blocks", 1), Some(5));
        assert_eq!(line_of_item(text, "blocks", 2), None);
    }
}
