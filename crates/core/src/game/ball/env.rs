//! The ball's Solver environment: a ball pushed across the platform game's blocks (their rapier
//! colliders, `PlatformWorld`) by rapier's kinematic controller, and a scripted pusher.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::Vector;
use rapier3d::parry::shape::Ball;

use crate::game::platform::PlatformRewards;
use crate::game::platform::course::Course;
use crate::game::platform::world::{PlatformBox, PlatformWorld};
use crate::game::{Scripted, Skill, SolverEnv, Step};
use crate::level::PlatformTrack;
use crate::level::platform::Platform;
use crate::level::profile::CharacterProfile;
use crate::level::stats::{Outcome, TrialResult};

/// Physics steps per second, and per decision.
const PHYSICS_HZ: f32 = 60.0;
const ACTION_REPEAT: u32 = 2;
const DT: f32 = 1.0 / PHYSICS_HZ;
/// Seconds between decisions.
const DECISION_DT: f32 = ACTION_REPEAT as f32 * DT;
/// Share of its horizontal speed a rolling ball loses per second when not pushed.
const ROLLING_LOSS: f32 = 0.8;

/// The observation's parts: all in world axes (a ball has no facing).
pub const OBSERVATION_LAYOUT: [(&str, usize); 7] = [
    ("goal_relative_position", 3),
    ("goal_distance", 1),
    ("next_block_relative_position", 3),
    ("next_block_size", 1),
    ("velocity", 3),
    ("grounded", 1),
    ("time_left", 1),
];

/// What each part of [`OBSERVATION_LAYOUT`] holds.
pub const OBSERVATION_MEANINGS: [&str; 7] = [
    "goal - ball's lowest point, world axes, / 50 m",
    "|goal - lowest point| / 50 m",
    "top centre of the block after the furthest one rolled onto, minus the lowest point, / 10 m",
    "that block's side / 6 m",
    "velocity / 10 m/s",
    "1 on a block, else 0",
    "1 - decisions taken / decisions allowed (10 s + 4 s per block, 30 decisions per s)",
];

/// Length of the observation.
pub const OBSERVATION_SIZE: usize = 13;

/// One decision: push the ball along the world's x and z (each in [-1, 1]), and hop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BallAction {
    /// The push along the world's x and z, each in [-1, 1].
    pub push: [f32; 2],
    /// Hop (only from the ground).
    pub hop: bool,
}

/// One run of the ball on a track of blocks.
pub struct BallEnv {
    world: PlatformWorld,
    goal: Vector,
    rewards: PlatformRewards,
    /// Its abilities: top speed, hop speed, gravity, push (ground and air) and radius.
    abilities: CharacterProfile,
    /// The run's way along the blocks (the platform game's, time limit and fall included).
    course: Course,
    centre: Vector,
    velocity: Vector,
    grounded: bool,
}

impl BallEnv {
    /// The environment of `track` leading to `goal`, the ball on the start block.
    pub fn new(track: &PlatformTrack, goal: [f64; 3], abilities: CharacterProfile) -> Self {
        let world = PlatformWorld::new(track);
        let start = world.platforms()[0].top;
        let mut env = Self {
            world,
            goal: Vector::new(goal[0] as f32, goal[1] as f32, goal[2] as f32),
            rewards: PlatformRewards::default(),
            abilities,
            course: Course::default(),
            centre: start,
            velocity: Vector::ZERO,
            grounded: false,
        };
        env.course = Course::new(&env.world, DECISION_DT);
        env.reset_on(0, 0);
        env
    }

    /// The environment of a track still being built from its start block.
    pub fn open(start: &PlatformTrack, goal: [f64; 3], abilities: CharacterProfile) -> Self {
        let mut env = Self::new(start, goal, abilities);
        env.course = env.course.opened();
        env
    }

    /// Adds the Generator's newest block; `closes`: it is the last.
    pub fn push_platform(&mut self, platform: &Platform, closes: bool) {
        self.world.push(platform);
        let bottom = self.bottom();
        self.course.grown(&self.world, closes, bottom, DECISION_DT);
    }

