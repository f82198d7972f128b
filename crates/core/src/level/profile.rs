//! A game profile: the abilities of the player's character (platform) or car (racing), and the
//! ranges its level pieces are drawn from, as a versioned file (`format: arlpcg-profile`), so
//! that levels are made and checked for a designer's own game rather than ours. The built-in default is today's game: a level without a profile is
//! played exactly as before, and a level made under another profile records it in full (name,
//! SHA-256 of its values, and the values), so that it is verified under the same abilities.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::level::Game;
use crate::level::params::{self, ParamRange, RangeError};
use crate::level::racing::{self, RoadShape};

/// The `format:` of a profile file.
pub const FORMAT: &str = "arlpcg-profile";
/// The version this build reads and writes.
pub const VERSION: u32 = 1;
/// The name of the built-in profile.
pub const DEFAULT_NAME: &str = "default";

/// The platform character's abilities.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CharacterProfile {
    /// Top horizontal speed, m/s.
    pub run_speed: f64,
    /// Vertical take-off speed of a jump, m/s.
    pub jump_speed: f64,
    /// Gravity, m/s².
    pub gravity: f64,
    /// Horizontal acceleration toward the commanded velocity on the ground, m/s².
    pub ground_accel: f64,
    /// Horizontal acceleration in the air (air control), m/s².
    pub air_accel: f64,
    /// Fastest turn, degrees per second.
    pub turn_rate: f64,
    /// Capsule radius, m.
    pub radius: f64,
    /// Capsule height, m (at least twice the radius).
    pub height: f64,
}

/// The racing car's abilities.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CarProfile {
    /// Total engine force at full throttle, N.
    pub engine_force: f64,
    /// Chassis mass, kg.
    pub mass: f64,
    /// Tyre grip (friction coefficient).
    pub grip: f64,
    /// Front wheels' steering at full lock, radians.
    pub max_steer: f64,
    /// Air and rolling drag, per second (with the engine it sets the top speed).
    pub damping: f64,
}

/// The ranges a platform level's blocks are drawn from, by the rules and the Generator; each
/// within the level format's own (`level::params`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockRanges {
    /// Shortest and longest centre-to-centre distance from the previous block, m.
    pub min_distance: f64,
    pub max_distance: f64,
    /// Smallest and largest side of a block's top, m.
    pub min_size: f64,
    pub max_size: f64,
    /// Largest drop (negative) and climb from the previous block, m.
    pub min_height: f64,
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

/// A profile file: which game, a name, that game's abilities and (optionally) its pieces'
/// ranges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileFile {
    pub format: String,
    pub version: u32,
    pub game: Game,
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<CharacterProfile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub car: Option<CarProfile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<BlockRanges>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<SegmentRanges>,
}

/// One game's abilities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Abilities {
    Platform(CharacterProfile),
    Racing(CarProfile),
}

/// One game's piece ranges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pieces {
    Platform(BlockRanges),
    Racing(SegmentRanges),
}

/// A checked profile: its name, abilities and piece ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub name: String,
    pub abilities: Abilities,
    pub pieces: Pieces,
}

/// How a level records the profile it was made under (`profile:` in a level file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileRecord {
    pub name: String,
    /// SHA-256 of the profile's values as [`Profile::to_yaml`] writes them.
    pub sha256: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<CharacterProfile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub car: Option<CarProfile>,
    /// The piece ranges, when they are not the built-in ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<BlockRanges>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<SegmentRanges>,
}

impl Default for CharacterProfile {
    /// Today's character (src/game/platform/character.rs; docs/platform-physics.md).
    fn default() -> Self {
        Self {
            run_speed: 8.0,
            jump_speed: 9.25,
            gravity: 20.0,
            ground_accel: 60.0,
            air_accel: 6.0,
            turn_rate: 270.0,
            radius: 0.4,
            height: 1.8,
        }
    }
}

