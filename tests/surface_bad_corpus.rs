//! The bad-input corpus (tests/data/bad, made by make_bad.py): every file is rejected by
//! `Surface::new` with the defect kind EXPECTED.txt names, and the message names an
//! element (triangle, edge or node) or says why the whole model is rejected.

mod common;

use common::{data_dir, read_msh41};
use curvetet::{Error, Surface};

#[test]
fn every_bad_file_gives_its_expected_kind() {
    let dir = data_dir().join("bad");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    let mut n = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for line in expected.lines().filter(|l| !l.trim().is_empty()) {
        let (file, kind) = line.split_once(' ').expect("`filename kind-name`");
        let m = read_msh41(&dir.join(file));
        match Surface::new(m.nodes, m.tris, m.tags) {
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
    assert!(n >= 15, "only {n} corpus files");
    assert!(kinds.len() >= 14, "only {} kinds covered", kinds.len());
}

#[test]
fn every_corpus_file_is_listed() {
    let dir = data_dir().join("bad");
    let expected = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.ends_with(".msh") {
            assert!(
                expected
                    .lines()
                    .any(|l| l.split_whitespace().next() == Some(&name)),
                "{name} is not in EXPECTED.txt"
            );
        }
    }
}
