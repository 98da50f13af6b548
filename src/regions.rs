//! Several regions, one conforming mesh.
//!
//! A surface whose triangles bound several regions — an interface between two regions
//! appears once, so the surface is non-manifold along the junctions where an interface
//! meets the outer boundary (as Gmsh physical surfaces bounding several physical
//! volumes, or a triangle soup of materials) — is split into one closed boundary per
//! region ([`crate::surface::regions`]); each region is meshed by [`generate`](crate::generate()) on its
//! own boundary, kept exactly, so the meshes share every interface node and triangle;
//! the meshes are merged into one [`TetMesh`] with a region id per tet
//! ([`TetMesh::tet_regions`]) and each interface triangle once among the boundary
//! triangles.
//!
//! [`MeshInput`] is what the command-line tool and the C ABI mesh: one closed surface
//! (possibly with cavities) takes exactly the single-surface path ([`generate`](crate::generate()) on a
//! [`Surface`]); a surface of several regions takes this one ([`generate_regions`]).
//!
//! Region ids are 1..n in the order of each region's lowest input triangle; regions are
//! named `region_ID` unless the input's physical names name volume ID. Interface
//! triangles keep their input tags; when the input has no tags at all, the outer boundary
//! stays untagged (`boundary`) and the interface between regions i < j gets its own tag
//! (2, 3, ... in order of the pairs) named `interface_i_j`.
//!
//! A linear (3-node) surface of several regions is not curved: its mid nodes are put at
//! the edge midpoints (with a warning), so the regions' boundaries agree on every edge.

use crate::front::FrontStats;
use crate::generate::{generate_with_progress, Generated, StageTimes};
use crate::geom::P3;
use crate::io::{Groups, PhysicalName, RawMesh, VolumeEntity};
use crate::mesh::merge::{merge, RegionMesh};
use crate::mesh::report::QualityReport;
use crate::mesh::{check, TetMesh};
use crate::surface::curve::CurveOptions;
use crate::surface::regions::{
    has_junction_edges, in_region, region_surface, split_regions, RegionBoundary,
};
use crate::{Error, Options, Repair, Result, Surface};

/// When a surface is taken as several regions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum RegionMode {
    /// Several regions when some edge has more than two triangles (a junction of
    /// regions) and two regions share triangles (an interface); otherwise one surface,
    /// nested shells being cavities.
    #[default]
    Auto,
    /// Every bounded region of space the triangles enclose is a region to mesh: a shell
    /// nested in another is the boundary of an inner region, not a cavity.
    EveryShell,
}

/// The warning of a linear surface of several regions.
pub const FLAT_WARNING: &str = "a linear surface of several regions is not curved: its edges \
                                stay straight (mid nodes at the edge midpoints)";

/// One region of a [`Regions`] input: its id, name and checked boundary surface.
#[derive(Debug, Clone)]
pub struct Region {
    /// The region's id (positive; its physical volume number in the outputs).
    pub id: i32,
    /// Its boundary (outer shell outward, cavity walls facing into the cavities), with
    /// its own node numbering.
    pub surface: Surface,
    /// Input node index of each node of `surface`.
    pub nodes: Vec<u32>,
    /// Input triangle index of each triangle of `surface`.
    pub triangles: Vec<u32>,
}

/// A surface of several regions, split and checked (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Regions {
    /// The input nodes and triangles (each interface once).
    nodes: Vec<P3>,
    tris: Vec<[u32; 6]>,
    n_nodes: usize,
    n_triangles: usize,
    tags: Vec<i32>,
    groups: Groups,
    regions: Vec<Region>,
    warnings: Vec<String>,
}

impl Regions {
    /// Splits P2 triangles `tris` over `nodes` (tags: one per triangle, or empty) into
    /// regions and checks each region's boundary ([`Surface::new_with_repair`]; an error
    /// names the region). Every bounded region is meshed.
    pub fn new(
        nodes: Vec<P3>,
        tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
    ) -> Result<Regions> {
        Regions::build(nodes, tris, tags, repair, None)
    }

