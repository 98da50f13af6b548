//! One mesh from the meshes of several regions that share boundary nodes.
//!
//! Each region was meshed on its own boundary surface, whose nodes are input nodes (the
//! region's `map` gives each local surface node's input index), so the meshes meet on
//! the interfaces node for node. The merged mesh numbers the input nodes the regions use
//! first (in input order), then each region's interior nodes (region by region); each
//! input triangle becomes one boundary triangle, oriented out of the first region that
//! has it.

use super::TetMesh;
use crate::geom::P3;

/// A region's mesh and how its surface relates to the input.
pub struct RegionMesh<'a> {
    /// The region's id (positive).
    pub id: i32,
    /// Its mesh: nodes `..map.len()` are its surface's nodes.
    pub mesh: &'a TetMesh,
    /// Input node index of each of the region surface's nodes.
    pub map: &'a [u32],
    /// Input triangle index of each of the region surface's triangles (its mesh's
    /// `boundary`, in order).
    pub triangles: &'a [u32],
}

/// Merges region meshes over an input of `n_input_nodes` nodes and `n_input_triangles`
/// triangles with tags `tags` (one per input triangle). Returns the mesh (with
/// `tet_regions` set) and, per boundary triangle, the input triangle it is.
pub fn merge(
    n_input_nodes: usize,
    n_input_triangles: usize,
    tags: &[i32],
    regions: &[RegionMesh],
) -> (TetMesh, Vec<u32>) {
    const NONE: u32 = u32::MAX;
    // Input nodes used by some region, in input order.
    let mut global = vec![NONE; n_input_nodes];
    for r in regions {
        for &v in r.map {
            global[v as usize] = 0;
        }
    }
    let mut nodes: Vec<P3> = Vec::new();
    let mut next = 0u32;
    for g in global.iter_mut().filter(|g| **g != NONE) {
        *g = next;
        next += 1;
    }
    nodes.resize(next as usize, [0.0; 3]);
    for r in regions {
        for (local, &v) in r.map.iter().enumerate() {
            nodes[global[v as usize] as usize] = r.mesh.nodes[local];
        }
    }
    let mut tets = Vec::new();
    let mut tet_regions = Vec::new();
    let mut boundary_of = vec![NONE; n_input_triangles];
    let mut boundary = Vec::new();
    let mut boundary_tags = Vec::new();
    let mut source = Vec::new();
    let mut owner: Vec<i32> = Vec::new();
    let mut interior: Vec<bool> = Vec::new();
    for r in regions {
        let n_surf = r.map.len();
        let base = nodes.len() as u32;
        nodes.extend_from_slice(&r.mesh.nodes[n_surf..]);
        let to_global = |v: u32| {
            if (v as usize) < n_surf {
                global[r.map[v as usize] as usize]
            } else {
                base + (v - n_surf as u32)
            }
        };
        for t in &r.mesh.tets {
            tets.push(t.map(to_global));
            tet_regions.push(r.id);
        }
        for (tri, &input) in r.mesh.boundary.iter().zip(r.triangles) {
            let b = boundary_of[input as usize];
            if b == NONE {
                boundary_of[input as usize] = boundary.len() as u32;
                boundary.push(tri.map(to_global));
                boundary_tags.push(tags.get(input as usize).copied().unwrap_or(0));
                source.push(input);
                owner.push(r.id);
            } else if owner[b as usize] == r.id {
                // Between two regions of one id (one physical volume): an interior face.
                interior[b as usize] = true;
            }
        }
        interior.resize(boundary.len(), false);
    }
    if interior.iter().any(|&x| x) {
        boundary = keep(boundary, &interior);
        boundary_tags = keep(boundary_tags, &interior);
        source = keep(source, &interior);
    }
    let mesh = TetMesh {
        nodes,
        tets,
        boundary,
        boundary_tags,
        groups: Default::default(),
        tet_regions,
    };
    (mesh, source)
}

/// The items of `v` whose `drop` flag is false.
fn keep<T>(v: Vec<T>, drop: &[bool]) -> Vec<T> {
    v.into_iter()
        .zip(drop)
        .filter(|(_, &d)| !d)
        .map(|(x, _)| x)
        .collect()
}
