//! What a point file may hold beyond "finite numbers": a bound on coordinate magnitudes,
//! refused at input with the file and line. (Near-duplicate points are refused by
//! [`crate::PointSeq`] itself, [`crate::geom::NEAR_DUPLICATE_REL`]; `io::validate` names
//! their lines.)

use std::path::Path;

use super::IoError;
use crate::geom::Point;

/// Largest coordinate magnitude accepted, `|x|, |y| ≤ 1e300`.
///
/// The bound keeps every difference of two coordinates and the bounding-box diagonal finite
/// (at most `3e300`), which is what the methods need: they work in coordinates normalised to
/// the bounding box, so squared chords and curvatures never see the raw magnitude. A value
/// such as `1e308` would pass the number parser and overflow in the first difference; it is
/// refused here with its line instead. Small magnitudes are not bounded: tiny coordinates
/// are a matter of scale.
pub const MAX_COORDINATE: f64 = 1e300;

/// Refuse a coordinate beyond [`MAX_COORDINATE`], naming its line.
pub(crate) fn check_magnitudes(
    path: &Path,
    points: &[Point],
    lines: &[usize],
) -> Result<(), IoError> {
    check_coordinates(path, points.iter().map(|p| [p.x, p.y]), lines)
}

/// [`check_magnitudes`] for points of any dimension.
pub(crate) fn check_coordinates<const D: usize>(
    path: &Path,
    points: impl Iterator<Item = [f64; D]>,
    lines: &[usize],
) -> Result<(), IoError> {
    for (i, p) in points.enumerate() {
        if let Some(&value) = p.iter().find(|v| v.abs() > MAX_COORDINATE) {
            return Err(IoError::TooLarge {
                path: path.to_path_buf(),
                line: lines.get(i).copied().unwrap_or(1),
                value,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{Format, ReadOptions, parse_points};

    fn msg(text: &str, closed: bool) -> String {
        let options = ReadOptions::default().with_closed(closed);
        parse_points(text.as_bytes(), Format::Text, Path::new("d.csv"), &options)
            .map(|_| String::new())
            .unwrap_or_else(|e| e.to_string())
    }

    #[test]
    fn magnitudes_beyond_the_bound_are_refused_with_their_line() {
        assert_eq!(
            msg("x,y\n0,0\n1,1\n2,1e308\n3,0\n", false),
            "d.csv:4: coordinate 1e308 is beyond ±1e300, the largest magnitude batten takes \
             (rescale the data)"
        );
        assert_eq!(
            msg("0,0\n-1.5e301,1\n2,0\n3,0\n", false),
            "d.csv:2: coordinate -1.5e301 is beyond ±1e300, the largest magnitude batten takes \
             (rescale the data)"
        );
        // At the bound, and at any tiny scale, points are taken.
        assert_eq!(msg("0,0\n1e300,1\n2,-1e300\n3,0\n", false), "");
        assert_eq!(
            msg("0,0\n1e-300,1e-300\n2e-300,0\n3e-300,1e-300\n", false),
            ""
        );
    }

    #[test]
    fn near_duplicates_are_refused_relative_to_the_extent() {
        // The repro: two points 1e-15 apart on a curve of extent ~3.
        assert_eq!(
            msg("0,0\n1,1\n1.000000000000001,1\n2,0\n3,1\n", false),
            "d.csv:3: point nearly duplicates the one on line 2 (3.7e-16 of the curve's size \
             apart, under 1e-12); remove one of them"
        );
        // The same spacing is fine at a scale where it is not small: the test is relative.
        let s = |v: f64| format!("{v}");
        let tiny = format!(
            "0,0\n{},{}\n{},0\n{},{}\n",
            s(1e-15),
            s(1e-15),
            s(2e-15),
            s(3e-15),
            s(1e-15)
        );
        assert_eq!(msg(&tiny, false), "");
        // On a closed curve, the last point against the first.
        assert_eq!(
            msg("0,0\n1,0\n1,1\n0,1\n0,1e-13\n", true),
            "d.csv:5: point nearly duplicates the one on line 1 (1.0e-13 of the curve's size \
             apart, under 1e-12); remove one of them"
        );
        assert_eq!(msg("0,0\n1,0\n1,1\n0,1\n0,1e-13\n", false), "");
        // Exact duplicates keep their own message.
        assert_eq!(
            msg("0,0\n1,0\n1,0\n0,1\n", false),
            "d.csv:3: point duplicates the previous one (line 2)"
        );
    }

    #[test]
    fn bounds_are_consistent() {
        // The largest accepted box has a finite diagonal: differences never overflow.
        let d = Point::new(MAX_COORDINATE, MAX_COORDINATE) - Point::new(-MAX_COORDINATE, 0.0);
        assert!(d.length().is_finite());
        const { assert!(crate::geom::NEAR_DUPLICATE_REL > 1e3 * f64::EPSILON) };
    }
}
