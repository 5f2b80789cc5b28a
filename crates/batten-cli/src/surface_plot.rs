//! `batten plot-surface`: curvature colour maps, isophotes, zebra stripes and the deviation
//! map of a B-spline surface, before and after fairing side by side at the same scale, as
//! PNG or SVG.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use batten::io;
use batten::surface::{
    BSplineSurface, Camera, Field, Palette, SampleGrid, Shading, SurfaceMesh, Xyz, isophote_range,
    render, zebra_range,
};
use clap::{Args, ValueEnum};

use crate::failure::Failure;
use crate::figure::{Bar, Figure, Row};
use crate::plot::check_output;

/// Free pixels around the surface inside a panel.
const PANEL_MARGIN: usize = 12;
/// Smallest and largest panel side, in pixels (a 2048-pixel panel takes about 200 MB of
/// depth buffer while it is drawn).
const PANEL_SIZES: std::ops::RangeInclusive<usize> = 64..=2048;

/// What `batten plot-surface` draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SurfaceKind {
    /// Gaussian curvature K = kappa1 kappa2
    Gaussian,
    /// Mean curvature H = (kappa1 + kappa2)/2
    Mean,
    /// The larger principal curvature
    Kappa1,
    /// The smaller principal curvature
    Kappa2,
    /// Bands of equal brightness n·L under a parallel light, edged in black
    Isophotes,
    /// Reflection of parallel light tubes running along the picture's horizontal
    Zebra,
    /// Distance between the surface and the faired one at the same parameters (needs --faired)
    Deviation,
    /// Every view that applies, one per row
    All,
}

/// Arguments of `batten plot-surface`.
#[derive(Debug, Args)]
pub struct PlotSurfaceArgs {
    /// Surface file (.json): a B-spline surface or a grid of points
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Where to write the picture (.png or .svg; never an input file)
    #[arg(short, long, value_name = "OUT.png|OUT.svg")]
    pub output: PathBuf,
    /// The faired surface, drawn next to the input at the same scale and colour range
    #[arg(long, value_name = "FAIRED.json")]
    pub faired: Option<PathBuf>,
    /// What to draw
    #[arg(long, value_enum, default_value_t = SurfaceKind::All)]
    pub kind: SurfaceKind,
    /// Direction towards the viewer (orthographic view), x,y,z
    #[arg(long, value_name = "X,Y,Z", default_value = "1,-2,3", value_parser = parse_xyz,
          allow_hyphen_values = true)]
    pub view: Xyz,
    /// Direction towards the light of the isophotes, x,y,z [default: the view direction]
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_xyz, allow_hyphen_values = true)]
    pub light: Option<Xyz>,
    /// Isophote bands, or zebra stripe pairs, across the range seen on the surface(s)
    #[arg(long, value_name = "N", default_value_t = 12,
          value_parser = clap::value_parser!(u16).range(2..=200))]
    pub stripes: u16,
    /// Width of one panel in pixels
    #[arg(long, value_name = "PX", default_value_t = 480)]
    pub width: usize,
    /// Height of one panel in pixels
    #[arg(long, value_name = "PX", default_value_t = 360)]
    pub height: usize,
}

fn parse_xyz(s: &str) -> Result<Xyz, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let bad = || format!("'{s}' is not three numbers x,y,z");
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = p.parse::<f64>().map_err(|_| bad())?;
        if !v[k].is_finite() {
            return Err(bad());
        }
    }
    if v.iter().all(|&x| x == 0.0) {
        return Err(format!("'{s}' is the zero vector, not a direction"));
    }
    Ok(v)
}

