//! Both games, written once over the game abstraction: the same level, start seed and player
//! give the same run bit for bit (observations and rewards), and another start seed gives
//! another run, so the check can fail.

use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame, Scripted, Skill, SolverEnv};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Every observation and reward of a run on rule level 11 from start `seed`, as raw bits. The
/// median scripted player (noisy, from its own seed) plays, and every tenth action is drawn at
/// random from a fixed stream, so that the run exercises falls, slides and air.
fn run_bits<G: GameSpec>(seed: u64) -> Vec<u32> {
    let level = G::rule_level(11, &Default::default()).expect("rule level 11 builds");
    let mut env = G::solver_env(&level).expect("a level of this game");
    env.reset(seed);
    let mut player = G::scripted(seed, Skill::Median);
    let mut random = ChaCha8Rng::seed_from_u64(7);
    let mut observation = vec![0.0; G::Env::OBSERVATION_SIZE];
    let mut bits = Vec::new();
    for tick in 0..2000 {
        let action = match tick % 10 {
            0 => G::Env::random_action(&mut random),
            _ => player.act(&env),
        };
        let step = env.step(action);
        env.observe(&mut observation);
        bits.extend(observation.iter().map(|x| x.to_bits()));
        bits.push(step.reward.to_bits());
        if step.outcome.is_some() {
            break;
        }
    }
    bits
}

fn same_seed_same_run<G: GameSpec>() {
    let first = run_bits::<G>(5);
    assert!(
        first.len() > 50 * G::Env::OBSERVATION_SIZE,
        "{}: the run lasted {} values",
        G::GAME,
        first.len()
    );
    assert_eq!(first, run_bits::<G>(5), "{}", G::GAME);
    assert_ne!(
        first,
        run_bits::<G>(6),
        "{}: another start seed should start elsewhere",
        G::GAME
    );
}

#[test]
fn the_same_level_seed_and_player_give_a_bitwise_identical_run_in_both_games() {
    same_seed_same_run::<PlatformGame>();
    same_seed_same_run::<RacingGame>();
}
