//! The Solver's trials on the level on screen, as they come in: counts, the success ratio with
//! its interval, progress, air time and the failures per piece.

use ratatui::Frame;
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Style, Stylize};
use ratatui::text::Line;
use ratatui::widgets::{Bar, BarChart, BarGroup, Block, Paragraph};

use super::pacing::aux_colour;
use super::{App, Effect};
use arlpcg_core::level::Game;
use arlpcg_core::level::stats::{Outcome, SolverStats, TrialResult, wilson_interval};

/// The Solver's trials on the level on screen, as they come in.
#[derive(Debug, Clone, PartialEq)]
pub struct Trials {
    /// The request's number; answers to an older one are dropped.
    pub id: u64,
    /// How many trials were asked for.
    pub wanted: u32,
    /// The runs finished so far, in the order they ended.
    pub results: Vec<TrialResult>,
    /// The final statistics (the same as `arlpcg verify` gives), once all trials are in.
    pub stats: Option<SolverStats>,
    /// Why the trials stopped before they were all in, if they could not be played.
    pub error: Option<String>,
    /// Why the scripted expert plays them in the Solver's place, if it does.
    pub stand_in: Option<String>,
}

impl Trials {
    /// Trials finished so far.
    pub fn done(&self) -> u32 {
        self.results.len() as u32
    }

    /// Successful trials so far.
    pub fn successes(&self) -> u32 {
        self.results
            .iter()
            .filter(|r| r.outcome == Outcome::Success)
            .count() as u32
    }

    /// Success ratio and its 95% interval so far (`None` before the first trial).
    pub fn success(&self) -> Option<(f64, [f64; 2])> {
        let n = self.done();
        (n > 0).then(|| {
            let s = self.successes();
            (s as f64 / n as f64, wilson_interval(s, n))
        })
    }

    /// Mean fraction of the track covered so far (`None` before the first trial).
    pub fn mean_progress(&self) -> Option<f64> {
        let n = self.results.len();
        (n > 0).then(|| self.results.iter().map(|r| r.progress).sum::<f64>() / n as f64)
    }

    /// Racing: mean seconds per run with the car in the air so far (`None` on platform levels
    /// and before the first trial).
    pub fn mean_air_seconds(&self, game: Game) -> Option<f64> {
        let dt = arlpcg_core::game::facts::facts(game).air_time_step?;
        let air: Vec<u32> = self.results.iter().filter_map(|r| r.air_steps).collect();
        (!air.is_empty())
            .then(|| dt * air.iter().map(|&a| f64::from(a)).sum::<f64>() / air.len() as f64)
    }

    /// Runs so far that ended as `outcome`.
    pub fn count(&self, outcome: Outcome) -> u32 {
        self.results.iter().filter(|r| r.outcome == outcome).count() as u32
    }

    /// The piece with the most failures (the first of equals); none before a run fails.
    pub fn most_failed(failures: &[u32]) -> Option<usize> {
        let most = *failures.iter().max()?;
        (most > 0).then(|| failures.iter().position(|&f| f == most))?
    }

    /// Failed runs per block so far (`blocks` blocks), as `SolverStats::failures_by_piece`.
    pub fn failures_by_block(&self, blocks: usize) -> Vec<u32> {
        let mut failures = vec![0; blocks];
        for r in self
            .results
            .iter()
            .filter(|r| r.outcome != Outcome::Success)
        {
            if blocks > 0 {
                failures[r.target_piece.min(blocks - 1)] += 1;
            }
        }
        failures
    }
}

impl App {
    /// The Solver's trials on the level on screen, from the first.
    pub(super) fn start_trials(&mut self) -> Vec<Effect> {
        let Some(level) = self.level.clone() else {
            return Vec::new();
        };
        let id = self.id();
        self.trials = Some(Trials {
            id,
            wanted: self.trials_wanted,
            results: Vec::new(),
            stats: None,
            error: None,
            stand_in: None,
        });
        vec![Effect::Trials {
            id,
            seed: level.seed.unwrap_or(0),
            level,
            trials: self.trials_wanted,
        }]
    }
}

/// The bottom-right panel's first view: the failures on each piece, coloured by the λ the
/// piece was built at when the level is paced.
pub(crate) fn draw_failures(app: &App, frame: &mut Frame, area: Rect) {
    let piece = arlpcg_core::game::facts::facts(app.game).piece_name(false);
    let block = Block::bordered().title(format!(" failures per {piece} (v: sweep) "));
    let (Some(level), Some(trials)) = (&app.level, &app.trials) else {
        frame.render_widget(block, area);
        return;
    };
    let counts = trials.failures_by_block(level.piece_count());
    let Some(worst) = Trials::most_failed(&counts) else {
        let text = if trials.done() == 0 {
            "waiting for the first runs"
        } else {
            "no run has failed so far"
        };
        frame.render_widget(Paragraph::new(text).block(block), area);
        return;
    };
    let failed: u32 = counts.iter().sum();
    let most = counts[worst];
    let block = block.title_bottom(format!(
        " most: {piece} {worst}, {most} of {failed} ({:.0}%) ",
        100.0 * f64::from(most) / f64::from(failed)
    ));
    let piece_aux = |i: usize| level.pacing.as_ref()?.piece_aux.get(i).copied().flatten();
    let bars: Vec<Bar> = counts
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let style = match piece_aux(i) {
                _ if app.selected == Some(i) => Style::new().cyan(),
                // Beside the map's colours: where the curve asked for it to be hard.
                Some(aux) => Style::new().fg(aux_colour(aux)),
                None => Style::new().red(),
            };
            Bar::default()
                .value(u64::from(c))
                .text_value(String::new())
                .style(style)
        })
        .collect();
    let inner = block.inner(area);
    frame.render_widget(block, area);
    // The count axis on the left (the highest bar's count at its top, 0 at the bottom), the
    // piece numbers under the bars.
    let [y_axis, plot] = Layout::horizontal([
        Constraint::Length(most.to_string().len() as u16 + 1),
        Constraint::Min(1),
    ])
    .areas(inner);
    let [bars_area, x_axis] =
        Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(plot);
    let columns = bars_area.width as usize;
    let gap = usize::from(counts.len() * 2 <= columns);
    let width = ((columns / counts.len().max(1)).saturating_sub(gap)).clamp(1, 3);
    let chart = BarChart::default()
        .data(BarGroup::default().bars(&bars))
        .max(u64::from(most))
        .bar_width(width as u16)
        .bar_gap(gap as u16);
    frame.render_widget(chart, bars_area);
    let mut counts_axis = vec![Line::from(most.to_string()); 1];
    counts_axis.resize(bars_area.height.saturating_sub(1) as usize, Line::default());
    counts_axis.push(Line::from("0"));
    frame.render_widget(
        Paragraph::new(counts_axis)
            .alignment(Alignment::Right)
            .dark_gray(),
        Rect {
            height: bars_area.height,
            ..y_axis
        },
    );
    frame.render_widget(
        Paragraph::new(piece_numbers(counts.len(), width + gap, columns)).dark_gray(),
        x_axis,
    );
}

/// The piece numbers under bars `stride` columns apart: every number that fits, at least one
/// space between two, each starting under its bar.
fn piece_numbers(pieces: usize, stride: usize, columns: usize) -> String {
    let mut axis = String::new();
    for i in 0..pieces {
        let at = i * stride;
        let label = i.to_string();
        let room = axis.is_empty() || at > axis.len();
        if room && at + label.len() <= columns {
            axis.push_str(&" ".repeat(at - axis.len()));
            axis.push_str(&label);
        }
    }
    axis
}
