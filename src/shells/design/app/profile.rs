//! The game profile the designer's levels are made for (docs/games.md, profiles): `f` loads a
//! profile file, `e` picks one of the game's main abilities, `[` and `]` scale it by 5% within
//! its range; each change makes the level again, and the trials follow.

use std::path::PathBuf;

use super::{App, Effect, PromptKind};
use arlpcg_core::level::profile::{Profile, main_abilities};

/// The profile levels are made for, and the ability its keys change.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProfileEdit {
    /// None: the built-in profile.
    pub profile: Option<Profile>,
    /// Index into the game's [`main_abilities`].
    pub ability: usize,
}

/// What marks a profile changed by the keys.
const EDITED: &str = " (edited)";

impl App {
    /// `f`: type the path of a profile file.
    pub(super) fn profile_prompt(&mut self) -> Vec<Effect> {
        self.open_prompt(PromptKind::Profile)
    }

    pub(super) fn submit_profile(&mut self, text: &str) -> Vec<Effect> {
        self.say(format!("loading the profile {text}"));
        vec![Effect::LoadProfile {
            path: PathBuf::from(text),
            game: self.game,
        }]
    }

    /// A profile file read: levels are made for it from now on.
    pub(super) fn profile_loaded(&mut self, result: Result<Box<Profile>, String>) -> Vec<Effect> {
        match result {
            Ok(profile) if profile.game() == self.game => {
                self.profile_mut().profile = Some(*profile);
                self.say_ability();
                self.generate()
            }
            Ok(_) => Vec::new(), // the game changed while it loaded
            Err(problem) => {
                self.complain(problem);
                Vec::new()
            }
        }
    }

    /// `e`: the next ability of the game for `[` and `]`.
    pub(super) fn next_ability(&mut self) -> Vec<Effect> {
        let count = main_abilities(self.game).len();
        let edit = self.profile_mut();
        edit.ability = (edit.ability + 1) % count;
        self.say_ability();
        Vec::new()
    }

    /// `[` `]`: the chosen ability times `factor`, within its range; the level is made again.
    pub(super) fn scale_ability(&mut self, factor: f64) -> Vec<Effect> {
        let field = self.chosen_ability();
        let profile = self.current_profile();
        let Some((value, range)) = profile.value(field) else {
            return Vec::new();
        };
        let scaled = range.clamp((value * factor * 1000.0).round() / 1000.0);
        let Some(mut changed) = profile.with_value(field, scaled) else {
            self.complain(format!("{field} {scaled} does not fit the character"));
            return Vec::new();
        };
        if !changed.name.ends_with(EDITED) {
            let base: String = changed.name.chars().take(54).collect();
            changed.name = format!("{base}{EDITED}");
        }
        self.profile_mut().profile = Some(changed);
        self.say_ability();
        self.generate()
    }

    /// The ability `[` and `]` change, as the profile file names it.
    fn chosen_ability(&self) -> &'static str {
        let all = main_abilities(self.game);
        all[self.profile().ability % all.len()]
    }

    /// The profile levels are made for now (the built-in one when none is loaded).
    fn current_profile(&self) -> Profile {
        self.profile()
            .profile
            .clone()
            .unwrap_or_else(|| Profile::default_of(self.game))
    }

    fn say_ability(&mut self) {
        let profile = self.current_profile();
        let field = self.chosen_ability();
        if let Some((value, range)) = profile.value(field) {
            let name = field.rsplit('.').next().unwrap_or(field).replace('_', " ");
            self.say(format!(
                "profile `{}`: {name} {value} {} (e: next ability, [ ]: -5% / +5%, f: load a file)",
                profile.name, range.unit
            ));
        }
    }
}
