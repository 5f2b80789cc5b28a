//! Pictures for surface interrogation: the surface tessellated on a parameter grid
//! ([`SurfaceMesh`]), seen in an orthographic view ([`Camera`]) and rasterised with a depth
//! buffer into an RGBA [`Raster`], each pixel coloured by a [`Shading`]:
//!
//! - a colour map of a scalar field ([`Field`]: κ1, κ2, K, H, or the distance to another
//!   surface at the same parameters), blue below zero, white at zero, red above
//!   ([`Palette::Diverging`]), or white to dark blue from zero ([`Palette::Sequential`], for
//!   the deviation), lightly shaded by the angle to the viewer so the shape stays legible;
//! - isophotes: bands of equal `n·L` (the brightness under a parallel light `L`), with a
//!   black line where the band changes. A G1 (tangent) break makes the lines jump, a G2
//!   (curvature) break makes them kink, a dent closes them into rings;
//! - zebra: the reflection `r = 2(n·e)n − e` of a room lit by parallel tubes that run along
//!   the picture's horizontal, black and white by the angle of `r` about that axis. Stripes
//!   are continuous across a G1-continuous surface and smooth across a G2 one.
//!
//! Normals are evaluated exactly at the mesh vertices and interpolated per pixel; both sides
//! of the surface are lit (the normal is turned towards the viewer), as in CAD viewers.
//! Everything here is pure computation on pixels; encoding (PNG, SVG) is the caller's.

use super::patch::{BSplineSurface, SurfaceCurvature, Xyz};
use super::sample::{SampleGrid, sample_curvature};
use crate::error::{Error, Result};

/// Mesh samples per knot span and direction.
pub const MESH_SAMPLES_PER_SPAN: usize = 8;

/// The fewest mesh samples in a direction, so that a single-span patch still renders
/// smoothly.
pub const MESH_MIN_SAMPLES: usize = 97;

/// Brightness of a colour-map pixel seen edge-on, relative to one seen face-on: the colour
/// is multiplied by `MAP_SHADE_FLOOR + (1 − MAP_SHADE_FLOOR)·|n·e|`.
pub const MAP_SHADE_FLOOR: f64 = 0.6;

/// The colour of samples where the surface is singular (`S_u × S_v = 0`).
pub const SINGULAR_RGB: [u8; 3] = [128, 128, 128];

/// The background.
pub const BACKGROUND_RGB: [u8; 3] = [255, 255, 255];

/// A scalar field over a surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// The larger principal curvature κ1.
    Kappa1,
    /// The smaller principal curvature κ2.
    Kappa2,
    /// Gaussian curvature K.
    Gaussian,
    /// Mean curvature H.
    Mean,
}

impl Field {
    fn of(self, c: &SurfaceCurvature) -> f64 {
        match self {
            Field::Kappa1 => c.kappa1,
            Field::Kappa2 => c.kappa2,
            Field::Gaussian => c.gaussian,
            Field::Mean => c.mean,
        }
    }
}

/// How a value in a colour map's range becomes a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Palette {
    /// Blue (low) – white (middle) – red (high); the range is symmetric about 0 for signed
    /// quantities, so white is 0.
    Diverging,
    /// White (low) to dark blue (high), for distances.
    Sequential,
}

impl Palette {
    /// The colour at `t ∈ [0, 1]` (clamped; NaN gives [`SINGULAR_RGB`]).
    pub fn colour(self, t: f64) -> [u8; 3] {
        if t.is_nan() {
            return SINGULAR_RGB;
        }
        let t = t.clamp(0.0, 1.0);
        let mix = |a: [f64; 3], b: [f64; 3], s: f64| -> [u8; 3] {
            let c = |k: usize| (a[k] + (b[k] - a[k]) * s).round().clamp(0.0, 255.0) as u8;
            [c(0), c(1), c(2)]
        };
        const BLUE: [f64; 3] = [33.0, 102.0, 172.0];
        const WHITE: [f64; 3] = [247.0, 247.0, 247.0];
        const RED: [f64; 3] = [178.0, 24.0, 43.0];
        const NAVY: [f64; 3] = [8.0, 48.0, 107.0];
        match self {
            Palette::Diverging if t < 0.5 => mix(BLUE, WHITE, 2.0 * t),
            Palette::Diverging => mix(WHITE, RED, 2.0 * t - 1.0),
            Palette::Sequential => mix(WHITE, NAVY, t),
        }
    }
}

