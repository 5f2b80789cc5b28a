//! Writing to stdout and stderr, and formatting numbers for people.

use std::io::{ErrorKind, Write as _};

use anyhow::anyhow;

use crate::failure::Failure;

/// Write `text` to stdout. A closed pipe is not an error (the reader has what it wanted).
///
/// # Errors
/// Any other write error, as a [`Failure::failed`].
pub fn stdout(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure::failed(anyhow!(
            "cannot write to standard output: {e}"
        ))),
    }
}

/// Write one line to stderr. There is nowhere to report a failure to write stderr.
pub fn note(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Write an error line to stderr: `error: MESSAGE`.
pub fn error_line(message: &str) {
    note(&format!("error: {message}"));
}

/// `x` with `digits` significant digits (the library's, so that the notes it writes read
/// like the CLI's tables).
pub use batten::io::format_sig as sig;

/// A count and its noun, singular for one: `count(1, "file")` is `1 file`, `count(2, "file")`
/// is `2 files`.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A duration in seconds, in the unit that suits it (`412 µs`, `12.3 ms`, `1.25 s`).
pub fn seconds(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.0} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts() {
        assert_eq!(count(0, "file"), "0 files");
        assert_eq!(count(1, "iteration"), "1 iteration");
        assert_eq!(count(12, "point"), "12 points");
    }

    #[test]
    fn durations() {
        assert_eq!(seconds(0.000412), "412 µs");
        assert_eq!(seconds(0.0123), "12.3 ms");
        assert_eq!(seconds(1.25), "1.25 s");
    }
}
