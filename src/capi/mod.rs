//! The C ABI (`include/curvetet.h`, generated from this module by cbindgen in build.rs).
//!
//! Style: opaque handles made by `curvetet_*_read`/`_from_arrays`/`curvetet_generate` and
//! released by `curvetet_*_free`; every fallible call returns a [`curvetet_status`] and
//! leaves a message for `curvetet_last_error_message()`; getters take `const` handles.
//!
//! Rules every entry point follows:
//! - the body runs inside `catch_unwind` (`guard`): nothing unwinds into C; a panic
//!   becomes `CURVETET_ERR_PANIC` with the panic message;
//! - pointers are checked for NULL and alignment, counts for overflow, before any slice
//!   is made from them; enums and versioned structs coming from C are validated
//!   (parameters of enum type arrive as plain integers, see [`NodeOrderArg`]);
//! - status-returning calls set the thread's last error message on failure and clear it
//!   to "" on success; accessors that return a count or pointer set it only on failure;
//! - an output handle `*out` is set to NULL first, so it is NULL on every failure.
//!
//! Handles are immutable after creation and `Send + Sync`: several threads may read one,
//! and several `curvetet_generate` calls may run at once on one surface.

mod guard;
mod mesh;
mod options;
mod status;
mod surface;

#[cfg(test)]
mod tests;

pub use mesh::{
    curvetet_generate, curvetet_mesh, curvetet_mesh_boundary_faces, curvetet_mesh_free,
    curvetet_mesh_nodes, curvetet_mesh_num_boundary_faces, curvetet_mesh_num_nodes,
    curvetet_mesh_num_regions, curvetet_mesh_num_tets, curvetet_mesh_quality,
    curvetet_mesh_report_json, curvetet_mesh_target_size, curvetet_mesh_tet_regions,
    curvetet_mesh_tets, curvetet_mesh_write, curvetet_mesh_write_with_flags, curvetet_node_order,
    curvetet_quality, NodeOrderArg, CURVETET_WRITE_BINARY, CURVETET_WRITE_MEDIT_LINEAR,
    CURVETET_WRITE_MSH22, QUALITY_SIZE_V1,
};
pub use options::{
    curvetet_options, curvetet_progress_fn, OPTIONS_SIZE_V1, OPTIONS_SIZE_V2, OPTIONS_SIZE_V3,
};
pub use status::{curvetet_status, StatusArg};
pub use surface::{
    curvetet_surface, curvetet_surface_free, curvetet_surface_from_arrays,
    curvetet_surface_from_arrays_with_flags, curvetet_surface_from_linear_with_flags,
    curvetet_surface_nodes, curvetet_surface_num_nodes, curvetet_surface_num_regions,
    curvetet_surface_num_triangles, curvetet_surface_num_warnings, curvetet_surface_read,
    curvetet_surface_read_with_flags, curvetet_surface_triangles, curvetet_surface_warning,
    CURVETET_SURFACE_NESTED_REGIONS, CURVETET_SURFACE_STRICT,
};

use guard::{check_ptr, status_call, value_call};
use std::ffi::c_char;

// Handles cross threads: make sure they can.
const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<curvetet_surface>();
    send_sync::<curvetet_mesh>();
};

/// The library version, e.g. "0.1.0" (the same as the `CURVETET_VERSION` macro of the
/// header it was built with). A static string: never free it.
#[no_mangle]
pub extern "C" fn curvetet_version() -> *const c_char {
    value_call("curvetet_version", c"".as_ptr(), || {
        Ok(concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast())
    })
}

/// The library version as one number, MAJOR * 10000 + MINOR * 100 + PATCH (0.1.0 is
/// 100; the same as the `CURVETET_VERSION_NUMBER` macro of the header it was built
/// with), for comparing at run time: `curvetet_version_number() >= 10200` is 1.2.0 or
/// later.
#[no_mangle]
pub extern "C" fn curvetet_version_number() -> u32 {
    value_call("curvetet_version_number", 0, || Ok(VERSION_NUMBER))
}

