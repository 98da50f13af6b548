//! The whole region at once, for a surface no front attempt closes: interior points from
//! the size field, then the constrained fill ([`crate::geom::cdt_fill`]) of the surface's
//! triangles with those points. The boundary is kept exactly (added points are strictly
//! inside), and the linear and high-order stages improve the tets like the front's.
//!
//! The points are the centres and corners of a graded octree's leaves: a body-centred
//! cubic lattice wherever the size is uniform, whose Delaunay tets are all alike and well
//! shaped. A leaf is at most [`LEAF_PER_SIZE`] times the size at its centre; points
//! nearer the surface than [`CLEARANCE`] times the size are dropped (the surface's own
//! vertices are there), as are points inside a surface edge's diametral ball or a
//! triangle's equatorial ball: there they would keep the edge or triangle out of the
//! Delaunay tetrahedralization and cost Steiner points on the surface (on CAD parts' long
//! edges, hundreds). Points outside the surface (exact ray parity) are left out too;
//! the fill is tried with them only where it fails without them.
//!
//! The fill places Steiner points at segment crossings; where that fails, or its first
//! round of moving them off the surface leaves many on it ([`Patience`]), it is run again
//! halving the segments ([`Split`]); where every such try fails, a last one recovers the
//! missing segments by recursive flips first ([`Split::FlipsThenHalving`]).

use super::grid::{Aabb, FaceGrid};
use super::size::SizeField;
use super::{FillTry, FrontOutput, FrontStats};
use crate::geom::cdt_fill::{self, Patience, Split};
use crate::geom::distance::point_triangle_dist2;
use crate::geom::vec3::{axpy, cross, dist, dist2, dot, mid, scale, sub, P3};
use rustc_hash::FxHashSet as HashSet;

/// Largest leaf side, as a multiple of the size at its centre. The lattice's edges are
/// the side and 0.87 of it, and leaves are between half and all of this.
const LEAF_PER_SIZE: f64 = 1.3;

/// Interior points at least this many sizes from the surface.
const CLEARANCE: f64 = 0.6;

/// Octree depth limit (integer corner coordinates fit in 32 bits).
const MAX_DEPTH: u32 = 24;

/// Most interior candidate points (a size field far below the part's extent).
const MAX_POINTS: usize = 20_000_000;

/// Tetrahedralize the region bounded by the P2 surface's corner triangles, with interior
/// points spaced by `size`. Err says why the fill could not go on.
pub(crate) fn whole_fill(
    surf_nodes: &[P3],
    surf_tris: &[[u32; 6]],
    size: &SizeField,
) -> Result<FrontOutput, String> {
    whole_fill_trying(surf_nodes, surf_tris, size, INSIDE_TRIES)
}

/// The tries of [`whole_fill`] with the points inside, in order. On the OpenSCAD corpus
/// the try with no flat tets first left 63 unforced slivers where the try at crossings
/// first left 77 (example005 15 -> 9, example020 37 -> 29, no part more), and it fills
/// what both others fail on (a CSG bracket, 12-segment aniso tori).
const INSIDE_TRIES: &[Split] = &[Split::NoFlatTets, Split::AtCrossing, Split::Halving];

