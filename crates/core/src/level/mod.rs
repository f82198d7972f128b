//! Levels as pure data: what a Generator (or the rules, or a designer's hand) built, where it came
//! from, and what the Solver measured on it. Files in and out live in [`yaml`] and [`gltf`];
//! nothing here touches the disk.

pub mod gltf;
pub mod heading;
pub mod pacing;
pub mod params;
pub mod platform;
pub mod profile;
pub mod racing;
pub mod road;
pub mod scene;
pub mod stats;
pub mod yaml;
pub mod yaml_limits;

use std::fmt;

use serde::{Deserialize, Serialize};

pub use platform::{BlockParams, Platform, PlatformTrack, Start};
pub use racing::{Obstacle, RacingTrack, SegmentParams};
pub use stats::{SolverRef, SolverStats};

/// The games: the paper's two, and (built with the `test-game` feature, for the tests alone) a
/// third that proves a game plugs in. Each is a [`GameSpec`](../game/trait.GameSpec.html) in
/// its own folder under `game/`, and `game::for_game!` turns a `Game` into its type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Game {
    /// Jump across blocks to the goal block (the game a command plays when none is named).
    #[default]
    Platform,
    /// Drive a banked road to the goal.
    Racing,
    /// Roll a ball across blocks to the goal block (tests only).
    #[cfg(feature = "test-game")]
    Ball,
}

impl Game {
    /// Every game, in the order lists and the designer's Tab go through them.
    pub const ALL: [Game; Game::COUNT] = [
        Game::Platform,
        Game::Racing,
        #[cfg(feature = "test-game")]
        Game::Ball,
    ];

    /// How many games there are.
    pub const COUNT: usize = if cfg!(feature = "test-game") { 3 } else { 2 };

    /// The game's name, as files and the command line write it (`platform`, `racing`).
    pub fn name(self) -> &'static str {
        match self {
            Game::Platform => "platform",
            Game::Racing => "racing",
            #[cfg(feature = "test-game")]
            Game::Ball => "ball",
        }
    }

    /// What the game's levels are built from.
    pub fn shape(self) -> ShapeKind {
        match self {
            Game::Platform => ShapeKind::Blocks,
            Game::Racing => ShapeKind::Road,
            #[cfg(feature = "test-game")]
            Game::Ball => ShapeKind::Blocks,
        }
    }

    /// Who plays it: what a profile's abilities describe.
    pub fn player(self) -> PlayerKind {
        match self {
            Game::Platform => PlayerKind::Character,
            Game::Racing => PlayerKind::Car,
            #[cfg(feature = "test-game")]
            Game::Ball => PlayerKind::Character,
        }
    }

    /// The game after this one in [`Game::ALL`], the first after the last.
    pub fn next(self) -> Game {
        let k = Game::ALL.iter().position(|g| *g == self).unwrap_or(0);
        Game::ALL[(k + 1) % Game::ALL.len()]
    }

    /// Where this game stands in [`Game::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// One value per game, indexed by [`Game`] (the designer's loaded policies and profile of each).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PerGame<T>([T; Game::COUNT]);

impl<T> PerGame<T> {
    /// Each game's value, made by `make`.
    pub fn from_fn(mut make: impl FnMut(Game) -> T) -> Self {
        Self(std::array::from_fn(|k| make(Game::ALL[k])))
    }
}

impl<T> std::ops::Index<Game> for PerGame<T> {
    type Output = T;
    fn index(&self, game: Game) -> &T {
        &self.0[game.index()]
    }
}

impl<T> std::ops::IndexMut<Game> for PerGame<T> {
    fn index_mut(&mut self, game: Game) -> &mut T {
        &mut self.0[game.index()]
    }
}

impl std::str::FromStr for Game {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Game::ALL
            .into_iter()
            .find(|game| game.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown game `{s}`: expected {}",
                    Game::ALL.map(Game::name).join(" or ")
                )
            })
    }
}