    /// Starts a run on block `block`, the ball within a metre of its centre (seeded).
    pub fn reset_on(&mut self, block: usize, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let block = block.min(self.world.platforms().len() - 1);
        let top = self.world.platforms()[block].top;
        let offset = Vector::new(
            rng.random_range(-1.0..=1.0),
            0.0,
            rng.random_range(-1.0..=1.0),
        );
        let lift = self.abilities.radius as f32 + 0.05;
        self.centre = top + offset + Vector::Y * lift;
        self.velocity = Vector::ZERO;
        self.grounded = false;
        let bottom = self.bottom();
        self.course.restart(&self.world, block, bottom);
    }

    /// The ball's lowest point.
    pub fn bottom(&self) -> Vector {
        self.centre - Vector::Y * self.abilities.radius as f32
    }

    fn next_block(&self) -> PlatformBox {
        self.world.platforms()[self.course.next_index(&self.world)]
    }

    fn standing_on(&self) -> Option<usize> {
        let bottom = self.bottom();
        self.grounded
            .then(|| {
                self.world
                    .platforms()
                    .iter()
                    .position(|p| (bottom.y - p.top.y).abs() < 0.2 && p.covers(bottom, 0.0))
            })
            .flatten()
    }

    /// Whether the ball rests on the newest block of a growing track.
    pub fn awaits_platform(&self) -> bool {
        self.course.awaits_platform(&self.world)
    }

    /// The furthest block rolled onto (0: the start block).
    pub fn furthest(&self) -> usize {
        self.course.furthest()
    }

    /// One physics step: push, gravity, the hop, and rapier's controller through the blocks.
    fn physics_step(&mut self, action: BallAction) {
        let a = &self.abilities;
        let push = Vector::new(action.push[0], 0.0, action.push[1]);
        let accel = if self.grounded {
            a.ground_accel
        } else {
            a.air_accel
        } as f32;
        let mut horizontal = Vector::new(self.velocity.x, 0.0, self.velocity.z) + push * accel * DT;
        if push.length_squared() < 1e-6 && self.grounded {
            horizontal *= 1.0 - ROLLING_LOSS * DT;
        }
        let top_speed = a.run_speed as f32;
        if horizontal.length() > top_speed {
            horizontal = horizontal.normalize() * top_speed;
        }
        let mut vertical = self.velocity.y - a.gravity as f32 * DT;
        if action.hop && self.grounded {
            vertical = a.jump_speed as f32;
        }
        self.velocity = Vector::new(horizontal.x, vertical, horizontal.z);
        let shape = Ball::new(a.radius as f32);
        let moved = self
            .world
            .move_character(DT, &shape, self.centre, self.velocity * DT);
        self.centre += moved.translation;
        self.grounded = moved.grounded;
        if self.grounded && self.velocity.y < 0.0 {
            self.velocity.y = 0.0;
        }
    }
}

impl SolverEnv for BallEnv {
    type Action = BallAction;
    const OBSERVATION_SIZE: usize = OBSERVATION_SIZE;

    fn reset(&mut self, seed: u64) {
        self.reset_on(0, seed);
    }

    fn step(&mut self, action: BallAction) -> Step {
        if let Some(finished) = self.course.finished() {
            return finished;
        }
        for _ in 0..ACTION_REPEAT {
            self.physics_step(action);
        }
        let now = (self.bottom(), self.standing_on());
        self.course.after_decision(&self.world, now, &self.rewards)
    }

    fn observe(&self, out: &mut [f32]) {
        let bottom = self.bottom();
        let next = self.next_block();
        let to_goal = self.goal - bottom;
        let to_next = next.top - bottom;
        let values = (to_goal / 50.0)
            .to_array()
            .into_iter()
            .chain([to_goal.length() / 50.0])
            .chain((to_next / 10.0).to_array())
            .chain([next.size / 6.0])
            .chain((self.velocity / 10.0).to_array())
            .chain([f32::from(u8::from(self.grounded))])
            .chain([self.course.time_left()]);
        for (slot, value) in out.iter_mut().zip(values) {
            *slot = value;
        }
    }

