//! Curving a linear (3-node) triangle surface into a P2 (6-node) one: no CAD model needed.
//!
//! A segmented image gives a linear surface (marching cubes, then cleaning); STL, OFF,
//! OBJ and PLY files, MeshLab layers and VTK polydata are linear. [`curve_linear`] (also
//! [`Surface::from_linear`]) turns one into a checked P2 [`Surface`] for the mesher:
//!
//! 1. **Checks** of the linear surface (`check`): the P2 surface's checks applied to the
//!    corner triangles, with the same [`SurfaceDefect`] kinds —
//!    empty, indices, zero-area facets (by index), coordinates, unused and duplicate
//!    vertices, open / non-manifold edges and vertices, inconsistent orientation, exact
//!    self-intersection.
//! 2. **Reconstruction** (`sectors`, `tangents`): face normals; feature edges, whose
//!    dihedral angle exceeds [`CurveOptions::feature_angle_deg`]; per vertex, one normal
//!    per smooth sector of its fan (Max's weights, exact on spheres; see
//!    [`NormalWeights`]), so normals never average across a sharp edge; per smooth feature-curve vertex, the curve's tangent (circle through it
//!    and its two curve neighbours).
//! 3. **Mid nodes** (`midpoint`), one per edge:
//!    - an edge whose two end sectors are exactly planar (exact predicate) stays straight:
//!      its mid node is the chord midpoint, so flat regions stay exactly flat;
//!    - a smooth edge follows the arc leaving each end along the chord projected into that
//!      end's tangent plane ([`MidpointRule::Arc`]; exact on spheres);
//!    - a feature edge follows its feature curve: the arc with the curve's tangents at its
//!      ends (one end's only when the other is a corner; straight between two corners),
//!      then is put back into the plane of an adjacent planar region, exactly when that
//!      plane is axis-aligned (so a rim of a flat end face stays in it).
//! 4. **Guards** (`guard`): no curved triangle may bend past
//!    [`CurveOptions::min_normal_cosine`] (fold check on the order-6 lattice) and no
//!    sub-triangles may intersect; offending edges go back to straight, edge by edge,
//!    until clean.
//! 5. [`Surface::new`] checks the result, as for any P2 input (an intersection it finds
//!    sends the surface back to the guards).
//!
//! Input vertices keep their index and their bit-exact coordinates; mid nodes follow them,
//! one per edge in sorted (smaller vertex, larger vertex) order. Unless
//! [`CurveOptions::repair`] is [`Repair::Strict`], vertices no triangle uses are dropped
//! first (the others keep their order) and inconsistently oriented facets are flipped,
//! each with a warning (see [`crate::surface::repair`]).
//!
//! **Why the arc rule** (measured on the benchmark surfaces, `tests/curve.rs`, Max
//! normals): on the sphere (h = 0.2) the arc rule puts every mid node on the sphere (max
//! distance 2.2e-16; PN: 1.6e-4) and cuts the linear surface's volume error 508-fold (PN:
//! 98-fold); on the torus (h = 0.14), max distance 8.2e-4 (PN 9.7e-4) and 162-fold (PN
//! 39-fold). With exact normals the arc rule is exact on any circle, the PN midpoint is
//! not.

mod check;
mod guard;
mod midpoint;
mod sectors;
mod smooth;
mod tangents;

pub use guard::GuardCounts;

use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::vec3::{dot, normalize, scale, sub};
use crate::geom::P3;
use crate::surface::repair::{self, Done};
use crate::surface::{Repair, Surface};

use midpoint::{arc_mid, pn_mid, tangent_from_normal};

/// How a smooth (non-feature) edge's mid node is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MidpointRule {
    /// The arc with the end tangents taken from the vertex normals (exact on spheres).
    #[default]
    Arc,
    /// The PN-triangle cubic edge's midpoint, m = (a+b)/2 - (w_ab N_a + w_ba N_b)/8.
    PnTriangle,
}

