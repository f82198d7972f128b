//! The platform Generator (docs/spec.md §1.1 and §2): its observation, its action (a block,
//! framed relative to the goal), and the platform game's side of the Generator abstraction
//! ([`PlatformBuild`], [`GeneratorGame`] for [`PlatformGame`]). The rewards and the match of a
//! Generator against a Solver are written once for both games in `crate::game::generator`; the
//! platform Generator places the next block when the Solver stands on the newest one.

use rand_chacha::ChaCha8Rng;

use super::env::{PlatformEnv, PlatformRewards};
use super::reach::{self, Reach};
use crate::game::generator::{
    BuildLimits, GeneratorGame, GeneratorRewards, Knob, Placement, TrackBuild, named,
};
use crate::game::platform::rules::goal_and_start;
use crate::game::{PlatformGame, Player};
use crate::level::Track;
use crate::level::heading::{direction_heading, wrap_degrees};
use crate::level::params::{self, quantize};
use crate::level::platform::{BlockParams, PlatformTrack, headroom_of};
use crate::level::profile::Abilities;

/// The named parts of the Generator's observation, in order, with their lengths (one aux input).
pub const GENERATOR_OBSERVATION_LAYOUT: [(&str, usize); 9] = [
    ("goal_relative_position", 3),
    ("goal_bearing_sin_cos", 2),
    ("goal_distance", 1),
    ("last_block_size", 1),
    ("previous_block_relative_position", 3),
    ("previous_block_size", 1),
    ("last_turn_sin_cos", 2),
    ("blocks_left", 1),
    ("aux", 1),
];

/// What each part of [`GENERATOR_OBSERVATION_LAYOUT`] holds, for a port of it.
pub const GENERATOR_OBSERVATION_MEANINGS: [&str; 9] = [
    "goal - the last block's top centre in its frame (forward f = (cos H, 0, -sin H) for its heading H, up, left l = (f.z, 0, -f.x)) / 50 m",
    "sin, cos of atan2(left, forward) of that vector (+ left)",
    "its horizontal length / 50 m",
    "the last block's side / 6 m",
    "the block before the last, minus the last's top centre, same frame, / 10 m (0 when the last is the start)",
    "its side / 6 m (0 at the start)",
    "sin, cos of the turn the last block was placed with (a turn of 0 at the start: (0, 1))",
    "1 - blocks placed / the piece budget",
    "λ: +1 easy, -1 hard",
];

/// Length of the Generator's observation vector.
pub const GENERATOR_OBSERVATION_SIZE: usize = {
    let mut total = 0;
    let mut i = 0;
    while i < GENERATOR_OBSERVATION_LAYOUT.len() {
        total += GENERATOR_OBSERVATION_LAYOUT[i].1;
        i += 1;
    }
    total
};

/// The Generator's action names, in the policy's order, each a value in [-1, 1] mapped onto its
/// range of docs/spec.md §1.1. The turn is taken relative to the bearing of the goal (0 aims straight at it) and
/// the height change relative to the climb that stays on course for the goal (0 keeps the slope
/// from the last block to the goal); the level stores both as docs/spec.md §1.1 defines them (turn
/// relative to the last two blocks, height relative to the last block). With docs/spec.md's own
/// frames an untrained Generator wanders: in a first run 74-90% of its tracks overlapped
/// themselves or ran out of blocks and none reached its goal in a million Solver steps, so the
/// Solver never saw a success.
pub const GENERATOR_ACTIONS: [&str; 4] = [
    "distance", "turn_from_goal_bearing", "size", "height_from_goal_slope",
];

/// The platform Generator's style knobs (docs/decisions.md): how long its jumps are and how
/// much its blocks step up and down, each measured by `BlockRanges::style`.
pub const KNOBS: [Knob; 2] = [
    Knob {
        name: crate::level::platform::BLOCK_KNOBS[0],
        meaning: "-1 short hops ... +1 long leaps (a block's distance within the profile's range)",
    },
    Knob {
        name: crate::level::platform::BLOCK_KNOBS[1],
        meaning: "-1 level ... +1 steep steps up and down (a block's height change, either way, within the profile's largest)",
    },
];

