//! Orientation of each shell, nesting of shells, and flipping an inside-out surface.
//!
//! Runs after the intersection checks, so the chord shells are embedded, pairwise
//! disjoint and (by the vertex rule) vertex-disjoint; within a shell the edge rule (or
//! the repair before it) has already made the orientation consistent.
//!
//! **Shell orientation**: the exact sign of the volume enclosed by the shell's chord
//! triangles, sum of det[a, b, c] over them, computed exactly (no tolerance) with a
//! fixed-point accumulator. Positive = outward (right-hand rule). The curved surface has
//! the same orientation, since the fold check makes curved and chord normals agree.
//!
//! **Nesting**: the depth of a shell is the number of other shells that contain it. As
//! shells are disjoint, one vertex decides: it is inside shell S when the ray from it
//! along +x crosses S an odd number of times. Crossings are decided exactly with
//! Simulation of Simplicity: the ray's start is perturbed symbolically to
//! (x, y + ε, z + ε²), so it never passes through an edge or vertex of S, and a triangle
//! is crossed when the perturbed (y, z) lies inside its (y, z) projection and its plane
//! lies ahead in +x (both exact orientation signs). Triangles parallel to the x axis are
//! never crossed by the perturbed ray.
//!
//! **Rule**: a shell at even depth must be outward, at odd depth inward (a cavity's shell
//! faces into the cavity, i.e. opposite to its container; an island inside a cavity is
//! outward again). If every shell is the other way round, the whole surface is inside
//! out: it is accepted and flipped, with the warning
//! [`FLIPPED_WARNING`](super::FLIPPED_WARNING). If only some are, the shells disagree:
//! the wrong ones are flipped with a warning ([`repair`](super::repair)), or under
//! [`Repair::Strict`](super::Repair::Strict) it is an
//! [`InconsistentOrientation`](SurfaceDefect::InconsistentOrientation) error naming one
//! shell of each kind.
//!
//! **Flip**: corners (c0, c1, c2) become (c0, c2, c1); the mid nodes follow their edges:
//! new edge (0,1) is old (2,0), new (1,2) is old (1,2), new (2,0) is old (0,1), so the
//! six nodes [c0, c1, c2, m01, m12, m20] become [c0, c2, c1, m20, m12, m01].

use super::describe;
use super::exact_sum::ExactSum;
use super::grid::{bbox, Aabb, Grid};
use super::topology::SurfaceEdge;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::predicates::orient3d;
use crate::geom::P3;

/// What the orientation check concluded about an acceptable surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Oriented outward as given.
    Outward,
    /// Consistently inside out: must be flipped.
    Inward,
}

/// Exact sign (-1, 0, +1) of the volume enclosed by the chord triangles `ts`.
pub fn chord_volume_sign(nodes: &[P3], tris: &[[u32; 6]], ts: &[u32]) -> i32 {
    let mut acc = ExactSum::new();
    for &t in ts {
        let tri = &tris[t as usize];
        acc.add_det3(
            nodes[tri[0] as usize],
            nodes[tri[1] as usize],
            nodes[tri[2] as usize],
        );
    }
    acc.sign()
}

#[inline]
fn yz(p: P3) -> robust::Coord<f64> {
    robust::Coord { x: p[1], y: p[2] }
}

/// Sign of orient2d((y, z) of p, u, w) with p perturbed to (y + ε, z + ε²): never 0 for
/// u != w in (y, z).
#[inline]
fn orient_yz_sos(p: P3, u: P3, w: P3) -> i32 {
    let v = robust::orient2d(yz(p), yz(u), yz(w));
    if v > 0.0 {
        return 1;
    }
    if v < 0.0 {
        return -1;
    }
    // d/dp_y of det[u - p, w - p] = u_z - w_z; d/dp_z = w_y - u_y (the det is affine in p).
    if u[2] != w[2] {
        return if u[2] > w[2] { 1 } else { -1 };
    }
    if w[1] != u[1] {
        return if w[1] > u[1] { 1 } else { -1 };
    }
    0
}

