//! [`Failure`]: an error and the exit code it maps to.

use std::process::ExitCode;

use anyhow::anyhow;

/// Exit code of a fairing that failed or missed its tolerance, or of a failed write.
pub const EXIT_FAILED: u8 = 1;
/// Exit code of bad input or usage.
pub const EXIT_USAGE: u8 = 2;

/// Why a command stopped. Its message is printed as one line on stderr, so it must be
/// complete at the top level: no `context` chains.
#[derive(Debug)]
pub struct Failure {
    code: u8,
    /// What went wrong.
    pub error: anyhow::Error,
}

impl Failure {
    /// Bad input or usage: exit 2.
    pub fn usage(error: impl Into<anyhow::Error>) -> Failure {
        Failure {
            code: EXIT_USAGE,
            error: error.into(),
        }
    }

    /// A computation or write that failed: exit 1.
    pub fn failed(error: impl Into<anyhow::Error>) -> Failure {
        Failure {
            code: EXIT_FAILED,
            error: error.into(),
        }
    }

    /// A library error, prefixed with `what` (e.g. `data.csv: method mst failed`). Errors
    /// about the request (unknown method or option, a bad parameter value, a closed curve
    /// for a method that takes none, input the geometry code rejects) exit 2; errors of the
    /// computation itself exit 1.
    pub fn from_batten(what: &str, e: batten::Error) -> Failure {
        use batten::Error as E;
        let usage = matches!(
            e,
            E::UnknownMethod { .. }
                | E::UnknownOption { .. }
                | E::InvalidParameter { .. }
                | E::ClosedUnsupported { .. }
                | E::PlanarOnly { .. }
                | E::TooFewPoints { .. }
                | E::NonFinite { .. }
                | E::DuplicatePoint { .. }
        );
        let error = if what.is_empty() {
            anyhow!("{e}")
        } else {
            anyhow!("{what}: {e}")
        };
        Failure {
            code: if usage { EXIT_USAGE } else { EXIT_FAILED },
            error,
        }
    }

    /// The process exit code.
    pub fn exit_code(&self) -> ExitCode {
        ExitCode::from(self.code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_errors_map_to_exit_codes() {
        let f = Failure::from_batten(
            "",
            batten::Error::UnknownMethod {
                name: "x".into(),
                known: "mst".into(),
            },
        );
        assert_eq!(f.code, EXIT_USAGE);
        assert_eq!(f.error.to_string(), "unknown method 'x' (known: mst)");
        let f = Failure::from_batten(
            "a.csv: method m failed",
            batten::Error::Singular("s".into()),
        );
        assert_eq!(f.code, EXIT_FAILED);
        assert_eq!(
            f.error.to_string(),
            "a.csv: method m failed: singular system: s"
        );
    }
}
