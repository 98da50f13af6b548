//! Rust-side tests of the C ABI: the panic boundary, status mapping, struct versioning
//! and argument checks. The C programs in tests/c exercise the same functions from C.

use super::guard::{status_call, value_call};
use super::options::{parse, MAX_STRUCT_SIZE};
use super::surface::{curvetet_surface_from_linear, curvetet_surface_from_linear_smoothed};
use super::*;
use crate::{Error, SizeMode, SurfaceDefect};
use std::ffi::{c_void, CStr, CString};
use std::ptr::{null, null_mut};

fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated.
    unsafe { CStr::from_ptr(curvetet_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn sphere_path() -> CString {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/sphere_p2.msh");
    CString::new(p).unwrap()
}

#[test]
fn a_panic_becomes_a_status_with_its_message() {
    let st = status_call("f", || panic!("boom {}", 42));
    assert_eq!(st, curvetet_status::CURVETET_ERR_PANIC);
    let msg = last_error();
    assert!(msg.contains("f:") && msg.contains("boom 42"), "{msg}");
    let v = value_call("g", 7usize, || -> crate::Result<usize> {
        panic!("static str")
    });
    assert_eq!(v, 7);
    assert!(last_error().contains("static str"));
    // A success clears the message.
    assert_eq!(status_call("h", || Ok(())), curvetet_status::CURVETET_OK);
    assert_eq!(last_error(), "");
}

#[test]
fn every_error_maps_to_its_stable_code() {
    use curvetet_status::*;
    let io = std::io::Error::new(std::io::ErrorKind::NotFound, "x");
    let cases = [
        (
            Error::InvalidArgument("a".into()),
            CURVETET_ERR_INVALID_ARGUMENT,
            1,
        ),
        (Error::io("p", io), CURVETET_ERR_IO, 2),
        (Error::parse("f:1", "bad"), CURVETET_ERR_PARSE, 3),
        (
            Error::surface(SurfaceDefect::NotClosed, "edge"),
            CURVETET_ERR_INVALID_SURFACE,
            4,
        ),
        (
            Error::MeshingFailed {
                msg: "m".into(),
                partial: None,
            },
            CURVETET_ERR_MESHING_FAILED,
            5,
        ),
        (
            Error::InvalidMesh {
                elements: vec![],
                msg: "m".into(),
                mesh: None,
            },
            CURVETET_ERR_INVALID_MESH,
            6,
        ),
        (Error::Cancelled, CURVETET_ERR_CANCELLED, 7),
    ];
    for (e, st, code) in cases {
        assert_eq!(curvetet_status::of(&e), st);
        assert_eq!(st as i32, code);
        assert_eq!(curvetet_status::from_int(code), Some(st));
    }
    assert_eq!(CURVETET_OK as i32, 0);
    assert_eq!(CURVETET_ERR_PANIC as i32, 8);
    for code in 0..=8 {
        let name = unsafe { CStr::from_ptr(curvetet_error_name(StatusArg(code))) };
        assert!(name.to_str().unwrap().starts_with("CURVETET_"));
    }
    let name = unsafe { CStr::from_ptr(curvetet_error_name(StatusArg(99))) };
    assert_eq!(name.to_str().unwrap(), "CURVETET_UNKNOWN_STATUS");
    let name = unsafe { CStr::from_ptr(curvetet_error_name(StatusArg(-1))) };
    assert_eq!(name.to_str().unwrap(), "CURVETET_UNKNOWN_STATUS");
}

#[test]
fn version_is_the_crate_version() {
    let v = unsafe { CStr::from_ptr(curvetet_version()) };
    assert_eq!(v.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    // The number is the same version: "0.1.0" -> 100.
    let parts: Vec<u32> = env!("CARGO_PKG_VERSION")
        .split('.')
        .map(|p| p.parse().unwrap())
        .collect();
    assert_eq!(
        curvetet_version_number(),
        parts[0] * 10000 + parts[1] * 100 + parts[2]
    );
}

#[test]
fn options_struct_size_is_checked() {
    let mut o = std::mem::MaybeUninit::<curvetet_options>::uninit();
    unsafe { curvetet_options_default(o.as_mut_ptr()) };
    let o = unsafe { o.assume_init() };
    assert_eq!(
        o.struct_size as usize,
        std::mem::size_of::<curvetet_options>()
    );
    assert!(o.struct_size as usize > OPTIONS_SIZE_V1);
    let p = unsafe { parse(&o) }.unwrap();
    assert_eq!(p.options.alpha, 1.5);
    assert!(p.options.optimize);
    assert_eq!(p.options.size, SizeMode::Graded);
    assert!(unsafe { parse(null()) }.is_ok());

    // uniform_size picks the paper's size when no size is given; a given size wins.
    let mut u = o;
    u.uniform_size = 1;
    assert_eq!(
        unsafe { parse(&u) }.unwrap().options.size,
        SizeMode::Uniform
    );
    u.size = 0.5;
    assert_eq!(
        unsafe { parse(&u) }.unwrap().options.size,
        SizeMode::Fixed(0.5)
    );
    // thorough is off by default and passed through.
    assert!(!p.options.thorough);
    let mut t = o;
    t.thorough = 1;
    assert!(unsafe { parse(&t) }.unwrap().options.thorough);
    // A first-version struct (without uniform_size or thorough) is read up to its size
    // only.
    let mut v1 = o;
    v1.uniform_size = 1;
    v1.thorough = 1;
    v1.struct_size = OPTIONS_SIZE_V1 as u32;
    let p1 = unsafe { parse(&v1) }.unwrap().options;
    assert_eq!(p1.size, SizeMode::Graded);
    assert!(!p1.thorough);
    assert!(unsafe { parse(null()) }.is_ok());

    // A second-version struct (uniform_size, then 4 bytes of tail padding where this
    // header has `thorough`) from an old caller: garbage in that padding must not turn
    // `thorough` on, while `uniform_size` is read.
    assert!(std::mem::offset_of!(curvetet_options, thorough) < OPTIONS_SIZE_V2);
    let mut v2 = o;
    v2.struct_size = OPTIONS_SIZE_V2 as u32;
    v2.uniform_size = 1;
    v2.thorough = 0x5a5a_5a5a; // what an old caller's stack left in its padding
    v2.pin_threads = 1; // past the old struct's end
    let p2 = unsafe { parse(&v2) }.unwrap().options;
    assert_eq!(p2.size, SizeMode::Uniform);
    assert!(
        !p2.thorough,
        "an old struct's padding was read as `thorough`"
    );
    assert!(!p2.pin_threads);
    // The same bytes with this version's size: both are read.
    v2.struct_size = OPTIONS_SIZE_V3 as u32;
    let p3 = unsafe { parse(&v2) }.unwrap().options;
    assert!(p3.thorough && p3.pin_threads);
    // pin_threads is off by default (a host application places its own threads).
    assert_eq!(o.pin_threads, 0);
    assert!(!p.options.pin_threads);

    for bad in [
        0u32,
        4,
        OPTIONS_SIZE_V1 as u32 - 1,
        MAX_STRUCT_SIZE as u32 + 1,
    ] {
        let mut b = o;
        b.struct_size = bad;
        let e = unsafe { parse(&b) }.err().expect("rejected");
        assert!(e.to_string().contains("struct_size"), "{e}");
    }

    // A newer, bigger struct: accepted when its extra bytes are zero.
    #[repr(C)]
    struct Newer {
        base: curvetet_options,
        extra: [u64; 4],
    }
    let mut n = Newer {
        base: o,
        extra: [0; 4],
    };
    n.base.struct_size = std::mem::size_of::<Newer>() as u32;
    n.base.alpha = 2.0;
    let p = unsafe { parse(&n.base) }.unwrap();
    assert_eq!(p.options.alpha, 2.0);
    n.extra[2] = 1;
    let e = unsafe { parse(&n.base) }.err().expect("unknown field set");
    assert!(e.to_string().contains("newer"), "{e}");

    // curvetet_options_init fills a newer struct's tail with zeros.
    let mut n = Newer {
        base: o,
        extra: [u64::MAX; 4],
    };
    let st = unsafe { curvetet_options_init(&mut n.base, std::mem::size_of::<Newer>()) };
    assert_eq!(st, curvetet_status::CURVETET_OK);
    assert_eq!(n.extra, [0; 4]);
    assert_eq!(n.base.struct_size as usize, std::mem::size_of::<Newer>());
    assert!(unsafe { parse(&n.base) }.is_ok());
    let st = unsafe { curvetet_options_init(&mut n.base, 3) };
    assert_eq!(st, curvetet_status::CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("struct_size"));
    let st = unsafe { curvetet_options_init(null_mut(), OPTIONS_SIZE_V1) };
    assert_eq!(st, curvetet_status::CURVETET_ERR_INVALID_ARGUMENT);
}

#[test]
fn option_values_are_validated() {
    let mut o = curvetet_options::defaults();
    o.size = -1.0;
    assert_eq!(unsafe { parse(&o) }.unwrap().options.size, SizeMode::Graded);
    o.size = 0.25;
    assert_eq!(
        unsafe { parse(&o) }.unwrap().options.size,
        SizeMode::Fixed(0.25)
    );
    for (alpha, size) in [
        (f64::NAN, 0.0),
        (-1.0, 0.0),
        (1.5, f64::NAN),
        (1.5, f64::INFINITY),
    ] {
        o.alpha = alpha;
        o.size = size;
        assert!(matches!(
            unsafe { parse(&o) },
            Err(Error::InvalidArgument(_))
        ));
    }
}

#[test]
fn null_and_misaligned_pointers_are_rejected() {
    use curvetet_status::*;
    let mut s: *mut curvetet_surface = 8 as *mut _; // not NULL: must be reset
    let st = unsafe { curvetet_surface_read(null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(s.is_null());
    assert!(last_error().contains("path is NULL"));
    let st = unsafe { curvetet_surface_read(sphere_path().as_ptr(), null_mut()) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("out is NULL"));
    let st = unsafe { curvetet_surface_from_arrays(null(), 3, null(), 0, null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("xyz is NULL"), "{}", last_error());
    // No triangles at all is a surface defect, not an argument error.
    let st = unsafe { curvetet_surface_from_arrays(null(), 0, null(), 0, null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_SURFACE);
    // A count whose byte size overflows.
    let xyz = [0.0f64; 3];
    let st = unsafe {
        curvetet_surface_from_arrays(xyz.as_ptr(), usize::MAX / 2, null(), 0, null(), &mut s)
    };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    // Misaligned.
    let bytes = [0u8; 64];
    let odd = bytes.as_ptr().wrapping_add(1).cast::<f64>();
    let st = unsafe { curvetet_surface_from_arrays(odd, 1, null(), 0, null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("aligned"), "{}", last_error());

    let mut m: *mut curvetet_mesh = 8 as *mut _;
    assert_eq!(
        unsafe { curvetet_generate(null(), null(), &mut m) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    assert!(m.is_null());
    assert_eq!(unsafe { curvetet_mesh_num_nodes(null()) }, 0);
    assert!(last_error().contains("m is NULL"));
    assert!(unsafe { curvetet_mesh_nodes(null()) }.is_null());
    assert!(unsafe { curvetet_mesh_report_json(null()) }.is_null());
    assert_eq!(unsafe { curvetet_surface_num_nodes(null()) }, 0);
    unsafe { curvetet_surface_free(null_mut()) };
    unsafe { curvetet_mesh_free(null_mut()) };
}

extern "C" fn cancel_at_third_call(user: *mut c_void, fraction: f64, stage: *const c_char) -> i32 {
    // SAFETY: the test passes a *mut Vec<(f64, String)>.
    let calls = unsafe { &mut *user.cast::<Vec<(f64, String)>>() };
    let stage = unsafe { CStr::from_ptr(stage) }
        .to_string_lossy()
        .into_owned();
    calls.push((fraction, stage));
    (calls.len() >= 3) as i32
}

#[test]
fn generate_through_the_abi() {
    use curvetet_status::*;
    let mut s = null_mut();
    assert_eq!(
        unsafe { curvetet_surface_read(sphere_path().as_ptr(), &mut s) },
        CURVETET_OK
    );
    assert_eq!(last_error(), "");
    let (nn, nt) = unsafe {
        (
            curvetet_surface_num_nodes(s),
            curvetet_surface_num_triangles(s),
        )
    };
    assert!(nn > 0 && nt > 0);

    // Cancelled at the third progress report.
    let mut calls: Vec<(f64, String)> = Vec::new();
    let mut o = curvetet_options::defaults();
    o.progress = Some(cancel_at_third_call);
    o.user_data = (&mut calls as *mut Vec<(f64, String)>).cast();
    let mut m = null_mut();
    assert_eq!(
        unsafe { curvetet_generate(s, &o, &mut m) },
        CURVETET_ERR_CANCELLED
    );
    assert!(m.is_null());
    assert_eq!(calls.len(), 3);
    assert!(last_error().contains("cancelled"), "{}", last_error());

    assert_eq!(unsafe { curvetet_generate(s, null(), &mut m) }, CURVETET_OK);
    let mesh = unsafe { &*m };
    let g = &mesh.generated;
    assert_eq!(unsafe { curvetet_mesh_num_tets(m) }, g.mesh.tets.len());
    assert_eq!(unsafe { curvetet_mesh_num_nodes(m) }, g.mesh.nodes.len());
    assert_eq!(unsafe { curvetet_mesh_num_boundary_faces(m) }, nt);

    let n = g.mesh.tets.len();
    let mut gmsh = vec![0u32; 10 * n];
    let mut vtk = vec![0u32; 10 * n];
    assert_eq!(
        unsafe { curvetet_mesh_tets(m, NodeOrderArg(0), gmsh.as_mut_ptr()) },
        CURVETET_OK
    );
    assert_eq!(
        unsafe { curvetet_mesh_tets(m, NodeOrderArg(1), vtk.as_mut_ptr()) },
        CURVETET_OK
    );
    for k in 0..n {
        assert_eq!(gmsh[10 * k..10 * k + 8], vtk[10 * k..10 * k + 8]);
        assert_eq!(
            (gmsh[10 * k + 8], gmsh[10 * k + 9]),
            (vtk[10 * k + 9], vtk[10 * k + 8])
        );
    }
    assert_eq!(
        unsafe { curvetet_mesh_tets(m, NodeOrderArg(2), vtk.as_mut_ptr()) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    assert!(last_error().contains("order is 2"));

    // Quality: a full struct, then an older/smaller one is refused below v1, and a bigger
    // one is filled up to this library's size.
    let mut q = curvetet_quality {
        struct_size: std::mem::size_of::<curvetet_quality>() as u32,
        ..Default::default()
    };
    assert_eq!(unsafe { curvetet_mesh_quality(m, &mut q) }, CURVETET_OK);
    assert_eq!(q.num_tets as usize, n);
    assert_eq!(q.num_invalid, 0);
    assert!(q.min_scaled_jacobian > 0.0 && q.min_scaled_jacobian_certified > 0.0);
    q.struct_size = 0;
    assert_eq!(
        unsafe { curvetet_mesh_quality(m, &mut q) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    #[repr(C)]
    struct Bigger {
        q: curvetet_quality,
        more: f64,
    }
    let mut b = Bigger {
        q: curvetet_quality {
            struct_size: std::mem::size_of::<Bigger>() as u32,
            ..Default::default()
        },
        more: 42.0,
    };
    assert_eq!(unsafe { curvetet_mesh_quality(m, &mut b.q) }, CURVETET_OK);
    assert_eq!(b.q.struct_size as usize, QUALITY_SIZE_V1);
    assert_eq!(b.more, 42.0);
    assert_eq!(b.q.num_tets as usize, n);

    let json = unsafe { CStr::from_ptr(curvetet_mesh_report_json(m)) };
    let v: serde_json::Value = serde_json::from_str(json.to_str().unwrap()).unwrap();
    assert_eq!(v["report"]["num_tets"].as_u64(), Some(n as u64));
    // Same pointer on the second call (owned by the mesh).
    assert_eq!(json.as_ptr(), unsafe { curvetet_mesh_report_json(m) });
    // Optimization is on by default: it ran, and its time is part of the stage times.
    assert!(v["optimize"]["linear"]["passes"].as_u64().unwrap() > 0);
    assert!(v["times"]["optimize"].as_f64().unwrap() > 0.0);
    let sj_optimized = g.report.quality.scaled_jacobian_certified.min;

    // `optimize = 0` is honoured: no optimization, and the raw front mesh is worse.
    let mut o = curvetet_options::defaults();
    o.optimize = 0;
    let mut raw = null_mut();
    assert_eq!(unsafe { curvetet_generate(s, &o, &mut raw) }, CURVETET_OK);
    let rg = unsafe { &(*raw).generated };
    assert_eq!(rg.optimize.linear.passes, 0);
    assert_eq!(rg.times.optimize, 0.0);
    assert!(rg.report.quality.scaled_jacobian_certified.min < sj_optimized);
    // The boundary is the same either way.
    assert_eq!(rg.mesh.boundary, g.mesh.boundary);
    unsafe { curvetet_mesh_free(raw) };

    let bad = CString::new("/nonexistent-dir/x.msh").unwrap();
    assert_eq!(
        unsafe { curvetet_mesh_write(m, bad.as_ptr()) },
        CURVETET_ERR_IO
    );
    let bad = CString::new("x.unknown").unwrap();
    assert_eq!(
        unsafe { curvetet_mesh_write(m, bad.as_ptr()) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    assert_eq!(
        unsafe { curvetet_mesh_write_with_flags(m, bad.as_ptr(), 64) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    assert!(last_error().contains("flag"));

    unsafe { curvetet_mesh_free(m) };
    unsafe { curvetet_surface_free(s) };
}

#[test]
fn impossible_counts_and_thread_counts_are_refused_at_once() {
    use curvetet_status::*;
    let t = std::time::Instant::now();
    // 2^32 + 1 nodes: refused from the count alone, before the arrays are touched (so the
    // small arrays here are never read past their end), instead of a 100 GB copy.
    let xyz = [0.0f64; 3];
    let tri = [0u32; 6];
    let mut s: *mut curvetet_surface = null_mut();
    let big = (1usize << 32) + 1;
    let st =
        unsafe { curvetet_surface_from_arrays(xyz.as_ptr(), big, tri.as_ptr(), 1, null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(s.is_null());
    assert!(
        last_error().contains("num_nodes is 4294967297"),
        "{}",
        last_error()
    );
    let st =
        unsafe { curvetet_surface_from_arrays(xyz.as_ptr(), 1, tri.as_ptr(), big, null(), &mut s) };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("num_triangles"), "{}", last_error());
    let st = unsafe {
        curvetet_surface_from_linear(xyz.as_ptr(), big, tri.as_ptr(), 1, null(), 40.0, &mut s)
    };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    // Smoothing iterations above the cap.
    let st = unsafe {
        curvetet_surface_from_linear_smoothed(
            xyz.as_ptr(),
            1,
            tri.as_ptr(),
            1,
            null(),
            40.0,
            u32::MAX,
            &mut s,
        )
    };
    assert_eq!(st, CURVETET_ERR_INVALID_ARGUMENT);
    assert!(last_error().contains("at most 1000"), "{}", last_error());

    // 100,000 threads: refused before any thread starts.
    let mut s = null_mut();
    assert_eq!(
        unsafe { curvetet_surface_read(sphere_path().as_ptr(), &mut s) },
        CURVETET_OK
    );
    assert!(
        t.elapsed() < std::time::Duration::from_secs(1),
        "{:?}",
        t.elapsed()
    );
    let t = std::time::Instant::now();
    let mut o = curvetet_options::defaults();
    o.threads = 100_000;
    let mut m = null_mut();
    assert_eq!(
        unsafe { curvetet_generate(s, &o, &mut m) },
        CURVETET_ERR_INVALID_ARGUMENT
    );
    assert!(m.is_null());
    assert!(last_error().contains("100000 threads"), "{}", last_error());
    assert!(
        t.elapsed() < std::time::Duration::from_secs(1),
        "{:?}",
        t.elapsed()
    );
    unsafe { curvetet_surface_free(s) };
}

#[test]
fn mesh_write_replaces_a_file_whole_and_reports_a_missing_directory() {
    use curvetet_status::*;
    let dir = std::env::temp_dir().join(format!("curvetet-capi-write-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut s = null_mut();
    assert_eq!(
        unsafe { curvetet_surface_read(sphere_path().as_ptr(), &mut s) },
        CURVETET_OK
    );
    let mut o = curvetet_options::defaults();
    o.optimize = 0;
    let mut m = null_mut();
    assert_eq!(unsafe { curvetet_generate(s, &o, &mut m) }, CURVETET_OK);
    let out = dir.join("out.vtu");
    std::fs::write(&out, vec![b'x'; 50 << 20]).unwrap(); // longer than the mesh
    let c = CString::new(out.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { curvetet_mesh_write(m, c.as_ptr()) }, CURVETET_OK);
    let bytes = std::fs::read(&out).unwrap();
    let mesh = unsafe { &*m };
    let expected = crate::io::mesh_to_bytes(
        &mesh.generated.mesh,
        crate::io::Format::Vtu,
        &Default::default(),
    )
    .unwrap();
    assert!(bytes == expected, "the file is not exactly the mesh");
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["out.vtu"], "a temporary file was left");
    let missing = CString::new(dir.join("no/such/dir/out.msh").to_str().unwrap()).unwrap();
    assert_eq!(
        unsafe { curvetet_mesh_write(m, missing.as_ptr()) },
        CURVETET_ERR_IO
    );
    assert!(
        last_error().contains("no/such/dir/out.msh"),
        "{}",
        last_error()
    );
    unsafe {
        curvetet_mesh_free(m);
        curvetet_surface_free(s);
    }
}

#[test]
fn a_caught_panic_names_its_location_and_prints_nothing() {
    if std::env::var_os("CURVETET_TEST_PANIC_CHILD").is_some() {
        // In the child process: a panic inside an entry point, with stderr not captured.
        let st = status_call("f", || panic!("quiet please"));
        assert_eq!(st, curvetet_status::CURVETET_ERR_PANIC);
        return;
    }
    let line = line!() + 1;
    let st = status_call("f", || panic!("located"));
    assert_eq!(st, curvetet_status::CURVETET_ERR_PANIC);
    let msg = last_error();
    assert!(
        msg.contains(&format!("src/capi/tests.rs:{line}")) && msg.contains("located"),
        "{msg}"
    );
    // The same test in a child process, whose stderr is not captured by the test
    // harness: Rust's default hook would print "panicked at ... quiet please" there.
    let o = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "capi::tests::a_caught_panic_names_its_location_and_prints_nothing",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("CURVETET_TEST_PANIC_CHILD", "1")
        .output()
        .unwrap();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(
        o.status.success() && out.contains("1 passed"),
        "{out}\n{err}"
    );
    assert!(
        !err.contains("quiet please") && !out.contains("quiet please"),
        "{err}"
    );
}

/// `CURVETET_SURFACE_STRICT` refuses what the default repairs: a P2 surface with a
/// flipped triangle and an unused node, a linear one with a flipped facet, a file with
/// the cavity facing the wrong way; unknown flag bits are an argument error.
#[test]
fn the_strict_flag_refuses_what_is_repaired_by_default() {
    use super::surface::curvetet_surface_free;
    let raw = crate::io::read(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/sphere_p2.msh"
    )))
    .unwrap();
    let (nodes, tris) = (raw.nodes, raw.tri6);
    let mut xyz: Vec<f64> = nodes.iter().flatten().copied().collect();
    xyz.extend([9.0, 9.0, 9.0]); // an unused node
    let mut tri6: Vec<u32> = tris.iter().flatten().copied().collect();
    let t = &mut tri6[6 * 5..6 * 6];
    t.swap(1, 2);
    t.swap(3, 5);
    let from_arrays = |flags: u32| {
        let mut s = null_mut();
        // SAFETY: arrays of the stated lengths.
        let st = unsafe {
            curvetet_surface_from_arrays_with_flags(
                xyz.as_ptr(),
                nodes.len() + 1,
                tri6.as_ptr(),
                tris.len(),
                null(),
                flags,
                &mut s,
            )
        };
        (st, s)
    };
    let (st, s) = from_arrays(0);
    assert_eq!(st, curvetet_status::CURVETET_OK, "{}", last_error());
    // SAFETY: a live surface.
    unsafe {
        assert_eq!(curvetet_surface_num_warnings(s), 2);
        assert_eq!(curvetet_surface_num_nodes(s), nodes.len());
        let w = CStr::from_ptr(curvetet_surface_warning(s, 1)).to_string_lossy();
        assert!(w.contains("flipped 1 of"), "{w}");
        let mut back = vec![0u32; 6 * tris.len()];
        curvetet_surface_triangles(s, back.as_mut_ptr(), null_mut());
        assert_eq!(back, tris.iter().flatten().copied().collect::<Vec<_>>());
        curvetet_surface_free(s);
    }
    let (st, s) = from_arrays(CURVETET_SURFACE_STRICT);
    assert_eq!(st, curvetet_status::CURVETET_ERR_INVALID_SURFACE);
    assert!(s.is_null());
    assert!(last_error().contains("unused-node"), "{}", last_error());
    // Bit 1 is CURVETET_SURFACE_NESTED_REGIONS; bit 2 is unknown.
    let (st, _) = from_arrays(4);
    assert_eq!(st, curvetet_status::CURVETET_ERR_INVALID_ARGUMENT);
    assert!(
        last_error().contains("unknown flag bits 0x4"),
        "{}",
        last_error()
    );

    // Linear: the octahedron with one facet flipped.
    let xyz: [f64; 18] = [
        1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0,
    ];
    let tri3: [u32; 24] = [
        0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 5, 3,
    ];
    let linear = |flags: u32| {
        let mut s = null_mut();
        // SAFETY: arrays of the stated lengths.
        let st = unsafe {
            curvetet_surface_from_linear_with_flags(
                xyz.as_ptr(),
                6,
                tri3.as_ptr(),
                8,
                null(),
                40.0,
                0,
                flags,
                &mut s,
            )
        };
        // SAFETY: NULL or live.
        unsafe { curvetet_surface_free(s) };
        st
    };
    assert_eq!(linear(0), curvetet_status::CURVETET_OK, "{}", last_error());
    assert_eq!(
        linear(CURVETET_SURFACE_STRICT),
        curvetet_status::CURVETET_ERR_INVALID_SURFACE
    );
    assert!(last_error().contains("inconsistent-orientation"));

    // A file: the bad corpus's cavity facing out.
    let p = CString::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/bad/shells_disagree.msh"
    ))
    .unwrap();
    for (flags, want) in [
        (0, curvetet_status::CURVETET_OK),
        (
            CURVETET_SURFACE_STRICT,
            curvetet_status::CURVETET_ERR_INVALID_SURFACE,
        ),
    ] {
        let mut s = null_mut();
        // SAFETY: a NUL-terminated path.
        let st = unsafe { curvetet_surface_read_with_flags(p.as_ptr(), flags, &mut s) };
        assert_eq!(st, want, "{}", last_error());
        // SAFETY: NULL or live.
        unsafe { curvetet_surface_free(s) };
    }
    // The same file with its inner shell taken as a region: two regions, meshed into one
    // mesh with a region id per tet.
    let mut s = null_mut();
    // SAFETY: a NUL-terminated path; the handles are live until freed.
    unsafe {
        let st =
            curvetet_surface_read_with_flags(p.as_ptr(), CURVETET_SURFACE_NESTED_REGIONS, &mut s);
        assert_eq!(st, curvetet_status::CURVETET_OK, "{}", last_error());
        assert_eq!(curvetet_surface_num_regions(s), 2);
        let mut m = null_mut();
        let st = curvetet_generate(s, null(), &mut m);
        assert_eq!(st, curvetet_status::CURVETET_OK, "{}", last_error());
        assert_eq!(curvetet_mesh_num_regions(m), 2);
        let n = curvetet_mesh_num_tets(m);
        let mut reg = vec![0i32; n];
        let st = curvetet_mesh_tet_regions(m, reg.as_mut_ptr());
        assert_eq!(st, curvetet_status::CURVETET_OK);
        assert_eq!(reg, (*m).generated.mesh.tet_regions);
        assert!(reg.contains(&1) && reg.contains(&2));
        curvetet_mesh_free(m);
        curvetet_surface_free(s);
    }
    // The linear constructor takes one surface only.
    assert_eq!(
        linear(CURVETET_SURFACE_NESTED_REGIONS),
        curvetet_status::CURVETET_ERR_INVALID_ARGUMENT
    );
}
