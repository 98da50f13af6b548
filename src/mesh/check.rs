//! Conformity and volume checks of a P2 tet mesh, independent of how it was made:
//! positive corners (exact), every interior face shared by exactly two tets with opposite
//! orientations, boundary faces exactly the given boundary triangles (same orientation),
//! one mid node per edge, and the linear volume equal to the volume the linear boundary
//! encloses.
//!
//! A mesh of several regions (tets with region ids, as Gmsh physical volumes) may also
//! list the interface triangles between two regions among its boundary triangles
//! ([`check_conformity_regions`]): such a triangle must be a face of two tets of
//! different regions; the outer boundary alone must enclose the tets' volume.

use super::TetMesh;
use crate::geom::predicates::orient3d;
use crate::geom::quadrature::{enclosed_volume_linear, CompensatedSum};
use crate::geom::shape::{TET10_EDGES, TET_OUT_FACES as OUT, TRI6_EDGES};
use crate::geom::vec3::tet_det;
use crate::{Error, Result};

fn compensated_sum(xs: impl Iterator<Item = f64>) -> f64 {
    xs.collect::<CompensatedSum>().value()
}
use rayon::prelude::*;

/// Figures from a passed conformity check.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Conformity {
    /// Number of tets.
    pub tets: usize,
    /// Faces shared by two tets.
    pub interior_faces: usize,
    /// Faces of one tet (== boundary triangles on the outer boundary).
    pub boundary_faces: usize,
    /// Boundary triangles between two tets of different regions (0 for one region).
    pub interface_faces: usize,
    /// Sum of the straight-sided tet volumes.
    pub volume_linear: f64,
    /// Volume enclosed by the flat boundary triangles.
    pub enclosed_linear: f64,
}

fn bad(elements: Vec<usize>, msg: String) -> Error {
    Error::InvalidMesh {
        elements,
        msg,
        mesh: None,
    }
}

/// Check conformity of a one-region mesh: its boundary triangles are exactly the faces
/// of one tet. The error names the first offending elements.
pub fn check_conformity(m: &TetMesh) -> Result<Conformity> {
    check_conformity_regions(m, &[])
}

