//! Point lists as text: one `x,y` (a planar curve) or `x,y,z` (a space curve) per line
//! (`.csv`, `.txt`).
//!
//! # Reading
//!
//! A hand parser, not the `csv` crate: the format mixes things `csv` does not do (separators
//! chosen per line among comma, semicolon and runs of whitespace; trailing `#` comments), and
//! the parser must know the physical line of every point to report errors. Rules, per line:
//!
//! 1. Everything from the first `#` on is a comment. What is left is trimmed; an empty line is
//!    skipped.
//! 2. Fields are separated by `;` if the line has one, else by `,` if it has one, else by runs
//!    of spaces and tabs. Each field is trimmed, and one pair of surrounding double quotes is
//!    removed (spreadsheets quote numbers). Empty fields count (`1,2,` has three fields).
//! 3. The first non-empty line is a header, and skipped, when *none* of its fields is a number
//!    (`x,y`, `X Y`). Any later non-numeric field is an error.
//! 4. Every other line has two fields (a planar curve) or three (a space curve), each a number
//!    as Rust's `f64::from_str` reads it (`1`, `-2.5`, `1e-300`, `.5`). A header of three
//!    fields (`x,y,z`) makes the file a space curve; otherwise the first data row decides, and
//!    every row must have as many fields as it. `NaN`, `inf` and numbers too large for an
//!    `f64` are errors, as are decimal commas (`1,5;2,5` is a row of two non-numbers).
//!
//! Line numbers are physical lines, 1-based; `\r\n` endings are accepted, and a UTF-8 byte
//! order mark at the start is ignored.
//!
//! # Writing
//!
//! A header `x,y` (`x,y,z`), then one row per point, with numbers in the shortest form that reads
//! back to the same `f64` bit for bit (see [`super::format_f64`]).

use std::path::Path;

use super::IoError;
use super::number::push_f64;
use crate::geom::{Point, Xyz};

/// Longest field text echoed in an error message, in characters.
const MAX_ECHO_CHARS: usize = 40;

/// The points of a file: planar or in space.
#[derive(Debug, PartialEq)]
pub(crate) enum Coords {
    /// `x,y` rows.
    Planar(Vec<Point>),
    /// `x,y,z` rows.
    Space(Vec<Xyz>),
}

/// Points and the 1-based line each came from.
pub(crate) struct ParsedText {
    pub coords: Coords,
    pub lines: Vec<usize>,
}

/// What a row must hold, as a message says it.
fn expected_fields(dimension: Option<usize>) -> &'static str {
    match dimension {
        Some(2) => "2 fields (x, y)",
        Some(3) => "3 fields (x, y, z)",
        _ => "2 fields (x, y) or 3 (x, y, z)",
    }
}

/// Inputs at least this large are read in parallel (see [`parse_parallel`]).
const PARALLEL_MIN_BYTES: usize = 4 << 20;
/// The part read first, alone, in [`parse_parallel`] (then cut at the next line end).
const PREFIX_BYTES: usize = 64 << 10;
/// The size of the pieces [`parse_parallel`] reads in parallel (cut at line ends).
const PIECE_BYTES: usize = 1 << 20;

/// Parse the text format. `path` is only used in error messages.
pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<ParsedText, IoError> {
    if bytes.len() >= PARALLEL_MIN_BYTES
        && let Some(parsed) = parse_parallel(bytes)
    {
        return Ok(parsed);
    }
    parse_sequential(bytes, path)
}