/// How pixels are coloured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// A colour map of the mesh's values over `[lo, hi]`.
    Map {
        /// The value drawn at the palette's start.
        lo: f64,
        /// The value drawn at its end.
        hi: f64,
        /// The palette.
        palette: Palette,
    },
    /// Isophotes: `bands` bands of equal width of the brightness `n·light` over `[lo, hi]`
    /// (see [`isophote_range`] for the range seen on given meshes).
    Isophotes {
        /// Direction towards the light (need not be unit).
        light: Xyz,
        /// The brightness at the first band's start.
        lo: f64,
        /// The brightness at the last band's end.
        hi: f64,
        /// Number of bands.
        bands: usize,
    },
    /// Zebra: `stripes` black and `stripes` white stripes over the angle range `[lo, hi]`
    /// of the reflection about the tubes (see [`zebra_range`]).
    Zebra {
        /// The angle at the first stripe's start, in radians.
        lo: f64,
        /// The angle at the last stripe's end.
        hi: f64,
        /// Number of stripe pairs.
        stripes: usize,
    },
}

/// A surface tessellated on a parameter grid: points, unit normals and a scalar value per
/// vertex (row by row, u outer).
#[derive(Clone, Debug)]
pub struct SurfaceMesh {
    nu: usize,
    nv: usize,
    points: Vec<Xyz>,
    normals: Vec<Option<Xyz>>,
    curvature: Vec<Option<SurfaceCurvature>>,
    values: Vec<f64>,
}

impl SurfaceMesh {
    /// The mesh grid of a surface: [`MESH_SAMPLES_PER_SPAN`] per knot span and direction, at
    /// least [`MESH_MIN_SAMPLES`].
    pub fn grid(s: &BSplineSurface) -> SampleGrid {
        let g = SampleGrid::with_density(s, MESH_SAMPLES_PER_SPAN);
        let (du, dv) = s.domain();
        SampleGrid {
            u: crate::fair::local::uniform_samples(du, g.u.len().max(MESH_MIN_SAMPLES)),
            v: crate::fair::local::uniform_samples(dv, g.v.len().max(MESH_MIN_SAMPLES)),
        }
    }

    /// Tessellate `s` on `grid`, with the curvature at every vertex; the values start as NaN.
    pub fn new(s: &BSplineSurface, grid: &SampleGrid) -> SurfaceMesh {
        let curvature = sample_curvature(s, grid);
        let mut points = Vec::with_capacity(grid.len());
        for &u in &grid.u {
            for &v in &grid.v {
                points.push(s.point(u, v));
            }
        }
        SurfaceMesh {
            nu: grid.u.len(),
            nv: grid.v.len(),
            normals: curvature.iter().map(|c| c.map(|c| c.normal)).collect(),
            values: vec![f64::NAN; points.len()],
            points,
            curvature,
        }
    }

    /// Set the values to a curvature field (NaN at singular vertices).
    pub fn set_field(&mut self, f: Field) {
        self.values = self
            .curvature
            .iter()
            .map(|c| c.map_or(f64::NAN, |c| f.of(&c)))
            .collect();
    }

    /// Set the values to `|S(u, v) − other(u, v)|` at the mesh's parameters `grid` (the grid
    /// this mesh was built on).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `grid` is not this mesh's size.
    pub fn set_deviation(&mut self, other: &BSplineSurface, grid: &SampleGrid) -> Result<()> {
        if grid.u.len() != self.nu || grid.v.len() != self.nv {
            return Err(Error::LengthMismatch {
                what: "deviation grid",
                expected: self.nu * self.nv,
                got: grid.len(),
            });
        }
        let mut k = 0;
        for &u in &grid.u {
            for &v in &grid.v {
                let q = other.point(u, v);
                let p = self.points[k];
                self.values[k] = dist(p, q);
                k += 1;
            }
        }
        Ok(())
    }

