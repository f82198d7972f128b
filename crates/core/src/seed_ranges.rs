//! The ranges of seeds each part of the tool draws its levels from, in one place, so that no
//! level a policy trained on is ever used to measure it.
//!
//! | seeds | what |
//! |---|---|
//! | 0 .. 2^32 | levels a user asks for (`generate`, `verify`, the designer) |
//! | [`EVAL_SEED_BASE`] .. | `eval`'s controllability and cross levels |
//! | [`VALIDATION_SEED_BASE`] .. | `eval`'s validation set (its Generator half from 2^24 further per λ) |
//! | [`CURVE_SEED_BASE`] .. | the levels a difficulty curve is measured on (`generate --target-success`) |
//! | [`FINISH_CHECK_SEED_BASE`] .. | the levels a training run's finish checks its knob on (`generator.finish.own_check_every`) |
//! | [`TRAINING_SEED_BASE`] .. | every level and match of training |

/// First seed of `eval`'s controllability (and cross) levels.
pub const EVAL_SEED_BASE: u64 = 1 << 32;
/// First seed of `eval`'s validation set.
pub const VALIDATION_SEED_BASE: u64 = 2 << 32;
/// Seeds between the λ blocks of the validation set's Generator half.
pub const VALIDATION_AUX_STRIDE: u64 = 1 << 24;
/// First seed of the levels a difficulty curve is measured on.
pub const CURVE_SEED_BASE: u64 = 3 << 32;
/// First seed of the levels a training run's finish checks its knob on, apart from the own
/// check's ([`EVAL_SEED_BASE`]), so that the check a run ends with is not the one it stopped on.
pub const FINISH_CHECK_SEED_BASE: u64 = 4 << 32;
/// First seed of training's levels and matches.
pub const TRAINING_SEED_BASE: u64 = 1 << 40;

// The ranges stay apart: eval and the curve draw at most 2^24 seeds per block (six blocks in the
// validation set), and training starts above them all. A change that breaks this fails the build.
const _: () = {
    assert!(VALIDATION_SEED_BASE - EVAL_SEED_BASE >= 6 * VALIDATION_AUX_STRIDE);
    assert!(CURVE_SEED_BASE - VALIDATION_SEED_BASE >= 6 * VALIDATION_AUX_STRIDE);
    assert!(CURVE_SEED_BASE + (1 << 32) <= FINISH_CHECK_SEED_BASE);
    assert!(FINISH_CHECK_SEED_BASE + (1 << 32) <= TRAINING_SEED_BASE);
};
