//! [`BSplineSurface`]: a tensor-product B-spline or NURBS surface
//! `S(u, v) = Σ_i Σ_j w_ij P_ij N_i(u) N_j(v) / Σ_i Σ_j w_ij N_i(u) N_j(v)` (Salvi & Várady
//! eq 12, with optional weights), its partial derivatives up to second order and the
//! differential geometry built on them (docs/algorithms/README.md §0.6).

use crate::error::{Error, Result};
use crate::fair::local::principal_curvatures;
use crate::spline::{KnotVector, MAX_ORDER, basis_derivs};

pub use crate::geom::Xyz;

/// A tensor-product B-spline surface of degrees `(p, q)` on clamped knot vectors, with
/// optional positive weights (NURBS).
///
/// Control points are stored row by row: `P_ij` (i along u, j along v) at `i·n_v + j`, the
/// layout of the JSON file's nested lists.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineSurface {
    degree: (usize, usize),
    knots_u: KnotVector,
    knots_v: KnotVector,
    n: (usize, usize),
    control: Vec<Xyz>,
    weights: Option<Vec<f64>>,
}

/// Position and partial derivatives up to second order at one parameter pair.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SurfaceDerivs {
    /// `S(u, v)`.
    pub point: Xyz,
    /// `∂S/∂u`.
    pub su: Xyz,
    /// `∂S/∂v`.
    pub sv: Xyz,
    /// `∂²S/∂u²`.
    pub suu: Xyz,
    /// `∂²S/∂u∂v`.
    pub suv: Xyz,
    /// `∂²S/∂v²`.
    pub svv: Xyz,
}

/// The first (E, F, G) and second (L, M, N) fundamental forms and the unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FundamentalForms {
    /// `S_u·S_u`.
    pub e: f64,
    /// `S_u·S_v`.
    pub f: f64,
    /// `S_v·S_v`.
    pub g: f64,
    /// `S_uu·n`.
    pub l: f64,
    /// `S_uv·n`.
    pub m: f64,
    /// `S_vv·n`.
    pub n: f64,
    /// `n = S_u × S_v / |S_u × S_v|`.
    pub normal: Xyz,
}

/// Curvatures at one point (docs/algorithms/README.md §0.6): `κ1 ≥ κ2`, `K = κ1 κ2`, `H = (κ1 +
/// κ2)/2`, signs following the normal `S_u × S_v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceCurvature {
    /// The larger principal curvature.
    pub kappa1: f64,
    /// The smaller principal curvature.
    pub kappa2: f64,
    /// Gaussian curvature `K = (LN − M²)/(EG − F²)`.
    pub gaussian: f64,
    /// Mean curvature `H = (EN − 2FM + GL)/(2(EG − F²))`.
    pub mean: f64,
    /// The unit normal.
    pub normal: Xyz,
}

/// The non-zero basis functions of one direction at one parameter: the first index and
/// `N^{(d)}` for `d = 0..=2`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Basis1 {
    /// Index of the first of the `p + 1` non-zero functions.
    pub first: usize,
    /// `values[d][a]`: the d-th derivative of `N_{first + a}`.
    pub values: [[f64; MAX_ORDER]; 3],
}

