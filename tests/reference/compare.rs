//! Reading and comparing tetrahedral meshes made by curvetet, TetGen and CGAL.
//!
//! Deliberately independent of curvetet's own code (its readers, checker, quadrature and
//! quality measures): this module reads the files the three tools write (Gmsh MSH 4.1 ASCII,
//! TetGen .node/.ele/.face, medit .mesh, OFF) with its own parsers and checks them with its
//! own face hashing, exact orientation predicate (the `robust` crate, sign calibrated on a
//! known positive tet) and quadrature. Checks return `Err(message)` instead of panicking so
//! the test can print the whole side-by-side table before failing.

#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;

pub type P3 = [f64; 3];

/// A tetrahedral mesh as read from a file: corner indices per tet (0-based), the six
/// mid-edge nodes per tet for a quadratic mesh (Gmsh order: edges (0,1),(1,2),(2,0),(3,0),
/// (3,2),(3,1)), and the boundary triangles the file lists, if any (corners, then mids).
#[derive(Default)]
pub struct Mesh {
    pub nodes: Vec<P3>,
    pub tets: Vec<[usize; 4]>,
    pub mids: Vec<[usize; 6]>,
    pub file_tris: Vec<Vec<usize>>,
}

/// A closed triangle surface: corners, and the mid-edge nodes of (0,1),(1,2),(2,0) for a
/// quadratic one (empty for a linear one).
pub struct Surf {
    pub nodes: Vec<P3>,
    pub tris: Vec<[usize; 3]>,
    pub mids: Vec<[usize; 3]>,
}

fn read(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

fn tokens(text: &str) -> impl Iterator<Item = &str> {
    // '#' starts a comment in OFF, TetGen and medit files.
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(str::split_whitespace)
}

struct Toks<'a, I: Iterator<Item = &'a str>> {
    it: I,
    what: String,
}

impl<'a, I: Iterator<Item = &'a str>> Toks<'a, I> {
    fn word(&mut self) -> Result<&'a str, String> {
        self.it
            .next()
            .ok_or_else(|| format!("{}: unexpected end of file", self.what))
    }
    fn f(&mut self) -> Result<f64, String> {
        let w = self.word()?;
        w.parse()
            .map_err(|_| format!("{}: bad number {w:?}", self.what))
    }
    fn u(&mut self) -> Result<usize, String> {
        let w = self.word()?;
        w.parse()
            .map_err(|_| format!("{}: bad integer {w:?}", self.what))
    }
    fn p(&mut self) -> Result<P3, String> {
        Ok([self.f()?, self.f()?, self.f()?])
    }
}

fn toks<'a>(text: &'a str, path: &Path) -> Toks<'a, impl Iterator<Item = &'a str>> {
    Toks {
        it: tokens(text),
        what: path.display().to_string(),
    }
}

/// OFF triangle surface (0-based, optionally with comments).
pub fn read_off(path: &Path) -> Result<Surf, String> {
    let text = read(path)?;
    let mut t = toks(&text, path);
    if t.word()? != "OFF" {
        return Err(format!("{}: not OFF", path.display()));
    }
    let (nv, nf, _) = (t.u()?, t.u()?, t.u()?);
    let nodes = (0..nv).map(|_| t.p()).collect::<Result<Vec<_>, _>>()?;
    let mut tris = Vec::with_capacity(nf);
    for _ in 0..nf {
        if t.u()? != 3 {
            return Err(format!("{}: non-triangle face", path.display()));
        }
        tris.push([t.u()?, t.u()?, t.u()?]);
    }
    Ok(Surf {
        nodes,
        tris,
        mids: Vec::new(),
    })
}

