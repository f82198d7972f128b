//! A scripted, non-learning platform controller: face the next block, run at the speed whose
//! jump lands just inside it, jump at the edge. It reads the world directly (it is a test
//! instrument and a stand-in Solver, not a learner), and is seeded: each run takes off a little
//! earlier or later, as a player would. Its [`Skill`] sets how much: the expert takes off up to
//! 0.3 m early and runs at the speed it wants; weaker players take off earlier still and misjudge
//! the run-up speed of each jump (docs/platform-physics.md, "The scripted controller's skills").

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::Vector;

use super::character::{Body, DECISION_DT, PlatformAction};
use super::env::PlatformEnv;
use super::world::PlatformBox;
use crate::game::Skill;

/// Take-off jitter of the expert scripted controller, m.
pub const VERIFY_JITTER: f32 = 0.3;

/// What a skill means to the platform controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerSkill {
    /// Take-off up to this many metres before the planned point, drawn per jump.
    pub takeoff_jitter: f32,
    /// The run-up speed of each jump is off by up to this share, either way, drawn per jump.
    pub speed_error: f32,
}

impl ControllerSkill {
    /// What `skill` means to the controller.
    pub fn of(skill: Skill) -> Self {
        let (takeoff_jitter, speed_error) = match skill {
            Skill::Novice => (1.5, 0.3),
            Skill::Median => (1.1, 0.2),
            Skill::Expert => (VERIFY_JITTER, 0.0),
        };
        Self {
            takeoff_jitter,
            speed_error,
        }
    }
}
/// Metres inside the next block's near edge the controller aims to land.
const LANDING_DEPTH: f32 = 1.5;
/// Largest heading error, degrees, at which it still runs and jumps.
const ALIGNED_DEG: f32 = 12.0;

/// The scripted controller.
pub struct ScriptedController {
    rng: ChaCha8Rng,
    skill: ControllerSkill,
    /// Commanded speed fraction, kept through the air.
    forward: f32,
    /// Take-off distance before the edge drawn for the current jump.
    takeoff_margin: f32,
    /// Factor on the run-up speed drawn for the current jump.
    speed_factor: f32,
}

impl ScriptedController {
    /// A controller whose take-off point varies by up to `takeoff_jitter` metres, seeded.
    pub fn new(seed: u64, takeoff_jitter: f32) -> Self {
        Self::with_skill(
            seed,
            ControllerSkill {
                takeoff_jitter,
                speed_error: 0.0,
            },
        )
    }

    /// A controller of `skill`, seeded.
    pub fn with_skill(seed: u64, skill: ControllerSkill) -> Self {
        let skill = ControllerSkill {
            takeoff_jitter: skill.takeoff_jitter.max(0.0),
            speed_error: skill.speed_error.clamp(0.0, 0.9),
        };
        let mut this = Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            skill,
            forward: 0.0,
            takeoff_margin: 0.0,
            speed_factor: 1.0,
        };
        this.draw_next_jump();
        this
    }

    /// Draws the timing of the next jump (the speed only when this player misjudges it, so the
    /// expert's runs are those of the controller before skills).
    fn draw_next_jump(&mut self) {
        self.takeoff_margin = self.rng.random_range(0.0..=self.skill.takeoff_jitter);
        if self.skill.speed_error > 0.0 {
            let e = self.skill.speed_error;
            self.speed_factor = 1.0 + self.rng.random_range(-e..=e);
        }
    }

    /// The action for the current state of `env`.
    pub fn act(&mut self, env: &PlatformEnv) -> PlatformAction {
        let c = env.character();
        let platforms = env.world().platforms();
        let current = platforms[env.furthest()];
        let next = platforms[(env.furthest() + 1).min(platforms.len() - 1)];
        let to_next = Vector::new(next.top.x - c.feet.x, 0.0, next.top.z - c.feet.z);
        let wanted_yaw = (-to_next.z).atan2(to_next.x);
        let error = wrap_radians(wanted_yaw - c.yaw);
        let body = c.body;
        let turn = (error / (body.turn_rate_deg.to_radians() * DECISION_DT)).clamp(-1.0, 1.0);
        if !c.grounded {
            return PlatformAction {
                forward: self.forward,
                turn,
                jump: false,
            };
        }
        if error.abs() > ALIGNED_DEG.to_radians() {
            self.forward = 0.1;
            return PlatformAction {
                forward: self.forward,
                turn,
                jump: false,
            };
        }
        let direction = to_next.normalize_or_zero();
        let (enter, leave) = crossing(&next, c.feet, direction);
        // Take off at this block's edge, or sooner where the next block overlaps it: its side
        // stops the capsule one radius short of its footprint.
        let takeoff =
            exit_distance(&current, c.feet, direction).min((enter - body.radius).max(0.0));
        let aim = enter + LANDING_DEPTH.min(0.5 * (leave - enter));
        let flight = flight_time(&body, next.top.y - c.feet.y);
        let speed = ((aim - takeoff) / flight).clamp(1.0, body.run_speed);
        self.forward = (self.speed_factor * speed / body.run_speed).min(1.0);
        let jump = takeoff < speed * DECISION_DT + self.takeoff_margin;
        if jump {
            self.draw_next_jump();
        }
        PlatformAction {
            forward: self.forward,
            turn,
            jump,
        }
    }
}

/// Seconds from take-off until a jump comes down to `rise` metres above the take-off height
/// (the longest flight when the rise is out of reach), for `body`.
fn flight_time(body: &Body, rise: f32) -> f32 {
    let (jump, gravity) = (body.jump_speed, body.gravity);
    let discriminant = (jump * jump - 2.0 * gravity * rise).max(0.0);
    (jump + discriminant.sqrt()) / gravity
}

/// Distance along `direction` from `point` (inside the block's footprint) to its edge.
fn exit_distance(block: &PlatformBox, point: Vector, direction: Vector) -> f32 {
    crossing(block, point, direction).1.max(0.0)
}

/// Distances along the horizontal ray `point + t * direction` at which it enters and leaves the
/// block's square footprint (slab method, in the block's frame).
fn crossing(block: &PlatformBox, point: Vector, direction: Vector) -> (f32, f32) {
    let origin = block.to_local(point);
    let dir = block.to_local(block.top + direction);
    let half = 0.5 * block.size;
    let mut near = f32::NEG_INFINITY;
    let mut far = f32::INFINITY;
    for (o, d) in [(origin.x, dir.x), (origin.z, dir.z)] {
        if d.abs() < 1e-6 {
            if o.abs() > half {
                return (f32::INFINITY, f32::INFINITY);
            }
            continue;
        }
        let (t1, t2) = ((-half - o) / d, (half - o) / d);
        near = near.max(t1.min(t2));
        far = far.min(t1.max(t2));
    }
    (near, far)
}

fn wrap_radians(angle: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    let wrapped = angle.rem_euclid(tau);
    if wrapped > std::f32::consts::PI {
        wrapped - tau
    } else {
        wrapped
    }
}

impl crate::game::Scripted<PlatformEnv> for ScriptedController {
    fn act(&mut self, env: &PlatformEnv) -> PlatformAction {
        ScriptedController::act(self, env)
    }
}
