//! The racing Generator (docs/spec.md §1.2 and §2): its observation (the goal seen from the
//! road's end, and two fans of plan-view rays that sense obstacles and the road's own earlier
//! parts ahead), its action (a segment, framed relative to the goal), and the racing game's side
//! of the Generator abstraction ([`RacingBuild`], [`GeneratorGame`] for [`RacingGame`]). The
//! Generator places the next segment when the car comes within [`REQUEST_DISTANCE`] of the
//! road's end.

use rand_chacha::ChaCha8Rng;

use super::env::{RacingEnv, RacingRewards, SIGHT};
use crate::game::generator::{
    BuildLimits, DEFAULT_CURVE_OFFSET, GeneratorGame, GeneratorRewards, Knob, Placement,
    TrackBuild, named,
};
use crate::game::{Player, RacingGame};
use crate::level::Track;
use crate::level::heading::{direction_heading, heading_direction, wrap_degrees};
use crate::level::params::{SEGMENT_CURVE, SEGMENT_HEIGHT, SEGMENT_LENGTH, quantize};
use crate::level::profile::{Abilities, SegmentRanges};
use crate::level::racing::{self, Obstacle, RacingTrack, RoadShape, SegmentParams};
use crate::level::road::Road;
use crate::level::stats::Outcome;

/// The next segment is requested when the car is this close to the road's end, m: the Solver's
/// [`SIGHT`] plus a margin. The paper requests at 15 m for a Solver that sees about that far;
/// ours sees 60 m ahead, and a Solver that saw the end of an unfinished road in every match
/// learned a policy that did not carry over to finished tracks (docs/racing-physics.md).
pub const REQUEST_DISTANCE: f64 = SIGHT + 5.0;
/// The Generator's rays: this many, spread evenly over ±[`RAY_SPREAD`] degrees around the road's
/// heading at its end...
pub const RAYS: usize = 9;
const RAY_SPREAD: f64 = 80.0;
/// ...each this long, m, tested every [`RAY_STEP`] m.
pub const RAY_LENGTH: f64 = 80.0;
const RAY_STEP: f64 = 4.0;
/// The segment budget of a Generator's track by default (goals are at most 360 m away,
/// segments 20-30 m long).
pub const DEFAULT_MAX_SEGMENTS: usize = 30;
/// Obstacles drawn into each training match's scene (some draws fall too near the start or the
/// goal and are dropped).
pub const MATCH_OBSTACLES: u32 = 3;

/// The named parts of the Generator's observation, in order, with their lengths (one aux input).
pub const GENERATOR_OBSERVATION_LAYOUT: [(&str, usize); 9] = [
    ("goal_relative_position", 3),
    ("goal_bearing_sin_cos", 2),
    ("goal_distance", 1),
    ("heading_sin_cos", 2),
    ("last_segment", 3),
    ("segments_left", 1),
    ("obstacle_rays", RAYS),
    ("road_rays", RAYS),
    ("aux", 1),
];

/// What each part of [`GENERATOR_OBSERVATION_LAYOUT`] holds, for a port of it.
pub const GENERATOR_OBSERVATION_MEANINGS: [&str; 9] = [
    "goal - the road's end in its frame (forward f = (cos H, 0, -sin H) for the end's heading H, up, left l = (f.z, 0, -f.x)) / 100 m",
    "sin, cos of atan2(left, forward) of that vector (+ left)",
    "its horizontal length / 300 m",
    "sin, cos of the end's heading H (0 along +X, + turns left)",
    "the last segment: (length - 20) / 5 - 1, curve / 30 degrees, height / 5 m (0 before the first)",
    "1 - segments placed / the piece budget",
    "9 plan-view rays from the road's end at H - 80 to H + 80 degrees (right to left) in 4 m steps: the first distance within 6 m of an obstacle's footprint / 80 m (1: none within 80 m)",
    "the same rays to the first point within 12 m of the centre line before the road's last 36 m (every third sample)",
    "λ: +1 easy, -1 hard",
];

