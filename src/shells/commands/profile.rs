//! `arlpcg profile init | check`: a game's built-in profile to edit, and what a profile file
//! allows ([`crate::services::profile`]).

use anyhow::Result;

use crate::services::profile::{CHECK_LEVELS, load, measure};
use crate::shells::cli::ProfileCommand;
use arlpcg_core::level::profile::Profile;

pub fn run(command: &ProfileCommand) -> Result<()> {
    match command {
        ProfileCommand::Init { game } => {
            print!("{}", Profile::default_of(*game).to_commented_yaml());
            Ok(())
        }
        ProfileCommand::Check { file, trials } => {
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
            if allowance.completed == 0 {
                anyhow::bail!(
                    "{}: under this profile the scripted expert completes none of {CHECK_LEVELS} rule levels: no level can be completed; give the {} more ability",
                    file.display(),
                    match profile.game() {
                        arlpcg_core::level::Game::Platform => "character",
                        arlpcg_core::level::Game::Racing => "car",
                    }
                );
            }
            Ok(())
        }
    }
}
