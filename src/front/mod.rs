//! The advancing front (paper 2.1-2.8, Algorithms 1 and 2), with a closing strategy that
//! goes beyond the paper: relaxed filters in steps, then local remeshing.
//!
//! The front starts as the input triangles turned inward. Each step takes the smallest
//! live front face, places the ideal apex at the regular-tetrahedron height along its
//! inward normal, gathers front vertices within `alpha * h` of it, ranks candidates by
//! quality (Algorithm 2: an existing vertex near the ideal point beats a new one), and
//! accepts the first that passes the exact validity test and, when it touches the
//! curved boundary, the certified Jacobian test. New faces that coincide with front
//! faces close them.

mod cavity;
mod constrained;
mod diagnose;
mod grid;
mod queue;
mod repair;
pub mod size;
pub mod validity;
mod whole_fill;

use crate::geom::bezier::certify;
use crate::geom::predicates::orient3d;
use crate::geom::shape::{tri6_normal, TET10_EDGES};
use crate::geom::tet_quality::{dihedral_extremes, skewness_from_extremes};
use crate::geom::vec3::*;
use crate::options::Options;
use crate::{Error, Result};
use grid::{Aabb, FaceGrid, PointGrid};
use queue::FaceQueue;
use rustc_hash::FxHashMap as HashMap;
use size::{regular_height, SizeField};
use validity::{FaceRef, NEW_POINT, TET_OUT_FACES};

/// What the front produced: straight-sided tets on low-order vertices.
pub struct FrontOutput {
    /// All points: the surface nodes (same indices) then the new interior vertices.
    pub pts: Vec<P3>,
    /// Positive tets (corner ids).
    pub tets: Vec<[u32; 4]>,
    /// Per tet: 1 − equiangular skewness of its corners as the front measured it when it
    /// chose the tet (`geom::tet_quality`, the corners in tet order), NaN where it did not
    /// measure (tets of filled cavities). The linear stage starts from these.
    pub quality: Vec<f64>,
    /// Statistics of the run.
    pub stats: FrontStats,
}

/// Counters of one front run.
#[derive(Debug, Default, Clone, serde::Serialize)]
pub struct FrontStats {
    /// Faces processed (pops of the queue that were live).
    pub steps: u64,
    /// Tets accepted at relaxed levels 1 and 2.
    pub relaxed: [u64; 2],
    /// Tets accepted with a new vertex.
    pub new_vertices: u64,
    /// Local remeshing operations.
    pub repairs: u64,
    /// Tets deleted by repairs.
    pub deleted: u64,
    /// Stuck cavities closed by the exact search.
    pub cavities: u64,
    /// Stuck cavities closed by the constrained fill.
    pub constrained: u64,
    /// Tets accepted as a last resort with a non-positive P2 Jacobian (linear-valid, with
    /// a free mid node), left for the high-order optimizer to untangle.
    pub p2_invalid: u64,
    /// Whole-front restarts (see [`RESTARTS`]): the front could not be closed, or the
    /// optimizer left an element of the previous attempt invalid. With a whole fill,
    /// the front attempts that ran before it less one (0 where none ran:
    /// [`FrontStats::fill_first`], or a front that stalled on its first attempt).
    pub restarts: u32,
    /// Search radius factor of the run that succeeded.
    pub alpha: f64,
    /// Size field factor of the run that succeeded.
    pub size_scale: f64,
    /// No front attempt closed: the whole region was filled at once (interior points
    /// from the size field, then the constrained fill; see `whole_fill`).
    pub whole_fill: bool,
    /// The whole fill's tries, in order, the last the one that filled (empty without a
    /// whole fill).
    pub whole_fill_tries: Vec<FillTry>,
    /// The whole fill ran first, before any front attempt: more than
    /// [`FILL_FIRST_POOR_FRACTION`] of the surface's triangles are poorly shaped, or one
    /// has an aspect ratio above [`FILL_FIRST_WORST_ASPECT_RATIO`].
    pub fill_first: bool,
    /// Seconds spent in front attempts whose tets were dropped: attempts that did not
    /// close, before the one that did or before the whole fill, and attempts whose mesh
    /// the optimizer left with elements it could not certify (then the next
    /// configuration ran).
    pub discarded_seconds: f64,
}

/// One try of the whole fill (`whole_fill`): how it placed Steiner points, with which
/// interior points, where it stopped, and the time of each stage it reached (0 for a
/// stage not reached).
#[derive(Debug, Default, Clone, serde::Serialize)]
pub struct FillTry {
    /// Where edge recovery put its Steiner points: `"crossings"` (where a segment
    /// leaves a tet), `"halves"` (halving the segment), `"no flat tets"` (flips in
    /// the plane of coplanar surface points first, then at crossings, with no
    /// numerically flat tet in the recovery), or `"recursive flips, then halves"` (the
    /// last try).
    pub steiner_at: &'static str,
    /// Whether the interior points outside the surface were inserted too (they change
    /// the Delaunay tetrahedralization recovery starts from; their tets are dropped).
    pub points_outside: bool,
    /// Why the try stopped; None for the try that filled.
    pub error: Option<String>,
    /// Delaunay tetrahedralization of the surface's corners and the interior points (0
    /// for the second try on the same points: it starts from the first one's).
    pub delaunay_seconds: f64,
    /// Recovery of the surface's edges.
    pub edges_seconds: f64,
    /// Recovery of the surface's triangles.
    pub faces_seconds: f64,
    /// Moving the Steiner points off the surface.
    pub steiner_removal_seconds: f64,
    /// Steiner points edge and face recovery added (all on the surface until moved).
    pub steiner_points: usize,
    /// Surface edges missing from the Delaunay tetrahedralization that the last try's
    /// recursive flips brought in before any Steiner point (0 on the other tries).
    pub flipped_segments: usize,
    /// Placing the interior points (the octree, the inside test and the clearance from
    /// the surface): on the first try, for the points inside, and again on the first
    /// try with the points outside too ([`FillTry::points_outside`]); 0 on the others.
    pub points_seconds: f64,
    /// After the Steiner points moved: contracting flat tets and slivers, lifting points
    /// above thin tets on the surface, and collecting the tets (0 where the try stopped
    /// before).
    pub finish_seconds: f64,
}

#[derive(Clone, Copy)]
struct Face {
    v: [u32; 3],
    alive: bool,
    tries: u8,
    /// Index of the input triangle when this face is a boundary face, else u32::MAX.
    btri: u32,
    /// Version: queue entries with an older version are stale.
    ver: u32,
    /// A lower bound of the distance from the face's centroid to the nearest surface
    /// vertex (0: unknown), for [`SizeField::at_near`].
    dnear: f64,
}

/// Wedges (unmeshed dihedral angle between neighbouring front faces) below this are
/// closed first: left for later they become the pockets an advancing front gets stuck in.
const WEDGE_FIRST_DEG: f64 = 75.0;

/// Inputs with at least this many triangles queue their interior faces by size class
/// (`queue::size_class`) and oldest first within a class, rather than by exact size:
/// on a large front the exact order jumps across the whole domain at every step, while
/// oldest first keeps consecutive steps in one neighbourhood (the 1M-tet torus's front
/// 9.8 -> 8.6 s, the 100k one's 0.93 -> 0.84 s, with fewer relaxed steps). Smaller inputs
/// (every benchmark surface has at most 2,300 triangles) keep the exact smallest-first
/// order, which the mixed-size surfaces need: size classes made the hinge's outcome
/// depend on the class width (min J / max J 0.19-0.56).
pub const SIZE_CLASS_MIN_TRIANGLES: usize = 8192;

/// A candidate apex.
#[derive(Clone, Copy)]
struct Cand {
    /// The apex's vertex id, or [`NEW_POINT`] for a new point at `p`.
    id: u32,
    p: P3,
    q: f64,
    dist_a: f64,
}

/// The ideal apex of one front face and the sizes it was measured with.
struct ApexFrame {
    /// The face's corners.
    fp: [P3; 3],
    /// Its centroid and inward unit normal.
    c: P3,
    n: P3,
    /// The size field at the centroid (this attempt's scale applied).
    l_field: f64,
    /// The target edge length: the field, kept within 0.55-1.8 times the face's mean edge.
    target: f64,
    /// The regular-tet height of `target`, and the ideal apex at that height.
    h: f64,
    ideal: P3,
}

/// The shape floors a relaxation level ranks candidates with.
#[derive(Clone, Copy)]
enum Floors {
    /// `Options::min_dihedral_deg` and `Options::max_skewness`.
    Options,
    /// A third of the dihedral floor, skewness up to 0.97.
    Relaxed,
    /// None: every candidate is kept, even one whose quality is undefined.
    None,
    /// None, but a candidate whose quality is undefined (NaN) is dropped.
    NoneScored,
}

/// The floor on the angle between a new edge and a nearby front face.
#[derive(Clone, Copy)]
enum GapFloor {
    /// `Options::min_edge_face_angle_deg` divided by this.
    Options(f64),
    /// This many degrees.
    Degrees(f64),
}

