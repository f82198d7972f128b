//! The platform character: a capsule moved by rapier's kinematic character controller under our
//! own velocity rules (run, turn, jump, gravity, limited air control). Its abilities come from
//! the game profile ([`crate::level::profile::CharacterProfile`]); the built-in ones are the
//! calibration described in `docs/platform-physics.md`.

use rapier3d::math::Vector;
use rapier3d::parry::shape::Capsule;

use super::world::PlatformWorld;
use crate::level::profile::CharacterProfile;

/// The character's abilities as the simulation steps with them (from a [`CharacterProfile`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Top horizontal speed, m/s.
    pub run_speed: f32,
    /// Vertical take-off speed of a jump, m/s.
    pub jump_speed: f32,
    /// Gravity, m/s².
    pub gravity: f32,
    /// Horizontal acceleration toward the commanded velocity on the ground, m/s².
    pub ground_accel: f32,
    /// Horizontal acceleration in the air (air control), m/s².
    pub air_accel: f32,
    /// Fastest turn, degrees per second.
    pub turn_rate_deg: f32,
    /// Capsule radius, m.
    pub radius: f32,
    /// Half the length of the capsule's straight part, m.
    pub half_height: f32,
}

impl From<CharacterProfile> for Body {
    fn from(p: CharacterProfile) -> Self {
        Self {
            run_speed: p.run_speed as f32,
            jump_speed: p.jump_speed as f32,
            gravity: p.gravity as f32,
            ground_accel: p.ground_accel as f32,
            air_accel: p.air_accel as f32,
            turn_rate_deg: p.turn_rate as f32,
            radius: p.radius as f32,
            half_height: (0.5 * p.height - p.radius) as f32,
        }
    }
}

impl Default for Body {
    fn default() -> Self {
        CharacterProfile::default().into()
    }
}

/// Backwards the character runs at this fraction of its run speed.
pub const BACKWARD_FACTOR: f32 = 0.5;
/// Physics steps per second.
pub const PHYSICS_HZ: f32 = 60.0;
/// Physics steps per Solver decision (decisions at 30 Hz).
pub const ACTION_REPEAT: u32 = 2;
/// Seconds between Solver decisions.
pub const DECISION_DT: f32 = ACTION_REPEAT as f32 / PHYSICS_HZ;

/// One Solver decision.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlatformAction {
    /// Run forward (1) or backward (-1), in [-1, 1].
    pub forward: f32,
    /// Turn left (1, counter-clockwise seen from above) or right (-1), in [-1, 1].
    pub turn: f32,
    /// Jump (only takes effect on the ground).
    pub jump: bool,
}

impl PlatformAction {
    /// A policy's action row `[forward, turn, jump]`: continuous parts clipped to [-1, 1] (they
    /// are unbounded Gaussian samples), jump when the binary part is 1.
    pub fn from_policy_row(row: &[f32]) -> Self {
        Self {
            forward: row[0].clamp(-1.0, 1.0),
            turn: row[1].clamp(-1.0, 1.0),
            jump: row[2] > 0.5,
        }
        .sanitized()
    }

    /// Clamps the continuous parts into [-1, 1]; NaN becomes 0.
    pub fn sanitized(self) -> Self {
        let clean = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(-1.0, 1.0) };
        Self {
            forward: clean(self.forward),
            turn: clean(self.turn),
            jump: self.jump,
        }
    }
}

/// The character's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Character {
    /// The bottom of the capsule (the feet).
    pub feet: Vector,
    /// Velocity, m/s.
    pub velocity: Vector,
    /// Facing, radians about +Y (0 along +X).
    pub yaw: f32,
    /// Whether the character is on the ground.
    pub grounded: bool,
    /// The abilities it moves with.
    pub body: Body,
}

impl Character {
    /// A character standing still at `feet`, facing `yaw` (radians).
    pub fn new(feet: Vector, yaw: f32, body: Body) -> Self {
        Self {
            feet,
            velocity: Vector::ZERO,
            yaw,
            grounded: true,
            body,
        }
    }

    /// The unit vector the character faces.
    pub fn facing(&self) -> Vector {
        Vector::new(self.yaw.cos(), 0.0, -self.yaw.sin())
    }

    fn shape(&self) -> Capsule {
        Capsule::new_y(self.body.half_height, self.body.radius)
    }

    fn centre_offset(&self) -> Vector {
        Vector::Y * (self.body.half_height + self.body.radius)
    }

    /// Advances one decision (`ACTION_REPEAT` physics steps) under `action`.
    pub fn step(&mut self, world: &PlatformWorld, action: PlatformAction) {
        let action = action.sanitized();
        let dt = 1.0 / PHYSICS_HZ;
        let shape = self.shape();
        let body = self.body;
        for substep in 0..ACTION_REPEAT {
            self.yaw += action.turn * body.turn_rate_deg.to_radians() * dt;
            let speed = if action.forward >= 0.0 {
                action.forward * body.run_speed
            } else {
                action.forward * body.run_speed * BACKWARD_FACTOR
            };
            let wanted = self.facing() * speed;
            let accel = if self.grounded {
                body.ground_accel
            } else {
                body.air_accel
            };
            let horizontal = Vector::new(self.velocity.x, 0.0, self.velocity.z);
            let change = wanted - horizontal;
            let max_change = accel * dt;
            let horizontal = if change.length() <= max_change {
                wanted
            } else {
                horizontal + change * (max_change / change.length())
            };
            let mut vertical = self.velocity.y;
            if action.jump && self.grounded && substep == 0 {
                vertical = body.jump_speed;
            }
            // On the ground, snap-to-ground holds the character down; pushing into the floor
            // as well makes rapier's controller stall now and then (it reads the floor as a wall).
            if !(self.grounded && vertical <= 0.0) {
                vertical -= body.gravity * dt;
            }
            let desired = Vector::new(horizontal.x, vertical, horizontal.z) * dt;
            let moved = world.move_character(dt, &shape, self.feet + self.centre_offset(), desired);
            self.feet += moved.translation;
            // Blocked by a wall or a ceiling: lose the velocity into it.
            let mut velocity = Vector::new(horizontal.x, vertical, horizontal.z);
            if (moved.translation.x - desired.x).abs() > 1e-4
                || (moved.translation.z - desired.z).abs() > 1e-4
            {
                velocity.x = moved.translation.x / dt;
                velocity.z = moved.translation.z / dt;
            }
            if vertical > 0.0 && moved.translation.y < desired.y - 1e-4 {
                velocity.y = 0.0;
            }
            self.grounded = moved.grounded && velocity.y <= 0.0;
            if self.grounded {
                velocity.y = 0.0;
            }
            self.velocity = velocity;
        }
    }
}
