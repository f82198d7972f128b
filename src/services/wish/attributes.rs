//! What a wish list can speak of: each attribute's name, unit, the games (by the shape of their
//! pieces) that have it, the values it can take, what it reads (the pieces, one player's runs or
//! the panel's) and how it is measured. `generate --want` searches with these measures,
//! `verify --check` and campaigns check with them, the level file records them: one
//! definition each (docs/wish.md lists them).

use std::fmt;

use crate::services::panel::Judge;
use arlpcg_core::level::stats::{PanelStats, Rating, SolverStats};
use arlpcg_core::level::{Level, Shape, ShapeKind};

/// One measurable attribute of a level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Attribute {
    /// Pieces (blocks or segments).
    Pieces,
    /// The way along the pieces, m: blocks' centre-to-centre distances, or the road's length.
    Length,
    /// Height gained over the pieces, m: the sum of every rise.
    Climb,
    /// Height lost over the pieces, m: the sum of every fall.
    Drop,
    /// Blocks: the longest centre-to-centre distance from one block to the next, m.
    Jump,
    /// Road: the sharpest heading change of one segment, degrees (either way).
    Curve,
    /// Road: decisions per run with the car in the air, the mean of the verifying runs.
    Air,
    /// Where the piece most runs failed on lies along the way: 0 the first piece, 1 the last
    /// (its index over the pieces after the first).
    Hardest,
    /// The verifying player's success ratio, or a panel judge's.
    Success(Option<Judge>),
    /// The panel's difficulty rating b, logits.
    B,
    /// Some run completed the level (no range).
    Completed,
    /// A style knob's measure over the pieces, in [-1, 1] (`Level::style`).
    Knob(&'static str),
}

/// What an attribute reads besides the level's pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Reads {
    /// The pieces alone: known as soon as the level is built.
    Pieces,
    /// The runs of the player that verifies the level (or of one judge).
    Runs,
    /// The panel's rating.
    Panel,
}

/// The attributes every game has, by name, in the order docs/wish.md lists them.
const COMMON: [(&str, Attribute); 7] = [
    ("pieces", Attribute::Pieces),
    ("length", Attribute::Length),
    ("climb", Attribute::Climb),
    ("drop", Attribute::Drop),
    ("hardest", Attribute::Hardest),
    ("success", Attribute::Success(None)),
    ("b", Attribute::B),
];

