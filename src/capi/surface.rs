//! `curvetet_surface`: a checked, immutable P2 surface behind an opaque handle.

use super::guard::{
    check_counts, check_ptr, copy_groups, copy_out, deref, input_slice, invalid, status_call,
    times, value_call,
};
use super::status::curvetet_status;
use crate::surface::Repair;
use crate::{MeshInput, RegionMode, Result};
use std::ffi::{c_char, CStr, CString};
use std::path::PathBuf;

/// A closed quadratic (6-node) triangle surface, checked on creation (closed, manifold,
/// consistently oriented, no self-intersection, ...), or a surface of several regions
/// (materials sharing interfaces: each interface triangle given once; each region's
/// boundary checked; see `curvetet_surface_num_regions`). Opaque. Immutable once
/// created, so it may be used from several threads at once (e.g. two `curvetet_generate`
/// calls).
#[allow(non_camel_case_types)] // the C name fixed by the ABI contract
pub struct curvetet_surface {
    pub(crate) input: MeshInput,
    /// The surface's warnings as C strings (owned here, handed out by pointer).
    warnings: Vec<CString>,
}

impl curvetet_surface {
    fn new(input: MeshInput) -> curvetet_surface {
        let warnings = input
            .warnings()
            .iter()
            .map(|w| CString::new(w.replace('\0', "\\0")).unwrap_or_default())
            .collect();
        curvetet_surface { input, warnings }
    }
}

/// Store a new handle in `*out`.
///
/// # Safety
/// `out` is non-NULL and aligned (checked by the caller of this helper).
unsafe fn give(out: *mut *mut curvetet_surface, s: impl Into<MeshInput>) {
    // SAFETY: see above.
    unsafe { *out = Box::into_raw(Box::new(curvetet_surface::new(s.into()))) };
}

/// Set `*out` to NULL first, so that it is NULL on every failure.
///
/// # Safety
/// A non-NULL `out` must be valid for writing one pointer.
pub(crate) unsafe fn reset_out<T>(out: *mut *mut T) -> Result<()> {
    super::guard::check_ptr(out.cast_const(), "out")?;
    // SAFETY: non-NULL and aligned (checked); writable by contract.
    unsafe { *out = std::ptr::null_mut() };
    Ok(())
}

/// A C path string as a filesystem path (bytes on Unix, so any file name works).
///
/// # Safety
/// A non-NULL `path` must be a NUL-terminated string.
pub(crate) unsafe fn c_path(path: *const c_char) -> Result<PathBuf> {
    if path.is_null() {
        return Err(invalid("path is NULL"));
    }
    // SAFETY: non-NULL; NUL-terminated by contract.
    let c = unsafe { CStr::from_ptr(path) };
    if c.is_empty() {
        return Err(invalid("path is empty"));
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(c.to_bytes())))
    }
    #[cfg(not(unix))]
    {
        c.to_str()
            .map(PathBuf::from)
            .map_err(|_| invalid("path is not valid UTF-8"))
    }
}

/// Build a surface from arrays, copying them (the arrays may be freed afterwards).
///
/// - `xyz`: `3 * num_nodes` coordinates (x0, y0, z0, x1, ...).
/// - `tri6`: `6 * num_triangles` 0-based node indices per triangle, corners first, then
///   the mid-edge nodes of edges (0,1), (1,2), (2,0) (Gmsh's and VTK's order), outward
///   (right-hand rule). A consistently inward surface is flipped, with a warning (see
///   `curvetet_surface_num_warnings`); so are inconsistently oriented triangles, and
///   nodes no triangle uses are dropped (the others renumbered), each with a warning
///   (`curvetet_surface_from_arrays_with_flags` with `CURVETET_SURFACE_STRICT` refuses
///   both).
/// - `tags`: `num_triangles` tags (e.g. Gmsh physical tags) kept on the boundary of the
///   mesh, or NULL for all 0.
///
/// On success `*out` is a new surface the caller owns (free it with
/// `curvetet_surface_free`). On failure `*out` is NULL and the status is
/// `CURVETET_ERR_INVALID_ARGUMENT` (NULL `out`, NULL array with a nonzero count, count
/// overflow, a count above 4294967295 (node indices are 32-bit), or no memory for the
/// copy: never an abort) or `CURVETET_ERR_INVALID_SURFACE` (the message names the failing check and
/// the triangle, edge or node).
///
/// # Safety
/// Each non-NULL array must hold the number of elements stated above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_from_arrays(
    xyz: *const f64,
    num_nodes: usize,
    tri6: *const u32,
    num_triangles: usize,
    tags: *const i32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe {
        from_arrays_call(
            "curvetet_surface_from_arrays",
            xyz,
            num_nodes,
            tri6,
            num_triangles,
            tags,
            0,
            out,
        )
    }
}

