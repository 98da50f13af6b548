//! curvetet: direct quadratic (10-node) curvilinear tetrahedral meshing of closed quadratic
//! (6-node) triangle surfaces by an advancing front, with certified element validity.
//!
//! Data flows one way: [`io`] reads a [`Surface`] (checked on construction), the front
//! fills it with straight-sided P2 tetrahedra, the optimizer moves the free high-order
//! nodes, and the result is certified (Bernstein bounds of the Jacobian) before it is
//! returned as a [`TetMesh`].

pub mod capi;
pub mod error;
pub mod front;
pub mod generate;
pub mod geom;
pub mod io;
pub mod mesh;
pub mod optimize;
pub mod options;
pub mod surface;
pub mod threads;

pub use error::{Error, Result, SurfaceDefect};
pub use generate::{generate, generate_with_progress, Generated};
pub use mesh::TetMesh;
pub use options::{Options, SizeFrom, SizeMode};
pub use surface::Surface;

/// README.md's Rust example, compiled and run as a doctest so that it cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
