//! `curvetet_mesh`: a generated, certified P2 tetrahedral mesh behind an opaque handle,
//! `curvetet_generate`, and the accessors.

use super::guard::{check_ptr, copy_out, deref, invalid, status_call, value_call, Failure};
use super::options::{check_struct_size, parse};
use super::status::{curvetet_status, CURVETET_ERR_CANCELLED};
use super::surface::{c_path, curvetet_surface, reset_out};
use crate::io::order::{tet10_to, Convention};
use crate::io::{MshVersion, WriteOptions};
use crate::mesh::report::{element_qualities, QualityReport};
use crate::{generate_input, Error, Generated};
use std::ffi::{c_char, c_int, CString};
use std::mem::{offset_of, size_of};
use std::sync::OnceLock;

/// A generated quadratic (10-node) tetrahedral mesh, certified valid, with its quality
/// report. Opaque. Immutable, so it may be read from several threads at once.
#[allow(non_camel_case_types)] // the C name fixed by the ABI contract
pub struct curvetet_mesh {
    pub(crate) generated: Generated,
    /// The region id of each tet (for one region: the volume's physical tag).
    regions: Vec<i32>,
    /// The JSON report, made on first request.
    json: OnceLock<CString>,
}

/// Node order of the 10-node tetrahedra handed out by `curvetet_mesh_tets`. Both orders
/// have the corners first and then the mid-edge nodes of edges (0,1), (1,2), (2,0); they
/// differ in the last three.
#[allow(non_camel_case_types)] // the C names fixed by the ABI contract
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum curvetet_node_order {
    /// Gmsh element type 11: then edges (3,0), (3,2), (3,1).
    CURVETET_ORDER_GMSH = 0,
    /// VTK cell type 24 (VTK_QUADRATIC_TETRA): then edges (0,3), (1,3), (2,3), i.e. Gmsh's
    /// order with the last two nodes swapped.
    CURVETET_ORDER_VTK = 1,
}

/// A `curvetet_node_order` as received from C (any `int` may arrive; an out-of-range
/// value in a Rust enum would be undefined behaviour). Shown as `curvetet_node_order` in
/// the header (cbindgen.toml renames it).
#[repr(transparent)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeOrderArg(pub c_int);

/// Quality of a mesh (see `curvetet_mesh_quality`). Angles in degrees.
#[allow(non_camel_case_types)] // the C name fixed by the ABI contract
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct curvetet_quality {
    /// Set to `sizeof(curvetet_quality)` before calling `curvetet_mesh_quality`.
    pub struct_size: u32,
    /// Number of tetrahedra.
    pub num_tets: u64,
    /// Tetrahedra whose Jacobian is not certified positive (0 for a returned mesh).
    pub num_invalid: u64,
    /// Smallest scaled Jacobian (min J / max J over the element, sampled).
    pub min_scaled_jacobian: f64,
    /// Mean scaled Jacobian.
    pub mean_scaled_jacobian: f64,
    /// Smallest certified lower bound of the scaled Jacobian (Bernstein coefficients).
    pub min_scaled_jacobian_certified: f64,
    /// Largest equiangular skewness (0 best, 1 degenerate).
    pub max_skewness: f64,
    /// Smallest dihedral angle.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle.
    pub max_dihedral_deg: f64,
}

/// `sizeof(curvetet_quality)` of the first version of the ABI.
pub const QUALITY_SIZE_V1: usize =
    offset_of!(curvetet_quality, max_dihedral_deg) + size_of::<f64>();

/// Flag of `curvetet_mesh_write_with_flags`: binary output (.msh binary, .vtu with
/// base64 arrays); an error for .vtk and .mesh.
pub const CURVETET_WRITE_BINARY: u32 = 1;
/// Flag of `curvetet_mesh_write_with_flags`: Gmsh MSH 2.2 instead of 4.1 (.msh only).
pub const CURVETET_WRITE_MSH22: u32 = 2;
/// Flag of `curvetet_mesh_write_with_flags`: linear `Triangles`/`Tetrahedra` (corner
/// nodes) instead of the P2 sections (.mesh only), for tools that read only linear medit.
pub const CURVETET_WRITE_MEDIT_LINEAR: u32 = 4;

