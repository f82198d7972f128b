//! Drawing the designer: reads the state, never changes it.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style, Stylize};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Points};
use ratatui::widgets::{Block, Paragraph, Wrap};

mod overlay;
mod platform;
mod racing;

use super::app::pacing::aux_colour;
use super::app::{App, GoalSetting, PolicyInfo, SidePane};
use super::layout::{Areas, SLIDER_LEFT, SLIDER_RIGHT, fits};
use crate::services::panel::Judge;
use arlpcg_core::level::stats::Outcome;
use arlpcg_core::level::{Game, Level, Shape};
use arlpcg_core::rl::checkpoint::Role;

/// The key map, as the help overlay and the README show it.
pub const KEYS: [(&str, &str); 22] = [
    (
        "← →  (mouse: click/drag)",
        "λ down/up by 0.1 (-1 hard ... +1 easy), or a knob",
    ),
    (
        "Home End  m",
        "-1 / +1 / the next slider: λ, each style knob",
    ),
    ("Enter, Space", "generate again (same settings: same level)"),
    ("n s", "draw a new seed / type a seed"),
    ("g", "goal: from the seed / set by hand"),
    ("d D", "goal distance -5 / +5 m, racing 20 (goal by hand)"),
    ("h H", "goal height -1 / +1 m"),
    ("a A", "goal direction -15° / +15°"),
    ("↑ ↓", "select a block/segment: its parameters in stats"),
    ("t", "Solver trials per level (default 100)"),
    ("T W", "target success / wish list or words: searched for"),
    ("r", "replay one Solver run on the map"),
    ("w", "λ sweep: success against λ for this seed and goal"),
    ("v V", "panel: failures / λ sweep / judges / 3D in browser"),
    ("P C", "pacing: next preset / type a curve fraction:λ, ..."),
    ("k K", "keep pieces up to the selected one / let go"),
    ("x", "export YAML (with the Solver statistics) + .glb"),
    ("p o", "load policies / open a campaign folder (its view)"),
    (
        "f e [ ]",
        "profile: load a file / next ability / ability -/+5%",
    ),
    ("c j J", "cards / next judge plays trials / all judges play"),
    ("Tab", "game: platform / racing"),
    ("? / q, Esc", "this help (any key closes it) / quit"),
];

const HINTS: &str = "←→ λ  ⏎ generate  n seed  r replay  w sweep  x export  p load  ? help  q quit";

/// Draws the designer's screen, in the terminal's own colours under `NO_COLOR`.
pub fn render(app: &App, frame: &mut Frame) {
    draw_screen(app, frame);
    if !app.colour {
        // NO_COLOR: every cell in the terminal's own colours; bold and reversed stay.
        for cell in frame.buffer_mut().content.iter_mut() {
            cell.set_fg(Color::Reset).set_bg(Color::Reset);
        }
    }
}

fn draw_screen(app: &App, frame: &mut Frame) {
    let screen = frame.area();
    if !fits(screen) {
        let text = format!(
            "The designer needs a terminal of at least 80×24 (this one is {}×{}).",
            screen.width, screen.height
        );
        frame.render_widget(Paragraph::new(text).wrap(Wrap { trim: true }), screen);
        return;
    }
    let areas = Areas::with_knobs(screen, app.knob_names());
    header(app, frame, areas.header);
    controls(app, frame, &areas);
    match app.level.as_deref() {
        Some(level) => match level.shape() {
            Shape::Blocks(track) => {
                platform::map(app, level, track, frame, areas.map);
                platform::profile(app, level, track, frame, areas.profile);
            }
            Shape::Road(track) => {
                let road = track.road();
                racing::map(app, level, track, &road, frame, areas.map);
                racing::profile(app, level, &road, frame, areas.profile);
            }
        },
        None => {
            let text = match &app.generation_error {
                Some(problem) => problem.clone(),
                None => "generating…".to_string(),
            };
            frame.render_widget(
                Paragraph::new(text)
                    .wrap(Wrap { trim: true })
                    .block(Block::bordered().title(" level ")),
                areas.map,
            );
        }
    }
    stats(app, frame, areas.stats);
    match app.panel {
        SidePane::Failures => super::app::trials::draw_failures(app, frame, areas.panel),
        SidePane::Sweep => super::app::sweep::draw(app, frame, areas.panel),
        SidePane::Judges => super::app::judges::draw(app, frame, areas.panel),
    }
    footer(app, frame, areas.footer);
    overlay::overlay(app, frame, screen);
}

