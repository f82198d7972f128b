//! The designer's worker threads: they hold the policies, do the [`Effect`]s and answer with
//! [`Response`]s. The newest request of each kind wins: a request that a newer one of its kind
//! has superseded is skipped, and long work (trials, sweeps) stops as soon as it is superseded,
//! so moving the slider never queues stale work.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};

use anyhow::Result;

use super::app::campaign::OpenedCampaign;
use super::app::judges::{PANEL_SEED, PanelUpdate};
use super::app::{
    Effect, ExportOutcome, JudgeSwitch, LoadedInfo, PolicyInfo, Response, SweepPoint,
};
use crate::services::fsio::Overwrite;
use crate::services::generation::{self, GeneratorPolicy, LevelRequest};
use crate::services::level_files::{Format, LevelFiles, write_level_files};
use crate::services::panel::{Judge, rate};
use crate::services::policies::{load_aware_solver, load_generator, load_solver, policy_paths};
use crate::services::verify::{self, Solver, SolverPolicy, Watch};
use arlpcg_core::game::Skill;
use arlpcg_core::level::{Game, Level};
use arlpcg_core::rl::checkpoint::{PolicyError, TrainMode};

/// The policies of one game in use; either may be missing (rule levels; the scripted player).
#[derive(Default, Clone)]
pub struct Policies {
    pub generator: Option<Arc<GeneratorPolicy>>,
    pub solver: Option<Arc<SolverPolicy>>,
    /// The folder's ability-aware Solver, which plays levels made for abilities the Solver did
    /// not train with ([`SolverPolicy::or_aware`]).
    pub aware: Option<Arc<SolverPolicy>>,
    /// The scripted player's skill, when it plays (no Solver).
    pub skill: Skill,
}

/// The policies of each game.
#[derive(Default, Clone)]
pub struct GamePolicies {
    pub platform: Policies,
    pub racing: Policies,
}

impl GamePolicies {
    pub fn of(&self, game: Game) -> &Policies {
        match game {
            Game::Platform => &self.platform,
            Game::Racing => &self.racing,
        }
    }

    pub fn of_mut(&mut self, game: Game) -> &mut Policies {
        match game {
            Game::Platform => &mut self.platform,
            Game::Racing => &mut self.racing,
        }
    }
}

impl Policies {
    /// Why the Solver policy may not play `level`: the abilities it is made for lie beyond the
    /// range the policy trained over (it says to train for them).
    fn beyond_range(&self, level: &Level) -> Option<String> {
        match self.policy_for(level)?.fit(level.profile.as_ref()) {
            verify::ProfileFit::Beyond(problem) => Some(problem),
            _ => None,
        }
    }

    /// The Solver policy that plays `level`, if one does.
    fn policy_for(&self, level: &Level) -> Option<&SolverPolicy> {
        let solver = self.solver.as_deref()?;
        Some(solver.or_aware(self.aware.as_deref(), level.profile.as_ref()))
    }

