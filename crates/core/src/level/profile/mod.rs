//! A game profile: the abilities of the player's character (platform) or car (racing), and the
//! ranges its level pieces are drawn from, as a versioned file (`format: arlpcg-profile`), so
//! that levels are made and checked for a designer's own game rather than ours. The built-in
//! default is today's game: a level without a profile is played exactly as before, and a level
//! made under another profile records it in full (name, SHA-256 of its values, and the values),
//! so that it is verified under the same abilities.
//!
//! Here: the file, the checked profile and the record a level keeps. `abilities.rs` holds the
//! character's and the car's fields, `pieces.rs` the blocks' and the segments' ranges.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::level::Game;
use crate::level::params::{self, ParamRange, RangeError};

mod abilities;
mod pieces;
pub use abilities::{
    ABILITIES_PART, Abilities, AbilityRanges, CAR_FIELDS, CHARACTER_FIELDS, CarProfile,
    CharacterProfile, MAIN_ABILITIES, ability_columns, main_abilities,
};
pub use pieces::{BLOCK_FIELDS, BlockRanges, Pieces, SEGMENT_FIELDS, SegmentRanges};

/// The `format:` of a profile file.
pub const FORMAT: &str = "arlpcg-profile";
/// The version this build reads and writes.
pub const VERSION: u32 = 1;
/// The name of the built-in profile.
pub const DEFAULT_NAME: &str = "default";

/// A profile file: which game, a name, that game's abilities and (optionally) its pieces'
/// ranges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// The file's format version ([`VERSION`]).
    pub version: u32,
    /// The game the profile is for.
    pub game: Game,
    /// The profile's name.
    pub name: String,
    /// The character's abilities (platform).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<CharacterProfile>,
    /// The car's abilities (racing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub car: Option<CarProfile>,
    /// The blocks' ranges (platform), when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<BlockRanges>,
    /// The road segments' ranges (racing), when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<SegmentRanges>,
}

/// A checked profile: its game, name, abilities (of the game's [`PlayerKind`]) and piece ranges
/// (of the game's [`ShapeKind`](crate::level::ShapeKind)).
///
/// [`PlayerKind`]: crate::level::PlayerKind
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The game the profile is for.
    pub game: Game,
    /// The profile's name.
    pub name: String,
    /// The player's abilities.
    pub abilities: Abilities,
    /// The ranges its level pieces are drawn from.
    pub pieces: Pieces,
}

/// How a level records the profile it was made under (`profile:` in a level file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileRecord {
    /// The profile's name.
    pub name: String,
    /// SHA-256 of the profile's values as [`Profile::to_yaml`] writes them.
    pub sha256: String,
    /// The character's abilities (platform).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<CharacterProfile>,
    /// The car's abilities (racing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub car: Option<CarProfile>,
    /// The piece ranges, when they are not the built-in ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<BlockRanges>,
    /// The road segments' ranges, when they are not the built-in ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<SegmentRanges>,
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

    /// A copy with every -0 field at 0: a file's `-0.0` reads as `0.0`, the same profile with
    /// the same SHA-256 (as `--aux -0` is `--aux 0`).
    fn normalized(mut self) -> Self {
        for k in 0..Self::FIELDS.len() {
            *self.slot(k) += 0.0;
        }
        self
    }

    /// A copy with the field named `name` at `value` (-0 as 0), unchecked.
    fn set(&self, name: &str, value: f64) -> Option<Self> {
        let k = Self::FIELDS.iter().position(|(r, _)| r.name == name)?;
        let mut copy = *self;
        *copy.slot(k) = value + 0.0;
        Some(copy)
    }
}