/// [`parse_sequential`]'s result for a large planar file without errors, read in parallel:
/// the first [`PREFIX_BYTES`] (to the next line end) by [`parse_sequential`], which settles
/// the header and that the rows are `x,y`, then the rest in pieces of [`PIECE_BYTES`] cut at
/// line ends, each by the same per-line rules, joined in order with their line numbers
/// offset. `None` for anything else — a space curve, no data row in the prefix, any error —
/// and the caller reads the file again sequentially, which gives the same points or the
/// same first error.
fn parse_parallel(bytes: &[u8]) -> Option<ParsedText> {
    use rayon::prelude::*;

    // The end of the line that `from` is in (`from` ≤ the length). Cut at line ends, the
    // pieces are whole UTF-8 sequences, each checked where it is read.
    let cut = |from: usize| -> usize {
        match bytes[from..].iter().position(|&b| b == b'\n') {
            Some(k) => from + k + 1,
            None => bytes.len(),
        }
    };
    let split = cut(PREFIX_BYTES.min(bytes.len()));
    let prefix = parse_sequential(&bytes[..split], Path::new("")).ok()?;
    let Coords::Planar(mut points) = prefix.coords else {
        return None;
    };
    if points.is_empty() {
        return None;
    }
    // The prefix ends at a line end when pieces follow it: its lines are its line ends.
    let prefix_lines = bytes[..split].iter().filter(|&&b| b == b'\n').count();
    let mut pieces = Vec::new();
    let mut start = split;
    while start < bytes.len() {
        let end = cut((start + PIECE_BYTES).min(bytes.len()));
        pieces.push(&bytes[start..end]);
        start = end;
    }
    let parsed: Vec<(Vec<Point>, Vec<usize>, usize)> = pieces
        .par_iter()
        .map(|piece| planar_rows(std::str::from_utf8(piece).ok()?))
        .collect::<Option<_>>()?;
    let total: usize = parsed.iter().map(|p| p.0.len()).sum();
    points.reserve_exact(total);
    let mut lines = prefix.lines;
    lines.reserve_exact(total);
    let mut offset = prefix_lines;
    for (p, l, count) in parsed {
        points.extend_from_slice(&p);
        lines.extend(l.iter().map(|k| k + offset));
        offset += count;
    }
    Some(ParsedText {
        coords: Coords::Planar(points),
        lines,
    })
}

/// The `x,y` rows of a piece of a file past its first data row, by [`parse_sequential`]'s
/// rules, with their 1-based line numbers in the piece and the piece's number of lines;
/// `None` at the first line that [`parse_sequential`] would refuse.
fn planar_rows(piece: &str) -> Option<(Vec<Point>, Vec<usize>, usize)> {
    let mut points = Vec::with_capacity(piece.len() / 24);
    let mut lines = Vec::with_capacity(piece.len() / 24);
    let mut count = 0;
    for (i, raw) in piece.lines().enumerate() {
        count = i + 1;
        let row = plain_row(raw).unwrap_or_else(|| general_row(raw))?;
        let Some([x, y]) = row else {
            continue; // empty or a comment
        };
        points.push(Point::new(x, y));
        lines.push(i + 1);
    }
    Some((points, lines, count))
}

/// A row of [`planar_rows`]: `Some(Some([x, y]))` a point, `Some(None)` a line without
/// content, `None` a line that [`parse_sequential`] would refuse.
type PlanarRow = Option<Option<[f64; 2]>>;

/// [`planar_rows`]' rules for one line by the general path: comments, `;` and `,` separators,
/// quotes, Unicode spaces.
fn general_row(raw: &str) -> PlanarRow {
    let content = match raw.find('#') {
        Some(k) => &raw[..k],
        None => raw,
    }
    .trim();
    if content.is_empty() {
        return Some(None);
    }
    let mut fields = [""; 3];
    if first_fields(content, &mut fields) != 2 {
        return None;
    }
    number_pair(fields[0], fields[1]).map(Some)
}

/// Two finite numbers, as [`parse_sequential`] reads fields.
#[inline]
fn number_pair(x: &str, y: &str) -> Option<[f64; 2]> {
    let x = x.parse::<f64>().ok()?;
    let y = y.parse::<f64>().ok()?;
    (x.is_finite() && y.is_finite()).then_some([x, y])
}

/// Whether `b` is an ASCII character that `char::is_whitespace` accepts (which, unlike
/// `u8::is_ascii_whitespace`, includes the vertical tab).
#[inline]
fn ascii_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\x0b' | b'\x0c' | b'\r')
}

/// `s` less its leading and trailing [`ascii_space`]s, as text (`s` is ASCII).
fn trim(s: &[u8]) -> &str {
    let start = s.iter().position(|&c| !ascii_space(c)).unwrap_or(s.len());
    let end = s
        .iter()
        .rposition(|&c| !ascii_space(c))
        .map_or(start, |e| e + 1);
    std::str::from_utf8(&s[start..end]).unwrap_or_default()
}

