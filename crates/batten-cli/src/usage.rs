//! clap's usage errors as one line: `error: invalid value 'foo' for --kind: expected one of
//! comb, curvature, ...`. clap's own rendering takes three to seven lines (the error, a usage
//! line, "For more information, try '--help'"); batten's contract is one line naming the flag
//! and what it accepts, as for every other error. Help and version requests are not errors and
//! print in full.

use std::error::Error as _;

use clap::error::{ContextKind, ContextValue, ErrorKind};

/// What to do with a clap error: print help or version as clap does, or one usage line.
pub enum ClapOutcome {
    /// `--help`, `--version`, or a bare `batten`: clap prints and exits itself.
    Print(clap::Error),
    /// A usage error: print this message as `error: MESSAGE`, exit 2.
    Usage(String),
}

/// Classify a clap error; `argv` (the process arguments) lets the message say what was meant
/// where clap only sees a stray word (`--fix-ends tangent`, where `=` is required).
pub fn classify(e: clap::Error, argv: &[String]) -> ClapOutcome {
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => ClapOutcome::Print(e),
        _ => ClapOutcome::Usage(one_line(&e, argv)),
    }
}

/// A context value as text; lists joined with ", ".
fn text(e: &clap::Error, kind: ContextKind) -> Option<String> {
    match e.get(kind)? {
        ContextValue::String(s) => Some(s.clone()),
        ContextValue::Strings(v) => Some(v.join(", ")),
        ContextValue::StyledStr(s) => Some(s.to_string()),
        ContextValue::StyledStrs(v) => Some(
            v.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", "),
        ),
        ContextValue::Number(n) => Some(n.to_string()),
        ContextValue::Bool(b) => Some(b.to_string()),
        _ => None,
    }
}

/// The flag of an `--name <VALUE>` context, without the value placeholder.
fn flag(arg: &str) -> &str {
    arg.split_once(' ').map_or(arg, |(f, _)| f)
}

/// The one-line message of a usage error.
fn one_line(e: &clap::Error, argv: &[String]) -> String {
    let arg = text(e, ContextKind::InvalidArg).unwrap_or_default();
    let value = text(e, ContextKind::InvalidValue).unwrap_or_default();
    let suggestion = text(e, ContextKind::SuggestedArg)
        .or_else(|| text(e, ContextKind::SuggestedSubcommand))
        .map(|s| format!(" (did you mean '{s}'?)"))
        .unwrap_or_default();
    match e.kind() {
        ErrorKind::InvalidValue if value.is_empty() => {
            format!("{} needs a value", flag(&arg))
        }
        ErrorKind::InvalidValue => match text(e, ContextKind::ValidValue) {
            Some(valid) => format!(
                "invalid value '{value}' for {}: expected one of {valid}",
                flag(&arg)
            ),
            None => format!("invalid value '{value}' for {}", flag(&arg)),
        },
        ErrorKind::ValueValidation => {
            let why = e.source().map(ToString::to_string).unwrap_or_default();
            format!("invalid value '{value}' for {}: {why}", flag(&arg))
        }
        ErrorKind::UnknownArgument => match flag_before(&arg, argv) {
            Some("--fix-ends") => format!(
                "unexpected argument '{arg}': --fix-ends takes its value after '=', as in \
                 --fix-ends={arg}"
            ),
            _ => format!("unexpected argument '{arg}'{suggestion}"),
        },
        ErrorKind::InvalidSubcommand => format!(
            "unknown command '{}'{suggestion} (commands: analyze, fair, methods, compare, \
             plot, report, batch, evaluate)",
            text(e, ContextKind::InvalidSubcommand).unwrap_or_default()
        ),
        ErrorKind::MissingRequiredArgument => format!("missing {arg}"),
        ErrorKind::MissingSubcommand => "missing a command (see batten --help)".to_string(),
        ErrorKind::ArgumentConflict => {
            let other = text(e, ContextKind::PriorArg).unwrap_or_default();
            format!("{} cannot be used with {}", flag(&arg), flag(&other))
        }
        ErrorKind::NoEquals => format!(
            "{} takes its value after '=' (as in {}=VALUE)",
            flag(&arg),
            flag(&arg)
        ),
        _ => fallback(e),
    }
}

/// The argument before `word` in `argv`, when it is a flag.
fn flag_before<'a>(word: &str, argv: &'a [String]) -> Option<&'a str> {
    let i = argv.iter().position(|a| a == word)?;
    let prev = argv.get(i.checked_sub(1)?)?;
    prev.starts_with("--").then_some(prev.as_str())
}

/// The first line of clap's own message, without its `error: ` prefix.
fn fallback(e: &clap::Error) -> String {
    let rendered = e.render().to_string();
    let first = rendered.lines().next().unwrap_or("invalid arguments");
    first.strip_prefix("error: ").unwrap_or(first).to_string()
}

#[cfg(test)]
mod tests {
    use clap::Parser as _;

    use super::*;
    use crate::Cli;

    fn message(args: &[&str]) -> String {
        let argv: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        match Cli::try_parse_from(&argv) {
            Ok(_) => panic!("{args:?} parsed"),
            Err(e) => match classify(e, &argv) {
                ClapOutcome::Usage(m) => m,
                ClapOutcome::Print(_) => panic!("{args:?} printed help"),
            },
        }
    }

    #[test]
    fn messages_name_the_flag_and_what_it_accepts() {
        assert_eq!(
            message(&[
                "batten",
                "fair",
                "a.csv",
                "-o",
                "b.csv",
                "--tolerance",
                "-0.1"
            ]),
            "invalid value '-0.1' for --tolerance: '-0.1' is negative: give a positive \
             distance in data units or 'auto'"
        );
        assert_eq!(
            message(&["batten", "plot", "a.csv", "-o", "b.svg", "--kind", "foo"]),
            "invalid value 'foo' for --kind: expected one of comb, curvature, radius, xc, \
             displacement, all"
        );
        assert_eq!(
            message(&[
                "batten",
                "fair",
                "a.csv",
                "-o",
                "b.csv",
                "--fix-ends",
                "tangent"
            ]),
            "unexpected argument 'tangent': --fix-ends takes its value after '=', as in \
             --fix-ends=tangent"
        );
        assert_eq!(
            message(&["batten", "batch", "a.csv", "-o", "out", "--jobs", "0"]),
            "invalid value '0' for --jobs: '0' is not a whole number from 1 to 1024"
        );
        assert_eq!(
            message(&["batten", "fair", "a.csv"]),
            "missing --output <OUTPUT>"
        );
        let m = message(&["batten", "fiar"]);
        assert!(
            m.starts_with("unknown command 'fiar' (did you mean 'fair'?)"),
            "{m}"
        );
        for m in [
            message(&["batten", "fair", "a.csv", "-o", "b.csv", "--bogus"]),
            message(&["batten", "fair", "a.csv", "-o", "b.csv", "--closed=3"]),
            message(&["batten", "fair", "a.csv", "-o", "b.csv", "--method"]),
            message(&["batten", "fair", "a.csv", "-o", "b.csv", "-o", "c.csv"]),
        ] {
            assert_eq!(m.lines().count(), 1, "{m}");
            assert!(!m.is_empty());
        }
    }
}
