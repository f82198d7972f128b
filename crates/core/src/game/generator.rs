//! The Generator's side of either game (docs/spec.md §1 and §2): a track under construction
//! ([`TrackBuild`]: what the Generator sees, what its action places), its rewards, and a
//! [`Match`]: one Generator building a level while one Solver plays it, written once for both
//! games. The platform Generator places the next block when the Solver stands on the newest one;
//! the racing Generator places the next segment when the car comes within
//! [`super::racing::generator::REQUEST_DISTANCE`] (65 m) of the road's end. The Generator's
//! episode ends with the Solver's run, or, with [`GeneratorRewards::retries`], with its last
//! try on a piece it keeps failing (a failed run starts again on that piece).
//!
//! Rewards follow the paper's eq. 1 with a vector of aux inputs λᵢ, each with weights αᵢ (on the
//! Generator's own, internal reward) and βᵢ (on the reward from the Solver's behaviour):
//! - progress: `progress_per_metre` for every metre the Solver's furthest piece comes closer to
//!   the goal, whatever λ;
//! - the Solver fails: `failure · Σ βᵢ λᵢ` (with the default `failure = -10` and β = 1: -10·λ,
//!   +10 at λ = -1, the sign docs/spec.md §2 decides);
//! - each piece placed: `step_penalty · Σ αᵢ min(λᵢ, 0)` (a small cost only when λ < 0: finish or
//!   fail fast);
//! - racing: each Solver step with the car in the air, `air_step · Σ βᵢ max(-λᵢ, 0)` (only when
//!   λ < 0);
//! - an invalid placement (overlap, crossing, obstacle) or a track that runs out of pieces before
//!   the goal: `invalid`, and the match ends;
//! - with retries, the failure term instead: [`GeneratorRewards::on_piece_failure`] at the
//!   piece where each failure happens.
//!
//! A paced match ([`MatchPacing`]) changes λ along the track: each piece is built, and each of
//! the terms above paid, at the λ of the piece it belongs to (the failure and air terms at the
//! piece the Solver is on), so failing the Solver pays only where λ asks for it.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::{GameSpec, SolverEnv, Step};
use crate::level::Track;
use crate::level::stats::Outcome;

/// The weights of one aux input in the Generator's reward (paper eq. 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AuxWeights {
    /// α: weight on the Generator's internal reward (the per-piece cost when λ < 0).
    pub alpha: f32,
    /// β: weight on the external reward (the Solver's failure, its air time).
    pub beta: f32,
}

/// The Generator's reward terms (docs/spec.md §2); see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GeneratorRewards {
    /// Per metre the Solver's furthest piece comes closer to the goal.
    pub progress_per_metre: f32,
    /// Scaled by Σ βᵢ λᵢ when the Solver fails.
    pub failure: f32,
    /// Scaled by Σ αᵢ min(λᵢ, 0) for each piece placed.
    pub step_penalty: f32,
    /// Scaled by Σ βᵢ max(-λᵢ, 0) for each Solver step in the air (racing; 0 turns it off).
    pub air_step: f32,
    /// An invalid piece, or no goal within the piece budget: the match ends.
    pub invalid: f32,
    /// Tries the Solver has again on a piece it failed, from that piece's start, before the
    /// match ends (0: it ends at the first failure, the paper's match). With retries every
    /// failure is paid where it happens ([`GeneratorRewards::on_piece_failure`]), so a late
    /// failure is worth no more than an early one, and a piece that fails again and again (a
    /// wall) costs more than it pays.
    pub retries: u32,
    /// With retries: the hazard per piece (the Solver's chance to fail a piece) that pays best at
    /// λ = -1, falling linearly to 0 at λ = 0.
    pub hazard_at_hardest: f32,
    /// With retries: the weight of a piece's first failure at λ < 0, times its share of the way
    /// to the goal (so the term does not grow with the number of pieces).
    pub piece_failure_weight: f32,
    /// The weights of each aux input (both games use one).
    pub aux: Vec<AuxWeights>,
    /// The weight of each of the game's style knobs ([`GeneratorGame::KNOBS`], in order); none:
    /// the Generator has no knobs (it neither observes nor is paid for them).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub knobs: Vec<f32>,
    /// Set by training while its Solver is below the hard-success floor, never read from a
    /// file: the terms paid at λ < 0 (the Solver's failure, the piece cost, air time) are paid
    /// as at λ = 0, that is not at all.
    #[serde(skip)]
    pub hard_side_unpaid: bool,
}