/// The body of the two `curvetet_surface_from_arrays*` functions.
///
/// # Safety
/// As `curvetet_surface_from_arrays`.
#[allow(clippy::too_many_arguments)] // the C function's arguments, forwarded
unsafe fn from_arrays_call(
    name: &str,
    xyz: *const f64,
    num_nodes: usize,
    tri6: *const u32,
    num_triangles: usize,
    tags: *const i32,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    status_call(name, || {
        // SAFETY: `out` is the caller's; checked inside.
        unsafe { reset_out(out)? };
        check_counts(num_nodes, num_triangles)?;
        let n3 = times(num_nodes, 3, "num_nodes")?;
        let t6 = times(num_triangles, 6, "num_triangles")?;
        // SAFETY: lengths as documented; NULL/alignment/size checked inside.
        let (xyz, tri6) = unsafe { (input_slice(xyz, n3, "xyz")?, input_slice(tri6, t6, "tri6")?) };
        let tags = if tags.is_null() {
            Vec::new()
        } else {
            // SAFETY: as above.
            unsafe { input_slice(tags, num_triangles, "tags")? }.to_vec()
        };
        let nodes: Vec<[f64; 3]> = copy_groups(xyz, "xyz")?;
        let tris: Vec<[u32; 6]> = copy_groups(tri6, "tri6")?;
        let (repair, mode) = flags_of(flags)?;
        let s = MeshInput::from_arrays(nodes, tris, tags, repair, mode)?;
        // SAFETY: `out` checked by reset_out.
        unsafe { give(out, s) };
        Ok(())
    })
}

/// Flag of the `curvetet_surface_*_with_flags` functions: refuse a surface whose
/// triangles are inconsistently oriented (status `CURVETET_ERR_INVALID_SURFACE`, kind
/// inconsistent-orientation) or that has nodes no triangle uses (unused-node), instead of
/// reorienting the triangles or dropping the nodes with a warning (the default). A
/// consistently inside-out surface is still flipped, with a warning.
pub const CURVETET_SURFACE_STRICT: u32 = 1;

/// Flag of `curvetet_surface_from_arrays_with_flags` and `curvetet_surface_read_with_flags`:
/// take a closed shell nested in another as the boundary of an inner region to mesh, not
/// as a cavity. Without it, a surface is taken as several regions only where its
/// triangles meet at junction edges (an edge of three or more triangles) and two regions
/// share interface triangles.
pub const CURVETET_SURFACE_NESTED_REGIONS: u32 = 2;

/// The repair policy and region mode `flags` (of `curvetet_surface_*_with_flags`) ask
/// for; unknown bits are an error.
fn flags_of(flags: u32) -> Result<(Repair, RegionMode)> {
    let known = CURVETET_SURFACE_STRICT | CURVETET_SURFACE_NESTED_REGIONS;
    if flags & !known != 0 {
        return Err(invalid(format!("unknown flag bits {:#x}", flags & !known)));
    }
    let repair = if flags & CURVETET_SURFACE_STRICT != 0 {
        Repair::Strict
    } else {
        Repair::Unambiguous
    };
    let mode = if flags & CURVETET_SURFACE_NESTED_REGIONS != 0 {
        RegionMode::EveryShell
    } else {
        RegionMode::Auto
    };
    Ok((repair, mode))
}

/// The repair policy of `flags` for the linear constructor, which takes one surface only:
/// `CURVETET_SURFACE_NESTED_REGIONS` is refused there.
fn repair_of(flags: u32) -> Result<Repair> {
    if flags & CURVETET_SURFACE_NESTED_REGIONS != 0 {
        return Err(invalid(
            "CURVETET_SURFACE_NESTED_REGIONS is for curvetet_surface_from_arrays_with_flags \
             and curvetet_surface_read_with_flags",
        ));
    }
    Ok(flags_of(flags)?.0)
}

