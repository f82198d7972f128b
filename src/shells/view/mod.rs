//! The 3D view's web server, shared by `arlpcg view` (a level file, or a folder's newest) and
//! the designer (`V`: the level on screen). It serves one page on 127.0.0.1 (`page.html`:
//! WebGL with no library, so it works offline) with the first scene inside
//! ([`crate::services::view::scene_json`]); the page asks for `/version` a few times a second
//! and fetches `/scene.json` again when it changes. When its λ slider moves (a [`Shown`] that
//! can rebuild its level: `arlpcg view`'s file), the page builds the level itself from
//! `/generator.json` with the modules of `web/` served at `/web/NAME` (levels from the seed, as
//! a web game would), or asks for `/scene.json?aux=λ` where those cannot (a profile's level, a
//! level whose start and goal are not its seed's).

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, PoisonError};

use anyhow::{Context, Result};
use serde_json::Value;

/// The page, with `/*SCENE*/` where the first scene goes.
const PAGE: &str = include_str!("page.html");

/// What the page shows.
pub trait Shown: Send + Sync {
    /// A string that changes whenever the scene does.
    fn version(&self) -> Result<String>;
    /// The version and the scene shown now.
    fn current(&self) -> Result<(String, Value)>;
    /// The version and the scene shown now, rebuilt at λ `aux` by a Generator.
    fn rebuilt(&self, aux: f64) -> Result<(String, Value)> {
        anyhow::bail!("this view cannot rebuild its level at λ = {aux}: it has no Generator")
    }
    /// The Generator that rebuilds the level shown now, as the page builds with it
    /// ([`crate::services::onnx::web::web_generator`], JSON).
    fn web_generator(&self) -> Result<String> {
        anyhow::bail!("this view has no Generator")
    }
    /// What the page's build takes to make the shown level's profile's levels
    /// ([`crate::services::onnx::web::profile_build`]; null for a level made for no profile),
    /// asked for when the slider first moves: measuring a character's reach takes a moment.
    fn profile_build(&self) -> Result<Value> {
        anyhow::bail!("this view has no Generator")
    }
    /// The first trials of the shown level's verification played again
    /// ([`crate::services::view::runs_json`]), fetched once the page has loaded; nothing (an
    /// empty object) for a view that replays none (the designer's, which shows its own trials).
    fn runs(&self) -> Result<Value> {
        Ok(serde_json::json!({}))
    }
}

/// The modules of `web/` the page imports, served at `/web/NAME`: a Generator's levels built in
/// the page (`network.mjs` over the levels' own modules) and drawn (`view-scene.mjs`).
const MODULES: [(&str, &str); 7] = [
    ("levels.mjs", include_str!("../../../web/levels.mjs")),
    ("network.mjs", include_str!("../../../web/network.mjs")),
    (
        "onnx-means.mjs",
        include_str!("../../../web/onnx-means.mjs"),
    ),
    ("racing.mjs", include_str!("../../../web/racing.mjs")),
    ("rng.mjs", include_str!("../../../web/rng.mjs")),
    (
        "view-scene.mjs",
        include_str!("../../../web/view-scene.mjs"),
    ),
    (
        "ziggurat-normal.mjs",
        include_str!("../../../web/ziggurat-normal.mjs"),
    ),
];

/// A server on 127.0.0.1:`port` (0: any free port) and the address it listens on.
pub fn bind(port: u16) -> Result<(tiny_http::Server, SocketAddr)> {
    let server = tiny_http::Server::http(("127.0.0.1", port))
        .map_err(|e| anyhow::anyhow!("cannot serve on 127.0.0.1:{port}: {e}"))?;
    let address = server
        .server_addr()
        .to_ip()
        .context("the server has no IP address")?;
    Ok((server, address))
}

/// Answers the page's requests for `shown`, for as long as the server lives.
pub fn serve(server: &tiny_http::Server, shown: &dyn Shown) {
    // Each request on a thread of its own: a slow answer (runs played again, a Generator
    // loaded) holds up no other (the page's modules, its polling, a rebuild).
    std::thread::scope(|scope| {
        for request in server.incoming_requests() {
            scope.spawn(move || answer(request, shown));
        }
    });
}