/// Does the symbolically perturbed ray from `p` along +x cross triangle (a, b, c)?
/// `p` must not lie on the triangle.
pub(crate) fn ray_crosses(p: P3, a: P3, b: P3, c: P3) -> bool {
    let s2 = {
        let v = robust::orient2d(yz(a), yz(b), yz(c));
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            return false;
        }
    };
    if orient_yz_sos(p, a, b) != s2 || orient_yz_sos(p, b, c) != s2 || orient_yz_sos(p, c, a) != s2
    {
        return false;
    }
    // The plane is ahead when p is on the side opposite to where +x leads: n_x has the
    // sign s2, and p + t e_x reaches the plane for t > 0 iff orient3d(a, b, c, p) = -s2.
    orient3d(a, b, c, p) * s2 < 0
}

/// Checks the orientation of every shell against its nesting depth (see module docs).
pub fn check_orientation(
    nodes: &[P3],
    tris: &[[u32; 6]],
    shell: &[u32],
    n_shells: usize,
) -> Result<Verdict> {
    match orient_shells(nodes, tris, shell, n_shells, false)? {
        Shells::Outward => Ok(Verdict::Outward),
        Shells::Inward => Ok(Verdict::Inward),
        // Not returned when the shells may not be repaired.
        Shells::Wrong(_) => Err(Error::InvalidArgument(
            "internal: shells to flip without repair".to_string(),
        )),
    }
}

/// What [`orient_shells`] concluded about an acceptable surface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Shells {
    /// Oriented outward as given.
    Outward,
    /// Consistently inside out: flip every triangle.
    Inward,
    /// Per shell, whether it faces the wrong way (some do, some do not): flip those.
    Wrong(Vec<bool>),
}

/// [`check_orientation`]; when the shells disagree, `repair` says which to flip
/// ([`Shells::Wrong`]) rather than refusing the surface.
pub(crate) fn orient_shells(
    nodes: &[P3],
    tris: &[[u32; 6]],
    shell: &[u32],
    n_shells: usize,
    repair: bool,
) -> Result<Shells> {
    // Triangles grouped by shell (counting sort), lowest triangle first in each group.
    let mut start = vec![0usize; n_shells + 1];
    for &s in shell {
        start[s as usize + 1] += 1;
    }
    for s in 0..n_shells {
        start[s + 1] += start[s];
    }
    let mut fill = start.clone();
    let mut by_shell = vec![0u32; tris.len()];
    for (t, &s) in shell.iter().enumerate() {
        by_shell[fill[s as usize]] = t as u32;
        fill[s as usize] += 1;
    }
    let group = |s: usize| &by_shell[start[s]..start[s + 1]];
    let first_tri = |s: usize| group(s)[0] as usize;

    let mut sign = vec![0i32; n_shells];
    for (s, sg) in sign.iter_mut().enumerate() {
        *sg = chord_volume_sign(nodes, tris, group(s));
        if *sg == 0 {
            let t = first_tri(s);
            return Err(Error::surface(
                SurfaceDefect::InconsistentOrientation,
                format!(
                    "the shell containing {} encloses exactly zero volume, so it has no \
                     orientation",
                    describe::tri(t, &tris[t])
                ),
            ));
        }
    }

    let depth = if n_shells == 1 {
        vec![0usize]
    } else {
        nesting_depths(nodes, tris, shell, n_shells, &first_tri)
    };
    let wrong: Vec<bool> = (0..n_shells)
        .map(|s| sign[s] != if depth[s] % 2 == 0 { 1 } else { -1 })
        .collect();
    if wrong.iter().all(|w| !w) {
        return Ok(Shells::Outward);
    }
    if wrong.iter().all(|w| *w) {
        return Ok(Shells::Inward);
    }
    if repair {
        return Ok(Shells::Wrong(wrong));
    }
    let describe_shell = |s: usize| {
        let t = first_tri(s);
        let dir = |sg: i32| if sg > 0 { "outward" } else { "inward" };
        let should = if wrong[s] {
            format!("but should be {}", dir(-sign[s]))
        } else {
            "as it should be".to_string()
        };
        format!(
            "shell {s} (the one containing {}; {} triangles; nesting depth {}) is {} {should}",
            describe::tri(t, &tris[t]),
            group(s).len(),
            depth[s],
            dir(sign[s])
        )
    };
    let good = (0..n_shells).find(|&s| !wrong[s]).unwrap_or(0);
    let bad = (0..n_shells).find(|&s| wrong[s]).unwrap_or(0);
    Err(Error::surface(
        SurfaceDefect::InconsistentOrientation,
        format!(
            "shells disagree: {}, while {} (a shell at even nesting depth faces out; a \
             shell inside another, a cavity, faces the other way from its container)",
            describe_shell(good),
            describe_shell(bad)
        ),
    ))
}