/// [`general_row`] in one pass over the bytes, for the lines of a large file that are plain
/// ASCII without `#`, `;` or `"` (nearly all of them): `x,y` or `x y`. `None` for any other
/// line, which then takes the general path; the same result as it otherwise.
#[inline]
fn plain_row(raw: &str) -> Option<PlanarRow> {
    let b = raw.as_bytes();
    let mut comma = None;
    let mut commas = 0;
    for (k, &c) in b.iter().enumerate() {
        match c {
            b',' => {
                commas += 1;
                comma = Some(k);
            }
            b'#' | b';' | b'"' => return None,
            c if c >= 0x80 => return None,
            _ => {}
        }
    }
    if let Some(k) = comma {
        if commas != 1 {
            return Some(None); // three fields or more: refused
        }
        return Some(number_pair(trim(&b[..k]), trim(&b[k + 1..])).map(Some));
    }
    // Whitespace-separated: exactly two runs of non-space characters, or none at all.
    let mut fields = b.split(|&c| ascii_space(c)).filter(|f| !f.is_empty());
    match (fields.next(), fields.next(), fields.next()) {
        (None, _, _) => Some(Some(None)),
        (Some(x), Some(y), None) => Some(number_pair(trim(x), trim(y)).map(Some)),
        _ => Some(None),
    }
}

/// The text format read line by line (see the module documentation).
fn parse_sequential(bytes: &[u8], path: &Path) -> Result<ParsedText, IoError> {
    let text = std::str::from_utf8(bytes).map_err(|e| IoError::NotUtf8 {
        path: path.to_path_buf(),
        line: 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);

    // One point per line at most: reserve once rather than grow 20 times (10⁶ points).
    let capacity = 1 + bytes.iter().filter(|&&b| b == b'\n').count();
    let mut planar: Vec<Point> = Vec::new();
    let mut space: Vec<Xyz> = Vec::new();
    let mut lines = Vec::with_capacity(capacity);
    let mut seen_content = false;
    // Set by a three-field header or by the first data row.
    let mut dimension: Option<usize> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = match raw.find('#') {
            Some(k) => &raw[..k],
            None => raw,
        }
        .trim();
        if content.is_empty() {
            continue;
        }
        if !seen_content {
            seen_content = true;
            let header = split_fields(content);
            if header.iter().all(|f| f.parse::<f64>().is_err()) {
                if header.len() == 3 {
                    dimension = Some(3);
                }
                continue; // the header
            }
        }
        let mut fields = [""; 3];
        let found = first_fields(content, &mut fields);
        let d = match dimension {
            Some(d) if d == found => d,
            None if found == 2 || found == 3 => {
                dimension = Some(found);
                if found == 2 {
                    planar.reserve(capacity);
                } else {
                    space.reserve(capacity);
                }
                found
            }
            _ => {
                return Err(IoError::FieldCount {
                    path: path.to_path_buf(),
                    line,
                    found,
                    expected: expected_fields(dimension),
                });
            }
        };
        let mut xyz = [0.0; 3];
        for (k, (field, slot)) in fields[..d].iter().zip(&mut xyz).enumerate() {
            let v = field.parse::<f64>().map_err(|_| IoError::NotANumber {
                path: path.to_path_buf(),
                line,
                field: k + 1,
                text: echo(field),
            })?;
            if !v.is_finite() {
                return Err(IoError::NonFinite {
                    path: path.to_path_buf(),
                    line,
                });
            }
            *slot = v;
        }
        if d == 2 {
            planar.push(Point::new(xyz[0], xyz[1]));
        } else {
            space.push(xyz);
        }
        lines.push(line);
    }
    let coords = if dimension == Some(3) {
        Coords::Space(space)
    } else {
        Coords::Planar(planar)
    };
    Ok(ParsedText { coords, lines })
}

/// Split a trimmed, comment-free, non-empty line into trimmed, unquoted fields.
fn split_fields(content: &str) -> Vec<&str> {
    let fields: Vec<&str> = if content.contains(';') {
        content.split(';').collect()
    } else if content.contains(',') {
        content.split(',').collect()
    } else {
        content.split_whitespace().collect()
    };
    fields.into_iter().map(|f| unquote(f.trim())).collect()
}