impl Default for CarProfile {
    /// Today's car (docs/racing-physics.md).
    fn default() -> Self {
        Self {
            engine_force: 7200.0,
            mass: 1200.0,
            grip: 0.9,
            max_steer: 0.5,
            damping: 0.21,
        }
    }
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

/// A field: its range (name, bounds, unit) and what it is, as `profile init` comments it.
const fn field(
    name: &'static str,
    min: f64,
    max: f64,
    unit: &'static str,
    what: &'static str,
) -> (ParamRange, &'static str) {
    (ParamRange::new(name, min, max, unit), what)
}

/// The observation part an ability-aware Solver's observation ends with: the game's
/// [`main_abilities`] relative to ours.
pub const ABILITIES_PART: &str = "abilities";

/// How many main abilities each game has.
pub const MAIN_ABILITIES: usize = 3;

/// How many ability columns an agent trained with `spread` observes after the game's
/// observation: the main abilities when it is ability-aware (spread above 0), else none.
pub fn ability_columns(spread: f64) -> usize {
    if spread > 0.0 { MAIN_ABILITIES } else { 0 }
}

/// The main abilities of `game`, as a profile file names them: the designer's keys change them,
/// and an ability-aware Solver observes them and trains over a range of them.
pub fn main_abilities(game: Game) -> [&'static str; MAIN_ABILITIES] {
    match game {
        Game::Platform => [
            "character.jump_speed", "character.run_speed", "character.gravity",
        ],
        Game::Racing => ["car.engine_force", "car.grip", "car.max_steer"],
    }
}

/// The stream [`Abilities::varied`] draws from, apart from every other use of a seed.
const VARIATION_STREAM: u64 = 0xab11_7135;

/// Each character field.
pub const CHARACTER_FIELDS: [(ParamRange, &str); 8] = [
    field(
        "character.run_speed", 2.0, 20.0, "m/s", "top horizontal speed",
    ),
    field(
        "character.jump_speed", 3.0, 20.0, "m/s", "vertical take-off speed of a jump",
    ),
    field("character.gravity", 2.0, 50.0, "m/s²", "gravity"),
    field(
        "character.ground_accel", 5.0, 200.0, "m/s²", "acceleration on the ground",
    ),
    field(
        "character.air_accel", 0.0, 60.0, "m/s²", "acceleration in the air (air control)",
    ),
    field("character.turn_rate", 45.0, 1080.0, "°/s", "fastest turn"),
    field("character.radius", 0.2, 1.0, "m", "capsule radius"),
    field(
        "character.height",
        0.8,
        3.0,
        "m",
        "capsule height, at least twice the radius",
    ),
];

/// Each car field.
pub const CAR_FIELDS: [(ParamRange, &str); 5] = [
    field(
        "car.engine_force", 1000.0, 30000.0, "N", "engine force at full throttle",
    ),
    field("car.mass", 300.0, 5000.0, "kg", "chassis mass"),
    field("car.grip", 0.2, 3.0, "", "tyre friction coefficient"),
    field("car.max_steer", 0.1, 1.0, "rad", "steering at full lock"),
    field("car.damping", 0.02, 1.0, "1/s", "air and rolling drag"),
];

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

/// A group of a profile's numbers, each with its entry in `FIELDS`: read, checked and changed
/// by the field's name.
trait Fields: Copy {
    const FIELDS: &'static [(ParamRange, &'static str)];

    /// The field at `k` of `FIELDS`, to change in place.
    fn slot(&mut self, k: usize) -> &mut f64;

    fn get(&self, k: usize) -> f64 {
        let mut copy = *self;
        *copy.slot(k)
    }

    /// Checks every field's range.
    fn check_each(&self) -> Result<(), RangeError> {
        for (k, (range, _)) in Self::FIELDS.iter().enumerate() {
            range.check(self.get(k))?;
        }
        Ok(())
    }

    /// The field named `name` (`character.jump_speed`) with its range.
    fn field(&self, name: &str) -> Option<(f64, ParamRange)> {
        let k = Self::FIELDS.iter().position(|(r, _)| r.name == name)?;
        Some((self.get(k), Self::FIELDS[k].0))
    }

    /// A copy with the field named `name` at `value`, unchecked.
    fn set(&self, name: &str, value: f64) -> Option<Self> {
        let k = Self::FIELDS.iter().position(|(r, _)| r.name == name)?;
        let mut copy = *self;
        *copy.slot(k) = value;
        Some(copy)
    }
}

/// The `n`-th of `values`.
fn nth<'a>(values: impl IntoIterator<Item = &'a mut f64>, n: usize) -> &'a mut f64 {
    values.into_iter().nth(n).expect("a field of the table")
}

/// Checks that a least value is not above its most, naming both.
fn ordered(least: (&str, f64), most: (&str, f64)) -> Result<(), String> {
    if least.1 > most.1 {
        return Err(format!(
            "{} {} is above {} {}",
            least.0,
            params::show_number(least.1),
            most.0,
            params::show_number(most.1)
        ));
    }
    Ok(())
}

