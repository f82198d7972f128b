//! `arlpcg view`: the page, the scene and the version it serves on 127.0.0.1, following a
//! folder's newest level. (The page's drawing in a real browser is checked by `.ci/run`, with
//! headless Chromium: `.ci/check-view.mjs`.)

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Stdio};

use crate::common::{arlpcg, fails_with, test_command};

/// A running `arlpcg view`, stopped when dropped.
struct Viewer {
    child: Child,
    address: String,
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn view(path: &std::path::Path) -> Viewer {
    view_with(path, &[])
}

fn view_with(path: &std::path::Path, more: &[&str]) -> Viewer {
    let mut child = test_command()
        .args(["view", path.to_str().unwrap()])
        .args(more)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let address = line
        .split("http://")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    Viewer { child, address }
}

/// The body of `GET path` from the view at `address` (host:port), with its status code.
pub fn get(address: &str, path: &str) -> (u16, String) {
    let mut stream = TcpStream::connect(address).unwrap();
    write!(stream, "GET {path} HTTP/1.0\r\nHost: {address}\r\n\r\n").unwrap();
    let mut answer = String::new();
    stream.read_to_string(&mut answer).unwrap();
    let status = answer[9..12].parse().unwrap();
    let body = answer.split_once("\r\n\r\n").unwrap().1.to_string();
    (status, body)
}

fn pieces(viewer: &Viewer) -> (String, u64) {
    let (status, body) = get(&viewer.address, "/scene.json");
    assert_eq!(status, 200, "{body}");
    let json: serde_json::Value = serde_json::from_str(&body).unwrap();
    let version = json["version"].as_str().unwrap().to_string();
    (version, json["scene"]["pieces"].as_u64().unwrap())
}

#[test]
fn the_view_serves_the_newest_level_of_a_folder_and_follows_it() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("levels");
    let easy = shipped.join("platform/platform_seed7_aux+1.00.yaml");
    let track = shipped.join("racing/racing_seed7_aux+0.00.yaml");
    std::fs::copy(&easy, dir.path().join("a.yaml")).unwrap();
    let viewer = view(dir.path());

    let (status, page) = get(&viewer.address, "/");
    assert_eq!(status, 200);
    assert!(
        page.contains("<canvas") && page.contains("\"boxes\""),
        "the first scene is in the page"
    );
    assert!(!page.contains("/*SCENE*/"));
    assert!(
        !page.contains("http://") && !page.contains("https://"),
        "nothing from the network"
    );
    let (first, blocks) = pieces(&viewer);
    let level = arlpcg_core::level::yaml::load(&easy).unwrap();
    assert_eq!(blocks, level.piece_count() as u64);
    assert_eq!(get(&viewer.address, "/version").1, first);

    // A newer level in the folder is what the page shows next.
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::copy(&track, dir.path().join("b.yaml")).unwrap();
    let (second, segments) = pieces(&viewer);
    assert_ne!(second, first);
    let road = arlpcg_core::level::yaml::load(&track).unwrap();
    assert_eq!(segments, road.piece_count() as u64);
    assert_eq!(get(&viewer.address, "/nothing").0, 404);

    // A broken newest file is an error the page is told of; the server keeps serving.
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(
        dir.path().join("c.yaml"),
        "format: arlpcg-level\nversion: 1\ngame: chess\n",
    )
    .unwrap();
    let (status, problem) = get(&viewer.address, "/scene.json");
    assert_eq!(status, 500);
    assert!(problem.contains("c.yaml"), "{problem}");
    std::fs::remove_file(dir.path().join("c.yaml")).unwrap();
    assert_eq!(pieces(&viewer).1, segments);
}