/// How the normal of a vertex (of one smooth sector of its fan) is averaged from its
/// triangles' normals. Measured on the benchmark surfaces (`tests/curve.rs`, arc rule):
///
/// | surface | `Max`: volume error ratio linear/curved, max mid-node distance | `Angle` |
/// |---|---|---|
/// | sphere (analytic) | 508x, 2.2e-16 | 129x, 1.3e-3 |
/// | torus (analytic) | 162x, 8.2e-4 | 89x, 1.4e-3 |
/// | tube (cylinder mid nodes' radius error) | 5.6e-4 | 7.8e-4 |
/// | screw (volume error vs CAD) | 0.29 % | 0.15 % |
/// | hinge (min curved/chord normal cosine) | 0.56 | 0.79 |
///
/// `Max` is the default: best on the analytic surfaces. Its weights grow as 1/(edge
/// length)^2, so on meshes that mix very small and large triangles the small ones
/// dominate; `Angle` is the more even-handed choice there.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum NormalWeights {
    /// Max (1999): (u x w) / (|u|^2 |w|^2) per wedge; exact on spheres.
    #[default]
    Max,
    /// Angle-weighted face normals (Thürmer & Wüthrich 1998).
    Angle,
}

/// Options of [`curve_linear`]. `CurveOptions::default()` gives the settings that suit
/// most CAD and scanned surfaces; the `with_*` methods change one setting each.
///
/// ```
/// use curvetet::CurveOptions;
///
/// // A faceted part: treat edges sharper than 30 degrees as features, keep the rest smooth.
/// let opts = CurveOptions::default().with_feature_angle_deg(30.0);
/// assert!(opts.validate().is_ok());
/// assert!(CurveOptions::default().with_feature_angle_deg(200.0).validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CurveOptions {
    /// An edge whose two triangles' normals differ by more than this angle (degrees) is a
    /// feature (sharp) edge: normals are not averaged across it and its mid node follows
    /// the feature curve. Default 40. 180 turns feature detection off; 0 makes every
    /// non-flat edge a feature.
    pub feature_angle_deg: f64,
    /// Smallest admitted cosine between a curved triangle's normal and its chord normal on
    /// the order-6 lattice; below it, edges are straightened. Must be in (0, 1]; the
    /// surface check itself requires > 0. Default 0.25: a curved triangle may turn its
    /// normal by up to about 75 degrees, no more.
    pub min_normal_cosine: f64,
    /// How smooth edges are curved. Default [`MidpointRule::Arc`].
    pub rule: MidpointRule,
    /// How vertex normals are averaged. Default [`NormalWeights::Max`].
    pub normals: NormalWeights,
    /// Taubin smoothing iterations (λ 0.5, μ −0.53, uniform weights) on the vertices
    /// before curving; default 0: the vertices are kept. For surfaces from image
    /// segmentation, whose needle and cap triangles leave the front stuck; moves the
    /// surface.
    pub smooth_iterations: u32,
    /// Whether unused vertices are dropped and inconsistently oriented shells reoriented
    /// (with a warning), or refused ([`Repair::Strict`]). Applies to P2 input read with
    /// these options too ([`crate::io::read_any_surface`]). Default
    /// [`Repair::Unambiguous`].
    pub repair: Repair,
}

/// The most smoothing iterations [`CurveOptions::smooth_iterations`] accepts: each one
/// shrinks the surface a little, and far fewer (10) already make marching-cubes
/// triangles well shaped; a larger count is a mistake that would run for hours.
pub const MAX_SMOOTH_ITERATIONS: u32 = 1000;

impl Default for CurveOptions {
    fn default() -> Self {
        CurveOptions {
            feature_angle_deg: 40.0,
            min_normal_cosine: 0.25,
            rule: MidpointRule::Arc,
            normals: NormalWeights::Max,
            smooth_iterations: 0,
            repair: Repair::Unambiguous,
        }
    }
}

impl CurveOptions {
    /// With feature angle `deg` ([`CurveOptions::feature_angle_deg`]).
    pub fn with_feature_angle_deg(mut self, deg: f64) -> Self {
        self.feature_angle_deg = deg;
        self
    }

