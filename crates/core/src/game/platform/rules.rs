//! Rule-based level generation: the paper's Rule-PCG baseline, and a level source that needs no
//! trained policy. Parameters are drawn at random within the range of docs/spec.md §1.1s, under rules that keep
//! the level valid and playable: head (loosely) for the goal, never overlap an earlier block,
//! keep every jump within the character's reach, end on a block that reaches the goal.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::game::Player;
use crate::game::platform::reach::Reach;
use crate::level::heading;
use crate::level::params::quantize;
use crate::level::platform::{self, BlockParams, Platform, PlatformTrack, Start, headroom_of};
use crate::level::{Level, PlatformRulesConfig, Source, Track};

/// Goals are drawn this far from the start, horizontally, m...
pub const GOAL_DISTANCE: (f64, f64) = (30.0, 70.0);
/// ...and this far above (or below) it, m.
pub const GOAL_HEIGHT: (f64, f64) = (-6.0, 10.0);
/// Candidate blocks drawn for each placement before the attempt is abandoned.
const CANDIDATES: usize = 40;
/// Whole-level attempts before giving up (never reached in practice: levels are found within a
/// few attempts).
const ATTEMPTS: usize = 1000;

/// A goal drawn at random around the origin: any direction, `GOAL_DISTANCE` away, `GOAL_HEIGHT` up.
pub fn random_goal(rng: &mut ChaCha8Rng) -> [f64; 3] {
    let heading = rng.random_range(-180.0..180.0);
    let distance = rng.random_range(GOAL_DISTANCE.0..=GOAL_DISTANCE.1);
    let height = rng.random_range(GOAL_HEIGHT.0..=GOAL_HEIGHT.1);
    let [x, z] = heading::heading_direction(heading);
    [
        quantize(distance * x),
        quantize(height),
        quantize(distance * z),
    ]
}

/// The goal (drawn unless given) and start block of level `seed`, and the seeded stream the
/// level's other draws continue from. Every level source draws them this way, so levels of the
/// same seed lead to the same goal whoever builds them.
pub fn goal_and_start(seed: u64, goal: Option<[f64; 3]>) -> ([f64; 3], Start, ChaCha8Rng) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let drawn = random_goal(&mut rng);
    let start = Start {
        heading: quantize(rng.random_range(-180.0..180.0)),
        ..Start::default()
    };
    (goal.unwrap_or(drawn), start, rng)
}

/// Why the rules could not build a level.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the rules found no valid level toward goal {goal:?} in {ATTEMPTS} attempts of at most {max_blocks} blocks"
)]
pub struct NoLevel {
    /// The goal the rules aimed at, m.
    pub goal: [f64; 3],
    /// The most blocks a level may have.
    pub max_blocks: u32,
}

/// A rule-based platform level, reproducible from `seed`: the goal and start heading are drawn
/// from it, unless `goal` is given, every block within the player's ranges and every jump within
/// its reach. `aux` is recorded in the level; the rules do not use it.
pub fn platform_level(
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    config: &PlatformRulesConfig,
    player: &Player,
) -> Result<Level, NoLevel> {
    platform_level_draw(seed, aux, goal, config, player, 0)
}

/// Draw number `draw` of level `seed`: the `draw`-th valid level (from 0) of the seed's stream,
/// toward the same goal. Draw 0 is [`platform_level`].
pub fn platform_level_draw(
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    config: &PlatformRulesConfig,
    player: &Player,
    draw: u32,
) -> Result<Level, NoLevel> {
    let (goal, start, mut rng) = goal_and_start(seed, goal);
    let reach = Reach::of_player(player);
    let mut skip = draw;
    for _ in 0..ATTEMPTS {
        if let Some(track) = attempt(&mut rng, start, goal, config, (player, &reach)) {
            if skip > 0 {
                skip -= 1;
                continue;
            }
            return Ok(Level {
                seed: Some(seed),
                aux,
                goal,
                track: Track::Platform(track),
                source: Source::Rules { rules: *config },
                stats: None,
                pacing: None,
                profile: None,
                knobs: Default::default(),
                want: None,
            });
        }
    }
    Err(NoLevel {
        goal,
        max_blocks: config.max_blocks,
    })
}

/// One try at a whole track for a player and its reach; `None` when it gets stuck or runs out
/// of blocks.
fn attempt(
    rng: &mut ChaCha8Rng,
    start: Start,
    goal: [f64; 3],
    config: &PlatformRulesConfig,
    (player, reach): (&Player, &Reach),
) -> Option<PlatformTrack> {
    let mut track = PlatformTrack::new(start).with_headroom(headroom_of(player.abilities.as_ref()));
    while track.block_count() < config.max_blocks as usize {
        let placed = (0..CANDIDATES).any(|_| {
            let candidate = draw(rng, track.last(), goal, config, (player, reach));
            is_jumpable(track.last(), &track.preview(&candidate), config, reach)
                && track.push(candidate).is_ok()
        });
        if !placed {
            return None;
        }
        if track.last().reaches(goal) {
            return Some(track);
        }
    }
    None
}