/// `curvetet_surface_from_arrays` with `flags`: 0, or a bitwise or of
/// `CURVETET_SURFACE_STRICT` and `CURVETET_SURFACE_NESTED_REGIONS` (a shell nested in
/// another bounds a region of its own rather than a cavity). Statuses as `curvetet_surface_from_arrays`, and `CURVETET_ERR_INVALID_ARGUMENT` for
/// unknown flag bits.
///
/// # Safety
/// As `curvetet_surface_from_arrays`.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_from_arrays_with_flags(
    xyz: *const f64,
    num_nodes: usize,
    tri6: *const u32,
    num_triangles: usize,
    tags: *const i32,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe {
        from_arrays_call(
            "curvetet_surface_from_arrays_with_flags",
            xyz,
            num_nodes,
            tri6,
            num_triangles,
            tags,
            flags,
            out,
        )
    }
}

/// Build a surface from a closed *linear* (3-node) triangle mesh: it is checked like a
/// P2 surface (closed, manifold, oriented, no zero-area facet, no self-intersection),
/// then curved (each edge gets a mid node on a smooth reconstruction; edges sharper than
/// `feature_angle_deg` are features whose mid nodes follow the feature curve; flat
/// regions stay flat; no curved triangle folds). The input vertices keep their indices
/// and exact coordinates; mid nodes are appended after them. Inconsistently oriented
/// facets are flipped and unused vertices dropped (the others renumbered), each with a
/// warning (`curvetet_surface_from_linear_with_flags` with `CURVETET_SURFACE_STRICT`
/// refuses both).
///
/// - `xyz`: `3 * num_nodes` coordinates; `tri3`: `3 * num_triangles` 0-based corners,
///   outward; `tags`: `num_triangles` tags or NULL; `feature_angle_deg`: e.g. 40
///   (0 < angle <= 180).
///
/// On success `*out` is a new surface the caller owns (free it with
/// `curvetet_surface_free`). On failure `*out` is NULL and the status is
/// `CURVETET_ERR_INVALID_ARGUMENT` (NULL `out`, NULL array with a nonzero count, a count
/// above 4294967295, bad angle, more than 1000 smoothing iterations) or `CURVETET_ERR_INVALID_SURFACE` (the message names the failing check and the
/// facet, edge or vertex).
///
/// # Safety
/// Each non-NULL array must hold the number of elements stated above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_from_linear(
    xyz: *const f64,
    num_nodes: usize,
    tri3: *const u32,
    num_triangles: usize,
    tags: *const i32,
    feature_angle_deg: f64,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe {
        from_linear_call(
            "curvetet_surface_from_linear",
            xyz,
            num_nodes,
            tri3,
            num_triangles,
            tags,
            feature_angle_deg,
            0,
            0,
            out,
        )
    }
}

/// [`curvetet_surface_from_linear`] after `smooth_iterations` Taubin smoothing
/// iterations of the vertices (λ 0.5, μ −0.53, uniform weights; 0: none, the same as
/// `curvetet_surface_from_linear`). For surfaces from image segmentation (marching
/// cubes), whose needle and cap triangles leave the front stuck: 10 iterations make them
/// well shaped. The vertices keep their indices but move (by a fraction of a voxel), and
/// sharp edges are rounded: not for CAD surfaces. Statuses as
/// `curvetet_surface_from_linear`; the smoothed surface is checked again.
///
/// # Safety
/// As `curvetet_surface_from_linear`.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_from_linear_smoothed(
    xyz: *const f64,
    num_nodes: usize,
    tri3: *const u32,
    num_triangles: usize,
    tags: *const i32,
    feature_angle_deg: f64,
    smooth_iterations: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe {
        from_linear_call(
            "curvetet_surface_from_linear_smoothed",
            xyz,
            num_nodes,
            tri3,
            num_triangles,
            tags,
            feature_angle_deg,
            smooth_iterations,
            0,
            out,
        )
    }
}

/// `curvetet_surface_from_linear_smoothed` with `flags`: 0, or
/// `CURVETET_SURFACE_STRICT` (refuse inconsistently oriented facets and unused vertices
/// rather than flip and drop them with a warning). Statuses as
/// `curvetet_surface_from_linear`, and `CURVETET_ERR_INVALID_ARGUMENT` for unknown flag
/// bits.
///
/// # Safety
/// As `curvetet_surface_from_linear`.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // the C function's arguments
pub unsafe extern "C" fn curvetet_surface_from_linear_with_flags(
    xyz: *const f64,
    num_nodes: usize,
    tri3: *const u32,
    num_triangles: usize,
    tags: *const i32,
    feature_angle_deg: f64,
    smooth_iterations: u32,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe {
        from_linear_call(
            "curvetet_surface_from_linear_with_flags",
            xyz,
            num_nodes,
            tri3,
            num_triangles,
            tags,
            feature_angle_deg,
            smooth_iterations,
            flags,
            out,
        )
    }
}