/// What one relaxation level of [`Mesher::advance`] allows. A face is tried at level 0
/// first; each failure raises its level (up to 2) for the next time it is popped; level 3
/// is the late resort after local remeshing has not helped.
struct Relaxation {
    /// Candidate vertices within this many `alpha * h` of the ideal apex.
    search_radius: f64,
    /// New points keep this far from front vertices, as a fraction of the *field* size,
    /// so a pocket of small faces cannot breed ever smaller elements.
    new_point_spacing: f64,
    /// Heights of the new points tried, as fractions of the ideal height.
    new_point_heights: &'static [f64],
    /// Shape floors for ranking.
    shape_floors: Floors,
    /// Edge/face angle floor in the validity test.
    gap_floor: GapFloor,
    /// Proximity floors (fractions of the target size): a new point, an existing vertex.
    proximity: (f64, f64),
    /// A candidate that fails only the look-ahead or the boundary gap floor is taken when
    /// nothing else passes.
    fallback_ok: bool,
    /// A linear-valid tet whose P2 Jacobian is not positive is taken when it has a free
    /// mid node for the optimizer to move (the look-ahead and the boundary gap floor are
    /// then waived).
    p2_invalid_ok: bool,
}

/// The relaxation levels, strictest first.
const RELAXATION: [Relaxation; 4] = [
    // 0: the paper's step, the options' floors.
    Relaxation {
        search_radius: 1.0,
        new_point_spacing: 0.45,
        new_point_heights: &[1.0],
        shape_floors: Floors::Options,
        gap_floor: GapFloor::Options(1.0),
        proximity: (0.35, 0.35),
        fallback_ok: false,
        p2_invalid_ok: false,
    },
    // 1: twice the search radius, a lower new point, floors relaxed.
    Relaxation {
        search_radius: 2.0,
        new_point_spacing: 0.35,
        new_point_heights: &[1.0, 0.7],
        shape_floors: Floors::Relaxed,
        gap_floor: GapFloor::Options(2.5),
        proximity: (0.2, 0.2),
        fallback_ok: false,
        p2_invalid_ok: false,
    },
    // 2: any valid tet; a look-ahead failure as a fallback.
    Relaxation {
        search_radius: 3.0,
        new_point_spacing: 0.25,
        new_point_heights: &[1.0, 0.7, 0.5],
        shape_floors: Floors::None,
        gap_floor: GapFloor::Degrees(1.0),
        proximity: (0.12, 0.0),
        fallback_ok: true,
        p2_invalid_ok: false,
    },
    // 3: late resort, a tet for the high-order optimizer to untangle.
    Relaxation {
        search_radius: 3.0,
        new_point_spacing: 0.25,
        new_point_heights: &[1.0, 0.7, 0.5],
        shape_floors: Floors::NoneScored,
        gap_floor: GapFloor::Degrees(1.0),
        proximity: (0.12, 0.0),
        fallback_ok: false,
        p2_invalid_ok: true,
    },
];
/// Smallest wedge a new face may leave against a boundary face at any relaxation level: a
/// thinner one could only be closed by a flat tet with a curved face, which is invalid
/// on concave boundaries, and boundary faces can never be remeshed.
const MIN_BOUNDARY_GAP_DEG: f64 = 5.0;

#[cfg(test)]
thread_local! {
    /// Tests of the repair and give-up path turn the constrained fill off on their thread.
    static FILL_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Tests only: every front attempt fails at once, so that the whole fill runs.
    static FRONT_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

fn front_enabled() -> bool {
    #[cfg(test)]
    {
        !FRONT_OFF.with(|c| c.get())
    }
    #[cfg(not(test))]
    {
        true
    }
}

fn fill_enabled() -> bool {
    #[cfg(test)]
    {
        !FILL_OFF.with(|c| c.get())
    }
    #[cfg(not(test))]
    {
        true
    }
}

#[inline]
fn key3(v: [u32; 3]) -> [u32; 3] {
    let mut k = v;
    k.sort_unstable();
    k
}

/// Progress callback: fraction in [0, 1], stage name; returns true to cancel.
pub type Progress<'p> = &'p mut dyn FnMut(f64, &str) -> bool;

pub(crate) struct Mesher<'a> {
    opts: &'a Options,
    surf_nodes: &'a [P3],
    surf_tris: &'a [[u32; 6]],
    n_surf: usize,
    pts: Vec<P3>,
    /// Live front faces at each vertex: the vertex is on the front (a candidate, in
    /// `vgrid`) while this is positive.
    vdeg: Vec<u32>,
    faces: Vec<Face>,
    /// `faces[i].alive`, compact (the grid reads it for every listed face).
    face_alive: Vec<bool>,
    face_map: HashMap<[u32; 3], u32>,
    btri_map: HashMap<[u32; 3], u32>,
    bedge_mid: HashMap<(u32, u32), u32>,
    queue: FaceQueue,
    /// Directed edge (a, b) of a live front face -> that face.
    edges: HashMap<(u32, u32), u32>,
    grid: FaceGrid,
    vgrid: PointGrid,
    tets: Vec<[u32; 4]>,
    /// [`FrontOutput::quality`] of each tet.
    tet_q: Vec<f64>,
    tet_alive: Vec<bool>,
    size: &'a SizeField,
    /// Multiplies the size field (restarts refine).
    size_scale: f64,
    /// Candidate search radius factor (the user's alpha, changed on restarts).
    alpha: f64,
    stats: FrontStats,
    repairs_at: HashMap<(i32, i32, i32), u32>,
    repair_cell: f64,
    /// Live front faces.
    open_faces: usize,
    /// The fewest live front faces so far, and the repair count when the front had them
    /// (see [`MAX_REPAIRS_WITHOUT_PROGRESS`]).
    fewest_open: (usize, u64),
    /// This attempt's [`repairs_without_progress_limit`] (the tests lower it).
    max_repairs_without_progress: u64,
    /// Steps without a new most-filled volume after which the attempt stalls
    /// ([`stall_limit`]).
    stall_limit: u64,
    /// Validity-test work without a new most-filled volume after which the attempt
    /// stalls ([`stall_work_limit`]).
    stall_work_limit: u64,
    /// Validity-test work so far: front faces gathered for a candidate's test, plus one
    /// per gather (see [`stall_work_limit`]).
    work: u64,
    /// Validity-test work this attempt may do in all ([`front_work_budget`], less what
    /// earlier attempts spent); u64::MAX: no bound.
    work_budget: u64,
    /// Set when the attempt gave up by [`Mesher::stall_limit`],
    /// [`Mesher::stall_work_limit`] or [`Mesher::work_budget`].
    stalled: bool,
    /// Close stuck cavities by the constrained fill (off only in tests of the repair path).
    use_fill: bool,
    /// May the fill make curved tets with a non-positive Jacobian (for the optimizer)?
    fill_p2_invalid: bool,
    /// The stage name progress is reported under ([`attempt_stage`]).
    stage: String,
    // scratch
    near_ids: Vec<u32>,
    near: Vec<FaceRef>,
    cands: Vec<Cand>,
    found: Vec<(u32, f64)>,
    volume_done: f64,
    /// Queue interior faces by size class ([`SIZE_CLASS_MIN_TRIANGLES`]).
    size_classes: bool,
}

