//! Unit tests of the surface checks on small hand-built surfaces: one passing family
//! (tetrahedron, octahedron, icosahedron, box, nested shells) and one test per defect.

use super::*;
use crate::error::SurfaceDefect;
use crate::geom::vec3::{add, dist2, mid, normalize, scale, sub, tet_det};

/// A P2 surface under construction: corner ids are the vertex ids; mid nodes follow.
#[derive(Clone, Debug)]
struct P2 {
    nodes: Vec<P3>,
    tris: Vec<[u32; 6]>,
}

impl P2 {
    /// Builds P2 triangles on `faces`, one mid node per edge placed by `mid_of`.
    fn new(verts: &[P3], faces: &[[u32; 3]], mid_of: impl Fn(P3, P3) -> P3) -> P2 {
        let mut nodes = verts.to_vec();
        let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
        let mut tris = Vec::new();
        for f in faces {
            let mut t = [f[0], f[1], f[2], 0, 0, 0];
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let id = *mids.entry(key).or_insert_with(|| {
                    nodes.push(mid_of(verts[a as usize], verts[b as usize]));
                    nodes.len() as u32 - 1
                });
                t[3 + k] = id;
            }
            tris.push(t);
        }
        P2 { nodes, tris }
    }

    fn check(&self) -> Result<Surface> {
        Surface::new(self.nodes.clone(), self.tris.clone(), vec![])
    }

    fn check_strict(&self) -> Result<Surface> {
        Surface::new_with_repair(
            self.nodes.clone(),
            self.tris.clone(),
            vec![],
            Repair::Strict,
        )
    }

    /// The defect the strict checks report. Without `Strict`, only unused nodes and
    /// orientation may be repaired: every other defect is still refused.
    fn defect(&self) -> (SurfaceDefect, String) {
        let (kind, msg) = match self.check_strict() {
            Err(Error::InvalidSurface { kind, msg }) => (kind, msg),
            Err(e) => panic!("expected a surface defect, got {e}"),
            Ok(_) => panic!("expected a surface defect, the surface was accepted"),
        };
        if !matches!(
            kind,
            SurfaceDefect::UnusedNode | SurfaceDefect::InconsistentOrientation
        ) {
            let e = self.check().expect_err("refused without --strict too");
            assert_eq!(e.surface_defect(), Some(kind), "{e}");
        }
        (kind, msg)
    }

    /// Another surface's triangles added as a separate set of nodes.
    fn union(&self, other: &P2) -> P2 {
        let off = self.nodes.len() as u32;
        let mut r = self.clone();
        r.nodes.extend_from_slice(&other.nodes);
        r.tris.extend(other.tris.iter().map(|t| t.map(|v| v + off)));
        r
    }

    fn flipped(&self) -> P2 {
        let mut r = self.clone();
        for t in &mut r.tris {
            *t = [t[0], t[2], t[1], t[5], t[4], t[3]];
        }
        r
    }

    fn moved(&self, f: impl Fn(P3) -> P3) -> P2 {
        let mut r = self.clone();
        for p in &mut r.nodes {
            *p = f(*p);
        }
        r
    }

    /// Drops unused nodes, renumbering the rest.
    fn compact(&self) -> P2 {
        let mut used = vec![false; self.nodes.len()];
        for t in &self.tris {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut map = vec![u32::MAX; self.nodes.len()];
        let mut nodes = Vec::new();
        for (i, p) in self.nodes.iter().enumerate() {
            if used[i] {
                map[i] = nodes.len() as u32;
                nodes.push(*p);
            }
        }
        let tris = self
            .tris
            .iter()
            .map(|t| t.map(|v| map[v as usize]))
            .collect();
        P2 { nodes, tris }
    }
}

/// Faces of a regular convex polyhedron: all triples of vertices at mutual squared
/// distance `e2`, oriented outward (w.r.t. the origin).
fn hull_faces(v: &[P3], e2: f64) -> Vec<[u32; 3]> {
    let n = v.len();
    let close = |a: usize, b: usize| (dist2(v[a], v[b]) - e2).abs() < 1e-9;
    let mut f = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if close(i, j) && close(j, k) && close(i, k) {
                    let nrm = crate::geom::vec3::tri_normal(v[i], v[j], v[k]);
                    let c = crate::geom::vec3::centroid3(v[i], v[j], v[k]);
                    if crate::geom::vec3::dot(nrm, c) > 0.0 {
                        f.push([i as u32, j as u32, k as u32]);
                    } else {
                        f.push([i as u32, k as u32, j as u32]);
                    }
                }
            }
        }
    }
    f
}

/// Mid node projected on the sphere of radius |a| about the origin.
fn sphere_mid(a: P3, b: P3) -> P3 {
    scale(normalize(mid(a, b)), crate::geom::vec3::norm(a))
}

fn octahedron(r: f64) -> P2 {
    let v: Vec<P3> = vec![
        [r, 0.0, 0.0],
        [-r, 0.0, 0.0],
        [0.0, r, 0.0],
        [0.0, -r, 0.0],
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
    ];
    P2::new(&v, &hull_faces(&v, 2.0 * r * r), sphere_mid)
}

fn icosahedron() -> P2 {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v = Vec::new();
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            v.push([0.0, s1, s2 * g]);
            v.push([s1, s2 * g, 0.0]);
            v.push([s2 * g, 0.0, s1]);
        }
    }
    P2::new(&v, &hull_faces(&v, 4.0), sphere_mid)
}

