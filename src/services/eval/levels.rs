//! The levels an evaluation plays: Generator levels at each λ, the validation set, and the
//! [`PlayLayout`] that describes them without the levels themselves.

use crate::services::generation::{self, GeneratorPolicy, LevelRequest};
use arlpcg_core::game::facts::{facts, piece_values};
use arlpcg_core::level::Level;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::seed_ranges::{EVAL_SEED_BASE, VALIDATION_AUX_STRIDE, VALIDATION_SEED_BASE};

use super::styles::{KNOB_SETTINGS, KnobLayout};
use super::{AUX_VALUES, Budget, KNOB_BETWEEN, NamedSolver, PlayLayout};

/// Seeds tried per wanted level before the table notes a shortfall (the Generator may fail to
/// reach a goal).
const SEED_TRIES: u64 = 4;

/// Generator levels at `aux` for `profile` (none: the built-in game): `count` of them from
/// seeds `base`, `base + 1`, ... (a seed whose level the Generator cannot build is skipped,
/// within `SEED_TRIES` seeds per level).
pub fn generator_levels(
    generator: &GeneratorPolicy,
    aux: f64,
    base: u64,
    count: u32,
    profile: Option<&Profile>,
) -> Result<Vec<Level>, candle_core::Error> {
    styled_levels(generator, (aux, &[]), base, count, profile)
}

/// [`generator_levels`] with the Generator's style knobs at `knobs` (in its game's order;
/// missing: 0).
fn styled_levels(
    generator: &GeneratorPolicy,
    (aux, knobs): (f64, &[f32]),
    base: u64,
    count: u32,
    profile: Option<&Profile>,
) -> Result<Vec<Level>, candle_core::Error> {
    let mut levels = Vec::with_capacity(count as usize);
    for seed in base..base + count as u64 * SEED_TRIES {
        if levels.len() == count as usize {
            break;
        }
        let request = LevelRequest::new(seed, Some(aux))
            .obstacles(facts(generator.game).scene_obstacles)
            .profile(profile.cloned())
            .knobs(knobs.to_vec());
        match generation::generator_level(generator, &request) {
            Ok(level) => levels.push(level),
            // (No prefix is kept here, so `Keep` does not occur.)
            Err(
                generation::GenerationError::NoLevel { .. }
                | generation::GenerationError::Keep { .. },
            ) => {}
            Err(generation::GenerationError::Network(e)) => return Err(e),
        }
    }
    Ok(levels)
}

/// The validation set for `profile`: rule levels and Generator levels (λ cycling through
/// [`AUX_VALUES`]), half each.
pub fn validation_levels(
    generator: &GeneratorPolicy,
    count: u32,
    profile: Option<&Profile>,
) -> Result<Vec<Level>, candle_core::Error> {
    let base = VALIDATION_SEED_BASE;
    let rule_count = count / 2;
    let game = generator.game;
    let mut levels: Vec<Level> = (0..rule_count as u64)
        .filter_map(|k| {
            let request = LevelRequest::new(base + k, None)
                .obstacles(facts(game).scene_obstacles)
                .profile(profile.cloned());
            generation::rules_level(game, &request).ok()
        })
        .collect();
    let per_aux = (count - rule_count).div_ceil(AUX_VALUES.len() as u32);
    for (k, &aux) in AUX_VALUES.iter().enumerate() {
        let seeds = base + (1 + k as u64) * VALIDATION_AUX_STRIDE;
        let wanted = per_aux.min(count - levels.len() as u32);
        levels.extend(generator_levels(generator, aux, seeds, wanted, profile)?);
    }
    Ok(levels)
}

/// Whether a level comes from the rules (the validation set's first half).
pub fn is_rule_level(level: &Level) -> bool {
    matches!(
        level.source,
        arlpcg_core::level::Source::Rules { .. } | arlpcg_core::level::Source::RacingRules { .. }
    )
}

/// The levels of an evaluation and its layout.
pub struct Levels {
    /// The Generator's levels at each λ of [`AUX_VALUES`].
    pub by_aux: Vec<Vec<Level>>,
    /// The same goals at each λ of [`KNOB_BETWEEN`].
    pub between: Vec<Vec<Level>>,
    /// The validation set: its rule levels first, then the Generator's.
    pub validation: Vec<Level>,
    /// Per style knob, the same goals at each setting of [`KNOB_SETTINGS`] (λ and the other
    /// knobs at 0; none for a Generator without knobs).
    pub by_knob: Vec<Vec<Vec<Level>>>,
    /// The evaluation's layout: what it plays.
    pub layout: PlayLayout,
}

/// Builds every level the evaluation plays, for `profile` (deterministic: the same Generator,
/// budget and profile give the same levels on every machine).
pub fn levels(
    generator: &GeneratorPolicy,
    solvers: &[NamedSolver],
    budget: Budget,
    profile: Option<&Profile>,
) -> Result<Levels, candle_core::Error> {
    let by_aux: Vec<Vec<Level>> = AUX_VALUES
        .iter()
        .map(|&aux| generator_levels(generator, aux, EVAL_SEED_BASE, budget.tracks, profile))
        .collect::<Result<_, _>>()?;
    let between: Vec<Vec<Level>> = KNOB_BETWEEN
        .iter()
        .map(|&aux| generator_levels(generator, aux, EVAL_SEED_BASE, budget.tracks, profile))
        .collect::<Result<_, _>>()?;
    let validation = validation_levels(generator, budget.validation_tracks, profile)?;
    let game = generator.game;
    let by_knob: Vec<Vec<Vec<Level>>> = (0..generator.knobs)
        .map(|k| {
            KNOB_SETTINGS
                .iter()
                .map(|&value| {
                    let mut knobs = vec![0.0; generator.knobs];
                    knobs[k] = value as f32;
                    styled_levels(
                        generator,
                        (0.0, &knobs),
                        EVAL_SEED_BASE,
                        budget.tracks,
                        profile,
                    )
                })
                .collect::<Result<_, _>>()
        })
        .collect::<Result<_, _>>()?;
    let knobs = by_knob
        .iter()
        .zip(game.shape().knobs())
        .enumerate()
        .map(|(k, (levels, name))| KnobLayout::of(name, k, levels))
        .collect();
    let piece_means = by_aux
        .iter()
        .map(|levels| {
            let pieces: Vec<Vec<f64>> = levels.iter().flat_map(piece_values).collect();
            (!pieces.is_empty()).then(|| {
                (0..facts(game).piece_columns.len())
                    .map(|k| pieces.iter().map(|p| p[k]).sum::<f64>() / pieces.len() as f64)
                    .collect()
            })
        })
        .collect();
    let layout = PlayLayout {
        game,
        levels_per_aux: by_aux.iter().map(Vec::len).collect(),
        levels_between: between.iter().map(Vec::len).collect(),
        piece_means,
        validation_levels: validation.len(),
        validation_rule_levels: validation.iter().filter(|l| is_rule_level(l)).count(),
        solvers: solvers.iter().map(|s| s.mode.clone()).collect(),
        knobs,
    };
    Ok(Levels {
        by_aux,
        between,
        validation,
        by_knob,
        layout,
    })
}