    /// [`Regions::new`] with the volume entities of a Gmsh file (`entities`: each
    /// triangle's surface entity tag): a region whose boundary is on exactly the bounding
    /// surfaces of a volume entity takes that volume's physical tag as its id (its entity
    /// tag when it has no single physical tag), and a region no volume entity matches is
    /// a hole, not meshed (with a warning). When no region matches any volume entity, the
    /// regions are numbered 1..n (with a warning).
    pub fn with_volumes(
        nodes: Vec<P3>,
        tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        entities: &[i32],
        volumes: &[VolumeEntity],
        repair: Repair,
    ) -> Result<Regions> {
        if entities.len() != tris.len() {
            return Err(Error::InvalidArgument(format!(
                "{} surface entity tags for {} triangles",
                entities.len(),
                tris.len()
            )));
        }
        Regions::build(nodes, tris, tags, repair, Some((entities, volumes)))
    }

    fn build(
        nodes: Vec<P3>,
        tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
        gmsh: Option<(&[i32], &[VolumeEntity])>,
    ) -> Result<Regions> {
        if !tags.is_empty() && tags.len() != tris.len() {
            return Err(Error::InvalidArgument(format!(
                "{} tags for {} triangles (give one tag per triangle, or none)",
                tags.len(),
                tris.len()
            )));
        }
        crate::surface::coords::check_coordinates(&nodes)?;
        let mut split = split_regions(&nodes, &tris)?;
        let mut warnings = Vec::new();
        if let Some((entities, volumes)) = gmsh {
            match_volumes(&mut split, entities, volumes, &mut warnings);
        }
        let untagged = tags.iter().all(|&t| t == 0);
        let mut tags = if tags.is_empty() {
            vec![0; tris.len()]
        } else {
            tags
        };
        let mut groups = Groups::default();
        if untagged && split.len() > 1 {
            // Interfaces get their own tags, 2, 3, ... by region pair.
            let mut owner: Vec<Vec<i32>> = vec![Vec::new(); tris.len()];
            for r in &split {
                for &t in &r.triangles {
                    owner[t as usize].push(r.id);
                }
            }
            let mut pairs: Vec<(i32, i32)> = owner
                .iter()
                .filter(|o| o.len() == 2)
                .map(|o| (o[0].min(o[1]), o[0].max(o[1])))
                .collect();
            pairs.sort_unstable();
            pairs.dedup();
            for (t, o) in owner.iter().enumerate() {
                if o.len() == 2 {
                    let key = (o[0].min(o[1]), o[0].max(o[1]));
                    tags[t] = 2 + pairs.binary_search(&key).expect("a listed pair") as i32;
                }
            }
            for (k, (i, j)) in pairs.iter().enumerate() {
                groups.names.push(PhysicalName {
                    dim: 2,
                    tag: 2 + k as i32,
                    name: format!("interface_{i}_{j}"),
                });
            }
        }
        let mut regions = Vec::with_capacity(split.len());
        for r in &split {
            let (surface, map) = region_surface(&nodes, &tris, &tags, r, repair)?;
            warnings.extend(
                surface
                    .warnings()
                    .iter()
                    .map(|w| format!("region {}: {w}", r.id)),
            );
            regions.push(Region {
                id: r.id,
                surface,
                nodes: map,
                triangles: r.triangles.clone(),
            });
        }
        Ok(Regions {
            n_nodes: nodes.len(),
            n_triangles: tris.len(),
            nodes,
            tris,
            tags,
            groups,
            regions,
            warnings,
        })
    }

    /// [`Regions::new`] on linear triangles: mid nodes at the edge midpoints (appended
    /// after `nodes`), with a warning saying the edges stay straight.
    pub fn from_linear(
        nodes: Vec<P3>,
        tri3: &[[u32; 3]],
        tags: Vec<i32>,
        repair: Repair,
    ) -> Result<Regions> {
        let (nodes, tris) = flat_p2(nodes, tri3)?;
        let mut r = Regions::new(nodes, tris, tags, repair)?;
        r.warnings.insert(0, FLAT_WARNING.to_string());
        Ok(r)
    }

    /// These regions with the group names `groups` (as read from the input file): its
    /// named volumes name the regions of the same id, its named surfaces the tags.
    pub fn with_groups(mut self, groups: Groups) -> Regions {
        let generated = std::mem::take(&mut self.groups.names);
        self.groups = groups;
        for n in generated {
            if self.groups.name(n.dim, n.tag).is_none() {
                self.groups.names.push(n);
            }
        }
        self
    }

