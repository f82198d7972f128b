//! The abilities of the player's character (platform) or car (racing): the fields a profile
//! sets, their ranges, and how an ability-aware agent observes and varies the main ones.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{Fields, Profile, field, nth};
use crate::level::params::{ParamRange, RangeError};
use crate::level::{Game, PlayerKind};

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

/// A player's abilities, of the kind its game has ([`PlayerKind`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Abilities {
    /// A platform character's abilities.
    Character(CharacterProfile),
    /// A racing car's abilities.
    Car(CarProfile),
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

/// The observation part an ability-aware Solver's observation ends with: the game's
/// [`main_abilities`] relative to ours.
pub const ABILITIES_PART: &str = "abilities";

/// How many main abilities each game has.
pub const MAIN_ABILITIES: usize = 3;

/// How many ability columns an agent observes after the game's observation: the main
/// abilities when it is ability-aware (it trained over [`AbilityRanges`]), else none.
pub fn ability_columns(aware: bool) -> usize {
    if aware { MAIN_ABILITIES } else { 0 }
}

/// The main abilities of `game`, as a profile file names them: the designer's keys change them,
/// and an ability-aware Solver observes them and trains over a range of them.
pub fn main_abilities(game: Game) -> [&'static str; MAIN_ABILITIES] {
    main_of(game.player())
}

/// The main abilities of a player of `kind`.
fn main_of(kind: PlayerKind) -> [&'static str; MAIN_ABILITIES] {
    match kind {
        PlayerKind::Character => [
            "character.jump_speed", "character.run_speed", "character.gravity",
        ],
        PlayerKind::Car => ["car.engine_force", "car.grip", "car.max_steer"],
    }
}

/// How many evenly spaced values of each main ability's range [`AbilityRanges::draw`] draws
/// from.
pub const DRAWN_VALUES: usize = 5;

/// The stream [`AbilityRanges::draw`] draws from, apart from every other use of a seed.
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

impl Abilities {
    /// `game`'s abilities from a file's `character:` and `car:` (the one of its game, and
    /// not the other), each field in range.
    pub(super) fn checked(
        game: Game,
        character: Option<CharacterProfile>,
        car: Option<CarProfile>,
    ) -> Result<Self, String> {
        match (game.player(), character, car) {
            (PlayerKind::Character, Some(c), None) => {
                c.check().map_err(|e| e.to_string())?;
                Ok(Abilities::Character(c.normalized()))
            }
            (PlayerKind::Car, None, Some(c)) => {
                c.check().map_err(|e| e.to_string())?;
                Ok(Abilities::Car(c.normalized()))
            }
            (PlayerKind::Character, _, _) => {
                Err(format!("a {game} profile has `character:` and no `car:`"))
            }
            (PlayerKind::Car, _, _) => {
                Err(format!("a {game} profile has `car:` and no `character:`"))
            }
        }
    }

    /// The field named as in [`CHARACTER_FIELDS`] or [`CAR_FIELDS`], with its range; none for a
    /// field of the other game.
    pub fn value(&self, field: &str) -> Option<(f64, ParamRange)> {
        match self {
            Abilities::Character(c) => c.field(field),
            Abilities::Car(c) => c.field(field),
        }
    }

    /// These abilities with `field` at `value`, when they are then valid.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        Some(match self {
            Abilities::Character(c) => {
                let c = c.set(field, value)?;
                c.check().ok()?;
                Abilities::Character(c)
            }
            Abilities::Car(c) => {
                let c = c.set(field, value)?;
                c.check().ok()?;
                Abilities::Car(c)
            }
        })
    }

    /// Each of the game's [`main_abilities`] relative to the built-in one (0: ours, 0.1: 10%
    /// more): what an ability-aware Solver observes.
    pub fn relative_main(&self) -> [f32; MAIN_ABILITIES] {
        let ours = Self::built_in(self.kind());
        main_of(self.kind()).map(|field| {
            let value = |a: &Self| a.value(field).expect("a main ability of the game").0;
            (value(self) / value(&ours) - 1.0) as f32
        })
    }

    /// The abilities of `profile`, or ours when there is none.
    pub fn of(profile: Option<&Profile>, game: Game) -> Self {
        profile.map_or(Self::default_of(game), |p| p.abilities)
    }

    /// The built-in abilities of `game`.
    pub fn default_of(game: Game) -> Self {
        Self::built_in(game.player())
    }

    /// The built-in abilities of a player of `kind`.
    fn built_in(kind: PlayerKind) -> Self {
        match kind {
            PlayerKind::Character => Abilities::Character(CharacterProfile::default()),
            PlayerKind::Car => Abilities::Car(CarProfile::default()),
        }
    }

    /// Whose abilities they are.
    pub fn kind(&self) -> PlayerKind {
        match self {
            Abilities::Character(_) => PlayerKind::Character,
            Abilities::Car(_) => PlayerKind::Car,
        }
    }
}

