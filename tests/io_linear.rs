//! The linear surface readers (STL ASCII/binary, OFF, OBJ, PLY ASCII/binary LE/BE): the
//! same mesh written in every format reads back to the same welded vertices (bit-identical)
//! and triangles; truncated, mutated and hostile files give an `Err` (or, for random
//! mutations, any result), never a panic and never a large allocation driven by a header
//! count. A counting global allocator records the largest single allocation in this test
//! binary.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::fmt::Write as _;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};

use common::data_dir;
use curvetet::io::{read, read_bytes, Format, RawMesh};
use curvetet::Result;

struct Tracking;
static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        LARGEST.fetch_max(l.size(), Ordering::Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        LARGEST.fetch_max(l.size(), Ordering::Relaxed);
        System.alloc_zeroed(l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        LARGEST.fetch_max(new, Ordering::Relaxed);
        System.realloc(p, l, new)
    }
}

#[global_allocator]
static GLOBAL: Tracking = Tracking;

/// Read without letting a panic escape: the panic is the failure.
fn guarded(bytes: &[u8], f: Format, what: &str) -> Result<RawMesh> {
    match catch_unwind(AssertUnwindSafe(|| read_bytes(bytes, f, "input"))) {
        Ok(r) => r,
        Err(_) => panic!("{what}: the reader panicked"),
    }
}

/// The sphere's linear surface with coordinates rounded to f32 (so binary STL and float
/// PLY hold exactly the same values as the text formats).
fn sphere_f32() -> RawMesh {
    let mut m = read(&data_dir().join("sphere_lin.off")).unwrap();
    for p in &mut m.nodes {
        *p = p.map(|x| x as f32 as f64);
    }
    m
}

