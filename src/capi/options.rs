//! `curvetet_options`: the versioned options struct, and its conversion to [`Options`].
//!
//! Versioning: the caller puts `sizeof(curvetet_options)` of the header it was compiled
//! with in `struct_size`. Each field belongs to the version that added it, and a library
//! reads a field only when `struct_size` is at least that version's whole `sizeof`
//! ([`OPTIONS_SIZE_V1`], [`OPTIONS_SIZE_V2`], [`OPTIONS_SIZE_V3`]); the fields of a
//! newer version take their defaults. Whole sizes, not field ends: a field added in an
//! older version's tail padding (`thorough`, in the padding after `uniform_size`) would
//! otherwise be read from the garbage an older caller left there. The library refuses:
//! - a `struct_size` smaller than the first version's ([`OPTIONS_SIZE_V1`]): it was never
//!   set (0) or is garbage;
//! - a `struct_size` above [`MAX_STRUCT_SIZE`] (garbage);
//! - a larger, newer struct whose bytes past this library's `sizeof` are not all zero:
//!   the caller set options this library does not know, and ignoring them would be silent.

use super::guard::{check_ptr, invalid};
use crate::{Options, Result, SizeMode};
use std::ffi::{c_char, c_int, c_void};
use std::mem::{align_of, offset_of, size_of};

/// Progress callback: called from the thread that called `curvetet_generate`, with the
/// fraction of the work done (0..1, non-decreasing within a stage) and a short stage
/// name ("front"; "front (attempt 2 of 4)" and so on when the front starts again with
/// another configuration, its fraction from 0; "optimize" (0 and 0.5: the linear and the
/// high-order stage) unless optimization is off; "certify"; the string is valid only during
/// the call). Return nonzero
/// to cancel: `curvetet_generate` then returns `CURVETET_ERR_CANCELLED` promptly. It must
/// not unwind (throw a C++ exception or `longjmp`) through curvetet.
#[allow(non_camel_case_types)] // the C name fixed by the ABI contract
pub type curvetet_progress_fn = Option<
    unsafe extern "C" fn(user_data: *mut c_void, fraction: f64, stage: *const c_char) -> c_int,
>;

/// Options of `curvetet_generate`. Initialise with `curvetet_options_default` (or
/// `curvetet_options_init`), then change fields.
#[allow(non_camel_case_types)] // the C name fixed by the ABI contract
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct curvetet_options {
    /// `sizeof(curvetet_options)`: lets the struct grow. Set by `curvetet_options_default`.
    pub struct_size: u32,
    /// Search radius factor: candidates within alpha * h of the ideal point (default 1.5,
    /// the paper's). Must be finite and > 0.
    pub alpha: f64,
    /// Target edge length; <= 0 (default): graded from the surface's triangle sizes.
    /// NaN or +infinity is an error.
    pub size: f64,
    /// Nonzero (default 1): quality improvement and high-order optimization.
    pub optimize: i32,
    /// Worker threads for the parallel stages; 0 (default): one per CPU. The pool is
    /// created by each `curvetet_generate` call and gone when it returns; the front and
    /// the progress callback run on the calling thread. The result does not depend on it.
    /// At most 4 per CPU and at most 1024: more is `CURVETET_ERR_INVALID_ARGUMENT`,
    /// before any work.
    pub threads: u32,
    /// Progress callback; may be NULL (default).
    pub progress: curvetet_progress_fn,
    /// Passed to `progress` unchanged; may be NULL.
    pub user_data: *mut c_void,
    /// Nonzero: when `size` <= 0, use the paper's uniform size (tetrahedron height from
    /// the mean curved triangle area, its eq. 1) instead of grading from the boundary.
    /// Default 0. (Added in 0.1 after the first struct; older callers get the default.)
    pub uniform_size: i32,
    /// Nonzero: more high-order rounds where some element starts poor (CAD parts), for
    /// fewer elements left between the worst one and min J / max J 0.85, at two to three
    /// times that stage's work there. Default 0. Read only when `struct_size` is at least
    /// the third version's size (this header's `sizeof`): the bytes of an older,
    /// smaller struct here were its padding.
    pub thorough: i32,
    /// Nonzero: keep each worker thread on its own CPU when there is one worker per CPU
    /// the process may use (`threads` = 0 or that count). Default 0: threads are left to
    /// the operating system, as a host application expects of a library; pinning helps a
    /// process that does nothing else (the `curvetet` command pins). The environment
    /// variable `CURVETET_PIN_THREADS` overrides this either way (`0`: never, `1`: as if
    /// set). The result does not depend on it.
    pub pin_threads: i32,
}

/// `sizeof(curvetet_options)` of the first version of the ABI (curvetet 0.1): every
/// accepted struct has at least these fields.
pub const OPTIONS_SIZE_V1: usize =
    offset_of!(curvetet_options, user_data) + size_of::<*mut c_void>();

/// `sizeof(curvetet_options)` of the second version: `uniform_size` added, then tail
/// padding (where `thorough` was later declared: not read at this size). 56 on 64-bit
/// platforms.
pub const OPTIONS_SIZE_V2: usize = (offset_of!(curvetet_options, uniform_size) + size_of::<i32>())
    .next_multiple_of(align_of::<curvetet_options>());