/// Gmsh MSH 4.1 ASCII: every `$Nodes` block, and elements of types 2 (3-node triangle),
/// 9 (6-node triangle), 4 (4-node tet) and 11 (10-node tet); other element types are skipped.
pub fn read_msh41(path: &Path) -> Result<Mesh, String> {
    let text = read(path)?;
    let bad = |m: &str| format!("{}: {m}", path.display());
    let mut m = Mesh::default();
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut lines = text.lines();
    let ints = |l: Option<&str>| -> Result<Vec<usize>, String> {
        l.ok_or_else(|| bad("unexpected end of file"))?
            .split_whitespace()
            .map(|w| w.parse().map_err(|_| bad(&format!("bad integer {w:?}"))))
            .collect()
    };
    let mut raw_elems: Vec<(usize, Vec<usize>)> = Vec::new();
    while let Some(line) = lines.next() {
        match line.trim() {
            "$MeshFormat" => {
                let v = lines.next().unwrap_or("");
                if !v.starts_with("4.1 0") {
                    return Err(bad(&format!("not MSH 4.1 ASCII: {v:?}")));
                }
            }
            "$Nodes" => {
                let h = ints(lines.next())?;
                for _ in 0..h[0] {
                    let b = ints(lines.next())?;
                    let (parametric, n) = (b[2], b[3]);
                    let tags = (0..n)
                        .map(|_| ints(lines.next()).map(|v| v[0]))
                        .collect::<Result<Vec<_>, _>>()?;
                    for tag in tags {
                        let l = lines.next().ok_or_else(|| bad("short $Nodes"))?;
                        let c: Vec<f64> = l
                            .split_whitespace()
                            .map(|w| w.parse().map_err(|_| bad("bad coordinate")))
                            .collect::<Result<_, _>>()?;
                        if c.len() < 3 || (parametric == 0 && c.len() != 3) {
                            return Err(bad("bad node line"));
                        }
                        index.insert(tag, m.nodes.len());
                        m.nodes.push([c[0], c[1], c[2]]);
                    }
                }
            }
            "$Elements" => {
                let h = ints(lines.next())?;
                for _ in 0..h[0] {
                    let b = ints(lines.next())?;
                    let (ty, n) = (b[2], b[3]);
                    for _ in 0..n {
                        let v = ints(lines.next())?;
                        raw_elems.push((ty, v[1..].to_vec()));
                    }
                }
            }
            _ => {}
        }
    }
    for (ty, tags) in raw_elems {
        let v = tags
            .iter()
            .map(|t| {
                index
                    .get(t)
                    .copied()
                    .ok_or_else(|| bad(&format!("node {t}?")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        match (ty, v.len()) {
            (2, 3) | (9, 6) => m.file_tris.push(v),
            (4, 4) => m.tets.push([v[0], v[1], v[2], v[3]]),
            (11, 10) => {
                m.tets.push([v[0], v[1], v[2], v[3]]);
                m.mids.push([v[4], v[5], v[6], v[7], v[8], v[9]]);
            }
            (2 | 9 | 4 | 11, _) => return Err(bad("element with wrong node count")),
            _ => {}
        }
    }
    if !m.mids.is_empty() && m.mids.len() != m.tets.len() {
        return Err(bad("mixed linear and quadratic tets"));
    }
    Ok(m)
}

/// A P2 surface from MSH 4.1 (6-node triangles) as a `Surf`.
pub fn read_msh41_surface(path: &Path) -> Result<Surf, String> {
    let m = read_msh41(path)?;
    let mut s = Surf {
        nodes: m.nodes,
        tris: Vec::new(),
        mids: Vec::new(),
    };
    for t in m.file_tris {
        if t.len() != 6 {
            return Err(format!("{}: not a 6-node triangle", path.display()));
        }
        s.tris.push([t[0], t[1], t[2]]);
        s.mids.push([t[3], t[4], t[5]]);
    }
    Ok(s)
}

/// TetGen output `STEM.node`, `STEM.ele` and, when present, `STEM.face` (0- or 1-based,
/// as the .node file's first index says).
pub fn read_tetgen(stem: &Path) -> Result<Mesh, String> {
    let file = |ext: &str| {
        stem.with_file_name(format!(
            "{}.{ext}",
            stem.file_name().unwrap().to_string_lossy()
        ))
    };
    let node_path = file("node");
    let text = read(&node_path)?;
    let mut t = toks(&text, &node_path);
    let (n, dim, nattr, nmark) = (t.u()?, t.u()?, t.u()?, t.u()?);
    if dim != 3 {
        return Err(format!("{}: dimension {dim}", node_path.display()));
    }
    let mut m = Mesh::default();
    let mut base = 0;
    for i in 0..n {
        let id = t.u()?;
        if i == 0 {
            base = id;
        }
        if id != i + base {
            return Err(format!("{}: node ids not consecutive", node_path.display()));
        }
        m.nodes.push(t.p()?);
        for _ in 0..nattr + nmark {
            t.f()?;
        }
    }
    let idx = |v: usize| -> Result<usize, String> {
        v.checked_sub(base)
            .filter(|&i| i < n)
            .ok_or_else(|| format!("node index {v} out of range"))
    };
    let ele_path = file("ele");
    let text = read(&ele_path)?;
    let mut t = toks(&text, &ele_path);
    let (ne, npt, eattr) = (t.u()?, t.u()?, t.u()?);
    if npt != 4 {
        return Err(format!("{}: {npt} nodes per tet", ele_path.display()));
    }
    for _ in 0..ne {
        t.u()?;
        m.tets
            .push([idx(t.u()?)?, idx(t.u()?)?, idx(t.u()?)?, idx(t.u()?)?]);
        for _ in 0..eattr {
            t.f()?;
        }
    }
    let face_path = file("face");
    if face_path.exists() {
        let text = read(&face_path)?;
        let mut t = toks(&text, &face_path);
        let (nf, fmark) = (t.u()?, t.u()?);
        for _ in 0..nf {
            t.u()?;
            m.file_tris
                .push(vec![idx(t.u()?)?, idx(t.u()?)?, idx(t.u()?)?]);
            for _ in 0..fmark {
                t.f()?;
            }
        }
    }
    Ok(m)
}

/// medit `.mesh` (ASCII): Vertices, Triangles, Tetrahedra (1-based, with a reference each).
pub fn read_medit(path: &Path) -> Result<Mesh, String> {
    let text = read(path)?;
    let mut t = toks(&text, path);
    let mut m = Mesh::default();
    let mut tets1: Vec<[usize; 4]> = Vec::new();
    let mut tris1: Vec<Vec<usize>> = Vec::new();
    while let Ok(w) = t.word() {
        match w {
            "MeshVersionFormatted" | "Dimension" => {
                t.u()?;
            }
            "Vertices" => {
                for _ in 0..t.u()? {
                    m.nodes.push(t.p()?);
                    t.f()?;
                }
            }
            "Triangles" => {
                for _ in 0..t.u()? {
                    tris1.push(vec![t.u()?, t.u()?, t.u()?]);
                    t.f()?;
                }
            }
            "Tetrahedra" => {
                for _ in 0..t.u()? {
                    tets1.push([t.u()?, t.u()?, t.u()?, t.u()?]);
                    t.f()?;
                }
            }
            "End" => break,
            other => return Err(format!("{}: unsupported section {other}", path.display())),
        }
    }
    let n = m.nodes.len();
    let idx = |v: usize| {
        v.checked_sub(1)
            .filter(|&i| i < n)
            .ok_or_else(|| format!("{}: vertex {v} out of range", path.display()))
    };
    for tt in tets1 {
        m.tets
            .push([idx(tt[0])?, idx(tt[1])?, idx(tt[2])?, idx(tt[3])?]);
    }
    for tr in tris1 {
        m.file_tris
            .push(tr.iter().map(|&v| idx(v)).collect::<Result<_, _>>()?);
    }
    Ok(m)
}

// ---------------------------------------------------------------------------------------
// Geometry, independent of curvetet.

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn det3(a: P3, b: P3, c: P3) -> f64 {
    dot(a, cross(b, c))
}

/// Neumaier's compensated sum.
#[derive(Default, Clone, Copy)]
pub struct Sum {
    s: f64,
    c: f64,
}
impl Sum {
    pub fn add(&mut self, x: f64) {
        let t = self.s + x;
        if self.s.abs() >= x.abs() {
            self.c += (self.s - t) + x;
        } else {
            self.c += (x - t) + self.s;
        }
        self.s = t;
    }
    pub fn get(self) -> f64 {
        self.s + self.c
    }
}

/// Exact orientation: +1 when `d` is on the side of plane (a,b,c) that makes (a,b,c,d) a
/// right-handed (positive volume) tet, -1 on the other side, 0 when coplanar. The sign of
/// `robust::orient3d` is calibrated on the unit tet rather than assumed.
pub fn orientation(a: P3, b: P3, c: P3, d: P3) -> i32 {
    let c3 = |p: P3| robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    };
    let o = |a: P3, b: P3, c: P3, d: P3| robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    let unit = o([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let v = o(a, b, c, d);
    if v == 0.0 {
        0
    } else if (v > 0.0) == (unit > 0.0) {
        1
    } else {
        -1
    }
}

/// Volume enclosed by a linear surface (divergence theorem, compensated sum).
pub fn surface_volume_linear(s: &Surf) -> f64 {
    let mut v = Sum::default();
    for t in &s.tris {
        v.add(det3(s.nodes[t[0]], s.nodes[t[1]], s.nodes[t[2]]) / 6.0);
    }
    v.get()
}

/// 3-point Gauss-Legendre on [0,1].
const GL3: [(f64, f64); 3] = [
    (0.112_701_665_379_258_31, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// Volume enclosed by a P2 surface: (1/3)∮ x·n dA. The integrand x·(x_u × x_v) is a
/// degree-4 polynomial on the reference triangle; through the collapsed map
/// (u, v) = (a, b(1-a)) (Jacobian 1-a) it is of degree ≤ 5 in each of a, b, so the 3×3
/// Gauss product rule is exact.
pub fn surface_volume_p2(s: &Surf) -> f64 {
    let mut v = Sum::default();
    for (t, m) in s.tris.iter().zip(&s.mids) {
        let p = [
            s.nodes[t[0]],
            s.nodes[t[1]],
            s.nodes[t[2]],
            s.nodes[m[0]],
            s.nodes[m[1]],
            s.nodes[m[2]],
        ];
        for &(a, wa) in &GL3 {
            for &(b, wb) in &GL3 {
                let (u, w) = (a, b * (1.0 - a));
                let l = [1.0 - u - w, u, w];
                // dL/du, dL/dw
                let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
                let mut x = [0.0; 3];
                let mut xu = [0.0; 3];
                let mut xw = [0.0; 3];
                let mut acc = |q: P3, n: f64, du: f64, dw: f64| {
                    for k in 0..3 {
                        x[k] += n * q[k];
                        xu[k] += du * q[k];
                        xw[k] += dw * q[k];
                    }
                };
                for i in 0..3 {
                    let g = 4.0 * l[i] - 1.0;
                    acc(p[i], l[i] * (2.0 * l[i] - 1.0), g * dl[i][0], g * dl[i][1]);
                }
                for (e, (i, j)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                    acc(
                        p[3 + e],
                        4.0 * l[i] * l[j],
                        4.0 * (dl[i][0] * l[j] + l[i] * dl[j][0]),
                        4.0 * (dl[i][1] * l[j] + l[i] * dl[j][1]),
                    );
                }
                v.add(wa * wb * (1.0 - a) * dot(x, cross(xu, xw)) / 3.0);
            }
        }
    }
    v.get()
}

/// Jacobian determinant of a 10-node tet (Gmsh order) at reference point (x, y, z).
fn tet10_detj(p: &[P3; 10], x: f64, y: f64, z: f64) -> f64 {
    let l = [1.0 - x - y - z, x, y, z];
    let dl: [P3; 4] = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut j = [[0.0; 3]; 3]; // j[k] = dX/dξ_k
    let mut add = |q: P3, g: P3| {
        for k in 0..3 {
            for c in 0..3 {
                j[k][c] += g[k] * q[c];
            }
        }
    };
    for i in 0..4 {
        let f = 4.0 * l[i] - 1.0;
        add(p[i], [f * dl[i][0], f * dl[i][1], f * dl[i][2]]);
    }
    for (e, (a, b)) in [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)]
        .into_iter()
        .enumerate()
    {
        let g = [
            4.0 * (dl[a][0] * l[b] + l[a] * dl[b][0]),
            4.0 * (dl[a][1] * l[b] + l[a] * dl[b][1]),
            4.0 * (dl[a][2] * l[b] + l[a] * dl[b][2]),
        ];
        add(p[4 + e], g);
    }
    det3(j[0], j[1], j[2])
}

/// (∫ det J, min det J / max det J over the sample points) of a 10-node tet. det J is a
/// cubic; through the collapsed map (x, y, z) = (a, b(1-a), c(1-a)(1-b)) (Jacobian
/// (1-a)²(1-b)) it is of degree ≤ 5 in each variable, so the 3×3×3 Gauss rule is exact.
/// The ratio is sampled at those 27 points and the 10 nodes (a sample, not a certificate).
fn tet10_volume(p: &[P3; 10]) -> (f64, f64) {
    let mut v = 0.0;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(a, wa) in &GL3 {
        for &(b, wb) in &GL3 {
            for &(c, wc) in &GL3 {
                let (x, y, z) = (a, b * (1.0 - a), c * (1.0 - a) * (1.0 - b));
                let d = tet10_detj(p, x, y, z);
                v += wa * wb * wc * (1.0 - a) * (1.0 - a) * (1.0 - b) * d;
                lo = lo.min(d);
                hi = hi.max(d);
            }
        }
    }
    let nodes = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.5],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
    ];
    for q in nodes {
        let d = tet10_detj(p, q[0], q[1], q[2]);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    (v, lo / hi)
}

/// Sum of the straight-sided (corner) tets' signed volumes.
pub fn linear_volume(m: &Mesh) -> f64 {
    let mut v = Sum::default();
    for t in &m.tets {
        let p = t.map(|i| m.nodes[i]);
        v.add(det3(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])) / 6.0);
    }
    v.get()
}

/// Curved volume and the minimum sampled scaled Jacobian (min det J / max det J per tet)
/// of a quadratic mesh.
pub fn curved_volume(m: &Mesh) -> (f64, f64) {
    let mut v = Sum::default();
    let mut qmin = f64::INFINITY;
    for (t, e) in m.tets.iter().zip(&m.mids) {
        let p: [P3; 10] = std::array::from_fn(|k| m.nodes[if k < 4 { t[k] } else { e[k - 4] }]);
        let (vol, q) = tet10_volume(&p);
        v.add(vol);
        qmin = qmin.min(q);
    }
    (v.get(), qmin)
}

/// The six dihedral angles (degrees) of a straight tet.
pub fn dihedral_angles(p: [P3; 4]) -> [f64; 6] {
    let pairs = [
        (0, 1, 2, 3),
        (0, 2, 1, 3),
        (0, 3, 1, 2),
        (1, 2, 0, 3),
        (1, 3, 0, 2),
        (2, 3, 0, 1),
    ];
    pairs.map(|(a, b, c, d)| {
        let e = sub(p[b], p[a]);
        let n1 = cross(e, sub(p[c], p[a]));
        let n2 = cross(e, sub(p[d], p[a]));
        let cos = dot(n1, n2) / (dot(n1, n1) * dot(n2, n2)).sqrt();
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    })
}

/// Equiangular skewness (paper eq. 2) from the dihedral angles.
pub fn skewness(angles: &[f64; 6]) -> f64 {
    let te = (1.0f64 / 3.0).acos().to_degrees(); // 70.5288°
    let mx = angles.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mn = angles.iter().copied().fold(f64::INFINITY, f64::min);
    ((mx - te) / (180.0 - te)).max((te - mn) / te)
}

/// Quality of the straight-sided (corner) tets: min dihedral angle, max skewness, and the
/// fraction of tets with skewness > 0.9.
pub fn linear_quality(m: &Mesh) -> (f64, f64, f64) {
    let (mut mn, mut sk, mut bad) = (f64::INFINITY, 0.0f64, 0usize);
    for t in &m.tets {
        let a = dihedral_angles(t.map(|i| m.nodes[i]));
        mn = a.iter().copied().fold(mn, f64::min);
        let s = skewness(&a);
        sk = sk.max(s);
        bad += usize::from(s > 0.9);
    }
    (mn, sk, bad as f64 / m.tets.len().max(1) as f64)
}

// ---------------------------------------------------------------------------------------
// Conformity.

/// The outward-oriented faces of a positive tet (a,b,c,d): each face's normal by the
/// right-hand rule points away from the opposite vertex.
const FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];

fn rotations(f: [usize; 3]) -> [[usize; 3]; 3] {
    [f, [f[1], f[2], f[0]], [f[2], f[0], f[1]]]
}

/// What the conformity check found.
pub struct Conformity {
    /// Boundary faces (faces of exactly one tet), oriented outward.
    pub boundary: Vec<[usize; 3]>,
    pub interior_faces: usize,
    /// +1 when the tool's tets are right-handed, -1 when all are left-handed.
    pub orientation: i32,
}

/// Checks that no tet is degenerate or duplicated, that all tets have one orientation
/// (`+1` right-handed; `None` accepts either convention as long as it is the same for every
/// tet), and that every interior face is shared by exactly two tets, with opposite
/// orientations. For a quadratic mesh also that every edge has one mid node.
pub fn conformity(m: &Mesh, expect: Option<i32>) -> Result<Conformity, String> {
    if m.tets.is_empty() {
        return Err("no tets".into());
    }
    let mut sign = 0;
    for (i, t) in m.tets.iter().enumerate() {
        let s = orientation(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]);
        if s == 0 {
            return Err(format!("tet {i} {t:?} is flat (exactly)"));
        }
        if sign == 0 {
            sign = s;
            if let Some(e) = expect {
                if e != s {
                    return Err(format!("tet {i} inverted (orientation {s}, expected {e})"));
                }
            }
        } else if s != sign {
            return Err(format!("tet {i} {t:?} inverted relative to tet 0"));
        }
    }
    let mut seen: HashMap<[usize; 4], usize> = HashMap::with_capacity(m.tets.len());
    for (i, t) in m.tets.iter().enumerate() {
        let mut k = *t;
        k.sort_unstable();
        if let Some(j) = seen.insert(k, i) {
            return Err(format!("tets {j} and {i} are duplicates"));
        }
    }
    // Oriented faces as if every tet were right-handed.
    let mut faces: HashMap<[usize; 3], Vec<[usize; 3]>> = HashMap::with_capacity(2 * m.tets.len());
    for t in &m.tets {
        let t = if sign > 0 {
            *t
        } else {
            [t[0], t[2], t[1], t[3]]
        };
        for f in FACES {
            let v = [t[f[0]], t[f[1]], t[f[2]]];
            let mut k = v;
            k.sort_unstable();
            faces.entry(k).or_default().push(v);
        }
    }
    let mut boundary = Vec::new();
    let mut interior = 0;
    for (k, vs) in &faces {
        match vs.len() {
            1 => boundary.push(vs[0]),
            2 => {
                let r = [vs[1][0], vs[1][2], vs[1][1]];
                if !rotations(vs[0]).contains(&r) {
                    return Err(format!("face {k:?}: its two tets are on the same side"));
                }
                interior += 1;
            }
            n => return Err(format!("face {k:?} shared by {n} tets")),
        }
    }
    if !m.mids.is_empty() {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let edges = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
        for (t, e) in m.tets.iter().zip(&m.mids) {
            for (k, (a, b)) in edges.into_iter().enumerate() {
                let key = (t[a].min(t[b]), t[a].max(t[b]));
                let prev = *mid.entry(key).or_insert(e[k]);
                if prev != e[k] {
                    return Err(format!("edge {key:?} has two mid nodes"));
                }
            }
        }
    }
    boundary.sort_unstable();
    Ok(Conformity {
        boundary,
        interior_faces: interior,
        orientation: sign,
    })
}

type Key = [u64; 3];
fn key(p: P3) -> Key {
    p.map(f64::to_bits)
}

/// A triangle by the exact coordinates of its corners, rotated so that the smallest corner
/// comes first (orientation kept).
fn tri_key(c: [Key; 3]) -> [Key; 3] {
    let i = (0..3).min_by_key(|&i| c[i]).unwrap();
    [c[i], c[(i + 1) % 3], c[(i + 2) % 3]]
}

/// Checks that the mesh's boundary faces are exactly the surface's triangles, by exact
/// (bit-identical) corner coordinates and with the same orientation; for a P2 surface and a
/// quadratic mesh also each boundary edge's mid node, by exact coordinates. Returns how
/// many boundary faces were matched.
pub fn boundary_matches(m: &Mesh, c: &Conformity, s: &Surf) -> Result<usize, String> {
    if c.boundary.len() != s.tris.len() {
        return Err(format!(
            "{} boundary faces, the surface has {} triangles",
            c.boundary.len(),
            s.tris.len()
        ));
    }
    let mut want: HashMap<[Key; 3], usize> = HashMap::with_capacity(s.tris.len());
    for (i, t) in s.tris.iter().enumerate() {
        if want
            .insert(tri_key(t.map(|v| key(s.nodes[v]))), i)
            .is_some()
        {
            return Err(format!("surface triangle {i} is duplicated"));
        }
    }
    let mut edge_mid: HashMap<(usize, usize), usize> = HashMap::new();
    if !m.mids.is_empty() && !s.mids.is_empty() {
        let edges = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
        for (t, e) in m.tets.iter().zip(&m.mids) {
            for (k, (a, b)) in edges.into_iter().enumerate() {
                edge_mid.insert((t[a].min(t[b]), t[a].max(t[b])), e[k]);
            }
        }
    }
    for f in &c.boundary {
        let k = tri_key(f.map(|v| key(m.nodes[v])));
        let Some(&i) = want.get(&k) else {
            // Reversed, or not an input triangle at all?
            let r = tri_key([k[0], k[2], k[1]]);
            return Err(if want.contains_key(&r) {
                format!("boundary face {f:?} is an input triangle with reversed orientation")
            } else {
                format!(
                    "boundary face {f:?} ({:?}) is not an input triangle",
                    f.map(|v| m.nodes[v])
                )
            });
        };
        want.remove(&k);
        if !edge_mid.is_empty() {
            let t = s.tris[i];
            for (e, (a, b)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                // The mesh's vertices at the surface triangle's corners a and b.
                let find = |v: usize| {
                    f.iter()
                        .copied()
                        .find(|&w| key(m.nodes[w]) == key(s.nodes[t[v]]))
                        .unwrap()
                };
                let (x, y) = (find(a), find(b));
                let mid = edge_mid[&(x.min(y), x.max(y))];
                if key(m.nodes[mid]) != key(s.nodes[s.mids[i][e]]) {
                    return Err(format!(
                        "surface triangle {i} edge {e}: mid node {:?} in the mesh, {:?} in the input",
                        m.nodes[mid],
                        s.nodes[s.mids[i][e]]
                    ));
                }
            }
        }
    }
    Ok(s.tris.len())
}

/// Boundary faces the file itself lists (TetGen's .face, medit Triangles, msh triangles)
/// against the boundary the tets have, as unordered corner sets: `Ok` when they agree (or
/// the file lists none), else how many listed triangles are not tet boundary faces and how
/// many tet boundary faces are not listed.
pub fn file_boundary_consistent(m: &Mesh, c: &Conformity) -> Result<(), (usize, usize)> {
    if m.file_tris.is_empty() {
        return Ok(());
    }
    let sorted = |f: &[usize]| {
        let mut k = [f[0], f[1], f[2]];
        k.sort_unstable();
        k
    };
    let a: std::collections::HashSet<[usize; 3]> = c.boundary.iter().map(|f| sorted(f)).collect();
    let b: std::collections::HashSet<[usize; 3]> = m.file_tris.iter().map(|f| sorted(f)).collect();
    let extra = b.difference(&a).count() + (m.file_tris.len() - b.len());
    let missing = a.difference(&b).count();
    if extra == 0 && missing == 0 {
        Ok(())
    } else {
        Err((extra, missing))
    }
}

/// Surface area of a linear surface.
pub fn surface_area(s: &Surf) -> f64 {
    let mut a = Sum::default();
    for t in &s.tris {
        let n = cross(
            sub(s.nodes[t[1]], s.nodes[t[0]]),
            sub(s.nodes[t[2]], s.nodes[t[0]]),
        );
        a.add(0.5 * dot(n, n).sqrt());
    }
    a.get()
}

/// Mean edge length of a linear surface (each edge counted from both its triangles).
pub fn mean_edge(s: &Surf) -> f64 {
    let mut l = 0.0;
    for t in &s.tris {
        for k in 0..3 {
            let d = sub(s.nodes[t[(k + 1) % 3]], s.nodes[t[k]]);
            l += dot(d, d).sqrt();
        }
    }
    l / (3 * s.tris.len()) as f64
}

/// Checks that `lin` lists the same triangles as `p2` (same order, same corner order) with
/// corner coordinates equal up to `rel` relative (the data's .msh files carry 16
/// significant digits, the .off twins 17). Returns the largest relative difference seen.
pub fn twins_match(p2: &Surf, lin: &Surf, rel: f64) -> Result<f64, String> {
    if p2.tris.len() != lin.tris.len() {
        return Err(format!("{} vs {} triangles", p2.tris.len(), lin.tris.len()));
    }
    let mut worst = 0.0f64;
    for (i, (a, b)) in p2.tris.iter().zip(&lin.tris).enumerate() {
        for k in 0..3 {
            let (p, q) = (p2.nodes[a[k]], lin.nodes[b[k]]);
            for c in 0..3 {
                let d = (p[c] - q[c]).abs();
                let r = if d == 0.0 {
                    0.0
                } else {
                    d / p[c].abs().max(q[c].abs())
                };
                worst = worst.max(r);
                if r > rel {
                    return Err(format!("triangle {i} corner {k}: {p:?} vs {q:?}"));
                }
            }
        }
    }
    Ok(worst)
}