/// The Generator's action names, in the policy's order, each a value in [-1, 1] mapped onto its
/// range of docs/spec.md §1.2. The curve is taken relative to the bearing of the goal from the
/// road's end (0 turns toward it, as far as a segment may) and the height change relative to the
/// climb that stays on course for the goal's height; the track file stores both as docs/spec.md
/// §1.2 defines them. As with the platform Generator, this lets an untrained Generator reach its
/// goal.
pub const GENERATOR_ACTIONS: [&str; 3] = [
    "length", "curve_from_goal_bearing", "height_from_goal_slope",
];

/// A policy's action row (unbounded Gaussian samples) as the next segment of `road` toward
/// `goal`: each value clipped to [-1, 1] (NaN becomes the middle) and mapped onto its range, the
/// curve the goal's bearing plus up to ±`curve_offset` degrees (then clipped to the segment's
/// ±30°), the height change added to the on-course climb; each within `ranges`.
pub fn segment_from_action(
    road: &Road,
    goal: [f64; 3],
    row: &[f32],
    curve_offset: f64,
    ranges: &SegmentRanges,
) -> SegmentParams {
    let unit = |v: f32| {
        if v.is_nan() {
            0.0
        } else {
            (v as f64).clamp(-1.0, 1.0)
        }
    };
    let (end, heading) = road.end();
    let (lengths, curves, heights) = (ranges.length(), ranges.curve(), ranges.height());
    let length = quantize(lengths.from_unit(unit(row[0])));
    let bearing = wrap_degrees(direction_heading(goal[0] - end[0], goal[2] - end[2]) - heading);
    let curve = quantize(curves.clamp(bearing + curve_offset * unit(row[1])));
    let plan = (goal[0] - end[0]).hypot(goal[2] - end[2]).max(1e-6);
    let on_course = (goal[1] - end[1]) * (length / plan).min(1.0);
    let height = quantize(heights.clamp(on_course + heights.max * unit(row[2])));
    SegmentParams {
        length,
        curve,
        height,
    }
}

/// The racing Generator's style knobs (docs/decisions.md): how sharply its road turns and how
/// much it climbs and falls, each measured by `SegmentRanges::style`.
pub const KNOBS: [Knob; 2] = [
    Knob {
        name: crate::level::racing::ROAD_KNOBS[0],
        meaning: "-1 sweeping ... +1 sharp (a segment's heading change, either way, within the profile's largest)",
    },
    Knob {
        name: crate::level::racing::ROAD_KNOBS[1],
        meaning: "-1 flat ... +1 bumpy (a segment's height change, either way, within the profile's largest)",
    },
];

/// A racing track the Generator is building toward its goal around the scene's obstacles,
/// within its segment budget.
#[derive(Debug, Clone)]
pub struct RacingBuild {
    /// The segments and obstacles so far.
    pub track: RacingTrack,
    /// The road the segments so far make.
    pub road: Road,
    /// The goal the road leads to, m.
    pub goal: [f64; 3],
    /// The segment budget: the most segments the Generator may place.
    pub max_segments: usize,
    /// See [`segment_from_action`].
    pub curve_offset: f64,
    /// Who drives the road in a match: the Solver's car has the player's abilities.
    pub player: Player,
}

impl RacingBuild {
    /// An empty road of `shape` at the origin heading `heading` degrees, among `obstacles`,
    /// with the default [`DEFAULT_CURVE_OFFSET`].
    pub fn new(
        heading: f64,
        goal: [f64; 3],
        obstacles: Vec<Obstacle>,
        max_segments: usize,
        shape: RoadShape,
    ) -> Self {
        let mut track = RacingTrack::new([0.0; 3], heading);
        track.obstacles = obstacles;
        track.road = shape;
        let road = track.road();
        Self {
            track,
            road,
            goal,
            max_segments,
            curve_offset: DEFAULT_CURVE_OFFSET,
            player: Player::default(),
        }
    }

