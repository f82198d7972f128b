//! `arlpcg view`: a level in 3D in a web browser. The binary serves one page on 127.0.0.1
//! (`src/shells/view/page.html`, WebGL with no library, so it works offline) with the level's
//! scene inside ([`crate::services::view`]); the page asks for `/version` a few times a second
//! and fetches `/scene.json` again when the file, or a folder's newest level, changes.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use anyhow::{Context, Result};

use crate::services::view::scene_json;
use crate::shells::cli::ViewArgs;
use arlpcg_core::level::yaml;

/// The page, with `/*SCENE*/` where the first scene goes.
const PAGE: &str = include_str!("../view/page.html");

pub fn run(args: &ViewArgs) -> Result<()> {
    let shown = Shown::new(&args.level)?;
    shown.current()?;
    let server = tiny_http::Server::http(("127.0.0.1", args.port))
        .map_err(|e| anyhow::anyhow!("cannot serve on 127.0.0.1:{}: {e}", args.port))?;
    let address = server
        .server_addr()
        .to_ip()
        .context("the server has no IP address")?;
    crate::say!(
        "showing {} at http://{address}/ (Ctrl-C stops)",
        args.level.display()
    );
    for request in server.incoming_requests() {
        let answer = match request.url().split('?').next().unwrap_or("") {
            "/" => shown.current().map(|(version, scene)| {
                let first = serde_json::json!({"version": version, "scene": scene});
                // Inside a <script> element "</" would end it early.
                let inline = first.to_string().replace("</", "<\\/");
                reply(
                    PAGE.replace("/*SCENE*/", &inline),
                    "text/html; charset=utf-8",
                )
            }),
            "/scene.json" => shown.current().map(|(version, scene)| {
                let body = serde_json::json!({"version": version, "scene": scene});
                reply(body.to_string(), "application/json")
            }),
            "/version" => shown
                .version_and_file()
                .map(|(version, _)| reply(version, "text/plain; charset=utf-8")),
            _ => Ok(tiny_http::Response::from_string("not found").with_status_code(404)),
        };
        let response = answer.unwrap_or_else(|problem| {
            crate::warn!("{problem:#}");
            tiny_http::Response::from_string(format!("{problem:#}")).with_status_code(500)
        });
        // A browser that went away is no reason to stop serving.
        let _ = request.respond(response);
    }
    Ok(())
}

fn reply(body: String, kind: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    let header = tiny_http::Header::from_bytes("Content-Type", kind).expect("a valid header");
    tiny_http::Response::from_string(body).with_header(header)
}

/// What the page shows: a level file, or the newest level file of a folder.
struct Shown {
    path: PathBuf,
}

impl Shown {
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

    /// The version and the scene of the level shown now.
    fn current(&self) -> Result<(String, serde_json::Value)> {
        let (version, path) = self.version_and_file()?;
        let level = yaml::load(&path)?;
        let title = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Ok((version, scene_json(&level, &title)))
    }
}