impl Default for GeneratorRewards {
    fn default() -> Self {
        Self {
            progress_per_metre: 0.1,
            failure: -10.0,
            step_penalty: 0.1,
            air_step: 0.0,
            invalid: -10.0,
            retries: 0,
            hazard_at_hardest: 0.05,
            piece_failure_weight: 10.0,
            aux: vec![AuxWeights {
                alpha: 1.0,
                beta: 1.0,
            }],
            knobs: Vec::new(),
            hard_side_unpaid: false,
        }
    }
}

impl GeneratorRewards {
    /// The reward when the Solver fails, at aux inputs `aux`.
    pub fn on_failure(&self, aux: &[f32]) -> f32 {
        self.failure * self.weighted(aux, |w, l| w.beta * l)
    }

    /// With retries, the reward for the Solver's failure on a piece that takes `share` of the way
    /// to the goal, at aux inputs `aux`; `repeat`: it has failed this piece before. At λ ≥ 0
    /// every failure is charged [`GeneratorRewards::on_failure`]. At λ < 0 the first failure
    /// pays `on_failure · piece_failure_weight · share` and each repeat costs that times
    /// `c = (1 - h)² / (1 - (1 - h)²)`, with `h` the hazard λ asks for: a piece the Solver fails
    /// with chance `p` (and retries) earns `p - c·p²/(1 - p)` in expectation, most at `p = h`.
    pub fn on_piece_failure(&self, aux: &[f32], share: f64, repeat: bool) -> f32 {
        let charge = self.on_failure(aux);
        if charge <= 0.0 {
            return charge;
        }
        let pay = charge * self.piece_failure_weight * share as f32;
        if !repeat {
            return pay;
        }
        let hardness = (-aux.first().copied().unwrap_or(0.0)).clamp(0.0, 1.0);
        let hazard = (self.hazard_at_hardest * hardness).clamp(1e-3, 0.99);
        let kept = (1.0 - hazard).powi(2);
        -pay * kept / (1.0 - kept)
    }

    /// The reward for placing a piece, at aux inputs `aux`.
    pub fn per_piece(&self, aux: &[f32]) -> f32 {
        self.step_penalty * self.weighted(aux, |w, l| w.alpha * l.min(0.0))
    }

    /// The reward for one Solver step in the air, at aux inputs `aux`.
    pub fn per_air_step(&self, aux: &[f32]) -> f32 {
        self.air_step * self.weighted(aux, |w, l| w.beta * (-l).max(0.0))
    }

    /// The reward for placing a piece whose style measures `measures` (each in [-1, 1]) at knob
    /// values `knobs`: Σ wᵢ kᵢ mᵢ, so a knob at +1 pays pieces that measure high, at -1 pieces
    /// that measure low, and at 0 nothing.
    pub fn per_style(&self, knobs: &[f32], measures: &[f32]) -> f32 {
        self.knobs
            .iter()
            .zip(knobs)
            .zip(measures)
            .map(|((w, k), m)| w * k * m)
            .sum()
    }

    fn weighted(&self, aux: &[f32], term: impl Fn(&AuxWeights, f32) -> f32) -> f32 {
        let paid = |l: f32| if self.hard_side_unpaid { l.max(0.0) } else { l };
        self.aux
            .iter()
            .zip(aux)
            .map(|(w, &l)| term(w, paid(l)))
            .sum()
    }
}

/// What a Generator's placement led to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// Placed; the track goes on.
    Placed,
    /// Placed, and it reaches the goal: the track is complete.
    Completed,
    /// It overlaps or crosses the track, or runs into an obstacle: the match ends.
    Invalid,
    /// The track already holds its budget of pieces without reaching the goal: the match ends.
    OutOfPieces,
}

impl Placement {
    /// Whether the placement ends the Generator's episode as invalid.
    pub fn is_invalid(self) -> bool {
        matches!(self, Placement::Invalid | Placement::OutOfPieces)
    }
}