impl curvetet_quality {
    fn of(r: &QualityReport) -> curvetet_quality {
        let q = &r.quality;
        curvetet_quality {
            struct_size: size_of::<curvetet_quality>() as u32,
            num_tets: r.num_tets as u64,
            num_invalid: r.num_invalid as u64,
            min_scaled_jacobian: q.scaled_jacobian.min,
            mean_scaled_jacobian: q.scaled_jacobian.mean,
            min_scaled_jacobian_certified: q.scaled_jacobian_certified.min,
            max_skewness: q.skewness.max,
            min_dihedral_deg: q.min_dihedral.min,
            max_dihedral_deg: q.max_dihedral.max,
        }
    }
}

/// Generate a certified quadratic tetrahedral mesh of surface `s`.
///
/// `opt` may be NULL (defaults). The progress callback, if any, is called from the
/// calling thread; a nonzero return stops the work promptly with
/// `CURVETET_ERR_CANCELLED`. Several calls may run at once on the same surface (from
/// different threads); the result depends only on the surface and the options (not on
/// `threads`).
///
/// On success `*out` is a new mesh the caller owns (free it with `curvetet_mesh_free`).
/// On failure `*out` is NULL and the status is `CURVETET_ERR_INVALID_ARGUMENT` (NULL `s`
/// or `out`, bad `struct_size`, an option out of range), `CURVETET_ERR_MESHING_FAILED`
/// (the front could not be closed; the message says where), `CURVETET_ERR_INVALID_MESH`
/// (the final certification failed: a bug guard) or `CURVETET_ERR_CANCELLED`.
///
/// # Safety
/// `s` must be NULL or a live surface, not freed during the call; a non-NULL `opt` must
/// point to at least `opt->struct_size` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn curvetet_generate(
    s: *const curvetet_surface,
    opt: *const super::options::curvetet_options,
    out: *mut *mut curvetet_mesh,
) -> curvetet_status {
    status_call("curvetet_generate", || {
        // SAFETY: checked inside.
        unsafe { reset_out(out)? };
        // SAFETY: live by contract.
        let s = unsafe { deref(s, "s")? };
        // SAFETY: struct_size readable bytes by contract.
        let parsed = unsafe { parse(opt)? };
        let mut last: (f64, String) = (0.0, String::new());
        let result = match parsed.progress {
            None => generate_input(&s.input, &parsed.options, &mut |_, _| false),
            Some(cb) => {
                let user = parsed.user_data;
                let mut stage_c = CString::default();
                let mut progress = |fraction: f64, stage: &str| -> bool {
                    if stage != last.1 {
                        last.1 = stage.to_string();
                        stage_c = CString::new(stage.replace('\0', "")).unwrap_or_default();
                    }
                    last.0 = fraction;
                    // SAFETY: a C function pointer the caller gave us, with its own
                    // user_data; `stage_c` outlives the call.
                    unsafe { cb(user, fraction, stage_c.as_ptr()) != 0 }
                };
                generate_input(&s.input, &parsed.options, &mut progress)
            }
        };
        let generated = match result {
            Ok(g) => g,
            Err(Error::Cancelled) => {
                return Err(Failure {
                    status: CURVETET_ERR_CANCELLED,
                    msg: format!(
                        "cancelled by the progress callback (stage \"{}\", fraction {:.3})",
                        last.1, last.0
                    ),
                })
            }
            Err(e) => return Err(e.into()),
        };
        let mesh = &generated.mesh;
        let regions = if mesh.tet_regions.is_empty() {
            let tag = mesh.groups.volume_tag;
            let tag = if tag > 0 { tag } else { crate::io::VOLUME_TAG };
            vec![tag; mesh.tets.len()]
        } else {
            mesh.tet_regions.clone()
        };
        let m = curvetet_mesh {
            generated,
            regions,
            json: OnceLock::new(),
        };
        // SAFETY: `out` checked by reset_out.
        unsafe { *out = Box::into_raw(Box::new(m)) };
        Ok(())
    })
}

/// Free a mesh. NULL is fine. Pointers obtained from it (nodes, report) become invalid.
///
/// # Safety
/// `m` must be NULL or a mesh from this library not yet freed, not in use elsewhere.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_free(m: *mut curvetet_mesh) {
    if !m.is_null() {
        value_call("curvetet_mesh_free", (), || {
            // SAFETY: created by Box::into_raw in curvetet_generate, not yet freed.
            drop(unsafe { Box::from_raw(m) });
            Ok(())
        })
    }
}