impl Attribute {
    /// The attribute called `name` in a `shape` game, or an error naming the ones it has.
    pub fn named(name: &str, shape: ShapeKind) -> Result<Attribute, String> {
        Self::all(shape)
            .into_iter()
            .find(|a| a.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::all(shape).iter().map(Attribute::name).collect();
                format!(
                    "`{name}` is not an attribute of these levels; theirs are {}",
                    names.join(", ")
                )
            })
    }

    /// The attribute called `name` in some game (see [`crate::services::wish::Want::fit`]).
    pub fn named_in_any(name: &str) -> Result<Attribute, String> {
        let all = Self::all_shapes();
        all.iter()
            .find(|a| a.name() == name)
            .copied()
            .ok_or_else(|| {
                let mut unique = Vec::new();
                for n in all.iter().map(Attribute::name) {
                    if !unique.contains(&n) {
                        unique.push(n);
                    }
                }
                format!(
                    "`{name}` is not an attribute; the attributes are {}",
                    unique.join(", ")
                )
            })
    }

    /// Every attribute of a `shape` game (`success` for the verifying player).
    pub fn all(shape: ShapeKind) -> Vec<Attribute> {
        let mut all: Vec<Attribute> = COMMON.iter().map(|(_, a)| *a).collect();
        all.push(Attribute::Completed);
        match shape {
            ShapeKind::Blocks => all.push(Attribute::Jump),
            ShapeKind::Road => all.extend([Attribute::Curve, Attribute::Air]),
        }
        all.extend(shape.knobs().iter().map(|&k| Attribute::Knob(k)));
        all
    }

    fn all_shapes() -> Vec<Attribute> {
        let mut all = Self::all(ShapeKind::Blocks);
        all.extend(Self::all(ShapeKind::Road));
        all
    }

    /// Its name in a wish list.
    pub fn name(&self) -> &'static str {
        match self {
            Attribute::Pieces => "pieces",
            Attribute::Length => "length",
            Attribute::Climb => "climb",
            Attribute::Drop => "drop",
            Attribute::Jump => "jump",
            Attribute::Curve => "curve",
            Attribute::Air => "air",
            Attribute::Hardest => "hardest",
            Attribute::Success(_) => "success",
            Attribute::B => "b",
            Attribute::Completed => "completed",
            Attribute::Knob(name) => name,
        }
    }

    /// The profile field (`arlpcg profile init`) that holds every piece's value of it at most a
    /// bound: the jump at `blocks.max_distance`, the curve at `segments.max_curve`.
    pub fn profile_bound(&self) -> Option<&'static str> {
        match self {
            Attribute::Jump => Some("blocks.max_distance"),
            Attribute::Curve => Some("segments.max_curve"),
            _ => None,
        }
    }

    /// What it reads besides the pieces.
    pub fn reads(&self) -> Reads {
        match self {
            Attribute::Air | Attribute::Hardest | Attribute::Success(_) | Attribute::Completed => {
                Reads::Runs
            }
            Attribute::B => Reads::Panel,
            _ => Reads::Pieces,
        }
    }

    /// The values it can take: a range beyond them asks the impossible.
    pub fn domain(&self) -> (f64, f64) {
        match self {
            Attribute::Pieces | Attribute::Length | Attribute::Climb | Attribute::Drop => {
                (0.0, f64::INFINITY)
            }
            Attribute::Jump | Attribute::Air => (0.0, f64::INFINITY),
            Attribute::Curve => (0.0, 180.0),
            Attribute::Hardest | Attribute::Success(_) | Attribute::Completed => (0.0, 1.0),
            Attribute::B => (f64::NEG_INFINITY, f64::INFINITY),
            Attribute::Knob(_) => (-1.0, 1.0),
        }
    }

    /// How far apart two values of it are, for naming the closest miss: 1 unit of the
    /// attribute, or the span of a bounded one.
    pub fn scale(&self) -> f64 {
        match self.domain() {
            (low, high) if (high - low).is_finite() => high - low,
            _ => match self {
                Attribute::Pieces | Attribute::Climb | Attribute::Drop | Attribute::Jump => 1.0,
                Attribute::B => 1.0,
                _ => 10.0,
            },
        }
    }

    /// Its unit, as a measured value is shown.
    pub fn unit(&self) -> &'static str {
        match self {
            Attribute::Length | Attribute::Climb | Attribute::Drop | Attribute::Jump => " m",
            Attribute::Curve => "°",
            _ => "",
        }
    }

    /// Its value on `level`, with `evidence` for what it reads of runs and the panel; an
    /// error says what the level lacks for it.
    pub fn value(&self, level: &Level, evidence: &Evidence) -> Result<f64, String> {
        let rises = || -> Vec<f64> {
            match level.shape() {
                Shape::Blocks(track) => track.block_params().iter().map(|b| b.height).collect(),
                Shape::Road(track) => track.segments.iter().map(|s| s.height).collect(),
            }
        };
        match self {
            Attribute::Pieces => Ok(level.piece_count() as f64),
            Attribute::Length => Ok(match level.shape() {
                Shape::Blocks(track) => track.block_params().iter().map(|b| b.distance).sum(),
                Shape::Road(track) => track.segments.iter().map(|s| s.length).sum(),
            }),
            Attribute::Climb => Ok(rises().iter().filter(|h| **h > 0.0).sum()),
            Attribute::Drop => Ok(-rises().iter().filter(|h| **h < 0.0).sum::<f64>()),
            Attribute::Jump => match level.shape() {
                Shape::Blocks(track) => Ok(track
                    .block_params()
                    .iter()
                    .map(|b| b.distance)
                    .fold(0.0, f64::max)),
                Shape::Road(_) => Err("a road has no jumps".into()),
            },
            Attribute::Curve => match level.shape() {
                Shape::Road(track) => Ok(track
                    .segments
                    .iter()
                    .map(|s| s.curve.abs())
                    .fold(0.0, f64::max)),
                Shape::Blocks(_) => Err("blocks have no curves".into()),
            },
            Attribute::Knob(name) => {
                let index = level.game().shape().knobs().iter().position(|k| k == name);
                index
                    .and_then(|i| level.style().get(i).copied())
                    .ok_or_else(|| format!("these levels have no knob {name}"))
            }
            Attribute::Air => evidence
                .runs()?
                .mean_air_steps
                .ok_or_else(|| "its runs measured no air time".into()),
            Attribute::Hardest => hardest(level, evidence.runs()?),
            Attribute::Success(None) => Ok(evidence.runs()?.success_ratio),
            Attribute::Success(Some(judge)) => evidence.judge(*judge).map(|(ratio, _)| ratio),
            Attribute::Completed => Ok(f64::from(evidence.runs()?.successes > 0)),
            Attribute::B => evidence
                .rating()
                .map(|r| r.b)
                .ok_or_else(|| "the level has no panel rating (play it with --panel)".into()),
        }
    }

    /// The 95% interval of its value, for the attributes measured by a finite number of runs
    /// (success) or fitted (b); none for the others.
    pub fn interval(&self, evidence: &Evidence) -> Option<[f64; 2]> {
        match self {
            Attribute::Success(None) => evidence.stats.map(|s| s.ci95),
            Attribute::Success(Some(judge)) => evidence.judge(*judge).ok().map(|(_, ci)| ci),
            Attribute::B => evidence.rating().map(|r| r.ci95),
            _ => None,
        }
    }
}