fn stl_ascii(m: &RawMesh) -> Vec<u8> {
    let mut s = String::from("solid sphere\n");
    for t in &m.tri3 {
        s.push_str("  facet normal 0 0 0\n    outer loop\n");
        for &v in t {
            let p = m.nodes[v as usize];
            writeln!(s, "      vertex {:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid sphere\n");
    s.into_bytes()
}

fn stl_binary(m: &RawMesh, header: &[u8]) -> Vec<u8> {
    let mut v = vec![b' '; 80];
    v[..header.len()].copy_from_slice(header);
    v.extend((m.tri3.len() as u32).to_le_bytes());
    for t in &m.tri3 {
        v.extend([0u8; 12]);
        for &i in t {
            for x in m.nodes[i as usize] {
                v.extend((x as f32).to_le_bytes());
            }
        }
        v.extend([0u8; 2]);
    }
    v
}

fn off(m: &RawMesh) -> Vec<u8> {
    let mut s = format!("OFF\n# sphere\n{} {} 0\n", m.nodes.len(), m.tri3.len());
    for p in &m.nodes {
        writeln!(s, "{:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    for t in &m.tri3 {
        writeln!(s, "3 {} {} {}", t[0], t[1], t[2]).unwrap();
    }
    s.into_bytes()
}

fn obj(m: &RawMesh) -> Vec<u8> {
    let mut s = String::from("# sphere\no sphere\n");
    for p in &m.nodes {
        writeln!(s, "v {:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    let n = m.nodes.len() as i64;
    for (k, t) in m.tri3.iter().enumerate() {
        // Mix the index forms: plain, v/t/n, v//n, negative.
        match k % 4 {
            0 => writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1),
            1 => writeln!(s, "f {}/1/1 {}/1/1 {}/1/1", t[0] + 1, t[1] + 1, t[2] + 1),
            2 => writeln!(s, "f {}//1 {}//1 {}//1", t[0] + 1, t[1] + 1, t[2] + 1),
            _ => writeln!(
                s,
                "f {} {} {}",
                t[0] as i64 - n,
                t[1] as i64 - n,
                t[2] as i64 - n
            ),
        }
        .unwrap();
    }
    s.into_bytes()
}

/// PLY: "ascii", "le" or "be"; float coordinates when `float` (else double).
fn ply(m: &RawMesh, enc: &str, float: bool) -> Vec<u8> {
    let ty = if float { "float" } else { "double" };
    let format = match enc {
        "ascii" => "ascii",
        "le" => "binary_little_endian",
        _ => "binary_big_endian",
    };
    let mut v = format!(
        "ply\nformat {format} 1.0\ncomment made by the test\nelement vertex {}\n\
         property {ty} x\nproperty {ty} y\nproperty {ty} z\nproperty uchar red\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.nodes.len(),
        m.tri3.len()
    )
    .into_bytes();
    let be = enc == "be";
    for p in &m.nodes {
        for x in p {
            match (enc, float) {
                ("ascii", _) => v.extend(format!("{x:?} ").bytes()),
                (_, true) if be => v.extend((*x as f32).to_be_bytes()),
                (_, true) => v.extend((*x as f32).to_le_bytes()),
                (_, false) if be => v.extend(x.to_be_bytes()),
                (_, false) => v.extend(x.to_le_bytes()),
            }
        }
        if enc == "ascii" {
            v.extend(b"255\n");
        } else {
            v.push(255);
        }
    }
    for t in &m.tri3 {
        if enc == "ascii" {
            v.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
        } else {
            v.push(3);
            for &i in t {
                v.extend(if be {
                    (i as i32).to_be_bytes()
                } else {
                    (i as i32).to_le_bytes()
                });
            }
        }
    }
    v
}

/// Every encoding of the f32 sphere: (name, format, bytes).
fn all_files(m: &RawMesh) -> Vec<(String, Format, Vec<u8>)> {
    let mut v = vec![
        ("ascii.stl".into(), Format::Stl, stl_ascii(m)),
        ("binary.stl".into(), Format::Stl, stl_binary(m, b"binary")),
        // A binary file whose header starts with "solid", as many exporters write.
        (
            "solid-binary.stl".into(),
            Format::Stl,
            stl_binary(m, b"solid sphere"),
        ),
        ("sphere.off".into(), Format::Off, off(m)),
        ("sphere.obj".into(), Format::Obj, obj(m)),
    ];
    for enc in ["ascii", "le", "be"] {
        for float in [true, false] {
            v.push((
                format!("{enc}-{float}.ply"),
                Format::Ply,
                ply(m, enc, float),
            ));
        }
    }
    v
}

#[test]
fn every_format_reads_back_the_same_welded_mesh() {
    let m = sphere_f32();
    for (name, f, bytes) in all_files(&m) {
        let r = read_bytes(&bytes, f, &name).unwrap_or_else(|e| panic!("{name}: {e}"));
        // Bit-identical coordinates, same numbering (first occurrence follows the file).
        let same = r.nodes.len() == m.nodes.len()
            && r.nodes
                .iter()
                .zip(&m.nodes)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits));
        if name.ends_with(".stl") {
            // STL has no vertex list: vertices are numbered by first use in the facets.
            assert_eq!(r.nodes.len(), m.nodes.len(), "{name}: welding");
            for (t, u) in r.tri3.iter().zip(&m.tri3) {
                for k in 0..3 {
                    assert_eq!(
                        r.nodes[t[k] as usize].map(f64::to_bits),
                        m.nodes[u[k] as usize].map(f64::to_bits),
                        "{name}"
                    );
                }
            }
        } else {
            assert!(same, "{name}: vertices differ");
            assert_eq!(r.tri3, m.tri3, "{name}");
        }
        assert_eq!(r.tri3_tags, vec![0; m.tri3.len()], "{name}");
    }
}

#[test]
fn ascii_and_binary_stl_weld_to_the_same_vertices() {
    let m = sphere_f32();
    let a = read_bytes(&stl_ascii(&m), Format::Stl, "a.stl").unwrap();
    let b = read_bytes(&stl_binary(&m, b"solid x"), Format::Stl, "b.stl").unwrap();
    assert_eq!(a, b);
    assert_eq!(a.nodes.len(), 356);
    // The shared data's own ASCII STL (17 digits) welds to its OFF twin's vertices exactly.
    if let Some(dir) = common::shared_data_dir() {
        for name in ["sphere", "tube"] {
            let s = read(&dir.join(format!("{name}_lin.stl"))).unwrap();
            let o = read(&dir.join(format!("{name}_lin.off"))).unwrap();
            assert_eq!(s.nodes.len(), o.nodes.len(), "{name}");
            let mut sn: Vec<[u64; 3]> = s.nodes.iter().map(|p| p.map(f64::to_bits)).collect();
            let mut on: Vec<[u64; 3]> = o.nodes.iter().map(|p| p.map(f64::to_bits)).collect();
            sn.sort_unstable();
            on.sort_unstable();
            assert_eq!(sn, on, "{name}");
        }
    }
}

#[test]
fn truncated_files_are_errors_not_panics() {
    let m = sphere_f32();
    let mut cuts_tried = 0;
    for (name, f, bytes) in all_files(&m) {
        let n = bytes.len();
        let mut cuts: Vec<usize> = (0..200).map(|k| k * n / 200).collect();
        cuts.extend([1, 5, 79, 80, 83, 84, 85, n - 1]);
        for cut in cuts {
            let r = guarded(&bytes[..cut], f, &format!("{name} cut at {cut}"));
            // OBJ has no counts: a file cut at a line end is a valid smaller mesh. Cutting
            // only trailing whitespace leaves a complete file.
            let only_ws = bytes[cut..].iter().all(|b| b.is_ascii_whitespace());
            if f != Format::Obj && !only_ws {
                assert!(r.is_err(), "{name} cut at {cut} of {n} was accepted");
            }
            cuts_tried += 1;
        }
    }
    assert!(cuts_tried > 2000);
    assert!(LARGEST.load(Ordering::Relaxed) < 64 << 20);
}

#[test]
fn mutated_files_never_panic() {
    let m = sphere_f32();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for (name, f, bytes) in all_files(&m) {
        for k in 0..150 {
            let mut b = bytes.clone();
            for _ in 0..1 + k % 8 {
                let i = (rnd() % b.len() as u64) as usize;
                b[i] = match rnd() % 4 {
                    0 => b'9',
                    1 => b'-',
                    2 => 0xff,
                    _ => (rnd() & 0xff) as u8,
                };
            }
            let _ = guarded(&b, f, &format!("{name} mutation {k}"));
        }
    }
    assert!(LARGEST.load(Ordering::Relaxed) < 64 << 20);
}

#[test]
fn hostile_counts_do_not_allocate() {
    let huge_stl = {
        let mut v = vec![0u8; 80];
        v.extend(u32::MAX.to_le_bytes());
        v.extend([0u8; 50]);
        v
    };
    let cases: Vec<(&str, Format, Vec<u8>)> =
        vec![
        ("count.stl", Format::Stl, huge_stl),
        (
            "count.off",
            Format::Off,
            b"OFF\n4000000000 4000000000 0\n0 0 0\n".to_vec(),
        ),
        (
            "count.ply",
            Format::Ply,
            b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
              property float y\nproperty float z\nelement face 4000000000\n\
              property list uint int vertex_indices\nend_header\n\0\0\0\0"
                .to_vec(),
        ),
        (
            "list.ply",
            Format::Ply,
            b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
              property float y\nproperty float z\nelement face 1\n\
              property list uint int vertex_indices\nend_header\n\xff\xff\xff\xff"
                .to_vec(),
        ),
        (
            "empty-element.ply",
            Format::Ply,
            b"ply\nformat ascii 1.0\nelement nothing 18446744073709551615\nend_header\n".to_vec(),
        ),
        (
            "poly.off",
            Format::Off,
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n".to_vec(),
        ),
        ("index.obj", Format::Obj, b"v 0 0 0\nf 1 2 99999999999999\n".to_vec()),
    ];
    for (name, f, bytes) in cases {
        let r = guarded(&bytes, f, name);
        assert!(r.is_err(), "{name} was accepted");
        eprintln!("{name}: {}", r.unwrap_err());
    }
    assert!(LARGEST.load(Ordering::Relaxed) < 64 << 20);
}
