//! IGES (`.igs`, `.iges`; fixed-form ASCII, IGES 5.3).
//!
//! An IGES file is a sequence of 80-column records: columns 1–72 hold data, column 73 the
//! section letter (`S` start, `G` global, `D` directory entry, `P` parameter data, `T`
//! terminate) and columns 74–80 the record's sequence number within its section. The global
//! section starts with the parameter and record delimiters (default `,` and `;`, else given
//! as Hollerith strings `1H,`). Every entity has two directory records of nine 8-column
//! fields (type, pointer to its first parameter record, …, level, view, transformation
//! matrix, …, status; then type, line weight, colour, parameter record count, form, …) and
//! parameter records with data in columns 1–64 and a pointer back to the directory entry in
//! 66–72. Strings are Hollerith (`5Hhello`); reals may use `D` or `E` exponents.
//!
//! Read: entity 126 (rational B-spline curve: K, M, PROP1–4, knots, weights, control points,
//! V(0), V(1), normal) as a B-spline (without weights when PROP3 says polynomial or all
//! weights are equal), and entity 106 (copious data) forms 1, 2, 11, 12 and 63 (closed) as
//! points: planar when every z is the same, else a space curve (closed when its last point
//! repeats its first). Only independent entities count (subordinate switch 00 or 02);
//! entities with a transformation matrix are refused, as are 126 entities whose z varies (a
//! 3-D B-spline) and 126 entities that use part of their parameter range. Which one:
//! [`Pick::entity`] names the directory entry (its sequence number), [`Pick::layer`] the
//! level; otherwise the only curve of the file.
//!
//! Write: a B-spline as entity 126, points as entity 106 form 11 (63 when closed), both at
//! the origin's z, space points as entity 106 form 12 (x, y, z triples; a closed curve's
//! first point repeated at the end), in millimetres. Reals are written as the shortest decimal that reads
//! back bit for bit (`1.0D-1`), so a file batten writes reads back exactly.

use std::fmt::Write as _;

use std::path::Path;

use super::{IoError, Location, Origin, Pick, Raw};
use crate::geom::Point;
use crate::spline::{BSplineCurve, KnotVector};

/// Columns of a record.
const RECORD: usize = 80;
/// Data columns of S, G and D records.
const DATA: usize = 72;
/// Data columns of P records.
const P_DATA: usize = 64;
/// Relative tolerance (of the knot domain's length) within which V(0), V(1) of entity 126
/// count as its whole domain: they are printed decimals of the end knots.
const PARAM_RANGE_REL: f64 = 1e-9;
/// IGES 5.3 version flag of the global section.
const IGES_VERSION: i64 = 11;
/// Units flag of written files: millimetres.
const UNITS_MM: i64 = 2;

fn err(path: &Path, line: usize, message: impl Into<String>) -> IoError {
    IoError::Format {
        path: path.to_path_buf(),
        at: if line == 0 {
            Location::File
        } else {
            Location::Line(line)
        },
        message: message.into(),
    }
}

/// One record: its text (padded to 80 columns) and its 1-based line in the file.
struct Rec {
    text: Vec<u8>,
    line: usize,
}

/// One directory entry.
struct Dir {
    /// Sequence number of its first D record (its "DE pointer").
    de: usize,
    line: usize,
    kind: i64,
    param: usize,
    level: i64,
    matrix: i64,
    status: String,
    param_count: usize,
    form: i64,
}

/// Split the file into records by section.
fn records(bytes: &[u8], path: &Path) -> Result<[Vec<Rec>; 5], IoError> {
    let mut secs: [Vec<Rec>; 5] = Default::default();
    let lines: Vec<&[u8]> = if !bytes.contains(&b'\n') && bytes.len().is_multiple_of(RECORD) {
        bytes.chunks(RECORD).collect()
    } else {
        bytes.split(|&b| b == b'\n').collect()
    };
    for (i, raw) in lines.iter().enumerate() {
        let line = i + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        if raw.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        if raw.len() > RECORD {
            return Err(err(
                path,
                line,
                format!("record of {} columns; IGES records have 80", raw.len()),
            ));
        }
        if raw.len() < DATA + 1 {
            return Err(err(
                path,
                line,
                "record too short for a section letter in column 73 (not a fixed-form IGES file?)",
            ));
        }
        let mut text = raw.to_vec();
        text.resize(RECORD, b' ');
        let idx = match text[DATA] {
            b'S' => 0,
            b'G' => 1,
            b'D' => 2,
            b'P' => 3,
            b'T' => 4,
            b'C' => {
                return Err(err(
                    path,
                    line,
                    "compressed IGES (section C) is not supported",
                ));
            }
            c => {
                return Err(err(
                    path,
                    line,
                    format!(
                        "unknown section letter '{}' in column 73",
                        char::from(c).escape_debug()
                    ),
                ));
            }
        };
        secs[idx].push(Rec { text, line });
    }
    if secs[1].is_empty() || secs[2].is_empty() {
        return Err(err(
            path,
            0,
            "no global (G) or directory (D) section: not an IGES file",
        ));
    }
    Ok(secs)
}