fn policy_label(info: &Option<PolicyInfo>, none: &str) -> String {
    match info {
        Some(p) => format!(
            "{} {}",
            p.card.training.mode,
            millions(p.card.training.steps)
        ),
        None => none.to_string(),
    }
}

fn millions(steps: u64) -> String {
    if steps >= 100_000 {
        format!("{:.1}M", steps as f64 / 1e6)
    } else {
        format!("{}k", steps / 1000)
    }
}

/// What a policy's training budget counts: the Solver's steps, the Generator's pieces.
fn budget_unit(role: Role, game: Game) -> &'static str {
    match role {
        Role::Solver => "steps",
        Role::Generator => piece_name(game, true),
    }
}

/// What a piece of `game` is called.
pub(super) fn piece_name(game: Game, plural: bool) -> &'static str {
    arlpcg_core::game::facts::facts(game).piece_name(plural)
}

fn header(app: &App, frame: &mut Frame, area: Rect) {
    let game = |g: Game| {
        let style = if app.game == g {
            Style::new().reversed()
        } else {
            Style::new().dim()
        };
        Span::styled(format!(" {} ", g.name()), style)
    };
    let mut line = Line::from(
        std::iter::once(Span::styled(" arlpcg designer ", Style::new().bold()))
            .chain(Game::ALL.map(game))
            .collect::<Vec<_>>(),
    );
    // The training budgets, in each policy's own unit, where the width allows.
    let mode = |info: &Option<PolicyInfo>, none: &str| match info {
        Some(p) => {
            let t = &p.card.training;
            let budget = format!(
                " {} {}",
                millions(t.steps),
                budget_unit(p.card.role, p.card.game)
            );
            (t.mode.to_string(), budget)
        }
        None => (none.to_string(), String::new()),
    };
    let (generator, generator_budget) = mode(&app.policies().generator, "rules");
    let scripted = Judge::Scripted(app.policies().skill).name();
    let (solver, solver_budget) = mode(&app.policies().solver, &scripted);
    let long =
        format!("  Generator: {generator}{generator_budget}  Solver: {solver}{solver_budget}");
    let policies = if line.width() + long.chars().count() <= area.width as usize {
        long
    } else {
        format!("  Generator: {generator}  Solver: {solver}")
    };
    line.push_span(Span::raw(policies));
    // The profile the shown level was made for, where the width allows.
    if let Some(profile) = app.level.as_ref().and_then(|l| l.profile.as_ref()) {
        let named = format!("  profile: {}", profile.name);
        if line.width() + named.chars().count() <= area.width as usize {
            line.push_span(Span::styled(named, Style::new().bold()));
        }
    }
    frame.render_widget(Paragraph::new(line), area);
}

