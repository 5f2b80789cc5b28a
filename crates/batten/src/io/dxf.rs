//! DXF (`.dxf`, ASCII or binary), through the `dxf` crate.
//!
//! Reading takes the curve entities of the drawing's model and paper space:
//! - `LWPOLYLINE`: its vertices as points (closed flag kept; its elevation is the z);
//! - `POLYLINE` (2-D or 3-D; not meshes): its vertices as points, without the frame
//!   control points of a spline-fit polyline;
//! - `SPLINE`: its degree, knots, control points and weights as a B-spline; or, when it has
//!   no control points, its fit points as points.
//!
//! Which entity: the one with handle [`Pick::entity`], else the only one on layer
//! [`Pick::layer`], else the only curve entity of the file; otherwise the error lists them.
//! A curve whose points all have the same z is planar, and its z is written back; a 3-D
//! `POLYLINE` or `SPLINE` fit points whose z varies are a space curve (`x, y, z` points). A
//! `SPLINE` with control points whose z varies (a 3-D B-spline), arc segments (bulges) and
//! entities in an object coordinate system other than the world's (extrusion not +z) are
//! refused.
//!
//! Writing: points as an `LWPOLYLINE` with the elevation and layer of the input, space
//! points as a 3-D `POLYLINE`, a B-spline as a `SPLINE` (degree, knots, control points,
//! weights; rational and closed flags), in an R2000 drawing. The `dxf` crate writes ASCII numbers with 12 decimal places, so a written
//! file reads back within 5·10⁻¹³ of each coordinate, not bit for bit.

use std::path::Path;

use dxf::entities::{Entity, EntityType, LwPolyline, Polyline, Spline, Vertex};
use dxf::enums::AcadVersion;
use dxf::{Drawing, LwPolylineVertex};

use super::error::one_line;
use super::{IoError, Location, Origin, Pick, Raw, ReadOptions, Source, validated};
use crate::geom::{Point, Xyz};
use crate::spline::{BSplineCurve, KnotVector};

/// POLYLINE flag: the vertices are 3-D.
const POLYLINE_3D: i32 = 8;
/// POLYLINE flags of meshes, which are not curves.
const POLYLINE_MESH: i32 = 16 | 64;
/// VERTEX flag: a vertex of a 3-D polyline.
const VERTEX_3D: i32 = 32;
/// VERTEX flag: a frame control point of a spline-fit polyline (not on the curve).
const VERTEX_FRAME: i32 = 16;
/// SPLINE flag: planar.
const SPLINE_PLANAR: i32 = 8;

fn format_err(path: &Path, message: impl Into<String>) -> IoError {
    IoError::Format {
        path: path.to_path_buf(),
        at: Location::File,
        message: message.into(),
    }
}

/// A curve entity of the drawing: its handle, layer and kind.
pub(crate) struct Found<'a> {
    pub entity: &'a Entity,
    pub kind: &'static str,
}

impl Found<'_> {
    pub(super) fn handle(&self) -> String {
        format!("{:X}", self.entity.common.handle.0)
    }

    fn describe(&self) -> String {
        format!(
            "{} {} on layer {}",
            self.kind,
            self.handle(),
            self.entity.common.layer
        )
    }
}

/// Load a drawing from bytes.
///
/// The `dxf` crate (0.6) panics on some malformed values instead of returning an error (a
/// date such as `$TDCREATE` far out of range overflows chrono's `TimeDelta`); the panic is
/// caught here and becomes the same one-line error as any other malformed file. (The
/// default panic hook still prints the crate's message to stderr first.)
pub(crate) fn load(bytes: &[u8], path: &Path) -> Result<Drawing, IoError> {
    let loaded = std::panic::catch_unwind(|| {
        let mut reader = bytes;
        Drawing::load(&mut reader)
    });
    match loaded {
        Ok(Ok(d)) => Ok(d),
        Ok(Err(e)) => Err(format_err(
            path,
            format!("malformed DXF: {}", one_line(&e.to_string())),
        )),
        Err(payload) => {
            let why = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown cause".to_string());
            Err(format_err(
                path,
                format!("malformed DXF: a value out of range ({})", one_line(&why)),
            ))
        }
    }
}