impl BSplineSurface {
    /// A B-spline (`weights = None`) or NURBS surface from `n_u × n_v` control points given
    /// row by row (`P_ij` at `i·n_v + j`).
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] for a degree of 0 or above `MAX_ORDER − 1`, or weights
    ///   that are not positive and finite;
    /// - [`Error::TooFewPoints`] for fewer than `degree + 1` control points in a direction;
    /// - [`Error::LengthMismatch`] when `control` or `weights` does not hold `n_u·n_v` entries;
    /// - [`Error::InvalidKnots`] for a knot count other than `n + degree + 1`, knots that are
    ///   not clamped (first and last `degree + 1` equal), an interior multiplicity above the
    ///   degree, or an empty domain;
    /// - [`Error::NonFinite`] for a non-finite coordinate (index = the control point's
    ///   position in row order).
    pub fn try_new(
        degree: (usize, usize),
        knots: (KnotVector, KnotVector),
        n: (usize, usize),
        control: Vec<Xyz>,
        weights: Option<Vec<f64>>,
    ) -> Result<BSplineSurface> {
        for (dir, p, nn, k) in [
            ("u", degree.0, n.0, &knots.0),
            ("v", degree.1, n.1, &knots.1),
        ] {
            if p == 0 || p >= MAX_ORDER {
                return Err(Error::InvalidParameter {
                    name: format!("degree_{dir}"),
                    reason: format!("{p} is outside 1..={}", MAX_ORDER - 1),
                });
            }
            if nn < p + 1 {
                return Err(Error::TooFewPoints {
                    needed: p + 1,
                    got: nn,
                });
            }
            check_clamped(dir, p, nn, k)?;
        }
        let count = n.0 * n.1;
        if control.len() != count {
            return Err(Error::LengthMismatch {
                what: "control_points",
                got: control.len(),
                expected: count,
            });
        }
        if let Some(index) = control
            .iter()
            .position(|c| c.iter().any(|x| !x.is_finite()))
        {
            return Err(Error::NonFinite { index });
        }
        if let Some(w) = &weights {
            if w.len() != count {
                return Err(Error::LengthMismatch {
                    what: "weights",
                    got: w.len(),
                    expected: count,
                });
            }
            if let Some(index) = w.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(Error::InvalidParameter {
                    name: "weights".into(),
                    reason: format!(
                        "weight [{}][{}] must be positive and finite",
                        index / n.1,
                        index % n.1
                    ),
                });
            }
        }
        Ok(BSplineSurface {
            degree,
            knots_u: knots.0,
            knots_v: knots.1,
            n,
            control,
            weights,
        })
    }

    /// A non-rational surface on clamped uniform knots over `[0, 1]²`.
    ///
    /// # Errors
    /// As [`BSplineSurface::try_new`].
    pub fn clamped_uniform(
        degree: (usize, usize),
        n: (usize, usize),
        control: Vec<Xyz>,
    ) -> Result<BSplineSurface> {
        let ku = KnotVector::clamped_uniform(degree.0, n.0)?;
        let kv = KnotVector::clamped_uniform(degree.1, n.1)?;
        BSplineSurface::try_new(degree, (ku, kv), n, control, None)
    }

    /// Degrees `(p, q)` in u and v.
    pub fn degree(&self) -> (usize, usize) {
        self.degree
    }

    /// Control-point counts `(n_u, n_v)`.
    pub fn size(&self) -> (usize, usize) {
        self.n
    }

    /// The knot vectors in u and v.
    pub fn knots(&self) -> (&KnotVector, &KnotVector) {
        (&self.knots_u, &self.knots_v)
    }

    /// Control points, row by row.
    pub fn control_points(&self) -> &[Xyz] {
        &self.control
    }

    /// Control point `P_ij`.
    ///
    /// # Panics
    /// When `i ≥ n_u` or `j ≥ n_v`.
    pub fn control_point(&self, i: usize, j: usize) -> Xyz {
        assert!(
            i < self.n.0 && j < self.n.1,
            "control point index out of range"
        );
        self.control[i * self.n.1 + j]
    }

    /// The weights, row by row (`None` for a non-rational surface).
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// The same surface with other control points (same count, same order).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] or [`Error::NonFinite`].
    pub fn with_control_points(&self, control: Vec<Xyz>) -> Result<BSplineSurface> {
        BSplineSurface::try_new(
            self.degree,
            (self.knots_u.clone(), self.knots_v.clone()),
            self.n,
            control,
            self.weights.clone(),
        )
    }

    /// The parameter domain `((u_min, u_max), (v_min, v_max))`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        let u = self.knots_u.as_slice();
        let v = self.knots_v.as_slice();
        (
            (u[self.degree.0], u[self.n.0]),
            (v[self.degree.1], v[self.n.1]),
        )
    }

    /// The number of non-empty knot spans in u and v.
    pub fn spans(&self) -> (usize, usize) {
        let count = |k: &KnotVector, p: usize, n: usize| {
            k.as_slice()[p..=n]
                .windows(2)
                .filter(|w| w[1] > w[0])
                .count()
        };
        (
            count(&self.knots_u, self.degree.0, self.n.0),
            count(&self.knots_v, self.degree.1, self.n.1),
        )
    }

    /// The non-zero basis functions in u at `u` (clamped into the domain).
    pub(crate) fn basis_u(&self, u: f64) -> Basis1 {
        basis1(&self.knots_u, self.degree.0, self.n.0, u)
    }

    /// The non-zero basis functions in v at `v` (clamped into the domain).
    pub(crate) fn basis_v(&self, v: f64) -> Basis1 {
        basis1(&self.knots_v, self.degree.1, self.n.1, v)
    }

    /// `S(u, v)`. Parameters outside the domain are clamped into it.
    pub fn point(&self, u: f64, v: f64) -> Xyz {
        let (bu, bv) = (self.basis_u(u), self.basis_v(v));
        let h = self.homogeneous(&bu, &bv, 0);
        let w = h[0][3];
        [h[0][0] / w, h[0][1] / w, h[0][2] / w]
    }

    /// Position and the first and second partial derivatives at `(u, v)` (clamped into the
    /// domain; at a knot, the derivatives of the span to its right, of the last span at the
    /// end).
    pub fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (bu, bv) = (self.basis_u(u), self.basis_v(v));
        rational_derivs(&self.homogeneous(&bu, &bv, 2))
    }

    /// The homogeneous sums `Σ w P N_i^{(a)} N_j^{(b)}` (xyz) and `Σ w N_i^{(a)} N_j^{(b)}`
    /// (4th entry) for `(a, b)` in the order of [`HOMOGENEOUS_ORDER`], up to total order
    /// `order` (0 or 2).
    pub(crate) fn homogeneous(&self, bu: &Basis1, bv: &Basis1, order: usize) -> Homogeneous {
        let (p, q) = self.degree;
        let mut h = [[0.0; 4]; 6];
        let terms = if order == 0 { 1 } else { 6 };
        for a in 0..=p {
            let i = bu.first + a;
            for b in 0..=q {
                let j = bv.first + b;
                let idx = i * self.n.1 + j;
                let c = self.control[idx];
                let w = self.weights.as_ref().map_or(1.0, |w| w[idx]);
                let hw = [c[0] * w, c[1] * w, c[2] * w, w];
                for (t, &(du, dv)) in HOMOGENEOUS_ORDER.iter().enumerate().take(terms) {
                    let nn = bu.values[du][a] * bv.values[dv][b];
                    if nn != 0.0 {
                        for k in 0..4 {
                            h[t][k] += nn * hw[k];
                        }
                    }
                }
            }
        }
        h
    }

    /// The unit normal `S_u × S_v / |S_u × S_v|`, `None` at a singular point.
    pub fn normal(&self, u: f64, v: f64) -> Option<Xyz> {
        let d = self.derivatives(u, v);
        let c = cross(d.su, d.sv);
        let len = norm(c);
        (len > 0.0 && len.is_finite()).then(|| [c[0] / len, c[1] / len, c[2] / len])
    }

    /// The fundamental forms at `(u, v)`, `None` at a singular point.
    pub fn fundamental_forms(&self, u: f64, v: f64) -> Option<FundamentalForms> {
        forms(&self.derivatives(u, v))
    }

    /// Principal, Gaussian and mean curvature at `(u, v)` (docs/algorithms/README.md §0.6), `None`
    /// at a singular point (`S_u × S_v = 0`).
    pub fn curvature(&self, u: f64, v: f64) -> Option<SurfaceCurvature> {
        curvature_of(&self.derivatives(u, v))
    }

    /// The axis-aligned bounding box of the control points, `(min, max)`; it holds the
    /// surface (convex hull property, positive weights).
    pub fn control_bbox(&self) -> (Xyz, Xyz) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for c in &self.control {
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        (lo, hi)
    }

    /// The diagonal length of [`BSplineSurface::control_bbox`].
    pub fn control_diagonal(&self) -> f64 {
        let (lo, hi) = self.control_bbox();
        norm(sub(hi, lo))
    }
}

