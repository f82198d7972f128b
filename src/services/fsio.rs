//! Writing files safely: every file is written to a temporary file beside its target, synced,
//! then renamed into place, so a crash or a full disk never leaves a half-written level; and an
//! existing file is never replaced unless the caller allows it.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// Whether an existing file may be replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Overwrite {
    /// Refuse to replace an existing file.
    Never,
    /// Replace an existing file.
    Allowed,
}

/// Fails if `path` exists and may not be overwritten (checked before any work is written).
pub fn check_writable(path: &Path, overwrite: Overwrite) -> Result<()> {
    if overwrite == Overwrite::Never && path.exists() {
        bail!(
            "{} already exists (use --force to overwrite it)",
            path.display()
        );
    }
    Ok(())
}

/// Fails unless `path` is a regular file (or a link to one): a FIFO would block the opening
/// forever, a device never end, a folder not read. Checked before a path is opened.
pub fn check_regular(path: &Path, what: &str) -> Result<()> {
    let meta = std::fs::metadata(path)
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    if !meta.is_file() {
        bail!(
            "{what} {} is not a regular file (a folder, FIFO, socket or device)",
            path.display()
        );
    }
    Ok(())
}

/// Reads a whole regular file of at most `limit` bytes; `what` names it in errors (devices,
/// FIFOs, folders and larger files are refused before anything is read).
pub fn read_limited(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>> {
    use std::io::Read;
    check_regular(path, what)?;
    let file = std::fs::File::open(path)
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    let meta = file
        .metadata()
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    if !meta.is_file() {
        bail!("{what} {} is not a regular file", path.display());
    }
    if meta.len() > limit {
        bail!(
            "{what} {} is {} bytes, more than the {limit} a {what} may have",
            path.display(),
            meta.len()
        );
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    if bytes.len() as u64 > limit {
        bail!(
            "{what} {} grew past {limit} bytes while it was read",
            path.display()
        );
    }
    Ok(bytes)
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8], overwrite: Overwrite) -> Result<()> {
    check_writable(path, overwrite)?;
    let temp = synced_temp(path, bytes)?;
    match overwrite {
        Overwrite::Never => temp.persist_noclobber(path).map(drop).map_err(|e| e.error),
        Overwrite::Allowed => temp.persist(path).map(drop).map_err(|e| e.error),
    }
    .with_context(|| format!("cannot write {}", path.display()))
}

/// Files written all or nothing: each is staged as a synced temporary file beside its target
/// (nothing is held in memory), then [`FileBatch::commit`] renames them all into place. If staging
/// or any rename fails, every target is left as it was before: files the batch created are
/// removed, files it replaced are put back, and the temporaries go (also when the batch is
/// dropped uncommitted).
#[derive(Default)]
pub struct FileBatch {
    staged: Vec<(tempfile::NamedTempFile, PathBuf, Overwrite)>,
}

impl FileBatch {
    /// An empty batch.
    pub fn new() -> Self {
        Self::default()
    }

    /// Stages `bytes` for `path`: refused at once if `path` exists and may not be replaced, or
    /// is not a regular file (a folder or FIFO is never replaced).
    pub fn stage(&mut self, path: &Path, bytes: &[u8], overwrite: Overwrite) -> Result<()> {
        check_writable(path, overwrite)?;
        check_not_in_the_way(path)?;
        let temp = synced_temp(path, bytes)?;
        self.staged.push((temp, path.to_path_buf(), overwrite));
        Ok(())
    }

    /// How many files are staged.
    pub fn len(&self) -> usize {
        self.staged.len()
    }

    /// Whether nothing is staged.
    pub fn is_empty(&self) -> bool {
        self.staged.is_empty()
    }

    /// Renames every staged file into place, in the order staged; on a failure undoes the
    /// renames done so far and says which file failed.
    pub fn commit(self) -> Result<()> {
        // (target, its previous contents moved aside, if it had any)
        let mut done: Vec<(PathBuf, Option<tempfile::TempPath>)> = Vec::new();
        let mut failure = None;
        for (temp, path, overwrite) in self.staged {
            let backup = match overwrite {
                Overwrite::Allowed if path.exists() => match move_aside(&path) {
                    Ok(backup) => Some(backup),
                    Err(e) => {
                        failure = Some(e);
                        break;
                    }
                },
                _ => None,
            };
            // Never replaces: a file that appeared since the check (another run's) stays.
            match temp.persist_noclobber(&path) {
                Ok(_) => done.push((path, backup)),
                Err(e) => {
                    if let Some(backup) = backup {
                        let _ = std::fs::rename(&backup, &path);
                        let _ = backup.keep();
                    }
                    failure = Some(
                        anyhow::Error::from(e.error)
                            .context(format!("cannot write {}", path.display())),
                    );
                    break;
                }
            }
        }
        let Some(failure) = failure else {
            return Ok(()); // backups are removed as they drop
        };
        for (path, backup) in done.into_iter().rev() {
            match backup {
                Some(backup) => {
                    let _ = std::fs::rename(&backup, &path);
                    let _ = backup.keep();
                }
                None => {
                    let _ = std::fs::remove_file(&path);
                }
            }
        }
        Err(failure.context("nothing was written (the files written before it were taken back)"))
    }
}

/// Fails if something other than a regular file (a folder, link, FIFO or device) stands at
/// `path`: such a thing is never read as a level's file nor replaced.
pub fn check_not_in_the_way(path: &Path) -> Result<()> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| !m.is_file()) {
        bail!(
            "{} is in the way: it is not a regular file (a folder, link, FIFO or device), and is never replaced",
            path.display()
        );
    }
    Ok(())
}

