//! The designer's state and its pure update: `update(state, message) -> effects`. Keys, mouse,
//! ticks and the worker's answers come in as [`Message`]s; the work to do goes out as
//! [`Effect`]s, which the shell hands to the worker threads. Nothing here touches the terminal,
//! the file system or a clock, so key scripts drive it in tests.

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::layout::Rect;

use arlpcg_core::level::heading::{direction_heading, heading_direction, wrap_degrees};
use arlpcg_core::level::params::quantize;

pub use crate::services::generation::Ask;
use crate::services::level_files::GltfOptions;
use crate::services::verify::Recording;
use arlpcg_core::level::{Game, Level, PerGame};

use super::layout::Areas;

pub mod campaign;
mod input;
pub mod judges;
mod loaded;
mod messages;
pub mod pacing;
pub mod profile;
mod responses;
pub mod sweep;
pub mod trials;

pub use input::PromptKind;
pub use messages::{Effect, ExportOutcome, Message, Response};
pub use trials::Trials;

pub use loaded::{JudgeSwitch, LoadedInfo, PolicyInfo};
pub use sweep::{Sweep, SweepPoint};

/// Steps of the λ slider (keys), and its range.
pub const AUX_STEP: f64 = 0.1;
/// Default Solver trials on each generated level.
pub const DEFAULT_TRIALS: u32 = 100;
/// Most trials one level may be given from the prompt.
pub const MAX_TRIALS: u32 = 10_000;
/// Replay steps shown per tick (the game runs at 50 steps/s; ticks come every ~33 ms).
pub const REPLAY_STEPS_PER_TICK: usize = 2;

/// Where the goal comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GoalSetting {
    /// Drawn from the seed, as the rules and the Generator draw it.
    FromSeed,
    /// Set by the designer: horizontal distance (m), height above the start (m), direction
    /// (degrees, the heading convention of level files).
    Custom {
        /// Horizontal distance from the start, m.
        distance: f64,
        /// Height above the start, m.
        height: f64,
        /// Direction, degrees (the heading convention of level files).
        direction: f64,
    },
}

impl GoalSetting {
    /// The goal position, or `None` to draw it from the seed.
    pub fn position(&self) -> Option<[f64; 3]> {
        match *self {
            GoalSetting::FromSeed => None,
            GoalSetting::Custom {
                distance,
                height,
                direction,
            } => {
                let [x, z] = heading_direction(direction);
                Some([quantize(distance * x), height, quantize(distance * z)])
            }
        }
    }
}

/// Whether a level is on its way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Loading {
    /// None: the level on screen (or its error) answers the newest request.
    #[default]
    Idle,
    /// Generation `id` is in flight; an older one's level is dropped when it arrives.
    Generating {
        /// The generation's request number.
        id: u64,
    },
}

/// Whether the designer runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// The loop goes on.
    #[default]
    Designing,
    /// `q`, Esc or Ctrl-C: the loop ends and the terminal is restored.
    Quitting,
}

/// What covers the screen, if anything.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    /// Nothing: the designer's screen.
    None,
    /// The keys and what they do (`?`).
    Help,
    /// The loaded policies' cards.
    Cards,
    /// A prompt being typed.
    Prompt {
        /// What it asks for.
        kind: PromptKind,
        /// What has been typed.
        text: String,
    },
    /// Export would overwrite these files.
    ConfirmOverwrite {
        /// The files that exist.
        paths: Vec<PathBuf>,
    },
    /// The campaign open in [`App::campaign`].
    Campaign,
}

/// What the bottom-right panel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SidePane {
    /// The failures on each piece.
    Failures,
    /// The λ sweep.
    Sweep,
    /// The whole panel of judges on the level on screen.
    Judges,
}

/// A recorded run being played back.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// The run's seed.
    pub seed: u64,
    /// The run, recorded.
    pub recording: Recording,
    /// Index into the recording's path.
    pub frame: usize,
}

