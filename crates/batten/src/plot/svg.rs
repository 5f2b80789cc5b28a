//! A tiny SVG writer: text escaping, compact numbers, path data.
//!
//! Everything drawn is first mapped to pixels, so coordinates are written with one decimal
//! (a tenth of a pixel), trailing zeros dropped: `12.3`, `40`, `-0.5`. That keeps a path of
//! 4000 vertices near 50 kB.

use std::fmt::Write as _;

/// Coordinates are clamped to ±this many pixels before they are written: far outside any
/// drawing, and small enough that the tenths fit an `i64` exactly.
const COORD_LIMIT: f64 = 1e9;

/// Append `x` rounded to a tenth, without trailing zeros (`-0` written as `0`).
///
/// Callers pass finite values (non-finite points break a path, see [`PathData::line_to`]);
/// a non-finite value that slips through is written as `0` so the document stays valid.
pub(crate) fn push_num(buf: &mut String, x: f64) {
    let x = if x.is_finite() {
        x.clamp(-COORD_LIMIT, COORD_LIMIT)
    } else {
        0.0
    };
    // |x| ≤ 1e9, so the tenths fit an i64 exactly.
    let tenths = (x * 10.0).round() as i64;
    if tenths < 0 {
        buf.push('-');
    }
    let a = tenths.unsigned_abs();
    // Writing to a String cannot fail.
    let _ = write!(buf, "{}", a / 10);
    if !a.is_multiple_of(10) {
        let _ = write!(buf, ".{}", a % 10);
    }
}

/// `x` as [`push_num`] writes it.
pub(crate) fn num(x: f64) -> String {
    let mut s = String::new();
    push_num(&mut s, x);
    s
}

/// `text` with the five XML special characters escaped, and control characters (which XML
/// 1.0 forbids) replaced by spaces.
pub(crate) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c if c.is_control() => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// The `d` attribute of a `<path>`, built from absolute pixel coordinates.
#[derive(Clone, Debug, Default)]
pub(crate) struct PathData {
    d: String,
    /// Whether the pen is down (the last command drew or moved to a finite point).
    open: bool,
}

impl PathData {
    pub(crate) fn new() -> PathData {
        PathData::default()
    }

    /// True when nothing has been added.
    pub(crate) fn is_empty(&self) -> bool {
        self.d.is_empty()
    }

    fn push_xy(&mut self, x: f64, y: f64) {
        push_num(&mut self.d, x);
        self.d.push(' ');
        push_num(&mut self.d, y);
    }

    /// Start a new subpath at `(x, y)`. A non-finite point lifts the pen.
    pub(crate) fn move_to(&mut self, x: f64, y: f64) {
        if !(x.is_finite() && y.is_finite()) {
            self.open = false;
            return;
        }
        self.d.push('M');
        self.push_xy(x, y);
        self.open = true;
    }

    /// A line to `(x, y)`, or a move there when the pen is up. A non-finite point lifts the
    /// pen, so a polyline with gaps is drawn as separate pieces.
    pub(crate) fn line_to(&mut self, x: f64, y: f64) {
        if !self.open {
            self.move_to(x, y);
            return;
        }
        if !(x.is_finite() && y.is_finite()) {
            self.open = false;
            return;
        }
        self.d.push('L');
        self.push_xy(x, y);
    }

    /// A separate segment from `a` to `b` (skipped when either end is not finite).
    pub(crate) fn segment(&mut self, a: (f64, f64), b: (f64, f64)) {
        if a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite() {
            self.move_to(a.0, a.1);
            self.line_to(b.0, b.1);
        }
    }

    /// A zero-length subpath at `(x, y)`: drawn as a dot by a round line cap.
    pub(crate) fn dot(&mut self, x: f64, y: f64) {
        if x.is_finite() && y.is_finite() {
            self.move_to(x, y);
            self.d.push_str("h0");
        }
        self.open = false;
    }

    /// The finished attribute value.
    pub(crate) fn as_str(&self) -> &str {
        &self.d
    }
}

/// The shared style sheet. Class names carry a `bt-` prefix: a style sheet inside an SVG
/// that is inlined in HTML applies to the whole page, so the names must not clash.
const STYLE: &str = "\
text{font-family:sans-serif;fill:#222}\
.bt-title{font-size:15px;font-weight:bold}\
.bt-tick{font-size:11px;fill:#444}\
.bt-label{font-size:12px}\
.bt-legend{font-size:11.5px}\
.bt-note{font-size:11px;fill:#666}\
.bt-frame{fill:none;stroke:#888;stroke-width:1}\
.bt-grid{fill:none;stroke:#e6e6e6;stroke-width:1}\
.bt-zero{fill:none;stroke:#999;stroke-width:1;stroke-dasharray:4 3}\
.bt-curve0{fill:none;stroke:#1f5fa8;stroke-width:1.6;stroke-linejoin:round}\
.bt-curve1{fill:none;stroke:#c8362b;stroke-width:1.6;stroke-linejoin:round}\
.bt-teeth0{fill:none;stroke:#7fa8d6;stroke-width:0.7}\
.bt-teeth1{fill:none;stroke:#e99a92;stroke-width:0.7}\
.bt-env0{fill:none;stroke:#1f5fa8;stroke-width:1;stroke-linejoin:round;opacity:0.8}\
.bt-env1{fill:none;stroke:#c8362b;stroke-width:1;stroke-linejoin:round;opacity:0.8}\
.bt-dots0{fill:none;stroke:#0b2f5a;stroke-width:3.5;stroke-linecap:round}\
.bt-dots1{fill:none;stroke:#7a1c14;stroke-width:3.5;stroke-linecap:round}\
.bt-cap0{fill:none;stroke:#1f5fa8;stroke-width:1.4;stroke-dasharray:2 3;opacity:0.6}\
.bt-cap1{fill:none;stroke:#c8362b;stroke-width:1.4;stroke-dasharray:2 3;opacity:0.6}\
.bt-limit{fill:none;stroke:#b07a00;stroke-width:1;stroke-dasharray:6 4}\
.bt-infl0{fill:#ffd23f;stroke:#1f5fa8;stroke-width:1.5}\
.bt-infl1{fill:#ffd23f;stroke:#c8362b;stroke-width:1.5}\
.bt-disp{fill:none;stroke:#2a9d3a;stroke-width:1.4;stroke-linecap:round}\
.bt-bar{fill:none;stroke:#2a9d3a;stroke-width:1.2}\
.bt-tol{fill:none;stroke:#b07a00;stroke-width:1;stroke-dasharray:6 4}";