    /// The regions, by id.
    pub fn regions(&self) -> &[Region] {
        &self.regions
    }

    /// The group names the merged mesh is written with.
    pub fn groups(&self) -> &Groups {
        &self.groups
    }

    /// Warnings raised while checking the regions (each names its region).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of input triangles (each interface counted once).
    pub fn num_triangles(&self) -> usize {
        self.n_triangles
    }

    /// The input nodes.
    pub fn nodes(&self) -> &[P3] {
        &self.nodes
    }

    /// The input triangles, as given (each interface once).
    pub fn triangles(&self) -> &[[u32; 6]] {
        &self.tris
    }

    /// One tag per input triangle (interfaces of an untagged input have their own; see
    /// the [module docs](self)).
    pub fn tags(&self) -> &[i32] {
        &self.tags
    }
}

/// Gives each region of `split` the id of the Gmsh volume entity bounded by exactly its
/// boundary's surface entities, and drops the regions no volume entity matches (holes);
/// leaves the ids 1..n when none matches (see [`Regions::with_volumes`]).
fn match_volumes(
    split: &mut Vec<RegionBoundary>,
    entities: &[i32],
    volumes: &[VolumeEntity],
    warnings: &mut Vec<String>,
) {
    let matched: Vec<Option<i32>> = split
        .iter()
        .map(|r| {
            let mut set: Vec<i32> = r
                .triangles
                .iter()
                .map(|&t| entities[t as usize].saturating_abs())
                .collect();
            set.sort_unstable();
            set.dedup();
            volumes
                .iter()
                .find(|v| v.surfaces == set)
                .map(|v| match v.physical[..] {
                    [p] if p > 0 => p,
                    _ => v.tag.max(1),
                })
        })
        .collect();
    if matched.iter().all(Option::is_none) {
        warnings.push(format!(
            "the file's {} volume entities are bounded by none of the {} regions' surfaces: \
             the regions are numbered 1..{}",
            volumes.len(),
            split.len(),
            split.len()
        ));
        return;
    }
    let holes: Vec<i32> = split
        .iter()
        .zip(&matched)
        .filter(|(_, m)| m.is_none())
        .map(|(r, _)| r.id)
        .collect();
    if !holes.is_empty() {
        warnings.push(format!(
            "{} of {} regions are holes (no volume entity of the file is bounded by their \
             surfaces): not meshed",
            holes.len(),
            split.len()
        ));
    }
    let mut k = 0;
    split.retain_mut(|r| {
        let m = matched[k];
        k += 1;
        match m {
            Some(id) => {
                r.id = id;
                true
            }
            None => false,
        }
    });
}

/// 6-node triangles with straight edges from 3-node ones: one new node at the midpoint
/// of each corner edge.
fn flat_p2(mut nodes: Vec<P3>, tri3: &[[u32; 3]]) -> Result<(Vec<P3>, Vec<[u32; 6]>)> {
    use std::collections::HashMap;
    let n = nodes.len();
    if let Some((t, &v)) = tri3
        .iter()
        .enumerate()
        .find_map(|(t, x)| x.iter().find(|&&v| v as usize >= n).map(|v| (t, v)))
    {
        return Err(Error::surface(
            crate::SurfaceDefect::IndexOutOfRange,
            format!("triangle {t}: node index {v} is out of range ({n} nodes)"),
        ));
    }
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    let mut tris = Vec::with_capacity(tri3.len());
    for t in tri3 {
        let mut m = [0u32; 3];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            m[k] = *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                nodes.push(crate::geom::vec3::mid(nodes[a as usize], nodes[b as usize]));
                nodes.len() as u32 - 1
            });
        }
        tris.push([t[0], t[1], t[2], m[0], m[1], m[2]]);
    }
    Ok((nodes, tris))
}

/// What one region's meshing gave (part of [`Generated::regions`]).
#[derive(Debug, Clone, serde::Serialize)]
#[non_exhaustive]
pub struct RegionResult {
    /// The region's id.
    pub id: i32,
    /// Its name in the outputs.
    pub name: String,
    /// The quality of its tets.
    pub report: QualityReport,
    /// Its front's counters.
    pub front: FrontStats,
    /// Its stage times.
    pub times: StageTimes,
    /// Its uniform (or smallest graded) size.
    pub size: f64,
}