/// Check conformity of a mesh whose tets have region ids `regions` (one per tet; empty:
/// one region): the faces of one tet are exactly the boundary triangles that are not
/// interfaces, and an interface triangle is a face of two tets of different regions (a
/// triangle between two tets of one region, such as a cavity's wall with tets inside,
/// is an error).
pub fn check_conformity_regions(m: &TetMesh, regions: &[i32]) -> Result<Conformity> {
    if !regions.is_empty() && regions.len() != m.tets.len() {
        return Err(Error::InvalidArgument(format!(
            "{} region ids for {} tets",
            regions.len(),
            m.tets.len()
        )));
    }
    let region = |t: usize| regions.get(t).copied().unwrap_or(0);
    let p = |i: u32| m.nodes[i as usize];
    let n = m.nodes.len() as u32;
    for (ti, t) in m.tets.iter().enumerate() {
        if t.iter().any(|&v| v >= n) {
            return Err(bad(
                vec![ti],
                format!("tet {ti} refers to a node out of range"),
            ));
        }
    }
    let inverted: Vec<usize> = m
        .tets
        .iter()
        .enumerate()
        .filter(|(_, t)| orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) <= 0)
        .map(|(i, _)| i)
        .collect();
    if !inverted.is_empty() {
        return Err(bad(
            inverted.iter().take(20).cloned().collect(),
            format!(
                "{} tets are inverted or degenerate (first: tet {})",
                inverted.len(),
                inverted[0]
            ),
        ));
    }
    let inc = Incidence::new(m);
    // Faces and edges, through the corner incidence: far less memory than a face hash
    // map (the final check ran at 190 B/tet with one; this takes about 20). One parallel
    // pass over the corner vertices ([`faces_and_edges_at`]) counts the faces of one tet
    // and finds the first tet, in tet order, with a face or mid-node defect; the
    // per-tet tests below rebuild that defect's message.
    let faces_of = |ti: usize| -> std::result::Result<usize, Error> {
        let t = &m.tets[ti];
        let mut one = 0;
        for f in &OUT {
            let v = [t[f[0]], t[f[1]], t[f[2]]];
            let mut others = inc.with_face(m, v).filter(|&u| u != ti);
            let Some(u) = others.next() else {
                one += 1;
                continue;
            };
            if others.next().is_some() {
                let mut k = v;
                k.sort_unstable();
                return Err(bad(
                    vec![ti],
                    format!("face {k:?} is shared by more than two tets (tet {ti})"),
                ));
            }
            if outward_face(&m.tets[u], v).is_some_and(|w| same_orientation(w, v)) {
                let (a, b) = (u.min(ti), u.max(ti));
                let mut k = v;
                k.sort_unstable();
                return Err(bad(
                    vec![a, b],
                    format!(
                        "tets {a} and {b} overlap: they share face {k:?} with the same orientation"
                    ),
                ));
            }
        }
        Ok(one)
    };
    let at = (0..m.nodes.len() as u32)
        .into_par_iter()
        .map_init(VertexScratch::default, |s, v| {
            faces_and_edges_at(m, &inc, v, s)
        })
        .reduce(AtVertex::default, AtVertex::merge);
    let one_tet = at.one_tet;
    if at.bad_face != usize::MAX {
        faces_of(at.bad_face)?;
        // (Unreachable: the pass and the per-tet test find the same defects.)
        return Err(bad(
            vec![at.bad_face],
            format!("tet {} has a defective face", at.bad_face),
        ));
    }
    let interior = (4 * m.tets.len() - one_tet) / 2;
    if one_tet > m.boundary.len() {
        return Err(bad(
            vec![],
            format!(
                "the tets have {one_tet} faces of one tet, the boundary has {} triangles",
                m.boundary.len()
            ),
        ));
    }
    // Every boundary triangle a face of one tet, outward, and no triangle twice (so that
    // the counts above matching means the sets match).
    let mut keys: Vec<([u32; 3], usize)> = m
        .boundary
        .iter()
        .enumerate()
        .map(|(bi, b)| {
            let mut k = [b[0], b[1], b[2]];
            k.sort_unstable();
            (k, bi)
        })
        .collect();
    keys.par_sort_unstable();
    if let Some(w) = keys.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(bad(
            vec![],
            format!(
                "boundary triangles {} and {} have the same corners {:?}",
                w[0].1, w[1].1, w[0].0
            ),
        ));
    }
    drop(keys);
    // Each boundary triangle: on the outer boundary (true) or an interface (false).
    let outer: Vec<std::result::Result<bool, (usize, u32, u32)>> = m
        .boundary
        .par_iter()
        .map(|b| {
            let v = [b[0], b[1], b[2]];
            if v.iter().any(|&x| x >= n) {
                return Err((0, 0, 0));
            }
            let mut holders = inc.with_face(m, v);
            match (holders.next(), holders.next()) {
                (Some(u), None)
                    if outward_face(&m.tets[u], v).is_some_and(|w| same_orientation(w, v)) =>
                {
                    Ok(true)
                }
                (Some(_), None) => Err((1, 0, 0)),
                (Some(u), Some(w)) if region(u) != region(w) => Ok(false),
                (Some(u), Some(w)) => Err((2, u as u32, w as u32)),
                _ => Err((3, 0, 0)),
            }
        })
        .collect();
    if let Some((bi, &Err((kind, u, w)))) = outer.iter().enumerate().find(|(_, r)| r.is_err()) {
        let b = &m.boundary[bi];
        let v = [b[0], b[1], b[2]];
        return Err(bad(
            vec![],
            match kind {
                0 => format!("boundary triangle {bi} refers to a node out of range"),
                1 => format!("boundary triangle {bi} {v:?} is reversed in the mesh"),
                2 if regions.is_empty() => format!(
                    "boundary triangle {bi} {v:?} is not a face of one tet (tets {u} and {w} \
                     share it; as an interface between regions, give the tets region ids)"
                ),
                2 => format!(
                    "boundary triangle {bi} {v:?} lies between tets {u} and {w} of one region \
                     ({}), not between two regions",
                    region(u as usize)
                ),
                _ => format!("boundary triangle {bi} {v:?} is not a face of one tet"),
            },
        ));
    }
    let outer: Vec<bool> = outer.into_iter().map(|r| r == Ok(true)).collect();
    let n_outer = outer.iter().filter(|&&o| o).count();
    if one_tet != n_outer {
        return Err(bad(
            vec![],
            format!(
                "the tets have {one_tet} faces of one tet, the boundary has {n_outer} \
                 triangles on them ({} in all)",
                m.boundary.len()
            ),
        ));
    }
    // One mid node per edge: every tet's equals that of the first tet holding the edge,
    // and the boundary's on boundary edges.
    if at.bad_mid != usize::MAX {
        let ti = at.bad_mid;
        let t = &m.tets[ti];
        for (e, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            let mnode = t[4 + e];
            // Tet ti itself holds the edge: there is a first tet.
            let prev = inc.edge_mid(m, a, b).unwrap_or(mnode);
            if prev != mnode {
                return Err(bad(
                    vec![ti],
                    format!("edge ({a}, {b}) has two mid nodes ({prev} and {mnode}); tet {ti}"),
                ));
            }
        }
        // (Unreachable, as for faces.)
        return Err(bad(
            vec![ti],
            format!("tet {ti} has an edge with two mid nodes"),
        ));
    }
    let bmid_err = m.boundary.par_iter().enumerate().find_map_first(|(bi, b)| {
        TRI6_EDGES.iter().enumerate().find_map(|(e, [i, j])| {
            let (a, c) = (b[*i], b[*j]);
            (inc.edge_mid(m, a, c) != Some(b[3 + e])).then(|| {
                bad(
                    vec![],
                    format!(
                        "boundary triangle {bi}: its mid node on edge ({a}, {c}) is not the tets'"
                    ),
                )
            })
        })
    });
    if let Some(e) = bmid_err {
        return Err(e);
    }
    let volume_linear = compensated_sum(
        m.tets
            .iter()
            .map(|t| tet_det(p(t[0]), p(t[1]), p(t[2]), p(t[3])) / 6.0),
    );
    let outer_tris: Vec<[u32; 6]> = m
        .boundary
        .iter()
        .zip(&outer)
        .filter(|(_, &on_outer)| on_outer)
        .map(|(b, _)| *b)
        .collect();
    let enclosed_linear = enclosed_volume_linear(&m.nodes, &outer_tris);
    Ok(Conformity {
        tets: m.tets.len(),
        interior_faces: interior,
        boundary_faces: one_tet,
        interface_faces: m.boundary.len() - n_outer,
        volume_linear,
        enclosed_linear,
    })
}