impl Fields for CharacterProfile {
    const FIELDS: &'static [(ParamRange, &'static str)] = &CHARACTER_FIELDS;
    fn slot(&mut self, k: usize) -> &mut f64 {
        nth(
            [
                &mut self.run_speed, &mut self.jump_speed, &mut self.gravity,
                &mut self.ground_accel, &mut self.air_accel, &mut self.turn_rate, &mut self.radius,
                &mut self.height,
            ],
            k,
        )
    }
}

impl CharacterProfile {
    /// Checks every field's range, and the capsule's shape.
    pub fn check(&self) -> Result<(), RangeError> {
        self.check_each()?;
        let least = 2.0 * self.radius;
        ParamRange::new(
            "character.height", least, 3.0, "m (twice the radius at least)",
        )
        .check(self.height)
        .map(drop)
    }
}

impl Fields for CarProfile {
    const FIELDS: &'static [(ParamRange, &'static str)] = &CAR_FIELDS;
    fn slot(&mut self, k: usize) -> &mut f64 {
        nth(
            [
                &mut self.engine_force, &mut self.mass, &mut self.grip, &mut self.max_steer,
                &mut self.damping,
            ],
            k,
        )
    }
}

impl CarProfile {
    /// Checks every field's range.
    pub fn check(&self) -> Result<(), RangeError> {
        self.check_each()
    }
}

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

    pub fn distance(&self) -> ParamRange {
        ParamRange::new("distance", self.min_distance, self.max_distance, "m")
    }

    pub fn size(&self) -> ParamRange {
        ParamRange::new("size", self.min_size, self.max_size, "m")
    }

    pub fn height(&self) -> ParamRange {
        ParamRange::new("height", self.min_height, self.max_height, "m")
    }

    pub fn turn(&self) -> ParamRange {
        ParamRange::new("angle", -self.max_turn, self.max_turn, "degrees")
    }

    /// Checks that each of `block`'s parameters lies within these ranges.
    #[cfg(test)]
    pub(crate) fn check_block(
        &self,
        block: &crate::level::platform::BlockParams,
    ) -> Result<(), RangeError> {
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

    pub fn length(&self) -> ParamRange {
        ParamRange::new("length", self.min_length, self.max_length, "m")
    }

    pub fn curve(&self) -> ParamRange {
        ParamRange::new("curve", -self.max_curve, self.max_curve, "degrees")
    }

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
    fn checked(
        game: Game,
        blocks: Option<BlockRanges>,
        segments: Option<SegmentRanges>,
    ) -> Result<Self, String> {
        match (game, blocks, segments) {
            (Game::Platform, blocks, None) => {
                let blocks = blocks.unwrap_or_default();
                blocks.check()?;
                Ok(Pieces::Platform(blocks))
            }
            (Game::Racing, None, segments) => {
                let segments = segments.unwrap_or_default();
                segments.check()?;
                Ok(Pieces::Racing(segments))
            }
            (Game::Platform, _, _) => {
                Err("a platform profile has `blocks:`, not `segments:`".into())
            }
            (Game::Racing, _, _) => Err("a racing profile has `segments:`, not `blocks:`".into()),
        }
    }

    /// The built-in ranges of `game`.
    pub fn default_of(game: Game) -> Self {
        match game {
            Game::Platform => Pieces::Platform(BlockRanges::default()),
            Game::Racing => Pieces::Racing(SegmentRanges::default()),
        }
    }

    /// The platform ranges (the built-in ones for a racing profile).
    pub fn blocks(&self) -> BlockRanges {
        match self {
            Pieces::Platform(b) => *b,
            Pieces::Racing(_) => BlockRanges::default(),
        }
    }

    /// The racing ranges (the built-in ones for a platform profile).
    pub fn segments(&self) -> SegmentRanges {
        match self {
            Pieces::Racing(s) => *s,
            Pieces::Platform(_) => SegmentRanges::default(),
        }
    }

    /// The field named as in [`BLOCK_FIELDS`] or [`SEGMENT_FIELDS`], with its range.
    pub fn value(&self, field: &str) -> Option<(f64, ParamRange)> {
        match self {
            Pieces::Platform(b) => b.field(field),
            Pieces::Racing(s) => s.field(field),
        }
    }

    /// These ranges with `field` at `value`, when they are then valid.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        let changed = match self {
            Pieces::Platform(b) => Pieces::Platform(b.set(field, value)?),
            Pieces::Racing(s) => Pieces::Racing(s.set(field, value)?),
        };
        let game = changed.game();
        let (blocks, segments) = changed.sections();
        Pieces::checked(game, blocks, segments).ok()
    }

    pub fn game(&self) -> Game {
        match self {
            Pieces::Platform(_) => Game::Platform,
            Pieces::Racing(_) => Game::Racing,
        }
    }

    /// The file's `blocks:` and `segments:`.
    fn sections(&self) -> (Option<BlockRanges>, Option<SegmentRanges>) {
        match *self {
            Pieces::Platform(b) => (Some(b), None),
            Pieces::Racing(s) => (None, Some(s)),
        }
    }

    /// The sections a file writes: none for the built-in ranges, so that a profile of
    /// abilities alone keeps its SHA-256.
    fn written(&self) -> (Option<BlockRanges>, Option<SegmentRanges>) {
        if *self == Self::default_of(self.game()) {
            (None, None)
        } else {
            self.sections()
        }
    }
}

