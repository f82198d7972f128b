//! Rule-based racing tracks (the Rule-PCG baseline for racing, and tracks that need no policy):
//! head for a goal drawn from the seed, segment by segment, never crossing the road or an
//! obstacle, with curves and height changes kept inside the car's ability by a margin
//! (docs/racing-physics.md).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::game::Player;
use crate::level::heading::{direction_heading, heading_direction, wrap_degrees};
use crate::level::params::quantize;
use crate::level::profile::SegmentRanges;
use crate::level::racing::{
    self, Obstacle, RacingRulesConfig, RacingTrack, RoadShape, SegmentParams,
};
use crate::level::road::Road;
use crate::level::{Level, Source, Track};

/// Goals are drawn this far from the start, horizontally, m...
pub const GOAL_DISTANCE: (f64, f64) = (220.0, 360.0);
/// ...within this many degrees of the start heading...
pub const GOAL_BEARING: f64 = 40.0;
/// ...and this far above (or below) it, m.
pub const GOAL_HEIGHT: (f64, f64) = (-12.0, 12.0);
/// Candidate segments drawn for each placement.
const CANDIDATES: usize = 24;
/// Whole-track attempts before giving up.
const ATTEMPTS: usize = 200;

/// Why the rules could not build a track.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the rules found no valid track toward goal {goal:?} in {ATTEMPTS} attempts of at most {max_segments} segments"
)]
pub struct NoTrack {
    /// The goal the rules aimed at, m.
    pub goal: [f64; 3],
    /// The most segments a track may have.
    pub max_segments: u32,
}

/// The goal (drawn unless given), the start heading and the obstacles of track `seed`, and the
/// seeded stream the track's other draws continue from. Every track source draws them this
/// way, so tracks of the same seed lead to the same goal around the same obstacles.
pub fn goal_and_start(
    seed: u64,
    goal: Option<[f64; 3]>,
    obstacles: u32,
) -> ([f64; 3], f64, Vec<Obstacle>, ChaCha8Rng) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let heading = quantize(rng.random_range(-180.0..180.0));
    let bearing = heading + rng.random_range(-GOAL_BEARING..=GOAL_BEARING);
    let distance = rng.random_range(GOAL_DISTANCE.0..=GOAL_DISTANCE.1);
    let [x, z] = heading_direction(bearing);
    let drawn = [
        quantize(distance * x),
        quantize(rng.random_range(GOAL_HEIGHT.0..=GOAL_HEIGHT.1)),
        quantize(distance * z),
    ];
    let goal = goal.unwrap_or(drawn);
    let placed = (0..obstacles)
        .filter_map(|_| draw_obstacle(&mut rng, goal))
        .collect();
    (goal, heading, placed, rng)
}

/// An obstacle somewhere between the start (the origin) and `goal`, clear of both.
fn draw_obstacle(rng: &mut ChaCha8Rng, goal: [f64; 3]) -> Option<Obstacle> {
    let along = rng.random_range(0.25..=0.75);
    let across = rng.random_range(-25.0..=25.0);
    let length = goal[0].hypot(goal[2]).max(1.0);
    let (ux, uz) = (goal[0] / length, goal[2] / length);
    let x = quantize(along * goal[0] - across * uz);
    let z = quantize(along * goal[2] + across * ux);
    let y = quantize(along * goal[1] - 2.0);
    let obstacle = if rng.random_bool(0.5) {
        Obstacle::Box {
            position: [x, y, z],
            size: [
                quantize(rng.random_range(4.0..=14.0)),
                quantize(rng.random_range(3.0..=10.0)),
                quantize(rng.random_range(4.0..=14.0)),
            ],
            heading: quantize(rng.random_range(-180.0..180.0)),
        }
    } else {
        Obstacle::Cylinder {
            position: [x, y, z],
            radius: quantize(rng.random_range(2.0..=7.0)),
            height: quantize(rng.random_range(3.0..=10.0)),
        }
    };
    // The built-in road's clearance and 12 m more: the scene is drawn before any profile's
    // road, and the margin covers the widest road one may ask for.
    let clear = RoadShape::default().min_obstacle_distance() + 12.0;
    let far_from = |p: [f64; 3]| obstacle.plan_distance(p[0], p[2]) > clear;
    (far_from([0.0; 3]) && far_from(goal)).then_some(obstacle)
}