/// Split free-format parameter data into tokens, up to the record delimiter. Hollerith
/// strings (`3Habc`) are one token holding their text; other tokens are trimmed.
fn tokens(data: &[u8], pd: u8, rd: u8) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        while i < data.len() && data[i] == b' ' {
            i += 1;
        }
        let start = i;
        let mut j = i;
        while j < data.len() && data[j].is_ascii_digit() {
            j += 1;
        }
        if j > start && j < data.len() && data[j] == b'H' {
            let n: usize = std::str::from_utf8(&data[start..j])
                .ok()
                .and_then(|s| s.parse().ok())
                .ok_or("bad Hollerith length")?;
            let end = j + 1 + n;
            if end > data.len() {
                return Err(format!(
                    "Hollerith string of {n} characters runs past the data"
                ));
            }
            out.push(String::from_utf8_lossy(&data[j + 1..end]).into_owned());
            i = end;
            while i < data.len() && data[i] == b' ' {
                i += 1;
            }
        } else {
            while i < data.len() && data[i] != pd && data[i] != rd {
                i += 1;
            }
            out.push(String::from_utf8_lossy(&data[start..i]).trim().to_string());
        }
        match data.get(i) {
            Some(&c) if c == pd => i += 1,
            Some(&c) if c == rd => return Ok(out),
            Some(&c) => {
                return Err(format!(
                    "expected a delimiter, found '{}'",
                    char::from(c).escape_debug()
                ));
            }
            None => return Err("the record delimiter is missing".into()),
        }
    }
}

fn int(tok: &str) -> Option<i64> {
    if tok.is_empty() {
        return Some(0);
    }
    tok.parse().ok()
}