impl<'a> Mesher<'a> {
    pub(crate) fn new(
        surf_nodes: &'a [P3],
        surf_tris: &'a [[u32; 6]],
        opts: &'a Options,
        size: &'a SizeField,
    ) -> Mesher<'a> {
        let n_surf = surf_nodes.len();
        let mut edge_len_sum = 0.0;
        let mut edge_len_max = 0.0f64;
        let mut bedge_mid =
            HashMap::with_capacity_and_hasher(surf_tris.len() * 3 / 2, Default::default());
        for t in surf_tris {
            for (k, [i, j]) in crate::geom::shape::TRI6_EDGES.iter().enumerate() {
                let (a, b) = (t[*i], t[*j]);
                let l = dist(surf_nodes[a as usize], surf_nodes[b as usize]);
                edge_len_sum += l;
                edge_len_max = edge_len_max.max(l);
                bedge_mid.insert((a.min(b), a.max(b)), t[3 + k]);
            }
        }
        let mean_edge = edge_len_sum / (3 * surf_tris.len()).max(1) as f64;
        // Cells about the size of a query box (a tet's box widened by the proximity
        // floors, 2-3 edge lengths): twice the mean edge was 15-20% faster on the front
        // than one mean edge (100k-tet torus; fewer cells visited, fewer duplicates).
        let cell = 2.0 * mean_edge.max(edge_len_max / 8.0);
        let (bounds, max_cells) = (Aabb::of(surf_nodes), (16 * surf_tris.len()).max(1 << 16));
        let mut m = Mesher {
            opts,
            surf_nodes,
            surf_tris,
            n_surf,
            pts: surf_nodes.to_vec(),
            vdeg: vec![0; n_surf],
            faces: Vec::with_capacity(surf_tris.len() * 4),
            face_alive: Vec::with_capacity(surf_tris.len() * 4),
            face_map: HashMap::with_capacity_and_hasher(surf_tris.len() * 2, Default::default()),
            btri_map: HashMap::with_capacity_and_hasher(surf_tris.len(), Default::default()),
            bedge_mid,
            queue: FaceQueue::default(),
            edges: HashMap::with_capacity_and_hasher(surf_tris.len() * 6, Default::default()),
            grid: FaceGrid::new(bounds, cell, max_cells),
            vgrid: PointGrid::new(bounds, cell, max_cells),
            tets: Vec::new(),
            tet_q: Vec::new(),
            tet_alive: Vec::new(),
            size,
            size_scale: 1.0,
            alpha: opts.alpha,
            stats: FrontStats::default(),
            repairs_at: HashMap::default(),
            open_faces: 0,
            fewest_open: (usize::MAX, 0),
            max_repairs_without_progress: repairs_without_progress_limit(0),
            stall_limit: stall_limit(surf_tris.len()),
            stall_work_limit: stall_work_limit(surf_tris.len()),
            work: 0,
            work_budget: u64::MAX,
            stalled: false,
            use_fill: fill_enabled(),
            fill_p2_invalid: true,
            stage: attempt_stage(0),
            repair_cell: 2.0 * mean_edge,
            near_ids: Vec::new(),
            near: Vec::new(),
            cands: Vec::new(),
            found: Vec::new(),
            volume_done: 0.0,
            size_classes: surf_tris.len() >= SIZE_CLASS_MIN_TRIANGLES,
        };
        for (i, t) in surf_tris.iter().enumerate() {
            m.btri_map.insert(key3([t[0], t[1], t[2]]), i as u32);
            // Front faces point into the unmeshed region: reverse the outward input.
            m.add_face([t[0], t[2], t[1]]);
        }
        m
    }

    fn add_face(&mut self, v: [u32; 3]) {
        let id = self.faces.len() as u32;
        let k = key3(v);
        let btri = if v.iter().all(|&x| (x as usize) < self.n_surf) {
            self.btri_map.get(&k).copied().unwrap_or(u32::MAX)
        } else {
            u32::MAX
        };
        self.face_alive.push(true);
        self.open_faces += 1;
        self.faces.push(Face {
            v,
            alive: true,
            tries: 0,
            btri,
            ver: 0,
            dnear: 0.0,
        });
        for k in 0..3 {
            self.edges.insert((v[k], v[(k + 1) % 3]), id);
        }
        self.face_map.insert(k, id);
        let p = [
            self.pts[v[0] as usize],
            self.pts[v[1] as usize],
            self.pts[v[2] as usize],
        ];
        self.grid.insert(id, &Aabb::of(&p));
        for &x in &v {
            let xi = x as usize;
            self.vdeg[xi] += 1;
            if self.vdeg[xi] == 1 {
                self.vgrid.insert(x, self.pts[xi]);
            }
        }
        self.enqueue(id);
        // A neighbour in a thin wedge with the new face is queued again, under its
        // thinnest wedge now. (Every such neighbour: whether it already sat in the
        // thin-wedge class with a thinner key is not tracked, and skipping those would
        // change the order the faces are taken in.)
        for k in 0..3 {
            if let Some(&g) = self.edges.get(&(v[(k + 1) % 3], v[k])) {
                if self.thin_wedge_deg(g, id).is_some() {
                    self.faces[g as usize].ver += 1;
                    self.enqueue(g);
                }
            }
        }
    }

    /// Unmeshed dihedral angle (degrees) at the edge shared by live faces `f` and `g`.
    fn wedge_deg(&self, f: u32, g: u32) -> f64 {
        self.wedge_below(f, g, f64::INFINITY).unwrap_or(360.0)
    }

    /// [`Mesher::wedge_deg`] when it is below [`WEDGE_FIRST_DEG`] (the only wedges the
    /// queue orders by angle), else `None`.
    fn thin_wedge_deg(&self, f: u32, g: u32) -> Option<f64> {
        self.wedge_below(f, g, WEDGE_FIRST_DEG)
    }

    /// The wedge angle at the edge of `f` and `g` if it is below `limit` (at most 75° or
    /// infinite). Below 75° the angle is the one between the normals, so a cosine
    /// clearly under cos 75° settles "not below" without normalizing, the acos and the
    /// exact predicate (the margin, 2e-9, is far above the cosine's rounding error, so the
    /// outcome and the value are those of the full computation).
    fn wedge_below(&self, f: u32, g: u32, limit: f64) -> Option<f64> {
        const COS_75: f64 = 0.258_819_045_102_520_76;
        debug_assert!(limit <= WEDGE_FIRST_DEG || limit == f64::INFINITY);
        let fv = self.faces[f as usize].v;
        let gv = self.faces[g as usize].v;
        let fp = fv.map(|x| self.pts[x as usize]);
        let gp = gv.map(|x| self.pts[x as usize]);
        let (r1, r2) = (
            tri_normal(fp[0], fp[1], fp[2]),
            tri_normal(gp[0], gp[1], gp[2]),
        );
        if limit <= WEDGE_FIRST_DEG {
            let m = (norm2(r1) * norm2(r2)).sqrt();
            if m.is_finite() && -dot(r1, r2) < (COS_75 - 2e-9) * m {
                return None;
            }
        }
        let cos = (-dot(normalize(r1), normalize(r2))).clamp(-1.0, 1.0);
        let theta = cos.acos().to_degrees();
        let d = gv.iter().find(|x| !fv.contains(x))?;
        let w = if orient3d(fp[0], fp[1], fp[2], self.pts[*d as usize]) > 0 {
            theta
        } else {
            360.0 - theta
        };
        (w < limit).then_some(w)
    }

    /// Queue live face `id` under its current version: faces in a thin wedge with a
    /// neighbour first (thinnest first), then boundary faces smallest first, then interior
    /// faces smallest first (by size class, oldest first within one, on large inputs: see
    /// [`SIZE_CLASS_MIN_TRIANGLES`]).
    fn enqueue(&mut self, id: u32) {
        let f = self.faces[id as usize];
        let mut wedge = 360.0f64;
        for k in 0..3 {
            if let Some(&g) = self.edges.get(&(f.v[(k + 1) % 3], f.v[k])) {
                if let Some(w) = self.thin_wedge_deg(id, g) {
                    wedge = wedge.min(w);
                }
            }
        }
        let p = self.face_pts(id);
        let (class, key) = if wedge < WEDGE_FIRST_DEG {
            (0, wedge)
        } else if f.btri != u32::MAX {
            (1, face_size(&p))
        } else if self.size_classes {
            (2, queue::size_class(face_size(&p)))
        } else {
            (2, face_size(&p))
        };
        self.queue.push(f.tries, class, key, id, f.ver);
    }

    fn kill_face(&mut self, id: u32) {
        let f = &mut self.faces[id as usize];
        if !f.alive {
            return;
        }
        f.alive = false;
        self.open_faces -= 1;
        let v = f.v;
        self.face_alive[id as usize] = false;
        for k in 0..3 {
            let e = (v[k], v[(k + 1) % 3]);
            if self.edges.get(&e) == Some(&id) {
                self.edges.remove(&e);
            }
        }
        self.face_map.remove(&key3(v));
        // A vertex whose count drops to 0 leaves the front; `vgrid` skips it from then on.
        for &x in &v {
            self.vdeg[x as usize] -= 1;
        }
    }

    fn new_point(&mut self, p: P3) -> u32 {
        let id = self.pts.len() as u32;
        self.pts.push(p);
        self.vdeg.push(0);
        id
    }

    /// The six nodes of boundary triangle `b` (input orientation).
    fn btri_nodes(&self, b: u32) -> [P3; 6] {
        let t = &self.surf_tris[b as usize];
        std::array::from_fn(|k| self.surf_nodes[t[k] as usize])
    }

    /// Ten nodes of the P2 tet on corners `t`, with boundary mid nodes on boundary edges;
    /// `None` when every edge is straight.
    fn p2_nodes(&self, t: [u32; 4], tp: &[P3; 4]) -> Option<[P3; 10]> {
        let mut x = [[0.0; 3]; 10];
        x[..4].copy_from_slice(tp);
        let mut curved = false;
        for (k, [i, j]) in TET10_EDGES.iter().enumerate() {
            let (a, b) = (t[*i], t[*j]);
            x[4 + k] = mid(tp[*i], tp[*j]);
            if (a as usize) < self.n_surf && (b as usize) < self.n_surf {
                if let Some(&m) = self.bedge_mid.get(&(a.min(b), a.max(b))) {
                    let mp = self.surf_nodes[m as usize];
                    if mp != x[4 + k] {
                        x[4 + k] = mp;
                        curved = true;
                    }
                }
            }
        }
        curved.then_some(x)
    }

    fn run(&mut self, progress: Progress) -> Result<()> {
        let total_volume = {
            let mut v = 0.0;
            for t in self.surf_tris {
                let p = |k: usize| self.surf_nodes[t[k] as usize];
                v += det3(p(0), p(1), p(2)) / 6.0;
            }
            v.abs().max(f64::MIN_POSITIVE)
        };
        let max_steps = 200 * self.surf_tris.len() as u64 + 1_000_000;
        let max_repairs = 50 + self.surf_tris.len() as u64;
        let mut last_report = 0.0;
        // The most volume filled so far (counted in steps of PROGRESS_FRACTION), and the
        // step and work at which it was filled.
        let (mut best_volume, mut best_step, mut best_work) = (0.0f64, 0u64, 0u64);
        while let Some((tries, fid, ver)) = self.queue.pop() {
            let f = self.faces[fid as usize];
            if !f.alive || f.tries != tries || f.ver != ver {
                continue;
            }
            self.stats.steps += 1;
            if self.open_faces < self.fewest_open.0 {
                self.fewest_open = (self.open_faces, self.stats.repairs);
            }
            if self.stats.steps > max_steps {
                return Err(self.stuck_error(fid, "step limit reached"));
            }
            if self.volume_done >= best_volume + PROGRESS_FRACTION * total_volume {
                best_volume = self.volume_done;
                best_step = self.stats.steps;
                best_work = self.work;
            }
            if self.stats.steps - best_step > self.stall_limit
                || self.work - best_work > self.stall_work_limit
            {
                self.stalled = true;
                let why = format!(
                    "{} steps ({} face tests) without filling more of the volume",
                    self.stats.steps - best_step,
                    self.work - best_work
                );
                return Err(self.stuck_error(fid, &why));
            }
            if self.work > self.work_budget {
                self.stalled = true;
                let why = format!(
                    "{} face tests, the front's budget on this surface",
                    self.work
                );
                return Err(self.stuck_error(fid, &why));
            }
            // The filled fraction of the volume, never reported lower than before (local
            // remeshing deletes tets; the progress contract is non-decreasing).
            let frac = (self.volume_done / total_volume)
                .clamp(0.0, 1.0)
                .max(last_report);
            if frac - last_report >= 0.01 || self.stats.steps % 4096 == 0 {
                last_report = frac;
                if progress(frac, &self.stage) {
                    return Err(Error::Cancelled);
                }
            }
            let max_level = tries.min(2);
            let mut done = false;
            for level in 0..=max_level {
                if self.advance(fid, level) {
                    if level > 0 {
                        self.stats.relaxed[level as usize - 1] += 1;
                    }
                    done = true;
                    break;
                }
            }
            if done {
                continue;
            }
            if tries < 3 {
                let f = &mut self.faces[fid as usize];
                f.tries = tries + 1;
                f.ver += 1;
                self.enqueue(fid);
                continue;
            }
            // Stuck at every level: close its cavity exactly if it is small...
            // ...or, where the front is about to give up, by the constrained fill (it
            // closes what the search cannot; where local remeshing works, the remeshed
            // front makes better tets).
            if let Some(c) = self.component(fid, constrained::MAX_FILL_FACES) {
                if c.len() <= cavity::MAX_CAVITY_FACES && self.fill_cavity(&c) {
                    self.stats.cavities += 1;
                    continue;
                }
                let giving_up = self.stats.repairs + 1 >= max_repairs
                    || self.stats.repairs + 1 - self.fewest_open.1
                        >= self.max_repairs_without_progress
                    || self.repair_count(fid) >= repair::MAX_REPAIRS_PER_REGION;
                if self.use_fill && giving_up {
                    let fixed = self.fixed_around(&c);
                    if self.constrained_fill(&c, &fixed) {
                        self.stats.constrained += 1;
                        continue;
                    }
                }
            }
            // ...else, where remeshing has not helped, accept a tet the optimizer must
            // untangle...
            // (Right after the first failed repair when the optimizer will run; without
            // it such a tet would fail certification, so only as a late resort.)
            let late = if self.opts.optimize { 1 } else { 4 };
            if self.repair_count(fid) >= late && self.advance(fid, 3) {
                continue;
            }
            // ...else remesh around it.
            if self.stats.repairs >= max_repairs {
                return Err(self.stuck_error(fid, "repair limit reached"));
            }
            let stalled = self.stats.repairs - self.fewest_open.1;
            if stalled >= self.max_repairs_without_progress {
                let why = format!(
                    "{stalled} local remeshings without closing more of the front (it had {} \
                     faces at its fewest)",
                    self.fewest_open.0
                );
                return Err(self.stuck_error(fid, &why));
            }
            self.repair(fid)?;
        }
        Ok(())
    }

    /// Target edge length at `x`: the size field times this run's factor.
    fn size_at(&self, x: P3) -> f64 {
        self.size_near(x, 0.0).0
    }

    /// [`Mesher::size_at`] given and returning a lower bound of the distance from `x` to
    /// the nearest surface vertex ([`SizeField::at_near`]).
    fn size_near(&self, x: P3, dnear: f64) -> (f64, f64) {
        let (l, d) = self.size.at_near(x, dnear);
        (self.size_scale * l, d)
    }

    fn face_pts(&self, fid: u32) -> [P3; 3] {
        let v = self.faces[fid as usize].v;
        [
            self.pts[v[0] as usize],
            self.pts[v[1] as usize],
            self.pts[v[2] as usize],
        ]
    }

    fn stuck_error(&mut self, fid: u32, why: &str) -> Error {
        let v = self.faces[fid as usize].v;
        let c = {
            let p = self.face_pts(fid);
            centroid3(p[0], p[1], p[2])
        };
        let open = self.faces.iter().filter(|f| f.alive).count();
        if std::env::var_os("CURVETET_DIAGNOSE").is_some() {
            let comp = self.component(fid, 100_000).map_or(0, |c| c.len());
            eprintln!("stuck front component: {comp} faces");
            eprintln!("{}", self.diagnose(fid));
        }
        Error::MeshingFailed {
            msg: format!(
                "{why}: the front could not be closed near ({:.6}, {:.6}, {:.6}) at face with vertices {:?}; {open} front faces remain open",
                c[0], c[1], c[2], v
            ),
            partial: None,
        }
    }

    /// Try to build a tet on front face `fid` at relaxation `level` (an index into
    /// [`RELAXATION`]). True on success. Three stages: [`Mesher::gather`] the candidate
    /// apexes, [`Mesher::rank`] them (Algorithm 2), [`Mesher::accept`] the first that
    /// passes the exact and certified tests.
    fn advance(&mut self, fid: u32, level: u8) -> bool {
        let r = &RELAXATION[level as usize];
        let frame = self.apex_frame(fid);
        if !self.gather(fid, &frame, r) {
            return false;
        }
        let mut cands = std::mem::take(&mut self.cands);
        self.rank(&mut cands, &frame, r);
        let chosen = self.accept(fid, &frame, r, &cands);
        self.cands = cands;
        let Some(cd) = chosen else {
            return false;
        };
        let f = self.faces[fid as usize];
        let apex = if cd.id == NEW_POINT {
            self.stats.new_vertices += 1;
            self.new_point(cd.p)
        } else {
            cd.id
        };
        // (The quality measured above, of these corners in this order; NaN was scored -1.)
        let q = if cd.q >= 0.0 { cd.q } else { f64::NAN };
        self.insert_tet([f.v[0], f.v[1], f.v[2], apex], fid, q);
        true
    }

    /// Where the ideal apex of front face `fid` lies: the regular-tet height of the
    /// target size along the face's inward normal (the curved face's tangent-plane normal
    /// on a boundary face).
    fn apex_frame(&mut self, fid: u32) -> ApexFrame {
        let f = self.faces[fid as usize];
        let fp = self.face_pts(fid);
        let c = centroid3(fp[0], fp[1], fp[2]);
        let flat_n = tri_normal(fp[0], fp[1], fp[2]);
        let n = if f.btri != u32::MAX {
            // Tangent-plane normal of the curved face at its centre (outward input: negate).
            let x = self.btri_nodes(f.btri);
            let nn = normalize(scale(tri6_normal(&x, 1.0 / 3.0, 1.0 / 3.0), -1.0));
            if dot(nn, flat_n) > 0.0 {
                nn
            } else {
                normalize(flat_n)
            }
        } else {
            normalize(flat_n)
        };
        let lf = (dist(fp[0], fp[1]) + dist(fp[1], fp[2]) + dist(fp[2], fp[0])) / 3.0;
        let (l_field, dnear) = self.size_near(c, f.dnear);
        self.faces[fid as usize].dnear = dnear;
        let target = l_field.clamp(0.55 * lf, 1.8 * lf);
        let h = regular_height(target);
        ApexFrame {
            fp,
            c,
            n,
            l_field,
            target,
            h,
            ideal: axpy(c, h, n),
        }
    }

    /// Gather the candidate apexes of face `fid` into `self.cands`: front vertices near
    /// the ideal point in front of the face, the apexes of the faces across its edges,
    /// and new points on the normal. False when there is none.
    fn gather(&mut self, fid: u32, fr: &ApexFrame, r: &Relaxation) -> bool {
        let f = self.faces[fid as usize];
        let fp = fr.fp;
        let (a, h) = (fr.ideal, fr.h);
        let radius = r.search_radius * self.alpha * h;
        let min_new_dist = r.new_point_spacing * fr.l_field;
        // Candidate existing vertices.
        let mut found = std::mem::take(&mut self.found);
        self.front_vertices_within(a, radius, &mut found);
        self.cands.clear();
        let mut nearest_existing = f64::INFINITY;
        for &(id, d2) in &found {
            if f.v.contains(&id) {
                continue;
            }
            let p = self.pts[id as usize];
            nearest_existing = nearest_existing.min(d2.sqrt());
            if orient3d(fp[0], fp[1], fp[2], p) <= 0 {
                continue;
            }
            self.cands.push(Cand {
                id,
                p,
                q: 0.0,
                dist_a: d2.sqrt(),
            });
        }
        self.found = found;
        // The vertices across the face's edges (the neighbours' apexes) are always
        // candidates, however far: they are how a wedge closes, and with mixed sizes a
        // large neighbour's apex can lie outside the search radius.
        for k in 0..3 {
            let Some(&g) = self.edges.get(&(f.v[(k + 1) % 3], f.v[k])) else {
                continue;
            };
            let gv = self.faces[g as usize].v;
            let Some(&id) = gv.iter().find(|x| !f.v.contains(x)) else {
                continue;
            };
            if self.cands.iter().any(|c| c.id == id) {
                continue;
            }
            let p = self.pts[id as usize];
            if orient3d(fp[0], fp[1], fp[2], p) > 0 {
                self.cands.push(Cand {
                    id,
                    p,
                    q: 0.0,
                    dist_a: dist(p, a),
                });
            }
        }
        // New points: the ideal one, and lower ones when relaxing.
        for &s in r.new_point_heights {
            let p = axpy(fr.c, s * h, fr.n);
            // Distance to existing front vertices near the new point.
            let dmin = if s == 1.0 {
                nearest_existing
            } else {
                self.nearest_front_vertex(p, fr.target)
            };
            if dmin >= min_new_dist {
                self.cands.push(Cand {
                    id: NEW_POINT,
                    p,
                    q: 0.0,
                    dist_a: 0.0,
                });
            }
        }
        !self.cands.is_empty()
    }

    /// Score the candidates (1 - skewness, cheap floating point), drop those below the
    /// level's floors, and order them (Algorithm 2): best quality first; if the best is
    /// a new point, existing vertices closer than h to the ideal point come first,
    /// nearest first.
    fn rank(&self, cands: &mut Vec<Cand>, fr: &ApexFrame, r: &Relaxation) {
        let fp = fr.fp;
        let (min_dih, max_skew) = match r.shape_floors {
            Floors::Options => (self.opts.min_dihedral_deg, self.opts.max_skewness),
            Floors::Relaxed => (self.opts.min_dihedral_deg / 3.0, 0.97),
            Floors::None | Floors::NoneScored => (0.0, 1.0),
        };
        cands.retain_mut(|cd| {
            let tp = [fp[0], fp[1], fp[2], cd.p];
            let (mn, mx) = dihedral_extremes(&tp);
            let sk = skewness_from_extremes(mn, mx);
            cd.q = if sk.is_nan() { -1.0 } else { 1.0 - sk };
            matches!(r.shape_floors, Floors::None) || (mn >= min_dih && sk <= max_skew)
        });
        cands.sort_by(|x, y| y.q.total_cmp(&x.q).then(x.id.cmp(&y.id)));
        if let Some(first) = cands.first() {
            if first.id == NEW_POINT {
                let h = fr.h;
                let mut close: Vec<Cand> = cands
                    .iter()
                    .filter(|c| c.id != NEW_POINT && c.dist_a < h)
                    .cloned()
                    .collect();
                if !close.is_empty() {
                    close.sort_by(|x, y| x.dist_a.total_cmp(&y.dist_a).then(x.id.cmp(&y.id)));
                    let rest: Vec<Cand> = cands
                        .iter()
                        .filter(|c| c.id == NEW_POINT || c.dist_a >= h)
                        .cloned()
                        .collect();
                    close.extend(rest);
                    *cands = close;
                }
            }
        }
    }

    /// The first ranked candidate whose tet passes the exact validity test with the
    /// level's proximity and gap floors, the certified P2 test, and the look-ahead; at
    /// the levels that allow it, the first that failed only the look-ahead or the
    /// boundary gap floor.
    fn accept(&mut self, fid: u32, fr: &ApexFrame, r: &Relaxation, cands: &[Cand]) -> Option<Cand> {
        let f = self.faces[fid as usize];
        let fp = fr.fp;
        let min_gap = match r.gap_floor {
            GapFloor::Options(k) => self.opts.min_edge_face_angle_deg / k,
            GapFloor::Degrees(d) => d,
        };
        // Proximity floors: (new point, existing vertex). A new point never comes right
        // against the front, whatever the level: it would leave a sliver layer.
        let (prox_new, prox_old) = (r.proximity.0 * fr.target, r.proximity.1 * fr.target);
        let mut fallback = None;
        for cd in cands {
            let apex = cd.id;
            let t = [f.v[0], f.v[1], f.v[2], apex];
            let tp = [fp[0], fp[1], fp[2], cd.p];
            let prox = if cd.id == NEW_POINT {
                prox_new
            } else {
                prox_old
            };
            let mut bb = Aabb::of(&tp);
            for d in 0..3 {
                bb.lo[d] -= prox;
                bb.hi[d] += prox;
            }
            self.gather_near(&bb, fid);
            let pts = &self.pts;
            let pos = |i: u32| pts[i as usize];
            let Ok(verdict) = validity::check(t, tp, &self.near, pos, prox) else {
                continue;
            };
            if verdict.min_gap_deg < min_gap {
                continue;
            }
            let thin_boundary_gap = verdict.min_gap_boundary_deg < MIN_BOUNDARY_GAP_DEG;
            let mut p2_invalid = false;
            if let Some(x) = self.p2_nodes(t, &tp) {
                if !curved_valid(&x) {
                    // Last resort: a linear-valid tet whose P2 Jacobian is not positive,
                    // if it has a free mid node the optimizer can move.
                    let free_edge = TET10_EDGES.iter().any(|[i, j]| {
                        let (a, b) = (t[*i], t[*j]);
                        !((a as usize) < self.n_surf
                            && (b as usize) < self.n_surf
                            && self.bedge_mid.contains_key(&(a.min(b), a.max(b))))
                    });
                    if !r.p2_invalid_ok || !free_edge {
                        continue;
                    }
                    p2_invalid = true;
                }
            }
            // Look ahead: every thin wedge T leaves must be closable by a valid tet, with
            // T in place. (Against boundary faces at every level: those wedges can never
            // be reopened.)
            let mut closable = true;
            for i in 0..verdict.num_closings {
                if !self.closing_ok(verdict.closings[i], t, cd.p) {
                    closable = false;
                    break;
                }
            }
            if (!closable || thin_boundary_gap) && !r.p2_invalid_ok {
                // A candidate that fails only the look-ahead or the boundary gap floor is
                // still taken, where the level allows, when nothing else passes: the wedge
                // it leaves may close another way, and a stuck face certainly does not.
                if r.fallback_ok && fallback.is_none() && !p2_invalid {
                    fallback = Some(*cd);
                }
                continue;
            }
            if p2_invalid {
                self.stats.p2_invalid += 1;
            }
            return Some(*cd);
        }
        fallback
    }

    /// Can the thin wedge between front face `c[0..3]` and candidate tet `t` (apex
    /// position `apex`) be closed by tet `c` once `t` is in place? Exact validity against
    /// the front around both, with `t`'s new faces added, and certified P2 validity.
    fn closing_ok(&mut self, c: [u32; 4], t: [u32; 4], apex: P3) -> bool {
        let pos = |v: u32, pts: &[P3]| {
            if v == NEW_POINT {
                apex
            } else {
                pts[v as usize]
            }
        };
        let ct = c.map(|v| pos(v, &self.pts));
        if orient3d(ct[0], ct[1], ct[2], ct[3]) <= 0 {
            return false;
        }
        if !self.p2_nodes(c, &ct).map_or(true, |x| curved_valid(&x)) {
            return false;
        }
        let tp = t.map(|v| pos(v, &self.pts));
        let mut bb = Aabb::of(&ct);
        let tb = Aabb::of(&tp);
        for d in 0..3 {
            bb.lo[d] = bb.lo[d].min(tb.lo[d]);
            bb.hi[d] = bb.hi[d].max(tb.hi[d]);
        }
        let base_key = key3([c[0], c[1], c[2]]);
        let t_base = key3([t[0], t[1], t[2]]);
        let base_id = self.face_map.get(&base_key).copied().unwrap_or(u32::MAX);
        self.gather_near(&bb, base_id);
        // The front after T: T's base face gone, its new faces added.
        self.near.retain(|f| key3(f.v) != t_base);
        for g in &TET_OUT_FACES[1..] {
            let v = [t[g[0]], t[g[1]], t[g[2]]];
            let k = key3(v);
            if let Some(j) = self.near.iter().position(|f| key3(f.v) == k) {
                self.near.swap_remove(j);
            } else {
                self.near.push(FaceRef { v, boundary: false });
            }
        }
        let pts = &self.pts;
        validity::check(c, ct, &self.near, |v| pos(v, pts), 0.0).is_ok()
    }

    /// Fill `self.near` with the live front faces whose grid cells meet `bb`, except
    /// face `exclude`.
    fn gather_near(&mut self, bb: &Aabb, exclude: u32) {
        let alive = &self.face_alive;
        let mut ids = std::mem::take(&mut self.near_ids);
        self.grid.query(bb, |i| alive[i as usize], &mut ids);
        self.work += 1 + ids.len() as u64;
        self.near.clear();
        for &i in &ids {
            if i != exclude {
                let f = &self.faces[i as usize];
                self.near.push(FaceRef {
                    v: f.v,
                    boundary: f.btri != u32::MAX,
                });
            }
        }
        self.near_ids = ids;
    }

    /// The front vertices within `r` of `q`, with their squared distances, into `out`.
    fn front_vertices_within(&mut self, q: P3, r: f64, out: &mut Vec<(u32, f64)>) {
        let vdeg = &self.vdeg;
        self.vgrid
            .within(q, r, &self.pts, |v| vdeg[v as usize] > 0, out);
    }

    fn nearest_front_vertex(&mut self, p: P3, r: f64) -> f64 {
        let mut found = std::mem::take(&mut self.found);
        self.front_vertices_within(p, r, &mut found);
        let d = found
            .iter()
            .map(|x| x.1.sqrt())
            .fold(f64::INFINITY, f64::min);
        self.found = found;
        d
    }

    /// Add tet `t` on front face `base`, with its measured quality `q` (NaN: unknown).
    fn insert_tet(&mut self, t: [u32; 4], base: u32, q: f64) {
        let tp = [0, 1, 2, 3].map(|k| self.pts[t[k] as usize]);
        self.volume_done += tet_det(tp[0], tp[1], tp[2], tp[3]) / 6.0;
        self.tets.push(t);
        self.tet_q.push(q);
        self.tet_alive.push(true);
        self.kill_face(base);
        // (The point the base face's bound is for: its centroid as `advance` computes it.)
        let base_c = {
            let p = self.face_pts(base);
            centroid3(p[0], p[1], p[2])
        };
        let base_dnear = self.faces[base as usize].dnear;
        for g in &TET_OUT_FACES[1..] {
            let v = [t[g[0]], t[g[1]], t[g[2]]];
            match self.face_map.get(&key3(v)) {
                Some(&other) => self.kill_face(other),
                None => {
                    self.add_face(v);
                    // The distance to the nearest surface vertex is 1-Lipschitz; the
                    // margins cover the rounding of both distances.
                    if base_dnear > 0.0 {
                        let c = centroid3(tp[g[0]], tp[g[1]], tp[g[2]]);
                        let d = (base_dnear - 1.000001 * dist(c, base_c)) * (1.0 - 1e-9);
                        if let Some(f) = self.faces.last_mut() {
                            f.dnear = d.max(0.0);
                        }
                    }
                }
            }
        }
    }
}

