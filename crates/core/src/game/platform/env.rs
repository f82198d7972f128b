//! The Solver's platform environment: reset with a level and a seed, step with an action, read
//! the observation (state vector + height map), the reward (docs/spec.md §2) and how the run ended.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::Vector;

use super::character::{Body, Character, DECISION_DT, PlatformAction};
use super::course::Course;
pub use super::course::{FALL_MARGIN, PlatformRewards};
use super::world::PlatformWorld;
use crate::game::SolverEnv;
use crate::game::Step;
use crate::level::PlatformTrack;
use crate::level::platform::Platform;
use crate::level::stats::Outcome;

/// Rows and columns of the height map.
pub const HEIGHT_MAP_SIDE: usize = 5;
/// Ray offsets ahead of the character (its frame), m.
const HEIGHT_MAP_FORWARD: [f32; HEIGHT_MAP_SIDE] = [-1.5, 0.0, 1.5, 3.0, 4.5];
/// Ray offsets to the character's left, m.
const HEIGHT_MAP_LEFT: [f32; HEIGHT_MAP_SIDE] = [-3.0, -1.5, 0.0, 1.5, 3.0];
/// Rays start this far above the feet...
const RAY_START_HEIGHT: f32 = 2.2;
/// ...and see this far down.
const RAY_LENGTH: f32 = 8.0;

/// The named parts of the observation vector, in order, with their lengths.
pub const OBSERVATION_LAYOUT: [(&str, usize); 9] = [
    ("goal_relative_position", 3),
    ("goal_distance", 1),
    ("next_block_relative_position", 3),
    ("next_block_size", 1),
    ("velocity", 3),
    ("next_block_bearing_sin_cos", 2),
    ("grounded", 1),
    ("time_left", 1),
    ("height_map", HEIGHT_MAP_SIDE * HEIGHT_MAP_SIDE),
];

/// What each part of [`OBSERVATION_LAYOUT`] holds, for a port of it (an export's sidecar).
pub const OBSERVATION_MEANINGS: [&str; 9] = [
    "goal - feet in the character's frame (forward f = (cos yaw, 0, -sin yaw), up, left l = (f.z, 0, -f.x)), / 50 m",
    "|goal - feet| / 50 m",
    "top centre of the block after the furthest one stood on, minus the feet, character frame, / 10 m",
    "that block's side / 6 m",
    "velocity in the character's frame / 10 m/s",
    "sin, cos of the next block's bearing, atan2(left, forward) of its relative position (+ left)",
    "1 on the ground, else 0",
    "1 - decisions taken / decisions allowed (10 s + 4 s per block, 30 decisions per s)",
    "(2.2 - d) / 4 for 25 rays straight down from 2.2 m above the feet, d the distance to a hit (8 m: none); forward-major: rows 1.5 m behind to 4.5 m ahead in 1.5 m steps, each from 3 m right to 3 m left in 1.5 m steps",
];

/// Length of the state part (everything before the height map).
const STATE_SIZE: usize = OBSERVATION_SIZE - HEIGHT_MAP_SIDE * HEIGHT_MAP_SIDE;

/// Length of the observation vector.
pub const OBSERVATION_SIZE: usize = {
    let mut total = 0;
    let mut i = 0;
    while i < OBSERVATION_LAYOUT.len() {
        total += OBSERVATION_LAYOUT[i].1;
        i += 1;
    }
    total
};

/// One Solver run on one platform level.
pub struct PlatformEnv {
    world: PlatformWorld,
    goal: Vector,
    rewards: PlatformRewards,
    /// The run's way along the blocks.
    course: Course,
    character: Character,
    /// The character's abilities (the game profile's).
    body: Body,
}

impl PlatformEnv {
    /// The environment of a track leading to `goal`, with the character on the start block.
    pub fn new(track: &PlatformTrack, goal: [f64; 3], rewards: PlatformRewards) -> Self {
        let world = PlatformWorld::new(track);
        let start = world.platforms()[0];
        let mut env = Self {
            world,
            goal: Vector::new(goal[0] as f32, goal[1] as f32, goal[2] as f32),
            rewards,
            course: Course::default(),
            character: Character::new(start.top, start.heading, Body::default()),
            body: Body::default(),
        };
        env.course = Course::new(&env.world, DECISION_DT);
        env.reset(0);
        env
    }

