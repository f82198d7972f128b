//! The racing road resolved from its segments, pure math (no physics): the centre line, its
//! height profile, its banking, and the triangle meshes that physics and glTF share; and the
//! rules of the road a track must keep ([`TrackError`]: no crossing, no obstacle hit).
//!
//! - **Plan**: each segment is an arc of constant curvature (`curve / length`), so heading is
//!   continuous at every join (C1 in plan).
//! - **Height**: each segment rises by `height` along a smoothstep `3t² − 2t³`, so the slope is
//!   zero at every join (C1 in height). Two segments that rise then fall make a crest whose
//!   vertical curvature is `6·height / length²`; a car leaves the ground there once
//!   `speed² · curvature > g` (docs/racing-physics.md).
//! - **Banking**: `bank = banking · curve / length` (the track's [`RoadShape::banking`]), clipped
//!   to ±[`MAX_BANK_DEGREES`], tilted into the turn; blended linearly over [`BANK_BLEND`] m
//!   either side of a join so the surface has no step.
//! - **Width**: the track's [`RoadShape::width`]; how near the road may come to itself and to
//!   an obstacle follows from it.
//!
//! Heading `h` (degrees about +Y) points along `(cos h, 0, −sin h)`; positive curve turns left.

use super::racing::{Obstacle, RacingTrack, RoadShape, SegmentParams};

/// The steepest banking, degrees (reached at the built-in gain by the tightest curve, 30° over
/// 20 m).
pub const MAX_BANK_DEGREES: f64 = 15.0;
/// Banking changes linearly over this many metres either side of a join.
pub const BANK_BLEND: f64 = 6.0;
/// Distance between cross-sections of the mesh along the centre line, at most, m.
pub const SAMPLE_SPACING: f64 = 1.0;
/// How far the skirts along the road's edges hang below it (glTF only), m.
pub const SKIRT_DEPTH: f64 = 0.8;

/// One cross-section of the road.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadSample {
    /// Distance along the centre line from the start, m.
    pub s: f64,
    /// The segment this sample lies in.
    pub segment: usize,
    /// The point on the centre line, m.
    pub centre: [f64; 3],
    /// Heading, radians.
    pub heading: f64,
    /// Height gained per metre along the road.
    pub slope: f64,
    /// Bank angle, radians (positive: the left edge is lower).
    pub bank: f64,
}

impl RoadSample {
    /// Unit vector along the road (with its slope).
    pub fn forward(&self) -> [f64; 3] {
        let (s, c) = self.heading.sin_cos();
        normalize([c, self.slope, -s])
    }

    /// Unit vector across the road to the left, tilted by the banking.
    pub fn left(&self) -> [f64; 3] {
        let (s, c) = self.heading.sin_cos();
        let (sb, cb) = self.bank.sin_cos();
        [-s * cb, -sb, -c * cb]
    }

    /// Unit normal of the surface (up, for a road that is not upside down).
    pub fn up(&self) -> [f64; 3] {
        normalize(cross(self.forward(), self.left()))
    }

    /// A point `lateral` metres to the left of the centre line (negative: right).
    pub fn across(&self, lateral: f64) -> [f64; 3] {
        let l = self.left();
        [0, 1, 2].map(|k| self.centre[k] + lateral * l[k])
    }
}

/// The road of a track, sampled along its centre line.
#[derive(Debug, Clone, PartialEq)]
pub struct Road {
    shape: RoadShape,
    samples: Vec<RoadSample>,
    /// Where each segment starts along the road, m; one more entry: the road's length.
    starts: Vec<f64>,
    /// Bank of each segment away from its joins, radians.
    banks: Vec<f64>,
    /// Pose at the end of the road: position, heading (radians).
    end: ([f64; 3], f64),
}

/// A rule of the road broken by a track.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackError {
    /// Two segments' centre lines come too close.
    #[error(
        "segment {later} crosses segment {earlier}: the road's centre lines come {distance:.1} m apart, less than {min} m"
    )]
    Crosses {
        /// The earlier segment's index.
        earlier: usize,
        /// The later segment's index.
        later: usize,
        /// How close their centre lines come, m.
        distance: f64,
        /// The least distance allowed (the road's width + 3 m).
        min: f64,
    },
    /// A segment's centre line passes too close to an obstacle.
    #[error(
        "segment {segment} runs into obstacle {obstacle}: its centre line passes {distance:.1} m from it, less than {min} m"
    )]
    HitsObstacle {
        /// The segment's index.
        segment: usize,
        /// The obstacle's index.
        obstacle: usize,
        /// How close the centre line passes, m.
        distance: f64,
        /// The least distance allowed (half the road's width + 1.5 m).
        min: f64,
    },
}