impl fmt::Display for Game {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The pieces of a level, one variant per game: the variant names the game that plays it.
#[derive(Debug, Clone, PartialEq)]
pub enum Track {
    /// A platform level's blocks.
    Platform(PlatformTrack),
    /// A racing level's road and obstacles.
    Racing(RacingTrack),
    /// A ball level's blocks (the tests' third game).
    #[cfg(feature = "test-game")]
    Ball(PlatformTrack),
}

/// What a level's pieces are, whichever game plays them: what the level's checks, its file,
/// its scene and the designer's drawing read, so that a game whose levels are built from pieces
/// another game has needs no more of them than a [`Track`] variant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape<'a> {
    /// Blocks to cross, from a start block to a goal block.
    Blocks(&'a PlatformTrack),
    /// A road of segments, with obstacles beside it.
    Road(&'a RacingTrack),
}

/// The kind of a [`Shape`]: what a profile's piece ranges describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeKind {
    /// Blocks to land on (platform, ball).
    Blocks,
    /// A road of segments, with obstacles (racing).
    Road,
}

impl ShapeKind {
    /// The style knobs a level of this shape may record (`knobs:`), as its games' Generators
    /// name them (`GeneratorGame::KNOBS`).
    pub fn knobs(self) -> &'static [&'static str] {
        match self {
            ShapeKind::Blocks => &platform::BLOCK_KNOBS,
            ShapeKind::Road => &racing::ROAD_KNOBS,
        }
    }
}

/// Who plays a game: what a profile's abilities describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlayerKind {
    /// Runs and jumps (`character:` in a profile).
    Character,
    /// Drives (`car:`).
    Car,
}

impl Track {
    /// What the pieces are.
    pub fn shape(&self) -> Shape<'_> {
        match self {
            Track::Platform(track) => Shape::Blocks(track),
            Track::Racing(track) => Shape::Road(track),
            #[cfg(feature = "test-game")]
            Track::Ball(track) => Shape::Blocks(track),
        }
    }

    /// The game that plays it.
    pub fn game(&self) -> Game {
        match self {
            Track::Platform(_) => Game::Platform,
            Track::Racing(_) => Game::Racing,
            #[cfg(feature = "test-game")]
            Track::Ball(_) => Game::Ball,
        }
    }

    /// `game`'s track of `blocks`; none for a game of another [`ShapeKind`].
    pub fn of_blocks(game: Game, blocks: PlatformTrack) -> Option<Track> {
        match game {
            Game::Platform => Some(Track::Platform(blocks)),
            #[cfg(feature = "test-game")]
            Game::Ball => Some(Track::Ball(blocks)),
            Game::Racing => None,
        }
    }

    /// `game`'s track of `road`; none for a game of another [`ShapeKind`].
    pub fn of_road(game: Game, road: RacingTrack) -> Option<Track> {
        match game {
            Game::Racing => Some(Track::Racing(road)),
            _ => None,
        }
    }
}

/// A file a level depends on (a trained policy, or the level a prefix was kept from), pinned by
/// the hash of its contents.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyRef {
    /// The policy file's path, as written.
    pub path: String,
    /// The SHA-256 of the file's contents, lowercase hex.
    pub sha256: String,
}

impl PolicyRef {
    /// The file at `path` whose contents are `bytes`.
    pub fn pinned(path: String, bytes: &[u8]) -> Self {
        Self {
            path,
            sha256: sha256_hex(bytes),
        }
    }
}

/// The SHA-256 of `bytes`, as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The settings of the rule-based generator (the paper's Rule-PCG baseline).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlatformRulesConfig {
    /// Give up on a level (and draw another) after this many blocks without reaching the goal.
    pub max_blocks: u32,
    /// Each block's heading is drawn within this many degrees either side of the goal direction.
    pub angle_spread: f64,
    /// Jumps are kept this many metres shorter than the character's longest jump at that height.
    pub reach_margin: f64,
}

impl PlatformRulesConfig {
    /// Checks each setting's range (NaN fails): `Err("field: what it must be")`.
    pub fn check(&self) -> Result<(), String> {
        if !(1..=platform::MAX_BLOCKS as u32).contains(&self.max_blocks) {
            return Err(format!(
                "max_blocks {} must be within [1, {}]",
                self.max_blocks,
                platform::MAX_BLOCKS
            ));
        }
        if !(0.0..=180.0).contains(&self.angle_spread) {
            return Err(format!(
                "angle_spread {} must be a number of degrees within [0, 180]",
                params::show_number(self.angle_spread)
            ));
        }
        if !(0.0..=MAX_REACH_MARGIN).contains(&self.reach_margin) {
            return Err(format!(
                "reach_margin {} must be a number of metres within [0, {MAX_REACH_MARGIN}]",
                params::show_number(self.reach_margin)
            ));
        }
        Ok(())
    }
}

