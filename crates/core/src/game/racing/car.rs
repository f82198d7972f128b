//! The car: rapier3d's ray-cast vehicle (`DynamicRayCastVehicleController`) on a dynamic chassis
//! over the road's triangle mesh. Its abilities come from the game profile ([`Car`] from a
//! [`CarProfile`]); the built-in ones are calibrated in docs/racing-physics.md.
//!
//! A [`RacingWorld`] is rebuilt for every run from the road's shared shape (the mesh, its BVH
//! and its plan grid are built once per track), so a run depends only on the track and its actions: the same
//! inputs give a bitwise identical trajectory.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

use rapier3d::control::{DynamicRayCastVehicleController, WheelTuning};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::parry::query::RayCast;
use rapier3d::parry::shape::{TriMesh, TriMeshFlags};
use rapier3d::prelude::*;

use crate::level::profile::CarProfile;
use crate::level::racing::{Obstacle, RacingTrack};
use crate::level::road::Road;

/// Seconds per decision (one physics step).
pub const DECISION_DT: f32 = 1.0 / 30.0;
/// Gravity, m/s².
pub const GRAVITY: f32 = 9.81;
/// Half extents of the chassis box (length, height, width), m.
pub const CHASSIS_HALF: [f32; 3] = [2.0, 0.3, 0.9];
/// The centre of mass sits this far below the box's centre, m.
const COM_DROP: f32 = 0.25;
/// Wheel attachment points, chassis frame: front left, front right, rear left, rear right.
const WHEELS: [[f32; 3]; 4] = [
    [1.3, -0.2, -0.85],
    [1.3, -0.2, 0.85],
    [-1.3, -0.2, -0.85],
    [-1.3, -0.2, 0.85],
];
/// Wheel radius, m.
pub const WHEEL_RADIUS: f32 = 0.35;
/// Suspension rest length, m.
pub const SUSPENSION_REST: f32 = 0.35;

/// The car's abilities as the simulation steps with them (from a [`CarProfile`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Car {
    /// Total engine force at full throttle (rear wheels), N.
    pub engine_force: f32,
    /// Chassis mass, kg.
    pub mass: f32,
    /// Tyre friction coefficient (rapier's `friction_slip`).
    pub grip: f32,
    /// Front wheels' steering at full lock, radians.
    pub max_steer: f32,
    /// Air and rolling drag on the chassis, per second: with the engine it sets the top speed
    /// `engine_force / (mass · damping)`.
    pub damping: f32,
}

impl Car {
    /// Brake impulse cap per wheel per step at full brake, N·s (about 0.8 g on four wheels).
    pub fn brake_impulse(&self) -> f32 {
        self.mass * 0.8 * GRAVITY * DECISION_DT / 4.0
    }
}

impl From<CarProfile> for Car {
    fn from(p: CarProfile) -> Self {
        Self {
            engine_force: p.engine_force as f32,
            mass: p.mass as f32,
            grip: p.grip as f32,
            max_steer: p.max_steer as f32,
            damping: p.damping as f32,
        }
    }
}

impl Default for Car {
    fn default() -> Self {
        CarProfile::default().into()
    }
}

/// The car starts this far along the road, m, and this high above it.
pub const START_S: f64 = 5.0;
const START_LIFT: f32 = 0.25;

/// What the driver does for one decision.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CarAction {
    /// > 0: engine force (share of full throttle); < 0: brakes (share of full braking).
    pub throttle: f32,
    /// Steering, −1 full right … +1 full left.
    pub steer: f32,
}

impl CarAction {
    /// The action a policy's output row (two values in [−1, 1]) stands for.
    pub fn from_policy_row(row: &[f32]) -> Self {
        Self {
            throttle: row[0].clamp(-1.0, 1.0),
            steer: row[1].clamp(-1.0, 1.0),
        }
    }
}

/// The shapes of one track, built once and shared by every run on it.
#[derive(Clone)]
pub struct TrackShapes {
    road: SharedShape,
    /// The road's triangles by where they lie in plan, for rays cast straight down.
    plan: Arc<PlanGrid>,
    obstacles: Arc<[(Pose, SharedShape)]>,
    /// The obstacles' bounding boxes in plan (x, z), widened by [`PlanGrid::MARGIN`].
    obstacle_plans: Arc<[[f32; 4]]>,
}