    /// The values at the vertices.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The smallest and largest finite value, or `None` if there is none.
    pub fn value_range(&self) -> Option<(f64, f64)> {
        self.values
            .iter()
            .filter(|x| x.is_finite())
            .fold(None, |acc, &x| match acc {
                None => Some((x, x)),
                Some((lo, hi)) => Some((lo.min(x), hi.max(x))),
            })
    }

    /// The vertices.
    pub fn points(&self) -> &[Xyz] {
        &self.points
    }
}

/// An orthographic view: the picture plane's axes `right` and `up`, the direction `eye`
/// towards the viewer, and the map from the plane to pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    right: Xyz,
    up: Xyz,
    eye: Xyz,
    scale: f64,
    centre: [f64; 2],
    size: [usize; 2],
}

impl Camera {
    /// Look along `−view` (from the side `view` points to) so that every point of `meshes`
    /// fits a `width × height` picture with `margin` pixels free on each side. The picture's
    /// vertical is the projection of +z (of +y when looking along z).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a zero or non-finite `view`, or a picture smaller
    /// than its margins.
    pub fn fit(
        view: Xyz,
        meshes: &[&SurfaceMesh],
        width: usize,
        height: usize,
        margin: usize,
    ) -> Result<Camera> {
        let eye = unit(view).ok_or_else(|| Error::InvalidParameter {
            name: "view".into(),
            reason: "must be a finite non-zero direction".into(),
        })?;
        if width <= 2 * margin || height <= 2 * margin {
            return Err(Error::InvalidParameter {
                name: "picture size".into(),
                reason: format!("{width}x{height} leaves no room inside a {margin}-pixel margin"),
            });
        }
        let right = unit(cross([0.0, 0.0, 1.0], eye))
            .or_else(|| unit(cross([0.0, 1.0, 0.0], eye)))
            .unwrap_or([1.0, 0.0, 0.0]);
        let up = cross(eye, right);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in meshes.iter().flat_map(|m| m.points.iter()) {
            let q = [dot(*p, right), dot(*p, up)];
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !(lo[0].is_finite() && hi[0].is_finite()) {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let span = |k: usize| (hi[k] - lo[k]).max(f64::MIN_POSITIVE);
        let scale =
            ((width - 2 * margin) as f64 / span(0)).min((height - 2 * margin) as f64 / span(1));
        Ok(Camera {
            right,
            up,
            eye,
            scale,
            centre: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
            size: [width, height],
        })
    }

    /// Pixel coordinates `(x, y)` (y down) and depth (larger is nearer) of a point.
    pub fn project(&self, p: Xyz) -> [f64; 3] {
        [
            0.5 * self.size[0] as f64 + self.scale * (dot(p, self.right) - self.centre[0]),
            0.5 * self.size[1] as f64 - self.scale * (dot(p, self.up) - self.centre[1]),
            dot(p, self.eye),
        ]
    }
}

/// An RGBA image, row by row from the top, 4 bytes a pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Raster {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width · height · 4` bytes.
    pub rgba: Vec<u8>,
}

impl Raster {
    /// A raster filled with one opaque colour.
    pub fn filled(width: usize, height: usize, rgb: [u8; 3]) -> Raster {
        let mut rgba = Vec::with_capacity(width * height * 4);
        for _ in 0..width * height {
            rgba.extend_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
        Raster {
            width,
            height,
            rgba,
        }
    }

    /// The colour at `(x, y)`.
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        let k = 4 * (y * self.width + x);
        [self.rgba[k], self.rgba[k + 1], self.rgba[k + 2]]
    }

    /// Set the colour at `(x, y)` (ignored outside).
    pub fn put(&mut self, x: usize, y: usize, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let k = 4 * (y * self.width + x);
            self.rgba[k..k + 3].copy_from_slice(&rgb);
            self.rgba[k + 3] = 255;
        }
    }

    /// Copy `other` in with its top-left corner at `(x, y)` (clipped).
    pub fn blit(&mut self, other: &Raster, x: usize, y: usize) {
        for j in 0..other.height {
            for i in 0..other.width {
                self.put(x + i, y + j, other.pixel(i, j));
            }
        }
    }
}

/// What the rasteriser keeps per covered pixel.
#[derive(Clone, Copy)]
struct Fragment {
    depth: f64,
    normal: Xyz,
    value: f64,
}

