//! The designer's worker threads: they hold the policies, do the [`Effect`]s and answer with
//! [`Response`]s. The newest request of each kind wins: a request that a newer one of its kind
//! has superseded is skipped, and long work (trials, sweeps) stops as soon as it is superseded,
//! so moving the slider never queues stale work.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};

use anyhow::Result;
use rayon::ThreadPool;

use super::app::campaign::OpenedCampaign;
use super::app::judges::{PANEL_SEED, PanelUpdate};
use super::app::{Effect, ExportOutcome, Response, SweepPoint};
use crate::services::fsio::Overwrite;
use crate::services::generation::{Ask, KeptPrefix, LevelRequest};
use crate::services::level_files::{Format, GltfOptions, LevelFiles, write_level_files};
use crate::services::making::{self, LevelSource, Proof};
use crate::services::panel::rate;
use crate::services::verify::{self, Solver, Watch};
use crate::services::wish::Want;
use arlpcg_core::level::{Game, Level};

mod policies;
pub use policies::{GamePolicies, Policies, load};
use policies::{load_into, next_judge};

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
        | Effect::RegenerateCampaignLevel { .. }
        | Effect::OpenView => (Slot::Always, 0),
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
/// one for the panel (so neither holds up the level on screen). Each does its work inside a
/// rayon pool of its own, as a command does (`shells::commands::in_pool`): the worlds' steps and
/// the matrix products a tick splits across threads are handed on within the pool, not woken
/// from outside it on every call, and a long sweep never holds a pool thread that the level on
/// screen waits for.
pub struct Workers {
    latest: Arc<Latest>,
    main: Sender<Effect>,
    sweeps: Sender<Effect>,
    panel: Sender<Effect>,
}

