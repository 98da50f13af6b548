//! Malformed, truncated and hostile input to every reader: always an `Err` (or, for
//! random mutations, any result), never a panic, never a long run, and never a large
//! allocation driven by a header count. A counting global allocator records the largest
//! single allocation made in this test binary; every input here is under a megabyte.

use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use curvetet::io::{mesh_to_bytes, read_bytes, Format, MshVersion, RawMesh, WriteOptions};
use curvetet::{Result, TetMesh};

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

/// No allocation in this binary may exceed this (inputs are < 1 MB).
const ALLOC_LIMIT: usize = 64 << 20;

fn assert_small_allocations() {
    let m = LARGEST.load(Ordering::Relaxed);
    assert!(m < ALLOC_LIMIT, "an allocation of {m} bytes");
}

/// Read without letting a panic escape: the panic is the failure.
fn guarded(bytes: &[u8], f: Format, what: &str) -> Result<RawMesh> {
    let t = Instant::now();
    let r = catch_unwind(AssertUnwindSafe(|| read_bytes(bytes, f, "input")));
    let dt = t.elapsed();
    assert!(
        dt < Duration::from_millis(500),
        "{what}: took {dt:?} on {} bytes",
        bytes.len()
    );
    match r {
        Ok(r) => r,
        Err(_) => panic!("{what}: the reader panicked"),
    }
}

fn expect_err(bytes: &[u8], f: Format, what: &str) -> String {
    match guarded(bytes, f, what) {
        Ok(m) => panic!(
            "{what}: accepted ({} nodes, {} tri6, {} tet10)",
            m.nodes.len(),
            m.tri6.len(),
            m.tet10.len()
        ),
        Err(e) => e.to_string(),
    }
}

/// A curved P2 mesh: one tet and its four faces.
fn small_mesh() -> TetMesh {
    let c = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut nodes = c.to_vec();
    for (k, [a, b]) in curvetet::geom::shape::TET10_EDGES.iter().enumerate() {
        let w = 0.01 * (k as f64 + 1.0) / 7.0;
        nodes.push(std::array::from_fn(|d| 0.5 * (c[*a][d] + c[*b][d]) + w));
    }
    // Edge mid node indices: (0,1)=4 (1,2)=5 (2,0)=6 (3,0)=7 (3,2)=8 (3,1)=9.
    TetMesh {
        nodes,
        tets: vec![[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]],
        boundary: vec![
            [0, 2, 1, 6, 5, 4],
            [0, 1, 3, 4, 9, 7],
            [0, 3, 2, 7, 8, 6],
            [1, 2, 3, 5, 8, 9],
        ],
        boundary_tags: vec![1, 2, 3, 3],
        groups: Default::default(),
        tet_regions: Vec::new(),
    }
}

fn sphere() -> RawMesh {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sphere_p2.msh");
    curvetet::io::read(&p).unwrap()
}