impl RacingTrack {
    /// The resolved road: centre line, banking and edges.
    pub fn road(&self) -> Road {
        Road::new(self)
    }

    /// Checks that the road never crosses itself or an obstacle.
    pub fn check_geometry(&self) -> Result<(), TrackError> {
        let road = self.road();
        if let Some(e) = road.first_crossing(0) {
            return Err(e);
        }
        road.first_obstacle_hit(&self.obstacles, 0)
            .map_or(Ok(()), Err)
    }
}

impl Road {
    /// The road of `track`'s segments.
    pub fn new(track: &RacingTrack) -> Self {
        let mut road = Self::start(track.position, track.heading, track.road);
        for segment in &track.segments {
            road.push(*segment);
        }
        road
    }

    /// A road of `shape` with no segments yet, starting at `position`, heading `heading`
    /// degrees.
    pub fn start(position: [f64; 3], heading: f64, shape: RoadShape) -> Self {
        Self {
            shape,
            samples: Vec::new(),
            starts: vec![0.0],
            banks: Vec::new(),
            end: (position, heading.to_radians()),
        }
    }

    /// Appends a segment. Banking near the previous join is re-blended, so the samples of the
    /// previous segment's last [`BANK_BLEND`] metres change.
    pub fn push(&mut self, params: SegmentParams) {
        let index = self.banks.len();
        let (origin, heading) = self.end;
        let length = params.length;
        let curvature = params.curve.to_radians() / length;
        let bank = (self.shape.banking * params.curve / length)
            .clamp(-MAX_BANK_DEGREES, MAX_BANK_DEGREES)
            .to_radians();
        self.banks.push(bank);
        let start_s = *self.starts.last().expect("starts is never empty");
        self.starts.push(start_s + length);
        // The previous segment's final sample (s = its length) is this one's first.
        if index > 0 {
            self.samples.pop();
        }
        let steps = (length / SAMPLE_SPACING).ceil() as usize;
        for k in 0..=steps {
            let s = length * k as f64 / steps as f64;
            let (centre, h, slope) = along(origin, heading, curvature, params.height, length, s);
            self.samples.push(RoadSample {
                s: start_s + s,
                segment: index,
                centre,
                heading: h,
                slope,
                bank: 0.0,
            });
        }
        let (end, end_heading, _) =
            along(origin, heading, curvature, params.height, length, length);
        self.end = (end, end_heading);
        // Re-bank everything the new join can reach.
        let from = start_s - BANK_BLEND;
        for i in (0..self.samples.len()).rev() {
            if self.samples[i].s < from {
                break;
            }
            self.samples[i].bank = self.bank_at(self.samples[i].s);
        }
    }

    /// Bank at distance `s` along the road, radians.
    fn bank_at(&self, s: f64) -> f64 {
        let segment = self.segment_at(s);
        let own = self.banks[segment];
        let start = self.starts[segment];
        let end = self.starts[segment + 1];
        if segment > 0 && s - start < BANK_BLEND {
            let t = (s - start + BANK_BLEND) / (2.0 * BANK_BLEND);
            return self.banks[segment - 1] + t * (own - self.banks[segment - 1]);
        }
        if segment + 1 < self.banks.len() && end - s < BANK_BLEND {
            let t = (s - end + BANK_BLEND) / (2.0 * BANK_BLEND);
            return own + t * (self.banks[segment + 1] - own);
        }
        own
    }

    /// The segment at distance `s` along the road (clamped to the first and last).
    pub fn segment_at(&self, s: f64) -> usize {
        let count = self.banks.len();
        match self.starts[1..].iter().position(|&end| s < end) {
            Some(i) => i,
            None => count.saturating_sub(1),
        }
    }

    /// The road's cross-sections, from the start.
    pub fn samples(&self) -> &[RoadSample] {
        &self.samples
    }

    /// How many segments the road has.
    pub fn segment_count(&self) -> usize {
        self.banks.len()
    }