/// Draw a mesh seen by `camera`, coloured by `shading`.
pub fn render(mesh: &SurfaceMesh, camera: &Camera, shading: &Shading) -> Raster {
    let [w, h] = camera.size;
    let mut frags: Vec<Option<Fragment>> = vec![None; w * h];
    let proj: Vec<[f64; 3]> = mesh.points.iter().map(|&p| camera.project(p)).collect();
    let at = |i: usize, j: usize| i * mesh.nv + j;
    for i in 0..mesh.nu.saturating_sub(1) {
        for j in 0..mesh.nv.saturating_sub(1) {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            for tri in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                raster_triangle(mesh, &proj, tri, [w, h], &mut frags);
            }
        }
    }
    let mut out = Raster::filled(w, h, BACKGROUND_RGB);
    let eye = camera.eye;
    // Band index per pixel, for the isophote edges.
    let mut band: Vec<Option<i64>> = vec![None; w * h];
    for y in 0..h {
        for x in 0..w {
            let Some(f) = frags[y * w + x] else { continue };
            let Some(n) = unit(f.normal) else {
                out.put(x, y, SINGULAR_RGB);
                continue;
            };
            // Two-sided: light the side that faces the viewer.
            let n = if dot(n, eye) < 0.0 { scale(n, -1.0) } else { n };
            let facing = dot(n, eye).clamp(0.0, 1.0);
            let rgb = match *shading {
                Shading::Map { lo, hi, palette } => {
                    let t = if hi > lo {
                        (f.value - lo) / (hi - lo)
                    } else {
                        0.5
                    };
                    let c = palette.colour(t);
                    let k = MAP_SHADE_FLOOR + (1.0 - MAP_SHADE_FLOOR) * facing;
                    c.map(|v| (f64::from(v) * k).round() as u8)
                }
                Shading::Isophotes {
                    light,
                    lo,
                    hi,
                    bands,
                } => {
                    let i = brightness(n, light, eye);
                    // The brightest value `hi` belongs to the last band, not a new one.
                    let b = band_of(i, lo, hi, bands).clamp(0, bands.max(1) as i64 - 1);
                    band[y * w + x] = Some(b);
                    let t = (b as f64 + 0.5) / bands.max(1) as f64;
                    isophote_colour(t)
                }
                Shading::Zebra { lo, hi, stripes } => {
                    let k = band_of(zebra_angle(n, camera), lo, hi, 2 * stripes);
                    if k.rem_euclid(2) == 0 {
                        [250, 250, 250]
                    } else {
                        [20, 20, 20]
                    }
                }
            };
            out.put(x, y, rgb);
        }
    }
    if matches!(shading, Shading::Isophotes { .. }) {
        for y in 0..h {
            for x in 0..w {
                let Some(b) = band[y * w + x] else { continue };
                let right = (x + 1 < w).then(|| band[y * w + x + 1]).flatten();
                let below = (y + 1 < h).then(|| band[(y + 1) * w + x]).flatten();
                if right.is_some_and(|r| r != b) || below.is_some_and(|r| r != b) {
                    out.put(x, y, [0, 0, 0]);
                }
            }
        }
    }
    out
}

/// The brightness `n·l` of a unit normal already turned towards the viewer, for a light
/// along `light` (along `eye` when `light` is zero).
fn brightness(n: Xyz, light: Xyz, eye: Xyz) -> f64 {
    dot(n, unit(light).unwrap_or(eye))
}

/// The angle about the zebra's light tubes (which run along the picture's horizontal) of
/// the reflection `r = 2(n·e)n − e` of the viewing direction.
fn zebra_angle(n: Xyz, camera: &Camera) -> f64 {
    let r = sub(scale(n, 2.0 * dot(n, camera.eye)), camera.eye);
    dot(r, camera.up).atan2(dot(r, camera.eye))
}

/// Which of `count` equal bands over `[lo, hi]` holds `x` (bands continue outside).
fn band_of(x: f64, lo: f64, hi: f64, count: usize) -> i64 {
    let width = if hi > lo { hi - lo } else { 1.0 } / count.max(1) as f64;
    ((x - lo) / width).floor() as i64
}

