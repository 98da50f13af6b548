//! Splitting a surface of several regions into closed region boundaries.
//!
//! The input is a set of triangles (3- or 6-node; only the corners are read) that is
//! closed but may be non-manifold along the junctions of regions: an interface between
//! two regions appears once, so an edge where a wall meets the boundary has three or more
//! triangles. Each triangle has two *sides* (the one its right-hand normal points to, and
//! the other); the regions are found on the sides, so the triangles' orientation in the
//! input does not matter.
//!
//! 1. **Pairing at edges.** Around each corner edge (a, b) (a the smaller node id), the
//!    triangles using it are sorted by the angle of their third corner around the axis
//!    a → b, with exact orientation signs ([`orient3d`]): one reference triangle splits
//!    the turn into two half-turns by the sign of orient3d(a, b, c₀, cᵢ), and within a
//!    half-turn cᵢ comes before cⱼ when orient3d(a, b, cᵢ, cⱼ) has the sign of a quarter
//!    turn. Two consecutive triangles bound one wedge of space: the side of the first
//!    that faces forward and the side of the second that faces back are in the same
//!    region. An edge of one triangle is an open surface; two triangles on the same
//!    half-plane overlap; both are errors naming the edge.
//! 2. **Shells.** The sides connected through such pairings form closed shells, each
//!    facing into one cell of space. Oriented away from its cell, a shell has a positive
//!    enclosed volume when it is the outer boundary of a bounded cell, and a negative
//!    one when it is a cavity's wall or faces the unbounded exterior (exact sign,
//!    [`chord_volume_sign`]).
//! 3. **Nesting.** A negative shell belongs to the innermost positive shell containing
//!    it (exact ray parity from one of its vertices that is not on that shell,
//!    `ray_crosses`); one contained by no positive shell faces the exterior and is
//!    dropped. A region is a positive shell with its cavity shells.
//!
//! Regions are numbered 1..n in the order of their outer shell's lowest triangle. Each
//! region's boundary is returned as input triangles, each marked whether it must be
//! reversed to face out of the region (the [`Surface`] convention: outer shell outward,
//! cavity walls into the cavity). The geometric checks (self-intersection, folds) are
//! left to [`Surface::new`] on each region's boundary.

use std::cmp::Ordering;

use super::orientation::{chord_volume_sign, ray_crosses};
use super::topology::edge_uses;
use super::Surface;
use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::predicates::orient3d;
use crate::geom::P3;

/// One region: its id and the input triangles of its boundary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RegionBoundary {
    /// The region's id (1..n in order of the outer shell's lowest triangle).
    pub id: i32,
    /// Input triangle indices of the boundary (outer shell, then cavity shells).
    pub triangles: Vec<u32>,
    /// For each of `triangles`, whether it must be reversed to face out of the region.
    pub reversed: Vec<bool>,
    /// Number of shells (1 + the cavities).
    pub shells: usize,
}

/// Does some corner edge of `tris` have more than two triangles (a region junction)?
pub fn has_junction_edges<const N: usize>(tris: &[[u32; N]]) -> bool {
    let uses = edge_uses(tris);
    uses.windows(3)
        .any(|w| (w[0].0, w[0].1) == (w[2].0, w[2].1))
}

/// A small union-find over triangle sides.
struct Sides(Vec<u32>);