/// The outward surface of tetrahedron `c` (any orientation), flat P2 (chord midpoints).
fn tet(c: [P3; 4]) -> P2 {
    let pos = tet_det(c[0], c[1], c[2], c[3]) > 0.0;
    let mut faces = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    if !pos {
        for f in &mut faces {
            f.swap(1, 2);
        }
    }
    P2::new(&c, &faces, mid)
}

const O: P3 = [0.0, 0.0, 0.0];
const X: P3 = [1.0, 0.0, 0.0];
const Y: P3 = [0.0, 1.0, 0.0];
const Z: P3 = [0.0, 0.0, 1.0];

fn unit_tet() -> P2 {
    tet([O, X, Y, Z])
}

/// An axis-aligned box, two flat P2 triangles per face (coplanar neighbours).
fn cube() -> P2 {
    let mut v = Vec::new();
    for i in 0..8 {
        v.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    }
    // Quads outward (right-hand rule), split along a diagonal.
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let mut faces = Vec::new();
    for q in quads {
        faces.push([q[0], q[1], q[2]]);
        faces.push([q[0], q[2], q[3]]);
    }
    P2::new(&v, &faces, mid)
}

fn assert_defect(s: &P2, kind: SurfaceDefect, needles: &[&str]) -> String {
    let (k, msg) = s.defect();
    assert_eq!(k, kind, "wrong kind; message: {msg}");
    for n in needles {
        assert!(msg.contains(n), "message {msg:?} lacks {n:?}");
    }
    msg
}

// ---------------------------------------------------------------- accepted surfaces

#[test]
fn platonic_p2_surfaces_pass() {
    for (name, s, nt) in [
        (
            "tetrahedron",
            tet([
                [1.0, 1.0, 1.0],
                [1.0, -1.0, -1.0],
                [-1.0, 1.0, -1.0],
                [-1.0, -1.0, 1.0],
            ]),
            4,
        ),
        ("octahedron", octahedron(1.0), 8),
        ("icosahedron", icosahedron(), 20),
        ("cube", cube(), 12),
    ] {
        let surf = s.check().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(surf.triangles().len(), nt, "{name}");
        assert!(surf.warnings().is_empty(), "{name}");
        assert!(surf.volume() > 0.0 && surf.chord_volume() > 0.0, "{name}");
        assert_eq!(surf.shell_count(), 1);
        assert_eq!(surf.edges().len(), 3 * nt / 2);
    }
    // P2 octahedron with projected mids: between the chord volume and the sphere's.
    let s = octahedron(1.0).check().unwrap();
    assert!((s.chord_volume() - 4.0 / 3.0).abs() < 1e-12);
    assert!(s.volume() > 4.0 / 3.0 && s.volume() < 4.0 / 3.0 * std::f64::consts::PI);
    let c = cube().check().unwrap();
    assert!((c.volume() - 1.0).abs() < 1e-14 && (c.chord_volume() - 1.0).abs() < 1e-14);
    assert_eq!(c.min_normal_cosine(), 1.0);
}

#[test]
fn helpers_for_the_mesher() {
    let s = octahedron(1.0).check().unwrap();
    assert_eq!(s.corner_nodes(), &[0, 1, 2, 3, 4, 5]);
    assert!(s.is_corner(3) && !s.is_corner(6));
    assert_eq!(s.mid_nodes(), (6..18).collect::<Vec<u32>>());
    let map = s.edge_mid_map();
    assert_eq!(map.len(), 12);
    for (t, tri) in s.triangles().iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            assert_eq!(s.mid_node(a, b), Some(tri[3 + k]));
            assert_eq!(s.mid_node(b, a), Some(tri[3 + k]));
            assert_eq!(map[&(a.min(b), a.max(b))], tri[3 + k]);
            let n = s.neighbors()[t][k] as usize;
            assert!(s.neighbors()[n].contains(&(t as u32)));
            assert!(s.triangles()[n][..3].contains(&a) && s.triangles()[n][..3].contains(&b));
        }
    }
    for e in s.edges() {
        let t0 = s.triangles()[e.tris[0] as usize];
        let k = (0..3).find(|&k| t0[k] == e.nodes[0]).unwrap();
        assert_eq!(t0[(k + 1) % 3], e.nodes[1], "tris[0] runs the edge forward");
    }
    assert_eq!(s.mid_node(0, 1), None); // opposite vertices
    assert!(s.shell_ids().iter().all(|&x| x == 0));
}

#[test]
fn tags_default_and_length() {
    let s = octahedron(1.0);
    let surf = Surface::new(s.nodes.clone(), s.tris.clone(), vec![]).unwrap();
    assert!(surf.tags().iter().all(|&t| t == 0));
    let tags: Vec<i32> = (0..8).collect();
    let surf = Surface::new(s.nodes.clone(), s.tris.clone(), tags.clone()).unwrap();
    assert_eq!(surf.tags(), &tags[..]);
    let e = Surface::new(s.nodes.clone(), s.tris.clone(), vec![1, 2]).unwrap_err();
    assert!(matches!(e, Error::InvalidArgument(_)), "{e}");
}

// ---------------------------------------------------------------- index-level defects

#[test]
fn empty() {
    let e = Surface::new(vec![], vec![], vec![]).unwrap_err();
    assert_eq!(e.surface_defect(), Some(SurfaceDefect::Empty));
    let e = Surface::new(vec![[0.0; 3]], vec![], vec![]).unwrap_err();
    assert_eq!(e.surface_defect(), Some(SurfaceDefect::Empty));
}

