//! Drawing the designer: reads the state, never changes it.

use ratatui::Frame;
use ratatui::layout::{Constraint, Flex, Layout, Rect};
use ratatui::style::{Color, Modifier, Style, Stylize};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as CanvasLine, Points};
use ratatui::widgets::{
    Axis, Bar, BarChart, BarGroup, Block, Chart, Clear, Dataset, GraphType, Paragraph, Wrap,
};

use super::app::{App, GoalSetting, Overlay, Panel, PolicyInfo, SweepPoint};
use super::layout::{Areas, SLIDER_LEFT, SLIDER_RIGHT, fits};
use crate::level::platform::{Platform, PlatformTrack, heading_direction};
use crate::level::racing::{Obstacle, RacingTrack};
use crate::level::road::{ROAD_WIDTH, Road};
use crate::level::stats::Outcome;
use crate::level::{Game, Level, Track};
use crate::rl::checkpoint::Role;

/// The key map, as the help overlay and the README show it.
pub const KEYS: [(&str, &str); 21] = [
    (
        "← →  (mouse: click/drag)",
        "λ down/up by 0.1 (-1 hard ... +1 easy)",
    ),
    ("Home End", "λ = -1 / λ = +1"),
    ("Enter, Space", "generate again (same settings: same level)"),
    ("n", "draw a new seed"),
    ("s", "type a seed"),
    ("g", "goal: from the seed / set by hand"),
    ("d D", "goal distance -5 / +5 m, racing 20 (goal by hand)"),
    ("h H", "goal height -1 / +1 m"),
    ("a A", "goal direction -15° / +15°"),
    ("↑ ↓", "select a block/segment: its parameters in stats"),
    ("t", "Solver trials per level (default 100)"),
    ("T", "target success rate: λ is searched for it"),
    ("r", "replay one Solver run on the map"),
    ("w", "λ sweep: success against λ for this seed and goal"),
    ("v", "bottom-right panel: failures per piece / λ sweep"),
    ("x", "export YAML (with the Solver statistics) + .glb"),
    ("p", "load policies (a folder or one .safetensors file)"),
    ("c", "show the loaded policies' cards"),
    ("Tab", "game: platform / racing"),
    ("?", "this help (any key closes it)"),
    ("q, Esc", "quit"),
];

const HINTS: &str = "←→ λ  ⏎ generate  n seed  r replay  w sweep  x export  p load  ? help  q quit";

