//! What the subcommands share: reading the input, building options, checking methods.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::anyhow;
use batten::FairOptions;
use batten::fair::{self, EndFix, FairMethod};
use batten::io::{self, PointData, Source, SpaceData};
use clap::Args;

use crate::failure::Failure;
use crate::formats::{self, PickArgs};

/// Read and validate the input points (any format by extension, `-` for standard input as
/// CSV); every problem is a usage error (exit 2) naming the file and line.
///
/// # Errors
/// [`Failure::usage`] with the [`io::IoError`] message.
pub fn read(path: &Path, closed: bool) -> Result<PointData, Failure> {
    read_picked(path, closed, &PickArgs::default())
}

/// [`read`], with `--format` and the flags that pick one curve of a DXF, IGES or SVG file.
///
/// # Errors
/// [`Failure::usage`]: the file's problem, a flag for another format, or a B-spline (which
/// the command does not take).
pub fn read_picked(path: &Path, closed: bool, pick: &PickArgs) -> Result<PointData, Failure> {
    match read_points_any(path, closed, pick)? {
        Points::Planar(d) => Ok(d),
        Points::Space(_) => Err(space_not_planar(path)),
    }
}

/// What a point file holds: a planar curve or a space curve.
#[derive(Debug)]
pub enum Points {
    /// `x, y` points.
    Planar(PointData),
    /// `x, y, z` points.
    Space(SpaceData),
}

/// [`read_picked`] for the commands that take space curves too (`analyze`, `fair`, `plot`,
/// `batch`).
///
/// # Errors
/// As [`read_picked`].
pub fn read_points_any(path: &Path, closed: bool, pick: &PickArgs) -> Result<Points, Failure> {
    let format = formats::format_of(path, pick.format)?;
    let name = formats::display_name(path);
    pick.check(format, &name.display().to_string())?;
    match formats::read_input(path, format, closed, &pick.pick())?.source {
        Source::Points(d) => Ok(Points::Planar(d)),
        Source::Space(d) => Ok(Points::Space(d)),
        Source::Curve(_) => Err(Failure::usage(io::IoError::CurveNotPoints { path: name })),
    }
}

/// The usage error for a space curve given to a command that takes planar curves.
pub fn space_not_planar(path: &Path) -> Failure {
    Failure::usage(anyhow!(
        "{}; 3-D curves are taken by analyze, plot, and fair and batch with --method band or mst",
        io::IoError::SpaceNotPlanar {
            path: formats::display_name(path)
        }
    ))
}

/// Parse `--set KEY=VALUE` arguments. Keys and values are trimmed; the key must be
/// non-empty and given once.
///
/// # Errors
/// [`Failure::usage`] naming the malformed or repeated argument.
pub fn parse_sets(sets: &[String]) -> Result<BTreeMap<String, String>, Failure> {
    let mut params = BTreeMap::new();
    for s in sets {
        let Some((k, v)) = s.split_once('=') else {
            return Err(Failure::usage(anyhow!(
                "malformed --set '{}': expected KEY=VALUE",
                s.escape_debug()
            )));
        };
        let (k, v) = (k.trim(), v.trim());
        if k.is_empty() {
            return Err(Failure::usage(anyhow!(
                "malformed --set '{}': the key is empty",
                s.escape_debug()
            )));
        }
        if params.insert(k.to_string(), v.to_string()).is_some() {
            return Err(Failure::usage(anyhow!("--set {k} is given more than once")));
        }
    }
    Ok(params)
}

/// Look a method up.
///
/// # Errors
/// [`Failure::usage`] with the library's "unknown method" message listing the known ones.
pub fn method(name: &str) -> Result<&'static dyn FairMethod, Failure> {
    fair::method(name).map_err(|e| Failure::from_batten("", e))
}

/// Check the options against the method (unknown keys, tolerance, closed support).
///
/// # Errors
/// [`Failure::usage`].
pub fn check(m: &dyn FairMethod, closed: bool, options: &FairOptions) -> Result<(), Failure> {
    fair::check_options(m, closed, options).map_err(|e| Failure::from_batten("", e))
}

/// `--fix-ends=WHAT` (clap value parser).
///
/// # Errors
/// A message naming the accepted values.
pub fn parse_end_fix(s: &str) -> Result<EndFix, String> {
    s.parse::<EndFix>()
        .map_err(|_| format!("'{s}' is not one of position, tangent, curvature (or free)"))
}

/// The value of `--tolerance`: a distance in data units, or `auto` (`k·σ̂` from the data).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// A distance in data units.
    Given(f64),
    /// `k·σ̂`, from the noise estimate of the input.
    Auto,
}

/// `--tolerance D|auto` (clap value parser). Negative and non-finite values are refused
/// here, with the flag named.
///
/// # Errors
/// A message naming what the flag accepts.
pub fn parse_tolerance(s: &str) -> Result<Tolerance, String> {
    if s.trim() == "auto" {
        return Ok(Tolerance::Auto);
    }
    let what = match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => return Ok(Tolerance::Given(v)),
        Ok(v) if v < 0.0 => "is negative",
        Ok(0.0) => "is zero",
        Ok(_) => "is not finite",
        Err(_) => "is not a number",
    };
    Err(format!(
        "'{s}' {what}: give a positive distance in data units or 'auto'"
    ))
}

