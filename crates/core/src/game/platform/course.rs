//! A run's way along a track of blocks, whoever runs it: the path still to go, the furthest
//! block stood on, the decisions taken and the time allowed, how the run ends and what it pays
//! (the Solver's rewards). The platform character's environment keeps one, and so does any game
//! played on the platform game's blocks (the test game's ball).

use rapier3d::math::Vector;

use super::world::PlatformWorld;
use crate::game::Step;
use crate::level::stats::Outcome;

/// The Solver's reward weights (docs/spec.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformRewards {
    /// Per metre of progress along the track toward the goal (negative when moving back).
    pub progress_per_metre: f32,
    /// On reaching the goal block.
    pub success: f32,
    /// On falling or running out of time.
    pub failure: f32,
}

impl Default for PlatformRewards {
    fn default() -> Self {
        // A jump of a typical 7 m block pays about +7 and a fall costs 5, so attempting a jump
        // pays once it succeeds about 40% of the time. (At 0.1 per metre the Solver learned to
        // wait on the start block: a jump had to succeed 88% of the time to be worth a fall, and
        // the time-out's penalty is discounted to nothing 1000 steps ahead.)
        Self {
            progress_per_metre: 1.0,
            success: 10.0,
            failure: -5.0,
        }
    }
}

/// A run has fallen when its lowest point is this far below the lowest block.
pub const FALL_MARGIN: f32 = 5.0;
/// Time allowed for a level: this many seconds...
const TIME_BASE_S: f32 = 10.0;
/// ...plus this many per block.
const TIME_PER_BLOCK_S: f32 = 4.0;

/// A run's way along the blocks of a [`PlatformWorld`] (the world is the environment's; every
/// method that needs it is given it).
#[derive(Debug, Clone, Default)]
pub struct Course {
    /// Path length from each block's top centre to the last one's, along the track.
    path_after: Vec<f32>,
    /// Decisions allowed.
    max_steps: u32,
    /// The track is still growing (the Generator places blocks as the Solver advances):
    /// reaching the last block is not yet success.
    open: bool,
    /// Highest block index stood on (0 is the start block).
    furthest: usize,
    /// Decisions taken.
    steps: u32,
    /// Path still to go at the last decision, m.
    remaining: f32,
    outcome: Option<Outcome>,
}

impl Course {
    /// The course of `world`'s blocks, decisions `decision_dt` seconds apart; call
    /// [`Course::restart`] before the first decision.
    pub fn new(world: &PlatformWorld, decision_dt: f32) -> Self {
        let mut course = Self::default();
        course.measure(world, decision_dt);
        course
    }

    /// The same course on a track still being built: reaching its last block is not success.
    pub fn opened(mut self) -> Self {
        self.open = true;
        self
    }

    /// Path lengths along the track and the time limit, from the blocks placed so far.
    fn measure(&mut self, world: &PlatformWorld, decision_dt: f32) {
        let tops: Vec<Vector> = world.platforms().iter().map(|p| p.top).collect();
        self.path_after = vec![0.0; tops.len()];
        for i in (0..tops.len() - 1).rev() {
            self.path_after[i] = self.path_after[i + 1] + tops[i].distance(tops[i + 1]);
        }
        let blocks = (tops.len() - 1) as f32;
        self.max_steps = ((TIME_BASE_S + TIME_PER_BLOCK_S * blocks) / decision_dt).ceil() as u32;
    }

    /// After the Generator's newest block joined `world` (`closes`: it is the last, so standing
    /// on it is success): the run goes on from `at` with the longer time limit.
    pub fn grown(&mut self, world: &PlatformWorld, closes: bool, at: Vector, decision_dt: f32) {
        self.open = !closes;
        self.measure(world, decision_dt);
        self.remaining = self.path_remaining(world, at);
    }

    /// A new run from block `block`, the runner at `at`: the blocks before it count as left
    /// behind.
    pub fn restart(&mut self, world: &PlatformWorld, block: usize, at: Vector) {
        self.furthest = block;
        self.steps = 0;
        self.outcome = None;
        self.remaining = self.path_remaining(world, at);
    }

    /// Index of the next block to reach (the last one once the run has succeeded).
    pub fn next_index(&self, world: &PlatformWorld) -> usize {
        (self.furthest + 1).min(world.platforms().len() - 1)
    }

    /// Path still to go from `at`: to the next block's top centre, then along the track (0 on
    /// the last block: done, or waiting for the Generator's next).
    fn path_remaining(&self, world: &PlatformWorld, at: Vector) -> f32 {
        if self.furthest == world.platforms().len() - 1 {
            return 0.0;
        }
        let next = self.next_index(world);
        at.distance(world.platforms()[next].top) + self.path_after[next]
    }

    /// A finished run stays finished: the step of a decision after its end.
    pub fn finished(&self) -> Option<Step> {
        self.outcome.map(|outcome| Step::finished(outcome, 0.0))
    }

    /// Ends a decision: the runner now at `at` (its lowest point), on block `standing` if it
    /// stands on one. Pays the progress along the path, and ends the run on the last block of a
    /// closed track (success), below the lowest block (fell) or out of time.
    pub fn after_decision(
        &mut self,
        world: &PlatformWorld,
        (at, standing): (Vector, Option<usize>),
        rewards: &PlatformRewards,
    ) -> Step {
        self.steps += 1;
        if let Some(index) = standing {
            self.furthest = self.furthest.max(index);
        }
        let remaining = self.path_remaining(world, at);
        let reward = rewards.progress_per_metre * (self.remaining - remaining);
        self.remaining = remaining;
        let last = world.platforms().len() - 1;
        let outcome = if self.furthest == last && !self.open {
            Some(Outcome::Success)
        } else if at.y < world.lowest_top() - FALL_MARGIN {
            Some(Outcome::Fell)
        } else if self.steps >= self.max_steps {
            Some(Outcome::TimedOut)
        } else {
            None
        };
        self.outcome = outcome;
        Step::after(outcome, reward, rewards.success, rewards.failure)
    }

    /// Whether the runner stands on the newest block of a growing track: the Generator's turn
    /// to place the next one.
    pub fn awaits_platform(&self, world: &PlatformWorld) -> bool {
        self.open && self.outcome.is_none() && self.furthest == world.platforms().len() - 1
    }

    /// Highest block index stood on so far (0 is the start block).
    pub fn furthest(&self) -> usize {
        self.furthest
    }

    /// Fraction of the blocks reached, in [0, 1].
    pub fn progress(&self, world: &PlatformWorld) -> f64 {
        self.furthest as f64 / (world.platforms().len() - 1).max(1) as f64
    }

    /// Decisions taken so far.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Decisions allowed.
    pub fn max_steps(&self) -> u32 {
        self.max_steps
    }

    /// The share of the time allowed still left, in [0, 1].
    pub fn time_left(&self) -> f32 {
        1.0 - self.steps as f32 / self.max_steps as f32
    }

    /// How the run ended, once it has.
    pub fn outcome(&self) -> Option<Outcome> {
        self.outcome
    }
}
