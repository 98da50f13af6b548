//! curvetet: direct quadratic (10-node) curvilinear tetrahedral meshing of closed quadratic
//! (6-node) triangle surfaces by an advancing front, with certified element validity.
//!
//! Data flows one way: a reader ([`read_any_surface`], or [`Surface::new`] on arrays)
//! gives a [`Surface`] (checked on construction), [`generate`] fills it with straight-sided
//! P2 tetrahedra by an advancing front, moves the free high-order nodes to improve the
//! elements, certifies every element (Bernstein bounds of the Jacobian) and returns the
//! [`TetMesh`] with its [`QualityReport`]; a writer ([`write_mesh`]) saves it.
//!
//! ```
//! use curvetet::{generate, Options, Surface};
//!
//! // A closed surface from arrays: the unit corner tetrahedron, four 6-node triangles
//! // (corners, then the mid nodes of edges (0,1), (1,2), (2,0); outward).
//! let nodes = vec![
//!     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0],
//!     [0.5, 0.0, 0.0], [0.5, 0.5, 0.0], [0.0, 0.5, 0.0], // mid 01, 12, 02
//!     [0.0, 0.0, 0.5], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5], // mid 03, 13, 23
//! ];
//! let triangles = vec![
//!     [0, 2, 1, 6, 5, 4],
//!     [0, 1, 3, 4, 8, 7],
//!     [0, 3, 2, 7, 9, 6],
//!     [1, 2, 3, 5, 9, 8],
//! ];
//! let surface = Surface::new(nodes, triangles, Vec::new())?;
//! let out = generate(&surface, &Options::default().with_threads(1))?;
//! assert_eq!(out.report.num_invalid, 0); // every element certified
//! assert!((out.report.volume_curved - 1.0 / 6.0).abs() < 1e-12);
//! # Ok::<(), curvetet::Error>(())
//! ```
//!
//! A surface bounding several regions (materials sharing interfaces, as Gmsh physical
//! volumes) is meshed into one conforming mesh with a region id per tet by
//! [`generate_regions`]; [`MeshInput`] reads either kind from a file and
//! [`generate_input`] meshes it (what the command-line tool and the C ABI do).
//!
//! The command-line tool (`curvetet`, cargo feature `cli`, on by default) and the C ABI
//! (`include/curvetet.h`) are built on the same functions.

pub mod io;

mod error;
mod options;
pub mod regions;

// The modules below are public only for this repository's command-line tool, tests,
// benchmarks and examples (and the C ABI's symbols): not part of the library's API, hidden
// from its documentation, and free to change in any release. Use the items re-exported
// below instead.
#[doc(hidden)]
pub mod capi;
#[doc(hidden)]
pub mod front;
#[doc(hidden)]
pub mod generate;
#[doc(hidden)]
pub mod geom;
#[doc(hidden)]
pub mod mesh;
#[doc(hidden)]
pub mod optimize;
#[doc(hidden)]
pub mod surface;
#[doc(hidden)]
pub mod threads;

pub use error::{Error, Result, SurfaceDefect};
pub use front::{FillTry, FrontStats};
pub use generate::{
    estimated_peak_memory, generate, generate_with_progress, Generated, StageTimes,
};
pub use geom::tet_quality::{QualitySummary, TetQualitySummary};
pub use io::{
    mesh_to_bytes, read, read_any_surface, read_bytes, read_surface, write_mesh, write_surface,
    Format, MshVersion, RawMesh, WriteOptions,
};
pub use mesh::report::QualityReport;
pub use mesh::slivers::SliverCensus;
pub use mesh::TetMesh;
pub use optimize::{HighOrderStats, LinearSeconds, LinearStats, OptimizeStats};
pub use options::{Options, SizeFrom, SizeMode};
pub use regions::{
    generate_input, generate_regions, MeshInput, Region, RegionMode, RegionResult, Regions,
};
pub use surface::curve::{CurveOptions, MidpointRule, NormalWeights};
pub use surface::{Repair, Surface};

/// README.md's Rust example, compiled and run as a doctest so that it cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
