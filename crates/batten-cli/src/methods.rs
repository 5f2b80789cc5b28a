//! `batten methods`: the registry, for people, or as JSON for programs (`--json`: the
//! library's [`fair::catalogue`], which the Python package's `batten.methods()` returns too).

use std::fmt::Write as _;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::fair::{self, FairMethod};
use clap::Args;

use crate::failure::Failure;
use crate::output;

/// Arguments of `batten methods`.
#[derive(Debug, Args)]
pub struct MethodsArgs {
    /// Print a JSON array (name, summary, closed_curves, bspline_input, parameters with name,
    /// type, default and doc), the default method first
    #[arg(long)]
    json: bool,
}

/// Run `batten methods`.
///
/// # Errors
/// Only a failed write to stdout.
pub fn run(args: &MethodsArgs) -> Result<ExitCode, Failure> {
    let text = if args.json {
        let mut s = crate::json::pretty(&fair::catalogue())
            .map_err(|e| Failure::failed(anyhow!("cannot encode the methods: {e}")))?;
        s.push('\n');
        s
    } else {
        listing(fair::methods(), fair::default_method())
    };
    output::stdout(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// One block per method: name (and whether it is the default), description, closed-curve
/// support, parameters with default and doc.
fn listing(methods: &[&dyn FairMethod], default: &str) -> String {
    let mut s = String::new();
    for (i, m) in methods.iter().enumerate() {
        if i > 0 {
            s.push('\n');
        }
        let tag = if m.name() == default {
            " (default)"
        } else {
            ""
        };
        // Writing to a String cannot fail.
        let _ = writeln!(s, "{}{tag}", m.name());
        let _ = writeln!(s, "  {}", m.description());
        let closed = if m.supports_closed() { "yes" } else { "no" };
        let _ = writeln!(s, "  closed curves: {closed}");
        let params = m.parameters();
        if params.is_empty() {
            s.push_str("  parameters: none\n");
            continue;
        }
        s.push_str("  parameters (--set KEY=VALUE):\n");
        let pairs: Vec<String> = params
            .iter()
            .map(|p| format!("{}={}", p.name, p.default))
            .collect();
        let width = pairs.iter().map(String::len).max().unwrap_or(0);
        for (kv, p) in pairs.iter().zip(params) {
            let _ = writeln!(s, "    {kv:<width$}  {}", p.doc);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_every_registered_method_with_its_parameters() {
        let text = listing(fair::methods(), fair::default_method());
        for m in fair::methods() {
            assert!(text.contains(m.name()), "{text}");
            for p in m.parameters() {
                assert!(
                    text.contains(&format!("{}={}", p.name, p.default)),
                    "{text}"
                );
            }
        }
        assert!(text.contains(&format!("{} (default)", fair::default_method())));
    }
}
