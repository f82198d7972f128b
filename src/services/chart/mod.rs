//! Line charts as PNG files, with no system dependency: the lines are drawn into an RGB buffer,
//! the text is rasterized with `ab_glyph` from the bundled DejaVu Sans (free licence,
//! `LICENSE-DejaVu.txt` beside it), and `png` encodes the result. Used for the learning curves of `train` and the
//! chart of `eval`. The same chart gives the same bytes.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};

const FONT: &[u8] = include_bytes!("DejaVuSans.ttf");
const WIDTH: usize = 900;
const HEIGHT: usize = 520;
/// Plot area margins: left, right, top, bottom, px.
const MARGIN: [usize; 4] = [80, 190, 50, 60];
const BACKGROUND: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [40, 40, 40];
const GRID: [u8; 3] = [225, 225, 225];
/// Series colours, in order (colour-blind friendly).
const PALETTE: [[u8; 3]; 6] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
];

/// One named line of points (x, y); NaN points are skipped (the line breaks there).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The line's name, in the legend.
    pub name: String,
    /// Its points.
    pub points: Vec<(f64, f64)>,
}

/// A line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// The chart's title.
    pub title: String,
    /// The x axis's label.
    pub x_label: String,
    /// The y axis's label.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Fixed y range; by default the data's range.
    pub y_range: Option<(f64, f64)>,
}

struct Canvas {
    pixels: Vec<u8>,
    font: FontRef<'static>,
}

impl Canvas {
    fn new() -> Self {
        Self {
            pixels: BACKGROUND.repeat(WIDTH * HEIGHT),
            font: FontRef::try_from_slice(FONT).expect("the bundled font parses"),
        }
    }

    /// Blends `color` into pixel (x, y) with coverage `alpha`.
    fn blend(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x >= WIDTH as i64 || y >= HEIGHT as i64 {
            return;
        }
        let i = (y as usize * WIDTH + x as usize) * 3;
        let a = alpha.clamp(0.0, 1.0);
        for (k, c) in color.iter().enumerate() {
            let old = self.pixels[i + k] as f32;
            self.pixels[i + k] = (old + (*c as f32 - old) * a).round() as u8;
        }
    }

    /// A line `width` px wide, drawn as overlapping discs along it.
    fn line(&mut self, from: (f64, f64), to: (f64, f64), color: [u8; 3], width: f64) {
        let length = (to.0 - from.0).hypot(to.1 - from.1);
        let steps = (length * 2.0).ceil().max(1.0) as usize;
        let r = width / 2.0;
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let (cx, cy) = (from.0 + (to.0 - from.0) * t, from.1 + (to.1 - from.1) * t);
            let reach = r.ceil() as i64 + 1;
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let (px, py) = (cx.floor() as i64 + dx, cy.floor() as i64 + dy);
                    let d = (px as f64 + 0.5 - cx).hypot(py as f64 + 0.5 - cy);
                    let coverage = (r + 0.5 - d).clamp(0.0, 1.0) as f32;
                    if coverage > 0.0 {
                        self.blend_max(px, py, color, coverage);
                    }
                }
            }
        }
    }

    /// Like `blend`, but a pixel already closer to `color` keeps its value (overlapping discs
    /// of one line do not darken each other).
    fn blend_max(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x >= WIDTH as i64 || y >= HEIGHT as i64 {
            return;
        }
        let i = (y as usize * WIDTH + x as usize) * 3;
        for (k, c) in color.iter().enumerate() {
            let old = self.pixels[i + k] as f32;
            let target = old + (*c as f32 - old) * alpha;
            let closer = (target - *c as f32).abs() < (old - *c as f32).abs();
            if closer {
                self.pixels[i + k] = target.round() as u8;
            }
        }
    }

    fn rect(&mut self, x0: usize, y0: usize, x1: usize, y1: usize, color: [u8; 3]) {
        for y in y0..y1.min(HEIGHT) {
            for x in x0..x1.min(WIDTH) {
                self.blend(x as i64, y as i64, color, 1.0);
            }
        }
    }

    /// Width of `text` at `size` px.
    fn text_width(&self, text: &str, size: f32) -> f64 {
        let font = self.font.as_scaled(PxScale::from(size));
        text.chars()
            .map(|c| font.h_advance(font.glyph_id(c)) as f64)
            .sum()
    }

    /// Draws `text` with its baseline-left at (x, y); `rotated`: reading upward (y axis label).
    fn text(&mut self, text: &str, x: f64, y: f64, size: f32, color: [u8; 3], rotated: bool) {
        let scale = PxScale::from(size);
        let scaled = self.font.as_scaled(scale);
        let mut caret = 0.0f32;
        let mut coverage = Vec::new();
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            let glyph = id.with_scale_and_position(scale, point(caret, 0.0));
            caret += scaled.h_advance(id);
            if let Some(outline) = self.font.outline_glyph(glyph) {
                let bounds = outline.px_bounds();
                outline.draw(|gx, gy, a| {
                    coverage.push((
                        bounds.min.x as f64 + gx as f64,
                        bounds.min.y as f64 + gy as f64,
                        a,
                    ));
                });
            }
        }
        for (gx, gy, a) in coverage {
            let (px, py) = if rotated {
                (x + gy, y - gx)
            } else {
                (x + gx, y + gy)
            };
            self.blend(px.round() as i64, py.round() as i64, color, a);
        }
    }

    fn png(&self) -> Vec<u8> {
        encode(&self.pixels, HEIGHT)
    }
}

