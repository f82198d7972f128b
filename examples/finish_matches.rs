//! Plays a policy folder's Generator and Solver, both frozen, in matches built as training
//! builds them (the Generator places the next piece when the Solver comes close to the newest;
//! a placement that fails ends the match uncounted), and splits the judged matches by whether
//! the Generator, left to go on alone, would have completed its level. A failure on a level
//! that would never have been completed counts in training's hard-match success (and pays the
//! Generator's failure reward) but has no counterpart in `eval`, which plays complete levels
//! only (docs/training.md, "What the finish's stop counts").
//!
//! ```sh
//! cargo run --release --example finish_matches -- platform policies/platform -1 600
//! ```

use std::path::Path;

use anyhow::{Context, Result, bail};
use arlpcg::services::generation::GeneratorPolicy;
use arlpcg::services::policies::{GENERATOR_FILE, SOLVER_FILE, load_generator, load_solver};
use arlpcg::services::verify::SolverPolicy;
use arlpcg_core::game::facts::facts;
use arlpcg_core::game::generator::{GeneratorGame, Match, Placement, TrackBuild, observation_size};
use arlpcg_core::game::{PlatformGame, RacingGame, SolverEnv};
use arlpcg_core::level::Game;
use arlpcg_core::level::stats::Outcome;
use arlpcg_core::rl::policy::ActMode;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Match seeds start here, away from training's and eval's.
const SEED_BASE: u64 = 500_000;

/// How one match ended.
struct Ended {
    /// The Solver's run ended (else a placement failed first, and the match is not judged).
    judged: bool,
    success: bool,
    /// The Generator completes the level: during the match, or alone after the Solver's run.
    completes: bool,
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [game, dir, aux, matches] = args.as_slice() else {
        bail!("usage: finish_matches GAME POLICY_DIR AUX MATCHES");
    };
    let game: Game = game.parse().map_err(|e| anyhow::anyhow!("{e}"))?;
    let dir = Path::new(dir);
    let aux: f32 = aux.parse().context("AUX: a number in [-1, 1]")?;
    let matches: u64 = matches.parse().context("MATCHES: a count")?;
    let (generator, _) = load_generator(&dir.join(GENERATOR_FILE), game)?;
    let (solver, _) = load_solver(&dir.join(SOLVER_FILE), game)?;
    let ended = match game {
        Game::Platform => play::<PlatformGame>(&generator, &solver, aux, matches)?,
        Game::Racing => play::<RacingGame>(&generator, &solver, aux, matches)?,
    };
    let judged: Vec<&Ended> = ended.iter().filter(|e| e.judged).collect();
    let complete: Vec<&&Ended> = judged.iter().filter(|e| e.completes).collect();
    let ratio = |part: usize, whole: usize| part as f64 / whole.max(1) as f64;
    println!(
        "{} at λ = {aux}: {} matches, {:.3} ended by a failed placement; of the {} judged, success {:.3}; \
         {:.3} of them on levels the Generator completes, success there {:.3}",
        dir.display(),
        matches,
        ratio(ended.len() - judged.len(), ended.len()),
        judged.len(),
        ratio(judged.iter().filter(|e| e.success).count(), judged.len()),
        ratio(complete.len(), judged.len()),
        ratio(
            complete.iter().filter(|e| e.success).count(),
            complete.len()
        ),
    );
    Ok(())
}

fn play<G: GeneratorGame>(
    generator: &GeneratorPolicy,
    solver: &SolverPolicy,
    aux: f32,
    matches: u64,
) -> Result<Vec<Ended>> {
    let rewards = G::default_rewards();
    let obstacles = facts(G::GAME).scene_obstacles;
    let decide = |observation: &mut [f32], rng: &mut ChaCha8Rng| {
        generator.normalizer.normalize(observation);
        generator.policy.choose(observation, ActMode::Sample, rng)
    };
    let ended = (SEED_BASE..SEED_BASE + matches)
        .into_par_iter()
        .map(|seed| -> Result<Ended> {
            let (build, mut generator_rng) = G::new_build(seed, None, generator.limits, obstacles);
            let mut game: Match<G> = Match::new(build, vec![aux], seed);
            let mut solver_rng = ChaCha8Rng::seed_from_u64(seed);
            let mut seen = vec![0.0; observation_size::<G>()];
            let mut observation = vec![0.0; <G::Env as SolverEnv>::OBSERVATION_SIZE];
            let mut completed = false;
            loop {
                while game.needs_piece() {
                    game.observe_generator(&mut seen);
                    let action = decide(&mut seen, &mut generator_rng)?;
                    match game.place(&action) {
                        Placement::Placed => {}
                        Placement::Completed => completed = true,
                        Placement::Invalid | Placement::OutOfPieces => {
                            return Ok(Ended {
                                judged: false,
                                success: false,
                                completes: false,
                            });
                        }
                    }
                }
                game.env().observe(&mut observation);
                solver.normalizer.normalize(&mut observation);
                let action =
                    solver
                        .policy
                        .choose(&observation, ActMode::Sample, &mut solver_rng)?;
                let (step, _) = game.step_solver(G::Env::action_from_policy_row(&action), &rewards);
                let Some(outcome) = step.outcome else {
                    continue;
                };
                let success = outcome == Outcome::Success;
                // The Generator's samples do not depend on the Solver, so going on alone from
                // here builds the level the match would have had.
                let mut build = game.build().clone();
                let mut completes = completed;
                while !completes && build.piece_count() < generator.limits.max_pieces {
                    build.observe(&[aux], &mut seen);
                    match build.place(&decide(&mut seen, &mut generator_rng)?) {
                        Placement::Placed => {}
                        Placement::Completed => completes = true,
                        Placement::Invalid | Placement::OutOfPieces => break,
                    }
                }
                return Ok(Ended {
                    judged: true,
                    success,
                    completes,
                });
            }
        })
        .collect::<Result<_>>()?;
    Ok(ended)
}
