//! Mesh files in and out: Gmsh .msh (2.2 and 4.1, ASCII and binary), VTK .vtu (XML) and
//! legacy .vtk, and medit .mesh; linear triangle surfaces from STL, OFF, OBJ and PLY.
//!
//! | format | read | write |
//! |---|---|---|
//! | `.msh` | 2.2 (also 2.0/2.1) and 4.1, ASCII and binary, either endianness | 4.1 (default) or 2.2, ASCII (default) or binary |
//! | `.vtu` | ASCII, inline base64 `binary` and `appended` (raw or base64) arrays; UInt32/UInt64 header; uncompressed, zlib or LZ4 | ASCII (default) or inline base64 binary |
//! | `.vtk` | legacy ASCII and BINARY `UNSTRUCTURED_GRID`, classic and 5.x `CELLS` layouts | legacy ASCII (version 4.2 layout) |
//! | `.mesh` | ASCII medit (`Triangles`, `TrianglesP2`, `Tetrahedra`, `TetrahedraP2`) | ASCII medit, P2 (default) or linear |
//! | `.stl` | ASCII and binary (3-node triangles, vertices welded exactly) | — |
//! | `.off` | ASCII OFF and its COFF/NOFF/... variants, polygons split as fans | — |
//! | `.obj` | `v` and `f` lines (`i`, `i/t`, `i//n`, `i/t/n`, negative indices), fans | — |
//! | `.ply` | ASCII, binary little and big endian; `vertex` x y z, `face` index lists, fans | — |
//!
//! The linear formats hold only 3-node triangles ([`RawMesh::tri3`]); a linear surface
//! becomes a P2 [`Surface`](crate::Surface) through [`read_any_surface`] (which curves it,
//! see [`crate::surface::curve`]). Their vertices are welded exactly: identical
//! coordinates become one vertex, and coordinates are kept bit-identical (`f32` values
//! convert to `f64` exactly).
//!
//! Readers keep 3- and 6-node triangles and 4- and 10-node tetrahedra, converted to
//! curvetet's (Gmsh) node order through [`order`]; other elements are counted in
//! [`RawMesh::ignored_elements`]. Malformed input gives [`Error::Parse`] with `file:LINE`
//! (text) or `file: byte N` (binary); it never panics, and no header count makes a reader
//! reserve more memory than the file's size justifies.
//!
//! What the writers put in a file:
//! Every boundary part and the volume is a physical group with a positive number (see
//! [`Groups`]): a positive triangle tag is its own group's number (so tags read back
//! unchanged); tags <= 0 take the first free numbers (untagged triangles, tag 0, become
//! group 1 named `boundary` when 1 is free); the volume's number is
//! [`Groups::volume_tag`] (the input's, default [`VOLUME_TAG`]).
//! - `.msh`: one surface entity per group, in that physical group; one volume entity in
//!   the volume's group; `$PhysicalNames` with the input's names, `boundary` for the
//!   untagged triangles and `volume` for an unnamed volume.
//! - `.vtu`/`.vtk`: one unstructured grid holding both the tetrahedra (type 24) and the
//!   boundary triangles (type 22), with an Int32 cell array `BoundaryTag` that holds each
//!   triangle's group number and 0 for the tetrahedra (ParaView and meshio read mixed
//!   cells; use a Threshold on the cell type or the tag to see one or the other); a
//!   `.vtu` names the groups in field data arrays (name -> (number, dimension)), read back
//!   into [`RawMesh::physical_names`].
//! - A mesh of several regions ([`TetMesh::tet_regions`]): each region is a volume group
//!   numbered by its id and named as the input named it, else `region_ID`; in `.msh` one
//!   volume entity per region, in `.vtu`/`.vtk` each tetrahedron's `BoundaryTag` holds its
//!   region id (instead of 0), in `.mesh` its reference. The interface triangles between
//!   two regions are boundary triangles like the others, listed once.
//! - `.mesh`: `Vertices` (reference 0), `TrianglesP2` with reference = group number, and
//!   `TetrahedraP2` with the volume's number, in the order established in [`order`];
//!   with [`WriteOptions::medit_linear`], `Triangles` and `Tetrahedra` on the corner nodes
//!   instead (for meshio, MMG, TetGen, which do not read the P2 sections).

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result, SurfaceDefect};
use crate::geom::P3;
use crate::mesh::TetMesh;

