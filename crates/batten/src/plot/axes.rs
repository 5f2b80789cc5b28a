//! Panels: the data-to-pixel map, axes with "nice" ticks, titles and legends.

use super::svg::{PathData, Svg};

/// Pixels between the left edge of a panel and its plot area (tick labels, y label).
const MARGIN_LEFT: f64 = 78.0;
/// Pixels right of the plot area.
const MARGIN_RIGHT: f64 = 22.0;
/// Pixels above the plot area (the title).
const MARGIN_TOP: f64 = 34.0;
/// Pixels below the plot area for the tick labels and the x label.
const MARGIN_BOTTOM: f64 = 52.0;
/// Pixels per legend row (the rows sit below the x label).
const LEGEND_ROW: f64 = 16.0;
/// Horizontal pixels per tick aimed at.
const PX_PER_XTICK: f64 = 90.0;
/// Vertical pixels per tick aimed at.
const PX_PER_YTICK: f64 = 55.0;
/// A range narrower than this fraction of its magnitude is drawn as if it had no width
/// (its values differ by rounding only).
const MIN_RELATIVE_SPAN: f64 = 1e-9;
/// Fraction of a value range added on each side of a graph, so nothing touches the frame.
pub(crate) const GRAPH_PAD: f64 = 0.05;

/// A rectangle in pixels (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rect {
    pub x: f64,
    pub y: f64,
    pub w: f64,
    pub h: f64,
}

impl Rect {
    /// The plot area of a panel occupying `self` with a legend of `legend_rows` rows: the
    /// panel less its margins.
    pub(crate) fn plot_area(&self, legend_rows: usize) -> Rect {
        let bottom = MARGIN_BOTTOM + LEGEND_ROW * legend_rows as f64 + 6.0;
        Rect {
            x: self.x + MARGIN_LEFT,
            y: self.y + MARGIN_TOP,
            w: (self.w - MARGIN_LEFT - MARGIN_RIGHT).max(1.0),
            h: (self.h - MARGIN_TOP - bottom).max(1.0),
        }
    }
}

/// A closed interval of data values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Range {
    pub lo: f64,
    pub hi: f64,
}

impl Range {
    /// The smallest range holding every finite value, or `None` when there is none.
    pub(crate) fn of(values: impl IntoIterator<Item = f64>) -> Option<Range> {
        let mut r: Option<Range> = None;
        for v in values.into_iter().filter(|v| v.is_finite()) {
            r = Some(match r {
                None => Range { lo: v, hi: v },
                Some(r) => Range {
                    lo: r.lo.min(v),
                    hi: r.hi.max(v),
                },
            });
        }
        r
    }

    /// The smallest ranges of the first and of the second coordinates of the pairs whose
    /// both coordinates are finite, or zero-width ranges at 0 when there is none.
    pub(crate) fn of_pairs(pairs: impl IntoIterator<Item = (f64, f64)>) -> (Range, Range) {
        let (mut xr, mut yr): (Option<Range>, Option<Range>) = (None, None);
        for (x, y) in pairs {
            if x.is_finite() && y.is_finite() {
                xr = Some(xr.map_or(Range { lo: x, hi: x }, |r| r.including(x)));
                yr = Some(yr.map_or(Range { lo: y, hi: y }, |r| r.including(y)));
            }
        }
        let zero = Range { lo: 0.0, hi: 0.0 };
        (xr.unwrap_or(zero), yr.unwrap_or(zero))
    }