/// A track the Generator is building, with its goal and piece budget.
pub trait TrackBuild: Clone + Send + Sync {
    /// The point the track must reach.
    fn goal(&self) -> [f64; 3];
    /// Pieces placed so far.
    fn piece_count(&self) -> usize;
    /// Who the track is made for and played by in a match.
    fn player(&self) -> &super::Player;
    /// Writes the Generator's observation at aux inputs `aux` into `out`.
    fn observe(&self, aux: &[f32], out: &mut [f32]);
    /// Places the piece a policy's action row (unbounded samples, clipped here) stands for.
    fn place(&mut self, row: &[f32]) -> Placement;
    /// Distance from where piece `k` leaves the Solver (0: the start) to the goal, m.
    fn distance_to_goal(&self, k: usize) -> f64;
    /// The style of piece `piece` (0: the first placed), one measure in [-1, 1] per knob of the
    /// game ([`GeneratorGame::KNOBS`]), into `out`.
    fn piece_style(&self, piece: usize, out: &mut [f32]);
    /// Two numbers per piece that the training metrics average ([`GeneratorGame::PIECE_FEATURES`]).
    fn piece_features(&self) -> Vec<[f64; 2]>;
    /// The finished track.
    fn into_track(self) -> Track;
    /// The state the Generator's observation is computed from, by name (the golden episodes of
    /// docs/engines.md): positions and headings in the world, and what each plan-view ray found.
    fn port_state(&self) -> super::PortState;
    /// What the action → piece mapping reads besides [`Self::port_state`], by name (the golden
    /// episodes' `piece_rules`; none for a game whose golden episodes record no pieces).
    fn port_piece_rules(&self) -> std::collections::BTreeMap<String, Vec<f64>> {
        Default::default()
    }
    /// The piece the action `row` stands for on this track, by the level file's parameter
    /// names, as placing it computes it (none: not recorded).
    fn port_piece(&self, _row: &[f32]) -> Option<std::collections::BTreeMap<String, f64>> {
        None
    }
}

/// Names and values, as a port's records write them.
pub fn named<const N: usize, T: Clone>(
    pairs: [(&str, T); N],
) -> std::collections::BTreeMap<String, T> {
    pairs
        .into_iter()
        .map(|(name, value)| (name.to_string(), value))
        .collect()
}

/// A game whose levels a Generator builds: its track under construction, the Generator's
/// observation and actions as a policy card names them, and how the Solver's environment grows
/// with the track.
pub trait GeneratorGame: GameSpec {
    /// The game's track under construction.
    type Build: TrackBuild;
    /// The Generator's observation, named parts in order.
    const GENERATOR_OBSERVATION_LAYOUT: &'static [(&'static str, usize)];
    /// The Generator's actions, in the policy's order.
    const GENERATOR_ACTIONS: &'static [&'static str];
    /// The piece budget of a Generator's track by default.
    const DEFAULT_MAX_PIECES: usize;
    /// The most pieces a level of the game may hold.
    const MAX_PIECES: usize;
    /// The style knobs a Generator of the game may take beside λ, in order.
    const KNOBS: &'static [Knob];
    /// The names of the two [`TrackBuild::piece_features`], as the metrics columns call them.
    const PIECE_FEATURES: [&'static str; 2];
    /// The game's training recipe: a training configuration (`train --config`'s YAML) laid
    /// over the defaults, which are the platform game's ("{}": nothing changed).
    const RECIPE: &'static str;
    /// The Generator reward defaults of the game.
    fn default_rewards() -> GeneratorRewards;
    /// The empty track of `seed`: goal (drawn unless given), start and scene drawn from the seed
    /// as the rules draw them, and the stream the Generator's sampling continues from. Racing
    /// scenes get `obstacles` obstacles.
    fn new_build(
        seed: u64,
        goal: Option<[f64; 3]>,
        limits: BuildLimits,
        obstacles: u32,
    ) -> (Self::Build, ChaCha8Rng);
    /// A track holding the first `pieces` pieces of `track` (its start, goal and obstacles too),
    /// for the Generator to continue; `Err` says why it cannot (not this game, too many pieces,
    /// the prefix already reaches the goal).
    fn kept_build(
        track: &Track,
        goal: [f64; 3],
        pieces: usize,
        limits: BuildLimits,
    ) -> Result<Self::Build, String>;
    /// The Solver's environment on a track with its first piece placed, still growing unless
    /// `complete` (the first piece reaches the goal).
    fn open_env(build: &Self::Build, complete: bool) -> Self::Env;
    /// Adds the newest piece of `build` to the environment; `complete`: it reaches the goal.
    fn extend_env(env: &mut Self::Env, build: &Self::Build, complete: bool);
    /// Whether the Solver has come close enough to the newest piece to ask for the next.
    fn wants_piece(env: &Self::Env) -> bool;
    /// The index of the furthest piece the Solver has left behind (0: the start), as
    /// [`TrackBuild::distance_to_goal`] counts.
    fn furthest_piece(env: &Self::Env) -> usize;
    /// Steps the Solver has spent in the air in this run.
    fn air_steps(env: &Self::Env) -> u32;
    /// Starts the Solver again (seeded `seed`) at the start of the piece after `piece`, the
    /// furthest it had left behind ([`GeneratorGame::furthest_piece`]), as after a reset.
    fn respawn(env: &mut Self::Env, piece: usize, seed: u64);
}