fn controls(app: &App, frame: &mut Frame, areas: &Areas) {
    let names = app.knob_names();
    let title = match names.is_empty() {
        true => " λ (aux): how hard the Generator builds ",
        false => " λ (aux): how hard the Generator builds; style knobs (m: which the arrows move) ",
    };
    frame.render_widget(Block::bordered().title(title), areas.controls);
    let width = areas.slider.width as usize;
    // The slider the keys move: λ, or a knob (its value; λ's curve while paced).
    // (A knob's ends take as many columns as λ's, so the mouse maps the same way.)
    let (value, ends) = match app.slider {
        0 => (app.aux, (SLIDER_LEFT.to_string(), SLIDER_RIGHT.to_string())),
        k => (
            app.knobs.get(k - 1).copied().unwrap_or(0.0),
            (
                format!("{:>w$}", "-1 ", w = SLIDER_LEFT.chars().count()),
                format!("{:<w$}", " +1", w = SLIDER_RIGHT.chars().count()),
            ),
        ),
    };
    let mut slider = match app.ask.curve().filter(|_| app.slider == 0) {
        // The curve from start to goal, taller where it is harder.
        Some(curve) => super::app::pacing::curve_line(curve, width),
        None => {
            let knob = (((value + 1.0) / 2.0) * (width.saturating_sub(1)) as f64).round() as usize;
            let track: String = (0..width)
                .map(|i| match i.cmp(&knob) {
                    std::cmp::Ordering::Less => '━',
                    std::cmp::Ordering::Equal => '●',
                    std::cmp::Ordering::Greater => '─',
                })
                .collect();
            let mut line = Line::from(vec![
                Span::raw(ends.0).red(),
                Span::styled(track, Style::new().fg(Color::Cyan)),
                Span::raw(ends.1).green(),
            ]);
            // λ and each knob's value, the one the keys move in bold.
            let values = std::iter::once(("λ", app.aux))
                .chain(names.iter().copied().zip(app.knobs.iter().copied()));
            for (k, (name, v)) in values.enumerate() {
                let style = match k == app.slider {
                    true => Style::new().bold(),
                    false => Style::new().dim(),
                };
                line.push_span(Span::styled(format!("  {name} {v:+.2}"), style));
            }
            line
        }
    };
    if let Some(kept) = &app.kept {
        slider.push_span(Span::styled(
            format!("  keeping {}", kept.pieces),
            Style::new().fg(Color::Blue),
        ));
    }
    if let Some(target) = app.ask.success() {
        slider.push_span(Span::styled(
            format!(" for success {target:.2}"),
            Style::new().fg(Color::Cyan),
        ));
    }
    let row = Rect {
        width: areas.controls.width.saturating_sub(2),
        x: areas.controls.x + 1,
        ..areas.slider
    };
    frame.render_widget(Paragraph::new(slider), row);
    let goal = match (app.goal, app.level.as_deref()) {
        (GoalSetting::Custom { .. }, _) | (_, None) => describe_goal(app.goal.position()),
        (GoalSetting::FromSeed, Some(level)) => describe_goal(Some(level.goal)),
    };
    let origin = match app.goal {
        GoalSetting::FromSeed => "from seed",
        GoalSetting::Custom { .. } => "by hand",
    };
    let mut settings = Line::from(vec![
        Span::raw("seed "),
        Span::styled(app.seed.to_string(), Style::new().bold()),
        Span::raw(format!("   goal ({origin}) {goal}")),
        Span::raw(format!("   trials {}", app.trials_wanted)).dim(),
    ]);
    if let Some(curve) = app.ask.curve() {
        settings.push_span(Span::styled(
            format!("   {}: {curve}", super::app::pacing::preset_name(curve)),
            Style::new().fg(Color::Magenta),
        ));
    }
    // With knobs, the style the level on screen measures (what each knob asks for).
    if let (false, Some(level)) = (names.is_empty(), app.level.as_deref()) {
        let measured: Vec<String> = names
            .iter()
            .zip(level.style())
            .map(|(name, v)| format!("{name} {v:+.2}"))
            .collect();
        settings.push_span(Span::styled(
            format!("   measured {}", measured.join(" ")),
            Style::new().fg(Color::Yellow),
        ));
    }
    frame.render_widget(Paragraph::new(settings), areas.settings);
}

fn describe_goal(goal: Option<[f64; 3]>) -> String {
    match goal {
        Some([x, y, z]) => format!("{:.0} m away, {:+.0} m up", x.hypot(z), y),
        None => "drawn from the seed".into(),
    }
}

/// A top-down map titled `title`, square around `points` (padded by `pad` metres), drawn in
/// braille by `paint`.
fn map_canvas<F: Fn(&mut Context)>(
    title: String,
    points: &[[f64; 2]],
    area: Rect,
    pad: f64,
    paint: F,
) -> Canvas<'static, F> {
    let (x_bounds, y_bounds) = bounds(points, area, pad);
    Canvas::default()
        .block(Block::bordered().title(title))
        .marker(Marker::Braille)
        .x_bounds(x_bounds)
        .y_bounds(y_bounds)
        .paint(paint)
}

/// Square bounds around `points` for a canvas of `area` (braille: 2×4 dots a cell), padded.
fn bounds(points: &[[f64; 2]], area: Rect, pad: f64) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let dots = [
        (area.width.saturating_sub(2).max(1) * 2) as f64,
        (area.height.saturating_sub(2).max(1) * 4) as f64,
    ];
    let span = [hi[0] - lo[0] + 2.0 * pad, hi[1] - lo[1] + 2.0 * pad];
    let per_dot = (span[0] / dots[0]).max(span[1] / dots[1]);
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let half = [per_dot * dots[0] / 2.0, per_dot * dots[1] / 2.0];
    (
        [centre[0] - half[0], centre[0] + half[0]],
        [centre[1] - half[1], centre[1] + half[1]],
    )
}

