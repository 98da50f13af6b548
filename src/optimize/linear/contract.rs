//! Edge contraction: an interior vertex `r` is merged into a neighbour `k` (which may be
//! on the boundary; then `k` stays where it is, else `k` may move to `r`'s position or
//! the edge midpoint). The tets of the edge disappear. The link condition keeps the mesh
//! a manifold tiling; every new or moved tet must be positive (exact) and the minimum
//! quality of the touched tets must rise.

use super::mesh::LinMesh;
use crate::geom::tet_quality::positive_and_not_flat;
use crate::geom::vec3::{mid, P3};

/// Scratch buffers of the contraction.
#[derive(Default)]
pub(super) struct ContractScratch {
    link_r: Vec<[u32; 3]>,
    link_k: Vec<[u32; 3]>,
    edges_r: Vec<[u32; 2]>,
    edges_k: Vec<[u32; 2]>,
    verts_r: Vec<u32>,
    verts_k: Vec<u32>,
    ring_e: Vec<[u32; 2]>,
    ring_v: Vec<u32>,
    touched: Vec<u32>,
    new_tets: Vec<[u32; 4]>,
    /// The quality of each of `new_tets`.
    new_q: Vec<f64>,
}

fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

fn sorted2(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// Link of vertex `v`: the faces opposite it, their edges and vertices (sorted, unique).
fn link(m: &LinMesh, v: u32, f: &mut Vec<[u32; 3]>, e: &mut Vec<[u32; 2]>, p: &mut Vec<u32>) {
    f.clear();
    e.clear();
    p.clear();
    for &t in &m.vt[v as usize] {
        let tv = m.tets[t as usize];
        let mut o = [0u32; 3];
        let mut k = 0;
        for &x in &tv {
            if x != v {
                o[k] = x;
                k += 1;
            }
        }
        f.push(sorted3(o));
        e.push(sorted2(o[0], o[1]));
        e.push(sorted2(o[1], o[2]));
        e.push(sorted2(o[0], o[2]));
        p.extend_from_slice(&o);
    }
    f.sort_unstable();
    f.dedup();
    e.sort_unstable();
    e.dedup();
    p.sort_unstable();
    p.dedup();
}

/// Count of common elements of two sorted slices.
fn common<T: Ord>(a: &[T], b: &[T]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                n += 1;
                i += 1;
                j += 1;
            }
        }
    }
    n
}

/// Whether (r, k) is an edge that meets the link condition, Lk(r) ∩ Lk(k) = Lk(rk)
/// (triangles, edges, vertices): merging `r` into `k` then keeps the mesh a manifold
/// (whether every new tet is positive is for the caller to check).
fn linkable(m: &LinMesh, r: u32, k: u32, s: &mut ContractScratch) -> bool {
    link(m, r, &mut s.link_r, &mut s.edges_r, &mut s.verts_r);
    link(m, k, &mut s.link_k, &mut s.edges_k, &mut s.verts_k);
    s.ring_e.clear();
    s.ring_v.clear();
    for &t in &m.vt[r as usize] {
        let tv = m.tets[t as usize];
        if tv.contains(&k) {
            let mut o = [0u32; 2];
            let mut n = 0;
            for &x in &tv {
                if x != r && x != k {
                    o[n] = x;
                    n += 1;
                }
            }
            s.ring_e.push(sorted2(o[0], o[1]));
            s.ring_v.extend_from_slice(&o);
        }
    }
    if s.ring_e.is_empty() {
        return false; // not an edge
    }
    s.ring_e.sort_unstable();
    s.ring_e.dedup();
    s.ring_v.sort_unstable();
    s.ring_v.dedup();
    common(&s.link_r, &s.link_k) == 0
        && common(&s.edges_r, &s.edges_k) == s.ring_e.len()
        && common(&s.verts_r, &s.verts_k) == s.ring_v.len()
}

