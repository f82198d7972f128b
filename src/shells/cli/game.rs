//! `--game` where the command line leaves it out: the game of the policies or the profile the
//! command names, so that `arlpcg design --policies policies/racing` opens the racing game and
//! `generate --profile car.yaml` makes racing levels for a car, as a designer expects.

use std::path::Path;

use clap::parser::ValueSource;
use clap::{ArgMatches, CommandFactory, FromArgMatches};

use super::{Cli, Command};
use crate::services::fsio::read_limited;
use crate::services::policies::{GENERATOR_FILE, SOLVER_FILE};
use arlpcg_core::level::Game;
use arlpcg_core::rl::checkpoint::{MAX_POLICY_BYTES, read_card};

impl Cli {
    /// The command line of this process, parsed, with `--game` implied where it is left out
    /// ([`Cli::parse_from_args`]).
    pub fn parse_args() -> Result<Cli, clap::Error> {
        Self::from_matches(&Cli::command().try_get_matches()?)
    }

    /// `args` parsed; a command that takes `--game` and was not given it plays the game its
    /// `--policies` (eval's `--runs` too: a folder's Generator card, else its Solver's, or the
    /// file's own) and its `--profile` name; else platform. Files of two games are refused,
    /// naming both. A file that cannot be read names no game: the command reads it again and
    /// says what is wrong with it.
    pub fn parse_from_args<I, T>(args: I) -> Result<Cli, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        Self::from_matches(&Cli::command().try_get_matches_from(args)?)
    }

    fn from_matches(matches: &ArgMatches) -> Result<Cli, clap::Error> {
        let mut cli = Cli::from_arg_matches(matches)?;
        let game_left_out = matches.subcommand().is_some_and(|(_, sub)| {
            sub.ids().any(|id| id == "game")
                && sub.value_source("game") == Some(ValueSource::DefaultValue)
        });
        if let Some(command) = cli.command.as_mut().filter(|_| game_left_out) {
            command.imply_game().map_err(|e| {
                clap::Error::raw(clap::error::ErrorKind::ArgumentConflict, e + "\n")
            })?;
        }
        Ok(cli)
    }
}

impl Command {
    /// Sets the command's game to the one its policies or profile name, if any does; refused
    /// when they name two games, naming both.
    fn imply_game(&mut self) -> Result<(), String> {
        let (game, named): (&mut Game, Vec<Option<&Path>>) = match self {
            Command::Design(a) => (
                &mut a.game,
                vec![a.policies.as_deref(), a.profile.as_deref()],
            ),
            Command::Generate(a) => (
                &mut a.game,
                vec![a.policies.as_deref(), a.profile.as_deref()],
            ),
            Command::Campaign(a) => (
                &mut a.game,
                vec![a.policies.as_deref(), a.profile.as_deref()],
            ),
            Command::Bench(a) => (&mut a.game, vec![a.policies.as_deref()]),
            Command::Eval(a) => {
                let mut named: Vec<Option<&Path>> = (a.policies.iter().chain(&a.runs))
                    .map(|p| Some(p.as_path()))
                    .collect();
                named.push(a.profile.as_deref());
                (&mut a.game, named)
            }
            _ => return Ok(()),
        };
        let mut games = named
            .into_iter()
            .flatten()
            .filter_map(|path| Some((path, game_named_by(path)?)));
        let Some((first, implied)) = games.next() else {
            return Ok(());
        };
        if let Some((other, its)) = games.find(|(_, its)| *its != implied) {
            return Err(format!(
                "{} is for the {implied} game and {} for the {its} game: give files of one \
                 game (--game names it)",
                first.display(),
                other.display()
            ));
        }
        *game = implied;
        Ok(())
    }
}

/// The game a policies folder, a policy file or a profile file is for; none when it cannot be
/// read as one. A policy's game is read from the card written beside it (`solver.yaml`, a few
/// hundred bytes, which a run's record keeps alone), else from the policy file's own header.
fn game_named_by(path: &Path) -> Option<Game> {
    if path.is_dir() {
        return [GENERATOR_FILE, SOLVER_FILE]
            .into_iter()
            .find_map(|file| game_named_by(&path.join(file)));
    }
    if path.extension().is_some_and(|e| e == "safetensors") {
        let card_beside = || {
            let bytes = read_limited(&path.with_extension("yaml"), 1 << 20, "policy card").ok()?;
            let card: serde_yaml::Value = serde_yaml::from_slice(&bytes).ok()?;
            card.get("game")?.as_str()?.parse().ok()
        };
        let own_card = || {
            let bytes = read_limited(path, MAX_POLICY_BYTES, "policy").ok()?;
            read_card(&bytes).ok().map(|card| card.game)
        };
        return card_beside().or_else(own_card);
    }
    crate::services::profile::load(path).ok().map(|p| p.game())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn game_of(args: &[&str]) -> Game {
        // `generate` needs a folder to write to; nothing is written here.
        let out: &[&str] = match args[0] {
            "generate" => &["--out", "unwritten"],
            _ => &[],
        };
        let all = std::iter::once("arlpcg").chain(args.iter().chain(out).copied());
        let cli = Cli::parse_from_args(all).expect("arguments that parse");
        match cli.command.expect("a subcommand") {
            Command::Generate(a) => a.game,
            Command::Design(a) => a.game,
            Command::Eval(a) => a.game,
            other => panic!("not a command with --game: {other:?}"),
        }
    }

    #[test]
    fn the_game_left_out_is_the_one_the_policies_or_the_profile_name() {
        let racing_car = "results/racing/profiles/godot4/profile.yaml";
        assert_eq!(
            game_of(&["generate", "--policies", "policies/racing", "--aux=1"]),
            Game::Racing
        );
        assert_eq!(
            game_of(&["generate", "--rules", "--aux=1", "--profile", racing_car]),
            Game::Racing
        );
        assert_eq!(
            game_of(&["design", "--policies", "policies/racing/solver.safetensors"]),
            Game::Racing
        );
        assert_eq!(
            game_of(&["eval", "--policies", "policies/racing"]),
            Game::Racing
        );
        // A run's record in the repository keeps its cards alone.
        assert_eq!(
            game_of(&["eval", "--runs", "runs/racing-rule-pcg-s0"]),
            Game::Racing
        );
        // Nothing that names a game, or a file that is not one: platform, as before.
        assert_eq!(game_of(&["generate", "--rules", "--aux=1"]), Game::Platform);
        assert_eq!(
            game_of(&[
                "generate", "--rules", "--aux=1", "--profile", "no/such/profile.yaml"
            ]),
            Game::Platform
        );
        // Policies of one game and a profile of the other: refused, naming both.
        let mixed = Cli::parse_from_args([
            "arlpcg", "generate", "--policies", "policies/platform", "--aux=1", "--profile",
            racing_car, "--out", "unwritten",
        ])
        .expect_err("two games");
        let said = mixed.to_string();
        assert!(
            said.contains("policies/platform is for the platform game"),
            "{said}"
        );
        assert!(
            said.contains("godot4/profile.yaml for the racing game"),
            "{said}"
        );
        assert_eq!(mixed.exit_code(), 2);
        // Given, it is kept: the command then says the policies are another game's.
        assert_eq!(
            game_of(&[
                "generate", "--game", "platform", "--policies", "policies/racing", "--aux=1"
            ]),
            Game::Platform
        );
    }
}
