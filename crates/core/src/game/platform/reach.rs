//! How far the character can jump: the reach table (largest makeable edge gap per height change),
//! measured with the scripted controller in the real simulation on chained jumps (the second of
//! two equal jumps, turned), and the function that measures it. `docs/platform-physics.md`
//! prints the table; a test re-measures it.

use super::character::Body;
use super::env::{PlatformEnv, PlatformRewards};
use super::scripted::ScriptedController;
use crate::game::SolverEnv;
use crate::level::platform::{BlockParams, PlatformTrack, Start};
use crate::level::profile::{Abilities, CharacterProfile};
use crate::level::stats::{Outcome, TrialResult};

/// The height changes the table lists, m.
pub const REACH_HEIGHTS: [f64; 5] = [-2.0, -1.0, 0.0, 1.0, 2.0];
/// The turns, degrees, of the second jump of a [`chained_jump`] that the table must clear.
pub const REACH_TURNS: [f64; 5] = [-90.0, -45.0, 0.0, 45.0, 90.0];
/// The sharpest turn, degrees off the direction of the last jump, that stays within reach: after
/// a fast landing a sharper one means stopping and turning back on the block, and the scripted
/// controller fails it even across short gaps (`docs/platform-physics.md`, "Chained jumps").
pub const MAX_TURN: f64 = 90.0;
/// Largest edge gap, m, that the scripted controller (take-off jitter `REACH_JITTER`) clears in
/// every one of `REACH_TRIALS` seeded runs of a [`chained_jump`] at every turn of `REACH_TURNS`,
/// for each height change of `REACH_HEIGHTS`, measured in steps of `REACH_STEP` from 1 m up to
/// the largest gap the parameter ranges allow (6 m). A jump right after a landing is harder
/// than one from standstill on the start block, so this is the reach anywhere in a level.
pub const REACH_TABLE: [f64; 5] = [6.0, 6.0, 6.0, 6.0, 4.25];
/// Resolution of the table, m.
pub const REACH_STEP: f64 = 0.25;
/// Seeded runs per table entry.
pub const REACH_TRIALS: u64 = 8;
/// Take-off jitter of the scripted controller when measuring, m.
pub const REACH_JITTER: f32 = 0.3;
/// The gaps the table scans: the ranges allow edge gaps up to 6 m (10 m between 4 m blocks).
const GAP_RANGE: (f64, f64) = (1.0, 6.0);

/// How far a character can jump: per height change of [`REACH_HEIGHTS`], the largest edge gap,
/// m, that the scripted controller clears on chained jumps (see [`measure_reach`]). The rules and
/// the Generator keep every jump within it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach(pub [f64; 5]);

impl Default for Reach {
    /// The built-in character's reach, [`REACH_TABLE`].
    fn default() -> Self {
        Self(REACH_TABLE)
    }
}

impl Reach {
    /// The reach of a character of `body`: the built-in table for the built-in body (a test
    /// measures it), else measured (about a second).
    pub fn of(body: Body) -> Self {
        if body == Body::default() {
            Self::default()
        } else {
            Self(measure_reach(body))
        }
    }

    /// The reach of `player`'s character (the built-in one's when it has no platform
    /// abilities), measured once per process and kept: a batch, a campaign, a training run or
    /// the designer's edits measure each character once. The same abilities always give the
    /// same table, so keeping it changes no result.
    pub fn of_player(player: &crate::game::Player) -> Self {
        Self::of_player_in(player, REACH_TRIALS)
    }

    /// The reach of `player`'s character counted in at least `runs` of the [`REACH_TRIALS`]
    /// runs ([`measure_reach_in`]): [`Reach::of_player`] at all of them, a longer reach at
    /// fewer (a Generator's `reach_runs`). `runs` is taken within [1, `REACH_TRIALS`]. Measured
    /// once per process, character and count, and kept.
    pub fn of_player_in(player: &crate::game::Player, runs: u64) -> Self {
        use std::sync::{Mutex, OnceLock};
        let runs = runs.clamp(1, REACH_TRIALS);
        let character = match player.abilities {
            Some(Abilities::Character(character)) => character,
            _ if runs == REACH_TRIALS => return Self::default(),
            _ => CharacterProfile::default(),
        };
        type Measured = Vec<(CharacterProfile, u64, Reach)>;
        static MEASURED: OnceLock<Mutex<Measured>> = OnceLock::new();
        let measured = MEASURED.get_or_init(Default::default);
        let known = |all: &Measured| {
            all.iter()
                .find(|(c, r, _)| *c == character && *r == runs)
                .map(|(_, _, reach)| *reach)
        };
        if let Some(reach) = known(&measured.lock().unwrap_or_else(|e| e.into_inner())) {
            return reach;
        }
        let body = Body::from(character);
        let reach = match runs {
            REACH_TRIALS => Self::of(body),
            _ => Self(measure_reach_in(body, runs)),
        };
        measured
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((character, runs, reach));
        reach
    }

