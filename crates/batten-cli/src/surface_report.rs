//! `batten report` on a B-spline surface: one self-contained HTML page with the input's
//! analysis, a table of the surface methods' results, and for each method the curvature
//! map, isophotes, zebra and deviation before and after (PNG images inlined as `data:` URIs;
//! no scripts, fonts or other resources to fetch).

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::io;
use batten::surface::{
    BSplineSurface, MinMax, SurfaceAnalysis, SurfaceFairOptions, SurfaceFairReport, SurfaceMethod,
    analyze_surface, fair_surface,
};

use crate::failure::{EXIT_FAILED, Failure};
use crate::figure::base64;
use crate::input::Tolerance;
use crate::output::{self, sig};
use crate::plot::check_output;
use crate::surface_plot::{SurfaceKind, Views, figure};

/// Significant digits of the tables.
const DIGITS: usize = 4;

/// Panel size on the page: two panels and a colour bar fit a 1200-pixel window.
const PANEL: [usize; 2] = [500, 360];

/// The views of each method's section.
const METHOD_VIEWS: [SurfaceKind; 4] = [
    SurfaceKind::Mean,
    SurfaceKind::Isophotes,
    SurfaceKind::Zebra,
    SurfaceKind::Deviation,
];

/// The views of the input's section.
const INPUT_VIEWS: [SurfaceKind; 3] = [
    SurfaceKind::Gaussian,
    SurfaceKind::Mean,
    SurfaceKind::Isophotes,
];

const CSS: &str = "\
body{font-family:sans-serif;color:#222;margin:24px auto;max-width:1180px;padding:0 12px}\
h1{font-size:24px;margin-bottom:4px}h2{font-size:19px;margin-top:32px;border-bottom:1px solid #ddd}\
p.meta{color:#555;margin-top:0}\
table{border-collapse:collapse;margin:8px 0}\
th,td{border:1px solid #ccc;padding:3px 9px;font-size:14px}\
th{background:#f3f3f3}td.r{text-align:right}\
img{max-width:100%;height:auto;border:1px solid #ddd}p.note{color:#8a1c10}";

/// Whether `path` holds a surface: a `.json` file whose top-level object has a surface key
/// (`degree_u` or `grid`). Anything unreadable is left to the curve reader to report.
pub fn is_surface_file(path: &Path) -> bool {
    let is_json = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if !is_json {
        return false;
    }
    let Ok(bytes) = std::fs::read(path) else {
        return false;
    };
    match serde_json::from_slice::<serde_json::Value>(&bytes) {
        Ok(serde_json::Value::Object(m)) => m.contains_key("degree_u") || m.contains_key("grid"),
        _ => false,
    }
}

/// What `batten report` passes on for a surface.
#[derive(Debug)]
pub struct SurfaceReportArgs<'a> {
    pub input: &'a Path,
    pub output: &'a Path,
    pub methods: &'a [String],
    pub tolerance: Option<Tolerance>,
    /// `--fix-ends` or `--closed` was given: options for curves.
    pub curve_options: bool,
}

/// Write the report page of a surface.
///
/// # Errors
/// Usage errors (exit 2, nothing written); a failed write (exit 1). A method that fails or
/// misses the tolerance is shown on the page and makes the exit code 1.
pub fn run(args: &SurfaceReportArgs) -> Result<ExitCode, Failure> {
    let name = args.input.display().to_string();
    if args.curve_options {
        return Err(Failure::usage(anyhow!(
            "{name}: a surface: --fix-ends and --closed are for curves"
        )));
    }
    let tolerance = match args.tolerance {
        None => None,
        Some(Tolerance::Given(d)) => Some(d),
        Some(Tolerance::Auto) => {
            return Err(Failure::usage(anyhow!(
                "{name}: a surface: --tolerance auto is for curves; give a distance"
            )));
        }
    };
    let methods: Vec<SurfaceMethod> = if args.methods.is_empty() {
        SurfaceMethod::ALL.to_vec()
    } else {
        args.methods
            .iter()
            .map(|m| SurfaceMethod::from_name(m).map_err(|e| Failure::from_batten("", e)))
            .collect::<Result<_, _>>()?
    };
    check_output(args.output, &["html", "htm"], &[args.input])?;
    let s = io::read_surface_json(args.input).map_err(Failure::usage)?;
    let before = analyze_surface(&s);
    let views = Views {
        width: PANEL[0],
        height: PANEL[1],
        ..Views::DEFAULT
    };
    let mut runs = Vec::new();
    for &m in &methods {
        let mut o = SurfaceFairOptions::default().with_method(m);
        o.tolerance = tolerance;
        runs.push((m, fair_surface(&s, &o)));
    }
    let page = page(&name, &s, &before, &runs, &views)?;
    io::write_atomic(args.output, page.as_bytes()).map_err(Failure::failed)?;
    let mut failed = false;
    for (m, run) in &runs {
        match run {
            Err(e) => {
                output::error_line(&format!("{name}: method {} failed: {e}", m.name()));
                failed = true;
            }
            Ok((_, r)) if !r.tolerance_met => {
                output::error_line(&format!(
                    "{name}: method {}: tolerance {} not met (max displacement {})",
                    m.name(),
                    sig(r.tolerance, DIGITS),
                    sig(r.max_displacement, DIGITS)
                ));
                failed = true;
            }
            Ok(_) => {}
        }
    }
    Ok(if failed {
        ExitCode::from(EXIT_FAILED)
    } else {
        ExitCode::SUCCESS
    })
}

type Run = (
    SurfaceMethod,
    batten::Result<(BSplineSurface, SurfaceFairReport)>,
);