/// Run `batten plot-surface`. Options and paths are checked before anything is read, and
/// nothing is written unless the whole picture was drawn.
///
/// # Errors
/// Usage errors and bad input (exit 2); a failed write (exit 1).
pub fn run(args: &PlotSurfaceArgs) -> Result<ExitCode, Failure> {
    for (name, v) in [("--width", args.width), ("--height", args.height)] {
        if !PANEL_SIZES.contains(&v) {
            return Err(Failure::usage(anyhow!(
                "{name} {v}: a panel is {} to {} pixels",
                PANEL_SIZES.start(),
                PANEL_SIZES.end()
            )));
        }
    }
    if args.kind == SurfaceKind::Deviation && args.faired.is_none() {
        return Err(Failure::usage(anyhow!("--kind deviation needs --faired")));
    }
    let mut inputs = vec![args.input.as_path()];
    inputs.extend(args.faired.as_deref());
    check_output(&args.output, &["png", "svg"], &inputs)?;
    let before = io::read_surface_json(&args.input).map_err(Failure::usage)?;
    let after = match &args.faired {
        None => None,
        Some(p) => {
            let f = io::read_surface_json(p).map_err(Failure::usage)?;
            if f.domain() != before.domain() {
                return Err(Failure::usage(anyhow!(
                    "{}: parameter domain {:?} differs from {}'s {:?}; the faired surface \
                     must share the input's parameters",
                    p.display(),
                    f.domain(),
                    args.input.display(),
                    before.domain()
                )));
            }
            Some(f)
        }
    };
    let views = Views {
        view: args.view,
        light: args.light,
        stripes: args.stripes,
        width: args.width,
        height: args.height,
    };
    let figure = figure(
        &args.input.display().to_string(),
        &before,
        after.as_ref(),
        &kinds(args.kind, after.is_some()),
        &views,
    )?;
    let bytes = if is_svg(&args.output) {
        figure.svg().map(String::into_bytes)
    } else {
        figure.png()
    }
    .map_err(|e| Failure::failed(e.context(format!("{}: cannot encode", args.output.display()))))?;
    io::write_atomic(&args.output, &bytes).map_err(Failure::failed)?;
    Ok(ExitCode::SUCCESS)
}

fn is_svg(p: &std::path::Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
}

/// How the views are drawn (the options of `plot-surface` that are not paths).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Views {
    /// Direction towards the viewer.
    pub view: Xyz,
    /// Direction towards the isophotes' light; `None` for the view direction.
    pub light: Option<Xyz>,
    /// Isophote bands or zebra stripe pairs.
    pub stripes: u16,
    /// One panel's size in pixels.
    pub width: usize,
    /// One panel's size in pixels.
    pub height: usize,
}

impl Views {
    /// The defaults of `plot-surface`'s options (kept equal to the clap defaults above; a
    /// unit test checks).
    pub const DEFAULT: Views = Views {
        view: [1.0, -2.0, 3.0],
        light: None,
        stripes: 12,
        width: 480,
        height: 360,
    };
}

/// The views `kind` stands for (`all`: every one that applies).
pub(crate) fn kinds(kind: SurfaceKind, faired: bool) -> Vec<SurfaceKind> {
    match kind {
        SurfaceKind::All => {
            let mut k = vec![
                SurfaceKind::Gaussian,
                SurfaceKind::Mean,
                SurfaceKind::Kappa1,
                SurfaceKind::Kappa2,
                SurfaceKind::Isophotes,
                SurfaceKind::Zebra,
            ];
            if faired {
                k.push(SurfaceKind::Deviation);
            }
            k
        }
        k => vec![k],
    }
}

/// The picture: one row per view of `kinds`, the input `before` (named `name` in the
/// titles) and, if given, the faired surface `after` beside it.
///
/// # Errors
/// A view or picture size the library refuses; `deviation` without `after` (exit 2).
pub(crate) fn figure(
    name: &str,
    before: &BSplineSurface,
    after: Option<&BSplineSurface>,
    kinds: &[SurfaceKind],
    v: &Views,
) -> Result<Figure, Failure> {
    let grid = SurfaceMesh::grid(before);
    let mut meshes = vec![SurfaceMesh::new(before, &grid)];
    if let Some(a) = after {
        // The same parameters as the input's mesh, so the deviation compares like with like.
        meshes.push(SurfaceMesh::new(a, &grid));
    }
    let camera = Camera::fit(
        v.view,
        &meshes.iter().collect::<Vec<_>>(),
        v.width,
        v.height,
        PANEL_MARGIN,
    )
    .map_err(|e| Failure::from_batten("", e))?;
    let sides = if after.is_some() {
        " - before (left), after (right)"
    } else {
        ""
    };
    let mut rows = Vec::new();
    for &kind in kinds {
        let title = format!("{name}: {}{sides}", title(kind));
        let row = match kind {
            SurfaceKind::Gaussian
            | SurfaceKind::Mean
            | SurfaceKind::Kappa1
            | SurfaceKind::Kappa2 => curvature_row(kind, title, &mut meshes, &camera),
            SurfaceKind::Isophotes | SurfaceKind::Zebra => {
                stripes_row(kind, title, &meshes, &camera, v)
            }
            SurfaceKind::Deviation | SurfaceKind::All => {
                deviation_row(name, before, &grid, &mut meshes, &camera)?
            }
        };
        rows.push(row);
    }
    Ok(Figure {
        rows,
        panel: [v.width, v.height],
    })
}

