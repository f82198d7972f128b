//! `arlpcg view`: a level in 3D in a web browser, served by [`crate::shells::view`]: a level
//! file, or the newest level file of a folder, followed as it changes; its scene rebuilt at
//! another λ by a Generator when the page's slider moves.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::SystemTime;

use anyhow::{Context, Result};
use serde_json::{Value, json};

use crate::services::generation::GeneratorPolicy;
use crate::services::making::LevelSource;
use crate::services::onnx::web::{profile_build, web_generator};
use crate::services::policies::{GENERATOR_FILE, load_generator};
use crate::services::view::{
    Trail, knob_values, obstacle_count, rebuild_request, runs_json, scene_json,
};
use crate::shells::cli::ViewArgs;
use crate::shells::common::shipped_dir;
use crate::shells::view::{self, Shown};
use arlpcg_core::level::{Game, Level, yaml};

pub fn run(args: &ViewArgs) -> Result<()> {
    let shown = ShownFile::new(&args.level, args.policies.clone())?;
    shown.current()?;
    let (server, address) = view::bind(args.port)?;
    crate::say!(
        "showing {} at http://{address}/ (Ctrl-C stops)",
        args.level.display()
    );
    view::serve(&server, &shown);
    Ok(())
}

/// What the page shows: a level file, or the newest level file of a folder, and the Generators
/// that rebuild it at another λ.
struct ShownFile {
    path: PathBuf,
    /// `--policies`: a folder holding generator.safetensors, or a Generator's file; none: the
    /// shipped policies of the shown level's game.
    policies: Option<PathBuf>,
    /// Each game's Generator once loaded, or why it could not be.
    generators: Mutex<Vec<(Game, Loaded)>>,
}

impl ShownFile {
    fn new(path: &Path, policies: Option<PathBuf>) -> Result<Self> {
        anyhow::ensure!(
            path.exists(),
            "{}: no such level file or folder",
            path.display()
        );
        Ok(Self {
            path: path.to_path_buf(),
            policies,
            generators: Mutex::default(),
        })
    }

    /// The Generator that rebuilds `game`'s levels, and its file; loaded once.
    fn generator(&self, game: Game) -> Loaded {
        let mut loaded = self
            .generators
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        if let Some((_, known)) = loaded.iter().find(|(g, _)| *g == game) {
            return known.clone();
        }
        let load = || -> Result<Arc<LoadedGenerator>> {
            let path = match &self.policies {
                Some(path) if path.is_dir() => path.join(GENERATOR_FILE),
                Some(path) => path.clone(),
                None => shipped_dir(game)?.join(GENERATOR_FILE),
            };
            let (policy, card) = load_generator(&path, game)?;
            let web = web_generator(
                &policy.policy,
                &card,
                policy.reference.clone(),
                policy.limits,
            )
            .with_context(|| format!("{}", path.display()))?;
            Ok(Arc::new(LoadedGenerator { policy, path, web }))
        };
        let known = load().map_err(|e| format!("{e:#}"));
        loaded.push((game, known.clone()));
        known
    }

    /// What the page's λ slider needs for `level`: the λ it was made at, the Generator that
    /// rebuilds it and what the page builds from (`seed`, `obstacles`, `knobs`; `goal`: the page
    /// builds a level itself only where its seed gives its goal and its start (the scene's
    /// `spawn`); `profile`: made for one, whose rules the page asks for at `/build.json`), or
    /// why there is none.
    fn slider(&self, title: &str, level: &Level) -> Value {
        let generator = match self.generator(level.game()) {
            Ok(generator) => generator,
            Err(why) => return json!({"none": why}),
        };
        let knobs = match generator.policy.knobs {
            0 => Vec::new(),
            _ => knob_values(level),
        };
        json!({
            "aux": level.aux,
            "generator": generator.path.display().to_string(),
            "title": title,
            "game": level.game().name(),
            "seed": level.seed,
            "obstacles": obstacle_count(level),
            "knobs": knobs,
            "goal": level.goal,
            "profile": level.profile.is_some(),
        })
    }

