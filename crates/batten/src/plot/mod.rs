//! SVG pictures of curves and their curvature (feature `plot`, on by default).
//!
//! [`render`] draws a point sequence, and optionally its faired version over it, as one SVG
//! document of one or more panels ([`PlotKind`]):
//!
//! - **comb**: the curve with its curvature comb (teeth along the normal, of length
//!   `scale·κ`, drawn as [`CombSample`](crate::analysis::CombSample) documents:
//!   `point + scale·κ·normal`, so they point towards the centre of curvature) and the
//!   envelope through the tooth tips, the data points as dots, and the inflections (sign
//!   changes of κ, counted and placed as [`FairnessMetrics`](crate::FairnessMetrics) counts
//!   them) as circles. The scale is chosen so that the largest tooth drawn is
//!   [`DEFAULT_COMB_FRACTION`] of the input's bounding-box diagonal, unless
//!   [`PlotOptions::comb_scale`] sets it; with a faired curve both combs share the scale, and
//!   each point's displacement is drawn as a segment from old to new.
//! - **curvature**: κ against arc length, inflections on the zero line.
//! - **radius**: ρ = 1/κ against arc length. ρ is infinite where the curve is straight, so,
//!   as Kuragano et al. say, "a limit value should be assigned": |ρ| is capped at
//!   [`PlotOptions::rho_max`] and the capped parts are drawn dashed at ±ρ_max.
//! - **xc**: HAN's x–c plot of a function segment, the polyline `(x_i, c_i)` with
//!   `c_i = y''(x_i)/6` of the [`CubicSplineFn`](crate::spline::CubicSplineFn) with HAN's end
//!   condition, in the data frame when x increases strictly, else in the chord frame (first
//!   point at the origin, last point on the positive x axis).
//! - **displacement**: how far each point moved, against its index (needs a faired curve).
//! - **all**: the panels stacked; x–c only when the points are a function segment,
//!   displacement only with a faired curve.
//!
//! Everything is measured on the analysis curve of [`crate::analysis::analysis_curve`], the
//! curve every metric of the crate is measured on.
//!
//! # Large inputs
//!
//! The data are never thinned; what is drawn is. A panel draws at most [`MAX_TEETH`] comb
//! teeth and [`MAX_VERTICES`] vertices per polyline (chosen evenly by arc length; graphs
//! keep the smallest and largest value of each arc-length bin so no spike is lost),
//! [`MAX_DOTS`] data points (every k-th) and [`MAX_MARKERS`] inflection markers; the legend
//! says when it shows fewer than there are. A curve of 10⁶ points gives an SVG of about
//! half a megabyte.
//!
//! # The SVG
//!
//! Plain SVG 1.1 with one embedded style sheet (class names prefixed `bt-`, so the document
//! can be inlined in HTML), no scripts, no external resources, no element ids; coordinates
//! in pixels with one decimal. Every series is one `<path>` with a `data-series` attribute
//! naming it; inflection markers are `<circle class="bt-infl0">` (input) and `bt-infl1`
//! (faired).
//!
//! ```
//! use batten::plot::{PlotKind, PlotOptions, render};
//! use batten::{Point, PointSeq};
//!
//! let pts: Vec<Point> = (0..41)
//!     .map(|i| {
//!         let x = -1.5 + 0.075 * i as f64;
//!         Point::new(x, x * x * x - x)
//!     })
//!     .collect();
//! let seq = PointSeq::open(pts).unwrap();
//! let svg = render(&seq, None, &PlotOptions::DEFAULT.with_kind(PlotKind::Comb)).unwrap();
//! assert!(svg.starts_with("<svg"));
//! assert_eq!(svg.matches("class=\"bt-infl0\"").count(), 1); // y = x³ − x inflects once
//! ```

mod axes;
mod panels;
mod sample;
mod space;
mod svg;

use std::fmt;
use std::str::FromStr;

use self::axes::Rect;
use self::sample::{Sampled, XcData, function_frame, xc_data};
pub use self::space::{SPACE_VIEWS, auto_space_comb_scale, render_space};
use self::svg::Svg;
use crate::error::{Error, Result};
use crate::geom::PointSeq;

/// The most comb teeth drawn per curve.
pub const MAX_TEETH: usize = 2000;
/// The most vertices drawn per polyline (curve, comb envelope, graph).
pub const MAX_VERTICES: usize = 4000;
/// The most data points drawn as dots (and displacement segments) per curve.
pub const MAX_DOTS: usize = 2000;
/// The most inflection markers drawn per curve.
pub const MAX_MARKERS: usize = 1000;
/// The automatic comb scale makes the largest tooth drawn this fraction of the diagonal of
/// the input's bounding box.
pub const DEFAULT_COMB_FRACTION: f64 = 0.15;
/// The smallest panel accepted, in pixels (width, height).
pub const MIN_PANEL: (f64, f64) = (240.0, 180.0);
/// Height of the heading of an [`PlotKind::All`] picture with a title, in pixels.
const HEADING: f64 = 34.0;
/// Height of a line of notes under the panels, in pixels.
const NOTE_LINE: f64 = 18.0;