/// Order of the partial derivatives `(a, b)` (a in u, b in v) in [`Homogeneous`].
pub(crate) const HOMOGENEOUS_ORDER: [(usize, usize); 6] =
    [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];

/// Homogeneous partial derivatives `[A_x, A_y, A_z, W]` in [`HOMOGENEOUS_ORDER`].
pub(crate) type Homogeneous = [[f64; 4]; 6];

/// The partial derivatives of `S = A / W` from the homogeneous ones by the quotient rule
/// (Piegl & Tiller eq 4.20): `S_u = (A_u − W_u S)/W`,
/// `S_uu = (A_uu − 2 W_u S_u − W_uu S)/W`, `S_uv = (A_uv − W_u S_v − W_v S_u − W_uv S)/W`.
/// With all weights 1 this is the polynomial case exactly (`W = 1`, its derivatives 0).
pub(crate) fn rational_derivs(h: &Homogeneous) -> SurfaceDerivs {
    let w = h[0][3];
    let a = |t: usize| [h[t][0], h[t][1], h[t][2]];
    let s = scale(a(0), 1.0 / w);
    let su = scale(sub(a(1), scale(s, h[1][3])), 1.0 / w);
    let sv = scale(sub(a(2), scale(s, h[2][3])), 1.0 / w);
    let suu = scale(
        sub(sub(a(3), scale(su, 2.0 * h[1][3])), scale(s, h[3][3])),
        1.0 / w,
    );
    let suv = scale(
        sub(
            sub(sub(a(4), scale(sv, h[1][3])), scale(su, h[2][3])),
            scale(s, h[4][3]),
        ),
        1.0 / w,
    );
    let svv = scale(
        sub(sub(a(5), scale(sv, 2.0 * h[2][3])), scale(s, h[5][3])),
        1.0 / w,
    );
    SurfaceDerivs {
        point: s,
        su,
        sv,
        suu,
        suv,
        svv,
    }
}

