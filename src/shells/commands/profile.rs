//! `arlpcg profile init | check`: a game's built-in profile to edit, and what a profile file
//! allows ([`crate::services::profile`]).

use anyhow::Result;

use crate::services::profile::{CHECK_LEVELS, load, measure};
use crate::shells::cli::ProfileCommand;
use arlpcg_core::level::profile::Profile;

pub fn run(command: &ProfileCommand) -> Result<()> {
    match command {
        ProfileCommand::Init { game } => {
            crate::shells::common::say(format_args!(
                "{}",
                Profile::default_of(*game).to_commented_yaml()
            ));
            Ok(())
        }
        ProfileCommand::Check { file, trials, .. } => {
            let profile = load(file)?;
            crate::say!(
                "{}: the {} profile `{}` (sha256 {})",
                file.display(),
                profile.game(),
                profile.name,
                &profile.sha256()[..12]
            );
            let allowance = measure(&profile, *trials);
            for line in &allowance.lines {
                crate::say!("{line}");
            }
            // The rules keep within the profile's reach, so a weak one gets levels only toward
            // the goals it reaches: under half of them is a profile the game cannot be played
            // with.
            if allowance.completed * 2 < CHECK_LEVELS {
                anyhow::bail!(
                    "{}: under this profile the scripted expert completes {} of {CHECK_LEVELS} rule levels: most of the game's goals cannot be reached; give the {} more ability",
                    file.display(),
                    allowance.completed,
                    arlpcg_core::game::facts::facts(profile.game()).player_kind
                );
            }
            Ok(())
        }
    }
}
