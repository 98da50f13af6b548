//! Conformity and volume checks of a P2 tet mesh, independent of how it was made:
//! positive corners (exact), every interior face shared by exactly two tets with opposite
//! orientations, boundary faces exactly the given boundary triangles (same orientation),
//! one mid node per edge, and the linear volume equal to the volume the linear boundary
//! encloses.

use super::TetMesh;
use crate::geom::predicates::orient3d;
use crate::geom::quadrature::CompensatedSum;
use crate::geom::shape::{TET10_EDGES, TRI6_EDGES};
use crate::geom::vec3::{det3, sub, tet_det};
use crate::{Error, Result};

fn compensated_sum(xs: impl Iterator<Item = f64>) -> f64 {
    xs.collect::<CompensatedSum>().value()
}
use std::collections::HashMap;

/// Figures from a passed conformity check.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Conformity {
    /// Number of tets.
    pub tets: usize,
    /// Faces shared by two tets.
    pub interior_faces: usize,
    /// Faces of one tet (== boundary triangles).
    pub boundary_faces: usize,
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

/// Check conformity; the error names the first offending elements.
pub fn check_conformity(m: &TetMesh) -> Result<Conformity> {
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
    // Faces: outward orientation of positive tet (v0, v1, v2, v3).
    const OUT: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let mut faces: HashMap<[u32; 3], (u32, [u32; 3], u32)> =
        HashMap::with_capacity(m.tets.len() * 3);
    for (ti, t) in m.tets.iter().enumerate() {
        for f in &OUT {
            let v = [t[f[0]], t[f[1]], t[f[2]]];
            let mut k = v;
            k.sort_unstable();
            let e = faces.entry(k).or_insert((0, v, ti as u32));
            e.0 += 1;
            if e.0 == 2 && same_orientation(e.1, v) {
                return Err(bad(
                    vec![e.2 as usize, ti],
                    format!(
                        "tets {} and {ti} overlap: they share face {:?} with the same orientation",
                        e.2, k
                    ),
                ));
            }
            if e.0 > 2 {
                return Err(bad(
                    vec![ti],
                    format!("face {k:?} is shared by more than two tets (tet {ti})"),
                ));
            }
        }
    }
    let mut interior = 0;
    let mut boundary: HashMap<[u32; 3], [u32; 3]> = HashMap::new();
    for (k, (c, v, _)) in &faces {
        if *c == 2 {
            interior += 1;
        } else {
            boundary.insert(*k, *v);
        }
    }
    if boundary.len() != m.boundary.len() {
        return Err(bad(
            vec![],
            format!(
                "the tets have {} faces of one tet, the boundary has {} triangles",
                boundary.len(),
                m.boundary.len()
            ),
        ));
    }
    for (bi, b) in m.boundary.iter().enumerate() {
        let v = [b[0], b[1], b[2]];
        let mut k = v;
        k.sort_unstable();
        match boundary.get(&k) {
            Some(w) if same_orientation(*w, v) => {}
            Some(_) => {
                return Err(bad(
                    vec![],
                    format!("boundary triangle {bi} {v:?} is reversed in the mesh"),
                ))
            }
            None => {
                return Err(bad(
                    vec![],
                    format!("boundary triangle {bi} {v:?} is not a face of one tet"),
                ))
            }
        }
    }
    // One mid node per edge, the boundary's on boundary edges.
    let mut mids: HashMap<(u32, u32), u32> = HashMap::with_capacity(m.tets.len() * 2);
    for (ti, t) in m.tets.iter().enumerate() {
        for (e, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            let mnode = t[4 + e];
            let prev = *mids.entry((a.min(b), a.max(b))).or_insert(mnode);
            if prev != mnode {
                return Err(bad(
                    vec![ti],
                    format!("edge ({a}, {b}) has two mid nodes ({prev} and {mnode}); tet {ti}"),
                ));
            }
        }
    }
    for (bi, b) in m.boundary.iter().enumerate() {
        for (e, [i, j]) in TRI6_EDGES.iter().enumerate() {
            let (a, c) = (b[*i], b[*j]);
            if mids.get(&(a.min(c), a.max(c))) != Some(&b[3 + e]) {
                return Err(bad(
                    vec![],
                    format!(
                        "boundary triangle {bi}: its mid node on edge ({a}, {c}) is not the tets'"
                    ),
                ));
            }
        }
    }
    let volume_linear = compensated_sum(
        m.tets
            .iter()
            .map(|t| tet_det(p(t[0]), p(t[1]), p(t[2]), p(t[3])) / 6.0),
    );
    // Divergence theorem about a node of the mesh (not the origin) to keep precision.
    let o = m.boundary.first().map(|b| p(b[0])).unwrap_or([0.0; 3]);
    let enclosed_linear = compensated_sum(
        m.boundary
            .iter()
            .map(|b| det3(sub(p(b[0]), o), sub(p(b[1]), o), sub(p(b[2]), o)) / 6.0),
    );
    Ok(Conformity {
        tets: m.tets.len(),
        interior_faces: interior,
        boundary_faces: boundary.len(),
        volume_linear,
        enclosed_linear,
    })
}

fn same_orientation(a: [u32; 3], b: [u32; 3]) -> bool {
    b == a || b == [a[1], a[2], a[0]] || b == [a[2], a[0], a[1]]
}