    /// Length of the centre line, m.
    pub fn length(&self) -> f64 {
        *self.starts.last().expect("starts is never empty")
    }

    /// Where segment `i` starts along the road, m.
    pub fn segment_start(&self, i: usize) -> f64 {
        self.starts[i]
    }

    /// The end of the centre line and the heading there (degrees).
    pub fn end(&self) -> ([f64; 3], f64) {
        (self.end.0, self.end.1.to_degrees())
    }

    /// How wide the road is and how it banks.
    pub fn shape(&self) -> RoadShape {
        self.shape
    }

    /// The first crossing that involves a segment numbered `from` or later: a point of it
    /// comes too near a part of the road that is more than [`RoadShape::crossing_arc`] away
    /// along it.
    pub fn first_crossing(&self, from: usize) -> Option<TrackError> {
        let (arc, min) = (self.shape.crossing_arc(), self.shape.min_self_distance());
        let first_new = self.samples.iter().position(|p| p.segment >= from)?;
        for (j, later) in self.samples.iter().enumerate().skip(first_new) {
            for earlier in &self.samples[..j] {
                if later.s - earlier.s <= arc {
                    break;
                }
                let (dx, dz) = (
                    later.centre[0] - earlier.centre[0],
                    later.centre[2] - earlier.centre[2],
                );
                let squared = dx * dx + dz * dz;
                if squared < min * min {
                    return Some(TrackError::Crosses {
                        earlier: earlier.segment,
                        later: later.segment,
                        distance: squared.sqrt(),
                        min,
                    });
                }
            }
        }
        None
    }

    /// The first obstacle that a segment numbered `from` or later comes too near.
    pub fn first_obstacle_hit(&self, obstacles: &[Obstacle], from: usize) -> Option<TrackError> {
        let min = self.shape.min_obstacle_distance();
        self.samples
            .iter()
            .filter(|p| p.segment >= from)
            .find_map(|p| {
                obstacles.iter().enumerate().find_map(|(k, o)| {
                    let distance = o.plan_distance(p.centre[0], p.centre[2]);
                    (distance < min).then_some(TrackError::HitsObstacle {
                        segment: p.segment,
                        obstacle: k,
                        distance,
                        min,
                    })
                })
            })
    }

    /// The sample nearest to `point` horizontally, searching `window` samples either side of
    /// `hint` (a car moves a few samples per step; the whole road when `hint` is `None`).
    pub fn nearest(&self, point: [f64; 3], hint: Option<usize>, window: usize) -> usize {
        let (lo, hi) = match hint {
            Some(h) => (
                h.saturating_sub(window),
                (h + window + 1).min(self.samples.len()),
            ),
            None => (0, self.samples.len()),
        };
        let mut best = lo;
        let mut best_d = f64::INFINITY;
        for i in lo..hi {
            let c = self.samples[i].centre;
            let d = (c[0] - point[0]).powi(2) + (c[2] - point[2]).powi(2);
            if d < best_d {
                best_d = d;
                best = i;
            }
        }
        best
    }

    /// The sample nearest to distance `s` along the road (clamped to its ends).
    pub fn nearest_along(&self, s: f64) -> usize {
        let after = self.samples.partition_point(|p| p.s < s);
        match after {
            0 => 0,
            i if i == self.samples.len() => i - 1,
            i if s - self.samples[i - 1].s < self.samples[i].s - s => i - 1,
            i => i,
        }
    }

    /// The road's top surface as a triangle mesh: two vertices per cross-section, triangles
    /// counter-clockwise seen from above (their normals face up). UV: u across (0 left edge,
    /// 1 right edge), v along the road in road widths.
    pub fn surface_mesh(&self) -> TriangleMesh {
        self.surface_between(0, self.samples.len() - 1)
    }

    /// The cross-sections of segment `i`, as an inclusive range of sample indices (the last is
    /// the next segment's first, so the pieces join without a gap).
    pub fn segment_samples(&self, i: usize) -> (usize, usize) {
        let first = self.samples.partition_point(|p| p.segment < i);
        let last = self.samples.partition_point(|p| p.segment <= i);
        (first, last.min(self.samples.len() - 1))
    }