fn real(tok: &str) -> Option<f64> {
    if tok.is_empty() {
        return Some(0.0);
    }
    let t = tok.replace(['D', 'd'], "e");
    t.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// The parameter and record delimiters of the global section.
fn delimiters(g: &[u8]) -> Result<(u8, u8), String> {
    let mut pd = b',';
    let mut i = 0;
    if g.starts_with(b"1H") && g.len() > 2 {
        pd = g[2];
        i = 3;
    }
    // After parameter 1 comes the parameter delimiter, then parameter 2.
    if g.get(i) == Some(&pd) {
        i += 1;
    }
    let rest = &g[i..];
    let rd = if rest.starts_with(b"1H") && rest.len() > 2 {
        rest[2]
    } else {
        b';'
    };
    if pd == rd {
        return Err("the parameter and record delimiters are the same".into());
    }
    Ok((pd, rd))
}

fn field(rec: &Rec, k: usize) -> &str {
    std::str::from_utf8(&rec.text[8 * k..8 * k + 8])
        .unwrap_or("")
        .trim()
}

/// Read the picked curve of an IGES file.
pub(crate) fn parse(bytes: &[u8], path: &Path, pick: &Pick) -> Result<(Raw, Origin), IoError> {
    let [_, g, d, p, _] = records(bytes, path)?;
    let gdata: Vec<u8> = g.iter().flat_map(|r| r.text[..DATA].to_vec()).collect();
    let (pd, rd) =
        delimiters(&gdata).map_err(|m| err(path, g[0].line, format!("global section: {m}")))?;
    let dirs = directory(&d, path)?;
    let e = choose(&dirs, pick, path)?;
    let params = Params::of(e, &p, pd, rd, path)?;
    let origin = Origin {
        z: 0.0,
        layer: Some(e.level.to_string()),
        name: Some(e.de.to_string()),
    };
    if e.kind == 106 {
        return copious_data(e, &params, origin);
    }
    b_spline(&params, origin)
}

/// The directory entries, two D records each.
fn directory(d: &[Rec], path: &Path) -> Result<Vec<Dir>, IoError> {
    if d.len() % 2 == 1 {
        return Err(err(
            path,
            d[d.len() - 1].line,
            "odd number of directory (D) records",
        ));
    }
    let mut dirs = Vec::with_capacity(d.len() / 2);
    for (k, pair) in d.chunks(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let bad = |rec: &Rec, f: usize| {
            err(
                path,
                rec.line,
                format!(
                    "directory entry {}: field {} '{}' is not an integer",
                    2 * k + 1,
                    f,
                    field(rec, (f - 1) % 9)
                ),
            )
        };
        let geti = |rec: &Rec, f: usize| int(field(rec, (f - 1) % 9)).ok_or_else(|| bad(rec, f));
        dirs.push(Dir {
            de: 2 * k + 1,
            line: a.line,
            kind: geti(a, 1)?,
            param: usize::try_from(geti(a, 2)?).unwrap_or(0),
            level: geti(a, 5)?,
            matrix: geti(a, 7)?,
            status: field(a, 8).to_string(),
            param_count: usize::try_from(geti(b, 13)?).unwrap_or(0),
            form: geti(b, 14)?,
        });
    }
    Ok(dirs)
}

/// Whether a directory entry is a curve batten reads: an independent entity 126, or 106 of
/// a form that holds a curve.
fn is_curve(e: &Dir) -> bool {
    let sub = e.status.get(2..4).unwrap_or("00");
    let independent = matches!(sub, "00" | "02" | "" | "0");
    independent && (e.kind == 126 || (e.kind == 106 && matches!(e.form, 1 | 2 | 11 | 12 | 63)))
}

/// A directory entry as messages name it.
fn describe(e: &Dir) -> String {
    format!(
        "entity {} form {} at DE {} (level {})",
        e.kind, e.form, e.de, e.level
    )
}

/// Directory entries as messages list them.
fn list(v: &[&Dir]) -> String {
    if v.is_empty() {
        "none".to_string()
    } else {
        v.iter().map(|e| describe(e)).collect::<Vec<_>>().join(", ")
    }
}

/// The one curve entity `pick` leaves, or why there is none.
fn choose<'d>(dirs: &'d [Dir], pick: &Pick, path: &Path) -> Result<&'d Dir, IoError> {
    let all: Vec<&Dir> = dirs.iter().filter(|e| is_curve(e)).collect();
    let mut chosen = all.clone();
    if let Some(de) = &pick.entity {
        let want = de
            .trim()
            .trim_start_matches(['D', 'd'])
            .parse::<usize>()
            .ok();
        chosen.retain(|e| Some(e.de) == want);
        if chosen.is_empty() {
            return Err(err(
                path,
                0,
                format!(
                    "no curve entity at directory entry {de} (curve entities: {})",
                    list(&all)
                ),
            ));
        }
    }
    if let Some(level) = &pick.layer {
        let want = level.trim().parse::<i64>().ok();
        chosen.retain(|e| Some(e.level) == want);
        if chosen.is_empty() {
            return Err(err(
                path,
                0,
                format!(
                    "no curve entity on level {level} (curve entities: {})",
                    list(&all)
                ),
            ));
        }
    }
    match chosen.as_slice() {
        [] => Err(err(
            path,
            0,
            "no entity 126 (B-spline curve) or 106 (copious data, forms 1, 2, 11, 12, 63)",
        )),
        [e] => Ok(*e),
        many => Err(err(
            path,
            0,
            format!(
                "{} curve entities, pick one with --entity DE or --layer LEVEL: {}",
                many.len(),
                list(many)
            ),
        )),
    }
}

/// The parameter data of the chosen entity, as tokens, with what names it in messages.
struct Params<'a> {
    toks: Vec<String>,
    /// The entity as [`describe`] names it.
    what: String,
    /// The line of its first P record.
    pline: usize,
    path: &'a Path,
}

