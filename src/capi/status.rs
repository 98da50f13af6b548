//! Status codes, the thread-local last error message, and the mapping from [`Error`].

use crate::Error;
use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};

/// The result of every fallible curvetet call. `CURVETET_OK` (0) is success; on any
/// other value `curvetet_last_error_message()` says what went wrong.
// The enum and its variants carry the C names fixed by the ABI contract.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum curvetet_status {
    /// Success.
    CURVETET_OK = 0,
    /// A NULL pointer, a bad size or count, a bad enum value, or an option out of range.
    CURVETET_ERR_INVALID_ARGUMENT = 1,
    /// A file could not be opened, read or written (OS error).
    CURVETET_ERR_IO = 2,
    /// A file is malformed; the message gives file and line (or byte offset).
    CURVETET_ERR_PARSE = 3,
    /// The surface fails a check (not closed, self-intersecting, ...); the message names
    /// the check and the triangle, edge or node.
    CURVETET_ERR_INVALID_SURFACE = 4,
    /// The advancing front could not fill the volume.
    CURVETET_ERR_MESHING_FAILED = 5,
    /// The produced mesh failed its final certification (a bug guard; never returned as
    /// a valid mesh).
    CURVETET_ERR_INVALID_MESH = 6,
    /// The progress callback asked to stop.
    CURVETET_ERR_CANCELLED = 7,
    /// An internal error (a Rust panic) was caught at the ABI boundary; the message holds
    /// the panic message. Please report it.
    CURVETET_ERR_PANIC = 8,
}

pub use curvetet_status::*;

/// A `curvetet_status` as received *from* C. A C caller may pass any `int`, and an
/// out-of-range value in a Rust enum would be undefined behaviour, so parameters take this
/// transparent integer; the header shows it as `curvetet_status` (cbindgen.toml renames it).
#[repr(transparent)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StatusArg(pub c_int);

impl curvetet_status {
    /// The status of a given integer value, if it is one.
    pub fn from_int(v: c_int) -> Option<curvetet_status> {
        Some(match v {
            0 => CURVETET_OK,
            1 => CURVETET_ERR_INVALID_ARGUMENT,
            2 => CURVETET_ERR_IO,
            3 => CURVETET_ERR_PARSE,
            4 => CURVETET_ERR_INVALID_SURFACE,
            5 => CURVETET_ERR_MESHING_FAILED,
            6 => CURVETET_ERR_INVALID_MESH,
            7 => CURVETET_ERR_CANCELLED,
            8 => CURVETET_ERR_PANIC,
            _ => return None,
        })
    }

    /// The status code of an error (the stable mapping of the ABI).
    pub fn of(e: &Error) -> curvetet_status {
        match e {
            Error::InvalidArgument(_) => CURVETET_ERR_INVALID_ARGUMENT,
            Error::Io { .. } => CURVETET_ERR_IO,
            Error::Parse { .. } => CURVETET_ERR_PARSE,
            Error::InvalidSurface { .. } => CURVETET_ERR_INVALID_SURFACE,
            Error::MeshingFailed { .. } => CURVETET_ERR_MESHING_FAILED,
            Error::InvalidMesh { .. } => CURVETET_ERR_INVALID_MESH,
            Error::Cancelled => CURVETET_ERR_CANCELLED,
        }
    }

    /// The enumerator's name as a static NUL-terminated string.
    pub fn name(self) -> &'static std::ffi::CStr {
        match self {
            CURVETET_OK => c"CURVETET_OK",
            CURVETET_ERR_INVALID_ARGUMENT => c"CURVETET_ERR_INVALID_ARGUMENT",
            CURVETET_ERR_IO => c"CURVETET_ERR_IO",
            CURVETET_ERR_PARSE => c"CURVETET_ERR_PARSE",
            CURVETET_ERR_INVALID_SURFACE => c"CURVETET_ERR_INVALID_SURFACE",
            CURVETET_ERR_MESHING_FAILED => c"CURVETET_ERR_MESHING_FAILED",
            CURVETET_ERR_INVALID_MESH => c"CURVETET_ERR_INVALID_MESH",
            CURVETET_ERR_CANCELLED => c"CURVETET_ERR_CANCELLED",
            CURVETET_ERR_PANIC => c"CURVETET_ERR_PANIC",
        }
    }
}

thread_local! {
    /// The calling thread's last error message; `None` means "" (no error).
    static LAST_ERROR: RefCell<Option<CString>> = const { RefCell::new(None) };
}

/// Record `msg` as this thread's last error. NUL bytes in it are shown as `\0`.
pub(crate) fn set_last_error(msg: &str) {
    let msg = if msg.is_empty() {
        "unknown error".to_string()
    } else {
        msg.replace('\0', "\\0")
    };
    let c = CString::new(msg).unwrap_or_default();
    // try_with: during thread teardown the slot may be gone; then there is nobody to tell.
    let _ = LAST_ERROR.try_with(|e| *e.borrow_mut() = Some(c));
}

/// Clear this thread's last error (a successful call).
pub(crate) fn clear_last_error() {
    let _ = LAST_ERROR.try_with(|e| {
        if let Ok(mut e) = e.try_borrow_mut() {
            *e = None;
        }
    });
}

/// A pointer to this thread's last error message, valid until the next call on this
/// thread that sets or clears it.
pub(crate) fn last_error_ptr() -> *const c_char {
    LAST_ERROR
        .try_with(|e| match e.try_borrow() {
            Ok(e) => match e.as_ref() {
                Some(c) => c.as_ptr(),
                None => c"".as_ptr(),
            },
            Err(_) => c"".as_ptr(),
        })
        .unwrap_or(c"".as_ptr())
}