    /// The top surface between cross-sections `first` and `last` (inclusive).
    pub fn surface_between(&self, first: usize, last: usize) -> TriangleMesh {
        let mut mesh = TriangleMesh::default();
        let width = self.shape.width;
        for p in &self.samples[first..=last] {
            let up = p.up().map(|c| c as f32);
            let v = (p.s / width) as f32;
            mesh.vertex(p.across(0.5 * width), up, [0.0, v]);
            mesh.vertex(p.across(-0.5 * width), up, [1.0, v]);
        }
        mesh.strip(0, last - first + 1, 0, 1);
        mesh
    }

    /// The skirts that hang from both edges between cross-sections `first` and `last`
    /// (inclusive): what a player sees as the road's thickness, normals facing outward.
    pub fn skirts_between(&self, first: usize, last: usize) -> TriangleMesh {
        let mut mesh = TriangleMesh::default();
        let rows = last - first + 1;
        let width = self.shape.width;
        for side in [1.0, -1.0] {
            let base = mesh.positions.len() as u32;
            for p in &self.samples[first..=last] {
                let outward = p.left().map(|c| (side * c) as f32);
                let top = p.across(side * 0.5 * width);
                let bottom = [top[0], top[1] - SKIRT_DEPTH, top[2]];
                let v = (p.s / width) as f32;
                mesh.vertex(top, outward, [0.0, v]);
                mesh.vertex(bottom, outward, [1.0, v]);
            }
            // Left skirt: seen from the left, bottom → top → next top runs counter-clockwise;
            // the right skirt is its mirror image.
            if side > 0.0 {
                mesh.strip(base, rows, 1, 0);
            } else {
                mesh.strip(base, rows, 0, 1);
            }
        }
        mesh
    }
}

/// An indexed triangle mesh, in f32 as glTF and rapier store it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions, m.
    pub positions: Vec<[f32; 3]>,
    /// Vertex normals, unit length.
    pub normals: Vec<[f32; 3]>,
    /// Vertex texture coordinates.
    pub uvs: Vec<[f32; 2]>,
    /// Triangles, as three indices into the vertices.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Adds a vertex.
    pub fn vertex(&mut self, position: [f64; 3], normal: [f32; 3], uv: [f32; 2]) {
        self.positions.push(position.map(|c| c as f32));
        self.normals.push(normal);
        self.uvs.push(uv);
    }

    /// Two triangles between each pair of consecutive rows of two vertices (`base + 2·row`
    /// and `+1`), wound so that `a → b → next b` is counter-clockwise.
    pub fn strip(&mut self, base: u32, rows: usize, a: u32, b: u32) {
        for row in 0..rows.saturating_sub(1) as u32 {
            let this = base + 2 * row;
            let next = this + 2;
            self.triangles.push([this + a, this + b, next + b]);
            self.triangles.push([this + a, next + b, next + a]);
        }
    }

    /// The geometric normal of triangle `t` (unit length).
    pub fn face_normal(&self, t: usize) -> [f64; 3] {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize].map(f64::from));
        normalize(cross(sub(b, a), sub(c, a)))
    }
}