impl<'a> Params<'a> {
    /// The entity's parameter data, checked to be where the directory says and to start
    /// with the entity's type.
    fn of(e: &Dir, p: &[Rec], pd: u8, rd: u8, path: &'a Path) -> Result<Params<'a>, IoError> {
        let what = describe(e);
        if e.matrix != 0 {
            return Err(err(
                path,
                e.line,
                format!(
                    "{what} has a transformation matrix (DE {}), which batten does not apply",
                    e.matrix
                ),
            ));
        }
        if e.param == 0 || e.param > p.len() || e.param - 1 + e.param_count.max(1) > p.len() {
            return Err(err(
                path,
                e.line,
                format!(
                    "{what}: its parameter data pointer {} (with {} records) is outside the P section of {} records",
                    e.param,
                    e.param_count,
                    p.len()
                ),
            ));
        }
        let recs = &p[e.param - 1..e.param - 1 + e.param_count.max(1)];
        let data: Vec<u8> = recs
            .iter()
            .flat_map(|r| r.text[..P_DATA].to_vec())
            .collect();
        let pline = recs[0].line;
        let toks = tokens(&data, pd, rd).map_err(|m| err(path, pline, format!("{what}: {m}")))?;
        let params = Params {
            toks,
            what,
            pline,
            path,
        };
        if params.int(0)? != e.kind {
            return Err(params.fail(format!(
                "its parameter data starts with entity type '{}'",
                params.toks.first().map_or("", String::as_str)
            )));
        }
        Ok(params)
    }

    /// An error about the entity's parameter data.
    fn fail(&self, m: String) -> IoError {
        err(self.path, self.pline, format!("{}: {m}", self.what))
    }

    /// Parameter `i` as an integer.
    fn int(&self, i: usize) -> Result<i64, IoError> {
        let t = self
            .toks
            .get(i)
            .ok_or_else(|| self.fail(format!("{} parameters, more expected", self.toks.len())))?;
        int(t).ok_or_else(|| self.fail(format!("parameter {i} '{t}' is not an integer")))
    }

    /// Parameter `i` as a finite real.
    fn real(&self, i: usize) -> Result<f64, IoError> {
        let t = self
            .toks
            .get(i)
            .ok_or_else(|| self.fail(format!("{} parameters, more expected", self.toks.len())))?;
        real(t).ok_or_else(|| self.fail(format!("parameter {i} '{t}' is not a finite real")))
    }
}

/// The constant z, or the first two values that differ.
fn planar(zs: &[f64]) -> Result<f64, (f64, f64)> {
    match zs.iter().find(|&&z| z != zs[0]) {
        Some(&z) => Err((zs[0], z)),
        None => Ok(zs.first().copied().unwrap_or(0.0)),
    }
}

/// Entity 106: planar points, or space points when z varies.
fn copious_data(e: &Dir, params: &Params<'_>, origin: Origin) -> Result<(Raw, Origin), IoError> {
    let (ti, tr) = (|i| params.int(i), |i| params.real(i));
    let pline = params.pline;
    let ip = ti(1)?;
    let n = usize::try_from(ti(2)?).map_err(|_| params.fail("negative point count".into()))?;
    let (first, stride, zs) = match ip {
        1 => (4, 2, None),
        2 => (3, 3, Some(2)),
        3 => (3, 6, Some(2)),
        _ => {
            return Err(params.fail(format!("interpretation flag {ip}, expected 1, 2 or 3")));
        }
    };
    let mut points = Vec::with_capacity(n);
    let mut z = Vec::with_capacity(n);
    for i in 0..n {
        let b = first + stride * i;
        points.push(Point::new(tr(b)?, tr(b + 1)?));
        z.push(match zs {
            Some(o) => tr(b + o)?,
            None => tr(3)?,
        });
    }
    let z = match planar(&z) {
        Ok(z) => z,
        Err(_) => {
            let mut points: Vec<[f64; 3]> =
                points.iter().zip(&z).map(|(p, z)| [p.x, p.y, *z]).collect();
            // A copious-data curve that returns to its start is closed.
            let closed = points.len() > 1 && points.last() == points.first();
            if closed {
                points.pop();
            }
            let lines = vec![pline; points.len()];
            return Ok((
                Raw::Space {
                    points,
                    lines,
                    closed,
                },
                origin,
            ));
        }
    };
    let closed = e.form == 63;
    if closed && points.len() > 1 && points.last() == points.first() {
        points.pop();
    }
    let lines = vec![pline; points.len()];
    Ok((
        Raw::Points {
            points,
            lines,
            closed,
        },
        Origin { z, ..origin },
    ))
}

/// Entity 126: a planar, untrimmed B-spline.
fn b_spline(params: &Params<'_>, origin: Origin) -> Result<(Raw, Origin), IoError> {
    let (ti, tr) = (|i| params.int(i), |i| params.real(i));
    let fail = |m: String| params.fail(m);
    let toks = &params.toks;
    let k = usize::try_from(ti(1)?).map_err(|_| fail("negative K".into()))?;
    let m = usize::try_from(ti(2)?).map_err(|_| fail("negative degree M".into()))?;
    let polynomial = ti(5)? == 1;
    let nk = k + m + 2;
    let kb = 7;
    let wb = kb + nk;
    let cb = wb + k + 1;
    let vb = cb + 3 * (k + 1);
    if toks.len() < vb + 2 {
        return Err(fail(format!(
            "{} parameters; K = {k}, M = {m} need at least {}",
            toks.len(),
            vb + 2
        )));
    }
    let knots = (0..nk).map(|i| tr(kb + i)).collect::<Result<Vec<_>, _>>()?;
    let weights = (0..=k).map(|i| tr(wb + i)).collect::<Result<Vec<_>, _>>()?;
    let mut ctrl = Vec::with_capacity(k + 1);
    let mut z = Vec::with_capacity(k + 1);
    for i in 0..=k {
        ctrl.push(Point::new(tr(cb + 3 * i)?, tr(cb + 3 * i + 1)?));
        z.push(tr(cb + 3 * i + 2)?);
    }
    let z = planar(&z).map_err(|(a, b)| {
        fail(format!(
            "z varies ({a} and {b}): a 3-D B-spline is not taken (3-D copious data, entity 106, \
             is, as a space curve)"
        ))
    })?;
    let (v0, v1) = (tr(vb)?, tr(vb + 1)?);
    let weights = if polynomial || weights.iter().all(|&w| w == weights[0]) {
        None
    } else {
        Some(weights)
    };
    let curve = KnotVector::try_new(knots)
        .and_then(|kv| BSplineCurve::try_new(m, kv, ctrl, weights))
        .map_err(|e| fail(e.to_string()))?;
    let u = curve.knots().as_slice();
    let (a, b) = (u[m], u[k + 1]);
    let slack = PARAM_RANGE_REL * (b - a);
    if v0 > a + slack || v1 < b - slack {
        return Err(fail(format!(
            "it uses the parameters [{v0}, {v1}] of its domain [{a}, {b}]; trimmed curves are not supported"
        )));
    }
    Ok((Raw::Curve(curve), Origin { z, ..origin }))
}

/// A real in the shortest form that reads back bit for bit, with a decimal point and a `D`
/// exponent: `1.0D-1`, `-2.5D3`, `0.0D0`.
pub(crate) fn real_str(x: f64) -> String {
    let s = format!("{x:e}");
    let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
    if mant.contains('.') {
        format!("{mant}D{exp}")
    } else {
        format!("{mant}.0D{exp}")
    }
}

/// A Hollerith string.
fn holl(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// Today's date as IGES writes it: `YYYYMMDD.HHNNSS` (UTC).
fn date_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let days = i64::try_from(secs / 86_400).unwrap_or(0);
    let rem = secs % 86_400;
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}{month:02}{day:02}.{:02}{:02}{:02}",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Lay tokens into records of `width` columns, each token followed by `,` and the last by
/// `;`, never splitting a token.
fn lay(tokens: &[String], width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for (i, t) in tokens.iter().enumerate() {
        let item = format!("{t}{}", if i + 1 == tokens.len() { ';' } else { ',' });
        let cur = lines.last_mut().map_or(0, |l| l.len());
        if cur > 0 && cur + item.len() > width {
            lines.push(String::new());
        }
        if let Some(l) = lines.last_mut() {
            l.push_str(&item);
        }
    }
    lines
}

/// A whole IGES file with one entity.
fn file(kind: i64, form: i64, params: &[String], max_coord: f64, origin: &Origin) -> String {
    let mut out = String::new();
    let rec = |out: &mut String, data: &str, sec: char, seq: usize| {
        let _ = writeln!(out, "{data:<72}{sec}{seq:>7}");
    };
    let date = date_now();
    let version = env!("CARGO_PKG_VERSION");
    let s = ["batten: faired planar curve"];
    for (i, l) in s.iter().enumerate() {
        rec(&mut out, l, 'S', i + 1);
    }
    let g: Vec<String> = vec![
        holl(","),
        holl(";"),
        holl("batten"),
        holl(origin.name.as_deref().unwrap_or("curve")),
        holl("batten"),
        holl(version),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        holl("batten"),
        real_str(1.0),
        UNITS_MM.to_string(),
        holl("MM"),
        "1".into(),
        real_str(1.0),
        holl(&date),
        real_str(1e-10),
        real_str(max_coord),
        String::new(),
        String::new(),
        IGES_VERSION.to_string(),
        "0".into(),
        holl(&date),
    ];
    let glines = lay(&g, DATA);
    for (i, l) in glines.iter().enumerate() {
        rec(&mut out, l, 'G', i + 1);
    }
    let plines = lay(params, P_DATA);
    let level: i64 = origin
        .layer
        .as_deref()
        .and_then(|l| l.parse().ok())
        .unwrap_or(0);
    let d1 = format!(
        "{kind:>8}{:>8}{:>8}{:>8}{level:>8}{:>8}{:>8}{:>8}{:>8}",
        1, 0, 0, 0, 0, 0, "00000000"
    );
    let label = if kind == 126 { "BSPLINE" } else { "COPIOUS" };
    let d2 = format!(
        "{kind:>8}{:>8}{:>8}{:>8}{form:>8}{:>8}{:>8}{label:>8}{:>8}",
        0,
        0,
        plines.len(),
        "",
        "",
        0
    );
    rec(&mut out, &d1, 'D', 1);
    rec(&mut out, &d2, 'D', 2);
    for (i, l) in plines.iter().enumerate() {
        rec(&mut out, &format!("{l:<64}{:>8}", 1), 'P', i + 1);
    }
    let t = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        s.len(),
        glines.len(),
        2,
        plines.len()
    );
    rec(&mut out, &t, 'T', 1);
    out
}