/// Everything the designer shows and remembers.
#[derive(Debug, Clone, PartialEq)]
pub struct App {
    /// The game on screen.
    pub game: Game,
    /// Each game's policies ([`App::policies`]: the game on screen's).
    pub loaded: PerGame<LoadedInfo>,
    /// The slider's λ (in target-success mode, the λ of the level found).
    pub aux: f64,
    /// What difficulty is asked for: the slider's λ, a success rate, or λ along the level.
    pub ask: Ask,
    /// The style knobs of a Generator trained with them, in its game's order, each in
    /// [-1, 1] (0: no preference); empty for one without.
    pub knobs: Vec<f64>,
    /// Which slider the arrow keys and the mouse move: 0 λ, k the k-th knob (`m` cycles).
    pub slider: usize,
    /// The prefix every regeneration keeps.
    pub kept: Option<crate::services::generation::KeptPrefix>,
    /// Each game's wish list its levels are searched to meet (`W`; none: λ alone;
    /// [`App::want`]: the game on screen's).
    pub wants: PerGame<Option<crate::services::wish::Want>>,
    /// Each game's profile levels are made for, and the ability its keys change ([`profile`];
    /// [`App::profile`]: the game on screen's).
    pub profiles: PerGame<profile::ProfileEdit>,
    /// The seed levels are generated with.
    pub seed: u64,
    /// Where the goal comes from.
    pub goal: GoalSetting,
    /// Solver trials per level.
    pub trials_wanted: u32,
    /// Where exports go (in a folder per game).
    pub out_dir: PathBuf,
    /// How the exported glTF carries its colliders (`design --physics`, `--collision-names`).
    pub gltf: GltfOptions,
    /// The level on screen.
    pub level: Option<Arc<Level>>,
    /// The generation in flight, if any.
    pub loading: Loading,
    /// Why the last generation failed, if it did.
    pub generation_error: Option<String>,
    /// The Solver's trials on the level on screen.
    pub trials: Option<Trials>,
    /// The run being played back.
    pub replay: Option<Replay>,
    /// The recording asked for (request id, run seed), until it arrives.
    recording: Option<(u64, u64)>,
    replays: u64,
    /// The λ sweep, once started.
    pub sweep: Option<Sweep>,
    /// The panel of judges on the level on screen, once started.
    pub judging: Option<judges::Judging>,
    /// The campaign opened last (`o`).
    pub campaign: Option<campaign::CampaignView>,
    /// What the bottom-right panel shows.
    pub panel: SidePane,
    /// Selected block (index into the level's blocks).
    pub selected: Option<usize>,
    /// What covers the screen, if anything.
    pub overlay: Overlay,
    /// The latest message for the footer, and whether it reports a problem.
    pub status: Option<(String, bool)>,
    /// The terminal's size.
    pub size: Rect,
    /// Whether the mouse is dragging the slider.
    dragging: bool,
    next_id: u64,
    /// Whether the screen is drawn in colour (not under `NO_COLOR`).
    pub colour: bool,
    /// Whether the loop goes on or ends.
    pub mode: Mode,
}

impl App {
    /// A designer for `game` that will show a level as soon as the first effects run.
    pub fn new(game: Game, policies: LoadedInfo, seed: u64, out_dir: PathBuf) -> Self {
        Self {
            game,
            loaded: {
                let mut loaded = PerGame::<LoadedInfo>::default();
                loaded[game] = policies;
                loaded
            },
            aux: 1.0,
            ask: Ask::Aux(1.0),
            knobs: Vec::new(),
            slider: 0,
            kept: None,
            wants: PerGame::default(),
            profiles: PerGame::default(),
            seed,
            goal: GoalSetting::FromSeed,
            trials_wanted: DEFAULT_TRIALS,
            out_dir,
            gltf: GltfOptions::default(),
            level: None,
            loading: Loading::Idle,
            generation_error: None,
            trials: None,
            replay: None,
            recording: None,
            replays: 0,
            sweep: None,
            judging: None,
            campaign: None,
            panel: SidePane::Failures,
            selected: None,
            overlay: Overlay::None,
            status: None,
            size: Rect::new(0, 0, 80, 24),
            dragging: false,
            next_id: 1,
            colour: true,
            mode: Mode::Designing,
        }
    }

    /// The first effects: generate the level for the starting settings.
    pub fn start(&mut self) -> Vec<Effect> {
        self.generate()
    }

