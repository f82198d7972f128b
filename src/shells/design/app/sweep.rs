//! The λ sweep (`w`, and the `v` panel that shows it): the Solver's success against λ for the
//! seed and goal on screen, one level per λ, drawn as the points come in.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::symbols::Marker;
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, Paragraph, Wrap};

use super::{App, Effect, SidePane};

/// The λ values of a sweep.
pub const SWEEP_AUX: [f64; 9] = [-1.0, -0.75, -0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0];
/// Trials per λ in a sweep.
pub const SWEEP_TRIALS: u32 = 40;
/// One λ of a sweep: its success ratio, or why it has none.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepPoint {
    /// Not measured yet.
    Pending,
    /// The success ratio measured.
    Success(f64),
    /// No level to measure, or the trials failed: why.
    NoLevel(String),
}

/// A λ sweep for the seed and goal it was started with.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The request's number; answers to an older one are dropped.
    pub id: u64,
    /// The seed the sweep was started with.
    pub seed: u64,
    /// Each λ with its point, in order.
    pub points: Vec<(f64, SweepPoint)>,
}

impl App {
    /// `w`: success against λ for this seed and goal, in the bottom-right panel.
    pub(super) fn sweep(&mut self) -> Vec<Effect> {
        let id = self.id();
        self.sweep = Some(Sweep {
            id,
            seed: self.seed,
            points: SWEEP_AUX
                .iter()
                .map(|&a| (a, SweepPoint::Pending))
                .collect(),
        });
        self.panel = SidePane::Sweep;
        vec![Effect::Sweep {
            id,
            game: self.game,
            seed: self.seed,
            goal: self.goal.position(),
            auxes: SWEEP_AUX.to_vec(),
            trials: SWEEP_TRIALS,
            profile: self.profile().profile.clone(),
            knobs: self.knob_values(),
        }]
    }

    /// One point of the sweep on screen came in.
    pub(super) fn sweep_point(&mut self, id: u64, index: usize, point: SweepPoint) {
        if let Some(sweep) = self.sweep.as_mut().filter(|s| s.id == id)
            && let Some(slot) = sweep.points.get_mut(index)
        {
            slot.1 = point;
        }
    }
}

/// The bottom-right panel's second view: success against λ as the sweep's points come in.
pub(crate) fn draw(app: &App, frame: &mut Frame, area: Rect) {
    let Some(sweep) = &app.sweep else {
        frame.render_widget(
            Paragraph::new("press w to sweep λ for this seed and goal")
                .wrap(Wrap { trim: true })
                .block(Block::bordered().title(" λ sweep (v: panel) ")),
            area,
        );
        return;
    };
    let points: Vec<(f64, f64)> = sweep
        .points
        .iter()
        .filter_map(|(aux, p)| match p {
            SweepPoint::Success(s) => Some((*aux, *s)),
            _ => None,
        })
        .collect();
    let pending = sweep
        .points
        .iter()
        .filter(|(_, p)| *p == SweepPoint::Pending)
        .count();
    let title = if pending > 0 {
        format!(" λ sweep, seed {} ({pending} to go) ", sweep.seed)
    } else {
        format!(" λ sweep, seed {} ", sweep.seed)
    };
    let dataset = Dataset::default()
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(Style::new().cyan())
        .data(&points);
    let chart = Chart::new(vec![dataset])
        .block(Block::bordered().title(title))
        .x_axis(
            Axis::default()
                .bounds([-1.0, 1.0])
                .labels(["-1", "0", "+1"]),
        )
        .y_axis(Axis::default().bounds([0.0, 1.0]).labels(["0", "0.5", "1"]));
    frame.render_widget(chart, area);
}
