//! Atomic writes, and the registry of their temporary files.
//!
//! A file is written into a new temporary file beside it (`.NAME.PID.N.tmp`), flushed to disk,
//! then renamed over the target: readers see the old file or the new one, never a partial
//! one. Several files that belong together (a faired curve and its report) are written as a
//! set ([`write_atomic_set`]): every temporary first, then every rename, so that a failure
//! while writing leaves none of them.
//!
//! Every temporary file is listed in a process-wide registry from its creation to its rename.
//! A program that ends on a signal calls [`remove_temporaries`] (from a signal-handling
//! thread, not from an async signal handler: it takes a lock) so that no `.NAME.PID.N.tmp` is
//! left behind. The library installs no signal handler itself.

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::thread::ThreadId;

use super::IoError;

/// Distinguishes temporary files of concurrent writes from one process.
static TEMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// How many temporary names to try before giving up.
const TEMP_ATTEMPTS: usize = 64;

/// The temporary files that exist now, and whether new ones are refused.
#[derive(Debug)]
struct Registry {
    live: Vec<PathBuf>,
    /// After [`remove_temporaries`]: the one thread still allowed to write (the one that
    /// cleaned up, to write a last file such as a batch summary).
    sealed_for: Option<ThreadId>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    live: Vec::new(),
    sealed_for: None,
});

/// The registry, whether or not a thread panicked while holding it (its list stays valid:
/// every change is one push or one removal).
fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Remove every temporary file of an atomic write still in progress, and refuse new ones
/// from every thread but the calling one. Returns how many files were removed.
///
/// For a program that is about to end on a signal: call it from the thread that handles the
/// signal, write what must still be written from that same thread, then end the process.
/// Writes in progress on other threads fail (their rename finds no file, or their next
/// temporary file is refused); a set being renamed ([`write_atomic_set`]) finishes first, so
/// it is written whole or not at all.
pub fn remove_temporaries() -> usize {
    let mut r = registry();
    r.sealed_for = Some(std::thread::current().id());
    let mut removed = 0;
    for tmp in r.live.drain(..) {
        if fs::remove_file(&tmp).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// `path`'s directory (`.` for a bare file name) and file name.
fn split(path: &Path) -> Result<(&Path, &std::ffi::OsStr), IoError> {
    let name = path.file_name().ok_or_else(|| IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Ok((dir, name))
}

/// Create and register a new temporary file beside `path`.
fn create_temporary(path: &Path) -> Result<(PathBuf, fs::File), IoError> {
    let write_err = |source| IoError::Write {
        path: path.to_path_buf(),
        source,
    };
    let (dir, name) = split(path)?;
    let mut r = registry();
    if r.sealed_for
        .is_some_and(|t| t != std::thread::current().id())
    {
        return Err(write_err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "interrupted",
        )));
    }
    let mut attempt = 0;
    loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".{}.{n}.tmp", std::process::id()));
        let tmp = dir.join(tmp_name);
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => {
                r.live.push(tmp.clone());
                return Ok((tmp, f));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt < TEMP_ATTEMPTS => {
                attempt += 1;
            }
            Err(e) => return Err(write_err(e)),
        }
    }
}

/// Remove a temporary file and its registration.
fn discard(tmp: &Path) {
    let mut r = registry();
    // Best effort: the file may already be gone (removed on a signal).
    let _ = fs::remove_file(tmp);
    r.live.retain(|t| t != tmp);
}

/// Whether `path` can be written, checked without touching it: it is not a directory, its
/// directory exists, and a file can be created there (a temporary one, removed at once).
/// For a program to refuse an output before it computes anything.
///
/// # Errors
/// [`IoError::Write`] with what stands in the way.
pub fn check_writable(path: &Path) -> Result<(), IoError> {
    let err = |kind, what: &str| IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::new(kind, what.to_string()),
    };
    let (dir, _) = split(path)?;
    if path.is_dir() {
        return Err(err(std::io::ErrorKind::IsADirectory, "it is a directory"));
    }
    if !dir.is_dir() {
        return Err(err(
            std::io::ErrorKind::NotFound,
            &format!("directory {} does not exist", dir.display()),
        ));
    }
    let (tmp, file) = create_temporary(path)?;
    drop(file);
    discard(&tmp);
    Ok(())
}

/// Write `contents` to `path` atomically: into a new temporary file in the same directory
/// (`.NAME.PID.N.tmp`), flushed to disk, then renamed over `path`. Readers see the old file
/// or the new one, never a partial one; on failure the temporary file is removed and `path`
/// is untouched. The new file has default permissions; a symbolic link at `path` is
/// replaced by the file, not followed.
///
/// # Errors
/// [`IoError::Write`].
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), IoError> {
    write_atomic_set(&[(path, contents)])
}

/// Write several files as one set: every file into its temporary file first (flushed to
/// disk), then every temporary renamed over its target, in order. A failure while writing
/// removes every temporary file and leaves every target as it was; only a rename failing
/// after an earlier one succeeded can leave part of the set (renames within one directory
/// fail only when the directory changes under the program). Targets must be distinct.
///
/// # Errors
/// [`IoError::Write`] naming the file that could not be written.
pub fn write_atomic_set(files: &[(&Path, &[u8])]) -> Result<(), IoError> {
    write_set(files, None)
}

/// A file written into its temporary file ahead of the set it belongs to ([`stage`]):
/// flushed to disk and registered like every temporary file, not yet renamed. Given to
/// [`write_atomic_set_staged`] it is renamed last; dropped otherwise, its temporary file is
/// removed.
#[derive(Debug)]
pub struct Staged {
    path: PathBuf,
    tmp: Option<PathBuf>,
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            discard(&tmp);
        }
    }
}

