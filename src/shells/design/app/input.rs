//! The designer's input: keys (with the prompts they open) and the mouse on the slider (λ or a
//! style knob), as changes of [`App`] and the effects they ask for.

use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEvent, MouseEventKind,
};
use ratatui::layout::Position;

use super::*;

impl App {
    pub(super) fn key(&mut self, key: KeyEvent) -> Vec<Effect> {
        if key.kind == KeyEventKind::Release {
            return Vec::new();
        }
        if key.modifiers.contains(KeyModifiers::CONTROL) && key.code == KeyCode::Char('c') {
            self.mode = Mode::Quitting;
            return Vec::new();
        }
        match std::mem::replace(&mut self.overlay, Overlay::None) {
            Overlay::None => {}
            Overlay::Help | Overlay::Cards => {
                if !matches!(key.code, KeyCode::Char('q')) {
                    return Vec::new();
                }
            }
            Overlay::Prompt { kind, text } => return self.prompt_key(kind, text, key),
            Overlay::Campaign => return self.campaign_view_key(key),
            Overlay::ConfirmOverwrite { .. } => {
                if matches!(key.code, KeyCode::Char('y' | 'Y')) {
                    return self.export(true);
                }
                self.say("export cancelled: nothing written");
                return Vec::new();
            }
        }
        self.status = None;
        match key.code {
            KeyCode::Char('q') | KeyCode::Esc => {
                self.mode = Mode::Quitting;
                Vec::new()
            }
            KeyCode::Char('?') => {
                self.overlay = Overlay::Help;
                Vec::new()
            }
            KeyCode::Char('c') => {
                self.overlay = Overlay::Cards;
                Vec::new()
            }
            KeyCode::Char('j') => {
                self.say("switching judge".to_string());
                vec![Effect::NextJudge {
                    game: self.game,
                    after: self.policies().judge(),
                    folder: self.policies().folder(),
                }]
            }
            KeyCode::Tab => self.switch_game(),
            KeyCode::Left => self.set_slider(self.slider_value() - AUX_STEP),
            KeyCode::Right => self.set_slider(self.slider_value() + AUX_STEP),
            KeyCode::Home => self.set_slider(-1.0),
            KeyCode::End => self.set_slider(1.0),
            KeyCode::Char('m') => self.next_slider(),
            KeyCode::Enter | KeyCode::Char(' ') => self.generate(),
            KeyCode::Char('n') => {
                self.seed = next_seed(self.seed);
                self.generate()
            }
            KeyCode::Char('s') => self.open_prompt(PromptKind::Seed),
            KeyCode::Char('t') => self.open_prompt(PromptKind::Trials),
            KeyCode::Char('T') => self.open_prompt(PromptKind::Target),
            KeyCode::Char('W') => self.open_prompt(PromptKind::Want),
            KeyCode::Char('p') => self.open_prompt(PromptKind::Policies),
            KeyCode::Char('g') => self.toggle_goal(),
            KeyCode::Char('d') => self.adjust_goal(-1.0, 0.0, 0.0),
            KeyCode::Char('D') => self.adjust_goal(1.0, 0.0, 0.0),
            KeyCode::Char('h') => self.adjust_goal(0.0, -1.0, 0.0),
            KeyCode::Char('H') => self.adjust_goal(0.0, 1.0, 0.0),
            KeyCode::Char('a') => self.adjust_goal(0.0, 0.0, -15.0),
            KeyCode::Char('A') => self.adjust_goal(0.0, 0.0, 15.0),
            KeyCode::Up => {
                self.select(-1);
                Vec::new()
            }
            KeyCode::Down => {
                self.select(1);
                Vec::new()
            }
            KeyCode::Char('r') => self.record(),
            KeyCode::Char('w') => self.sweep(),
            KeyCode::Char('v') => {
                self.panel = match self.panel {
                    SidePane::Failures => SidePane::Sweep,
                    SidePane::Sweep => SidePane::Judges,
                    SidePane::Judges => SidePane::Failures,
                };
                self.judge_if_shown()
            }
            KeyCode::Char('V') => self.open_view(),
            KeyCode::Char('J') => self.judge_level(),
            KeyCode::Char('x') => self.export(false),
            KeyCode::Char('P') => self.next_pacing(),
            KeyCode::Char('C') => self.open_prompt(PromptKind::Curve),
            KeyCode::Char('o') => self.campaign_key_o(),
            KeyCode::Char('f') => self.profile_prompt(),
            KeyCode::Char('e') => self.next_ability(),
            KeyCode::Char('[') => self.scale_ability(0.95),
            KeyCode::Char(']') => self.scale_ability(1.05),
            KeyCode::Char('k') => self.keep_prefix(),
            KeyCode::Char('K') => self.release_prefix(),
            _ => Vec::new(),
        }
    }