#[test]
fn index_out_of_range() {
    let mut s = octahedron(1.0);
    s.tris[2][4] = 99;
    let c = s.tris[2];
    assert_defect(
        &s,
        SurfaceDefect::IndexOutOfRange,
        &[
            &format!("triangle 2 (corners {}, {}, {})", c[0], c[1], c[2]),
            "99",
        ],
    );
}

#[test]
fn repeated_node() {
    let mut s = octahedron(1.0);
    s.tris[5][1] = s.tris[5][0];
    assert_defect(&s, SurfaceDefect::RepeatedNode, &["triangle 5 "]);
    let mut s = octahedron(1.0);
    s.tris[3][5] = s.tris[3][3]; // two mid nodes equal
    assert_defect(&s, SurfaceDefect::RepeatedNode, &["triangle 3 "]);
}

// ---------------------------------------------------------------- coordinate defects

#[test]
fn nan_and_inf() {
    let mut s = octahedron(1.0);
    s.nodes[4][1] = f64::NAN;
    assert_defect(
        &s,
        SurfaceDefect::NonFiniteCoordinate,
        &["node 4 (0.0, NaN, 1.0)"],
    );
    let mut s = octahedron(1.0);
    s.nodes[7][0] = f64::NEG_INFINITY;
    assert_defect(&s, SurfaceDefect::NonFiniteCoordinate, &["node 7 (-inf"]);
}

#[test]
fn coordinates_1e300() {
    let s = octahedron(1.0).moved(|p| scale(p, 1e300));
    assert_defect(&s, SurfaceDefect::CoordinateRange, &["node 0 (1e300"]);
    // Just inside the limit is fine.
    let s = octahedron(1.0).moved(|p| scale(p, 1e29));
    s.check().unwrap();
}

#[test]
fn scale_1e_300() {
    // The whole model at 1e-300: every coordinate is a tiny nonzero.
    let s = octahedron(1.0).moved(|p| scale(p, 1e-300));
    assert_defect(&s, SurfaceDefect::CoordinateRange, &["node 0"]);
    // A model of size 1e-40 (coordinates fine) is too small as a whole.
    let s = octahedron(1.0).moved(|p| scale(p, 1e-40));
    assert_defect(&s, SurfaceDefect::CoordinateRange, &["diagonal"]);
    // Small but admitted: size 1e-20.
    let s = octahedron(1.0).moved(|p| scale(p, 1e-20));
    let surf = s.check().unwrap();
    assert!(surf.volume() > 0.0);
    // One tiny nonzero coordinate in a normal model.
    let mut s = octahedron(1.0);
    s.nodes[2][0] = 1e-70;
    assert_defect(&s, SurfaceDefect::CoordinateRange, &["node 2 (1e-70"]);
}

#[test]
fn duplicate_node() {
    // A copy of vertex 0 used by one triangle: two nodes at the same place.
    let mut s = octahedron(1.0);
    s.nodes.push(s.nodes[0]);
    let t = s.tris.iter().position(|t| t[0] == 0).unwrap();
    s.tris[t][0] = 18;
    assert_defect(
        &s,
        SurfaceDefect::DuplicateNode,
        &["node 0 (1.0, 0.0, 0.0) and node 18"],
    );
    // -0.0 and 0.0 are the same coordinate.
    let mut s = octahedron(1.0);
    let mut p = s.nodes[4];
    p[0] = -0.0;
    s.nodes.push(p);
    let t = s
        .tris
        .iter()
        .position(|t| t[0] == 4 || t[1] == 4 || t[2] == 4)
        .unwrap();
    let k = (0..3).find(|&k| s.tris[t][k] == 4).unwrap();
    s.tris[t][k] = 18;
    assert_defect(&s, SurfaceDefect::DuplicateNode, &["node 4", "node 18"]);
}

#[test]
fn unused_node() {
    let mut s = octahedron(1.0);
    s.nodes.push([5.0, 5.0, 5.0]);
    assert_defect(&s, SurfaceDefect::UnusedNode, &["node 18 (5.0, 5.0, 5.0)"]);
}

// ---------------------------------------------------------------- topology defects

#[test]
fn open_surface() {
    let mut s = octahedron(1.0);
    let gone = s.tris.remove(3);
    let msg = assert_defect(&s, SurfaceDefect::NotClosed, &["used by one triangle"]);
    // The edge named is one of the removed triangle's.
    let named = (0..3).any(|k| {
        let (a, b) = (gone[k], gone[(k + 1) % 3]);
        msg.contains(&format!("edge ({}, {})", a.min(b), a.max(b)))
    });
    assert!(named, "{msg}");
}

#[test]
fn non_manifold_edge_three_triangles() {
    // Octahedron plus an equatorial membrane: each equator edge gets a third triangle.
    let mut s = octahedron(1.0);
    let diag_mid = s.nodes.len() as u32;
    s.nodes.push([0.0, 0.0, 0.0]);
    let m = |s: &P2, a: u32, b: u32| -> u32 {
        for t in &s.tris {
            for k in 0..3 {
                if (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a) {
                    return t[3 + k];
                }
            }
        }
        unreachable!()
    };
    // (+x, +y, -x) and (-x, -y, +x), i.e. vertices (0, 2, 1) and (1, 3, 0).
    let t1 = [0, 2, 1, m(&s, 0, 2), m(&s, 2, 1), diag_mid];
    let t2 = [1, 3, 0, m(&s, 1, 3), m(&s, 3, 0), diag_mid];
    s.tris.push(t1);
    s.tris.push(t2);
    assert_defect(
        &s,
        SurfaceDefect::NonManifoldEdge,
        &["used by 3 triangles", "triangle 8 (corners 0, 2, 1)"],
    );
}