impl Abilities {
    /// `game`'s abilities from a file's `character:` and `car:` (the one of its game, and
    /// not the other), each field in range.
    fn checked(
        game: Game,
        character: Option<CharacterProfile>,
        car: Option<CarProfile>,
    ) -> Result<Self, String> {
        match (game, character, car) {
            (Game::Platform, Some(c), None) => {
                c.check().map_err(|e| e.to_string())?;
                Ok(Abilities::Platform(c))
            }
            (Game::Racing, None, Some(c)) => {
                c.check().map_err(|e| e.to_string())?;
                Ok(Abilities::Racing(c))
            }
            (Game::Platform, _, _) => {
                Err("a platform profile has `character:` and no `car:`".into())
            }
            (Game::Racing, _, _) => Err("a racing profile has `car:` and no `character:`".into()),
        }
    }

    /// The field named as in [`CHARACTER_FIELDS`] or [`CAR_FIELDS`], with its range; none for a
    /// field of the other game.
    pub fn value(&self, field: &str) -> Option<(f64, ParamRange)> {
        match self {
            Abilities::Platform(c) => c.field(field),
            Abilities::Racing(c) => c.field(field),
        }
    }

    /// These abilities with `field` at `value`, when they are then valid.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        Some(match self {
            Abilities::Platform(c) => {
                let c = c.set(field, value)?;
                c.check().ok()?;
                Abilities::Platform(c)
            }
            Abilities::Racing(c) => {
                let c = c.set(field, value)?;
                c.check().ok()?;
                Abilities::Racing(c)
            }
        })
    }

    /// Each of the game's [`main_abilities`] relative to the built-in one (0: ours, 0.1: 10%
    /// more): what an ability-aware Solver observes.
    pub fn relative_main(&self) -> [f32; MAIN_ABILITIES] {
        let ours = Self::default_of(self.game());
        main_abilities(self.game()).map(|field| {
            let value = |a: &Self| a.value(field).expect("a main ability of the game").0;
            (value(self) / value(&ours) - 1.0) as f32
        })
    }

    /// Whether each main ability lies within `spread` (a share, 0.2 for ±20%) of `base`'s.
    pub fn within(&self, base: &Self, spread: f64) -> bool {
        self.game() == base.game()
            && main_abilities(self.game()).iter().all(|field| {
                let (value, _) = self.value(field).expect("a main ability of the game");
                let (from, _) = base.value(field).expect("a main ability of the game");
                (value / from - 1.0).abs() <= spread + 1e-9
            })
    }

    /// These abilities with each main one scaled by `1 + s`, `s` drawn uniformly within
    /// `±spread` from a generator seeded by `seed` (kept within the field's range): the
    /// character or car of one training episode.
    pub fn varied(&self, spread: f64, seed: u64) -> Self {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ VARIATION_STREAM);
        let mut varied = *self;
        for field in main_abilities(self.game()) {
            let (value, range) = varied.value(field).expect("a main ability of the game");
            let scaled =
                (value * (1.0 + rng.random_range(-spread..=spread))).clamp(range.min, range.max);
            varied = varied.with_value(field, scaled).unwrap_or(varied);
        }
        varied
    }

    /// The abilities of `profile`, or ours when there is none.
    pub fn of(profile: Option<&Profile>, game: Game) -> Self {
        profile.map_or(Self::default_of(game), |p| p.abilities)
    }

    /// The built-in abilities of `game`.
    pub fn default_of(game: Game) -> Self {
        match game {
            Game::Platform => Abilities::Platform(CharacterProfile::default()),
            Game::Racing => Abilities::Racing(CarProfile::default()),
        }
    }

    pub fn game(&self) -> Game {
        match self {
            Abilities::Platform(_) => Game::Platform,
            Abilities::Racing(_) => Game::Racing,
        }
    }
}