impl TrackShapes {
    /// The road surface of `road` and the obstacles of `track` as rapier shapes.
    pub fn new(road: &Road, obstacles: &[Obstacle]) -> Self {
        let (road, plan) = Self::road_shape(road);
        let obstacles: Arc<[(Pose, SharedShape)]> = obstacles
            .iter()
            .map(|o| match *o {
                Obstacle::Box {
                    position,
                    size,
                    heading,
                } => (
                    Pose::from_parts(
                        Vector::new(
                            position[0] as f32,
                            (position[1] + 0.5 * size[1]) as f32,
                            position[2] as f32,
                        ),
                        Rotation::from_rotation_y(heading.to_radians() as f32),
                    ),
                    SharedShape::cuboid(
                        0.5 * size[0] as f32,
                        0.5 * size[1] as f32,
                        0.5 * size[2] as f32,
                    ),
                ),
                Obstacle::Cylinder {
                    position,
                    radius,
                    height,
                } => (
                    Pose::from_translation(Vector::new(
                        position[0] as f32,
                        (position[1] + 0.5 * height) as f32,
                        position[2] as f32,
                    )),
                    SharedShape::cylinder(0.5 * height as f32, radius as f32),
                ),
            })
            .collect();
        let margin = PlanGrid::MARGIN as f32;
        let obstacle_plans = obstacles
            .iter()
            .map(|(pose, shape)| {
                let aabb = shape.compute_aabb(pose);
                [
                    aabb.mins.x - margin,
                    aabb.mins.z - margin,
                    aabb.maxs.x + margin,
                    aabb.maxs.z + margin,
                ]
            })
            .collect();
        Self {
            road,
            plan,
            obstacles,
            obstacle_plans,
        }
    }

    /// Rebuilds the road's shape after `road` grew.
    pub fn set_road(&mut self, road: &Road) {
        (self.road, self.plan) = Self::road_shape(road);
    }

    /// The shapes of a whole track.
    pub fn of_track(track: &RacingTrack) -> Self {
        Self::new(&track.road(), &track.obstacles)
    }

    /// The road's surface as one triangle mesh, and its triangles by plan position.
    fn road_shape(road: &Road) -> (SharedShape, Arc<PlanGrid>) {
        let mesh = road.surface_mesh();
        let vertices = mesh
            .positions
            .iter()
            .map(|p| Vector::new(p[0], p[1], p[2]))
            .collect();
        let shape = SharedShape::trimesh_with_flags(
            vertices,
            mesh.triangles,
            TriMeshFlags::FIX_INTERNAL_EDGES,
        )
        .expect("a road of at least one segment is a valid triangle mesh");
        let plan = PlanGrid::new(Self::mesh(&shape));
        (shape, Arc::new(plan))
    }

    fn mesh(road: &SharedShape) -> &TriMesh {
        road.as_trimesh().expect("the road is a triangle mesh")
    }

    /// Distance down from `origin` to the road or an obstacle, up to `max`: what rapier's scene
    /// query gives for a ray straight down (the same triangles, obstacles and tests, the nearest
    /// hit), from only the triangles whose plan covers the ray's.
    fn cast_down(&self, road_pose: &Pose, origin: Vector, max: f32) -> f32 {
        let ray = Ray::new(origin, -Vector::Y);
        let local = ray.inverse_transform_by(road_pose);
        let mesh = Self::mesh(&self.road);
        let road = self
            .plan
            .under(origin)
            .iter()
            .filter_map(|&t| mesh.triangle(t).cast_local_ray(&local, max, true));
        let obstacles = self
            .obstacles
            .iter()
            .zip(self.obstacle_plans.iter())
            .filter(|(_, [x0, z0, x1, z1])| {
                (*x0..=*x1).contains(&origin.x) && (*z0..=*z1).contains(&origin.z)
            })
            .filter_map(|((pose, shape), _)| shape.cast_ray(pose, &ray, max, true));
        road.chain(obstacles).fold(max, f32::min)
    }
}

/// A triangle mesh's triangles by the square cells of the horizontal plane that their
/// footprints (a little widened) overlap: a ray straight down can only hit those of its cell.
struct PlanGrid {
    cells: HashMap<(i32, i32), Vec<u32>, BuildHasherDefault<CellHasher>>,
}

impl PlanGrid {
    /// Side of a cell, m.
    const CELL: f64 = 1.5;
    /// Footprints are widened by this much, m, far more than rounding in a hit test can reach.
    const MARGIN: f64 = 0.01;