/// The fundamental forms from the partial derivatives, `None` where `S_u × S_v` vanishes.
pub(crate) fn forms(d: &SurfaceDerivs) -> Option<FundamentalForms> {
    let c = cross(d.su, d.sv);
    let len = norm(c);
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let normal = scale(c, 1.0 / len);
    Some(FundamentalForms {
        e: dot(d.su, d.su),
        f: dot(d.su, d.sv),
        g: dot(d.sv, d.sv),
        l: dot(d.suu, normal),
        m: dot(d.suv, normal),
        n: dot(d.svv, normal),
        normal,
    })
}

/// Curvatures from the partial derivatives (docs/algorithms/README.md §0.6, through the curve
/// code's [`principal_curvatures`]).
pub(crate) fn curvature_of(d: &SurfaceDerivs) -> Option<SurfaceCurvature> {
    let pc = principal_curvatures(d.su, d.sv, d.suu, d.suv, d.svv)?;
    Some(SurfaceCurvature {
        kappa1: pc.kappa1,
        kappa2: pc.kappa2,
        gaussian: pc.kappa1 * pc.kappa2,
        mean: 0.5 * (pc.kappa1 + pc.kappa2),
        normal: pc.normal,
    })
}

fn basis1(k: &KnotVector, p: usize, n: usize, t: f64) -> Basis1 {
    let u = k.as_slice();
    let t = t.clamp(u[p], u[n]);
    let span = k.find_span(p, n, t);
    let mut out = [[0.0; MAX_ORDER]; 4];
    basis_derivs(u, p, span, t, 2, &mut out);
    Basis1 {
        first: span - p,
        values: [out[0], out[1], out[2]],
    }
}

fn check_clamped(dir: &str, p: usize, n: usize, k: &KnotVector) -> Result<()> {
    let u = k.as_slice();
    if u.len() != n + p + 1 {
        return Err(Error::InvalidKnots(format!(
            "knots_{dir} has {} knots for {n} control points of degree {p}: expected {}",
            u.len(),
            n + p + 1
        )));
    }
    if u[..=p].iter().any(|&x| x != u[0]) || u[n..].iter().any(|&x| x != u[n + p]) {
        return Err(Error::InvalidKnots(format!(
            "knots_{dir} is not clamped: the first and the last {} knots must be equal",
            p + 1
        )));
    }
    if u[p] >= u[n] {
        return Err(Error::InvalidKnots(format!(
            "knots_{dir}: the parameter domain is empty"
        )));
    }
    let mut i = p + 1;
    while i < n {
        let m = u[i..n].iter().take_while(|&&x| x == u[i]).count();
        if m > p {
            return Err(Error::InvalidKnots(format!(
                "knots_{dir}: interior knot {} has multiplicity {m} > degree {p}",
                u[i]
            )));
        }
        i += m;
    }
    Ok(())
}

pub(crate) fn dot(a: Xyz, b: Xyz) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: Xyz, b: Xyz) -> Xyz {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn sub(a: Xyz, b: Xyz) -> Xyz {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn scale(a: Xyz, s: f64) -> Xyz {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn norm(a: Xyz) -> f64 {
    dot(a, a).sqrt()
}

pub(crate) fn distance(a: Xyz, b: Xyz) -> f64 {
    norm(sub(a, b))
}