/// `--max-iterations N` (clap value parser): a whole number from 1 to
/// [`fair::MAX_ITERATIONS`].
///
/// # Errors
/// A message naming the accepted range.
pub fn parse_max_iterations(s: &str) -> Result<usize, String> {
    parse_count(s, fair::MAX_ITERATIONS)
}

/// A whole number from 1 to `max`.
///
/// # Errors
/// A message naming the accepted range.
pub fn parse_count(s: &str, max: usize) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("'{s}' is not a whole number from 1 to {max}")),
    }
}

/// Options from the common flags.
pub fn options(
    tolerance: Option<Tolerance>,
    fix_ends: EndFix,
    max_iterations: Option<usize>,
    params: BTreeMap<String, String>,
) -> FairOptions {
    let mut o = FairOptions::default().with_end_fix(fix_ends);
    match tolerance {
        Some(Tolerance::Given(d)) => o.tolerance = Some(d),
        Some(Tolerance::Auto) => o = o.with_auto_tolerance(),
        None => {}
    }
    o.max_iterations = max_iterations;
    o.params = params;
    o
}

/// The method `how` names (or the default) and the options of `how` and `bounds`, checked
/// against each other for a curve that is `closed` or not (`fair` and `batch`).
///
/// # Errors
/// [`Failure::usage`]: an unknown method, a malformed or unknown `--set`, an option the
/// method does not take.
pub fn method_options(
    how: &MethodArgs,
    bounds: &BoundArgs,
    closed: bool,
) -> Result<(&'static dyn FairMethod, FairOptions), Failure> {
    let name = how
        .method
        .as_deref()
        .unwrap_or_else(|| fair::default_method());
    let method = method(name)?;
    let params = parse_sets(&how.set)?;
    let options = options(
        bounds.tolerance,
        bounds.fix_ends.unwrap_or_default(),
        how.max_iterations,
        params,
    );
    check(method, closed, &options)?;
    Ok((method, options))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn sets(v: &[&str]) -> Result<BTreeMap<String, String>, String> {
        let owned: Vec<String> = v.iter().map(|s| s.to_string()).collect();
        parse_sets(&owned).map_err(|f| f.error.to_string())
    }

    #[test]
    fn set_arguments() {
        let p = sets(&["p=0.5", " lambda = 2 "]).unwrap();
        assert_eq!(p.get("p").map(String::as_str), Some("0.5"));
        assert_eq!(p.get("lambda").map(String::as_str), Some("2"));
        assert_eq!(
            sets(&["a=b=c"]).unwrap().get("a").map(String::as_str),
            Some("b=c")
        );
        assert_eq!(
            sets(&["p"]).unwrap_err(),
            "malformed --set 'p': expected KEY=VALUE"
        );
        assert_eq!(
            sets(&["=3"]).unwrap_err(),
            "malformed --set '=3': the key is empty"
        );
        assert_eq!(
            sets(&["p=1", "p=2"]).unwrap_err(),
            "--set p is given more than once"
        );
        assert_eq!(
            sets(&["a\nb"]).unwrap_err(),
            "malformed --set 'a\\nb': expected KEY=VALUE"
        );
    }
}

/// The bounds every fairing command takes: the tolerance and what to keep at the ends.
#[derive(Debug, Args)]
pub struct BoundArgs {
    /// Largest distance any point may move, in data units, or `auto`: k times the noise
    /// estimate σ̂ of the input (k = 3; `band`'s default, with k = max(3, √(2 ln n))); points
    /// in which `auto` finds no noise are left as they are
    #[arg(long, value_name = "D|auto", allow_hyphen_values = true, value_parser = parse_tolerance)]
    pub tolerance: Option<Tolerance>,
    /// Keep the ends of an open curve: the end points (bare `--fix-ends`, or `=position`),
    /// also the end tangents (`=tangent`) or also the end curvatures (`=curvature`)
    #[arg(long, value_name = "WHAT", num_args = 0..=1, require_equals = true,
          default_missing_value = "position", value_parser = parse_end_fix)]
    pub fix_ends: Option<EndFix>,
}

/// The method and its settings, for `fair` and `batch`.
#[derive(Debug, Args)]
pub struct MethodArgs {
    /// Fairing method (see `batten methods`) [default: the first listed there]
    #[arg(long, value_name = "NAME")]
    pub method: Option<String>,
    /// Upper bound on the method's iterations (its own unit: sweeps, moves or passes), 1 to
    /// 1000000
    #[arg(long, value_name = "N", value_parser = parse_max_iterations)]
    pub max_iterations: Option<usize>,
    /// A method parameter, KEY=VALUE (repeat for several; see `batten methods`)
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}
