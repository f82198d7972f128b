//! The Solver's racing environment: reset with a track and a seed, step with throttle and
//! steering, read the observation (state + centre line ahead + a fan of downward rays), the
//! reward (docs/spec.md §2; values in docs/racing-physics.md) and how the run ended: the goal, off the road, flipped or out of time.
//! It counts the steps the car spends in the air.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::{Rotation, Vector};

use super::car::{Car, CarAction, DECISION_DT, RacingWorld, START_S, TrackShapes};
use crate::game::SolverEnv;
use crate::game::Step;
use crate::level::racing::{RacingTrack, SegmentParams};
use crate::level::road::Road;
use crate::level::stats::Outcome;

/// Centre-line points the observation looks ahead to, m along the road from the car.
pub const LOOK_AHEAD: [f64; 5] = [8.0, 16.0, 26.0, 40.0, 60.0];
/// How far along the road ahead the Solver's observation reaches (its furthest look-ahead
/// point; the ray fan reaches less far), m. A Generator building the road during a run keeps at
/// least this much road ahead of the car, so the Solver sees the same things in a match as on a
/// finished track.
pub const SIGHT: f64 = LOOK_AHEAD[LOOK_AHEAD.len() - 1];
/// Ray fan, metres ahead of the car (its heading, level)...
const FAN_FORWARD: [f32; 4] = [5.0, 11.0, 19.0, 30.0];
/// ...and to its left.
const FAN_LEFT: [f32; 5] = [-7.0, -3.5, 0.0, 3.5, 7.0];
/// Fan rays start this high above the chassis...
const FAN_START_HEIGHT: f32 = 6.0;
/// ...and see this far down.
const FAN_LENGTH: f32 = 18.0;
/// The chassis centre this high over the road below it, with no wheel touching, is in the air, m
/// (at rest it rides 0.8 m over the road).
pub const AIR_HEIGHT: f32 = 1.4;
/// Off the road: no wheel touching, the chassis beyond an edge, for this many seconds...
const OFF_ROAD_S: f32 = 0.3;
/// ...or this far below the road, m.
const BELOW_ROAD: f64 = 4.0;
/// Flipped: the chassis's up axis this close to horizontal or worse...
const FLIP_UP: f32 = 0.3;
/// ...for this many seconds.
const FLIP_S: f32 = 1.0;
/// Time allowed: this many seconds...
const TIME_BASE_S: f64 = 10.0;
/// ...plus the road's length at this speed, m/s.
const TIME_SPEED: f64 = 6.0;
/// The start is jittered (seeded) up to this far sideways, m...
const START_JITTER_M: f64 = 1.0;
/// ...and turned up to this much, degrees.
const START_JITTER_DEG: f64 = 4.0;

/// The named parts of the observation vector, in order, with their lengths. Nothing in it
/// depends on how long the road is beyond [`SIGHT`] (no fraction of the road done, no fraction
/// of the time limit left): a road a Generator is still building reads as a finished one.
pub const OBSERVATION_LAYOUT: [(&str, usize); 9] = [
    ("goal_relative_position", 3),
    ("goal_bearing_sin_cos", 2),
    ("velocity", 3),
    ("angular_velocity", 3),
    ("world_up_in_car_frame", 3),
    ("lateral_offset", 1),
    ("road_bearing_sin_cos", 2),
    ("centre_line_ahead", 2 * LOOK_AHEAD.len()),
    ("ray_fan", FAN_FORWARD.len() * FAN_LEFT.len()),
];

