//! Pacing in the designer: λ along the level from a preset or a typed curve (`P`, `C`), and a
//! locked prefix (`k` keeps every piece up to the selected one, `K` lets go) that every
//! regeneration keeps.

use super::*;
use crate::services::generation::KeptPrefix;
use arlpcg_core::level::PolicyRef;
use arlpcg_core::level::pacing::AuxCurve;

/// λ along the level the designer asks the Generator for.
#[derive(Debug, Clone, PartialEq)]
pub struct PacingChoice {
    /// The preset's name, or `custom`.
    pub name: &'static str,
    pub curve: AuxCurve,
}

/// The presets `P` cycles through, after the plain slider.
pub const PRESETS: [(&str, &str); 4] = [
    ("ramp up", "0:1, 1:-1"),
    ("ramp down", "0:-1, 1:1"),
    ("hard middle", "0:1, 0.3:1, 0.4:-1, 0.6:-1, 0.7:1, 1:1"),
    ("breather", "0:-1, 0.7:-1, 0.8:1, 1:1"),
];

fn preset(k: usize) -> PacingChoice {
    let (name, text) = PRESETS[k];
    PacingChoice {
        name,
        curve: AuxCurve::parse(text).expect("the presets parse"),
    }
}

impl App {
    /// `P`: the next preset (after the last, back to one λ from the slider).
    pub(super) fn next_pacing(&mut self) -> Vec<Effect> {
        let next = match self.ask.pacing() {
            None => Some(0),
            Some(choice) => PRESETS
                .iter()
                .position(|(name, _)| *name == choice.name)
                .map(|k| k + 1)
                .filter(|&k| k < PRESETS.len()),
        };
        self.set_pacing(next.map(preset))
    }

    /// A curve typed at the `C` prompt.
    pub(super) fn submit_curve(&mut self, text: &str) -> Vec<Effect> {
        match AuxCurve::parse(text) {
            Ok(curve) => self.set_pacing(Some(PacingChoice {
                name: "custom",
                curve,
            })),
            Err(problem) => {
                self.complain(format!("aux curve: {problem}"));
                Vec::new()
            }
        }
    }

    /// Pacing on (`Some`) or off: a Generator is needed to follow a curve.
    pub(super) fn set_pacing(&mut self, pacing: Option<PacingChoice>) -> Vec<Effect> {
        if pacing.is_some() && self.policies.generator.is_none() {
            self.complain("pacing needs a Generator (p loads one): rule levels have no λ");
            return Vec::new();
        }
        match &pacing {
            Some(choice) => self.say(format!("pacing: {} ({})", choice.name, choice.curve)),
            None => self.say(format!("one λ again: {:+.2}", self.aux)),
        }
        self.ask = pacing.map_or(Ask::Slider, Ask::Pacing);
        self.generate()
    }

    /// `k`: keep every piece up to the selected one; later levels continue after them.
    pub(super) fn keep_prefix(&mut self) -> Vec<Effect> {
        let (Some(level), Some(selected)) = (&self.level, self.selected) else {
            self.complain("select the last piece to keep with ↑ ↓ first");
            return Vec::new();
        };
        if self.policies.generator.is_none() {
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
        if self.ask.target().is_some() {
            self.ask = Ask::Slider;
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