mod atomic;
mod cursor;
mod groups;
mod linear;
mod lines;
mod medit;
mod msh_read;
mod msh_types;
mod msh_write;
mod obj;
mod off;
pub mod order;
mod ply;
mod stl;
mod surface;
mod text_out;
mod vtk;
mod vtk_cells;
mod vtu;
mod vtu_data;
mod vtu_write;
mod weld;

pub use atomic::{check_output_dir, remove_unfinished_temporaries, same_file, write_atomic};
pub use groups::{
    Groups, PhysicalName, DEFAULT_VOLUME_NAME, REGION_NAME_PREFIX, UNTAGGED_BOUNDARY_NAME,
};
pub use surface::{
    read_any_surface, read_surface, surface_from_raw, surface_from_raw_any,
    surface_from_raw_with_repair,
};

/// The physical (msh) and reference (medit) tag written for the tetrahedra.
pub const VOLUME_TAG: i32 = 1;

/// Everything a mesh file can hold that curvetet uses. Node indices are 0-based into
/// `nodes`; element nodes are in curvetet's (Gmsh) order whatever the file's format.
///
/// Nodes keep the file's numbering: in .msh files they are numbered by ascending node
/// tag (tags 1..N become indices 0..N-1; sparse tags keep their order), in .vtu/.vtk
/// and .mesh files they are in file order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawMesh {
    /// Node coordinates.
    pub nodes: Vec<[f64; 3]>,
    /// 3-node triangles.
    pub tri3: Vec<[u32; 3]>,
    /// One tag per 3-node triangle.
    pub tri3_tags: Vec<i32>,
    /// 6-node triangles, Gmsh order: corners, then mid nodes of (0,1), (1,2), (2,0).
    pub tri6: Vec<[u32; 6]>,
    /// One tag per 6-node triangle.
    pub tri6_tags: Vec<i32>,
    /// 4-node tetrahedra.
    pub tet4: Vec<[u32; 4]>,
    /// One tag per 4-node tetrahedron.
    pub tet4_tags: Vec<i32>,
    /// 10-node tetrahedra, Gmsh order: corners, then mid nodes of (0,1), (1,2), (2,0),
    /// (3,0), (3,2), (3,1).
    pub tet10: Vec<[u32; 10]>,
    /// One tag per 10-node tetrahedron.
    pub tet10_tags: Vec<i32>,
    /// Elements of other kinds (points, lines, quads, ...) that were skipped.
    pub ignored_elements: u64,
    /// Named physical groups (Gmsh `$PhysicalNames`), in file order.
    pub physical_names: Vec<PhysicalName>,
    /// The volume entities a Gmsh 4.1 surface file lists (`$Entities`), with their
    /// bounding surfaces: which regions of a surface of several regions to mesh, and
    /// their numbers ([`crate::MeshInput`]). Empty for other files and for files with
    /// tetrahedra.
    pub volumes: Vec<VolumeEntity>,
    /// With `volumes`: the surface entity tag of each 3-node triangle.
    pub tri3_entities: Vec<i32>,
    /// With `volumes`: the surface entity tag of each 6-node triangle.
    pub tri6_entities: Vec<i32>,
}

/// A Gmsh volume entity of a surface file (`$Entities` of MSH 4.1).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VolumeEntity {
    /// The entity's tag.
    pub tag: i32,
    /// Its physical tags (physical volumes it is in).
    pub physical: Vec<i32>,
    /// The tags of its bounding surface entities, sorted, without orientation signs.
    pub surfaces: Vec<i32>,
}

impl RawMesh {
    /// The volume's tag and the group names: the tag of the first 10-node (else 4-node)
    /// tetrahedron when positive; else (a surface, or tets tagged 0 as in a .vtu) the
    /// only named volume group if there is exactly one; else [`VOLUME_TAG`].
    pub fn groups(&self) -> Groups {
        let from_tets = self
            .tet10_tags
            .first()
            .or(self.tet4_tags.first())
            .copied()
            .filter(|&t| t > 0);
        let mut volumes = self.physical_names.iter().filter(|n| n.dim == 3);
        let named = match (volumes.next(), volumes.next()) {
            (Some(n), None) if n.tag > 0 => Some(n.tag),
            _ => None,
        };
        let tets = !self.tet10_tags.is_empty() || !self.tet4_tags.is_empty();
        Groups {
            volume_tag: if tets { from_tets.or(named) } else { named }.unwrap_or(VOLUME_TAG),
            names: self.physical_names.clone(),
        }
    }