/// What each part of [`OBSERVATION_LAYOUT`] holds, for a port of it (an export's sidecar).
pub const OBSERVATION_MEANINGS: [&str; 9] = [
    "goal - chassis centre in the car's level heading frame (x ahead, y up, z right; heading = atan2(-F.z, F.x) of the body's forward axis F), / 100 m",
    "sin, cos of atan2(-z, x) of that vector (+ left)",
    "linear velocity in the body frame (x forward, y up, z right) / 20 m/s",
    "angular velocity in the body frame, rad/s",
    "world +Y in the body frame",
    "the chassis centre's signed distance from the nearest centre-line point across the road's heading there (+ left) / half the road's width (4.5 m on the built-in road; ±1 at the edges)",
    "sin, cos of (the road's heading at the nearest centre-line point - the car's heading)",
    "the centre line 8, 16, 26, 40, 60 m further along than the car, each in the level heading frame as x / 60 m then z / 20 m",
    "(6 - d) / 6 for 20 rays straight down from 6 m above the chassis centre, d the distance to road or obstacle (18 m: none); forward-major: rows 5, 11, 19, 30 m ahead, each from 7 m right to 7 m left in 3.5 m steps, in the level heading frame",
];

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
const FAN_SIZE: usize = FAN_FORWARD.len() * FAN_LEFT.len();

/// The Solver's reward weights (docs/spec.md §2; values in docs/racing-physics.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RacingRewards {
    /// Per metre of progress along the centre line (negative when going back).
    pub progress_per_metre: f32,
    /// On reaching the end of the road.
    pub success: f32,
    /// On leaving the road, flipping or running out of time.
    pub failure: f32,
}

impl Default for RacingRewards {
    fn default() -> Self {
        Self {
            progress_per_metre: 0.1,
            success: 10.0,
            failure: -5.0,
        }
    }
}

/// One Solver run on one racing track.
pub struct RacingEnv {
    road: Road,
    shapes: TrackShapes,
    goal: [f64; 3],
    rewards: RacingRewards,
    /// The car's abilities (the game profile's).
    car: Car,
    world: RacingWorld,
    max_steps: u32,
    /// Index of the road sample nearest the car.
    nearest: usize,
    /// Distance along the road of the car, m.
    along: f64,
    steps: u32,
    air_steps: u32,
    loose_steps: u32,
    flipped_steps: u32,
    outcome: Option<Outcome>,
    /// The road reaches the goal (false while a Generator is still building it): only then does
    /// its end count as success.
    complete: bool,
}

impl RacingEnv {
    /// The environment of a track leading to `goal`, with the car at the start.
    pub fn new(track: &RacingTrack, goal: [f64; 3], rewards: RacingRewards) -> Self {
        let road = track.road();
        let shapes = TrackShapes::new(&road, &track.obstacles);
        Self::from_parts(road, shapes, goal, rewards)
    }

    /// The environment of a resolved road and its shapes, with the car at the start.
    fn from_parts(road: Road, shapes: TrackShapes, goal: [f64; 3], rewards: RacingRewards) -> Self {
        let car = Car::default();
        let world = RacingWorld::new(&shapes, car, Vector::ZERO, 0.0);
        let max_steps = Self::time_limit(&road);
        let mut env = Self {
            road,
            shapes,
            goal,
            rewards,
            car,
            world,
            max_steps,
            nearest: 0,
            along: 0.0,
            steps: 0,
            air_steps: 0,
            loose_steps: 0,
            flipped_steps: 0,
            outcome: None,
            complete: true,
        };
        env.reset(0);
        env
    }

    /// The same environment for a car of other abilities (a game profile's).
    pub fn with_car(mut self, car: Car) -> Self {
        self.car = car;
        self.reset(0);
        self
    }

    /// The environment of a track a Generator is still building: it starts with `track` (at
    /// least one segment) and grows with [`RacingEnv::push_segment`]; `complete`: it already
    /// reaches the goal.
    pub fn open(
        track: &RacingTrack,
        goal: [f64; 3],
        rewards: RacingRewards,
        complete: bool,
    ) -> Self {
        let mut env = Self::new(track, goal, rewards);
        env.complete = complete;
        env
    }