/// The block budget of a Generator's track by default: a track that has not reached its goal
/// within it is invalid (goals are at most 70 m away, blocks 5-10 m apart).
pub const DEFAULT_MAX_BLOCKS: usize = 30;

/// A policy's action row (unbounded Gaussian samples) as the next block of `track` toward
/// `goal` for `player`: each value is clipped to [-1, 1] and mapped onto the player's block
/// ranges (NaN becomes the middle), the turn added to the goal's bearing from the last block and
/// kept within [`reach::MAX_TURN`] and the ranges' sharpest turn of the last jump's direction,
/// the height change to the climb that keeps the slope toward the goal (see
/// [`GENERATOR_ACTIONS`]) and at most the reach's highest climb, the distance shortened to keep
/// the edge gap within reach ([`reach::Reach::max_gap`]) for that height change.
pub fn block_from_action(
    track: &PlatformTrack,
    goal: [f64; 3],
    row: &[f32],
    (player, reach): (&Player, &Reach),
) -> BlockParams {
    let unit = |v: f32| if v.is_nan() { 0.0 } else { v as f64 };
    let ranges = player.blocks();
    let (distance, size, height) = (ranges.distance(), ranges.size(), ranges.height());
    let last = track.last();
    let (dx, dz) = (goal[0] - last.position[0], goal[2] - last.position[2]);
    let bearing = direction_heading(dx, dz);
    let turn = params::BLOCK_ANGLE.from_unit(unit(row[1]));
    let sharpest = ranges.max_turn.min(reach::MAX_TURN);
    let mut block = BlockParams {
        distance: quantize(distance.from_unit(unit(row[0]))),
        angle: quantize(
            wrap_degrees(bearing - last.heading + quantize(turn)).clamp(-sharpest, sharpest),
        ),
        size: quantize(size.from_unit(unit(row[2]))),
        height: quantize(height.from_unit(unit(row[3]))),
    };
    let rise = goal[1] - last.position[1];
    let on_course = rise * (block.distance / dx.hypot(dz).max(1e-6)).min(1.0);
    block.height = quantize(
        height
            .clamp(on_course + block.height)
            .min(reach.max_climb()),
    );
    // Never beyond the character's reach: a longer jump makes a level impossible, not harder,
    // and a failure there teaches the Solver nothing.
    let longest = reach.max_gap(block.height) + 0.5 * (last.size + block.size);
    block.distance = quantize(block.distance.min(longest).max(distance.min));
    block
}

/// Writes the Generator's observation of a track (see [`GENERATOR_OBSERVATION_LAYOUT`]) into
/// `out`: the goal and the previous block in the frame of the last block, and the aux inputs.
pub fn observe(
    track: &PlatformTrack,
    goal: [f64; 3],
    aux: &[f32],
    max_blocks: usize,
    out: &mut [f32],
) {
    assert_eq!(
        out.len(),
        GENERATOR_OBSERVATION_SIZE,
        "observation buffer of the wrong size"
    );
    let platforms = track.platforms();
    let last = track.last();
    let local = |point: [f64; 3]| -> [f64; 3] {
        let [fx, fz] = crate::level::heading::heading_direction(last.heading);
        let d = [
            point[0] - last.position[0],
            point[1] - last.position[1],
            point[2] - last.position[2],
        ];
        // Forward along the heading, up, and left (a positive turn).
        [d[0] * fx + d[2] * fz, d[1], d[0] * fz - d[2] * fx]
    };
    let to_goal = local(goal);
    let goal_distance = to_goal[0].hypot(to_goal[2]);
    let bearing = to_goal[2].atan2(to_goal[0]);
    let (previous, turn) = match platforms.len() {
        1 => (None, 0.0),
        n => (
            Some(platforms[n - 2]),
            track.block_params()[n - 2].angle.to_radians(),
        ),
    };
    let previous_position = previous.map_or([0.0; 3], |p| local(p.position).map(|x| x / 10.0));
    let values = to_goal
        .map(|x| x / 50.0)
        .into_iter()
        .chain([bearing.sin(), bearing.cos(), goal_distance / 50.0])
        .chain([last.size / 6.0])
        .chain(previous_position)
        .chain([previous.map_or(0.0, |p| p.size / 6.0)])
        .chain([turn.sin(), turn.cos()])
        .chain([1.0 - track.block_count() as f64 / max_blocks as f64])
        .map(|x| x as f32)
        .chain(aux.iter().copied());
    let mut written = 0;
    for (slot, value) in out.iter_mut().zip(values) {
        *slot = value;
        written += 1;
    }
    debug_assert_eq!(written, GENERATOR_OBSERVATION_SIZE);
}