/// Number of nodes (corners and mid-edge nodes). The surface's nodes come first, with
/// the same indices and bit-identical coordinates. 0 if `m` is NULL (and the last error
/// message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_num_nodes(m: *const curvetet_mesh) -> usize {
    value_call("curvetet_mesh_num_nodes", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(m, "m")? }.generated.mesh.nodes.len())
    })
}

/// The node coordinates: `3 * curvetet_mesh_num_nodes(m)` doubles (x0, y0, z0, x1, ...),
/// owned by `m` and valid until `curvetet_mesh_free(m)`. NULL if `m` is NULL (and the
/// last error message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_nodes(m: *const curvetet_mesh) -> *const f64 {
    value_call("curvetet_mesh_nodes", std::ptr::null(), || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        Ok(m.generated.mesh.nodes.as_ptr().cast::<f64>())
    })
}

/// Number of 10-node tetrahedra; 0 if `m` is NULL (and the last error message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_num_tets(m: *const curvetet_mesh) -> usize {
    value_call("curvetet_mesh_num_tets", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(m, "m")? }.generated.mesh.tets.len())
    })
}

/// Copy the tetrahedra into `out`, which must hold `10 * curvetet_mesh_num_tets(m)`
/// 0-based node indices, in node order `order`. Tetrahedra are positively oriented.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `m` or `out` is NULL or `order` is not a
/// `curvetet_node_order` value.
///
/// # Safety
/// `m` must be a live mesh and `out` hold the count above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_tets(
    m: *const curvetet_mesh,
    order: NodeOrderArg,
    out: *mut u32,
) -> curvetet_status {
    status_call("curvetet_mesh_tets", || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        let convention = match order.0 {
            0 => Convention::Gmsh,
            1 => Convention::Vtk,
            v => {
                return Err(invalid(format!(
                    "order is {v}; expected CURVETET_ORDER_GMSH (0) or CURVETET_ORDER_VTK (1)"
                ))
                .into())
            }
        };
        check_ptr(out.cast_const(), "out")?;
        for (i, t) in m.generated.mesh.tets.iter().enumerate() {
            let t = tet10_to(convention, t);
            // SAFETY: `out` holds 10 * num_tets elements by contract; non-NULL, aligned.
            unsafe { std::ptr::copy_nonoverlapping(t.as_ptr(), out.add(10 * i), 10) };
        }
        Ok(())
    })
}

/// Number of regions of the mesh (distinct region ids, `curvetet_mesh_tet_regions`): 1
/// for a closed surface, more for a surface of several regions; 0 if `m` is NULL (and the
/// last error message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_num_regions(m: *const curvetet_mesh) -> usize {
    value_call("curvetet_mesh_num_regions", 0, || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        let mut ids = m.regions.clone();
        ids.sort_unstable();
        ids.dedup();
        Ok(ids.len())
    })
}

/// Copy the region id of each tetrahedron into `out`, which must hold
/// `curvetet_mesh_num_tets(m)` ints (in the order of `curvetet_mesh_tets`). Region ids
/// are positive: 1..n for a surface of several regions (in the order of each region's
/// lowest input triangle; the physical volume numbers of the written files), and the
/// volume's physical tag (1 unless the input file numbered it) for one region.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `m` or `out` is NULL (with tets).
///
/// # Safety
/// `m` must be a live mesh and `out` hold the count above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_tet_regions(
    m: *const curvetet_mesh,
    out: *mut i32,
) -> curvetet_status {
    status_call("curvetet_mesh_tet_regions", || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        check_ptr(out.cast_const(), "out")?;
        // SAFETY: buffer size by contract; NULL/alignment checked inside.
        unsafe { copy_out(&m.regions, out, "out")? };
        Ok(())
    })
}

/// Number of boundary triangles: the input surface's triangles, each exactly once.
/// 0 if `m` is NULL (and the last error message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_num_boundary_faces(m: *const curvetet_mesh) -> usize {
    value_call("curvetet_mesh_num_boundary_faces", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(m, "m")? }.generated.mesh.boundary.len())
    })
}

