//! The `arlpcg` command: checks the arguments are UTF-8, parses them and runs the subcommand
//! (src/shells), with mimalloc as the allocator.

use std::process::ExitCode;

/// mimalloc: about 3x faster PPO updates than glibc's allocator (fewer page faults).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    // SAFETY: first thing in main, before any other thread exists.
    unsafe { arlpcg::shells::common::fix_thread_count() };
    // Levels, cards and sidecars record paths and commands as UTF-8 text: an argument that is
    // not UTF-8 could not be recorded as given, so it is refused before anything happens.
    if let Some((k, arg)) = std::env::args_os()
        .enumerate()
        .skip(1)
        .find(|(_, arg)| arg.to_str().is_none())
    {
        arlpcg::warn!(
            "error: argument {k} ({}) is not valid UTF-8: arlpcg records paths and commands as \
             UTF-8 text in levels and cards; rename the file or folder",
            arg.to_string_lossy()
        );
        return ExitCode::from(2);
    }
    let cli = match arlpcg::shells::cli::Cli::parse_args() {
        Ok(cli) => cli,
        // A usage error quotes the argument it refuses: a huge one is cut down to its ends.
        Err(e) if e.use_stderr() => {
            let text = e.render().to_string();
            arlpcg::warn!(
                "{}",
                arlpcg::shells::common::cut_long_lines(text.trim_end())
            );
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
        Err(e) => e.exit(), // --help and --version
    };
    let done = arlpcg::shells::commands::run(cli);
    // Standard output could not be written (a full disk): what was to be said is lost.
    if let (Ok(()), Some(failed)) = (&done, arlpcg::shells::common::stdout_failed()) {
        arlpcg::warn!("error: {failed}");
        return ExitCode::FAILURE;
    }
    match done {
        // What the command wrote to files is whole; what it had left to say had nowhere to go.
        Ok(()) if arlpcg::shells::common::stdout_closed() => {
            ExitCode::from(arlpcg::shells::common::BROKEN_PIPE_EXIT)
        }
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            arlpcg::warn!(
                "error: {}",
                arlpcg::shells::commands::one_line(&format!("{err:#}"))
            );
            ExitCode::from(arlpcg::shells::commands::exit_code(&err))
        }
    }
}