/// The largest `reach_margin` (metres): beyond it few jumps remain possible.
pub const MAX_REACH_MARGIN: f64 = 3.0;

impl Default for PlatformRulesConfig {
    fn default() -> Self {
        Self {
            max_blocks: 40,
            angle_spread: 60.0,
            reach_margin: 0.5,
        }
    }
}

/// Where a level came from.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Source {
    /// Written by hand (the default for files that say nothing).
    #[default]
    Hand,
    /// Drawn by the rule-based platform generator.
    Rules {
        /// The rule generator's settings the level was drawn with.
        rules: PlatformRulesConfig,
    },
    /// Drawn by the rule-based racing generator.
    #[serde(rename = "racing-rules")]
    RacingRules {
        /// The rule generator's settings the level was drawn with.
        rules: racing::RacingRulesConfig,
    },
    /// Built by a trained Generator policy.
    Policy {
        /// The Generator policy that built it.
        generator: PolicyRef,
    },
    /// The first `pieces` pieces kept from the level file `from`, the rest built by a trained
    /// Generator (`generate --keep`); `aux` or `aux_curve` is the λ of the rest.
    Kept {
        /// How many pieces were kept from `from`.
        pieces: u32,
        /// The level file the pieces were kept from.
        from: PolicyRef,
        /// The Generator policy that built the rest.
        generator: PolicyRef,
    },
}

impl Source {
    /// How many pieces were kept from another level (0 unless [`Source::Kept`]).
    pub fn kept_pieces(&self) -> usize {
        match self {
            Source::Kept { pieces, .. } => *pieces as usize,
            _ => 0,
        }
    }
}

/// The name of the knobs' part of a Generator's observation (after the game's, before the
/// abilities of an ability-aware one), as its card lists it.
pub const KNOBS_PART: &str = "knobs";

/// A level of either game.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    /// The seed it was generated from (none for hand-made levels).
    pub seed: Option<u64>,
    /// The aux input λ it was generated with (+1 easy, -1 hard).
    pub aux: Option<f64>,
    /// The point the track leads to.
    pub goal: [f64; 3],
    /// The level's pieces.
    pub track: Track,
    /// Where the level came from: by hand, rules or a Generator policy.
    pub source: Source,
    /// What the Solver measured on it, when it has been verified.
    pub stats: Option<SolverStats>,
    /// λ along the level, when it was built with an aux curve (then `aux` is none).
    pub pacing: Option<pacing::Pacing>,
    /// The game profile it was made and verified under; none for the built-in one.
    pub profile: Option<crate::level::profile::Profile>,
    /// The style knobs it was built with, by name, each in [-1, 1] (none: no preference).
    pub knobs: std::collections::BTreeMap<String, f64>,
    /// The wish list it was searched to meet (`generate --want`), with what was measured.
    pub want: Option<WantRecord>,
}

/// What a level was searched to meet (`generate --want`, `--ask`): the wish list as it was
/// read, the draw of its seed that met it, how many candidates were tried, and the value each
/// constraint measured on the kept level (src/services/wish defines the attributes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WantRecord {
    /// The wish list, in the form `generate --want` reads.
    pub asked: String,
    /// The draw of the level's seed that was kept.
    pub draw: u32,
    /// Candidates built (draws × λ) before this one met every constraint, this one included.
    pub tried: u32,
    /// Each constraint with the value it measured.
    pub measured: Vec<MeasuredConstraint>,
}

/// One constraint of a [`WantRecord`] and its value on the level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredConstraint {
    /// The constraint, as written (`climb >= 6`).
    pub constraint: String,
    /// Its attribute's value on the level.
    pub value: f64,
}