/// Write `contents` into a new temporary file beside `path` and flush it, ahead of the set
/// it will belong to ([`write_atomic_set_staged`]): so that a caller can write a large file
/// while it still computes the others. `path` itself is not touched.
///
/// # Errors
/// [`IoError::Write`]; the temporary file is then removed.
pub fn stage(path: &Path, contents: &[u8]) -> Result<Staged, IoError> {
    let (tmp, mut file) = create_temporary(path)?;
    let staged = Staged {
        path: path.to_path_buf(),
        tmp: Some(tmp),
    };
    file.write_all(contents)
        .and_then(|()| file.sync_all())
        .map_err(|source| IoError::Write {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(staged)
}

/// As [`write_atomic_set`], with `staged` (written ahead by [`stage`]) the set's last file:
/// `files` are written, then renamed in order, then `staged`. A failure while writing
/// removes `staged`'s temporary file too.
///
/// # Errors
/// As [`write_atomic_set`].
pub fn write_atomic_set_staged(files: &[(&Path, &[u8])], staged: Staged) -> Result<(), IoError> {
    write_set(files, Some(staged))
}

/// [`write_atomic_set`], and [`write_atomic_set_staged`] with `staged`.
fn write_set(files: &[(&Path, &[u8])], mut staged: Option<Staged>) -> Result<(), IoError> {
    let mut temps: Vec<(PathBuf, PathBuf)> = Vec::with_capacity(files.len() + 1);
    let written = files.iter().try_for_each(|&(path, contents)| {
        let (tmp, mut file) = create_temporary(path)?;
        temps.push((tmp, path.to_path_buf()));
        file.write_all(contents)
            .and_then(|()| file.sync_all())
            .map_err(|source| IoError::Write {
                path: path.to_path_buf(),
                source,
            })
    });
    if let Err(e) = written {
        temps.iter().for_each(|(t, _)| discard(t));
        // `staged`, dropped, removes its own.
        return Err(e);
    }
    if let Some(s) = staged.as_mut()
        && let Some(tmp) = s.tmp.take()
    {
        temps.push((tmp, s.path.clone()));
    }
    // The renames hold the registry, so that a cleanup on a signal waits for the whole set.
    let mut r = registry();
    let mut result = Ok(());
    for (tmp, path) in &temps {
        if result.is_ok() {
            result = fs::rename(tmp, path).map_err(|source| IoError::Write {
                path: path.clone(),
                source,
            });
        }
        if result.is_err() {
            let _ = fs::remove_file(tmp);
        }
        r.live.retain(|t| t != tmp);
    }
    result
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn tempdir() -> PathBuf {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let d = std::env::temp_dir().join(format!("batten-atomic-{}-{n}", std::process::id()));
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_set_is_written_whole_or_not_at_all() {
        let dir = tempdir();
        let (a, b) = (dir.join("a.csv"), dir.join("b.json"));
        write_atomic_set(&[(&a, b"1"), (&b, b"2")]).unwrap();
        assert_eq!(names(&dir), ["a.csv", "b.json"]);
        // A target in a missing directory fails when its temporary file is created, before
        // any rename: the first target keeps its old contents.
        let missing = dir.join("no/such/c.json");
        let e = write_atomic_set(&[(&a, b"new"), (&missing, b"x")]).unwrap_err();
        assert!(e.to_string().contains("no/such/c.json"), "{e}");
        assert_eq!(fs::read_to_string(&a).unwrap(), "1");
        assert_eq!(names(&dir), ["a.csv", "b.json"]);
        assert!(registry().live.iter().all(|t| !t.starts_with(&dir)));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writability_is_checked_without_a_trace() {
        let dir = tempdir();
        assert!(check_writable(&dir.join("x.csv")).is_ok());
        fs::create_dir(dir.join("d.json")).unwrap();
        let e = check_writable(&dir.join("d.json")).unwrap_err().to_string();
        assert!(
            e.ends_with("d.json: cannot write: it is a directory"),
            "{e}"
        );
        let e = check_writable(&dir.join("no/x.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot write: directory "), "{e}");
        assert!(e.ends_with("no does not exist"), "{e}");
        assert!(check_writable(Path::new("/proc/x.json")).is_err());
        assert_eq!(names(&dir), ["d.json"]);
        fs::remove_dir_all(&dir).unwrap();
    }

    /// A staged file is renamed last in its set, after the files written with it; dropped
    /// without a set, or with a set that fails, its temporary file goes.
    #[test]
    fn staged_files_are_renamed_last_or_removed() {
        let d = tempdir();
        let (report, points) = (d.join("r.json"), d.join("p.csv"));
        let staged = stage(&points, b"1,2\n").unwrap();
        assert_eq!(names(&d).len(), 1, "{:?}", names(&d));
        assert!(!points.exists());
        write_atomic_set_staged(&[(&report, b"{}")], staged).unwrap();
        assert_eq!(names(&d), vec!["p.csv", "r.json"]);
        assert_eq!(fs::read(&points).unwrap(), b"1,2\n");
        // Dropped: removed.
        let staged = stage(&points, b"3,4\n").unwrap();
        drop(staged);
        assert_eq!(names(&d), vec!["p.csv", "r.json"]);
        assert_eq!(fs::read(&points).unwrap(), b"1,2\n");
        // A set that fails (a file in a missing directory): nothing renamed, nothing left.
        let staged = stage(&points, b"5,6\n").unwrap();
        let bad = d.join("missing").join("r.json");
        assert!(write_atomic_set_staged(&[(&bad, b"{}")], staged).is_err());
        assert_eq!(names(&d), vec!["p.csv", "r.json"]);
        assert_eq!(fs::read(&points).unwrap(), b"1,2\n");
        fs::remove_dir_all(&d).unwrap();
    }
}
