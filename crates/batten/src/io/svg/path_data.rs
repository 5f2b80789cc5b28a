//! The SVG path-data mini-language (`d="M 0 0 C 1 2 3 4 5 6 Z"`), parsed into absolute
//! line, quadratic and cubic segments.
//!
//! Follows SVG 2 §9.3 (path data grammar): commands `M L H V C S Q T Z` in upper case
//! (absolute) and lower case (relative to the current point); numbers may be packed
//! (`1-2` is 1 and −2, `.5.5` is 0.5 and 0.5) and separated by white space and at most one
//! comma; extra coordinate pairs after `M` are implicit `L` (after `m`, `l`); other commands
//! repeat with their arguments. `S` and `T` reflect the previous control point when the
//! previous command was of their kind, else use the current point. Elliptical arcs (`A`)
//! are refused: they are not polynomial curves.

use crate::geom::Point;

/// One segment in absolute coordinates. `at` is the byte offset in the path data of the
/// command (or of the repeated arguments) that made it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Seg {
    /// A straight segment.
    Line { p: [Point; 2], at: usize },
    /// A quadratic Bézier.
    Quad { p: [Point; 3], at: usize },
    /// A cubic Bézier.
    Cubic { p: [Point; 4], at: usize },
}

impl Seg {
    /// The end point.
    pub(super) fn end(&self) -> Point {
        match self {
            Seg::Line { p, .. } => p[1],
            Seg::Quad { p, .. } => p[2],
            Seg::Cubic { p, .. } => p[3],
        }
    }

    /// The byte offset of the command in the path data.
    pub(super) fn at(&self) -> usize {
        match self {
            Seg::Line { at, .. } | Seg::Quad { at, .. } | Seg::Cubic { at, .. } => *at,
        }
    }

    /// The same segment as a cubic Bézier (lines and quadratics degree-elevated exactly up
    /// to rounding: `q₁ = p₀ + 2/3 (p₁ − p₀)`, …).
    pub(super) fn to_cubic(self) -> [Point; 4] {
        match self {
            Seg::Line { p, .. } => [
                p[0],
                p[0].lerp(p[1], 1.0 / 3.0),
                p[0].lerp(p[1], 2.0 / 3.0),
                p[1],
            ],
            Seg::Quad { p, .. } => [
                p[0],
                p[0].lerp(p[1], 2.0 / 3.0),
                p[2].lerp(p[1], 2.0 / 3.0),
                p[2],
            ],
            Seg::Cubic { p, .. } => p,
        }
    }

    /// The point at parameter `t ∈ [0, 1]` (de Casteljau).
    pub(super) fn eval(&self, t: f64) -> Point {
        match self {
            Seg::Line { p, .. } => p[0].lerp(p[1], t),
            Seg::Quad { p, .. } => p[0].lerp(p[1], t).lerp(p[1].lerp(p[2], t), t),
            Seg::Cubic { p, .. } => {
                let a = p[0].lerp(p[1], t);
                let b = p[1].lerp(p[2], t);
                let c = p[2].lerp(p[3], t);
                a.lerp(b, t).lerp(b.lerp(c, t), t)
            }
        }
    }
}

/// One subpath: a start point, its segments, and whether `Z` closed it. When the current
/// point was away from the start, `Z` added the closing line as a segment.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Subpath {
    pub start: Point,
    /// Byte offset of the `M` that started the subpath.
    pub at: usize,
    pub segs: Vec<Seg>,
    pub closed: bool,
}

/// A problem in path data, at a byte offset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct PathError {
    pub at: usize,
    pub message: String,
}

fn err<T>(at: usize, message: impl Into<String>) -> Result<T, PathError> {
    Err(PathError {
        at,
        message: message.into(),
    })
}

struct Lexer<'a> {
    s: &'a [u8],
    i: usize,
}

