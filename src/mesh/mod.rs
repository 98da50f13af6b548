//! The output: a quadratic (10-node) tetrahedral mesh with its boundary.

use crate::geom::P3;

/// A P2 tetrahedral mesh.
///
/// Tets use Gmsh's 10-node order: corners 0..3, then mid nodes of edges (0,1), (1,2),
/// (2,0), (3,0), (3,2), (3,1). Tets are positive (det[v1-v0, v2-v0, v3-v0] > 0).
/// `boundary` holds the input triangles (same six node coordinates, outward) with their
/// input `boundary_tags`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    /// All nodes: the input surface's nodes first (same indices), then interior ones.
    pub nodes: Vec<P3>,
    /// 10-node tetrahedra, Gmsh order.
    pub tets: Vec<[u32; 10]>,
    /// 6-node boundary triangles, Gmsh order, outward.
    pub boundary: Vec<[u32; 6]>,
    /// One tag per boundary triangle.
    pub boundary_tags: Vec<i32>,
    /// The volume's physical tag and the group names the writers use (from the input
    /// surface's file; see [`crate::io::Groups`]).
    pub groups: crate::io::Groups,
    /// The region (physical volume) of each tet, for a mesh of several regions (see
    /// [`crate::generate_regions`]); empty when every tet is in the one volume
    /// `groups.volume_tag`. Region ids are positive; the writers put each region in its
    /// own physical group, and [`TetMesh::boundary`] then also holds the interface
    /// triangles between two regions (once each).
    pub tet_regions: Vec<i32>,
}

impl TetMesh {
    /// The distinct region ids, ascending (empty for a one-region mesh).
    pub fn region_ids(&self) -> Vec<i32> {
        let mut r = self.tet_regions.clone();
        r.sort_unstable();
        r.dedup();
        r
    }
}

pub mod build;
pub mod check;
pub mod merge;
pub mod plot;
pub mod report;
pub mod slivers;