impl Workers {
    /// Starts the workers on `policies`, each with a pool of `threads` (default: one per
    /// core); their answers go to `answers`. Fails when the system starts no more threads.
    pub fn start(
        policies: GamePolicies,
        answers: Sender<Response>,
        threads: Option<u64>,
    ) -> anyhow::Result<Self> {
        let policies = Arc::new(Mutex::new(policies));
        let latest = Arc::new(Latest::default());
        let spawn = |name: &str| -> anyhow::Result<Sender<Effect>> {
            let (tx, rx) = std::sync::mpsc::channel();
            let (policies, latest, answers) = (policies.clone(), latest.clone(), answers.clone());
            let pool = crate::shells::common::thread_pool(threads)?;
            std::thread::Builder::new()
                .name(name.into())
                .spawn(move || serve(rx, &policies, &latest, &answers, &pool))?;
            Ok(tx)
        };
        Ok(Self {
            main: spawn("designer-worker")?,
            sweeps: spawn("designer-sweeps")?,
            panel: spawn("designer-panel")?,
            latest,
        })
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
    pool: &ThreadPool,
) {
    while let Ok(effect) = requests.recv() {
        let (slot, id) = slot(&effect);
        if latest.superseded(slot, id) {
            continue;
        }
        pool.install(|| {
            perform(
                effect,
                policies,
                &|| latest.superseded(slot, id),
                &|response| {
                    // The designer may have quit; its answers are then of no use.
                    let _ = answers.send(response);
                },
            )
        });
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
            knobs,
            want,
        } => {
            let request = LevelRequest::new(seed, None)
                .goal(goal)
                .profile(profile)
                .knobs(knobs);
            let asked = (ask, keep, want);
            send(Response::Level {
                id,
                result: make_level(&shelf[game], game, request, asked, trials, stop).map(Arc::new),
            })
        }
        Effect::Trials {
            id,
            level,
            trials,
            seed,
        } => play_trials(&shelf[level.game()], id, &level, trials, seed, stop, send),
        Effect::Record { id, level, seed } => send(Response::Recorded {
            id,
            result: verify::record(&level, &shelf[level.game()].solver(&level), seed)
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
            knobs,
        } => {
            let current = &shelf[game];
            for (index, aux) in auxes.into_iter().enumerate() {
                if stop() {
                    return;
                }
                let request = LevelRequest::new(seed, Some(aux))
                    .goal(goal)
                    .profile(profile.clone())
                    .knobs(knobs.clone());
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
            gltf,
        } => send(Response::Exported(export(
            &level,
            (&dir, &stem),
            gltf,
            overwrite,
        ))),
        Effect::NextJudge {
            game,
            after,
            folder,
        } => send(Response::Judged(
            judges_folder(folder, game)
                .and_then(|folder| next_judge(policies, game, after, &folder))
                .map(Box::new),
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
            regenerate_campaign_level(policies, &folder, game, level, dir, stop)
                .map_err(|e| format!("level {} was not searched anew: {e:#}", level + 1)),
        )),
        Effect::Panel {
            id,
            level,
            folder,
            trials,
        } => play_panel(&level, folder, trials, stop, &|update| {
            send(Response::Panel { id, update })
        }),
        // The shell serves the view itself (design/browser.rs); a worker has nothing to do.
        Effect::OpenView => {}
    }
}

/// The level asked for: one that meets the wish list (its λ searched), else one that meets
/// the success target over `trials` runs, else the Generator's (or the rules') level at its λ;
/// continuing the kept prefix where one is given.
fn make_level(
    policies: &Policies,
    game: Game,
    request: LevelRequest,
    (ask, keep, want): (Ask, Option<KeptPrefix>, Option<Want>),
    trials: u32,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Level, String> {
    if let Some(want) = want {
        let mut request = request;
        if let Some(keep) = keep {
            request = request.keep(keep);
        }
        return wanted_level(policies, game, request, &want, stop);
    }
    match (ask.success(), ask.aux()) {
        (Some(target), _) => target_level(policies, &request, (target, trials), stop),
        (None, aux) => {
            let mut request = request;
            if let Some(aux) = aux {
                request = request.aux(aux);
            }
            if let Some(keep) = keep {
                request = request.keep(keep);
            }
            policies.level(game, request)
        }
    }
}

/// Runs per candidate of a wish list's search in the designer (`generate --want`'s default).
const WANT_TRIALS: u32 = 20;

/// A level of `request`'s seed that meets `want` ([`making::wanted`]): played by the Solver
/// that plays under its profile (else the scripted player), the scripted judges for theirs.
fn wanted_level(
    policies: &Policies,
    game: Game,
    request: LevelRequest,
    want: &Want,
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<Level, String> {
    let request = request.obstacles(arlpcg_core::game::facts::facts(game).scene_obstacles);
    let source = policies
        .generator
        .as_deref()
        .map_or(LevelSource::Rules(game), LevelSource::Generator);
    let solver = match policies.solver.as_deref() {
        Some(policy) => Solver::Policy(policy),
        None => Solver::Scripted(policies.skill),
    };
    let judges: Vec<_> = want
        .judges()
        .into_iter()
        .map(|j| (j, j.player(None)))
        .collect();
    let search = making::wanted::Search {
        want,
        solver: Some(&solver),
        judges: &judges,
        trials: WANT_TRIALS,
    };
    let watch = verify::Watch {
        on_trial: &|_| {},
        stop,
    };
    match making::verified_level(source, &request, &Proof::Wanted(search), &watch, &|_| {}) {
        Ok(Some(level)) => Ok(level),
        Ok(None) => Err("stopped".into()),
        Err(e) => Err(format!("{e:#}")),
    }
}

/// The folder the judges of `game` come from: `folder`, else the shipped policies.
fn judges_folder(folder: Option<PathBuf>, game: Game) -> Result<PathBuf, String> {
    match folder {
        Some(folder) => Ok(folder),
        None => crate::shells::common::shipped_dir(game).map_err(|e| format!("{e:#}")),
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
/// ([`crate::services::campaign::regenerate_level`]) and the judge of the policies folder
/// `dir` (none: the shipped one), read back for the view.
fn regenerate_campaign_level(
    policies: &Mutex<GamePolicies>,
    folder: &Path,
    game: Game,
    k: usize,
    dir: Option<PathBuf>,
    stop: &(dyn Fn() -> bool + Sync),
) -> anyhow::Result<Box<OpenedCampaign>> {
    let dir = judges_folder(dir, game).map_err(anyhow::Error::msg)?;
    let generator = policies
        .lock()
        .ok()
        .and_then(|shelf| shelf[game].generator.clone())
        .ok_or_else(|| anyhow::anyhow!("no {game} Generator is loaded (p loads one)"))?;
    let (folder, record, levels) = crate::services::campaign::regenerate_level(
        folder,
        k,
        &generator,
        (&dir, crate::shells::common::cache_dir().as_deref()),
        stop,
    )?;
    Ok(Box::new(OpenedCampaign {
        folder,
        record,
        levels: levels.into_iter().map(Arc::new).collect(),
        regenerated: Some(k),
    }))
}

/// Every judge of the panel in `folder` (none: the shipped policies) plays `level` `trials`
/// times, each reported as it ends; then the level is rated. Nothing more once `stop` says so.
fn play_panel(
    level: &Level,
    folder: Option<PathBuf>,
    trials: u32,
    stop: &(dyn Fn() -> bool + Sync),
    send: &dyn Fn(PanelUpdate),
) {
    let panel = judges_folder(folder, level.game()).and_then(|folder| {
        crate::services::policies::load_panel(&folder, level.game(), None)
            .map_err(|e| format!("{e:#}"))
    });
    let panel = match panel {
        Ok(panel) => panel,
        Err(e) => return send(PanelUpdate::Failed(e)),
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
    let (who, stand_in) = current.player(level);
    if let Some(why) = stand_in {
        send(Response::StandIn { id, why });
    }
    match verify::verify_watched(level, &who, trials, seed, &watch) {
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

/// The target-success search of `generate --target-success` with the designer's policies: the
/// λ→success curve is read from the Generator's folder or the cache (or, the first time,
/// measured into the cache). A newer request (`stop`) ends the measurement and the search.
fn target_level(
    policies: &Policies,
    asked: &LevelRequest,
    (target, trials): (f64, u32),
    stop: &(dyn Fn() -> bool + Sync),
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
    let cache = crate::shells::common::cache_dir();
    let curve = crate::services::policies::difficulty_curve(
        (folder, cache.as_deref()),
        generator,
        &Solver::Policy(solver),
        asked.profile.as_ref(),
        || {},
        stop,
    )
    .map_err(|e| format!("{e:#}"))?;
    let proof = Proof::Target {
        solver: &Solver::Policy(solver),
        curve: &curve,
        target,
        trials,
        checks: &[],
    };
    let watch = verify::Watch {
        on_trial: &|_| {},
        stop,
    };
    making::verified_level(
        LevelSource::Generator(generator),
        asked,
        &proof,
        &watch,
        &|_| {},
    )
    .map_err(|e| format!("{e:#}"))?
    .ok_or_else(|| "the search was stopped".to_string())
}

/// Writes the level's YAML and `.glb` (its colliders as `gltf` says) into `dir` as `stem.*`,
/// unless one exists and `overwrite` is false.
fn export(
    level: &Level,
    (dir, stem): (&Path, &str),
    gltf: GltfOptions,
    overwrite: bool,
) -> ExportOutcome {
    let files = LevelFiles::new(dir, stem, &[Format::Yaml, Format::Glb]).with_gltf(gltf);
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
