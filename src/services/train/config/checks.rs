//! The checks of a training configuration that serde cannot make (sizes, ranges, finite
//! numbers), and which fields a resumed run may change. Problems name the field.

use super::{GeneratorConfig, TrainConfig};
use arlpcg_core::game::facts::facts;
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::Game;

/// Limits on the networks' size (a 4096-unit layer is already 64 MB of weights and moments).
const MAX_HIDDEN_LAYERS: usize = 8;
const MAX_HIDDEN_UNITS: usize = 4096;
/// Stages of one run.
const MAX_STAGES: usize = 16;
/// Snapshots of the Solver a Generator may play against (each is a network's weights).
const MAX_POPULATION: usize = 16;
/// Limit on each phase length and the warm-up (10^12 steps: years of training).
const MAX_PHASE_STEPS: u64 = 1_000_000_000_000;
/// Hard matches in a finish's block (a Generator phase plays a few hundred a minute).
const MAX_HARD_MATCH_BLOCK: u32 = 100_000;
/// The most levels, and runs per level, a finished run's own check plays at each end of λ.
const MAX_OWN_CHECK: u32 = 1000;
/// The most retries a Solver gets on one piece of a match.
const MAX_RETRIES: u32 = 10;

/// Checks that `new` may replace `old` in a resumed run: the fields that fix the networks'
/// shapes, the number of matches and the seed stream stay; learning rates, coefficients,
/// rewards and the phase schedule may change. The racing Generator's curve offset belongs to
/// its weights and is checked against the Generator checkpoint's card instead (a run may pair
/// a Solver checkpoint with another run's Generator).
pub(in crate::services::train) fn check_resumable_change(
    old: &TrainConfig,
    new: &TrainConfig,
) -> Result<(), String> {
    let fixed = [
        ("seed", old.seed == new.seed),
        ("hidden", old.hidden == new.hidden),
        (
            "solver.num_envs",
            old.solver.num_envs == new.solver.num_envs,
        ),
        (
            "generator.max_pieces",
            old.generator.max_pieces == new.generator.max_pieces,
        ),
        ("profile", old.profile == new.profile),
        ("ability_spread", old.ability_spread == new.ability_spread),
        ("ability_ranges", old.ability_ranges == new.ability_ranges),
        (
            "generator.rule_level_share",
            old.rule_level_envs() == new.rule_level_envs(),
        ),
    ];
    match fixed.iter().find(|(_, same)| !same) {
        Some((name, _)) => Err(format!(
            "{name} cannot change in a resumed run (it fixes the networks, the matches or the seed stream)"
        )),
        None => Ok(()),
    }
}

/// The stages' and the finish's fields.
fn check_schedule(g: &GeneratorConfig) -> Result<(), String> {
    if g.hard_success_floor
        .is_some_and(|r| !(0.0..=1.0).contains(&r))
    {
        return Err("hard_success_floor must be a ratio in [0, 1]".into());
    }
    if g.stages.len() > MAX_STAGES {
        return Err(format!("stages: at most {MAX_STAGES}"));
    }
    for (k, stage) in g.stages.iter().enumerate() {
        let rate = stage.solver_learning_rate;
        if !(rate.is_finite() && (0.0..=1.0).contains(&rate)) {
            return Err(format!(
                "stages[{k}].solver_learning_rate must be a number in [0, 1]"
            ));
        }
        if !(1..=MAX_PHASE_STEPS).contains(&stage.solver_phase_steps)
            || !(1..=MAX_PHASE_STEPS).contains(&stage.generator_phase_steps)
        {
            return Err(format!(
                "stages[{k}]: solver_phase_steps and generator_phase_steps must be within [1, {MAX_PHASE_STEPS}]"
            ));
        }
        if stage
            .snapshot_share
            .is_some_and(|p| !(0.0..=1.0).contains(&p))
        {
            return Err(format!(
                "stages[{k}].snapshot_share must be a number in [0, 1]"
            ));
        }
        if k > 0 && stage.from_steps <= g.stages[k - 1].from_steps {
            return Err(format!(
                "stages[{k}].from_steps must be after the stage before it"
            ));
        }
    }
    if g.finish.solver_steps > 0 {
        if !(1..=MAX_PHASE_STEPS).contains(&g.finish.generator_phase_steps)
            || !(1..=MAX_PHASE_STEPS).contains(&g.finish.solver_phase_steps)
            || g.finish.solver_steps > MAX_PHASE_STEPS
        {
            return Err(format!(
                "finish: solver_steps, solver_phase_steps and generator_phase_steps must be within [1, {MAX_PHASE_STEPS}]"
            ));
        }
        for (name, ratio) in [
            (
                "generator_until_hard_success", g.finish.generator_until_hard_success,
            ),
            ("until_hard_success", g.finish.until_hard_success),
            ("paced_share", g.finish.paced_share),
        ] {
            if ratio.is_some_and(|r| !(0.0..=1.0).contains(&r)) {
                return Err(format!("finish.{name} must be a ratio in [0, 1]"));
            }
        }
        if !(1..=MAX_HARD_MATCH_BLOCK).contains(&g.finish.hard_match_block) {
            return Err(format!(
                "finish.hard_match_block must be within [1, {MAX_HARD_MATCH_BLOCK}] matches"
            ));
        }
        let rate = g.finish.solver_learning_rate;
        if !(rate.is_finite() && (0.0..=1.0).contains(&rate)) {
            return Err("finish.solver_learning_rate must be a number in [0, 1]".into());
        }
        if g.finish
            .generator_entropy
            .is_some_and(|e| !(0.0..=1.0).contains(&e))
        {
            return Err("finish.generator_entropy must be a number in [0, 1]".into());
        }
        if g.finish
            .generator_learning_rate
            .is_some_and(|r| !(r > 0.0 && r <= 1.0))
        {
            return Err("finish.generator_learning_rate must be a number in (0, 1]".into());
        }
        if g.finish.own_check_every == Some(0) {
            return Err("finish.own_check_every must be at least 1 Generator step".into());
        }
        if g.finish
            .scripted_opponent
            .is_some_and(|o| !(o.share > 0.0 && o.share <= 1.0))
        {
            return Err("finish.scripted_opponent.share must be a number in (0, 1]".into());
        }
        if g.ppo.anneal_lr {
            return Err(
                "finish: the Generator's learning rate is annealed to 0 by the finish \
                 (generator.ppo.anneal_lr); turn annealing off or set finish.solver_steps to 0"
                    .into(),
            );
        }
    }
    Ok(())
}