/// RGB rows of [`WIDTH`] pixels, `height` of them, as PNG bytes.
fn encode(pixels: &[u8], height: usize) -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, WIDTH as u32, height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .expect("writing to memory cannot fail");
        writer
            .write_image_data(pixels)
            .expect("the buffer matches the header");
    }
    bytes
}

/// Charts one above the other in one PNG, each as [`LineChart::to_png`] draws it alone.
pub fn stacked_png(charts: &[LineChart]) -> Vec<u8> {
    let pixels: Vec<u8> = charts.iter().flat_map(|c| c.draw().pixels).collect();
    encode(&pixels, HEIGHT * charts.len())
}

/// About five round tick values covering [lo, hi].
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / 5.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick label: few digits, SI suffixes for large values.
fn label(value: f64) -> String {
    let a = value.abs();
    if a >= 1e6 {
        format!("{:.1}M", value / 1e6)
    } else if a >= 1e4 {
        format!("{:.0}k", value / 1e3)
    } else if a >= 100.0 || value.fract() == 0.0 {
        format!("{value:.0}")
    } else {
        format!("{value:.2}")
    }
}

impl LineChart {
    /// The chart as PNG bytes.
    pub fn to_png(&self) -> Vec<u8> {
        self.draw().png()
    }

    fn draw(&self) -> Canvas {
        let finite = |v: &f64| v.is_finite();
        let points = || self.series.iter().flat_map(|s| s.points.iter());
        let xs: Vec<f64> = points().map(|p| p.0).filter(finite).collect();
        let ys: Vec<f64> = points().map(|p| p.1).filter(finite).collect();
        let range = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            match (lo.is_finite(), hi > lo) {
                (true, true) => (lo, hi),
                (true, false) => (lo - 1.0, lo + 1.0),
                _ => (0.0, 1.0),
            }
        };
        let (x0, x1) = range(&xs);
        let (y0, y1) = self.y_range.unwrap_or_else(|| range(&ys));
        let [left, right, top, bottom] = MARGIN;
        let (w, h) = (
            (WIDTH - left - right) as f64,
            (HEIGHT - top - bottom) as f64,
        );
        let to_px = |x: f64, y: f64| {
            (
                left as f64 + (x - x0) / (x1 - x0) * w,
                top as f64 + (1.0 - (y - y0) / (y1 - y0)) * h,
            )
        };
        let mut canvas = Canvas::new();
        for y in ticks(y0, y1) {
            let (_, py) = to_px(x0, y);
            canvas.rect(left, py as usize, WIDTH - right, py as usize + 1, GRID);
            let text = label(y);
            let tw = canvas.text_width(&text, 13.0);
            canvas.text(&text, left as f64 - 8.0 - tw, py + 4.0, 13.0, INK, false);
        }
        for x in ticks(x0, x1) {
            let (px, _) = to_px(x, y0);
            canvas.rect(px as usize, top, px as usize + 1, HEIGHT - bottom, GRID);
            let text = label(x);
            let tw = canvas.text_width(&text, 13.0);
            let y = (HEIGHT - bottom) as f64 + 18.0;
            canvas.text(&text, px - tw / 2.0, y, 13.0, INK, false);
        }
        canvas.rect(left, top, left + 1, HEIGHT - bottom, INK);
        canvas.rect(
            left,
            HEIGHT - bottom,
            WIDTH - right,
            HEIGHT - bottom + 1,
            INK,
        );
        for (k, series) in self.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let mut previous: Option<(f64, f64)> = None;
            for &(x, y) in &series.points {
                if !(x.is_finite() && y.is_finite()) {
                    previous = None;
                    continue;
                }
                let p = to_px(x, y.clamp(y0, y1));
                match previous {
                    Some(q) => canvas.line(q, p, color, 2.0),
                    None => canvas.line(p, p, color, 4.0),
                }
                previous = Some(p);
            }
            let ly = top as f64 + 20.0 + 22.0 * k as f64;
            let lx = (WIDTH - right) as f64 + 16.0;
            canvas.line((lx, ly - 4.0), (lx + 24.0, ly - 4.0), color, 3.0);
            canvas.text(&series.name, lx + 32.0, ly, 13.0, INK, false);
        }
        let tw = canvas.text_width(&self.title, 17.0);
        canvas.text(
            &self.title,
            (WIDTH as f64 - tw) / 2.0,
            30.0,
            17.0,
            INK,
            false,
        );
        let tw = canvas.text_width(&self.x_label, 14.0);
        let x_label_at = left as f64 + (w - tw) / 2.0;
        canvas.text(
            &self.x_label,
            x_label_at,
            HEIGHT as f64 - 14.0,
            14.0,
            INK,
            false,
        );
        let tw = canvas.text_width(&self.y_label, 14.0);
        let y_label_at = top as f64 + (h + tw) / 2.0;
        canvas.text(&self.y_label, 22.0, y_label_at, 14.0, INK, true);
        canvas
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> LineChart {
        LineChart {
            title: "Solver success".into(),
            x_label: "environment steps".into(),
            y_label: "success ratio".into(),
            series: vec![
                Series {
                    name: "rule-pcg".into(),
                    points: vec![(0.0, 0.0), (1e6, 0.5), (f64::NAN, 0.6), (2e6, 0.9)],
                },
                Series {
                    name: "arlpcg".into(),
                    points: vec![(0.0, 0.1), (2e6, 0.95)],
                },
            ],
            y_range: Some((0.0, 1.0)),
        }
    }

    #[test]
    fn a_chart_is_a_png_of_its_size_with_ink_and_colour_and_the_same_bytes_each_time() {
        let bytes = chart().to_png();
        assert_eq!(bytes, chart().to_png());
        let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut pixels).unwrap();
        assert_eq!((info.width, info.height), (WIDTH as u32, HEIGHT as u32));
        let rgb: Vec<&[u8]> = pixels.chunks(3).collect();
        let dark = rgb.iter().filter(|p| p.iter().all(|&c| c < 100)).count();
        let blue = rgb.iter().filter(|p| **p == PALETTE[0]).count();
        let orange = rgb.iter().filter(|p| **p == PALETTE[1]).count();
        assert!(dark > 2000, "axes and text: {dark} dark pixels");
        assert!(
            blue > 300 && orange > 300,
            "both lines drawn: {blue}, {orange}"
        );
    }

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(
            ticks(0.0, 1.0),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        assert_eq!(ticks(0.0, 4_000_000.0).len(), 5);
        assert_eq!(label(2_500_000.0), "2.5M");
        assert_eq!(label(0.25), "0.25");
    }
}