    /// The P2 mesh in it: nodes, 10-node tets and 6-node boundary triangles with tags.
    /// Tets with several distinct positive tags are a mesh of several regions: their tags
    /// become [`TetMesh::tet_regions`].
    ///
    /// A file with only 3-node triangles is a linear surface:
    /// `Error::InvalidSurface(LinearSurface)`; 4-node tets without 10-node ones likewise
    /// cannot make a [`TetMesh`].
    pub fn into_tet_mesh(self) -> Result<TetMesh> {
        if self.tri6.is_empty() && !self.tri3.is_empty() {
            return Err(Error::surface(
                SurfaceDefect::LinearSurface,
                format!(
                    "the file has {} 3-node triangles and no 6-node ones",
                    self.tri3.len()
                ),
            ));
        }
        if self.tet10.is_empty() && !self.tet4.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "the file has {} 4-node tetrahedra and no 10-node ones",
                self.tet4.len()
            )));
        }
        let groups = self.groups();
        let tet_regions = if self.tet10_tags.iter().all(|&t| t > 0)
            && self.tet10_tags.iter().any(|&t| t != self.tet10_tags[0])
        {
            self.tet10_tags
        } else {
            Vec::new()
        };
        Ok(TetMesh {
            nodes: self.nodes,
            tets: self.tet10,
            boundary: self.tri6,
            boundary_tags: self.tri6_tags,
            groups,
            tet_regions,
        })
    }
}

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Format {
    /// Gmsh `.msh`.
    Msh,
    /// VTK XML unstructured grid `.vtu`.
    Vtu,
    /// VTK legacy `.vtk`.
    Vtk,
    /// medit / Gamma mesh format `.mesh` (ASCII).
    Medit,
    /// STL `.stl`, ASCII or binary (linear triangles; read only).
    Stl,
    /// Object File Format `.off`, ASCII (linear polygons; read only).
    Off,
    /// Wavefront `.obj` (linear polygons; read only).
    Obj,
    /// Stanford `.ply`, ASCII or binary (linear polygons; read only).
    Ply,
}

impl Format {
    /// The format of a path, from its extension (`.msh`, `.vtu`, `.vtk`, `.mesh`, `.stl`,
    /// `.off`, `.obj`, `.ply`; any case).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("msh") => Ok(Format::Msh),
            Some("vtu") => Ok(Format::Vtu),
            Some("vtk") => Ok(Format::Vtk),
            Some("mesh") => Ok(Format::Medit),
            Some("stl") => Ok(Format::Stl),
            Some("off") => Ok(Format::Off),
            Some("obj") => Ok(Format::Obj),
            Some("ply") => Ok(Format::Ply),
            _ => Err(Error::InvalidArgument(format!(
                "{}: unknown mesh file extension (expected .msh, .vtu, .vtk, .mesh, .stl, .off, \
                 .obj or .ply)",
                path.display()
            ))),
        }
    }

    /// The usual file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Msh => "msh",
            Format::Vtu => "vtu",
            Format::Vtk => "vtk",
            Format::Medit => "mesh",
            Format::Stl => "stl",
            Format::Off => "off",
            Format::Obj => "obj",
            Format::Ply => "ply",
        }
    }

    /// Does curvetet write this format? (The linear surface formats are read only: they
    /// cannot hold P2 elements.)
    pub fn is_writable(self) -> bool {
        matches!(
            self,
            Format::Msh | Format::Vtu | Format::Vtk | Format::Medit
        )
    }
}

/// Read a mesh file; the format comes from the extension. Only a regular file (or a link
/// to one) is read: a device such as `/dev/zero`, a FIFO or a directory is an
/// [`Error::Io`] at once, and a file too large for the memory available is an error, not
/// an abort.
pub fn read(path: &Path) -> Result<RawMesh> {
    let format = Format::from_path(path)?;
    let bytes = read_regular_file(path)?;
    read_bytes(&bytes, format, &path.display().to_string())
}

