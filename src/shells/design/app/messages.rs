//! What flows through the designer's update: [`Message`]s in (keys, mouse, ticks, the worker's
//! [`Response`]s) and [`Effect`]s out (the work the shell hands to the worker threads).

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::crossterm::event::{KeyEvent, MouseEvent};

use super::judges;
use super::{JudgeSwitch, LoadedInfo, SweepPoint};
use crate::services::panel::Judge;
use crate::services::verify::Recording;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::stats::{SolverStats, TrialResult};
use arlpcg_core::level::{Game, Level};

/// A message from the user (through the terminal) or from the worker.
#[derive(Debug, Clone)]
pub enum Message {
    Key(KeyEvent),
    Mouse(MouseEvent),
    Resize {
        width: u16,
        height: u16,
    },
    /// Animation clock (about 30 per second).
    Tick,
    Worker(Response),
}

/// The worker's answers; each names the request it answers.
#[derive(Debug, Clone)]
pub enum Response {
    Level {
        id: u64,
        result: Result<Arc<Level>, String>,
    },
    Trial {
        id: u64,
        result: TrialResult,
    },
    TrialsDone {
        id: u64,
        stats: Box<SolverStats>,
    },
    /// The trials could not be played (the Solver does not fit the level, say).
    TrialsFailed {
        id: u64,
        problem: String,
    },
    Recorded {
        id: u64,
        result: Result<Box<Recording>, String>,
    },
    SweepPoint {
        id: u64,
        index: usize,
        point: SweepPoint,
    },
    /// Export done (the paths written), refused because files exist, or failed.
    Exported(ExportOutcome),
    Loaded(Result<Box<LoadedInfo>, String>),
    Judged(Result<Box<JudgeSwitch>, String>),
    Panel {
        id: u64,
        update: judges::PanelUpdate,
    },
    /// A campaign folder read back (or why not).
    Campaign(Result<Box<super::campaign::OpenedCampaign>, String>),
    /// A game profile read from a file (or why not).
    Profile(Result<Box<Profile>, String>),
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExportOutcome {
    Written(Vec<PathBuf>),
    WouldOverwrite(Vec<PathBuf>),
    Failed(String),
}

/// Work for the worker threads.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// A level of `game` as `ask` says: at a λ or along a curve of λ (after the pieces kept
    /// from an earlier level), or one whose success, measured with `trials` runs, is within
    /// ±0.1 of a rate (the search of `generate --target-success`).
    Generate {
        id: u64,
        game: Game,
        seed: u64,
        goal: Option<[f64; 3]>,
        ask: crate::services::generation::Ask,
        keep: Option<crate::services::generation::KeptPrefix>,
        trials: u32,
        /// The game profile the level is made for (none: the built-in one).
        profile: Option<Profile>,
    },
    Trials {
        id: u64,
        level: Arc<Level>,
        trials: u32,
        seed: u64,
    },
    Record {
        id: u64,
        level: Arc<Level>,
        seed: u64,
    },
    Sweep {
        id: u64,
        game: Game,
        seed: u64,
        goal: Option<[f64; 3]>,
        auxes: Vec<f64>,
        trials: u32,
        profile: Option<Profile>,
    },
    Export {
        level: Box<Level>,
        dir: PathBuf,
        stem: String,
        overwrite: bool,
    },
    /// Policies of `game` from a folder or one file.
    Load { path: PathBuf, game: Game },
    /// The next judge after `after` whose Solver is in `folder` (or a scripted skill) plays.
    NextJudge {
        game: Game,
        after: Judge,
        folder: PathBuf,
    },
    /// Read the campaign in `folder` (its campaign.yaml and levels).
    OpenCampaign { folder: PathBuf },
    /// Read a game profile of `game` from `path`.
    LoadProfile { path: PathBuf, game: Game },
    /// Search level `level` of the campaign in `folder` anew (the Generator on the shelf, the
    /// judge and the panel from `policies`), rate the campaign again and rewrite its files.
    RegenerateCampaignLevel {
        folder: PathBuf,
        game: Game,
        level: usize,
        policies: PathBuf,
    },
    /// Every judge whose Solver is in `folder`, and the scripted skills, play `level`.
    Panel {
        id: u64,
        level: Arc<Level>,
        folder: PathBuf,
        trials: u32,
    },
}