    /// The same environment for a character of other abilities (a game profile's).
    pub fn with_body(mut self, body: Body) -> Self {
        self.body = body;
        self.reset(0);
        self
    }

    /// The environment of a track the Generator is still building: it starts with `track`
    /// (often just the start block) and grows with [`PlatformEnv::push_platform`].
    pub fn open(track: &PlatformTrack, goal: [f64; 3], rewards: PlatformRewards) -> Self {
        let mut env = Self::new(track, goal, rewards);
        env.course = env.course.opened();
        env
    }

    /// Adds the Generator's next block. `closes`: it is the last one (it reaches the goal), so
    /// standing on it is success. The run goes on where it was; its time limit grows.
    pub fn push_platform(&mut self, platform: &Platform, closes: bool) {
        self.world.push(platform);
        let feet = self.character.feet;
        self.course.grown(&self.world, closes, feet, DECISION_DT);
    }

    /// Whether the character stands on the newest block of a growing track: the Generator's
    /// turn to place the next one.
    pub fn awaits_platform(&self) -> bool {
        self.course.awaits_platform(&self.world)
    }

    /// Starts a new run on block `block` (0: the start block), as [`PlatformEnv::reset`] does on
    /// the start block; the blocks before it count as left behind.
    pub fn reset_on(&mut self, block: usize, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let block = block.min(self.world.platforms().len() - 1);
        let start = self.world.platforms()[block];
        let reach = (0.5 * start.size - self.body.radius - 0.5).clamp(0.0, 1.0);
        let local = Vector::new(
            rng.random_range(-reach..=reach),
            0.0,
            rng.random_range(-reach..=reach),
        );
        let offset = rapier3d::math::Rotation::from_rotation_y(start.heading) * local;
        let yaw = start.heading + rng.random_range(-90.0f32..=90.0).to_radians();
        self.character = Character::new(start.top + offset, yaw, self.body);
        let feet = self.character.feet;
        self.course.restart(&self.world, block, feet);
    }

    /// The platform the character stands on, if grounded on one.
    fn standing_on(&self) -> Option<usize> {
        if !self.character.grounded {
            return None;
        }
        let feet = self.character.feet;
        self.world
            .platforms()
            .iter()
            .position(|p| (feet.y - p.top.y).abs() < 0.2 && p.covers(feet, self.body.radius))
    }

    /// Index of the next platform to reach (the last one once the run has succeeded).
    fn next_index(&self) -> usize {
        self.course.next_index(&self.world)
    }

    /// How far each height-map ray travels down before it hits something ([`RAY_LENGTH`] where
    /// nothing is below), forward-major: from [`HEIGHT_MAP_FORWARD`]'s first row (behind), each
    /// row from right to left ([`HEIGHT_MAP_LEFT`]), every ray from [`RAY_START_HEIGHT`] above
    /// the feet.
    fn height_map_hits(&self) -> [f32; HEIGHT_MAP_SIDE * HEIGHT_MAP_SIDE] {
        let c = &self.character;
        let forward = c.facing();
        let left = Vector::new(forward.z, 0.0, -forward.x);
        let origins = HEIGHT_MAP_FORWARD.iter().flat_map(|&f| {
            HEIGHT_MAP_LEFT
                .iter()
                .map(move |&l| c.feet + forward * f + left * l + Vector::Y * RAY_START_HEIGHT)
        });
        let mut hits = [0.0; HEIGHT_MAP_SIDE * HEIGHT_MAP_SIDE];
        self.world.cast_down(origins, RAY_LENGTH, &mut hits);
        hits
    }

    /// The observation as a new vector.
    pub fn observation(&self) -> Vec<f32> {
        let mut out = vec![0.0; OBSERVATION_SIZE];
        self.observe(&mut out);
        out
    }

    /// The character as it stands now.
    pub fn character(&self) -> &Character {
        &self.character
    }

    /// The blocks the run plays on.
    pub fn world(&self) -> &PlatformWorld {
        &self.world
    }

    /// Highest platform index stood on so far (0 is the start block).
    pub fn furthest(&self) -> usize {
        self.course.furthest()
    }

