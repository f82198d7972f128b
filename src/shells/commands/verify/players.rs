//! Who plays `verify`: the Solver of each game met, resolved from the arguments once (the
//! shipped one, its ability-aware one and the scripted expert in their place, or what
//! `--solver`/`--policy` names).

use std::collections::HashMap;
use std::collections::HashSet;
use std::path::Path;

use anyhow::Result;

use crate::services::policies::load_solver;
use crate::services::verify::{ProfileFit, Solver, SolverPolicy, default_player};
use crate::shells::cli::{SolverChoice, VerifyArgs, default_solver};
use arlpcg_core::game::Skill;
use arlpcg_core::level::{Game, Level};

/// The Solver of each game met so far, resolved from the arguments once per game.
#[derive(Default)]
pub(super) struct Solvers {
    resolved: HashMap<Game, Resolved>,
    /// What the run has said of a policy that plays, or gives way, under a profile it never
    /// trained with (each line once).
    said: HashSet<String>,
}

enum Resolved {
    /// A Solver policy. Unless `named` (by --policy or --solver policy), the scripted expert
    /// plays levels made for abilities it did not train with ([`default_player`]).
    Policy {
        policy: Box<SolverPolicy>,
        named: bool,
    },
    Scripted(Skill),
    Random,
}

impl Solvers {
    /// Resolves the Solver for levels of `game` (once), and says who plays.
    pub(super) fn resolve(&mut self, game: Game, args: &VerifyArgs) -> Result<()> {
        if self.resolved.contains_key(&game) {
            return Ok(());
        }
        let shipped = default_solver(game);
        let found = shipped.as_ref().is_ok_and(|path| path.exists());
        let choice = args.solver.unwrap_or(if args.policy.is_some() || found {
            SolverChoice::Policy
        } else {
            SolverChoice::ScriptedExpert
        });
        let resolved = match choice {
            SolverChoice::Policy => match &args.policy {
                Some(policy) => Resolved::Policy {
                    policy: Box::new(load_solver(policy, game)?.0),
                    named: true,
                },
                None => {
                    let policy = shipped.as_ref().map_err(|e| anyhow::anyhow!("{e:#}"))?;
                    Resolved::Policy {
                        policy: Box::new(load_solver(policy, game)?.0),
                        named: args.solver.is_some(),
                    }
                }
            },
            SolverChoice::Random => Resolved::Random,
            scripted => Resolved::Scripted(scripted.skill().expect("the other choices")),
        };
        if !args.json {
            let who = match &resolved {
                Resolved::Policy { policy, .. } => format!("policy {}", policy.reference.path),
                Resolved::Scripted(_) if args.solver.is_none() => match &shipped {
                    Ok(path) => {
                        format!("scripted player (no trained Solver at {})", path.display())
                    }
                    Err(e) => format!("scripted player ({e:#})"),
                },
                Resolved::Scripted(skill) => format!("scripted player ({skill})"),
                Resolved::Random => "random actions".into(),
            };
            crate::warn!("{game} solver: {who}");
        }
        self.resolved.insert(game, resolved);
        Ok(())
    }

    /// Says once that a Solver policy plays a level made for abilities other than those it
    /// trained with, or gives way to the scripted expert there; refuses a level beyond a named
    /// ability-aware policy's range.
    pub(super) fn check_profile(&mut self, level: &Level, file: &Path) -> Result<()> {
        let Resolved::Policy { policy, named } = &self.resolved[&level.game()] else {
            return Ok(());
        };
        let played = level.profile.as_ref();
        let said = match default_player(policy, played) {
            (_, Some(gave_way)) if !named => gave_way,
            _ => match policy.fit(played) {
                ProfileFit::Fits => return Ok(()),
                ProfileFit::Beyond(problem) => anyhow::bail!("{}: {problem}", file.display()),
                ProfileFit::Untrained(said) => said,
            },
        };
        if self.said.insert(said.clone()) {
            crate::warn!("{said}");
        }
        Ok(())
    }

    /// Who plays `level`.
    pub(super) fn get(&self, level: &Level) -> Solver<'_> {
        let played = level.profile.as_ref();
        match &self.resolved[&level.game()] {
            Resolved::Policy {
                policy,
                named: false,
            } => default_player(policy, played).0,
            Resolved::Policy { policy, .. } => Solver::Policy(policy),
            Resolved::Scripted(skill) => Solver::Scripted(*skill),
            Resolved::Random => Solver::Random,
        }
    }
}