/// [`whole_fill`] with the tries `inside` with the points inside (the tests of the
/// linear stage's passes keep the fill they were measured on).
fn whole_fill_trying(
    surf_nodes: &[P3],
    surf_tris: &[[u32; 6]],
    size: &SizeField,
    inside: &[Split],
) -> Result<FrontOutput, String> {
    let clock = std::time::Instant::now();
    let FillInput {
        corners,
        pts,
        mut interior,
        faces,
    } = fill_input(surf_nodes, surf_tris, size, false)?;
    // (On the first try's report.)
    let mut placed = clock.elapsed().as_secs_f64();
    let n_corners = pts.len();
    // Thin tets on the surface get a point above it, at most a size high.
    let height = |p: P3| size.at(p);
    // Steiner points at crossings first (with the points inside: after flips in planes,
    // and no numerically flat tet in the recovery; then without those); halving where
    // crossings pile up. With the points inside first; where that fails, with those
    // outside too (they change the Delaunay tetrahedralization the recovery starts from,
    // and with it where its Steiner points fall; their tets are dropped).
    let mut why = Vec::new();
    let mut filled = None;
    let mut tries = Vec::new();
    // Last, with the points inside: recursive flips before halving (slow: only where
    // every other way fails).
    let ways: [(bool, &[Split]); 3] = [
        (false, inside),
        (true, &[Split::AtCrossing, Split::Halving]),
        (false, &[Split::FlipsThenHalving]),
    ];
    'fills: for (with_outside, splits) in ways {
        if with_outside {
            // The candidates again, those outside kept too (the first try's have only
            // those inside: clearing the others, most of the octree's, took most of
            // the points' time).
            let clock = std::time::Instant::now();
            let local = |v: u32| local_index(&corners, v);
            interior = interior_points(&pts, surf_tris, &local, size, true)?;
            placed += clock.elapsed().as_secs_f64();
        }
        let mut all = pts.clone();
        all.extend(
            interior
                .iter()
                .filter(|&&(_, inside)| inside || with_outside)
                .map(|&(p, _)| p),
        );
        // Both tries start from the same Delaunay tetrahedralization, built once (the
        // first try's time has it).
        let clock = std::time::Instant::now();
        let dt = cdt_fill::delaunay(&all);
        let mut built = clock.elapsed().as_secs_f64();
        for &split in splits {
            // Halving follows a try at crossings, so that one may give up early.
            // The last try has no other way after it.
            let patience = match split {
                Split::AtCrossing | Split::NoFlatTets => Patience::GiveUpEarly,
                Split::Halving if with_outside => Patience::LastResort,
                Split::Halving => Patience::Exhaustive,
                Split::FlipsThenHalving => Patience::LastResort,
            };
            let mut stages = cdt_fill::Stages {
                delaunay: std::mem::take(&mut built),
                ..cdt_fill::Stages::default()
            };
            let r = cdt_fill::fill_from(
                dt.clone(),
                &faces,
                split,
                Some(&height),
                patience,
                &mut stages,
            );
            // Where recovery stopped, for the user to look at.
            let r = r.map_err(|e| match stages.stuck_near {
                Some(p) => format!("{e}, near ({:.6}, {:.6}, {:.6})", p[0], p[1], p[2]),
                None => e.to_string(),
            });
            tries.push(FillTry {
                steiner_at: match split {
                    Split::AtCrossing => "crossings",
                    Split::Halving => "halves",
                    Split::NoFlatTets => "no flat tets",
                    Split::FlipsThenHalving => "recursive flips, then halves",
                },
                points_outside: with_outside,
                error: r.as_ref().err().cloned(),
                delaunay_seconds: stages.delaunay,
                edges_seconds: stages.edges,
                faces_seconds: stages.faces,
                steiner_removal_seconds: stages.steiner_removal,
                steiner_points: stages.steiner_points,
                flipped_segments: stages.flipped_segments,
                points_seconds: std::mem::take(&mut placed),
                finish_seconds: stages.finish,
            });
            match r {
                Ok(f) => {
                    filled = Some(f);
                    break 'fills;
                }
                Err(e) => why.push(format!(
                    "{e} ({split:?}{})",
                    if with_outside {
                        ", points outside too"
                    } else {
                        ""
                    }
                )),
            }
        }
    }
    let filled = filled.ok_or_else(|| why.join("; "))?;
    // Global ids: corners keep theirs; used interior and Steiner points follow the
    // surface nodes in order of first use.
    let mut out_pts = surf_nodes.to_vec();
    let mut new_id = vec![u32::MAX; filled.pts.len()];
    let mut tets = Vec::with_capacity(filled.tets.len());
    for t in &filled.tets {
        tets.push(t.map(|v| {
            let v = v as usize;
            if v < n_corners {
                corners[v]
            } else {
                if new_id[v] == u32::MAX {
                    new_id[v] = out_pts.len() as u32;
                    out_pts.push(filled.pts[v]);
                }
                new_id[v]
            }
        }));
    }
    let quality = vec![f64::NAN; tets.len()];
    Ok(FrontOutput {
        pts: out_pts,
        tets,
        quality,
        stats: FrontStats {
            whole_fill: true,
            whole_fill_tries: tries,
            ..FrontStats::default()
        },
    })
}

/// What the fill is given: the surface's corners and the interior candidates.
struct FillInput {
    /// The corner nodes' global ids, sorted: local vertex `i` is `corners[i]`.
    corners: Vec<u32>,
    /// The corners' points, in local numbering.
    pts: Vec<P3>,
    /// The interior candidates, each with whether the surface encloses it (those it
    /// does not only when asked: see [`interior_points`]).
    interior: Vec<(P3, bool)>,
    /// The corner triangles in local numbering, reversed: the fill wants the region on
    /// each face's positive side.
    faces: Vec<[u32; 3]>,
}