fn esc(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn range(m: Option<MinMax>) -> String {
    m.map_or_else(
        || "–".into(),
        |m| format!("{} … {}", sig(m.min, DIGITS), sig(m.max, DIGITS)),
    )
}

/// An `<img>` of the views of `kinds`.
fn image(
    name: &str,
    before: &BSplineSurface,
    after: Option<&BSplineSurface>,
    kinds: &[SurfaceKind],
    views: &Views,
    alt: &str,
) -> Result<String, Failure> {
    let png = figure(name, before, after, kinds, views)?
        .png()
        .map_err(|e| Failure::failed(e.context(format!("{name}: cannot encode a picture"))))?;
    Ok(format!(
        "<p><img alt=\"{}\" src=\"data:image/png;base64,{}\"></p>\n",
        esc(alt),
        base64(&png)
    ))
}

/// The page: the input's metrics and views, the table of the methods' results, and a
/// section per method.
fn page(
    name: &str,
    s: &BSplineSurface,
    a: &SurfaceAnalysis,
    runs: &[Run],
    views: &Views,
) -> Result<String, Failure> {
    let mut h = String::with_capacity(1 << 20);
    let title = format!("batten report: {name}");
    // Writing to a String cannot fail.
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{t}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<h1>{t}</h1>\n",
        t = esc(&title)
    );
    let _ = writeln!(
        h,
        "<p class=\"meta\">B-spline surface of degree {}×{}, {}×{} control points{}; \
         measured on {}×{} samples; made by batten {}.</p>",
        a.degree_u,
        a.degree_v,
        a.control_points[0],
        a.control_points[1],
        if s.weights().is_some() {
            " (rational)"
        } else {
            ""
        },
        a.samples[0],
        a.samples[1],
        env!("CARGO_PKG_VERSION")
    );
    input_section(&mut h, name, s, a, views)?;
    comparison_table(&mut h, runs);
    method_sections(&mut h, name, s, runs, views)?;
    h.push_str("</body>\n</html>\n");
    Ok(h)
}

/// The input's section: its metrics and the views of [`INPUT_VIEWS`].
fn input_section(
    h: &mut String,
    name: &str,
    s: &BSplineSurface,
    a: &SurfaceAnalysis,
    views: &Views,
) -> Result<(), Failure> {
    h.push_str("<h2>Input</h2>\n<table class=\"metrics\">\n");
    for (k, v) in [
        ("κ1", range(a.kappa1)),
        ("κ2", range(a.kappa2)),
        ("Gaussian K", range(a.gaussian)),
        ("mean H", range(a.mean)),
        ("umbilic fraction", sig(a.umbilic_fraction, DIGITS)),
        ("fairness measure Π̂", sig(a.fairness_measure, DIGITS)),
    ] {
        let _ = writeln!(h, "<tr><th>{k}</th><td class=\"r\">{v}</td></tr>");
    }
    h.push_str("</table>\n");
    h.push_str(&image(
        name,
        s,
        None,
        &INPUT_VIEWS,
        views,
        "the input's Gaussian and mean curvature and isophotes",
    )?);
    Ok(())
}

/// The table of the methods' results, a row each (or the reason it failed).
fn comparison_table(h: &mut String, runs: &[Run]) {
    h.push_str(
        "<h2>Comparison</h2>\n<table class=\"compare\">\n<tr><th>method</th>\
                <th>Π̂ after</th><th>κ1 after</th><th>κ2 after</th><th>moves</th>\
                <th>max displacement</th><th>tolerance</th><th>time</th></tr>\n",
    );
    for (m, run) in runs {
        match run {
            Ok((_, r)) => {
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td class=\"r\">{}</td><td class=\"r\">{}</td>\
                     <td class=\"r\">{}</td><td class=\"r\">{}</td><td class=\"r\">{}</td>\
                     <td class=\"r\">{} ({})</td><td class=\"r\">{}</td></tr>",
                    m.name(),
                    sig(r.after.pi_hat, DIGITS),
                    range(r.after.kappa1),
                    range(r.after.kappa2),
                    r.moves,
                    sig(r.max_displacement, DIGITS),
                    sig(r.tolerance, DIGITS),
                    if r.tolerance_met { "met" } else { "NOT met" },
                    output::seconds(r.time_s)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td colspan=\"7\">failed: {}</td></tr>",
                    m.name(),
                    esc(&e.to_string())
                );
            }
        }
    }
    h.push_str("</table>\n");
}

/// A section per method: what it did, and the views of [`METHOD_VIEWS`] before and after.
fn method_sections(
    h: &mut String,
    name: &str,
    s: &BSplineSurface,
    runs: &[Run],
    views: &Views,
) -> Result<(), Failure> {
    for (m, run) in runs {
        let _ = writeln!(h, "<h2>{}</h2>", m.name());
        match run {
            Ok((faired, r)) => {
                let _ = writeln!(
                    h,
                    "<p>{} moves of {} control points; Π̂ {} → {}; largest control-point \
                     move {}.</p>",
                    r.moves,
                    r.moved_points,
                    sig(r.before.pi_hat, DIGITS),
                    sig(r.after.pi_hat, DIGITS),
                    sig(r.max_control_point_move, DIGITS)
                );
                h.push_str(&image(
                    name,
                    s,
                    Some(faired),
                    &METHOD_VIEWS,
                    views,
                    &format!("{}: before and after", m.name()),
                )?);
            }
            Err(e) => {
                let _ = writeln!(h, "<p class=\"note\">failed: {}</p>", esc(&e.to_string()));
            }
        }
    }
    Ok(())
}