impl Lexer<'_> {
    fn skip_ws(&mut self) {
        while self.i < self.s.len()
            && matches!(self.s[self.i], b' ' | b'\t' | b'\n' | b'\r' | b'\x0c')
        {
            self.i += 1;
        }
    }

    /// Skip white space and at most one comma.
    fn skip_sep(&mut self) {
        self.skip_ws();
        if self.i < self.s.len() && self.s[self.i] == b',' {
            self.i += 1;
            self.skip_ws();
        }
    }

    /// Whether a number starts here (after separators).
    fn number_follows(&mut self) -> bool {
        self.skip_sep();
        self.i < self.s.len() && matches!(self.s[self.i], b'0'..=b'9' | b'.' | b'-' | b'+')
    }

    /// One number: `[+-]? (digits ('.' digits?)? | '.' digits) ([eE] [+-]? digits)?`.
    fn number(&mut self, what: &str) -> Result<f64, PathError> {
        self.skip_sep();
        let start = self.i;
        let s = self.s;
        let mut j = self.i;
        if j < s.len() && matches!(s[j], b'+' | b'-') {
            j += 1;
        }
        let int_start = j;
        while j < s.len() && s[j].is_ascii_digit() {
            j += 1;
        }
        let mut digits = j - int_start;
        if j < s.len() && s[j] == b'.' {
            j += 1;
            let f = j;
            while j < s.len() && s[j].is_ascii_digit() {
                j += 1;
            }
            digits += j - f;
        }
        if digits == 0 {
            let found = match s.get(start) {
                None => "the end of the path data".to_string(),
                Some(&c) => format!("'{}'", char::from(c).escape_debug()),
            };
            return err(start, format!("expected a number ({what}), found {found}"));
        }
        if j < s.len() && matches!(s[j], b'e' | b'E') {
            let mut k = j + 1;
            if k < s.len() && matches!(s[k], b'+' | b'-') {
                k += 1;
            }
            let e = k;
            while k < s.len() && s[k].is_ascii_digit() {
                k += 1;
            }
            if k > e {
                j = k;
            }
        }
        // The slice is ASCII by construction.
        let text = std::str::from_utf8(&s[start..j]).unwrap_or("");
        let v: f64 = match text.parse() {
            Ok(v) => v,
            Err(_) => return err(start, format!("'{text}' is not a number")),
        };
        if !v.is_finite() {
            return err(start, format!("'{text}' is too large"));
        }
        self.i = j;
        Ok(v)
    }

    fn pair(&mut self, what: &str) -> Result<Point, PathError> {
        let x = self.number(what)?;
        let y = self.number(what)?;
        Ok(Point::new(x, y))
    }
}

/// Parse path data into subpaths.
///
/// # Errors
/// A [`PathError`] at the offending byte: an unknown command, a missing or malformed
/// number, data that does not start with `M`, an arc.
pub(crate) fn parse(d: &str) -> Result<Vec<Subpath>, PathError> {
    let mut pp = PathParser {
        d,
        lx: Lexer {
            s: d.as_bytes(),
            i: 0,
        },
        subpaths: Vec::new(),
        cur: Point::new(0.0, 0.0),
        last_cubic_ctrl: None,
        last_quad_ctrl: None,
        cmd: None,
    };
    loop {
        pp.lx.skip_ws();
        if pp.lx.i >= pp.lx.s.len() {
            break;
        }
        let at = pp.lx.i;
        let command = pp.command(at)?;
        if pp.subpaths.is_empty() && !matches!(command, b'M' | b'm') {
            return err(at, "path data must start with M (moveto)");
        }
        let seg = pp.segment(command, at)?;
        pp.last_cubic_ctrl = None;
        pp.last_quad_ctrl = None;
        if let Some(s) = seg {
            pp.push(s, at);
        }
        pp.cmd = Some(command);
        // Arguments may repeat: keep the command for a following number.
        if matches!(command, b'Z' | b'z') {
            pp.lx.skip_ws();
            if pp.lx.number_follows() {
                return err(pp.lx.i, "closepath (Z) takes no numbers");
            }
        }
    }
    if pp.subpaths.is_empty() {
        return err(0, "empty path data");
    }
    Ok(pp.subpaths)
}

/// The state of [`parse`] between commands.
struct PathParser<'a> {
    d: &'a str,
    lx: Lexer<'a>,
    subpaths: Vec<Subpath>,
    cur: Point,
    /// The reflected control point for S (cubic) and T (quadratic).
    last_cubic_ctrl: Option<Point>,
    last_quad_ctrl: Option<Point>,
    cmd: Option<u8>,
}

