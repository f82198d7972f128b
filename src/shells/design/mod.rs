//! `arlpcg design` (and `arlpcg` with no arguments): the designer's terminal UI.
//!
//! Three parts, as docs/architecture.md asks: the state and its pure `update` ([`app`]), the drawing
//! that only reads it ([`view`], on the areas of [`layout`]), and this thin shell, which owns
//! the terminal, turns terminal events and worker answers into messages, and hands the effects
//! to the worker threads ([`worker`]), but for the 3D view in the browser, which it serves
//! itself ([`browser`]).

pub mod app;
pub mod browser;
pub mod layout;
pub mod view;
pub mod worker;

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

use anyhow::{Context, Result};
use ratatui::DefaultTerminal;
use ratatui::crossterm::event::{self, DisableMouseCapture, EnableMouseCapture, Event};
use ratatui::crossterm::execute;

use app::{App, Effect, LoadedInfo, Message, Mode, Response};
use arlpcg_core::level::Game;
use browser::Browser;
use worker::{GamePolicies, Policies, Workers};

/// Time between animation ticks.
const TICK: Duration = Duration::from_millis(33);

/// What `arlpcg design` was asked for.
pub struct DesignOptions {
    /// The game shown first.
    pub game: Game,
    /// The policies folder; `None`: the shipped ones (`policies/<game>`), or rules and the
    /// scripted controller when they are missing.
    pub policies: Option<PathBuf>,
    /// Where exports go.
    pub out: PathBuf,
    /// The seed to start with.
    pub seed: u64,
    /// A campaign folder to open the campaign view on (its game is the one shown).
    pub campaign: Option<PathBuf>,
    /// A game profile the levels of the game opened on are made for.
    pub profile: Option<PathBuf>,
    /// How exported glTF files carry their colliders.
    pub gltf: crate::services::level_files::GltfOptions,
    /// The threads each of the designer's workers (levels and trials, sweeps, the panel) plays
    /// on (default: one per core).
    pub threads: Option<u64>,
}

/// The policies the designer starts on for `game`, and a note when it falls back to rules and
/// the scripted player. `--policies` is for the game the designer opens on; the other game
/// starts on its shipped policies.
fn starting_policies(
    options: &DesignOptions,
    game: Game,
) -> Result<(Policies, LoadedInfo, Option<String>)> {
    match options.policies.as_ref().filter(|_| game == options.game) {
        Some(path) => {
            let (policies, info) = worker::load(path, game)
                .with_context(|| format!("--policies {}", path.display()))?;
            Ok((policies, info, None))
        }
        None => {
            let shipped = crate::shells::common::shipped_dir(game);
            match shipped.and_then(|shipped| worker::load(&shipped, game)) {
                Ok((policies, info)) => Ok((policies, info, None)),
                Err(e) => Ok((
                    Policies::default(),
                    LoadedInfo::default(),
                    Some(format!(
                        "no shipped policies ({e:#}): rule levels and the scripted controller; p loads others"
                    )),
                )),
            }
        }
    }
}

/// Runs the designer until the user quits.
pub fn run(mut options: DesignOptions) -> Result<()> {
    // A campaign that cannot be read is an error before the terminal opens.
    if let Some(folder) = &options.campaign {
        options.game = crate::services::campaign::open(folder)?.1.game;
    }
    let (policies, info, note) = starting_policies(&options, options.game)?;
    let profile = match &options.profile {
        Some(file) => Some(crate::services::profile::for_game(
            crate::services::profile::load(file)?,
            options.game,
            file,
        )?),
        None => None,
    };
    let mut shelf = GamePolicies::default();
    shelf[options.game] = policies;
    let mut others = Vec::new();
    for game in Game::ALL.into_iter().filter(|g| *g != options.game) {
        let (policies, info, _) = starting_policies(&options, game)?;
        shelf[game] = policies;
        others.push((game, info));
    }
    let (answers, responses) = channel();
    let workers = Workers::start(shelf, answers, options.threads)?;
    let mut app = App::new(options.game, info, options.seed, options.out);
    app.gltf = options.gltf;
    app.profile_mut().profile = profile;
    for (game, info) in others {
        app.loaded[game] = info;
    }
    let opening = options.campaign.map(|folder| app.open_campaign(folder));
    // https://no-color.org: present and not empty.
    app.colour = std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty());
    if let Some(note) = note {
        app.status = Some((note, true));
    }
    // Mouse capture off on panic too; ratatui's own hook (installed by init) restores the rest.
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let _ = execute!(std::io::stdout(), DisableMouseCapture);
        previous(info);
    }));
    let mut terminal = ratatui::try_init().context("cannot open the terminal for the designer")?;
    let result = execute!(std::io::stdout(), EnableMouseCapture)
        .context("cannot enable the mouse")
        .and_then(|()| {
            for effect in opening.into_iter().flatten() {
                workers.submit(effect);
            }
            event_loop(&mut terminal, &mut app, &workers, &responses)
        });
    let _ = execute!(std::io::stdout(), DisableMouseCapture);
    ratatui::restore();
    result
}

fn event_loop(
    terminal: &mut DefaultTerminal,
    app: &mut App,
    workers: &Workers,
    responses: &Receiver<Response>,
) -> Result<()> {
    let size = terminal.size()?;
    app::update(
        app,
        Message::Resize {
            width: size.width,
            height: size.height,
        },
    );
    let mut browser = Browser::default();
    for effect in app.start() {
        workers.submit(effect);
    }
    while app.mode == Mode::Designing {
        terminal.draw(|frame| view::render(app, frame))?;
        let message = if event::poll(TICK)? {
            match event::read()? {
                Event::Key(key) => Message::Key(key),
                Event::Mouse(mouse) => Message::Mouse(mouse),
                Event::Resize(width, height) => Message::Resize { width, height },
                _ => continue,
            }
        } else {
            Message::Tick
        };
        let mut effects = app::update(app, message);
        while let Ok(response) = responses.try_recv() {
            effects.extend(app::update(app, Message::Worker(response)));
        }
        for effect in effects {
            match effect {
                Effect::OpenView => browser.open(app),
                effect => workers.submit(effect),
            }
        }
        browser.follow(app);
    }
    Ok(())
}
