//! Where levels come from: the rules of either game ([`rules_level`]), or a trained Generator
//! policy ([`generator_level`]): it places piece after piece toward the goal at the chosen λ, as
//! it learned to (sampling its actions from a generator seeded by the level's seed). An attempt
//! that overlaps or crosses itself, hits an obstacle or runs out of pieces is dropped and the
//! next one, drawn from the same seeded stream, is tried; so the same policy, seed, λ and goal
//! give the same level.
//!
//! The goal and start heading are drawn from the seed exactly as the rules draw them, so a rule
//! level and a Generator level of the same seed lead to the same goal.

use crate::game::generator::{BuildLimits, GeneratorGame, Placement, TrackBuild, observation_size};
use crate::game::{PlatformGame, RacingGame};
use crate::level::racing::RacingRulesConfig;
use crate::level::{Game, Level, PolicyRef, RulesConfig, Source};
use crate::rl::normalizer::RunningNorm;
use crate::rl::policy::{ActMode, ActorCritic};

/// Why the rules built no level.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoRuleLevel {
    #[error(transparent)]
    Platform(#[from] crate::game::rules::NoLevel),
    #[error(transparent)]
    Racing(#[from] crate::game::racing::rules::NoTrack),
}

/// A rule-based level of `game` for `seed` (its goal drawn from the seed unless given); racing
/// tracks get `obstacles` obstacles. `aux` is recorded, not used.
pub fn rules_level(
    game: Game,
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    obstacles: u32,
) -> Result<Level, NoRuleLevel> {
    rules_level_draw(game, seed, aux, goal, obstacles, 0)
}

/// Draw number `draw` of [`rules_level`]: the next valid level of the seed's stream, toward the
/// same goal (what `generate --verify` hands out when no run completed the earlier draws).
pub fn rules_level_draw(
    game: Game,
    seed: u64,
    aux: Option<f64>,
    goal: Option<[f64; 3]>,
    obstacles: u32,
    draw: u32,
) -> Result<Level, NoRuleLevel> {
    Ok(match game {
        Game::Platform => {
            crate::game::rules::platform_level_draw(seed, aux, goal, &RulesConfig::default(), draw)?
        }
        Game::Racing => {
            let config = RacingRulesConfig {
                obstacles,
                ..RacingRulesConfig::default()
            };
            crate::game::racing::rules::racing_level_draw(seed, aux, goal, &config, draw)?
        }
    })
}

/// Attempts before giving up on a level.
pub const ATTEMPTS: usize = 64;

/// A trained Generator, ready to build levels.
pub struct GeneratorPolicy {
    /// The game it builds levels of.
    pub game: Game,
    pub policy: ActorCritic,
    pub normalizer: RunningNorm,
    pub reference: PolicyRef,
    /// The piece budget and curve offset it was trained with.
    pub limits: BuildLimits,
}

/// Why the Generator built no level.
#[derive(Debug, thiserror::Error)]
pub enum GenerationError {
    #[error(
        "the Generator built no valid level toward goal {goal:?} at aux {aux} in {ATTEMPTS} attempts (each overlapped or crossed itself, hit an obstacle or ran out of pieces); try another seed or goal"
    )]
    NoLevel { goal: [f64; 3], aux: f64 },
    #[error("the Generator's network failed: {0}")]
    Network(#[from] candle_core::Error),
}

/// A level of the Generator's game built at aux `aux` toward `goal` (drawn from `seed` when not
/// given); racing scenes get `obstacles` obstacles, drawn from the seed.
pub fn generator_level(
    generator: &GeneratorPolicy,
    seed: u64,
    aux: f64,
    goal: Option<[f64; 3]>,
    obstacles: u32,
) -> Result<Level, GenerationError> {
    generator_level_draw(generator, seed, aux, goal, obstacles, 0)
}