/// Moves the file at `path` to a fresh temporary name beside it (removed when dropped).
fn move_aside(path: &Path) -> Result<tempfile::TempPath> {
    let backup = tempfile::Builder::new()
        .prefix(".arlpcg-")
        .suffix(".tmp")
        .tempfile_in(parent_dir(path))
        .with_context(|| format!("cannot set {} aside", path.display()))?
        .into_temp_path();
    std::fs::rename(path, &backup)
        .with_context(|| format!("cannot set {} aside", path.display()))?;
    Ok(backup)
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

/// `bytes` in a synced, world-readable temporary file beside `path`.
fn synced_temp(path: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile> {
    let dir = parent_dir(path);
    let mut temp = tempfile::Builder::new()
        .prefix(".arlpcg-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a file in {}", dir.display()))?;
    temp.write_all(bytes)
        .and_then(|()| readable_by_all(temp.as_file()))
        .and_then(|()| temp.as_file().sync_all())
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(temp)
}

/// Temporary files this tool writes before renaming them into place: `.arlpcg-*.tmp`.
fn is_our_temp(name: &str) -> bool {
    name.starts_with(".arlpcg-") && name.ends_with(".tmp")
}

/// How old a temporary file must be to count as left by a killed run: a live writer renames
/// its temporaries within seconds.
pub const STALE_TEMP_AGE: std::time::Duration = std::time::Duration::from_secs(600);

/// Holds folder `dir` for one writer at a time (an advisory `flock` on the folder itself, so no
/// lock file is left behind): two batches written into one folder at once would check, stage and
/// roll back over each other's files. Waits while another process holds it, after calling
/// `on_wait` once. The lock goes with the returned handle, or with the process however it ends.
/// Where a folder cannot be opened as a file (not on Unix), nothing is locked.
pub fn lock_folder(dir: &Path, on_wait: impl FnOnce()) -> Result<Option<std::fs::File>> {
    let Ok(handle) = std::fs::File::open(dir) else {
        return Ok(None);
    };
    match handle.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            on_wait();
            handle
                .lock()
                .with_context(|| format!("cannot lock {}", dir.display()))?;
        }
        Err(std::fs::TryLockError::Error(e)) => {
            return Err(e).with_context(|| format!("cannot lock {}", dir.display()));
        }
    }
    Ok(Some(handle))
}

