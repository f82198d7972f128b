//! The games as deterministic simulations over rapier3d: the same level, seed and actions give
//! the same trajectory, bit for bit. Nothing here prints, reads the clock or uses a global RNG.

#[cfg(feature = "test-game")]
pub mod ball;
pub mod facts;
pub mod generator;
pub mod platform;
pub mod racing;
mod spec;

pub use crate::level::stats::Skill;
pub use platform::PlatformGame;
pub use racing::RacingGame;
pub use spec::{
    GameSpec, NoRuleLevel, Player, PortState, RuleAsk, Scripted, SolverEnv, Step, observe_solver,
};

/// Runs `body` with `G` standing for the game type of the runtime [`Game`](crate::level::Game)
/// `game`: the one place a game's name becomes its type. Each entry point (a command, a loaded
/// policy, a level read from a file) dispatches once; what runs inside is generic over
/// `G: GameSpec` and compiled per game.
///
/// ```
/// use arlpcg_core::game::GameSpec;
/// let name = arlpcg_core::for_game!(arlpcg_core::level::Game::Racing, G => G::FACTS.piece);
/// assert_eq!(name, "segment");
/// ```
#[macro_export]
macro_rules! for_game {
    ($game:expr, $G:ident => $body:expr) => {
        match $game {
            $crate::level::Game::Platform => {
                type $G = $crate::game::platform::PlatformGame;
                $body
            }
            $crate::level::Game::Racing => {
                type $G = $crate::game::racing::RacingGame;
                $body
            }
            #[cfg(feature = "test-game")]
            $crate::level::Game::Ball => {
                type $G = $crate::game::ball::BallGame;
                $body
            }
        }
    };
}
