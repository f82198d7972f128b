//! Game profiles as the commands use them (`--profile FILE`, `arlpcg profile`): read from a
//! file, and measured for what they allow with the scripted expert playing.

use std::path::Path;

use anyhow::Result;
use rayon::prelude::*;

use crate::services::generation::{LevelRequest, rules_level};
use crate::services::verify::{self, Solver};
use arlpcg_core::game::{GameSpec, Skill};
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::Profile;

/// Rule levels the scripted expert plays to see whether a profile allows any level.
pub const CHECK_LEVELS: u64 = 10;

/// A profile file, read and checked; the error names the file and the field.
pub fn load(path: &Path) -> Result<Profile> {
    let bytes = crate::services::fsio::read_limited(path, 1 << 16, "profile")?;
    let text = String::from_utf8(bytes)
        .map_err(|_| anyhow::anyhow!("{}: not UTF-8 text", path.display()))?;
    Profile::parse(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// `profile` for a command on `game`: refused when it is another game's.
pub fn for_game(profile: Profile, game: Game, path: &Path) -> Result<Profile> {
    if profile.game() != game {
        anyhow::bail!(
            "{}: a {} profile, not a {game} one; pass --game {} or another profile",
            path.display(),
            profile.game(),
            profile.game()
        );
    }
    Ok(profile)
}

/// What a profile allows: figures from its abilities and from the scripted expert's runs.
pub struct Allowance {
    /// One line per figure.
    pub lines: Vec<String>,
    /// Rule levels (of [`CHECK_LEVELS`]) the scripted expert completed at least once.
    pub completed: u64,
}

/// Measures what `profile` allows: its jump (platform) or its speed and grip (racing), and how
/// many of [`CHECK_LEVELS`] rule levels the scripted expert completes in `trials` runs each.
pub fn measure(profile: &Profile, trials: u32) -> Allowance {
    let mut lines = arlpcg_core::for_game!(profile.game(), G => G::ability_figures(profile));
    let game = profile.game();
    let played: Vec<Option<(u32, u32)>> = (0..CHECK_LEVELS)
        .into_par_iter()
        .map(|seed| {
            let request = LevelRequest::new(seed, None).profile(Some(profile.clone()));
            let level = rules_level(game, &request).ok()?;
            let stats = verify::verify(&level, &Solver::Scripted(Skill::Expert), trials, 0, &|| {})
                .expect("a rule level of the profile's game");
            Some((stats.successes, trials))
        })
        .collect();
    let completed = played.iter().flatten().filter(|(s, _)| *s > 0).count() as u64;
    let (successes, runs) = played
        .iter()
        .flatten()
        .fold((0, 0), |(s, r), (a, b)| (s + a, r + b));
    lines.push(format!(
        "the scripted expert completes {completed} of {CHECK_LEVELS} rule levels ({successes} of {runs} runs)"
    ));
    Allowance { lines, completed }
}