    /// The two fans of plan-view rays from the road's end: to the first point too near an
    /// obstacle, and to the first too near an earlier part of the road (beyond the arc near its
    /// end that a new segment joins).
    fn plan_rays(&self) -> ([f32; RAYS], [f32; RAYS]) {
        let mut obstacle_rays = [0.0; RAYS];
        let obstacles = &self.track.obstacles;
        let shape = self.road.shape();
        let clearance = shape.min_obstacle_distance();
        self.rays(&mut obstacle_rays, |x, z| {
            obstacles.iter().any(|o| o.plan_distance(x, z) < clearance)
        });
        let reach = self.road.length() - shape.crossing_arc();
        let apart = shape.min_self_distance();
        let earlier: Vec<[f64; 2]> = self
            .road
            .samples()
            .iter()
            .step_by(3)
            .take_while(|p| p.s < reach)
            .map(|p| [p.centre[0], p.centre[2]])
            .collect();
        let mut road_rays = [0.0; RAYS];
        self.rays(&mut road_rays, |x, z| {
            earlier
                .iter()
                .any(|c| (c[0] - x).powi(2) + (c[1] - z).powi(2) < apart * apart)
        });
        (obstacle_rays, road_rays)
    }

    /// Distance along each ray from the road's end to the first point within `too_near` of
    /// something `near` tells the distance to, over [`RAY_LENGTH`] (1: nothing).
    fn rays(&self, out: &mut [f32], near: impl Fn(f64, f64) -> bool) {
        let (end, heading) = self.road.end();
        let steps = (RAY_LENGTH / RAY_STEP) as usize;
        for (k, slot) in out.iter_mut().enumerate() {
            let angle = heading - RAY_SPREAD + 2.0 * RAY_SPREAD * k as f64 / (RAYS - 1) as f64;
            let [dx, dz] = heading_direction(angle);
            *slot = (1..=steps)
                .map(|i| i as f64 * RAY_STEP)
                .find(|&d| near(end[0] + d * dx, end[2] + d * dz))
                .map_or(1.0, |d| (d / RAY_LENGTH) as f32);
        }
    }
}

impl RacingBuild {
    /// The segment the action `row` stands for at the road's end ([`segment_from_action`]).
    fn next_segment(&self, row: &[f32]) -> SegmentParams {
        segment_from_action(
            &self.road,
            self.goal,
            row,
            self.curve_offset,
            &self.player.segments(),
        )
    }
}

impl TrackBuild for RacingBuild {
    fn player(&self) -> &Player {
        &self.player
    }

    fn goal(&self) -> [f64; 3] {
        self.goal
    }

    fn piece_count(&self) -> usize {
        self.track.segments.len()
    }

    fn observe(&self, aux: &[f32], out: &mut [f32]) {
        let (end, heading) = self.road.end();
        let [fx, fz] = heading_direction(heading);
        let d = [
            self.goal[0] - end[0],
            self.goal[1] - end[1],
            self.goal[2] - end[2],
        ];
        // Forward along the heading, up, and left (a positive curve).
        let to_goal = [d[0] * fx + d[2] * fz, d[1], d[0] * fz - d[2] * fx];
        let distance = to_goal[0].hypot(to_goal[2]);
        let bearing = to_goal[2].atan2(to_goal[0]);
        let last = self.track.segments.last().map_or([0.0; 3], |s| {
            [
                SEGMENT_LENGTH.to_unit(s.length),
                s.curve / SEGMENT_CURVE.max,
                s.height / SEGMENT_HEIGHT.max,
            ]
        });
        let h = heading.to_radians();
        let state = to_goal
            .map(|x| x / 100.0)
            .into_iter()
            .chain([bearing.sin(), bearing.cos(), distance / 300.0])
            .chain([h.sin(), h.cos()])
            .chain(last)
            .chain([1.0 - self.track.segments.len() as f64 / self.max_segments as f64])
            .map(|x| x as f32);
        let mut written = 0;
        for (slot, value) in out.iter_mut().zip(state) {
            *slot = value;
            written += 1;
        }
        let (obstacle_out, rest) = out[written..].split_at_mut(RAYS);
        let (road_out, aux_out) = rest.split_at_mut(RAYS);
        let (obstacle_rays, road_rays) = self.plan_rays();
        obstacle_out.copy_from_slice(&obstacle_rays);
        road_out.copy_from_slice(&road_rays);
        assert_eq!(aux_out.len(), aux.len(), "one value per aux input");
        aux_out.copy_from_slice(aux);
    }