/// A surface to mesh: one closed surface, or several regions.
#[derive(Debug, Clone)]
pub enum MeshInput {
    /// One closed surface (possibly with cavities): [`generate`](crate::generate()).
    Surface(Surface),
    /// Several regions: [`generate_regions`].
    Regions(Regions),
}

impl From<Surface> for MeshInput {
    fn from(s: Surface) -> MeshInput {
        MeshInput::Surface(s)
    }
}

impl From<Regions> for MeshInput {
    fn from(r: Regions) -> MeshInput {
        MeshInput::Regions(r)
    }
}

impl MeshInput {
    /// The input of a [`RawMesh`] (`name` for messages): its P2 triangles, or its linear
    /// ones curved with `curve` (as [`crate::io::surface_from_raw_any`]), unless they
    /// bound several regions (under `mode`), which are split ([`Regions`]).
    pub fn from_raw(
        raw: RawMesh,
        name: &str,
        curve: &CurveOptions,
        mode: RegionMode,
    ) -> Result<MeshInput> {
        let linear = raw.tri6.is_empty() && !raw.tri3.is_empty();
        if !MeshInput::several_regions(&raw, mode) {
            return crate::io::surface_from_raw_any(raw, name, curve).map(MeshInput::Surface);
        }
        let groups = raw.groups();
        let regions = if linear && raw.volumes.len() >= 2 {
            let (nodes, tris) = flat_p2(raw.nodes, &raw.tri3)?;
            let mut r = Regions::with_volumes(
                nodes,
                tris,
                raw.tri3_tags,
                &raw.tri3_entities,
                &raw.volumes,
                curve.repair,
            )?;
            r.warnings.insert(0, FLAT_WARNING.to_string());
            Ok(r)
        } else if linear {
            Regions::from_linear(raw.nodes, &raw.tri3, raw.tri3_tags, curve.repair)
        } else if raw.volumes.len() >= 2 {
            Regions::with_volumes(
                raw.nodes,
                raw.tri6,
                raw.tri6_tags,
                &raw.tri6_entities,
                &raw.volumes,
                curve.repair,
            )
        } else {
            Regions::new(raw.nodes, raw.tri6, raw.tri6_tags, curve.repair)
        }
        .map_err(|e| named(e, name))?;
        Ok(MeshInput::Regions(regions.with_groups(groups)))
    }

    /// Do the triangles of `raw` (6-node, else 3-node) bound several regions under
    /// `mode`? [`RegionMode::Auto`]: some edge has more than two triangles and the
    /// triangles split into regions of which two share a triangle (an interface; bodies
    /// merely touching along an edge are not regions, and a surface that does not split
    /// is left to the single-surface checks, which name its defect).
    /// [`RegionMode::EveryShell`]: the triangles split into more than one region. A
    /// volume mesh's file never does (its boundary is one surface).
    pub fn several_regions(raw: &RawMesh, mode: RegionMode) -> bool {
        if !raw.tet4.is_empty() || !raw.tet10.is_empty() {
            return false;
        }
        let linear = raw.tri6.is_empty() && !raw.tri3.is_empty();
        let junctions = if linear {
            has_junction_edges(&raw.tri3)
        } else {
            has_junction_edges(&raw.tri6)
        };
        let gmsh_volumes = raw.volumes.len() >= 2;
        if !junctions && mode == RegionMode::Auto && !gmsh_volumes {
            return false;
        }
        let split = if linear {
            split_regions(&raw.nodes, &raw.tri3)
        } else {
            split_regions(&raw.nodes, &raw.tri6)
        };
        let Ok(split) = split else {
            return false;
        };
        if gmsh_volumes {
            return split.len() > 1;
        }
        match mode {
            RegionMode::EveryShell => split.len() > 1,
            RegionMode::Auto => {
                let mut seen = vec![false; raw.tri3.len().max(raw.tri6.len())];
                split.iter().flat_map(|r| &r.triangles).any(|&t| {
                    let again = seen[t as usize];
                    seen[t as usize] = true;
                    again
                })
            }
        }
    }