/// The bytes of the regular file `path` (see [`read`]).
fn read_regular_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::{Error as IoError, ErrorKind, Read};
    // Checked before opening: opening a FIFO would wait for a writer.
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (a device, FIFO or socket)"
        };
        return Err(Error::io(
            path,
            IoError::new(ErrorKind::InvalidInput, format!("{what}; give a mesh file")),
        ));
    }
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut bytes = Vec::new();
    usize::try_from(len)
        .ok()
        .and_then(|n| bytes.try_reserve_exact(n).ok())
        .ok_or_else(|| {
            Error::io(
                path,
                IoError::new(
                    ErrorKind::OutOfMemory,
                    format!("not enough memory to read this {len}-byte file"),
                ),
            )
        })?;
    file.read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    Ok(bytes)
}

/// Read a mesh held in memory; `name` is used in error locations. Never panics, whatever
/// the bytes.
pub fn read_bytes(bytes: &[u8], format: Format, name: &str) -> Result<RawMesh> {
    let mesh = match format {
        Format::Msh => msh_read::read(bytes, name)?,
        Format::Vtu => vtu::read(bytes, name)?,
        Format::Vtk => vtk::read(bytes, name)?,
        Format::Medit => medit::read(bytes, name)?,
        Format::Stl => stl::read(bytes, name)?,
        Format::Off => off::read(bytes, name)?,
        Format::Obj => obj::read(bytes, name)?,
        Format::Ply => ply::read(bytes, name)?,
    };
    debug_assert!(indices_in_range(&mesh));
    Ok(mesh)
}

fn indices_in_range(m: &RawMesh) -> bool {
    let n = m.nodes.len() as u32;
    let ok = |s: &[u32]| s.iter().all(|&i| i < n);
    m.tri3.iter().all(|e| ok(e))
        && m.tri6.iter().all(|e| ok(e))
        && m.tet4.iter().all(|e| ok(e))
        && m.tet10.iter().all(|e| ok(e))
        && m.tri3.len() == m.tri3_tags.len()
        && m.tri6.len() == m.tri6_tags.len()
        && m.tet4.len() == m.tet4_tags.len()
        && m.tet10.len() == m.tet10_tags.len()
}

/// Gmsh .msh file format version to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MshVersion {
    /// MSH 4.1 (Gmsh's current format).
    #[default]
    V41,
    /// MSH 2.2 (the legacy format many solvers still read).
    V22,
}

impl MshVersion {
    /// The version as Gmsh writes it in `$MeshFormat`: `"4.1"` or `"2.2"`.
    pub fn as_str(self) -> &'static str {
        match self {
            MshVersion::V41 => "4.1",
            MshVersion::V22 => "2.2",
        }
    }
}

/// How to write a mesh file. `WriteOptions::default()` writes ASCII .msh 4.1; the `with_*`
/// methods change one setting each.
///
/// ```
/// use curvetet::{Format, MshVersion, WriteOptions};
///
/// let opts = WriteOptions::default().with_msh_version(MshVersion::V22).with_binary(true);
/// assert!(curvetet::io::check_write_options(Format::Msh, &opts).is_ok());
/// // Legacy .vtk is ASCII only: asking for binary is an error, not a silent fallback.
/// assert!(curvetet::io::check_write_options(Format::Vtk, &opts).is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct WriteOptions {
    /// Version of .msh files (default 4.1).
    pub msh_version: MshVersion,
    /// Binary encoding: .msh binary, or .vtu with inline base64 arrays. Not available for
    /// .vtk and .mesh (an error). Default: ASCII.
    pub binary: bool,
    /// For .mesh only: write linear `Triangles` and `Tetrahedra` (corner nodes) instead of
    /// `TrianglesP2` and `TetrahedraP2`, for tools that read only linear medit files.
    pub medit_linear: bool,
    /// For .vtu and .vtk: add the Float64 cell arrays `ScaledJacobian` (sampled min J /
    /// max J) and `EquiangularSkewness` of each tetrahedron (0 for the triangles), as the
    /// VTK filter's output has.
    pub quality_arrays: bool,
}