/// Copy the boundary triangles: `tri6_out` receives `6 * curvetet_mesh_num_boundary_faces(m)`
/// 0-based node indices (corners, then mid nodes of (0,1), (1,2), (2,0); Gmsh and VTK
/// agree), outward; `tags_out` (may be NULL) one input tag per triangle. They are the
/// surface's triangles, with the same node indices.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `m` or `tri6_out` is NULL.
///
/// # Safety
/// `m` must be a live mesh and the buffers hold the counts above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_boundary_faces(
    m: *const curvetet_mesh,
    tri6_out: *mut u32,
    tags_out: *mut i32,
) -> curvetet_status {
    status_call("curvetet_mesh_boundary_faces", || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        check_ptr(tri6_out.cast_const(), "tri6_out")?;
        let mesh = &m.generated.mesh;
        // SAFETY: buffer sizes by contract; NULL/alignment checked inside.
        unsafe {
            copy_out(mesh.boundary.as_flattened(), tri6_out, "tri6_out")?;
            if !tags_out.is_null() {
                copy_out(&mesh.boundary_tags, tags_out, "tags_out")?;
            }
        }
        Ok(())
    })
}

/// Fill `*out` with the mesh's quality. Set `out->struct_size = sizeof(curvetet_quality)`
/// first: the library fills the fields that fit in it (an older, smaller struct gets the
/// fields it has) and sets `struct_size` to the number of bytes it filled.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `m` or `out` is NULL or
/// `out->struct_size` is smaller than the first version's (e.g. 0: not set).
///
/// # Safety
/// `m` must be a live mesh; `out` must point to `out->struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_quality(
    m: *const curvetet_mesh,
    out: *mut curvetet_quality,
) -> curvetet_status {
    status_call("curvetet_mesh_quality", || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        check_ptr(out.cast_const(), "out")?;
        // SAFETY: non-NULL, aligned; struct_size is the first field of every version.
        let size = unsafe { std::ptr::addr_of!((*out).struct_size).read() } as usize;
        check_struct_size(size, QUALITY_SIZE_V1, "curvetet_quality")?;
        let q = curvetet_quality::of(&m.generated.report);
        let filled = size.min(size_of::<curvetet_quality>());
        // Write field `$f` when the caller's struct holds it.
        macro_rules! put {
            ($f:ident) => {
                if offset_of!(curvetet_quality, $f) + size_of_val(&q.$f) <= filled {
                    // SAFETY: the field lies within the caller's `size` bytes.
                    unsafe { std::ptr::addr_of_mut!((*out).$f).write(q.$f) };
                }
            };
        }
        put!(num_tets);
        put!(num_invalid);
        put!(min_scaled_jacobian);
        put!(mean_scaled_jacobian);
        put!(min_scaled_jacobian_certified);
        put!(max_skewness);
        put!(min_dihedral_deg);
        put!(max_dihedral_deg);
        // SAFETY: as above.
        unsafe { std::ptr::addr_of_mut!((*out).struct_size).write(filled as u32) };
        Ok(())
    })
}

/// Per-element quality, in the order of `curvetet_mesh_tets`: `scaled_jacobian_out`
/// receives `curvetet_mesh_num_tets(m)` sampled scaled Jacobians (min J / max J over the
/// element; 1 for a straight-sided tet), `skewness_out` as many equiangular skewnesses
/// (paper eq. 2 on the corner tet; 0 best, 1 degenerate). Either may be NULL (not
/// wanted). Computed on each call (in parallel), so keep the result rather than call
/// it per element.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `m` is NULL or a buffer is misaligned.
///
/// # Safety
/// `m` must be a live mesh and each non-NULL buffer hold the count above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_tet_quality(
    m: *const curvetet_mesh,
    scaled_jacobian_out: *mut f64,
    skewness_out: *mut f64,
) -> curvetet_status {
    status_call("curvetet_mesh_tet_quality", || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        if scaled_jacobian_out.is_null() && skewness_out.is_null() {
            return Ok(());
        }
        let q = element_qualities(&m.generated.mesh);
        // SAFETY: each non-NULL buffer holds num_tets elements by contract; alignment
        // is checked inside.
        unsafe {
            if !scaled_jacobian_out.is_null() {
                let sj: Vec<f64> = q.iter().map(|e| e.scaled_jacobian).collect();
                copy_out(&sj, scaled_jacobian_out, "scaled_jacobian_out")?;
            }
            if !skewness_out.is_null() {
                let sk: Vec<f64> = q.iter().map(|e| e.skewness).collect();
                copy_out(&sk, skewness_out, "skewness_out")?;
            }
        }
        Ok(())
    })
}