/// Writes `files` into folder `dir`, all or none, one batch into a folder at a time
/// ([`lock_folder`]; `on_wait` if another run holds it): each file is staged beside its target
/// as the iterator makes it (memory stays bounded), then all are renamed into place. A file
/// that exists already with the same bytes is left alone (a re-run finishes a batch); one with
/// other bytes is replaced only when `replace(path)`, else the batch is refused, the message
/// ending with `refusal` (how to allow it). Returns (files written, files left as they were).
pub fn write_batch(
    dir: &Path,
    files: impl IntoIterator<Item = (PathBuf, Vec<u8>)>,
    replace: &dyn Fn(&Path) -> bool,
    refusal: &str,
    on_wait: impl FnOnce(),
) -> Result<(usize, usize)> {
    let _held = lock_folder(dir, on_wait)?;
    remove_stale_temps(dir, std::time::SystemTime::now())?;
    let mut batch = FileBatch::new();
    let mut kept = 0;
    let nothing = "nothing was written";
    for (path, bytes) in files {
        check_not_in_the_way(&path).with_context(|| nothing.to_string())?;
        let overwrite = match std::fs::read(&path) {
            Ok(existing) if existing == bytes => {
                kept += 1;
                continue;
            }
            Ok(_) if !replace(&path) => bail!(
                "{} already exists with other contents ({refusal}); {nothing}",
                path.display()
            ),
            Ok(_) => Overwrite::Allowed,
            // Absent when checked: written only if still absent (another run may get there
            // first, and its file is not replaced).
            Err(_) => Overwrite::Never,
        };
        batch
            .stage(&path, &bytes, overwrite)
            .with_context(|| nothing.to_string())?;
    }
    let staged = batch.len();
    batch.commit()?;
    Ok((staged, kept))
}

/// Removes the temporary files a killed run left in `dir` (older than [`STALE_TEMP_AGE`],
/// so another run's file being written is never touched); returns how many went. `now` is the
/// caller's clock.
pub fn remove_stale_temps(dir: &Path, now: std::time::SystemTime) -> Result<usize> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(0);
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let Ok(meta) = entry.metadata() else { continue };
        let old = meta
            .modified()
            .ok()
            .and_then(|m| now.duration_since(m).ok())
            .is_some_and(|age| age >= STALE_TEMP_AGE);
        if is_our_temp(name) && meta.is_file() && old {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!(
                    "cannot remove the stale temporary file {}",
                    entry.path().display()
                )
            })?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// The first entry of `dir` besides this tool's temporary files and the names in `besides`, if
/// it exists and has one.
pub fn first_entry(dir: &Path, besides: &[&str]) -> Result<Option<String>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(e).with_context(|| format!("cannot read the folder {}", dir.display()));
        }
    };
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot read the folder {}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !is_our_temp(&name) && !besides.contains(&name.as_str()) {
            return Ok(Some(name));
        }
    }
    Ok(None)
}