/// Face size for the queue (smallest faces first): the smallest altitude, squared, so a
/// skinny face (a thin boundary strip) is meshed while its surroundings are still open.
fn face_size(p: &[P3; 3]) -> f64 {
    let l2 = dist2(p[0], p[1])
        .max(dist2(p[1], p[2]))
        .max(dist2(p[2], p[0]));
    let a2 = norm2(tri_normal(p[0], p[1], p[2])); // (2 x area)²
    if l2 > 0.0 {
        a2 / l2
    } else {
        0.0
    }
}

/// Certified positivity of a curved candidate's Jacobian (Bernstein bounds).
fn curved_valid(x: &[P3; 10]) -> bool {
    certify(x).is_valid()
}

/// A front attempt gives up (and the next [`RESTARTS`] configuration runs) after this many
/// local remeshings since the front last had fewer live faces than ever before: it is
/// cycling, deleting and refilling the same pockets. Measured with `scripts/aniso-torus.py`
/// surfaces: attempts that closed went at most 66 repairs without a new fewest (30 x 50's
/// second attempt; 8 on the hinge, 0-15 elsewhere), while the attempts that failed went on
/// 71-278 repairs past theirs (0.4-1.1 million steps at about 30 µs each, against 7 µs on
/// the 100k-tet torus) before the per-region limit stopped them: 30 x 60 took 78 s for its
/// three failed attempts and the fourth that closed, and now takes 15 s for the same mesh.
/// The last of the [`RESTARTS`] is exempt: with nothing left to restart with, it goes on.
pub const MAX_REPAIRS_WITHOUT_PROGRESS: u64 = 80;