impl Sides {
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// Side index of triangle `t`: `2t` faces where its normal points, `2t + 1` the other way.
fn side(t: u32, front: bool) -> u32 {
    2 * t + u32::from(!front)
}

fn edge_error(kind: SurfaceDefect, a: u32, b: u32, nodes: &[P3], what: &str) -> Error {
    Error::surface(
        kind,
        format!(
            "edge ({a}, {b}) at {:?} - {:?}: {what}",
            nodes[a as usize], nodes[b as usize]
        ),
    )
}

/// Pairs the sides of the triangles around edge (a, b) (see module docs). `fan` holds
/// (triangle, third corner, runs a → b).
fn pair_edge(
    nodes: &[P3],
    a: u32,
    b: u32,
    fan: &mut [(u32, u32, bool)],
    sides: &mut Sides,
) -> Result<()> {
    if fan.len() < 2 {
        return Err(edge_error(
            SurfaceDefect::NotClosed,
            a,
            b,
            nodes,
            &format!("used by one triangle ({}): the surface is open", fan[0].0),
        ));
    }
    let (pa, pb) = (nodes[a as usize], nodes[b as usize]);
    let p = |v: u32| nodes[v as usize];
    // The sign of a counterclockwise quarter turn around the axis a -> b.
    let quarter = orient3d(
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    );
    let c0 = p(fan[0].1);
    let axis = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
    // Half-turn of each triangle: 0 = [0, pi), 1 = [pi, 2 pi); `opposite` marks angle pi.
    let mut keyed: Vec<(u8, bool, (u32, u32, bool))> = Vec::with_capacity(fan.len());
    for (i, &f) in fan.iter().enumerate() {
        if i == 0 {
            keyed.push((0, false, f));
            continue;
        }
        let s = orient3d(pa, pb, c0, p(f.1));
        if s == quarter {
            keyed.push((0, false, f));
        } else if s == -quarter {
            keyed.push((1, false, f));
        } else {
            // In the reference's plane: the same half-plane (overlap) or the opposite.
            let perp = |c: P3| {
                let v = [c[0] - pa[0], c[1] - pa[1], c[2] - pa[2]];
                let l2 = crate::geom::vec3::dot(axis, axis);
                let k = crate::geom::vec3::dot(v, axis) / l2;
                [v[0] - k * axis[0], v[1] - k * axis[1], v[2] - k * axis[2]]
            };
            if crate::geom::vec3::dot(perp(c0), perp(p(f.1))) > 0.0 {
                return Err(edge_error(
                    SurfaceDefect::SelfIntersection,
                    a,
                    b,
                    nodes,
                    &format!("triangles {} and {} overlap", fan[0].0, f.0),
                ));
            }
            keyed.push((1, true, f));
        }
    }
    let mut overlap = None;
    keyed.sort_by(|x, y| {
        x.0.cmp(&y.0).then_with(|| y.1.cmp(&x.1)).then_with(|| {
            if x.1 || y.1 || x.2 .0 == y.2 .0 {
                return Ordering::Equal;
            }
            let s = orient3d(pa, pb, p(x.2 .1), p(y.2 .1));
            if s == quarter {
                Ordering::Less
            } else if s == -quarter {
                Ordering::Greater
            } else {
                overlap = Some((x.2 .0, y.2 .0));
                Ordering::Equal
            }
        })
    });
    if let Some((t, u)) = overlap {
        return Err(edge_error(
            SurfaceDefect::SelfIntersection,
            a,
            b,
            nodes,
            &format!("triangles {t} and {u} overlap"),
        ));
    }
    if keyed.iter().filter(|k| k.1).count() > 1 {
        return Err(edge_error(
            SurfaceDefect::SelfIntersection,
            a,
            b,
            nodes,
            "two triangles overlap opposite the first",
        ));
    }
    let n = keyed.len();
    for i in 0..n {
        let (t, _, fwd) = keyed[i].2;
        let (u, _, ufwd) = keyed[(i + 1) % n].2;
        // The side of t facing forward (counterclockwise) is its front when it runs
        // a -> b; the side of u facing back is its back then.
        sides.union(side(t, fwd), side(u, !ufwd));
    }
    Ok(())
}

/// Splits closed triangles `tris` (corners read; node ids into `nodes`) into regions
/// (see module docs).
pub fn split_regions<const N: usize>(
    nodes: &[P3],
    tris: &[[u32; N]],
) -> Result<Vec<RegionBoundary>> {
    if tris.is_empty() {
        return Err(Error::surface(
            SurfaceDefect::Empty,
            "no triangles".to_string(),
        ));
    }
    for (t, tri) in tris.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= nodes.len()) {
            return Err(Error::surface(
                SurfaceDefect::IndexOutOfRange,
                format!(
                    "triangle {t}: node index {v} is out of range ({} nodes)",
                    nodes.len()
                ),
            ));
        }
    }
    let uses = edge_uses(tris);
    let mut sides = Sides((0..2 * tris.len() as u32).collect());
    let mut fan = Vec::new();
    let mut i = 0;
    while i < uses.len() {
        let (a, b) = (uses[i].0, uses[i].1);
        fan.clear();
        while i < uses.len() && (uses[i].0, uses[i].1) == (a, b) {
            let (t, k) = (uses[i].2, uses[i].3 as usize);
            let tri = &tris[t as usize];
            let fwd = tri[k] == a;
            fan.push((t, tri[(k + 2) % 3], fwd));
            i += 1;
        }
        pair_edge(nodes, a, b, &mut fan, &mut sides)?;
    }
    // Shells: the components of sides, each triangle oriented away from its cell.
    let mut comp_of = vec![u32::MAX; 2 * tris.len()];
    let mut shells: Vec<Vec<(u32, bool)>> = Vec::new();
    for s in 0..2 * tris.len() as u32 {
        let r = sides.find(s) as usize;
        if comp_of[r] == u32::MAX {
            comp_of[r] = shells.len() as u32;
            shells.push(Vec::new());
        }
        // A front side faces into its cell: reversed, the triangle faces away from it.
        shells[comp_of[r] as usize].push((s / 2, s % 2 == 0));
    }
    for sh in &shells {
        let mut ts: Vec<u32> = sh.iter().map(|x| x.0).collect();
        ts.sort_unstable();
        if let Some(w) = ts.windows(2).find(|w| w[0] == w[1]) {
            return Err(Error::surface(
                SurfaceDefect::NonManifoldEdge,
                format!(
                    "triangle {} has the same region on both sides (a wall inside a region)",
                    w[0]
                ),
            ));
        }
    }
    let oriented = |sh: &[(u32, bool)]| -> Vec<[u32; 6]> {
        sh.iter()
            .map(|&(t, rev)| {
                let c = &tris[t as usize];
                if rev {
                    [c[0], c[2], c[1], 0, 0, 0]
                } else {
                    [c[0], c[1], c[2], 0, 0, 0]
                }
            })
            .collect()
    };
    let mut sign = Vec::with_capacity(shells.len());
    let mut volume = Vec::with_capacity(shells.len());
    for sh in &shells {
        let o = oriented(sh);
        let all: Vec<u32> = (0..o.len() as u32).collect();
        let s = chord_volume_sign(nodes, &o, &all);
        if s == 0 {
            return Err(Error::surface(
                SurfaceDefect::DegenerateTriangle,
                format!("the shell through triangle {} encloses no volume", sh[0].0),
            ));
        }
        sign.push(s);
        volume.push(crate::geom::quadrature::enclosed_volume_linear(nodes, &o).abs());
    }
    let outer: Vec<usize> = (0..shells.len()).filter(|&s| sign[s] > 0).collect();
    let mut vertices: Vec<Vec<u32>> = shells
        .iter()
        .map(|sh| {
            let mut v: Vec<u32> = sh
                .iter()
                .flat_map(|&(t, _)| tris[t as usize][..3].to_vec())
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        })
        .collect();
    vertices.shrink_to_fit();
    // Each negative shell: the innermost positive shell containing it.
    let mut cavities: Vec<Vec<usize>> = vec![Vec::new(); shells.len()];
    for s in (0..shells.len()).filter(|&s| sign[s] < 0) {
        let mut best: Option<usize> = None;
        for &o in &outer {
            let Some(&v) = vertices[s]
                .iter()
                .find(|v| vertices[o].binary_search(v).is_err())
            else {
                continue;
            };
            let q = nodes[v as usize];
            let crossings = shells[o]
                .iter()
                .filter(|&&(t, _)| {
                    let c = &tris[t as usize];
                    ray_crosses(
                        q,
                        nodes[c[0] as usize],
                        nodes[c[1] as usize],
                        nodes[c[2] as usize],
                    )
                })
                .count();
            if crossings % 2 == 1 && best.map_or(true, |b| volume[o] < volume[b]) {
                best = Some(o);
            }
        }
        if let Some(o) = best {
            cavities[o].push(s);
        }
    }
    let mut order: Vec<usize> = outer.clone();
    let lowest = |s: usize| shells[s].iter().map(|x| x.0).min().unwrap_or(0);
    order.sort_by_key(|&s| lowest(s));
    Ok(order
        .iter()
        .enumerate()
        .map(|(k, &o)| {
            let mut triangles = Vec::new();
            let mut reversed = Vec::new();
            for &s in std::iter::once(&o).chain(&cavities[o]) {
                for &(t, rev) in &shells[s] {
                    triangles.push(t);
                    reversed.push(rev);
                }
            }
            RegionBoundary {
                id: k as i32 + 1,
                triangles,
                reversed,
                shells: 1 + cavities[o].len(),
            }
        })
        .collect())
}

