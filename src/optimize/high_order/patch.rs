//! Patches: a bad element with `layers` rings of vertex neighbours around it. A node of
//! the patch is free when it is not a surface node and every element containing it is
//! in the patch (so moving it changes no element outside); corner nodes are free only
//! when vertices may move. The patch's *active* elements are those containing a free
//! node: the only ones whose geometry the optimization changes. Two patches whose active
//! elements are disjoint can be optimized at the same time; [`colour`] groups them.

use crate::mesh::TetMesh;

/// Node → elements incidence (all ten nodes), compressed rows.
pub(super) struct NodeElems {
    off: Vec<u32>,
    list: Vec<u32>,
    /// True for nodes that are some element's corner.
    pub is_vertex: Vec<bool>,
}

impl NodeElems {
    /// Incidence of `mesh`.
    pub fn new(mesh: &TetMesh) -> NodeElems {
        let n = mesh.nodes.len();
        let mut off = vec![0u32; n + 1];
        let mut is_vertex = vec![false; n];
        for t in &mesh.tets {
            for (k, &v) in t.iter().enumerate() {
                off[v as usize + 1] += 1;
                if k < 4 {
                    is_vertex[v as usize] = true;
                }
            }
        }
        for i in 0..n {
            off[i + 1] += off[i];
        }
        let mut fill = off.clone();
        let mut list = vec![0u32; off[n] as usize];
        for (e, t) in mesh.tets.iter().enumerate() {
            for &v in t {
                let f = &mut fill[v as usize];
                list[*f as usize] = e as u32;
                *f += 1;
            }
        }
        NodeElems {
            off,
            list,
            is_vertex,
        }
    }

    /// Elements containing node `n`.
    #[inline]
    pub fn of(&self, n: u32) -> &[u32] {
        &self.list[self.off[n as usize] as usize..self.off[n as usize + 1] as usize]
    }
}

/// One patch.
#[derive(Clone, Debug, Default)]
pub(super) struct Patch {
    /// Elements with a free node (sorted).
    pub elems: Vec<u32>,
    /// Free nodes (sorted).
    pub free: Vec<u32>,
}

/// Reusable membership marks for building patches.
pub(super) struct Marks {
    elem: Vec<u32>,
    node: Vec<u32>,
    stamp: u32,
    sel: Vec<u32>,
    frontier: Vec<u32>,
}

impl Marks {
    /// Marks for a mesh of `ne` elements and `nn` nodes.
    pub fn new(ne: usize, nn: usize) -> Marks {
        Marks {
            elem: vec![0; ne],
            node: vec![0; nn],
            stamp: 0,
            sel: Vec::new(),
            frontier: Vec::new(),
        }
    }
}

/// The patch of `layers` vertex-neighbour rings around `seed`.
pub(super) fn build(
    mesh: &TetMesh,
    adj: &NodeElems,
    n_surf: usize,
    seed: u32,
    layers: usize,
    move_vertices: bool,
    mk: &mut Marks,
) -> Patch {
    mk.stamp += 1;
    let st = mk.stamp;
    mk.sel.clear();
    mk.sel.push(seed);
    mk.elem[seed as usize] = st;
    let mut start = 0;
    for _ in 0..layers {
        let end = mk.sel.len();
        mk.frontier.clear();
        for i in start..end {
            let e = mk.sel[i];
            for &v in &mesh.tets[e as usize][..4] {
                for &f in adj.of(v) {
                    if mk.elem[f as usize] != st {
                        mk.elem[f as usize] = st;
                        mk.frontier.push(f);
                    }
                }
            }
        }
        start = end;
        mk.sel.extend_from_slice(&mk.frontier);
    }
    let mut p = Patch::default();
    for &e in &mk.sel {
        for &n in &mesh.tets[e as usize] {
            let ni = n as usize;
            if ni < n_surf || mk.node[ni] == st {
                continue;
            }
            mk.node[ni] = st;
            if adj.is_vertex[ni] && !move_vertices {
                continue;
            }
            if adj.of(n).iter().all(|&f| mk.elem[f as usize] == st) {
                p.free.push(n);
            }
        }
    }
    p.free.sort_unstable();
    for &n in &p.free {
        p.elems.extend_from_slice(adj.of(n));
    }
    p.elems.sort_unstable();
    p.elems.dedup();
    p
}

/// Colour of each patch such that patches of one colour have disjoint active elements
/// (greedy, in patch order: deterministic).
pub(super) fn colour(patches: &[Patch], n_elems: usize) -> Vec<u32> {
    // Colours used by the patches containing each element, as a bit set (colours >= 64
    // are given one patch each, by counting on from 64).
    let mut used = vec![0u64; n_elems];
    let mut next_big = 64u32;
    let mut out = Vec::with_capacity(patches.len());
    for p in patches {
        let mut forbidden = 0u64;
        for &e in &p.elems {
            forbidden |= used[e as usize];
        }
        let c = (!forbidden).trailing_zeros();
        if c < 64 {
            for &e in &p.elems {
                used[e as usize] |= 1u64 << c;
            }
            out.push(c);
        } else {
            out.push(next_big);
            next_big += 1;
        }
    }
    out
}
