//! A training run's finish (`generator.finish`): the Generator's last stretch against the
//! final Solver, its stops, and the platform recipe's.

use serde::{Deserialize, Serialize};

use arlpcg_core::level::stats::Skill;

/// The last stretch of an adversarial run, after the Solver's `steps`: the Generator learns
/// against the final Solver alone (no snapshots), in phases of `generator_phase_steps`, until
/// the Solver has played `solver_steps` more steps. By default the Solver is frozen (its
/// one-iteration phases only play; its observation normalizer follows them); a
/// `solver_learning_rate` above 0 lets it keep up a little, in phases of `solver_phase_steps`.
/// The run's budget is then `steps + solver_steps`; learning rates that anneal reach 0 at
/// `steps`, so an annealed Generator learning rate is refused with a finish.
/// Its optional fields are written out even when none (`null`): a configuration file's
/// missing fields take the game's defaults (`TrainConfig::parse_for`), so a printed or saved
/// configuration with a field left out would read back as that game's value. A file may give
/// some of its fields only (`serde(default)` lets it read as written; the recipe's values then
/// fill the rest).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Finish {
    /// Solver steps played in the finish (0: no finish).
    pub solver_steps: u64,
    pub generator_phase_steps: u64,
    /// The Solver's constant learning rate in the finish (0: frozen).
    #[serde(default)]
    pub solver_learning_rate: f64,
    /// Solver steps in each of its finish phases (1: one iteration).
    #[serde(default = "one_iteration")]
    pub solver_phase_steps: u64,
    /// The finish's Generator phases end once the Solver's success on hard matches (λ < 0)
    /// has fallen to this ratio, counted over blocks of `hard_match_block` of them;
    /// `generator_phase_steps` stays the limit. None: they end at `generator_phase_steps`.
    #[serde(default)]
    pub generator_until_hard_success: Option<f64>,
    /// With a learning Solver: the finish ends once a Solver phase after its Generator phase
    /// (the catch-up) has brought the Solver's success on hard matches back up to this ratio,
    /// counted the same way; `solver_steps` stays the limit. None: the finish ends at
    /// `solver_steps`.
    #[serde(default)]
    pub until_hard_success: Option<f64>,
    /// Hard matches (λ < 0) in each block over which the two stops above count the Solver's
    /// success, one block after another. A larger block stops on a fall that lasts rather
    /// than on one block's dip (a block of 32 has a standard error of 0.09 at a success of
    /// one half).
    #[serde(default = "hard_match_block")]
    pub hard_match_block: u32,
    /// The Generator's entropy bonus in the finish's Generator phases, in place of
    /// `generator.ppo.ent_coef` (none: that one): a larger one keeps it trying new tracks
    /// against the final Solver instead of refining those it already makes.
    #[serde(default)]
    pub generator_entropy: Option<f32>,
    /// The Generator's learning rate in the finish's Generator phases, in place of
    /// `generator.ppo.learning_rate` (none: that one): against a frozen Solver a larger step
    /// finds its weak spots in fewer blocks, though not in every seed (docs/trials.md).
    #[serde(default)]
    pub generator_learning_rate: Option<f64>,
    /// Every this many Generator steps of the finish, the pair plays the own check
    /// (`generator.own_check`) on levels of seeds of its own (`FINISH_CHECK_SEED_BASE`), and
    /// the finish's Generator phase ends once it passes the bars with a margin at the hard end
    /// (`own_check::FINISH_HARD_MARGIN`): the stop the product needs, where the block stop
    /// above waits for one lucky block. A phase that runs to `generator_phase_steps` without
    /// passing ends with the Generator of its best check (the least short of the bars), kept
    /// in the run folder as `generator-best-check.safetensors` (none: no such check).
    #[serde(default)]
    pub own_check_every: Option<u64>,
    /// A scripted player that plays a share of the matches while the finish's Generator
    /// learns, so that its failures pay the Generator as the final Solver's do (none: the final
    /// Solver plays every match). The stops above count the final Solver's matches only.
    #[serde(default)]
    pub scripted_opponent: Option<ScriptedOpponent>,
    /// Platform: the finish's Generator cuts its jumps to the gaps the reach measurement clears
    /// in at least this many of its 8 runs, not all 8 (none: the reach table the rules keep
    /// to, as before the finish), and its card says so (`reach_runs`), so that its levels are
    /// cut the same way wherever it plays. Against a strong Solver the reliable table leaves
    /// hard levels easy (docs/decisions.md, D22).
    #[serde(default)]
    pub reach_runs: Option<u64>,
    /// The Generator's style knobs (`generator.rewards.knobs`) are drawn in the finish only:
    /// before it every knob is 0 (no preference) and pays nothing, so the levels the Solver
    /// learns from are those of a Generator without knobs, and the knobs cost its validation
    /// nothing (docs/decisions.md, D20). False: drawn in every match.
    #[serde(default)]
    pub knobs_only: bool,
    /// The share of the finish's matches that are paced (λ changes once along the level), in
    /// place of `generator.paced_share` (none: that one), so that a Generator that learns
    /// against the final Solver for long keeps following λ after a stretch of another λ.
    #[serde(default)]
    pub paced_share: Option<f64>,
}

