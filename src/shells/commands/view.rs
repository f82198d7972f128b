//! `arlpcg view`: a level in 3D in a web browser, served by [`crate::shells::view`]: a level
//! file, or the newest level file of a folder, followed as it changes.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use anyhow::{Context, Result};

use crate::services::view::{Trail, scene_json};
use crate::shells::cli::ViewArgs;
use crate::shells::view::{self, Shown};
use arlpcg_core::level::yaml;

pub fn run(args: &ViewArgs) -> Result<()> {
    let shown = ShownFile::new(&args.level)?;
    shown.current()?;
    let (server, address) = view::bind(args.port)?;
    crate::say!(
        "showing {} at http://{address}/ (Ctrl-C stops)",
        args.level.display()
    );
    view::serve(&server, &shown);
    Ok(())
}

/// What the page shows: a level file, or the newest level file of a folder.
struct ShownFile {
    path: PathBuf,
}

impl ShownFile {
    fn new(path: &Path) -> Result<Self> {
        anyhow::ensure!(
            path.exists(),
            "{}: no such level file or folder",
            path.display()
        );
        Ok(Self {
            path: path.to_path_buf(),
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

    fn current(&self) -> Result<(String, serde_json::Value)> {
        let (version, path) = self.version_and_file()?;
        let level = yaml::load(&path)?;
        let title = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Ok((
            version,
            scene_json(&level, &title, &Trail::of_certificate(&level)),
        ))
    }
}