/// Checks the values serde cannot: sizes, ranges, finite numbers.
pub(in crate::services::train) fn check_config(
    config: &TrainConfig,
    game: Game,
) -> Result<(), String> {
    if config.hidden.is_empty()
        || config.hidden.len() > MAX_HIDDEN_LAYERS
        || !config
            .hidden
            .iter()
            .all(|h| (1..=MAX_HIDDEN_UNITS).contains(h))
    {
        return Err(format!(
            "hidden: give 1 to {MAX_HIDDEN_LAYERS} layers, each of 1 to {MAX_HIDDEN_UNITS} units"
        ));
    }
    if !(1..=MAX_PHASE_STEPS).contains(&config.steps) {
        return Err(format!("steps must be in [1, {MAX_PHASE_STEPS}]"));
    }
    if !(0.0..=0.5).contains(&config.ability_spread) {
        return Err("ability_spread must be a share within [0, 0.5] (0.2: ±20%)".into());
    }
    config.trained_over(game)?;
    let own = config.generator.own_check;
    if own.levels > MAX_OWN_CHECK || own.trials > MAX_OWN_CHECK {
        return Err(format!(
            "generator.own_check: levels and trials must be within [0, {MAX_OWN_CHECK}]"
        ));
    }
    if let Some(record) = &config.profile {
        record
            .profile(game)
            .map_err(|problem| format!("profile.{problem}"))?;
    }
    let minutes = config.checkpoint_minutes;
    if !(minutes.is_finite() && (0.0..=24.0 * 60.0).contains(&minutes)) {
        return Err(
            "checkpoint_minutes must be a number in [0, 1440] (0: after every iteration)".into(),
        );
    }
    for (name, p) in [
        ("solver", &config.solver),
        ("generator.ppo", &config.generator.ppo),
    ] {
        p.check().map_err(|problem| format!("{name}.{problem}"))?;
    }
    let share = config.generator.rule_level_share;
    if !(0.0..1.0).contains(&share) || config.rule_level_envs() >= config.solver.num_envs {
        return Err(format!(
            "generator.rule_level_share must be a share in [0, 1) that leaves at least one of \
             the {} environments (solver.num_envs) to the Generator's matches",
            config.solver.num_envs
        ));
    }
    check_generator(&config.generator, game).map_err(|problem| format!("generator.{problem}"))
}

