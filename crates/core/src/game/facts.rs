//! What the layers above `game` know of a game as plain data: the names of its pieces and its
//! scripted player, its evaluation scenes, the columns its tables report, the paper's figures.
//! [`facts`] is the one place that turns a runtime [`Game`] into them; code that needs the
//! game's types instead goes through [`GameSpec`](super::GameSpec) and one dispatch per command.

use crate::level::{Game, Level, Track};

/// One game's facts.
#[derive(Debug)]
pub struct GameFacts {
    pub game: Game,
    /// A piece, and several (`block`/`blocks`, `segment`/`segments`).
    pub piece: &'static str,
    pub pieces: &'static str,
    /// Where a failed run is counted: "on the way to" a block, "on" a segment.
    pub failed_at: &'static str,
    /// Obstacles in each evaluation and designer scene (the racing Generator trained with 3).
    pub scene_obstacles: u32,
    /// The controllability table's piece columns: (name, unit), in [`piece_values`]'s order.
    pub piece_columns: &'static [(&'static str, &'static str)],
    /// Seconds a decision lasts, where the game measures air time (racing).
    pub air_time_step: Option<f64>,
    /// The range of goal distances and heights (m) the rules draw from; a goal set by hand
    /// stays within them.
    pub goal_distance: (f64, f64),
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
    pub generator_observation: ObservationFacts,
}

/// An observation's parts in order, and what each holds.
#[derive(Debug)]
pub struct ObservationFacts {
    pub layout: &'static [(&'static str, usize)],
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

/// The platform game's facts.
pub const PLATFORM: GameFacts = GameFacts {
    game: Game::Platform,
    piece: "block",
    pieces: "blocks",
    failed_at: "on the way to",
    scene_obstacles: 0,
    piece_columns: &[("avg_block_distance", " m"), ("avg_block_size", " m")],
    air_time_step: None,
    goal_distance: super::platform::rules::GOAL_DISTANCE,
    goal_height: super::platform::rules::GOAL_HEIGHT,
    goal_distance_step: 5.0,
    paper_controllability: [
        "0.97, 6.73 m, 5.95 m", "0.92, 6.98 m, 5.77 m", "0.88, 7.15 m, 5.42 m",
        "0.74, 7.11 m, 4.52 m", "0.69, 7.46 m, 4.01 m",
    ],
    controllability_header: "| λ | success ratio | completed by any | avg block distance | avg block size | blocks | failures on the last block | on the worst block | levels | paper: success, distance, size |\n|---|---|---|---|---|---|---|---|---|---|\n",
    paper_generalization: [
        ("fixed-track", "0.081 ± 0.205, 0.20 (54 steps)"),
        ("rule-pcg", "0.233 ± 0.200, 0.95 (451 steps)"),
        ("fixed-aux", "0.173 ± 0.195, 0.90 (442 steps)"),
        ("arlpcg", "0.457 ± 0.211, 1.00 (467 steps)"),
    ],
    solver_observation: ObservationFacts {
        layout: &super::platform::env::OBSERVATION_LAYOUT,
        meanings: &super::platform::env::OBSERVATION_MEANINGS,
    },
    generator_observation: ObservationFacts {
        layout: &super::platform::generator::GENERATOR_OBSERVATION_LAYOUT,
        meanings: &super::platform::generator::GENERATOR_OBSERVATION_MEANINGS,
    },
};

/// The racing game's facts.
pub const RACING: GameFacts = GameFacts {
    game: Game::Racing,
    piece: "segment",
    pieces: "segments",
    failed_at: "on",
    scene_obstacles: super::racing::generator::MATCH_OBSTACLES,
    piece_columns: &[
        ("avg_segment_curve", "°"),
        ("avg_segment_length", " m"),
        ("avg_segment_height", " m"),
    ],
    air_time_step: Some(super::racing::car::DECISION_DT as f64),
    goal_distance: super::racing::rules::GOAL_DISTANCE,
    goal_height: super::racing::rules::GOAL_HEIGHT,
    goal_distance_step: 20.0,
    paper_controllability: [
        "0.99, 14.4°, 28.4 m, 1.5 m", "0.89, 14.7°, 27.1 m, 2.0 m", "0.77, 15.1°, 25.1 m, 2.5 m",
        "0.64, 15.3°, 23.0 m, 3.1 m", "0.61, 16.8°, 21.8 m, 3.9 m",
    ],
    controllability_header: "| λ | success ratio | completed by any | air time per run | avg segment curve | avg segment length | avg segment height change | segments | failures on the last segment | on the worst segment | tracks | paper: success, angle, length, height |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    paper_generalization: [
        ("fixed-track", "0.219 ± 0.280, 0.7 (431 m)"),
        ("rule-pcg", "0.174 ± 0.160, 0.9 (355 m)"),
        ("fixed-aux", "0.163 ± 0.138, 0.8 (382 m)"),
        ("arlpcg", "0.331 ± 0.225, 1.0 (507 m)"),
    ],
    solver_observation: ObservationFacts {
        layout: &super::racing::env::OBSERVATION_LAYOUT,
        meanings: &super::racing::env::OBSERVATION_MEANINGS,
    },
    generator_observation: ObservationFacts {
        layout: &super::racing::generator::GENERATOR_OBSERVATION_LAYOUT,
        meanings: &super::racing::generator::GENERATOR_OBSERVATION_MEANINGS,
    },
};

/// The facts of `game`.
pub fn facts(game: Game) -> &'static GameFacts {
    match game {
        Game::Platform => &PLATFORM,
        Game::Racing => &RACING,
    }
}

/// Each piece's parameters of `level`, as [`GameFacts::piece_columns`] names them (racing: the
/// curve's and the height change's size, whatever their sign).
pub fn piece_values(level: &Level) -> Vec<Vec<f64>> {
    match &level.track {
        Track::Platform(track) => track
            .block_params()
            .iter()
            .map(|b| vec![b.distance, b.size])
            .collect(),
        Track::Racing(track) => track
            .segments
            .iter()
            .map(|s| vec![s.curve.abs(), s.length, s.height.abs()])
            .collect(),
    }
}