#[test]
fn non_manifold_vertex_bowtie() {
    // Two tetrahedra touching at the origin only.
    let a = unit_tet();
    let b = tet([O, [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]);
    let mut s = a.union(&b);
    // Weld b's origin onto a's (node 0); b's copy becomes unused: drop it.
    let off = a.nodes.len() as u32;
    for t in &mut s.tris {
        for v in t.iter_mut() {
            if *v == off {
                *v = 0;
            }
        }
    }
    let s = s.compact();
    assert_defect(
        &s,
        SurfaceDefect::NonManifoldVertex,
        &["node 0 (0.0, 0.0, 0.0)", "more than one fan"],
    );
}

#[test]
fn one_triangle_flipped() {
    let mut s = octahedron(1.0);
    let t = s.tris[6];
    s.tris[6] = [t[0], t[2], t[1], t[5], t[4], t[3]];
    assert_defect(
        &s,
        SurfaceDefect::InconsistentOrientation,
        &[
            "same direction",
            &format!("triangle 6 (corners {}, {}, {})", t[0], t[2], t[1]),
        ],
    );
}

#[test]
fn mid_node_mismatch_between_two_triangles() {
    let mut s = octahedron(1.0);
    let (a, b) = (s.tris[0][0], s.tris[0][1]);
    let p = s.nodes[s.tris[0][3] as usize];
    s.nodes.push(scale(p, 1.01));
    s.tris[0][3] = s.nodes.len() as u32 - 1;
    assert_defect(
        &s,
        SurfaceDefect::MidNodeMismatch,
        &[&format!("edge ({}, {})", a.min(b), a.max(b)), "triangle 0 "],
    );
}

#[test]
fn mid_node_used_as_corner_or_twice() {
    // The mid node of an edge is made the node of another edge as well.
    let base = octahedron(1.0);
    let m0 = base.tris[0][3];
    // An edge of the opposite face (no corner in common with triangle 0).
    let opp = base
        .tris
        .iter()
        .find(|t| t[..3].iter().all(|v| !base.tris[0][..3].contains(v)))
        .unwrap();
    let (a, b) = (opp[0], opp[1]);
    let mut s = base.clone();
    for t in &mut s.tris {
        for k in 0..3 {
            let (x, y) = (t[k], t[(k + 1) % 3]);
            if (x.min(y), x.max(y)) == (a.min(b), a.max(b)) {
                t[3 + k] = m0;
            }
        }
    }
    let s = s.compact();
    assert_defect(
        &s,
        SurfaceDefect::MidNodeMismatch,
        &["mid node of two edges"],
    );

    // A mid node that is also a corner: the two triangles of an edge take a corner of a
    // third triangle as their mid node.
    let mut s = base.clone();
    let c = 1u32; // -x: not a corner of the two triangles on edge (0, 2)
    for t in &mut s.tris {
        for k in 0..3 {
            let (x, y) = (t[k], t[(k + 1) % 3]);
            if (x.min(y), x.max(y)) == (0, 2) {
                t[3 + k] = c;
            }
        }
    }
    let s = s.compact();
    assert_defect(
        &s,
        SurfaceDefect::MidNodeMismatch,
        &["also a corner", "edge (0, 2)"],
    );
}

// ---------------------------------------------------------------- geometric defects

#[test]
fn zero_area_triangle() {
    // A tet with edge O-X split at E = (0.5, 0, 0) on one side only, closed by the
    // collinear triangle (O, X, E).
    let v: Vec<P3> = vec![
        O,
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, 2.0],
        [0.5, 0.0, 0.0],
    ];
    let (o, x, y, z, e) = (0, 1, 2, 3, 4);
    let faces = vec![
        [o, y, x],
        [o, e, z],
        [e, x, z],
        [o, z, y],
        [x, y, z],
        [o, x, e],
    ];
    let s = P2::new(&v, &faces, mid);
    assert_defect(
        &s,
        SurfaceDefect::DegenerateTriangle,
        &["triangle 5 (corners 0, 1, 4)", "collinear"],
    );
}

#[test]
fn folded_curved_triangle() {
    // Push the mid node of an octahedron edge along the edge, past the 3/4 point: the
    // curved edge turns back and the normal flips there.
    let mut s = octahedron(1.0);
    let (a, b, m) = (s.tris[0][0], s.tris[0][1], s.tris[0][3]);
    let (pa, pb) = (s.nodes[a as usize], s.nodes[b as usize]);
    s.nodes[m as usize] = add(pa, scale(sub(pb, pa), 0.9));
    let msg = assert_defect(
        &s,
        SurfaceDefect::FoldedTriangle,
        &["triangle 0 ", "min cos"],
    );
    assert!(
        msg.contains("min cos(curved normal, chord normal) = -"),
        "{msg}"
    );
    // Pushed through along the normal: the patch turns inside out near the edge.
    let mut s = octahedron(1.0);
    let m = s.tris[0][3];
    s.nodes[m as usize] = scale(s.nodes[m as usize], -0.7);
    assert_defect(&s, SurfaceDefect::FoldedTriangle, &["triangle 0 "]);
}

