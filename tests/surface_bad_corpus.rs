//! The bad-input corpus (tests/data/bad, made by make_bad.py and make_bad_linear.py):
//! every file is rejected with the defect kind EXPECTED.txt names, and the message names
//! an element (triangle, edge or node) or says why the whole model is rejected. P2 files
//! (.msh) go to `Surface::new`; linear files (.off, .stl) go through the real readers to
//! `Surface::from_linear`, and must give the same kinds as their P2 counterparts. Each case
//! must finish within 10 s (a hang guard). The kinds are those of the strict checks
//! (`Repair::Strict`, `--strict`); by default the files whose only defect is unused nodes
//! or orientation are repaired with a warning, and every other file is refused with the
//! same kind as under strict.

mod common;

use common::{data_dir, read_msh41};
use curvetet::surface::curve::{curve_linear, CurveOptions};
use curvetet::surface::Repair;
use curvetet::{io, Error, Result, Surface};

/// The corpus files that are repaired (with one warning) unless strict.
const REPAIRED: [&str; 5] = [
    "unused_node.msh",
    "flipped_triangle.msh",
    "shells_disagree.msh",
    "flipped_lin.off",
    "unused_vertex_lin.off",
];

/// The surface a corpus file makes: P2 files through `Surface::new_with_repair`, linear
/// ones through the product's reader and `curve_linear` (as `Surface::from_linear`).
fn corpus_surface_with(path: &std::path::Path, repair: Repair) -> Result<Surface> {
    let name = path.file_name().unwrap().to_str().unwrap();
    if name.ends_with(".msh") {
        let m = read_msh41(path);
        Surface::new_with_repair(m.nodes, m.tris, m.tags, repair)
    } else {
        let raw = io::read(path).unwrap_or_else(|e| panic!("{name}: the reader failed: {e}"));
        assert!(raw.tri6.is_empty(), "{name}: not a linear file");
        let opts = CurveOptions::default()
            .with_feature_angle_deg(40.0)
            .with_repair(repair);
        curve_linear(raw.nodes, raw.tri3, raw.tri3_tags, &opts)
    }
}

/// [`corpus_surface_with`] under the strict checks.
fn corpus_surface(path: &std::path::Path) -> Result<Surface> {
    corpus_surface_with(path, Repair::Strict)
}

#[test]
fn default_repairs_only_orientation_and_unused_nodes() {
    let dir = data_dir().join("bad");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    let mut repaired = 0;
    for line in expected.lines().filter(|l| !l.trim().is_empty()) {
        let (file, kind) = line.split_once(' ').expect("`filename kind-name`");
        match corpus_surface_with(&dir.join(file), Repair::Unambiguous) {
            Ok(s) => {
                assert!(REPAIRED.contains(&file), "{file} ({kind}) was accepted");
                let w = s.warnings();
                assert_eq!(w.len(), 1, "{file}: {w:?}");
                let what = if kind == "unused-node" {
                    "used by no triangle: dropped"
                } else {
                    "orientation was inconsistent: flipped"
                };
                assert!(w[0].contains(what), "{file}: {w:?}");
                // The repaired surface passes the strict checks as it is.
                let again = Surface::new_with_repair(
                    s.nodes().to_vec(),
                    s.triangles().to_vec(),
                    s.tags().to_vec(),
                    Repair::Strict,
                )
                .unwrap_or_else(|e| panic!("{file}: {e}"));
                assert!(
                    again.warnings().is_empty(),
                    "{file}: {:?}",
                    again.warnings()
                );
                repaired += 1;
            }
            Err(e) => {
                assert!(!REPAIRED.contains(&file), "{file}: not repaired: {e}");
                assert_eq!(
                    e.surface_defect().map(|k| k.name()),
                    Some(kind),
                    "{file}: {e}"
                );
            }
        }
    }
    assert_eq!(repaired, REPAIRED.len());
}

#[test]
fn every_bad_file_gives_its_expected_kind() {
    let dir = data_dir().join("bad");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    let mut n = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for line in expected.lines().filter(|l| !l.trim().is_empty()) {
        let (file, kind) = line.split_once(' ').expect("`filename kind-name`");
        let t = std::time::Instant::now();
        let result = corpus_surface(&dir.join(file));
        assert!(
            t.elapsed() < std::time::Duration::from_secs(10),
            "{file}: took {:?} (hang guard: 10 s per case)",
            t.elapsed()
        );
        match result {
            Err(Error::InvalidSurface { kind: k, msg }) => {
                assert_eq!(k.name(), kind, "{file}: {msg}");
                let names_something = [
                    "triangle ",
                    "edge (",
                    "node ",
                    "no triangles",
                    "bounding box",
                ]
                .iter()
                .any(|w| msg.contains(w));
                assert!(names_something, "{file}: message names no element: {msg}");
                eprintln!("{file}: {kind}: {msg}");
            }
            Err(e) => panic!("{file}: expected {kind}, got another error: {e}"),
            Ok(_) => panic!("{file}: expected {kind}, but the surface was accepted"),
        }
        kinds.insert(kind.to_string());
        n += 1;
    }
    assert!(n >= 25, "only {n} corpus files");
    assert!(kinds.len() >= 14, "only {} kinds covered", kinds.len());
    let linear = expected.lines().filter(|l| l.contains("_lin.")).count();
    assert!(linear >= 10, "only {linear} linear corpus files");
}

/// A zero-area facet is reported with its index (triangle 4 of degenerate_lin.off,
/// triangle 2 of degenerate_facet_lin.stl, whose corners weld to a repeated vertex).
#[test]
fn linear_zero_area_facets_are_named_by_index() {
    let dir = data_dir().join("bad");
    for (file, t) in [
        ("degenerate_lin.off", "triangle 4 (corners 1, 0, 4)"),
        ("degenerate_facet_lin.stl", "triangle 2 "),
    ] {
        let e = corpus_surface(&dir.join(file)).unwrap_err();
        assert_eq!(
            e.surface_defect().map(|k| k.name()),
            Some("degenerate-triangle")
        );
        assert!(e.to_string().contains(t), "{file}: {e}");
    }
}

#[test]
fn every_corpus_file_is_listed() {
    let dir = data_dir().join("bad");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.ends_with(".msh") || name.ends_with(".off") || name.ends_with(".stl") {
            assert!(
                expected
                    .lines()
                    .any(|l| l.split_whitespace().next() == Some(&name)),
                "{name} is not in EXPECTED.txt"
            );
        }
    }
}