impl WriteOptions {
    /// With .msh version `version` ([`WriteOptions::msh_version`]).
    pub fn with_msh_version(mut self, version: MshVersion) -> Self {
        self.msh_version = version;
        self
    }

    /// With binary encoding on or off ([`WriteOptions::binary`]).
    pub fn with_binary(mut self, binary: bool) -> Self {
        self.binary = binary;
        self
    }

    /// With linear medit sections on or off ([`WriteOptions::medit_linear`]).
    pub fn with_medit_linear(mut self, linear: bool) -> Self {
        self.medit_linear = linear;
        self
    }

    /// With the per-element quality arrays of .vtu/.vtk on or off
    /// ([`WriteOptions::quality_arrays`]).
    pub fn with_quality_arrays(mut self, on: bool) -> Self {
        self.quality_arrays = on;
        self
    }
}

/// What the writers see: a validated P2 mesh or surface.
pub(crate) struct MeshView<'a> {
    pub nodes: &'a [P3],
    pub tri6: &'a [[u32; 6]],
    pub tags: &'a [i32],
    pub tet10: &'a [[u32; 10]],
    pub groups: &'a Groups,
    /// Region id per tet (positive), or empty for one volume.
    pub tet_regions: &'a [i32],
}

impl MeshView<'_> {
    fn validate(&self) -> Result<()> {
        let n = self.nodes.len();
        if n >= u32::MAX as usize {
            return Err(Error::InvalidArgument(format!("{n} nodes is too many")));
        }
        if self.tags.len() != self.tri6.len() {
            return Err(Error::InvalidArgument(format!(
                "{} triangles but {} tags",
                self.tri6.len(),
                self.tags.len()
            )));
        }
        for (i, t) in self.tri6.iter().enumerate() {
            if let Some(&v) = t.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidArgument(format!(
                    "triangle {i} refers to node {v}, but there are {n} nodes"
                )));
            }
        }
        if !self.tet_regions.is_empty() && self.tet_regions.len() != self.tet10.len() {
            return Err(Error::InvalidArgument(format!(
                "{} tetrahedra but {} region ids",
                self.tet10.len(),
                self.tet_regions.len()
            )));
        }
        if let Some(i) = self.tet_regions.iter().position(|&r| r <= 0) {
            return Err(Error::InvalidArgument(format!(
                "tetrahedron {i} has region id {}; region ids must be positive",
                self.tet_regions[i]
            )));
        }
        for (i, t) in self.tet10.iter().enumerate() {
            if let Some(&v) = t.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidArgument(format!(
                    "tetrahedron {i} refers to node {v}, but there are {n} nodes"
                )));
            }
        }
        Ok(())
    }
}

fn write_view<W: Write>(
    w: &mut W,
    format: Format,
    view: &MeshView,
    opts: &WriteOptions,
) -> std::io::Result<()> {
    // .msh writes the groups itself (entities, names); the others write each triangle's
    // physical tag (untagged triangles: the `boundary` group's number, not 0).
    let has_volume = !view.tet10.is_empty() || view.tri6.is_empty();
    let groups = groups::Resolved::new(view.tags, view.groups, has_volume, view.tet_regions);
    let tags = if format == Format::Msh {
        Vec::new()
    } else {
        groups.triangle_tags(view.tags)
    };
    let resolved = MeshView {
        tags: &tags,
        ..*view
    };
    let quality = (opts.quality_arrays
        && !view.tet10.is_empty()
        && matches!(format, Format::Vtu | Format::Vtk))
    .then(|| tet_quality_arrays(view));
    let quality = quality.as_deref();
    match format {
        Format::Msh => msh_write::write(w, view, opts),
        Format::Vtu => vtu_write::write(w, &resolved, &groups.names, quality, opts.binary),
        Format::Vtk => vtk::write(w, &resolved, quality),
        Format::Medit => medit::write(w, &resolved, groups.volume, opts.medit_linear),
        // Refused by `check_options` before any byte is written.
        Format::Stl | Format::Off | Format::Obj | Format::Ply => Err(std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "linear surface formats are read only",
        )),
    }
}

