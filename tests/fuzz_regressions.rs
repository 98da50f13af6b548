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