/// How far, in degrees, the racing Generator's curve action may ask to turn from the goal's
/// bearing by default: with 30 (the segment's own ±30° limit) the road keeps within about 30°
/// of the bearing and cannot bend away from the goal and back. A Generator's card records its
/// own.
pub const DEFAULT_CURVE_OFFSET: f64 = 30.0;

/// What bounds a Generator's track besides its actions (a Generator's card records both).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildLimits {
    /// The piece budget (the Generator's observation counts down from it).
    pub max_pieces: usize,
    /// Racing: how far, in degrees, the curve action may ask to turn from the goal's bearing
    /// (`segment_from_action` in `crates/core/src/game/racing/generator.rs`); the platform game ignores it.
    pub curve_offset: f64,
    /// Who the track is made for and played by in a match: the platform keeps every jump
    /// within the player's reach, and the Solver plays with its abilities.
    pub player: super::Player,
    /// Platform: the runs of the reach measurement's eight a jump must be cleared in for the
    /// Generator to place it (`Reach::of_player_in` in `crates/core/src/game/platform/reach.rs`);
    /// none: all of them, the reach table the rules keep to. Other games ignore it.
    pub reach_runs: Option<u64>,
}

impl BuildLimits {
    /// The defaults of game `G`, for the built-in player.
    pub fn default_for<G: GeneratorGame>() -> Self {
        Self {
            max_pieces: G::DEFAULT_MAX_PIECES,
            curve_offset: DEFAULT_CURVE_OFFSET,
            player: super::Player::default(),
            reach_runs: None,
        }
    }
}

/// Checks a kept prefix of `pieces` of a level's `of` pieces: they exist, and leave the
/// Generator a piece to place.
pub(crate) fn check_kept(pieces: usize, of: usize, limits: BuildLimits) -> Result<(), String> {
    if pieces > of {
        return Err(format!("the level has only {of} pieces, not {pieces}"));
    }
    if pieces >= limits.max_pieces {
        return Err(format!(
            "the Generator places at most {} pieces in all, so it cannot continue after {pieces}",
            limits.max_pieces
        ));
    }
    Ok(())
}

/// The error of a kept prefix that already reaches its goal.
pub(crate) fn prefix_reaches_goal(pieces: usize) -> String {
    format!("its first {pieces} pieces already reach the goal: keep fewer")
}

/// A style knob of a game's Generator: a value in [-1, 1] asked of a level beside λ (0: no
/// preference), paid for piece by piece ([`GeneratorRewards::per_style`]) by the piece's own
/// measure of the style ([`TrackBuild::piece_style`]); a level's measure is the mean over its
/// pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Knob {
    /// Its name, as `--aux` and the level file write it.
    pub name: &'static str,
    /// What -1 and +1 ask for, in words.
    pub meaning: &'static str,
}

pub use crate::level::KNOBS_PART;