    fn port_state(&self) -> crate::game::PortState {
        let (end, heading) = self.road.end();
        let (obstacle_rays, road_rays) = self.plan_rays();
        let last = self.track.segments.last();
        vec![
            ("goal", self.goal.to_vec()),
            ("road_end", end.to_vec()),
            ("road_end_heading_degrees", vec![heading]),
            (
                "last_segment",
                last.map_or(Vec::new(), |s| vec![s.length, s.curve, s.height]),
            ),
            ("segments", vec![self.track.segments.len() as f64]),
            ("max_segments", vec![self.max_segments as f64]),
            ("obstacle_rays", obstacle_rays.map(f64::from).to_vec()),
            ("road_rays", road_rays.map(f64::from).to_vec()),
        ]
    }

    /// The player's segment ranges and the curve offset.
    fn port_piece_rules(&self) -> std::collections::BTreeMap<String, Vec<f64>> {
        let r = self.player.segments();
        named([
            ("min_length", vec![r.min_length]),
            ("max_length", vec![r.max_length]),
            ("max_curve", vec![r.max_curve]),
            ("max_height", vec![r.max_height]),
            ("curve_offset", vec![self.curve_offset]),
        ])
    }

    fn port_piece(&self, row: &[f32]) -> Option<std::collections::BTreeMap<String, f64>> {
        let segment = self.next_segment(row);
        Some(named([
            ("length", segment.length),
            ("curve", segment.curve),
            ("height", segment.height),
        ]))
    }

    fn place(&mut self, row: &[f32]) -> Placement {
        let index = self.track.segments.len();
        if index >= self.max_segments {
            return Placement::OutOfPieces;
        }
        let segment = self.next_segment(row);
        self.road.push(segment);
        self.track.segments.push(segment);
        if self.road.first_crossing(index).is_some()
            || self
                .road
                .first_obstacle_hit(&self.track.obstacles, index)
                .is_some()
        {
            return Placement::Invalid;
        }
        if racing::reaches(self.road.end().0, self.goal) {
            Placement::Completed
        } else {
            Placement::Placed
        }
    }

    fn distance_to_goal(&self, k: usize) -> f64 {
        let p = match k {
            0 => self.track.position,
            k => self.road.samples()[self.road.nearest_along(self.road.segment_start(k))].centre,
        };
        crate::level::distance(self.goal, p)
    }

    fn piece_style(&self, piece: usize, out: &mut [f32]) {
        out.copy_from_slice(&self.player.segments().style(&self.track.segments[piece]));
    }

    fn piece_features(&self) -> Vec<[f64; 2]> {
        self.track
            .segments
            .iter()
            .map(|s| [s.curve.abs(), s.height.abs()])
            .collect()
    }

    fn into_track(self) -> Track {
        Track::Racing(self.track)
    }
}

