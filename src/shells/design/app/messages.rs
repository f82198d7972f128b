//! What flows through the designer's update: [`Message`]s in (keys, mouse, ticks, the worker's
//! [`Response`]s) and [`Effect`]s out (the work the shell hands to the worker threads).

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::crossterm::event::{KeyEvent, MouseEvent};

use super::judges;
use super::{JudgeSwitch, LoadedInfo, SweepPoint};
use crate::services::level_files::GltfOptions;
use crate::services::panel::Judge;
use crate::services::verify::Recording;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::stats::{SolverStats, TrialResult};
use arlpcg_core::level::{Game, Level};

/// A message from the user (through the terminal) or from the worker.
#[derive(Debug, Clone)]
pub enum Message {
    /// A key press.
    Key(KeyEvent),
    /// A mouse event.
    Mouse(MouseEvent),
    /// The terminal's new size.
    Resize {
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
    },
    /// Animation clock (about 30 per second).
    Tick,
    /// An answer from the worker.
    Worker(Response),
}

/// The worker's answers; each names the request it answers.
#[derive(Debug, Clone)]
pub enum Response {
    /// A level generated, or why not.
    Level {
        /// The request's number.
        id: u64,
        /// The level, or the problem in words.
        result: Result<Arc<Level>, String>,
    },
    /// One trial finished.
    Trial {
        /// The request's number.
        id: u64,
        /// How the run went.
        result: TrialResult,
    },
    /// Every trial played: their statistics.
    TrialsDone {
        /// The request's number.
        id: u64,
        /// The trials' statistics.
        stats: Box<SolverStats>,
    },
    /// The scripted expert plays the trials in the Solver's place: it never trained with the
    /// level's abilities.
    StandIn {
        /// The request's number.
        id: u64,
        /// Why, in words.
        why: String,
    },
    /// The trials could not be played (the Solver does not fit the level, say).
    TrialsFailed {
        /// The request's number.
        id: u64,
        /// Why, in words.
        problem: String,
    },
    /// One run recorded for replay, or why not.
    Recorded {
        /// The request's number.
        id: u64,
        /// The recording, or the problem in words.
        result: Result<Box<Recording>, String>,
    },
    /// One point of the λ sweep measured.
    SweepPoint {
        /// The request's number.
        id: u64,
        /// The point's index among the sweep's λ values.
        index: usize,
        /// What was measured there.
        point: SweepPoint,
    },
    /// Export done (the paths written), refused because files exist, or failed.
    Exported(ExportOutcome),
    /// Policies loaded (what was loaded), or why not.
    Loaded(Result<Box<LoadedInfo>, String>),
    /// The next judge's Solver loaded, or why not.
    Judged(Result<Box<JudgeSwitch>, String>),
    /// Progress of the panel playing a level.
    Panel {
        /// The request's number.
        id: u64,
        /// What the panel did.
        update: judges::PanelUpdate,
    },
    /// A campaign folder read back (or why not).
    Campaign(Result<Box<super::campaign::OpenedCampaign>, String>),
    /// A game profile read from a file (or why not).
    Profile(Result<Box<Profile>, String>),
}

/// How an export ended.
#[derive(Debug, Clone, PartialEq)]
pub enum ExportOutcome {
    /// The files written.
    Written(Vec<PathBuf>),
    /// Nothing written: these files exist and overwriting was not asked for.
    WouldOverwrite(Vec<PathBuf>),
    /// The export failed, in words.
    Failed(String),
}