/// The curve entities of a drawing, in file order.
pub(crate) fn curves(drawing: &Drawing) -> Vec<Found<'_>> {
    drawing
        .entities()
        .filter_map(|e| {
            let kind = match &e.specific {
                EntityType::LwPolyline(_) => "LWPOLYLINE",
                EntityType::Polyline(p) if p.flags & POLYLINE_MESH == 0 => "POLYLINE",
                EntityType::Spline(_) => "SPLINE",
                _ => return None,
            };
            Some(Found { entity: e, kind })
        })
        .collect()
}

/// Read the picked curve of a DXF file.
pub(crate) fn parse(bytes: &[u8], path: &Path, pick: &Pick) -> Result<(Raw, Origin), IoError> {
    let drawing = load(bytes, path)?;
    let all = curves(&drawing);
    let list = |v: &[&Found<'_>]| {
        v.iter()
            .map(|f| f.describe())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut chosen: Vec<&Found<'_>> = all.iter().collect();
    if let Some(h) = &pick.entity {
        let want = h.trim().trim_start_matches("0x").to_ascii_uppercase();
        chosen.retain(|f| f.handle() == want.trim_start_matches('0') || f.handle() == want);
        if chosen.is_empty() {
            return Err(format_err(
                path,
                format!(
                    "no curve entity with handle {h} (curve entities: {})",
                    if all.is_empty() {
                        "none".into()
                    } else {
                        list(&all.iter().collect::<Vec<_>>())
                    }
                ),
            ));
        }
    }
    if let Some(layer) = &pick.layer {
        chosen.retain(|f| f.entity.common.layer == *layer);
        if chosen.is_empty() {
            return Err(format_err(
                path,
                format!(
                    "no curve entity on layer {layer} (curve entities: {})",
                    if all.is_empty() {
                        "none".into()
                    } else {
                        list(&all.iter().collect::<Vec<_>>())
                    }
                ),
            ));
        }
    }
    let found = match chosen.as_slice() {
        [] => {
            return Err(format_err(path, "no LWPOLYLINE, POLYLINE or SPLINE entity"));
        }
        [f] => *f,
        many => {
            return Err(format_err(
                path,
                format!(
                    "{} curve entities, pick one with --entity HANDLE or --layer NAME: {}",
                    many.len(),
                    list(many)
                ),
            ));
        }
    };
    let (raw, z) = entity_curve(found, path)?;
    Ok((raw, origin_of(found, z)))
}

/// One entity as points or a B-spline, with its constant z.
pub(crate) fn entity_curve(found: &Found<'_>, path: &Path) -> Result<(Raw, f64), IoError> {
    let e = found.entity;
    let what = found.describe();
    let err = |m: String| format_err(path, format!("{what}: {m}"));
    match &e.specific {
        EntityType::LwPolyline(lw) => lw_polyline_curve(lw, e.common.elevation, &err),
        EntityType::Polyline(pl) => polyline_curve(pl, &err),
        EntityType::Spline(sp) => spline_curve(sp, &err),
        _ => Err(err("not a curve entity".into())),
    }
}

/// Refuse a curve whose plane is not the world XY plane.
fn extrusion(v: &dxf::Vector, err: &dyn Fn(String) -> IoError) -> Result<(), IoError> {
    if v.x == 0.0 && v.y == 0.0 && v.z > 0.0 {
        Ok(())
    } else {
        Err(err(format!(
            "its plane has the normal ({}, {}, {}); batten takes curves in the world XY plane only",
            v.x, v.y, v.z
        )))
    }
}

/// The constant z, or the first two values that differ.
fn planar(zs: &mut dyn Iterator<Item = f64>) -> Result<f64, (f64, f64)> {
    let mut z0 = None;
    for z in zs {
        match z0 {
            None => z0 = Some(z),
            Some(a) if a == z => {}
            Some(a) => return Err((a, z)),
        }
    }
    Ok(z0.unwrap_or(0.0))
}

/// Space points, a closed entity's repeated first vertex left out.
fn space(mut points: Vec<Xyz>, closed: bool) -> Result<(Raw, f64), IoError> {
    if closed && points.len() > 1 && points.last() == points.first() {
        points.pop();
    }
    let lines = vec![1; points.len()];
    Ok((
        Raw::Space {
            points,
            lines,
            closed,
        },
        0.0,
    ))
}

/// Planar points at height `z`, a closed entity's repeated first vertex left out.
fn plane_points(mut points: Vec<Point>, closed: bool, z: f64) -> Result<(Raw, f64), IoError> {
    if closed && points.len() > 1 && points.last() == points.first() {
        points.pop();
    }
    let lines = vec![1; points.len()];
    Ok((
        Raw::Points {
            points,
            lines,
            closed,
        },
        z,
    ))
}

/// An arc segment's error: vertex `i` (0-based) has a bulge.
fn bulge_error(i: usize, err: &dyn Fn(String) -> IoError) -> IoError {
    err(format!(
        "vertex {} starts an arc segment (bulge); batten takes straight segments only",
        i + 1
    ))
}

/// An LWPOLYLINE's points, at its elevation.
fn lw_polyline_curve(
    lw: &LwPolyline,
    elevation: f64,
    err: &dyn Fn(String) -> IoError,
) -> Result<(Raw, f64), IoError> {
    extrusion(&lw.extrusion_direction, err)?;
    if let Some(i) = lw.vertices.iter().position(|v| v.bulge != 0.0) {
        return Err(bulge_error(i, err));
    }
    let points: Vec<Point> = lw.vertices.iter().map(|v| Point::new(v.x, v.y)).collect();
    plane_points(points, lw.is_closed(), elevation)
}

/// A POLYLINE's points (its frame vertices left out): planar, or space points when a 3-D
/// polyline's z varies.
fn polyline_curve(pl: &Polyline, err: &dyn Fn(String) -> IoError) -> Result<(Raw, f64), IoError> {
    extrusion(&pl.normal, err)?;
    let verts: Vec<_> = pl
        .vertices()
        .filter(|v| v.flags & VERTEX_FRAME == 0)
        .collect();
    if let Some(i) = verts.iter().position(|v| v.bulge != 0.0) {
        return Err(bulge_error(i, err));
    }
    let z = if pl.flags & POLYLINE_3D != 0 {
        match planar(&mut verts.iter().map(|v| v.location.z)) {
            Ok(z) => z,
            Err(_) => {
                let pts = verts
                    .iter()
                    .map(|v| [v.location.x, v.location.y, v.location.z])
                    .collect();
                return space(pts, pl.is_closed());
            }
        }
    } else {
        pl.location.z
    };
    let points: Vec<Point> = verts
        .iter()
        .map(|v| Point::new(v.location.x, v.location.y))
        .collect();
    plane_points(points, pl.is_closed(), z)
}

/// A SPLINE: its control points as a B-spline, or, with fit points only, those points
/// (space points when their z varies).
fn spline_curve(sp: &Spline, err: &dyn Fn(String) -> IoError) -> Result<(Raw, f64), IoError> {
    extrusion(&sp.normal, err)?;
    if sp.control_points.is_empty() {
        let Ok(z) = planar(&mut sp.fit_points.iter().map(|p| p.z)) else {
            let pts = sp.fit_points.iter().map(|p| [p.x, p.y, p.z]).collect();
            return space(pts, sp.is_closed());
        };
        let points: Vec<Point> = sp.fit_points.iter().map(|p| Point::new(p.x, p.y)).collect();
        return plane_points(points, sp.is_closed(), z);
    }
    let z = planar(&mut sp.control_points.iter().map(|p| p.z)).map_err(|(a, b)| {
        err(format!(
            "z varies ({a} and {b}): a 3-D B-spline is not taken (a 3-D POLYLINE or \
             SPLINE fit points are, as a space curve)"
        ))
    })?;
    let degree = usize::try_from(sp.degree_of_curve)
        .map_err(|_| err(format!("degree {} is not a degree", sp.degree_of_curve)))?;
    let ctrl: Vec<Point> = sp
        .control_points
        .iter()
        .map(|p| Point::new(p.x, p.y))
        .collect();
    let weights = if sp.weight_values.is_empty() {
        None
    } else {
        Some(sp.weight_values.clone())
    };
    let curve = KnotVector::try_new(sp.knot_values.clone())
        .and_then(|k| BSplineCurve::try_new(degree, k, ctrl, weights))
        .map_err(|e| err(e.to_string()))?;
    Ok((Raw::Curve(curve), z))
}

/// The origin of a found entity: its handle, layer and z.
fn origin_of(found: &Found<'_>, z: f64) -> Origin {
    Origin {
        z,
        layer: Some(found.entity.common.layer.clone()),
        name: Some(found.handle()),
    }
}

/// A whole DXF drawing, kept to write back with some curves replaced: what `batch` does
/// with a DXF file. Every other entity, table and header variable is written back as the
/// `dxf` crate read it; handles and layers are kept.
#[derive(Debug)]
pub struct DxfDrawing {
    drawing: Drawing,
    path: std::path::PathBuf,
}

/// One curve entity of a [`DxfDrawing`]: where it sits, and its points or B-spline (or why
/// batten cannot take it).
#[derive(Debug)]
pub struct DxfCurve {
    /// Handle (`name`), layer and z.
    pub origin: Origin,
    /// `LWPOLYLINE`, `POLYLINE` or `SPLINE`.
    pub kind: &'static str,
    /// What it holds: validated points or a B-spline; or the one-line reason it cannot be
    /// taken (a bulge, a varying z, too few points, ...).
    pub source: Result<Source, IoError>,
}

/// New geometry for a curve entity of a [`DxfDrawing`].
#[derive(Clone, Copy, Debug)]
pub enum DxfGeometry<'a> {
    /// As many points as the entity gave (a closed entity's repeated first vertex is kept
    /// repeated).
    Points(&'a [Point]),
    /// A B-spline for a `SPLINE` with control points: degree, knots, control points and
    /// weights are replaced.
    Curve(&'a BSplineCurve),
    /// Space points for a 3-D `POLYLINE` or `SPLINE` fit points read as a space curve: x, y
    /// and z are replaced.
    Space(&'a [Xyz]),
}

impl DxfDrawing {
    /// Parse a drawing; `path` names it in messages.
    ///
    /// # Errors
    /// [`IoError::Format`] for a file the `dxf` crate cannot read.
    pub fn parse(bytes: &[u8], path: &Path) -> Result<DxfDrawing, IoError> {
        Ok(DxfDrawing {
            drawing: load(bytes, path)?,
            path: path.to_path_buf(),
        })
    }

    /// Read a drawing from a file.
    ///
    /// # Errors
    /// [`IoError::Read`], and what [`DxfDrawing::parse`] reports.
    pub fn read(path: &Path) -> Result<DxfDrawing, IoError> {
        DxfDrawing::parse(&super::read_bytes(path)?, path)
    }

    /// Every curve entity (`LWPOLYLINE`, `POLYLINE` that is not a mesh, `SPLINE`) in file
    /// order, points validated as by [`super::parse_points`] with `options`.
    pub fn curves(&self, options: &ReadOptions) -> Vec<DxfCurve> {
        curves(&self.drawing)
            .iter()
            .map(|f| {
                let (source, z) = match entity_curve(f, &self.path) {
                    Ok((raw, z)) => (validated(raw, &self.path, options), z),
                    Err(e) => (Err(e), 0.0),
                };
                DxfCurve {
                    origin: origin_of(f, z),
                    kind: f.kind,
                    source,
                }
            })
            .collect()
    }

    /// Replace the geometry of the curve entity with handle `handle` (as
    /// [`DxfCurve::origin`] names it); z, layer, handle and every other property stay.
    ///
    /// # Errors
    /// [`IoError::Format`] when no curve entity has that handle, the point count differs
    /// from what the entity gave, or a B-spline is given for anything but a `SPLINE` with
    /// control points (or points for one).
    pub fn replace(&mut self, handle: &str, geometry: DxfGeometry<'_>) -> Result<(), IoError> {
        let path = self.path.clone();
        let fail = |m: String| format_err(&path, format!("entity {handle}: {m}"));
        let Some(e) = self
            .drawing
            .entities_mut()
            .find(|e| format!("{:X}", e.common.handle.0) == handle)
        else {
            return Err(fail("no such entity".into()));
        };
        // New (x, y) for `n` vertices of which the first `given` were read (a closed
        // entity may repeat its first vertex at the end).
        let points_for = |n: usize, pts: &[Point]| -> Result<Vec<Point>, IoError> {
            repeat_first(n, pts).ok_or_else(|| {
                fail(format!(
                    "{} points for an entity of {n} vertices",
                    pts.len()
                ))
            })
        };
        let space_for = |n: usize, pts: &[Xyz]| -> Result<Vec<Xyz>, IoError> {
            repeat_first(n, pts).ok_or_else(|| {
                fail(format!(
                    "{} points for an entity of {n} vertices",
                    pts.len()
                ))
            })
        };
        match (&mut e.specific, geometry) {
            (EntityType::LwPolyline(lw), DxfGeometry::Points(pts)) => {
                let new = points_for(lw.vertices.len(), pts)?;
                for (v, p) in lw.vertices.iter_mut().zip(new) {
                    (v.x, v.y) = (p.x, p.y);
                }
            }
            (EntityType::Polyline(pl), DxfGeometry::Points(pts)) => {
                let n = pl
                    .vertices()
                    .filter(|v| v.flags & VERTEX_FRAME == 0)
                    .count();
                let new = points_for(n, pts)?;
                let on_curve = pl.vertices_mut().filter(|v| v.flags & VERTEX_FRAME == 0);
                for (v, p) in on_curve.zip(new) {
                    (v.location.x, v.location.y) = (p.x, p.y);
                }
            }
            (EntityType::Polyline(pl), DxfGeometry::Space(pts)) => {
                let n = pl
                    .vertices()
                    .filter(|v| v.flags & VERTEX_FRAME == 0)
                    .count();
                let new = space_for(n, pts)?;
                let on_curve = pl.vertices_mut().filter(|v| v.flags & VERTEX_FRAME == 0);
                for (v, p) in on_curve.zip(new) {
                    v.location = dxf::Point::new(p[0], p[1], p[2]);
                }
            }
            (EntityType::Spline(sp), DxfGeometry::Space(pts)) if sp.control_points.is_empty() => {
                let new = space_for(sp.fit_points.len(), pts)?;
                for (v, p) in sp.fit_points.iter_mut().zip(new) {
                    *v = dxf::Point::new(p[0], p[1], p[2]);
                }
            }
            (EntityType::Spline(sp), DxfGeometry::Points(pts)) if sp.control_points.is_empty() => {
                let new = points_for(sp.fit_points.len(), pts)?;
                for (v, p) in sp.fit_points.iter_mut().zip(new) {
                    (v.x, v.y) = (p.x, p.y);
                }
            }
            (EntityType::Spline(sp), DxfGeometry::Curve(c)) if !sp.control_points.is_empty() => {
                let z = sp.control_points.first().map_or(0.0, |p| p.z);
                sp.degree_of_curve = i32::try_from(c.degree())
                    .map_err(|_| fail("the degree does not fit a DXF integer".into()))?;
                sp.knot_values = c.knots().as_slice().to_vec();
                sp.control_points = c
                    .control_points()
                    .iter()
                    .map(|p| dxf::Point::new(p.x, p.y, z))
                    .collect();
                sp.weight_values = c.weights().map(<[f64]>::to_vec).unwrap_or_default();
                sp.set_is_rational(c.weights().is_some());
            }
            (EntityType::Spline(_), DxfGeometry::Points(_)) => {
                return Err(fail(
                    "a SPLINE with control points takes a B-spline, not points".into(),
                ));
            }
            (_, DxfGeometry::Curve(_)) => {
                return Err(fail(
                    "only a SPLINE with control points takes a B-spline".into(),
                ));
            }
            _ => return Err(fail("not a curve entity".into())),
        }
        Ok(())
    }

    /// The drawing as ASCII DXF, in the version it was read in, or R2000 when that version
    /// cannot hold its LWPOLYLINE or SPLINE entities (a file without a header reads as R12,
    /// and the `dxf` crate leaves out of a file what its version cannot hold).
    ///
    /// # Errors
    /// [`IoError::Format`] when the `dxf` crate cannot encode it.
    pub fn to_bytes(&self) -> Result<Vec<u8>, IoError> {
        let modern = self.drawing.entities().any(|e| {
            matches!(
                e.specific,
                EntityType::LwPolyline(_) | EntityType::Spline(_)
            )
        });
        if modern && self.drawing.header.version < AcadVersion::R2000 {
            let mut d = self.drawing.clone();
            d.header.version = AcadVersion::R2000;
            return save(&d, &self.path);
        }
        save(&self.drawing, &self.path)
    }
}

/// `pts` for an entity of `n` vertices: as they are, or with the first repeated at the end
/// (a closed entity that repeats its first vertex); `None` for another count.
fn repeat_first<T: Copy>(n: usize, pts: &[T]) -> Option<Vec<T>> {
    match n.checked_sub(pts.len()) {
        Some(0) => Some(pts.to_vec()),
        Some(1) if pts.len() > 1 => {
            let mut v = pts.to_vec();
            v.push(pts[0]);
            Some(v)
        }
        _ => None,
    }
}

/// The layer an output goes on: the input's, else `0`.
fn layer_of(origin: &Origin) -> String {
    origin.layer.clone().unwrap_or_else(|| "0".to_string())
}

/// A new R2000 drawing with the origin's layer, holding `entity` on it.
fn drawing_with(entity: Option<Entity>, origin: &Origin) -> Drawing {
    let mut drawing = Drawing::new();
    drawing.header.version = AcadVersion::R2000;
    let layer = layer_of(origin);
    if !drawing.layers().any(|l| l.name == layer) {
        let l = dxf::tables::Layer {
            name: layer.clone(),
            ..Default::default()
        };
        drawing.add_layer(l);
    }
    if let Some(mut entity) = entity {
        entity.common.layer = layer;
        drawing.add_entity(entity);
    }
    drawing
}

fn save(drawing: &Drawing, path: &Path) -> Result<Vec<u8>, IoError> {
    let mut out = Vec::new();
    drawing
        .save(&mut out)
        .map_err(|e| format_err(path, format!("cannot encode the DXF: {e}")))?;
    Ok(out)
}

/// Points as an LWPOLYLINE.
pub(crate) fn format_points(
    points: &[Point],
    closed: bool,
    origin: &Origin,
    path: &Path,
) -> Result<Vec<u8>, IoError> {
    let mut lw = LwPolyline {
        vertices: points
            .iter()
            .map(|p| LwPolylineVertex {
                x: p.x,
                y: p.y,
                ..Default::default()
            })
            .collect(),
        ..Default::default()
    };
    lw.set_is_closed(closed);
    let mut entity = Entity::new(EntityType::LwPolyline(lw));
    entity.common.elevation = origin.z;
    save(&drawing_with(Some(entity), origin), path)
}

/// Space points as a 3-D POLYLINE.
pub(crate) fn format_space_points(
    points: &[Xyz],
    closed: bool,
    origin: &Origin,
    path: &Path,
) -> Result<Vec<u8>, IoError> {
    let mut drawing = drawing_with(None, origin);
    let mut pl = Polyline {
        flags: POLYLINE_3D,
        ..Default::default()
    };
    for p in points {
        // The vertices' handles come from the drawing they go into.
        pl.add_vertex(
            &mut drawing,
            Vertex {
                location: dxf::Point::new(p[0], p[1], p[2]),
                flags: VERTEX_3D,
                ..Default::default()
            },
        );
    }
    pl.set_is_closed(closed);
    let mut entity = Entity::new(EntityType::Polyline(pl));
    entity.common.layer = layer_of(origin);
    drawing.add_entity(entity);
    save(&drawing, path)
}

/// A B-spline as a SPLINE.
pub(crate) fn format_curve(
    curve: &BSplineCurve,
    closed: bool,
    origin: &Origin,
    path: &Path,
) -> Result<Vec<u8>, IoError> {
    let mut sp = Spline {
        degree_of_curve: i32::try_from(curve.degree())
            .map_err(|_| format_err(path, "the degree does not fit a DXF integer"))?,
        knot_values: curve.knots().as_slice().to_vec(),
        control_points: curve
            .control_points()
            .iter()
            .map(|p| dxf::Point::new(p.x, p.y, origin.z))
            .collect(),
        weight_values: curve.weights().map(<[f64]>::to_vec).unwrap_or_default(),
        flags: SPLINE_PLANAR,
        normal: dxf::Vector::z_axis(),
        ..Default::default()
    };
    sp.set_is_rational(curve.weights().is_some());
    sp.set_is_closed(closed);
    save(
        &drawing_with(Some(Entity::new(EntityType::Spline(sp))), origin),
        path,
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Within the 12 decimal places the `dxf` crate writes.
    const DXF_ROUNDING: f64 = 5.0e-13;

    fn read(bytes: &[u8], pick: &Pick) -> Result<(Raw, Origin), String> {
        parse(bytes, Path::new("d.dxf"), pick).map_err(|e| e.to_string())
    }

    fn pts() -> Vec<Point> {
        (0..6)
            .map(|i| Point::new(i as f64 * 1.25, ((i * i) % 7) as f64 / 3.0))
            .collect()
    }

    fn close(a: Point, b: Point) -> bool {
        let near = |u: f64, v: f64| (u - v).abs() <= DXF_ROUNDING + f64::EPSILON * v.abs();
        near(a.x, b.x) && near(a.y, b.y)
    }

    #[test]
    fn polyline_round_trip_keeps_points_z_layer_and_closedness() {
        let origin = Origin {
            z: 2.5,
            layer: Some("HULL".into()),
            name: None,
        };
        for closed in [false, true] {
            let bytes = format_points(&pts(), closed, &origin, Path::new("o.dxf")).unwrap();
            let (raw, o) = read(&bytes, &Pick::default()).unwrap();
            let Raw::Points {
                points, closed: c, ..
            } = raw
            else {
                panic!()
            };
            assert_eq!(c, closed);
            assert_eq!(points.len(), 6);
            assert!(points.iter().zip(pts()).all(|(a, b)| close(*a, b)));
            assert_eq!(o.z, 2.5);
            assert_eq!(o.layer.as_deref(), Some("HULL"));
        }
    }

    #[test]
    fn spline_round_trip_keeps_degree_knots_and_weights() {
        let knots = KnotVector::try_new(vec![0., 0., 0., 0.5, 1., 1., 1.]).unwrap();
        let ctrl = vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 2.0),
            Point::new(2.0, -1.0 / 3.0),
            Point::new(3.0, 0.5),
        ];
        let c =
            BSplineCurve::try_new(2, knots, ctrl.clone(), Some(vec![1.0, 0.5, 2.0, 1.0])).unwrap();
        let bytes = format_curve(&c, false, &Origin::default(), Path::new("o.dxf")).unwrap();
        let (raw, o) = read(&bytes, &Pick::default()).unwrap();
        let Raw::Curve(back) = raw else { panic!() };
        assert_eq!(back.degree(), 2);
        assert_eq!(back.knots(), c.knots());
        assert_eq!(back.weights(), c.weights());
        assert!(
            back.control_points()
                .iter()
                .zip(&ctrl)
                .all(|(a, b)| close(*a, *b))
        );
        assert_eq!(o.z, 0.0);
    }

    fn two_entities() -> Vec<u8> {
        let mut d = Drawing::new();
        d.header.version = AcadVersion::R2000;
        for (layer, z) in [("A", 0.0), ("B", 1.0)] {
            let lw = LwPolyline {
                vertices: pts()
                    .iter()
                    .map(|p| LwPolylineVertex {
                        x: p.x,
                        y: p.y,
                        ..Default::default()
                    })
                    .collect(),
                ..Default::default()
            };
            let mut e = Entity::new(EntityType::LwPolyline(lw));
            e.common.layer = layer.into();
            e.common.elevation = z;
            d.add_entity(e);
        }
        let sp = Spline {
            degree_of_curve: 3,
            fit_points: (0..5)
                .map(|i| dxf::Point::new(f64::from(i), 0.0, f64::from(i)))
                .collect(),
            ..Default::default()
        };
        let mut e = Entity::new(EntityType::Spline(sp));
        e.common.layer = "C".into();
        d.add_entity(e);
        let mut out = Vec::new();
        d.save(&mut out).unwrap();
        out
    }

    /// A SPLINE with control points whose z varies is a 3-D B-spline: refused in one line.
    #[test]
    fn a_3d_bspline_is_refused() {
        let mut d = Drawing::new();
        d.header.version = AcadVersion::R2000;
        let sp = Spline {
            degree_of_curve: 3,
            knot_values: vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            control_points: (0..4)
                .map(|i| dxf::Point::new(f64::from(i), 1.0, 0.5 * f64::from(i)))
                .collect(),
            ..Default::default()
        };
        d.add_entity(Entity::new(EntityType::Spline(sp)));
        let mut bytes = Vec::new();
        d.save(&mut bytes).unwrap();
        let e = read(&bytes, &Pick::default()).unwrap_err();
        assert!(e.starts_with("d.dxf: SPLINE "), "{e}");
        assert!(
            e.contains("z varies (0 and 0.5): a 3-D B-spline is not taken"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1);
    }

    #[test]
    fn picking_by_handle_or_layer_and_the_ambiguity_message() {
        let bytes = two_entities();
        let e = read(&bytes, &Pick::default()).unwrap_err();
        assert!(e.starts_with("d.dxf: 3 curve entities, pick one with --entity HANDLE or --layer NAME: LWPOLYLINE "), "{e}");
        assert!(e.contains(" on layer A, LWPOLYLINE "), "{e}");
        let (_, o) = read(&bytes, &Pick::default().with_layer(Some("B".into()))).unwrap();
        assert_eq!(o.z, 1.0);
        let handle = o.name.unwrap();
        let (_, o2) = read(
            &bytes,
            &Pick::default().with_entity(Some(handle.to_lowercase())),
        )
        .unwrap();
        assert_eq!(o2.layer.as_deref(), Some("B"));
        let e = read(&bytes, &Pick::default().with_layer(Some("X".into()))).unwrap_err();
        assert!(
            e.starts_with("d.dxf: no curve entity on layer X (curve entities: "),
            "{e}"
        );
        // SPLINE fit points whose z varies: a space curve.
        let (raw, o) = read(&bytes, &Pick::default().with_layer(Some("C".into()))).unwrap();
        assert_eq!(o.layer.as_deref(), Some("C"));
        let Raw::Space { points, .. } = raw else {
            panic!("not a space curve: {raw:?}")
        };
        assert_eq!(points[3], [3.0, 0.0, 3.0]);
    }

    #[test]
    fn bulges_and_garbage_are_refused() {
        let mut d = Drawing::new();
        d.header.version = AcadVersion::R2000;
        let lw = LwPolyline {
            vertices: pts()
                .iter()
                .enumerate()
                .map(|(i, p)| LwPolylineVertex {
                    x: p.x,
                    y: p.y,
                    bulge: if i == 2 { 0.5 } else { 0.0 },
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        };
        d.add_entity(Entity::new(EntityType::LwPolyline(lw)));
        let mut out = Vec::new();
        d.save(&mut out).unwrap();
        let e = read(&out, &Pick::default()).unwrap_err();
        assert!(
            e.ends_with(
                "vertex 3 starts an arc segment (bulge); batten takes straight segments only"
            ),
            "{e}"
        );
        let e = read(
            b"  0\nSECTION\n  2\nENTITIES\n  0\nLINE\n 10\nabc\n",
            &Pick::default(),
        )
        .unwrap_err();
        assert!(e.starts_with("d.dxf: malformed DXF: "), "{e}");
        let e = read(
            b"  0\nSECTION\n  2\nENTITIES\n  0\nENDSEC\n  0\nEOF\n",
            &Pick::default(),
        )
        .unwrap_err();
        assert_eq!(e, "d.dxf: no LWPOLYLINE, POLYLINE or SPLINE entity");
    }

    /// Regression: the `dxf` crate panics on a date out of chrono's range (found by the
    /// damaged-file property test); batten reports it as a malformed file.
    #[test]
    fn a_date_out_of_range_is_an_error_not_a_panic() {
        let text = "  0\nSECTION\n  2\nHEADER\n  9\n$TDCREATE\n 40\n1e300\n  0\nENDSEC\n  0\nEOF\n";
        let e = read(text.as_bytes(), &Pick::default()).unwrap_err();
        assert!(
            e.starts_with("d.dxf: malformed DXF: a value out of range ("),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
}
