//! What the designer knows of the policies in use: their files and cards, the scripted player's
//! skill, and who of the panel of judges plays the trials.

use std::path::{Path, PathBuf};

use crate::services::panel::Judge;
use arlpcg_core::game::Skill;
use arlpcg_core::rl::checkpoint::PolicyCard;

/// What is known about a loaded policy, for display.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyInfo {
    /// The policy file.
    pub path: PathBuf,
    /// Its card.
    pub card: PolicyCard,
}

/// The policies the worker holds: a Generator and a Solver, each optional (without a Generator
/// the designer draws rule levels; without a Solver the scripted controller plays).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LoadedInfo {
    /// The Generator, if one is loaded.
    pub generator: Option<PolicyInfo>,
    /// The Solver, if one is loaded.
    pub solver: Option<PolicyInfo>,
    /// The scripted player's skill, when it plays (no Solver).
    pub skill: Skill,
}

impl LoadedInfo {
    /// Who plays the trials: the Solver, by its training mode, or the scripted player.
    pub fn judge(&self) -> Judge {
        match &self.solver {
            Some(solver) => Judge::Solver(solver.card.training.mode),
            None => Judge::Scripted(self.skill),
        }
    }

    /// The folder the judges come from: the Solver's, else the Generator's; none: the shipped
    /// policies of the game (which the worker finds).
    pub fn folder(&self) -> Option<PathBuf> {
        [&self.solver, &self.generator]
            .into_iter()
            .flatten()
            .find_map(|p| p.path.parent().map(Path::to_path_buf))
    }
}

/// The judge now playing the trials, after `j`.
#[derive(Debug, Clone, PartialEq)]
pub struct JudgeSwitch {
    /// The judge's Solver, if it is a policy.
    pub solver: Option<PolicyInfo>,
    /// The scripted player's skill, when it plays (no Solver).
    pub skill: Skill,
}