    /// Who plays `level`.
    fn solver(&self, level: &Level) -> Solver<'_> {
        match self.policy_for(level) {
            Some(policy) => Solver::Policy(policy),
            None => Solver::Scripted(self.skill),
        }
    }

    /// The level of `game` that `request` asks for: the Generator's, or the rules' without
    /// one; racing scenes hold the obstacles evaluation scenes hold.
    pub fn level(&self, game: Game, request: LevelRequest) -> Result<Level, String> {
        let request = request.obstacles(arlpcg_core::game::facts::facts(game).scene_obstacles);
        match &self.generator {
            Some(generator) => {
                generation::generator_level(generator, &request).map_err(|e| e.to_string())
            }
            None => generation::rules_level(game, &request).map_err(|e| e.to_string()),
        }
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
            policies.aware = load_aware_solver(path, game)?.map(Arc::new);
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

/// Which requests supersede each other.
#[derive(Debug, Clone, Copy)]
enum Slot {
    /// Generation and the trials on the generated level.
    Level = 0,
    Record = 1,
    Sweep = 2,
    Panel = 3,
    /// Exports and loads: never superseded.
    Always = 4,
}

fn slot(effect: &Effect) -> (Slot, u64) {
    match effect {
        Effect::Generate { id, .. } | Effect::Trials { id, .. } => (Slot::Level, *id),
        Effect::Record { id, .. } => (Slot::Record, *id),
        Effect::Sweep { id, .. } => (Slot::Sweep, *id),
        Effect::Panel { id, .. } => (Slot::Panel, *id),
        Effect::Export { .. }
        | Effect::Load { .. }
        | Effect::NextJudge { .. }
        | Effect::OpenCampaign { .. }
        | Effect::LoadProfile { .. }
        | Effect::RegenerateCampaignLevel { .. } => (Slot::Always, 0),
    }
}

/// The newest request id of each slot, shared by the UI (which raises them) and the workers.
#[derive(Default)]
struct Latest([AtomicU64; 5]);

impl Latest {
    fn superseded(&self, slot: Slot, id: u64) -> bool {
        !matches!(slot, Slot::Always) && self.0[slot as usize].load(Ordering::Relaxed) != id
    }
}

/// The worker threads: one for levels, trials, replays, exports and loads; one for sweeps and
/// one for the panel (so neither holds up the level on screen).
pub struct Workers {
    latest: Arc<Latest>,
    main: Sender<Effect>,
    sweeps: Sender<Effect>,
    panel: Sender<Effect>,
}

impl Workers {
    /// Starts the workers on `policies`; their answers go to `answers`.
    pub fn start(policies: GamePolicies, answers: Sender<Response>) -> Self {
        let policies = Arc::new(Mutex::new(policies));
        let latest = Arc::new(Latest::default());
        let spawn = |name: &str| {
            let (tx, rx) = std::sync::mpsc::channel();
            let (policies, latest, answers) = (policies.clone(), latest.clone(), answers.clone());
            std::thread::Builder::new()
                .name(name.into())
                .spawn(move || serve(rx, &policies, &latest, &answers))
                .expect("the OS starts a thread");
            tx
        };
        Self {
            main: spawn("designer-worker"),
            sweeps: spawn("designer-sweeps"),
            panel: spawn("designer-panel"),
            latest,
        }
    }

    /// Hands `effect` to its worker; it supersedes older requests of its kind.
    pub fn submit(&self, effect: Effect) {
        let (slot, id) = slot(&effect);
        if !matches!(slot, Slot::Always) {
            self.latest.0[slot as usize].store(id, Ordering::Relaxed);
        }
        let to = match slot {
            Slot::Sweep => &self.sweeps,
            Slot::Panel => &self.panel,
            _ => &self.main,
        };
        // A worker only stops when the designer drops its sender, so sending cannot fail.
        let _ = to.send(effect);
    }
}

type SharedPolicies = Mutex<GamePolicies>;

fn serve(
    requests: Receiver<Effect>,
    policies: &SharedPolicies,
    latest: &Latest,
    answers: &Sender<Response>,
) {
    while let Ok(effect) = requests.recv() {
        let (slot, id) = slot(&effect);
        if latest.superseded(slot, id) {
            continue;
        }
        perform(
            effect,
            policies,
            &|| latest.superseded(slot, id),
            &|response| {
                // The designer may have quit; its answers are then of no use.
                let _ = answers.send(response);
            },
        );
    }
}

/// Does `effect` with `policies`, answering through `send`; long work ends early when `stop`
/// says so. The worker threads call it; tests call it inline.
pub fn perform(
    effect: Effect,
    policies: &Mutex<GamePolicies>,
    stop: &(dyn Fn() -> bool + Sync),
    send: &(dyn Fn(Response) + Sync),
) {
    let shelf = policies.lock().map(|p| p.clone()).unwrap_or_default();
    match effect {
        Effect::Generate {
            id,
            game,
            seed,
            goal,
            ask,
            keep,
            trials,
            profile,
        } => {
            let result = match (ask.success(), ask.aux()) {
                (Some(target), _) => {
                    let asked = LevelRequest::new(seed, None).goal(goal).profile(profile);
                    target_level(shelf.of(game), &asked, target, trials)
                }
                (None, aux) => {
                    let mut request = LevelRequest::new(seed, None).goal(goal).profile(profile);
                    if let Some(aux) = aux {
                        request = request.aux(aux);
                    }
                    if let Some(keep) = keep {
                        request = request.keep(keep);
                    }
                    shelf.of(game).level(game, request)
                }
            };
            send(Response::Level {
                id,
                result: result.map(Arc::new),
            })
        }
        Effect::Trials {
            id,
            level,
            trials,
            seed,
        } => play_trials(shelf.of(level.game()), id, &level, trials, seed, stop, send),
        Effect::Record { id, level, seed } => send(Response::Recorded {
            id,
            result: verify::record(&level, &shelf.of(level.game()).solver(&level), seed)
                .map(Box::new)
                .map_err(|e| e.to_string()),
        }),
        Effect::Sweep {
            id,
            game,
            seed,
            goal,
            auxes,
            trials,
            profile,
        } => {
            let current = shelf.of(game);
            for (index, aux) in auxes.into_iter().enumerate() {
                if stop() {
                    return;
                }
                let request = LevelRequest::new(seed, Some(aux))
                    .goal(goal)
                    .profile(profile.clone());
                let Some(point) = sweep_point(current, game, request, trials, stop) else {
                    return;
                };
                send(Response::SweepPoint { id, index, point });
            }
        }
        Effect::Export {
            level,
            dir,
            stem,
            overwrite,
        } => send(Response::Exported(export(&level, &dir, &stem, overwrite))),
        Effect::NextJudge {
            game,
            after,
            folder,
        } => send(Response::Judged(
            next_judge(policies, game, after, &folder).map(Box::new),
        )),
        Effect::Load { path, game } => send(Response::Loaded(load_into(policies, &path, game))),
        Effect::OpenCampaign { folder } => send(Response::Campaign(open_campaign(&folder))),
        Effect::LoadProfile { path, game } => send(Response::Profile(
            crate::services::profile::load(&path)
                .and_then(|p| crate::services::profile::for_game(p, game, &path))
                .map(Box::new)
                .map_err(|e| format!("{e:#}")),
        )),
        Effect::RegenerateCampaignLevel {
            folder,
            game,
            level,
            policies: dir,
        } => send(Response::Campaign(
            regenerate_campaign_level(policies, &folder, game, level, &dir, stop)
                .map_err(|e| format!("level {} was not searched anew: {e:#}", level + 1)),
        )),
        Effect::Panel {
            id,
            level,
            folder,
            trials,
        } => play_panel(&level, &folder, trials, stop, &|update| {
            send(Response::Panel { id, update })
        }),
    }
}

/// The campaign in `folder`, read back for the designer's view.
fn open_campaign(folder: &Path) -> Result<Box<OpenedCampaign>, String> {
    let (folder, record, levels) =
        crate::services::campaign::open(folder).map_err(|e| format!("{e:#}"))?;
    Ok(Box::new(OpenedCampaign {
        folder,
        record,
        levels: levels.into_iter().map(Arc::new).collect(),
        regenerated: None,
    }))
}

/// Level `k` of the campaign in `folder` searched anew with the Generator on the shelf
/// ([`crate::services::campaign::regenerate_level`]), read back for the view.
fn regenerate_campaign_level(
    policies: &Mutex<GamePolicies>,
    folder: &Path,
    game: Game,
    k: usize,
    dir: &Path,
    stop: &(dyn Fn() -> bool + Sync),
) -> anyhow::Result<Box<OpenedCampaign>> {
    let generator = policies
        .lock()
        .ok()
        .and_then(|shelf| shelf.of(game).generator.clone())
        .ok_or_else(|| anyhow::anyhow!("no {game} Generator is loaded (p loads one)"))?;
    let (folder, record, levels) =
        crate::services::campaign::regenerate_level(folder, k, &generator, dir, stop)?;
    Ok(Box::new(OpenedCampaign {
        folder,
        record,
        levels: levels.into_iter().map(Arc::new).collect(),
        regenerated: Some(k),
    }))
}

/// Every judge of the panel in `folder` plays `level` `trials` times, each reported as it
/// ends; then the level is rated. Nothing more once `stop` says so.
fn play_panel(
    level: &Level,
    folder: &Path,
    trials: u32,
    stop: &(dyn Fn() -> bool + Sync),
    send: &dyn Fn(PanelUpdate),
) {
    let panel = match crate::services::policies::load_panel(folder, level.game(), None) {
        Ok(panel) => panel,
        Err(e) => return send(PanelUpdate::Failed(format!("{e:#}"))),
    };
    send(PanelUpdate::Judges(panel.names()));
    let watch = Watch {
        on_trial: &|_| {},
        stop,
    };
    let on_judge = |index: usize, stats: &arlpcg_core::level::stats::SolverStats| {
        send(PanelUpdate::Played {
            index,
            success_ratio: stats.success_ratio,
            ci95: stats.ci95,
        })
    };
    match crate::services::panel::play(&panel, level, trials, PANEL_SEED, &watch, &on_judge) {
        Ok(Some(mut stats)) => {
            rate(&mut [&mut stats]);
            send(PanelUpdate::Rated(Box::new(stats)));
        }
        Ok(None) => {}
        Err(e) => send(PanelUpdate::Failed(e.to_string())),
    }
}

/// Plays `trials` runs of `level` with the game's current player, answering each trial as it
/// ends and then the statistics (nothing when `stop` cut the trials short).
fn play_trials(
    current: &Policies,
    id: u64,
    level: &Level,
    trials: u32,
    seed: u64,
    stop: &(dyn Fn() -> bool + Sync),
    send: &(dyn Fn(Response) + Sync),
) {
    let on_trial = |result: &_| {
        send(Response::Trial {
            id,
            result: *result,
        })
    };
    let watch = Watch {
        on_trial: &on_trial,
        stop,
    };
    if let Some(problem) = current.beyond_range(level) {
        return send(Response::TrialsFailed { id, problem });
    }
    match verify::verify_watched(level, &current.solver(level), trials, seed, &watch) {
        Ok(Some(stats)) => send(Response::TrialsDone {
            id,
            stats: Box::new(stats),
        }),
        Ok(None) => {}
        Err(e) => send(Response::TrialsFailed {
            id,
            problem: e.to_string(),
        }),
    }
}

/// One point of the λ sweep: the success of the current player on the level `request` asks
/// for, or why there is none; `None` when `stop` cut the trials short.
fn sweep_point(
    current: &Policies,
    game: Game,
    request: LevelRequest,
    trials: u32,
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<SweepPoint> {
    let seed = request.seed;
    let level = match current.level(game, request) {
        Ok(level) => level,
        Err(problem) => return Some(SweepPoint::NoLevel(problem)),
    };
    if let Some(problem) = current.beyond_range(&level) {
        return Some(SweepPoint::NoLevel(problem));
    }
    let watch = Watch {
        on_trial: &|_| {},
        stop,
    };
    match verify::verify_watched(&level, &current.solver(&level), trials, seed, &watch) {
        Ok(Some(stats)) => Some(SweepPoint::Success(stats.success_ratio)),
        Ok(None) => None,
        Err(e) => Some(SweepPoint::NoLevel(e.to_string())),
    }
}

/// Loads the policies at `path` for `game` into the shared shelf: a single file replaces only
/// its own role.
fn load_into(
    policies: &Mutex<GamePolicies>,
    path: &Path,
    game: Game,
) -> Result<Box<LoadedInfo>, String> {
    let (loaded, info) = load(path, game).map_err(|e| format!("{e:#}"))?;
    if let Ok(mut shared) = policies.lock() {
        let old = shared.of_mut(game);
        *old = Policies {
            generator: loaded.generator.or(old.generator.clone()),
            aware: match loaded.solver {
                Some(_) => loaded.aware,
                None => old.aware.clone(),
            },
            solver: loaded.solver.or(old.solver.clone()),
            skill: old.skill,
        };
    }
    Ok(Box::new(info))
}

/// The judge after `after` in [`Judge::ALL`] (cyclically) that can play: a scripted skill, or a
/// Solver whose file is in `folder` (others are passed over); it becomes the game's player.
fn next_judge(
    policies: &Mutex<GamePolicies>,
    game: Game,
    after: Judge,
    folder: &Path,
) -> Result<JudgeSwitch, String> {
    let start = Judge::ALL.iter().position(|j| *j == after).unwrap_or(0);
    for k in 1..=Judge::ALL.len() {
        let judge = Judge::ALL[(start + k) % Judge::ALL.len()];
        let (solver, info, skill) = match judge {
            Judge::Scripted(skill) => ((None, None), None, skill),
            Judge::Solver(_) => {
                let path = crate::services::policies::judge_file(folder, judge)
                    .expect("a Solver judge has a file");
                if !path.exists() {
                    continue;
                }
                let (policy, card) = crate::services::policies::load_judge(folder, game, judge)
                    .map_err(|e| format!("{e:#}"))?
                    .expect("a Solver judge is loaded with its policy");
                // The ARLPCG judge brings the folder's ability-aware Solver with it.
                let aware = match judge {
                    Judge::Solver(TrainMode::Arlpcg) => load_aware_solver(folder, game)
                        .map_err(|e| format!("{e:#}"))?
                        .map(Arc::new),
                    Judge::Solver(_) | Judge::Scripted(_) => None,
                };
                (
                    (Some(Arc::new(policy)), aware),
                    Some(PolicyInfo { path, card }),
                    Skill::Expert,
                )
            }
        };
        if let Ok(mut shared) = policies.lock() {
            let current = shared.of_mut(game);
            (current.solver, current.aware) = solver;
            current.skill = skill;
        }
        return Ok(JudgeSwitch {
            solver: info,
            skill,
        });
    }
    Err("no judge can play".into())
}

/// The target-success search of `generate --target-success` with the designer's policies: the
/// λ→success curve is read from (or, the first time, measured into) the Generator's folder.
fn target_level(
    policies: &Policies,
    asked: &LevelRequest,
    target: f64,
    trials: u32,
) -> Result<Level, String> {
    let generator = policies
        .generator
        .as_deref()
        .ok_or("a success target needs a Generator")?;
    let solver = policies
        .solver
        .as_deref()
        .ok_or("a success target needs a trained Solver to measure success with (p loads one)")?;
    let folder = Path::new(&generator.reference.path)
        .parent()
        .unwrap_or(Path::new("."));
    let curve = crate::services::policies::difficulty_curve(
        folder,
        generator,
        &Solver::Policy(solver),
        || {},
        &|| false,
    )
    .map_err(|e| format!("{e:#}"))?;
    crate::services::difficulty::level_for(
        generator,
        &Solver::Policy(solver),
        &curve,
        asked,
        target,
        trials,
    )
    .map_err(|e| e.to_string())
}

/// Writes the level's YAML and `.glb` into `dir` as `stem.*`, unless one exists and `overwrite`
/// is false.
fn export(level: &Level, dir: &Path, stem: &str, overwrite: bool) -> ExportOutcome {
    let files = LevelFiles::new(dir, stem, &[Format::Yaml, Format::Glb]);
    let paths = files.paths();
    let existing: Vec<PathBuf> = paths.iter().filter(|p| p.exists()).cloned().collect();
    if !existing.is_empty() && !overwrite {
        return ExportOutcome::WouldOverwrite(existing);
    }
    let written = std::fs::create_dir_all(dir)
        .map_err(anyhow::Error::from)
        .and_then(|()| write_level_files(level, &files, Overwrite::Allowed));
    match written {
        Ok(()) => ExportOutcome::Written(paths),
        Err(e) => ExportOutcome::Failed(format!("export to {} failed: {e:#}", dir.display())),
    }
}
