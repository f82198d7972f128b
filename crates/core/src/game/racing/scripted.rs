//! A scripted, non-learning driver: pure pursuit of a point on the centre line ahead, at the
//! speed the road ahead allows (its tightest curve at a share of the tyres' grip, its sharpest
//! crest below take-off speed). It reads the road directly (a test instrument and a stand-in
//! Solver, not a learner) and is seeded: each run drives a little faster or slower. Its
//! [`Skill`] sets how well it judges the road: the expert uses 70% of the grip and steers
//! exactly; weaker drivers count on more grip than there is and their steering wobbles
//! (docs/racing-physics.md, "The scripted driver's skills").

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::Vector;

use super::car::{CarAction, GRAVITY};
use super::env::RacingEnv;
use crate::game::Skill;

/// Speed jitter of the scripted driver when it verifies tracks (±10%).
pub const VERIFY_JITTER: f32 = 0.1;

/// What a skill means to the scripted driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverSkill {
    /// Speed factor of each run, 1 ± this share.
    pub pace_jitter: f32,
    /// Share of the tyres' grip the driver counts on in curves.
    pub grip_share: f32,
    /// Steering error, a share of full lock, drawn anew every [`WOBBLE_DECISIONS`] decisions.
    pub steer_wobble: f32,
}

impl DriverSkill {
    /// What `skill` means to the driver.
    pub fn of(skill: Skill) -> Self {
        let (grip_share, steer_wobble) = match skill {
            Skill::Novice => (1.5, 0.25),
            Skill::Median => (1.3, 0.2),
            Skill::Expert => (GRIP_SHARE, 0.0),
        };
        Self {
            pace_jitter: VERIFY_JITTER,
            grip_share,
            steer_wobble,
        }
    }
}

/// Decisions a steering error lasts.
pub const WOBBLE_DECISIONS: u32 = 8;
/// Distance between the front and rear axles, m.
const WHEELBASE: f32 = 2.6;
/// The fastest the driver goes on a straight, m/s.
pub const CRUISE_SPEED: f32 = 24.0;
/// Share of the tyres' grip the driver uses in curves.
const GRIP_SHARE: f32 = 0.7;
/// Share of take-off speed the driver keeps to over crests (below 1: wheels stay down).
const CREST_SHARE: f32 = 0.85;
/// Deceleration the driver plans with when slowing for what is ahead, m/s².
const PLANNED_BRAKING: f32 = 4.0;

/// The scripted driver.
pub struct ScriptedDriver {
    rng: ChaCha8Rng,
    skill: DriverSkill,
    /// Speed factor of this run (1 ± jitter).
    pace: f32,
    /// Hold this speed whatever the road ahead (to measure what the car can do).
    hold: Option<f32>,
    /// The current steering error and the decisions it has lasted.
    wobble: f32,
    wobble_age: u32,
}

impl ScriptedDriver {
    /// A driver whose speed varies by up to `jitter` (a share, e.g. 0.1 for ±10%), seeded.
    pub fn new(seed: u64, jitter: f32) -> Self {
        Self::with_skill(
            seed,
            DriverSkill {
                pace_jitter: jitter,
                ..DriverSkill::of(Skill::Expert)
            },
        )
    }

    /// A driver of `skill`, seeded.
    pub fn with_skill(seed: u64, skill: DriverSkill) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_d71e);
        let jitter = skill.pace_jitter.clamp(0.0, 0.9);
        Self {
            pace: 1.0 + rng.random_range(-jitter..=jitter),
            rng,
            skill,
            hold: None,
            wobble: 0.0,
            wobble_age: 0,
        }
    }

    /// A driver that steers as the scripted one but holds `speed` m/s (braking if it must),
    /// blind to curves and crests ahead.
    pub fn holding(speed: f32) -> Self {
        Self {
            hold: Some(speed),
            ..Self::with_skill(0, DriverSkill::of(Skill::Expert))
        }
    }

    /// The speed the road ahead allows from distance `along`, m/s, counting on `grip_share` of
    /// the tyres' grip in curves.
    fn safe_speed(env: &RacingEnv, along: f64, speed: f32, grip_share: f32) -> f32 {
        let road = env.road();
        let samples = road.samples();
        let horizon = (speed * speed / (2.0 * PLANNED_BRAKING) + 15.0) as f64;
        let first = road.nearest_along(along);
        let mut limit = CRUISE_SPEED;
        for pair in samples[first..].windows(2) {
            let [a, b] = pair else { continue };
            let ahead = (a.s - along).max(0.0) as f32;
            if ahead as f64 > horizon {
                break;
            }
            let ds = b.s - a.s;
            let curvature = ((b.heading - a.heading) / ds).abs() as f32;
            // Crests curve the road downward: slope falls along it.
            let crest = (-(b.slope - a.slope) / ds).max(0.0) as f32;
            let bank = a.bank.abs() as f32;
            let grip = grip_share * GRAVITY * (env.world().car().grip + bank.tan());
            let mut here = CRUISE_SPEED;
            if curvature > 1e-4 {
                here = here.min((grip / curvature).sqrt());
            }
            if crest > 1e-4 {
                here = here.min(CREST_SHARE * (GRAVITY / crest).sqrt());
            }
            // What speed now still brakes down to `here` in the distance left.
            let reachable = (here * here + 2.0 * PLANNED_BRAKING * ahead).sqrt();
            limit = limit.min(reachable);
        }
        limit
    }

    /// The action for the current state of `env`.
    pub fn act(&mut self, env: &RacingEnv) -> CarAction {
        let world = env.world();
        let position = world.position();
        let rotation = world.rotation();
        let velocity = world.velocity();
        let forward = rotation * Vector::X;
        let speed = velocity.dot(forward);
        let look = (4.0 + 0.6 * speed.max(0.0)).clamp(6.0, 20.0);
        let road = env.road();
        let target = road.samples()[road.nearest_along(env.along() + look as f64)].centre;
        let to_target =
            Vector::new(target[0] as f32, target[1] as f32, target[2] as f32) - position;
        let yaw = (-forward.z).atan2(forward.x);
        let (s, c) = yaw.sin_cos();
        let ahead = to_target.x * c - to_target.z * s;
        let left = -to_target.x * s - to_target.z * c;
        let alpha = left.atan2(ahead);
        let distance = ahead.hypot(left).max(1.0);
        let mut steer = (2.0 * WHEELBASE * alpha.sin() / distance).atan() / world.car().max_steer;
        if self.skill.steer_wobble > 0.0 {
            if self.wobble_age.is_multiple_of(WOBBLE_DECISIONS) {
                let w = self.skill.steer_wobble;
                self.wobble = self.rng.random_range(-w..=w);
            }
            self.wobble_age += 1;
            steer += self.wobble;
        }
        let grip_share = self.skill.grip_share;
        let wanted = match self.hold {
            Some(hold) => hold,
            None => self.pace * Self::safe_speed(env, env.along(), speed.max(0.0), grip_share),
        };
        let throttle = (0.8 * (wanted - speed)).clamp(-1.0, 1.0);
        CarAction {
            throttle,
            steer: steer.clamp(-1.0, 1.0),
        }
    }
}

impl crate::game::Scripted<RacingEnv> for ScriptedDriver {
    fn act(&mut self, env: &RacingEnv) -> CarAction {
        ScriptedDriver::act(self, env)
    }
}
