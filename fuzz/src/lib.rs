//! Shared checks of the curvetet fuzz targets (see README.md).

use curvetet::io::{read_bytes, surface_from_raw_any, Format, RawMesh};
use curvetet::surface::curve::CurveOptions;
use curvetet::Error;

/// Fuzz one reader: never panic; whatever it accepts has indices in range and one tag per
/// element, and becomes a surface or a clean error.
pub fn read(data: &[u8], format: Format) {
    let raw = match read_bytes(data, format, "fuzz") {
        Ok(raw) => raw,
        Err(e) => {
            check_error(&e);
            return;
        }
    };
    check_raw(&raw);
    // The surface checks (and, for a linear file, the curving) on what was read.
    if let Err(e) = surface_from_raw_any(raw, "fuzz", &CurveOptions::default()) {
        check_error(&e);
    }
}

/// A read error or a surface error; never an internal failure of the pipeline.
pub fn check_error(e: &Error) {
    match e {
        Error::Parse { .. } | Error::InvalidSurface { .. } | Error::InvalidArgument(_) => {}
        other => panic!("unexpected error kind from a reader/surface check: {other:?}"),
    }
    let msg = e.to_string();
    assert!(!msg.is_empty());
}

fn check_raw(m: &RawMesh) {
    let n = m.nodes.len() as u64;
    let ok = |s: &[u32]| s.iter().all(|&i| u64::from(i) < n);
    assert!(m.tri3.iter().all(|e| ok(e)), "tri3 index out of range");
    assert!(m.tri6.iter().all(|e| ok(e)), "tri6 index out of range");
    assert!(m.tet4.iter().all(|e| ok(e)), "tet4 index out of range");
    assert!(m.tet10.iter().all(|e| ok(e)), "tet10 index out of range");
    assert_eq!(m.tri3.len(), m.tri3_tags.len());
    assert_eq!(m.tri6.len(), m.tri6_tags.len());
    assert_eq!(m.tet4.len(), m.tet4_tags.len());
    assert_eq!(m.tet10.len(), m.tet10_tags.len());
}
