//! arlpcg's pure, seeded core, the bottom layer of the tool (docs/architecture.md):
//! - [`level`]: levels as data, their YAML file format and glTF export;
//! - [`rl`]: the actor-critic, PPO and its fused update, policy and checkpoint files;
//! - [`game`]: the two games as deterministic rapier3d simulations, their Solver and Generator
//!   environments, scripted players and rule levels;
//! - [`statistics`]: estimates over training seeds and the judges' difficulty rating;
//! - [`seed_ranges`]: which seeds each part of the tool draws from.
//!
//! `game` and `rl` sit side by side on `level`: neither imports the other. Nothing here reads
//! the clock, prints or uses a global RNG (the one file it reads is a level, `level::yaml::load`): the same inputs give the same bytes.
//! This crate depends on no other crate of the workspace, so the compiler refuses an import
//! from the layers above.

/// A type written as text (`Display`) and read back by its checking parser
/// (`fn parse(&str) -> Result<Self, String>`): `FromStr` (clap's value parser) and serde as that
/// text, so a file holds what a user types and a bad value is refused with the parser's words.
#[macro_export]
macro_rules! as_text {
    ($type:ty) => {
        impl ::std::str::FromStr for $type {
            type Err = String;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                <$type>::parse(s)
            }
        }

        impl ::serde::Serialize for $type {
            fn serialize<S: ::serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.collect_str(self)
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $type {
            fn deserialize<D: ::serde::Deserializer<'de>>(
                deserializer: D,
            ) -> Result<Self, D::Error> {
                let text = <String as ::serde::Deserialize>::deserialize(deserializer)?;
                <$type>::parse(&text).map_err(::serde::de::Error::custom)
            }
        }
    };
}

pub mod game;
pub mod level;
pub mod rl;
pub mod seed_ranges;
pub mod statistics;