/// The vertex unit normals of the meshes, turned towards the viewer.
fn facing_normals<'a>(
    meshes: &'a [&SurfaceMesh],
    camera: &'a Camera,
) -> impl Iterator<Item = Xyz> + 'a {
    meshes
        .iter()
        .flat_map(|m| m.normals.iter())
        .flatten()
        .map(|&n| {
            if dot(n, camera.eye) < 0.0 {
                scale(n, -1.0)
            } else {
                n
            }
        })
}

fn range_of(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    if lo <= hi { (lo, hi) } else { (0.0, 0.0) }
}

/// The range of the brightness `n·light` over the vertices of `meshes` as `camera` sees
/// them, so that the isophote bands of a gently curved panel spread over what is there
/// rather than over all of `[−1, 1]`, the same for a before and an after panel.
pub fn isophote_range(meshes: &[&SurfaceMesh], camera: &Camera, light: Xyz) -> (f64, f64) {
    range_of(facing_normals(meshes, camera).map(|n| brightness(n, light, camera.eye)))
}

/// The range of the zebra angle over the vertices of `meshes` (see [`isophote_range`]).
pub fn zebra_range(meshes: &[&SurfaceMesh], camera: &Camera) -> (f64, f64) {
    range_of(facing_normals(meshes, camera).map(|n| zebra_angle(n, camera)))
}

/// The isophote bands' colours: a dark-to-light ramp with a hue that turns, so that
/// neighbouring bands differ both in brightness and in hue.
fn isophote_colour(t: f64) -> [u8; 3] {
    let l = 0.25 + 0.7 * t;
    let hue = 2.0 * std::f64::consts::PI * t;
    let c = |phase: f64| {
        ((l + 0.18 * (hue + phase).cos()) * 255.0)
            .round()
            .clamp(0.0, 255.0) as u8
    };
    let third = 2.0 * std::f64::consts::PI / 3.0;
    [c(0.0), c(third), c(2.0 * third)]
}

/// Fill one triangle into the fragment buffer, interpolating depth, normal and value
/// linearly (exact for an orthographic view), keeping the nearest fragment.
fn raster_triangle(
    mesh: &SurfaceMesh,
    proj: &[[f64; 3]],
    tri: [usize; 3],
    [w, h]: [usize; 2],
    frags: &mut [Option<Fragment>],
) {
    let [a, b, c] = tri.map(|k| proj[k]);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
    let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize;
    let x1 = (a[0].max(b[0]).max(c[0]).ceil().max(0.0) as usize).min(w);
    let y1 = (a[1].max(b[1]).max(c[1]).ceil().max(0.0) as usize).min(h);
    let normal = |k: usize| mesh.normals[tri[k]].unwrap_or([f64::NAN; 3]);
    let (na, nb, nc) = (normal(0), normal(1), normal(2));
    let (va, vb, vc) = (
        mesh.values[tri[0]],
        mesh.values[tri[1]],
        mesh.values[tri[2]],
    );
    for y in y0..y1 {
        for x in x0..x1 {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let wa = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
            let wb = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
            let wc = 1.0 - wa - wb;
            if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                continue;
            }
            let depth = wa * a[2] + wb * b[2] + wc * c[2];
            let slot = &mut frags[y * w + x];
            if slot.is_some_and(|f| f.depth >= depth) {
                continue;
            }
            let n = [0, 1, 2].map(|k| wa * na[k] + wb * nb[k] + wc * nc[k]);
            *slot = Some(Fragment {
                depth,
                normal: n,
                value: wa * va + wb * vb + wc * vc,
            });
        }
    }
}