    /// The highest climb, m, of the table's heights from 0 up that the character still makes
    /// across the shortest gap scanned (2 m for the built-in character): a block higher above
    /// the last is out of reach, however close.
    pub fn max_climb(&self) -> f64 {
        REACH_HEIGHTS
            .iter()
            .zip(self.0)
            .skip_while(|(h, _)| **h < 0.0)
            .take_while(|(_, gap)| *gap >= GAP_RANGE.0)
            .map(|(h, _)| *h)
            .last()
            .unwrap_or(REACH_HEIGHTS[0])
    }

    /// The largest makeable gap at a height change, interpolated from the table (at most
    /// [`Reach::max_climb`] up: check the climb first).
    pub fn max_gap(&self, height: f64) -> f64 {
        let h = height.clamp(REACH_HEIGHTS[0], self.max_climb());
        let i = REACH_HEIGHTS
            .iter()
            .rposition(|&x| x <= h)
            .unwrap_or(0)
            .min(3);
        let t = (h - REACH_HEIGHTS[i]) / (REACH_HEIGHTS[i + 1] - REACH_HEIGHTS[i]);
        self.0[i] + t * (self.0[i + 1] - self.0[i])
    }
}

/// A level of one jump: a 4 m start block, then a 4 m block `gap` metres away and `height`
/// metres up.
pub fn single_jump(gap: f64, height: f64) -> PlatformTrack {
    let start = Start {
        size: 4.0,
        ..Start::default()
    };
    let block = BlockParams::new(gap + 4.0, 0.0, 4.0, height)
        .expect("gap within [1, 6] m and height within [-2, 2] m");
    PlatformTrack::from_params(start, &[block]).expect("one block never overlaps")
}

/// A level of two equal jumps: a 4 m start block, a 4 m block `gap` metres away and `height`
/// metres up, then another the same gap and height further on, `turn` degrees off the first
/// jump's direction. The second jump is the one the reach table measures.
pub fn chained_jump(gap: f64, height: f64, turn: f64) -> PlatformTrack {
    let start = Start {
        size: 4.0,
        ..Start::default()
    };
    let first = BlockParams::new(gap + 4.0, 0.0, 4.0, height)
        .expect("gap within [1, 6] m and height within [-2, 2] m");
    let second = BlockParams::new(gap + 4.0, turn, 4.0, height)
        .expect("gap within [1, 6] m, height within [-2, 2] m, turn within [-90, 90] degrees");
    PlatformTrack::from_params(start, &[first, second])
        .expect("two 4 m blocks at least 5 m apart, turned at most 90 degrees, never overlap")
}

/// Plays one run of `env` with the scripted controller, seeded by `seed`.
pub fn play_scripted(env: &mut PlatformEnv, seed: u64, jitter: f32) -> TrialResult {
    env.reset(seed);
    let mut controller = ScriptedController::new(seed, jitter);
    loop {
        let step = env.step(controller.act(env));
        if let Some(outcome) = step.outcome {
            return TrialResult {
                outcome,
                progress: env.progress(),
                target_piece: env.furthest(),
                steps: env.steps(),
                air_steps: None,
            };
        }
    }
}

/// How many of `trials` seeded scripted runs of a character of `body` reach the last block of
/// `track`.
pub fn successes(track: &PlatformTrack, body: Body, trials: u64, jitter: f32) -> u64 {
    let goal = track.last().position;
    let mut env = PlatformEnv::new(track, goal, PlatformRewards::default()).with_body(body);
    (0..trials)
        .filter(|&seed| play_scripted(&mut env, seed, jitter).outcome == Outcome::Success)
        .count() as u64
}

/// Measures the reach table: for each height change, the largest gap such that every chained
/// jump up to it (in `REACH_STEP` steps from 1 m, at every turn of `REACH_TURNS`) is cleared in
/// all `REACH_TRIALS` runs, for a character of `body`.
pub fn measure_reach(body: Body) -> [f64; 5] {
    measure_reach_in(body, REACH_TRIALS)
}

/// Measures a reach counted in at least `runs` of the `REACH_TRIALS` runs: for each height
/// change, the largest gap such that every chained jump up to it is cleared in `runs` or more of
/// them at every turn of `REACH_TURNS` ([`measure_reach`] at all of them). Fewer runs give the
/// gaps the scripted controller makes only sometimes: what a Generator may cut its jumps to
/// when the reliable table leaves a strong Solver's hard levels easy (docs/decisions.md, D22).
/// The heights and, at each gap, the turns are measured side by side (rayon): the same table.
pub fn measure_reach_in(body: Body, runs: u64) -> [f64; 5] {
    use rayon::prelude::*;
    let gaps: Vec<f64> = REACH_HEIGHTS
        .par_iter()
        .map(|&height| {
            let steps = ((GAP_RANGE.1 - GAP_RANGE.0) / REACH_STEP).round() as usize;
            let mut best = GAP_RANGE.0 - REACH_STEP;
            for k in 0..=steps {
                let gap = GAP_RANGE.0 + k as f64 * REACH_STEP;
                let cleared = REACH_TURNS.par_iter().all(|&turn| {
                    successes(
                        &chained_jump(gap, height, turn),
                        body,
                        REACH_TRIALS,
                        REACH_JITTER,
                    ) >= runs
                });
                if !cleared {
                    break;
                }
                best = gap;
            }
            best
        })
        .collect();
    std::array::from_fn(|k| gaps[k])
}
