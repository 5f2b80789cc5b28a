//! # batten — fairing of planar curves
//!
//! batten takes a point sequence or a B-spline whose curvature plot wiggles (spurious
//! inflections, bumps, curvature vibrations) and moves the data as little as possible until the
//! curve is fair, under a tolerance in data units that is never exceeded.
//!
//! The crate is organised by what a thing *is*:
//! - [`geom`]: points, vectors, bounding boxes, rigid motions;
//! - [`curve`]: capability traits for parametric curves;
//! - [`numeric`]: banded solvers, quadrature, 1-D minimisers;
//! - [`spline`]: spline representations and their constructors;
//! - [`analysis`]: curvature, arc length, inflections, energies, [`FairnessMetrics`];
//! - [`fair`]: the fairing methods behind one interface ([`fair::fair`]);
//! - [`io`]: point lists and curves in CSV, JSON, DXF, IGES and SVG;
//! - [`surface`]: B-spline surfaces, their interrogation and fairing;
//! - `plot`: SVG pictures of curves, curvature combs and curvature graphs (feature `plot`);
//! - [`error`]: the [`Error`] every fallible function returns.
//!
//! Each namespace re-exports its items by name, flat; the files below it are private modules
//! (each namespace's documentation lists what it exports). The most used names are also here
//! at the root.
//!
//! ```
//! use batten::{fair, FairOptions, Point, PointSeq};
//!
//! // A noisy arc.
//! let pts: Vec<Point> = (0..40)
//!     .map(|i| {
//!         let t = i as f64 * 0.05;
//!         let noise = if i % 2 == 0 { 1e-3 } else { -1e-3 };
//!         Point::new(t.cos() * (1.0 + noise), t.sin())
//!     })
//!     .collect();
//! let input = PointSeq::open(pts).unwrap();
//! let opts = FairOptions::default().with_tolerance(0.01);
//! let out = fair::fair("mst", &input, &opts).unwrap();
//! assert!(out.report.max_displacement <= 0.01);
//! assert!(out.report.tolerance_met);
//! ```

#![warn(unreachable_pub)]

pub mod analysis;
pub mod curve;
pub mod error;
pub mod fair;
pub mod geom;
pub mod io;
pub mod numeric;
#[cfg(feature = "plot")]
pub mod plot;
pub mod spline;
pub mod surface;
#[cfg(test)]
mod test_rng;
#[cfg(test)]
mod test_vectors;

pub use analysis::FairnessMetrics;
pub use curve::{Curve, CurveDeriv, Derivatives, Piecewise};
pub use error::{Error, Result};
pub use fair::{EndFix, FairOptions, FairReport, Faired};
pub use geom::PointSeq;
pub use geom::{BBox, Point, Rigid, SpaceSeq, Vec2, Xyz};