#[test]
fn mid_node_far_from_its_edge() {
    // Farther than an edge length from the edge's midpoint (here 2.7 edge lengths
    // through the centre; the fuzzer's case was 1e58 on a model scaled to 1e-58, which
    // the fold sampling let through and the volume could not be computed for).
    let mut s = octahedron(1.0);
    let m = s.tris[0][3];
    s.nodes[m as usize] = scale(s.nodes[m as usize], -2.0);
    let msg = assert_defect(
        &s,
        SurfaceDefect::MidNodeMismatch,
        &["triangle 0 ", "edge lengths from the edge's midpoint"],
    );
    assert!(msg.contains(&format!("mid node {m} ")), "{msg}");
    let mut s = icosahedron().moved(|p| scale(p, 1e-58));
    let m = s.tris[3][4] as usize;
    s.nodes[m] = [0.75, 0.0, -2.0];
    assert_defect(&s, SurfaceDefect::MidNodeMismatch, &["mid node"]);
    // Just under the limit is not this defect (a half-turn arc is 0.5).
    let mut s = octahedron(1.0);
    let (a, b, m) = (s.tris[0][0], s.tris[0][1], s.tris[0][3]);
    let (pa, pb) = (s.nodes[a as usize], s.nodes[b as usize]);
    let c = scale(add(pa, pb), 0.5);
    let len = dist2(pa, pb).sqrt();
    s.nodes[m as usize] = add(c, scale(normalize(c), 0.99 * len));
    if let Err(Error::InvalidSurface { kind, .. }) = s.check() {
        assert_ne!(kind, SurfaceDefect::MidNodeMismatch);
    }
}

// ---------------------------------------------------------------- intersections

#[test]
fn two_shells_crossing() {
    let s = octahedron(1.0).union(&octahedron(1.0).moved(|p| add(p, [0.5, 0.1, 0.05])));
    assert_defect(
        &s,
        SurfaceDefect::SelfIntersection,
        &["intersect", "triangle "],
    );
}

#[test]
fn touching_vertex_on_face() {
    // b's apex touches a's bottom face (z = 0) at an interior point.
    let b = tet([
        [0.25, 0.25, 0.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, -1.0],
        [0.0, 1.0, -1.0],
    ]);
    let s = unit_tet().union(&b);
    let msg = assert_defect(&s, SurfaceDefect::SelfIntersection, &["intersect"]);
    // The bottom face of a is triangle 0 (O, Y, X).
    assert!(msg.contains("triangle 0 (corners 0, 2, 1)"), "{msg}");
}

#[test]
fn crossing_tetrahedra() {
    let b = tet([
        [0.2, 0.2, 0.2],
        [-1.0, 0.1, 0.1],
        [0.1, -1.0, 0.1],
        [0.1, 0.1, -1.0],
    ]);
    let s = unit_tet().union(&b);
    assert_defect(&s, SurfaceDefect::SelfIntersection, &["intersect"]);
}

#[test]
fn coplanar_overlap() {
    // b's top face lies in z = 0 and overlaps a's bottom face.
    let b = tet([
        [0.2, 0.2, 0.0],
        [1.2, 0.2, 0.0],
        [0.2, 1.2, 0.0],
        [0.2, 0.2, -1.0],
    ]);
    let s = unit_tet().union(&b);
    assert_defect(
        &s,
        SurfaceDefect::SelfIntersection,
        &["triangle 0 (corners 0, 2, 1)"],
    );
}

#[test]
fn coincident_pillow() {
    // Two triangles on the same corners, opposite orientations, different bulges.
    let nodes = vec![
        O,
        X,
        Y,
        [0.5, 0.0, 0.1],
        [0.5, 0.5, 0.1],
        [0.0, 0.5, 0.1],
        [0.5, 0.0, -0.1],
        [0.5, 0.5, -0.1],
        [0.0, 0.5, -0.1],
    ];
    // Mid nodes shared per edge: the two triangles of an edge must agree, so both use
    // the same three mid nodes.
    let tris = vec![[0, 1, 2, 3, 4, 5], [0, 2, 1, 5, 4, 3]];
    let s = P2 {
        nodes: nodes[..6].to_vec(),
        tris,
    };
    assert_defect(
        &s,
        SurfaceDefect::SelfIntersection,
        &["triangle 0 ", "triangle 1 "],
    );
}

#[test]
fn curved_intersection_without_chord_intersection() {
    // Two tets 0.1 apart; a's bottom face bulges 0.2 down at the mid node of edge O-X.
    let a = unit_tet();
    let b = tet([
        [0.0, 0.0, -0.1],
        [1.0, 0.0, -0.1],
        [0.0, 1.0, -0.1],
        [0.0, 0.0, -1.1],
    ]);
    let mut s = a.union(&b);
    let m = (0..3).find_map(|k| {
        let t = s.tris[0];
        let (x, y) = (t[k], t[(k + 1) % 3]);
        ((x.min(y), x.max(y)) == (0, 1)).then_some(t[3 + k])
    });
    let m = m.unwrap() as usize;
    s.nodes[m] = [0.5, 0.0, -0.2];
    assert_defect(
        &s,
        SurfaceDefect::SelfIntersection,
        &["sub-triangles", "chord triangles do not"],
    );
    // The same bulge with a larger gap passes.
    let b2 = b.moved(|p| add(p, [0.0, 0.0, -0.2]));
    let mut s2 = a.union(&b2);
    s2.nodes[m] = [0.5, 0.0, -0.2];
    s2.check().unwrap();
}