/// The boundary of `region` as its own P2 [`Surface`] (checked): its nodes are the input
/// nodes it uses, in input order, and the returned map gives each one's input index.
pub fn region_surface(
    nodes: &[P3],
    tris: &[[u32; 6]],
    tags: &[i32],
    region: &RegionBoundary,
    repair: super::Repair,
) -> Result<(Surface, Vec<u32>)> {
    let mut used: Vec<u32> = region
        .triangles
        .iter()
        .flat_map(|&t| tris[t as usize])
        .collect();
    used.sort_unstable();
    used.dedup();
    let local = |v: u32| used.binary_search(&v).expect("a used node") as u32;
    let rtris: Vec<[u32; 6]> = region
        .triangles
        .iter()
        .zip(&region.reversed)
        .map(|(&t, &rev)| {
            let mut x = tris[t as usize].map(local);
            if rev {
                super::repair::flip(&mut x);
            }
            x
        })
        .collect();
    let rtags: Vec<i32> = if tags.is_empty() {
        Vec::new()
    } else {
        region.triangles.iter().map(|&t| tags[t as usize]).collect()
    };
    let rnodes: Vec<P3> = used.iter().map(|&v| nodes[v as usize]).collect();
    let surface = Surface::new_with_repair(rnodes, rtris, rtags, repair)
        .map_err(|e| in_region(e, region.id))?;
    Ok((surface, used))
}