/// What to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum PlotKind {
    /// The curve, its curvature comb, data points and inflections.
    Comb,
    /// Signed curvature κ against arc length.
    Curvature,
    /// Radius of curvature ρ = 1/κ against arc length, capped at ±ρ_max.
    Radius,
    /// HAN's x–c plot of a function segment.
    Xc,
    /// Displacement of each point against its index (needs a faired curve).
    Displacement,
    /// Every panel that applies, stacked.
    All,
}

impl PlotKind {
    /// Every kind, in the order [`PlotKind::All`] stacks them (`All` last).
    pub const KINDS: [PlotKind; 6] = [
        PlotKind::Comb,
        PlotKind::Curvature,
        PlotKind::Radius,
        PlotKind::Xc,
        PlotKind::Displacement,
        PlotKind::All,
    ];

    /// The name used on the command line: `comb`, `curvature`, `radius`, `xc`,
    /// `displacement`, `all`.
    pub fn name(self) -> &'static str {
        match self {
            PlotKind::Comb => "comb",
            PlotKind::Curvature => "curvature",
            PlotKind::Radius => "radius",
            PlotKind::Xc => "xc",
            PlotKind::Displacement => "displacement",
            PlotKind::All => "all",
        }
    }
}

impl fmt::Display for PlotKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PlotKind {
    type Err = Error;

    /// Parse a [`PlotKind::name`].
    fn from_str(s: &str) -> Result<PlotKind> {
        PlotKind::KINDS
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| Error::InvalidParameter {
                name: "plot kind".into(),
                reason: format!(
                    "unknown kind '{s}' (known: {})",
                    PlotKind::KINDS.map(PlotKind::name).join(", ")
                ),
            })
    }
}

/// How to draw.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct PlotOptions {
    /// The panel or panels.
    ///
    /// Default value: [`PlotKind::Comb`].
    pub kind: PlotKind,
    /// Tooth length per unit curvature, in data units (a tooth is `comb_scale·κ` long);
    /// `None` chooses it so that the largest tooth drawn is [`DEFAULT_COMB_FRACTION`] of the
    /// input's bounding-box diagonal.
    ///
    /// Default value: `None`.
    pub comb_scale: Option<f64>,
    /// The cap on |ρ| in the radius panel, in data units; `None` takes the diagonal of the
    /// input's bounding box: a radius longer than the whole curve reads as straight at the
    /// curve's own scale.
    ///
    /// Default value: `None`.
    pub rho_max: Option<f64>,
    /// Width of the picture in pixels.
    ///
    /// Default value: `800.0`.
    pub width: f64,
    /// Height of one panel in pixels ([`PlotKind::All`] stacks several).
    ///
    /// Default value: `520.0`.
    pub height: f64,
    /// The title: of the panel for a single kind, a heading above the panels for
    /// [`PlotKind::All`]. `None` gives each panel its own descriptive title.
    ///
    /// Default value: `None`.
    pub title: Option<String>,
}

impl PlotOptions {
    /// The defaults (see each field).
    pub const DEFAULT: PlotOptions = PlotOptions {
        kind: PlotKind::Comb,
        comb_scale: None,
        rho_max: None,
        width: 800.0,
        height: 520.0,
        title: None,
    };

    /// Draw `kind`.
    pub fn with_kind(mut self, kind: PlotKind) -> PlotOptions {
        self.kind = kind;
        self
    }

    /// Fix the comb scale (tooth length per unit curvature, data units).
    pub fn with_comb_scale(mut self, scale: f64) -> PlotOptions {
        self.comb_scale = Some(scale);
        self
    }

    /// Fix the cap on |ρ|.
    pub fn with_rho_max(mut self, rho_max: f64) -> PlotOptions {
        self.rho_max = Some(rho_max);
        self
    }

    /// Set the width and the panel height in pixels.
    pub fn with_size(mut self, width: f64, height: f64) -> PlotOptions {
        self.width = width;
        self.height = height;
        self
    }

    /// Set the title.
    pub fn with_title(mut self, title: impl Into<String>) -> PlotOptions {
        self.title = Some(title.into());
        self
    }

