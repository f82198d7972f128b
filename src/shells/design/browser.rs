//! The designer's 3D view (`V`): the level on screen served to the web browser by
//! [`crate::shells::view::LiveView`], moved on to each new level, and to the same level once its
//! trials colour the pieces by failures.

use std::process::{Command, Stdio};
use std::sync::Arc;

use super::app::App;
use crate::services::view::{Trail, scene_json};
use crate::shells::view::LiveView;

/// The view once opened, and which state of the level it shows.
#[derive(Default)]
pub struct Browser {
    live: Option<Arc<LiveView>>,
    /// The level shown (its address on screen) and whether its statistics were in.
    shown: Option<(usize, bool)>,
}

impl Browser {
    /// `V`: serves the level on screen (on the first press) and asks the system to open the
    /// page; the footer gives its address either way.
    pub fn open(&mut self, app: &mut App) {
        match self.serve(app) {
            Ok(url) => {
                let opened = if open_in_browser(&url) {
                    "opened in the web browser"
                } else {
                    "open it in a web browser"
                };
                app.status = Some((
                    format!("3D view at {url} ({opened}; it follows the level)"),
                    false,
                ));
            }
            Err(problem) => {
                app.status = Some((format!("cannot serve the 3D view: {problem:#}"), true));
            }
        }
    }

    /// The page's address, serving the level on screen from a thread of its own if it is not
    /// served yet.
    pub fn serve(&mut self, app: &App) -> anyhow::Result<String> {
        if let Some(live) = &self.live {
            return Ok(live.url());
        }
        let scene = scene(app).ok_or_else(|| anyhow::anyhow!("no level to show yet"))?;
        let live = LiveView::start(scene)?;
        self.shown = key(app);
        let url = live.url();
        self.live = Some(live);
        Ok(url)
    }

    /// Shows the level on screen if it changed since the last call (nothing before `V`).
    pub fn follow(&mut self, app: &App) {
        let Some(live) = &self.live else { return };
        let now = key(app);
        if now != self.shown
            && let Some(scene) = scene(app)
        {
            live.show(scene);
            self.shown = now;
        }
    }
}

/// Which level is on screen (its allocation: a new level is a new one), and whether its trials
/// are in.
fn key(app: &App) -> Option<(usize, bool)> {
    let level = app.level.as_ref()?;
    let stats = app.trials.as_ref().is_some_and(|t| t.stats.is_some());
    Some((Arc::as_ptr(level) as usize, stats))
}

fn scene(app: &App) -> Option<serde_json::Value> {
    let level = app.level_with_stats()?;
    let trail = Trail::of_certificate(&level);
    Some(scene_json(
        &level,
        &format!("{}.yaml", app.export_stem()),
        &trail,
    ))
}

/// Asks the system to open `url` in the default browser, with nothing printed on the
/// designer's screen; whether the opener could be started.
fn open_in_browser(url: &str) -> bool {
    let mut command = if cfg!(target_os = "macos") {
        Command::new("open")
    } else if cfg!(windows) {
        let mut command = Command::new("cmd");
        command.args(["/C", "start", ""]);
        command
    } else {
        Command::new("xdg-open")
    };
    command
        .arg(url)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .is_ok()
}