    /// The level file shown now, and when it last changed.
    fn file(&self) -> Result<(PathBuf, SystemTime)> {
        let modified = |p: &Path| {
            std::fs::metadata(p)
                .and_then(|m| m.modified())
                .with_context(|| format!("{}: cannot read", p.display()))
        };
        if !self.path.is_dir() {
            return Ok((self.path.clone(), modified(&self.path)?));
        }
        let mut newest: Option<(SystemTime, PathBuf)> = None;
        let entries = std::fs::read_dir(&self.path)
            .with_context(|| format!("{}: cannot read the folder", self.path.display()))?;
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "yaml") && !path.is_dir() {
                let when = modified(&path)?;
                if newest.as_ref().is_none_or(|(t, p)| (when, &path) > (*t, p)) {
                    newest = Some((when, path));
                }
            }
        }
        let (when, path) = newest.with_context(|| {
            format!(
                "{}: the folder holds no level file (.yaml)",
                self.path.display()
            )
        })?;
        Ok((path, when))
    }

    /// A string that changes whenever the shown level does, and the level's file.
    fn version_and_file(&self) -> Result<(String, PathBuf)> {
        let (path, modified) = self.file()?;
        let nanos = modified
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        Ok((format!("{}@{nanos}", path.display()), path))
    }
}

impl Shown for ShownFile {
    fn version(&self) -> Result<String> {
        Ok(self.version_and_file()?.0)
    }

    fn current(&self) -> Result<(String, Value)> {
        let (version, path) = self.version_and_file()?;
        let level = yaml::load(&path)?;
        let mut scene = scene_json(&level, &title(&path), &Trail::of_certificate(&level));
        scene["slider"] = self.slider(&title(&path), &level);
        Ok((version, scene))
    }

    fn rebuilt(&self, aux: f64) -> Result<(String, Value)> {
        let (version, path) = self.version_and_file()?;
        let (level, from) = yaml::load_pinned(&path)?;
        let generator = self.generator(level.game()).map_err(anyhow::Error::msg)?;
        let request = rebuild_request(Arc::new(level), from, aux);
        let rebuilt = LevelSource::Generator(&generator.policy).level(&request)?;
        let title = format!("{} at λ = {aux:+.2}", title(&path));
        let unplayed = Trail::None(format!(
            "rebuilt by {} (its seed's first draw, not played)",
            generator.path.display()
        ));
        let mut scene = scene_json(&rebuilt, &title, &unplayed);
        scene["slider"] = self.slider(&title, &rebuilt);
        Ok((version, scene))
    }

    fn runs(&self) -> Result<Value> {
        let (version, path) = self.version_and_file()?;
        let mut runs = runs_json(&yaml::load(&path)?);
        runs["version"] = json!(version);
        Ok(runs)
    }

    fn profile_build(&self) -> Result<Value> {
        let (_, path) = self.version_and_file()?;
        let level = yaml::load(&path)?;
        let generator = self.generator(level.game()).map_err(anyhow::Error::msg)?;
        Ok(level
            .profile
            .as_ref()
            .map_or(Value::Null, |p| profile_build(&generator.policy, p)))
    }

    fn web_generator(&self) -> Result<String> {
        let (_, path) = self.version_and_file()?;
        let game = yaml::load(&path)?.game();
        let generator = self.generator(game).map_err(anyhow::Error::msg)?;
        Ok(generator.web.clone())
    }
}

/// A game's Generator: the policy, its file and the same as a page builds with it (JSON).
struct LoadedGenerator {
    policy: GeneratorPolicy,
    path: PathBuf,
    web: String,
}

/// A game's Generator, or why it could not be loaded.
type Loaded = Result<Arc<LoadedGenerator>, String>;

/// A level file's name as the page's caption gives it.
fn title(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