/// The Generator's part of [`check_config`]; problems name the field below `generator.`.
fn check_generator(g: &GeneratorConfig, game: Game) -> Result<(), String> {
    if g.aux_values.is_empty()
        || g.aux_values.len() > 1000
        || g.aux_values.iter().any(|l| !(-1.0..=1.0).contains(l))
    {
        return Err("aux_values: give 1 to 1000 values, each within [-1, 1]".into());
    }
    if !(0.0..=1.0).contains(&g.paced_share) {
        return Err("paced_share must be a number in [0, 1]".into());
    }
    let knobs = arlpcg_core::for_game!(game, G => G::KNOBS.len());
    if !g.rewards.knobs.is_empty() && g.rewards.knobs.len() != knobs {
        return Err(format!(
            "rewards.knobs: the {game} game has {knobs} knobs, so give {knobs} weights (or none), not {}",
            g.rewards.knobs.len()
        ));
    }
    if let Some(values) = &g.knob_values
        && (values.is_empty()
            || values.len() > 1000
            || values.iter().any(|k| !(-1.0..=1.0).contains(k)))
    {
        return Err("knob_values: give 1 to 1000 values, each within [-1, 1]".into());
    }
    if g.rewards.aux.len() != 1 {
        return Err(format!(
            "rewards.aux: the {game} game has 1 aux input, so give 1 weight pair, not {}",
            g.rewards.aux.len()
        ));
    }
    let r = &g.rewards;
    let weights = r.aux.iter().flat_map(|w| [w.alpha, w.beta]);
    if ![
        r.progress_per_metre, r.failure, r.step_penalty, r.air_step, r.invalid,
        r.piece_failure_weight,
    ]
    .into_iter()
    .chain(weights)
    .chain(r.knobs.iter().copied())
    .all(f32::is_finite)
    {
        return Err("rewards: every weight must be a finite number".into());
    }
    if r.retries > MAX_RETRIES {
        return Err(format!("rewards.retries must be within [0, {MAX_RETRIES}]"));
    }
    if !(r.hazard_at_hardest > 0.0 && r.hazard_at_hardest < 1.0) {
        return Err("rewards.hazard_at_hardest must be a number in (0, 1)".into());
    }
    if g.snapshot_share.is_some_and(|p| !(0.0..=1.0).contains(&p)) {
        return Err("snapshot_share must be a number in [0, 1]".into());
    }
    check_schedule(g)?;
    if g.population > MAX_POPULATION {
        return Err(format!("population must be within [0, {MAX_POPULATION}]"));
    }
    if !(1..=MAX_PHASE_STEPS).contains(&g.population_every_steps) {
        return Err(format!(
            "population_every_steps must be within [1, {MAX_PHASE_STEPS}]"
        ));
    }
    let max_pieces = arlpcg_core::for_game!(game, G => G::MAX_PIECES);
    if !(1..=max_pieces).contains(&g.max_pieces) {
        return Err(format!("max_pieces must be within [1, {max_pieces}]"));
    }
    let default_offset = arlpcg_core::game::generator::DEFAULT_CURVE_OFFSET;
    if !(0.0..=180.0).contains(&g.curve_offset) {
        return Err("curve_offset must be a number of degrees in [0, 180]".into());
    }
    if !facts(game).curve_offset && g.curve_offset != default_offset {
        return Err(format!(
            "curve_offset does not steer the {game} Generator (leave it at {default_offset})"
        ));
    }
    if g.finish.knobs_only && (g.rewards.knobs.is_empty() || g.finish.solver_steps == 0) {
        return Err(
            "finish.knobs_only needs knobs (rewards.knobs) and a finish (finish.solver_steps)"
                .into(),
        );
    }
    if let Some(runs) = g.finish.reach_runs {
        match facts(game).reach_runs {
            None => {
                return Err(format!(
                    "finish.reach_runs: the {game} Generator's pieces are not cut to a reach"
                ));
            }
            Some(most) if !(1..=most).contains(&runs) => {
                return Err(format!("finish.reach_runs must be within [1, {most}] runs"));
            }
            Some(_) => {}
        }
    }
    if g.obstacles > arlpcg_core::level::racing::MAX_OBSTACLES as u32 {
        return Err(format!(
            "obstacles must be at most {}",
            arlpcg_core::level::racing::MAX_OBSTACLES
        ));
    }
    if !(-10.0..=2.0).contains(&g.initial_log_std) {
        return Err("initial_log_std must be within [-10, 2]".into());
    }
    if g.solver_warmup_steps > MAX_PHASE_STEPS
        || !(1..=MAX_PHASE_STEPS).contains(&g.solver_phase_steps)
        || !(1..=MAX_PHASE_STEPS).contains(&g.generator_phase_steps)
    {
        return Err(format!(
            "solver_phase_steps and generator_phase_steps must be within [1, {MAX_PHASE_STEPS}], solver_warmup_steps at most that"
        ));
    }
    Ok(())
}
