//! The static rapier3d world of a platform level: one fixed cuboid collider per block, and the
//! scene queries (shape casts of the character, downward rays of the height map) against it.

use rapier3d::control::{
    CharacterLength, EffectiveCharacterMovement, KinematicCharacterController,
};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::*;

use crate::level::platform::{BLOCK_THICKNESS, Platform, PlatformTrack};

/// The blocks of one level as rapier colliders, ready for queries.
pub struct PlatformWorld {
    bodies: RigidBodySet,
    colliders: ColliderSet,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    controller: KinematicCharacterController,
    /// The platforms as placed (0 is the start block), in f32 world units.
    platforms: Vec<PlatformBox>,
    lowest_top: f32,
}

/// A block as the simulation sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformBox {
    /// Centre of the top face.
    pub top: Vector,
    /// Heading in radians.
    pub heading: f32,
    /// Side of the top face, m.
    pub size: f32,
}

impl PlatformBox {
    fn from_platform(p: &Platform) -> Self {
        Self {
            top: Vector::new(
                p.position[0] as f32, p.position[1] as f32, p.position[2] as f32,
            ),
            heading: p.heading.to_radians() as f32,
            size: p.size as f32,
        }
    }

    /// `world` expressed in the block's frame (x along its heading, z across), relative to the
    /// centre of its top face.
    pub fn to_local(&self, world: Vector) -> Vector {
        Rotation::from_rotation_y(-self.heading) * (world - self.top)
    }

    /// Whether a horizontal point lies over the block's top, grown by `margin` on every side.
    pub fn covers(&self, world: Vector, margin: f32) -> bool {
        let local = self.to_local(world);
        let half = 0.5 * self.size + margin;
        local.x.abs() <= half && local.z.abs() <= half
    }
}

impl PlatformWorld {
    /// Builds the world of a track.
    pub fn new(track: &PlatformTrack) -> Self {
        let platforms: Vec<PlatformBox> = track
            .platforms()
            .iter()
            .map(PlatformBox::from_platform)
            .collect();
        let controller = KinematicCharacterController {
            offset: CharacterLength::Absolute(0.02),
            snap_to_ground: Some(CharacterLength::Absolute(0.1)),
            autostep: None,
            slide: true,
            ..Default::default()
        };
        let mut world = Self {
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            controller,
            platforms: Vec::with_capacity(platforms.len()),
            lowest_top: f32::INFINITY,
        };
        for block in platforms {
            world.add(block);
        }
        world
    }

    /// Adds the next platform of a growing track (the Generator's latest block).
    pub fn push(&mut self, platform: &Platform) {
        self.add(PlatformBox::from_platform(platform));
    }

    fn add(&mut self, block: PlatformBox) {
        let half_thickness = 0.5 * BLOCK_THICKNESS as f32;
        let centre = block.top - Vector::Y * half_thickness;
        let collider = ColliderBuilder::cuboid(0.5 * block.size, half_thickness, 0.5 * block.size)
            .position(Pose::from_parts(
                centre,
                Rotation::from_rotation_y(block.heading),
            ))
            .user_data(self.platforms.len() as u128)
            .build();
        let aabb = collider.compute_aabb();
        let handle = self.colliders.insert(collider);
        self.broad_phase
            .set_aabb(&IntegrationParameters::default(), handle, aabb);
        self.lowest_top = self.lowest_top.min(block.top.y);
        self.platforms.push(block);
    }

    /// The blocks, start block first.
    pub fn platforms(&self) -> &[PlatformBox] {
        &self.platforms
    }

    /// The top of the lowest block: falling well below it ends a run.
    pub fn lowest_top(&self) -> f32 {
        self.lowest_top
    }

    fn queries(&self) -> QueryPipeline<'_> {
        self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            QueryFilter::default(),
        )
    }

    /// Moves a character shape by `desired` through the blocks (rapier's kinematic character
    /// controller: it slides along walls and reports whether it ends on the ground).
    pub fn move_character(
        &self,
        dt: f32,
        shape: &dyn Shape,
        position: Vector,
        desired: Vector,
    ) -> EffectiveCharacterMovement {
        self.controller.move_shape(
            dt,
            &self.queries(),
            shape,
            &Pose::from_translation(position),
            desired,
            |_| {},
        )
    }

    /// Casts rays straight down from each origin, writing the distance to the first block hit
    /// (or `max_distance` when nothing is hit).
    pub fn cast_down(
        &self,
        origins: impl Iterator<Item = Vector>,
        max_distance: f32,
        out: &mut [f32],
    ) {
        let queries = self.queries();
        for (origin, slot) in origins.zip(out.iter_mut()) {
            let ray = Ray::new(origin, -Vector::Y);
            *slot = queries
                .cast_ray(&ray, max_distance, true)
                .map_or(max_distance, |(_, distance)| distance);
        }
    }
}