/// Position, heading and slope at `s` along a segment that starts at `origin` with `heading`.
fn along(
    origin: [f64; 3],
    heading: f64,
    curvature: f64,
    rise: f64,
    length: f64,
    s: f64,
) -> ([f64; 3], f64, f64) {
    let h = heading + curvature * s;
    let (dx, dz) = if curvature.abs() < 1e-12 {
        (s * heading.cos(), -s * heading.sin())
    } else {
        (
            (h.sin() - heading.sin()) / curvature,
            (h.cos() - heading.cos()) / curvature,
        )
    };
    let t = s / length;
    let y = rise * t * t * (3.0 - 2.0 * t);
    let slope = rise * 6.0 * t * (1.0 - t) / length;
    ([origin[0] + dx, origin[1] + y, origin[2] + dz], h, slope)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(segments: &[(f64, f64, f64)]) -> RacingTrack {
        let mut t = RacingTrack::new([0.0; 3], 0.0);
        t.segments = segments
            .iter()
            .map(|&(l, c, h)| SegmentParams::new(l, c, h).unwrap())
            .collect();
        t
    }

    #[test]
    fn a_straight_runs_along_x_and_a_left_curve_turns_to_minus_z() {
        let road = track(&[(20.0, 0.0, 0.0)]).road();
        let (end, heading) = road.end();
        assert!(
            (end[0] - 20.0).abs() < 1e-9 && end[2].abs() < 1e-9,
            "{end:?}"
        );
        assert_eq!(heading, 0.0);
        let road = track(&[(30.0, 30.0, 0.0)]).road();
        let (end, heading) = road.end();
        assert!((heading - 30.0).abs() < 1e-9);
        assert!(end[2] < -5.0, "a left turn heads to -z: {end:?}");
        // Arc length: the chord of a 30-degree arc of 30 m.
        let radius = 30.0 / 30f64.to_radians();
        let chord = 2.0 * radius * 15f64.to_radians().sin();
        assert!((end[0].hypot(end[2]) - chord).abs() < 1e-9);
    }

    #[test]
    fn joins_are_c1_heading_height_slope_and_banking_are_continuous() {
        let road = track(&[(25.0, 30.0, 5.0), (20.0, -30.0, -5.0), (30.0, 10.0, 2.0)]).road();
        for pair in road.samples().windows(2) {
            let [a, b] = pair else { unreachable!() };
            let ds = b.s - a.s;
            assert!(ds > 0.0 && ds <= SAMPLE_SPACING + 1e-9);
            assert!((b.heading - a.heading).abs() < 0.03 * ds, "{a:?} {b:?}");
            assert!((b.slope - a.slope).abs() < 0.1 * ds, "{a:?} {b:?}");
            let steepest_blend = MAX_BANK_DEGREES.to_radians() / BANK_BLEND;
            assert!(
                (b.bank - a.bank).abs() <= steepest_blend * ds + 1e-9,
                "{a:?} {b:?}"
            );
            let rise = b.centre[1] - a.centre[1];
            assert!((rise - 0.5 * (a.slope + b.slope) * ds).abs() < 0.01);
        }
        // A left turn banks into the turn: the left edge is lower.
        let mid = road.samples()[12];
        assert!(mid.bank > 0.0 && mid.across(4.0)[1] < mid.across(-4.0)[1]);
        let steepest = road
            .samples()
            .iter()
            .map(|p| p.bank.abs())
            .fold(0.0, f64::max);
        assert!((steepest.to_degrees() - MAX_BANK_DEGREES).abs() < 1e-9);
    }

    #[test]
    fn surface_triangles_face_up_and_skirts_face_out() {
        let road = track(&[(25.0, 30.0, 5.0), (20.0, -30.0, -5.0)]).road();
        let surface = road.surface_mesh();
        assert_eq!(surface.positions.len(), 2 * road.samples().len());
        for t in 0..surface.triangles.len() {
            let n = surface.face_normal(t);
            // Steepest: a 20-degree slope (5 m over 20 m) on a 15-degree bank.
            assert!(n[1] > 0.85, "triangle {t} faces {n:?}");
        }
        let skirts = road.skirts_between(0, road.samples().len() - 1);
        for t in 0..skirts.triangles.len() {
            let n = skirts.face_normal(t);
            let vertex = skirts.triangles[t][0] as usize;
            let stored = skirts.normals[vertex].map(f64::from);
            let agree = n[0] * stored[0] + n[1] * stored[1] + n[2] * stored[2];
            assert!(
                agree > 0.9,
                "skirt triangle {t}: winding {n:?}, normal {stored:?}"
            );
        }
    }

    #[test]
    fn a_road_that_loops_back_crosses_itself_and_one_that_passes_an_obstacle_hits_it() {
        let looping = track(&[(30.0, 30.0, 0.0); 13]);
        let err = looping.check_geometry().unwrap_err();
        assert!(matches!(err, TrackError::Crosses { .. }), "{err}");
        let straight = track(&[(30.0, 0.0, 0.0); 3]);
        straight.check_geometry().unwrap();
        let mut blocked = straight.clone();
        blocked.obstacles.push(Obstacle::Cylinder {
            position: [45.0, 0.0, 3.0],
            radius: 1.0,
            height: 5.0,
        });
        let err = blocked.check_geometry().unwrap_err();
        assert!(
            matches!(
                err,
                TrackError::HitsObstacle {
                    segment: 1,
                    obstacle: 0,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn nearest_finds_the_closest_cross_section() {
        let road = track(&[(30.0, 20.0, 0.0), (30.0, -20.0, 0.0)]).road();
        let p = road.samples()[40];
        let probe = p.across(2.0);
        assert_eq!(road.nearest(probe, None, 0), 40);
        assert_eq!(road.nearest(probe, Some(35), 8), 40);
    }
}