/// Whether the jump from `from` to `to` is within the character's reach, less the margin.
fn is_jumpable(
    from: &Platform,
    to: &Platform,
    config: &PlatformRulesConfig,
    reach: &Reach,
) -> bool {
    let rise = to.position[1] - from.position[1];
    rise <= reach.max_climb() + 1e-9
        && from.edge_gap(to) <= reach.max_gap(rise) - config.reach_margin
}

/// Draws one block's parameters within the player's ranges: aimed at the goal when it is within
/// one block's distance, otherwise heading for it within the configured spread, climbing toward
/// its height.
fn draw(
    rng: &mut ChaCha8Rng,
    last: &Platform,
    goal: [f64; 3],
    config: &PlatformRulesConfig,
    (player, reach): (&Player, &Reach),
) -> BlockParams {
    let ranges = player.blocks();
    let (distances, sizes, heights) = (ranges.distance(), ranges.size(), ranges.height());
    let (dx, dz) = (goal[0] - last.position[0], goal[2] - last.position[2]);
    let horizontal = dx.hypot(dz);
    let rise = goal[1] - last.position[1];
    let to_goal = heading::direction_heading(dx, dz);
    let size = rng.random_range(sizes.min..=sizes.max);
    let finish = distances.check(horizontal).is_ok()
        && rise.abs() <= heights.max.max(-heights.min) + platform::GOAL_REACH_VERTICAL;
    let (distance, heading, height) = if finish && rng.random_bool(0.8) {
        (horizontal, to_goal, heights.clamp(rise))
    } else {
        let spread = config.angle_spread.clamp(0.0, 180.0);
        let heading = to_goal + rng.random_range(-spread..=spread);
        let blocks_left = (horizontal / 7.5).max(1.0);
        let climb = heights
            .clamp(rise / blocks_left + rng.random_range(-1.0..=1.0))
            .min(reach.max_climb());
        let longest =
            distances.clamp(reach.max_gap(climb) - config.reach_margin + 0.5 * (last.size + size));
        let distance = rng.random_range(distances.min..=longest);
        (distance, heading, climb)
    };
    let angle = heading::wrap_degrees(heading - last.heading);
    BlockParams {
        distance: distances.clamp(quantize(distance)),
        angle: ranges.turn().clamp(quantize(angle)),
        size: quantize(size),
        height: quantize(height),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::level::profile::{BlockRanges, Pieces};

    #[test]
    fn rule_levels_are_valid_reproducible_and_reach_their_goal() {
        let config = PlatformRulesConfig::default();
        for seed in 0..30 {
            let level = platform_level(seed, None, None, &config, &Player::default()).unwrap();
            level.validate().unwrap();
            let again = platform_level(seed, None, None, &config, &Player::default()).unwrap();
            assert_eq!(level, again, "seed {seed} is not reproducible");
            let track = level.platform().unwrap();
            for pair in track.platforms().windows(2) {
                assert!(
                    is_jumpable(&pair[0], &pair[1], &config, &Reach::default()),
                    "seed {seed}: a jump out of reach"
                );
            }
        }
    }

    #[test]
    fn every_parameter_stays_in_its_range_and_the_players() {
        let narrow = BlockRanges {
            min_distance: 5.5,
            max_distance: 7.0,
            min_size: 5.0,
            max_size: 5.5,
            min_height: -1.0,
            max_height: 1.0,
            max_turn: 45.0,
        };
        let narrow_player = Player::default().with_pieces(Some(Pieces::Blocks(narrow)));
        let players = [
            (Player::default(), BlockRanges::default()),
            (narrow_player, narrow),
        ];
        for seed in 0..30 {
            for (player, ranges) in &players {
                let config = PlatformRulesConfig::default();
                let level = platform_level(seed, Some(0.5), None, &config, player).unwrap();
                for b in level.platform().unwrap().block_params() {
                    BlockParams::new(b.distance, b.angle, b.size, b.height).unwrap();
                    if let Err(outside) = ranges.check_block(b) {
                        panic!("seed {seed}: {b:?}: {outside}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_goal_high_above_the_start_gets_a_climbing_track() {
        let level = platform_level(
            3,
            None,
            Some([5.0, 10.0, 0.0]),
            &PlatformRulesConfig::default(),
            &Player::default(),
        )
        .unwrap();
        let last = level.platform().unwrap().last();
        assert!(last.position[1] >= 8.0, "{last:?}");
    }
}
