//! Replays inputs the fuzzers found (tests/data/fuzz/<target>/*), and every fuzz seed
//! (fuzz/seeds/<target>/*), through the fuzz targets' own checks (fuzz/src/lib.rs), without
//! libFuzzer: a crash once found stays fixed. Each input must finish within 10 s.

#[allow(dead_code)]
#[path = "../fuzz/src/lib.rs"]
mod fuzz;

use std::path::Path;
use std::time::{Duration, Instant};

fn replay(dir: &Path) -> usize {
    let mut n = 0;
    for target in fuzz::TARGETS {
        let Ok(entries) = std::fs::read_dir(dir.join(target)) else {
            continue;
        };
        let mut files: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
        files.sort();
        for f in files {
            let data = std::fs::read(&f).unwrap();
            let t = Instant::now();
            let r = std::panic::catch_unwind(|| fuzz::run(target, &data));
            assert!(r.is_ok(), "{target}: {} panicked", f.display());
            assert!(
                t.elapsed() < Duration::from_secs(10),
                "{target}: {} took {:?}",
                f.display(),
                t.elapsed()
            );
            n += 1;
        }
    }
    n
}

#[test]
fn fuzz_regressions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found = replay(&root.join("tests/data/fuzz"));
    eprintln!("NOTE: replayed {found} fuzz regression inputs");
}

#[test]
fn fuzz_seeds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert!(replay(&root.join("fuzz/seeds")) >= 50);
}

/// The meshes the mesher refused when they were saved (tests/data/fuzz/mesh_icosphere:
/// `InvalidMesh`, all without the optimizer, where no restart was made then) and the
/// meshing seeds: each must now give a certified mesh or a clean MeshingFailed, never a
/// refusal of its own mesh.
#[test]
fn saved_refusals_now_certify() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    for dir in [
        "tests/data/fuzz/mesh_icosphere",
        "fuzz/seeds/mesh_icosphere",
    ] {
        let mut files: Vec<_> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            let data = std::fs::read(&f).unwrap();
            let r = std::panic::catch_unwind(|| fuzz::mesh_icosphere_strict(&data, true));
            assert!(r.is_ok(), "{}: refused or failed", f.display());
            n += 1;
        }
    }
    assert!(n >= 4, "{n} inputs");
}

/// Each crash the fuzzers found, by name, with the clean error it must now give (release
/// builds have no overflow checks, so the replay above alone would not see an overflow).
#[test]
fn fuzz_crashes_give_clean_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let cases: &[(&str, curvetet::io::Format, &str)] = &[
        // msh 4.1 binary: a node block count near u64::MAX overflowed `read + n`.
        (
            "read_msh/node_block_count_overflow.msh",
            curvetet::io::Format::Msh,
            "node blocks hold more nodes than the header says",
        ),
        // PLY with two 'vertex' elements (12, then 6): faces were checked against the
        // first count and indexed the second list out of bounds.
        (
            "read_ply/second_vertex_element",
            curvetet::io::Format::Ply,
            "a second 'vertex' element",
        ),
    ];
    for (file, format, words) in cases {
        let data = std::fs::read(dir.join(file)).unwrap();
        match curvetet::io::read_bytes(&data, *format, file) {
            Err(e @ curvetet::Error::Parse { .. }) => {
                assert!(e.to_string().contains(words), "{file}: {e}")
            }
            Err(e) => panic!("{file}: expected a parse error, got {e}"),
            Ok(_) => panic!("{file}: accepted"),
        }
    }
}
