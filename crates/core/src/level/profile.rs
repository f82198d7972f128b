//! A game profile: the abilities of the player's character (platform) or car (racing) as a
//! versioned file (`format: arlpcg-profile`), so that levels are checked for a designer's own
//! game rather than ours. The built-in default is today's game: a level without a profile is
//! played exactly as before, and a level made under another profile records it in full (name,
//! SHA-256 of its values, and the values), so that it is verified under the same abilities.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::level::Game;
use crate::level::params::{ParamRange, RangeError};

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

/// A profile file: which game, a name, and that game's abilities.
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
}

/// One game's abilities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Abilities {
    Platform(CharacterProfile),
    Racing(CarProfile),
}

/// A checked profile: its name and abilities.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub name: String,
    pub abilities: Abilities,
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

impl CharacterProfile {
    /// The fields in the order of [`CHARACTER_FIELDS`], to change in place.
    fn values_mut(&mut self) -> [&mut f64; 8] {
        [
            &mut self.run_speed, &mut self.jump_speed, &mut self.gravity, &mut self.ground_accel,
            &mut self.air_accel, &mut self.turn_rate, &mut self.radius, &mut self.height,
        ]
    }

    fn values(&self) -> [f64; 8] {
        let mut copy = *self;
        copy.values_mut().map(|v| *v)
    }

    /// Checks every field's range, and the capsule's shape.
    pub fn check(&self) -> Result<(), RangeError> {
        for ((range, _), value) in CHARACTER_FIELDS.iter().zip(self.values()) {
            range.check(value)?;
        }
        let least = 2.0 * self.radius;
        ParamRange::new(
            "character.height", least, 3.0, "m (twice the radius at least)",
        )
        .check(self.height)
        .map(drop)
    }
}

impl CarProfile {
    /// The fields in the order of [`CAR_FIELDS`], to change in place.
    fn values_mut(&mut self) -> [&mut f64; 5] {
        [
            &mut self.engine_force, &mut self.mass, &mut self.grip, &mut self.max_steer,
            &mut self.damping,
        ]
    }

    fn values(&self) -> [f64; 5] {
        let mut copy = *self;
        copy.values_mut().map(|v| *v)
    }

    /// Checks every field's range.
    pub fn check(&self) -> Result<(), RangeError> {
        for ((range, _), value) in CAR_FIELDS.iter().zip(self.values()) {
            range.check(value)?;
        }
        Ok(())
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
        let at = |fields: &[(ParamRange, &str)]| fields.iter().position(|(r, _)| r.name == field);
        match self {
            Abilities::Platform(c) => {
                at(&CHARACTER_FIELDS).map(|k| (c.values()[k], CHARACTER_FIELDS[k].0))
            }
            Abilities::Racing(c) => at(&CAR_FIELDS).map(|k| (c.values()[k], CAR_FIELDS[k].0)),
        }
    }

    /// These abilities with `field` at `value`, when they are then valid.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        Some(match *self {
            Abilities::Platform(mut c) => {
                let at = CHARACTER_FIELDS.iter().position(|(r, _)| r.name == field)?;
                *c.values_mut()[at] = value;
                c.check().ok()?;
                Abilities::Platform(c)
            }
            Abilities::Racing(mut c) => {
                let at = CAR_FIELDS.iter().position(|(r, _)| r.name == field)?;
                *c.values_mut()[at] = value;
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
        }
    }

    pub fn game(&self) -> Game {
        self.abilities.game()
    }

    /// Whether these are the built-in abilities (whatever the name).
    pub fn is_default(&self) -> bool {
        self.abilities == Abilities::default_of(self.game())
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
        Ok(Self {
            name: file.name,
            abilities,
        })
    }

    fn file(&self) -> ProfileFile {
        let (character, car) = match self.abilities {
            Abilities::Platform(c) => (Some(c), None),
            Abilities::Racing(c) => (None, Some(c)),
        };
        ProfileFile {
            format: FORMAT.into(),
            version: VERSION,
            game: self.game(),
            name: self.name.clone(),
            character,
            car,
        }
    }

    /// The profile as a file, without comments (what its SHA-256 is of).
    pub fn to_yaml(&self) -> String {
        serde_yaml::to_string(&self.file()).expect("a profile serializes")
    }

    /// The profile as `profile init` prints it: a comment per field with its range.
    pub fn to_commented_yaml(&self) -> String {
        let fields: &[(ParamRange, &str)] = match self.abilities {
            Abilities::Platform(_) => &CHARACTER_FIELDS,
            Abilities::Racing(_) => &CAR_FIELDS,
        };
        let mut text = format!(
            "# An arlpcg game profile: the {} abilities levels are made and checked for.\n\
             # `arlpcg profile check FILE` measures what it allows; pass it with --profile FILE.\n",
            match self.abilities {
                Abilities::Platform(_) => "character's",
                Abilities::Racing(_) => "car's",
            }
        );
        for line in self.to_yaml().lines() {
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
        self.abilities.value(field)
    }

    /// The same profile with `field` at `value`, when that is a valid profile.
    pub fn with_value(&self, field: &str, value: f64) -> Option<Self> {
        Some(Self {
            name: self.name.clone(),
            abilities: self.abilities.with_value(field, value)?,
        })
    }

    /// SHA-256 of [`Profile::to_yaml`], hex.
    pub fn sha256(&self) -> String {
        crate::level::sha256_hex(self.to_yaml().as_bytes())
    }

    /// How a level made under this profile records it.
    pub fn record(&self) -> ProfileRecord {
        let file = self.file();
        ProfileRecord {
            name: self.name.clone(),
            sha256: self.sha256(),
            character: file.character,
            car: file.car,
        }
    }
}

impl ProfileRecord {
    /// The profile a level records, checked: its game's abilities, in range, and the SHA-256
    /// they hash to.
    pub fn profile(&self, game: Game) -> Result<Profile, String> {
        let abilities = Abilities::checked(game, self.character, self.car)?;
        let profile = Profile {
            name: self.name.clone(),
            abilities,
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
