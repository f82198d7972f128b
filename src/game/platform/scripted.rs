//! A scripted, non-learning platform controller: face the next block, run at the speed whose
//! jump lands just inside it, jump at the edge. It reads the world directly (it is a test
//! instrument and a stand-in Solver, not a learner), and is seeded: each run takes off a little
//! earlier or later, as a player would.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::math::Vector;

use super::character::{
    DECISION_DT, GRAVITY, JUMP_SPEED, PlatformAction, RADIUS, RUN_SPEED, TURN_RATE_DEG,
};
use super::env::PlatformEnv;
use super::world::PlatformBox;

/// Take-off jitter of the scripted controller when it verifies levels, m.
pub const VERIFY_JITTER: f32 = 0.3;
/// Metres inside the next block's near edge the controller aims to land.
const LANDING_DEPTH: f32 = 1.5;
/// Largest heading error, degrees, at which it still runs and jumps.
const ALIGNED_DEG: f32 = 12.0;

/// The scripted controller.
pub struct ScriptedController {
    rng: ChaCha8Rng,
    /// Up to this many metres of take-off timing noise (0 for a perfect player).
    takeoff_jitter: f32,
    /// Commanded speed fraction, kept through the air.
    forward: f32,
    /// Take-off distance before the edge drawn for the current jump.
    takeoff_margin: f32,
}

impl ScriptedController {
    /// A controller whose take-off point varies by up to `takeoff_jitter` metres, seeded.
    pub fn new(seed: u64, takeoff_jitter: f32) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let takeoff_margin = rng.random_range(0.0..=takeoff_jitter.max(0.0));
        Self {
            rng,
            takeoff_jitter: takeoff_jitter.max(0.0),
            forward: 0.0,
            takeoff_margin,
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
        let turn = (error / (TURN_RATE_DEG.to_radians() * DECISION_DT)).clamp(-1.0, 1.0);
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
        let takeoff = exit_distance(&current, c.feet, direction).min((enter - RADIUS).max(0.0));
        let aim = enter + LANDING_DEPTH.min(0.5 * (leave - enter));
        let flight = flight_time(next.top.y - c.feet.y);
        let speed = ((aim - takeoff) / flight).clamp(1.0, RUN_SPEED);
        self.forward = speed / RUN_SPEED;
        let jump = takeoff < speed * DECISION_DT + self.takeoff_margin;
        if jump {
            self.takeoff_margin = self.rng.random_range(0.0..=self.takeoff_jitter);
        }
        PlatformAction {
            forward: self.forward,
            turn,
            jump,
        }
    }
}

/// Seconds from take-off until a jump comes down to `rise` metres above the take-off height
/// (the longest flight when the rise is out of reach).
fn flight_time(rise: f32) -> f32 {
    let discriminant = (JUMP_SPEED * JUMP_SPEED - 2.0 * GRAVITY * rise).max(0.0);
    (JUMP_SPEED + discriminant.sqrt()) / GRAVITY
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