fn draw_replay(app: &App, ctx: &mut Context, project: impl Fn(&[f32; 3]) -> [f64; 2]) {
    let Some(replay) = &app.replay else {
        return;
    };
    let path = &replay.recording.path[..=replay.frame];
    let trail: Vec<(f64, f64)> = path
        .iter()
        .map(|f| {
            let [x, y] = project(f);
            (x, y)
        })
        .collect();
    ctx.draw(&Points {
        coords: &trail,
        color: Color::Magenta,
    });
    ctx.layer();
    if let Some(&(x, y)) = trail.last() {
        ctx.print(x, y, "@".magenta().bold());
    }
}

fn stats(app: &App, frame: &mut Frame, area: Rect) {
    let scripted = Judge::Scripted(app.policies().skill).name();
    let solver = match app.trials.as_ref().and_then(|t| t.stand_in.as_ref()) {
        Some(_) => format!(
            "{} in its place",
            Judge::Scripted(arlpcg_core::game::Skill::Expert).name()
        ),
        None => policy_label(&app.policies().solver, &scripted),
    };
    let mut lines = Vec::new();
    match &app.trials {
        Some(t) => {
            let running = if t.stats.is_some() || t.error.is_some() {
                ""
            } else {
                " …"
            };
            lines.push(Line::from(format!(
                "trials {}/{}  successes {}{running}",
                t.done(),
                t.wanted,
                t.successes()
            )));
            match t.success() {
                Some((ratio, [lo, hi])) => lines.push(Line::from(vec![
                    Span::raw("success "),
                    Span::styled(format!("{ratio:.2}"), Style::new().bold()),
                    Span::raw(format!("  95% [{lo:.2}, {hi:.2}]")),
                ])),
                None => lines.push(Line::from("success …")),
            }
            if let Some(progress) = t.mean_progress() {
                let endings = arlpcg_core::game::facts::facts(app.game).endings;
                let tallies = endings
                    .iter()
                    .filter_map(|(key, _)| Outcome::of_ending(key));
                let mut line = format!("progress {progress:.2}");
                for outcome in tallies {
                    line.push_str(&format!("  {} {}", outcome.tally_word(), t.count(outcome)));
                }
                lines.push(Line::from(line));
            }
            if let Some(air) = t.mean_air_seconds(app.game) {
                lines.push(Line::from(format!("air time {air:.2} s per run")));
            }
            if let Some(problem) = &t.error {
                lines.push(Line::from(format!("stopped: {problem}").red()));
            }
        }
        None => lines.push(Line::from("no trials yet")),
    }
    if let (Some(want), Some(level)) = (app.want(), &app.level) {
        wish_lines(
            want,
            level,
            app.trials.as_ref().and_then(|t| t.stats.as_ref()),
            &mut lines,
        );
    }
    if let Some(level) = &app.level {
        lines.push(Line::from(source_line(level)).dim());
        if let Shape::Road(track) = level.shape() {
            racing::stats(app, track, &mut lines);
        }
        if let Shape::Blocks(track) = level.shape() {
            let blocks = track.block_params();
            let n = blocks.len().max(1) as f64;
            lines.push(Line::from(format!(
                "mean jump {:.1} m, block {:.1} m",
                blocks.iter().map(|b| b.distance).sum::<f64>() / n,
                blocks.iter().map(|b| b.size).sum::<f64>() / n,
            )));
            if let Some(b) = app.selected.and_then(|i| blocks.get(i).map(|b| (i, b))) {
                let (i, b) = b;
                let failures = app
                    .trials
                    .as_ref()
                    .map_or(0, |t| t.failures_by_block(blocks.len())[i]);
                lines.push(
                    Line::from(format!(
                        "block {i}: jump {:.1} m, turn {:+.0}°",
                        b.distance, b.angle
                    ))
                    .cyan(),
                );
                lines.push(
                    Line::from(format!(
                        "  size {:.1} m, up {:+.1} m, {failures} fell",
                        b.size, b.height
                    ))
                    .cyan(),
                );
            }
        }
    }
    if app.generating() {
        lines.push(Line::from("generating…").yellow());
    }
    frame.render_widget(
        Paragraph::new(lines).block(Block::bordered().title(format!(" Solver: {solver} "))),
        area,
    );
}