    /// Adds the Generator's next segment; `closes`: it reaches the goal, so the road's end is
    /// success. The run goes on where it was; its time limit grows with the road.
    pub fn push_segment(&mut self, segment: SegmentParams, closes: bool) {
        self.road.push(segment);
        self.shapes.set_road(&self.road);
        self.world.replace_road(&self.shapes);
        self.max_steps = Self::time_limit(&self.road);
        self.complete = closes;
    }

    /// Steps allowed on `road`.
    fn time_limit(road: &Road) -> u32 {
        ((TIME_BASE_S + road.length() / TIME_SPEED) / DECISION_DT as f64).ceil() as u32
    }

    /// Distance left to the end of the road as built so far, m.
    pub fn road_left(&self) -> f64 {
        self.road.length() - self.along
    }

    /// Starts a new run [`START_S`] m into segment `segment`, as [`RacingEnv::reset`] does at
    /// the road's start.
    pub fn reset_on(&mut self, segment: usize, seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let segment = segment.min(self.road.segment_count() - 1);
        let start = self
            .road
            .nearest_along(self.road.segment_start(segment) + START_S);
        let sample = self.road.samples()[start];
        let offset = rng.random_range(-START_JITTER_M..=START_JITTER_M);
        let turn = rng
            .random_range(-START_JITTER_DEG..=START_JITTER_DEG)
            .to_radians();
        let p = sample.across(offset);
        self.world = RacingWorld::new(
            &self.shapes,
            self.car,
            Vector::new(p[0] as f32, p[1] as f32, p[2] as f32),
            (sample.heading + turn) as f32,
        );
        self.nearest = start;
        self.along = sample.s;
        self.steps = 0;
        self.air_steps = 0;
        self.loose_steps = 0;
        self.flipped_steps = 0;
        self.outcome = None;
    }

    /// Distance along the road of the point of the centre line nearest `position`.
    fn along_at(&self, position: [f64; 3]) -> f64 {
        let sample = self.road.samples()[self.nearest];
        let f = sample.forward();
        let flat = (f[0] * f[0] + f[2] * f[2]).sqrt();
        let ahead = ((position[0] - sample.centre[0]) * f[0]
            + (position[2] - sample.centre[2]) * f[2])
            / flat;
        (sample.s + ahead).clamp(0.0, self.road.length())
    }

    /// Signed horizontal distance of `position` left of the centre line, m.
    fn lateral_offset(&self, position: [f64; 3]) -> f64 {
        let sample = self.road.samples()[self.nearest];
        let (s, c) = sample.heading.sin_cos();
        // Left of heading h is (−sin h, 0, −cos h).
        -(position[0] - sample.centre[0]) * s - (position[2] - sample.centre[2]) * c
    }

    fn height_over_ground(&self) -> f32 {
        let mut distance = [0.0];
        self.world.cast_down(
            std::iter::once(self.world.position()),
            2.0 * AIR_HEIGHT,
            &mut distance,
        );
        distance[0]
    }

    /// The car's heading in the level (radians about +Y, 0 along +X), from its forward axis.
    fn yaw(&self) -> f32 {
        let forward = self.world.rotation() * Vector::X;
        (-forward.z).atan2(forward.x)
    }

    /// The centre line's points [`LOOK_AHEAD`] metres further along the road than the car.
    fn centre_line_ahead(&self) -> [[f64; 3]; LOOK_AHEAD.len()] {
        LOOK_AHEAD
            .map(|ahead| self.road.samples()[self.road.nearest_along(self.along + ahead)].centre)
    }

    /// How far each fan ray travels down before it hits road or obstacle ([`FAN_LENGTH`] where
    /// nothing is below), forward-major: from [`FAN_FORWARD`]'s nearest row, each row from right
    /// to left ([`FAN_LEFT`]), every ray from [`FAN_START_HEIGHT`] above the chassis's centre,
    /// in the car's level heading frame.
    fn fan_hits(&self) -> [f32; FAN_SIZE] {
        let position = self.world.position();
        let level = Rotation::from_rotation_y(self.yaw());
        let origins = FAN_FORWARD.iter().flat_map(|&f| {
            FAN_LEFT
                .iter()
                .map(move |&l| position + level * Vector::new(f, FAN_START_HEIGHT, -l))
        });
        let mut hits = [0.0; FAN_SIZE];
        self.world.cast_down(origins, FAN_LENGTH, &mut hits);
        hits
    }

