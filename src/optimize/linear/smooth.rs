//! Optimization-based smoothing of one interior vertex: maximize the minimum quality of
//! its star (a non-smooth max-min problem) by the active-set method of Freitag and
//! Ollivier-Gooch: the search direction is the minimum-norm point of the convex hull of
//! the gradients of the (nearly) active quality pieces, followed by a backtracking line
//! search that accepts only a strict rise of the minimum with every tet still valid.
//! Boundary vertices are never moved.

use super::mesh::LinMesh;
use super::objective::skew_pieces;
use crate::geom::tet_quality::EQUIANGULAR_DIHEDRAL_DEG;
use crate::geom::vec3::{dist2, dot, norm, P3};
use rayon::prelude::*;

/// Tuning of the smoother.
#[derive(Clone, Copy, Debug)]
pub(super) struct SmoothParams {
    /// Most line searches per call.
    pub max_iter: usize,
    /// Pieces within this of the minimum are active.
    pub active_tol: f64,
    /// Halvings of the step before giving up.
    pub max_halvings: usize,
    /// The minimum must rise by more than this.
    pub eps: f64,
}

impl Default for SmoothParams {
    fn default() -> Self {
        SmoothParams {
            max_iter: 12,
            active_tol: 1e-3,
            max_halvings: 10,
            eps: 1e-9,
        }
    }
}

/// Halvings of the step the line search makes in the sliver passes (a millionth of the
/// first step).
const SLIVER_HALVINGS: usize = 20;

/// Scratch buffers of the smoother.
#[derive(Default)]
pub(super) struct SmoothScratch {
    /// The star of the vertex being smoothed or searched ([`load_star`]).
    star: Vec<StarTet>,
    grads: Vec<[f64; 3]>,
    qs: Vec<f64>,
    /// [`star_min`]'s hint into `star`.
    hint: usize,
}

/// A tet of the star of the vertex being smoothed, with its corner positions read once
/// per smoothing rather than at every trial point (the other corners do not move
/// meanwhile).
#[derive(Clone, Copy)]
struct StarTet {
    /// The tet.
    t: u32,
    /// Its corners.
    tv: [u32; 4],
    /// Their positions (the vertex's at `k` is replaced by the trial point).
    c: [P3; 4],
    /// The vertex's corner.
    k: usize,
}

impl StarTet {
    /// The corner positions with the vertex at `p`.
    #[inline]
    fn at(&self, p: P3) -> [P3; 4] {
        let mut c = self.c;
        c[self.k] = p;
        c
    }
}

/// Minimum-norm point of the convex hull of `g` (Gilbert's algorithm; few points).
fn min_norm_point(g: &[[f64; 3]]) -> [f64; 3] {
    let mut x = g[0];
    for _ in 0..64 {
        // The hull point minimizing x . g_j.
        let mut j = 0;
        let mut best = f64::INFINITY;
        for (i, gi) in g.iter().enumerate() {
            let v = dot(x, *gi);
            if v < best {
                best = v;
                j = i;
            }
        }
        let xx = dot(x, x);
        if xx - best <= 1e-12 * xx.max(1e-300) {
            break;
        }
        let d = [g[j][0] - x[0], g[j][1] - x[1], g[j][2] - x[2]];
        let dd = dot(d, d);
        if dd <= 0.0 {
            break;
        }
        let t = (-dot(x, d) / dd).clamp(0.0, 1.0);
        x = [x[0] + t * d[0], x[1] + t * d[1], x[2] + t * d[2]];
    }
    x
}

/// Minimum quality of the star of `v` with `v` at `p` (each tet's into `qs`); stops early
/// (returning a value <= `floor`) as soon as some tet is not above `floor`. The values in
/// `qs` are exact when the result is above `floor` (the only case they are used in).
/// A tet [`LinMesh::exempt`] from the minimum only may not get worse (−∞ when it does).
///
/// `hint`: the star index of the tet that stopped the last call early (`usize::MAX`:
/// none), tried first. Consecutive trial points of a search or a line search lie near
/// each other, and the tet that rejected one mostly rejects the next. Which tet stops a
/// call changes only the value below `floor`, never the result above it.
fn star_min(
    m: &LinMesh,
    star: &[StarTet],
    p: P3,
    floor: f64,
    qs: &mut Vec<f64>,
    hint: &mut usize,
) -> f64 {
    // The quality of star tet `i` at `p`: Err when it stops the call.
    let eval = |i: usize| -> Result<f64, f64> {
        let StarTet { t, tv, .. } = star[i];
        let c = star[i].at(p);
        if m.exempt(t) {
            let q = m.quality_at(tv, &c);
            return if q < m.q[t as usize] {
                Err(f64::NEG_INFINITY)
            } else {
                Ok(q)
            };
        }
        let q = m.quality_above(tv, &c, floor);
        if q <= floor {
            Err(q)
        } else {
            Ok(q)
        }
    };
    qs.clear();
    let first = if *hint < star.len() {
        match eval(*hint) {
            Err(q) => return q,
            Ok(q) => Some(q),
        }
    } else {
        None
    };
    let mut lo = f64::INFINITY;
    for (i, st) in star.iter().enumerate() {
        let q = match first {
            Some(q) if i == *hint => Ok(q),
            _ => eval(i),
        };
        match q {
            Ok(q) => {
                qs.push(q);
                if !m.exempt(st.t) {
                    lo = lo.min(q);
                }
            }
            Err(q) => {
                *hint = i;
                return q;
            }
        }
    }
    lo
}