/// The fields of `content` as [`split_fields`] splits them, without collecting them: the
/// first three go to `out`, and the number of fields is returned (the reader's inner loop,
/// 10⁶ lines and more).
fn first_fields<'a>(content: &'a str, out: &mut [&'a str; 3]) -> usize {
    let mut n = 0;
    let mut put = |f: &'a str| {
        if let Some(slot) = out.get_mut(n) {
            *slot = unquote(f.trim());
        }
        n += 1;
    };
    if content.contains(';') {
        content.split(';').for_each(&mut put);
    } else if content.contains(',') {
        content.split(',').for_each(&mut put);
    } else {
        content.split_whitespace().for_each(&mut put);
    }
    n
}

/// `"1.5"` → `1.5`; anything else unchanged.
fn unquote(field: &str) -> &str {
    field
        .strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .unwrap_or(field)
}

/// A field as shown in a message: control characters escaped (so the message stays on one
/// line), at most [`MAX_ECHO_CHARS`] characters.
fn echo(field: &str) -> String {
    let mut out = String::new();
    for (n, c) in field.chars().enumerate() {
        if n == MAX_ECHO_CHARS {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Rows per parallel piece of the text writers: from two pieces on, the pieces are formatted
/// on the thread pool and joined in order (the same text; at 10⁶ points formatting took as
/// long as the `mst` fit).
const ROWS_PER_PIECE: usize = 1 << 16;

/// `header`, then `row` of every item, in order: in pieces of [`ROWS_PER_PIECE`] on the
/// thread pool for many items. `row_bytes` is the capacity reserved per row.
fn rows<T: Sync>(
    header: &str,
    items: &[T],
    row_bytes: usize,
    row: impl Fn(&mut String, &T) + Sync,
) -> String {
    use rayon::prelude::*;
    let piece = |items: &[T]| {
        let mut out = String::with_capacity(items.len() * row_bytes);
        for item in items {
            row(&mut out, item);
        }
        out
    };
    if items.len() < 2 * ROWS_PER_PIECE {
        let mut out = String::with_capacity(header.len() + items.len() * row_bytes);
        out.push_str(header);
        for item in items {
            row(&mut out, item);
        }
        return out;
    }
    let pieces: Vec<String> = items.par_chunks(ROWS_PER_PIECE).map(piece).collect();
    let mut out =
        String::with_capacity(header.len() + pieces.iter().map(String::len).sum::<usize>());
    out.push_str(header);
    for p in &pieces {
        out.push_str(p);
    }
    out
}

/// The text format of space points: header `x,y,z`, one row per point.
pub(crate) fn format_space(points: &[Xyz]) -> String {
    rows("x,y,z\n", points, 60, |out, p| {
        push_f64(out, p[0]);
        out.push(',');
        push_f64(out, p[1]);
        out.push(',');
        push_f64(out, p[2]);
        out.push('\n');
    })
}

/// The text format of `points`: header `x,y`, one row per point.
pub(crate) fn format(points: &[Point]) -> String {
    rows("x,y\n", points, 40, |out, p| {
        push_f64(out, p.x);
        out.push(',');
        push_f64(out, p.y);
        out.push('\n');
    })
}

#[cfg(test)]
impl ParsedText {
    /// The planar points (none for a space curve).
    fn points(&self) -> &[Point] {
        match &self.coords {
            Coords::Planar(p) => p,
            Coords::Space(_) => &[],
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use std::fmt::Write as _;

    use super::*;
    use crate::io::format_f64;

    fn parse_str(s: &str) -> Result<ParsedText, IoError> {
        parse(s.as_bytes(), Path::new("data.csv"))
    }

    fn msg(s: &str) -> String {
        match parse_str(s) {
            Ok(_) => panic!("expected an error for {s:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn parallel_writing_matches_sequential() {
        let pts: Vec<Point> = (0..2 * ROWS_PER_PIECE + 17)
            .map(|i| Point::new(i as f64 * 1e-3, (i as f64).sin() * 1e-7))
            .collect();
        let mut want = String::from("x,y\n");
        for p in &pts {
            let _ = writeln!(want, "{},{}", format_f64(p.x), format_f64(p.y));
        }
        assert_eq!(format(&pts), want);
    }

    #[test]
    fn plain_rows_read_as_the_general_path_does() {
        let lines = [
            "1,2",
            " 1 , 2 ",
            "1,2,3",
            ",",
            "",
            "   ",
            "\x0b1\x0b2\x0b",
            "1\x0b,\x0c2",
            "1",
            "1 2 3",
            "1\t2",
            "1e5,-2.5e-3",
            "inf,1",
            "NaN,2",
            "1e400,1",
            "\u{a0}1,2",
            "1\u{a0}2",
            "1 ,",
            ",2",
            "1,,",
            "a,b",
            "+1,-2",
            ".5, 5.",
            "1_0,2",
            "0x10,1",
            "1 2#c",
            "\"1\",2",
            "1;2",
            "1\r",
            "1,2\r",
            " \t ",
            "-0,0",
            "1e-320,5",
        ];
        for line in lines {
            let general = general_row(line);
            assert_eq!(plain_row(line).unwrap_or(general), general, "{line:?}");
        }
    }

    #[test]
    fn parallel_reading_matches_sequential() {
        // Past PARALLEL_MIN_BYTES, with every separator, comments, blank lines, CRLF, quotes
        // and a header, so that the pieces cut through all of them.
        let mut s = String::from("\u{feff}# made up\nx,y\n");
        let mut i = 0_u64;
        while s.len() < PARALLEL_MIN_BYTES + 3 * PIECE_BYTES / 2 {
            let (x, y) = (i as f64 * 0.001, (i as f64 * 0.37).sin());
            let _ = match i % 7 {
                0 => writeln!(s, "{x},{y}"),
                1 => writeln!(s, "{x};{y} # note"),
                2 => writeln!(s, "  {x}\t{y}\r"),
                3 => writeln!(s, "\"{x}\",\"{y}\""),
                4 => writeln!(s, "{x:e} {y:e}\n"),
                5 => writeln!(s, "# only a comment\n{x} , {y}"),
                _ => writeln!(s, "{x},{y}"),
            };
            i += 1;
        }
        let bytes = s.as_bytes();
        let par = parse_parallel(bytes).unwrap();
        let seq = parse_sequential(bytes, Path::new("data.csv")).unwrap();
        assert!(par.points().len() > 100_000);
        assert_eq!(par.points(), seq.points());
        assert_eq!(par.lines, seq.lines);
        // An error anywhere: the parallel reader declines, and the error is the sequential
        // reader's.
        let bad = format!("{s}1,2,3\n");
        assert!(parse_parallel(bad.as_bytes()).is_none());
        let lines = bad.lines().count();
        assert_eq!(
            msg(&bad),
            format!("data.csv:{lines}: expected 2 fields (x, y), found 3")
        );
    }

    #[test]
    fn separators_comments_header() {
        let p = parse_str(
            "# a comment\n\nx,y\n0,1\n1;2 # trailing\n  2\t3\n3   4\r\n\"4\",\"5\"\n 5 , 6 \n",
        )
        .unwrap();
        assert_eq!(
            p.points(),
            vec![
                Point::new(0.0, 1.0),
                Point::new(1.0, 2.0),
                Point::new(2.0, 3.0),
                Point::new(3.0, 4.0),
                Point::new(4.0, 5.0),
                Point::new(5.0, 6.0),
            ]
        );
        assert_eq!(p.lines, vec![4, 5, 6, 7, 8, 9]);
    }

    #[test]
    fn header_only_on_first_content_line() {
        let p = parse_str("# c\nX Y\n1 2\n").unwrap();
        assert_eq!(p.points(), vec![Point::new(1.0, 2.0)]);
        assert_eq!(
            msg("x,y\n1,2\nx,y\n"),
            "data.csv:3: field 1 'x' is not a number"
        );
        // A first line with a number in it is data, not a header.
        assert_eq!(msg("1,abc\n"), "data.csv:1: field 2 'abc' is not a number");
    }

    #[test]
    fn byte_order_mark_is_ignored() {
        let p = parse_str("\u{feff}x,y\n1,2\n").unwrap();
        assert_eq!(p.points(), vec![Point::new(1.0, 2.0)]);
    }

    #[test]
    fn empty_and_comment_only_give_no_points() {
        assert!(parse_str("").unwrap().points().is_empty());
        assert!(
            parse_str("# only\n\n   \nx,y\n")
                .unwrap()
                .points()
                .is_empty()
        );
    }

    #[test]
    fn bad_rows() {
        assert_eq!(
            msg("0,0\n1,2,3\n"),
            "data.csv:2: expected 2 fields (x, y), found 3"
        );
        assert_eq!(
            msg("0,0\n1\n"),
            "data.csv:2: expected 2 fields (x, y), found 1"
        );
        assert_eq!(
            msg("0,0\n1,2,\n"),
            "data.csv:2: expected 2 fields (x, y), found 3"
        );
        assert_eq!(
            msg("0,0\n1,1\n2,2\n3,3\n4,4\n5,6\nabc,7\n"),
            "data.csv:7: field 1 'abc' is not a number"
        );
        assert_eq!(
            msg("0,0\n1,2\n3,x1\n"),
            "data.csv:3: field 2 'x1' is not a number"
        );
        assert_eq!(
            msg("0,0\n1;2,5\n"),
            "data.csv:2: field 2 '2,5' is not a number"
        );
        assert_eq!(
            msg("0,0\n1,1\n2,2\n3,3\nNaN,1\n"),
            "data.csv:5: NaN or infinite value"
        );
        assert_eq!(msg("0,0\n1,inf\n"), "data.csv:2: NaN or infinite value");
        assert_eq!(
            msg("0,0\n1,-infinity\n"),
            "data.csv:2: NaN or infinite value"
        );
        assert_eq!(msg("0,0\n1,1e400\n"), "data.csv:2: NaN or infinite value");
    }

    #[test]
    fn error_echo_stays_on_one_line_and_short() {
        let m = msg("0,0\n1,a\u{7}b\n");
        assert_eq!(m, "data.csv:2: field 2 'a\\u{7}b' is not a number");
        let long = "z".repeat(100);
        let m = msg(&format!("0,0\n1,{long}\n"));
        assert!(m.len() < 100, "{m}");
        assert!(m.contains('…'));
    }

    #[test]
    fn invalid_utf8_names_the_line() {
        let e = parse(b"x,y\n1,2\n3,\xff\n", Path::new("data.csv"))
            .err()
            .map(|e| e.to_string());
        assert_eq!(e.as_deref(), Some("data.csv:3: not valid UTF-8 text"));
    }

    /// Values whose text form is hardest: signed zero, extremes, subnormals, and numbers
    /// with 17 significant digits.
    fn nasty_values() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 3.0,
            5e-324,
            -5e-324,
            f64::from_bits(0x000F_FFFF_FFFF_FFFF), // the largest subnormal
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.1,
            1.0 / 3.0,
            2.0 / 3.0,
            1e-5,
            9.999999999999999e-6,
            1e16,
            9999999999999998.0,
            123_456_789.123_456_79,
            std::f64::consts::PI,
            -std::f64::consts::E,
        ];
        // Random bit patterns (xorshift64), finite only.
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        while v.len() < 20_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let x = f64::from_bits(s);
            if x.is_finite() {
                v.push(x);
            }
        }
        v
    }

    #[test]
    fn format_f64_round_trips_bit_exact() {
        for x in nasty_values() {
            let t = format_f64(x);
            let y: f64 = t.parse().unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x:e} written as {t}");
            assert!(t.len() <= 24, "{t} is not short");
        }
        assert_eq!(format_f64(-0.0), "-0");
        assert_eq!(format_f64(1e300), "1e300");
        assert_eq!(format_f64(1e-300), "1e-300");
        assert_eq!(format_f64(5e-324), "5e-324");
        assert_eq!(format_f64(0.1), "0.1");
        assert_eq!(format_f64(-2.5), "-2.5");
    }

    #[test]
    fn format_then_parse_is_identity() {
        let vals = nasty_values();
        // Pairs of distinct consecutive values: a file does not need them, the format does.
        let points: Vec<Point> = vals
            .chunks_exact(2)
            .map(|c| Point::new(c[0], c[1]))
            .collect();
        let text = format(&points);
        assert!(text.starts_with("x,y\n"));
        let back = parse_str(&text).unwrap();
        assert_eq!(back.points().len(), points.len());
        for (a, b) in points.iter().zip(back.points()) {
            assert_eq!(a.x.to_bits(), b.x.to_bits());
            assert_eq!(a.y.to_bits(), b.y.to_bits());
        }
        assert_eq!(back.lines[0], 2);
    }
}