/// Temporary files are created private (0600); the files we deliver are ordinary (0644).
#[cfg(unix)]
fn readable_by_all(file: &std::fs::File) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    file.set_permissions(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn readable_by_all(_file: &std::fs::File) -> std::io::Result<()> {
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn never_overwrites_unless_allowed_and_leaves_no_temp_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("level.yaml");
        write_atomic(&path, b"one", Overwrite::Never).unwrap();
        let err = write_atomic(&path, b"two", Overwrite::Never).unwrap_err();
        assert!(err.to_string().contains("already exists"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"one");
        write_atomic(&path, b"three", Overwrite::Allowed).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"three");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec!["level.yaml"]);
    }

    #[test]
    fn only_old_temporary_files_of_ours_count_as_stale() {
        let dir = tempfile::tempdir().unwrap();
        for name in [
            ".arlpcg-old.tmp", ".arlpcg-new.tmp", "old.tmp", "level.yaml",
        ] {
            std::fs::write(dir.path().join(name), b"x").unwrap();
        }
        let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        for name in [".arlpcg-old.tmp", "old.tmp"] {
            let file = std::fs::File::options()
                .write(true)
                .open(dir.path().join(name))
                .unwrap();
            file.set_modified(hour_ago).unwrap();
        }
        let removed = remove_stale_temps(dir.path(), std::time::SystemTime::now()).unwrap();
        assert_eq!(removed, 1);
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, [".arlpcg-new.tmp", "level.yaml", "old.tmp"]);
        assert!(first_entry(dir.path(), &[]).unwrap().is_some());
        std::fs::remove_file(dir.path().join("level.yaml")).unwrap();
        std::fs::remove_file(dir.path().join("old.tmp")).unwrap();
        assert_eq!(
            first_entry(dir.path(), &[]).unwrap(),
            None,
            "our temporaries do not count"
        );
    }

    #[test]
    fn a_fifo_is_refused_without_being_opened() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("policy.safetensors");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: mkfifo is not available here");
            return;
        }
        let err = read_limited(&fifo, 100, "Solver policy").unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_batch_is_written_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let path = |name: &str| dir.path().join(name);
        std::fs::write(path("old.yaml"), b"old").unwrap();
        // Whole: a new file and a replaced one.
        let mut batch = FileBatch::new();
        batch
            .stage(&path("a.yaml"), b"a", Overwrite::Never)
            .unwrap();
        batch
            .stage(&path("old.yaml"), b"new", Overwrite::Allowed)
            .unwrap();
        batch.commit().unwrap();
        assert_eq!(names(dir.path()), ["a.yaml", "old.yaml"]);
        assert_eq!(std::fs::read(path("old.yaml")).unwrap(), b"new");
        // Not at all: the third file appears (another run) between staging and commit.
        let mut batch = FileBatch::new();
        batch
            .stage(&path("b.yaml"), b"b", Overwrite::Never)
            .unwrap();
        batch
            .stage(&path("old.yaml"), b"newer", Overwrite::Allowed)
            .unwrap();
        batch
            .stage(&path("c.yaml"), b"c", Overwrite::Never)
            .unwrap();
        std::fs::write(path("c.yaml"), b"theirs").unwrap();
        let err = batch.commit().unwrap_err();
        assert!(format!("{err:#}").contains("c.yaml"), "{err:#}");
        assert_eq!(names(dir.path()), ["a.yaml", "c.yaml", "old.yaml"]);
        assert_eq!(std::fs::read(path("old.yaml")).unwrap(), b"new", "put back");
        assert_eq!(
            std::fs::read(path("c.yaml")).unwrap(),
            b"theirs",
            "never replaced"
        );
        // Dropped uncommitted: nothing stays.
        let mut batch = FileBatch::new();
        batch
            .stage(&path("d.yaml"), b"d", Overwrite::Never)
            .unwrap();
        drop(batch);
        assert_eq!(names(dir.path()), ["a.yaml", "c.yaml", "old.yaml"]);
        // A folder where a file should go is refused at staging.
        std::fs::create_dir(path("e.yaml")).unwrap();
        let mut batch = FileBatch::new();
        let err = batch
            .stage(&path("e.yaml"), b"e", Overwrite::Allowed)
            .unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    #[test]
    fn a_missing_directory_is_a_clear_error() {
        let err = write_atomic(
            Path::new("/nonexistent-dir/level.yaml"),
            b"x",
            Overwrite::Never,
        )
        .unwrap_err();
        assert!(format!("{err:#}").contains("/nonexistent-dir"), "{err:#}");
    }
}