/// Steps per surface triangle, and steps in all, that a front attempt may go without
/// filling more of the volume than ever before ([`stall_limit`]).
const STALL_STEPS_PER_TRIANGLE: u64 = 20;
const STALL_STEPS_BASE: u64 = 2_000;

/// How long a front attempt may go without filling more of the volume than it ever had
/// before; past that it is deleting and refilling the same pockets, and the region goes
/// to the whole fill instead ([`run_front`]). Measured on the OpenSCAD corpus
/// (`../shared/data/openscad`): attempts that closed went at most 14 steps per surface
/// triangle without a new most-filled volume (example018: 70,559 steps on 4,960
/// triangles; 0.5-6 on the others), while those that never closed went 40-200 per
/// triangle and on (example002: over 65,536 steps on 376 triangles, at about 150 µs
/// each). Deterministic: counted in steps, not time.
fn stall_limit(surf_tris: usize) -> u64 {
    STALL_STEPS_PER_TRIANGLE * surf_tris as u64 + STALL_STEPS_BASE
}

/// The fraction of the region's volume by which a front attempt must beat the most it
/// has ever filled for the step and work counts of [`stall_limit`] and
/// [`stall_work_limit`] to start again. Deleting and refilling the same pockets makes
/// new maxima by a few tets' volume, and each such maximum would restart the counts of an
/// attempt that is only going round. Chosen by replaying the OpenSCAD corpus's filled
/// volume with this rule: every attempt that closed still closes, those that stall stall
/// earlier (CHANGELOG has the figures); a larger margin is further from what was checked
/// on surfaces that close slowly.
const PROGRESS_FRACTION: f64 = 0.002;