/// MAJOR * 10000 + MINOR * 100 + PATCH of this crate.
const VERSION_NUMBER: u32 = {
    /// A decimal string's value (the version parts cargo sets).
    const fn number(s: &str) -> u32 {
        let b = s.as_bytes();
        let mut n = 0;
        let mut i = 0;
        while i < b.len() {
            assert!(b[i].is_ascii_digit());
            n = n * 10 + (b[i] - b'0') as u32;
            i += 1;
        }
        n
    }
    let minor = number(env!("CARGO_PKG_VERSION_MINOR"));
    let patch = number(env!("CARGO_PKG_VERSION_PATCH"));
    assert!(minor < 100 && patch < 100);
    number(env!("CARGO_PKG_VERSION_MAJOR")) * 10000 + minor * 100 + patch
};

/// The message of the last failed curvetet call on this thread, "" when the last
/// status-returning call succeeded (or none was made). Never NULL. The string is owned by
/// the library and valid until the next curvetet call on this thread; copy it to keep it.
#[no_mangle]
pub extern "C" fn curvetet_last_error_message() -> *const c_char {
    // last_error_ptr cannot panic (try_with, try_borrow); the guard is for uniformity.
    value_call("curvetet_last_error_message", c"".as_ptr(), || {
        Ok(status::last_error_ptr())
    })
}

/// The name of a status code as a static string ("CURVETET_OK",
/// "CURVETET_ERR_INVALID_ARGUMENT", ...), or "CURVETET_UNKNOWN_STATUS" for a value that is
/// not one. Never NULL; never free it.
#[no_mangle]
pub extern "C" fn curvetet_error_name(status: StatusArg) -> *const c_char {
    value_call("curvetet_error_name", c"".as_ptr(), || {
        Ok(match curvetet_status::from_int(status.0) {
            Some(s) => s.name().as_ptr(),
            None => c"CURVETET_UNKNOWN_STATUS".as_ptr(),
        })
    })
}

/// Fill `*out` with the default options (alpha 1.5, graded size, optimize on, all cores,
/// no progress callback) and `struct_size = sizeof(curvetet_options)`. NULL `out` is
/// ignored (and the last error message says so).
///
/// It writes the whole struct as this library knows it: a program compiled against an
/// older header (smaller struct) that may run with a newer library should use
/// `curvetet_options_init(out, sizeof *out)` instead.
///
/// # Safety
/// A non-NULL `out` must be valid for writing a `curvetet_options`.
#[no_mangle]
pub unsafe extern "C" fn curvetet_options_default(out: *mut curvetet_options) {
    value_call("curvetet_options_default", (), || {
        check_ptr(out.cast_const(), "out")?;
        // SAFETY: non-NULL, aligned, writable by contract.
        unsafe { out.write(curvetet_options::defaults()) };
        Ok(())
    })
}

/// Fill the first `struct_size` bytes at `out` with the default options, as a caller's
/// struct of that size (pass `sizeof *out`): fields this library knows get their
/// defaults, bytes past them are zeroed, and `out->struct_size = struct_size`. Safe for a
/// struct from an older or a newer header.
///
/// Errors: `CURVETET_ERR_INVALID_ARGUMENT` when `out` is NULL or `struct_size` is smaller
/// than the first version's or implausibly large.
///
/// # Safety
/// A non-NULL `out` must be valid for writing `struct_size` bytes.
#[no_mangle]
pub unsafe extern "C" fn curvetet_options_init(
    out: *mut curvetet_options,
    struct_size: usize,
) -> curvetet_status {
    status_call("curvetet_options_init", || {
        check_ptr(out.cast_const(), "out")?;
        options::check_struct_size(struct_size, OPTIONS_SIZE_V1, "curvetet_options")?;
        let mut d = curvetet_options::defaults();
        d.struct_size = struct_size as u32;
        let ours = std::mem::size_of::<curvetet_options>();
        let n = struct_size.min(ours);
        // SAFETY: `out` holds struct_size bytes (contract); we write min(struct_size,
        // ours) bytes of a valid struct, then zero the rest of the caller's bytes.
        unsafe {
            std::ptr::copy_nonoverlapping(
                (&d as *const curvetet_options).cast::<u8>(),
                out.cast::<u8>(),
                n,
            );
            if struct_size > ours {
                std::ptr::write_bytes(out.cast::<u8>().add(ours), 0, struct_size - ours);
            }
        }
        Ok(())
    })
}