/// The page's λ slider: `/scene.json?aux=λ` is the level shown rebuilt at λ by the Generator
/// of `--policies` (unplayed), a λ outside [-1, 1] is refused, and without a Generator for the
/// level's game the scene says why there is no slider.
#[test]
fn the_slider_rebuilds_the_level_shown_at_another_aux() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let hard = root.join("levels/platform/platform_seed7_aux-1.00.yaml");
    let viewer = view_with(
        &hard,
        &[
            "--policies",
            root.join("policies/platform").to_str().unwrap(),
        ],
    );
    let scene = |query: &str| {
        let (status, body) = get(&viewer.address, &format!("/scene.json{query}"));
        assert_eq!(status, 200, "{body}");
        serde_json::from_str::<serde_json::Value>(&body).unwrap()["scene"].clone()
    };
    let file = scene("");
    assert_eq!(file["slider"]["aux"], -1.0);
    assert!(
        file["slider"]["generator"]
            .as_str()
            .unwrap()
            .ends_with("generator.safetensors")
    );
    let again = scene("?aux=-1");
    // (Colours aside: the file's pieces are tinted by its recorded failures.)
    let centres = |scene: &serde_json::Value| -> Vec<serde_json::Value> {
        let boxes = scene["boxes"].as_array().unwrap();
        boxes.iter().map(|b| b["centre"].clone()).collect()
    };
    assert_eq!(
        centres(&again),
        centres(&file),
        "its own λ: the file's level, seed 7's first draw"
    );
    let easy = scene("?aux=1");
    assert!(
        easy["title"].as_str().unwrap().ends_with("at λ = +1.00"),
        "{}",
        easy["title"]
    );
    assert!(
        easy["trail"]["none"]
            .as_str()
            .unwrap()
            .contains("not played")
    );
    assert_ne!(easy["pieces"], file["pieces"]);
    // What the page builds a level from itself: the seed and goal, and the Generator's numbers.
    let slider = &file["slider"];
    assert_eq!(
        (slider["game"].as_str(), slider["seed"].as_u64()),
        (Some("platform"), Some(7))
    );
    assert_eq!(slider["profile"], false);
    assert_eq!(slider["obstacles"], 0);
    let (status, body) = get(&viewer.address, "/generator.json");
    assert_eq!(status, 200, "{body}");
    let kit: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(kit["sidecar"]["role"], "generator");
    assert!(kit["sidecar"]["generator"]["piece_rules"].is_object());
    let observation = kit["sidecar"]["inputs"][0]["shape"][1].as_u64().unwrap();
    let layers = kit["network"]["layers"].as_array().unwrap();
    assert_eq!(layers[0]["inputs"].as_u64(), Some(observation));
    for layer in layers {
        let (inputs, outputs) = (
            layer["inputs"].as_u64().unwrap(),
            layer["outputs"].as_u64().unwrap(),
        );
        assert_eq!(
            layer["weight"].as_array().unwrap().len() as u64,
            inputs * outputs
        );
        assert_eq!(layer["bias"].as_array().unwrap().len() as u64, outputs);
    }
    let normalizer = &kit["network"]["normalizer"];
    assert_eq!(
        normalizer["mean"].as_array().unwrap().len() as u64,
        observation
    );
    // The page's modules, and nothing else under /web/.
    let (status, body) = get(&viewer.address, "/web/network.mjs");
    assert_eq!(status, 200);
    assert!(body.contains("export class PlainNetwork"));
    for missing in ["/web/solver.mjs", "/web/../Cargo.toml", "/web/"] {
        assert_eq!(get(&viewer.address, missing).0, 404, "{missing}");
    }
    for bad in ["?aux=1.5", "?aux=nan", "?aux=easy"] {
        let (status, body) = get(&viewer.address, &format!("/scene.json{bad}"));
        assert_eq!(status, 400, "{bad}: {body}");
        assert!(body.contains("not a λ in [-1, 1]"), "{body}");
    }
    drop(viewer);

    // A folder with no Generator: no slider, and why.
    let empty = tempfile::tempdir().unwrap();
    let viewer = view_with(&hard, &["--policies", empty.path().to_str().unwrap()]);
    let (_, body) = get(&viewer.address, "/scene.json");
    let none = serde_json::from_str::<serde_json::Value>(&body).unwrap()["scene"]["slider"]["none"]
        .clone();
    assert!(
        none.as_str().unwrap().contains("generator.safetensors"),
        "{none}"
    );
    let (status, body) = get(&viewer.address, "/scene.json?aux=0");
    assert_eq!(status, 500);
    assert!(body.contains("generator.safetensors"), "{body}");
    let (status, body) = get(&viewer.address, "/generator.json");
    assert_eq!(status, 500);
    assert!(body.contains("generator.safetensors"), "{body}");
}