/// Checks a profile's name: 1 to 64 characters of one line, none of them a control character
/// (a line break or a terminal's escape codes would reach every terminal that shows the name).
fn check_name(name: &str) -> Result<(), String> {
    if name.trim().is_empty() || name.len() > 64 {
        return Err("name: 1 to 64 characters".into());
    }
    if name.contains(char::is_control) {
        return Err(
            "name: a line of text without control characters (line breaks, escape codes)".into(),
        );
    }
    Ok(())
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

impl Profile {
    /// The built-in profile of `game`.
    pub fn default_of(game: Game) -> Self {
        Self {
            game,
            name: DEFAULT_NAME.into(),
            abilities: Abilities::default_of(game),
            pieces: Pieces::default_of(game),
        }
    }

    /// The game the profile is for.
    pub fn game(&self) -> Game {
        self.game
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
        check_name(&file.name)?;
        let abilities = Abilities::checked(file.game, file.character, file.car)?;
        let pieces = Pieces::checked(file.game, file.blocks, file.segments)?;
        Ok(Self {
            game: file.game,
            name: file.name,
            abilities,
            pieces,
        })
    }

    /// The profile as a file: its piece ranges in full, or (`full` false) only when they are
    /// not the built-in ones.
    fn file(&self, full: bool) -> ProfileFile {
        let (character, car) = match self.abilities {
            Abilities::Character(c) => (Some(c), None),
            Abilities::Car(c) => (None, Some(c)),
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
        let (ability_fields, player): (&[_], _) = match self.abilities {
            Abilities::Character(_) => (&CHARACTER_FIELDS, "character's"),
            Abilities::Car(_) => (&CAR_FIELDS, "car's"),
        };
        let (piece_fields, pieces): (&[_], _) = match self.pieces {
            Pieces::Blocks(_) => (&BLOCK_FIELDS, "blocks"),
            Pieces::Road(_) => (&SEGMENT_FIELDS, "segments"),
        };
        let fields: Vec<&(ParamRange, &str)> = ability_fields.iter().chain(piece_fields).collect();
        let full = serde_yaml::to_string(&self.file(true)).expect("a profile serializes");
        let mut text = format!(
            "# An arlpcg game profile: the {player} abilities levels are made and checked for, and the\n\
             # ranges of their {pieces}. `arlpcg profile check FILE` measures what it allows; pass it\n\
             # with --profile FILE.\n"
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
            game: self.game,
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
        check_name(&self.name)?;
        let profile = Profile {
            game,
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
    fn a_levels_style_is_the_mean_of_its_pieces_measures() {
        use crate::level::Shape;
        use crate::level::platform::{BlockParams, PlatformTrack, Start};
        let ranges = Pieces::default_of(Game::Platform);
        // The shortest jump, level, then the longest, 2 m up: stride -1 and +1, steps -1 and +1.
        let blocks = [
            BlockParams::new(5.0, 0.0, 5.0, 0.0).unwrap(),
            BlockParams::new(10.0, 0.0, 5.0, 2.0).unwrap(),
        ];
        let track = PlatformTrack::from_params(Start::default(), &blocks).unwrap();
        assert_eq!(ranges.style(Shape::Blocks(&track)), vec![0.0, 0.0]);
        let track = PlatformTrack::from_params(Start::default(), &blocks[1..]).unwrap();
        assert_eq!(ranges.style(Shape::Blocks(&track)), vec![1.0, 1.0]);
        let empty = PlatformTrack::new(Start::default());
        assert_eq!(ranges.style(Shape::Blocks(&empty)), vec![0.0, 0.0]);
    }

    #[test]
    fn drawn_abilities_stay_within_their_ranges_and_follow_their_seed() {
        for game in [Game::Platform, Game::Racing] {
            let ours = Abilities::default_of(game);
            assert_eq!(ours.relative_main(), [0.0; MAIN_ABILITIES]);
            let around = AbilityRanges::around(&ours, 0.2);
            let narrow = AbilityRanges::around(&ours, 0.1);
            assert!(around.holds(&ours));
            let drawn: Vec<Abilities> = (0..50).map(|seed| around.draw(&ours, seed)).collect();
            assert_eq!(drawn[7], around.draw(&ours, 7), "seeded");
            assert!(drawn.iter().all(|a| around.holds(a)));
            assert!(drawn.iter().any(|a| !narrow.holds(a)), "it spreads");
            for a in &drawn {
                assert!(a.relative_main().iter().all(|r| r.abs() <= 0.2 + 1e-6));
            }
            // Only the main abilities vary.
            let fields: &[(ParamRange, &str)] = match game.player() {
                crate::level::PlayerKind::Character => &CHARACTER_FIELDS,
                crate::level::PlayerKind::Car => &CAR_FIELDS,
            };
            for (range, _) in fields {
                if !main_abilities(game).contains(&range.name) {
                    assert_eq!(drawn[3].value(range.name), ours.value(range.name));
                }
            }
            // A file's names read back to the same ranges.
            assert_eq!(
                AbilityRanges::from_named(game.player(), &around.named()),
                Ok(around)
            );
        }
    }

    #[test]
    fn ability_ranges_from_a_file_name_the_field_that_is_wrong() {
        let kind = crate::level::PlayerKind::Character;
        let wide = |jump: [f64; 2]| {
            std::collections::BTreeMap::from([
                ("character.jump_speed".to_string(), jump),
                ("character.run_speed".to_string(), [4.0, 9.0]),
                ("character.gravity".to_string(), [9.0, 25.0]),
            ])
        };
        let ranges = AbilityRanges::from_named(kind, &wide([4.0, 11.0])).unwrap();
        let godot = Abilities::Character(CharacterProfile {
            run_speed: 5.0,
            jump_speed: 4.5,
            gravity: 9.8,
            ..CharacterProfile::default()
        });
        assert!(ranges.holds(&godot) && ranges.holds(&Abilities::default_of(Game::Platform)));
        let error = AbilityRanges::from_named(kind, &wide([11.0, 4.0])).unwrap_err();
        assert!(
            error.contains("character.jump_speed") && error.contains("backwards"),
            "{error}"
        );
        let error = AbilityRanges::from_named(kind, &wide([1.0, 4.0])).unwrap_err();
        assert!(error.contains("character.jump_speed"), "{error}");
        let mut missing = wide([4.0, 11.0]);
        missing.remove("character.gravity");
        let error = AbilityRanges::from_named(kind, &missing).unwrap_err();
        assert!(error.contains("character.gravity: missing"), "{error}");
        let mut other = wide([4.0, 11.0]);
        other.insert("car.grip".into(), [0.5, 1.0]);
        let error = AbilityRanges::from_named(kind, &other).unwrap_err();
        assert!(error.contains("car.grip is not a main ability"), "{error}");
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
