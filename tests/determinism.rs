//! Determinism: the same surface and options give byte-identical output files whatever the
//! thread count (1, 2, 4) and from run to run, for every tests/data P2 surface that meshes
//! (and every ../shared/data one, when present), through the library and through the CLI.

use curvetet::io::{mesh_to_bytes, Format, MshVersion, WriteOptions};
use curvetet::{generate, io, Options};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Surfaces that do not mesh yet, with the reason (they are skipped by name).
const SKIP: [(&str, &str); 1] = [(
    "hinge_p2.msh",
    "the front does not close on the hinge yet (MeshingFailed, see ARCHITECTURE.md)",
)];

fn surfaces() -> Vec<PathBuf> {
    let mut dirs = vec![PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")];
    let shared = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if shared.join("README.md").exists() {
        dirs.push(shared);
    }
    let mut out = Vec::new();
    for d in dirs {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.to_str().unwrap().ends_with("_p2.msh"))
            .collect();
        files.sort();
        for f in files {
            let name = f.file_name().unwrap().to_str().unwrap();
            if let Some((_, why)) = SKIP.iter().find(|(n, _)| *n == name) {
                eprintln!("NOTE: determinism: {} skipped: {why}", f.display());
                continue;
            }
            out.push(f);
        }
    }
    assert!(
        out.len() >= 5,
        "expected the tests/data surfaces, got {out:?}"
    );
    out
}

fn mesh_bytes(path: &Path, threads: usize) -> Vec<Vec<u8>> {
    let s = io::read_surface(path).unwrap();
    let opts = Options {
        threads,
        ..Options::default()
    };
    let g = generate(&s, &opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    // Every writer, so nothing format-specific hides a difference.
    let mut out = Vec::new();
    for (format, binary, version) in [
        (Format::Msh, false, MshVersion::V41),
        (Format::Msh, true, MshVersion::V22),
        (Format::Vtu, true, MshVersion::V41),
        (Format::Medit, false, MshVersion::V41),
    ] {
        let w = WriteOptions {
            msh_version: version,
            binary,
            ..WriteOptions::default()
        };
        out.push(mesh_to_bytes(&g.mesh, format, &w).unwrap());
    }
    out
}

#[test]
fn same_bytes_for_1_2_4_threads_and_across_runs() {
    for path in surfaces() {
        let one = mesh_bytes(&path, 1);
        for threads in [2, 4, 4] {
            let other = mesh_bytes(&path, threads);
            assert!(
                one == other,
                "{}: output differs between 1 and {threads} threads",
                path.display()
            );
        }
    }
}

#[test]
fn cli_output_files_identical_across_threads() {
    let dir = std::env::temp_dir().join(format!("curvetet-determinism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/torus_p2.msh");
    let mut files = Vec::new();
    for (run, threads) in [1, 2, 4, 4].into_iter().enumerate() {
        let out = dir.join(format!("torus_{run}_{threads}.msh"));
        let st = Command::new(env!("CARGO_BIN_EXE_curvetet"))
            .args(["mesh", "-q", "--threads", &threads.to_string()])
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        files.push(std::fs::read(&out).unwrap());
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(
        files.iter().all(|f| *f == files[0]),
        "CLI output differs between runs/threads"
    );
}