/// The local number of global node `v` among the sorted `corners` (`u32::MAX` if it is
/// not one).
fn local_index(corners: &[u32], v: u32) -> u32 {
    corners.binary_search(&v).map_or(u32::MAX, |i| i as u32)
}

fn fill_input(
    surf_nodes: &[P3],
    surf_tris: &[[u32; 6]],
    size: &SizeField,
    outside: bool,
) -> Result<FillInput, String> {
    let mut corners: Vec<u32> = surf_tris.iter().flat_map(|t| [t[0], t[1], t[2]]).collect();
    corners.sort_unstable();
    corners.dedup();
    let local = |v: u32| local_index(&corners, v);
    let pts: Vec<P3> = corners.iter().map(|&c| surf_nodes[c as usize]).collect();
    let interior = interior_points(&pts, surf_tris, &local, size, outside)?;
    let faces: Vec<[u32; 3]> = surf_tris
        .iter()
        .map(|t| [local(t[0]), local(t[2]), local(t[1])])
        .collect();
    Ok(FillInput {
        corners,
        pts,
        interior,
        faces,
    })
}

/// Octree leaf centres and corners in the surface's box, at least [`CLEARANCE`] sizes
/// from every triangle, in depth-first (Morton) order, so that consecutive points are
/// near each other for the Delaunay insertion's walk; each with whether the surface
/// encloses it. Those it does not enclose only when `outside` asks: the octree covers
/// the surface's box, and on thin CAD parts nearly all its points are outside.
fn interior_points(
    corner_pts: &[P3],
    surf_tris: &[[u32; 6]],
    local: &dyn Fn(u32) -> u32,
    size: &SizeField,
    outside: bool,
) -> Result<Vec<(P3, bool)>, String> {
    let bounds = Aabb::of(corner_pts);
    let ext = (0..3)
        .map(|d| bounds.hi[d] - bounds.lo[d])
        .fold(0.0, f64::max);
    if ext.is_nan() || ext <= 0.0 {
        return Err("the surface has no extent".into());
    }
    // The corner triangles' points, looked up once: the clearance test below reads
    // them for every candidate point near a triangle.
    let tris: Vec<[P3; 3]> = surf_tris
        .iter()
        .map(|t| [0, 1, 2].map(|k| corner_pts[local(t[k]) as usize]))
        .collect();
    // The grid's cell: twice the mean edge (one edge per triangle), as the front's.
    let mut mean_edge = 0.0;
    for p in &tris {
        mean_edge += crate::geom::vec3::dist(p[0], p[1]);
    }
    mean_edge /= surf_tris.len().max(1) as f64;
    let mut grid = FaceGrid::new(bounds, 2.0 * mean_edge, (16 * surf_tris.len()).max(1 << 16));
    let balls: Vec<Vec<(P3, f64)>> = tris.iter().map(|&t| protecting_balls(t)).collect();
    // Each triangle's box with its balls: what the grid files it under, and the filter
    // of what a cell's list gives (a needle's balls span many cells).
    let boxes: Vec<Aabb> = tris
        .iter()
        .zip(&balls)
        .map(|(t, balls)| {
            let mut b = Aabb::of(t);
            for &(c, r2) in balls {
                let r = r2.sqrt();
                b.lo = std::array::from_fn(|d| b.lo[d].min(c[d] - r));
                b.hi = std::array::from_fn(|d| b.hi[d].max(c[d] + r));
            }
            b
        })
        .collect();
    for (i, b) in boxes.iter().enumerate() {
        grid.insert(i as u32, b);
    }
    // Integer coordinates in units of the root side / 2^(MAX_DEPTH + 1): every leaf's
    // corners and centre are whole, so shared points are found exactly.
    let unit = ext / f64::from(1u32 << (MAX_DEPTH + 1));
    let at = |c: [u64; 3]| -> P3 { [0, 1, 2].map(|d| bounds.lo[d] + c[d] as f64 * unit) };
    let mut seen: HashSet<[u64; 3]> = HashSet::default();
    // Each candidate with what is known of the size there: the size itself (a leaf's
    // centre, measured to split or keep the leaf), or a lower bound of the distance to
    // the nearest surface vertex, from which the size field may answer without a
    // search (the same value, bit for bit: [`SizeField::at_near`]).
    let mut cand: Vec<(P3, Result<f64, f64>)> = Vec::new();
    // A lower bound of the distance from `q` to the nearest surface vertex, given one,
    // `bound`, at `p` (the triangle inequality, with a margin for rounding).
    let less =
        |bound: f64, p: P3, q: P3| ((bound - dist(p, q) * (1.0 + 1e-12)) * (1.0 - 1e-9)).max(0.0);
    // (min corner, depth, distance floor at the centre); children pushed in reverse
    // Morton order, so popped in order.
    let mut stack: Vec<([u64; 3], u32, f64)> = vec![([0; 3], 0, 0.0)];
    while let Some((lo, depth, floor)) = stack.pop() {
        let half = 1u64 << (MAX_DEPTH - depth);
        let side = ext / f64::from(1u32 << depth);
        let centre = lo.map(|c| c + half);
        let pc = at(centre);
        let (h, bound) = size.at_near(pc, floor);
        if side > LEAF_PER_SIZE * h && depth < MAX_DEPTH {
            for k in (0..8u64).rev() {
                let child = [0, 1, 2].map(|d| lo[d] + ((k >> d) & 1) * half);
                let child_centre = child.map(|c| c + half / 2);
                let child_floor = less(bound, pc, at(child_centre));
                stack.push((child, depth + 1, child_floor));
            }
            continue;
        }
        let mut emit = |c: [u64; 3], known: Result<f64, f64>| {
            if seen.insert(c) {
                cand.push((at(c), known));
            }
        };
        emit(centre, Ok(h));
        for k in 0..8u64 {
            let corner = [0, 1, 2].map(|d| lo[d] + ((k >> d) & 1) * 2 * half);
            emit(corner, Err(less(bound, pc, at(corner))));
        }
        if cand.len() > MAX_POINTS {
            return Err(format!(
                "more than {MAX_POINTS} interior points: the size is too small for the part"
            ));
        }
    }
    // Which are inside, first: those outside cost the Delaunay insertion and the
    // boundary recovery their tets, then are dropped with them, and are cleared only
    // when asked for.
    let positions: Vec<P3> = cand.iter().map(|&(p, _)| p).collect();
    let inside = crate::surface::inside::enclosed(&tris, &positions);
    drop(positions);
    let mut near = Vec::new();
    let mut keep = Vec::new();
    for ((p, known), inside) in cand.into_iter().zip(inside) {
        if !inside && !outside {
            continue;
        }
        let h = known.unwrap_or_else(|floor| size.at_near(p, floor).0);
        let r = CLEARANCE * h;
        let b = Aabb {
            lo: p.map(|x| x - r),
            hi: p.map(|x| x + r),
        };
        grid.query(&b, |_| true, &mut near);
        // (A triangle whose box misses `b` is farther than r, and so are its balls.)
        near.retain(|&i| boxes[i as usize].overlaps(&b));
        let clear = near.iter().all(|&i| {
            let q = tris[i as usize];
            point_triangle_dist2(p, q[0], q[1], q[2]) >= r * r
                && balls[i as usize].iter().all(|&(c, r2)| dist2(p, c) >= r2)
        });
        if clear {
            keep.push((p, inside));
        }
    }
    Ok(keep)
}