    fn action_from_policy_row(row: &[f32]) -> BallAction {
        let clean = |x: f32| {
            if x.is_finite() {
                x.clamp(-1.0, 1.0)
            } else {
                0.0
            }
        };
        BallAction {
            push: [clean(row[0]), clean(row[1])],
            hop: row[2] > 0.5,
        }
    }

    fn random_action(rng: &mut ChaCha8Rng) -> BallAction {
        BallAction {
            push: [rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0)],
            hop: rng.random_bool(0.5),
        }
    }

    fn trial_result(&self, outcome: Outcome) -> TrialResult {
        TrialResult {
            outcome,
            progress: self.course.progress(&self.world),
            target_piece: self.course.furthest(),
            steps: self.course.steps(),
            air_steps: None,
        }
    }

    fn marker(&self) -> [f32; 3] {
        self.bottom().to_array()
    }

    fn port_state(&self) -> crate::game::PortState {
        let next = self.next_block();
        vec![
            ("centre", crate::game::spec::coords(self.centre)),
            ("velocity", crate::game::spec::coords(self.velocity)),
            ("grounded", vec![f64::from(u8::from(self.grounded))]),
            ("steps", vec![f64::from(self.course.steps())]),
            ("max_steps", vec![f64::from(self.course.max_steps())]),
            ("goal", crate::game::spec::coords(self.goal)),
            ("next_block_top", crate::game::spec::coords(next.top)),
            ("next_block_size", vec![f64::from(next.size)]),
        ]
    }
}

/// A scripted pusher: rolls toward the next block at the speed whose hop lands on its centre,
/// and hops at the edge of the block it is on (or when a step stops it); weaker players misjudge
/// that speed by up to a share (novice 0.3, median 0.15, expert none), drawn per hop from the
/// run's seed.
pub struct BallPusher {
    rng: ChaCha8Rng,
    error: f32,
    factor: f32,
}

impl BallPusher {
    /// A pusher of this skill, its misjudgements drawn from `seed`.
    pub fn new(seed: u64, skill: Skill) -> Self {
        let error = match skill {
            Skill::Novice => 0.3,
            Skill::Median => 0.15,
            Skill::Expert => 0.0,
        };
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            error,
            factor: 1.0,
        }
    }
}

impl Scripted<BallEnv> for BallPusher {
    fn act(&mut self, env: &BallEnv) -> BallAction {
        let a = &env.abilities;
        let bottom = env.bottom();
        let next = env.next_block();
        let to_next = next.top - bottom;
        let flat = Vector::new(to_next.x, 0.0, to_next.z);
        let heading = flat.normalize_or_zero();
        let on = env
            .world
            .platforms()
            .iter()
            .rev()
            .find(|p| p.covers(bottom, 0.0) && (bottom.y - p.top.y).abs() < 0.3);
        let on_next = on.is_some_and(|p| p.top == next.top);
        // The flight of a hop from here to the next block's top, and the speed it needs.
        let (g, hop) = (a.gravity as f32, a.jump_speed as f32);
        let rise = hop * hop - 2.0 * g * to_next.y;
        let flight = if rise > 0.0 {
            (hop + rise.sqrt()) / g
        } else {
            hop / g
        };
        let wanted = match on_next {
            true => 0.0,
            false => (flat.length() / flight * self.factor).min(a.run_speed as f32),
        };
        let velocity = Vector::new(env.velocity.x, 0.0, env.velocity.z);
        let along = velocity.dot(heading);
        let across = velocity - heading * along;
        let push = (heading * (wanted - along) - across) * 0.5;
        let push = if push.length() > 1.0 {
            push.normalize()
        } else {
            push
        };
        let at_edge = on.is_none_or(|p| !p.covers(bottom + heading * 0.4, 0.0));
        let stopped = velocity.length() < 0.5 && flat.length() > 0.5 * next.size + 0.5;
        let hop = env.grounded && !on_next && (at_edge || stopped);
        if hop && self.error > 0.0 {
            self.factor = 1.0 + self.rng.random_range(-self.error..=self.error);
        }
        BallAction {
            push: [push.x, push.z],
            hop,
        }
    }
}