impl GeneratorGame for RacingGame {
    type Build = RacingBuild;
    const GENERATOR_OBSERVATION_LAYOUT: &'static [(&'static str, usize)] =
        &GENERATOR_OBSERVATION_LAYOUT;
    const GENERATOR_ACTIONS: &'static [&'static str] = &GENERATOR_ACTIONS;
    const DEFAULT_MAX_PIECES: usize = DEFAULT_MAX_SEGMENTS;
    const MAX_PIECES: usize = racing::MAX_SEGMENTS;
    const KNOBS: &'static [Knob] = &KNOBS;
    const PIECE_FEATURES: [&'static str; 2] = ["curve", "height"];
    const RECIPE: &'static str = include_str!("recipe.yaml");

    /// Progress pays 0.02 per metre (a racing goal is 220-360 m away, so a whole track pays
    /// about what a platform track's 30-70 m pay at 0.1, and stays below the failure term), and
    /// each step in the air 0.05 at λ = -1 (a 3 m crest at speed: about 1.4). The Solver has
    /// two retries, and a failure is paid on its segment, best at a hazard of 0.25 per segment
    /// at λ = -1 (weight 40): difficulty along the track, not a wall before the goal. Why:
    /// docs/decisions.md#d16.
    fn default_rewards() -> GeneratorRewards {
        GeneratorRewards {
            progress_per_metre: 0.02,
            air_step: 0.05,
            retries: 2,
            hazard_at_hardest: 0.25,
            piece_failure_weight: 40.0,
            ..GeneratorRewards::default()
        }
    }

    fn new_build(
        seed: u64,
        goal: Option<[f64; 3]>,
        limits: BuildLimits,
        obstacles: u32,
    ) -> (RacingBuild, ChaCha8Rng) {
        let (goal, heading, obstacles, rng) = super::rules::goal_and_start(seed, goal, obstacles);
        let road = limits.player.segments().road();
        let mut build = RacingBuild::new(heading, goal, obstacles, limits.max_pieces, road);
        build.curve_offset = limits.curve_offset;
        build.player = limits.player;
        (build, rng)
    }

    fn kept_build(
        track: &Track,
        goal: [f64; 3],
        pieces: usize,
        limits: BuildLimits,
    ) -> Result<RacingBuild, String> {
        let Track::Racing(kept) = track else {
            return Err("it is not a racing level".into());
        };
        crate::game::generator::check_kept(pieces, kept.segments.len(), limits)?;
        let mut prefix = kept.clone();
        prefix.segments.truncate(pieces);
        let build = RacingBuild {
            road: prefix.road(),
            track: prefix,
            goal,
            max_segments: limits.max_pieces,
            curve_offset: limits.curve_offset,
            player: limits.player,
        };
        if pieces > 0 && racing::reaches(build.road.end().0, goal) {
            return Err(crate::game::generator::prefix_reaches_goal(pieces));
        }
        Ok(build)
    }

    fn open_env(build: &RacingBuild, complete: bool) -> RacingEnv {
        let env = RacingEnv::open(&build.track, build.goal, RacingRewards::default(), complete);
        match build.player.abilities {
            Some(Abilities::Car(car)) => env.with_car(car.into()),
            _ => env,
        }
    }

    fn extend_env(env: &mut RacingEnv, build: &RacingBuild, complete: bool) {
        let segment = *build
            .track
            .segments
            .last()
            .expect("a placed segment is the newest");
        env.push_segment(segment, complete);
    }

    fn wants_piece(env: &RacingEnv) -> bool {
        env.outcome().is_none() && env.road_left() <= REQUEST_DISTANCE
    }

    fn furthest_piece(env: &RacingEnv) -> usize {
        if env.outcome() == Some(Outcome::Success) {
            env.road().segment_count()
        } else {
            env.segment()
        }
    }

    fn air_steps(env: &RacingEnv) -> u32 {
        env.air_steps()
    }

    fn respawn(env: &mut RacingEnv, piece: usize, seed: u64) {
        env.reset_on(piece, seed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::game::SolverEnv;
    use crate::game::generator::{Match, observation_size};
    use crate::game::racing::{OBSERVATION_SIZE, ScriptedDriver};

    #[test]
    fn a_segments_style_spans_its_ranges_either_way() {
        let ranges = SegmentRanges::default();
        let segment = |curve: f64, height: f64| SegmentParams {
            length: 20.0,
            curve,
            height,
        };
        assert_eq!(ranges.style(&segment(0.0, 0.0)), [-1.0, -1.0]);
        let sharpest = segment(-ranges.max_curve, ranges.max_height);
        assert_eq!(ranges.style(&sharpest), [1.0, 1.0]);
        let halfway = segment(0.5 * ranges.max_curve, -0.5 * ranges.max_height);
        assert_eq!(ranges.style(&halfway), [0.0, 0.0]);
    }

    #[test]
    fn a_wider_curve_offset_lets_the_road_bend_away_from_its_goal() {
        // The road's end points 40° to the right of the goal (straight ahead along +x, the goal
        // at 40° to the left).
        let road = Road::start([0.0; 3], 0.0, Default::default());
        let angle = 40f64.to_radians();
        let goal = [300.0 * angle.cos(), 0.0, -300.0 * angle.sin()];
        let away = [0.0, -1.0, 0.0];
        let default = segment_from_action(
            &road,
            goal,
            &away,
            DEFAULT_CURVE_OFFSET,
            &SegmentRanges::default(),
        );
        assert!(default.curve > 0.0, "30°: still turns toward the goal");
        let wide = segment_from_action(&road, goal, &away, 90.0, &SegmentRanges::default());
        assert_eq!(wide.curve, -30.0, "90°: turns away as far as a segment may");
        let toward = segment_from_action(&road, goal, &[0.0; 3], 90.0, &SegmentRanges::default());
        assert_eq!(toward.curve, 30.0, "0 still heads for the goal");
    }

    #[test]
    fn a_zero_action_turns_and_climbs_toward_the_goal() {
        let road = Road::start([0.0; 3], 0.0, Default::default());
        // Heading 0 runs along +x; a goal off to the left (−z) at 45°.
        let segment = segment_from_action(
            &road,
            [100.0, 10.0, -100.0],
            &[0.0; 3],
            DEFAULT_CURVE_OFFSET,
            &SegmentRanges::default(),
        );
        assert_eq!(segment.length, 25.0);
        assert_eq!(segment.curve, 30.0, "45° to the goal, clipped to the range");
        assert!(
            (segment.height - 10.0 * 25.0 / 141.42).abs() < 0.01,
            "{segment:?}"
        );
        let straight = segment_from_action(
            &road,
            [200.0, 0.0, 0.0],
            &[1.0, -1.0, f32::NAN],
            DEFAULT_CURVE_OFFSET,
            &SegmentRanges::default(),
        );
        assert_eq!(
            (straight.length, straight.curve, straight.height),
            (30.0, -30.0, 0.0)
        );
        // A profile's ranges bound every segment.
        let narrow = SegmentRanges {
            min_length: 22.0,
            max_length: 24.0,
            max_curve: 10.0,
            max_height: 1.0,
            ..SegmentRanges::default()
        };
        for row in [[1.0, -1.0, 1.0], [-1.0, 1.0, -1.0], [0.0; 3]] {
            let s = segment_from_action(&road, [100.0, 40.0, -100.0], &row, 90.0, &narrow);
            let within = [
                (narrow.length(), s.length),
                (narrow.curve(), s.curve),
                (narrow.height(), s.height),
            ];
            for (range, value) in within {
                assert!(range.check(value).is_ok(), "{s:?} outside {range}");
            }
        }
    }

    #[test]
    fn the_rays_see_an_obstacle_ahead_and_the_road_doubling_back() {
        let obstacle = Obstacle::Cylinder {
            position: [40.0, 0.0, 0.0],
            radius: 3.0,
            height: 5.0,
        };
        let build = RacingBuild::new(
            0.0,
            [300.0, 0.0, 0.0],
            vec![obstacle],
            30,
            RoadShape::default(),
        );
        let mut out = vec![0.0; observation_size::<RacingGame>()];
        build.observe(&[-1.0], &mut out);
        let rays = &out[12..12 + RAYS];
        // The middle ray runs along +x into the cylinder: blocked from 40 − 3 − 6 = 31 m on.
        assert!((rays[RAYS / 2] - 32.0 / 80.0).abs() < 1e-6, "{rays:?}");
        assert_eq!(rays[0], 1.0, "the outermost ray passes it");
        assert!(
            out[12 + RAYS..12 + 2 * RAYS].iter().all(|&r| r == 1.0),
            "no road yet"
        );
        assert_eq!(*out.last().unwrap(), -1.0, "aux last");
        // A road that has turned 270° on a circle sees its own beginning ahead, to the left.
        let mut turning = RacingBuild::new(
            0.0,
            [-300.0, 0.0, 0.0],
            Vec::new(),
            30,
            RoadShape::default(),
        );
        for _ in 0..9 {
            turning.road.push(SegmentParams {
                length: 20.0,
                curve: 30.0,
                height: 0.0,
            });
        }
        turning.observe(&[0.0], &mut out);
        assert!(
            out[12 + RAYS..12 + 2 * RAYS].iter().any(|&r| r < 1.0),
            "{:?}",
            &out[12 + RAYS..12 + 2 * RAYS]
        );
    }

    #[test]
    fn a_match_grows_the_road_ahead_of_the_car_and_ends_at_the_goal() {
        let (build, _) = RacingGame::new_build(
            11,
            Some([150.0, 0.0, 40.0]),
            BuildLimits::default_for::<RacingGame>(),
            0,
        );
        let mut game = Match::<RacingGame>::new(build, vec![1.0], 3);
        let rewards = RacingGame::default_rewards();
        let mut driver = ScriptedDriver::new(3, 0.0);
        let (mut placements, mut generator_return) = (0, 0.0);
        let mut outcome = None;
        let mut views = Vec::new();
        let mut actions = Vec::new();
        for _ in 0..20_000 {
            while game.needs_piece() {
                let placed = game.place(&[0.0; 3]);
                assert!(!placed.is_invalid(), "{placed:?}");
                placements += 1;
            }
            // Until the road reaches the goal, the Solver never sees where it ends.
            assert!(
                game.env().road_left() > SIGHT
                    || racing::reaches(game.build().road.end().0, game.build().goal),
                "the road is built beyond the Solver's sight"
            );
            let mut view = vec![0.0; OBSERVATION_SIZE];
            game.env().observe(&mut view);
            views.push(view);
            let action = driver.act(game.env());
            actions.push(action);
            let (step, reward) = game.step_solver(action, &rewards);
            generator_return += reward;
            if step.outcome.is_some() {
                outcome = step.outcome;
                break;
            }
        }
        assert_eq!(
            outcome,
            Some(Outcome::Success),
            "the scripted driver finishes"
        );
        assert!(placements >= 5, "{placements} segments for 155 m");
        assert!(racing::reaches(
            game.build().road.end().0,
            game.build().goal
        ));
        // Paid 0.02 per metre from the start to the road's end (within 12 m of the goal).
        let expected =
            0.02 * (game.build().distance_to_goal(0) - game.build().distance_to_goal(placements));
        assert!(
            (generator_return - expected as f32).abs() < 1e-3,
            "{generator_return} vs {expected}"
        );
        // The finished track plays the same way as a file.
        let level_track = game.build().clone().into_track();
        let Track::Racing(track) = level_track else {
            unreachable!()
        };
        let mut env = RacingEnv::new(&track, game.build().goal, RacingRewards::default());
        env.reset(3);
        assert_eq!(env.road().length(), game.env().road().length());
        // The same actions on the finished track make the same run: the Solver sees at every
        // step what it saw in the match, and the run ends the same way on the same step.
        let mut view = vec![0.0; OBSERVATION_SIZE];
        for (step, (seen, action)) in views.iter().zip(&actions).enumerate() {
            env.observe(&mut view);
            for (k, (a, b)) in seen.iter().zip(&view).enumerate() {
                assert!(
                    (a - b).abs() < 1e-4,
                    "step {step}, value {k}: {a} in the match, {b} on the track"
                );
            }
            let ended = env.step(*action).outcome;
            let last = step + 1 == actions.len();
            assert_eq!(ended, if last { outcome } else { None }, "step {step}");
        }
    }

    #[test]
    fn crossings_obstacles_and_running_out_of_segments_end_the_match() {
        let obstacle = Obstacle::Box {
            position: [30.0, 0.0, 0.0],
            size: [6.0, 4.0, 6.0],
            heading: 0.0,
        };
        let mut build = RacingBuild::new(
            0.0,
            [300.0, 0.0, 0.0],
            vec![obstacle],
            2,
            RoadShape::default(),
        );
        assert_eq!(
            build.place(&[0.0; 3]),
            Placement::Invalid,
            "straight into the box"
        );
        let mut short =
            RacingBuild::new(0.0, [300.0, 0.0, 0.0], Vec::new(), 2, RoadShape::default());
        assert_eq!(short.place(&[0.0; 3]), Placement::Placed);
        assert_eq!(short.place(&[0.0; 3]), Placement::Placed);
        assert_eq!(short.place(&[0.0; 3]), Placement::OutOfPieces);
        // A goal at the centre of the tightest circle stays 90° to the left: every segment
        // turns 30° left, and the road comes back onto itself.
        let mut circling =
            RacingBuild::new(0.0, [0.0, 0.0, -38.2], Vec::new(), 30, RoadShape::default());
        let placements: Vec<Placement> =
            (0..14).map(|_| circling.place(&[-1.0, 1.0, 0.0])).collect();
        assert!(placements.contains(&Placement::Invalid), "{placements:?}");
    }
}