/// Every written variant, with the length of its shortest complete prefix: truncating
/// before it must fail.
fn written_files() -> Vec<(String, Format, Vec<u8>, usize)> {
    let mesh = small_mesh();
    let s = sphere();
    let big = TetMesh {
        nodes: s.nodes,
        tets: vec![],
        boundary: s.tri6,
        boundary_tags: s.tri6_tags,
        groups: Default::default(),
        tet_regions: Vec::new(),
    };
    let mut out = Vec::new();
    for (mname, m) in [("tet", &mesh), ("sphere", &big)] {
        for (ver, vn) in [(MshVersion::V41, "4.1"), (MshVersion::V22, "2.2")] {
            for bin in [false, true] {
                let o = WriteOptions::default()
                    .with_msh_version(ver)
                    .with_binary(bin);
                let b = mesh_to_bytes(m, Format::Msh, &o).unwrap();
                let end = last_end(&b, b"$EndElements");
                out.push((format!("{mname} msh {vn} bin={bin}"), Format::Msh, b, end));
            }
        }
        for bin in [false, true] {
            let o = WriteOptions::default().with_binary(bin);
            let b = mesh_to_bytes(m, Format::Vtu, &o).unwrap();
            let end = last_end(&b, b"</VTKFile>");
            out.push((format!("{mname} vtu bin={bin}"), Format::Vtu, b, end));
        }
        let b = mesh_to_bytes(m, Format::Vtk, &WriteOptions::default()).unwrap();
        // Legacy VTK has no end marker and CELL_DATA is optional: a cut inside the cell
        // types that drops all cell data can leave a valid file (a cut "22" reads as
        // type 2, a poly-vertex). Cuts before CELL_TYPES must fail; later ones must
        // only not panic (checked by `truncated_files_are_errors` too).
        let end = last_end(&b, b"CELL_TYPES") - b"CELL_TYPES".len();
        out.push((format!("{mname} vtk"), Format::Vtk, b, end));
        let b = mesh_to_bytes(m, Format::Medit, &WriteOptions::default()).unwrap();
        let end = last_end(&b, b"End");
        out.push((format!("{mname} medit"), Format::Medit, b, end));
    }
    // The shipped Gmsh-written file too.
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/torus_p2.msh");
    let b = std::fs::read(p).unwrap();
    let end = last_end(&b, b"$EndElements");
    out.push(("torus gmsh-written".into(), Format::Msh, b, end));
    out
}

fn last_end(b: &[u8], marker: &[u8]) -> usize {
    let k = b
        .windows(marker.len())
        .rposition(|w| w == marker)
        .expect("marker present");
    k + marker.len()
}

#[test]
fn every_written_file_reads_back() {
    for (what, f, b, _) in written_files() {
        guarded(&b, f, &what).unwrap();
    }
    assert_small_allocations();
}

#[test]
fn truncated_files_are_errors() {
    for (what, f, b, end) in written_files() {
        // Every byte for the small files, about 400 cut points for the large ones, and
        // every byte of the last 64 before the end.
        let step = (b.len() / 400).max(1);
        let mut cuts: Vec<usize> = (0..end).step_by(step).collect();
        cuts.extend(end.saturating_sub(64)..end);
        for cut in cuts {
            let e = expect_err(&b[..cut], f, &format!("{what} cut at {cut}"));
            assert!(
                e.contains("input"),
                "{what} cut at {cut}: no location in '{e}'"
            );
        }
        // Past the last point where a cut is detectable: no panic, nothing invented.
        for cut in end..b.len() {
            if let Ok(m) = guarded(&b[..cut], f, &format!("{what} cut at {cut}")) {
                assert!(m.tri6.len() + m.tet10.len() <= 4000, "{what}");
            }
        }
    }
    assert_small_allocations();
}