    /// With smallest admitted normal cosine `cos` ([`CurveOptions::min_normal_cosine`]).
    pub fn with_min_normal_cosine(mut self, cos: f64) -> Self {
        self.min_normal_cosine = cos;
        self
    }

    /// With mid-node rule `rule` ([`CurveOptions::rule`]).
    pub fn with_rule(mut self, rule: MidpointRule) -> Self {
        self.rule = rule;
        self
    }

    /// With vertex-normal weights `normals` ([`CurveOptions::normals`]).
    pub fn with_normals(mut self, normals: NormalWeights) -> Self {
        self.normals = normals;
        self
    }

    /// With `n` smoothing iterations before curving ([`CurveOptions::smooth_iterations`]).
    pub fn with_smooth_iterations(mut self, n: u32) -> Self {
        self.smooth_iterations = n;
        self
    }

    /// With repairs `repair` allowed or refused ([`CurveOptions::repair`]).
    pub fn with_repair(mut self, repair: Repair) -> Self {
        self.repair = repair;
        self
    }

    /// Check every option; a bad one is an [`Error::InvalidArgument`] naming it. Callers
    /// that read a file first (the command-line tool) call it before reading.
    pub fn validate(&self) -> Result<()> {
        if self.smooth_iterations > MAX_SMOOTH_ITERATIONS {
            return Err(Error::InvalidArgument(format!(
                "{} smoothing iterations: at most {MAX_SMOOTH_ITERATIONS} (10 is enough for \
                 marching-cubes surfaces)",
                self.smooth_iterations
            )));
        }
        if !(0.0..=180.0).contains(&self.feature_angle_deg) {
            return Err(Error::InvalidArgument(format!(
                "feature angle {} degrees: must be within 0..=180",
                self.feature_angle_deg
            )));
        }
        if self.min_normal_cosine.is_nan()
            || self.min_normal_cosine <= 0.0
            || self.min_normal_cosine > 1.0
        {
            return Err(Error::InvalidArgument(format!(
                "min_normal_cosine {}: must be in (0, 1]",
                self.min_normal_cosine
            )));
        }
        Ok(())
    }
}

/// What curving did, for reports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct CurveReport {
    /// Edges (= mid nodes).
    pub edges: usize,
    /// Feature edges among them.
    pub feature_edges: usize,
    /// Edges whose mid node ended off the chord midpoint.
    pub curved_edges: usize,
    /// Edges kept straight because they lie in a planar region.
    pub flat_edges: usize,
    /// Edges the guards sent back to straight.
    pub straightened: GuardCounts,
}

/// Curves a closed linear triangle surface into a checked P2 [`Surface`] (module docs).
///
/// `nodes` are the vertices, `tri3` the triangles (0-based, outward by the right-hand
/// rule; a consistently inward surface is flipped with a warning, as in
/// [`Surface::new`]), `tags` one per triangle or empty. Errors: the linear surface's
/// defects as [`Error::InvalidSurface`], bad options as [`Error::InvalidArgument`].
pub fn curve_linear(
    nodes: Vec<P3>,
    tri3: Vec<[u32; 3]>,
    tags: Vec<i32>,
    opts: &CurveOptions,
) -> Result<Surface> {
    curve_linear_report(nodes, tri3, tags, opts).map(|(s, _)| s)
}

/// [`curve_linear`], also saying what it did.
pub fn curve_linear_report(
    nodes: Vec<P3>,
    tri3: Vec<[u32; 3]>,
    tags: Vec<i32>,
    opts: &CurveOptions,
) -> Result<(Surface, CurveReport)> {
    opts.validate()?;
    if !tags.is_empty() && tags.len() != tri3.len() {
        return Err(Error::InvalidArgument(format!(
            "{} tags for {} triangles (give one tag per triangle, or none)",
            tags.len(),
            tri3.len()
        )));
    }
    let (mut nodes, mut tri3) = (nodes, tri3);
    let mut done = Done::default();
    if opts.repair.allowed() {
        if let Some((kept, renumbered, n)) = repair::drop_unused(&nodes, &tri3) {
            done.record_dropped(n, nodes.len(), "vertices");
            (nodes, tri3) = (kept, renumbered);
        }
    }
    let dropped = done.dropped_note();
    curve_checked(nodes, tri3, tags, opts, done).map_err(|e| dropped.explain(e))
}

