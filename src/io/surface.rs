//! Reading an input surface from any mesh file we read.

use super::RawMesh;
use crate::surface::curve::{curve_linear, CurveOptions};
use crate::surface::Repair;
use crate::{Error, Result, Surface, SurfaceDefect};
use std::path::Path;

/// Read the P2 surface in `path`: its 6-node triangles (with tags). A volume mesh's file
/// works too (its boundary triangles are taken, other nodes dropped). A file holding only
/// 3-node triangles is a [`SurfaceDefect::LinearSurface`] error: use [`read_any_surface`]
/// to curve it.
pub fn read_surface(path: &Path) -> Result<Surface> {
    surface_from_raw(super::read(path)?, &path.display().to_string())
}

/// Read a surface from `path`, P2 or linear: 6-node triangles are taken as they are (as
/// [`read_surface`] does); a file with only 3-node triangles (STL, OFF, OBJ, PLY, or a
/// linear .msh/.vtu/.vtk/.mesh) is curved into a P2 surface with `opts` (see
/// [`crate::surface::curve`]).
pub fn read_any_surface(path: &Path, opts: &CurveOptions) -> Result<Surface> {
    surface_from_raw_any(super::read(path)?, &path.display().to_string(), opts)
}

/// The surface of a [`RawMesh`], P2 or linear (see [`read_any_surface`]); `name` is used
/// in messages.
pub fn surface_from_raw_any(raw: RawMesh, name: &str, opts: &CurveOptions) -> Result<Surface> {
    if raw.tri6.is_empty() && !raw.tri3.is_empty() {
        if !raw.tet4.is_empty() || !raw.tet10.is_empty() {
            return Err(Error::surface(
                SurfaceDefect::LinearSurface,
                format!("{name}: a linear volume mesh; give its boundary surface instead"),
            ));
        }
        let groups = raw.groups();
        return Ok(curve_linear(raw.nodes, raw.tri3, raw.tri3_tags, opts)?.with_groups(groups));
    }
    surface_from_raw_with_repair(raw, name, opts.repair)
}

/// The P2 surface of a [`RawMesh`]; `name` is used in messages.
pub fn surface_from_raw(raw: RawMesh, name: &str) -> Result<Surface> {
    surface_from_raw_with_repair(raw, name, Repair::Unambiguous)
}

/// [`surface_from_raw`], with the unambiguous repairs allowed or refused (see
/// [`crate::surface::repair`]).
pub fn surface_from_raw_with_repair(raw: RawMesh, name: &str, repair: Repair) -> Result<Surface> {
    if raw.tri6.is_empty() {
        let msg = if raw.tri3.is_empty() {
            format!("{name}: no triangles found (a closed 6-node triangle surface is needed)")
        } else {
            format!(
                "{name}: {} 3-node triangles and no 6-node ones; a quadratic (P2) surface is \
                 needed (curve it first: `curvetet curve`, or `io::read_any_surface`)",
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
    let groups = raw.groups();
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
    Ok(Surface::new_with_repair(nodes, tris, raw.tri6_tags, repair)?.with_groups(groups))
}
