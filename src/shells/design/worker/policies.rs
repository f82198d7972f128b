//! The policies the designer's workers hold, per game: loading a folder or a file, and switching
//! the judge that plays.

use std::path::Path;
use std::sync::{Arc, Mutex};

use anyhow::Result;

use super::super::app::{JudgeSwitch, LoadedInfo, PolicyInfo};
use crate::services::generation::{GeneratorPolicy, LevelRequest};
use crate::services::making::LevelSource;
use crate::services::panel::Judge;
use crate::services::policies::{load_generator, load_solver, policy_paths};
use crate::services::verify::{self, Solver, SolverPolicy};
use arlpcg_core::game::Skill;

use arlpcg_core::level::{Game, Level, PerGame};
use arlpcg_core::rl::checkpoint::PolicyError;

/// The policies of one game in use; either may be missing (rule levels; the scripted player).
#[derive(Default, Clone)]
pub struct Policies {
    /// The Generator, if one is loaded (none: rule levels).
    pub generator: Option<Arc<GeneratorPolicy>>,
    /// The Solver, if one is loaded (none: the scripted player).
    pub solver: Option<Arc<SolverPolicy>>,
    /// The scripted player's skill, when it plays (no Solver).
    pub skill: Skill,
}

/// The policies of each game.
pub type GamePolicies = PerGame<Policies>;

impl Policies {
    /// Who plays `level`: the Solver, where it trained with the level's abilities; else the
    /// scripted expert, and the line that says why ([`verify::default_player`]). Without a
    /// Solver, the scripted player at its skill.
    pub(super) fn player(&self, level: &Level) -> (Solver<'_>, Option<String>) {
        match self.solver.as_deref() {
            Some(solver) => verify::default_player(solver, level.profile.as_ref()),
            None => (Solver::Scripted(self.skill), None),
        }
    }

    /// Who plays `level` ([`Self::player`]).
    pub(super) fn solver(&self, level: &Level) -> Solver<'_> {
        self.player(level).0
    }

    /// The level of `game` that `request` asks for: the Generator's, or the rules' without
    /// one; racing scenes hold the obstacles evaluation scenes hold.
    pub fn level(&self, game: Game, request: LevelRequest) -> Result<Level, String> {
        let request = request.obstacles(arlpcg_core::game::facts::facts(game).scene_obstacles);
        let source = self
            .generator
            .as_deref()
            .map_or(LevelSource::Rules(game), LevelSource::Generator);
        source.level(&request).map_err(|e| e.to_string())
    }
}

/// Loads the policies of `game` at `path`: a folder (its generator.safetensors and
/// solver.safetensors, whichever exist) or one policy file (a Generator or a Solver, from its
/// card).
pub fn load(path: &Path, game: Game) -> Result<(Policies, LoadedInfo)> {
    let mut policies = Policies::default();
    let mut info = LoadedInfo::default();
    let mut load_generator_at = |p: &Path, policies: &mut Policies| -> Result<()> {
        let (generator, card) = load_generator(p, game)?;
        policies.generator = Some(Arc::new(generator));
        info.generator = Some(PolicyInfo {
            path: p.to_path_buf(),
            card,
        });
        Ok(())
    };
    if path.is_dir() {
        let (generator, solver) = policy_paths(path);
        if !generator.exists() && !solver.exists() {
            anyhow::bail!(
                "{} holds neither {} nor {}",
                path.display(),
                crate::services::policies::GENERATOR_FILE,
                crate::services::policies::SOLVER_FILE
            );
        }
        if generator.exists() {
            load_generator_at(&generator, &mut policies)?;
        }
        if solver.exists() {
            let (policy, card) = load_solver(&solver, game)?;
            policies.solver = Some(Arc::new(policy));
            info.solver = Some(PolicyInfo { path: solver, card });
        }
        return Ok((policies, info));
    }
    match load_generator_at(path, &mut policies) {
        Ok(()) => Ok((policies, info)),
        Err(e) if matches!(e.downcast_ref(), Some(PolicyError::WrongKind { .. })) => {
            let (policy, card) = load_solver(path, game)?;
            policies.solver = Some(Arc::new(policy));
            info.solver = Some(PolicyInfo {
                path: path.to_path_buf(),
                card,
            });
            Ok((policies, info))
        }
        Err(e) => Err(e),
    }
}

/// Loads the policies at `path` for `game` into the shared shelf: a single file replaces only
/// its own role.
pub(super) fn load_into(
    policies: &Mutex<GamePolicies>,
    path: &Path,
    game: Game,
) -> Result<Box<LoadedInfo>, String> {
    let (loaded, info) = load(path, game).map_err(|e| format!("{e:#}"))?;
    if let Ok(mut shared) = policies.lock() {
        let old = &mut shared[game];
        *old = Policies {
            generator: loaded.generator.or(old.generator.clone()),
            solver: loaded.solver.or(old.solver.clone()),
            skill: old.skill,
        };
    }
    Ok(Box::new(info))
}

/// The judge after `after` in [`Judge::ALL`] (cyclically) that can play: a scripted skill, or a
/// Solver whose file is in `folder` (others are passed over); it becomes the game's player.
pub(super) fn next_judge(
    policies: &Mutex<GamePolicies>,
    game: Game,
    after: Judge,
    folder: &Path,
) -> Result<JudgeSwitch, String> {
    let start = Judge::ALL.iter().position(|j| *j == after).unwrap_or(0);
    for k in 1..=Judge::ALL.len() {
        let judge = Judge::ALL[(start + k) % Judge::ALL.len()];
        let (solver, info, skill) = match judge {
            Judge::Scripted(skill) => (None, None, skill),
            Judge::Solver(_) => {
                let path = crate::services::policies::judge_file(folder, judge)
                    .expect("a Solver judge has a file");
                if !path.exists() {
                    continue;
                }
                let (policy, card) = crate::services::policies::load_judge(folder, game, judge)
                    .map_err(|e| format!("{e:#}"))?
                    .expect("a Solver judge is loaded with its policy");
                (
                    Some(Arc::new(policy)),
                    Some(PolicyInfo { path, card }),
                    Skill::Expert,
                )
            }
        };
        if let Ok(mut shared) = policies.lock() {
            let current = &mut shared[game];
            current.solver = solver;
            current.skill = skill;
        }
        return Ok(JudgeSwitch {
            solver: info,
            skill,
        });
    }
    Err("no judge can play".into())
}
