//! Assemble the P2 mesh from the front's straight-sided tets: boundary edges take the
//! input mid nodes, every other edge gets one new node at its midpoint (shared by all tets
//! of the edge), unused interior points are dropped, surface nodes keep their indices.

use super::TetMesh;
use crate::geom::shape::{TET10_EDGES, TRI6_EDGES};
use crate::geom::vec3::{mid, P3};
use rustc_hash::FxHashMap as HashMap;

/// Build the 10-node mesh. `pts[..n_surf]` are the surface nodes, the rest interior vertices.
pub fn assemble(
    pts: &[P3],
    tets: &[[u32; 4]],
    n_surf: usize,
    surf_tris: &[[u32; 6]],
    surf_tags: &[i32],
) -> TetMesh {
    let mut bedge: HashMap<(u32, u32), u32> =
        HashMap::with_capacity_and_hasher(surf_tris.len() * 3 / 2, Default::default());
    for t in surf_tris {
        for (k, [i, j]) in TRI6_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            bedge.insert((a.min(b), a.max(b)), t[3 + k]);
        }
    }
    // Renumber interior vertices in order of first use (deterministic).
    let mut remap = vec![u32::MAX; pts.len()];
    let mut nodes: Vec<P3> = pts[..n_surf].to_vec();
    for (i, r) in remap.iter_mut().enumerate().take(n_surf) {
        *r = i as u32;
    }
    for t in tets {
        for &v in t {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = nodes.len() as u32;
                nodes.push(pts[v as usize]);
            }
        }
    }
    // Each edge's mid node, found in the row of its smaller end: (other end, mid node)
    // pairs, a few per vertex, in slots counted beforehand (one per edge occurrence, an
    // upper bound). Rows are short and contiguous, where a hash map of all the edges
    // (1M tets: 1.05M edges) missed the cache at nearly every lookup. Only an edge between
    // two surface nodes can be a boundary edge.
    let n = nodes.len(); // the corners (mid nodes come after)
    let mut start = vec![0u32; n + 1];
    let corners = || tets.iter().map(|t| t.map(|v| remap[v as usize]));
    for c in corners() {
        for [i, j] in TET10_EDGES {
            start[c[i].min(c[j]) as usize + 1] += 1;
        }
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill: Vec<u32> = start[..n].to_vec();
    let mut slots = vec![(0u32, 0u32); start[n] as usize];
    let mut out = Vec::with_capacity(tets.len());
    for c in corners() {
        let mut x = [0u32; 10];
        x[..4].copy_from_slice(&c);
        for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (a, b) = (c[*i], c[*j]);
            let (lo, hi) = (a.min(b), a.max(b));
            let boundary = if (hi as usize) < n_surf {
                bedge.get(&(lo, hi)).copied()
            } else {
                None
            };
            x[4 + k] = match boundary {
                Some(m) => m,
                None => {
                    let row = start[lo as usize] as usize..fill[lo as usize] as usize;
                    match slots[row].iter().find(|s| s.0 == hi) {
                        Some(s) => s.1,
                        None => {
                            nodes.push(mid(nodes[a as usize], nodes[b as usize]));
                            let m = (nodes.len() - 1) as u32;
                            slots[fill[lo as usize] as usize] = (hi, m);
                            fill[lo as usize] += 1;
                            m
                        }
                    }
                }
            };
        }
        out.push(x);
    }
    let tags = if surf_tags.len() == surf_tris.len() {
        surf_tags.to_vec()
    } else {
        vec![0; surf_tris.len()]
    };
    TetMesh {
        nodes,
        tets: out,
        boundary: surf_tris.to_vec(),
        boundary_tags: tags,
        groups: Default::default(),
        tet_regions: Vec::new(),
    }
}