/// (scaled Jacobian, equiangular skewness) of each tetrahedron.
fn tet_quality_arrays(view: &MeshView) -> Vec<[f64; 2]> {
    use rayon::prelude::*;
    view.tet10
        .par_iter()
        .map(|t| {
            let x: [P3; 10] = std::array::from_fn(|k| view.nodes[t[k] as usize]);
            let q = crate::geom::tet_quality::tet_quality(&x);
            [q.scaled_jacobian, q.skewness]
        })
        .collect()
}

/// The id and name of each region of a mesh of several regions, as the writers name
/// them (the input's name for that volume, else `region_ID`); empty for one region.
pub fn region_names(mesh: &TetMesh) -> Vec<(i32, String)> {
    if mesh.tet_regions.is_empty() {
        return Vec::new();
    }
    let r = groups::Resolved::new(&mesh.boundary_tags, &mesh.groups, true, &mesh.tet_regions);
    r.volumes
        .iter()
        .map(|&v| {
            let name = r
                .names
                .iter()
                .find(|n| n.dim == 3 && n.tag == v)
                .map(|n| n.name.clone())
                .unwrap_or_default();
            (v, name)
        })
        .collect()
}

/// Can curvetet write `format` with `opts`? The writers check it too; this is for callers
/// that want to refuse a bad request before any work (an error naming the problem).
pub fn check_write_options(format: Format, opts: &WriteOptions) -> Result<()> {
    if !format.is_writable() {
        return Err(Error::InvalidArgument(format!(
            "cannot write the .{} extension: it is an input format for linear surfaces; write .msh, .vtu, .vtk or .mesh",
            format.extension()
        )));
    }
    if opts.binary && matches!(format, Format::Vtk | Format::Medit) {
        return Err(Error::InvalidArgument(format!(
            "binary output is not available for .{} files",
            format.extension()
        )));
    }
    Ok(())
}

fn check_options(format: Format, opts: &WriteOptions, view: &MeshView) -> Result<()> {
    check_write_options(format, opts)?;
    let biggest = view.nodes.len().max(view.tri6.len() + view.tet10.len());
    if format == Format::Msh && opts.msh_version == MshVersion::V22 && biggest >= i32::MAX as usize
    {
        return Err(Error::InvalidArgument(
            "too many nodes or elements for MSH 2.2 (32-bit tags); write MSH 4.1".into(),
        ));
    }
    Ok(())
}

fn write_file(path: &Path, view: &MeshView, opts: &WriteOptions) -> Result<()> {
    let format = Format::from_path(path)?;
    check_options(format, opts, view)?;
    view.validate()?;
    write_atomic(path, |w| write_view(w, format, view, opts))
}

/// Write a P2 tetrahedral mesh and its boundary triangles; the format comes from the
/// extension.
pub fn write_mesh(path: &Path, mesh: &TetMesh, opts: &WriteOptions) -> Result<()> {
    let view = MeshView {
        nodes: &mesh.nodes,
        tri6: &mesh.boundary,
        tags: &mesh.boundary_tags,
        tet10: &mesh.tets,
        groups: &mesh.groups,
        tet_regions: &mesh.tet_regions,
    };
    write_file(path, &view, opts)
}

/// Write a P2 surface (6-node triangles with one tag each), to `.msh`, `.vtu`, `.vtk` or
/// `.mesh`.
pub fn write_surface(
    path: &Path,
    nodes: &[[f64; 3]],
    tri6: &[[u32; 6]],
    tags: &[i32],
    opts: &WriteOptions,
) -> Result<()> {
    let view = MeshView {
        nodes,
        tri6,
        tags,
        tet10: &[],
        groups: &Groups::default(),
        tet_regions: &[],
    };
    write_file(path, &view, opts)
}

/// The bytes [`write_mesh`] would write for `format` (for tests, pipes and fuzzing).
pub fn mesh_to_bytes(mesh: &TetMesh, format: Format, opts: &WriteOptions) -> Result<Vec<u8>> {
    let view = MeshView {
        nodes: &mesh.nodes,
        tri6: &mesh.boundary,
        tags: &mesh.boundary_tags,
        tet10: &mesh.tets,
        groups: &mesh.groups,
        tet_regions: &mesh.tet_regions,
    };
    check_options(format, opts, &view)?;
    view.validate()?;
    let mut out = Vec::new();
    write_view(&mut out, format, &view, opts).expect("writing to memory cannot fail");
    Ok(out)
}