/// Put the star of `v` into `s.star`, worst tet first (so that a failing trial position
/// is rejected after few evaluations); returns the shortest edge at `v` and the star's
/// minimum quality.
fn load_star(m: &LinMesh, v: u32, s: &mut SmoothScratch) -> (f64, f64) {
    s.hint = usize::MAX;
    s.star.clear();
    s.star.extend(m.vt[v as usize].iter().map(|&t| {
        let tv = m.tets[t as usize];
        StarTet {
            t,
            tv,
            c: tv.map(|x| m.pts[x as usize]),
            k: tv.iter().position(|&x| x == v).unwrap_or(0),
        }
    }));
    s.star.sort_by(|a, b| {
        m.q[a.t as usize]
            .total_cmp(&m.q[b.t as usize])
            .then(a.t.cmp(&b.t))
    });
    let p = m.pts[v as usize];
    // (sqrt is monotone and correctly rounded: the root of the least square is the least
    // distance.)
    let mut min_len2 = f64::INFINITY;
    for st in &s.star {
        for (i, &x) in st.c.iter().enumerate() {
            if i != st.k {
                min_len2 = min_len2.min(dist2(p, x));
            }
        }
    }
    let min_len = min_len2.sqrt();
    let qmin = s
        .star
        .iter()
        .filter(|st| !m.exempt(st.t))
        .map(|st| m.q[st.t as usize])
        .fold(f64::INFINITY, f64::min);
    (min_len, qmin)
}