/// Straight-line distance between two points, m.
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// A level that breaks a rule of its game.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InvalidLevel {
    /// The level has no pieces of the named kind (`blocks`, `segments`).
    #[error("the level has no {0}: it needs at least one")]
    NoPieces(&'static str),
    /// The last block is out of the goal's reach.
    #[error(
        "the last block (at {at:?}) does not reach the goal {goal:?}: it must be within {h} m horizontally and {v} m vertically",
        h = platform::GOAL_REACH_HORIZONTAL,
        v = platform::GOAL_REACH_VERTICAL
    )]
    GoalNotReached {
        /// The last block's position, m.
        at: [f64; 3],
        /// The goal, m.
        goal: [f64; 3],
    },
    /// The road ends out of the goal's reach.
    #[error(
        "the road ends at {at:?}, which does not reach the goal {goal:?}: it must end within {h} m horizontally and {v} m vertically",
        h = racing::GOAL_REACH_HORIZONTAL,
        v = racing::GOAL_REACH_VERTICAL
    )]
    RoadShort {
        /// Where the road ends, m.
        at: [f64; 3],
        /// The goal, m.
        goal: [f64; 3],
    },
    /// The road's geometry breaks a rule.
    #[error("{0}")]
    Road(#[from] road::TrackError),
    /// More pieces of a kind than the game allows.
    #[error("the level has {count} {what}: at most {max} are allowed")]
    TooMany {
        /// The kind of piece (`segments`, `obstacles`).
        what: &'static str,
        /// How many the level has.
        count: usize,
        /// The most allowed.
        max: usize,
    },
    /// An obstacle breaks a rule.
    #[error("obstacles[{index}].{problem}")]
    Obstacle {
        /// The obstacle's index in the level's list.
        index: usize,
        /// Which field is wrong, and why.
        problem: String,
    },
    /// The level's statistics do not fit its track.
    #[error("{0}")]
    Stats(String),
    /// The level's wish-list record holds a value that is not a number.
    #[error("{0}")]
    Want(String),
    /// The level's source does not fit the level (wrong rules kind, more kept pieces than it has,
    /// bad rule settings).
    #[error("{0}")]
    Source(String),
    /// The level's aux curve is wrong, or the level has both a λ and a curve.
    #[error("{0}")]
    Pacing(String),
    /// The level records a knob its game's Generators do not take.
    #[error("`{name}` is not a knob of a {game} level (its knobs: {known})")]
    UnknownKnob {
        /// The name recorded.
        name: String,
        /// The level's game.
        game: Game,
        /// The knobs it may record.
        known: String,
    },
}

impl Level {
    /// The game that plays this level.
    pub fn game(&self) -> Game {
        self.track.game()
    }