    fn new(mesh: &TriMesh) -> Self {
        let mut cells: HashMap<_, Vec<u32>, _> = HashMap::default();
        for t in 0..mesh.num_triangles() as u32 {
            let triangle = mesh.triangle(t);
            let plan = [triangle.a, triangle.b, triangle.c].map(|v| [v.x as f64, v.z as f64]);
            let low = [0, 1].map(|k| plan.iter().map(|v| v[k]).fold(f64::INFINITY, f64::min));
            let high = [0, 1].map(|k| plan.iter().map(|v| v[k]).fold(f64::NEG_INFINITY, f64::max));
            let (x0, z0) = Self::cell(low[0] - Self::MARGIN, low[1] - Self::MARGIN);
            let (x1, z1) = Self::cell(high[0] + Self::MARGIN, high[1] + Self::MARGIN);
            for x in x0..=x1 {
                for z in z0..=z1 {
                    if Self::overlaps(plan, x, z) {
                        cells.entry((x, z)).or_default().push(t);
                    }
                }
            }
        }
        Self { cells }
    }

    fn cell(x: f64, z: f64) -> (i32, i32) {
        (
            (x / Self::CELL).floor() as i32,
            (z / Self::CELL).floor() as i32,
        )
    }

    /// Whether cell `(x, z)` widened by [`Self::MARGIN`] overlaps the triangle `plan` (in
    /// plan): no edge of it has the whole cell outside (the cell's own axes are the caller's
    /// range).
    fn overlaps(plan: [[f64; 2]; 3], x: i32, z: i32) -> bool {
        let corners = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .map(|(i, j)| [(x + i) as f64 * Self::CELL, (z + j) as f64 * Self::CELL]);
        (0..3).all(|e| {
            let [p, q, r] = [plan[e], plan[(e + 1) % 3], plan[(e + 2) % 3]];
            // The edge's normal, pointing to the triangle's side.
            let mut n = [p[1] - q[1], q[0] - p[0]];
            let side = n[0] * (r[0] - p[0]) + n[1] * (r[1] - p[1]);
            if side < 0.0 {
                n = [-n[0], -n[1]];
            }
            let reach = -Self::MARGIN * (n[0] * n[0] + n[1] * n[1]).sqrt();
            side == 0.0
                || corners
                    .iter()
                    .any(|c| n[0] * (c[0] - p[0]) + n[1] * (c[1] - p[1]) >= reach)
        })
    }

    /// The triangles a vertical ray through `p` may hit.
    fn under(&self, p: Vector) -> &[u32] {
        self.cells
            .get(&Self::cell(p.x as f64, p.z as f64))
            .map_or(&[], Vec::as_slice)
    }
}

/// Hashes a cell's two coordinates with one multiplication.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b.into());
        }
    }

    fn write_i32(&mut self, n: i32) {
        self.write_u64(n as u32 as u64);
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(29) ^ n).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

/// One run's physics: the road, the obstacles and the car.
pub struct RacingWorld {
    gravity: Vector,
    params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    vehicle: DynamicRayCastVehicleController,
    chassis: RigidBodyHandle,
    road: ColliderHandle,
    road_contacts: RoadContacts,
    shapes: TrackShapes,
    car: Car,
}

/// Leaves the chassis and the road out of collision detection while [`Self::skip`] (the
/// chassis cannot reach the road this step: [`RacingWorld::chassis_clear`]), so rapier neither
/// builds their contacts nor sweeps the chassis against the road's triangles for nothing.
struct RoadContacts {
    road: ColliderHandle,
    skip: bool,
}

impl PhysicsHooks for RoadContacts {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let road = context.collider1 == self.road || context.collider2 == self.road;
        (!(road && self.skip)).then_some(SolverFlags::COMPUTE_RIGID_IMPULSES)
    }
}

/// The chassis box's bottom face lies this far below the wheels' attachment points, m.
const BOTTOM_BELOW_WHEELS: f32 = CHASSIS_HALF[1] + WHEELS[0][1];
/// The box's corners lie beyond the wheels: a corner's height over the road is the wheels'
/// lowest less this share of their spread (linear extrapolation, along and across).
const CORNER_SPREAD: f32 = (CHASSIS_HALF[0] - WHEELS[0][0]) / (2.0 * WHEELS[0][0])
    + (CHASSIS_HALF[2] - WHEELS[1][2]) / (2.0 * WHEELS[1][2]);
