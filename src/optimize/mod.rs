//! Mesh improvement after the advancing front, in two stages:
//!
//! 1. [`linear`]: the straight-sided core is improved by flips (2-3, edge removal 3-2 /
//!    4-4 / n-to-(2n-4)), contraction of edges with an interior end point, smoothing of
//!    interior vertices and insertion of interior vertices on interior edges, worst
//!    element first; tets still very poor after that get a sampled search for better
//!    positions of their interior vertices. Boundary vertices never move and boundary
//!    faces never change; every operation keeps all tets positive (exact `orient3d`) and
//!    every tet touching a curved boundary edge certified valid.
//! 2. [`high_order`]: on the assembled P2 mesh, patches around the elements of lowest
//!    certified min J / max J are optimized (moving log barrier on the Bernstein
//!    coefficients of det J, L-BFGS), the free variables being the interior nodes only.
//!
//! Both stages are deterministic: the same input gives bit-identical output whatever the
//! number of threads.

pub mod boundary;
mod dual;
pub mod high_order;
pub mod linear;
#[cfg(test)]
pub(crate) mod testmesh;

pub use boundary::Boundary;
pub use high_order::{optimize_high_order, HighOrderParams, HighOrderStats, RoundTuning};
pub use linear::{improve_linear, improve_linear_known, LinearParams, LinearSeconds, LinearStats};

/// What the optimization stages did (part of [`crate::Generated`]).
#[derive(Debug, Clone, Default, serde::Serialize)]
#[non_exhaustive]
pub struct OptimizeStats {
    /// The linear (straight-sided) stage.
    pub linear: LinearStats,
    /// The high-order node optimization.
    pub high_order: HighOrderStats,
    /// Wall-clock seconds of the linear stage.
    pub time_linear: f64,
    /// Wall-clock seconds of the high-order stage.
    pub time_high_order: f64,
    /// Wall-clock seconds of putting the edges of uncertified elements back on their
    /// chords, with the optimizing and certifying again that goes with it (0 where the
    /// high-order stage left every element certified).
    pub time_chords: f64,
    /// Boundary edges put back on their chords (a surface curved from a linear one)
    /// where curved elements could not be certified.
    pub chords: usize,
    /// Interior edges put back on their chords where elements could not be certified.
    pub interior_chords: usize,
}