/// The body of the three `curvetet_surface_from_linear*` functions.
///
/// # Safety
/// As `curvetet_surface_from_linear`.
#[allow(clippy::too_many_arguments)] // the C function's arguments, forwarded
unsafe fn from_linear_call(
    name: &str,
    xyz: *const f64,
    num_nodes: usize,
    tri3: *const u32,
    num_triangles: usize,
    tags: *const i32,
    feature_angle_deg: f64,
    smooth_iterations: u32,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    status_call(name, || {
        // SAFETY: `out` is the caller's; checked inside.
        unsafe { reset_out(out)? };
        check_counts(num_nodes, num_triangles)?;
        let n3 = times(num_nodes, 3, "num_nodes")?;
        let t3 = times(num_triangles, 3, "num_triangles")?;
        // SAFETY: lengths as documented; NULL/alignment/size checked inside.
        let (xyz, tri3) = unsafe { (input_slice(xyz, n3, "xyz")?, input_slice(tri3, t3, "tri3")?) };
        let tags = if tags.is_null() {
            Vec::new()
        } else {
            // SAFETY: as above.
            unsafe { input_slice(tags, num_triangles, "tags")? }.to_vec()
        };
        let nodes: Vec<[f64; 3]> = copy_groups(xyz, "xyz")?;
        let tris: Vec<[u32; 3]> = copy_groups(tri3, "tri3")?;
        let opts = crate::surface::curve::CurveOptions::default()
            .with_feature_angle_deg(feature_angle_deg)
            .with_smooth_iterations(smooth_iterations)
            .with_repair(repair_of(flags)?);
        let s = crate::surface::curve::curve_linear(nodes, tris, tags, &opts)?;
        // SAFETY: `out` checked by reset_out.
        unsafe { give(out, s) };
        Ok(())
    })
}

/// Read a surface from a file, by extension: a P2 surface from Gmsh `.msh` (2.2/4.1,
/// ASCII/binary), VTK `.vtu`/`.vtk` or medit `.mesh`; or a linear one from `.stl`,
/// `.off`, `.obj`, `.ply` (or 3-node triangles in the formats above), which is curved as
/// in `curvetet_surface_from_linear` with a 40 degree feature angle. A volume mesh's file
/// works too (its boundary triangles are taken). The surface is checked as in
/// `curvetet_surface_from_arrays`.
///
/// On success `*out` is a new surface the caller owns (free it with
/// `curvetet_surface_free`). On failure `*out` is NULL and the status is
/// `CURVETET_ERR_INVALID_ARGUMENT` (NULL or empty `path`, NULL `out`, unknown extension),
/// `CURVETET_ERR_IO` (cannot open/read), `CURVETET_ERR_PARSE` (malformed; the message
/// gives file:line) or `CURVETET_ERR_INVALID_SURFACE`.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_read(
    path: *const c_char,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe { read_call("curvetet_surface_read", path, 0, out) }
}

/// `curvetet_surface_read` with `flags`: 0, or a bitwise or of `CURVETET_SURFACE_STRICT`
/// (refuse inconsistently oriented triangles and unused nodes rather than flip and drop
/// them with a warning) and `CURVETET_SURFACE_NESTED_REGIONS` (a shell nested in another
/// bounds a region of its own rather than a cavity). Statuses as `curvetet_surface_read`, and
/// `CURVETET_ERR_INVALID_ARGUMENT` for unknown flag bits.
///
/// # Safety
/// As `curvetet_surface_read`.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_read_with_flags(
    path: *const c_char,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    // SAFETY: forwarded as documented.
    unsafe { read_call("curvetet_surface_read_with_flags", path, flags, out) }
}

/// The body of the two `curvetet_surface_read*` functions.
///
/// # Safety
/// As `curvetet_surface_read`.
unsafe fn read_call(
    name: &str,
    path: *const c_char,
    flags: u32,
    out: *mut *mut curvetet_surface,
) -> curvetet_status {
    status_call(name, || {
        // SAFETY: checked inside.
        unsafe { reset_out(out)? };
        let (repair, mode) = flags_of(flags)?;
        let opts = crate::surface::curve::CurveOptions {
            repair,
            ..crate::surface::curve::CurveOptions::default()
        };
        // SAFETY: NUL-terminated by contract.
        let path = unsafe { c_path(path)? };
        let s = MeshInput::read(&path, &opts, mode)?;
        // SAFETY: `out` checked by reset_out.
        unsafe { give(out, s) };
        Ok(())
    })
}

