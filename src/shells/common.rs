//! What the shells share (the command layer, training's progress, the designer): usage errors
//! and interruptions with their exit codes, progress bars, the thread pool and the thread count
//! candle asks for, where the shipped policies are ([`policies_root`]) and what is said of
//! Solvers that play under a profile they never trained with.

use anyhow::Result;

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

/// Levels that failed their acceptance checks (`--check`; exit code 3, so that CI can tell a
/// batch that missed its spec from a run that failed). The files were written all the same.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ChecksFailed(pub String);

/// Whether a write to standard output has failed (a closed pipe, `| head`): what is left to
/// say is dropped, commands that stream lines stop early, and the process exits
/// [`BROKEN_PIPE_EXIT`].
static STDOUT_CLOSED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Why standard output could not be written, when it was not a closed pipe (a full disk:
/// `> /dev/full`): the process then exits 1 with this reason.
static STDOUT_FAILED: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// The exit code after standard output closed: 128 + SIGPIPE, as a shell reports a command a
/// closed pipe ended.
pub const BROKEN_PIPE_EXIT: u8 = 141;

/// Writes to standard output; a failed write is remembered, never a panic: a closed pipe ends
/// the command quietly ([`stdout_closed`]), any other failure (a full disk) is an error
/// ([`stdout_failed`]). Control characters from files are escaped ([`printable`]).
/// [`say!`](crate::say) is the `println!` of the commands.
pub fn say(text: std::fmt::Arguments) {
    use std::io::Write;
    if stdout_closed() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out
        .write_all(printable(&text.to_string()).as_bytes())
        .and_then(|()| out.flush())
    {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            let _ = STDOUT_FAILED.set(format!("cannot write to standard output: {e}"));
        }
        STDOUT_CLOSED.store(true, std::sync::atomic::Ordering::SeqCst);
    }
}

/// Writes to standard error, dropping the text where it cannot be written (a closed pipe).
/// Control characters are escaped as in [`say`]. [`warn!`](crate::warn) is the `eprintln!` of
/// the commands.
pub fn warn(text: std::fmt::Arguments) {
    use std::io::Write;
    let _ = std::io::stderr()
        .lock()
        .write_all(printable(&text.to_string()).as_bytes());
}

/// `text` safe for a terminal: every control character but the line break and the tab (a
/// terminal's escape codes, a carriage return that overwrites a line, text a file holds) is
/// written as its escape (`\u{1b}`).
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    let unsafe_char = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.contains(unsafe_char) {
        return std::borrow::Cow::Borrowed(text);
    }
    text.chars()
        .map(|c| match unsafe_char(c) {
            true => c.escape_default().to_string(),
            false => c.to_string(),
        })
        .collect::<String>()
        .into()
}

/// The most characters of one line of a message; a longer line (a huge argument quoted back)
/// keeps its two ends.
const MESSAGE_LINE_CHARS: usize = 400;

