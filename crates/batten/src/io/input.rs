//! Reading any format into points or a B-spline, and where the curve sat.

use std::path::Path;

use super::points::{parse_text_or_json, read_bytes, validate, validate_space};
use super::{Format, IoError, PointData, ReadOptions, SpaceData, dxf, iges, svg};
use crate::geom::{Point, Xyz};
use crate::spline::BSplineCurve;

/// Which curve to take from a file that can hold several (DXF, IGES, SVG), and how.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Pick {
    /// DXF: the entity's handle (hexadecimal, any case); IGES: the directory entry's
    /// sequence number (`D` line of its first record).
    ///
    /// Default value: `None` (the only curve of the file).
    pub entity: Option<String>,
    /// DXF: the layer name; IGES: the level number.
    ///
    /// Default value: `None`.
    pub layer: Option<String>,
    /// SVG: the `id` of the element.
    ///
    /// Default value: `None`.
    pub id: Option<String>,
    /// SVG: take N points per segment of a path instead of its B-spline.
    ///
    /// Default value: `None`.
    pub sample: Option<usize>,
}

impl Pick {
    /// Pick by DXF handle or IGES directory entry.
    pub fn with_entity(mut self, entity: Option<String>) -> Pick {
        self.entity = entity;
        self
    }
    /// Pick by DXF layer or IGES level.
    pub fn with_layer(mut self, layer: Option<String>) -> Pick {
        self.layer = layer;
        self
    }
    /// Pick an SVG element by id.
    pub fn with_id(mut self, id: Option<String>) -> Pick {
        self.id = id;
        self
    }
    /// Sample SVG paths with N points per segment.
    pub fn with_sample(mut self, sample: Option<usize>) -> Pick {
        self.sample = sample;
        self
    }
}

/// Where a curve sat in its file, so that it can be written back alike.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Origin {
    /// The constant z of a planar curve from a 3-D format (DXF, IGES); written back.
    pub z: f64,
    /// The DXF layer (or IGES level) it was on.
    pub layer: Option<String>,
    /// Its name: DXF handle, IGES directory entry, SVG id.
    pub name: Option<String>,
}

/// What an input file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A validated point list.
    Points(PointData),
    /// A B-spline curve.
    Curve(BSplineCurve),
    /// A validated space curve (`x, y, z` points).
    Space(SpaceData),
}

/// A curve read from a file and where it sat.
#[derive(Clone, Debug, PartialEq)]
pub struct Input {
    /// The points or the curve.
    pub source: Source,
    /// Where it came from.
    pub origin: Origin,
}

/// What a format reader hands back before validation.
#[derive(Debug)]
pub(crate) enum Raw {
    /// Points with the 1-based line of each, closed or not.
    Points {
        points: Vec<Point>,
        lines: Vec<usize>,
        closed: bool,
    },
    /// A B-spline.
    Curve(BSplineCurve),
    /// Space points (a 3-D DXF POLYLINE, or SPLINE fit points, whose z varies).
    Space {
        points: Vec<Xyz>,
        lines: Vec<usize>,
        closed: bool,
    },
}

/// Parse any input format held in memory (a file's bytes, or standard input); `path` names
/// it in messages. Points are validated as by [`parse_points`](super::parse_points); a B-spline is returned as
/// it is.
///
/// # Errors
/// Everything [`parse_points`](super::parse_points) reports, and [`IoError::Format`] for a malformed DXF, IGES or
/// SVG file, a 3-D curve (z not constant), or a choice the file leaves open.
pub fn parse_input(
    bytes: &[u8],
    format: Format,
    path: &Path,
    options: &ReadOptions,
    pick: &Pick,
) -> Result<Input, IoError> {
    let (raw, origin) = match format {
        Format::Text | Format::Json => {
            return Ok(Input {
                source: parse_text_or_json(bytes, format, path, options)?,
                origin: Origin::default(),
            });
        }
        Format::Dxf => dxf::parse(bytes, path, pick)?,
        Format::Iges => iges::parse(bytes, path, pick)?,
        Format::Svg => svg::parse(bytes, path, pick)?,
    };
    Ok(Input {
        source: validated(raw, path, options)?,
        origin,
    })
}

/// Validate what a format reader gave: points as [`parse_points`] does, a B-spline as it is.
pub(super) fn validated(raw: Raw, path: &Path, options: &ReadOptions) -> Result<Source, IoError> {
    Ok(match raw {
        Raw::Points {
            points,
            lines,
            closed,
        } => Source::Points(PointData {
            seq: validate(path, points, &lines, closed || options.closed)?,
            tangents: None,
            lines,
        }),
        Raw::Curve(c) => Source::Curve(c),
        Raw::Space {
            points,
            lines,
            closed,
        } => Source::Space(SpaceData {
            seq: validate_space(path, points, &lines, closed || options.closed)?,
            lines,
        }),
    })
}

/// Read any input file (format by extension, or `format` when given).
///
/// # Errors
/// [`IoError::Read`], [`IoError::UnknownFormat`], and everything [`parse_input`] reports.
pub fn read_input(
    path: &Path,
    format: Option<Format>,
    options: &ReadOptions,
    pick: &Pick,
) -> Result<Input, IoError> {
    let format = match format {
        Some(f) => f,
        None => Format::from_path(path)?,
    };
    let bytes = read_bytes(path)?;
    parse_input(&bytes, format, path, options, pick)
}