/// A rule-based racing level, reproducible from `seed`: the goal, start heading and obstacles
/// are drawn from it, unless `goal` is given; each segment within the player's ranges as well
/// as the configuration's. `aux` is recorded; the rules do not use it.
pub fn racing_level(
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    config: &RacingRulesConfig,
    player: &Player,
) -> Result<Level, NoTrack> {
    racing_level_draw(seed, aux, goal, config, player, 0)
}

/// Draw number `draw` of track `seed`: the `draw`-th valid track (from 0) of the seed's
/// stream, toward the same goal around the same obstacles. Draw 0 is [`racing_level`].
pub fn racing_level_draw(
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    config: &RacingRulesConfig,
    player: &Player,
    draw: u32,
) -> Result<Level, NoTrack> {
    let (goal, heading, obstacles, mut rng) = goal_and_start(seed, goal, config.obstacles);
    let no_track = NoTrack {
        goal,
        max_segments: config.max_segments,
    };
    // A goal no road of these segments can reach fails every attempt: say so at once.
    if out_of_reach(heading, goal, config, &player.segments()) {
        return Err(no_track);
    }
    let mut skip = draw;
    for _ in 0..ATTEMPTS {
        if let Some(mut track) = attempt(
            &mut rng,
            heading,
            goal,
            &obstacles,
            config,
            &player.segments(),
        ) {
            if skip > 0 {
                skip -= 1;
                continue;
            }
            track.obstacles = obstacles;
            return Ok(Level {
                seed: Some(seed),
                aux,
                goal,
                track: Track::Racing(track),
                source: Source::RacingRules { rules: *config },
                stats: None,
                pacing: None,
                profile: None,
                knobs: Default::default(),
                want: None,
            });
        }
    }
    Err(no_track)
}

/// Whether no road from the origin at `heading` of at most `config.max_segments` segments,
/// each within `ranges` and `config`, can end within reach of `goal`, however they are drawn:
/// each segment turns the road by at most its largest curve, so the road's end lies in the cone
/// of headings within the whole turn it may make (when that is under 90°), and no farther than
/// its segments' whole length. A profile whose roads hardly turn (`max_curve: 0`) would
/// otherwise spend every attempt on goals off its straight line.
fn out_of_reach(
    heading: f64,
    goal: [f64; 3],
    config: &RacingRulesConfig,
    ranges: &SegmentRanges,
) -> bool {
    let segments = f64::from(config.max_segments);
    let distance = goal[0].hypot(goal[2]);
    let reach = racing::GOAL_REACH_HORIZONTAL;
    if distance - reach > segments * (ranges.max_length + 1e-3) {
        return true;
    }
    // The largest curve, and the half step of the quantization it may round up by.
    let turn = segments * (config.max_curve.min(ranges.max_curve) + 1e-3);
    if turn >= 90.0 {
        return false;
    }
    let off_axis = wrap_degrees(direction_heading(goal[0], goal[2]) - heading).abs();
    let outside = off_axis - turn;
    let gap = match outside {
        ..=0.0 => 0.0,
        90.0.. => distance,
        _ => distance * outside.to_radians().sin(),
    };
    gap > reach
}