/// What the faces and edges whose smallest corner is one vertex show.
#[derive(Clone, Copy)]
struct AtVertex {
    /// Faces held by one tet.
    one_tet: usize,
    /// Smallest tet holding a face also held by two other tets, or held by another tet
    /// with the same orientation (usize::MAX: none).
    bad_face: usize,
    /// Smallest tet whose mid node on an edge differs from that of the first (smallest)
    /// tet holding the edge (usize::MAX: none).
    bad_mid: usize,
}

impl Default for AtVertex {
    fn default() -> Self {
        AtVertex {
            one_tet: 0,
            bad_face: usize::MAX,
            bad_mid: usize::MAX,
        }
    }
}

impl AtVertex {
    fn merge(a: AtVertex, b: AtVertex) -> AtVertex {
        AtVertex {
            one_tet: a.one_tet + b.one_tet,
            bad_face: a.bad_face.min(b.bad_face),
            bad_mid: a.bad_mid.min(b.bad_mid),
        }
    }
}

/// Buffers of [`faces_and_edges_at`].
#[derive(Default)]
struct VertexScratch {
    /// (other two corners ascending, tet, the tet's outward face).
    faces: Vec<([u32; 2], u32, [u32; 3])>,
    /// (other corner, tet, mid node).
    edges: Vec<(u32, u32, u32)>,
}

