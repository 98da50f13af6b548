//! The never-invalid guarantee, proven by fault injection: `generate` corrupts its own mesh
//! just before the final check when CURVETET_INJECT_INVALID_MESH is set (see
//! `curvetet::generate::INJECT_FAULT_ENV`), and the check must catch it through every door:
//! the library (`Error::InvalidMesh` naming the element, the mesh kept for inspection), the
//! C ABI (`CURVETET_ERR_INVALID_MESH`, no mesh handed out) and the CLI (exit 6, no output
//! file unless `--keep-partial`). A fault on the first attempt only must be cured by the
//! restart with the front's next configuration.
//!
//! One test function: the variable is process-wide.

use curvetet::capi::{
    curvetet_generate, curvetet_last_error_message, curvetet_mesh, curvetet_mesh_free,
    curvetet_status, curvetet_surface, curvetet_surface_free, curvetet_surface_read,
};
use curvetet::generate::INJECT_FAULT_ENV;
use curvetet::{generate, Error, Options, Surface};
use std::ffi::{CStr, CString};
use std::path::PathBuf;
use std::process::Command;

fn sphere_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/sphere_p2.msh")
}

fn expect_invalid(s: &Surface, spec: &str, tet: usize, words: &str) {
    std::env::set_var(INJECT_FAULT_ENV, spec);
    let opts = Options::default().with_threads(2);
    match generate(s, &opts) {
        Err(Error::InvalidMesh {
            elements,
            msg,
            mesh,
        }) => {
            assert!(elements.contains(&tet), "{spec}: elements {elements:?}");
            assert!(msg.contains(words), "{spec}: message {msg}");
            let mesh = mesh.expect("the failing mesh is kept for --keep-partial");
            assert!(mesh.tets.len() > tet);
        }
        Err(e) => panic!("{spec}: expected InvalidMesh, got {e}"),
        Ok(_) => panic!("{spec}: a corrupted mesh was returned as valid"),
    }
    std::env::remove_var(INJECT_FAULT_ENV);
}

fn c_generate(path: &std::path::Path) -> (curvetet_status, String, bool) {
    let p = CString::new(path.to_str().unwrap()).unwrap();
    let mut s: *mut curvetet_surface = std::ptr::null_mut();
    // SAFETY: valid C string and out pointer.
    let st = unsafe { curvetet_surface_read(p.as_ptr(), &mut s) };
    assert_eq!(st, curvetet_status::CURVETET_OK);
    let mut m: *mut curvetet_mesh = std::ptr::null_mut();
    // SAFETY: live surface, NULL options (defaults), valid out pointer.
    let st = unsafe { curvetet_generate(s, std::ptr::null(), &mut m) };
    // SAFETY: the message pointer is valid until the next call on this thread.
    let msg = unsafe { CStr::from_ptr(curvetet_last_error_message()) }
        .to_string_lossy()
        .into_owned();
    let got_mesh = !m.is_null();
    // SAFETY: both are NULL or live handles we own.
    unsafe {
        curvetet_mesh_free(m);
        curvetet_surface_free(s);
    }
    (st, msg, got_mesh)
}

fn cli(spec: Option<&str>, keep_partial: bool, out: &std::path::Path) -> (i32, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_curvetet"));
    cmd.args(["mesh", "-q", "--threads", "2"])
        .arg(sphere_path())
        .arg("-o")
        .arg(out);
    if keep_partial {
        cmd.arg("--keep-partial");
    }
    match spec {
        Some(s) => cmd.env(INJECT_FAULT_ENV, s),
        None => cmd.env_remove(INJECT_FAULT_ENV),
    };
    let o = cmd.output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn corrupted_meshes_are_never_returned() {
    let s = curvetet::io::read_surface(&sphere_path()).unwrap();
    std::env::remove_var(INJECT_FAULT_ENV);
    let clean = generate(&s, &Options::default()).expect("the sphere meshes");
    assert!(clean.mesh.tets.len() > 20);

    // Library: an inverted tet (conformity) and a non-positive Jacobian (certification).
    expect_invalid(&s, "invert:7", 7, "inverted");
    expect_invalid(&s, "jacobian:11", 11, "not certified valid");
    expect_invalid(&s, "jacobian", 0, "not certified valid");

    // Elements left uncertified on the first attempt only: the pipeline runs again from
    // the front's next configuration (alpha x 0.8) and delivers a certified mesh.
    std::env::set_var(INJECT_FAULT_ENV, "jacobian-once:5");
    let g = generate(&s, &Options::default());
    std::env::remove_var(INJECT_FAULT_ENV);
    let g = g.expect("the restart delivers a certified mesh");
    assert_eq!(g.front.restarts, 1);
    assert_eq!(g.front.alpha, 0.8 * Options::default().alpha);
    assert_eq!(g.report.num_invalid, 0);
    assert!(curvetet::mesh::report::uncertified(&g.mesh).is_empty());
    assert_eq!(clean.front.restarts, 0);

    // C ABI.
    std::env::set_var(INJECT_FAULT_ENV, "jacobian:3");
    let (st, msg, got_mesh) = c_generate(&sphere_path());
    std::env::remove_var(INJECT_FAULT_ENV);
    assert_eq!(st, curvetet_status::CURVETET_ERR_INVALID_MESH, "{msg}");
    assert!(msg.contains("not certified valid"), "{msg}");
    assert!(!got_mesh);
    let (st, msg, got_mesh) = c_generate(&sphere_path());
    assert_eq!(st, curvetet_status::CURVETET_OK, "{msg}");
    assert!(got_mesh);

    // CLI: exit 6 and no file; with --keep-partial the file is written (still exit 6).
    let dir = std::env::temp_dir().join(format!("curvetet-invalid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out.msh");
    for spec in ["invert:2", "jacobian:2"] {
        let (code, err) = cli(Some(spec), false, &out);
        assert_eq!(code, 6, "{spec}: {err}");
        assert!(err.contains("invalid mesh"), "{spec}: {err}");
        assert!(!out.exists(), "{spec}: an invalid mesh was written");
        let (code, err) = cli(Some(spec), true, &out);
        assert_eq!(code, 6, "{spec}: {err}");
        assert!(err.contains("--keep-partial"), "{spec}: {err}");
        assert!(out.exists());
        std::fs::remove_file(&out).unwrap();
    }
    let (code, err) = cli(None, false, &out);
    assert_eq!(code, 0, "{err}");
    assert!(out.exists());
    std::fs::remove_dir_all(&dir).ok();
}