    pub(super) fn open_prompt(&mut self, kind: PromptKind) -> Vec<Effect> {
        let text = match kind {
            PromptKind::Seed => self.seed.to_string(),
            PromptKind::Trials => self.trials_wanted.to_string(),
            PromptKind::Target => self.ask.success().map_or(String::new(), |t| format!("{t}")),
            PromptKind::Policies => String::new(),
            PromptKind::Curve => self.ask.curve().map_or(String::new(), ToString::to_string),
            PromptKind::Want => self.want().map_or(String::new(), ToString::to_string),
            PromptKind::Campaign | PromptKind::Profile => String::new(),
        };
        self.overlay = Overlay::Prompt { kind, text };
        Vec::new()
    }

    fn prompt_key(&mut self, kind: PromptKind, mut text: String, key: KeyEvent) -> Vec<Effect> {
        match key.code {
            KeyCode::Esc => return Vec::new(),
            KeyCode::Enter => return self.submit(kind, text.trim()),
            KeyCode::Backspace => {
                text.pop();
            }
            KeyCode::Char(c) if text.chars().count() < 200 => text.push(c),
            _ => {}
        }
        self.overlay = Overlay::Prompt { kind, text };
        Vec::new()
    }

    fn submit(&mut self, kind: PromptKind, text: &str) -> Vec<Effect> {
        match kind {
            PromptKind::Profile if text.is_empty() => Vec::new(),
            PromptKind::Profile => self.submit_profile(text),
            PromptKind::Campaign if text.is_empty() => Vec::new(),
            PromptKind::Campaign => self.open_campaign(PathBuf::from(text)),
            PromptKind::Seed => match text.parse::<u64>() {
                Ok(seed) => {
                    self.seed = seed;
                    self.generate()
                }
                Err(_) => {
                    self.complain(format!("seed `{text}`: give a whole number ≥ 0"));
                    Vec::new()
                }
            },
            PromptKind::Trials => match text.parse::<u32>() {
                Ok(n) if (1..=MAX_TRIALS).contains(&n) => {
                    self.trials_wanted = n;
                    self.start_trials()
                }
                _ => {
                    self.complain(format!(
                        "trials `{text}`: give a number from 1 to {MAX_TRIALS}"
                    ));
                    Vec::new()
                }
            },
            PromptKind::Target if text.trim().is_empty() => {
                if self.ask.success().is_none() {
                    return Vec::new();
                }
                self.say("back to the λ slider");
                self.set_target(None)
            }
            PromptKind::Target => match text.trim().parse::<f64>() {
                Ok(p) if (0.05..=0.95).contains(&p) => self.set_target(Some(p)),
                _ => {
                    self.complain(format!(
                        "target `{text}`: give a success rate from 0.05 to 0.95 (e.g. 0.6)"
                    ));
                    Vec::new()
                }
            },
            PromptKind::Want => self.submit_want(text),
            PromptKind::Curve if text.is_empty() => Vec::new(),
            PromptKind::Curve => self.submit_curve(text),
            PromptKind::Policies if text.is_empty() => Vec::new(),
            PromptKind::Policies => {
                self.say(format!("loading {text}"));
                vec![Effect::Load {
                    path: PathBuf::from(text),
                    game: self.game,
                }]
            }
        }
    }

    /// A wish list typed at `W` (or a sentence, read as one): each level is searched to meet
    /// it, the statistics show each constraint ✓ or ✗; empty: none.
    fn submit_want(&mut self, text: &str) -> Vec<Effect> {
        use crate::services::panel::Judge;
        use crate::services::wish::{Want, words};
        if text.is_empty() {
            if self.wants[self.game].take().is_some() {
                self.say("no wish list: λ alone");
                return self.generate();
            }
            return Vec::new();
        }
        let read = match Want::parse(text) {
            Ok(want) => Ok((want, String::new())),
            Err(_) => words::read(text, self.game).map(|r| {
                let unused: Vec<String> = r.unknown.into_iter().chain(r.other_game).collect();
                let unused = match unused.is_empty() {
                    true => String::new(),
                    false => format!(" (not used: {})", unused.join(", ")),
                };
                (r.want, unused)
            }),
        };
        let checked = read.and_then(|(want, unused)| {
            want.fit_search(self.game)?;
            match want.judges().iter().any(|j| matches!(j, Judge::Solver(_))) {
                true => Err("the designer plays the scripted judges; a Solver judge's success: arlpcg generate --want".into()),
                false => Ok((want, unused)),
            }
        });
        match checked {
            Ok((want, unused)) => {
                self.say(format!("wish list: {want}{unused}"));
                self.wants[self.game] = Some(want);
                self.generate()
            }
            Err(e) => {
                self.complain(format!("wish list: {e}"));
                Vec::new()
            }
        }
    }

