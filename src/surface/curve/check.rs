//! The checks of a linear surface, before it is curved: the P2 surface's checks applied to
//! the corner triangles, so a linear surface gets the same [`SurfaceDefect`] kinds and
//! messages (triangle index and corners, edge, node) as a P2 one.
//!
//! The linear surface is lifted to a P2 surface with *straight* edges: one new mid node per
//! undirected edge, numbered after the input vertices in the order of the sorted edge
//! (smaller vertex id, larger vertex id), placed at the chord midpoint. The checks then run
//! in the order of [`Surface::new`](crate::Surface::new), with the ones that concern mid
//! nodes left out:
//!
//! 1. no triangles ([`Empty`](SurfaceDefect::Empty)); an index past the end
//!    ([`IndexOutOfRange`](SurfaceDefect::IndexOutOfRange)); a triangle using one vertex
//!    twice, i.e. a facet with coincident corners (after welding, a zero-area facet of an
//!    STL file) → [`DegenerateTriangle`](SurfaceDefect::DegenerateTriangle);
//! 2. coordinates (finite, in range), unused vertices, duplicate vertices;
//! 3. topology: open, non-manifold edges and vertices, inconsistent orientation;
//! 4. exactly collinear corners → [`DegenerateTriangle`](SurfaceDefect::DegenerateTriangle),
//!    naming the triangle's index;
//! 5. exact self-intersection of the flat triangles.
//!
//! Orientation (and nesting of shells) is left to the final `Surface::new` of the curved
//! surface: the curving does not depend on which way the normals point.

use super::super::describe;
use super::super::topology::{SurfaceEdge, Topology};
use super::super::{coords, geometry, indices, intersect};
#[cfg(doc)]
use crate::error::SurfaceDefect;
use crate::error::{Error, Result, SurfaceDefect as Defect};
use crate::geom::vec3::mid;
use crate::geom::P3;

/// A checked linear surface, lifted to P2 with straight edges.
pub(crate) struct Lifted {
    /// Input vertices (unchanged, first) then one chord midpoint per edge.
    pub nodes: Vec<P3>,
    /// 6-node triangles: the input corners, then the mid nodes of (0,1), (1,2), (2,0).
    pub tris: Vec<[u32; 6]>,
    /// Corner edges sorted by node pair; edge `e` has mid node `n_input + e`.
    pub edges: Vec<SurfaceEdge>,
    /// Number of input vertices.
    pub n_input: usize,
}

/// Runs the checks of the module docs and lifts the surface.
pub(crate) fn check_linear(nodes: Vec<P3>, tri3: &[[u32; 3]]) -> Result<Lifted> {
    let n = nodes.len();
    if tri3.is_empty() {
        return Err(Error::surface(
            Defect::Empty,
            format!("the surface has no triangles ({n} vertices)"),
        ));
    }
    for (t, tri) in tri3.iter().enumerate() {
        let six = [tri[0], tri[1], tri[2], 0, 0, 0];
        if let Some(k) = tri.iter().position(|&v| v as usize >= n) {
            return Err(Error::surface(
                Defect::IndexOutOfRange,
                format!(
                    "{}: vertex index {} at position {k} is out of range ({n} vertices)",
                    describe::tri(t, &six),
                    tri[k]
                ),
            ));
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
            return Err(Error::surface(
                Defect::DegenerateTriangle,
                format!(
                    "{} has zero area: two of its corners are the same vertex (coincident \
                     facet corners)",
                    describe::tri(t, &six)
                ),
            ));
        }
    }
    if n + 3 * tri3.len() >= u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "{n} vertices and {} triangles: too many for 32-bit node indices once mid nodes \
             are added",
            tri3.len()
        )));
    }
    coords::check_coordinates(&nodes)?;

    // Undirected edges, sorted: edge e gets mid node n + e.
    let mut keys: Vec<(u32, u32)> = tri3
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    let mid_of = |a: u32, b: u32| -> u32 {
        let key = (a.min(b), a.max(b));
        // Every corner edge is among the keys.
        n as u32 + keys.binary_search(&key).unwrap_or(0) as u32
    };
    let tris: Vec<[u32; 6]> = tri3
        .iter()
        .map(|t| {
            [
                t[0],
                t[1],
                t[2],
                mid_of(t[0], t[1]),
                mid_of(t[1], t[2]),
                mid_of(t[2], t[0]),
            ]
        })
        .collect();
    let mids: Vec<P3> = keys
        .iter()
        .map(|&(a, b)| mid(nodes[a as usize], nodes[b as usize]))
        .collect();
    let mut all = nodes;
    all.extend(mids);

    indices::check_unused(n, &tris_corners_only(&tris), &all[..n])?;
    coords::check_duplicates(&all[..n])?;
    let topo = Topology::build(&all, &tris)?;
    geometry::check_degenerate(&all, &tris)?;
    intersect::check_chord_intersections(&all, &tris)?;
    debug_assert!(topo
        .edges
        .iter()
        .enumerate()
        .all(|(e, se)| se.mid as usize == n + e));
    Ok(Lifted {
        nodes: all,
        tris,
        edges: topo.edges,
        n_input: n,
    })
}

/// The triangles with their mid nodes replaced by corner 0 (for the unused-vertex check,
/// which must look at input vertices only).
fn tris_corners_only(tris: &[[u32; 6]]) -> Vec<[u32; 6]> {
    tris.iter()
        .map(|t| [t[0], t[1], t[2], t[0], t[0], t[0]])
        .collect()
}
