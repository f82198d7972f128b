//! Where everything goes on screen, from the terminal size alone: the view draws into these
//! areas and the update hit-tests the mouse against them, so both agree.

use ratatui::layout::{Constraint, Layout, Rect};

/// The smallest terminal the designer lays out for.
pub const MIN_SIZE: (u16, u16) = (80, 24);
/// Text left and right of the slider track, on its line.
pub const SLIDER_LEFT: &str = "hard -1 ";
/// Text right of the slider track.
pub const SLIDER_RIGHT: &str = " +1 easy";
/// Room after the slider for the λ readout...
pub const SLIDER_READOUT: u16 = 11;
/// ...and for each style knob's, beside its name.
const KNOB_READOUT: u16 = 8;

/// The screen's areas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Areas {
    /// The title line.
    pub header: Rect,
    /// The controls box (slider, seed, goal), border included.
    pub controls: Rect,
    /// The slider's track: one row; its first column is λ = -1, its last λ = +1.
    pub slider: Rect,
    /// The line under the slider (seed and goal).
    pub settings: Rect,
    /// The plan of the level.
    pub map: Rect,
    /// The level's side profile, under the plan.
    pub profile: Rect,
    /// The Solver's statistics.
    pub stats: Rect,
    /// The bottom-right panel (failures, sweep or judges).
    pub panel: Rect,
    /// The footer line: hints and messages.
    pub footer: Rect,
}

impl Areas {
    /// The areas of a screen of this size.
    pub fn of(screen: Rect) -> Self {
        Self::with_knobs(screen, &[])
    }

    /// The areas of a screen of this size whose slider line also reads out the style knobs
    /// `knobs` (their names), after λ.
    pub fn with_knobs(screen: Rect, knobs: &[&str]) -> Self {
        let readout = SLIDER_READOUT
            + knobs
                .iter()
                .map(|name| name.chars().count() as u16 + KNOB_READOUT)
                .sum::<u16>();
        let [header, controls, main, footer] = Layout::vertical([
            Constraint::Length(1),
            Constraint::Length(4),
            Constraint::Fill(1),
            Constraint::Length(1),
        ])
        .areas(screen);
        let inner = Rect {
            x: controls.x + 1,
            y: controls.y + 1,
            width: controls.width.saturating_sub(2),
            height: controls.height.saturating_sub(2),
        };
        let left_text = SLIDER_LEFT.chars().count() as u16;
        let right_text = SLIDER_RIGHT.chars().count() as u16;
        let slider = Rect {
            x: inner.x + left_text,
            y: inner.y,
            width: inner.width.saturating_sub(left_text + right_text + readout),
            height: 1.min(inner.height),
        };
        let settings = Rect {
            y: inner.y + 1,
            height: inner.height.saturating_sub(1),
            ..inner
        };
        let [left, right] =
            Layout::horizontal([Constraint::Percentage(58), Constraint::Fill(1)]).areas(main);
        let [map, profile] =
            Layout::vertical([Constraint::Percentage(62), Constraint::Fill(1)]).areas(left);
        let [stats, panel] =
            Layout::vertical([Constraint::Length(10), Constraint::Fill(1)]).areas(right);
        Self {
            header,
            controls,
            slider,
            settings,
            map,
            profile,
            stats,
            panel,
            footer,
        }
    }
}

/// Whether the screen is large enough to lay out.
pub fn fits(screen: Rect) -> bool {
    screen.width >= MIN_SIZE.0 && screen.height >= MIN_SIZE.1
}