/// Write the mesh (tetrahedra and boundary triangles with their tags) to `path`; the
/// format comes from the extension: `.msh` (Gmsh 4.1 ASCII), `.vtu`, `.vtk`, `.mesh`.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` (NULL `m` or `path`, unknown extension),
/// `CURVETET_ERR_IO` (cannot create or write the file).
///
/// # Safety
/// `m` must be a live mesh; `path` NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_write(
    m: *const curvetet_mesh,
    path: *const c_char,
) -> curvetet_status {
    // SAFETY: forwarded contract.
    unsafe { write_impl("curvetet_mesh_write", m, path, 0) }
}

/// `curvetet_mesh_write` with format flags: a bitwise OR of `CURVETET_WRITE_BINARY`,
/// `CURVETET_WRITE_MSH22` and `CURVETET_WRITE_MEDIT_LINEAR` (0: as `curvetet_mesh_write`).
///
/// Errors: as `curvetet_mesh_write`; also `CURVETET_ERR_INVALID_ARGUMENT` for unknown
/// flag bits or a flag the format does not support (binary .vtk or .mesh).
///
/// # Safety
/// `m` must be a live mesh; `path` NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_write_with_flags(
    m: *const curvetet_mesh,
    path: *const c_char,
    flags: u32,
) -> curvetet_status {
    // SAFETY: forwarded contract.
    unsafe { write_impl("curvetet_mesh_write_with_flags", m, path, flags) }
}

/// # Safety
/// As `curvetet_mesh_write`.
unsafe fn write_impl(
    func: &str,
    m: *const curvetet_mesh,
    path: *const c_char,
    flags: u32,
) -> curvetet_status {
    status_call(func, || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        // SAFETY: NUL-terminated by contract.
        let path = unsafe { c_path(path)? };
        let known = CURVETET_WRITE_BINARY | CURVETET_WRITE_MSH22 | CURVETET_WRITE_MEDIT_LINEAR;
        if flags & !known != 0 {
            return Err(invalid(format!("unknown flag bits {:#x}", flags & !known)).into());
        }
        let opts = WriteOptions {
            msh_version: if flags & CURVETET_WRITE_MSH22 != 0 {
                MshVersion::V22
            } else {
                MshVersion::V41
            },
            binary: flags & CURVETET_WRITE_BINARY != 0,
            medit_linear: flags & CURVETET_WRITE_MEDIT_LINEAR != 0,
            ..WriteOptions::default()
        };
        crate::io::write_mesh(&path, &m.generated.mesh, &opts)?;
        Ok(())
    })
}

/// The mesh's full report as a JSON object: counts, quality (min/max/mean and histograms
/// of each measure), front counters, stage times, the target size, and the library
/// version. A NUL-terminated string owned by `m`, valid until `curvetet_mesh_free(m)`.
/// NULL if `m` is NULL (and the last error message says so).
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_report_json(m: *const curvetet_mesh) -> *const c_char {
    value_call("curvetet_mesh_report_json", std::ptr::null(), || {
        // SAFETY: live by contract.
        let m = unsafe { deref(m, "m")? };
        let json = m.json.get_or_init(|| {
            let g = &m.generated;
            let v = serde_json::json!({
                "curvetet_version": env!("CARGO_PKG_VERSION"),
                "target_size": g.size,
                "report": g.report,
                "front": g.front,
                "times": g.times,
                "optimize": g.optimize,
                "regions": g.regions,
            });
            // serde_json escapes control characters, so the text has no NUL.
            CString::new(v.to_string()).unwrap_or_default()
        });
        Ok(json.as_ptr())
    })
}

/// The target edge length used: the uniform size (given or from the paper's eq. 1), or
/// the smallest boundary size when graded. 0 if `m` is NULL.
///
/// # Safety
/// `m` must be NULL or a live mesh.
#[no_mangle]
pub unsafe extern "C" fn curvetet_mesh_target_size(m: *const curvetet_mesh) -> f64 {
    value_call("curvetet_mesh_target_size", 0.0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(m, "m")? }.generated.size)
    })
}
