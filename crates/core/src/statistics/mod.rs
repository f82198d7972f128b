//! Statistics that do not belong to one level: estimates over training seeds with their
//! intervals ([`over_seeds`]), and the difficulty rating of levels by a panel of judges
//! ([`rating`]), and a player population going through a sequence of levels ([`population`]).

pub mod over_seeds;
pub mod population;
pub mod rating;
