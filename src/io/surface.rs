//! Reading an input surface from any mesh file we read.

use super::RawMesh;
use crate::{Error, Result, Surface, SurfaceDefect};
use std::path::Path;

/// Read the P2 surface in `path`: its 6-node triangles (with tags). A volume mesh's file
/// works too (its boundary triangles are taken, other nodes dropped). A file holding only
/// 3-node triangles is a [`SurfaceDefect::LinearSurface`] error.
pub fn read_surface(path: &Path) -> Result<Surface> {
    surface_from_raw(super::read(path)?, &path.display().to_string())
}

/// The P2 surface of a [`RawMesh`]; `name` is used in messages.
pub fn surface_from_raw(raw: RawMesh, name: &str) -> Result<Surface> {
    if raw.tri6.is_empty() {
        let msg = if raw.tri3.is_empty() {
            format!("{name}: no triangles found (a closed 6-node triangle surface is needed)")
        } else {
            format!(
                "{name}: {} 3-node triangles and no 6-node ones; a quadratic (P2) surface is needed",
                raw.tri3.len()
            )
        };
        let kind = if raw.tri3.is_empty() {
            SurfaceDefect::Empty
        } else {
            SurfaceDefect::LinearSurface
        };
        return Err(Error::surface(kind, msg));
    }
    let (nodes, tris) = if raw.tet4.is_empty() && raw.tet10.is_empty() {
        (raw.nodes, raw.tri6)
    } else {
        // A volume mesh: keep only the nodes of its boundary triangles, in file order.
        let mut remap = vec![u32::MAX; raw.nodes.len()];
        let mut nodes = Vec::new();
        let mut tris = raw.tri6;
        for t in &mut tris {
            for v in t.iter_mut() {
                let i = *v as usize;
                if remap[i] == u32::MAX {
                    remap[i] = nodes.len() as u32;
                    nodes.push(raw.nodes[i]);
                }
                *v = remap[i];
            }
        }
        (nodes, tris)
    };
    Surface::new(nodes, tris, raw.tri6_tags)
}