/// In the sliver passes: merge the interior vertex `r` into its neighbour `k`, which
/// stays where it is, where that leaves fewer unforced slivers ([`LinMesh::unforced`])
/// among the tets that change (the star of `r`; no other tet changes) and every new tet
/// scores above 0 (positive, and valid as a P2 element), or, with `chords` (a surface
/// curved from a linear one, whose curved boundary edges the straightening after the
/// high-order stage may put on their chords: [`super::LinearParams::chords`]), is a
/// positive straight tet that is not numerically flat. Returns true when applied.
pub(super) fn contract_fewer(
    m: &mut LinMesh,
    r: u32,
    k: u32,
    chords: bool,
    s: &mut ContractScratch,
) -> bool {
    if m.bnd.is_fixed(r) || !linkable(m, r, k, s) {
        return false;
    }
    // (A tet of the star that is not valid as a P2 element, which the sliver passes
    // otherwise leave alone, either goes with the edge (r, k) or must come out valid.)
    let star = &m.vt[r as usize];
    let before = star
        .iter()
        .filter(|&&t| m.unforced(m.tets[t as usize], m.q[t as usize]))
        .count();
    s.touched.clear();
    s.touched.extend_from_slice(star);
    s.new_tets.clear();
    s.new_q.clear();
    let mut after = 0;
    for &t in &s.touched {
        let tv = m.tets[t as usize];
        if tv.contains(&k) {
            continue;
        }
        let nv = tv.map(|x| if x == r { k } else { x });
        let q = m.quality(nv);
        after += usize::from(m.unforced(nv, q));
        let valid = q > 0.0 || (chords && positive_and_not_flat(&m.corners(nv)));
        if !valid || after >= before {
            return false;
        }
        s.new_tets.push(nv);
        s.new_q.push(q);
    }
    replace_touched(m, s);
    true
}

/// Replace the tets `s.touched` by `s.new_tets`, scored `s.new_q`.
fn replace_touched(m: &mut LinMesh, s: &ContractScratch) {
    for &t in &s.touched {
        m.remove(t);
    }
    for (&v, &q) in s.new_tets.iter().zip(&s.new_q) {
        m.add(v, q);
    }
}

/// Try contracting the edge (r, k), removing the interior vertex `r`. Returns true when
/// applied.
pub(super) fn contract(m: &mut LinMesh, r: u32, k: u32, eps: f64, s: &mut ContractScratch) -> bool {
    if m.bnd.is_fixed(r) || !linkable(m, r, k, s) {
        return false;
    }
    // Tets touched: star(r) ∪ star(k).
    s.touched.clear();
    s.touched.extend_from_slice(&m.vt[r as usize]);
    s.touched.extend_from_slice(&m.vt[k as usize]);
    s.touched.sort_unstable();
    s.touched.dedup();
    if s.touched.iter().any(|&t| m.exempt(t)) {
        return false;
    }
    let old = s
        .touched
        .iter()
        .map(|&t| m.q[t as usize])
        .fold(f64::INFINITY, f64::min);
    let (pr, pk) = (m.pts[r as usize], m.pts[k as usize]);
    let mut cands: [Option<P3>; 3] = [Some(pk), None, None];
    if !m.bnd.is_fixed(k) {
        cands[1] = Some(mid(pr, pk));
        cands[2] = Some(pr);
    }
    let mut best: Option<(f64, P3)> = None;
    for p in cands.into_iter().flatten() {
        // What a candidate must beat: the old minimum and the best candidate so far.
        let floor = best.map_or(old + eps, |b| b.0.max(old + eps));
        let mut worst = f64::INFINITY;
        for &t in &s.touched {
            let tv = m.tets[t as usize];
            if tv.contains(&r) && tv.contains(&k) {
                continue;
            }
            let nv = tv.map(|x| if x == r { k } else { x });
            let c = nv.map(|x| if x == k { p } else { m.pts[x as usize] });
            worst = worst.min(m.quality_above(nv, &c, floor));
            if worst <= floor {
                break;
            }
        }
        if worst > floor {
            best = Some((worst, p));
        }
    }
    let Some((_, p)) = best else {
        return false;
    };
    m.pts[k as usize] = p;
    s.new_tets.clear();
    s.new_q.clear();
    for &t in &s.touched {
        let tv = m.tets[t as usize];
        if !(tv.contains(&r) && tv.contains(&k)) {
            let nv = tv.map(|x| if x == r { k } else { x });
            s.new_tets.push(nv);
            s.new_q.push(m.quality(nv));
        }
    }
    replace_touched(m, s);
    true
}
