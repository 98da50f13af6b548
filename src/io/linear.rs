//! What the linear surface readers (STL, OFF, OBJ, PLY) share: splitting polygons into
//! triangles and turning the file's vertex list and faces into a welded [`RawMesh`].
//!
//! **Polygons** with more than three vertices (OBJ quads are common; OFF and PLY allow
//! them too) are split as fans from their first vertex, (v0, v1, v2), (v0, v2, v3), ...,
//! keeping the polygon's orientation. That is right for the convex planar polygons these
//! files normally hold; a non-convex or warped polygon may give overlapping or folded
//! triangles, which the surface checks then reject with the triangle's index (the fan's
//! triangles are numbered in file order, so the message can be traced back). Faces with
//! fewer than three vertices are a parse error.

use super::weld::weld_indexed;
use super::RawMesh;
use crate::error::Result;
use crate::geom::P3;

/// Appends the fan triangulation of polygon `poly` (at least three vertices) to `out`.
pub(crate) fn push_fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}

/// The mesh of an indexed linear surface: vertices welded exactly (see `weld`), faces
/// renumbered, every tag 0. Face indices must already be in range.
pub(crate) fn indexed_mesh(points: &[P3], tris: Vec<[u32; 3]>, name: &str) -> Result<RawMesh> {
    let (nodes, remap) = weld_indexed(points, name)?;
    let tri3: Vec<[u32; 3]> = tris
        .into_iter()
        .map(|t| t.map(|v| remap[v as usize]))
        .collect();
    Ok(RawMesh {
        nodes,
        tri3_tags: vec![0; tri3.len()],
        tri3,
        ..RawMesh::default()
    })
}