    /// The union of two ranges.
    pub(crate) fn union(self, o: Range) -> Range {
        Range {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// The range widened to include `v` (when finite).
    pub(crate) fn including(self, v: f64) -> Range {
        if v.is_finite() {
            Range {
                lo: self.lo.min(v),
                hi: self.hi.max(v),
            }
        } else {
            self
        }
    }

    /// The width `hi − lo`.
    pub(crate) fn span(&self) -> f64 {
        self.hi - self.lo
    }

    /// The range grown by `frac` of its width on each side; a range of zero width (or one
    /// too narrow to resolve against its magnitude) is grown to ±10 % of its magnitude, or
    /// to ±1 around zero.
    pub(crate) fn padded(self, frac: f64) -> Range {
        let mag = self.lo.abs().max(self.hi.abs());
        let w = self.span();
        if w.is_nan() || w <= mag * MIN_RELATIVE_SPAN {
            let half = if mag > 0.0 { 0.1 * mag } else { 1.0 };
            let mid = 0.5 * (self.lo + self.hi);
            return Range {
                lo: mid - half,
                hi: mid + half,
            };
        }
        Range {
            lo: self.lo - frac * w,
            hi: self.hi + frac * w,
        }
    }
}

/// A linear map from data to the pixels of a plot area (data y up, pixel y down).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub area: Rect,
    pub x: Range,
    pub y: Range,
}

impl Frame {
    /// Map `x` and `y` onto the whole area.
    pub(crate) fn new(area: Rect, x: Range, y: Range) -> Frame {
        Frame { area, x, y }
    }

    /// Map with one scale on both axes (for drawing geometry), the data centred in the area.
    pub(crate) fn equal_aspect(area: Rect, x: Range, y: Range) -> Frame {
        let (x, y) = (x.padded(0.0), y.padded(0.0));
        let per_px = (x.span() / area.w).max(y.span() / area.h);
        let (cx, cy) = (0.5 * (x.lo + x.hi), 0.5 * (y.lo + y.hi));
        let (hx, hy) = (0.5 * per_px * area.w, 0.5 * per_px * area.h);
        Frame {
            area,
            x: Range {
                lo: cx - hx,
                hi: cx + hx,
            },
            y: Range {
                lo: cy - hy,
                hi: cy + hy,
            },
        }
    }

    /// The pixel x of data x.
    pub(crate) fn px(&self, x: f64) -> f64 {
        self.area.x + (x - self.x.lo) / self.x.span() * self.area.w
    }

    /// The pixel y of data y.
    pub(crate) fn py(&self, y: f64) -> f64 {
        self.area.y + self.area.h - (y - self.y.lo) / self.y.span() * self.area.h
    }