/// Validity-test work per surface triangle, and in all, that a front attempt may spend
/// without filling more of the volume than ever before ([`stall_work_limit`]).
const STALL_WORK_PER_TRIANGLE: u64 = 20_000;
const STALL_WORK_BASE: u64 = 100_000_000;

/// [`stall_limit`] counted in work rather than steps: near the end of a stuck attempt
/// each step tries every relaxation level on dozens of candidates, each tested against
/// hundreds of front faces, so a step costs 100 times what it does early on and a step
/// bound alone let attempts stall for half a minute. The work is the number of front
/// faces gathered for the validity tests (plus one per gather), deterministic like the
/// step count. Measured on the OpenSCAD corpus (about 1e8 of these per second here):
/// attempts that closed went at most 8.4e7 without a new most-filled volume
/// (example018, 4,960 triangles; 5e6 or less on the others), while stuck ones went on
/// for 1e9-2e9 (linear_extrude, example024) before the step bound stopped them.
fn stall_work_limit(surf_tris: usize) -> u64 {
    STALL_WORK_PER_TRIANGLE * surf_tris as u64 + STALL_WORK_BASE
}

/// Validity-test work per surface triangle, and in all, that the front's attempts may
/// spend together before the region goes to the whole fill ([`front_work_budget`]).
const FRONT_WORK_PER_TRIANGLE: u64 = 30_000;
const FRONT_WORK_BASE: u64 = 40_000_000;

/// The validity-test work (as [`stall_work_limit`] counts it) that the front's attempts
/// may spend in all before the region goes to the whole fill ([`run_front`]). The
/// front's cost per filled tet grows as it nears a surface it cannot close: on the
/// OpenSCAD corpus the attempts that closed spent at most 7.3e4 per surface triangle
/// (example007; 5e4 or less on the others, 2.9e4 on example018's 4,960), and the ones
/// that stalled 2e4-1.2e6 (example019: 4.5e9 on 3,912 triangles, 46 s) before the stall
/// limits stopped them, a third of the corpus's time for meshes that were then thrown
/// away. Deterministic: counted in work, not time. Once the whole fill has failed, the
/// remaining attempts run without it.
fn front_work_budget(surf_tris: usize) -> u64 {
    FRONT_WORK_PER_TRIANGLE * surf_tris as u64 + FRONT_WORK_BASE
}

/// Restart schedule, as (alpha factor, size factor): when local remeshing cannot close the
/// front, the whole front runs again with a narrower, then a wider candidate search, then a
/// finer size. The front is greedy; another radius changes every choice it makes, so a
/// configuration that traps one run rarely traps the next (the hinge at alpha 2.5 closes
/// at 2.0). Deterministic: the same input always takes the same attempts; the report gives
/// the attempt that succeeded.
pub const RESTARTS: [(f64, f64); 4] = [(1.0, 1.0), (0.8, 1.0), (1.3, 1.0), (1.0, 0.85)];

