//! Where levels come from: the rules of either game ([`rules_level`]), or a trained Generator
//! policy ([`generator_level`]): it places piece after piece toward the goal at the chosen λ, as
//! it learned to (sampling its actions from a generator seeded by the level's seed). An attempt
//! that overlaps or crosses itself, hits an obstacle or runs out of pieces is dropped and the
//! next one, drawn from the same seeded stream, is tried; so the same policy, seed, λ and goal
//! give the same level.
//!
//! The goal and start heading are drawn from the seed exactly as the rules draw them, so a rule
//! level and a Generator level of the same seed lead to the same goal.

pub use arlpcg_core::game::NoRuleLevel;
use arlpcg_core::game::generator::{
    BuildLimits, GeneratorGame, Placement, TrackBuild, observe_build,
};
use arlpcg_core::game::{GameSpec, Player, RuleAsk};
use arlpcg_core::level::pacing::{AuxCurve, Pacing, covered, round_aux};
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::{Game, Level, PolicyRef, Source};
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};
use std::fmt;

/// λ for a level: one value for the whole level, or a curve along it (docs/designer.md,
/// pacing).
#[derive(Debug, Clone, PartialEq)]
pub enum AuxAsk {
    /// One λ for the whole level.
    Flat(f64),
    /// λ along the level.
    Curve(AuxCurve),
}

impl AuxAsk {
    /// The same ask `step` easier (λ up, clamped to 1, a curve moved up whole); none when it is
    /// already λ = 1 everywhere.
    pub fn eased(&self, step: f64) -> Option<AuxAsk> {
        match self {
            AuxAsk::Flat(aux) if *aux < 1.0 => Some(AuxAsk::Flat(round_aux((aux + step).min(1.0)))),
            AuxAsk::Curve(curve) if curve.points().iter().any(|&(_, aux)| aux < 1.0) => {
                Some(AuxAsk::Curve(curve.shifted(step)))
            }
            _ => None,
        }
    }
}

impl fmt::Display for AuxAsk {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AuxAsk::Flat(aux) => write!(f, "λ = {aux:+.2}"),
            AuxAsk::Curve(curve) => write!(f, "the curve \"{curve}\""),
        }
    }
}

/// What difficulty a designer asks for, one shape for `generate` (`--aux`, `--aux-curve`,
/// `--target-success`, which exclude each other), the designer (its slider, pacing curve or
/// success target) and its worker: a λ or a curve of λ for the Generator, or a success rate
/// that `difficulty::level_for` searches λ for.
#[derive(Debug, Clone, PartialEq)]
pub enum Ask {
    /// One λ (`--aux`).
    Aux(f64),
    /// A curve of λ along the level (`--aux-curve`).
    Curve(AuxCurve),
    /// A success rate to search λ for (`--target-success`).
    Success(f64),
}

impl Ask {
    /// The λ the Generator builds at; none when a success rate is asked for (the search
    /// chooses λ).
    pub fn aux(&self) -> Option<AuxAsk> {
        match self {
            Ask::Aux(aux) => Some(AuxAsk::Flat(*aux)),
            Ask::Curve(curve) => Some(AuxAsk::Curve(curve.clone())),
            Ask::Success(_) => None,
        }
    }

    /// The success rate asked for.
    pub fn success(&self) -> Option<f64> {
        match self {
            Ask::Success(target) => Some(*target),
            _ => None,
        }
    }

    /// The curve of λ asked for.
    pub fn curve(&self) -> Option<&AuxCurve> {
        match self {
            Ask::Curve(curve) => Some(curve),
            _ => None,
        }
    }
}

/// Which level to build: the seed its goal and the Generator's samples are drawn from, λ, and
/// what the seed would otherwise draw.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelRequest {
    /// The seed the goal and the Generator's samples are drawn from.
    pub seed: u64,
    /// λ; none for rule levels that record none (a Generator then builds at λ = 0).
    pub aux: Option<AuxAsk>,
    /// The goal; drawn from the seed when none.
    pub goal: Option<[f64; 3]>,
    /// Obstacles of a racing scene, drawn from the seed.
    pub obstacles: u32,
    /// Which valid level of the seed's stream (0: the first; `generate --verify` moves on to the
    /// next when no run completed the earlier ones).
    pub draw: u32,
    /// Pieces to keep from another level: the Generator continues after them (its start, goal
    /// and obstacles are that level's).
    pub keep: Option<KeptPrefix>,
    /// The game profile the level is made for (none: the built-in one); the level records it.
    pub profile: Option<Profile>,
    /// The value of each of the game's style knobs, in order, each in [-1, 1] (missing: 0, no
    /// preference); read by a Generator with knobs.
    pub knobs: Vec<f32>,
}

