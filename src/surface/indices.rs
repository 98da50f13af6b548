//! Index-level checks: empty input, node indices past the end, a node repeated within a
//! triangle, and nodes no triangle uses. O(n).

use super::describe;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::P3;

/// Empty, out-of-range indices, repeated nodes within a triangle (any two of the six).
pub fn check_indices(n_nodes: usize, tris: &[[u32; 6]]) -> Result<()> {
    if tris.is_empty() {
        return Err(Error::surface(
            SurfaceDefect::Empty,
            format!("the surface has no triangles ({n_nodes} nodes)"),
        ));
    }
    for (t, tri) in tris.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if v as usize >= n_nodes {
                return Err(Error::surface(
                    SurfaceDefect::IndexOutOfRange,
                    format!(
                        "{}: node index {v} at position {k} is out of range ({n_nodes} nodes)",
                        describe::tri(t, tri)
                    ),
                ));
            }
        }
    }
    for (t, tri) in tris.iter().enumerate() {
        for i in 0..6 {
            for j in i + 1..6 {
                if tri[i] == tri[j] {
                    return Err(Error::surface(
                        SurfaceDefect::RepeatedNode,
                        format!(
                            "{}: node {} appears at positions {i} and {j} (nodes {:?})",
                            describe::tri(t, tri),
                            tri[i],
                            tri
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Every node must be used by some triangle (as a corner or a mid node). Indices must
/// already be in range.
pub fn check_unused(n_nodes: usize, tris: &[[u32; 6]], nodes: &[P3]) -> Result<()> {
    let mut used = vec![false; n_nodes];
    for tri in tris {
        for &v in tri {
            used[v as usize] = true;
        }
    }
    if let Some(i) = used.iter().position(|u| !u) {
        let count = used.iter().filter(|u| !**u).count();
        return Err(Error::surface(
            SurfaceDefect::UnusedNode,
            format!(
                "{} is used by no triangle ({count} unused node(s) in all)",
                describe::node(i, nodes)
            ),
        ));
    }
    Ok(())
}