/// For each shell, how many other shells contain it (exact ray parity from one vertex).
fn nesting_depths(
    nodes: &[P3],
    tris: &[[u32; 6]],
    shell: &[u32],
    n_shells: usize,
    first_tri: &dyn Fn(usize) -> usize,
) -> Vec<usize> {
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|t| bbox([t[0], t[1], t[2]].map(|v| nodes[v as usize])))
        .collect();
    let grid = Grid::build(&boxes);
    let mut parity = vec![false; n_shells];
    let mut listed = vec![false; n_shells];
    let mut touched: Vec<u32> = Vec::new();
    let mut cand: Vec<u32> = Vec::new();
    let mut depth = vec![0usize; n_shells];
    for (s, d) in depth.iter_mut().enumerate() {
        let p = nodes[tris[first_tri(s)][0] as usize];
        grid.ray_x(&boxes, p, &mut cand);
        for &t in &cand {
            let other = shell[t as usize] as usize;
            if other == s {
                continue;
            }
            let tri = &tris[t as usize];
            let [a, b, c] = [0, 1, 2].map(|k| nodes[tri[k] as usize]);
            if ray_crosses(p, a, b, c) {
                if !listed[other] {
                    listed[other] = true;
                    touched.push(other as u32);
                }
                parity[other] = !parity[other];
            }
        }
        *d = touched.iter().filter(|&&o| parity[o as usize]).count();
        for &o in &touched {
            parity[o as usize] = false;
            listed[o as usize] = false;
        }
        touched.clear();
    }
    depth
}

/// Flips every triangle (see module docs) and keeps the adjacency and edges in step.
pub(crate) fn flip_all(
    tris: &mut [[u32; 6]],
    neighbors: &mut [[u32; 3]],
    edges: &mut [SurfaceEdge],
) {
    for t in tris.iter_mut() {
        *t = [t[0], t[2], t[1], t[5], t[4], t[3]];
    }
    for n in neighbors.iter_mut() {
        *n = [n[2], n[1], n[0]];
    }
    for e in edges.iter_mut() {
        e.tris.swap(0, 1);
    }
}

/// Flips the triangles of the shells marked in `wrong` (by shell id, `shell` per
/// triangle), keeping the adjacency and edges in step (an edge lies in one shell).
pub(crate) fn flip_shells(
    tris: &mut [[u32; 6]],
    neighbors: &mut [[u32; 3]],
    edges: &mut [SurfaceEdge],
    shell: &[u32],
    wrong: &[bool],
) {
    for (t, tri) in tris.iter_mut().enumerate() {
        if wrong[shell[t] as usize] {
            super::repair::flip(tri);
            let n = &mut neighbors[t];
            *n = [n[2], n[1], n[0]];
        }
    }
    for e in edges.iter_mut() {
        if wrong[shell[e.tris[0] as usize] as usize] {
            e.tris.swap(0, 1);
        }
    }
}