/// A platform track the Generator is building toward its goal, within its block budget.
#[derive(Debug, Clone)]
pub struct PlatformBuild {
    /// The blocks placed so far.
    pub track: PlatformTrack,
    /// The goal the track leads to, m.
    pub goal: [f64; 3],
    /// The block budget: the most blocks the Generator may place.
    pub max_blocks: usize,
    /// Who the track is for: its jumps keep within the player's reach...
    pub player: Player,
    /// ...measured once, as the build opens ([`Reach::of_player`]).
    pub reach: Reach,
}

impl TrackBuild for PlatformBuild {
    fn player(&self) -> &Player {
        &self.player
    }

    fn goal(&self) -> [f64; 3] {
        self.goal
    }

    fn piece_count(&self) -> usize {
        self.track.block_count()
    }

    fn observe(&self, aux: &[f32], out: &mut [f32]) {
        observe(&self.track, self.goal, aux, self.max_blocks, out);
    }

    fn port_state(&self) -> crate::game::PortState {
        let platforms = self.track.platforms();
        let last = self.track.last();
        let n = platforms.len();
        // The block before the last, and the turn the last was placed with (none: the last is
        // the start block).
        let previous = (n > 1).then(|| {
            let p = platforms[n - 2];
            [p.position.to_vec(), vec![p.size]].concat()
        });
        let turn = (n > 1).then(|| vec![self.track.block_params()[n - 2].angle]);
        vec![
            ("goal", self.goal.to_vec()),
            ("last_position", last.position.to_vec()),
            ("last_heading_degrees", vec![last.heading]),
            ("last_size", vec![last.size]),
            ("last_turn_degrees", turn.unwrap_or_default()),
            ("previous_position_size", previous.unwrap_or_default()),
            ("blocks", vec![self.track.block_count() as f64]),
            ("max_blocks", vec![self.max_blocks as f64]),
        ]
    }

    /// The player's block ranges, its reach table (by `REACH_HEIGHTS`) and the headroom a
    /// block keeps from any but the last (`PlatformTrack::push`).
    fn port_piece_rules(&self) -> std::collections::BTreeMap<String, Vec<f64>> {
        let r = self.player.blocks();
        named([
            ("headroom", vec![self.track.headroom()]),
            ("min_distance", vec![r.min_distance]),
            ("max_distance", vec![r.max_distance]),
            ("min_size", vec![r.min_size]),
            ("max_size", vec![r.max_size]),
            ("min_height", vec![r.min_height]),
            ("max_height", vec![r.max_height]),
            ("max_turn", vec![r.max_turn]),
            ("reach_table", self.reach.0.to_vec()),
        ])
    }

    fn port_piece(&self, row: &[f32]) -> Option<std::collections::BTreeMap<String, f64>> {
        let block = block_from_action(&self.track, self.goal, row, (&self.player, &self.reach));
        Some(named([
            ("distance", block.distance),
            ("angle", block.angle),
            ("size", block.size),
            ("height", block.height),
        ]))
    }

    fn place(&mut self, row: &[f32]) -> Placement {
        if self.track.block_count() >= self.max_blocks {
            return Placement::OutOfPieces;
        }
        let block = block_from_action(&self.track, self.goal, row, (&self.player, &self.reach));
        if self.track.push(block).is_err() {
            return Placement::Invalid;
        }
        if self.track.last().reaches(self.goal) {
            Placement::Completed
        } else {
            Placement::Placed
        }
    }

    fn distance_to_goal(&self, k: usize) -> f64 {
        let p = self.track.platforms()[k].position;
        crate::level::distance(self.goal, p)
    }

    fn piece_style(&self, piece: usize, out: &mut [f32]) {
        out.copy_from_slice(
            &self
                .player
                .blocks()
                .style(&self.track.block_params()[piece]),
        );
    }