    /// The road the run drives.
    pub fn road(&self) -> &Road {
        &self.road
    }

    /// The physics world: the road, the obstacles and the car.
    pub fn world(&self) -> &RacingWorld {
        &self.world
    }

    /// Distance along the road the car has reached, m.
    pub fn along(&self) -> f64 {
        self.along
    }

    /// The segment the car is on.
    pub fn segment(&self) -> usize {
        self.road.samples()[self.nearest].segment
    }

    /// Fraction of the road covered, in [0, 1].
    pub fn progress(&self) -> f64 {
        (self.along / self.road.length()).clamp(0.0, 1.0)
    }

    /// Decisions taken so far.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Steps with the car in the air (no wheel touching, chassis [`AIR_HEIGHT`] over the road).
    pub fn air_steps(&self) -> u32 {
        self.air_steps
    }

    /// How the run ended, once it has.
    pub fn outcome(&self) -> Option<Outcome> {
        self.outcome
    }
}

fn wrap(angle: f32) -> f32 {
    (angle + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
}

fn to_f64(v: Vector) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn to_f32(p: [f64; 3]) -> Vector {
    Vector::new(p[0] as f32, p[1] as f32, p[2] as f32)
}

impl Clone for RacingEnv {
    /// The same track and goal, with the car back at the start (seed 0).
    fn clone(&self) -> Self {
        let mut env = Self::from_parts(
            self.road.clone(),
            self.shapes.clone(),
            self.goal,
            self.rewards,
        );
        env.complete = self.complete;
        env
    }
}

impl crate::game::SolverEnv for RacingEnv {
    type Action = CarAction;
    const OBSERVATION_SIZE: usize = OBSERVATION_SIZE;

    /// Starts a new run: the car at rest [`START_S`] m along the road, shifted and turned at
    /// random (seeded) within a metre and a few degrees.
    fn reset(&mut self, seed: u64) {
        self.reset_on(0, seed);
    }

    /// Advances one decision.
    fn step(&mut self, action: CarAction) -> Step {
        if let Some(outcome) = self.outcome {
            return Step::finished(outcome, 0.0);
        }
        self.world.step(action);
        self.steps += 1;
        let position = to_f64(self.world.position());
        self.nearest = self.road.nearest(position, Some(self.nearest), 8);
        let sample = self.road.samples()[self.nearest];
        let along = self.along_at(position);
        let reward = self.rewards.progress_per_metre * (along - self.along) as f32;
        self.along = along;

        let wheels = self.world.wheels_in_contact();
        if wheels == 0 && self.height_over_ground() > AIR_HEIGHT {
            self.air_steps += 1;
        }
        let lateral = self.lateral_offset(position);
        let beyond_edge = lateral.abs() > 0.5 * self.road.shape().width;
        self.loose_steps = if wheels == 0 && beyond_edge {
            self.loose_steps + 1
        } else {
            0
        };
        let up = self.world.rotation() * Vector::Y;
        self.flipped_steps = if up.y < FLIP_UP {
            self.flipped_steps + 1
        } else {
            0
        };
        let outcome = if self.complete
            && along >= self.road.length() - crate::level::racing::FINISH_LENGTH
            && !beyond_edge
        {
            Some(Outcome::Success)
        } else if position[1] < sample.centre[1] - BELOW_ROAD
            || self.loose_steps as f32 * DECISION_DT >= OFF_ROAD_S
        {
            Some(Outcome::OffRoad)
        } else if self.flipped_steps as f32 * DECISION_DT >= FLIP_S {
            Some(Outcome::Flipped)
        } else if self.steps >= self.max_steps {
            Some(Outcome::TimedOut)
        } else {
            None
        };
        self.outcome = outcome;
        Step::after(outcome, reward, self.rewards.success, self.rewards.failure)
    }

    /// Writes the observation (see [`OBSERVATION_LAYOUT`]) into `out`.
    fn observe(&self, out: &mut [f32]) {
        assert_eq!(
            out.len(),
            OBSERVATION_SIZE,
            "observation buffer of the wrong size"
        );
        let position = self.world.position();
        let rotation = self.world.rotation();
        let into_car = rotation.inverse();
        let yaw = self.yaw();
        let level = Rotation::from_rotation_y(yaw);
        let into_level = level.inverse();
        let goal = Vector::new(
            self.goal[0] as f32, self.goal[1] as f32, self.goal[2] as f32,
        );
        let to_goal = into_level * (goal - position);
        let bearing = (-to_goal.z).atan2(to_goal.x);
        let sample = self.road.samples()[self.nearest];
        let road_bearing = wrap(sample.heading as f32 - yaw);
        let velocity = into_car * self.world.velocity();
        let spin = into_car * self.world.angular_velocity();
        let up = into_car * Vector::Y;
        let ahead = self.centre_line_ahead().map(|point| {
            let local = into_level * (to_f32(point) - position);
            [local.x / 60.0, local.z / 20.0]
        });
        // Written straight into `out`: no allocation per decision.
        let state = (to_goal / 100.0)
            .to_array()
            .into_iter()
            .chain([bearing.sin(), bearing.cos()])
            .chain((velocity / 20.0).to_array())
            .chain(spin.to_array())
            .chain(up.to_array())
            .chain([self.lateral_offset(to_f64(position)) as f32
                / (0.5 * self.road.shape().width as f32)])
            .chain([road_bearing.sin(), road_bearing.cos()])
            .chain(ahead.into_iter().flatten());
        for (slot, value) in out[..OBSERVATION_SIZE - FAN_SIZE].iter_mut().zip(state) {
            *slot = value;
        }
        let fan = &mut out[OBSERVATION_SIZE - FAN_SIZE..];
        for (slot, depth) in fan.iter_mut().zip(self.fan_hits()) {
            // Height of what the ray hit relative to the chassis; nothing hit reads -12 m.
            *slot = (FAN_START_HEIGHT - depth) / 6.0;
        }
    }

    fn action_from_policy_row(row: &[f32]) -> CarAction {
        CarAction::from_policy_row(row)
    }

    fn random_action(rng: &mut ChaCha8Rng) -> CarAction {
        CarAction {
            throttle: rng.random_range(-1.0..=1.0),
            steer: rng.random_range(-1.0..=1.0),
        }
    }

    fn trial_result(&self, outcome: Outcome) -> crate::level::stats::TrialResult {
        crate::level::stats::TrialResult {
            outcome,
            progress: self.progress(),
            target_piece: self.segment(),
            steps: self.steps(),
            air_steps: Some(self.air_steps()),
        }
    }

    fn marker(&self) -> [f32; 3] {
        self.world.position().to_array()
    }

    fn port_state(&self) -> crate::game::PortState {
        let rotation = self.world.rotation();
        let sample = self.road.samples()[self.nearest];
        vec![
            ("position", crate::game::spec::coords(self.world.position())),
            (
                "rotation_xyzw",
                [rotation.x, rotation.y, rotation.z, rotation.w]
                    .map(f64::from)
                    .to_vec(),
            ),
            ("velocity", crate::game::spec::coords(self.world.velocity())),
            (
                "angular_velocity",
                crate::game::spec::coords(self.world.angular_velocity()),
            ),
            ("goal", self.goal.to_vec()),
            ("road_point", sample.centre.to_vec()),
            ("road_heading", vec![sample.heading]),
            ("centre_line_ahead", self.centre_line_ahead().concat()),
            ("fan_hits", self.fan_hits().map(f64::from).to_vec()),
        ]
    }
}
