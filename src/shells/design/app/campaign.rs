//! The campaign view (`o`, or `design --campaign DIR`): a campaign folder that `arlpcg
//! campaign` wrote, as one column per level (the success asked and measured, the panel's b,
//! the share of players who reach it and who quit on it) under the ramp drawn as bars, and
//! the funnel's end. `← →` select a level, `Enter` opens it on the designer's screen (its
//! Solver trials run as for any level), `R` searches the selected level anew (from a seed the
//! campaign has not used, with the designer's Generator, to its ramp point for the campaign's
//! judge), the panel rates the campaign again and its files are rewritten; `o` types another
//! folder, `Esc` closes the view.

use std::path::PathBuf;
use std::sync::Arc;

use ratatui::Frame;
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::layout::Rect;
use ratatui::style::{Style, Stylize};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph};

use super::{App, Effect, Loading, Overlay, PromptKind};
use crate::services::campaign::Campaign;
use arlpcg_core::level::Level;

/// A campaign read back from its folder.
#[derive(Debug, Clone, PartialEq)]
pub struct OpenedCampaign {
    /// The campaign's folder.
    pub folder: PathBuf,
    /// Its record (campaign.yaml).
    pub record: Campaign,
    /// Its levels, in order.
    pub levels: Vec<Arc<Level>>,
    /// The level just searched anew (`R`), if that is why it was read.
    pub regenerated: Option<usize>,
}

/// The campaign on view, and the level selected in it.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignView {
    /// The campaign.
    pub opened: OpenedCampaign,
    /// The selected level's index.
    pub selected: usize,
}

/// Width of one level's column.
const COLUMN: usize = 7;
/// Width of the row labels.
const LABEL: usize = 10;
/// Rows of the ramp's bars.
const BAR_ROWS: usize = 6;

impl App {
    /// `o`: the campaign's view when one is open, else the prompt for a folder.
    pub(super) fn campaign_key_o(&mut self) -> Vec<Effect> {
        match &self.campaign {
            Some(_) => self.overlay = Overlay::Campaign,
            None => {
                self.overlay = Overlay::Prompt {
                    kind: PromptKind::Campaign,
                    text: String::new(),
                }
            }
        }
        Vec::new()
    }

    /// A campaign folder typed at the prompt, or given to `design --campaign`.
    pub fn open_campaign(&mut self, folder: PathBuf) -> Vec<Effect> {
        self.say(format!("opening the campaign in {}", folder.display()));
        vec![Effect::OpenCampaign { folder }]
    }

    /// The worker read the campaign (or could not).
    pub(super) fn campaign_opened(&mut self, result: Result<Box<OpenedCampaign>, String>) {
        match result {
            Ok(opened) => {
                let selected = match opened.regenerated {
                    Some(k) => {
                        let entry = &opened.record.levels[k];
                        self.say(format!(
                            "level {} searched anew: {:.2} measured for {:.2} asked; the panel rated the campaign again and its files were rewritten",
                            k + 1,
                            entry.measured,
                            entry.asked
                        ));
                        k
                    }
                    None => {
                        self.say(format!(
                            "campaign: {} {} levels from {}",
                            opened.levels.len(),
                            opened.record.game,
                            opened.folder.display()
                        ));
                        0
                    }
                };
                self.campaign = Some(CampaignView {
                    opened: *opened,
                    selected,
                });
                self.overlay = Overlay::Campaign;
            }
            Err(problem) => self.complain(format!("no campaign opened: {problem}")),
        }
    }

    /// A key while the campaign view is up.
    pub(super) fn campaign_view_key(&mut self, key: KeyEvent) -> Vec<Effect> {
        let Some(view) = self.campaign.as_mut() else {
            return Vec::new();
        };
        let count = view.opened.levels.len();
        self.overlay = Overlay::Campaign;
        match key.code {
            KeyCode::Left => view.selected = view.selected.saturating_sub(1),
            KeyCode::Right => view.selected = (view.selected + 1).min(count.saturating_sub(1)),
            KeyCode::Home => view.selected = 0,
            KeyCode::End => view.selected = count.saturating_sub(1),
            KeyCode::Enter => return self.open_selected_level(),
            KeyCode::Char('R') => {
                let (folder, level) = (view.opened.folder.clone(), view.selected);
                let game = view.opened.record.game;
                if game != self.game {
                    self.complain(format!("a {game} campaign: Tab to {game} first"));
                    return Vec::new();
                }
                self.say(format!(
                    "searching level {} anew, then the panel rates the campaign again…",
                    level + 1
                ));
                return vec![Effect::RegenerateCampaignLevel {
                    folder,
                    game,
                    level,
                    policies: self.policies().folder(),
                }];
            }
            KeyCode::Char('o') => {
                self.overlay = Overlay::Prompt {
                    kind: PromptKind::Campaign,
                    text: view.opened.folder.display().to_string(),
                }
            }
            KeyCode::Esc | KeyCode::Char('q') => self.overlay = Overlay::None,
            _ => {}
        }
        Vec::new()
    }