/// Smooth interior vertex `v`; returns true when it moved.
pub(super) fn smooth_vertex(
    m: &mut LinMesh,
    v: u32,
    prm: &SmoothParams,
    s: &mut SmoothScratch,
) -> bool {
    if m.bnd.is_fixed(v) || m.vt[v as usize].is_empty() || !m.dirty[v as usize] {
        return false;
    }
    let (min_len, mut qmin) = load_star(m, v, s);
    let mut p = m.pts[v as usize];
    // Largest step: a third of the shortest edge at v.
    let max_move = min_len / 3.0;
    let mut last_step = max_move;
    let mut moved = false;
    // The sliver score of a nearly flat tet is tiny and steep: a piece counts as active
    // within a fraction of the minimum (an absolute tolerance would make pieces pulling
    // the other way active and stall the ascent), and the line search may shrink its
    // step to a millionth.
    let (halvings, rel_tol) = if m.sliver_mode() {
        (prm.max_halvings.max(SLIVER_HALVINGS), true)
    } else {
        (prm.max_halvings, false)
    };
    for _ in 0..prm.max_iter {
        let active_tol = if rel_tol {
            prm.active_tol.min(0.5 * qmin.max(0.0))
        } else {
            prm.active_tol
        };
        // Active pieces and their gradients.
        s.grads.clear();
        for st in &s.star {
            let StarTet { t, tv, k, .. } = *st;
            let qt = m.q[t as usize];
            if qt > qmin + active_tol || m.exempt(t) {
                // Far from active: only its first-order behaviour matters for the step.
                continue;
            }
            let c = st.at(p);
            if qt < 0.0 {
                // P2-invalid (curved) tet: finite-difference gradient of its score.
                let h = 1e-6 * min_len;
                let mut g = [0.0; 3];
                for (d, gd) in g.iter_mut().enumerate() {
                    let mut cp = c;
                    cp[k][d] += h;
                    let mut cm = c;
                    cm[k][d] -= h;
                    *gd = (m.quality_at(tv, &cp) - m.quality_at(tv, &cm)) / (2.0 * h);
                }
                s.grads.push(g);
                continue;
            }
            if m.sliver_mode() {
                // The sliver score: the smallest dihedral angle over the tet's floor, at
                // most 1 (the even pieces are θ/θe).
                let scale = EQUIANGULAR_DIHEDRAL_DEG / m.bnd.tet_sliver_floor(tv);
                for piece in skew_pieces(&c, k).iter().step_by(2) {
                    let v = piece.v * scale;
                    if v < 1.0 && v <= qmin + active_tol {
                        s.grads.push(piece.g.map(|x| x * scale));
                    }
                }
                continue;
            }
            for piece in skew_pieces(&c, k) {
                if piece.v <= qmin + active_tol {
                    s.grads.push(piece.g);
                }
            }
        }
        if s.grads.is_empty() {
            break;
        }
        let d = min_norm_point(&s.grads);
        let dn = norm(d);
        if !dn.is_finite() || dn <= 0.0 {
            break;
        }
        let mut alpha = (max_move / dn).min(2.0 * last_step / dn);
        let mut accepted = false;
        for _ in 0..halvings {
            let np = [
                p[0] + alpha * d[0],
                p[1] + alpha * d[1],
                p[2] + alpha * d[2],
            ];
            let nq = star_min(m, &s.star, np, qmin + prm.eps, &mut s.qs, &mut s.hint);
            if nq > qmin + prm.eps {
                last_step = alpha * dn;
                p = np;
                qmin = nq;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
        moved = true;
        place(m, v, p, s);
    }
    m.dirty[v as usize] = false;
    moved
}

/// Sampled search for a better position of interior vertex `v` when its worst tet is
/// stuck in a poor local optimum of [`smooth_vertex`] (max-min quality is not smooth and
/// ascent stops at a kink): shrinking rings of trial points around the best position so
/// far, the best kept only if its star's minimum quality rose. Deterministic (a fixed
/// low-discrepancy sequence); a ring's trials run on the threads of the rayon pool it is
/// called in, and the result does not depend on their number. Returns true when it
/// moved.
pub(super) fn search_vertex(m: &mut LinMesh, v: u32, s: &mut SmoothScratch) -> bool {
    if m.bnd.is_fixed(v) || m.vt[v as usize].is_empty() {
        return false;
    }
    let (min_len, q0) = load_star(m, v, s);
    let p0 = m.pts[v as usize];
    let (mut best, mut bq) = (p0, q0);
    let mut scale = min_len;
    let mut ring = Vec::with_capacity(PER_RING);
    for _ in 0..RINGS {
        let centre = best;
        // The ring's trials at once (on the pool's threads), each against the best
        // quality before the ring; then in order, each kept if it beats the best so far.
        // The same choice as trying them one by one against the best so far: a trial
        // above that is above the ring's floor too, so its minimum is exact either way.
        let floor = bq;
        let star = &s.star;
        (0..PER_RING)
            .into_par_iter()
            .with_min_len(PER_RING / 4)
            .map_init(
                || (Vec::new(), usize::MAX),
                |(qs, hint), i| star_min(m, star, ring_trial(centre, scale, i), floor, qs, hint),
            )
            .collect_into_vec(&mut ring);
        for (i, &q) in ring.iter().enumerate() {
            if q > bq {
                best = ring_trial(centre, scale, i);
                bq = q;
            }
        }
        scale *= 0.5;
    }
    if bq <= q0 + 1e-9 {
        return false;
    }
    star_min(m, &s.star, best, f64::NEG_INFINITY, &mut s.qs, &mut s.hint);
    place(m, v, best, s);
    true
}

/// Rings of trial points of [`search_vertex`], each half the radius of the one before.
const RINGS: usize = 10;

/// Trial points per ring of [`search_vertex`].
const PER_RING: usize = 96;

/// Trial point `i` of [`search_vertex`]'s ring of radius `scale` around `centre`:
/// directions from a spherical Fibonacci lattice, radii cycling through (0, 1] of it.
fn ring_trial(centre: P3, scale: f64, i: usize) -> P3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (2 * i + 1) as f64 / PER_RING as f64;
    let r = (1.0 - z * z).sqrt();
    let phi = golden * i as f64;
    let len = scale * [1.0, 0.66, 0.33][i % 3];
    [
        centre[0] + len * r * phi.cos(),
        centre[1] + len * r * phi.sin(),
        centre[2] + len * z,
    ]
}

/// Move `v` to `p`, with `s.qs` holding the qualities of its star (`s.star`) there.
fn place(m: &mut LinMesh, v: u32, p: P3, s: &SmoothScratch) {
    m.pts[v as usize] = p;
    m.touch_star(v);
    for (st, &q) in s.star.iter().zip(&s.qs) {
        m.q[st.t as usize] = q;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::optimize::linear::{mesh::LinMesh, ElementQuality};
    use crate::optimize::testmesh::CubeMesh;
    use crate::optimize::Boundary;

    /// The bulged 3 x 3 x 3 cube test mesh, its boundary, and its points with the
    /// interior ones moved at random by up to `amp` (seed `seed`).
    fn jittered_cube(seed: u64, amp: f64) -> (CubeMesh, Boundary, Vec<P3>) {
        let c = crate::optimize::testmesh::cube(3, 0.08);
        let bnd = c.boundary();
        let pts = crate::optimize::testmesh::jittered(&c, seed, amp);
        (c, bnd, pts)
    }

    /// A trial point above the floor gets its star's qualities as the mesh scores them
    /// and their minimum; whatever the hint, the same, bit for bit. Below the floor the
    /// call says so and leaves as hint the tet that stopped it, which stops the next call
    /// at once.
    #[test]
    fn the_hint_changes_which_tet_stops_a_trial_only() {
        use rand::{Rng, SeedableRng};
        let (c, bnd, pts) = jittered_cube(5, 0.1);
        let m = LinMesh::new(pts, c.tets.clone(), &bnd, ElementQuality);
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut s = SmoothScratch::default();
        let (mut above, mut below, mut first) = (0, 0, 0);
        for v in (0..m.pts.len() as u32).filter(|&v| !bnd.is_fixed(v)) {
            let (len, q0) = load_star(&m, v, &mut s);
            let star = s.star.clone();
            for _ in 0..200 {
                let p = m.pts[v as usize].map(|x| x + rng.random_range(-0.3..0.3) * len);
                let floor = q0 + rng.random_range(-0.2..0.05);
                let mut none = usize::MAX;
                let mut plain = Vec::new();
                let want = star_min(&m, &star, p, floor, &mut plain, &mut none);
                if want > floor {
                    // The star's qualities with `v` at `p`, from the mesh itself.
                    let direct: Vec<f64> = star
                        .iter()
                        .map(|st| {
                            let tv = m.tets[st.t as usize];
                            m.quality_at(
                                tv,
                                &tv.map(|x| if x == v { p } else { m.pts[x as usize] }),
                            )
                        })
                        .collect();
                    assert_eq!(plain, direct);
                    assert_eq!(want, direct.iter().copied().fold(f64::INFINITY, f64::min));
                }
                for hint in [
                    usize::MAX,
                    0,
                    star.len() - 1,
                    rng.random_range(0..star.len()),
                ] {
                    let (mut h, mut qs) = (hint, Vec::new());
                    let got = star_min(&m, &star, p, floor, &mut qs, &mut h);
                    assert_eq!(got > floor, want > floor);
                    if want > floor {
                        assert_eq!(got.to_bits(), want.to_bits());
                        assert_eq!(qs, plain);
                        assert_eq!(h, hint);
                        above += 1;
                    } else {
                        below += 1;
                        // The stopping tet is the hint now: the same trial stops at it.
                        let mut again = Vec::new();
                        let q = star_min(&m, &star, p, floor, &mut again, &mut h);
                        assert!(q <= floor && again.is_empty(), "{q} {again:?}");
                        first += usize::from(h != hint);
                    }
                }
            }
        }
        assert!(
            above > 100 && below > 100 && first > 10,
            "{above} {below} {first}"
        );
    }

    /// A search's parallel rings choose the point that trying every trial in turn
    /// against the best so far chooses, with one thread or several.
    #[test]
    fn a_search_chooses_as_one_trial_at_a_time() {
        let (c, bnd, pts) = jittered_cube(9, 0.2);
        let m = LinMesh::new(pts, c.tets.clone(), &bnd, ElementQuality);
        let pools = [1, 3].map(|n| crate::threads::pool(n, false).unwrap());
        let mut moved = 0;
        for v in (0..m.pts.len() as u32).filter(|&v| !bnd.is_fixed(v)) {
            // One trial at a time.
            let mut s = SmoothScratch::default();
            let (len, q0) = load_star(&m, v, &mut s);
            let (mut best, mut bq, mut scale) = (m.pts[v as usize], q0, len);
            for _ in 0..RINGS {
                let centre = best;
                for i in 0..PER_RING {
                    let p = ring_trial(centre, scale, i);
                    let q = star_min(&m, &s.star, p, bq, &mut s.qs, &mut s.hint);
                    if q > bq {
                        (best, bq) = (p, q);
                    }
                }
                scale *= 0.5;
            }
            let want = if bq > q0 + 1e-9 {
                best
            } else {
                m.pts[v as usize]
            };
            for pool in &pools {
                let mut mv = m.clone();
                let mut s = SmoothScratch::default();
                let did = pool.install(|| search_vertex(&mut mv, v, &mut s));
                assert_eq!(did, bq > q0 + 1e-9);
                assert_eq!(mv.pts[v as usize], want, "vertex {v}");
                moved += usize::from(did);
            }
        }
        assert!(moved >= 8, "{moved}");
    }

    #[test]
    fn min_norm_point_of_a_segment_and_a_triangle() {
        let x = min_norm_point(&[[1.0, 1.0, 0.0], [1.0, -1.0, 0.0]]);
        assert!((x[0] - 1.0).abs() < 1e-9 && x[1].abs() < 1e-9);
        let x = min_norm_point(&[[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0]]);
        assert!(norm(x) < 1e-6, "{x:?}");
    }
}