    fn id(&mut self) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        id
    }

    /// Whether a generation is in flight.
    pub fn generating(&self) -> bool {
        self.loading != Loading::Idle
    }

    fn generate(&mut self) -> Vec<Effect> {
        self.fit_knobs();
        let id = self.id();
        self.loading = Loading::Generating { id };
        self.replay = None;
        self.recording = None;
        vec![Effect::Generate {
            id,
            game: self.game,
            seed: self.seed,
            goal: self.goal.position(),
            ask: self.ask.clone(),
            keep: self.kept.clone(),
            trials: self.trials_wanted,
            profile: self.profile().profile.clone(),
            knobs: self.knob_values(),
            want: self.want().cloned(),
        }]
    }

    /// The knobs the game on screen's Generator takes: none for the rules or a Generator
    /// trained without them, else each of its game's.
    pub fn knob_names(&self) -> &'static [&'static str] {
        match &self.policies().generator {
            Some(g) if arlpcg_core::rl::checkpoint::knob_part(&g.card) > 0 => {
                self.game.shape().knobs()
            }
            _ => &[],
        }
    }

    /// Keeps one value per knob of the Generator on screen (new ones at 0, no preference),
    /// and the slider on one that exists.
    fn fit_knobs(&mut self) {
        let count = self.knob_names().len();
        self.knobs.resize(count, 0.0);
        if self.slider > count {
            self.slider = 0;
        }
    }

    /// The knobs as a request takes them.
    pub(super) fn knob_values(&self) -> Vec<f32> {
        self.knobs.iter().map(|&v| v as f32).collect()
    }

    /// The policies of the game on screen.
    pub fn policies(&self) -> &LoadedInfo {
        &self.loaded[self.game]
    }

    pub(super) fn policies_mut(&mut self) -> &mut LoadedInfo {
        &mut self.loaded[self.game]
    }

    /// The wish list of the game on screen, if it has one.
    pub fn want(&self) -> Option<&crate::services::wish::Want> {
        self.wants[self.game].as_ref()
    }

    /// The profile of the game on screen.
    pub fn profile(&self) -> &profile::ProfileEdit {
        &self.profiles[self.game]
    }

    /// The profile of the game on screen, to change.
    pub fn profile_mut(&mut self) -> &mut profile::ProfileEdit {
        &mut self.profiles[self.game]
    }

    /// Tab: the next game, with its own policies and profile, from the same seed and λ (a goal
    /// set by hand goes back to the seed's: the games' goals lie at different distances).
    pub(super) fn switch_game(&mut self) -> Vec<Effect> {
        self.game = self.game.next();
        self.goal = GoalSetting::FromSeed;
        self.kept = None;
        // The knobs are the other game's: back to no preference, the arrows on λ.
        self.knobs.clear();
        self.slider = 0;
        if self.policies().generator.is_none() && self.ask.curve().is_some() {
            self.ask = Ask::Aux(self.aux);
        }
        // Each game keeps its own wish list: say which one now holds.
        if let Some(want) = self.want() {
            self.say(format!("{}'s wish list: {want}", self.game));
        }
        self.level = None;
        self.trials = None;
        self.sweep = None;
        self.selected = None;
        self.generation_error = None;
        self.generate()
    }

    fn set_aux(&mut self, aux: f64) -> Vec<Effect> {
        let aux = (aux.clamp(-1.0, 1.0) * 100.0).round() / 100.0;
        if self.ask == Ask::Aux(aux) {
            return Vec::new();
        }
        // Moving the slider leaves target-success mode and pacing.
        let was_paced = self.ask.curve().is_some();
        self.ask = Ask::Aux(aux);
        if was_paced {
            self.say("one λ again (P: pacing presets)");
        }
        self.aux = aux;
        self.generate()
    }

    /// Target-success mode on (`Some`) or off: a Generator is needed to steer.
    pub(super) fn set_target(&mut self, target: Option<f64>) -> Vec<Effect> {
        if target.is_some() && self.policies().generator.is_none() {
            self.complain(
                "a success target needs a Generator (p loads one): rule levels have no λ to steer",
            );
            return Vec::new();
        }
        match target {
            // The search steers one λ over the whole level.
            Some(target) => {
                self.ask = Ask::Success(target);
                self.kept = None;
            }
            None if self.ask.success().is_some() => self.ask = Ask::Aux(self.aux),
            None => {}
        }
        if let Some(p) = target {
            self.say(format!(
                "searching λ for success {p:.2} ± 0.1 ({} runs a candidate)",
                self.trials_wanted
            ));
        }
        self.generate()
    }

    fn say(&mut self, text: impl Into<String>) {
        self.status = Some((text.into(), false));
    }

    fn complain(&mut self, text: impl Into<String>) {
        self.status = Some((text.into(), true));
    }

    /// The file stem exports use: game, seed and λ (or the pacing preset), and the pieces kept.
    pub fn export_stem(&self) -> String {
        let mut stem = match self.ask.curve() {
            Some(curve) => format!(
                "{}_seed{}_pacing-{}",
                self.game,
                self.seed,
                pacing::preset_name(curve).replace(' ', "-")
            ),
            None => crate::services::level_files::file_stem(self.game, self.seed, Some(self.aux)),
        };
        if let Some(kept) = &self.kept {
            stem += &format!("_keep{}", kept.pieces);
        }
        stem
    }

    /// The level on screen with its Solver statistics and panel, once the trials are in: what
    /// `x` exports and the 3D view shows.
    pub fn level_with_stats(&self) -> Option<Level> {
        let mut level = Level::clone(self.level.as_ref()?);
        level.stats = self.trials.as_ref().and_then(|t| t.stats.clone());
        if let Some(stats) = &mut level.stats {
            stats.panel = self.panel_on_screen();
        }
        Some(level)
    }

    fn export(&mut self, overwrite: bool) -> Vec<Effect> {
        let Some(level) = self.level_with_stats() else {
            self.complain("no level to export yet");
            return Vec::new();
        };
        if level.stats.is_none() {
            self.say("exporting without Solver statistics (trials still running)");
        }
        vec![Effect::Export {
            level: Box::new(level),
            dir: self.out_dir.join(self.game.name()),
            stem: self.export_stem(),
            overwrite,
            gltf: self.gltf,
        }]
    }

    fn record(&mut self) -> Vec<Effect> {
        let Some(level) = self.level.clone() else {
            return Vec::new();
        };
        let id = self.id();
        self.replays += 1;
        let seed = level
            .seed
            .unwrap_or(0)
            .wrapping_add(1_000_000 + self.replays);
        self.replay = None;
        self.recording = Some((id, seed));
        self.say(format!("recording a run (seed {seed})"));
        vec![Effect::Record { id, level, seed }]
    }

    fn adjust_goal(&mut self, d_steps: f64, d_height: f64, d_direction: f64) -> Vec<Effect> {
        let GoalSetting::Custom {
            distance,
            height,
            direction,
        } = self.goal
        else {
            self.complain("the goal is drawn from the seed: press g to set it by hand");
            return Vec::new();
        };
        // Within the ranges the game's rules draw goals from, in the game's key steps.
        let facts = arlpcg_core::game::facts::facts(self.game);
        let (distances, heights) = (facts.goal_distance, facts.goal_height);
        let d_distance = d_steps * facts.goal_distance_step;
        self.goal = GoalSetting::Custom {
            distance: (distance + d_distance).clamp(distances.0, distances.1),
            height: (height + d_height).clamp(heights.0, heights.1),
            direction: wrap_degrees(direction + d_direction),
        };
        self.generate()
    }

    fn toggle_goal(&mut self) -> Vec<Effect> {
        self.goal = match self.goal {
            GoalSetting::Custom { .. } => GoalSetting::FromSeed,
            GoalSetting::FromSeed => {
                // Start from the goal on screen, so the level changes only when adjusted.
                let [x, y, z] = self
                    .level
                    .as_ref()
                    .map_or([0.0, 0.0, 50.0], |level| level.goal);
                GoalSetting::Custom {
                    distance: x.hypot(z).round(),
                    height: y.round(),
                    direction: direction_heading(x, z).round(),
                }
            }
        };
        self.generate()
    }

    fn select(&mut self, delta: isize) {
        let blocks = self.level.as_ref().map_or(0, |l| l.piece_count());
        if blocks == 0 {
            self.selected = None;
            return;
        }
        let next = match self.selected {
            None if delta > 0 => 0,
            None => blocks - 1,
            Some(i) => (i as isize + delta).rem_euclid(blocks as isize) as usize,
        };
        self.selected = Some(next);
    }

    fn tick(&mut self) {
        if let Some(replay) = &mut self.replay {
            let last = replay.recording.path.len().saturating_sub(1);
            replay.frame = (replay.frame + REPLAY_STEPS_PER_TICK).min(last);
        }
    }
}

/// The designer's update: applies `message` to `app` and returns the work it asks for.
pub fn update(app: &mut App, message: Message) -> Vec<Effect> {
    match message {
        Message::Key(key) => app.key(key),
        Message::Mouse(mouse) => app.mouse(mouse),
        Message::Resize { width, height } => {
            app.size = Rect::new(0, 0, width, height);
            Vec::new()
        }
        Message::Tick => {
            app.tick();
            Vec::new()
        }
        Message::Worker(response) => app.response(response),
    }
}

/// The λ under column `column` of the slider track `slider` (-1 at its left end, +1 at its right).
pub fn slider_aux(slider: Rect, column: u16) -> f64 {
    let span = slider.width.saturating_sub(1).max(1) as f64;
    let t = (column.saturating_sub(slider.x) as f64 / span).clamp(0.0, 1.0);
    ((-1.0 + 2.0 * t) * 20.0).round() / 20.0
}

/// The next seed `n` draws: a fixed scramble of the current one (SplitMix64), so key scripts
/// are reproducible.
pub fn next_seed(seed: u64) -> u64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) % 1_000_000
}