/// [`curve_linear_report`] after the unused vertices were dropped (`done`).
fn curve_checked(
    nodes: Vec<P3>,
    mut tri3: Vec<[u32; 3]>,
    tags: Vec<i32>,
    opts: &CurveOptions,
    mut done: Done,
) -> Result<(Surface, CurveReport)> {
    let nodes = if opts.smooth_iterations > 0 {
        // Smooth the checked surface, then check the smoothed one (it must still be a
        // valid surface: no fold, no self-intersection).
        let check::Lifted {
            mut nodes,
            edges,
            n_input,
            ..
        } = check_repaired(nodes, &mut tri3, opts.repair, &mut done)?;
        smooth::taubin(&mut nodes, n_input, &edges, opts.smooth_iterations);
        nodes.truncate(n_input);
        nodes
    } else {
        nodes
    };
    let lifted = check_repaired(nodes, &mut tri3, opts.repair, &mut done)?;
    let check::Lifted {
        mut nodes,
        tris,
        edges,
        n_input,
    } = lifted;
    let cos_feature = opts.feature_angle_deg.to_radians().cos();
    let fnormal = sectors::face_normals(&nodes, &tris);
    let sec = sectors::sectors(&nodes, &tris, &edges, &fnormal, cos_feature, opts.normals);
    let curve = tangents::feature_tangents(&nodes, n_input, &edges, &sec.feature, cos_feature);
    let mut report = CurveReport {
        edges: edges.len(),
        feature_edges: sec.feature.iter().filter(|&&f| f).count(),
        ..CurveReport::default()
    };

    // Sector normal at v for the sector of triangle t, made perpendicular to the feature
    // curve's tangent when v is on one (the surface contains the curve).
    let normal_at = |t: u32, v: u32| -> P3 {
        let n = sec.normal[sec.at(&tris, t, v) as usize];
        match &curve[v as usize] {
            Some(c) => {
                let m = normalize(sub(n, scale(c.tangent, dot(n, c.tangent))));
                if m.iter().all(|x| x.is_finite()) && m != [0.0; 3] {
                    m
                } else {
                    n
                }
            }
            None => n,
        }
    };
    let planar_side = |t: u32, a: u32, b: u32| {
        sec.planar[sec.at(&tris, t, a) as usize] && sec.planar[sec.at(&tris, t, b) as usize]
    };

    for (e, se) in edges.iter().enumerate() {
        let [a, b] = se.nodes;
        let (pa, pb) = (nodes[a as usize], nodes[b as usize]);
        let straight = crate::geom::vec3::mid(pa, pb);
        let flat = [planar_side(se.tris[0], a, b), planar_side(se.tris[1], a, b)];
        let m = if !sec.feature[e] {
            if flat[0] && flat[1] {
                report.flat_edges += 1;
                straight
            } else {
                let t = se.tris[0];
                let (na, nb) = (normal_at(t, a), normal_at(t, b));
                match opts.rule {
                    MidpointRule::Arc => {
                        let d = sub(pb, pa);
                        arc_mid(
                            pa,
                            pb,
                            tangent_from_normal(d, na),
                            tangent_from_normal(d, nb),
                        )
                    }
                    MidpointRule::PnTriangle => pn_mid(pa, pb, na, nb),
                }
            }
        } else if flat[0] && flat[1] {
            // Where two planar regions meet, the feature curve is their straight line.
            report.flat_edges += 1;
            straight
        } else {
            let ta = curve[a as usize]
                .as_ref()
                .and_then(|c| tangents::oriented(c, b));
            let tb = curve[b as usize]
                .as_ref()
                .and_then(|c| tangents::oriented(c, a))
                .map(|t| scale(t, -1.0));
            let mut m = arc_mid(pa, pb, ta, tb);
            for (k, &t) in se.tris.iter().enumerate() {
                if flat[k] {
                    m = into_plane(m, &tris[t as usize], &nodes, fnormal[t as usize]);
                }
            }
            m
        };
        let m = if m.iter().all(|x| x.is_finite()) {
            m
        } else {
            straight
        };
        nodes[n_input + e] = m;
    }

    let ends: Vec<([u32; 2], [u32; 2])> = edges.iter().map(|e| (e.nodes, e.tris)).collect();
    let surface = loop {
        let mut state = guard::Edges {
            nodes: &mut nodes,
            tris: &tris,
            ends: &ends,
            n_input,
        };
        report.straightened.fold += guard::fold_guard(&mut state, opts.min_normal_cosine);
        match Surface::build(
            state.nodes.to_vec(),
            tris.clone(),
            tags.clone(),
            opts.repair,
            done.clone(),
        ) {
            Ok(s) => break s,
            Err(e)
                if matches!(
                    e.surface_defect(),
                    Some(SurfaceDefect::SelfIntersection | SurfaceDefect::FoldedTriangle)
                ) =>
            {
                let n = guard::intersection_pass(&mut state);
                if n == 0 {
                    return Err(e);
                }
                report.straightened.intersection += n;
            }
            Err(e) => return Err(e),
        }
    };
    report.curved_edges = (0..edges.len())
        .filter(|&e| {
            let [a, b] = edges[e].nodes;
            nodes[n_input + e] != crate::geom::vec3::mid(nodes[a as usize], nodes[b as usize])
        })
        .count();
    Ok((surface.with_chords_allowed(), report))
}