/// Draw number `draw` of [`generator_level`]: the `draw`-th valid level (from 0) the Generator
/// builds from the seed's stream, toward the same goal.
pub fn generator_level_draw(
    generator: &GeneratorPolicy,
    seed: u64,
    aux: f64,
    goal: Option<[f64; 3]>,
    obstacles: u32,
    draw: u32,
) -> Result<Level, GenerationError> {
    match generator.game {
        Game::Platform => build_level::<PlatformGame>(generator, seed, aux, goal, obstacles, draw),
        Game::Racing => build_level::<RacingGame>(generator, seed, aux, goal, obstacles, draw),
    }
}

fn build_level<G: GeneratorGame>(
    generator: &GeneratorPolicy,
    seed: u64,
    aux: f64,
    goal: Option<[f64; 3]>,
    obstacles: u32,
    draw: u32,
) -> Result<Level, GenerationError> {
    let (empty, mut rng) = G::new_build(seed, goal, generator.limits, obstacles);
    let goal = empty.goal();
    let mut skip = draw;
    let aux_input = [aux as f32];
    let mut observation = vec![0.0; observation_size::<G>()];
    for _ in 0..ATTEMPTS {
        let mut build = empty.clone();
        while build.piece_count() < generator.limits.max_pieces {
            build.observe(&aux_input, &mut observation);
            generator.normalizer.normalize(&mut observation);
            let action = generator
                .policy
                .choose(&observation, ActMode::Sample, &mut rng)?;
            match build.place(&action) {
                Placement::Placed => continue,
                Placement::Invalid | Placement::OutOfPieces => break,
                Placement::Completed if skip > 0 => {
                    skip -= 1;
                    break;
                }
                Placement::Completed => {
                    return Ok(Level {
                        seed: Some(seed),
                        aux: Some(aux),
                        goal,
                        track: build.into_track(),
                        source: Source::Policy {
                            generator: generator.reference.clone(),
                        },
                        stats: None,
                    });
                }
            }
        }
    }
    Err(GenerationError::NoLevel { goal, aux })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::game::platform::generator::{GENERATOR_ACTIONS, GENERATOR_OBSERVATION_SIZE};
    use crate::game::rules::goal_and_start;
    use crate::level::platform::heading_direction;
    use crate::rl::policy::PolicyShape;

    fn untrained() -> GeneratorPolicy {
        let shape = PolicyShape {
            observation: GENERATOR_OBSERVATION_SIZE,
            hidden: vec![16],
            continuous: GENERATOR_ACTIONS.len(),
            binary: 0,
        };
        GeneratorPolicy {
            game: Game::Platform,
            policy: ActorCritic::new(shape, 3).unwrap(),
            normalizer: RunningNorm::new(GENERATOR_OBSERVATION_SIZE),
            reference: PolicyRef {
                path: "generator.safetensors".into(),
                sha256: "0".repeat(64),
            },
            limits: BuildLimits::default_for::<crate::game::PlatformGame>(),
        }
    }

    #[test]
    fn the_same_policy_seed_aux_and_goal_give_the_same_valid_level() {
        let generator = untrained();
        // A goal one block ahead of the start: even an untrained Generator gets there.
        let (_, start, _) = goal_and_start(5, None);
        let [x, z] = heading_direction(start.heading);
        let goal = [7.5 * x, 0.0, 7.5 * z];
        let a = generator_level(&generator, 5, -1.0, Some(goal), 0).unwrap();
        let b = generator_level(&generator, 5, -1.0, Some(goal), 0).unwrap();
        assert_eq!(a, b);
        a.validate().unwrap();
        assert_eq!(a.aux, Some(-1.0));
        assert!(matches!(a.source, Source::Policy { .. }));
        let other = generator_level(&generator, 6, -1.0, Some(goal), 0).unwrap();
        assert_ne!(
            a.platform(),
            other.platform(),
            "another seed, another level"
        );
    }

    #[test]
    fn an_unreachable_goal_is_a_clear_error() {
        let mut generator = untrained();
        generator.limits.max_pieces = 1;
        let err = generator_level(&generator, 1, 0.5, Some([500.0, 0.0, 0.0]), 0).unwrap_err();
        assert!(err.to_string().contains("no valid level"), "{err}");
    }
}