/// Writes the Generator's observation of `build` at aux inputs `aux` into `out`: the game's, then
/// the values of the knobs it takes (`knobs`, none for a Generator without knobs), then, for an
/// ability-aware Generator (`out` [`MAIN_ABILITIES`](crate::level::profile::MAIN_ABILITIES)
/// longer), the main abilities of the player the track is made for, relative to ours.
pub fn observe_build<G: GeneratorGame>(
    build: &G::Build,
    aux: &[f32],
    knobs: &[f32],
    out: &mut [f32],
) {
    let (game, rest) = out.split_at_mut(observation_size::<G>());
    build.observe(aux, game);
    let (knob_slots, abilities) = rest.split_at_mut(knobs.len());
    knob_slots.copy_from_slice(knobs);
    if !abilities.is_empty() {
        let played = build
            .player()
            .abilities
            .unwrap_or(crate::level::profile::Abilities::default_of(G::GAME));
        abilities.copy_from_slice(&played.relative_main());
    }
}

/// Length of the Generator's observation vector of game `G`.
pub fn observation_size<G: GeneratorGame>() -> usize {
    G::GENERATOR_OBSERVATION_LAYOUT.iter().map(|(_, k)| k).sum()
}

/// λ that changes once along a match's track: `before` up to the fraction `switch` of the
/// start-to-goal distance, `after` from there (a piece takes the value where it begins, as
/// `generate --aux-curve` builds a level).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatchPacing {
    /// λ up to `switch`.
    pub before: f32,
    /// λ from `switch` on.
    pub after: f32,
    /// The fraction of the start-to-goal distance where λ changes.
    pub switch: f64,
}

/// One Generator building a level while one Solver plays it.
pub struct Match<G: GeneratorGame> {
    /// λ of the match (a paced match: where it begins).
    pub aux: Vec<f32>,
    /// The values of the knobs the Generator takes (none: it takes none).
    pub knobs: Vec<f32>,
    pacing: Option<MatchPacing>,
    /// λ of each piece placed (all `aux` unless paced).
    piece_aux: Vec<f32>,
    build: G::Build,
    /// The Solver's run, from the first piece on.
    env: Option<G::Env>,
    solver_seed: u64,
    complete: bool,
    /// The furthest piece the Solver had left behind when the Generator was last paid.
    paid_up_to: usize,
    air_paid: u32,
    /// With retries: the piece after which the Solver last failed, and how often in a row.
    failed_after: usize,
    failures_here: u32,
    /// How the Solver's first failed run of the match ended (none: no run failed).
    first_failure: Option<Outcome>,
    /// The match has ended: the Solver completed the track, or failed with no retry left.
    over: bool,
}

impl<G: GeneratorGame> Match<G> {
    /// A new match on an empty track; the Generator places the first piece next, and the
    /// Solver's run (seeded `solver_seed`) starts on it.
    pub fn new(build: G::Build, aux: Vec<f32>, solver_seed: u64) -> Self {
        Self {
            aux,
            knobs: Vec::new(),
            pacing: None,
            piece_aux: Vec::new(),
            build,
            env: None,
            solver_seed,
            complete: false,
            paid_up_to: 0,
            air_paid: 0,
            failed_after: 0,
            failures_here: 0,
            first_failure: None,
            over: false,
        }
    }

    /// Whether the match has ended (the Solver completed the track, or failed with no retry
    /// left); a Solver run that fails with a retry left starts again and the match goes on.
    pub fn over(&self) -> bool {
        self.over
    }

    /// How the match ended for the Solver: success only if no run of it failed.
    pub fn solver_outcome(&self) -> Outcome {
        self.first_failure.unwrap_or(Outcome::Success)
    }

    /// The share of the way to the goal that the piece after `piece` covers (0 for one that
    /// leads away from it).
    fn share_after(build: &G::Build, piece: usize) -> f64 {
        let whole = build.distance_to_goal(0).max(1e-9);
        let next = (piece + 1).min(build.piece_count());
        ((build.distance_to_goal(piece) - build.distance_to_goal(next)) / whole).max(0.0)
    }

    /// The same match with the Generator's knobs at `knobs`.
    pub fn with_knobs(mut self, knobs: Vec<f32>) -> Self {
        self.knobs = knobs;
        self
    }

    /// The style reward for the piece placed last ([`GeneratorRewards::per_style`]); 0 for a
    /// Generator without knobs.
    pub fn placed_style_reward(&self, rewards: &GeneratorRewards) -> f32 {
        let n = self.build.piece_count();
        if self.knobs.is_empty() || n == 0 {
            return 0.0;
        }
        let mut measures = vec![0.0; self.knobs.len()];
        self.build.piece_style(n - 1, &mut measures);
        rewards.per_style(&self.knobs, &measures)
    }