/// The faces and edges of the tets around `v` whose smallest corner is `v` (so every
/// face and edge of the mesh is seen at exactly one vertex), grouped by sorting: a group
/// of one face is a face of one tet, of two an interior face (their orientations must
/// be opposite), larger a defect; the tets holding an edge must agree on its mid node.
/// Sorting each vertex's few dozen entries is faster than looking up every face and edge
/// of every tet in the rows (on the 1M-tet torus the whole check went 0.60 -> 0.32 s).
fn faces_and_edges_at(m: &TetMesh, inc: &Incidence, v: u32, s: &mut VertexScratch) -> AtVertex {
    let mut r = AtVertex::default();
    let row = inc.around(v);
    if row.is_empty() {
        return r;
    }
    s.faces.clear();
    s.edges.clear();
    for &u in row {
        let t = &m.tets[u as usize];
        for f in &OUT {
            let w = [t[f[0]], t[f[1]], t[f[2]]];
            if w.contains(&v) && w.iter().all(|&x| x >= v) {
                let mut k = w;
                k.sort_unstable();
                s.faces.push(([k[1], k[2]], u, w));
            }
        }
        for (e, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            if a == v && b > v {
                s.edges.push((b, u, t[4 + e]));
            } else if b == v && a > v {
                s.edges.push((a, u, t[4 + e]));
            }
        }
    }
    s.faces.sort_unstable_by_key(|e| (e.0, e.1));
    for g in s.faces.chunk_by(|a, b| a.0 == b.0) {
        match g {
            [_] => r.one_tet += 1,
            [x, y] => {
                if same_orientation(x.2, y.2) {
                    r.bad_face = r.bad_face.min(x.1.min(y.1) as usize);
                }
            }
            _ => {
                let first = g.iter().map(|x| x.1).min().unwrap_or(u32::MAX);
                r.bad_face = r.bad_face.min(first as usize);
            }
        }
    }
    s.edges.sort_unstable();
    for g in s.edges.chunk_by(|a, b| a.0 == b.0) {
        // Sorted by tet within the group: the first entry is the first tet's.
        let mid = g[0].2;
        if let Some(x) = g.iter().find(|x| x.2 != mid) {
            r.bad_mid = r.bad_mid.min(x.1 as usize);
        }
    }
    r
}

/// The tets around each corner vertex (compressed rows, tets ascending).
struct Incidence {
    start: Vec<u32>,
    tets: Vec<u32>,
}

impl Incidence {
    fn new(m: &TetMesh) -> Self {
        let mut start = vec![0u32; m.nodes.len() + 1];
        for t in &m.tets {
            for &v in &t[..4] {
                start[v as usize + 1] += 1;
            }
        }
        for i in 0..m.nodes.len() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut tets = vec![0u32; 4 * m.tets.len()];
        for (ti, t) in m.tets.iter().enumerate() {
            for &v in &t[..4] {
                tets[fill[v as usize] as usize] = ti as u32;
                fill[v as usize] += 1;
            }
        }
        Incidence { start, tets }
    }

