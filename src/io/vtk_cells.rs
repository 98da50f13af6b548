//! VTK cell types shared by the .vtu and legacy .vtk readers and writers, and the names
//! of the cell arrays taken as element tags.

use super::order::{self, Convention};
use super::{MeshView, RawMesh};

/// `VTK_TRIANGLE`.
pub(crate) const TRIANGLE: u8 = 5;
/// `VTK_TETRA`.
pub(crate) const TETRA: u8 = 10;
/// `VTK_QUADRATIC_TRIANGLE`.
pub(crate) const QUADRATIC_TRIANGLE: u8 = 22;
/// `VTK_QUADRATIC_TETRA`.
pub(crate) const QUADRATIC_TETRA: u8 = 24;

/// The cell array curvetet writes the tags to.
pub(crate) const TAG_ARRAY: &str = "BoundaryTag";

/// The per-tetrahedron quality cell arrays (as the VTK filter names them).
pub(crate) const QUALITY_ARRAYS: [&str; 2] = ["ScaledJacobian", "EquiangularSkewness"];

/// Cell arrays read as tags, most preferred first (ours, then meshio's and Gmsh's
/// names, then common solver names).
pub(crate) const TAG_ARRAYS: [&str; 7] = [
    TAG_ARRAY,
    "tags",
    "gmsh:physical",
    "CellEntityIds",
    "medit:ref",
    "gmsh:geometrical",
    "Tag",
];

/// Preference rank of a cell array name as a tag array (lower is better).
pub(crate) fn tag_rank(name: &[u8]) -> Option<usize> {
    TAG_ARRAYS.iter().position(|n| n.as_bytes() == name)
}

/// Number of points of the cell types curvetet keeps; `None` for other types.
pub(crate) fn cell_len(ty: i64) -> Option<usize> {
    match ty {
        t if t == TRIANGLE as i64 => Some(3),
        t if t == QUADRATIC_TRIANGLE as i64 => Some(6),
        t if t == TETRA as i64 => Some(4),
        t if t == QUADRATIC_TETRA as i64 => Some(10),
        _ => None,
    }
}

/// Add cell `i` of VTK type `ty` with point indices `conn` (offset by `base`) and `tag`.
/// Other cell types are counted as ignored. `Err` is a message naming the cell.
pub(crate) fn add_cell(
    mesh: &mut RawMesh,
    i: usize,
    ty: i64,
    conn: &[u64],
    base: u32,
    npoints: u64,
    tag: i32,
) -> Result<(), String> {
    let Some(want) = cell_len(ty) else {
        mesh.ignored_elements += 1;
        return Ok(());
    };
    if conn.len() != want {
        return Err(format!(
            "cell {i} of type {ty} has {} points, expected {want}",
            conn.len()
        ));
    }
    let mut v = [0u32; 10];
    for (o, &p) in v.iter_mut().zip(conn) {
        if p >= npoints {
            return Err(format!(
                "cell {i} refers to point {p}, but there are {npoints} points"
            ));
        }
        *o = base + p as u32;
    }
    match want {
        3 => {
            mesh.tri3.push([v[0], v[1], v[2]]);
            mesh.tri3_tags.push(tag);
        }
        6 => {
            let t: [u32; 6] = v[..6].try_into().expect("6 nodes");
            mesh.tri6.push(order::tri6_from(Convention::Vtk, &t));
            mesh.tri6_tags.push(tag);
        }
        4 => {
            mesh.tet4.push([v[0], v[1], v[2], v[3]]);
            mesh.tet4_tags.push(tag);
        }
        _ => {
            mesh.tet10.push(order::tet10_from(Convention::Vtk, &v));
            mesh.tet10_tags.push(tag);
        }
    }
    Ok(())
}

/// One cell as a writer emits it: VTK type, the first `len` of `nodes` in VTK order, tag.
pub(crate) struct Cell {
    pub ty: u8,
    pub nodes: [u32; 10],
    pub len: usize,
    pub tag: i32,
}

impl Cell {
    /// The cell's nodes.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.len]
    }
}

/// The cells a writer emits, in order: the tetrahedra, then the boundary triangles.
/// Tetrahedra get tag 0, or their region id in a mesh of several regions.
pub(crate) fn cells<'a>(view: &'a MeshView) -> impl Iterator<Item = Cell> + 'a {
    let tets = view.tet10.iter().enumerate().map(|(i, t)| Cell {
        ty: QUADRATIC_TETRA,
        nodes: order::tet10_to(Convention::Vtk, t),
        len: 10,
        tag: view.tet_regions.get(i).copied().unwrap_or(0),
    });
    let tris = view.tri6.iter().zip(view.tags).map(|(t, &g)| {
        let mut nodes = [0u32; 10];
        nodes[..6].copy_from_slice(&order::tri6_to(Convention::Vtk, t));
        Cell {
            ty: QUADRATIC_TRIANGLE,
            nodes,
            len: 6,
            tag: g,
        }
    });
    tets.chain(tris)
}

/// Number of cells and total connectivity length a writer emits.
pub(crate) fn sizes(view: &MeshView) -> (usize, usize) {
    (
        view.tet10.len() + view.tri6.len(),
        10 * view.tet10.len() + 6 * view.tri6.len(),
    )
}