/// The balls an interior point must stay out of for a surface triangle's edges and the
/// triangle itself to be Delaunay faces among the surface's points and it: each edge's
/// diametral ball, and the triangle's equatorial ball (centre its circumcentre) unless
/// the triangle is so obtuse that the ball reaches past its longest edge. As (centre,
/// squared radius).
fn protecting_balls(q: [P3; 3]) -> Vec<(P3, f64)> {
    let mut out: Vec<(P3, f64)> = (0..3)
        .map(|k| {
            let (a, b) = (q[k], q[(k + 1) % 3]);
            (mid(a, b), 0.25 * dist2(a, b))
        })
        .collect();
    let (u, v) = (sub(q[1], q[0]), sub(q[2], q[0]));
    let n = cross(u, v);
    let nn = dot(n, n);
    if nn > 0.0 {
        // Circumcentre: q0 + ((|u|² v - |v|² u) x n) / (2 |n|²).
        let w = sub(scale(v, dot(u, u)), scale(u, dot(v, v)));
        let c = axpy(q[0], 0.5 / nn, cross(w, n));
        let r2 = dist2(c, q[0]);
        let longest2 = (0..3)
            .map(|k| dist2(q[k], q[(k + 1) % 3]))
            .fold(0.0, f64::max);
        if r2 <= longest2 {
            out.push((c, r2));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::vec3::{det3, tet_det};
    use crate::Options;
    use std::collections::HashMap;

    /// The surface in `path` (from the crate root) and its whole fill with the tries
    /// `inside` with the points inside.
    fn fill_file(path: &str, inside: &[Split]) -> (crate::Surface, FrontOutput) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
        let s = crate::io::read_any_surface(&path, &Default::default()).unwrap();
        let size = crate::generate::size_field(&s, &Options::default());
        let out = whole_fill_trying(s.nodes(), s.triangles(), &size, inside).unwrap();
        (s, out)
    }

    /// The whole fill of a P2 surface: every tet positive, the boundary exactly the
    /// input's corner triangles, the volume the enclosed one, interior points added.
    fn check_whole_fill(path: &str) -> FrontOutput {
        let (s, out) = fill_file(path, INSIDE_TRIES);
        assert_eq!(&out.pts[..s.nodes().len()], s.nodes());
        assert!(out.pts.len() > s.nodes().len(), "no interior point");
        let mut vol = 0.0;
        // Per oriented face: uses minus uses of its reverse.
        let mut uses: HashMap<[u32; 3], i32> = HashMap::new();
        let canon = |f: [u32; 3]| {
            let r = (0..3).min_by_key(|&k| f[k]).unwrap();
            [f[r], f[(r + 1) % 3], f[(r + 2) % 3]]
        };
        for t in &out.tets {
            let p = t.map(|v| out.pts[v as usize]);
            let d = tet_det(p[0], p[1], p[2], p[3]);
            assert!(d > 0.0, "{t:?}");
            vol += d / 6.0;
            for g in super::super::validity::TET_OUT_FACES {
                let f = g.map(|j| t[j]);
                *uses.entry(canon(f)).or_insert(0) += 1;
                *uses.entry(canon([f[0], f[2], f[1]])).or_insert(0) -= 1;
            }
        }
        let mut bound: Vec<[u32; 3]> = uses
            .iter()
            .filter(|(_, &n)| n == 1)
            .map(|(f, _)| *f)
            .collect();
        let mut want: Vec<[u32; 3]> = s
            .triangles()
            .iter()
            .map(|t| canon([t[0], t[1], t[2]]))
            .collect();
        bound.sort_unstable();
        want.sort_unstable();
        assert_eq!(bound, want, "the boundary is not the input's");
        let enclosed: f64 = s
            .triangles()
            .iter()
            .map(|t| {
                det3(
                    s.nodes()[t[0] as usize],
                    s.nodes()[t[1] as usize],
                    s.nodes()[t[2] as usize],
                ) / 6.0
            })
            .sum();
        assert!(
            (vol - enclosed).abs() <= 1e-9 * enclosed,
            "{vol} vs {enclosed}"
        );
        assert!(out.stats.whole_fill);
        out
    }

    #[test]
    fn the_whole_fill_keeps_the_boundary_and_fills_the_volume() {
        let out = check_whole_fill("tests/data/sphere_p2.msh");
        // The size field's spacing: the same order of tets as the front makes (2,499).
        assert!(
            (1_000..10_000).contains(&out.tets.len()),
            "{}",
            out.tets.len()
        );
        check_whole_fill("tests/data/screw_p2.msh");
        // A thin strip at a step: rounded Steiner points make sub-faces whose projected
        // orientation alone misjudges the side the region is on.
        check_whole_fill("tests/data/hinge_p2.msh");
        check_whole_fill("tests/data/openscad/LetterBlock.stl");
        // Long edges between coplanar points: without the protecting balls, interior
        // points near them leave 900 Steiner points on 328 vertices, some stuck.
        check_whole_fill("tests/data/openscad/offset.stl");
        // Crossings next to nearly flat tets.
        check_whole_fill("tests/data/openscad/example007.stl");
    }

    /// A sphere drilled by two rotated holes through its centre
    /// (`scripts/csg-parts.py drilled2`): every try at crossings or halving stops
    /// (Steiner points rounded among nearly coplanar chains of other segments' points);
    /// the last try, recursive flips before halving, fills it, boundary kept.
    #[test]
    fn a_drilled_sphere_fills_by_recursive_flips_first() {
        let gz =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/csg/drilled2.stl.gz");
        let mut stl = tempfile::Builder::new().suffix(".stl").tempfile().unwrap();
        let file = std::fs::File::open(&gz).unwrap();
        std::io::copy(&mut flate2::read::GzDecoder::new(file), &mut stl).unwrap();
        let out = check_whole_fill(stl.path().to_str().unwrap());
        let tries = &out.stats.whole_fill_tries;
        assert!(
            tries[..tries.len() - 1].iter().all(|t| t.error.is_some()),
            "{tries:?}"
        );
        let last = tries.last().unwrap();
        assert_eq!(last.steiner_at, "recursive flips, then halves");
        assert!(last.error.is_none(), "{last:?}");
        // Of its 624 missing segments (TetGen's flips: all; greedy flips: 81; before
        // the flips kept off the segment's way and were kept where it failed: 380).
        assert!(last.flipped_segments >= 480, "{last:?}");
    }

    /// OpenSCAD part `name`'s whole fill with one way (`split`, `patience`), its interior
    /// candidates those inside only or (`outside`) all: the fill, its stages and the
    /// points it was given.
    fn fill_openscad(
        name: &str,
        outside: bool,
        split: Split,
        patience: Patience,
    ) -> (
        Result<cdt_fill::Filled, &'static str>,
        cdt_fill::Stages,
        Vec<P3>,
    ) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("tests/data/openscad/{name}.stl"));
        let s = crate::io::read_any_surface(&path, &Default::default()).unwrap();
        let size = crate::generate::size_field(&s, &Options::default());
        let inp = fill_input(s.nodes(), s.triangles(), &size, outside).unwrap();
        let mut all = inp.pts.clone();
        all.extend(inp.interior.iter().filter(|p| p.1 || outside).map(|p| p.0));
        let mut stages = cdt_fill::Stages::default();
        let r = cdt_fill::fill(&all, &inp.faces, split, None, patience, &mut stages);
        (r, stages, all)
    }

    /// OpenSCAD's example012 with its interior points: at crossings, 41 of its 1,303
    /// Steiner points stayed on the surface in the first round of moving them off and
    /// the fill gave up ([`Patience::GiveUpEarly`]; the exhaustive search failed too).
    /// Edge removals during recovery had made overlapping tets there (a fan triangle
    /// turned against the others, between nearly flat tets, passed a volume check);
    /// with the exact boundary check every point moves off, at crossings, at once.
    #[test]
    fn crossings_fill_where_edge_removals_kept_their_tets_apart() {
        let (r, stages, all) = fill_openscad(
            "example012",
            false,
            Split::AtCrossing,
            Patience::GiveUpEarly,
        );
        let filled = r.unwrap_or_else(|e| panic!("{e}"));
        assert!(filled.pts.len() > all.len(), "no Steiner point");
        assert!(stages.steiner_points > 0);
    }

    /// OpenSCAD's GEB (four shells of needle facets), halving with all its interior
    /// candidates: one Steiner point, on an edge between two coplanar facets and crowded
    /// by the points that halving piled up near a crossing of that edge, stayed on the
    /// surface through every round, and the fill failed (a last round with cavities of
    /// up to 4,000 tets, [`Patience::LastResort`], moved it). With the pieces split at
    /// their crossing once short, every point moves off in the regular rounds.
    #[test]
    fn a_crowded_edge_of_needles_fills_without_larger_cavities() {
        let (r, stages, all) = fill_openscad("GEB", true, Split::Halving, Patience::Exhaustive);
        let filled = r.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(stages.wide_cavity_points, 0);
        assert_eq!(&filled.pts[..all.len()], &all[..]);
    }

    /// OpenSCAD's CSG-modules, halving with its interior points: a segment that is one
    /// diagonal of a long planar quad of cap vertices crosses the other, a mesh edge,
    /// exactly. Halved on and on, it piled 61 points within 1e-4 of the crossing, two of
    /// which no cavity let off the surface; split at the crossing once its pieces are
    /// short (`cdt_fill::HALVING_DEPTH`), it fills. Its caps are planes of needle
    /// triangles: the Steiner points on them that only a tiny step moved off pinned
    /// their neighbours to the cap too (34 numerically flat tets, 198 such points,
    /// and 3 elements the later stages could not certify); deferred to the last round,
    /// most move off properly.
    #[test]
    fn a_segment_crossing_a_coplanar_edge_is_split_there_not_halved_on() {
        let (r, stages, all) =
            fill_openscad("CSG-modules", false, Split::Halving, Patience::Exhaustive);
        let filled = r.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(&filled.pts[..all.len()], &all[..]);
        assert!(stages.steiner_points > 0);
        let flat = filled
            .tets
            .iter()
            .filter(|t| {
                crate::geom::tet_quality::numerically_flat(&t.map(|v| filled.pts[v as usize]))
            })
            .count();
        assert!(flat <= 2, "{flat} numerically flat tets");
        assert!(filled.tiny < 100, "{} points at a tiny step", filled.tiny);
    }

    /// The torus (R = 1, r = 0.35, axis z): the candidates inside the tube are marked
    /// inside, those in the hole and the box's corners outside, and there are both;
    /// without those outside, the same points inside in the same order.
    #[test]
    fn interior_points_know_whether_the_surface_encloses_them() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/torus_p2.msh");
        let s = crate::io::read_any_surface(&path, &Default::default()).unwrap();
        let size = crate::generate::size_field(&s, &Options::default());
        let id = |v: u32| v;
        let pts = interior_points(s.nodes(), s.triangles(), &id, &size, true).unwrap();
        let only_inside = interior_points(s.nodes(), s.triangles(), &id, &size, false).unwrap();
        let want: Vec<(P3, bool)> = pts.iter().copied().filter(|p| p.1).collect();
        assert_eq!(only_inside, want);
        let inside = pts.iter().filter(|p| p.1).count();
        assert!(
            inside > 10 && inside < pts.len(),
            "{inside} of {}",
            pts.len()
        );
        for &(p, inside) in &pts {
            let ring = (p[0].hypot(p[1]) - 1.0).hypot(p[2]);
            assert_eq!(inside, ring < 0.35, "{p:?}");
        }
    }

    /// A raw marching-cubes surface has flat stretches of nearly cocircular vertices:
    /// the fill's flat tets on them (every corner on the surface) have circumspheres that
    /// the point lifted above their surface face can miss, so the Delaunay insertion of
    /// that point left them in place. Taking the flat tet into the cavity removes them.
    #[test]
    fn lifting_removes_flat_tets_whose_corners_are_all_on_the_surface() {
        use crate::geom::tet_quality::dihedral_extremes;
        let (s, out) = fill_file("tests/data/mc_blob.off", INSIDE_TRIES);
        let bnd = crate::optimize::Boundary::new(s.nodes().len(), s.triangles());
        let flat = out
            .tets
            .iter()
            .filter(|t| {
                t.iter().all(|&v| bnd.is_fixed(v))
                    && dihedral_extremes(&t.map(|v| out.pts[v as usize])).0 < 1.0
            })
            .count();
        // Measured: 288 with the Delaunay insertion alone, 14 taking the flat tet.
        assert!(
            flat < 25,
            "{flat} tets below 1° with every corner on the surface"
        );
    }

    /// The whole fill of the OpenSCAD part at `path`, after the linear stage with `prm`:
    /// its points, its tets and the surface's boundary.
    fn fill_then_linear(
        path: &str,
        prm: &crate::optimize::LinearParams,
    ) -> (Vec<P3>, Vec<[u32; 4]>, crate::optimize::Boundary) {
        use crate::optimize::linear::improve_linear;
        // The fill at crossings first, as the passes were measured on (with no flat
        // tets first, example002's fill leaves the passes far less to do).
        let (s, out) = fill_file(path, &[Split::AtCrossing, Split::Halving]);
        let bnd = crate::optimize::Boundary::new(s.nodes().len(), s.triangles())
            .with_sliver_floors(s.nodes(), s.triangles());
        let (pts, tets, _) = improve_linear(out.pts, out.tets, &bnd, prm);
        (pts, tets, bnd)
    }

    /// The linear stage on a whole fill with and without `guard_slivers`: the tets with a
    /// dihedral angle below 10° and no corner on the surface (never forced by it).
    fn interior_slivers_after_linear(path: &str, guard: bool) -> usize {
        use crate::mesh::slivers::is_sliver;
        use crate::optimize::linear::LinearParams;
        // (Without the sliver passes, which would hide what the guard does.)
        let prm = LinearParams {
            guard_slivers: guard,
            sliver_passes: 0,
            ..LinearParams::default()
        };
        let (pts, tets, bnd) = fill_then_linear(path, &prm);
        tets.iter()
            .filter(|t| {
                t.iter().all(|&v| !bnd.is_fixed(v)) && is_sliver(&t.map(|v| pts[v as usize]))
            })
            .count()
    }

    /// The tets with a dihedral angle below 1° and a corner off the surface after the
    /// linear stage with `prm` on a whole fill.
    fn flat_tets_after_linear(path: &str, prm: &crate::optimize::LinearParams) -> usize {
        use crate::geom::tet_quality::dihedral_extremes;
        let (pts, tets, bnd) = fill_then_linear(path, prm);
        tets.iter()
            .filter(|t| {
                t.iter().any(|&v| !bnd.is_fixed(v))
                    && dihedral_extremes(&t.map(|v| pts[v as usize])).0 < 1.0
            })
            .count()
    }

    #[test]
    fn the_flat_passes_leave_fewer_nearly_flat_tets() {
        use crate::optimize::LinearParams;
        let path = "tests/data/openscad/example005.stl";
        // Without the sliver passes after them, which go after every unforced sliver.
        let with_flat_passes = LinearParams {
            sliver_passes: 0,
            ..LinearParams::for_whole_fill()
        };
        let no_flat_passes = LinearParams {
            flat_skewness: None,
            ..with_flat_passes.clone()
        };
        let without = flat_tets_after_linear(path, &no_flat_passes);
        let with = flat_tets_after_linear(path, &with_flat_passes);
        // Measured: 224 without the flat passes, 143 with them.
        assert!(
            4 * with < 3 * without,
            "{with} nearly flat tets off the surface with the flat passes, {without} without"
        );
    }

    /// The whole fill's linear stage as `generate` runs it, with and without the sliver
    /// passes: the unforced slivers left (a dihedral angle below the least the sliver
    /// census allows at the tet's corners).
    #[test]
    fn the_sliver_passes_remove_the_unforced_slivers() {
        use crate::geom::tet_quality::dihedral_extremes;
        use crate::optimize::LinearParams;
        let unforced = |prm: &LinearParams| {
            let (pts, tets, bnd) = fill_then_linear("tests/data/openscad/example002.stl", prm);
            tets.iter()
                .filter(|t| {
                    dihedral_extremes(&t.map(|v| pts[v as usize])).0 < bnd.tet_sliver_floor(**t)
                })
                .count()
        };
        let without = unforced(&LinearParams {
            sliver_passes: 0,
            ..LinearParams::for_whole_fill()
        });
        let with = unforced(&LinearParams::for_whole_fill());
        assert!(
            without > 10,
            "{without} unforced slivers without the sliver passes"
        );
        assert_eq!(with, 0, "{with} unforced slivers with the sliver passes");
    }

    /// OpenSCAD's example004, curved from its STL: the whole fill leaves tets that no
    /// placement of their interior mid nodes makes valid, whose curved boundary edges
    /// the straightening after the high-order stage puts back on their chords. With
    /// those edges taken as chords in the sliver passes (`LinearParams::chords`), the
    /// passes lift their straight shape too, and no unforced sliver is left.
    #[test]
    fn the_sliver_passes_lift_the_tets_whose_edges_go_on_their_chords() {
        use crate::geom::tet_quality::dihedral_extremes;
        use crate::optimize::LinearParams;
        let unforced = |chords: bool| {
            let prm = LinearParams {
                chords,
                ..LinearParams::for_whole_fill()
            };
            let (pts, tets, bnd) = fill_then_linear("tests/data/openscad/example004.stl", &prm);
            tets.iter()
                .filter(|t| {
                    dihedral_extremes(&t.map(|v| pts[v as usize])).0 < bnd.tet_sliver_floor(**t)
                })
                .count()
        };
        // Measured: 20 without, 0 with.
        let (without, with) = (unforced(false), unforced(true));
        assert!(without >= 10, "{without} unforced slivers without chords");
        assert_eq!(with, 0, "{with} unforced slivers with chords");
    }

    #[test]
    fn the_sliver_guard_keeps_splits_from_spreading_slivers_inward() {
        let path = "tests/data/openscad/example002.stl";
        let (off, on) = (
            interior_slivers_after_linear(path, false),
            interior_slivers_after_linear(path, true),
        );
        // Measured: 90 without the guard (in every pass; it is on in the reach passes
        // anyway), 48 with it.
        assert!(
            3 * on < 2 * off,
            "{on} interior slivers with the guard, {off} without"
        );
    }
}
