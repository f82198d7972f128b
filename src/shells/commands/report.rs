//! `arlpcg report`: docs/results.md from the committed results and the shipped cards
//! ([`page::results_page`]), or the check that the committed page is current; and learning
//! curves drawn from a run's metrics.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::services::eval::page::{self, GamePage};
use crate::services::eval::{Results, seeds::SeedResults};
use crate::services::fsio::{self, Overwrite};
use crate::services::train;
use crate::shells::cli::ReportArgs;
use arlpcg_core::level::Game;
use arlpcg_core::rl::checkpoint::PolicyCard;

/// The largest results file, card or page read.
const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// The shipped policies a game's table lists, in its order.
const POLICIES: [&str; 5] = [
    "generator", "solver", "solver-rule-pcg", "solver-fixed-track", "solver-fixed-aux",
];

pub fn run(args: &ReportArgs) -> Result<()> {
    if !args.curves.is_empty() {
        for run in &args.curves {
            if !run.join("metrics.csv").is_file() {
                bail!(
                    "{}: no metrics.csv: not a training run's folder",
                    run.display()
                );
            }
            train::write_learning_curve(run)
                .with_context(|| format!("{}: cannot draw its learning curve", run.display()))?;
            crate::say!("{}", run.join("learning-curve.png").display());
        }
        return Ok(());
    }
    let games = Game::ALL
        .into_iter()
        .map(|game| read_game(game, &args.results, &args.policies))
        .collect::<Result<Vec<_>>>()?;
    let page = page::results_page(&games);
    if args.check {
        return check(&args.out, &page);
    }
    fsio::write_atomic(&args.out, page.as_bytes(), Overwrite::Allowed)?;
    crate::say!("{} ({} lines)", args.out.display(), page.lines().count());
    Ok(())
}

/// Fails naming the first line where the committed page differs from `page`.
fn check(path: &Path, page: &str) -> Result<()> {
    let committed = fsio::read_limited(path, MAX_FILE_BYTES, "results page")?;
    let committed = String::from_utf8_lossy(&committed);
    if committed == page {
        crate::say!("{} is current", path.display());
        return Ok(());
    }
    let line = committed
        .lines()
        .zip(page.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| committed.lines().count().min(page.lines().count()))
        + 1;
    bail!(
        "{}: line {line} is not what `arlpcg report` writes; run it and commit the page",
        path.display()
    )
}

fn read_game(game: Game, results: &Path, policies: &Path) -> Result<GamePage> {
    let dir = results.join(game.name());
    let results_json = dir.join("results.json");
    let results = Results::read(game, &read(&results_json)?)
        .with_context(|| format!("{}", results_json.display()))?;
    let seeds = read_seeds(&dir.join("seeds.json"))?;
    let mut more_seeds = Vec::new();
    for folder in subfolders(&dir)? {
        let file = folder.join("seeds.json");
        if file.is_file() {
            more_seeds.push((folder.display().to_string(), read_seeds(&file)?));
        }
    }
    let cards = POLICIES
        .iter()
        .map(|name| {
            (
                name,
                policies.join(game.name()).join(format!("{name}.yaml")),
            )
        })
        .map(|(name, path)| {
            let card: PolicyCard = serde_yaml::from_slice(&read(&path)?)
                .with_context(|| format!("{}", path.display()))?;
            if card.game != game {
                bail!(
                    "{}: the card of a {} policy in the {game} policies",
                    path.display(),
                    card.game
                );
            }
            // The page quotes its time: a number of seconds, not a NaN or a 309-digit one.
            let wall = card.training.wall_time_s;
            if !(0.0..=1e9).contains(&wall) {
                bail!(
                    "{}: training.wall_time_s: {} is not a number of seconds within [0, 1e9]",
                    path.display(),
                    arlpcg_core::level::params::show_number(wall)
                );
            }
            Ok((format!("{name}.safetensors"), card))
        })
        .collect::<Result<Vec<_>>>()?;
    let campaign_file = dir
        .join("campaign")
        .join(crate::services::campaign::CAMPAIGN_FILE);
    let campaign = match campaign_file.is_file() {
        true => Some(crate::services::campaign::read_record(&campaign_file)?),
        false => None,
    };
    if let Some(other) = campaign.as_ref().filter(|c| c.game != game) {
        bail!(
            "{}: a {} campaign in the {game} results",
            campaign_file.display(),
            other.game
        );
    }
    let mut profiles = Vec::new();
    if dir.join("profiles").is_dir() {
        for folder in subfolders(&dir.join("profiles"))? {
            let file = folder.join("results.json");
            if file.is_file() {
                let results = Results::read(game, &read(&file)?)
                    .with_context(|| format!("{}", file.display()))?;
                let name = folder
                    .file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .to_string();
                profiles.push((name, results));
            }
        }
    }
    let wish_file = dir.join("wish").join("score.json");
    let wish = match wish_file.is_file() {
        true => Some(
            serde_json::from_slice::<crate::services::wish::score::Score>(&read(&wish_file)?)
                .with_context(|| format!("{}", wish_file.display()))?,
        ),
        false => None,
    };
    if let Some(other) = wish.as_ref().filter(|w| w.game != game) {
        bail!(
            "{}: the score of {} asks in the {game} results",
            wish_file.display(),
            other.game
        );
    }
    Ok(GamePage {
        game,
        cards,
        results,
        seeds,
        more_seeds,
        campaign,
        profiles,
        wish,
    })
}

fn read(path: &Path) -> Result<Vec<u8>> {
    fsio::read_limited(path, MAX_FILE_BYTES, "results file")
}

fn read_seeds(path: &Path) -> Result<SeedResults> {
    SeedResults::read(&read(path)?).with_context(|| format!("{}", path.display()))
}

/// The folders in `dir`, by name.
fn subfolders(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut folders: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    Ok(folders)
}
