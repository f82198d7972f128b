//! What the layers above `game` know of a game as plain data: the names of its pieces and its
//! scripted player, its evaluation scenes, the columns its tables report, the paper's figures.
//! Each game's folder holds its own (`FACTS`, [`GameSpec::FACTS`]); [`facts`] turns a runtime
//! [`Game`] into them. Code that needs the game's types instead goes through [`GameSpec`] and
//! one dispatch per command ([`for_game!`](crate::for_game)).

use super::GameSpec;
use crate::level::{Game, Level};

/// One game's facts.
#[derive(Debug)]
pub struct GameFacts {
    /// The game.
    pub game: Game,
    /// A piece, and several (`block`/`blocks`, `segment`/`segments`).
    pub piece: &'static str,
    /// Several pieces (`blocks`, `segments`).
    pub pieces: &'static str,
    /// Where a failed run is counted: "on the way to" a block, "on" a segment.
    pub failed_at: &'static str,
    /// Who a profile's abilities describe: "character", "car".
    pub player_kind: &'static str,
    /// How a failed run can end: each ending's count in the statistics (the key of
    /// [`SolverStats::ending_count`](crate::level::stats::SolverStats::ending_count)) and its
    /// words, in the order a report lists them.
    pub endings: &'static [(&'static str, &'static str)],
    /// The most obstacles a level of the game holds (0: the game has none).
    pub max_obstacles: usize,
    /// Whether the Generator's curve offset (its card's `curve_offset`) steers it.
    pub curve_offset: bool,
    /// The runs a measured reach counts cleared jumps in, where the Generator's jumps are cut to
    /// one (platform: 8): its card's `reach_runs` lies within [1, that].
    pub reach_runs: Option<u64>,
    /// Obstacles in each evaluation and designer scene (the racing Generator trained with 3).
    pub scene_obstacles: u32,
    /// The controllability table's piece columns: (name, unit), in [`piece_values`]'s order.
    pub piece_columns: &'static [(&'static str, &'static str)],
    /// Seconds a decision lasts, where the game measures air time (racing).
    pub air_time_step: Option<f64>,
    /// The range of goal distances and heights (m) the rules draw from; a goal set by hand
    /// stays within them.
    pub goal_distance: (f64, f64),
    /// The range of goal heights the rules draw from, m.
    pub goal_height: (f64, f64),
    /// How far one press of the designer's goal-distance keys moves the goal (m).
    pub goal_distance_step: f64,
    /// The paper's controllability figures at each λ of 1, 0.5, 0, -0.5, -1 (docs/spec.md §4),
    /// as the markdown table's last column reads...
    pub paper_controllability: [&'static str; 5],
    /// ...and its controllability table's header.
    pub controllability_header: &'static str,
    /// The paper's generalization figure per training mode (docs/spec.md §4).
    pub paper_generalization: [(&'static str, &'static str); 4],
    /// The Solver's and the Generator's observations: each part's name and width, and what it
    /// holds (frame, scale, sign, order), for a port of it (an export's sidecar).
    pub solver_observation: ObservationFacts,
    /// The Generator's observation.
    pub generator_observation: ObservationFacts,
}

/// An observation's parts in order, and what each holds.
#[derive(Debug)]
pub struct ObservationFacts {
    /// Each part's name and width, in order.
    pub layout: &'static [(&'static str, usize)],
    /// What each part holds, in the same order.
    pub meanings: &'static [&'static str],
}

impl GameFacts {
    /// `piece` or `pieces`.
    pub fn piece_name(&self, plural: bool) -> &'static str {
        if plural { self.pieces } else { self.piece }
    }

    /// The paper's generalization figure for a Solver trained in `mode` ("" for none).
    pub fn paper_generalization(&self, mode: &str) -> &'static str {
        self.paper_generalization
            .iter()
            .find(|(m, _)| *m == mode)
            .map_or("", |(_, figure)| figure)
    }
}

/// The facts of `game`.
pub fn facts(game: Game) -> &'static GameFacts {
    crate::for_game!(game, G => G::FACTS)
}

/// Each piece's parameters of `level`, as [`GameFacts::piece_columns`] names them.
pub fn piece_values(level: &Level) -> Vec<Vec<f64>> {
    crate::for_game!(level.game(), G => G::piece_values(level))
}