/// A level made for a profile: the page gets the profile's piece rules at `/build.json`, with
/// the reach the server measured for its character, and the abilities the Generator observes.
#[test]
fn a_profiles_level_gives_the_page_its_rules() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let profile = root.join("results/platform/profiles/godot4/profile.yaml");
    let out = arlpcg([
        "generate",
        "--policies",
        root.join("policies/platform").to_str().unwrap(),
        "--profile",
        profile.to_str().unwrap(),
        "--aux=-1",
        "--count",
        "1",
        "--out",
        dir.path().to_str().unwrap(),
        "--format",
        "yaml",
    ]);
    assert!(out.status.success(), "{out:?}");
    let viewer = view(dir.path());
    let (_, body) = get(&viewer.address, "/scene.json");
    let slider =
        serde_json::from_str::<serde_json::Value>(&body).unwrap()["scene"]["slider"].clone();
    assert_eq!(slider["profile"], true);
    let (status, body) = get(&viewer.address, "/build.json");
    assert_eq!(status, 200, "{body}");
    let build: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(
        build["rules"]["reach_table"].as_array().map(Vec::len),
        Some(5),
        "{build}"
    );
    let abilities: Vec<f64> = serde_json::from_value(build["abilities"].clone()).unwrap();
    // Godot's character jumps slower, runs slower and falls slower than ours: each below 0.
    assert!(
        abilities.len() == 3 && abilities.iter().all(|a| *a < 0.0),
        "{abilities:?}"
    );
}

#[test]
fn the_view_replays_the_first_trials_of_a_verified_level() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let verified = root.join("levels/platform/platform_seed7_aux-1.00.yaml");
    let viewer = view(&verified);
    let (status, body) = get(&viewer.address, "/runs.json");
    assert_eq!(status, 200, "{body}");
    let answer: serde_json::Value = serde_json::from_str(&body).unwrap();
    let runs = answer["runs"]
        .as_array()
        .unwrap_or_else(|| panic!("{answer}"));
    // Its verification: 100 trials from seed 7, certificate 7, success 0.66.
    let seeds: Vec<u64> = runs.iter().map(|r| r["seed"].as_u64().unwrap()).collect();
    assert_eq!(seeds, (7..15).collect::<Vec<u64>>());
    assert_eq!(runs[0]["succeeded"], true, "the certificate's run");
    assert!(
        runs.iter()
            .all(|r| r["points"].as_array().unwrap().len() > 30)
    );
    assert!(
        answer["solver"]
            .as_str()
            .unwrap()
            .contains("solver.safetensors")
    );
    drop(viewer);

    // A level never verified: no runs, and why.
    let dir = tempfile::tempdir().unwrap();
    let bare = dir.path().join("bare.yaml");
    let out = arlpcg([
        "generate",
        "--rules",
        "--count",
        "1",
        "--seed",
        "3",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{out:?}");
    let written = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .find(|path| path.extension().is_some_and(|e| e == "yaml"))
        .unwrap();
    std::fs::rename(written, &bare).unwrap();
    let viewer = view(&bare);
    let (_, body) = get(&viewer.address, "/runs.json");
    assert!(body.contains("verify the level first"), "{body}");
}

#[test]
fn a_missing_level_or_an_empty_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = arlpcg(["view", dir.path().join("none.yaml").to_str().unwrap()]);
    fails_with(&out, 1, "no such level file or folder");
    let out = arlpcg(["view", dir.path().to_str().unwrap()]);
    fails_with(&out, 1, "holds no level file");
}