    /// What the level's pieces are.
    pub fn shape(&self) -> Shape<'_> {
        self.track.shape()
    }

    /// The level's style, one value in [-1, 1] per knob of its shape ([`ShapeKind::knobs`]),
    /// measured within the piece ranges of the profile it was made under (its game's built-in
    /// ones without one): see [`profile::Pieces::style`].
    pub fn style(&self) -> Vec<f64> {
        let pieces = self.profile.as_ref().map_or_else(
            || profile::Pieces::default_of(self.game()),
            |profile| profile.pieces,
        );
        pieces.style(self.shape())
    }

    /// The platform track, if this is a platform level.
    pub fn platform(&self) -> Option<&PlatformTrack> {
        match &self.track {
            Track::Platform(track) => Some(track),
            _ => None,
        }
    }

    /// The racing track, if this is a racing level.
    pub fn racing(&self) -> Option<&racing::RacingTrack> {
        match &self.track {
            Track::Racing(track) => Some(track),
            _ => None,
        }
    }

    /// How many pieces (blocks or segments) the level has.
    pub fn piece_count(&self) -> usize {
        match self.shape() {
            Shape::Blocks(track) => track.block_count(),
            Shape::Road(track) => track.segments.len(),
        }
    }

    /// Where each piece begins, as the fraction of the start-to-goal distance covered there
    /// (straight-line distances to the goal, 0 at the start): where an aux curve is read.
    pub fn piece_start_fractions(&self) -> Vec<f64> {
        let starts: Vec<[f64; 3]> = match self.shape() {
            Shape::Blocks(track) => track.platforms()[..track.block_count()]
                .iter()
                .map(|p| p.position)
                .collect(),
            Shape::Road(track) => {
                let road = track.road();
                (0..track.segments.len())
                    .map(|i| match i {
                        0 => track.position,
                        i => road.samples()[road.nearest_along(road.segment_start(i))].centre,
                    })
                    .collect()
            }
        };
        let whole = starts.first().map_or(0.0, |&s| distance(s, self.goal));
        starts
            .iter()
            .map(|&s| pacing::covered(whole, distance(s, self.goal)))
            .collect()
    }

    /// Checks the rules that span the whole level (ranges and overlaps are checked as pieces are
    /// built): the track reaches its goal and the statistics fit the track.
    pub fn validate(&self) -> Result<(), InvalidLevel> {
        match self.shape() {
            Shape::Blocks(track) => {
                if track.block_count() == 0 {
                    return Err(InvalidLevel::NoPieces("blocks"));
                }
                let last = track.last();
                if !last.reaches(self.goal) {
                    return Err(InvalidLevel::GoalNotReached {
                        at: last.position,
                        goal: self.goal,
                    });
                }
            }
            Shape::Road(track) => {
                if track.segments.is_empty() {
                    return Err(InvalidLevel::NoPieces("segments"));
                }
                let too_many = |what, count, max| {
                    (count > max).then_some(InvalidLevel::TooMany { what, count, max })
                };
                if let Some(e) = too_many("segments", track.segments.len(), racing::MAX_SEGMENTS)
                    .or_else(|| too_many("obstacles", track.obstacles.len(), racing::MAX_OBSTACLES))
                {
                    return Err(e);
                }
                for (index, obstacle) in track.obstacles.iter().enumerate() {
                    obstacle
                        .check()
                        .map_err(|problem| InvalidLevel::Obstacle { index, problem })?;
                }
                track.check_geometry()?;
                let (end, _) = track.road().end();
                if !racing::reaches(end, self.goal) {
                    return Err(InvalidLevel::RoadShort {
                        at: end.map(params::quantize),
                        goal: self.goal,
                    });
                }
            }
        }
        match (&self.source, self.game().shape()) {
            (Source::Rules { rules }, ShapeKind::Blocks) => rules.check(),
            (Source::RacingRules { rules }, ShapeKind::Road) => rules.check(),
            (Source::Rules { .. }, ShapeKind::Road) => {
                Err("kind `rules` is for platform levels (blocks); racing levels (road) use `racing-rules`".into())
            }
            (Source::RacingRules { .. }, ShapeKind::Blocks) => {
                Err("kind `racing-rules` is for racing levels (road); platform levels (blocks) use `rules`".into())
            }
            (Source::Kept { pieces, .. }, _) if *pieces as usize > self.piece_count() => {
                return Err(InvalidLevel::Source(format!(
                    "pieces: {pieces} kept, but the level has {} pieces",
                    self.piece_count()
                )));
            }
            _ => Ok(()),
        }
        .map_err(|problem| InvalidLevel::Source(format!("rules.{problem}")))?;
        if let Some(stats) = &self.stats {
            stats
                .check(self.piece_count())
                .map_err(InvalidLevel::Stats)?;
        }
        if let Some(want) = &self.want
            && let Some(bad) = want.measured.iter().find(|m| !m.value.is_finite())
        {
            return Err(InvalidLevel::Want(format!(
                "`{}` measured {}: a measured value must be a finite number",
                bad.constraint, bad.value
            )));
        }
        if let Some(pacing) = &self.pacing {
            if self.aux.is_some() {
                return Err(InvalidLevel::Pacing(
                    "a level has one λ (`aux`) or a curve (`aux_curve`), not both".into(),
                ));
            }
            pacing
                .check(self.piece_count(), self.source.kept_pieces())
                .map_err(InvalidLevel::Pacing)?;
        }
        let known = self.game().shape().knobs();
        if let Some(name) = self.knobs.keys().find(|k| !known.contains(&k.as_str())) {
            return Err(InvalidLevel::UnknownKnob {
                name: name.clone(),
                game: self.game(),
                known: known.join(", "),
            });
        }
        Ok(())
    }
}