/// `e` with "region ID: " before its message (surface, meshing and mesh errors).
pub fn in_region(e: Error, id: i32) -> Error {
    match e {
        Error::InvalidSurface { kind, msg } => Error::InvalidSurface {
            kind,
            msg: format!("region {id}: {msg}"),
        },
        Error::MeshingFailed { msg, partial } => Error::MeshingFailed {
            msg: format!("region {id}: {msg}"),
            partial,
        },
        Error::InvalidMesh {
            elements,
            msg,
            mesh,
        } => Error::InvalidMesh {
            elements,
            msg: format!("region {id}: {msg}"),
            mesh,
        },
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::demo::{icosphere, nested_spheres, split_box};

    fn volume(nodes: &[P3], tris: &[[u32; 6]], r: &RegionBoundary) -> f64 {
        let o: Vec<[u32; 6]> = r
            .triangles
            .iter()
            .zip(&r.reversed)
            .map(|(&t, &rev)| {
                let mut x = tris[t as usize];
                if rev {
                    crate::surface::repair::flip(&mut x);
                }
                x
            })
            .collect();
        crate::geom::quadrature::enclosed_volume_linear(nodes, &o)
    }

    #[test]
    fn one_sphere_is_one_region_facing_out_whatever_its_orientation() {
        let (nodes, mut tris) = icosphere(1);
        for flip_it in [false, true] {
            if flip_it {
                tris.iter_mut().for_each(crate::surface::repair::flip);
            }
            let r = split_regions(&nodes, &tris).expect("splits");
            assert_eq!(r.len(), 1);
            assert_eq!(r[0].triangles.len(), tris.len());
            assert_eq!(r[0].shells, 1);
            assert!(r[0].reversed.iter().all(|&x| x == flip_it));
            assert!(volume(&nodes, &tris, &r[0]) > 0.0);
            assert!(!has_junction_edges(&tris));
        }
    }

    #[test]
    fn nested_spheres_are_a_ball_and_a_shell_with_a_cavity() {
        let (nodes, tris) = nested_spheres(1, 0.5, 1.0);
        let half = tris.len() as u32 / 2;
        let r = split_regions(&nodes, &tris).expect("splits");
        assert_eq!(r.len(), 2);
        // Region 1: the ball (inner sphere, lowest triangles), as given.
        assert_eq!(r[0].shells, 1);
        assert!(r[0].triangles.iter().all(|&t| t < half));
        assert!(r[0].reversed.iter().all(|&x| !x));
        // Region 2: the outer sphere outward plus the inner sphere reversed.
        assert_eq!(r[1].shells, 2);
        assert_eq!(r[1].triangles.len(), tris.len());
        for (&t, &rev) in r[1].triangles.iter().zip(&r[1].reversed) {
            assert_eq!(rev, t < half, "triangle {t}");
        }
        let (v1, v2) = (volume(&nodes, &tris, &r[0]), volume(&nodes, &tris, &r[1]));
        let whole = crate::geom::quadrature::enclosed_volume_linear(&nodes, &tris[half as usize..]);
        assert!(
            (v1 + v2 - whole).abs() < 1e-12 * whole,
            "{v1} + {v2} vs {whole}"
        );
        assert!(v1 > 0.0 && v2 > 0.0);
    }

    #[test]
    fn a_split_box_is_two_boxes_sharing_the_wall() {
        let (nodes, tris) = split_box(2);
        assert!(has_junction_edges(&tris));
        let r = split_regions(&nodes, &tris).expect("splits");
        assert_eq!(r.len(), 2);
        for reg in &r {
            assert_eq!(reg.shells, 1);
            // 6 faces of 2 x 2 squares of 2 triangles.
            assert_eq!(reg.triangles.len(), 48);
            let v = volume(&nodes, &tris, reg);
            assert!((v - 1.0).abs() < 1e-14, "region {}: {v}", reg.id);
        }
        let shared: Vec<u32> = r[0]
            .triangles
            .iter()
            .filter(|t| r[1].triangles.contains(t))
            .copied()
            .collect();
        assert_eq!(shared.len(), 8);
        // Each side of a shared triangle faces out of one box.
        for t in shared {
            let k0 = r[0].triangles.iter().position(|&x| x == t).unwrap();
            let k1 = r[1].triangles.iter().position(|&x| x == t).unwrap();
            assert_ne!(r[0].reversed[k0], r[1].reversed[k1]);
        }
        // Each region is a valid surface of its own.
        for reg in &r {
            let (s, map) =
                region_surface(&nodes, &tris, &[], reg, crate::Repair::Strict).expect("valid");
            assert!(s.warnings().is_empty(), "{:?}", s.warnings());
            assert!(map.windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn an_open_edge_is_named() {
        let (nodes, mut tris) = split_box(1);
        tris.pop();
        let e = split_regions(&nodes, &tris).unwrap_err();
        assert_eq!(e.surface_defect(), Some(SurfaceDefect::NotClosed), "{e}");
        assert!(e.to_string().contains("edge ("), "{e}");
    }

    #[test]
    fn a_repeated_triangle_is_an_overlap() {
        let (nodes, mut tris) = icosphere(0);
        let t = tris[3];
        tris.push([t[0], t[2], t[1], t[5], t[4], t[3]]);
        let e = split_regions(&nodes, &tris).unwrap_err();
        assert_eq!(
            e.surface_defect(),
            Some(SurfaceDefect::SelfIntersection),
            "{e}"
        );
    }
}
