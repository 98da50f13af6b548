//! Combinatorial checks over corner edges and vertex fans, and the adjacency they yield.
//!
//! **Edge rule.** Every undirected corner edge {a, b} is collected with the triangles that
//! use it (sorting, O(n log n)). With `k` uses:
//! - `k > 2` → [`NonManifoldEdge`](SurfaceDefect::NonManifoldEdge), whatever the directions;
//! - `k == 1` → [`NotClosed`](SurfaceDefect::NotClosed);
//! - `k == 2` in the same direction (a→b twice) →
//!   [`InconsistentOrientation`](SurfaceDefect::InconsistentOrientation): two sheets meet
//!   properly but one of them is flipped;
//! - `k == 2` in opposite directions: fine, provided both use the same mid node, else
//!   [`MidNodeMismatch`](SurfaceDefect::MidNodeMismatch).
//!
//! When several edges fail, the kinds are reported in the order above (the first edge in
//! sorted order within a kind), so a dangling fin is reported as non-manifold rather than
//! as open. Then mid nodes: a node that is a mid node must not also be a corner, nor the
//! mid node of two different edges ([`MidNodeMismatch`](SurfaceDefect::MidNodeMismatch)).
//!
//! **Vertex rule.** With the edges sound, the triangles around a corner vertex are walked
//! through shared edges (crossing the edge leaving the vertex in each triangle); they
//! must all be reached in one walk, else
//! [`NonManifoldVertex`](SurfaceDefect::NonManifoldVertex) (e.g. two bodies touching at a
//! vertex). As a consequence, distinct shells share no vertex.

use rayon::prelude::*;

use super::describe;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::P3;

/// A corner edge of the surface with its mid node and its two triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceEdge {
    /// The two corner nodes, smaller id first.
    pub nodes: [u32; 2],
    /// The mid-edge node both triangles share.
    pub mid: u32,
    /// The two triangles using the edge: `tris[0]` runs it from `nodes[0]` to
    /// `nodes[1]`, `tris[1]` the other way.
    pub tris: [u32; 2],
}

/// What the topology checks establish, for the later stages.
#[derive(Debug, Clone)]
pub(crate) struct Topology {
    pub corners: Vec<u32>,
    pub edges: Vec<SurfaceEdge>,
    pub neighbors: Vec<[u32; 3]>,
    pub shell: Vec<u32>,
    pub shell_count: usize,
}

const NONE: u32 = u32::MAX;

/// Every use of a corner edge by a triangle, as (a, b, triangle, local edge k) with
/// a < b, where the triangle's edge k runs from its corner k to corner k + 1; sorted, so
/// the uses of one edge are adjacent. Only the first three nodes of each triangle are
/// read (linear or 6-node triangles).
pub(crate) fn edge_uses<const N: usize>(tris: &[[u32; N]]) -> Vec<(u32, u32, u32, u8)> {
    let mut rec: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3u8 {
            let (a, b) = (tri[k as usize], tri[(k as usize + 1) % 3]);
            rec.push((a.min(b), a.max(b), t as u32, k));
        }
    }
    rec.par_sort_unstable();
    rec
}

impl Topology {
    /// Runs the edge, mid-node and vertex-fan checks and builds adjacency and shells.
    /// Indices must be in range and distinct within each triangle.
    pub fn build(nodes: &[P3], tris: &[[u32; 6]]) -> Result<Topology> {
        let rec = edge_uses(tris);

        let mut non_manifold: Option<String> = None;
        let mut open: Option<String> = None;
        let mut same_dir: Option<String> = None;
        let mut mid_mismatch: Option<String> = None;
        let mut edges: Vec<SurfaceEdge> = Vec::with_capacity(rec.len() / 2);
        let mut neighbors = vec![[NONE; 3]; tris.len()];
        let forward = |r: &(u32, u32, u32, u8)| tris[r.2 as usize][r.3 as usize] == r.0;
        let tri_list = |g: &[(u32, u32, u32, u8)]| {
            g.iter()
                .map(|r| {
                    let t = r.2 as usize;
                    let (x, y) = (tris[t][r.3 as usize], tris[t][(r.3 as usize + 1) % 3]);
                    format!("{} runs it {x}->{y}", describe::tri(t, &tris[t]))
                })
                .collect::<Vec<_>>()
                .join("; ")
        };

        let mut i = 0;
        while i < rec.len() {
            let mut j = i + 1;
            while j < rec.len() && rec[j].0 == rec[i].0 && rec[j].1 == rec[i].1 {
                j += 1;
            }
            let g = &rec[i..j];
            let (a, b) = (g[0].0, g[0].1);
            i = j;
            if g.len() > 2 {
                if non_manifold.is_none() {
                    non_manifold = Some(format!(
                        "{} is used by {} triangles (a manifold edge has exactly 2): {}",
                        describe::edge(a, b),
                        g.len(),
                        tri_list(g)
                    ));
                }
                continue;
            }
            if g.len() == 1 {
                if open.is_none() {
                    open = Some(format!(
                        "{} is used by one triangle only (the surface has a hole there): {}",
                        describe::edge(a, b),
                        tri_list(g)
                    ));
                }
                continue;
            }
            let (r0, r1) = (g[0], g[1]);
            if forward(&r0) == forward(&r1) {
                if same_dir.is_none() {
                    same_dir = Some(format!(
                        "{} is run in the same direction by both its triangles (one of them is \
                         flipped): {}",
                        describe::edge(a, b),
                        tri_list(g)
                    ));
                }
                continue;
            }
            let (t0, k0) = (r0.2 as usize, r0.3 as usize);
            let (t1, k1) = (r1.2 as usize, r1.3 as usize);
            let (m0, m1) = (tris[t0][3 + k0], tris[t1][3 + k1]);
            if m0 != m1 && mid_mismatch.is_none() {
                mid_mismatch = Some(format!(
                    "{}: {} gives it mid node {m0} but {} gives mid node {m1} (the two \
                     triangles of an edge must share its mid node)",
                    describe::edge(a, b),
                    describe::tri(t0, &tris[t0]),
                    describe::tri(t1, &tris[t1])
                ));
            }
            neighbors[t0][k0] = t1 as u32;
            neighbors[t1][k1] = t0 as u32;
            let (tf, tb) = if forward(&r0) { (t0, t1) } else { (t1, t0) };
            edges.push(SurfaceEdge {
                nodes: [a, b],
                mid: m0,
                tris: [tf as u32, tb as u32],
            });
        }
        for (kind, msg) in [
            (SurfaceDefect::NonManifoldEdge, non_manifold),
            (SurfaceDefect::NotClosed, open),
            (SurfaceDefect::InconsistentOrientation, same_dir),
            (SurfaceDefect::MidNodeMismatch, mid_mismatch),
        ] {
            if let Some(msg) = msg {
                return Err(Error::surface(kind, msg));
            }
        }

        let corners = check_mid_roles(nodes, tris, &edges)?;
        check_vertex_fans(nodes, tris, &neighbors)?;
        let (shell, shell_count) = shells(&neighbors);
        Ok(Topology {
            corners,
            edges,
            neighbors,
            shell,
            shell_count,
        })
    }
}