fn max_coordinate(points: &[Point], z: f64) -> f64 {
    points
        .iter()
        .fold(z.abs(), |m, p| m.max(p.x.abs()).max(p.y.abs()))
        .max(1.0)
}

/// Points as entity 106, form 11 (form 63 when closed).
pub(crate) fn format_points(points: &[Point], closed: bool, origin: &Origin) -> String {
    let mut params = vec![
        "106".to_string(),
        "1".into(),
        points.len().to_string(),
        real_str(origin.z),
    ];
    for p in points {
        params.push(real_str(p.x));
        params.push(real_str(p.y));
    }
    let form = if closed { 63 } else { 11 };
    file(106, form, &params, max_coordinate(points, origin.z), origin)
}

/// Space points as entity 106 form 12 (x, y, z triples; a closed curve's first point
/// repeated at the end, which is how it reads back as closed).
pub(crate) fn format_space_points(points: &[[f64; 3]], closed: bool, origin: &Origin) -> String {
    let mut all: Vec<[f64; 3]> = points.to_vec();
    if closed && let Some(&first) = points.first() {
        all.push(first);
    }
    let mut params = vec!["106".to_string(), "2".into(), all.len().to_string()];
    for p in &all {
        params.extend(p.iter().map(|&c| real_str(c)));
    }
    let max = all.iter().flatten().fold(1.0_f64, |m, c| m.max(c.abs()));
    file(106, 12, &params, max, origin)
}

/// A B-spline as entity 126 (planar, normal +z).
pub(crate) fn format_curve(curve: &BSplineCurve, closed: bool, origin: &Origin) -> String {
    let ctrl = curve.control_points();
    let k = ctrl.len() - 1;
    let m = curve.degree();
    let u = curve.knots().as_slice();
    let mut params: Vec<String> = vec![
        "126".into(),
        k.to_string(),
        m.to_string(),
        "1".into(),
        u8::from(closed).to_string(),
        u8::from(curve.weights().is_none()).to_string(),
        "0".into(),
    ];
    params.extend(u.iter().map(|&x| real_str(x)));
    match curve.weights() {
        Some(w) => params.extend(w.iter().map(|&x| real_str(x))),
        None => params.extend(std::iter::repeat_n(real_str(1.0), k + 1)),
    }
    for p in ctrl {
        params.extend([real_str(p.x), real_str(p.y), real_str(origin.z)]);
    }
    params.extend([real_str(u[m]), real_str(u[k + 1])]);
    params.extend([real_str(0.0), real_str(0.0), real_str(1.0)]);
    file(126, 0, &params, max_coordinate(ctrl, origin.z), origin)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
