//! Pacing in the designer: λ along the level from a preset or a typed curve (`P`, `C`), and a
//! locked prefix (`k` keeps every piece up to the selected one, `K` lets go) that every
//! regeneration keeps.

use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};

use super::super::layout::{SLIDER_LEFT, SLIDER_RIGHT};
use super::{App, Ask, Effect};
use crate::services::generation::KeptPrefix;
use arlpcg_core::level::PolicyRef;
use arlpcg_core::level::pacing::AuxCurve;

/// The presets `P` cycles through, after the plain slider.
pub const PRESETS: [(&str, &str); 4] = [
    ("ramp up", "0:1, 1:-1"),
    ("ramp down", "0:-1, 1:1"),
    ("hard middle", "0:1, 0.3:1, 0.4:-1, 0.6:-1, 0.7:1, 1:1"),
    ("breather", "0:-1, 0.7:-1, 0.8:1, 1:1"),
];

fn preset(k: usize) -> AuxCurve {
    AuxCurve::parse(PRESETS[k].1).expect("the presets parse")
}

/// The name of the preset `curve` is, or `custom`.
pub fn preset_name(curve: &AuxCurve) -> &'static str {
    (0..PRESETS.len())
        .find(|&k| preset(k) == *curve)
        .map_or("custom", |k| PRESETS[k].0)
}

impl App {
    /// `P`: the next preset (after the last, back to one λ from the slider).
    pub(super) fn next_pacing(&mut self) -> Vec<Effect> {
        let next = match self.ask.curve() {
            None => Some(0),
            Some(curve) => (0..PRESETS.len())
                .position(|k| preset(k) == *curve)
                .map(|k| k + 1)
                .filter(|&k| k < PRESETS.len()),
        };
        self.set_pacing(next.map(preset))
    }

    /// A curve typed at the `C` prompt.
    pub(super) fn submit_curve(&mut self, text: &str) -> Vec<Effect> {
        match AuxCurve::parse(text) {
            Ok(curve) => self.set_pacing(Some(curve)),
            Err(problem) => {
                self.complain(format!("aux curve: {problem}"));
                Vec::new()
            }
        }
    }

    /// Pacing on (`Some`) or off: a Generator is needed to follow a curve.
    pub(super) fn set_pacing(&mut self, pacing: Option<AuxCurve>) -> Vec<Effect> {
        if pacing.is_some() && self.policies().generator.is_none() {
            self.complain("pacing needs a Generator (p loads one): rule levels have no λ");
            return Vec::new();
        }
        match &pacing {
            Some(curve) => self.say(format!("pacing: {} ({curve})", preset_name(curve))),
            None => self.say(format!("one λ again: {:+.2}", self.aux)),
        }
        self.ask = pacing.map_or(Ask::Aux(self.aux), Ask::Curve);
        self.generate()
    }

    /// `k`: keep every piece up to the selected one; later levels continue after them.
    pub(super) fn keep_prefix(&mut self) -> Vec<Effect> {
        let (Some(level), Some(selected)) = (&self.level, self.selected) else {
            self.complain("select the last piece to keep with ↑ ↓ first");
            return Vec::new();
        };
        if self.policies().generator.is_none() {
            self.complain("keeping a prefix needs a Generator (p loads one) to build the rest");
            return Vec::new();
        }
        let text = arlpcg_core::level::yaml::to_string(level);
        let pieces = selected + 1;
        self.kept = Some(KeptPrefix {
            level: level.clone(),
            pieces,
            from: PolicyRef::pinned(format!("designer: {}", self.export_stem()), text.as_bytes()),
        });
        self.say(format!(
            "keeping the first {pieces} {}: K lets go",
            arlpcg_core::game::facts::facts(self.game).pieces
        ));
        if self.ask.success().is_some() {
            self.ask = Ask::Aux(self.aux);
        }
        self.generate()
    }

    /// `K`: let go of the kept prefix.
    pub(super) fn release_prefix(&mut self) -> Vec<Effect> {
        if self.kept.take().is_none() {
            return Vec::new();
        }
        self.say("the whole level is generated again");
        self.generate()
    }
}

/// The slider's line while pacing: the curve from start to goal, `width` characters, taller
/// where it is harder.
pub(crate) fn curve_line(curve: &AuxCurve, width: usize) -> Line<'static> {
    let profile: String = (0..width)
        .map(|i| {
            let aux = curve.at(i as f64 / width.saturating_sub(1).max(1) as f64);
            let level = ((1.0 - aux) / 2.0 * 7.0).round() as usize;
            ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'][level.min(7)]
        })
        .collect();
    // Labels as wide as the slider's; the preset and its curve on the settings line.
    Line::from(vec![
        Span::raw(format!("{:<w$}", "start", w = SLIDER_LEFT.chars().count())),
        Span::styled(profile, Style::new().fg(Color::Magenta)),
        Span::raw(format!("{:>w$}", "goal", w = SLIDER_RIGHT.chars().count())),
        Span::styled("  pacing", Style::new().bold()),
    ])
}

/// The colour of λ: green at +1 (easy), yellow at 0, red at -1 (hard).
pub fn aux_colour(aux: f64) -> Color {
    let hard = ((1.0 - aux) / 2.0).clamp(0.0, 1.0);
    let red = (255.0 * (2.0 * hard).min(1.0)) as u8;
    let green = (255.0 * (2.0 * (1.0 - hard)).min(1.0)) as u8;
    Color::Rgb(red, green, 40)
}