/// One try at a whole track; `None` when it gets stuck or runs out of segments.
fn attempt(
    rng: &mut ChaCha8Rng,
    heading: f64,
    goal: [f64; 3],
    obstacles: &[Obstacle],
    config: &RacingRulesConfig,
    ranges: &SegmentRanges,
) -> Option<RacingTrack> {
    let mut track = RacingTrack::new([0.0; 3], heading);
    track.road = ranges.road();
    let mut road = track.road();
    while track.segments.len() < config.max_segments as usize {
        let index = track.segments.len();
        let (end, end_heading) = road.end();
        let before = plan_distance(end, goal);
        let mut best: Option<(f64, SegmentParams, Road)> = None;
        for _ in 0..CANDIDATES {
            let candidate = draw(rng, end, end_heading, goal, config, ranges);
            let mut next = road.clone();
            next.push(candidate);
            if next.first_crossing(index).is_some()
                || next.first_obstacle_hit(obstacles, index).is_some()
            {
                continue;
            }
            let (new_end, _) = next.end();
            if racing::reaches(new_end, goal) {
                best = Some((f64::NEG_INFINITY, candidate, next));
                break;
            }
            // The first candidate that closes in on the goal, else the one that gets closest.
            let after = plan_distance(new_end, goal);
            if after < before - 5.0 {
                best = Some((f64::NEG_INFINITY + 1.0, candidate, next));
                break;
            }
            if best.as_ref().is_none_or(|(score, ..)| after < *score) {
                best = Some((after, candidate, next));
            }
        }
        let (_, segment, next) = best?;
        track.segments.push(segment);
        road = next;
        if racing::reaches(road.end().0, goal) {
            return Some(track);
        }
    }
    None
}

/// Draws one segment: a curve anywhere within the configured range (leaning toward the goal
/// when far off course), climbing toward the goal's height, each within `ranges` too.
fn draw(
    rng: &mut ChaCha8Rng,
    end: [f64; 3],
    heading: f64,
    goal: [f64; 3],
    config: &RacingRulesConfig,
    ranges: &SegmentRanges,
) -> SegmentParams {
    let lengths = ranges.length();
    let length = quantize(rng.random_range(lengths.min..=lengths.max));
    let to_goal = direction_heading(goal[0] - end[0], goal[2] - end[2]);
    let error = wrap_degrees(to_goal - heading);
    let max_curve = config.max_curve.min(ranges.max_curve);
    let lean = (0.5 * error).clamp(-max_curve, max_curve);
    let curve =
        quantize((lean + rng.random_range(-max_curve..=max_curve)).clamp(-max_curve, max_curve));
    let segments_left = (plan_distance(end, goal) / 25.0).max(1.0);
    let max_height = config.max_height.min(ranges.max_height);
    let climb = (goal[1] - end[1]) / segments_left;
    let height = quantize(
        (climb + rng.random_range(-max_height..=max_height)).clamp(-max_height, max_height),
    );
    SegmentParams {
        length,
        curve,
        height,
    }
}

fn plan_distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).hypot(a[2] - b[2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::level::profile::Pieces;

    /// The early refusal never refuses a goal the rules reach, and refuses the goals a road
    /// that cannot turn misses.
    #[test]
    fn a_goal_out_of_reach_is_refused_at_once_and_only_then() {
        let config = RacingRulesConfig::default();
        let ours = Player::of(None);
        for seed in 0..12 {
            let (goal, heading, ..) = goal_and_start(seed, None, 0);
            let built = racing_level(seed, None, None, &config, &ours);
            assert!(built.is_ok(), "seed {seed}");
            assert!(!out_of_reach(heading, goal, &config, &ours.segments()));
        }
        let straight = SegmentRanges {
            max_curve: 0.0,
            ..SegmentRanges::default()
        };
        let player = Player::of(None).with_pieces(Some(Pieces::Road(straight)));
        let ahead = heading_direction(30.0);
        let on_axis = [200.0 * ahead[0], 0.0, 200.0 * ahead[1]];
        assert!(!out_of_reach(30.0, on_axis, &config, &straight));
        let aside = heading_direction(30.0 + 20.0);
        let off_axis = [200.0 * aside[0], 0.0, 200.0 * aside[1]];
        assert!(out_of_reach(30.0, off_axis, &config, &straight));
        // Most goals lie off a road that cannot turn; those on its line are still built.
        let refused: Vec<u64> = (0..12)
            .filter(|&seed| {
                let (goal, heading, ..) = goal_and_start(seed, None, 0);
                out_of_reach(heading, goal, &config, &straight)
            })
            .collect();
        assert!(refused.len() >= 6, "{refused:?}");
        let (_, heading, ..) = goal_and_start(0, None, 0);
        let [x, z] = heading_direction(heading);
        let ahead = [quantize(200.0 * x), 0.0, quantize(200.0 * z)];
        assert!(racing_level(0, None, Some(ahead), &config, &player).is_ok());
    }
}