/// A tiny deterministic generator (xorshift64*).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn garbage_is_an_error() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let formats = [Format::Msh, Format::Vtu, Format::Vtk, Format::Medit];
    for f in formats {
        expect_err(b"", f, "empty");
        expect_err(b"\n\n  \t", f, "blank");
        for i in 0..300 {
            let len = rng.below(4096);
            let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
            expect_err(&bytes, f, &format!("{f:?} garbage {i}"));
        }
    }
    // Garbage after a valid header.
    for (head, f) in [
        (&b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"[..], Format::Msh),
        (b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n", Format::Msh),
        (b"$MeshFormat\n2.2 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n3\n", Format::Msh),
        (b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n", Format::Vtk),
        (b"MeshVersionFormatted 2\nDimension 3\nVertices\n", Format::Medit),
        (b"<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"3\" NumberOfCells=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">", Format::Vtu),
    ] {
        for i in 0..200 {
            let mut bytes = head.to_vec();
            let len = rng.below(512);
            bytes.extend((0..len).map(|_| rng.next() as u8));
            expect_err(&bytes, f, &format!("{f:?} header + garbage {i}"));
        }
    }
    assert_small_allocations();
}

/// Random byte changes to valid files: any result, but no panic, quickly.
#[test]
fn mutated_files_never_panic() {
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    let files: Vec<_> = written_files()
        .into_iter()
        .filter(|f| f.2.len() < 20_000)
        .collect();
    let specials: [&[u8]; 14] = [
        b"9",
        b"-1",
        b"0",
        b"99999999999999999999",
        b"18446744073709551615",
        b"4294967295",
        b"-9223372036854775808",
        b"2147483648",
        b"nan",
        b"$",
        b" ",
        b"\n",
        b"<",
        b"\"",
    ];
    // CURVETET_FUZZ_ITERS raises the count for a longer local run.
    let iters: usize = std::env::var("CURVETET_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(600);
    for (what, f, b, _) in &files {
        for i in 0..iters {
            let mut m = b.clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(m.len());
                match rng.below(4) {
                    0 => m[at] = rng.next() as u8,
                    1 => m[at] ^= 1 << rng.below(8),
                    2 => {
                        let s = specials[rng.below(specials.len())];
                        m.splice(at..at, s.iter().copied());
                    }
                    _ => {
                        let n = rng.below(16).min(m.len() - at);
                        m.drain(at..at + n);
                    }
                }
                if m.is_empty() {
                    break;
                }
            }
            let _ = guarded(&m, *f, &format!("{what} mutation {i}"));
        }
    }
    assert_small_allocations();
}

#[test]
fn huge_header_counts_are_errors_without_huge_allocations() {
    let cases: Vec<(Format, Vec<u8>)> = vec![
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4000000000 1 4000000000\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3000000000 1 3000000000\n2 1 0 3000000000\n1\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n18446744073709551615 3 1 3\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n2 1 0 1\n1\n0 0 0\n$EndNodes\n$Elements\n1 999999999999 1 2\n2 1 9 999999999999\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n999999999999 0 0 0\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 0 0 0 1 1 1 999999999999 1\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4294967294\n1 0 0 0\n".to_vec()),
        (Format::Msh, b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n99999999999\n1 9 99999999999 1\n".to_vec()),
        (Format::Msh, {
            let mut v = b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n".to_vec();
            for x in [1u64, 1 << 40, 1, 1 << 40] {
                v.extend_from_slice(&x.to_le_bytes());
            }
            v
        }),
        (Format::Msh, {
            let mut v = b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n".to_vec();
            for x in [1u64, 1, 1, 1] {
                v.extend_from_slice(&x.to_le_bytes());
            }
            for x in [2i32, 1, 0] {
                v.extend_from_slice(&x.to_le_bytes());
            }
            v.extend_from_slice(&u64::MAX.to_le_bytes());
            v
        }),
        (Format::Msh, {
            let mut v = b"$MeshFormat\n2.2 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n1\n".to_vec();
            v.extend_from_slice(&1i32.to_le_bytes());
            v.extend_from_slice(&[0u8; 24]);
            v.extend_from_slice(b"\n$EndNodes\n$Elements\n1\n");
            for x in [9i32, i32::MAX, i32::MAX] {
                v.extend_from_slice(&x.to_le_bytes());
            }
            v
        }),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4000000000 double\n0 0 0\n".to_vec()),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3000000000 double\n0 0 0\n".to_vec()),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 0 0\nCELLS 99999999999999 99999999999999\n1 0\n".to_vec()),
        (Format::Vtk, b"# vtk DataFile Version 5.1\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 0 0\nCELLS 99999999999999 99999999999999\nOFFSETS vtktypeint64\n0 1\n".to_vec()),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 0 0\nCELLS 1 2\n1 0\nCELL_TYPES 1\n1\nCELL_DATA 99999999999999\nSCALARS BoundaryTag int 1\nLOOKUP_TABLE default\n1\n".to_vec()),
        (Format::Medit, b"MeshVersionFormatted 2\nDimension 3\nVertices\n4000000000\n0 0 0 0\n".to_vec()),
        (Format::Medit, b"MeshVersionFormatted 2\nDimension 3\nVertices\n3000000000\n0 0 0 0\n".to_vec()),
        (Format::Medit, b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nTetrahedraP2\n99999999999999999\n1 1 1 1 1 1 1 1 1 1 0\n".to_vec()),
        (Format::Medit, b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nCorners\n99999999999999999\n1\n".to_vec()),
        (Format::Vtu, br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="99999999999" NumberOfCells="99999999999"><Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0</DataArray></Points></Piece></UnstructuredGrid></VTKFile>"#.to_vec()),
        (Format::Vtu, br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="18446744073709551615" NumberOfCells="18446744073709551615"></Piece></UnstructuredGrid></VTKFile>"#.to_vec()),
        (Format::Vtu, br#"<VTKFile type="UnstructuredGrid" header_type="UInt64"><UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="0"><Points><DataArray type="Float64" NumberOfComponents="3" format="binary">/////////////w==AAAA</DataArray></Points></Piece></UnstructuredGrid></VTKFile>"#.to_vec()),
    ];
    for (i, (f, b)) in cases.iter().enumerate() {
        let e = expect_err(b, *f, &format!("huge count case {i}"));
        assert!(e.contains("input"), "case {i}: {e}");
    }
    assert_small_allocations();
}

#[test]
fn out_of_range_indices_name_the_element() {
    let cases: Vec<(Format, &[u8], &str)> = vec![
        (
            Format::Msh,
            b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 1 1\n2 1 2 1\n17 1 2 4\n$EndElements\n",
            "element 17 refers to node 4",
        ),
        (
            Format::Msh,
            b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n5 2 2 0 1 1 2 0\n$EndElements\n",
            "element 5 refers to node 0",
        ),
        (
            Format::Vtk,
            b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n0 0 0 1 0 0 0 1 0\nCELLS 2 8\n3 0 1 2\n3 0 1 3\nCELL_TYPES 2\n5\n5\n",
            "cell 1 refers to point 3",
        ),
        (
            Format::Vtu,
            br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="3" NumberOfCells="1"><Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray></Points><Cells><DataArray type="Int64" Name="connectivity" format="ascii">0 1 7</DataArray><DataArray type="Int64" Name="offsets" format="ascii">3</DataArray><DataArray type="UInt8" Name="types" format="ascii">5</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>"#,
            "cell 0 refers to point 7",
        ),
        (
            Format::Medit,
            b"MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n2\n1 2 3 0\n1 2 4 0\nEnd\n",
            "Triangles element 2 refers to vertex 4",
        ),
    ];
    for (f, b, want) in cases {
        let e = expect_err(b, f, want);
        assert!(e.contains(want), "expected '{want}' in '{e}'");
    }
}

#[test]
fn bad_numbers_are_errors_with_their_line_and_nan_is_read() {
    let msh = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0.5.5 0\n0 1 0\n$EndNodes\n";
    let e = expect_err(msh, Format::Msh, "bad float");
    assert!(e.starts_with("input:11:"), "{e}");
    assert!(e.contains("0.5.5"), "{e}");
    let nan = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 nan 0\n0 1 inf\n$EndNodes\n$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n";
    let m = guarded(nan, Format::Msh, "nan").unwrap();
    assert!(m.nodes[1][1].is_nan() && m.nodes[2][2].is_infinite());
    let vtk = b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 0 zero\n";
    let e = expect_err(vtk, Format::Vtk, "bad vtk float");
    assert!(e.starts_with("input:6:"), "{e}");
    let medit = b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 x\nEnd\n";
    let e = expect_err(medit, Format::Medit, "bad medit ref");
    assert!(e.starts_with("input:5:"), "{e}");
    let vtu = b"<VTKFile type=\"UnstructuredGrid\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"1\" NumberOfCells=\"0\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n0 0\n1e\n</DataArray></Points></Piece></UnstructuredGrid></VTKFile>";
    let e = expect_err(vtu, Format::Vtu, "bad vtu float");
    assert!(e.starts_with("input:7:"), "{e}");
    // Binary msh errors give byte offsets.
    let mut bin = b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n".to_vec();
    let at = bin.len();
    bin.extend_from_slice(&5u64.to_le_bytes());
    let e = expect_err(&bin, Format::Msh, "short binary");
    assert!(e.starts_with("input: byte "), "{e}");
    assert!(at > 0);
}

#[test]
fn unsupported_variants_say_so() {
    for (f, b, want) in [
        (Format::Msh, &b"$MeshFormat\n4 0 8\n$EndMeshFormat\n"[..], "4.0 is not supported"),
        (Format::Msh, b"$MeshFormat\n3 0 8\n$EndMeshFormat\n", "unsupported MSH version"),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 bit\n", "data type 'bit' is not supported in a binary file"),
        (Format::Vtk, b"# vtk DataFile Version 4.2\nx\nASCII\nDATASET POLYDATA\n", "only UNSTRUCTURED_GRID"),
        (Format::Vtu, b"<VTKFile type=\"PolyData\"></VTKFile>", "only UnstructuredGrid"),
        (Format::Vtu, b"<VTKFile type=\"UnstructuredGrid\" compressor=\"vtkLZMADataCompressor\"><UnstructuredGrid><Piece NumberOfPoints=\"1\" NumberOfCells=\"0\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">AAAA</DataArray></Points></Piece></UnstructuredGrid></VTKFile>", "compressor 'vtkLZMADataCompressor' is not supported"),
        (Format::Vtu, b"<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"1\" NumberOfCells=\"0\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece></UnstructuredGrid><AppendedData encoding=\"raw\">_\x00<\xff</AppendedData></VTKFile>", "declares 1023360000 bytes but holds"),
        (Format::Medit, b"MeshVersionFormatted 2\nDimension 3\nVertices\n0\nTetrahedraP2Ordering\n10\n", "Ordering sections"),
    ] {
        let e = expect_err(b, f, want);
        assert!(e.contains(want), "expected '{want}' in '{e}'");
    }
}

#[test]
fn deeply_nested_xml_is_an_error_without_a_large_allocation() {
    // A VTU header then a megabyte of unclosed tags: refused at the nesting bound, long
    // before the reader holds one name per open tag.
    let mut b = b"<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">".to_vec();
    for _ in 0..300_000 {
        b.extend_from_slice(b"<a>");
    }
    let e = expect_err(&b, Format::Vtu, "unclosed tags");
    assert!(e.contains("nested more than 64 deep"), "{e}");
    assert_small_allocations();
}

/// Every prefix of the binary files other tools write (VTK's appended raw zlib and LZ4
/// .vtu, inline zlib .vtu, binary legacy .vtk; checked-in fuzz seeds) is an error or, when
/// only the closing tags (or a legacy file's optional cell data) are cut, the whole mesh:
/// never a panic or a different mesh.
#[test]
fn prefixes_of_compressed_and_binary_vtk_files_fail_cleanly() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    for (file, f) in [
        ("read_vtu/ico_tets_vtk_raw_zlib.vtu", Format::Vtu),
        ("read_vtu/ico_tets_vtk_raw_lz4_u32.vtu", Format::Vtu),
        ("read_vtu/ico_tets_vtk_default.vtu", Format::Vtu),
        ("read_vtu/ico_tets_meshio_default.vtu", Format::Vtu),
        ("read_vtk/ico_tets_vtk_binary.vtk", Format::Vtk),
    ] {
        let bytes = std::fs::read(seeds.join(file)).unwrap();
        let full = curvetet::io::read_bytes(&bytes, f, "input").unwrap();
        let mut errors = 0;
        for n in 0..bytes.len() {
            match curvetet::io::read_bytes(&bytes[..n], f, "input") {
                Ok(m) => {
                    assert_eq!(m.nodes, full.nodes, "{file}: prefix of {n} bytes");
                    assert_eq!(m.tri6, full.tri6, "{file}: prefix of {n} bytes");
                    assert_eq!(m.tet10, full.tet10, "{file}: prefix of {n} bytes");
                }
                Err(_) => errors += 1,
            }
        }
        // All but the prefixes that cut only the closing tags or cell data fail.
        assert!(
            errors + 256 >= bytes.len(),
            "{file}: {errors} of {}",
            bytes.len()
        );
    }
}