/// Each constraint of the wish list: ✓ or ✗ with its value on the level, measured on the
/// trials once they are done (a judge's success as the search measured it), … before.
fn wish_lines(
    want: &crate::services::wish::Want,
    level: &Level,
    stats: Option<&arlpcg_core::level::SolverStats>,
    lines: &mut Vec<Line>,
) {
    use crate::services::wish::{Attribute, Evidence, Reads, Strictness};
    let evidence = Evidence {
        stats,
        ..Evidence::default()
    };
    for constraint in &want.constraints {
        let text = constraint.to_string();
        let recorded = level
            .want
            .as_ref()
            .and_then(|w| w.measured.iter().find(|m| m.constraint == text))
            .map(|m| m.value);
        let line = match constraint.attribute {
            Attribute::Success(Some(_)) => {
                recorded.map(|v| (constraint.low <= v && v <= constraint.high, v))
            }
            a if a.reads() > Reads::Pieces && stats.is_none() => None,
            a => a.value(level, &evidence).ok().map(|v| {
                (
                    constraint
                        .miss(level, &evidence, Strictness::Value)
                        .is_none(),
                    v,
                )
            }),
        };
        lines.push(match line {
            Some((true, v)) => Line::from(format!("✓ {text}  ({v:.2})")).green(),
            Some((false, v)) => Line::from(format!("✗ {text}  ({v:.2})")).red(),
            None => Line::from(format!("… {text}")).dim(),
        });
    }
}

/// The piece (of `pieces`) on which most of the Solver's runs so far failed; the maps mark it.
fn most_failed_piece(app: &App, pieces: usize) -> Option<usize> {
    let trials = app.trials.as_ref()?;
    crate::shells::design::app::trials::Trials::most_failed(&trials.failures_by_block(pieces))
}

/// The mark the maps print on the piece that fails most.
const MOST_FAILED_MARK: &str = "✕";

/// The colour of each of `pieces` pieces (blocks, segments): the selected one cyan; on a paced
/// level each by the λ it was built at (kept pieces without one blue), else by its share of
/// the failures so far.
fn piece_colours(app: &App, pieces: usize) -> Vec<Color> {
    if let Some(pacing) = app.level.as_ref().and_then(|l| l.pacing.as_ref()) {
        return (0..pieces)
            .map(|i| match pacing.piece_aux.get(i) {
                _ if app.selected == Some(i) => Color::Cyan,
                Some(Some(aux)) => aux_colour(*aux),
                _ => Color::Blue,
            })
            .collect();
    }
    let failures = app
        .trials
        .as_ref()
        .map(|t| t.failures_by_block(pieces))
        .unwrap_or_else(|| vec![0; pieces]);
    let most = failures.iter().copied().max().unwrap_or(0);
    failures
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            if app.selected == Some(i) {
                Color::Cyan
            } else if f == 0 {
                Color::White
            } else if f * 2 >= most {
                Color::Red
            } else {
                Color::Yellow
            }
        })
        .collect()
}

fn source_line(level: &Level) -> String {
    match &level.source {
        arlpcg_core::level::Source::Policy { .. } => "Generator level".into(),
        arlpcg_core::level::Source::Rules { .. }
        | arlpcg_core::level::Source::RacingRules { .. } => "rule level (no Generator)".into(),
        arlpcg_core::level::Source::Hand => "made by hand".into(),
        arlpcg_core::level::Source::Kept { pieces, .. } => {
            format!("{pieces} pieces kept, the rest by the Generator")
        }
    }
}

fn footer(app: &App, frame: &mut Frame, area: Rect) {
    let line = match &app.status {
        Some((text, true)) => Line::from(text.as_str()).red(),
        Some((text, false)) => Line::from(text.as_str()).yellow(),
        None => Line::from(HINTS).dim(),
    };
    frame.render_widget(Paragraph::new(line), area);
}