fn dot(a: Xyz, b: Xyz) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Xyz, b: Xyz) -> Xyz {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: Xyz, b: Xyz) -> Xyz {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: Xyz, s: f64) -> Xyz {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dist(a: Xyz, b: Xyz) -> f64 {
    dot(sub(a, b), sub(a, b)).sqrt()
}

/// The unit vector along `a`, or `None` for a zero, NaN or infinite vector.
fn unit(a: Xyz) -> Option<Xyz> {
    let n = dot(a, a).sqrt();
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bicubic graph of `z = c·(x² + y²)/2` over `[−1, 1]²` sampled on a grid (its
    /// curvature at the centre is `c` in both directions).
    fn bowl(c: f64) -> BSplineSurface {
        let n = 9;
        let grid: Vec<Vec<Xyz>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let x = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                        let y = -1.0 + 2.0 * j as f64 / (n - 1) as f64;
                        [x, y, 0.5 * c * (x * x + y * y)]
                    })
                    .collect()
            })
            .collect();
        super::super::fit::interpolate_grid(&grid).unwrap()
    }

    #[test]
    fn the_picture_is_fitted_and_centred() {
        let s = bowl(0.0);
        let m = SurfaceMesh::new(&s, &SurfaceMesh::grid(&s));
        let cam = Camera::fit([0.0, 0.0, 1.0], &[&m], 200, 100, 10).unwrap();
        // Seen from +z, the square [−1, 1]² is limited by the height: 80 px for 2 units.
        let p = cam.project([1.0, 1.0, 0.0]);
        assert!(
            (p[0] - 140.0).abs() < 1e-9 && (p[1] - 10.0).abs() < 1e-9,
            "{p:?}"
        );
        let q = cam.project([-1.0, -1.0, 0.0]);
        assert!(
            (q[0] - 60.0).abs() < 1e-9 && (q[1] - 90.0).abs() < 1e-9,
            "{q:?}"
        );
        assert!(Camera::fit([0.0; 3], &[&m], 200, 100, 10).is_err());
        assert!(Camera::fit([0.0, 0.0, 1.0], &[&m], 20, 100, 10).is_err());
    }

    #[test]
    fn the_mesh_covers_exactly_its_projection() {
        let s = bowl(0.0);
        let m = SurfaceMesh::new(&s, &SurfaceMesh::grid(&s));
        let cam = Camera::fit([0.0, 0.0, 1.0], &[&m], 100, 100, 10).unwrap();
        let (lo, hi) = zebra_range(&[&m], &cam);
        assert_eq!((lo, hi), (0.0, 0.0));
        let r = render(&m, &cam, &Shading::Zebra { lo, hi, stripes: 4 });
        // Inside the square [10, 90]²: a plane facing the viewer reflects the viewer's own
        // direction: one stripe, white. Outside: background.
        for (x, y) in [(12, 12), (50, 50), (87, 88)] {
            assert_eq!(r.pixel(x, y), [250, 250, 250], "({x}, {y})");
        }
        for (x, y) in [(5, 50), (50, 95), (95, 95)] {
            assert_eq!(r.pixel(x, y), BACKGROUND_RGB, "({x}, {y})");
        }
    }

    #[test]
    fn colour_maps_follow_the_field() {
        let s = bowl(0.5);
        let grid = SurfaceMesh::grid(&s);
        let mut m = SurfaceMesh::new(&s, &grid);
        m.set_field(Field::Gaussian);
        let (lo, hi) = m.value_range().unwrap();
        // K = c² / (1 + c²|x|²)² on the paraboloid: c² at the centre, falling outwards.
        assert!((hi - 0.25).abs() < 5e-3, "{hi}");
        assert!(lo > 0.0 && lo < hi, "{lo}");
        let cam = Camera::fit([0.0, 0.0, 1.0], &[&m], 101, 101, 0).unwrap();
        let shading = Shading::Map {
            lo: -hi,
            hi,
            palette: Palette::Diverging,
        };
        let r = render(&m, &cam, &shading);
        // Positive everywhere: red-ish (r > b), reddest in the middle.
        let centre = r.pixel(50, 50);
        let edge = r.pixel(2, 50);
        assert!(
            centre[0] > centre[2] && edge[0] > edge[2],
            "{centre:?} {edge:?}"
        );
        assert!(centre[1] < edge[1], "{centre:?} {edge:?}");
        // The deviation of a surface from itself is 0 everywhere.
        m.set_deviation(&s, &grid).unwrap();
        assert_eq!(m.value_range(), Some((0.0, 0.0)));
        assert!(
            m.set_deviation(
                &s,
                &SampleGrid {
                    u: vec![0.0],
                    v: vec![0.0]
                }
            )
            .is_err()
        );
    }

    #[test]
    fn isophotes_of_a_bowl_are_rings_about_the_light() {
        let s = bowl(1.0);
        let m = SurfaceMesh::new(&s, &SurfaceMesh::grid(&s));
        let cam = Camera::fit([0.0, 0.0, 1.0], &[&m], 121, 121, 0).unwrap();
        let light = [0.0, 0.0, 1.0];
        let (lo, hi) = isophote_range(&[&m], &cam, light);
        // n·z = 1/sqrt(1 + x² + y²) over [−1, 1]²: from 1/sqrt(3) at the corners to 1 (up
        // to the interpolant's error).
        assert!((lo - 1.0 / 3f64.sqrt()).abs() < 1e-2, "{lo}");
        assert!((hi - 1.0).abs() < 1e-6, "{hi}");
        let shading = Shading::Isophotes {
            light,
            lo,
            hi,
            bands: 16,
        };
        let r = render(&m, &cam, &shading);
        // n·z = 1/sqrt(1 + r²) depends on the radius only: the picture is symmetric under
        // the square's symmetries (up to a pixel at band edges, so compare a ring's count of
        // black pixels rather than single pixels).
        let black = |f: &dyn Fn(usize) -> (usize, usize)| {
            (0..121)
                .filter(|&k| r.pixel(f(k).0, f(k).1) == [0, 0, 0])
                .count()
        };
        let row = black(&|k| (k, 60));
        let col = black(&|k| (60, k));
        assert!(row >= 4, "{row}");
        assert!(row.abs_diff(col) <= 1, "{row} {col}");
        // The brightest band (facing the light) is at the centre.
        assert!(r.pixel(60, 60) != [0, 0, 0]);
        assert_eq!(r.pixel(60, 60), isophote_colour(15.5 / 16.0));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// Seen from any side, a flat square covers its projected parallelogram — as many
        /// pixels as its area, up to the pixels its outline cuts — and reflects the viewer's
        /// direction everywhere, so the zebra shows one white stripe.
        #[test]
        fn a_square_covers_its_projection_from_any_side(
            x in -1.0f64..1.0, y in -1.0f64..1.0, z in 0.2f64..1.0, flip in proptest::bool::ANY,
        ) {
            let s = bowl(0.0);
            let m = SurfaceMesh::new(&s, &SurfaceMesh::grid(&s));
            let view = [x, y, if flip { -z } else { z }];
            let cam = Camera::fit(view, &[&m], 160, 120, 8).unwrap();
            let (lo, hi) = zebra_range(&[&m], &cam);
            proptest::prop_assert!((hi - lo).abs() < 1e-9, "{lo} {hi}");
            let r = render(&m, &cam, &Shading::Zebra { lo, hi, stripes: 6 });
            let mut covered = 0usize;
            for py in 0..r.height {
                for px in 0..r.width {
                    let c = r.pixel(px, py);
                    if c != BACKGROUND_RGB {
                        proptest::prop_assert_eq!(c, [250, 250, 250]);
                        covered += 1;
                    }
                }
            }
            let corner = |a: f64, b: f64| cam.project([a, b, 0.0]);
            let (p0, p1, p3) = (corner(-1.0, -1.0), corner(1.0, -1.0), corner(-1.0, 1.0));
            let (e1, e2) = ([p1[0] - p0[0], p1[1] - p0[1]], [p3[0] - p0[0], p3[1] - p0[1]]);
            let area = (e1[0] * e2[1] - e1[1] * e2[0]).abs();
            let perimeter = 2.0 * (e1[0].hypot(e1[1]) + e2[0].hypot(e2[1]));
            proptest::prop_assert!(
                (covered as f64 - area).abs() <= perimeter,
                "{covered} pixels for an area of {area} (perimeter {perimeter})"
            );
        }
    }

    #[test]
    fn palettes_run_from_end_to_end() {
        assert_eq!(Palette::Diverging.colour(0.5), [247, 247, 247]);
        assert_eq!(Palette::Diverging.colour(-3.0), [33, 102, 172]);
        assert_eq!(Palette::Diverging.colour(1.0), [178, 24, 43]);
        assert_eq!(Palette::Sequential.colour(0.0), [247, 247, 247]);
        assert_eq!(Palette::Sequential.colour(f64::NAN), SINGULAR_RGB);
    }
}
