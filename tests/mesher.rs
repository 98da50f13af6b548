//! The mesher on real surfaces, checked independently of the front: every tet positive
//! (exact), every interior face shared by two tets with opposite orientation, boundary
//! faces == input triangles with bit-identical nodes, linear volume == volume enclosed
//! by the linear surface (1e-12), curved volume == V_p2 of the data README (1e-9), every
//! tet certified valid.

use curvetet::geom::bezier::certify;
use curvetet::geom::predicates::orient3d;
use curvetet::geom::quadrature::{enclosed_volume, enclosed_volume_linear, tet10_volume, CompensatedSum};
use curvetet::mesh::quality::tet_nodes;
use curvetet::{generate, io, Options, SizeMode, Surface, TetMesh};
use std::collections::HashMap;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// V_p2 from ../shared/data/README.md (volume enclosed by the curved P2 surface).
const V_P2: [(&str, f64); 6] = [
    ("sphere", 4.188659268),
    ("torus", 2.417959847),
    ("tube", 4.71240098),
    ("lv", 3234.7592),
    ("screw", 3787.149008),
    ("hinge", 6336.122621),
];

/// Check `m` against `s` without trusting the mesher. Returns (linear, curved) volumes.
fn check_mesh(s: &Surface, m: &TetMesh) -> (f64, f64) {
    let p = |i: u32| m.nodes[i as usize];
    // Surface nodes kept with the same indices and bit-identical coordinates.
    assert!(m.nodes.len() >= s.nodes().len());
    for (i, q) in s.nodes().iter().enumerate() {
        assert_eq!(m.nodes[i].map(f64::to_bits), q.map(f64::to_bits), "surface node {i} moved");
    }
    // Every tet positive, exactly.
    for (ti, t) in m.tets.iter().enumerate() {
        assert!(orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > 0, "tet {ti} not positive");
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
                assert!(rot(vs[0]).contains(&rev), "face {k:?}: two tets with the same orientation");
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
        let f = boundary.get(&k).unwrap_or_else(|| panic!("input triangle {bi} not a boundary face"));
        assert!(rot(*f).contains(&[tri[0], tri[1], tri[2]]), "input triangle {bi} reversed");
        for (e, [i, j]) in curvetet::geom::shape::TRI6_EDGES.iter().enumerate() {
            let (a, b) = (tri[*i], tri[*j]);
            assert_eq!(mids[&(a.min(b), a.max(b))], tri[3 + e], "triangle {bi}: mid node changed");
        }
    }
    // Volumes.
    let vl: f64 = m.tets.iter().map(|t| curvetet::geom::vec3::tet_det(p(t[0]), p(t[1]), p(t[2]), p(t[3])) / 6.0).collect::<CompensatedSum>().value();
    let el = enclosed_volume_linear(s.nodes(), s.triangles());
    assert!((vl - el).abs() <= 1e-12 * el.abs(), "linear volume {vl} vs enclosed {el}");
    let vc: f64 = (0..m.tets.len()).map(|t| tet10_volume(&tet_nodes(m, t))).collect::<CompensatedSum>().value();
    let ec = enclosed_volume(s.nodes(), s.triangles());
    assert!((vc - ec).abs() <= 1e-9 * ec.abs(), "curved volume {vc} vs enclosed {ec}");
    // Certified validity.
    let bad: Vec<usize> = (0..m.tets.len()).filter(|&t| !certify(&tet_nodes(m, t)).is_valid()).collect();
    assert!(bad.is_empty(), "{} tets not certified valid: {:?}", bad.len(), &bad[..bad.len().min(10)]);
    (vl, vc)
}

fn mesh_and_check(name: &str, opts: &Options) -> usize {
    let s = io::read_surface(&data(&format!("{name}_p2.msh"))).expect("surface reads and passes the checks");
    let g = generate(&s, opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (_, vc) = check_mesh(&s, &g.mesh);
    let vp2 = V_P2.iter().find(|x| x.0 == name).unwrap().1;
    assert!((vc - vp2).abs() <= 1e-9 * vp2 + 5e-10 * vp2.max(1.0), "{name}: curved volume {vc} vs README V_p2 {vp2}");
    g.mesh.tets.len()
}

#[test]
fn sphere() {
    mesh_and_check("sphere", &Options::default());
}

#[test]
fn torus() {
    mesh_and_check("torus", &Options::default());
}

#[test]
fn tube() {
    mesh_and_check("tube", &Options::default());
}

#[test]
fn lv() {
    mesh_and_check("lv", &Options::default());
}

#[test]
fn screw() {
    mesh_and_check("screw", &Options::default());
}

#[test]
fn alphas_and_uniform_size() {
    for name in ["sphere", "torus"] {
        for alpha in [1.2, 1.5, 2.0, 2.5] {
            mesh_and_check(name, &Options { alpha, ..Options::default() });
        }
        mesh_and_check(name, &Options { size: SizeMode::Uniform, ..Options::default() });
    }
}

#[test]
fn bad_options_are_clear_errors() {
    let s = io::read_surface(&data("sphere_p2.msh")).unwrap();
    for o in [
        Options { alpha: 0.0, ..Options::default() },
        Options { alpha: -1.0, ..Options::default() },
        Options { alpha: f64::NAN, ..Options::default() },
        Options { size: SizeMode::Fixed(f64::NAN), ..Options::default() },
        Options { size: SizeMode::Fixed(0.0), ..Options::default() },
    ] {
        let e = generate(&s, &o).unwrap_err();
        assert!(matches!(e, curvetet::Error::InvalidArgument(_)), "{e}");
    }
}