/// Above this fraction of poorly shaped surface triangles (aspect ratio above
/// [`crate::surface::geometry::POOR_ASPECT_RATIO`]) the whole fill runs first, and the
/// front only where the fill fails ([`run_front`]): every front attempt would stall and
/// be thrown away. On the OpenSCAD corpus (`../shared/data/openscad`) the front closed
/// no part above 0.15 (16 parts, 0.155-0.69) and every part it closed is at or below
/// 0.095 (example014); those 16 spent 0.7-16 s each, about 75 s in all, in front
/// attempts before the whole fill that meshed them, which gives the same mesh without
/// them. Raw marching-cubes surfaces (`scripts/marching-cubes.py`) have 0.02-0.05, the
/// `scripts/aniso-torus.py` tori and the six benchmark surfaces 0-0.001.
pub const FILL_FIRST_POOR_FRACTION: f64 = 0.15;

/// Above this largest aspect ratio of a surface triangle the whole fill runs first too
/// ([`run_front`]): the front has never closed a surface with such a needle. On the
/// OpenSCAD corpus (`../shared/data/openscad`) the parts the front closes have none
/// above 234 (example014), and the four others without enough poorly shaped triangles
/// for [`FILL_FIRST_POOR_FRACTION`] but with a needle above 1,000 (example006, example010,
/// logo, logo_and_text: 1,464-49,287) spent 3-12 s each in front attempts that were then
/// thrown away; the fill's mesh is the same without them. Raw marching-cubes surfaces
/// reach 1,230 (`tests/data/mc_blob.off`), and the front closes none of those either.
pub const FILL_FIRST_WORST_ASPECT_RATIO: f64 = 1000.0;

/// Whether the whole fill runs before any front attempt ([`FILL_FIRST_POOR_FRACTION`],
/// [`FILL_FIRST_WORST_ASPECT_RATIO`]).
fn fill_first(surf_nodes: &[P3], surf_tris: &[[u32; 6]]) -> bool {
    let shape = crate::surface::geometry::triangle_shape(surf_nodes, surf_tris);
    shape.poor as f64 > FILL_FIRST_POOR_FRACTION * surf_tris.len() as f64
        || shape.worst > FILL_FIRST_WORST_ASPECT_RATIO
}

/// [`MAX_REPAIRS_WITHOUT_PROGRESS`] for attempt `attempt` ([`RESTARTS`]), except the last:
/// with nothing left to restart with, it keeps going until the per-region or overall
/// limits (a cycling attempt occasionally closes: 30 x 50's second went 66 repairs without
/// progress, then closed).
fn repairs_without_progress_limit(attempt: usize) -> u64 {
    if attempt + 1 < RESTARTS.len() {
        MAX_REPAIRS_WITHOUT_PROGRESS
    } else {
        u64::MAX
    }
}

/// The progress stage name of front attempt `attempt` (0-based, [`RESTARTS`]): "front",
/// then "front (attempt 2 of 4)" and so on, so that a restart, whose fraction starts again
/// from 0, is a new stage.
fn attempt_stage(attempt: usize) -> String {
    if attempt == 0 {
        "front".to_string()
    } else {
        format!("front (attempt {} of {})", attempt + 1, RESTARTS.len())
    }
}

/// Run the front on a checked surface's arrays, restarting per [`RESTARTS`] when it
/// cannot close, starting with attempt `first` (a caller whose later stages refuse a
/// front's result asks for the next configuration; `stats.restarts` says which one
/// succeeded).
pub fn run_front(
    surf_nodes: &[P3],
    surf_tris: &[[u32; 6]],
    opts: &Options,
    size: &SizeField,
    first: usize,
    progress: Progress,
) -> Result<FrontOutput> {
    let mut failures = Vec::new();
    let mut last_partial = None;
    // The whole fill's error, once it has been tried.
    let mut fill_failed: Option<String> = None;
    if first == 0 && fill_first(surf_nodes, surf_tris) {
        match whole_fill_stage(surf_nodes, surf_tris, opts, size, Dropped::NONE, progress)? {
            Ok(mut out) => {
                out.stats.fill_first = true;
                return Ok(out);
            }
            Err(why) => fill_failed = Some(why),
        }
    }
    // Front work spent by the attempts so far (see `front_work_budget`), and their time.
    let mut spent = 0u64;
    let mut discarded = 0.0;
    let attempts = if front_enabled() {
        RESTARTS.len()
    } else {
        first
    };
    for (attempt, &(fa, fs)) in RESTARTS.iter().enumerate().take(attempts).skip(first) {
        let mut m = Mesher::new(surf_nodes, surf_tris, opts, size);
        m.alpha = opts.alpha * fa;
        m.size_scale = fs;
        m.stats.restarts = attempt as u32;
        m.stats.alpha = m.alpha;
        m.stats.size_scale = fs;
        m.stage = attempt_stage(attempt);
        m.max_repairs_without_progress = repairs_without_progress_limit(attempt);
        m.fill_p2_invalid = attempt + 1 < RESTARTS.len();
        if fill_failed.is_none() {
            m.work_budget = front_work_budget(surf_tris.len()).saturating_sub(spent);
        }
        let clock = std::time::Instant::now();
        match m.run(progress) {
            Ok(()) => {
                // The live tets and their qualities.
                let alive = |i: &usize| m.tet_alive[*i];
                let live = || (0..m.tets.len()).filter(alive);
                let tets: Vec<[u32; 4]> = live().map(|i| m.tets[i]).collect();
                let quality: Vec<f64> = live().map(|i| m.tet_q[i]).collect();
                let mut stats = m.stats;
                stats.discarded_seconds = discarded;
                return Ok(FrontOutput {
                    pts: m.pts,
                    tets,
                    quality,
                    stats,
                });
            }
            Err(Error::MeshingFailed { msg, partial }) => {
                spent += m.work;
                discarded += clock.elapsed().as_secs_f64();
                failures.push(format!("alpha {:.3}, size x{fs}: {msg}", m.alpha));
                last_partial = partial;
                // A stalled front hands the region to the whole fill at once (tried once;
                // where it fails, the next configuration runs).
                if m.stalled && fill_failed.is_none() {
                    let before = Dropped {
                        attempts: attempt + 1,
                        seconds: discarded,
                    };
                    match whole_fill_stage(surf_nodes, surf_tris, opts, size, before, progress)? {
                        Ok(out) => return Ok(out),
                        Err(why) => fill_failed = Some(why),
                    }
                }
                if attempt + 1 < RESTARTS.len() && progress(0.0, &attempt_stage(attempt + 1)) {
                    return Err(Error::Cancelled);
                }
            }
            Err(e) => return Err(e),
        }
    }
    // Every attempt failed: the whole region at once, boundary kept.
    let why = match fill_failed {
        Some(why) => why,
        None => {
            let before = Dropped {
                attempts,
                seconds: discarded,
            };
            match whole_fill_stage(surf_nodes, surf_tris, opts, size, before, progress)? {
                Ok(out) => return Ok(out),
                Err(why) => why,
            }
        }
    };
    Err(Error::MeshingFailed {
        msg: format!(
            "{} attempts failed: {}; the whole fill failed too: {why}",
            failures.len(),
            failures.join("; ")
        ),
        partial: last_partial,
    })
}

/// The front attempts whose meshes were dropped before the whole fill ran, which its
/// stats report.
#[derive(Clone, Copy, Debug)]
struct Dropped {
    /// Attempts, counted from the first configuration (those a caller skipped included).
    attempts: usize,
    /// Seconds the attempts run here took.
    seconds: f64,
}

impl Dropped {
    /// The whole fill ran first.
    const NONE: Dropped = Dropped {
        attempts: 0,
        seconds: 0.0,
    };
}

