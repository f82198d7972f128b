//! The bottom-right panel's third view: every judge's success on the level on screen, with its
//! interval, and the level's rating once all have played.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::Stylize;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};

use crate::shells::design::app::App;
use crate::shells::design::app::judging::{JudgePoint, PANEL_TRIALS};

pub fn judges(app: &App, frame: &mut Frame, area: Rect) {
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
