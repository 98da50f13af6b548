//! Taubin smoothing of a checked linear surface's vertices (Taubin 1995: a shrinking
//! step λ = 0.5 towards the neighbours' mean, then an inflating step μ = −0.53 away from
//! it; a low-pass filter that, unlike plain Laplacian smoothing, barely shrinks the
//! volume). For surfaces extracted from images (marching cubes): their needle and cap
//! triangles (aspect ratios of 20-50, angles up to 170°) leave the advancing front
//! stuck, and ten iterations make them well shaped (aspect ratio at most 3 on the
//! marching-cubes spheres and blobs measured) while moving the surface by a fraction of
//! a voxel. It moves every vertex and rounds sharp edges: not for CAD surfaces.
//!
//! Hand-written: the umbrella operator over an edge list is a few lines, and the mesh
//! crates that have it would bring their own mesh types.

use crate::geom::vec3::P3;
use crate::surface::SurfaceEdge;

/// Shrinking factor of each iteration's first step.
const LAMBDA: f64 = 0.5;
/// Inflating factor of each iteration's second step (|μ| slightly above λ).
const MU: f64 = -0.53;

/// `iterations` Taubin iterations on the first `n` of `nodes` (the corners), with
/// neighbours from `edges` (uniform weights). Deterministic: sums run in edge order.
pub(crate) fn taubin(nodes: &mut [P3], n: usize, edges: &[SurfaceEdge], iterations: u32) {
    let mut sum = vec![[0.0f64; 3]; n];
    let mut cnt = vec![0u32; n];
    for e in edges {
        for v in e.nodes {
            cnt[v as usize] += 1;
        }
    }
    for _ in 0..iterations {
        for f in [LAMBDA, MU] {
            sum.iter_mut().for_each(|s| *s = [0.0; 3]);
            for e in edges {
                let [a, b] = e.nodes.map(|v| v as usize);
                for d in 0..3 {
                    sum[a][d] += nodes[b][d];
                    sum[b][d] += nodes[a][d];
                }
            }
            for v in 0..n {
                if cnt[v] == 0 {
                    continue;
                }
                let k = cnt[v] as f64;
                for d in 0..3 {
                    nodes[v][d] += f * (sum[v][d] / k - nodes[v][d]);
                }
            }
        }
    }
}
