//! A verified level for a request, made in one place for `generate`, campaigns and the designer:
//! drawn from a [`LevelSource`] (the rules or a Generator) as a [`LevelRequest`] asks, then
//! proved as a [`Proof`] says: left unplayed, played with a draw that no run completes replaced
//! (and λ eased after [`Redraw::max_draws`] such draws), searched to a success rate, or
//! searched over λ and draws until it meets a wish list ([`wanted`]). A level that was played
//! carries its certificate: a recorded run that reaches the goal.

pub mod wanted;

use crate::services::difficulty::{self, Curve};
use crate::services::generation::{self, GenerationError, GeneratorPolicy, LevelRequest};
use crate::services::verify::{self, Solver, Watch};
use crate::services::wish::Constraint;
use arlpcg_core::level::{Game, Level};

/// Where levels come from.
#[derive(Clone, Copy)]
pub enum LevelSource<'a> {
    /// The rule-based levels of a game.
    Rules(Game),
    /// A trained Generator.
    Generator(&'a GeneratorPolicy),
}

impl LevelSource<'_> {
    /// The game it makes levels of.
    pub fn game(&self) -> Game {
        match self {
            LevelSource::Rules(game) => *game,
            LevelSource::Generator(generator) => generator.game,
        }
    }

    /// The level `request` names: its seed's draw, at its λ or curve, toward its goal, with its
    /// obstacles, kept prefix and profile.
    pub fn level(&self, request: &LevelRequest) -> anyhow::Result<Level> {
        Ok(match self {
            LevelSource::Rules(game) => generation::rules_level(*game, request)?,
            LevelSource::Generator(generator) => generation::generator_level(generator, request)?,
        })
    }
}

/// What happens to a draw that no run completed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Redraw {
    /// Draws of one seed tried at one λ before λ is eased.
    pub max_draws: u32,
    /// How much easier (λ up) the seed is asked again after `max_draws` draws no run completed:
    /// a batch keeps every seed, each level recording the λ it was built at.
    pub ease_step: f64,
    /// Keep the first draw even when no run completed it.
    pub keep_unsolved: bool,
}

impl Default for Redraw {
    fn default() -> Self {
        Self {
            max_draws: 10,
            ease_step: 0.25,
            keep_unsolved: false,
        }
    }
}

/// How a level is proved before it is kept.
pub enum Proof<'a> {
    /// Not played: the level as drawn.
    Unplayed,
    /// Played `trials` times (runs seeded from the level's seed); a draw that no run completes
    /// is replaced as `redraw` says.
    Played {
        /// Who plays.
        solver: &'a Solver<'a>,
        /// Runs per draw.
        trials: u32,
        /// What happens to a draw that no run completed.
        redraw: Redraw,
    },
    /// Searched until its success for `solver` over `trials` runs lies within
    /// [`difficulty::BAND`] of `target`, from the λ `curve` gives for it
    /// ([`difficulty::level_for`]); needs a Generator.
    Target {
        /// Whose success is searched for.
        solver: &'a Solver<'a>,
        /// The Generator's λ→success curve for that Solver.
        curve: &'a Curve,
        /// The success asked for.
        target: f64,
        /// Runs per candidate.
        trials: u32,
        /// Constraints a candidate's pieces must meet before it is played (a campaign's or
        /// `generate`'s checks; those reading runs are checked afterwards).
        checks: &'a [Constraint],
    },
    /// Searched over λ (or curves of λ) and draws until it meets every constraint of a wish
    /// list ([`wanted::Search`]); played where the wish list reads runs or `solver` is given.
    Wanted(wanted::Search<'a>),
}

