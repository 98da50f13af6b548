//! How messages name elements: one format everywhere, so users and tests can rely on it.
//!
//! - triangle: `triangle 12 (corners 3, 7, 9)` — 0-based index and corner node indices;
//! - edge: `edge (3, 7)` — its two corner node indices;
//! - node: `node 5 (x, y, z)` — 0-based index and coordinates.

use crate::geom::P3;

/// `triangle T (corners A, B, C)`.
pub(crate) fn tri(t: usize, tri: &[u32; 6]) -> String {
    format!("triangle {t} (corners {}, {}, {})", tri[0], tri[1], tri[2])
}

/// `edge (A, B)`.
pub(crate) fn edge(a: u32, b: u32) -> String {
    format!("edge ({a}, {b})")
}

/// `node I (x, y, z)`.
pub(crate) fn node(i: usize, nodes: &[P3]) -> String {
    match nodes.get(i) {
        Some(p) => format!("node {i} ({:?}, {:?}, {:?})", p[0], p[1], p[2]),
        None => format!("node {i}"),
    }
}