/// An SVG document being written.
#[derive(Debug)]
pub(crate) struct Svg {
    buf: String,
}

impl Svg {
    /// A document of `width` × `height` pixels with the style sheet and a white background.
    pub(crate) fn new(width: f64, height: f64) -> Svg {
        let mut buf = String::with_capacity(64 * 1024);
        let (w, h) = (num(width), num(height));
        let _ = write!(
            buf,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\">\n<style>{STYLE}</style>\n\
             <rect x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" fill=\"#fff\"/>\n"
        );
        Svg { buf }
    }

    /// Close the document and return its text.
    pub(crate) fn finish(mut self) -> String {
        self.buf.push_str("</svg>\n");
        self.buf
    }

    /// `<g>` with the given class, for grouping one panel or one series.
    pub(crate) fn group_open(&mut self, class: &str) {
        let _ = writeln!(self.buf, "<g class=\"{}\">", escape(class));
    }

    /// Close the innermost `<g>`.
    pub(crate) fn group_close(&mut self) {
        self.buf.push_str("</g>\n");
    }

    /// A `<path>` with class `class` and a `data-series` name (skipped when empty).
    pub(crate) fn path(&mut self, d: &PathData, class: &str, series: &str) {
        if d.is_empty() {
            return;
        }
        let _ = writeln!(
            self.buf,
            "<path class=\"{class}\" data-series=\"{}\" d=\"{}\"/>",
            escape(series),
            d.as_str()
        );
    }

    /// A `<path>` as [`Svg::path`] with a stroke width overriding the class's.
    pub(crate) fn path_with_width(&mut self, d: &PathData, class: &str, series: &str, width: f64) {
        if d.is_empty() {
            return;
        }
        let _ = writeln!(
            self.buf,
            "<path class=\"{class}\" data-series=\"{}\" style=\"stroke-width:{}\" d=\"{}\"/>",
            escape(series),
            num(width),
            d.as_str()
        );
    }

    /// A `<text>`; `anchor` is `start`, `middle` or `end`.
    pub(crate) fn text(&mut self, x: f64, y: f64, class: &str, anchor: &str, content: &str) {
        let _ = writeln!(
            self.buf,
            "<text class=\"{class}\" x=\"{}\" y=\"{}\" text-anchor=\"{anchor}\">{}</text>",
            num(x),
            num(y),
            escape(content)
        );
    }

    /// A `<text>` rotated by −90° about its anchor (a vertical axis label).
    pub(crate) fn text_vertical(&mut self, x: f64, y: f64, class: &str, content: &str) {
        let (xs, ys) = (num(x), num(y));
        let _ = writeln!(
            self.buf,
            "<text class=\"{class}\" x=\"{xs}\" y=\"{ys}\" text-anchor=\"middle\" \
             transform=\"rotate(-90 {xs} {ys})\">{}</text>",
            escape(content)
        );
    }

    /// A `<rect>`.
    pub(crate) fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, class: &str) {
        let _ = writeln!(
            self.buf,
            "<rect class=\"{class}\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>",
            num(x),
            num(y),
            num(w.max(0.0)),
            num(h.max(0.0))
        );
    }

    /// A `<circle>` (skipped when the centre is not finite).
    pub(crate) fn circle(&mut self, x: f64, y: f64, r: f64, class: &str) {
        if !(x.is_finite() && y.is_finite()) {
            return;
        }
        let _ = writeln!(
            self.buf,
            "<circle class=\"{class}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>",
            num(x),
            num(y),
            num(r)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_compact() {
        assert_eq!(num(12.34), "12.3");
        assert_eq!(num(12.36), "12.4");
        assert_eq!(num(40.0), "40");
        assert_eq!(num(-0.5), "-0.5");
        assert_eq!(num(-0.04), "0");
        assert_eq!(num(-3.0), "-3");
        assert_eq!(num(f64::NAN), "0");
        assert_eq!(num(1e300), "1000000000");
    }

    #[test]
    fn escaping() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\u{7}"),
            "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt; "
        );
    }

    #[test]
    fn path_breaks_at_non_finite_points() {
        let mut p = PathData::new();
        p.line_to(0.0, 0.0);
        p.line_to(1.0, 1.0);
        p.line_to(f64::NAN, 2.0);
        p.line_to(3.0, 3.0);
        p.line_to(4.0, 4.5);
        p.dot(5.0, 5.0);
        p.segment((0.0, 0.0), (f64::INFINITY, 1.0));
        assert_eq!(p.as_str(), "M0 0L1 1M3 3L4 4.5M5 5h0");
    }
}
