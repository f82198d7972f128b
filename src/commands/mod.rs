//! The subcommands: each resolves its arguments, runs the pure core, reports and writes files.
//! Errors come back as `anyhow` errors with the file and field named; `main` turns them into
//! one line and a non-zero exit code.

mod eval;
mod export;
mod generate;
pub mod policies;
mod verify;

pub use export::{LevelFiles, write_level_files};
pub use verify::one_line;

use anyhow::Result;

use crate::cli::{Cli, Command};

/// Arguments that do not fit together (exit code 2, as clap's own usage errors); every other
/// error is bad input or a failure (exit code 1).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Work stopped by Ctrl-C after keeping what was finished (exit code 130, as a shell reports
/// SIGINT).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Interrupted(pub String);

/// The exit code for an error: 2 for a [`UsageError`], 130 for [`Interrupted`], 1 for the rest.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    if err.downcast_ref::<UsageError>().is_some() {
        2
    } else if err.downcast_ref::<Interrupted>().is_some() {
        130
    } else {
        1
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Generate(args)) => generate::run(&args),
        Some(Command::Export(args)) => export::run(&args),
        Some(Command::Verify(args)) => verify::run(&args),
        Some(Command::Eval(args)) => eval::run(&args),
        Some(Command::Train(args)) => crate::train::run(&args),
        Some(Command::Design(args)) => design(args),
        None => {
            use std::io::IsTerminal;
            if std::io::stdin().is_terminal() && std::io::stdout().is_terminal() {
                design(crate::cli::DesignArgs {
                    game: crate::level::Game::Platform,
                    policies: None,
                    out: "levels".into(),
                    seed: 1,
                })
            } else {
                use clap::CommandFactory;
                Cli::command().print_long_help()?;
                Ok(())
            }
        }
    }
}

fn design(args: crate::cli::DesignArgs) -> Result<()> {
    crate::design::run(crate::design::DesignOptions {
        game: args.game,
        policies: args.policies,
        out: args.out,
        seed: args.seed,
    })
}

/// The rayon pool that environments, trials and candle's matrix products share: `threads`
/// workers, or one per core.
pub(crate) fn thread_pool(threads: Option<u64>) -> Result<rayon::ThreadPool> {
    let threads = threads.map_or_else(
        || std::thread::available_parallelism().map_or(2, |n| n.get()),
        |t| t as usize,
    );
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?)
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub(crate) fn progress_bar(total: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} [{elapsed} < {eta}]")
            .expect("the template is valid"),
    );
    bar.set_message(what.to_string());
    bar
}
