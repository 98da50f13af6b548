//! The input side: the P2 surface model and its checks.

use crate::geom::P3;

/// A closed quadratic (6-node) triangle surface: the input of the mesher.
///
/// Node order per triangle (Gmsh's): corners 0, 1, 2, then the mid-edge nodes of edges
/// (0,1), (1,2), (2,0). Triangles are oriented with outward normals (right-hand rule).
/// Build one with [`Surface::new`], which runs every check; the fields are read-only
/// thereafter so a `Surface` in hand is always a valid one.
#[derive(Debug, Clone)]
pub struct Surface {
    nodes: Vec<P3>,
    tris: Vec<[u32; 6]>,
    tags: Vec<i32>,
    warnings: Vec<String>,
}

impl Surface {
    /// Nodes (corners and mid-edge nodes).
    pub fn nodes(&self) -> &[P3] {
        &self.nodes
    }
    /// 6-node triangles, 0-based, outward.
    pub fn triangles(&self) -> &[[u32; 6]] {
        &self.tris
    }
    /// One tag per triangle (Gmsh physical or entity tag; 0 when none).
    pub fn tags(&self) -> &[i32] {
        &self.tags
    }
    /// Warnings raised while checking (e.g. "orientation was inward; flipped").
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}
