//! Pure geometry, no topology: exact predicates, P2 shape functions, quadrature,
//! Bernstein (Bézier) bounds of the P2 tetrahedron's Jacobian, and quality metrics.

pub mod bezier;
pub(crate) mod cdt_fill;
pub(crate) mod delaunay;
pub mod distance;
pub(crate) mod plane_flips;
pub mod predicates;
pub mod quadrature;
pub mod shape;
#[cfg(test)]
pub(crate) mod testutil;
pub mod tet_quality;
pub mod vec3;

pub use vec3::P3;
