//! [`EndFix`]: what to keep at the two ends of an open curve, the one representation of
//! `--fix-ends` for every method and measure.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::error::{Error, Result};

/// What `--fix-ends` keeps at the two ends of an open curve: nothing, the end points
/// (position, G0), also the end tangents (G1) or also the end curvatures (G2).
///
/// Methods that move points hold [`EndFix::held`] points at each end: 1 for the position, 2
/// for the tangent (the end chord keeps its direction and length) and 3 for the curvature
/// (also the circle through the three end points). Methods that move B-spline control points
/// hold as many end control points, which keeps the clamped curve's end tangent and
/// curvature exactly (`kuragano`, whose quintic is not clamped, holds every control point
/// acting at an end). The report measures the discrete end tangents and curvatures
/// ([`crate::fair::FairReport::end_changes`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EndFix {
    /// The ends may move.
    #[default]
    Free,
    /// The end points stay where they are.
    Position,
    /// The end points and end tangents are kept.
    Tangent,
    /// The end points, tangents and curvatures are kept.
    Curvature,
}

impl EndFix {
    /// Every value, loosest first.
    pub const ALL: [EndFix; 4] = [
        EndFix::Free,
        EndFix::Position,
        EndFix::Tangent,
        EndFix::Curvature,
    ];

    /// True unless [`EndFix::Free`].
    pub fn is_fixed(self) -> bool {
        self != EndFix::Free
    }

    /// Points (or end control points) held at each end: 0, 1, 2 or 3.
    pub fn held(self) -> usize {
        match self {
            EndFix::Free => 0,
            EndFix::Position => 1,
            EndFix::Tangent => 2,
            EndFix::Curvature => 3,
        }
    }

    /// The name used on the command line and in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            EndFix::Free => "free",
            EndFix::Position => "position",
            EndFix::Tangent => "tangent",
            EndFix::Curvature => "curvature",
        }
    }
}

impl fmt::Display for EndFix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for EndFix {
    type Err = Error;

    fn from_str(s: &str) -> Result<EndFix> {
        EndFix::ALL
            .into_iter()
            .find(|e| e.as_str() == s.trim())
            .ok_or_else(|| Error::InvalidParameter {
                name: "fix_ends".into(),
                reason: format!("'{s}' is not one of free, position, tangent, curvature"),
            })
    }
}