    /// Check the values.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a size below [`MIN_PANEL`] or not finite, and for a
    /// comb scale or ρ_max that is not finite and positive.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, reason: String| {
            Err(Error::InvalidParameter {
                name: name.into(),
                reason,
            })
        };
        if !(self.width.is_finite() && self.width >= MIN_PANEL.0 && self.width <= 1e5) {
            return bad(
                "width",
                format!(
                    "must be {} to 100000 pixels, got {}",
                    MIN_PANEL.0, self.width
                ),
            );
        }
        if !(self.height.is_finite() && self.height >= MIN_PANEL.1 && self.height <= 1e5) {
            return bad(
                "height",
                format!(
                    "must be {} to 100000 pixels, got {}",
                    MIN_PANEL.1, self.height
                ),
            );
        }
        for (name, v) in [("comb scale", self.comb_scale), ("rho_max", self.rho_max)] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return bad(name, format!("must be finite and positive, got {v}"));
            }
        }
        Ok(())
    }
}

impl Default for PlotOptions {
    fn default() -> PlotOptions {
        PlotOptions::DEFAULT
    }
}

/// The automatic comb scale for drawing `input` and `others` with one scale: the largest
/// tooth drawn of any of them is [`DEFAULT_COMB_FRACTION`] of the diagonal of `input`'s
/// bounding box. Zero when every curve is straight. Useful to draw several pictures (one
/// per fairing method, say) at the same scale.
///
/// # Errors
/// The analysis curve's constructor errors.
pub fn auto_comb_scale(input: &PointSeq, others: &[&PointSeq]) -> Result<f64> {
    let mut max_k = panels::max_drawn_curvature(&Sampled::new(input)?);
    for o in others {
        max_k = max_k.max(panels::max_drawn_curvature(&Sampled::new(o)?));
    }
    Ok(scale_for(input, max_k))
}

fn scale_for(input: &PointSeq, max_curvature: f64) -> f64 {
    comb_scale_for(input.scale(), max_curvature)
}

/// The comb scale that draws the largest curvature as [`DEFAULT_COMB_FRACTION`] of a curve of
/// size `size` (0 for a straight curve).
pub(crate) fn comb_scale_for(size: f64, max_curvature: f64) -> f64 {
    if max_curvature > 0.0 && max_curvature.is_finite() {
        DEFAULT_COMB_FRACTION * size / max_curvature
    } else {
        0.0
    }
}

/// A faired curve drawn over an input must match it point for point, open or closed alike:
/// `(len, closed)` of each.
pub(crate) fn check_faired(faired: Option<(usize, bool)>, input: (usize, bool)) -> Result<()> {
    let Some((len, closed)) = faired else {
        return Ok(());
    };
    if len != input.0 {
        return Err(Error::LengthMismatch {
            what: "faired points",
            got: len,
            expected: input.0,
        });
    }
    if closed != input.1 {
        return Err(Error::InvalidParameter {
            name: "faired".into(),
            reason: "one curve is closed and the other open".into(),
        });
    }
    Ok(())
}

/// Draw `input`, and `faired` over it when given, as an SVG document (see the
/// [module docs](self)).
///
/// # Errors
/// - [`Error::InvalidParameter`] for bad options ([`PlotOptions::validate`]), a `faired`
///   curve that is closed where the input is open or the other way round, and
///   [`PlotKind::Displacement`] without a faired curve;
/// - [`Error::LengthMismatch`] when `faired` has another number of points;
/// - [`Error::Degenerate`] for [`PlotKind::Xc`] on a closed curve or on points that are not a
///   function graph in their own frame nor in the chord frame;
/// - the spline constructors' errors.
pub fn render(
    input: &PointSeq,
    faired: Option<&PointSeq>,
    options: &PlotOptions,
) -> Result<String> {
    options.validate()?;
    check_faired(
        faired.map(|f| (f.len(), f.is_closed())),
        (input.len(), input.is_closed()),
    )?;
    if options.kind == PlotKind::Displacement && faired.is_none() {
        return Err(Error::InvalidParameter {
            name: "plot kind".into(),
            reason: "the displacement plot needs a faired curve".into(),
        });
    }
    let inp = Sampled::new(input)?;
    let fai = faired.map(Sampled::new).transpose()?;
    let series: Vec<&Sampled> = std::iter::once(&inp).chain(fai.as_ref()).collect();

    let mut notes = Vec::new();
    let xc = match options.kind {
        PlotKind::Xc => Some(xc_series(input, faired, &mut notes)?),
        PlotKind::All => match xc_series(input, faired, &mut notes) {
            Ok(x) => Some(x),
            Err(e) => {
                notes.push(format!("no x–c plot: {e}"));
                None
            }
        },
        _ => None,
    };
    let mut kinds: Vec<PlotKind> = match options.kind {
        PlotKind::All => vec![PlotKind::Comb, PlotKind::Curvature, PlotKind::Radius],
        k => vec![k],
    };
    if options.kind == PlotKind::All {
        if xc.is_some() {
            kinds.push(PlotKind::Xc);
        }
        if faired.is_some() {
            kinds.push(PlotKind::Displacement);
        }
    }
    let stacked = options.kind == PlotKind::All;
    let heading = if stacked && options.title.is_some() {
        HEADING
    } else {
        0.0
    };
    let notes_h = NOTE_LINE * notes.len() as f64;
    let total_h = heading + options.height * kinds.len() as f64 + notes_h;
    let mut svg = Svg::new(options.width, total_h);
    if stacked && let Some(t) = &options.title {
        svg.text(options.width / 2.0, 24.0, "bt-title", "middle", t);
    }
    let page = Page {
        input,
        faired,
        series: &series,
        xc: xc.as_ref(),
        options,
        stacked,
    };
    for (row, kind) in kinds.iter().enumerate() {
        let outer = Rect {
            x: 0.0,
            y: heading + options.height * row as f64,
            w: options.width,
            h: options.height,
        };
        page.panel(&mut svg, *kind, outer);
    }
    let top = heading + options.height * kinds.len() as f64;
    for (i, n) in notes.iter().enumerate() {
        svg.text(
            12.0,
            top + NOTE_LINE * (i as f64 + 0.8),
            "bt-note",
            "start",
            n,
        );
    }
    Ok(svg.finish())
}

