//! The overlays drawn over the designer: the key help, the policy cards, a prompt, the question
//! before an export overwrites files.

use ratatui::Frame;
use ratatui::layout::{Constraint, Flex, Layout, Rect};
use ratatui::style::{Modifier, Style, Stylize};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Wrap};

use super::{KEYS, budget_unit};
use crate::shells::design::app::{App, Overlay};

fn centred(screen: Rect, width: u16, height: u16) -> Rect {
    let [row] = Layout::vertical([Constraint::Length(height.min(screen.height))])
        .flex(Flex::Center)
        .areas(screen);
    let [area] = Layout::horizontal([Constraint::Length(width.min(screen.width))])
        .flex(Flex::Center)
        .areas(row);
    area
}

pub(super) fn overlay(app: &App, frame: &mut Frame, screen: Rect) {
    match &app.overlay {
        Overlay::None => {}
        Overlay::Campaign => crate::shells::design::app::campaign::draw(app, frame, screen),
        Overlay::Help => {
            let lines: Vec<Line> = KEYS
                .iter()
                .map(|(keys, what)| {
                    Line::from(vec![
                        Span::styled(format!("{keys:<25}"), Style::new().bold()),
                        Span::raw(*what),
                    ])
                })
                .collect();
            let area = centred(screen, 78, KEYS.len() as u16 + 2);
            frame.render_widget(Clear, area);
            frame.render_widget(
                Paragraph::new(lines).block(Block::bordered().title(" keys (any key closes) ")),
                area,
            );
        }
        Overlay::Cards => {
            let mut lines = Vec::new();
            for (role, info) in [
                ("Generator", &app.policies().generator),
                ("Solver", &app.policies().solver),
            ] {
                match info {
                    Some(p) => {
                        let t = &p.card.training;
                        lines.push(Line::from(format!("{role}: {}", p.path.display())).bold());
                        lines.push(Line::from(format!(
                            "  {} {}, mode {}, {} {}, {:.0} min, seed {}",
                            p.card.game,
                            p.card.role,
                            t.mode,
                            t.steps,
                            budget_unit(p.card.role, p.card.game),
                            t.wall_time_s / 60.0,
                            t.seed
                        )));
                        let mut results: Vec<_> = p.card.results.iter().collect();
                        results.sort_by(|a, b| a.0.cmp(b.0));
                        for (k, v) in results {
                            lines.push(Line::from(format!("  {k}: {v:.3}")));
                        }
                        let resumed = match t.resumed_with.len() {
                            0 => String::new(),
                            n => format!(" (resumed {n}×)"),
                        };
                        lines.push(Line::from(format!("  command: {}{resumed}", t.command)).dim());
                    }
                    None => lines.push(Line::from(format!(
                        "{role}: none loaded ({})",
                        if role == "Generator" {
                            "levels come from the rules"
                        } else {
                            "the scripted controller plays"
                        }
                    ))),
                }
            }
            let area = centred(screen, 78, 20);
            frame.render_widget(Clear, area);
            frame.render_widget(
                Paragraph::new(lines)
                    .wrap(Wrap { trim: false })
                    .block(Block::bordered().title(" policy cards (any key closes) ")),
                area,
            );
        }
        Overlay::Prompt { kind, text } => {
            let area = centred(screen, 70, 3);
            frame.render_widget(Clear, area);
            frame.render_widget(
                Paragraph::new(Line::from(vec![
                    Span::raw(text.as_str()),
                    Span::raw("█").slow_blink(),
                ]))
                .block(
                    Block::bordered().title(format!(" {} (Enter: ok, Esc: cancel) ", kind.label())),
                ),
                area,
            );
        }
        Overlay::ConfirmOverwrite { paths } => {
            let mut lines = vec![Line::from("These files exist:")];
            lines.extend(
                paths
                    .iter()
                    .map(|p| Line::from(format!("  {}", p.display())).add_modifier(Modifier::BOLD)),
            );
            lines.push(Line::from("Overwrite them? y: yes, any other key: no"));
            let area = centred(screen, 70, lines.len() as u16 + 2);
            frame.render_widget(Clear, area);
            frame.render_widget(
                Paragraph::new(lines)
                    .wrap(Wrap { trim: false })
                    .block(Block::bordered().title(" export ").yellow()),
                area,
            );
        }
    }
}
