//! What the optimizer must keep: the surface nodes (the first `n_surf` points) and the
//! boundary edges with their (possibly curved) mid nodes.

use crate::geom::shape::{TET10_EDGES, TRI6_EDGES};
use crate::geom::vec3::{mid, P3};
use crate::mesh::slivers::{sliver_floor, small_angles_at, SLIVER_DEG};
use rustc_hash::FxHashMap as HashMap;

/// The boundary of the domain as the optimizer sees it.
#[derive(Debug, Clone)]
pub struct Boundary {
    /// Points with an index below this are surface nodes: they never move.
    pub n_surf: usize,
    /// Boundary edge (smaller id, larger id) → its mid node (a surface node).
    pub edge_mid: HashMap<(u32, u32), u32>,
    /// Per surface node, the smallest dihedral angle (degrees) a tet touching it may
    /// have without counting as an unforced sliver ([`crate::mesh::slivers::sliver_floor`]):
    /// half the smallest angle of a boundary triangle at it when that is below
    /// [`crate::mesh::slivers::SMALL_ANGLE_DEG`], else [`SLIVER_DEG`]. Empty: [`SLIVER_DEG`] everywhere
    /// ([`Boundary::with_sliver_floors`] fills it).
    pub sliver_floor: Vec<f64>,
}

impl Boundary {
    /// The boundary of the closed P2 surface `tris` on the first `n_surf` points.
    pub fn new(n_surf: usize, tris: &[[u32; 6]]) -> Boundary {
        let mut edge_mid =
            HashMap::with_capacity_and_hasher(tris.len() * 3 / 2, Default::default());
        for t in tris {
            for (k, [i, j]) in TRI6_EDGES.iter().enumerate() {
                let (a, b) = (t[*i], t[*j]);
                edge_mid.insert((a.min(b), a.max(b)), t[3 + k]);
            }
        }
        Boundary {
            n_surf,
            edge_mid,
            sliver_floor: Vec::new(),
        }
    }

    /// With [`Boundary::sliver_floor`] measured on the surface nodes `nodes` and the
    /// triangles `tris` (the same as [`Boundary::new`]'s), as the sliver census does.
    pub fn with_sliver_floors(mut self, nodes: &[P3], tris: &[[u32; 6]]) -> Boundary {
        self.sliver_floor = small_angles_at(nodes, tris)
            .into_iter()
            .map(|(theta, _)| sliver_floor(theta))
            .collect();
        self
    }

    /// The smallest dihedral angle (degrees) the tet on corners `v` may have without
    /// counting as an unforced sliver (see [`Boundary::sliver_floor`]).
    #[inline]
    pub fn tet_sliver_floor(&self, v: [u32; 4]) -> f64 {
        v.iter()
            .filter_map(|&x| self.sliver_floor.get(x as usize))
            .fold(SLIVER_DEG, |a, &b| a.min(b))
    }

    /// True for a surface node.
    #[inline]
    pub fn is_fixed(&self, v: u32) -> bool {
        (v as usize) < self.n_surf
    }

    /// The mid node of `(a, b)` when it is a boundary edge.
    #[inline]
    pub fn edge_mid(&self, a: u32, b: u32) -> Option<u32> {
        if self.is_fixed(a) && self.is_fixed(b) {
            self.edge_mid.get(&(a.min(b), a.max(b))).copied()
        } else {
            None
        }
    }

    /// True when `(a, b)` is an edge of a boundary triangle.
    #[inline]
    pub fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        self.edge_mid(a, b).is_some()
    }

    /// The ten nodes of the P2 tet on corners `v` at positions `c`: boundary edges take
    /// their mid nodes from `pts`, every other edge its midpoint. The flag says whether
    /// some boundary mid node is off its chord midpoint (a curved tet).
    #[inline]
    pub fn tet10(&self, pts: &[P3], v: [u32; 4], c: &[P3; 4]) -> ([P3; 10], bool) {
        self.tet10_with(pts, v, c, |_| false)
    }

    /// [`Boundary::tet10`] with the boundary edges (smaller id, larger id) for which
    /// `on_chord` is true taken straight, as if their mid nodes were back on their
    /// chords.
    #[inline]
    pub fn tet10_with(
        &self,
        pts: &[P3],
        v: [u32; 4],
        c: &[P3; 4],
        on_chord: impl Fn((u32, u32)) -> bool,
    ) -> ([P3; 10], bool) {
        let mut x = [[0.0; 3]; 10];
        x[..4].copy_from_slice(c);
        let mut curved = false;
        for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
            let m = mid(c[*i], c[*j]);
            x[4 + k] = m;
            let (a, b) = (v[*i], v[*j]);
            if let Some(n) = self.edge_mid(a, b) {
                if on_chord((a.min(b), a.max(b))) {
                    continue;
                }
                let p = pts[n as usize];
                if p != m {
                    x[4 + k] = p;
                    curved = true;
                }
            }
        }
        (x, curved)
    }
}