/// `text` with every line longer than [`MESSAGE_LINE_CHARS`] cut down to its first 200 and last
/// 100 characters around a note of how many went.
pub fn cut_long_lines(text: &str) -> String {
    text.lines()
        .map(|line| {
            let chars: Vec<char> = line.chars().collect();
            if chars.len() <= MESSAGE_LINE_CHARS {
                return line.to_string();
            }
            let (head, tail) = (&chars[..200], &chars[chars.len() - 100..]);
            format!(
                "{} … ({} characters left out) … {}",
                head.iter().collect::<String>(),
                chars.len() - 300,
                tail.iter().collect::<String>()
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Whether standard output has closed (see [`say`]).
pub fn stdout_closed() -> bool {
    STDOUT_CLOSED.load(std::sync::atomic::Ordering::SeqCst)
}

/// Why standard output failed, when it was not a closed pipe (see [`say`]).
pub fn stdout_failed() -> Option<&'static str> {
    STDOUT_FAILED.get().map(String::as_str)
}

/// `println!` to standard output through [`say`]: a closed pipe ends nothing.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::shells::common::say(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` through [`warn`]: a closed standard error ends nothing.
#[macro_export]
macro_rules! warn {
    ($($arg:tt)*) => {
        $crate::shells::common::warn(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// The exit code for an error: 2 for a [`UsageError`], 3 for [`ChecksFailed`], 130 for
/// [`Interrupted`], 1 for the rest.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    if err.downcast_ref::<UsageError>().is_some() {
        2
    } else if err.downcast_ref::<ChecksFailed>().is_some() {
        3
    } else if err.downcast_ref::<Interrupted>().is_some() {
        130
    } else {
        1
    }
}

/// The rayon pool that environments, trials and candle's matrix products share: `threads`
/// workers, or one per core.
pub fn thread_pool(threads: Option<u64>) -> Result<rayon::ThreadPool> {
    let threads = threads.map_or_else(
        || std::thread::available_parallelism().map_or(2, |n| n.get()),
        |t| t as usize,
    );
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?)
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress_bar(total: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} [{elapsed} < {eta}]")
            .expect("the template is valid"),
    );
    bar.set_message(what.to_string());
    bar
}

/// Fixes the thread count candle uses, once per process: sets `RAYON_NUM_THREADS` to the
/// machine's available parallelism unless the user set it.
///
/// candle 0.11 asks for its thread count on every matrix product. Unless `RAYON_NUM_THREADS`
/// is set, on Linux machines that do not publish CPU capacities (most x86 machines) it answers
/// by parsing `/proc/cpuinfo` (`num_cpus::get_physical`) each time: about a third of the time
/// of a designer's Solver run went there and to the scheduler. Setting the variable once, to
/// the count rayon would use anyway, makes the answer an environment lookup.
///
/// # Safety
/// Changes the process environment: call it first thing in `main`, before any other thread
/// exists (see [`std::env::set_var`]).
pub unsafe fn fix_thread_count() {
    if std::env::var_os("RAYON_NUM_THREADS").is_none() {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        // SAFETY: the caller guarantees that no other thread reads or writes the environment.
        unsafe { std::env::set_var("RAYON_NUM_THREADS", threads.to_string()) };
    }
}

/// The code this binary runs, for the cards of the policies it trains: the last commit that
/// changed the code (src/, crates/, Cargo.toml, Cargo.lock) in the checkout it was built from,
/// `-dirty` when the code differs from that commit, "unknown" without git or that checkout.
/// Read when a run starts, not at build time, so that a commit recompiles nothing.
pub fn code_commit() -> String {
    const CODE: [&str; 4] = ["src", "crates", "Cargo.toml", "Cargo.lock"];
    let git = |args: &[&str]| {
        let out = std::process::Command::new("git")
            .arg("-C")
            .arg(env!("CARGO_MANIFEST_DIR"))
            .args(args)
            .args(["--"])
            .args(CODE)
            .stderr(std::process::Stdio::null())
            .output()
            .ok()?;
        out.status
            .success()
            .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
    };
    match git(&["log", "-1", "--format=%h", "--abbrev=7"]).filter(|c| !c.is_empty()) {
        Some(commit) if git(&["status", "--porcelain"]).is_some_and(|s| !s.is_empty()) => {
            format!("{commit}-dirty")
        }
        Some(commit) => commit,
        None => "unknown".into(),
    }
}

/// The folder where measured λ→success curves are kept between runs (never beside the
/// policies they are of, which are inputs): `$ARLPCG_CACHE`, else `$XDG_CACHE_HOME/arlpcg`,
/// else `$HOME/.cache/arlpcg`; none (each run measures anew) without any of them.
pub fn cache_dir() -> Option<std::path::PathBuf> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(std::path::PathBuf::from)
    };
    var("ARLPCG_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|dir| dir.join("arlpcg")))
        .or_else(|| var("HOME").map(|home| home.join(".cache").join("arlpcg")))
}

/// The environment variable that names the folder of the shipped policies (the one holding
/// `platform/` and `racing/`), for a binary run outside its checkout.
pub const POLICIES_VAR: &str = "ARLPCG_POLICIES";

/// The folder of the shipped policies, whose `platform/` and `racing/` are each game's default
/// `--policies`: `$ARLPCG_POLICIES` when it is set; else `policies/` in the working folder when
/// there is one (a checkout); else `policies/` beside the running binary or one or two folders
/// above it (`target/release/arlpcg` finds its checkout's). An error names every place looked
/// at.
pub fn policies_root() -> Result<std::path::PathBuf> {
    find_policies_root(
        std::env::var_os(POLICIES_VAR)
            .filter(|v| !v.is_empty())
            .map(std::path::PathBuf::from),
        std::path::Path::new("policies"),
        std::env::current_exe().ok().as_deref(),
    )
}

/// The folder of the shipped policies of `game` (`--policies` when it is not given):
/// `game`'s folder in [`policies_root`].
pub fn shipped_dir(game: arlpcg_core::level::Game) -> Result<std::path::PathBuf> {
    Ok(policies_root()?.join(game.name()))
}

/// [`policies_root`] from what it reads: the variable's value, the working folder's
/// `policies/` (`here`) and the running binary.
fn find_policies_root(
    var: Option<std::path::PathBuf>,
    here: &std::path::Path,
    exe: Option<&std::path::Path>,
) -> Result<std::path::PathBuf> {
    if let Some(dir) = var {
        if dir.is_dir() {
            return Ok(dir);
        }
        anyhow::bail!(
            "{POLICIES_VAR}={}: no such folder (it names the folder of the shipped policies, which holds platform/ and racing/)",
            dir.display()
        );
    }
    if here.is_dir() {
        return Ok(here.to_path_buf());
    }
    let beside: Vec<std::path::PathBuf> = exe
        .and_then(std::path::Path::parent)
        .map(|bin| {
            bin.ancestors()
                .take(3)
                .map(|d| d.join("policies"))
                .collect()
        })
        .unwrap_or_default();
    if let Some(found) = beside.iter().find(|dir| dir.is_dir()) {
        return Ok(found.clone());
    }
    let looked: Vec<String> =
        std::iter::once(format!("{} (in the working folder)", here.display()))
            .chain(beside.iter().map(|dir| dir.display().to_string()))
            .collect();
    anyhow::bail!(
        "no shipped policies: looked for {}; set {POLICIES_VAR} to the folder that holds platform/ and racing/, or give --policies",
        looked.join(", ")
    )
}

/// Whether `policy` may play under `profile` (none: the built-in game): a warning when it trained
/// with other abilities, an error when they lie beyond the range it trained over.
pub fn check_fit(
    policy: &crate::services::verify::SolverPolicy,
    profile: Option<&arlpcg_core::level::profile::Profile>,
) -> Result<()> {
    use crate::services::verify::ProfileFit;
    match policy.fit(profile) {
        ProfileFit::Fits => Ok(()),
        ProfileFit::Untrained(said) => {
            crate::warn!("{said}");
            Ok(())
        }
        ProfileFit::Beyond(problem) => Err(anyhow::anyhow!("{problem}")),
    }
}

/// What [`check_fit`] says of each Solver of `panel` that plays under `profile` (none: the
/// built-in game) though it never trained with its abilities (or beyond the range it trained
/// over): one line per thing said, naming the judges it is of. Nothing is refused: a panel's
/// judge plays as it can.
pub fn panel_fit(
    panel: &crate::services::panel::JudgePanel,
    profile: Option<&arlpcg_core::level::profile::Profile>,
) -> Vec<String> {
    use crate::services::verify::{ProfileFit, Solver};
    let mut said: Vec<(String, Vec<String>)> = Vec::new();
    for (k, (judge, _)) in panel.judges.iter().enumerate() {
        let Solver::Policy(policy) = panel.solver(k) else {
            continue;
        };
        let (ProfileFit::Untrained(problem) | ProfileFit::Beyond(problem)) = policy.fit(profile)
        else {
            continue;
        };
        match said.iter_mut().find(|(known, _)| *known == problem) {
            Some((_, judges)) => judges.push(judge.name()),
            None => said.push((problem, vec![judge.name()])),
        }
    }
    said.into_iter()
        .map(|(problem, judges)| {
            let judge = if judges.len() == 1 { "judge" } else { "judges" };
            format!("panel {judge} {}: {problem}", judges.join(", "))
        })
        .collect()
}

/// Says [`panel_fit`]'s lines.
pub fn check_panel_fit(
    panel: &crate::services::panel::JudgePanel,
    profile: Option<&arlpcg_core::level::profile::Profile>,
) {
    for line in panel_fit(panel, profile) {
        crate::warn!("{line}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn the_policies_are_found_by_the_variable_then_here_then_beside_the_binary() {
        let top = tempfile::tempdir().unwrap();
        let at = |p: &str| top.path().join(p);
        for dir in [
            "var", "checkout/policies", "checkout/target/release", "here",
        ] {
            std::fs::create_dir_all(at(dir)).unwrap();
        }
        let exe = at("checkout/target/release/arlpcg");
        let here = at("here/policies");
        // The binary's checkout, two folders up.
        let found = find_policies_root(None, &here, Some(&exe)).unwrap();
        assert_eq!(found, at("checkout/policies"));
        // The working folder's before it, the variable before both.
        std::fs::create_dir_all(&here).unwrap();
        assert_eq!(find_policies_root(None, &here, Some(&exe)).unwrap(), here);
        let var = Some(at("var"));
        assert_eq!(
            find_policies_root(var, &here, Some(&exe)).unwrap(),
            at("var")
        );
        // A variable naming no folder is an error, not a fallback.
        let missing = find_policies_root(Some(at("nowhere")), &here, Some(&exe)).unwrap_err();
        assert!(
            missing.to_string().starts_with("ARLPCG_POLICIES=")
                && missing.to_string().contains("nowhere"),
            "{missing}"
        );
    }

    #[test]
    fn without_policies_the_error_names_every_place_looked_at() {
        let top = tempfile::tempdir().unwrap();
        let exe = top.path().join("a/b/c/arlpcg");
        let here = Path::new("no-such-folder/policies");
        let error = find_policies_root(None, here, Some(&exe))
            .unwrap_err()
            .to_string();
        for place in ["a/b/c/policies", "a/b/policies", "a/policies"] {
            let place = top.path().join(place);
            assert!(error.contains(&place.display().to_string()), "{error}");
        }
        assert!(
            error.contains("no-such-folder/policies (in the working folder)"),
            "{error}"
        );
        assert!(
            error.contains("ARLPCG_POLICIES") && error.contains("--policies"),
            "{error}"
        );
        // Three folders up is not looked at.
        let above = top.path().join("policies").display().to_string();
        assert!(!error.contains(&above), "{error}");
    }
}