/// A corner's farthest distance from the bottom face under a wheel, m (how far spin moves it).
const CORNER_LEVER: f32 = 0.71;
/// Room left for what the wheels cannot see within a step: the road curving under the box and
/// the step's accelerations, m.
const CLEARANCE_SLACK: f32 = 0.15;

impl RacingWorld {
    /// A world with `car` standing at `position` (its wheels' height), heading `heading`
    /// radians, at rest.
    pub fn new(shapes: &TrackShapes, car: Car, position: Vector, heading: f32) -> Self {
        let mass = car.mass;
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let road = colliders.insert(Self::road_collider(shapes));
        for (pose, shape) in shapes.obstacles.iter() {
            colliders.insert(ColliderBuilder::new(shape.clone()).position(*pose));
        }
        let ride = SUSPENSION_REST + WHEEL_RADIUS + 0.2 + START_LIFT;
        let chassis = bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(Pose::from_parts(
                    position + Vector::Y * ride,
                    Rotation::from_rotation_y(heading),
                ))
                .linear_damping(car.damping)
                .angular_damping(0.5)
                .can_sleep(false),
        );
        let [hx, hy, hz] = CHASSIS_HALF;
        let inertia = Vector::new(
            mass / 3.0 * (hy * hy + hz * hz),
            mass / 3.0 * (hx * hx + hz * hz),
            mass / 3.0 * (hx * hx + hy * hy),
        );
        colliders.insert_with_parent(
            ColliderBuilder::cuboid(hx, hy, hz)
                .mass_properties(MassProperties::new(
                    Vector::new(0.0, -COM_DROP, 0.0),
                    mass,
                    inertia,
                ))
                .friction(0.6)
                .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS),
            chassis,
            &mut bodies,
        );
        let mut vehicle = DynamicRayCastVehicleController::new(chassis);
        let tuning = WheelTuning {
            suspension_stiffness: 30.0,
            suspension_compression: 3.0,
            suspension_damping: 4.0,
            max_suspension_travel: 0.3,
            side_friction_stiffness: 1.0,
            friction_slip: car.grip,
            max_suspension_force: mass * GRAVITY * 2.0,
        };
        for [x, y, z] in WHEELS {
            vehicle.add_wheel(
                Vector::new(x, y, z),
                -Vector::Y,
                Vector::Z,
                SUSPENSION_REST,
                WHEEL_RADIUS,
                &tuning,
            );
        }
        let params = IntegrationParameters {
            dt: DECISION_DT,
            ..Default::default()
        };
        let mut world = Self {
            gravity: Vector::new(0.0, -GRAVITY, 0.0),
            params,
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies,
            colliders,
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
            vehicle,
            chassis,
            road,
            road_contacts: RoadContacts { road, skip: false },
            shapes: shapes.clone(),
            car,
        };
        // Queries see the colliders only after collision detection has run once.
        world.pipeline.step(
            Vector::ZERO,
            &IntegrationParameters {
                dt: 0.0,
                ..world.params
            },
            &mut world.islands,
            &mut world.broad_phase,
            &mut world.narrow_phase,
            &mut world.bodies,
            &mut world.colliders,
            &mut world.impulse_joints,
            &mut world.multibody_joints,
            &mut world.soft_bodies,
            &mut world.ccd,
            &(),
            &(),
        );
        world
    }

    fn road_collider(shapes: &TrackShapes) -> ColliderBuilder {
        ColliderBuilder::new(shapes.road.clone()).friction(1.0)
    }

    /// Swaps the road for the longer one of `shapes` (a Generator added a segment), the car
    /// where it is. The road stays one collider whose shape changes; its bounding box in the
    /// broad phase is refitted at once, so the ray fan sees the new surface before the next step.
    pub fn replace_road(&mut self, shapes: &TrackShapes) {
        self.shapes = shapes.clone();
        let road = &mut self.colliders[self.road];
        road.set_shape(shapes.road.clone());
        // The scene queries (the Solver's ray fan) see the new shape now, not after the next
        // physics step.
        let aabb = road.compute_aabb();
        self.broad_phase.set_aabb(&self.params, self.road, aabb);
    }

    /// One decision: set the controls, update the wheels, step the physics.
    pub fn step(&mut self, action: CarAction) {
        let throttle = action.throttle.clamp(-1.0, 1.0);
        let steer = action.steer.clamp(-1.0, 1.0) * self.car.max_steer;
        let engine = 0.5 * self.car.engine_force * throttle.max(0.0);
        let brake = self.car.brake_impulse() * (-throttle).max(0.0);
        for (i, wheel) in self.vehicle.wheels_mut().iter_mut().enumerate() {
            let front = i < 2;
            wheel.steering = if front { steer } else { 0.0 };
            wheel.engine_force = if front { 0.0 } else { engine };
            wheel.brake = brake;
        }
        let filter = QueryFilter::exclude_dynamic().exclude_rigid_body(self.chassis);
        let queries = self.broad_phase.as_query_pipeline_mut(
            self.narrow_phase.query_dispatcher(),
            &mut self.bodies,
            &mut self.colliders,
            filter,
        );
        self.vehicle.update_vehicle(self.params.dt, queries);
        // Rapier sweeps every fast body (CCD): only where the chassis may meet the road or an
        // obstacle this step.
        self.road_contacts.skip = self.chassis_clear();
        self.params.max_ccd_substeps =
            usize::from(!self.road_contacts.skip || self.obstacle_near());
        self.pipeline.step(
            self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd,
            &self.road_contacts,
            &(),
        );
    }

    /// Whether the chassis box stays clear of the road this step, by the wheels' ray casts just
    /// made: all four wheels on the road, and the box's lowest corner (extrapolated from its
    /// height over the road under each wheel) more than [`CLEARANCE_SLACK`] above it after
    /// moving towards it at its fastest for a step.
    fn chassis_clear(&self) -> bool {
        let body = &self.bodies[self.chassis];
        let down = body.rotation() * -Vector::Y;
        let mut low = f32::INFINITY;
        let mut high = f32::NEG_INFINITY;
        let mut closing = 0.0f32;
        for wheel in self.vehicle.wheels() {
            let info = wheel.raycast_info();
            if !info.is_in_contact || info.ground_object != Some(self.road) {
                return false;
            }
            let normal = info.contact_normal_ws;
            let bottom = info.hard_point_ws + down * BOTTOM_BELOW_WHEELS;
            let height = (bottom - info.contact_point_ws).dot(normal);
            low = low.min(height);
            high = high.max(height);
            closing = closing.max(-body.velocity_at_point(bottom).dot(normal));
        }
        let reach = (closing + body.angvel().length() * CORNER_LEVER) * self.params.dt;
        low - CORNER_SPREAD * (high - low) - reach > CLEARANCE_SLACK
    }

    /// Whether an obstacle's plan lies within the chassis's reach this step (its bounding
    /// radius, a step at its speed and half a metre).
    fn obstacle_near(&self) -> bool {
        let body = &self.bodies[self.chassis];
        let p = body.translation();
        let reach =
            Vector::from(CHASSIS_HALF).length() + body.linvel().length() * self.params.dt + 0.5;
        self.shapes.obstacle_plans.iter().any(|[x0, z0, x1, z1]| {
            p.x > x0 - reach && p.x < x1 + reach && p.z > z0 - reach && p.z < z1 + reach
        })
    }

    /// The car's abilities.
    pub fn car(&self) -> &Car {
        &self.car
    }

    fn body(&self) -> &RigidBody {
        &self.bodies[self.chassis]
    }

    /// Centre of the chassis box.
    pub fn position(&self) -> Vector {
        self.body().translation()
    }

    /// The chassis's orientation.
    pub fn rotation(&self) -> Rotation {
        *self.body().rotation()
    }

    /// The chassis's velocity, m/s.
    pub fn velocity(&self) -> Vector {
        self.body().linvel()
    }

    /// The chassis's angular velocity, radians per second.
    pub fn angular_velocity(&self) -> Vector {
        self.body().angvel()
    }

    /// Wheels whose suspension ray touches the road (or an obstacle) this step.
    pub fn wheels_in_contact(&self) -> usize {
        self.vehicle
            .wheels()
            .iter()
            .filter(|w| w.raycast_info().is_in_contact)
            .count()
    }

    /// Distance down to the first surface (road or obstacle) below each of `origins`, up to
    /// `max`.
    pub fn cast_down(&self, origins: impl Iterator<Item = Vector>, max: f32, out: &mut [f32]) {
        let road_pose = self.colliders[self.road].position();
        for (origin, slot) in origins.zip(out.iter_mut()) {
            *slot = self.shapes.cast_down(road_pose, origin, max);
        }
    }
}