// ---------------------------------------------------------------- orientation and nesting

#[test]
fn inside_out_is_flipped() {
    let orig = icosahedron();
    let surf = orig.flipped().check().unwrap();
    assert_eq!(surf.warnings(), &[FLIPPED_WARNING.to_string()]);
    assert_eq!(FLIPPED_WARNING, "orientation was inward; flipped");
    assert!(surf.volume() > 0.0 && surf.chord_volume() > 0.0);
    // Flipping the flipped triangles gives back the original ones, mid nodes included.
    assert_eq!(surf.triangles(), &orig.tris[..]);
    // Adjacency follows the flip.
    let ref_s = orig.check().unwrap();
    assert_eq!(surf.neighbors(), ref_s.neighbors());
    assert_eq!(surf.edges(), ref_s.edges());
}

#[test]
fn nested_shells_cavity() {
    // Outer outward, inner inward (a cavity): accepted. The ray from the inner shell's
    // first vertex (1, 0, 0) passes exactly through the outer vertex (2, 0, 0).
    let outer = octahedron(2.0);
    let inner = octahedron(1.0);
    let s = outer.union(&inner.flipped());
    let surf = s.check().unwrap();
    assert!(surf.warnings().is_empty());
    assert_eq!(surf.shell_count(), 2);
    let v = surf.chord_volume();
    assert!((v - (32.0 / 3.0 - 4.0 / 3.0)).abs() < 1e-12, "{v}");
    // Both the wrong way round: the whole surface is inside out, flipped.
    let surf = outer.flipped().union(&inner).check().unwrap();
    assert_eq!(surf.warnings(), &[FLIPPED_WARNING.to_string()]);
    assert!((surf.chord_volume() - v).abs() < 1e-12);
    // An island in the cavity: outward again.
    let island = octahedron(0.5);
    outer
        .union(&inner.flipped())
        .union(&island)
        .check()
        .unwrap();
    // Cavity facing out, like its container: inconsistent.
    let msg = assert_defect(
        &outer.union(&inner),
        SurfaceDefect::InconsistentOrientation,
        &[
            "shells disagree",
            "nesting depth 1) is outward but should be inward",
        ],
    );
    assert!(
        msg.contains("shell 1") && msg.contains("triangle 8 "),
        "{msg}"
    );
}

#[test]
fn separate_bodies() {
    let a = icosahedron();
    let b = icosahedron().moved(|p| add(p, [5.0, 0.5, 0.25]));
    let surf = a.union(&b).check().unwrap();
    assert_eq!(surf.shell_count(), 2);
    assert!(surf.warnings().is_empty());
    assert_defect(
        &a.union(&b.flipped()),
        SurfaceDefect::InconsistentOrientation,
        &["shell 0", "shell 1", "depth 0"],
    );
    // Both inward: flipped as a whole.
    let surf = a.flipped().union(&b.flipped()).check().unwrap();
    assert_eq!(surf.warnings().len(), 1);
}

// ---------------------------------------------------------------- repairs

/// The reorientation warning says how many triangles of how many shells were flipped.
fn assert_reoriented(surf: &Surface, flipped: usize, shells: usize) {
    let w = surf.warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    let want = format!(
        "flipped {flipped} of {} triangles in {shells} of {} shell(s)",
        surf.triangles().len(),
        surf.shell_count()
    );
    assert!(w[0].contains(&want), "{w:?} lacks {want:?}");
}

#[test]
fn one_flipped_triangle_is_reoriented() {
    let orig = octahedron(1.0);
    let mut s = orig.clone();
    let t = s.tris[6];
    s.tris[6] = [t[0], t[2], t[1], t[5], t[4], t[3]];
    let surf = s.check().unwrap();
    assert_eq!(surf.triangles(), &orig.tris[..]);
    assert_reoriented(&surf, 1, 1);
    // The same when the flipped triangle is the shell's first: the other 7 agree with
    // it at first, then the shell is found inward and flipped back as a whole.
    let mut s = orig.clone();
    let t = s.tris[0];
    s.tris[0] = [t[0], t[2], t[1], t[5], t[4], t[3]];
    let surf = s.check().unwrap();
    assert_eq!(surf.triangles(), &orig.tris[..]);
    assert_reoriented(&surf, 1, 1);
    let ref_s = orig.check().unwrap();
    assert_eq!(surf.neighbors(), ref_s.neighbors());
    assert_eq!(surf.edges(), ref_s.edges());
}

#[test]
fn random_flips_of_p2_triangles_are_undone() {
    use rand::{Rng, SeedableRng};
    let orig = icosahedron();
    let clean = orig.check().unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(28);
    for _ in 0..20 {
        let mut s = orig.clone();
        let mut n = 0;
        for t in &mut s.tris {
            if rng.random_range(0..3) == 0 {
                *t = [t[0], t[2], t[1], t[5], t[4], t[3]];
                n += 1;
            }
        }
        if n == 0 || n == s.tris.len() {
            continue;
        }
        let surf = s.check().unwrap();
        assert_eq!(surf.triangles(), &orig.tris[..]);
        assert_eq!(surf.edges(), clean.edges());
        assert_reoriented(&surf, n, 1);
        let (kind, msg) = s.defect();
        assert_eq!(kind, SurfaceDefect::InconsistentOrientation, "{msg}");
        assert!(msg.contains("same direction"), "{msg}");
    }
}

