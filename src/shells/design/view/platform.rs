//! The platform level's drawing: blocks from above and the side profile.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Stylize};
use ratatui::symbols::Marker;
use ratatui::widgets::Block;
use ratatui::widgets::canvas::{Canvas, Line as CanvasLine};

use crate::shells::design::app::App;
use arlpcg_core::level::Level;
use arlpcg_core::level::heading::heading_direction;
use arlpcg_core::level::platform::{Platform, PlatformTrack};

use super::{MOST_FAILED_MARK, draw_replay, map_canvas, most_failed_piece, piece_colours};

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

pub(super) fn map(app: &App, level: &Level, track: &PlatformTrack, frame: &mut Frame, area: Rect) {
    let platforms = track.platforms();
    let colours = platform_colours(app, track.block_count());
    let most_failed = most_failed_piece(app, track.block_count());
    let mut points: Vec<[f64; 2]> = platforms.iter().flat_map(corners).collect();
    points.push([level.goal[0], level.goal[2]]);
    let title = format!(
        " top-down: {} blocks, goal {:.0} m ",
        track.block_count(),
        level.goal[0].hypot(level.goal[2])
    );
    let canvas = map_canvas(title, &points, area, 2.0, |ctx| {
        for (p, &colour) in platforms.iter().zip(&colours) {
            let c = corners(p);
            for k in 0..4 {
                let (a, b) = (c[k], c[(k + 1) % 4]);
                ctx.draw(&CanvasLine::new(a[0], a[1], b[0], b[1], colour));
            }
        }
        draw_replay(app, ctx, |f| [f[0] as f64, f[2] as f64]);
        if let Some(p) = most_failed.and_then(|i| platforms.get(i + 1)) {
            ctx.print(p.position[0], p.position[2], MOST_FAILED_MARK.red().bold());
        }
        ctx.print(level.goal[0], level.goal[2], "G".green().bold());
        let start = platforms[0].position;
        ctx.print(start[0], start[2], "S".blue().bold());
    });
    frame.render_widget(canvas, area);
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

pub(super) fn profile(
    app: &App,
    level: &Level,
    track: &PlatformTrack,
    frame: &mut Frame,
    area: Rect,
) {
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