/// A mid node is not a corner and belongs to one edge only. Returns the sorted corners.
fn check_mid_roles(nodes: &[P3], tris: &[[u32; 6]], edges: &[SurfaceEdge]) -> Result<Vec<u32>> {
    // role: NONE = not seen, CORNER, or the edge index + 1 (< CORNER).
    const CORNER: u32 = u32::MAX - 1;
    let mut role = vec![NONE; nodes.len()];
    let mut corner_tri = vec![NONE; nodes.len()];
    for (t, tri) in tris.iter().enumerate() {
        for &v in &tri[..3] {
            role[v as usize] = CORNER;
            if corner_tri[v as usize] == NONE {
                corner_tri[v as usize] = t as u32;
            }
        }
    }
    for (ei, e) in edges.iter().enumerate() {
        let m = e.mid as usize;
        let t = e.tris[0] as usize;
        if role[m] == CORNER {
            let c = corner_tri[m] as usize;
            return Err(Error::surface(
                SurfaceDefect::MidNodeMismatch,
                format!(
                    "{} is the mid node of {} (in {}) but also a corner of {}",
                    describe::node(m, nodes),
                    describe::edge(e.nodes[0], e.nodes[1]),
                    describe::tri(t, &tris[t]),
                    describe::tri(c, &tris[c])
                ),
            ));
        }
        if role[m] != NONE {
            let other = edges[(role[m] - 1) as usize];
            return Err(Error::surface(
                SurfaceDefect::MidNodeMismatch,
                format!(
                    "{} is the mid node of two edges: {} and {}",
                    describe::node(m, nodes),
                    describe::edge(other.nodes[0], other.nodes[1]),
                    describe::edge(e.nodes[0], e.nodes[1])
                ),
            ));
        }
        role[m] = ei as u32 + 1;
    }
    Ok((0..nodes.len() as u32)
        .filter(|&v| role[v as usize] == CORNER)
        .collect())
}

/// The triangles around each corner vertex form one fan (a single cycle through edges).
fn check_vertex_fans(nodes: &[P3], tris: &[[u32; 6]], nbr: &[[u32; 3]]) -> Result<()> {
    let mut visited = vec![false; 3 * tris.len()];
    let mut first_fan = vec![NONE; nodes.len()];
    for t in 0..tris.len() {
        for i in 0..3 {
            if visited[3 * t + i] {
                continue;
            }
            let v = tris[t][i];
            let f = first_fan[v as usize];
            if f != NONE {
                return Err(Error::surface(
                    SurfaceDefect::NonManifoldVertex,
                    format!(
                        "{}: its triangles form more than one fan ({} and {} are not \
                         connected around it through edges; e.g. two bodies touching at a \
                         vertex)",
                        describe::node(v as usize, nodes),
                        describe::tri(f as usize, &tris[f as usize]),
                        describe::tri(t, &tris[t])
                    ),
                ));
            }
            first_fan[v as usize] = t as u32;
            // Walk the fan: cross the edge leaving v (local edge ci) into the neighbour.
            let (mut ct, mut ci) = (t, i);
            for _ in 0..visited.len() {
                visited[3 * ct + ci] = true;
                let nt = nbr[ct][ci];
                if nt == NONE {
                    break; // cannot happen once the edge rule passed
                }
                let nt = nt as usize;
                let Some(nj) = tris[nt][..3].iter().position(|&x| x == v) else {
                    break;
                };
                (ct, ci) = (nt, nj);
                if visited[3 * ct + ci] {
                    break;
                }
            }
        }
    }
    Ok(())
}

/// Connected components through edges, numbered in order of their lowest triangle.
fn shells(nbr: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut shell = vec![NONE; nbr.len()];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for s in 0..nbr.len() {
        if shell[s] != NONE {
            continue;
        }
        shell[s] = count;
        stack.push(s as u32);
        while let Some(t) = stack.pop() {
            for &n in &nbr[t as usize] {
                if n != NONE && shell[n as usize] == NONE {
                    shell[n as usize] = count;
                    stack.push(n);
                }
            }
        }
        count += 1;
    }
    (shell, count as usize)
}
