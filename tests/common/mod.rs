//! Test-only helpers shared by the integration tests.
//!
//! `read_msh41` is a deliberately minimal Gmsh MSH 4.1 ASCII reader for 6-node triangles
//! (element type 9): enough to feed test files to `Surface::new`. It is not the product's
//! reader (that lives in `io`), and it trusts its input: malformed files panic.

#![allow(dead_code)]

use std::collections::HashMap;

/// Nodes, 0-based 6-node triangles and per-triangle entity tags.
pub struct Msh {
    pub nodes: Vec<[f64; 3]>,
    pub tris: Vec<[u32; 6]>,
    pub tags: Vec<i32>,
}

/// Reads a MSH 4.1 ASCII file with one or more `$Nodes` / type-9 `$Elements` blocks.
/// A node tag that no `$Nodes` block defines maps to index `u32::MAX`, so the surface
/// check reports it as out of range.
pub fn read_msh41(path: &std::path::Path) -> Msh {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let mut nodes = Vec::new();
    let mut index: HashMap<u64, u32> = HashMap::new();
    let mut tris = Vec::new();
    let mut tags = Vec::new();
    let num = |s: &str| -> f64 {
        s.parse::<f64>()
            .unwrap_or_else(|_| panic!("bad number {s:?}"))
    };
    while let Some(line) = lines.next() {
        match line.trim() {
            "$Nodes" => {
                let h: Vec<u64> = next_ints(&mut lines);
                for _ in 0..h[0] {
                    let b: Vec<u64> = next_ints(&mut lines);
                    let n = b[3] as usize;
                    let node_tags: Vec<u64> = (0..n).map(|_| next_ints(&mut lines)[0]).collect();
                    for t in node_tags {
                        let c: Vec<f64> =
                            lines.next().unwrap().split_whitespace().map(num).collect();
                        index.insert(t, nodes.len() as u32);
                        nodes.push([c[0], c[1], c[2]]);
                    }
                }
            }
            "$Elements" => {
                let h: Vec<u64> = next_ints(&mut lines);
                for _ in 0..h[0] {
                    let b: Vec<i64> = lines
                        .next()
                        .unwrap()
                        .split_whitespace()
                        .map(|s| s.parse().unwrap())
                        .collect();
                    assert_eq!(
                        b[2],
                        9,
                        "{}: only 6-node triangles (type 9)",
                        path.display()
                    );
                    for _ in 0..b[3] {
                        let e: Vec<u64> = next_ints(&mut lines);
                        let mut t = [0u32; 6];
                        for k in 0..6 {
                            t[k] = *index.get(&e[1 + k]).unwrap_or(&u32::MAX);
                        }
                        tris.push(t);
                        tags.push(b[1] as i32);
                    }
                }
            }
            _ => {}
        }
    }
    Msh { nodes, tris, tags }
}

fn next_ints<'a>(lines: &mut impl Iterator<Item = &'a str>) -> Vec<u64> {
    lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect()
}

/// The repository's `tests/data` folder.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// The shared benchmark data (`../shared/data` beside the repository), if present.
pub fn shared_data_dir() -> Option<std::path::PathBuf> {
    let d = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    d.join("README.md").exists().then_some(d)
}

/// A closed P2 icosphere of radius 1: `20 * 4^level` triangles, mid nodes on the sphere.
pub fn icosphere(level: u32) -> (Vec<[f64; 3]>, Vec<[u32; 6]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / n, p[1] / n, p[2] / n]
    };
    for p in v.iter_mut() {
        *p = unit(*p);
    }
    let midpoint = |v: &mut Vec<[f64; 3]>, cache: &mut HashMap<(u32, u32), u32>, a: u32, b: u32| {
        let key = (a.min(b), a.max(b));
        *cache.entry(key).or_insert_with(|| {
            let (p, q) = (v[a as usize], v[b as usize]);
            v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
            v.len() as u32 - 1
        })
    };
    for _ in 0..level {
        let mut cache = HashMap::new();
        let mut nf = Vec::with_capacity(4 * f.len());
        for t in &f {
            let a = midpoint(&mut v, &mut cache, t[0], t[1]);
            let b = midpoint(&mut v, &mut cache, t[1], t[2]);
            let c = midpoint(&mut v, &mut cache, t[2], t[0]);
            nf.extend([[t[0], a, c], [t[1], b, a], [t[2], c, b], [a, b, c]]);
        }
        f = nf;
    }
    let mut cache = HashMap::new();
    let mut tris = Vec::with_capacity(f.len());
    for t in &f {
        let a = midpoint(&mut v, &mut cache, t[0], t[1]);
        let b = midpoint(&mut v, &mut cache, t[1], t[2]);
        let c = midpoint(&mut v, &mut cache, t[2], t[0]);
        tris.push([t[0], t[1], t[2], a, b, c]);
    }
    (v, tris)
}