    /// `Enter`: the selected level on the designer's screen, its trials started.
    fn open_selected_level(&mut self) -> Vec<Effect> {
        let Some(view) = &self.campaign else {
            return Vec::new();
        };
        let (k, level) = (view.selected, view.opened.levels[view.selected].clone());
        let file = view.opened.record.levels[k].file.clone();
        if level.game() != self.game {
            self.complain(format!(
                "{file} is a {} level: Tab to {} first",
                level.game(),
                level.game()
            ));
            return Vec::new();
        }
        self.overlay = Overlay::None;
        // A level already in flight is dropped when it arrives.
        self.loading = Loading::Idle;
        self.replay = None;
        self.selected = None;
        self.generation_error = None;
        if let Some(seed) = level.seed {
            self.seed = seed;
        }
        if let Some(aux) = level.aux {
            self.aux = aux;
        }
        self.level = Some(level);
        self.say(format!("{file} of the campaign (o: back to the campaign)"));
        let mut effects = self.start_trials();
        effects.extend(self.judge_if_shown());
        effects
    }
}

/// The campaign view, over the whole screen.
pub(crate) fn draw(app: &App, frame: &mut Frame, screen: Rect) {
    let Some(view) = &app.campaign else {
        return;
    };
    let record = &view.opened.record;
    frame.render_widget(Clear, screen);
    let block = Block::bordered().title(format!(
        " campaign: {} {} levels, ramp {} for {} (← → select, ⏎ open, R search anew, o folder, Esc close) ",
        record.levels.len(),
        record.game,
        record.ramp,
        record.judge
    ));
    let inner = block.inner(screen);
    frame.render_widget(block, screen);
    // As many columns as fit, the selected one among them.
    let fit = ((inner.width as usize).saturating_sub(LABEL) / COLUMN).max(1);
    let first = view.selected.saturating_sub(fit - 1);
    let shown: Vec<usize> = (first..record.levels.len()).take(fit).collect();
    let cell = |k: usize, text: String| {
        let style = match k == view.selected {
            true => Style::new().reversed(),
            false => Style::new(),
        };
        Span::styled(format!("{text:>COLUMN$}"), style)
    };
    let row = |label: &str, value: &dyn Fn(usize) -> String| {
        let mut spans = vec![Span::raw(format!("{label:<LABEL$}"))];
        spans.extend(shown.iter().map(|&k| cell(k, value(k))));
        Line::from(spans)
    };
    let mut lines = Vec::new();
    // The ramp as bars: the success asked (░) and measured (█), share per row.
    for r in (0..BAR_ROWS).rev() {
        let level_of = |x: f64| (x * BAR_ROWS as f64).round() as usize;
        let label = match r {
            x if x == BAR_ROWS - 1 => "success",
            _ => "",
        };
        lines.push(row(label, &|k| {
            let l = &record.levels[k];
            let asked = if level_of(l.asked) > r {
                "░░"
            } else {
                "  "
            };
            let measured = if level_of(l.measured) > r {
                "██"
            } else {
                "  "
            };
            format!("{asked}{measured} ")
        }));
    }
    lines.push(row("", &|k| format!("#{}", k + 1)));
    lines.push(row("asked", &|k| format!("{:.2}", record.levels[k].asked)));
    lines.push(row("measured", &|k| {
        format!("{:.2}", record.levels[k].measured)
    }));
    lines.push(row("b", &|k| format!("{:+.2}", record.levels[k].b)));
    // A paced level shows its curve's mean λ, marked `~`.
    lines.push(row(
        "λ",
        &|k| match (&record.levels[k].aux, &record.levels[k].aux_curve) {
            (Some(aux), _) => format!("{aux:+.2}"),
            (None, Some(curve)) => format!("~{:+.2}", curve.mean()),
            (None, None) => "-".into(),
        },
    ));
    lines.push(row("reach", &|k| {
        format!("{:.0}%", 100.0 * record.levels[k].players.reach)
    }));
    lines.push(row("quit", &|k| {
        format!("{:.1}%", 100.0 * record.levels[k].players.quit)
    }));
    lines.push(Line::from(""));
    let selected = &record.levels[view.selected];
    lines.push(Line::from(format!(
        "level {} ({}): 95% interval {:.2} to {:.2}, b {:+.2} to {:+.2}, {:.2} attempts per success",
        view.selected + 1,
        selected.file,
        selected.ci95[0],
        selected.ci95[1],
        selected.b_ci95[0],
        selected.b_ci95[1],
        selected.players.attempts_per_success
    )));
    lines.push(Line::from(format!(
        "{:.1}% of players finish (θ ~ Normal({:+.2}, {:.2}), retry {:.2}); {}",
        100.0 * record.finishers(),
        record.population.theta_mean,
        record.population.theta_sd,
        record.population.retry,
        record.b_trend()
    )));
    lines.push(Line::from(vec![
        Span::raw("░░ asked  ").dim(),
        Span::raw("██ measured"),
    ]));
    frame.render_widget(Paragraph::new(lines), inner);
}
