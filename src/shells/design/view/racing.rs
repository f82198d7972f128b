//! The racing track's drawing: the road from above with its obstacles, the elevation with its
//! crests, and the track's statistics.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Stylize};
use ratatui::symbols::Marker;
use ratatui::text::Line;
use ratatui::widgets::Block;
use ratatui::widgets::canvas::{Canvas, Line as CanvasLine, Points};

use crate::shells::design::app::App;
use arlpcg_core::level::Level;
use arlpcg_core::level::heading::heading_direction;
use arlpcg_core::level::racing::{Obstacle, RacingTrack};
use arlpcg_core::level::road::Road;

use super::{MOST_FAILED_MARK, draw_replay, map_canvas, most_failed_piece, piece_colours};

/// The racing track's statistics and the selected segment, for the stats panel.
pub(super) fn stats(app: &App, track: &RacingTrack, lines: &mut Vec<Line>) {
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
pub(super) fn map(
    app: &App,
    level: &Level,
    track: &RacingTrack,
    road: &Road,
    frame: &mut Frame,
    area: Rect,
) {
    let colours = piece_colours(app, track.segments.len());
    let most_failed = most_failed_piece(app, track.segments.len());
    let half = 0.5 * road.shape().width;
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
    let title = format!(
        " top-down: {} segments, {:.0} m of road, goal {:.0} m ",
        track.segments.len(),
        road.length(),
        level.goal[0].hypot(level.goal[2])
    );
    let canvas = map_canvas(title, &points, area, 5.0, |ctx| {
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
        if let Some(i) = most_failed {
            let (first, last) = road.segment_samples(i);
            let middle = road.samples()[(first + last) / 2];
            ctx.print(
                middle.centre[0],
                middle.centre[2],
                MOST_FAILED_MARK.red().bold(),
            );
        }
        ctx.print(level.goal[0], level.goal[2], "G".green().bold());
        ctx.print(track.position[0], track.position[2], "S".blue().bold());
    });
    frame.render_widget(canvas, area);
}

/// The road's elevation along its length, coloured by the failures on each segment, with its
/// crests marked `^` (where the car may leave the ground).
pub(super) fn profile(app: &App, level: &Level, road: &Road, frame: &mut Frame, area: Rect) {
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
    let crests: Vec<&arlpcg_core::level::road::RoadSample> = samples
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
                    w[0].s, w[0].centre[1], w[1].s, w[1].centre[1], colour,
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