    fn piece_features(&self) -> Vec<[f64; 2]> {
        self.track
            .block_params()
            .iter()
            .map(|b| [b.distance, b.size])
            .collect()
    }

    fn into_track(self) -> Track {
        Track::Platform(self.track)
    }
}

impl GeneratorGame for PlatformGame {
    type Build = PlatformBuild;
    const GENERATOR_OBSERVATION_LAYOUT: &'static [(&'static str, usize)] =
        &GENERATOR_OBSERVATION_LAYOUT;
    const GENERATOR_ACTIONS: &'static [&'static str] = &GENERATOR_ACTIONS;
    const DEFAULT_MAX_PIECES: usize = DEFAULT_MAX_BLOCKS;
    const MAX_PIECES: usize = crate::level::platform::MAX_BLOCKS;
    const KNOBS: &'static [Knob] = &KNOBS;
    const PIECE_FEATURES: [&'static str; 2] = ["distance", "size"];
    const RECIPE: &'static str = include_str!("recipe.yaml");

    /// The paper's rewards, but each block placed at λ < 0 costs 0.5·|λ| (the paper's 0.1 let
    /// a hard level be a long one: 22.6 blocks at λ = -1 for 8.4 at +1). Why:
    /// docs/decisions.md#d17.
    fn default_rewards() -> GeneratorRewards {
        GeneratorRewards {
            step_penalty: 0.5,
            ..GeneratorRewards::default()
        }
    }

    fn new_build(
        seed: u64,
        goal: Option<[f64; 3]>,
        limits: BuildLimits,
        _obstacles: u32,
    ) -> (PlatformBuild, ChaCha8Rng) {
        let (goal, start, rng) = goal_and_start(seed, goal);
        let build = PlatformBuild {
            track: PlatformTrack::new(start)
                .with_headroom(headroom_of(limits.player.abilities.as_ref())),
            goal,
            max_blocks: limits.max_pieces,
            player: limits.player,
            reach: Reach::of_player_in(
                &limits.player,
                limits.reach_runs.unwrap_or(reach::REACH_TRIALS),
            ),
        };
        (build, rng)
    }

    fn kept_build(
        track: &Track,
        goal: [f64; 3],
        pieces: usize,
        limits: BuildLimits,
    ) -> Result<PlatformBuild, String> {
        let Track::Platform(kept) = track else {
            return Err("it is not a platform level".into());
        };
        crate::game::generator::check_kept(pieces, kept.block_count(), limits)?;
        let mut build = PlatformBuild {
            track: PlatformTrack::new(*kept.start())
                .with_headroom(headroom_of(limits.player.abilities.as_ref())),
            goal,
            max_blocks: limits.max_pieces,
            player: limits.player,
            reach: Reach::of_player_in(
                &limits.player,
                limits.reach_runs.unwrap_or(reach::REACH_TRIALS),
            ),
        };
        for params in &kept.block_params()[..pieces] {
            build.track.push(*params).map_err(|e| e.to_string())?;
        }
        if pieces > 0 && build.track.last().reaches(goal) {
            return Err(crate::game::generator::prefix_reaches_goal(pieces));
        }
        Ok(build)
    }

    fn open_env(build: &PlatformBuild, complete: bool) -> PlatformEnv {
        let start = PlatformTrack::new(*build.track.start());
        let mut env = PlatformEnv::open(&start, build.goal, PlatformRewards::default());
        if let Some(Abilities::Character(character)) = build.player.abilities {
            env = env.with_body(character.into());
        }
        env.push_platform(build.track.last(), complete);
        env
    }

    fn extend_env(env: &mut PlatformEnv, build: &PlatformBuild, complete: bool) {
        env.push_platform(build.track.last(), complete);
    }

    fn wants_piece(env: &PlatformEnv) -> bool {
        env.awaits_platform()
    }

    fn furthest_piece(env: &PlatformEnv) -> usize {
        env.furthest()
    }

    fn air_steps(_: &PlatformEnv) -> u32 {
        0
    }

    fn respawn(env: &mut PlatformEnv, piece: usize, seed: u64) {
        env.reset_on(piece, seed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::game::generator::Match;
    use crate::level::params::{BLOCK_DISTANCE, BLOCK_HEIGHT, BLOCK_SIZE};
    use crate::level::platform::Start;
    use crate::level::stats::Outcome;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The action row that places the next block straight toward `goal`, short jumps.
    fn aimed(track: &PlatformTrack, goal: [f64; 3]) -> [f32; 4] {
        let last = track.last();
        let (dx, dz) = (goal[0] - last.position[0], goal[2] - last.position[2]);
        [
            BLOCK_DISTANCE.to_unit(dx.hypot(dz).clamp(5.0, 6.0)),
            0.0,
            BLOCK_SIZE.to_unit(6.0),
            BLOCK_HEIGHT.to_unit((goal[1] - last.position[1]).clamp(-1.0, 1.0)),
        ]
        .map(|x| x as f32)
    }

    #[test]
    fn the_observation_sees_the_goal_in_the_last_blocks_frame() {
        let start = Start {
            heading: 90.0,
            ..Start::default()
        };
        let track = PlatformTrack::new(start);
        // Heading 90 points along -z; a goal 20 m along -z is straight ahead, one to +x is right.
        let mut out = [0.0; GENERATOR_OBSERVATION_SIZE];
        observe(&track, [0.0, 4.0, -20.0], &[0.5], 30, &mut out);
        assert!((out[0] - 0.4).abs() < 1e-6 && (out[1] - 0.08).abs() < 1e-6 && out[2].abs() < 1e-6);
        assert!(
            out[3].abs() < 1e-6 && (out[4] - 1.0).abs() < 1e-6,
            "bearing 0"
        );
        assert_eq!(out[GENERATOR_OBSERVATION_SIZE - 1], 0.5, "aux last");
        assert_eq!(out[GENERATOR_OBSERVATION_SIZE - 2], 1.0, "all blocks left");
        observe(&track, [20.0, 0.0, 0.0], &[0.5], 30, &mut out);
        assert!(
            (out[3] + 1.0).abs() < 1e-6,
            "a goal to the right is a negative turn"
        );
        let aim = aimed(&track, [20.0, 0.0, 0.0]);
        let block = block_from_action(
            &track,
            [20.0, 0.0, 0.0],
            &aim,
            (&Player::default(), &Reach::default()),
        );
        assert!((block.angle + 90.0).abs() < 1e-3, "{block:?}");
    }

    /// A track from the default start towards `goal`, of at most 30 blocks, for the built-in
    /// character.
    fn test_build(goal: [f64; 3]) -> PlatformBuild {
        PlatformBuild {
            track: PlatformTrack::new(Start::default()),
            goal,
            max_blocks: 30,
            player: Player::default(),
            reach: Reach::default(),
        }
    }

    #[test]
    fn a_blocks_style_spans_its_ranges_and_a_match_observes_and_pays_its_knobs() {
        let ranges = Player::default().blocks();
        let block = |distance: f64, height: f64| BlockParams {
            distance,
            angle: 0.0,
            size: 5.0,
            height,
        };
        assert_eq!(ranges.style(&block(5.0, 0.0)), [-1.0, -1.0]);
        assert_eq!(ranges.style(&block(10.0, -2.0)), [1.0, 1.0]);
        assert_eq!(ranges.style(&block(7.5, 1.0)), [0.0, 0.0]);
        // Knobs come after the game's observation; a long jump pays at stride +1, costs at -1.
        let rewards = GeneratorRewards {
            knobs: vec![1.0, 1.0],
            ..GeneratorRewards::default()
        };
        let long = [1.0, 0.0, 0.0, 0.0];
        let mut paid = Vec::new();
        for stride in [1.0, -1.0, 0.0] {
            let mut game = Match::<PlatformGame>::new(test_build([0.0, 0.0, -60.0]), vec![1.0], 7)
                .with_knobs(vec![stride, 0.5]);
            let mut out = vec![0.0; GENERATOR_OBSERVATION_SIZE + 2];
            game.observe_generator(&mut out);
            assert_eq!(out[GENERATOR_OBSERVATION_SIZE..], [stride, 0.5]);
            assert_eq!(game.place(&long), Placement::Placed);
            let measured = ranges.style(&game.build().track.block_params()[0]);
            assert!(measured[0] > 0.5, "{measured:?}");
            paid.push(game.placed_style_reward(&rewards) - 0.5 * measured[1]);
        }
        assert!(
            paid[0] > 0.5 && paid[1] < -0.5 && paid[2] == 0.0,
            "{paid:?}"
        );
    }

    #[test]
    fn a_match_grows_its_track_as_the_solver_advances_and_ends_at_the_goal() {
        let goal = [30.0, 2.0, 0.0];
        let build = test_build(goal);
        let mut game = Match::<PlatformGame>::new(build, vec![1.0], 7);
        let rewards = GeneratorRewards::default();
        let mut controller = crate::game::platform::ScriptedController::new(7, 0.0);
        let mut generator_return = 0.0;
        let mut placements = 0;
        for _ in 0..10_000 {
            if game.needs_piece() {
                let row = aimed(&game.build().track, goal);
                let placed = game.place(&row);
                assert!(
                    matches!(placed, Placement::Placed | Placement::Completed),
                    "{placed:?}"
                );
                placements += 1;
            }
            let action = controller.act(game.env());
            let (step, reward) = game.step_solver(action, &rewards);
            generator_return += reward;
            if let Some(outcome) = step.outcome {
                assert_eq!(
                    outcome,
                    Outcome::Success,
                    "the scripted Solver finishes easy jumps"
                );
                break;
            }
        }
        assert!(
            placements >= 5,
            "{placements} blocks for 30 m in steps of at most 6 m"
        );
        assert!(game.build().track.last().reaches(goal));
        // Paid 0.1 per metre for the whole way: from the start block (30.07 m from the goal) to
        // within 3 m of it.
        assert!(
            (2.7..=3.01).contains(&generator_return),
            "{generator_return}"
        );
    }

    /// A paced match (λ +1 then -1, or -1 then +1, switching halfway) played by the scripted
    /// controller until `stop_after` blocks are behind it, then standing still until its time
    /// runs out: the λ each block was built at, and the Generator's reward at the failure.
    fn paced_match(before: f32, after: f32, stop_after: usize) -> (Vec<f32>, Vec<f32>, f32) {
        use crate::game::generator::MatchPacing;
        let goal = [40.0, 0.0, 0.0];
        let build = test_build(goal);
        let pacing = MatchPacing {
            before,
            after,
            switch: 0.5,
        };
        let mut game = Match::<PlatformGame>::new(build, vec![before], 7).paced(pacing);
        let rewards = GeneratorRewards::default();
        let mut controller = crate::game::platform::ScriptedController::new(7, 0.0);
        let (mut observed, mut placed) = (Vec::new(), Vec::new());
        for _ in 0..20_000 {
            if game.needs_piece() {
                let mut observation = [0.0; GENERATOR_OBSERVATION_SIZE];
                game.observe_generator(&mut observation);
                observed.push(observation[GENERATOR_OBSERVATION_SIZE - 1]);
                let row = aimed(&game.build().track, goal);
                assert!(!game.place(&row).is_invalid());
                placed.push(game.placed_aux()[0]);
            }
            let action = if PlatformGame::furthest_piece(game.env()) >= stop_after {
                crate::game::platform::PlatformAction::default()
            } else {
                controller.act(game.env())
            };
            let (step, reward) = game.step_solver(action, &rewards);
            if let Some(outcome) = step.outcome {
                assert_ne!(outcome, Outcome::Success, "it stood still");
                return (observed, placed, reward);
            }
        }
        panic!("the run did not end");
    }

    #[test]
    fn a_paced_match_builds_and_pays_each_block_at_its_own_λ() {
        let (_, _, early) = paced_match(1.0, -1.0, 1);
        let (observed, placed, late) = paced_match(1.0, -1.0, 6);
        assert_eq!(
            observed, placed,
            "each block is built at the λ it was observed with"
        );
        // 40 m in blocks of at most 7.5 m: halfway comes after the first two or three.
        assert_eq!(&placed[..2], &[1.0, 1.0], "{placed:?}");
        assert_eq!(placed.last(), Some(&-1.0), "{placed:?}");
        assert!(placed.len() >= 6, "{placed:?}");
        // Standing still costs nothing but the failure: paid at the λ of the block the Solver
        // stands before (-10·λ).
        assert_eq!(early, -10.0, "failing at λ = +1 costs");
        assert_eq!(late, 10.0, "failing at λ = -1 pays");
        let (_, reversed, early) = paced_match(-1.0, 1.0, 1);
        assert_eq!(reversed[0], -1.0);
        assert_eq!(early, 10.0, "failing in the hard first half pays");
    }

    /// A hard match (λ = -1) with a retry: the scripted controller plays until `stop_after`
    /// blocks are behind it, then stands still, twice. Returns the Generator's reward at each
    /// failure, the share of the way of the block it failed to reach, and the match.
    fn retried_match(stop_after: usize) -> (Vec<f32>, f64, Match<PlatformGame>) {
        let goal = [40.0, 0.0, 0.0];
        let build = test_build(goal);
        let mut game = Match::<PlatformGame>::new(build, vec![-1.0], 7);
        let rewards = GeneratorRewards {
            retries: 1,
            ..GeneratorRewards::default()
        };
        let mut controller = crate::game::platform::ScriptedController::new(7, 0.0);
        let mut paid = Vec::new();
        for _ in 0..20_000 {
            if game.needs_piece() {
                let row = aimed(&game.build().track, goal);
                assert!(!game.place(&row).is_invalid());
            }
            let action = if PlatformGame::furthest_piece(game.env()) >= stop_after {
                crate::game::platform::PlatformAction::default()
            } else {
                controller.act(game.env())
            };
            let (step, reward) = game.step_solver(action, &rewards);
            if step.outcome.is_some() {
                assert_ne!(step.outcome, Some(Outcome::Success), "it stood still");
                paid.push(reward);
                if game.over() {
                    let build = game.build();
                    let share = (build.distance_to_goal(stop_after)
                        - build.distance_to_goal(stop_after + 1))
                        / build.distance_to_goal(0);
                    return (paid, share, game);
                }
                // Started again where it failed: on the block it stood on, the run going on.
                assert_eq!(PlatformGame::furthest_piece(game.env()), stop_after);
                assert_eq!(game.env().outcome(), None);
            }
        }
        panic!("the match did not end");
    }

    /// With retries, a failure is paid at the piece where it happens, by that piece's share of
    /// the way and not by being last; failing the same piece again costs more than the first
    /// failure paid (a wall does not pay), and the match ends when no retry is left.
    #[test]
    fn a_failure_is_charged_to_the_piece_it_happens_on() {
        let rewards = GeneratorRewards::default();
        for stop_after in [1, 3] {
            let (paid, share, game) = retried_match(stop_after);
            assert_eq!(paid.len(), 2, "one retry: two failures end the match");
            assert!(share > 0.05, "{share}");
            // The first failure: -10·λ × the weight × the share of the block not reached.
            let first = 10.0 * rewards.piece_failure_weight * share as f32;
            assert!((paid[0] - first).abs() < 1e-3, "{paid:?} vs {first}");
            // The repeat: that times (1 - h)² / (1 - (1 - h)²), h = 0.05 at λ = -1.
            assert!((paid[1] + first * 0.9025 / 0.0975).abs() < 1e-2, "{paid:?}");
            assert!(paid[0] + paid[1] < 0.0, "a piece failed twice costs");
            assert!(game.over());
            assert_eq!(game.solver_outcome(), Outcome::TimedOut);
        }
        // No retries (the paper's match): the first failure ends it, paid -10·λ wherever it is.
        let mut rewards = GeneratorRewards::default();
        assert_eq!(rewards.retries, 0);
        rewards.retries = 1;
        assert_eq!(rewards.on_piece_failure(&[1.0], 0.2, false), -10.0);
        assert_eq!(rewards.on_piece_failure(&[1.0], 0.2, true), -10.0);
        assert_eq!(rewards.on_piece_failure(&[0.0], 0.2, true), 0.0);
    }

    #[test]
    fn a_zero_action_heads_straight_for_the_goal_in_three_dimensions() {
        let track = PlatformTrack::new(Start {
            heading: 90.0,
            ..Start::default()
        });
        let block = block_from_action(
            &track,
            [20.0, 4.0, 0.0],
            &[0.0; 4],
            (&Player::default(), &Reach::default()),
        );
        assert_eq!(block.distance, 7.5);
        assert_eq!(
            block.angle, -90.0,
            "a right turn from heading 90 to the goal along +x"
        );
        assert_eq!(block.height, 1.5, "4 m over 20 m, for 7.5 m");
        let steep = block_from_action(
            &track,
            [20.0, 40.0, 0.0],
            &[0.0, 0.0, 0.0, 1.0],
            (&Player::default(), &Reach::default()),
        );
        assert_eq!(
            steep.height, 2.0,
            "clamped to the range of docs/spec.md §1.1"
        );
    }

    #[test]
    fn no_action_places_a_block_beyond_reach_or_turns_back() {
        let track = PlatformTrack::new(Start {
            size: 4.0,
            ..Start::default()
        });
        // Longest, smallest, steepest up: 10 m between 4 m blocks would be a 6 m gap 2 m up,
        // where the reach table allows 4.25 m.
        let far_up = block_from_action(
            &track,
            [60.0, 30.0, 0.0],
            &[1.0, 0.0, -1.0, 1.0],
            (&Player::default(), &Reach::default()),
        );
        assert_eq!(far_up.height, 2.0);
        assert_eq!(far_up.distance, 4.25 + 0.5 * (4.0 + 4.0));
        let far_flat = block_from_action(
            &track,
            [60.0, 0.0, 0.0],
            &[1.0, 0.0, -1.0, 0.0],
            (&Player::default(), &Reach::default()),
        );
        assert_eq!(far_flat.distance, 10.0, "a flat 6 m gap is within reach");
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..2000 {
            let row: [f32; 4] = std::array::from_fn(|_| rng.random_range(-1.5..1.5));
            let goal = [60.0, rng.random_range(-20.0..20.0), 10.0];
            let block =
                block_from_action(&track, goal, &row, (&Player::default(), &Reach::default()));
            let placed = track.preview(&block);
            let gap = track.last().edge_gap(&placed);
            assert!(
                gap <= Reach::default().max_gap(block.height) + 1e-3,
                "{block:?}: gap {gap}"
            );
            assert!(block.angle.abs() <= reach::MAX_TURN, "{block:?}");
            assert!(BLOCK_DISTANCE.check(block.distance).is_ok(), "{block:?}");
            // A profile's ranges bound every block.
            let narrow = crate::level::profile::BlockRanges {
                max_distance: 6.5,
                min_size: 5.0,
                max_height: 0.5,
                max_turn: 30.0,
                ..Default::default()
            };
            let player =
                Player::default().with_pieces(Some(crate::level::profile::Pieces::Blocks(narrow)));
            let block = block_from_action(&track, goal, &row, (&player, &Reach::default()));
            if let Err(outside) = narrow.check_block(&block) {
                panic!("{block:?}: {outside}");
            }
        }
    }

    #[test]
    fn overlaps_and_running_out_of_blocks_end_the_match() {
        // Three sides of a square (5 m jumps, two left turns of 90°); the goal lies on to the
        // left, so heading for it puts the fourth block onto the start block.
        let start = Start {
            size: 4.0,
            ..Start::default()
        };
        let side = |angle| BlockParams::new(5.0, angle, 4.0, 0.0).unwrap();
        let track =
            PlatformTrack::from_params(start, &[side(0.0), side(90.0), side(90.0)]).unwrap();
        let build = PlatformBuild {
            track,
            goal: [0.0, 0.0, 30.0],
            max_blocks: 4,
            player: Player::default(),
            reach: Reach::default(),
        };
        let mut game = Match::<PlatformGame>::new(build, vec![-1.0], 1);
        let toward_goal = [-1.0, 0.0, 0.0, 0.0];
        assert_eq!(
            game.place(&toward_goal),
            Placement::Invalid,
            "a 90° turn onto the start block"
        );
        let away = [-1.0, 1.0, 0.0, 0.0];
        assert_eq!(game.place(&away), Placement::Placed);
        assert_eq!(game.place(&away), Placement::OutOfPieces);
    }
}