/// The first `pieces` pieces of `level`, read from the file `from` (`generate --keep`).
#[derive(Debug, Clone, PartialEq)]
pub struct KeptPrefix {
    /// The level the pieces come from.
    pub level: std::sync::Arc<Level>,
    /// How many pieces to keep.
    pub pieces: usize,
    /// The level file, pinned by its hash.
    pub from: PolicyRef,
}

impl LevelRequest {
    /// The first level of `seed` at one λ, toward the goal the seed draws, without obstacles.
    pub fn new(seed: u64, aux: Option<f64>) -> Self {
        Self {
            seed,
            aux: aux.map(AuxAsk::Flat),
            goal: None,
            obstacles: 0,
            draw: 0,
            keep: None,
            profile: None,
            knobs: Vec::new(),
        }
    }

    /// The same request toward `goal` (none: drawn from the seed).
    pub fn goal(self, goal: Option<[f64; 3]>) -> Self {
        Self { goal, ..self }
    }

    /// The same request with `obstacles` obstacles.
    pub fn obstacles(self, obstacles: u32) -> Self {
        Self { obstacles, ..self }
    }

    /// The same request for valid level `draw` of the seed's stream.
    pub fn draw(self, draw: u32) -> Self {
        Self { draw, ..self }
    }

    /// The same request continuing after `keep`'s pieces.
    pub fn keep(self, keep: KeptPrefix) -> Self {
        Self {
            keep: Some(keep),
            ..self
        }
    }

    /// Made for `profile` (none: the built-in one).
    pub fn profile(self, profile: Option<Profile>) -> Self {
        Self { profile, ..self }
    }

    /// The same request with the game's style knobs at `knobs` (in order; missing: 0).
    pub fn knobs(self, knobs: Vec<f32>) -> Self {
        Self { knobs, ..self }
    }

    /// The same request at `aux`.
    pub fn aux(self, aux: AuxAsk) -> Self {
        Self {
            aux: Some(aux),
            ..self
        }
    }

    /// The one λ of the whole level, if it has one.
    fn flat_aux(&self) -> Option<f64> {
        match self.aux {
            Some(AuxAsk::Flat(aux)) => Some(aux),
            _ => None,
        }
    }
}

/// The player of `profile` (none: the built-in one), drawing pieces from its ranges.
pub fn player_for(profile: Option<&Profile>) -> Player {
    profile.map_or_else(Player::default, |profile| {
        Player::of(Some(profile.abilities)).with_pieces(Some(profile.pieces))
    })
}

/// A rule-based level of `game` (λ is recorded, not used; the rules know no curve), made for
/// the request's profile.
pub fn rules_level(game: Game, request: &LevelRequest) -> Result<Level, NoRuleLevel> {
    let ask = RuleAsk {
        seed: request.seed,
        aux: request.flat_aux(),
        goal: request.goal,
        obstacles: request.obstacles,
        draw: request.draw,
    };
    let player = player_for(request.profile.as_ref());
    let level = arlpcg_core::for_game!(game, G => G::rule_level_draw(ask, &player))?;
    Ok(Level {
        profile: request.profile.clone(),
        ..level
    })
}

/// Attempts before giving up on a level.
pub const ATTEMPTS: usize = 64;

/// A trained Generator, ready to build levels.
pub struct GeneratorPolicy {
    /// The game it builds levels of.
    pub game: Game,
    /// The network.
    pub policy: ActorCritic,
    /// Its observation normalizer.
    pub normalizer: RunningNorm,
    /// The policy file, pinned by its hash.
    pub reference: PolicyRef,
    /// The piece budget and curve offset it was trained with.
    pub limits: BuildLimits,
    /// How many of the game's style knobs it takes (0 or all of them).
    pub knobs: usize,
}