/// The ranges an ability-aware agent trained over, one `[least, most]` per main ability of its
/// game ([`main_abilities`]): each training episode and match drew its main abilities uniformly
/// within them, and the agent covers exactly the abilities they hold. A file writes them by name
/// (`ability_ranges:`, [`AbilityRanges::named`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AbilityRanges {
    kind: PlayerKind,
    ranges: [[f64; 2]; MAIN_ABILITIES],
}

impl AbilityRanges {
    /// Each main ability within `spread` (a share, 0.2 for ±20%) of `base`'s, kept within the
    /// field's own range.
    pub fn around(base: &Abilities, spread: f64) -> Self {
        let ranges = main_of(base.kind()).map(|field| {
            let (value, range) = base.value(field).expect("a main ability of the game");
            [
                (value * (1.0 - spread)).max(range.min),
                (value * (1.0 + spread)).min(range.max),
            ]
        });
        Self {
            kind: base.kind(),
            ranges,
        }
    }

    /// The ranges a file names (`character.jump_speed: [4, 11]`, ...): one for every main
    /// ability of a player of `kind` and none else, each in order and within the field's range.
    /// `Err` names the field.
    pub fn from_named(
        kind: PlayerKind,
        named: &BTreeMap<String, [f64; 2]>,
    ) -> Result<Self, String> {
        let main = main_of(kind);
        if let Some(other) = named.keys().find(|name| !main.contains(&name.as_str())) {
            return Err(format!(
                "{other} is not a main ability of a {} (those are {})",
                kind_word(kind),
                main.join(", ")
            ));
        }
        let ours = Abilities::built_in(kind);
        let mut ranges = [[0.0; 2]; MAIN_ABILITIES];
        for (slot, field) in ranges.iter_mut().zip(main) {
            let [least, most] = *named.get(field).ok_or_else(|| {
                format!(
                    "{field}: missing (every main ability needs its range: {})",
                    main.join(", ")
                )
            })?;
            let (_, range) = ours.value(field).expect("a main ability of the game");
            for end in [least, most] {
                range.check(end).map_err(|e| e.to_string())?;
            }
            if least > most {
                return Err(format!(
                    "{field}: [{least}, {most}] runs backwards (least first)"
                ));
            }
            *slot = [least + 0.0, most + 0.0];
        }
        Ok(Self { kind, ranges })
    }

    /// The ranges a configuration or a card gives: its `ability_ranges` by name, else its
    /// `ability_spread` (a share in (0, 0.5]) around `base`; none when it gives neither. `Err`
    /// names the field.
    pub fn given(
        named: Option<&BTreeMap<String, [f64; 2]>>,
        spread: Option<f64>,
        base: &Abilities,
    ) -> Result<Option<Self>, String> {
        if let Some(named) = named {
            return Self::from_named(base.kind(), named)
                .map(Some)
                .map_err(|problem| format!("ability_ranges: {problem}"));
        }
        match spread {
            Some(spread) if spread > 0.0 && spread <= 0.5 => Ok(Some(Self::around(base, spread))),
            Some(spread) => Err(format!(
                "ability_spread: {spread} is not a share in (0, 0.5]"
            )),
            None => Ok(None),
        }
    }

    /// The ranges by field name, as a file writes them.
    pub fn named(&self) -> BTreeMap<String, [f64; 2]> {
        main_of(self.kind)
            .iter()
            .zip(self.ranges)
            .map(|(field, range)| (field.to_string(), range))
            .collect()
    }

    /// Whether every main ability of `abilities` lies within its range.
    pub fn holds(&self, abilities: &Abilities) -> bool {
        abilities.kind() == self.kind
            && main_of(self.kind)
                .iter()
                .zip(self.ranges)
                .all(|(field, [least, most])| {
                    let (value, _) = abilities.value(field).expect("a main ability of the game");
                    (least - 1e-9..=most + 1e-9).contains(&value)
                })
    }

    /// `base` with each main ability drawn from a generator seeded by `seed` among
    /// [`DRAWN_VALUES`] evenly spaced values of its range, ends included: the character or car
    /// of one training episode or match. A run thus plays at most 125 characters, and measures
    /// each one's reach once (about a second each), however many matches it plays.
    pub fn draw(&self, base: &Abilities, seed: u64) -> Abilities {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ VARIATION_STREAM);
        let mut drawn = *base;
        for (field, [least, most]) in main_of(self.kind).iter().zip(self.ranges) {
            let step = rng.random_range(0..DRAWN_VALUES) as f64 / (DRAWN_VALUES - 1) as f64;
            let value = least + (most - least) * step;
            drawn = drawn.with_value(field, value).unwrap_or(drawn);
        }
        drawn
    }

    /// The ranges in words: `character.jump_speed 4-11, character.run_speed 4-9, ...`.
    pub fn describe(&self) -> String {
        main_of(self.kind)
            .iter()
            .zip(self.ranges)
            .map(|(field, [least, most])| format!("{field} {least}-{most}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A player of `kind` in words.
fn kind_word(kind: PlayerKind) -> &'static str {
    match kind {
        PlayerKind::Character => "character",
        PlayerKind::Car => "car",
    }
}
