//! `curvetet mesh --max-memory`: an input that would exceed the budget fails fast (exit 1,
//! a message naming the budget) instead of being killed by the OS; within the budget the
//! run is unchanged. A 4 GiB file (sparse: no disk used) is refused before it is read.

use curvetet::generate::estimated_peak_memory;
use curvetet::{io, Options, SizeMode};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn mesh(args: &[&str], input: &std::path::Path, out: &std::path::Path) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_curvetet"))
        .args(["mesh", "-q", "--threads", "1"])
        .args(args)
        .arg(input)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn max_memory_refuses_early_and_passes_otherwise() {
    let dir = std::env::temp_dir().join(format!("curvetet-maxmem-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out.msh");
    let sphere = data("sphere_p2.msh");

    // A generous budget: meshes as usual.
    let (code, err) = mesh(&["--max-memory", "4G"], &sphere, &out);
    assert_eq!(code, 0, "{err}");
    assert!(out.exists());
    std::fs::remove_file(&out).unwrap();

    // Over budget by the estimate of the meshing peak: exit 1, nothing written.
    let (code, err) = mesh(&["--max-memory", "200K"], &sphere, &out);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--max-memory") && err.contains("estimate"),
        "{err}"
    );
    assert!(!out.exists());
    // A tiny uniform size makes the estimate grow with the volume.
    let (code, err) = mesh(&["--max-memory", "1G", "--size", "0.001"], &sphere, &out);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--max-memory"), "{err}");

    // A huge input (4 GiB, sparse) fails at once, before reading.
    let huge = dir.join("huge.msh");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(4 << 30)
        .unwrap();
    let t = Instant::now();
    let (code, err) = mesh(&["--max-memory", "1G"], &huge, &out);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("reading this") && err.contains("--max-memory"),
        "{err}"
    );
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());

    // Bad values are usage errors.
    for bad in ["0", "-3G", "12Q", "lots"] {
        let (code, err) = mesh(&["--max-memory", bad], &sphere, &out);
        assert_eq!(code, 1, "{bad}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn estimate_grows_with_input_and_is_below_what_is_measured() {
    let s = io::read_surface(&data("sphere_p2.msh")).unwrap();
    let graded = estimated_peak_memory(&s, &Options::default());
    let fine = estimated_peak_memory(&s, &Options::default().with_size(SizeMode::Fixed(0.01)));
    assert!(graded > 0);
    assert!(fine > 100 * graded, "{fine} vs {graded}");
    // The sphere's graded mesh peaks at a few MiB; the estimate is a lower bound.
    assert!(graded < 8 << 20, "{graded}");
}

/// `curvetet ARGS` with its address space limited to `limit` bytes (as `prlimit --as`).
fn run_limited(args: &[&std::ffi::OsStr], limit: u64) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut c = Command::new(env!("CARGO_BIN_EXE_curvetet"));
    c.args(args);
    // SAFETY: only setrlimit, async-signal-safe, between fork and exec.
    unsafe {
        c.pre_exec(move || {
            let r = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &r) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    c.output().unwrap()
}

#[test]
fn a_vtu_of_ten_million_unclosed_tags_is_an_error_under_800_mib() {
    use std::os::unix::process::ExitStatusExt;
    let dir = std::env::temp_dir().join(format!("curvetet-tags-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tags.vtu");
    let mut b = b"<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">".to_vec();
    b.extend_from_slice(&b"<a>".repeat(10_000_000));
    std::fs::write(&path, &b).unwrap();
    drop(b);
    let out = dir.join("out.msh");
    let limit = 800 << 20;
    for args in [
        vec!["check".as_ref(), path.as_os_str()],
        vec![
            "mesh".as_ref(),
            path.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ],
    ] {
        let t = Instant::now();
        let o = run_limited(&args, limit);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.signal(), None, "{args:?}: killed: {err}");
        assert_eq!(o.status.code(), Some(3), "{args:?}: {err}");
        assert!(err.contains("tags.vtu") && err.contains("nested"), "{err}");
        assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    }
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_impossible_size_is_refused_at_once_without_max_memory() {
    // --size 0.001 on the unit sphere: the estimate is terabytes, above any machine's
    // available memory, the default budget.
    let dir = std::env::temp_dir().join(format!("curvetet-tiny-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out.msh");
    let t = Instant::now();
    let (code, err) = mesh(&["--size", "0.001"], &data("sphere_p2.msh"), &out);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("estimate") && err.contains("memory available"),
        "{err}"
    );
    assert!(t.elapsed() < Duration::from_secs(1), "{:?}", t.elapsed());
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).ok();
}