/// Free a surface. NULL is fine. Meshes generated from it stay valid (they own their
/// data). The surface must not be in use by another thread (e.g. in `curvetet_generate`).
///
/// # Safety
/// `s` must be NULL or a surface from this library not yet freed.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_free(s: *mut curvetet_surface) {
    if !s.is_null() {
        value_call("curvetet_surface_free", (), || {
            // SAFETY: created by Box::into_raw in this module, not yet freed (contract).
            drop(unsafe { Box::from_raw(s) });
            Ok(())
        })
    }
}

/// Number of nodes (corners and mid-edge nodes) of the surface; 0 if `s` is NULL (and
/// the last error message says so).
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_num_nodes(s: *const curvetet_surface) -> usize {
    value_call("curvetet_surface_num_nodes", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(s, "s")? }.input.nodes().len())
    })
}

/// Number of 6-node triangles of the surface; 0 if `s` is NULL (and the last error
/// message says so).
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_num_triangles(s: *const curvetet_surface) -> usize {
    value_call("curvetet_surface_num_triangles", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(s, "s")? }.input.triangles().len())
    })
}

/// The surface's node coordinates: `3 * curvetet_surface_num_nodes(s)` doubles (x0, y0,
/// z0, x1, ...), owned by `s` and valid until it is freed. NULL if `s` is NULL (and the
/// last error message says so).
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_nodes(s: *const curvetet_surface) -> *const f64 {
    value_call("curvetet_surface_nodes", std::ptr::null(), || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(s, "s")? }
            .input
            .nodes()
            .as_ptr()
            .cast::<f64>())
    })
}

/// Copy the surface's triangles: `tri6_out` receives `6 * curvetet_surface_num_triangles(s)`
/// 0-based node indices (Gmsh order, outward: after a flip these are the flipped
/// triangles), `tags_out` (may be NULL) one tag per triangle.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `s` or `tri6_out` is NULL.
///
/// # Safety
/// `s` must be a live surface; the buffers must hold the counts above.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_triangles(
    s: *const curvetet_surface,
    tri6_out: *mut u32,
    tags_out: *mut i32,
) -> curvetet_status {
    status_call("curvetet_surface_triangles", || {
        // SAFETY: live by contract.
        let s = unsafe { deref(s, "s")? };
        check_ptr(tri6_out.cast_const(), "tri6_out")?;
        let tris = s.input.triangles();
        // SAFETY: buffer sizes by contract; NULL/alignment checked inside.
        unsafe {
            copy_out(tris.as_flattened(), tri6_out, "tri6_out")?;
            if !tags_out.is_null() {
                copy_out(s.input.tags(), tags_out, "tags_out")?;
            }
        }
        Ok(())
    })
}

/// Number of regions the surface bounds: 1 for a closed surface (with or without
/// cavities), more for a surface of several regions (its mesh then has a region id per
/// tet, `curvetet_mesh_tet_regions`); 0 if `s` is NULL (and the last error message says
/// so).
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_num_regions(s: *const curvetet_surface) -> usize {
    value_call("curvetet_surface_num_regions", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(s, "s")? }.input.num_regions())
    })
}

/// Number of warnings raised while checking the surface (e.g. "orientation was inward;
/// flipped"); 0 if `s` is NULL.
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_num_warnings(s: *const curvetet_surface) -> usize {
    value_call("curvetet_surface_num_warnings", 0, || {
        // SAFETY: live by contract.
        Ok(unsafe { deref(s, "s")? }.warnings.len())
    })
}

/// Warning `i` (0-based) as a NUL-terminated string owned by `s` (valid until it is
/// freed); NULL if `s` is NULL or `i` is out of range (and the last error message says
/// so).
///
/// # Safety
/// `s` must be NULL or a live surface.
#[no_mangle]
pub unsafe extern "C" fn curvetet_surface_warning(
    s: *const curvetet_surface,
    i: usize,
) -> *const c_char {
    value_call("curvetet_surface_warning", std::ptr::null(), || {
        // SAFETY: live by contract.
        let s = unsafe { deref(s, "s")? };
        s.warnings.get(i).map(|w| w.as_ptr()).ok_or_else(|| {
            invalid(format!(
                "warning {i} does not exist ({} warnings)",
                s.warnings.len()
            ))
        })
    })
}