impl fmt::Display for Attribute {
    /// The name, and `for JUDGE` of a judge's success.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Attribute::Success(Some(judge)) => write!(f, "success for {}", judge.name()),
            other => f.write_str(other.name()),
        }
    }
}

/// Where the piece most runs failed on lies, 0 the first piece and 1 the last (the first such
/// piece on a tie); an error when no run failed.
fn hardest(level: &Level, stats: &SolverStats) -> Result<f64, String> {
    let failures = &stats.failures_by_piece;
    let most = failures.iter().copied().max().unwrap_or(0);
    if most == 0 {
        return Err("no run failed on any piece".into());
    }
    let piece = failures.iter().position(|&f| f == most).unwrap_or(0);
    let last = level.piece_count().saturating_sub(1);
    Ok(match last {
        0 => 1.0,
        last => piece as f64 / last as f64,
    })
}

/// What a level's checks read besides its pieces: one player's runs and the panel's.
#[derive(Debug, Clone, Copy, Default)]
pub struct Evidence<'a> {
    /// The runs of the player that verified the level.
    pub stats: Option<&'a SolverStats>,
    /// The panel's runs and rating.
    pub panel: Option<&'a PanelStats>,
    /// Runs of judges played for a wish list's `success for JUDGE` (read before the panel's).
    pub judges: &'a [(Judge, SolverStats)],
}

impl<'a> Evidence<'a> {
    /// What `level` records: its statistics and their panel's.
    pub fn of(level: &'a Level) -> Self {
        let stats = level.stats.as_ref();
        Evidence {
            stats,
            panel: stats.and_then(|s| s.panel.as_ref()),
            judges: &[],
        }
    }

    fn runs(&self) -> Result<&'a SolverStats, String> {
        self.stats
            .ok_or_else(|| "the level was not verified (its runs are missing)".into())
    }

    fn rating(&self) -> Option<Rating> {
        self.panel.and_then(|p| p.rating)
    }

    /// `judge`'s success ratio and its 95% interval, from its runs.
    fn judge(&self, judge: Judge) -> Result<(f64, [f64; 2]), String> {
        if let Some((_, stats)) = self.judges.iter().find(|(j, _)| *j == judge) {
            return Ok((stats.success_ratio, stats.ci95));
        }
        let name = judge.name();
        self.panel
            .and_then(|p| p.judges.iter().find(|j| j.judge == name))
            .map(|j| (j.success_ratio, j.ci95))
            .ok_or_else(|| format!("the level has no runs of {name} (play it with --panel)"))
    }
}
