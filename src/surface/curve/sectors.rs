//! Face normals, feature edges, and the smooth sectors of the vertex fans with their
//! normals.
//!
//! **Feature edge**: the angle between its two triangles' normals exceeds the feature
//! angle. (A metric decision, made on rounded normals; the topology never depends on it.)
//!
//! **Sectors**: the triangles around a vertex, split at the feature edges through it. A
//! *wedge* is one triangle's corner (triangle t, local corner i); the wedges of a vertex's
//! two triangles across a non-feature edge belong to the same sector (union-find over
//! wedges), so a vertex on a feature curve has one sector per side, a smooth vertex (or
//! one where a feature line ends) a single sector.
//!
//! **Sector normal**: a weighted mean of its triangles' normals, by default with Max's
//! weights (N. Max, "Weights for computing vertex normals from facet normals", 1999):
//! sum of (u x w) / (|u|^2 |w|^2) over the wedges with edge vectors u, w, exact for
//! vertices on a sphere however the fan is triangulated; or angle-weighted (Thürmer &
//! Wüthrich 1998). See [`NormalWeights`] for what each measured.
//!
//! **Planar sector**: every corner of its triangles lies exactly (orient3d == 0) in the
//! plane of its first triangle. Edges whose both end sectors are planar stay exactly
//! straight: flat regions stay flat.

use super::NormalWeights;
use crate::geom::predicates::orient3d;
use crate::geom::vec3::{cross, dot, norm, norm2, normalize, scale, sub};
use crate::geom::P3;
use crate::surface::topology::SurfaceEdge;

/// Per triangle, its unit normal (from the corners).
pub(crate) fn face_normals(nodes: &[P3], tris: &[[u32; 6]]) -> Vec<P3> {
    tris.iter()
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| nodes[t[k] as usize]);
            // Scale first so tiny or huge triangles neither underflow nor overflow.
            let s = [b, c]
                .iter()
                .flat_map(|p| (0..3).map(move |d| (p[d] - a[d]).abs()))
                .fold(0.0f64, f64::max);
            if s == 0.0 {
                return [0.0; 3];
            }
            let (u, v) = (scale(sub(b, a), 1.0 / s), scale(sub(c, a), 1.0 / s));
            normalize(cross(u, v))
        })
        .collect()
}

/// The sectors of all vertex fans.
pub(crate) struct Sectors {
    /// Per wedge (3 t + i), its sector id.
    pub of_wedge: Vec<u32>,
    /// Per sector, its unit normal.
    pub normal: Vec<P3>,
    /// Per sector, whether it is exactly planar.
    pub planar: Vec<bool>,
    /// Per edge, whether it is a feature edge.
    pub feature: Vec<bool>,
}

impl Sectors {
    /// The sector of vertex `v` in triangle `t`.
    pub fn at(&self, tris: &[[u32; 6]], t: u32, v: u32) -> u32 {
        let tri = &tris[t as usize];
        let i = (0..3).find(|&i| tri[i] == v).unwrap_or(0);
        self.of_wedge[3 * t as usize + i]
    }
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[parent[x as usize] as usize];
        parent[x as usize] = p;
        x = p;
    }
    x
}

/// Splits every fan into sectors (see module docs). `cos_feature` is the cosine of the
/// feature angle.
pub(crate) fn sectors(
    nodes: &[P3],
    tris: &[[u32; 6]],
    edges: &[SurfaceEdge],
    fnormal: &[P3],
    cos_feature: f64,
    weights: NormalWeights,
) -> Sectors {
    let feature: Vec<bool> = edges
        .iter()
        .map(|e| {
            let (n0, n1) = (fnormal[e.tris[0] as usize], fnormal[e.tris[1] as usize]);
            dot(n0, n1) < cos_feature
        })
        .collect();
    let wedge = |t: u32, v: u32| -> u32 {
        let tri = &tris[t as usize];
        3 * t + (0..3).find(|&i| tri[i] == v).unwrap_or(0) as u32
    };
    let mut parent: Vec<u32> = (0..3 * tris.len() as u32).collect();
    for (e, se) in edges.iter().enumerate() {
        if feature[e] {
            continue;
        }
        for &v in &se.nodes {
            let (a, b) = (
                find(&mut parent, wedge(se.tris[0], v)),
                find(&mut parent, wedge(se.tris[1], v)),
            );
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    // Number the sectors by their lowest wedge.
    let mut id = vec![u32::MAX; parent.len()];
    let mut of_wedge = vec![0u32; parent.len()];
    let mut count = 0u32;
    for w in 0..parent.len() as u32 {
        let r = find(&mut parent, w) as usize;
        if id[r] == u32::MAX {
            id[r] = count;
            count += 1;
        }
        of_wedge[w as usize] = id[r];
    }
    let mut sum = vec![[0.0f64; 3]; count as usize];
    let mut first_tri = vec![u32::MAX; count as usize];
    for (t, tri) in tris.iter().enumerate() {
        for i in 0..3 {
            let s = of_wedge[3 * t + i] as usize;
            let p = nodes[tri[i] as usize];
            let (u, w) = (
                sub(nodes[tri[(i + 1) % 3] as usize], p),
                sub(nodes[tri[(i + 2) % 3] as usize], p),
            );
            let (n, wgt) = match weights {
                // (u x w) / (|u|^2 |w|^2) = n sin(angle) / (|u| |w|).
                NormalWeights::Max => (cross(u, w), 1.0 / (norm2(u) * norm2(w))),
                NormalWeights::Angle => (fnormal[t], norm(cross(u, w)).atan2(dot(u, w))),
            };
            for d in 0..3 {
                sum[s][d] += wgt * n[d];
            }
            if first_tri[s] == u32::MAX {
                first_tri[s] = t as u32;
            }
        }
    }
    let normal: Vec<P3> = sum.into_iter().map(normalize).collect();
    let mut planar = vec![true; count as usize];
    for (t, tri) in tris.iter().enumerate() {
        for i in 0..3 {
            let s = of_wedge[3 * t + i] as usize;
            if !planar[s] {
                continue;
            }
            let r = &tris[first_tri[s] as usize];
            let [a, b, c] = [0, 1, 2].map(|k| nodes[r[k] as usize]);
            if (0..3).any(|k| orient3d(a, b, c, nodes[tri[k] as usize]) != 0) {
                planar[s] = false;
            }
        }
    }
    Sectors {
        of_wedge,
        normal,
        planar,
        feature,
    }
}