    /// The same match with λ changing along the track (one aux input).
    pub fn paced(mut self, pacing: MatchPacing) -> Self {
        self.aux = vec![pacing.before];
        self.pacing = Some(pacing);
        self
    }

    /// The λ curve of a paced match, if it is one.
    pub fn pacing(&self) -> Option<MatchPacing> {
        self.pacing
    }

    /// The track built so far.
    pub fn build(&self) -> &G::Build {
        &self.build
    }

    /// A paced match's λ for the next piece, at the fraction of the way the track has covered
    /// (none: the match has one λ, `aux`).
    fn next_paced_aux(&self) -> Option<f32> {
        let pacing = self.pacing?;
        let whole = self.build.distance_to_goal(0);
        let left = self.build.distance_to_goal(self.build.piece_count());
        let covered = crate::level::pacing::covered(whole, left);
        Some(if covered < pacing.switch {
            pacing.before
        } else {
            pacing.after
        })
    }

    /// λ of piece `k` (0: the first placed; beyond the last: the last's).
    pub fn piece_aux(&self, k: usize) -> &[f32] {
        match self.pacing {
            None => &self.aux,
            Some(_) => self
                .piece_aux
                .get(k.min(self.piece_aux.len().saturating_sub(1)))
                .map_or(&self.aux[..], std::slice::from_ref),
        }
    }

    /// λ of the piece placed last (valid or not).
    pub fn placed_aux(&self) -> &[f32] {
        self.piece_aux(usize::MAX)
    }

    /// The seed the match was made from (its Solver's run is reset with it).
    pub fn seed(&self) -> u64 {
        self.solver_seed
    }

    /// The Solver's run (once the first piece is placed).
    pub fn env(&self) -> &G::Env {
        self.env
            .as_ref()
            .expect("the Solver plays once the first piece is placed")
    }

    /// Whether the Solver's run has begun (the first piece is placed).
    pub fn started(&self) -> bool {
        self.env.is_some()
    }

    /// Whether it is the Generator's turn: at the start, and whenever the Solver has come close
    /// to the newest piece of an unfinished track.
    pub fn needs_piece(&self) -> bool {
        !self.complete && self.env.as_ref().is_none_or(|env| G::wants_piece(env))
    }

    /// The Generator's observation, into `out`.
    pub fn observe_generator(&self, out: &mut [f32]) {
        match self.next_paced_aux() {
            Some(aux) => observe_build::<G>(&self.build, &[aux], &self.knobs, out),
            None => observe_build::<G>(&self.build, &self.aux, &self.knobs, out),
        }
    }

    /// Places the Generator's piece (one action row).
    pub fn place(&mut self, row: &[f32]) -> Placement {
        let paced = self.next_paced_aux();
        let placement = self.build.place(row);
        self.piece_aux.extend(paced);
        if placement.is_invalid() {
            return placement;
        }
        self.complete = placement == Placement::Completed;
        match &mut self.env {
            Some(env) => G::extend_env(env, &self.build, self.complete),
            None => {
                let mut env = G::open_env(&self.build, self.complete);
                env.reset(self.solver_seed);
                self.env = Some(env);
            }
        }
        placement
    }