/// `sizeof(curvetet_options)` of the third version: `thorough` and `pin_threads` added
/// (64 on 64-bit platforms).
pub const OPTIONS_SIZE_V3: usize = (offset_of!(curvetet_options, pin_threads) + size_of::<i32>())
    .next_multiple_of(align_of::<curvetet_options>());

// Each version is larger than the one before, and the third is this struct: a fourth
// version adds its fields after `pin_threads` and its own size constant.
const _: () = {
    assert!(OPTIONS_SIZE_V1 < OPTIONS_SIZE_V2 && OPTIONS_SIZE_V2 < OPTIONS_SIZE_V3);
    assert!(OPTIONS_SIZE_V3 == size_of::<curvetet_options>());
    assert!(offset_of!(curvetet_options, thorough) < OPTIONS_SIZE_V2);
};

/// Largest `struct_size` accepted for a versioned struct: bigger is garbage.
pub(crate) const MAX_STRUCT_SIZE: usize = 4096;

impl curvetet_options {
    /// The defaults, with `struct_size` = this library's `sizeof(curvetet_options)`.
    pub fn defaults() -> curvetet_options {
        let d = Options::default();
        curvetet_options {
            struct_size: size_of::<curvetet_options>() as u32,
            alpha: d.alpha,
            size: 0.0,
            optimize: d.optimize as i32,
            threads: d.threads as u32,
            progress: None,
            user_data: std::ptr::null_mut(),
            uniform_size: 0,
            thorough: d.thorough as i32,
            pin_threads: d.pin_threads as i32,
        }
    }
}

/// Check a versioned struct's `struct_size` (the first field): between `v1` and
/// [`MAX_STRUCT_SIZE`]. `what` names the struct.
pub(crate) fn check_struct_size(size: usize, v1: usize, what: &str) -> Result<()> {
    if size < v1 {
        return Err(invalid(format!(
            "{what}->struct_size is {size}, smaller than the first version's {v1}: set it to \
             sizeof({what})"
        )));
    }
    if size > MAX_STRUCT_SIZE {
        return Err(invalid(format!(
            "{what}->struct_size is {size}, larger than any version ({MAX_STRUCT_SIZE} at \
             most): is the struct initialised?"
        )));
    }
    Ok(())
}

/// What `curvetet_generate` takes from a `curvetet_options`.
pub(crate) struct Parsed {
    pub options: Options,
    pub progress: curvetet_progress_fn,
    pub user_data: *mut c_void,
}

/// Read the caller's options (NULL: defaults), honouring `struct_size`.
///
/// # Safety
/// A non-NULL `p` must point to at least `p->struct_size` readable bytes.
pub(crate) unsafe fn parse(p: *const curvetet_options) -> Result<Parsed> {
    let mut o = curvetet_options::defaults();
    if !p.is_null() {
        check_ptr(p, "opt")?;
        // SAFETY: non-NULL and aligned; struct_size is the first field, present in every
        // version.
        let size = unsafe { std::ptr::addr_of!((*p).struct_size).read() } as usize;
        check_struct_size(size, OPTIONS_SIZE_V1, "curvetet_options")?;
        let ours = size_of::<curvetet_options>();
        if size > ours {
            // SAFETY: the caller promises `size` readable bytes (<= MAX_STRUCT_SIZE).
            let extra =
                unsafe { std::slice::from_raw_parts(p.cast::<u8>().add(ours), size - ours) };
            if let Some(k) = extra.iter().position(|&b| b != 0) {
                return Err(invalid(format!(
                    "curvetet_options->struct_size is {size}, from a newer curvetet; byte {} \
                     is set but this library ({}) knows only the first {ours} bytes",
                    ours + k,
                    env!("CARGO_PKG_VERSION")
                )));
            }
        }
        // Copy field `$f` when the caller's struct is at least the version `$v` that
        // added it (the module docs say why whole versions, not field ends).
        macro_rules! take {
            ($f:ident, $v:expr) => {
                if size >= $v {
                    debug_assert!(offset_of!(curvetet_options, $f) + size_of_val(&o.$f) <= $v);
                    // SAFETY: the field lies within the caller's `size` bytes.
                    o.$f = unsafe { std::ptr::addr_of!((*p).$f).read() };
                }
            };
        }
        take!(alpha, OPTIONS_SIZE_V1);
        take!(size, OPTIONS_SIZE_V1);
        take!(optimize, OPTIONS_SIZE_V1);
        take!(threads, OPTIONS_SIZE_V1);
        take!(progress, OPTIONS_SIZE_V1);
        take!(user_data, OPTIONS_SIZE_V1);
        take!(uniform_size, OPTIONS_SIZE_V2);
        take!(thorough, OPTIONS_SIZE_V3);
        take!(pin_threads, OPTIONS_SIZE_V3);
    }
    let mut options = Options {
        alpha: o.alpha,
        optimize: o.optimize != 0,
        thorough: o.thorough != 0,
        threads: o.threads as usize,
        pin_threads: o.pin_threads != 0,
        ..Options::default()
    };
    options.size = if o.size.is_nan() || o.size > 0.0 {
        SizeMode::Fixed(o.size) // NaN and infinity are rejected by validate()
    } else if o.uniform_size != 0 {
        SizeMode::Uniform
    } else {
        SizeMode::Graded
    };
    options.validate()?;
    Ok(Parsed {
        options,
        progress: o.progress,
        user_data: o.user_data,
    })
}