#[test]
fn cavity_facing_the_wrong_way_is_flipped() {
    let (outer, inner) = (octahedron(2.0), octahedron(1.0));
    let good = outer.union(&inner.flipped());
    let surf = outer.union(&inner).check().unwrap();
    assert_eq!(surf.triangles(), &good.tris[..]);
    assert_reoriented(&surf, 8, 1);
    let v = surf.chord_volume();
    assert!((v - (32.0 / 3.0 - 4.0 / 3.0)).abs() < 1e-12, "{v}");
    // Outer inward, cavity right (facing into the cavity, like an inward outer shell):
    // the outer one is flipped.
    let surf = outer.flipped().union(&inner.flipped()).check().unwrap();
    assert_eq!(surf.triangles(), &good.tris[..]);
    assert_reoriented(&surf, 8, 1);
    // One triangle of the cavity flipped as well: 7 of its 8 need flipping.
    let mut s = outer.union(&inner);
    let t = s.tris[9];
    s.tris[9] = [t[0], t[2], t[1], t[5], t[4], t[3]];
    let surf = s.check().unwrap();
    assert_eq!(surf.triangles(), &good.tris[..]);
    assert_reoriented(&surf, 7, 1);
    // An island in the cavity facing in: flipped outward.
    let island = octahedron(0.5);
    let surf = good.union(&island.flipped()).check().unwrap();
    assert_eq!(surf.triangles(), &good.union(&island).tris[..]);
    assert_reoriented(&surf, 8, 1);
}

#[test]
fn a_separate_body_facing_in_is_flipped() {
    let a = icosahedron();
    let b = icosahedron().moved(|p| add(p, [5.0, 0.5, 0.25]));
    let surf = a.union(&b.flipped()).check().unwrap();
    assert_eq!(surf.triangles(), &a.union(&b).tris[..]);
    assert_reoriented(&surf, 20, 1);
}

#[test]
fn unused_nodes_are_dropped() {
    let orig = octahedron(1.0);
    let mut s = orig.clone();
    // One unused node at the end, one at the front (all indices shift by one).
    s.nodes.push([5.0, 5.0, 5.0]);
    s.nodes.insert(0, [7.0, 0.0, 0.0]);
    for t in &mut s.tris {
        *t = t.map(|v| v + 1);
    }
    let surf = s.check().unwrap();
    assert_eq!(surf.nodes(), &orig.nodes[..]);
    assert_eq!(surf.triangles(), &orig.tris[..]);
    assert_eq!(
        surf.warnings(),
        &[
            "2 of 20 nodes used by no triangle: dropped, the others renumbered (`--strict` \
           refuses this)"
                .to_string()
        ]
    );
    // Strict: the old error, naming the first unused node.
    let (kind, msg) = s.defect();
    assert_eq!(kind, SurfaceDefect::UnusedNode);
    assert!(
        msg.contains("node 0 (7.0, 0.0, 0.0)") && msg.contains("2 unused"),
        "{msg}"
    );
    // An unused node's coordinates do not matter: dropped before they are checked.
    let mut nan = s.clone();
    nan.nodes[0] = [f64::NAN; 3];
    assert_eq!(nan.check().unwrap().nodes(), &orig.nodes[..]);
    // Both repairs at once: two warnings.
    let t = s.tris[3];
    s.tris[3] = [t[0], t[2], t[1], t[5], t[4], t[3]];
    let surf = s.check().unwrap();
    assert_eq!(surf.triangles(), &orig.tris[..]);
    assert_eq!(surf.warnings().len(), 2, "{:?}", surf.warnings());
    assert!(surf.warnings()[1].contains("flipped 1 of 8"));
}

#[test]
fn a_non_orientable_surface_stays_an_error() {
    // The 6-vertex projective plane (on vertices in general position): every edge used
    // twice, no consistent orientation. Refused as before, repair or not.
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.2],
        [0.3, 1.0, 0.1],
        [0.2, 0.4, 1.0],
        [1.1, 1.2, 0.3],
        [0.5, -0.7, 0.9],
    ];
    let s = P2::new(&v, &super::repair::tests::RP2, mid);
    let (kind, msg) = s.defect();
    assert_eq!(kind, SurfaceDefect::InconsistentOrientation, "{msg}");
    let e = s.check().expect_err("refused");
    assert_eq!(
        e.surface_defect(),
        Some(SurfaceDefect::InconsistentOrientation)
    );
    assert!(e.to_string().contains("same direction"), "{e}");
}

#[test]
fn errors_after_dropping_unused_nodes_say_the_numbers_changed() {
    let mut s = octahedron(1.0);
    s.nodes.insert(0, [7.0, 0.0, 0.0]);
    for t in &mut s.tris {
        *t = t.map(|v| v + 1);
    }
    s.tris.remove(3);
    let e = s.check().expect_err("open");
    assert_eq!(e.surface_defect(), Some(SurfaceDefect::NotClosed));
    let note = " (nodes numbered after dropping the 1 that no triangle uses; `--strict` keeps \
                the input's numbers)";
    assert!(e.to_string().ends_with(note), "{e}");
    assert_eq!(e.to_string().matches("numbered after").count(), 1, "{e}");
    // Strict: the unused node first, in the input's numbers.
    assert_eq!(s.defect().0, SurfaceDefect::UnusedNode);
    // Linear: the same, once.
    let tri3: Vec<[u32; 3]> = s.tris.iter().map(|t| [t[0], t[1], t[2]]).collect();
    let nodes = s.nodes.clone();
    let e = Surface::from_linear(nodes, tri3, vec![], 40.0).expect_err("open");
    assert_eq!(e.surface_defect(), Some(SurfaceDefect::NotClosed));
    assert!(
        e.to_string()
            .contains("vertices numbered after dropping the"),
        "{e}"
    );
    assert_eq!(e.to_string().matches("numbered after").count(), 1, "{e}");
}

