//! Sliver census: which tets have a dihedral angle below [`SLIVER_DEG`], and which of
//! those the input's own triangles force.
//!
//! A tet that touches (shares a corner with) a boundary triangle whose smallest angle θ is
//! below [`SMALL_ANGLE_DEG`] may be that thin: near a needle or cap triangle, every
//! tetrahedralization that keeps the triangle has thin tets, down to about θ / 2. Such a
//! sliver is *forced* when its smallest dihedral angle is at least θ / 2 for the smallest
//! θ at its corners; every other sliver is *unforced*: the mesher could have avoided it.

use super::TetMesh;
use crate::geom::tet_quality::dihedral_extremes;
use crate::geom::vec3::*;

/// A tet with a dihedral angle below this many degrees is a sliver.
pub const SLIVER_DEG: f64 = 10.0;
/// Boundary triangles with an angle below this many degrees may force slivers.
pub const SMALL_ANGLE_DEG: f64 = 20.0;

/// How many slivers a mesh has, forced by the input or not.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct SliverCensus {
    /// Slivers the input forces (see the module documentation).
    pub forced: usize,
    /// Slivers the input does not force.
    pub unforced: usize,
    /// The smallest dihedral angle of an unforced sliver, degrees (`None` without one).
    pub worst_unforced_deg: Option<f64>,
    /// The boundary triangle (index in `TetMesh::boundary`) with the smallest angle among
    /// those that force a sliver, and that angle in degrees.
    pub worst_forcing_triangle: Option<(usize, f64)>,
}

/// Whether the tet on corners `c` is a sliver: a dihedral angle below [`SLIVER_DEG`].
pub fn is_sliver(c: &[P3; 4]) -> bool {
    dihedral_extremes(c).0 < SLIVER_DEG
}

/// The smallest angle of the triangle on corners `p`, degrees.
pub fn smallest_angle_deg(p: [P3; 3]) -> f64 {
    let mut best = f64::INFINITY;
    for k in 0..3 {
        let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        let (u, v) = (sub(b, a), sub(c, a));
        let cos = dot(u, v) / (norm2(u) * norm2(v)).sqrt();
        best = best.min(cos.clamp(-1.0, 1.0).acos().to_degrees());
    }
    best
}

/// Per node of `nodes`: the smallest angle below [`SMALL_ANGLE_DEG`] of a triangle of
/// `tris` (corners first) at it, and that triangle's index; (∞, `usize::MAX`) where
/// there is none.
pub fn small_angles_at(nodes: &[P3], tris: &[[u32; 6]]) -> Vec<(f64, usize)> {
    let mut at = vec![(f64::INFINITY, usize::MAX); nodes.len()];
    for (i, t) in tris.iter().enumerate() {
        let a = smallest_angle_deg([t[0], t[1], t[2]].map(|v| nodes[v as usize]));
        if a < SMALL_ANGLE_DEG {
            for &v in &t[..3] {
                if a < at[v as usize].0 {
                    at[v as usize] = (a, i);
                }
            }
        }
    }
    at
}

/// The smallest dihedral angle (degrees) of a tet that is not an unforced sliver, given
/// the smallest small angle `theta` at its corners ([`small_angles_at`]; ∞ for none):
/// half of it, or [`SLIVER_DEG`].
pub fn sliver_floor(theta: f64) -> f64 {
    if theta < SMALL_ANGLE_DEG {
        theta / 2.0
    } else {
        SLIVER_DEG
    }
}

/// The census of `m`'s straight-sided (corner) tets against its boundary triangles.
pub fn census(m: &TetMesh) -> SliverCensus {
    let at = small_angles_at(&m.nodes, &m.boundary);
    let mut c = SliverCensus::default();
    for t in &m.tets {
        let p = [t[0], t[1], t[2], t[3]].map(|v| m.nodes[v as usize]);
        if !is_sliver(&p) {
            continue;
        }
        let (mn, _) = dihedral_extremes(&p);
        let (theta, tri) =
            t[..4]
                .iter()
                .map(|&v| at[v as usize])
                .fold(
                    (f64::INFINITY, usize::MAX),
                    |a, b| if b.0 < a.0 { b } else { a },
                );
        if mn >= sliver_floor(theta) {
            c.forced += 1;
            if c.worst_forcing_triangle.map_or(true, |w| theta < w.1) {
                c.worst_forcing_triangle = Some((tri, theta));
            }
        } else {
            c.unforced += 1;
            if c.worst_unforced_deg.map_or(true, |w| mn < w) {
                c.worst_unforced_deg = Some(mn);
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(nodes: Vec<P3>, tets: Vec<[u32; 4]>, boundary: Vec<[u32; 3]>) -> TetMesh {
        // Mid nodes do not matter here: point every mid-node slot at corner 0.
        let pad = |t: [u32; 4]| std::array::from_fn(|k| if k < 4 { t[k] } else { t[0] });
        TetMesh {
            nodes,
            tets: tets.into_iter().map(pad).collect(),
            boundary: boundary
                .into_iter()
                .map(|b| [b[0], b[1], b[2], b[0], b[0], b[0]])
                .collect(),
            boundary_tags: Vec::new(),
            groups: Default::default(),
            tet_regions: Vec::new(),
        }
    }

    #[test]
    fn a_flat_tet_is_forced_only_next_to_a_needle() {
        // A sliver: four nearly coplanar points (dihedral angles near 0 and 180).
        let sliver = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.9, 0.0],
            [0.5, 0.3, 0.001],
        ];
        let (mn, _) = dihedral_extremes(&[sliver[0], sliver[1], sliver[2], sliver[3]]);
        assert!(mn < 1.0, "{mn}");
        // Beside a well-shaped boundary triangle: unforced.
        let m = mesh(sliver.clone(), vec![[0, 1, 2, 3]], vec![[0, 1, 2]]);
        let c = census(&m);
        assert_eq!((c.forced, c.unforced), (0, 1), "{c:?}");
        assert!(c.worst_unforced_deg.unwrap() < 1.0);
        // Beside a needle whose smallest angle is at most twice the sliver's: forced.
        let mut nodes = sliver.clone();
        nodes.push([40.0, 0.0, 0.0]);
        nodes.push([40.0, 0.01, 0.0]);
        let needle = smallest_angle_deg([nodes[0], nodes[4], nodes[5]]);
        assert!(needle < 2.0 * mn, "{needle} vs {mn}");
        let m = mesh(nodes.clone(), vec![[0, 1, 2, 3]], vec![[0, 4, 5]]);
        let c = census(&m);
        assert_eq!((c.forced, c.unforced), (1, 0), "{c:?}");
        assert_eq!(c.worst_forcing_triangle.map(|w| w.0), Some(0));
        // A needle that is not that thin does not excuse it.
        nodes[5] = [40.0, 10.0, 0.0];
        let m = mesh(nodes, vec![[0, 1, 2, 3]], vec![[0, 4, 5]]);
        let c = census(&m);
        assert_eq!((c.forced, c.unforced), (0, 1), "{c:?}");
    }

    #[test]
    fn a_regular_tet_is_no_sliver() {
        let s = 1.0 / 2f64.sqrt();
        let nodes = vec![
            [1.0, 0.0, -s],
            [-1.0, 0.0, -s],
            [0.0, 1.0, s],
            [0.0, -1.0, s],
        ];
        let m = mesh(nodes, vec![[0, 1, 2, 3]], vec![[0, 1, 2]]);
        assert_eq!(census(&m), SliverCensus::default());
    }
}
