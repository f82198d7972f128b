//! A trained Solver ready to play, and how it stands to the abilities of a profile it is to play
//! under (who plays where no player was named: [`default_player`]).

use arlpcg_core::level::profile::{Abilities, AbilityRanges, Profile};
use arlpcg_core::level::{Game, Level, PolicyRef};
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::ActorCritic;

use super::Solver;
use arlpcg_core::game::Skill;

/// A trained Solver, ready to play.
pub struct SolverPolicy {
    /// The game it was trained for.
    pub game: Game,
    /// The network.
    pub policy: ActorCritic,
    /// Its observation normalizer.
    pub normalizer: RunningNorm,
    /// The policy file, pinned by its hash.
    pub reference: PolicyRef,
    /// The game profile it trained for (none: the built-in game).
    pub profile: Option<Profile>,
    /// An ability-aware Solver: it trained with each main ability drawn within these ranges,
    /// and observes them (none: it trained with one character or car).
    pub trained_over: Option<AbilityRanges>,
}

/// How a Solver policy stands to the abilities of a profile it is to play under.
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileFit {
    /// It trained with them, or over a range that holds them.
    Fits,
    /// A policy of one character or car, trained with others: its statistics are not those of
    /// a player who trained with them (the message says so).
    Untrained(String),
    /// Beyond the range an ability-aware policy trained over: refused (the message says how to
    /// train for it).
    Beyond(String),
}

impl SolverPolicy {
    /// How it stands to playing under `played` (none: the built-in abilities).
    pub fn fit(&self, played: Option<&Profile>) -> ProfileFit {
        let abilities = |profile: Option<&Profile>| Abilities::of(profile, self.game);
        let name = |profile: Option<&Profile>| {
            profile.map_or("the built-in abilities".to_string(), |p| {
                format!("profile `{}`", p.name)
            })
        };
        let trained = self.profile.as_ref();
        match &self.trained_over {
            Some(ranges) if !ranges.holds(&abilities(played)) => ProfileFit::Beyond(format!(
                "{} lies beyond the abilities the Solver policy {} trained over ({}): train a Solver for it (arlpcg train --profile FILE)",
                name(played),
                self.reference.path,
                ranges.describe()
            )),
            None if abilities(played) != abilities(trained) => ProfileFit::Untrained(format!(
                "the Solver policy trained for {} plays under {}: its statistics are of a player who never trained with them (the scripted player, --solver scripted, plays with them)",
                name(trained),
                name(played)
            )),
            _ => ProfileFit::Fits,
        }
    }

    /// Who plays in its place under `played` when no player was named
    /// ([`default_player`]): none where it trained with those abilities, else the scripted
    /// expert and the line that says why.
    pub fn stand_in(&self, played: Option<&Profile>) -> Option<(Skill, String)> {
        let name = |profile: Option<&Profile>| {
            profile.map_or("the built-in abilities".to_string(), |p| {
                format!("profile `{}`", p.name)
            })
        };
        let why = match self.fit(played) {
            ProfileFit::Fits => return None,
            ProfileFit::Untrained(_) => format!(
                "the Solver policy {} never trained with the abilities of {}",
                self.reference.path,
                name(played)
            ),
            ProfileFit::Beyond(_) => format!(
                "{} lies beyond the abilities the Solver policy {} trained over ({})",
                name(played),
                self.reference.path,
                self.trained_over.map(|r| r.describe()).unwrap_or_default()
            ),
        };
        Some((
            Skill::Expert,
            format!(
                "{why}: the scripted expert, who plays with any abilities, plays in its place (name a Solver policy to have it play anyway)"
            ),
        ))
    }

    /// What it observes after the game's observation on `level`: for an ability-aware Solver
    /// the level's main abilities relative to ours, else nothing.
    pub(super) fn ability_row(&self, level: &Level) -> Vec<f32> {
        if self.trained_over.is_none() {
            return Vec::new();
        }
        let played = Abilities::of(level.profile.as_ref(), level.game());
        played.relative_main().to_vec()
    }
}

/// Who plays under `played` when no player was named: `solver` where it trained with those
/// abilities, else the scripted expert, who plays with any abilities, and the line that says
/// why (a command says it and plays on: it never reports a Solver's play of a character it
/// cannot play).
pub fn default_player<'a>(
    solver: &'a SolverPolicy,
    played: Option<&Profile>,
) -> (Solver<'a>, Option<String>) {
    match solver.stand_in(played) {
        None => (Solver::Policy(solver), None),
        Some((skill, why)) => (Solver::Scripted(skill), Some(why)),
    }
}