/// Work for the worker threads.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// A level of `game` as `ask` says: at a λ or along a curve of λ (after the pieces kept
    /// from an earlier level), or one whose success, measured with `trials` runs, is within
    /// ±0.1 of a rate (the search of `generate --target-success`).
    Generate {
        /// The request's number, which its answer carries.
        id: u64,
        /// The game.
        game: Game,
        /// The level's seed.
        seed: u64,
        /// The goal, m (none: drawn from the seed).
        goal: Option<[f64; 3]>,
        /// What is asked: a λ, a curve of λ, or a success rate.
        ask: crate::services::generation::Ask,
        /// Pieces kept from an earlier level, if any.
        keep: Option<crate::services::generation::KeptPrefix>,
        /// Runs per measurement of a success target.
        trials: u32,
        /// The game profile the level is made for (none: the built-in one).
        profile: Option<Profile>,
        /// The Generator's style knobs, in its game's order (empty: none).
        knobs: Vec<f32>,
        /// The wish list the level is searched to meet (none: the ask alone).
        want: Option<crate::services::wish::Want>,
    },
    /// Play `trials` runs of `level` with the game's current player, from `seed`.
    Trials {
        /// The request's number, which its answers carry.
        id: u64,
        /// The level to play.
        level: Arc<Level>,
        /// How many runs.
        trials: u32,
        /// The first run's seed.
        seed: u64,
    },
    /// Record one run of `level` with `seed`, to replay it.
    Record {
        /// The request's number, which its answer carries.
        id: u64,
        /// The level to play.
        level: Arc<Level>,
        /// The run's seed.
        seed: u64,
    },
    /// The λ sweep: a level at each of `auxes`, each played `trials` times.
    Sweep {
        /// The request's number, which its answers carry.
        id: u64,
        /// The game.
        game: Game,
        /// The levels' seed, and the first trial's.
        seed: u64,
        /// The goal, m (none: drawn from the seed).
        goal: Option<[f64; 3]>,
        /// The λ values, in order.
        auxes: Vec<f64>,
        /// Runs per level.
        trials: u32,
        /// The game profile the levels are made for (none: the built-in one).
        profile: Option<Profile>,
        /// The Generator's style knobs, in its game's order (empty: none).
        knobs: Vec<f32>,
    },
    /// Write the level's YAML and .glb files into `dir` as `stem.*`.
    Export {
        /// The level to write.
        level: Box<Level>,
        /// The folder.
        dir: PathBuf,
        /// The files' name without extension.
        stem: String,
        /// Whether to replace files that exist.
        overwrite: bool,
        /// How the .glb carries its colliders.
        gltf: GltfOptions,
    },
    /// Policies of `game` from a folder or one file.
    Load {
        /// The folder or policy file.
        path: PathBuf,
        /// The game.
        game: Game,
    },
    /// The next judge after `after` whose Solver is in `folder` (or a scripted skill) plays.
    NextJudge {
        /// The game.
        game: Game,
        /// The judge playing now.
        after: Judge,
        /// The folder of Solvers (none: the shipped policies of `game`).
        folder: Option<PathBuf>,
    },
    /// Read the campaign in `folder` (its campaign.yaml and levels).
    OpenCampaign {
        /// The campaign's folder.
        folder: PathBuf,
    },
    /// Read a game profile of `game` from `path`.
    LoadProfile {
        /// The profile file.
        path: PathBuf,
        /// The game it must be for.
        game: Game,
    },
    /// Search level `level` of the campaign in `folder` anew (the Generator on the shelf, the
    /// judge and the panel from `policies`), rate the campaign again and rewrite its files.
    RegenerateCampaignLevel {
        /// The campaign's folder.
        folder: PathBuf,
        /// The game.
        game: Game,
        /// The level's index in the campaign, from 0.
        level: usize,
        /// The folder of the judge's and the panel's policies (none: the shipped policies of
        /// `game`).
        policies: Option<PathBuf>,
    },
    /// Every judge whose Solver is in `folder`, and the scripted skills, play `level`.
    Panel {
        /// The request's number, which its answers carry.
        id: u64,
        /// The level to play.
        level: Arc<Level>,
        /// The folder of the panel's Solvers (none: the shipped policies of the level's game).
        folder: Option<PathBuf>,
        /// Runs per judge.
        trials: u32,
    },
    /// Show the level on screen in 3D in the web browser, and follow it from now on: the
    /// shell's, not the workers' (it serves the page itself).
    OpenView,
}