    /// Steps the Solver; returns its step and the Generator's reward from it (progress toward
    /// the goal, air time, and the failure term when the run failed).
    pub fn step_solver(
        &mut self,
        action: <G::Env as SolverEnv>::Action,
        rewards: &GeneratorRewards,
    ) -> (Step, f32) {
        let env = self
            .env
            .as_mut()
            .expect("the Solver plays once the first piece is placed");
        let step = env.step(action);
        let mut generator = 0.0;
        let furthest = G::furthest_piece(env);
        if furthest > self.paid_up_to {
            let gained = self.build.distance_to_goal(self.paid_up_to)
                - self.build.distance_to_goal(furthest);
            generator += rewards.progress_per_metre * gained as f32;
            self.paid_up_to = furthest;
        }
        let air = G::air_steps(env);
        let failed = step.outcome.is_some_and(|o| o != Outcome::Success);
        // With retries, a repeat: the Solver failed after this same piece the time before.
        let repeat = self.failures_here > 0 && furthest == self.failed_after;
        {
            // λ of the piece the Solver is on: the one after those it has left behind.
            let aux = self.piece_aux(furthest);
            if air > self.air_paid {
                generator += rewards.per_air_step(aux) * (air - self.air_paid) as f32;
            }
            if failed && rewards.retries == 0 {
                generator += rewards.on_failure(aux);
            } else if failed {
                let share = Self::share_after(&self.build, furthest);
                generator += rewards.on_piece_failure(aux, share, repeat);
            }
        }
        self.air_paid = self.air_paid.max(air);
        match step.outcome {
            None => {}
            Some(Outcome::Success) => self.over = true,
            Some(outcome) => {
                self.first_failure.get_or_insert(outcome);
                self.failed_after = furthest;
                self.failures_here = if repeat { self.failures_here + 1 } else { 1 };
                if self.failures_here > rewards.retries {
                    self.over = true;
                } else {
                    let seed = self.solver_seed.wrapping_add(u64::from(self.failures_here));
                    let env = self.env.as_mut().expect("the Solver is playing");
                    G::respawn(env, furthest, seed);
                    self.air_paid = 0;
                }
            }
        }
        (step, generator)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failure_piece_and_air_rewards_follow_the_sign_of_aux() {
        let r = GeneratorRewards {
            air_step: 0.05,
            ..GeneratorRewards::default()
        };
        assert_eq!(r.on_failure(&[-1.0]), 10.0);
        assert_eq!(r.on_failure(&[1.0]), -10.0);
        assert_eq!(r.on_failure(&[0.0]), 0.0);
        assert_eq!(r.per_piece(&[1.0]), 0.0);
        assert_eq!(r.per_piece(&[0.5]), 0.0);
        assert!((r.per_piece(&[-0.5]) + 0.05).abs() < 1e-6);
        assert_eq!(r.per_air_step(&[0.5]), 0.0, "air pays only when λ < 0");
        assert!((r.per_air_step(&[-1.0]) - 0.05).abs() < 1e-6);
        assert!((r.per_air_step(&[-0.5]) - 0.025).abs() < 1e-6);
        let two = GeneratorRewards {
            aux: vec![
                AuxWeights {
                    alpha: 1.0,
                    beta: 1.0,
                },
                AuxWeights {
                    alpha: 0.0,
                    beta: 0.5,
                },
            ],
            ..GeneratorRewards::default()
        };
        assert_eq!(two.on_failure(&[1.0, -1.0]), -10.0 + 5.0);
    }

    #[test]
    fn with_the_hard_side_unpaid_only_the_easy_side_is_paid() {
        let r = GeneratorRewards {
            air_step: 0.05,
            retries: 2,
            hard_side_unpaid: true,
            ..GeneratorRewards::default()
        };
        assert_eq!(r.on_failure(&[-1.0]), 0.0);
        assert_eq!(r.on_piece_failure(&[-1.0], 0.5, false), 0.0);
        assert_eq!(r.on_piece_failure(&[-1.0], 0.5, true), 0.0);
        assert_eq!(r.per_piece(&[-1.0]), 0.0);
        assert_eq!(r.per_air_step(&[-1.0]), 0.0);
        assert_eq!(
            r.on_failure(&[1.0]),
            -10.0,
            "failing an easy level still costs"
        );
        assert_eq!(r.on_piece_failure(&[0.5], 0.5, true), -5.0);
    }

    #[test]
    fn a_knob_pays_pieces_that_measure_its_way_and_nothing_at_zero() {
        let none = GeneratorRewards::default();
        assert_eq!(none.per_style(&[1.0, 1.0], &[1.0, 1.0]), 0.0, "no knobs");
        let r = GeneratorRewards {
            knobs: vec![0.5, 2.0],
            ..GeneratorRewards::default()
        };
        assert_eq!(r.per_style(&[1.0, 0.0], &[0.8, 1.0]), 0.4);
        assert_eq!(r.per_style(&[-1.0, 0.0], &[0.8, 1.0]), -0.4);
        assert_eq!(r.per_style(&[0.0, -0.5], &[0.8, -1.0]), 1.0);
        assert_eq!(r.per_style(&[0.0, 0.0], &[1.0, 1.0]), 0.0);
    }
}