/// Answers one of the page's requests.
fn answer(request: tiny_http::Request, shown: &dyn Shown) {
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
        "/scene.json" => match asked_aux(request.url()) {
            Err(problem) => Ok(tiny_http::Response::from_string(problem).with_status_code(400)),
            Ok(aux) => aux
                .map_or_else(|| shown.current(), |aux| shown.rebuilt(aux))
                .map(|(version, scene)| {
                    let body = serde_json::json!({"version": version, "scene": scene});
                    reply(body.to_string(), "application/json")
                }),
        },
        "/version" => shown
            .version()
            .map(|version| reply(version, "text/plain; charset=utf-8")),
        "/build.json" => shown
            .profile_build()
            .map(|build| reply(build.to_string(), "application/json")),
        "/runs.json" => shown
            .runs()
            .map(|runs| reply(runs.to_string(), "application/json")),
        "/generator.json" => shown
            .web_generator()
            .map(|kit| reply(kit, "application/json")),
        path => match MODULES
            .iter()
            .find(|(name, _)| path.strip_prefix("/web/") == Some(*name))
        {
            Some((_, module)) => Ok(reply(module.to_string(), "text/javascript")),
            None => Ok(tiny_http::Response::from_string("not found").with_status_code(404)),
        },
    };
    let response = answer.unwrap_or_else(|problem| {
        crate::warn!("{problem:#}");
        tiny_http::Response::from_string(format!("{problem:#}")).with_status_code(500)
    });
    // A browser that went away is no reason to stop serving.
    let _ = request.respond(response);
}

/// The λ a `/scene.json?aux=λ` request asks for (none without `aux`), or why it is refused.
fn asked_aux(url: &str) -> Result<Option<f64>, String> {
    let Some((_, query)) = url.split_once('?') else {
        return Ok(None);
    };
    let Some(text) = query.split('&').find_map(|pair| pair.strip_prefix("aux=")) else {
        return Ok(None);
    };
    match text.parse::<f64>() {
        Ok(aux) if (-1.0..=1.0).contains(&aux) => Ok(Some(aux)),
        _ => Err(format!("aux: {text:?} is not a λ in [-1, 1]")),
    }
}

fn reply(body: String, kind: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    let header = tiny_http::Header::from_bytes("Content-Type", kind).expect("a valid header");
    tiny_http::Response::from_string(body).with_header(header)
}

/// A scene held in memory and served from a thread of its own: the designer's view, which
/// [`LiveView::show`] moves on to each new level.
pub struct LiveView {
    /// The scene's version (1, 2, …) and the scene.
    scene: Mutex<(u64, Value)>,
    /// Where the page is served.
    pub address: SocketAddr,
}

impl LiveView {
    /// Serves `scene` on a free port of 127.0.0.1 until the process ends.
    pub fn start(scene: Value) -> Result<Arc<LiveView>> {
        let (server, address) = bind(0)?;
        let live = Arc::new(LiveView {
            scene: Mutex::new((1, scene)),
            address,
        });
        let shown = live.clone();
        std::thread::Builder::new()
            .name("view".into())
            .spawn(move || serve(&server, shown.as_ref()))
            .context("cannot start the view's server")?;
        Ok(live)
    }

    /// Shows `scene` from now on: the page fetches it within a second.
    pub fn show(&self, scene: Value) {
        let mut held = self.scene.lock().unwrap_or_else(PoisonError::into_inner);
        *held = (held.0 + 1, scene);
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }
}

impl Shown for LiveView {
    fn version(&self) -> Result<String> {
        let held = self.scene.lock().unwrap_or_else(PoisonError::into_inner);
        Ok(held.0.to_string())
    }

    fn current(&self) -> Result<(String, Value)> {
        let held = self.scene.lock().unwrap_or_else(PoisonError::into_inner);
        Ok((held.0.to_string(), held.1.clone()))
    }
}