#[test]
fn clean_surfaces_are_not_touched() {
    // Nothing to repair: the very triangles, no warning (strict or not).
    for s in [octahedron(1.0), icosahedron(), cube()] {
        let a = s.check().unwrap();
        let b = s.check_strict().unwrap();
        assert_eq!(a.triangles(), &s.tris[..]);
        assert_eq!(a.nodes(), &s.nodes[..]);
        assert_eq!(a.triangles(), b.triangles());
        assert!(a.warnings().is_empty() && b.warnings().is_empty());
    }
    // Inside out: flipped with the same warning as ever, strict or not.
    let s = icosahedron().flipped();
    for surf in [s.check().unwrap(), s.check_strict().unwrap()] {
        assert_eq!(surf.warnings(), &[FLIPPED_WARNING.to_string()]);
        assert_eq!(surf.triangles(), &icosahedron().tris[..]);
    }
}

#[test]
fn ray_crossing_sos() {
    use super::orientation::ray_crosses;
    let (a, b, c) = ([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0]);
    assert!(ray_crosses([0.0, 0.2, 0.2], a, b, c));
    assert!(!ray_crosses([2.0, 0.2, 0.2], a, b, c));
    assert!(!ray_crosses([0.0, 0.8, 0.8], a, b, c));
    // Through a vertex / an edge: a closed fan around the hit point counts exactly once.
    let apex = [1.0, 0.0, 0.0];
    let ring = [
        [1.5, 1.0, 0.0],
        [1.5, 0.0, 1.0],
        [1.5, -1.0, 0.0],
        [1.5, 0.0, -1.0],
    ];
    let hits = (0..4)
        .filter(|&k| ray_crosses([0.0, 0.0, 0.0], apex, ring[k], ring[(k + 1) % 4]))
        .count();
    assert_eq!(hits, 1);
    let hits = (0..4)
        .filter(|&k| ray_crosses([0.0, 0.0, 0.5], apex, ring[k], ring[(k + 1) % 4]))
        .count();
    assert_eq!(hits, 1);
}

// ---------------------------------------------------------------- robustness

/// Random mutations of valid surfaces (indices, coordinates, triangle order and count)
/// never panic: every input gives `Ok` or an error.
#[test]
fn random_mutations_never_panic() {
    use rand::{rngs::StdRng, Rng, SeedableRng};
    let mut rng = StdRng::seed_from_u64(11);
    let bases = [
        octahedron(1.0),
        icosahedron(),
        cube(),
        unit_tet().union(&tet([
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 0.0, 1.0],
        ])),
    ];
    let specials = [
        0.0,
        -0.0,
        1.0,
        0.5,
        1e-70,
        1e300,
        f64::NAN,
        f64::INFINITY,
        1e30,
        -1e30,
    ];
    let mut outcomes = [0usize; 2];
    for it in 0..3000 {
        let mut s = bases[it % bases.len()].clone();
        for _ in 0..rng.random_range(1..4) {
            let nn = s.nodes.len() as u32;
            match rng.random_range(0..8) {
                0 => {
                    let t = rng.random_range(0..s.tris.len());
                    let k = rng.random_range(0..6);
                    s.tris[t][k] = rng.random_range(0..nn + 2);
                }
                1 => {
                    let i = rng.random_range(0..s.nodes.len());
                    let d = rng.random_range(0..3);
                    s.nodes[i][d] = specials[rng.random_range(0..specials.len())];
                }
                2 => {
                    let i = rng.random_range(0..s.nodes.len());
                    let j = rng.random_range(0..s.nodes.len());
                    s.nodes[i] = s.nodes[j];
                }
                3 => {
                    let i = rng.random_range(0..s.nodes.len());
                    for d in 0..3 {
                        s.nodes[i][d] += rng.random_range(-0.6..0.6);
                    }
                }
                4 if s.tris.len() > 1 => {
                    let t = rng.random_range(0..s.tris.len());
                    s.tris.remove(t);
                }
                5 => {
                    let t = rng.random_range(0..s.tris.len());
                    let tri = s.tris[t];
                    s.tris.push(tri);
                }
                6 => {
                    let t = rng.random_range(0..s.tris.len());
                    let x = s.tris[t];
                    s.tris[t] = [x[0], x[2], x[1], x[5], x[4], x[3]];
                }
                _ => {
                    let t = rng.random_range(0..s.tris.len());
                    s.tris[t].swap(rng.random_range(0..6), rng.random_range(0..6));
                }
            }
        }
        let r = std::panic::catch_unwind(|| s.check().is_ok());
        match r {
            Ok(ok) => outcomes[ok as usize] += 1,
            Err(_) => panic!("panic on mutated surface {it}: {s:?}"),
        }
    }
    assert!(outcomes[0] > 100, "{outcomes:?}");
}