/// Why the Generator built no level.
#[derive(Debug, thiserror::Error)]
pub enum GenerationError {
    /// No attempt built a valid level.
    #[error(
        "the Generator built no valid level toward goal {goal:?} at aux {aux_ask} in {ATTEMPTS} attempts (each overlapped or crossed itself, hit an obstacle or ran out of pieces); try another seed or goal"
    )]
    NoLevel {
        /// The goal, m.
        goal: [f64; 3],
        /// The λ asked for, in words.
        aux_ask: String,
    },
    /// The kept pieces cannot start this Generator's level.
    #[error("cannot keep that prefix: {problem}")]
    Keep {
        /// Why, in words.
        problem: String,
    },
    /// The network failed.
    #[error("the Generator's network failed: {0}")]
    Network(#[from] candle_core::Error),
}

/// A level of the Generator's game, built as `request` asks.
pub fn generator_level(
    generator: &GeneratorPolicy,
    request: &LevelRequest,
) -> Result<Level, GenerationError> {
    arlpcg_core::for_game!(generator.game, G => build_level::<G>(generator, request))
}

/// The λ piece `i` of a kept level records (only a paced level's pieces record one), so that
/// the kept piece is written exactly as it was.
fn kept_piece_aux(level: &Level, i: usize) -> Option<f64> {
    level
        .pacing
        .as_ref()
        .and_then(|pacing| pacing.piece_aux.get(i).copied().flatten())
}

/// λ for the next piece of `build`: the level's one λ, or the curve's value at the fraction of
/// the start-to-goal distance the track has covered.
fn piece_aux<B: TrackBuild>(aux_ask: Option<&AuxAsk>, build: &B) -> f64 {
    match aux_ask {
        None => 0.0,
        Some(AuxAsk::Flat(aux)) => *aux,
        Some(AuxAsk::Curve(curve)) => {
            let whole = build.distance_to_goal(0);
            let left = build.distance_to_goal(build.piece_count());
            round_aux(curve.at(covered(whole, left)))
        }
    }
}