impl Profile {
    /// The built-in profile of `game`.
    pub fn default_of(game: Game) -> Self {
        Self {
            name: DEFAULT_NAME.into(),
            abilities: Abilities::default_of(game),
            pieces: Pieces::default_of(game),
        }
    }

    pub fn game(&self) -> Game {
        self.abilities.game()
    }

    /// Whether these are the built-in abilities and piece ranges (whatever the name).
    pub fn is_default(&self) -> bool {
        self.abilities == Abilities::default_of(self.game())
            && self.pieces == Pieces::default_of(self.game())
    }

    /// Reads a profile file's text; `Err` is one line naming the field.
    pub fn parse(text: &str) -> Result<Self, String> {
        let file: ProfileFile = serde_yaml::from_str(text).map_err(|e| e.to_string())?;
        if file.format != FORMAT {
            return Err(format!("format: `{}`, not `{FORMAT}`", file.format));
        }
        if file.version != VERSION {
            return Err(format!(
                "version: {} is not a version this tool reads ({VERSION})",
                file.version
            ));
        }
        if file.name.trim().is_empty() || file.name.len() > 64 {
            return Err("name: 1 to 64 characters".into());
        }
        let abilities = Abilities::checked(file.game, file.character, file.car)?;
        let pieces = Pieces::checked(file.game, file.blocks, file.segments)?;
        Ok(Self {
            name: file.name,
            abilities,
            pieces,
        })
    }

    /// The profile as a file: its piece ranges in full, or (`full` false) only when they are
    /// not the built-in ones.
    fn file(&self, full: bool) -> ProfileFile {
        let (character, car) = match self.abilities {
            Abilities::Platform(c) => (Some(c), None),
            Abilities::Racing(c) => (None, Some(c)),
        };
        let (blocks, segments) = if full {
            self.pieces.sections()
        } else {
            self.pieces.written()
        };
        ProfileFile {
            format: FORMAT.into(),
            version: VERSION,
            game: self.game(),
            name: self.name.clone(),
            character,
            car,
            blocks,
            segments,
        }
    }

    /// The profile as a file, without comments (what its SHA-256 is of); built-in piece ranges
    /// are left out, so that a profile of abilities alone hashes as it always has.
    pub fn to_yaml(&self) -> String {
        serde_yaml::to_string(&self.file(false)).expect("a profile serializes")
    }

    /// The profile as `profile init` prints it, piece ranges in full: a comment per field with
    /// its range.
    pub fn to_commented_yaml(&self) -> String {
        let fields: Vec<&(ParamRange, &str)> = match self.abilities {
            Abilities::Platform(_) => CHARACTER_FIELDS.iter().chain(&BLOCK_FIELDS).collect(),
            Abilities::Racing(_) => CAR_FIELDS.iter().chain(&SEGMENT_FIELDS).collect(),
        };
        let full = serde_yaml::to_string(&self.file(true)).expect("a profile serializes");
        let mut text = format!(
            "# An arlpcg game profile: the {} abilities levels are made and checked for, and the\n\
             # ranges of their {}. `arlpcg profile check FILE` measures what it allows; pass it\n\
             # with --profile FILE.\n",
            match self.abilities {
                Abilities::Platform(_) => "character's",
                Abilities::Racing(_) => "car's",
            },
            match self.abilities {
                Abilities::Platform(_) => "blocks",
                Abilities::Racing(_) => "segments",
            }
        );
        for line in full.lines() {
            let key = line.trim_start().split(':').next().unwrap_or_default();
            let field = fields
                .iter()
                .find(|(range, _)| range.name.rsplit('.').next() == Some(key));
            match field {
                Some((range, what)) => {
                    let _ = writeln!(text, "{line:<28} # {what}, {range}");
                }
                None => {
                    let _ = writeln!(text, "{line}");
                }
            }
        }
        text
    }

    /// The field named as in [`CHARACTER_FIELDS`] or [`CAR_FIELDS`] (`character.jump_speed`),
    /// with its range; none for a field of the other game.
    pub fn value(&self, field: &str) -> Option<(f64, ParamRange)> {
        self.abilities
            .value(field)
            .or_else(|| self.pieces.value(field))
    }