    /// The input of P2 arrays (as [`Surface::new_with_repair`] takes them): one checked
    /// surface, or several regions under `mode` ([`MeshInput::several_regions`]).
    pub fn from_arrays(
        nodes: Vec<P3>,
        tris: Vec<[u32; 6]>,
        tags: Vec<i32>,
        repair: Repair,
        mode: RegionMode,
    ) -> Result<MeshInput> {
        let raw = RawMesh {
            nodes,
            tri6: tris,
            ..RawMesh::default()
        };
        if !MeshInput::several_regions(&raw, mode) {
            return Surface::new_with_repair(raw.nodes, raw.tri6, tags, repair)
                .map(MeshInput::Surface);
        }
        Regions::new(raw.nodes, raw.tri6, tags, repair).map(MeshInput::Regions)
    }

    /// [`MeshInput::from_raw`] on the file `path`.
    pub fn read(path: &std::path::Path, curve: &CurveOptions, mode: RegionMode) -> Result<Self> {
        let raw = crate::io::read(path)?;
        MeshInput::from_raw(raw, &path.display().to_string(), curve, mode)
    }

    /// Number of regions (1 for a surface).
    pub fn num_regions(&self) -> usize {
        match self {
            MeshInput::Surface(_) => 1,
            MeshInput::Regions(r) => r.regions.len(),
        }
    }

    /// The nodes: the surface's, or the input's of several regions.
    pub fn nodes(&self) -> &[P3] {
        match self {
            MeshInput::Surface(s) => s.nodes(),
            MeshInput::Regions(r) => r.nodes(),
        }
    }

    /// The triangles: the surface's (outward), or the input's of several regions.
    pub fn triangles(&self) -> &[[u32; 6]] {
        match self {
            MeshInput::Surface(s) => s.triangles(),
            MeshInput::Regions(r) => r.triangles(),
        }
    }

    /// One tag per triangle of [`MeshInput::triangles`].
    pub fn tags(&self) -> &[i32] {
        match self {
            MeshInput::Surface(s) => s.tags(),
            MeshInput::Regions(r) => r.tags(),
        }
    }

    /// The checks' warnings.
    pub fn warnings(&self) -> &[String] {
        match self {
            MeshInput::Surface(s) => s.warnings(),
            MeshInput::Regions(r) => r.warnings(),
        }
    }

    /// [`crate::estimated_peak_memory`] of the surface, or the sum over the regions
    /// (they are meshed one after the other, but the merged mesh holds them all).
    pub fn estimated_peak_memory(&self, opts: &Options) -> u64 {
        match self {
            MeshInput::Surface(s) => crate::generate::estimated_peak_memory(s, opts),
            MeshInput::Regions(r) => r
                .regions
                .iter()
                .map(|x| crate::generate::estimated_peak_memory(&x.surface, opts))
                .fold(0u64, u64::saturating_add),
        }
    }

    /// Number of input triangles.
    pub fn num_triangles(&self) -> usize {
        match self {
            MeshInput::Surface(s) => s.triangles().len(),
            MeshInput::Regions(r) => r.num_triangles(),
        }
    }
}

/// `e` with the input's name before a surface error's message.
fn named(e: Error, name: &str) -> Error {
    match e {
        Error::InvalidSurface { kind, msg } => Error::InvalidSurface {
            kind,
            msg: format!("{name}: {msg}"),
        },
        e => e,
    }
}

/// Meshes `input`: [`generate_with_progress`] on a surface, [`generate_regions`] on
/// several regions.
pub fn generate_input(
    input: &MeshInput,
    opts: &Options,
    progress: &mut dyn FnMut(f64, &str) -> bool,
) -> Result<Generated> {
    match input {
        MeshInput::Surface(s) => generate_with_progress(s, opts, progress),
        MeshInput::Regions(r) => generate_regions(r, opts, progress),
    }
}

