//! What `batten batch` checks before it fairs anything: the inputs (files, directories,
//! patterns), the output and report names (no two inputs may write the same file), the output
//! directory (never an input's) and the summary's place. A usage error found here leaves
//! nothing behind.

use std::collections::HashMap;
use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::anyhow;
use batten::io::{Format, IoError};

use crate::failure::Failure;
use crate::fair_cmd;

/// Suffix of the report written beside each output: `NAME.csv` → `NAME.report.json`.
const REPORT_SUFFIX: &str = ".report.json";

/// One input: where it is read from and where its results go.
#[derive(Clone, Debug)]
pub(super) struct Job {
    pub(super) input: PathBuf,
    pub(super) output: PathBuf,
    pub(super) report: PathBuf,
}

/// The inputs as listed: files as given, directories expanded to their point files sorted by
/// name, patterns to the point files they match sorted by name.
///
/// # Errors
/// [`Failure::usage`] for a directory that cannot be listed, a pattern that matches nothing,
/// or no input file at all.
pub(super) fn expand(args: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let mut inputs = Vec::new();
    for arg in args {
        if arg.is_dir() {
            inputs.extend(list_dir(arg, None)?);
        } else if let Some(pattern) = pattern(arg) {
            let dir = arg.parent().unwrap_or(Path::new(""));
            let found = list_dir(dir, Some(pattern))?;
            if found.is_empty() {
                return Err(Failure::usage(anyhow!(
                    "{}: matches no .csv, .txt, .json, .dxf, .igs or .svg file",
                    arg.display()
                )));
            }
            inputs.extend(found);
        } else if !arg.exists() && Format::from_path(arg).is_err() {
            // Not a point file by name, and nothing there: most likely a folder that is not
            // there (`scans/`). Say so, rather than "unknown file format" for each.
            return Err(Failure::usage(anyhow!(
                "{}: no such file or directory",
                arg.display()
            )));
        } else {
            // A file, or a point file that does not exist: reading it reports what is wrong,
            // as a row of the summary.
            inputs.push(arg.clone());
        }
    }
    if inputs.is_empty() {
        return Err(Failure::usage(anyhow!(
            "no .csv, .txt, .json, .dxf, .igs or .svg files in {}",
            args.iter()
                .map(|a| a.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    Ok(inputs)
}

/// The file-name pattern of `path`, when it names no existing file and its last component
/// holds `*` or `?`.
fn pattern(path: &Path) -> Option<&str> {
    if path.exists() {
        return None;
    }
    let name = path.file_name()?.to_str()?;
    name.contains(['*', '?']).then_some(name)
}

/// The point files (known extension, not hidden, regular files or links to them) of `dir`
/// whose names match `pattern` (all, without one), sorted by name.
fn list_dir(dir: &Path, pattern: Option<&str>) -> Result<Vec<PathBuf>, Failure> {
    let read_from = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let cannot = |e: std::io::Error| {
        Failure::usage(anyhow!(
            "{}: cannot read directory: {e}",
            read_from.display()
        ))
    };
    let mut names: Vec<OsString> = Vec::new();
    for entry in fs::read_dir(read_from).map_err(cannot)? {
        let name = entry.map_err(cannot)?.file_name();
        let lossy = name.to_string_lossy();
        let shown = match pattern {
            Some(p) => wildcard_match(p, &lossy) && (p.starts_with('.') || !lossy.starts_with('.')),
            None => !lossy.starts_with('.'),
        };
        let path = dir.join(&name);
        if shown && Format::from_path(&path).is_ok() && path.is_file() {
            names.push(name);
        }
    }
    names.sort();
    Ok(names.into_iter().map(|n| dir.join(n)).collect())
}

/// Whether `name` matches `pattern`, where `*` matches any run of characters and `?` any one
/// character. Greedy, backtracking to the last `*` only: O(pattern × name), never exponential.
fn wildcard_match(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    let (mut pi, mut ni) = (0, 0);
    // The last `*` seen and the name position it is currently matched up to.
    let mut star: Option<(usize, usize)> = None;
    while let Some(&c) = n.get(ni) {
        match p.get(pi) {
            Some('*') => {
                star = Some((pi, ni));
                pi += 1;
            }
            Some(&q) if q == '?' || q == c => {
                pi += 1;
                ni += 1;
            }
            _ => match star {
                Some((sp, sn)) => {
                    star = Some((sp, sn + 1));
                    pi = sp + 1;
                    ni = sn + 1;
                }
                None => return false,
            },
        }
    }
    p.iter().skip(pi).all(|&c| c == '*')
}

/// The output and report paths of every input.
///
/// # Errors
/// [`Failure::usage`] when an input has no file name, or two inputs would write the same file
/// (compared ignoring ASCII case, as on case-insensitive file systems): the same file given
/// twice, `a/x.csv` and `b/x.csv`, or `x.csv` and `x.json` (both report to `x.report.json`).
pub(super) fn plan(inputs: &[PathBuf], out_dir: &Path) -> Result<Vec<Job>, Failure> {
    let mut writers: HashMap<String, &Path> = HashMap::new();
    let mut jobs = Vec::with_capacity(inputs.len());
    for input in inputs {
        let (Some(name), Some(stem)) = (input.file_name(), input.file_stem()) else {
            return Err(Failure::usage(anyhow!(
                "{}: not a file name",
                input.display()
            )));
        };
        let mut report = stem.to_os_string();
        report.push(REPORT_SUFFIX);
        for out_name in [name, report.as_os_str()] {
            let key = out_name.to_string_lossy().to_ascii_lowercase();
            if let Some(other) = writers.insert(key, input) {
                let target = out_dir.join(out_name);
                return Err(Failure::usage(if other == input.as_path() {
                    anyhow!("{} is given more than once", input.display())
                } else {
                    anyhow!(
                        "{} and {} would both write {}",
                        other.display(),
                        input.display(),
                        target.display()
                    )
                }));
            }
        }
        jobs.push(Job {
            input: input.clone(),
            output: out_dir.join(name),
            report: out_dir.join(report),
        });
    }
    Ok(jobs)
}

/// Refuse an output directory that is not a directory, or that holds an input (by the path
/// given or, through links, by the file's real place), so that no input is ever replaced.
pub(super) fn check_out_dir(jobs: &[Job], out_dir: &Path) -> Result<(), Failure> {
    if !out_dir.exists() {
        return Ok(());
    }
    if !out_dir.is_dir() {
        return Err(Failure::usage(anyhow!(
            "{}: not a directory",
            out_dir.display()
        )));
    }
    let Ok(out_real) = fs::canonicalize(out_dir) else {
        return Ok(());
    };
    let mut parents: HashMap<PathBuf, Option<PathBuf>> = HashMap::new();
    for job in jobs {
        let parent = match job.input.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let given = parents
            .entry(parent.to_path_buf())
            .or_insert_with(|| fs::canonicalize(parent).ok());
        let real = fs::canonicalize(&job.input).ok();
        let real_parent = real.as_deref().and_then(Path::parent);
        if given.as_deref() == Some(out_real.as_path()) || real_parent == Some(out_real.as_path()) {
            return Err(Failure::usage(anyhow!(
                "refusing to write into {}: it is the directory of the input {}",
                out_dir.display(),
                job.input.display()
            )));
        }
    }
    Ok(())
}

/// The summary goes into an existing directory or the output directory, and replaces neither
/// an input nor an output of the batch.
pub(super) fn check_summary(path: &Path, jobs: &[Job], out_dir: &Path) -> Result<(), Failure> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let in_out_dir = fair_cmd::same_path(dir, out_dir)
        || matches!(
            (fs::canonicalize(dir), fs::canonicalize(out_dir)),
            (Ok(a), Ok(b)) if a == b
        );
    if path.is_dir() || !in_out_dir {
        fair_cmd::check_writable(path)?;
    }
    if let Ok(real) = fs::canonicalize(path) {
        for job in jobs {
            if fs::canonicalize(&job.input).is_ok_and(|i| i == real) {
                return Err(Failure::usage(IoError::SameFile {
                    input: job.input.clone(),
                    output: path.to_path_buf(),
                }));
            }
        }
    }
    if in_out_dir && let Some(name) = path.file_name() {
        let key = name.to_string_lossy().to_ascii_lowercase();
        let clash = jobs.iter().find(|j| {
            [&j.output, &j.report].iter().any(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase() == key)
            })
        });
        if let Some(job) = clash {
            return Err(Failure::usage(anyhow!(
                "--summary {} would replace a result of {}",
                path.display(),
                job.input.display()
            )));
        }
    }
    Ok(())
}

/// Create the output directory (and its parents) and check that a file can be written in it,
/// and that the summary can be written once the directory exists. On failure, every
/// directory this created is removed again: a usage error leaves nothing behind.
///
/// # Errors
/// [`Failure::usage`] (exit 2) naming the directory or the summary.
pub(super) fn create_out_dir(out_dir: &Path, summary: Option<&Path>) -> Result<(), Failure> {
    // The first missing ancestor: what to remove if a check fails.
    let mut created = None;
    let mut p = out_dir;
    while !p.as_os_str().is_empty() && !p.exists() {
        created = Some(p.to_path_buf());
        p = p.parent().unwrap_or(Path::new(""));
    }
    let checked = fs::create_dir_all(out_dir)
        .map_err(|e| {
            Failure::usage(anyhow!(
                "{}: cannot write: cannot create the directory: {e}",
                out_dir.display()
            ))
        })
        .and_then(|()| {
            fair_cmd::check_writable(&out_dir.join("probe.json")).map_err(|_| {
                Failure::usage(anyhow!(
                    "{}: cannot write: no file can be created in the directory",
                    out_dir.display()
                ))
            })
        })
        .and_then(|()| summary.map_or(Ok(()), fair_cmd::check_writable));
    if checked.is_err()
        && let Some(top) = created
    {
        // Best effort: only directories this run created, and only when still empty.
        let mut d = out_dir.to_path_buf();
        while fs::remove_dir(&d).is_ok() && d != top {
            if !d.pop() {
                break;
            }
        }
    }
    checked
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards() {
        for (p, n) in [
            ("*.csv", "a.csv"),
            ("*.csv", ".csv"),
            ("frame-??.csv", "frame-07.csv"),
            ("*", ""),
            ("a*b*c", "aXbYbZc"),
            ("**x", "x"),
            ("é?.json", "éz.json"),
        ] {
            assert!(wildcard_match(p, n), "{p} should match {n}");
        }
        for (p, n) in [
            ("*.csv", "a.csv.bak"),
            ("frame-??.csv", "frame-7.csv"),
            ("a*b*c", "aXbYbZ"),
            ("?", ""),
            ("x", "xx"),
        ] {
            assert!(!wildcard_match(p, n), "{p} should not match {n}");
        }
        // Backtracking on the last star stays linear.
        let long = "a".repeat(10_000);
        assert!(!wildcard_match("*a*a*a*b", &long));
    }

    #[test]
    fn output_names_may_not_collide() {
        let out = Path::new("out");
        let jobs = plan(&[PathBuf::from("a/x.csv"), PathBuf::from("b/y.json")], out);
        let jobs = jobs.map_err(|f| f.error.to_string());
        assert!(jobs.is_ok(), "{jobs:?}");
        let err = |inputs: &[&str]| {
            let v: Vec<PathBuf> = inputs.iter().map(PathBuf::from).collect();
            plan(&v, out).err().map(|f| f.error.to_string())
        };
        assert_eq!(
            err(&["a/x.csv", "b/X.CSV"]).as_deref(),
            Some(
                format!(
                    "a/x.csv and b/X.CSV would both write {}",
                    out.join("X.CSV").display()
                )
                .as_str()
            )
        );
        assert!(err(&["x.csv", "x.json"]).is_some_and(|e| e.ends_with("x.report.json")));
        assert!(err(&["x.csv", "x.report.json"]).is_some());
        assert_eq!(
            err(&["d/x.csv", "d/x.csv"]).as_deref(),
            Some("d/x.csv is given more than once")
        );
        assert_eq!(err(&[".."]).as_deref(), Some("..: not a file name"));
    }
}