    /// The same profile with `field` (an ability or a piece range) at `value`, when that is a
    /// valid profile.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        let (abilities, pieces) = match self.abilities.value(field) {
            Some(_) => (self.abilities.with_value(field, value)?, self.pieces),
            None => (self.abilities, self.pieces.with_value(field, value)?),
        };
        Some(Self {
            name: self.name.clone(),
            abilities,
            pieces,
        })
    }

    /// SHA-256 of [`Profile::to_yaml`], hex.
    pub fn sha256(&self) -> String {
        crate::level::sha256_hex(self.to_yaml().as_bytes())
    }

    /// How a level made under this profile records it.
    pub fn record(&self) -> ProfileRecord {
        let file = self.file(false);
        ProfileRecord {
            name: self.name.clone(),
            sha256: self.sha256(),
            character: file.character,
            car: file.car,
            blocks: file.blocks,
            segments: file.segments,
        }
    }
}

impl ProfileRecord {
    /// The profile a level records, checked: its game's abilities and piece ranges, in range,
    /// and the SHA-256 they hash to.
    pub fn profile(&self, game: Game) -> Result<Profile, String> {
        let profile = Profile {
            name: self.name.clone(),
            abilities: Abilities::checked(game, self.character, self.car)?,
            pieces: Pieces::checked(game, self.blocks, self.segments)?,
        };
        if profile.sha256() != self.sha256 {
            return Err(format!(
                "sha256: {} is not the SHA-256 of the abilities recorded ({})",
                self.sha256,
                profile.sha256()
            ));
        }
        Ok(profile)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varied_abilities_stay_within_their_spread_and_follow_their_seed() {
        for game in [Game::Platform, Game::Racing] {
            let ours = Abilities::default_of(game);
            assert_eq!(ours.relative_main(), [0.0; MAIN_ABILITIES]);
            let varied: Vec<Abilities> = (0..50).map(|seed| ours.varied(0.2, seed)).collect();
            assert_eq!(varied[7], ours.varied(0.2, 7), "seeded");
            assert!(varied.iter().all(|a| a.within(&ours, 0.2)));
            assert!(varied.iter().any(|a| !a.within(&ours, 0.1)), "it spreads");
            for a in &varied {
                assert!(a.relative_main().iter().all(|r| r.abs() <= 0.2 + 1e-6));
            }
            // Only the main abilities vary.
            let fields: &[(ParamRange, &str)] = match game {
                Game::Platform => &CHARACTER_FIELDS,
                Game::Racing => &CAR_FIELDS,
            };
            for (range, _) in fields {
                if !main_abilities(game).contains(&range.name) {
                    assert_eq!(varied[3].value(range.name), ours.value(range.name));
                }
            }
        }
    }

    #[test]
    fn the_default_profile_reads_back_what_init_prints() {
        for game in [Game::Platform, Game::Racing] {
            let profile = Profile::default_of(game);
            assert!(profile.is_default());
            let text = profile.to_commented_yaml();
            assert_eq!(Profile::parse(&text).unwrap(), profile, "{text}");
            // The built-in ranges are printed in full, but hashed as a profile of abilities
            // alone, as before ranges were part of a profile.
            let yaml = profile.to_yaml();
            assert!(text.contains("max_height"), "{text}");
            assert!(
                !yaml.contains("blocks:") && !yaml.contains("segments:"),
                "{yaml}"
            );
            assert_eq!(profile.record().profile(game).unwrap(), profile);
        }
    }

    #[test]
    fn a_bad_profile_names_its_field() {
        let base = Profile::default_of(Game::Platform).to_yaml();
        let bad = |from: &str, to: &str| {
            assert!(base.contains(from), "{base}");
            Profile::parse(&base.replace(from, to)).unwrap_err()
        };
        assert!(bad("jump_speed: 9.25", "jump_speed: .nan").contains("character.jump_speed"));
        assert!(
            bad("gravity: 20.0", "gravity: 500").contains("character.gravity 500 is out of range")
        );
        assert!(bad("radius: 0.4", "radius: 0.4\n  wings: 2").contains("unknown field `wings`"));
        assert!(
            bad("radius: 0.4\n  height: 1.8", "radius: 0.6\n  height: 1.0")
                .contains("twice the radius")
        );
        assert!(bad("game: platform", "game: racing").contains("racing profile has `car:`"));
        assert!(bad("format: arlpcg-profile", "format: x").contains("format: `x`"));
        let record = Profile::default_of(Game::Platform).record();
        let forged = ProfileRecord {
            sha256: "00".into(),
            ..record
        };
        assert!(
            forged
                .profile(Game::Platform)
                .unwrap_err()
                .contains("sha256")
        );
    }
}