    /// The pixel position of a data point.
    pub(crate) fn map(&self, x: f64, y: f64) -> (f64, f64) {
        (self.px(x), self.py(y))
    }
}

/// Tick positions for `r` with a step of 1, 2 or 5 times a power of ten, about `target`
/// of them, and the step.
pub(crate) fn nice_ticks(r: Range, target: usize) -> (Vec<f64>, f64) {
    let span = r.span();
    if !(span > 0.0 && span.is_finite()) {
        return (vec![r.lo], 1.0);
    }
    let rough = span / target.max(1) as f64;
    let mag = 10f64.powf(rough.log10().floor());
    let norm = rough / mag;
    let nice = if norm < 1.5 {
        1.0
    } else if norm < 3.5 {
        2.0
    } else if norm < 7.5 {
        5.0
    } else {
        10.0
    };
    let step = nice * mag;
    let first = (r.lo / step).ceil();
    let last = (r.hi / step).floor();
    let mut ticks = Vec::new();
    let mut k = first;
    while k <= last && ticks.len() <= 4 * target + 4 {
        let v = k * step;
        // Snap rounding noise at zero (e.g. 3 × 0.1 − 0.3).
        ticks.push(if v.abs() < step * 1e-9 { 0.0 } else { v });
        k += 1.0;
    }
    (ticks, step)
}

/// A tick label: as many decimals as the step needs; exponent form for very large or very
/// small magnitudes.
pub(crate) fn format_tick(v: f64, step: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    let step_exp = step.abs().log10().floor();
    let mag_exp = v.abs().log10().floor();
    if mag_exp >= 6.0 || step_exp <= -5.0 {
        // Digits after the mantissa's point: down to the step's decade.
        let d = (mag_exp - step_exp).clamp(0.0, 15.0) as usize;
        format!("{v:.d$e}")
    } else {
        let d = (-step_exp).clamp(0.0, 15.0) as usize;
        format!("{v:.d$}")
    }
}

/// Draw the title of a panel occupying `outer`.
pub(crate) fn title(svg: &mut Svg, outer: Rect, text: &str) {
    svg.text(
        outer.x + outer.w / 2.0,
        outer.y + 22.0,
        "bt-title",
        "middle",
        text,
    );
}

/// Draw the grid, the frame, the ticks with their labels and the axis labels of `f`.
pub(crate) fn axes(svg: &mut Svg, f: &Frame, xlabel: &str, ylabel: &str) {
    let a = f.area;
    let (xt, xstep) = nice_ticks(f.x, (a.w / PX_PER_XTICK).round().max(2.0) as usize);
    let (yt, ystep) = nice_ticks(f.y, (a.h / PX_PER_YTICK).round().max(2.0) as usize);
    let mut grid = PathData::new();
    let mut marks = PathData::new();
    for &x in &xt {
        let px = f.px(x);
        grid.segment((px, a.y), (px, a.y + a.h));
        marks.segment((px, a.y + a.h), (px, a.y + a.h + 5.0));
    }
    for &y in &yt {
        let py = f.py(y);
        grid.segment((a.x, py), (a.x + a.w, py));
        marks.segment((a.x - 5.0, py), (a.x, py));
    }
    svg.path(&grid, "bt-grid", "grid");
    svg.rect(a.x, a.y, a.w, a.h, "bt-frame");
    svg.path(&marks, "bt-frame", "ticks");
    for &x in &xt {
        svg.text(
            f.px(x),
            a.y + a.h + 18.0,
            "bt-tick",
            "middle",
            &format_tick(x, xstep),
        );
    }
    for &y in &yt {
        svg.text(
            a.x - 8.0,
            f.py(y) + 4.0,
            "bt-tick",
            "end",
            &format_tick(y, ystep),
        );
    }
    svg.text(
        a.x + a.w / 2.0,
        a.y + a.h + 38.0,
        "bt-label",
        "middle",
        xlabel,
    );
    svg.text_vertical(a.x - 60.0, a.y + a.h / 2.0, "bt-label", ylabel);
}

/// How a legend entry's sample is drawn.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Swatch {
    /// A short line in the given class.
    Line(&'static str),
    /// A dot in the given class.
    Dot(&'static str),
    /// A circle marker in the given class.
    Marker(&'static str),
}

/// One legend entry.
#[derive(Clone, Debug)]
pub(crate) struct LegendItem {
    pub swatch: Swatch,
    pub label: String,
}

impl LegendItem {
    pub(crate) fn new(swatch: Swatch, label: impl Into<String>) -> LegendItem {
        LegendItem {
            swatch,
            label: label.into(),
        }
    }
}

/// Approximate width of legend text: 6.3 px per character at the legend's font size.
const LEGEND_CHAR_PX: f64 = 6.3;

/// Widths of the legend entries in pixels: swatch, text, gap.
fn legend_widths(items: &[LegendItem]) -> Vec<f64> {
    items
        .iter()
        .map(|it| 30.0 + LEGEND_CHAR_PX * it.label.chars().count() as f64 + 18.0)
        .collect()
}

/// The row each legend entry goes on in a panel occupying `outer`, wrapping full rows.
fn legend_layout(outer: Rect, items: &[LegendItem]) -> Vec<(usize, f64)> {
    let left = outer.x + MARGIN_LEFT;
    let right = outer.x + outer.w - MARGIN_RIGHT;
    let (mut row, mut x) = (0, left);
    legend_widths(items)
        .into_iter()
        .map(|w| {
            if x + w > right && x > left {
                row += 1;
                x = left;
            }
            let at = (row, x);
            x += w;
            at
        })
        .collect()
}

/// How many rows the legend of a panel occupying `outer` takes.
pub(crate) fn legend_rows(outer: Rect, items: &[LegendItem]) -> usize {
    legend_layout(outer, items)
        .last()
        .map_or(0, |&(row, _)| row + 1)
}

/// Draw the legend in rows below the x label of the panel occupying `outer`.
pub(crate) fn legend(svg: &mut Svg, outer: Rect, items: &[LegendItem]) {
    let rows = legend_rows(outer, items);
    let top = outer.y + outer.h - LEGEND_ROW * rows as f64 - 4.0;
    for (it, (row, x)) in items.iter().zip(legend_layout(outer, items)) {
        let y = top + LEGEND_ROW * row as f64 + 8.0;
        let mut d = PathData::new();
        match it.swatch {
            Swatch::Line(class) => {
                d.segment((x, y - 4.0), (x + 24.0, y - 4.0));
                svg.path(&d, class, "legend");
            }
            Swatch::Dot(class) => {
                d.dot(x + 12.0, y - 4.0);
                svg.path(&d, class, "legend");
            }
            // A second class keeps legend markers apart from the markers in the plot.
            Swatch::Marker(class) => svg.circle(x + 12.0, y - 4.0, 4.0, &format!("{class} bt-key")),
        }
        svg.text(x + 30.0, y, "bt-legend", "start", &it.label);
    }
}

/// `x` with three significant digits, for legends: fixed notation for magnitudes in
/// `[1e-3, 1e5)`, exponent notation otherwise.
pub(crate) fn sig3(x: f64) -> String {
    if !x.is_finite() {
        return x.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    // The decade after rounding to three digits (0.09999 is 0.100, not 0.1000).
    let rounded: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    let e = rounded.abs().log10().floor();
    if (-3.0..5.0).contains(&e) {
        let d = (2.0 - e).max(0.0) as usize;
        format!("{x:.d$}")
    } else {
        format!("{x:.2e}")
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_nice() {
        let (t, s) = nice_ticks(Range { lo: 0.0, hi: 10.0 }, 5);
        assert_eq!(s, 2.0);
        assert_eq!(t, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        let (t, s) = nice_ticks(
            Range {
                lo: -0.33,
                hi: 0.71,
            },
            5,
        );
        assert!((s - 0.2).abs() < 1e-15);
        assert_eq!(t.len(), 5);
        assert_eq!(t[1], 0.0);
        let labels: Vec<String> = t.iter().map(|&v| format_tick(v, s)).collect();
        assert_eq!(labels, vec!["-0.2", "0", "0.2", "0.4", "0.6"]);
        let (t, s) = nice_ticks(
            Range {
                lo: 1.0e6,
                hi: 1.6e6,
            },
            4,
        );
        assert_eq!(s, 2e5);
        assert_eq!(format_tick(t[1], s), "1.2e6");
        assert_eq!(format_tick(3e-6, 1e-6), "3e-6");
        assert_eq!(format_tick(25.0, 5.0), "25");
        assert_eq!(sig3(0.012345), "0.0123");
        assert_eq!(sig3(123.45), "123");
        assert_eq!(sig3(2.5e7), "2.50e7");
        assert_eq!(sig3(0.099999), "0.100");
    }

    #[test]
    fn degenerate_ranges_get_a_width() {
        let r = Range { lo: 0.0, hi: 0.0 }.padded(GRAPH_PAD);
        assert_eq!((r.lo, r.hi), (-1.0, 1.0));
        let r = Range { lo: 5.0, hi: 5.0 }.padded(GRAPH_PAD);
        assert_eq!((r.lo, r.hi), (4.5, 5.5));
        assert!(Range::of([f64::NAN]).is_none());
        let r = Range::of([3.0, f64::INFINITY, -1.0]).unwrap();
        assert_eq!((r.lo, r.hi), (-1.0, 3.0));
    }

    #[test]
    fn equal_aspect_keeps_scales_equal() {
        let area = Rect {
            x: 0.0,
            y: 0.0,
            w: 400.0,
            h: 200.0,
        };
        let f = Frame::equal_aspect(area, Range { lo: 0.0, hi: 1.0 }, Range { lo: 0.0, hi: 1.0 });
        let (x0, y0) = f.map(0.0, 0.0);
        let (x1, y1) = f.map(1.0, 1.0);
        assert!(((x1 - x0) - (y0 - y1)).abs() < 1e-9);
        assert!((y0 - y1 - 200.0).abs() < 1e-9);
    }
}