impl PathParser<'_> {
    /// The command at `at`: its letter, or the previous command repeated before a number.
    fn command(&mut self, at: usize) -> Result<u8, PathError> {
        let c = self.lx.s[at];
        Ok(if c.is_ascii_alphabetic() {
            self.lx.i += 1;
            c
        } else {
            match self.cmd {
                // Repeated arguments: M becomes L, Z takes none.
                Some(b'M') => b'L',
                Some(b'm') => b'l',
                Some(b'Z' | b'z') | None => {
                    let c = char::from_u32(self.d[at..].chars().next().map_or(0, u32::from))
                        .unwrap_or('?');
                    return err(
                        at,
                        format!("expected a command letter, found '{}'", c.escape_debug()),
                    );
                }
                Some(k) => k,
            }
        })
    }

    /// Read the arguments of `command` (at `at`): the segment it draws, if any (M and Z
    /// change the subpaths themselves).
    fn segment(&mut self, command: u8, at: usize) -> Result<Option<Seg>, PathError> {
        let cur = self.cur;
        let lx = &mut self.lx;
        let rel = command.is_ascii_lowercase();
        // Relative coordinates are offsets from the current point; absolute ones are taken
        // as written (not added to the origin, which would turn −0 into +0).
        let base = |cur: Point| rel.then_some(cur);
        let off = |b: Option<Point>, q: Point| b.map_or(q, |b| Point::new(b.x + q.x, b.y + q.y));
        let mut seg: Option<Seg> = None;
        match command.to_ascii_uppercase() {
            b'M' => {
                let p = off(base(cur), lx.pair("moveto x, y")?);
                self.cur = p;
                self.subpaths.push(Subpath {
                    start: p,
                    at,
                    segs: Vec::new(),
                    closed: false,
                });
            }
            b'L' => {
                let p = off(base(cur), lx.pair("lineto x, y")?);
                seg = Some(Seg::Line { p: [cur, p], at });
            }
            b'H' => {
                let x = lx.number("horizontal lineto x")?;
                let p = Point::new(if rel { cur.x + x } else { x }, cur.y);
                seg = Some(Seg::Line { p: [cur, p], at });
            }
            b'V' => {
                let y = lx.number("vertical lineto y")?;
                let p = Point::new(cur.x, if rel { cur.y + y } else { y });
                seg = Some(Seg::Line { p: [cur, p], at });
            }
            b'C' => {
                let b = base(cur);
                let c1 = off(b, lx.pair("curveto x1, y1")?);
                let c2 = off(b, lx.pair("curveto x2, y2")?);
                let p = off(b, lx.pair("curveto x, y")?);
                seg = Some(Seg::Cubic {
                    p: [cur, c1, c2, p],
                    at,
                });
            }
            b'S' => {
                let b = base(cur);
                let c1 = self
                    .last_cubic_ctrl
                    .map_or(cur, |q| Point::new(2.0 * cur.x - q.x, 2.0 * cur.y - q.y));
                let c2 = off(b, lx.pair("smooth curveto x2, y2")?);
                let p = off(b, lx.pair("smooth curveto x, y")?);
                seg = Some(Seg::Cubic {
                    p: [cur, c1, c2, p],
                    at,
                });
            }
            b'Q' => {
                let b = base(cur);
                let c1 = off(b, lx.pair("quadratic curveto x1, y1")?);
                let p = off(b, lx.pair("quadratic curveto x, y")?);
                seg = Some(Seg::Quad {
                    p: [cur, c1, p],
                    at,
                });
            }
            b'T' => {
                let c1 = self
                    .last_quad_ctrl
                    .map_or(cur, |q| Point::new(2.0 * cur.x - q.x, 2.0 * cur.y - q.y));
                let p = off(base(cur), lx.pair("smooth quadratic curveto x, y")?);
                seg = Some(Seg::Quad {
                    p: [cur, c1, p],
                    at,
                });
            }
            b'Z' => self.close(at),
            b'A' => {
                return err(
                    at,
                    "elliptical arcs (A) are not supported: convert them to Bézier curves in your editor",
                );
            }
            _ => {
                return err(
                    at,
                    format!(
                        "unknown path command '{}'",
                        char::from(command).escape_debug()
                    ),
                );
            }
        }
        Ok(seg)
    }

    /// Z: close the current subpath (with a line back to its start when not there) and move
    /// to its start.
    fn close(&mut self, at: usize) {
        let cur = self.cur;
        // `if let` on the last subpath: one exists (checked above).
        if let Some(sp) = self.subpaths.last_mut() {
            if cur != sp.start {
                sp.segs.push(Seg::Line {
                    p: [cur, sp.start],
                    at,
                });
            }
            sp.closed = true;
            self.cur = sp.start;
        }
    }

    /// Add a drawn segment to the current subpath (or to a new one after Z) and move on to
    /// its end.
    fn push(&mut self, s: Seg, at: usize) {
        match s {
            Seg::Cubic { p, .. } => self.last_cubic_ctrl = Some(p[2]),
            Seg::Quad { p, .. } => self.last_quad_ctrl = Some(p[1]),
            Seg::Line { .. } => {}
        }
        self.cur = s.end();
        if let Some(sp) = self.subpaths.last_mut() {
            if sp.closed {
                // Drawing on after Z starts a new subpath at the same start point.
                let start = sp.start;
                self.subpaths.push(Subpath {
                    start,
                    at,
                    segs: vec![s],
                    closed: false,
                });
            } else {
                sp.segs.push(s);
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn pt(x: f64, y: f64) -> Point {
        Point::new(x, y)
    }

    fn one(d: &str) -> Subpath {
        let mut v = parse(d).unwrap();
        assert_eq!(v.len(), 1, "{d}");
        v.remove(0)
    }

    fn ends(sp: &Subpath) -> Vec<Point> {
        sp.segs.iter().map(Seg::end).collect()
    }

    #[test]
    fn lines_absolute_relative_and_implicit() {
        let sp = one("M1,2 L3 4 5 6 H7 V8 h-1 v-1 l1-1z");
        assert_eq!(sp.start, pt(1.0, 2.0));
        assert_eq!(
            ends(&sp),
            vec![
                pt(3.0, 4.0),
                pt(5.0, 6.0),
                pt(7.0, 6.0),
                pt(7.0, 8.0),
                pt(6.0, 8.0),
                pt(6.0, 7.0),
                pt(7.0, 6.0),
                pt(1.0, 2.0),
            ]
        );
        assert!(sp.closed);
        // m with several pairs: the rest are relative lineto.
        let sp = one("m 10 10 1 0 0 1");
        assert_eq!(sp.start, pt(10.0, 10.0));
        assert_eq!(ends(&sp), vec![pt(11.0, 10.0), pt(11.0, 11.0)]);
        // M with several pairs: absolute lineto.
        let sp = one("M 10 10 1 0 0 1");
        assert_eq!(ends(&sp), vec![pt(1.0, 0.0), pt(0.0, 1.0)]);
    }

    #[test]
    fn packed_numbers() {
        let sp = one("M.5.5L-1-2e1 1E+1,+3 L 1e-2.5");
        assert_eq!(sp.start, pt(0.5, 0.5));
        assert_eq!(
            ends(&sp),
            vec![pt(-1.0, -20.0), pt(10.0, 3.0), pt(0.01, 0.5)]
        );
    }

    #[test]
    fn curves_and_reflections() {
        let sp = one("M0 0 C1 1 2 1 3 0 S5 -1 6 0 s1 1 2 0");
        let Seg::Cubic { p, .. } = sp.segs[1] else {
            panic!()
        };
        // Reflection of (2, 1) about (3, 0).
        assert_eq!(
            p,
            [pt(3.0, 0.0), pt(4.0, -1.0), pt(5.0, -1.0), pt(6.0, 0.0)]
        );
        let Seg::Cubic { p, .. } = sp.segs[2] else {
            panic!()
        };
        assert_eq!(p, [pt(6.0, 0.0), pt(7.0, 1.0), pt(7.0, 1.0), pt(8.0, 0.0)]);
        // S after a non-cubic: the first control point is the current point.
        let sp = one("M0 0 L1 0 S2 1 3 0");
        let Seg::Cubic { p, .. } = sp.segs[1] else {
            panic!()
        };
        assert_eq!(p[1], pt(1.0, 0.0));
        let sp = one("M0 0 Q1 2 2 0 T4 0 t2 0");
        let Seg::Quad { p, .. } = sp.segs[1] else {
            panic!()
        };
        assert_eq!(p, [pt(2.0, 0.0), pt(3.0, -2.0), pt(4.0, 0.0)]);
        let Seg::Quad { p, .. } = sp.segs[2] else {
            panic!()
        };
        assert_eq!(p, [pt(4.0, 0.0), pt(5.0, 2.0), pt(6.0, 0.0)]);
        let sp = one("M1 1 q1 1 2 0 c1 0 1 1 0 1");
        assert_eq!(sp.segs[0].end(), pt(3.0, 1.0));
        let Seg::Cubic { p, .. } = sp.segs[1] else {
            panic!()
        };
        assert_eq!(p, [pt(3.0, 1.0), pt(4.0, 1.0), pt(4.0, 2.0), pt(3.0, 2.0)]);
    }

    #[test]
    fn elevation_and_evaluation_agree() {
        let segs = [
            Seg::Line {
                p: [pt(0.0, 0.0), pt(3.0, 6.0)],
                at: 0,
            },
            Seg::Quad {
                p: [pt(0.0, 0.0), pt(1.0, 2.0), pt(2.0, 0.0)],
                at: 0,
            },
        ];
        for s in segs {
            let c = Seg::Cubic {
                p: s.to_cubic(),
                at: 0,
            };
            for i in 0..=10 {
                let t = f64::from(i) / 10.0;
                assert!(s.eval(t).distance(c.eval(t)) < 1e-15, "{s:?} at {t}");
            }
        }
    }

    #[test]
    fn subpaths_and_close() {
        let v = parse("M0 0 L1 0 L1 1 Z M5 5 L6 6").unwrap();
        assert_eq!(v.len(), 2);
        assert!(v[0].closed);
        assert_eq!(v[0].segs.len(), 3);
        assert_eq!(v[1].start, pt(5.0, 5.0));
        // Z at the start point adds no segment.
        let sp = one("M0 0 L1 0 L0 0 Z");
        assert_eq!(sp.segs.len(), 2);
        // Drawing on after Z starts a new subpath from the start point.
        let v = parse("M0 0 L1 0 L1 1 Z L2 2").unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!(
            v[1].segs[0],
            Seg::Line {
                p: [pt(0.0, 0.0), pt(2.0, 2.0)],
                at: 17
            }
        );
    }

    #[test]
    fn errors_name_the_place() {
        let e = |d: &str| parse(d).unwrap_err();
        assert_eq!(e("L1 1").message, "path data must start with M (moveto)");
        assert_eq!(e("").message, "empty path data");
        let x = e("M0 0 L1");
        assert_eq!(x.at, 7);
        assert_eq!(
            x.message,
            "expected a number (lineto x, y), found the end of the path data"
        );
        let x = e("M0 0 L1 x");
        assert_eq!(
            (x.at, x.message.as_str()),
            (8, "expected a number (lineto x, y), found 'x'")
        );
        let x = e("M0 0 A1 1 0 0 1 2 2");
        assert_eq!(x.at, 5);
        assert!(
            x.message
                .starts_with("elliptical arcs (A) are not supported")
        );
        let x = e("M0 0 K1 1");
        assert_eq!((x.at, x.message.as_str()), (5, "unknown path command 'K'"));
        assert_eq!(e("M0 0 Z 1 1").message, "closepath (Z) takes no numbers");
        assert_eq!(e("M0 0 1e999 0").message, "'1e999' is too large");
        assert_eq!(
            e("M0 0 L1,,2").message,
            "expected a number (lineto x, y), found ','"
        );
        assert_eq!(
            e("M0 0 L. 2").message,
            "expected a number (lineto x, y), found '.'"
        );
    }
}