pub fn render(app: &App, frame: &mut Frame) {
    let screen = frame.area();
    if !fits(screen) {
        let text = format!(
            "The designer needs a terminal of at least 80×24 (this one is {}×{}).",
            screen.width, screen.height
        );
        frame.render_widget(Paragraph::new(text).wrap(Wrap { trim: true }), screen);
        return;
    }
    let areas = Areas::of(screen);
    header(app, frame, areas.header);
    controls(app, frame, &areas);
    match app.level.as_deref() {
        Some(level) => match &level.track {
            Track::Platform(track) => {
                map(app, level, track, frame, areas.map);
                profile(app, level, track, frame, areas.profile);
            }
            Track::Racing(track) => {
                let road = track.road();
                racing_map(app, level, track, &road, frame, areas.map);
                racing_profile(app, level, &road, frame, areas.profile);
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
        Panel::Failures => failures(app, frame, areas.panel),
        Panel::Sweep => sweep(app, frame, areas.panel),
    }
    footer(app, frame, areas.footer);
    overlay(app, frame, screen);
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
fn piece_name(game: Game, plural: bool) -> &'static str {
    match (game, plural) {
        (Game::Platform, false) => "block",
        (Game::Platform, true) => "blocks",
        (Game::Racing, false) => "segment",
        (Game::Racing, true) => "segments",
    }
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
    let mut line = Line::from(vec![
        Span::styled(" arlpcg designer ", Style::new().bold()),
        game(Game::Platform),
        game(Game::Racing),
    ]);
    // The training budgets, in each policy's own unit, where the width allows.
    let mode = |info: &Option<PolicyInfo>, none: &str| match info {
        Some(p) => {
            let t = &p.card.training;
            let budget = format!(
                " {} {}",
                millions(t.steps),
                budget_unit(p.card.role, p.card.game)
            );
            (t.mode.clone(), budget)
        }
        None => (none.to_string(), String::new()),
    };
    let (generator, generator_budget) = mode(&app.policies.generator, "rules");
    let (solver, solver_budget) = mode(&app.policies.solver, "scripted");
    let long =
        format!("  Generator: {generator}{generator_budget}  Solver: {solver}{solver_budget}");
    let policies = if line.width() + long.chars().count() <= area.width as usize {
        long
    } else {
        format!("  Generator: {generator}  Solver: {solver}")
    };
    line.push_span(Span::raw(policies));
    frame.render_widget(Paragraph::new(line), area);
}

fn controls(app: &App, frame: &mut Frame, areas: &Areas) {
    frame.render_widget(
        Block::bordered().title(" λ (aux): how hard the Generator builds "),
        areas.controls,
    );
    let width = areas.slider.width as usize;
    let knob = (((app.aux + 1.0) / 2.0) * (width.saturating_sub(1)) as f64).round() as usize;
    let track: String = (0..width)
        .map(|i| match i.cmp(&knob) {
            std::cmp::Ordering::Less => '━',
            std::cmp::Ordering::Equal => '●',
            std::cmp::Ordering::Greater => '─',
        })
        .collect();
    let mut slider = Line::from(vec![
        Span::raw(SLIDER_LEFT).red(),
        Span::styled(track, Style::new().fg(Color::Cyan)),
        Span::raw(SLIDER_RIGHT).green(),
        Span::styled(format!("  λ {:+.2}", app.aux), Style::new().bold()),
    ]);
    if let Some(target) = app.target {
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
    let settings = Line::from(vec![
        Span::raw("seed "),
        Span::styled(app.seed.to_string(), Style::new().bold()),
        Span::raw(format!("   goal ({origin}) {goal}")),
        Span::raw(format!("   trials {}", app.trials_wanted)).dim(),
    ]);
    frame.render_widget(Paragraph::new(settings), areas.settings);
}

fn describe_goal(goal: Option<[f64; 3]>) -> String {
    match goal {
        Some([x, y, z]) => format!("{:.0} m away, {:+.0} m up", x.hypot(z), y),
        None => "drawn from the seed".into(),
    }
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

/// The corners of a block's top, `[x, z]`, in order around it.
fn corners(p: &Platform) -> [[f64; 2]; 4] {
    let [fx, fz] = heading_direction(p.heading);
    let h = p.size / 2.0;
    [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(along, across)| {
        [
            p.position[0] + along * fx - across * fz,
            p.position[2] + along * fz + across * fx,
        ]
    })
}

/// The colour of every platform (0 is the start block; `i + 1` is block `i`): the selected
/// block cyan, the others by their share of the failures so far.
fn platform_colours(app: &App, blocks: usize) -> Vec<Color> {
    std::iter::once(Color::Blue)
        .chain(piece_colours(app, blocks))
        .collect()
}

fn map(app: &App, level: &Level, track: &PlatformTrack, frame: &mut Frame, area: Rect) {
    let platforms = track.platforms();
    let colours = platform_colours(app, track.block_count());
    let mut points: Vec<[f64; 2]> = platforms.iter().flat_map(corners).collect();
    points.push([level.goal[0], level.goal[2]]);
    let (x_bounds, y_bounds) = bounds(&points, area, 2.0);
    let title = format!(
        " top-down: {} blocks, goal {:.0} m ",
        track.block_count(),
        level.goal[0].hypot(level.goal[2])
    );
    let canvas = Canvas::default()
        .block(Block::bordered().title(title))
        .marker(Marker::Braille)
        .x_bounds(x_bounds)
        .y_bounds(y_bounds)
        .paint(|ctx| {
            for (p, &colour) in platforms.iter().zip(&colours) {
                let c = corners(p);
                for k in 0..4 {
                    let (a, b) = (c[k], c[(k + 1) % 4]);
                    ctx.draw(&CanvasLine::new(a[0], a[1], b[0], b[1], colour));
                }
            }
            draw_replay(app, ctx, |f| [f[0] as f64, f[2] as f64]);
            ctx.print(level.goal[0], level.goal[2], "G".green().bold());
            let start = platforms[0].position;
            ctx.print(start[0], start[2], "S".blue().bold());
        });
    frame.render_widget(canvas, area);
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

/// Horizontal distance along the track of each platform centre.
fn stations(platforms: &[Platform]) -> Vec<f64> {
    let mut s = vec![0.0];
    for w in platforms.windows(2) {
        let d = (w[1].position[0] - w[0].position[0]).hypot(w[1].position[2] - w[0].position[2]);
        s.push(s.last().copied().unwrap_or(0.0) + d);
    }
    s
}

/// Where `(x, z)` lies along the track, as a distance from the start (nearest point of the
/// polyline through the platform centres).
fn along(platforms: &[Platform], stations: &[f64], x: f64, z: f64) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    for (i, w) in platforms.windows(2).enumerate() {
        let (a, b) = (w[0].position, w[1].position);
        let (dx, dz) = (b[0] - a[0], b[2] - a[2]);
        let len2 = (dx * dx + dz * dz).max(1e-9);
        let t = (((x - a[0]) * dx + (z - a[2]) * dz) / len2).clamp(0.0, 1.0);
        let (px, pz) = (a[0] + t * dx, a[2] + t * dz);
        let d = (x - px).hypot(z - pz);
        if d < best.0 {
            best = (d, stations[i] + t * (stations[i + 1] - stations[i]));
        }
    }
    best.1
}

fn profile(app: &App, level: &Level, track: &PlatformTrack, frame: &mut Frame, area: Rect) {
    let platforms = track.platforms();
    let colours = platform_colours(app, track.block_count());
    let s = stations(platforms);
    let last = *s.last().unwrap_or(&0.0);
    let mut lo = level.goal[1].min(0.0);
    let mut hi = level.goal[1].max(0.0);
    for p in platforms {
        lo = lo.min(p.position[1]);
        hi = hi.max(p.position[1]);
    }
    let canvas = Canvas::default()
        .block(Block::bordered().title(format!(
            " side profile: {:.0} m of track, {:+.0} m to climb ",
            last, level.goal[1]
        )))
        .marker(Marker::Braille)
        .x_bounds([-4.0, last + 4.0])
        .y_bounds([lo - 2.0, hi + 2.0])
        .paint(|ctx| {
            for ((p, &at), &colour) in platforms.iter().zip(&s).zip(&colours) {
                let (y, h) = (p.position[1], p.size / 2.0);
                ctx.draw(&CanvasLine::new(at - h, y, at + h, y, colour));
            }
            draw_replay(app, ctx, |f| {
                [along(platforms, &s, f[0] as f64, f[2] as f64), f[1] as f64]
            });
            ctx.print(last, level.goal[1] + 1.0, "G".green().bold());
        });
    frame.render_widget(canvas, area);
}

fn stats(app: &App, frame: &mut Frame, area: Rect) {
    let scripted = match app.game {
        Game::Platform => "scripted controller",
        Game::Racing => "scripted driver",
    };
    let solver = policy_label(&app.policies.solver, scripted);
    let mut lines = Vec::new();
    match &app.trials {
        Some(t) => {
            let running = if t.stats.is_some() { "" } else { " …" };
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
                lines.push(Line::from(match app.game {
                    Game::Platform => format!(
                        "progress {:.2}  fell {}  timeout {}",
                        progress,
                        t.count(Outcome::Fell),
                        t.count(Outcome::TimedOut)
                    ),
                    Game::Racing => format!(
                        "progress {:.2}  off road {}  flipped {}  timeout {}",
                        progress,
                        t.count(Outcome::OffRoad),
                        t.count(Outcome::Flipped),
                        t.count(Outcome::TimedOut)
                    ),
                }));
            }
            if let Some(air) = t.mean_air_seconds() {
                lines.push(Line::from(format!("air time {air:.2} s per run")));
            }
        }
        None => lines.push(Line::from("no trials yet")),
    }
    if let Some(level) = &app.level {
        lines.push(Line::from(source_line(level)).dim());
        if let Some(track) = level.racing() {
            racing_stats(app, track, &mut lines);
        }
        if let Some(track) = level.platform() {
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

/// The racing track's statistics and the selected segment, for the stats panel.
fn racing_stats(app: &App, track: &RacingTrack, lines: &mut Vec<Line>) {
    let segments = &track.segments;
    let n = segments.len().max(1) as f64;
    lines.push(Line::from(format!(
        "mean curve {:.1}°, length {:.1} m, height {:.1} m",
        segments.iter().map(|s| s.curve.abs()).sum::<f64>() / n,
        segments.iter().map(|s| s.length).sum::<f64>() / n,
        segments.iter().map(|s| s.height.abs()).sum::<f64>() / n,
    )));
    if let Some((i, s)) = app.selected.and_then(|i| segments.get(i).map(|s| (i, s))) {
        let failures = app
            .trials
            .as_ref()
            .map_or(0, |t| t.failures_by_block(segments.len())[i]);
        lines.push(
            Line::from(format!(
                "segment {i}: {:.1} m, curve {:+.0}°, up {:+.1} m",
                s.length, s.curve, s.height
            ))
            .cyan(),
        );
        lines.push(Line::from(format!("  {failures} runs failed on it")).cyan());
    }
}

/// The colour of each of `pieces` pieces (blocks, segments): the selected one cyan, the others by
/// their share of the failures so far.
fn piece_colours(app: &App, pieces: usize) -> Vec<Color> {
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

/// The footprint of an obstacle, `[x, z]` corners (a cylinder as a 12-gon).
fn obstacle_outline(obstacle: &Obstacle) -> Vec<[f64; 2]> {
    match *obstacle {
        Obstacle::Box {
            position,
            size,
            heading,
        } => {
            let [fx, fz] = heading_direction(heading);
            let (hx, hz) = (size[0] / 2.0, size[2] / 2.0);
            [(-hx, -hz), (hx, -hz), (hx, hz), (-hx, hz)]
                .map(|(a, b)| [position[0] + a * fx - b * fz, position[2] + a * fz + b * fx])
                .to_vec()
        }
        Obstacle::Cylinder {
            position, radius, ..
        } => (0..12)
            .map(|k| {
                let t = k as f64 * std::f64::consts::TAU / 12.0;
                [
                    position[0] + radius * t.cos(),
                    position[2] + radius * t.sin(),
                ]
            })
            .collect(),
    }
}

/// The racing track from above: the road's edges (coloured by the failures on each segment),
/// its banked stretches (blue dots on the centre line: the steeper the bank, the denser),
/// obstacles, start, goal and a replayed run.
fn racing_map(
    app: &App,
    level: &Level,
    track: &RacingTrack,
    road: &Road,
    frame: &mut Frame,
    area: Rect,
) {
    let colours = piece_colours(app, track.segments.len());
    let half = 0.5 * ROAD_WIDTH;
    let edges: Vec<([f64; 3], [f64; 3], usize, f64)> = road
        .samples()
        .iter()
        .map(|p| (p.across(half), p.across(-half), p.segment, p.bank))
        .collect();
    let mut points: Vec<[f64; 2]> = edges
        .iter()
        .flat_map(|(l, r, ..)| [[l[0], l[2]], [r[0], r[2]]])
        .collect();
    points.push([level.goal[0], level.goal[2]]);
    let outlines: Vec<Vec<[f64; 2]>> = track.obstacles.iter().map(obstacle_outline).collect();
    points.extend(outlines.iter().flatten());
    let (x_bounds, y_bounds) = bounds(&points, area, 5.0);
    let title = format!(
        " top-down: {} segments, {:.0} m of road, goal {:.0} m ",
        track.segments.len(),
        road.length(),
        level.goal[0].hypot(level.goal[2])
    );
    let canvas = Canvas::default()
        .block(Block::bordered().title(title))
        .marker(Marker::Braille)
        .x_bounds(x_bounds)
        .y_bounds(y_bounds)
        .paint(|ctx| {
            for outline in &outlines {
                for k in 0..outline.len() {
                    let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
                    ctx.draw(&CanvasLine::new(a[0], a[1], b[0], b[1], Color::DarkGray));
                }
            }
            for pair in edges.windows(2) {
                let (a, b) = (&pair[0], &pair[1]);
                let colour = colours.get(b.2).copied().unwrap_or(Color::White);
                ctx.draw(&CanvasLine::new(a.0[0], a.0[2], b.0[0], b.0[2], colour));
                ctx.draw(&CanvasLine::new(a.1[0], a.1[2], b.1[0], b.1[2], colour));
            }
            let banked: Vec<(f64, f64)> = road
                .samples()
                .iter()
                .enumerate()
                .filter(|(i, p)| {
                    let degrees = p.bank.abs().to_degrees();
                    degrees >= 10.0 || (degrees >= 4.0 && i % 2 == 0)
                })
                .map(|(_, p)| (p.centre[0], p.centre[2]))
                .collect();
            ctx.draw(&Points {
                coords: &banked,
                color: Color::LightBlue,
            });
            draw_replay(app, ctx, |f| [f[0] as f64, f[2] as f64]);
            ctx.print(level.goal[0], level.goal[2], "G".green().bold());
            ctx.print(track.position[0], track.position[2], "S".blue().bold());
        });
    frame.render_widget(canvas, area);
}

/// The road's elevation along its length, coloured by the failures on each segment, with its
/// crests marked `^` (where the car may leave the ground).
fn racing_profile(app: &App, level: &Level, road: &Road, frame: &mut Frame, area: Rect) {
    let samples = road.samples();
    let colours = piece_colours(app, road.segment_count());
    let length = road.length();
    let (mut lo, mut hi) = (level.goal[1].min(0.0), level.goal[1].max(0.0));
    for p in samples {
        lo = lo.min(p.centre[1]);
        hi = hi.max(p.centre[1]);
    }
    // A crest: the slope turns from climbing to falling, and the road drops at least 1 m within
    // 15 m either side.
    let crests: Vec<&crate::level::road::RoadSample> = samples
        .windows(2)
        .filter(|w| w[0].slope > 0.0 && w[1].slope <= 0.0)
        .map(|w| &w[1])
        .filter(|p| {
            let near = samples.iter().filter(|q| (q.s - p.s).abs() <= 15.0);
            near.map(|q| p.centre[1] - q.centre[1]).fold(0.0, f64::max) >= 1.0
        })
        .collect();
    let canvas = Canvas::default()
        .block(Block::bordered().title(format!(
            " elevation: {length:.0} m of road, {:+.0} m to climb, {} crests ",
            level.goal[1],
            crests.len()
        )))
        .marker(Marker::Braille)
        .x_bounds([-5.0, length + 5.0])
        .y_bounds([lo - 2.0, hi + 2.0])
        .paint(|ctx| {
            for w in samples.windows(2) {
                let colour = colours.get(w[1].segment).copied().unwrap_or(Color::White);
                ctx.draw(&CanvasLine::new(
                    w[0].s,
                    w[0].centre[1],
                    w[1].s,
                    w[1].centre[1],
                    colour,
                ));
            }
            draw_replay(app, ctx, |f| {
                let at = [f[0] as f64, f[1] as f64, f[2] as f64];
                [samples[road.nearest(at, None, 0)].s, f[1] as f64]
            });
            for p in &crests {
                ctx.print(p.s, p.centre[1] + 0.8, "^".yellow());
            }
            ctx.print(length, level.goal[1] + 1.0, "G".green().bold());
        });
    frame.render_widget(canvas, area);
}

fn source_line(level: &Level) -> String {
    match &level.source {
        crate::level::Source::Policy { .. } => "Generator level".into(),
        crate::level::Source::Rules { .. } | crate::level::Source::RacingRules { .. } => {
            "rule level (no Generator)".into()
        }
        crate::level::Source::Hand => "made by hand".into(),
    }
}

fn failures(app: &App, frame: &mut Frame, area: Rect) {
    let block = Block::bordered().title(format!(
        " failures per {} (v: sweep) ",
        piece_name(app.game, false)
    ));
    let (Some(level), Some(trials)) = (&app.level, &app.trials) else {
        frame.render_widget(block, area);
        return;
    };
    let counts = trials.failures_by_block(level.piece_count());
    if counts.iter().all(|&c| c == 0) {
        let text = if trials.done() == 0 {
            "waiting for the first runs"
        } else {
            "no run has failed so far"
        };
        frame.render_widget(Paragraph::new(text).block(block), area);
        return;
    }
    let bars: Vec<Bar> = counts
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let style = if app.selected == Some(i) {
                Style::new().cyan()
            } else {
                Style::new().red()
            };
            Bar::default()
                .value(c as u64)
                .text_value(String::new())
                .style(style)
        })
        .collect();
    let inner = area.width.saturating_sub(2) as usize;
    let gap = usize::from(counts.len() * 2 <= inner);
    let width = ((inner / counts.len().max(1)).saturating_sub(gap)).clamp(1, 3) as u16;
    let chart = BarChart::default()
        .block(block)
        .data(BarGroup::default().bars(&bars))
        .bar_width(width)
        .bar_gap(gap as u16);
    frame.render_widget(chart, area);
}

fn sweep(app: &App, frame: &mut Frame, area: Rect) {
    let Some(sweep) = &app.sweep else {
        frame.render_widget(
            Paragraph::new("press w to sweep λ for this seed and goal")
                .wrap(Wrap { trim: true })
                .block(Block::bordered().title(" λ sweep (v: failures) ")),
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

fn footer(app: &App, frame: &mut Frame, area: Rect) {
    let line = match &app.status {
        Some((text, true)) => Line::from(text.as_str()).red(),
        Some((text, false)) => Line::from(text.as_str()).yellow(),
        None => Line::from(HINTS).dim(),
    };
    frame.render_widget(Paragraph::new(line), area);
}

fn centred(screen: Rect, width: u16, height: u16) -> Rect {
    let [row] = Layout::vertical([Constraint::Length(height.min(screen.height))])
        .flex(Flex::Center)
        .areas(screen);
    let [area] = Layout::horizontal([Constraint::Length(width.min(screen.width))])
        .flex(Flex::Center)
        .areas(row);
    area
}

fn overlay(app: &App, frame: &mut Frame, screen: Rect) {
    match &app.overlay {
        Overlay::None => {}
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
                ("Generator", &app.policies.generator),
                ("Solver", &app.policies.solver),
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
                        lines.push(Line::from(format!("  command: {}", t.command)).dim());
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