/// What every panel of one [`render`] draws from.
struct Page<'a> {
    input: &'a PointSeq,
    faired: Option<&'a PointSeq>,
    series: &'a [&'a Sampled<'a>],
    xc: Option<&'a (Vec<(usize, XcData)>, bool)>,
    options: &'a PlotOptions,
    /// Whether the panels are stacked under one heading ([`PlotKind::All`]).
    stacked: bool,
}

impl Page<'_> {
    /// A panel's title: the user's title for a single panel, else `default`.
    fn title_for(&self, default: &str) -> String {
        match (&self.options.title, self.stacked) {
            (Some(t), false) => t.clone(),
            _ => default.to_string(),
        }
    }

    /// Draw the panel of `kind` in `outer`.
    fn panel(&self, svg: &mut Svg, kind: PlotKind, outer: Rect) {
        let (input, series, options) = (self.input, self.series, self.options);
        match kind {
            PlotKind::Comb => {
                let scale = match options.comb_scale {
                    Some(s) => s,
                    None => scale_for(
                        input,
                        series
                            .iter()
                            .map(|s| panels::max_drawn_curvature(s))
                            .fold(0.0, f64::max),
                    ),
                };
                panels::comb(svg, outer, series, scale, &self.title_for("Curvature comb"));
            }
            PlotKind::Curvature => panels::curvature(
                svg,
                outer,
                series,
                &self.title_for("Curvature κ against arc length"),
            ),
            PlotKind::Radius => {
                let rho_max = options.rho_max.unwrap_or_else(|| input.scale());
                panels::radius(
                    svg,
                    outer,
                    series,
                    rho_max,
                    &self.title_for("Radius of curvature ρ = 1/κ against arc length"),
                );
            }
            PlotKind::Xc => {
                if let Some((data, chord)) = self.xc {
                    let s: Vec<(usize, &XcData)> = data.iter().map(|(k, d)| (*k, d)).collect();
                    panels::xc(
                        svg,
                        outer,
                        &s,
                        *chord,
                        &self.title_for("x–c plot (Han): c = y″/6 of the cubic spline function"),
                    );
                }
            }
            PlotKind::Displacement => {
                if let Some(f) = self.faired {
                    panels::displacement(
                        svg,
                        outer,
                        input.points(),
                        f.points(),
                        &self.title_for("Displacement of each point"),
                    );
                }
            }
            PlotKind::All => {}
        }
    }
}

/// The x–c data of the input and, when it is a function in the same frame, the faired
/// points; and whether the frame is the chord frame. A faired curve that is not a function
/// there is left out with a note.
fn xc_series(
    input: &PointSeq,
    faired: Option<&PointSeq>,
    notes: &mut Vec<String>,
) -> Result<(Vec<(usize, XcData)>, bool)> {
    if input.is_closed() {
        return Err(Error::Degenerate(
            "the x–c plot is for open function segments; the curve is closed".into(),
        ));
    }
    let (frame, chord) = function_frame(input.points()).ok_or_else(|| {
        Error::Degenerate(
            "the x–c plot needs a function segment: x increases strictly neither in the data \
             frame nor in the chord frame"
                .into(),
        )
    })?;
    let mut out = vec![(0, xc_data(input.points(), &frame)?)];
    if let Some(f) = faired {
        match xc_data(f.points(), &frame) {
            Ok(d) => out.push((1, d)),
            Err(e) => notes.push(format!("faired x–c plot left out: {e}")),
        }
    }
    Ok((out, chord))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