/// [`check::check_linear`]; when `repair` allows and the triangles are not consistently
/// oriented (on a closed manifold surface), each shell is made consistent (recorded in
/// `done`) and the checks run again.
fn check_repaired(
    nodes: Vec<P3>,
    tri3: &mut [[u32; 3]],
    repair: Repair,
    done: &mut Done,
) -> Result<check::Lifted> {
    if !repair.allowed() {
        return check::check_linear(nodes, tri3);
    }
    let again = nodes.clone();
    match check::check_linear(nodes, tri3) {
        Err(e) if e.surface_defect() == Some(SurfaceDefect::InconsistentOrientation) => {
            let Some(flips) = repair::consistent_flips(tri3) else {
                return Err(e);
            };
            for (t, &f) in tri3.iter_mut().zip(&flips) {
                if f {
                    repair::flip(t);
                }
            }
            done.add_flips(&flips);
            check::check_linear(again, tri3)
        }
        r => r,
    }
}

/// `m` moved into the plane of triangle `tri` (unit normal `n`): exactly, by setting the
/// shared coordinate, when the triangle's corners share one (an axis-aligned plane);
/// otherwise by projection (to rounding).
fn into_plane(m: P3, tri: &[u32; 6], nodes: &[P3], n: P3) -> P3 {
    let [a, b, c] = [0, 1, 2].map(|k| nodes[tri[k] as usize]);
    for d in 0..3 {
        if a[d] == b[d] && a[d] == c[d] {
            let mut out = m;
            out[d] = a[d];
            return out;
        }
    }
    let off = dot(sub(m, a), n);
    sub(m, scale(n, off))
}

impl Surface {
    /// A P2 surface from a closed linear triangle surface, curved with default options and
    /// feature angle `feature_angle_deg` (degrees; 40 is the usual choice): see
    /// [`curve_linear`]. This is the entry point for callers that hold a linear mesh in
    /// memory (the C ABI, VTK polydata, MeshLab layers). Input vertices keep their index
    /// and exact coordinates (unused ones are dropped, with a warning); one mid node per
    /// edge is appended after them.
    pub fn from_linear(
        nodes: Vec<P3>,
        tri3: Vec<[u32; 3]>,
        tags: Vec<i32>,
        feature_angle_deg: f64,
    ) -> Result<Surface> {
        curve_linear(
            nodes,
            tri3,
            tags,
            &CurveOptions::default().with_feature_angle_deg(feature_angle_deg),
        )
    }
}