fn build_level<G: GeneratorGame>(
    generator: &GeneratorPolicy,
    request: &LevelRequest,
) -> Result<Level, GenerationError> {
    let limits = BuildLimits {
        player: player_for(request.profile.as_ref()),
        ..generator.limits
    };
    let (empty, mut rng) = G::new_build(request.seed, request.goal, limits, request.obstacles);
    // A kept prefix replaces the seed's scene; the seed still drives the Generator's samples.
    let (empty, kept_aux) = match &request.keep {
        None => (empty, Vec::new()),
        Some(keep) => {
            let build = G::kept_build(&keep.level.track, keep.level.goal, keep.pieces, limits)
                .map_err(|problem| GenerationError::Keep { problem })?;
            let aux = (0..keep.pieces)
                .map(|i| kept_piece_aux(&keep.level, i))
                .collect();
            (build, aux)
        }
    };
    let goal = empty.goal();
    let mut skip = request.draw;
    let aux_ask = request.aux.as_ref();
    // An ability-aware Generator also observes the abilities of the profile it builds for.
    let mut observation = vec![0.0; generator.policy.shape().observation];
    let knobs: Vec<f32> = (0..generator.knobs)
        .map(|k| request.knobs.get(k).copied().unwrap_or(0.0))
        .collect();
    for _ in 0..ATTEMPTS {
        let mut build = empty.clone();
        let mut piece_auxes = kept_aux.clone();
        while build.piece_count() < generator.limits.max_pieces {
            let aux = piece_aux(aux_ask, &build);
            piece_auxes.push(Some(aux));
            observe_build::<G>(&build, &[aux as f32], &knobs, &mut observation);
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
                    let kept_pacing = request
                        .keep
                        .as_ref()
                        .is_some_and(|keep| keep.level.pacing.is_some());
                    // Pieces that record their own λ need a curve beside them: a flat λ after
                    // a kept paced prefix is the flat curve `0:λ`.
                    let curve = match aux_ask {
                        Some(AuxAsk::Curve(curve)) => Some(curve.clone()),
                        Some(AuxAsk::Flat(aux)) if kept_pacing => {
                            AuxCurve::new(vec![(0.0, *aux)]).ok()
                        }
                        _ => None,
                    };
                    let source = match &request.keep {
                        None => Source::Policy {
                            generator: generator.reference.clone(),
                        },
                        Some(keep) => Source::Kept {
                            pieces: keep.pieces as u32,
                            from: keep.from.clone(),
                            generator: generator.reference.clone(),
                        },
                    };
                    return Ok(Level {
                        seed: Some(request.seed),
                        aux: request.flat_aux().filter(|_| curve.is_none()),
                        goal,
                        track: build.into_track(),
                        source,
                        stats: None,
                        pacing: curve.map(|curve| Pacing {
                            curve,
                            piece_aux: piece_auxes,
                        }),
                        profile: request.profile.clone(),
                        knobs: G::KNOBS
                            .iter()
                            .zip(&knobs)
                            .map(|(knob, &value)| (knob.name.to_string(), f64::from(value)))
                            .collect(),
                        want: None,
                    });
                }
            }
        }
    }
    Err(GenerationError::NoLevel {
        goal,
        aux_ask: match aux_ask {
            None => "0".into(),
            Some(AuxAsk::Flat(aux)) => aux.to_string(),
            Some(AuxAsk::Curve(curve)) => format!("curve `{curve}`"),
        },
    })
}
#[cfg(test)]
mod tests {
    use super::*;
    use arlpcg_core::game::platform::generator::{GENERATOR_ACTIONS, GENERATOR_OBSERVATION_SIZE};
    use arlpcg_core::game::platform::rules::goal_and_start;
    use arlpcg_core::level::heading::heading_direction;
    use arlpcg_core::rl::policy::PolicyShape;

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
            limits: BuildLimits::default_for::<arlpcg_core::game::PlatformGame>(),
            knobs: 0,
        }
    }

    #[test]
    fn the_same_policy_seed_aux_and_goal_give_the_same_valid_level() {
        let generator = untrained();
        // A goal one block ahead of the start: even an untrained Generator gets there.
        let (_, start, _) = goal_and_start(5, None);
        let [x, z] = heading_direction(start.heading);
        let goal = [7.5 * x, 0.0, 7.5 * z];
        let a = generator_level(
            &generator,
            &LevelRequest::new(5, Some(-1.0)).goal(Some(goal)),
        )
        .unwrap();
        let b = generator_level(
            &generator,
            &LevelRequest::new(5, Some(-1.0)).goal(Some(goal)),
        )
        .unwrap();
        assert_eq!(a, b);
        a.validate().unwrap();
        assert_eq!(a.aux, Some(-1.0));
        assert!(matches!(a.source, Source::Policy { .. }));
        let other = generator_level(
            &generator,
            &LevelRequest::new(6, Some(-1.0)).goal(Some(goal)),
        )
        .unwrap();
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
        let err = generator_level(
            &generator,
            &LevelRequest::new(1, Some(0.5)).goal(Some([500.0, 0.0, 0.0])),
        )
        .unwrap_err();
        assert!(err.to_string().contains("no valid level"), "{err}");
    }

    #[test]
    fn an_eased_ask_moves_lambda_up_to_one_and_no_further() {
        assert_eq!(AuxAsk::Flat(-1.0).eased(0.25), Some(AuxAsk::Flat(-0.75)));
        assert_eq!(AuxAsk::Flat(0.9).eased(0.25), Some(AuxAsk::Flat(1.0)));
        assert_eq!(AuxAsk::Flat(1.0).eased(0.25), None);
        let curve = AuxCurve::parse("0:1, 0.5:1, 0.5:-1, 1:-1").unwrap();
        let eased = AuxAsk::Curve(curve).eased(0.25).unwrap();
        assert_eq!(
            eased.to_string(),
            "the curve \"0:1, 0.5:1, 0.5:-0.75, 1:-0.75\""
        );
        assert_eq!(
            AuxAsk::Curve(AuxCurve::parse("0:1, 1:1").unwrap()).eased(0.25),
            None
        );
    }
}