/// A row of a curvature map (`kind` one of the four curvatures): every panel on one
/// diverging colour scale, symmetric about zero.
fn curvature_row(
    kind: SurfaceKind,
    title: String,
    meshes: &mut [SurfaceMesh],
    camera: &Camera,
) -> Row {
    let field = match kind {
        SurfaceKind::Gaussian => Field::Gaussian,
        SurfaceKind::Mean => Field::Mean,
        SurfaceKind::Kappa1 => Field::Kappa1,
        _ => Field::Kappa2,
    };
    let mut m = 0.0f64;
    for mesh in meshes.iter_mut() {
        mesh.set_field(field);
        if let Some((lo, hi)) = mesh.value_range() {
            m = m.max(lo.abs()).max(hi.abs());
        }
    }
    if m == 0.0 {
        // A plane: any symmetric range draws it white.
        m = 1.0;
    }
    let shading = Shading::Map {
        lo: -m,
        hi: m,
        palette: Palette::Diverging,
    };
    Row {
        title,
        panels: meshes.iter().map(|x| render(x, camera, &shading)).collect(),
        bar: Some(Bar {
            lo: -m,
            hi: m,
            palette: Palette::Diverging,
        }),
    }
}

/// A row of isophotes or zebra stripes (`kind`).
fn stripes_row(
    kind: SurfaceKind,
    title: String,
    meshes: &[SurfaceMesh],
    camera: &Camera,
    v: &Views,
) -> Row {
    // Bands over the range seen on both panels, so a gently curved hood shows
    // as many as a ball and before and after share them.
    let shading = if kind == SurfaceKind::Isophotes {
        let light = v.light.unwrap_or(v.view);
        let (lo, hi) = isophote_range(&meshes.iter().collect::<Vec<_>>(), camera, light);
        Shading::Isophotes {
            light,
            lo,
            hi,
            bands: usize::from(v.stripes),
        }
    } else {
        let (lo, hi) = zebra_range(&meshes.iter().collect::<Vec<_>>(), camera);
        Shading::Zebra {
            lo,
            hi,
            stripes: usize::from(v.stripes),
        }
    };
    Row {
        title,
        panels: meshes.iter().map(|x| render(x, camera, &shading)).collect(),
        bar: None,
    }
}

/// The row of the deviation map: the distance from `before` drawn on the faired surface
/// (the second mesh, sampled at `grid`).
///
/// # Errors
/// `deviation` without a faired surface (exit 2); the library's refusal to compare.
fn deviation_row(
    name: &str,
    before: &BSplineSurface,
    grid: &SampleGrid,
    meshes: &mut [SurfaceMesh],
    camera: &Camera,
) -> Result<Row, Failure> {
    let Some(mesh) = meshes.get_mut(1) else {
        return Err(Failure::usage(anyhow!("--kind deviation needs --faired")));
    };
    mesh.set_deviation(before, grid)
        .map_err(|e| Failure::from_batten("", e))?;
    let hi = mesh.value_range().map_or(0.0, |r| r.1);
    let shading = Shading::Map {
        lo: 0.0,
        hi,
        palette: Palette::Sequential,
    };
    Ok(Row {
        title: format!("{name}: distance to the faired surface, on the faired one"),
        panels: vec![render(mesh, camera, &shading)],
        bar: Some(Bar {
            lo: 0.0,
            hi,
            palette: Palette::Sequential,
        }),
    })
}

fn title(kind: SurfaceKind) -> &'static str {
    match kind {
        SurfaceKind::Gaussian => "Gaussian curvature K",
        SurfaceKind::Mean => "mean curvature H",
        SurfaceKind::Kappa1 => "principal curvature kappa1",
        SurfaceKind::Kappa2 => "principal curvature kappa2",
        SurfaceKind::Isophotes => "isophotes",
        SurfaceKind::Zebra => "zebra",
        SurfaceKind::Deviation | SurfaceKind::All => "deviation",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clap_defaults_are_views_default() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            args: PlotSurfaceArgs,
        }
        let a = Cli::parse_from(["x", "in.json", "-o", "out.png"]).args;
        let d = Views::DEFAULT;
        assert_eq!(a.view, d.view);
        assert_eq!(a.light, d.light);
        assert_eq!(a.stripes, d.stripes);
        assert_eq!((a.width, a.height), (d.width, d.height));
    }

    #[test]
    fn directions_parse() {
        assert_eq!(parse_xyz("1,-2, 3"), Ok([1.0, -2.0, 3.0]));
        assert!(parse_xyz("1,2").is_err());
        assert!(parse_xyz("0,0,0").unwrap_err().contains("zero vector"));
        assert!(parse_xyz("1,nan,0").is_err());
        assert!(parse_xyz("a,b,c").is_err());
    }
}
