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

/// A closed P2 icosphere of radius 1 (see `curvetet::surface::demo::icosphere`).
pub fn icosphere(level: u32) -> (Vec<[f64; 3]>, Vec<[u32; 6]>) {
    curvetet::surface::demo::icosphere(level)
}