    /// Fraction of the blocks reached, in [0, 1].
    pub fn progress(&self) -> f64 {
        self.course.progress(&self.world)
    }

    /// Decisions taken so far.
    pub fn steps(&self) -> u32 {
        self.course.steps()
    }

    /// How the run ended, once it has.
    pub fn outcome(&self) -> Option<Outcome> {
        self.course.outcome()
    }
}

impl crate::game::SolverEnv for PlatformEnv {
    type Action = PlatformAction;
    const OBSERVATION_SIZE: usize = OBSERVATION_SIZE;

    /// Starts a new run: the character stands on the start block, placed and turned at random
    /// (seeded) within a metre of its centre and 90 degrees of the track's direction.
    fn reset(&mut self, seed: u64) {
        self.reset_on(0, seed);
    }

    /// Advances one decision.
    fn step(&mut self, action: PlatformAction) -> Step {
        if let Some(finished) = self.course.finished() {
            return finished;
        }
        self.character.step(&self.world, action);
        let now = (self.character.feet, self.standing_on());
        self.course.after_decision(&self.world, now, &self.rewards)
    }

    /// Writes the observation (see [`OBSERVATION_LAYOUT`]) into `out`.
    fn observe(&self, out: &mut [f32]) {
        assert_eq!(
            out.len(),
            OBSERVATION_SIZE,
            "observation buffer of the wrong size"
        );
        let c = &self.character;
        let forward = c.facing();
        let left = Vector::new(forward.z, 0.0, -forward.x);
        let local = |v: Vector| [v.dot(forward), v.y, v.dot(left)];
        let next = self.world.platforms()[self.next_index()];
        let to_goal = self.goal - c.feet;
        let to_next = next.top - c.feet;
        let bearing = to_next.dot(left).atan2(to_next.dot(forward));
        let state = local(to_goal)
            .map(|x| x / 50.0)
            .into_iter()
            .chain([to_goal.length() / 50.0])
            .chain(local(to_next).map(|x| x / 10.0))
            .chain([next.size / 6.0])
            .chain(local(c.velocity).map(|x| x / 10.0))
            .chain([bearing.sin(), bearing.cos()])
            .chain([if c.grounded { 1.0 } else { 0.0 }])
            .chain([self.course.time_left()]);
        let (state_out, map) = out.split_at_mut(STATE_SIZE);
        for (slot, value) in state_out.iter_mut().zip(state) {
            *slot = value;
        }
        for (slot, depth) in map.iter_mut().zip(self.height_map_hits()) {
            *slot = (RAY_START_HEIGHT - depth) / 4.0;
        }
    }

    fn action_from_policy_row(row: &[f32]) -> PlatformAction {
        PlatformAction::from_policy_row(row)
    }

    fn random_action(rng: &mut ChaCha8Rng) -> PlatformAction {
        PlatformAction {
            forward: rng.random_range(-1.0..=1.0),
            turn: rng.random_range(-1.0..=1.0),
            jump: rng.random_bool(0.5),
        }
    }

    fn trial_result(&self, outcome: Outcome) -> crate::level::stats::TrialResult {
        crate::level::stats::TrialResult {
            outcome,
            progress: self.progress(),
            target_piece: self.furthest(),
            steps: self.steps(),
            air_steps: None,
        }
    }

    fn marker(&self) -> [f32; 3] {
        let f = self.character().feet;
        [f.x, f.y, f.z]
    }

    fn port_state(&self) -> crate::game::PortState {
        let c = &self.character;
        let next = self.world.platforms()[self.next_index()];
        vec![
            ("feet", crate::game::spec::coords(c.feet)),
            ("yaw", vec![f64::from(c.yaw)]),
            ("velocity", crate::game::spec::coords(c.velocity)),
            ("grounded", vec![f64::from(u8::from(c.grounded))]),
            ("steps", vec![f64::from(self.course.steps())]),
            ("max_steps", vec![f64::from(self.course.max_steps())]),
            ("goal", crate::game::spec::coords(self.goal)),
            ("next_block_top", crate::game::spec::coords(next.top)),
            ("next_block_size", vec![f64::from(next.size)]),
            (
                "height_map_hits",
                self.height_map_hits().map(f64::from).to_vec(),
            ),
        ]
    }
}