/// The level `request` asks of `source`, proved as `proof` says, with its certificate where it
/// was played. `Ok(None)` when `watch.stop` cut the plays short. `eased` hears each λ eased,
/// with its reason, before the seed is drawn again.
pub fn verified_level(
    source: LevelSource,
    request: &LevelRequest,
    proof: &Proof,
    watch: &Watch,
    eased: &dyn Fn(&str),
) -> anyhow::Result<Option<Level>> {
    let seed = request.seed;
    match *proof {
        Proof::Unplayed => source.level(request).map(Some),
        Proof::Target {
            solver,
            curve,
            target,
            trials,
            checks,
        } => {
            let LevelSource::Generator(generator) = source else {
                anyhow::bail!("a success target needs a Generator: the rules know no λ");
            };
            let level = match difficulty::level_for(
                generator,
                solver,
                curve,
                request,
                (target, trials),
                checks,
                watch.stop,
            ) {
                Err(difficulty::TargetError::SearchStopped) => return Ok(None),
                searched => searched?,
            };
            Ok(Some(verify::certified(level, solver, seed)?))
        }
        Proof::Played {
            solver,
            trials,
            redraw,
        } => played_level(source, request, (solver, trials, redraw), watch, eased),
        Proof::Wanted(ref search) => search.level(source, request, watch),
    }
}

/// Whether `error` says a Generator built no valid level (which a lower λ may build); rule
/// levels fail with another error.
fn built_nothing(error: &anyhow::Error) -> bool {
    matches!(
        error.downcast_ref::<GenerationError>(),
        Some(GenerationError::NoLevel { .. })
    )
}

/// Whether `source` builds the seed's first draw of `request` at its λ or at a lower one (λ
/// eased by `step`, up to λ = 1), as [`Proof::Played`] eases it; the error of the last λ tried
/// when it builds none (rule levels have no λ to ease). `generate --verify` checks every seed
/// of a batch with it before any level is played.
pub fn buildable(source: LevelSource, request: &LevelRequest, step: f64) -> anyhow::Result<()> {
    let mut request = LevelRequest {
        draw: 0,
        ..request.clone()
    };
    loop {
        match source.level(&request) {
            Err(e) if built_nothing(&e) => {
                match request.aux.as_ref().and_then(|asked| asked.eased(step)) {
                    Some(easier) => request.aux = Some(easier),
                    None => return Err(e),
                }
            }
            built => return built.map(drop),
        }
    }
}

/// [`Proof::Played`]: each draw of the seed played in turn until one is completed by a run;
/// after `redraw.max_draws` of them, or when the Generator builds no further valid level, a
/// Generator's λ is eased by `redraw.ease_step`, and so on up to λ = 1.
fn played_level(
    source: LevelSource,
    request: &LevelRequest,
    (solver, trials, redraw): (&Solver, u32, Redraw),
    watch: &Watch,
    eased: &dyn Fn(&str),
) -> anyhow::Result<Option<Level>> {
    let seed = request.seed;
    let mut request = request.clone();
    let mut replaced = 0;
    loop {
        // The draws tried at this λ before the Generator built no further valid level.
        let mut built_only = None;
        for draw in 0..redraw.max_draws {
            let mut level = match source.level(&LevelRequest {
                draw,
                ..request.clone()
            }) {
                Err(e) if built_nothing(&e) => {
                    built_only = Some(draw);
                    break;
                }
                built => built?,
            };
            let Some(mut stats) = verify::verify_watched(&level, solver, trials, seed, watch)?
            else {
                return Ok(None);
            };
            if stats.successes == 0 && !redraw.keep_unsolved {
                replaced += 1;
                continue;
            }
            stats.redraws = replaced;
            level.stats = Some(stats);
            return Ok(Some(verify::certified(level, solver, seed)?));
        }
        // Only a Generator's λ can be eased; rule levels have none.
        let asked = match source {
            LevelSource::Generator(_) => request.aux.as_ref(),
            LevelSource::Rules(_) => None,
        };
        let at = asked.map_or(String::new(), |a| format!(" at {a}"));
        let why = match built_only {
            Some(0) => format!("the Generator built no valid level{at}"),
            Some(draws) => format!(
                "none of the {draws} levels{at} was completed by any of {trials} runs and the Generator built no further one"
            ),
            None => format!(
                "none of the {} levels drawn for this seed{at} was completed by any of {trials} runs",
                redraw.max_draws
            ),
        };
        let Some(easier) = asked.and_then(|a| a.eased(redraw.ease_step)) else {
            match built_only {
                Some(0) => anyhow::bail!("{why}"),
                _ => anyhow::bail!("{why} (--allow-unsolved keeps the first anyway)"),
            }
        };
        eased(&format!("seed {seed}: {why}; asking {easier}"));
        request.aux = Some(easier);
    }
}