    /// The value of the slider the keys move: λ, or the selected knob's.
    fn slider_value(&self) -> f64 {
        match self.slider {
            0 => self.aux,
            k => self.knobs[k - 1],
        }
    }

    /// Moves the slider the keys move (λ or the selected knob) to `value`.
    fn set_slider(&mut self, value: f64) -> Vec<Effect> {
        match self.slider {
            0 => self.set_aux(value),
            k => self.set_knob(k - 1, value),
        }
    }

    /// `m`: the next slider for the arrow keys (λ, then each knob), for a Generator with knobs.
    fn next_slider(&mut self) -> Vec<Effect> {
        self.fit_knobs();
        let names = self.knob_names();
        if names.is_empty() {
            self.complain(
                "this Generator takes no style knobs (train one with generator.rewards.knobs)",
            );
            return Vec::new();
        }
        self.slider = (self.slider + 1) % (names.len() + 1);
        let name = match self.slider {
            0 => "λ",
            k => names[k - 1],
        };
        self.say(format!("the arrows move {name} (m: the next slider)"));
        Vec::new()
    }

    /// `V`: the level on screen in 3D in the web browser (the shell serves it).
    fn open_view(&mut self) -> Vec<Effect> {
        if self.level.is_none() {
            self.complain("no level to show yet");
            return Vec::new();
        }
        vec![Effect::OpenView]
    }

    fn set_knob(&mut self, k: usize, value: f64) -> Vec<Effect> {
        let value = (value.clamp(-1.0, 1.0) * 100.0).round() / 100.0;
        if self.knobs[k] == value {
            return Vec::new();
        }
        self.knobs[k] = value;
        self.generate()
    }

    /// The mouse on the slider: a click, a drag or the wheel moves it (λ, or the knob `m`
    /// picked).
    pub(super) fn mouse(&mut self, mouse: MouseEvent) -> Vec<Effect> {
        if self.overlay != Overlay::None {
            return Vec::new();
        }
        let slider = Areas::with_knobs(self.size, self.knob_names()).slider;
        let at = Position::new(mouse.column, mouse.row);
        match mouse.kind {
            MouseEventKind::Down(MouseButton::Left) if slider.contains(at) => {
                self.dragging = true;
                self.set_slider(slider_aux(slider, mouse.column))
            }
            MouseEventKind::Drag(MouseButton::Left) if self.dragging => {
                self.set_slider(slider_aux(slider, mouse.column))
            }
            MouseEventKind::Up(_) => {
                self.dragging = false;
                Vec::new()
            }
            MouseEventKind::ScrollUp if slider.contains(at) => {
                self.set_slider(self.slider_value() + AUX_STEP)
            }
            MouseEventKind::ScrollDown if slider.contains(at) => {
                self.set_slider(self.slider_value() - AUX_STEP)
            }
            _ => Vec::new(),
        }
    }
}

/// A prompt being typed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PromptKind {
    /// The seed.
    Seed,
    /// Solver trials per level.
    Trials,
    /// A policies folder or policy file to load.
    Policies,
    /// A target success rate.
    Target,
    /// A wish list, or a sentence in plain words.
    Want,
    /// An aux curve.
    Curve,
    /// A campaign folder to open.
    Campaign,
    /// A game profile file to load.
    Profile,
}

impl PromptKind {
    /// What the prompt asks for, in words.
    pub fn label(self) -> &'static str {
        match self {
            PromptKind::Seed => "seed",
            PromptKind::Trials => "Solver trials per level",
            PromptKind::Target => "target success rate, 0.05-0.95 (empty: back to the λ slider)",
            PromptKind::Want => "wish list or plain words, docs/wish.md (empty: none)",
            PromptKind::Policies => "policies folder, or a Generator/Solver .safetensors file",
            PromptKind::Curve => "aux curve, fraction:λ, ... (e.g. 0:1, 0.5:1, 0.6:-1, 1:-1)",
            PromptKind::Campaign => "campaign folder (what `arlpcg campaign` wrote)",
            PromptKind::Profile => "game profile file (`arlpcg profile init` writes one)",
        }
    }
}