/// The scripted player as the Generator's opponent in a finish ([`Finish::scripted_opponent`]);
/// a file may give some of its fields only, as for [`Finish`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScriptedOpponent {
    pub skill: Skill,
    /// The share of matches it plays, in (0, 1].
    pub share: f64,
    /// Whether it plays only easy matches (λ > 0), leaving every hard one to the final Solver.
    #[serde(default)]
    pub easy_only: bool,
}

/// The default of [`Finish::hard_match_block`].
pub const HARD_MATCH_BLOCK: u32 = 32;

fn hard_match_block() -> u32 {
    HARD_MATCH_BLOCK
}

fn one_iteration() -> u64 {
    1
}

/// The median player in half the matches, easy and hard: the platform recipe's.
impl Default for ScriptedOpponent {
    fn default() -> Self {
        ScriptedOpponent {
            skill: Skill::Median,
            share: 0.5,
            easy_only: false,
        }
    }
}

impl Default for Finish {
    fn default() -> Self {
        Finish::NONE
    }
}

impl Finish {
    /// No finish; its other fields are a finish's defaults (the Solver frozen in one-iteration
    /// phases, 100k-step Generator phases, no stop on success), which the recipes' finishes
    /// start from.
    pub const NONE: Finish = Finish {
        solver_steps: 0,
        generator_phase_steps: 100_000,
        solver_learning_rate: 0.0,
        solver_phase_steps: 1,
        generator_until_hard_success: None,
        until_hard_success: None,
        hard_match_block: HARD_MATCH_BLOCK,
        generator_entropy: None,
        generator_learning_rate: None,
        own_check_every: None,
        scripted_opponent: None,
        reach_runs: None,
        knobs_only: false,
        paced_share: None,
    };
}

/// The platform recipe's finish: one Generator phase, entropy bonus 0.01, against the final
/// Solver, frozen (no snapshots), and the median scripted controller, each playing half the
/// matches, until the Solver succeeds on at most 40% of its hard matches (blocks of 64; at most
/// 1M Generator steps), then one frozen Solver iteration. Why: docs/decisions.md#d5 to #d8.
pub const PLATFORM_FINISH: Finish = Finish {
    solver_steps: 16_384,
    generator_phase_steps: 1_000_000,
    generator_until_hard_success: Some(0.4),
    hard_match_block: 64,
    generator_entropy: Some(0.01),
    scripted_opponent: Some(ScriptedOpponent {
        skill: Skill::Median,
        share: 0.5,
        easy_only: false,
    }),
    ..Finish::NONE
};