/// The whole fill of the region ([`whole_fill`]), after the front attempts `before`.
/// The inner Err says why it failed.
fn whole_fill_stage(
    surf_nodes: &[P3],
    surf_tris: &[[u32; 6]],
    opts: &Options,
    size: &SizeField,
    before: Dropped,
    progress: Progress,
) -> Result<std::result::Result<FrontOutput, String>> {
    if progress(0.0, "whole fill") {
        return Err(Error::Cancelled);
    }
    Ok(
        whole_fill::whole_fill(surf_nodes, surf_tris, size).map(|mut out| {
            out.stats.restarts = before.attempts.saturating_sub(1) as u32;
            out.stats.discarded_seconds = before.seconds;
            out.stats.alpha = opts.alpha;
            out.stats.size_scale = 1.0;
            out
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `tests/data/NAME_p2.msh`.
    fn data_surface(name: &str) -> crate::Surface {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("tests/data/{name}_p2.msh"));
        crate::io::read_any_surface(&path, &Default::default()).expect(name)
    }

    /// A raw marching-cubes surface has few poorly shaped triangles (101 of 2,316) but a
    /// needle above [`FILL_FIRST_WORST_ASPECT_RATIO`] (1,230): the whole fill runs
    /// first. The benchmark surfaces go to the front.
    #[test]
    fn a_surface_with_an_extreme_needle_goes_to_the_whole_fill_first() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mc_blob.off");
        let s = crate::io::read_any_surface(&path, &Default::default()).unwrap();
        let shape = crate::surface::geometry::triangle_shape(s.nodes(), s.triangles());
        assert!(
            (shape.poor as f64) < FILL_FIRST_POOR_FRACTION * s.triangles().len() as f64,
            "{shape:?}"
        );
        assert!(shape.worst > FILL_FIRST_WORST_ASPECT_RATIO, "{shape:?}");
        assert!(fill_first(s.nodes(), s.triangles()));
        for name in ["sphere", "torus", "tube", "lv", "screw", "hinge"] {
            let s = data_surface(name);
            assert!(!fill_first(s.nodes(), s.triangles()), "{name}");
        }
    }

    /// The whole fill's tets go through the linear and high-order stages and the final
    /// checks like the front's: a certified, conforming mesh of the sphere.
    #[test]
    fn where_no_front_attempt_closes_the_whole_fill_meshes() {
        FRONT_OFF.with(|c| c.set(true));
        let s = data_surface("sphere");
        let g = crate::generate::generate(&s, &Options::default());
        FRONT_OFF.with(|c| c.set(false));
        let g = g.expect("the whole fill meshes the sphere");
        assert!(g.front.whole_fill, "{:?}", g.front);
        // No front attempt ran: no restart.
        assert_eq!(g.front.restarts, 0);
        let q = &g.report.quality;
        assert_eq!(g.report.num_invalid, 0);
        assert!(
            q.scaled_jacobian_certified.min > 0.3,
            "{:?}",
            q.scaled_jacobian_certified
        );
    }

    /// OpenSCAD's example022 through the whole fill, the linear and the high-order stage:
    /// every element certifies. (It first guarded the whole fill's linear bounds; since
    /// uncertified elements are straightened (`generate::straighten_uncertified`) it
    /// passes without them too, and `whole_fill`'s flat-pass test guards those.)
    #[test]
    fn a_whole_fill_of_a_cad_part_certifies() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/openscad/example022.stl");
        let s = crate::io::read_any_surface(&path, &Default::default()).expect("example022");
        FRONT_OFF.with(|c| c.set(true));
        let g = crate::generate::generate(&s, &Options::default());
        FRONT_OFF.with(|c| c.set(false));
        let g = g.unwrap_or_else(|e| panic!("the whole fill fails on example022: {e}"));
        assert!(g.front.whole_fill, "{:?}", g.front);
        assert_eq!(g.report.num_invalid, 0);
        assert!(g.report.quality.scaled_jacobian_certified.min > 0.0);
    }

    /// OpenSCAD's offset: the first attempt cycles near the end, and each of those steps
    /// tests dozens of candidates against hundreds of faces; the work bound ends it
    /// before the step bound would (which ran for 15,041 steps past the best volume).
    #[test]
    fn a_cycling_attempt_stalls_by_its_work_before_its_step_bound() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/openscad/offset.stl");
        let s = crate::io::read_any_surface(&path, &Default::default()).expect("offset");
        let opts = Options::default();
        let size = crate::generate::size_field(&s, &opts);
        let mut m = Mesher::new(s.nodes(), s.triangles(), &opts, &size);
        let Err(Error::MeshingFailed { msg, .. }) = m.run(&mut |_, _| false) else {
            panic!("offset's first attempt was expected to stall");
        };
        assert!(m.stalled, "{msg}");
        let steps: u64 = msg
            .split(' ')
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{msg}"));
        assert!(steps <= m.stall_limit, "{msg}");
    }

    /// OpenSCAD's example002: the first attempt fills most of the volume, then spends
    /// over three times its budget in work before the stall limits stop it; the budget
    /// ends it first. example018 closes slowly (the most work per triangle of the
    /// attempts in `tests/data/openscad` that close) and still closes within it.
    #[test]
    fn the_front_stops_at_its_work_budget_and_closes_within_it_where_it_can() {
        let opts = Options::default();
        let attempt = |name: &str| {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("tests/data/openscad/{name}.stl"));
            let s = crate::io::read_any_surface(&path, &Default::default()).expect(name);
            let size = crate::generate::size_field(&s, &opts);
            let mut m = Mesher::new(s.nodes(), s.triangles(), &opts, &size);
            let budget = front_work_budget(s.triangles().len());
            m.work_budget = budget;
            let r = m.run(&mut |_, _| false);
            (r, m.stalled, m.work, budget, m.open_faces)
        };
        let (r, stalled, work, budget, _) = attempt("example002");
        let Err(Error::MeshingFailed { msg, .. }) = r else {
            panic!("example002's first attempt was expected to fail");
        };
        assert!(stalled && msg.contains("budget"), "{msg}");
        assert!(
            work > budget && work < budget + budget / 10,
            "{work} {budget}"
        );
        let (r, _, work, budget, open) = attempt("example018");
        assert!(r.is_ok() && open == 0, "{:?}", r.err());
        assert!(work <= budget, "{work} {budget}");
    }

    #[test]
    fn the_constrained_fill_closes_where_the_front_would_give_up() {
        FILL_OFF.with(|c| c.set(false));
        let s = data_surface("screw");
        let opts = Options::default();
        let size = crate::generate::size_field(&s, &opts);
        // No local remeshing allowed: without the fill this gives up (the next test).
        let mut m = Mesher::new(s.nodes(), s.triangles(), &opts, &size);
        m.max_repairs_without_progress = 0;
        m.run(&mut |_, _| false).expect("the fill closes the screw");
        assert!(m.stats.constrained > 0, "{:?}", m.stats);
        assert_eq!(m.stats.repairs, 0, "{:?}", m.stats);
        assert_eq!(m.open_faces, 0);
    }

    #[test]
    fn an_attempt_that_stops_closing_the_front_gives_up() {
        // The repair path, as it runs where the fill cannot close a cavity.
        FILL_OFF.with(|c| c.set(true));
        let s = data_surface("screw");
        let opts = Options::default();
        let size = crate::generate::size_field(&s, &opts);
        // The screw's first attempt closes after two repairs; the open-face count it
        // keeps agrees with the faces.
        let mut m = Mesher::new(s.nodes(), s.triangles(), &opts, &size);
        m.run(&mut |_, _| false).expect("the screw closes");
        assert!(m.stats.repairs > 0, "{:?}", m.stats);
        assert_eq!(m.open_faces, m.faces.iter().filter(|f| f.alive).count());
        assert_eq!(m.open_faces, 0);
        assert!(m.fewest_open.0 > 0 && m.fewest_open.1 <= m.stats.repairs);
        // With no repair allowed past the fewest open faces, the first repair ends it.
        let mut m = Mesher::new(s.nodes(), s.triangles(), &opts, &size);
        m.max_repairs_without_progress = 0;
        let err = m.run(&mut |_, _| false).expect_err("gives up").to_string();
        assert!(
            err.contains("local remeshings without closing more of the front"),
            "{err}"
        );
        assert_eq!(m.stats.repairs, 0, "{:?}", m.stats);
    }

    #[test]
    fn only_the_last_attempt_keeps_cycling() {
        let n = RESTARTS.len();
        assert!(
            (0..n - 1).all(|a| repairs_without_progress_limit(a) == MAX_REPAIRS_WITHOUT_PROGRESS)
        );
        assert_eq!(repairs_without_progress_limit(n - 1), u64::MAX);
    }

    /// (fraction, stage) of every progress call of `run_front` from attempt `first`.
    fn progress_of(s: &crate::Surface, first: usize) -> (Vec<(f64, String)>, FrontStats) {
        let opts = Options::default();
        let size = crate::generate::size_field(s, &opts);
        let mut calls = Vec::new();
        let out = run_front(
            s.nodes(),
            s.triangles(),
            &opts,
            &size,
            first,
            &mut |f, st| {
                calls.push((f, st.to_string()));
                false
            },
        )
        .expect("closes");
        (calls, out.stats)
    }

    #[test]
    fn progress_never_goes_back_within_a_stage_and_names_the_attempt() {
        // Local remeshing is what can make the filled volume drop: without the fill.
        FILL_OFF.with(|c| c.set(true));
        // The hinge's front remeshes locally (deleting tets, so the filled volume drops).
        let (calls, stats) = progress_of(&data_surface("hinge"), 0);
        assert!(stats.repairs > 10, "{stats:?}");
        assert!(calls.len() > 50 && calls.iter().all(|c| c.1 == "front"));
        for w in calls.windows(2) {
            assert!(w[1].0 >= w[0].0, "{} then {}", w[0].0, w[1].0);
        }
        // A later attempt is a stage of its own (its fraction starts from 0 again).
        let (calls, stats) = progress_of(&data_surface("screw"), 1);
        assert_eq!(stats.restarts, 1);
        assert!(!calls.is_empty());
        assert!(
            calls.iter().all(|c| c.1 == "front (attempt 2 of 4)"),
            "{calls:?}"
        );
    }
}
