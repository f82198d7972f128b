//! The whole panel on the level on screen (`J`, and the `v` panel that shows it): every judge
//! of the policies' folder plays the level, and the level is rated on the Rasch scale, with the
//! figures `arlpcg verify LEVEL --panel --trials 40` gives for the exported file. An export of
//! a level the panel has measured records the panel in its statistics.

use std::sync::Arc;

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::Stylize;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};

use super::{App, Effect, SidePane};
use arlpcg_core::level::Level;
use arlpcg_core::level::stats::PanelStats;

/// Runs per judge.
pub const PANEL_TRIALS: u32 = 40;
/// The seed of each judge's first run (`verify`'s default).
pub const PANEL_SEED: u64 = 0;

/// One judge's runs, as they come in.
#[derive(Debug, Clone, PartialEq)]
pub enum JudgePoint {
    /// Not played yet.
    Pending,
    /// Played: its success.
    Played {
        /// Runs that reached the goal, as a share.
        success_ratio: f64,
        /// 95% Wilson score interval of the share.
        ci95: [f64; 2],
    },
}

/// The panel on one level.
#[derive(Debug, Clone, PartialEq)]
pub struct Judging {
    /// The request's number; answers to an older one are dropped.
    pub id: u64,
    /// The level it measures: a new level is measured afresh.
    pub level: Arc<Level>,
    /// Each judge's name and runs (empty until the panel is loaded).
    pub judges: Vec<(String, JudgePoint)>,
    /// Every judge's statistics and the level's rating, once all have played.
    pub stats: Option<PanelStats>,
    /// Why the panel could not play (a Solver file of the wrong game, say).
    pub error: Option<String>,
}

/// What the worker reports of a panel's play.
#[derive(Debug, Clone, PartialEq)]
pub enum PanelUpdate {
    /// The judges, in the order they play.
    Judges(Vec<String>),
    /// One judge has played.
    Played {
        /// The judge's place in the panel's order.
        index: usize,
        /// Runs that reached the goal, as a share.
        success_ratio: f64,
        /// 95% Wilson score interval of the share.
        ci95: [f64; 2],
    },
    /// All have played: the panel with the level's rating.
    Rated(Box<PanelStats>),
    /// The panel could not play, in words.
    Failed(String),
}

impl App {
    /// `J`: the whole panel plays the level on screen; the bottom-right panel shows it.
    pub(super) fn judge_level(&mut self) -> Vec<Effect> {
        self.panel = SidePane::Judges;
        let Some(level) = self.level.clone() else {
            self.complain("no level for the panel to play yet");
            return Vec::new();
        };
        let id = self.id();
        self.judging = Some(Judging {
            id,
            level: level.clone(),
            judges: Vec::new(),
            stats: None,
            error: None,
        });
        vec![Effect::Panel {
            id,
            level,
            folder: self.policies().folder(),
            trials: PANEL_TRIALS,
        }]
    }

    /// The panel, when it is shown, follows the level on screen.
    pub(super) fn judge_if_shown(&mut self) -> Vec<Effect> {
        let measured = self.judging.as_ref().map(|j| &j.level);
        if self.panel == SidePane::Judges && measured != self.level.as_ref() {
            self.judge_level()
        } else {
            Vec::new()
        }
    }

    pub(super) fn panel_update(&mut self, id: u64, update: PanelUpdate) {
        let Some(judging) = self.judging.as_mut().filter(|j| j.id == id) else {
            return;
        };
        match update {
            PanelUpdate::Judges(names) => {
                judging.judges = names
                    .into_iter()
                    .map(|n| (n, JudgePoint::Pending))
                    .collect();
            }
            PanelUpdate::Played {
                index,
                success_ratio,
                ci95,
            } => {
                if let Some(slot) = judging.judges.get_mut(index) {
                    slot.1 = JudgePoint::Played {
                        success_ratio,
                        ci95,
                    };
                }
            }
            PanelUpdate::Rated(stats) => judging.stats = Some(*stats),
            PanelUpdate::Failed(problem) => {
                judging.error = Some(problem.clone());
                self.complain(format!("the panel could not play: {problem}"));
            }
        }
    }

    /// The panel's statistics on the level on screen, once complete.
    pub(super) fn panel_on_screen(&self) -> Option<PanelStats> {
        let judging = self.judging.as_ref()?;
        (Some(&judging.level) == self.level.as_ref())
            .then(|| judging.stats.clone())
            .flatten()
    }
}

/// The bottom-right panel's third view: every judge's success on the level on screen, with
/// its interval, and the level's rating once all have played.
pub(crate) fn draw(app: &App, frame: &mut Frame, area: Rect) {
    let title = format!(" panel, {PANEL_TRIALS} runs each (v: failures) ");
    let block = Block::bordered().title(title);
    let Some(judging) = &app.judging else {
        let text = "press J: every judge plays the level on screen";
        frame.render_widget(
            Paragraph::new(text).wrap(Wrap { trim: true }).block(block),
            area,
        );
        return;
    };
    let mut lines: Vec<Line> = Vec::new();
    if judging.judges.is_empty() && judging.error.is_none() {
        lines.push(Line::from("loading the judges").dim());
    }
    let name_width = judging
        .judges
        .iter()
        .map(|(name, _)| name.chars().count())
        .max()
        .unwrap_or(0);
    // Name, ratio, interval and spaces take the rest of a line from the bar.
    let bar_width = (area.width as usize).saturating_sub(name_width + 22).max(1);
    for (name, point) in &judging.judges {
        let mut spans = vec![Span::raw(format!("{name:<name_width$} "))];
        match point {
            JudgePoint::Pending => spans.push(Span::raw("…").dim()),
            JudgePoint::Played {
                success_ratio,
                ci95,
            } => {
                let filled = (success_ratio * bar_width as f64).round() as usize;
                spans.push(Span::raw(format!(
                    "{success_ratio:.2} {:.2}-{:.2} ",
                    ci95[0], ci95[1]
                )));
                spans.push(Span::raw("█".repeat(filled)).cyan());
                spans.push(Span::raw("░".repeat(bar_width - filled.min(bar_width))).dim());
            }
        }
        lines.push(Line::from(spans));
    }
    if let Some(rating) = judging.stats.as_ref().and_then(|s| s.rating) {
        lines.push(Line::from(format!(
            "difficulty b {:+.2} (95% CI {:+.2} to {:+.2})",
            rating.b, rating.ci95[0], rating.ci95[1]
        )));
    }
    if let Some(problem) = &judging.error {
        lines.push(Line::from(problem.as_str()).red());
    }
    frame.render_widget(
        Paragraph::new(lines).wrap(Wrap { trim: true }).block(block),
        area,
    );
}