/// Meshes each region of `regions` (one after the other; `progress` sees the fraction of
/// all regions and "region ID: stage") and merges the meshes (see the
/// [module docs](self)). The merged mesh passes the multi-region conformity check
/// ([`check::check_conformity_regions`]) and its tet volume equals the enclosed volume
/// (1e-10 relative), or the result is [`Error::InvalidMesh`]. [`Generated::regions`]
/// holds each region's report; `front` and `times` are summed over the regions,
/// `optimize`, `size` and `size_from` are the first region's.
pub fn generate_regions(
    regions: &Regions,
    opts: &Options,
    progress: &mut dyn FnMut(f64, &str) -> bool,
) -> Result<Generated> {
    opts.validate()?;
    let n = regions.regions.len();
    let mut done: Vec<Generated> = Vec::with_capacity(n);
    for (k, r) in regions.regions.iter().enumerate() {
        let mut cb = |f: f64, stage: &str| {
            progress(
                (k as f64 + f) / n as f64,
                &format!("region {}: {stage}", r.id),
            )
        };
        let g =
            generate_with_progress(&r.surface, opts, &mut cb).map_err(|e| in_region(e, r.id))?;
        done.push(g);
    }
    let parts: Vec<RegionMesh> = regions
        .regions
        .iter()
        .zip(&done)
        .map(|(r, g)| RegionMesh {
            id: r.id,
            mesh: &g.mesh,
            map: &r.nodes,
            triangles: &r.triangles,
        })
        .collect();
    let (mut mesh, _) = merge(regions.n_nodes, regions.n_triangles, &regions.tags, &parts);
    mesh.groups = regions.groups.clone();
    let t = std::time::Instant::now();
    let pool = crate::threads::pool(opts.threads, opts.pin_threads)?;
    let conf = pool
        .install(|| check::check_conformity_regions(&mesh, &mesh.tet_regions))
        .map_err(|e| with_mesh(e, &mesh))?;
    let rel = (conf.volume_linear - conf.enclosed_linear).abs() / conf.enclosed_linear.abs();
    if rel > 1e-10 {
        return Err(Error::InvalidMesh {
            elements: vec![],
            msg: format!(
                "the regions' tet volumes sum to {} but the outer boundary encloses {} \
                 (relative difference {rel:e})",
                conf.volume_linear, conf.enclosed_linear
            ),
            mesh: Some(Box::new(mesh)),
        });
    }
    let certify = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    // Every region's elements were certified.
    let report = pool.install(|| QualityReport::with_invalid(&mesh, 0));
    let report_time = t.elapsed().as_secs_f64();
    let resolved_names = crate::io::region_names(&mesh);
    let mut times = StageTimes::default();
    let mut front = FrontStats::default();
    let mut results = Vec::with_capacity(n);
    for (r, g) in regions.regions.iter().zip(&done) {
        add_times(&mut times, &g.times);
        add_front(&mut front, &g.front);
        results.push(RegionResult {
            id: r.id,
            name: resolved_names
                .iter()
                .find(|x| x.0 == r.id)
                .map(|x| x.1.clone())
                .unwrap_or_default(),
            report: g.report.clone(),
            front: g.front.clone(),
            times: g.times.clone(),
            size: g.size,
        });
    }
    times.certify += certify;
    times.report += report_time;
    let first = done.swap_remove(0);
    Ok(Generated {
        mesh,
        report,
        front,
        times,
        optimize: first.optimize,
        size_from: first.size_from,
        size: first.size,
        regions: results,
    })
}

fn with_mesh(e: Error, mesh: &TetMesh) -> Error {
    match e {
        Error::InvalidMesh { elements, msg, .. } => Error::InvalidMesh {
            elements,
            msg,
            mesh: Some(Box::new(mesh.clone())),
        },
        e => e,
    }
}

fn add_times(a: &mut StageTimes, b: &StageTimes) {
    a.size_field += b.size_field;
    a.front += b.front;
    a.assemble += b.assemble;
    a.optimize += b.optimize;
    a.certify += b.certify;
    a.report += b.report;
}

fn add_front(a: &mut FrontStats, b: &FrontStats) {
    a.steps += b.steps;
    a.relaxed[0] += b.relaxed[0];
    a.relaxed[1] += b.relaxed[1];
    a.new_vertices += b.new_vertices;
    a.repairs += b.repairs;
    a.deleted += b.deleted;
    a.cavities += b.cavities;
    a.constrained += b.constrained;
    a.whole_fill |= b.whole_fill;
    a.whole_fill_tries
        .extend(b.whole_fill_tries.iter().cloned());
    a.p2_invalid += b.p2_invalid;
    a.restarts += b.restarts;
    a.discarded_seconds += b.discarded_seconds;
    a.alpha = b.alpha;
    a.size_scale = b.size_scale;
}
