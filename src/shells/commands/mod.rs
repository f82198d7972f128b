//! The subcommands: each resolves its arguments, runs the pure core, reports and writes files.
//! Errors come back as `anyhow` errors with the file and field named; `main` turns them into
//! one line and a non-zero exit code.

mod bench;
pub(crate) mod campaign;
mod eval;
mod export;
mod export_policy;
mod generate;
mod profile;
mod report;
mod train;
mod verify;
mod view;

pub use crate::shells::common::{ChecksFailed, Interrupted, UsageError, exit_code};
pub use verify::one_line;

use anyhow::Result;

use crate::shells::cli::{Cli, Command};

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Generate(args)) => in_pool(args.threads, || generate::run(&args)),
        Some(Command::Export(args)) => export::run(&args),
        Some(Command::ExportPolicy(args)) => export_policy::run(&args),
        Some(Command::View(args)) => view::run(&args),
        Some(Command::Verify(args)) => in_pool(args.threads, || verify::run(&args)),
        Some(Command::Bench(args)) => in_pool(args.threads, || bench::run(&args)),
        Some(Command::Campaign(args)) => in_pool(args.threads, || campaign::run(&args)),
        Some(Command::Eval(args)) => eval::run(&args),
        Some(Command::Report(args)) => report::run(&args),
        Some(Command::Profile(command)) => match command {
            crate::shells::cli::ProfileCommand::Check { threads, .. } => {
                in_pool(threads, || profile::run(&command))
            }
            _ => profile::run(&command),
        },
        Some(Command::Train(args)) => train::run(&args),
        Some(Command::Design(args)) => design(args),
        None => {
            use std::io::IsTerminal;
            if std::io::stdin().is_terminal() && std::io::stdout().is_terminal() {
                design(crate::shells::cli::DesignArgs {
                    game: arlpcg_core::level::Game::default(),
                    policies: None,
                    out: "levels".into(),
                    seed: 1,
                    campaign: None,
                    profile: None,
                    gltf: crate::shells::cli::GltfArgs::default(),
                    threads: None,
                })
            } else {
                use clap::CommandFactory;
                Cli::command().print_long_help()?;
                Ok(())
            }
        }
    }
}

/// `run` in a pool of `threads` workers (default: one per core), where every trial it plays
/// runs: results do not depend on the count.
fn in_pool(threads: Option<u64>, run: impl FnOnce() -> Result<()> + Send) -> Result<()> {
    crate::shells::common::thread_pool(threads)?.install(run)
}

fn design(args: crate::shells::cli::DesignArgs) -> Result<()> {
    crate::shells::design::run(crate::shells::design::DesignOptions {
        game: args.game,
        policies: args.policies,
        out: args.out,
        seed: args.seed,
        campaign: args.campaign,
        profile: args.profile,
        gltf: args.gltf.into(),
        threads: args.threads,
    })
}
