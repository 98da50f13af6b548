//! Independent checks of a generated mesh against its surface (shared by mesher tests).

use curvetet::geom::bezier::certify;
use curvetet::geom::predicates::orient3d;
use curvetet::geom::quadrature::{
    enclosed_volume, enclosed_volume_linear, tet10_volume, CompensatedSum,
};
use curvetet::mesh::report::tet_nodes;
use curvetet::{Surface, TetMesh};
use std::collections::HashMap;

/// Check `m` against `s` without trusting the mesher. Returns (linear, curved) volumes.
pub fn check_mesh(s: &Surface, m: &TetMesh) -> (f64, f64) {
    check_mesh_with_chords(s, m, false)
}

/// [`check_mesh`] for a surface curved from a linear one (`chords`): a mid node of the
/// surface may also be exactly its edge's chord midpoint (the mesher straightens a
/// boundary edge that cannot be certified curved; the input's own edge is straight).
/// The corners stay bit-identical, and the curved volume is then compared with the
/// volume the surface with those chords encloses.
pub fn check_mesh_with_chords(s: &Surface, m: &TetMesh, chords: bool) -> (f64, f64) {
    let p = |i: u32| m.nodes[i as usize];
    // Surface nodes kept with the same indices and bit-identical coordinates (or, with
    // `chords`, a mid node exactly on its chord).
    assert!(m.nodes.len() >= s.nodes().len());
    let mut chord_of: HashMap<u32, [u32; 2]> = HashMap::new();
    for t in s.triangles() {
        for (e, [i, j]) in curvetet::geom::shape::TRI6_EDGES.iter().enumerate() {
            chord_of.insert(t[3 + e], [t[*i], t[*j]]);
        }
    }
    let mut straight = 0;
    for (i, q) in s.nodes().iter().enumerate() {
        if m.nodes[i].map(f64::to_bits) == q.map(f64::to_bits) {
            continue;
        }
        let on_chord = chords
            && chord_of.get(&(i as u32)).is_some_and(|[a, b]| {
                let c = curvetet::geom::vec3::mid(s.nodes()[*a as usize], s.nodes()[*b as usize]);
                m.nodes[i].map(f64::to_bits) == c.map(f64::to_bits)
            });
        assert!(on_chord, "surface node {i} moved");
        straight += 1;
    }
    if straight > 0 {
        eprintln!("{straight} boundary edges straightened");
    }
    let meshed_nodes: Vec<_> = m.nodes[..s.nodes().len()].to_vec();
    // Every tet positive, exactly.
    for (ti, t) in m.tets.iter().enumerate() {
        assert!(
            orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > 0,
            "tet {ti} not positive"
        );
    }
    // Faces: each interior face twice with opposite orientation, boundary faces once.
    let out = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let mut faces: HashMap<[u32; 3], Vec<[u32; 3]>> = HashMap::new();
    for t in &m.tets {
        for f in &out {
            let v = [t[f[0]], t[f[1]], t[f[2]]];
            let mut k = v;
            k.sort_unstable();
            faces.entry(k).or_default().push(v);
        }
    }
    let rot = |a: [u32; 3]| [a, [a[1], a[2], a[0]], [a[2], a[0], a[1]]];
    let mut boundary: HashMap<[u32; 3], [u32; 3]> = HashMap::new();
    for (k, vs) in &faces {
        match vs.len() {
            1 => {
                boundary.insert(*k, vs[0]);
            }
            2 => {
                let rev = [vs[1][0], vs[1][2], vs[1][1]];
                assert!(
                    rot(vs[0]).contains(&rev),
                    "face {k:?}: two tets with the same orientation"
                );
            }
            n => panic!("face {k:?} in {n} tets"),
        }
    }
    // Boundary faces == input triangles (orientation and mid nodes included).
    assert_eq!(boundary.len(), s.triangles().len(), "boundary face count");
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &m.tets {
        for (e, [i, j]) in curvetet::geom::shape::TET10_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            let prev = *mids.entry((a.min(b), a.max(b))).or_insert(t[4 + e]);
            assert_eq!(prev, t[4 + e], "edge ({a},{b}) has two mid nodes");
        }
    }
    for (bi, tri) in s.triangles().iter().enumerate() {
        let mut k = [tri[0], tri[1], tri[2]];
        k.sort_unstable();
        let f = boundary
            .get(&k)
            .unwrap_or_else(|| panic!("input triangle {bi} not a boundary face"));
        assert!(
            rot(*f).contains(&[tri[0], tri[1], tri[2]]),
            "input triangle {bi} reversed"
        );
        for (e, [i, j]) in curvetet::geom::shape::TRI6_EDGES.iter().enumerate() {
            let (a, b) = (tri[*i], tri[*j]);
            assert_eq!(
                mids[&(a.min(b), a.max(b))],
                tri[3 + e],
                "triangle {bi}: mid node changed"
            );
        }
    }
    // Volumes.
    let vl: f64 = m
        .tets
        .iter()
        .map(|t| curvetet::geom::vec3::tet_det(p(t[0]), p(t[1]), p(t[2]), p(t[3])) / 6.0)
        .collect::<CompensatedSum>()
        .value();
    let el = enclosed_volume_linear(s.nodes(), s.triangles());
    assert!(
        (vl - el).abs() <= 1e-12 * el.abs(),
        "linear volume {vl} vs enclosed {el}"
    );
    let vc: f64 = (0..m.tets.len())
        .map(|t| tet10_volume(&tet_nodes(m, t)))
        .collect::<CompensatedSum>()
        .value();
    let ec = enclosed_volume(&meshed_nodes, s.triangles());
    assert!(
        (vc - ec).abs() <= 1e-9 * ec.abs(),
        "curved volume {vc} vs enclosed {ec}"
    );
    // Certified validity.
    let bad: Vec<usize> = (0..m.tets.len())
        .filter(|&t| !certify(&tet_nodes(m, t)).is_valid())
        .collect();
    assert!(
        bad.is_empty(),
        "{} tets not certified valid: {:?}",
        bad.len(),
        &bad[..bad.len().min(10)]
    );
    (vl, vc)
}
