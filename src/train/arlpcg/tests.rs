//! The adversarial loop's matches, played against a Solver that stands still.

use rand::SeedableRng;

use super::*;
use crate::game::PlatformGame;
use crate::rl::policy::ActorCritic;
use crate::rl::ppo::PpoConfig;
use crate::train::TrainConfig;
use crate::train::cards::{generator_shape, solver_shape};

/// An untrained Generator at λ = -1 against a Solver that stands still: every run fails
/// on the first block, long before the goal.
fn standing_still_matches(matches: usize) -> AdversarialEnvs<PlatformGame> {
    let config = TrainConfig::default();
    let game = crate::level::Game::Platform;
    let policy = ActorCritic::new(generator_shape(&config, game), 3).unwrap();
    policy
        .set_log_std(config.generator.initial_log_std)
        .unwrap();
    let generator = Generator {
        ppo: Ppo::new(PpoConfig::default(), policy).unwrap(),
        norm: RunningNorm::new(observation_size::<PlatformGame>()),
    };
    let rules = MatchRules {
        aux_values: vec![-1.0],
        limits: BuildLimits::default_for::<PlatformGame>(),
        obstacles: 0,
        rewards: PlatformGame::default_rewards(),
        snapshot_share: None,
        paced_share: 0.0,
    };
    let mut envs = AdversarialEnvs::new(
        matches,
        generator,
        ChaCha8Rng::seed_from_u64(3),
        rules,
        AdversarialRecord::default(),
        Vec::new(),
        solver_shape(&config, game).action_size(),
    )
    .unwrap();
    envs.set_phase(Phase::Generator);
    envs
}

#[test]
fn a_failure_is_judged_only_on_a_level_the_generator_completes_alone() {
    let matches = 16;
    let mut envs = standing_still_matches(matches);
    let width = solver_shape(&TrainConfig::default(), crate::level::Game::Platform).action_size();
    let still = vec![0.0; matches * width];
    let mut out = vec![Transition::default(); matches];
    while envs.stats.episodes < 48 {
        envs.step(&still, &mut out);
    }
    let stats = envs.take_stats();
    let (judged, invalid) = (stats.judged[1], stats.invalid);
    assert_eq!(stats.successes[1], 0, "it stood still");
    assert!(
        judged > 0 && invalid > 0,
        "{judged} judged, {invalid} invalid"
    );
    assert_eq!(judged + invalid, stats.episodes);
    // Standing on the start, the Solver only ever saw the first block: each judged level
    // was completed to its goal (30 m away or more, blocks at most 10 m apart) by the
    // Generator alone.
    assert!(
        stats.pieces[1] >= 3 * judged,
        "{} blocks in {judged} judged levels",
        stats.pieces[1]
    );
}