    fn around(&self, v: u32) -> &[u32] {
        &self.tets[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }

    /// The tets whose corners include the three of `v`.
    fn with_face<'a>(&'a self, m: &'a TetMesh, v: [u32; 3]) -> impl Iterator<Item = usize> + 'a {
        // Scan the shortest of the three lists.
        let len = |x: u32| self.start[x as usize + 1] - self.start[x as usize];
        let k = (0..3).min_by_key(|&k| len(v[k])).unwrap_or(0);
        let (p, q) = (v[(k + 1) % 3], v[(k + 2) % 3]);
        self.around(v[k])
            .iter()
            .map(|&u| u as usize)
            .filter(move |&u| {
                let c = &m.tets[u][..4];
                c.contains(&p) && c.contains(&q)
            })
    }

    /// The mid node of edge (a, b) in the first tet holding it.
    fn edge_mid(&self, m: &TetMesh, a: u32, b: u32) -> Option<u32> {
        self.around(a).iter().find_map(|&u| {
            let t = &m.tets[u as usize];
            if !t[..4].contains(&b) {
                return None;
            }
            TET10_EDGES.iter().enumerate().find_map(|(e, [i, j])| {
                ((t[*i] == a && t[*j] == b) || (t[*i] == b && t[*j] == a)).then_some(t[4 + e])
            })
        })
    }
}

/// Tet `t`'s outward face on the corners of `v` (`None` if it does not hold them).
fn outward_face(t: &[u32; 10], v: [u32; 3]) -> Option<[u32; 3]> {
    OUT.iter()
        .find(|f| f.iter().all(|&k| v.contains(&t[k])))
        .map(|f| [t[f[0]], t[f[1]], t[f[2]]])
}

fn same_orientation(a: [u32; 3], b: [u32; 3]) -> bool {
    b == a || b == [a[1], a[2], a[0]] || b == [a[2], a[0], a[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::testmesh::cube;

    fn msg(m: &TetMesh) -> String {
        match check_conformity(m) {
            Err(Error::InvalidMesh { msg, .. }) => msg,
            other => panic!("expected InvalidMesh, got {other:?}"),
        }
    }

    #[test]
    fn a_cube_passes_with_its_counts_and_volume() {
        let m = cube(3, 0.0).p2();
        let c = check_conformity(&m).unwrap();
        assert_eq!(c.tets, 6 * 27);
        assert_eq!(c.boundary_faces, m.boundary.len());
        assert_eq!(c.boundary_faces, 6 * 9 * 2);
        assert_eq!(2 * c.interior_faces + c.boundary_faces, 4 * c.tets);
        assert!((c.volume_linear - 1.0).abs() < 1e-14);
        assert!((c.enclosed_linear - 1.0).abs() < 1e-14);
    }

    /// The vertex pass and the per-tet tests that word the message agree: random
    /// corruptions (a mid node swapped between tets, a tet repeated, a tet's corners
    /// permuted into another's place) are reported with the per-tet message, never the
    /// fallback one.
    #[test]
    fn vertex_pass_finds_what_the_messages_describe() {
        use rand::{Rng, SeedableRng};
        let base = cube(3, 0.05).p2();
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let n = base.tets.len();
        let mut kinds = [0usize; 3];
        for _ in 0..300 {
            let mut m = base.clone();
            let kind = rng.random_range(0..3);
            let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
            match kind {
                0 => {
                    let (e, f) = (rng.random_range(4..10), rng.random_range(4..10));
                    let x = m.tets[a][e];
                    m.tets[a][e] = m.tets[b][f];
                    m.tets[b][f] = x;
                }
                1 => m.tets.push(m.tets[a]),
                _ => {
                    let t = m.tets[a];
                    m.tets[b] = t;
                }
            }
            match check_conformity(&m) {
                Ok(_) => {}
                Err(Error::InvalidMesh { msg, .. }) => {
                    assert!(
                        !msg.contains("defective face") && !msg.contains("an edge with two"),
                        "{msg}"
                    );
                    kinds[kind] += 1;
                }
                Err(e) => panic!("{e}"),
            }
        }
        assert!(kinds.iter().all(|&k| k > 50), "{kinds:?}");
    }

    #[test]
    fn each_defect_is_named() {
        let base = cube(3, 0.05).p2();
        // An inverted tet.
        let mut m = base.clone();
        m.tets[5].swap(0, 1);
        assert!(msg(&m).contains("inverted"), "{}", msg(&m));
        // A tet twice: its interior faces are in three tets.
        let mut m = base.clone();
        m.tets.push(m.tets[7]);
        assert!(msg(&m).contains("more than two tets"), "{}", msg(&m));
        // A tet on the same side of another's face: they overlap.
        let mut m = base.clone();
        let t = m.tets[9];
        let c = (0..3).map(|d| t[..4].iter().map(|&v| m.nodes[v as usize][d]).sum::<f64>() / 4.0);
        let c: Vec<f64> = c.collect();
        m.nodes.push([c[0], c[1], c[2]]);
        let p = m.nodes.len() as u32 - 1;
        m.tets
            .push([t[0], t[1], t[2], p, t[4], t[5], t[6], p, p, p]);
        assert!(msg(&m).contains("overlap"), "{}", msg(&m));
        // A missing tet: its faces become faces of one tet that are not boundary.
        let mut m = base.clone();
        let interior = (0..m.tets.len())
            .find(|&t| {
                m.tets[t][..4]
                    .iter()
                    .all(|&v| m.boundary.iter().all(|b| !b[..3].contains(&v)))
            })
            .unwrap_or(40);
        m.tets.remove(interior);
        assert!(msg(&m).contains("faces of one tet"), "{}", msg(&m));
        // A reversed boundary triangle.
        let mut m = base.clone();
        let b = &mut m.boundary[3];
        b.swap(1, 2);
        b.swap(3, 5);
        assert!(msg(&m).contains("reversed"), "{}", msg(&m));
        // A boundary triangle listed twice instead of another.
        let mut m = base.clone();
        m.boundary[4] = m.boundary[5];
        assert!(msg(&m).contains("same corners"), "{}", msg(&m));
        // Two mid nodes on one edge.
        let mut m = base.clone();
        let t = (0..m.tets.len())
            .rev()
            .find(|&t| m.tets[t][4] as usize >= 100)
            .unwrap();
        m.nodes.push(m.nodes[m.tets[t][4] as usize]);
        m.tets[t][4] = m.nodes.len() as u32 - 1;
        assert!(msg(&m).contains("two mid nodes"), "{}", msg(&m));
        // A boundary mid node that is not the tets'.
        let mut m = base.clone();
        m.boundary[2][4] = m.boundary[2][3];
        assert!(msg(&m).contains("is not the tets'"), "{}", msg(&m));
        // Out of range.
        let mut m = base.clone();
        m.tets[0][7] = m.nodes.len() as u32;
        assert!(msg(&m).contains("out of range"), "{}", msg(&m));
    }
}
