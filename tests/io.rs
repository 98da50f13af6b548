//! Integration tests of curvetet::io: reading the benchmark surfaces, round trips of a
//! curved P2 mesh through every format we write (checking geometry, not only indices),
//! hand-written files in each foreign node order, and external readers (meshio, gmsh).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

use curvetet::geom::shape::{tet10_point, tri6_point};
use curvetet::io::{
    self, mesh_to_bytes, read_bytes, Format, MshVersion, RawMesh, WriteOptions, VOLUME_TAG,
};
use curvetet::{SurfaceDefect, TetMesh};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn out_dir(test: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/out")
        .join(test);
    std::fs::create_dir_all(&d).unwrap();
    d
}

// ------------------------------------------------------------------ geometry helpers

/// Volume enclosed by a P2 triangle surface: (1/3) * integral of x . n dA, with the
/// degree-4 Dunavant rule (the integrand is a degree-4 polynomial: exact).
fn p2_volume(nodes: &[[f64; 3]], tris: &[[u32; 6]]) -> f64 {
    let (a, b) = (0.445948490915965, 0.091576213509771);
    let (wa, wb) = (0.223381589678011, 0.109951743655322);
    let rule = [
        (a, a, wa),
        (1.0 - 2.0 * a, a, wa),
        (a, 1.0 - 2.0 * a, wa),
        (b, b, wb),
        (1.0 - 2.0 * b, b, wb),
        (b, 1.0 - 2.0 * b, wb),
    ];
    let mut v = 0.0;
    for t in tris {
        let x: [[f64; 3]; 6] = std::array::from_fn(|k| nodes[t[k] as usize]);
        for &(u, w, wt) in &rule {
            let p = tri6_point(&x, u, w);
            let n = curvetet::geom::shape::tri6_normal(&x, u, w);
            v += 0.5 * wt * (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / 3.0;
        }
    }
    v
}

/// A small genuinely curved P2 mesh: two positive tets sharing a face, every mid node
/// moved off its chord, coordinates with many significant digits, and the six boundary
/// triangles (outward) with tags in non-contiguous runs.
fn curved_mesh() -> TetMesh {
    let corners = [
        [0.1234567891234567, -0.2, 0.3],
        [1.1, 0.0371, 0.29],
        [0.13, 1.0123456789, 0.31],
        [0.11, 0.02, 1.3333333333333333],
        [0.5, 0.45, -0.7],
    ];
    let tets_c = [[0usize, 1, 2, 3], [0, 2, 1, 4]];
    let mut nodes: Vec<[f64; 3]> = corners.to_vec();
    let mut mid: HashMap<(usize, usize), u32> = HashMap::new();
    let mut mid_of = |a: usize, b: usize, nodes: &mut Vec<[f64; 3]>| -> u32 {
        let key = (a.min(b), a.max(b));
        *mid.entry(key).or_insert_with(|| {
            let k = nodes.len() as f64;
            let (p, q) = (corners[a], corners[b]);
            let wob = [
                0.05 * (1.3 * k).sin(),
                0.05 * (0.7 * k).cos(),
                0.05 * (2.1 * k + 0.5).sin(),
            ];
            nodes.push(std::array::from_fn(|d| 0.5 * (p[d] + q[d]) + wob[d]));
            nodes.len() as u32 - 1
        })
    };
    let tet_edges = curvetet::geom::shape::TET10_EDGES;
    let mut tets = Vec::new();
    for c in tets_c {
        let mut t = [0u32; 10];
        for k in 0..4 {
            t[k] = c[k] as u32;
        }
        for (k, [a, b]) in tet_edges.iter().enumerate() {
            t[4 + k] = mid_of(c[*a], c[*b], &mut nodes);
        }
        tets.push(t);
    }
    // Outward faces of a positive Gmsh tet.
    let faces = [[0usize, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut count: BTreeMap<[usize; 3], usize> = BTreeMap::new();
    for c in tets_c {
        for f in faces {
            let mut key = [c[f[0]], c[f[1]], c[f[2]]];
            key.sort();
            *count.entry(key).or_default() += 1;
        }
    }
    let mut boundary = Vec::new();
    for c in tets_c {
        for f in faces {
            let v = [c[f[0]], c[f[1]], c[f[2]]];
            let mut key = v;
            key.sort();
            if count[&key] == 1 {
                boundary.push([
                    v[0] as u32,
                    v[1] as u32,
                    v[2] as u32,
                    mid_of(v[0], v[1], &mut nodes),
                    mid_of(v[1], v[2], &mut nodes),
                    mid_of(v[2], v[0], &mut nodes),
                ]);
            }
        }
    }
    assert_eq!(boundary.len(), 6);
    TetMesh {
        nodes,
        tets,
        boundary,
        boundary_tags: vec![4, 7, 4, 2, 7, 9],
        groups: Default::default(),
        tet_regions: Vec::new(),
    }
}

const TET_POINTS: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [0.25, 0.25, 0.25],
    [0.1, 0.2, 0.3],
    [0.5, 0.5, 0.0],
    [0.0, 0.3, 0.6],
    [0.7, 0.1, 0.15],
];
const TRI_POINTS: [[f64; 2]; 5] = [
    [0.0, 0.0],
    [1.0 / 3.0, 1.0 / 3.0],
    [0.5, 0.5],
    [0.1, 0.7],
    [0.6, 0.2],
];

fn tet_xyz(nodes: &[[f64; 3]], t: &[u32; 10]) -> [[f64; 3]; 10] {
    std::array::from_fn(|k| nodes[t[k] as usize])
}
fn tri_xyz(nodes: &[[f64; 3]], t: &[u32; 6]) -> [[f64; 3]; 6] {
    std::array::from_fn(|k| nodes[t[k] as usize])
}

/// The mesh read back has the same curved geometry, element by element, exactly.
fn assert_same_geometry(what: &str, orig: &TetMesh, back: &RawMesh, tet_tag: i32) {
    assert_eq!(back.tet10.len(), orig.tets.len(), "{what}: tets");
    assert_eq!(back.tri6.len(), orig.boundary.len(), "{what}: triangles");
    for (i, (a, b)) in orig.tets.iter().zip(&back.tet10).enumerate() {
        let (xa, xb) = (tet_xyz(&orig.nodes, a), tet_xyz(&back.nodes, b));
        for p in TET_POINTS {
            assert_eq!(
                tet10_point(&xa, p),
                tet10_point(&xb, p),
                "{what}: tet {i} at {p:?}"
            );
        }
    }
    for (i, (a, b)) in orig.boundary.iter().zip(&back.tri6).enumerate() {
        let (xa, xb) = (tri_xyz(&orig.nodes, a), tri_xyz(&back.nodes, b));
        for [u, v] in TRI_POINTS {
            assert_eq!(
                tri6_point(&xa, u, v),
                tri6_point(&xb, u, v),
                "{what}: triangle {i} at {u},{v}"
            );
        }
    }
    assert_eq!(back.tri6_tags, orig.boundary_tags, "{what}: triangle tags");
    assert!(
        back.tet10_tags.iter().all(|&t| t == tet_tag),
        "{what}: tet tags"
    );
}

/// Every format/version/encoding combination we write.
fn variants() -> Vec<(String, Format, WriteOptions)> {
    let mut v = Vec::new();
    for (ver, vname) in [(MshVersion::V41, "41"), (MshVersion::V22, "22")] {
        for binary in [false, true] {
            v.push((
                format!("msh{vname}_{}.msh", if binary { "bin" } else { "ascii" }),
                Format::Msh,
                WriteOptions::default()
                    .with_msh_version(ver)
                    .with_binary(binary),
            ));
        }
    }
    for binary in [false, true] {
        v.push((
            format!("vtu_{}.vtu", if binary { "bin" } else { "ascii" }),
            Format::Vtu,
            WriteOptions::default().with_binary(binary),
        ));
    }
    v.push(("legacy.vtk".into(), Format::Vtk, WriteOptions::default()));
    v.push(("p2.mesh".into(), Format::Medit, WriteOptions::default()));
    v
}

fn tet_tag_of(format: Format) -> i32 {
    match format {
        Format::Msh | Format::Medit => VOLUME_TAG,
        Format::Vtu | Format::Vtk => 0,
        _ => unreachable!("{format:?} holds no tetrahedra"),
    }
}

// ------------------------------------------------------------------ reading data

#[test]
fn reads_the_benchmark_copies() {
    for (file, nodes, tris, v_p2) in [
        ("sphere_p2.msh", 1418, 708, 4.188659268),
        ("torus_p2.msh", 3312, 1656, 2.417959847),
    ] {
        let m = io::read(&data(file)).unwrap();
        assert_eq!(m.nodes.len(), nodes, "{file}");
        assert_eq!(m.tri6.len(), tris, "{file}");
        assert!(m.tri3.is_empty() && m.tet4.is_empty() && m.tet10.is_empty());
        assert_eq!(m.ignored_elements, 0);
        // No physical groups: the tag is the entity tag, 1.
        assert!(m.tri6_tags.iter().all(|&t| t == 1), "{file}");
        let v = p2_volume(&m.nodes, &m.tri6);
        assert!((v - v_p2).abs() < 1e-8, "{file}: volume {v} vs {v_p2}");
    }
}

/// The six benchmark surfaces in ../shared/data (present beside the repository in CI
/// and for developers); counts and P2 volumes from its README.
#[test]
fn reads_every_shared_benchmark_surface() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if !dir.is_dir() {
        println!("note: {} not found; skipped", dir.display());
        return;
    }
    for (file, nodes, tris, v_p2) in [
        ("sphere_p2.msh", 1418, 708, 4.188659268),
        ("torus_p2.msh", 3312, 1656, 2.417959847),
        ("tube_p2.msh", 4584, 2292, 4.71240098),
        ("lv_p2.msh", 4202, 2100, 3234.7592),
        ("screw_p2.msh", 830, 414, 3787.149008),
        ("hinge_p2.msh", 3912, 1960, 6336.122621),
    ] {
        let m = io::read(&dir.join(file)).unwrap();
        assert_eq!((m.nodes.len(), m.tri6.len()), (nodes, tris), "{file}");
        let v = p2_volume(&m.nodes, &m.tri6);
        // The README prints 8 to 10 significant digits.
        assert!((v - v_p2).abs() <= 2e-8 * v_p2, "{file}: {v} vs {v_p2}");
    }
}

// ------------------------------------------------------------------ round trips

#[test]
fn round_trip_every_format_keeps_curved_geometry() {
    let mesh = curved_mesh();
    let dir = out_dir("round_trip");
    for (file, format, opts) in variants() {
        let path = dir.join(&file);
        io::write_mesh(&path, &mesh, &opts).unwrap();
        let back = io::read(&path).unwrap();
        assert_same_geometry(&file, &mesh, &back, tet_tag_of(format));
        // Same node and element order too.
        assert_eq!(back.nodes, mesh.nodes, "{file}");
        assert_eq!(back.tet10, mesh.tets, "{file}");
        assert_eq!(back.tri6, mesh.boundary, "{file}");
        assert!(back.tri3.is_empty() && back.tet4.is_empty(), "{file}");
        // The in-memory writer gives the same bytes as the file writer.
        assert_eq!(
            std::fs::read(&path).unwrap(),
            mesh_to_bytes(&mesh, format, &opts).unwrap(),
            "{file}"
        );
        // And the RawMesh converts back to the TetMesh.
        assert_eq!(back.into_tet_mesh().unwrap().tets, mesh.tets);
    }
}

#[test]
fn round_trip_linear_medit_keeps_corners() {
    let mesh = curved_mesh();
    let opts = WriteOptions::default().with_medit_linear(true);
    let bytes = mesh_to_bytes(&mesh, Format::Medit, &opts).unwrap();
    let back = read_bytes(&bytes, Format::Medit, "lin.mesh").unwrap();
    assert!(back.tri6.is_empty() && back.tet10.is_empty());
    assert_eq!(back.nodes, mesh.nodes);
    let corners4: Vec<[u32; 4]> = mesh.tets.iter().map(|t| [t[0], t[1], t[2], t[3]]).collect();
    let corners3: Vec<[u32; 3]> = mesh.boundary.iter().map(|t| [t[0], t[1], t[2]]).collect();
    assert_eq!(back.tet4, corners4);
    assert_eq!(back.tri3, corners3);
    assert_eq!(back.tri3_tags, mesh.boundary_tags);
    // A linear surface cannot become a P2 mesh.
    let err = back.into_tet_mesh().unwrap_err();
    assert_eq!(err.surface_defect(), Some(SurfaceDefect::LinearSurface));
}

#[test]
fn round_trip_surface_only() {
    let m = io::read(&data("sphere_p2.msh")).unwrap();
    let dir = out_dir("surface");
    for (file, format, opts) in variants() {
        let path = dir.join(&file);
        let tags: Vec<i32> = (0..m.tri6.len()).map(|i| 1 + (i as i32 / 100)).collect();
        io::write_surface(&path, &m.nodes, &m.tri6, &tags, &opts).unwrap();
        let back = io::read(&path).unwrap();
        assert_eq!(back.nodes, m.nodes, "{file}");
        assert_eq!(back.tri6, m.tri6, "{file}");
        assert_eq!(back.tri6_tags, tags, "{file}");
        assert!(back.tet10.is_empty(), "{file}: {format:?}");
    }
}

/// Every boundary part is a group with a positive number in every format (issue 30):
/// positive tags are kept, 0 and then -3 take the first free numbers, 1 and 2.
#[test]
fn non_positive_tags_get_free_positive_groups() {
    let mut mesh = curved_mesh();
    mesh.boundary_tags = vec![0, 5, -3, 5, 0, 5];
    let want = vec![1, 5, 2, 5, 1, 5];
    for ver in [MshVersion::V41, MshVersion::V22] {
        for binary in [false, true] {
            let opts = WriteOptions::default()
                .with_msh_version(ver)
                .with_binary(binary);
            let bytes = mesh_to_bytes(&mesh, Format::Msh, &opts).unwrap();
            let back = read_bytes(&bytes, Format::Msh, "t.msh").unwrap();
            assert_eq!(back.tri6_tags, want, "{ver:?} binary {binary}");
            // Tag 0 is the group named `boundary`, the volume `volume`.
            let names: Vec<_> = back
                .physical_names
                .iter()
                .map(|n| (n.dim, n.tag, n.name.as_str()))
                .collect();
            assert_eq!(names, vec![(2, 1, "boundary"), (3, 1, "volume")]);
            assert!(back.tet10_tags.iter().all(|&t| t == 1));
        }
    }
    for f in [Format::Vtu, Format::Vtk, Format::Medit] {
        let bytes = mesh_to_bytes(&mesh, f, &WriteOptions::default()).unwrap();
        let back = read_bytes(&bytes, f, "t").unwrap();
        assert_eq!(back.tri6_tags, want, "{f:?}");
    }
}

#[test]
fn writer_rejects_bad_input() {
    let mut mesh = curved_mesh();
    mesh.tets[1][7] = 999;
    let e = mesh_to_bytes(&mesh, Format::Msh, &WriteOptions::default()).unwrap_err();
    assert!(e.to_string().contains("tetrahedron 1"), "{e}");
    let mut mesh = curved_mesh();
    mesh.boundary_tags.pop();
    assert!(mesh_to_bytes(&mesh, Format::Vtu, &WriteOptions::default()).is_err());
    let mesh = curved_mesh();
    let bin = WriteOptions::default().with_binary(true);
    assert!(mesh_to_bytes(&mesh, Format::Vtk, &bin).is_err());
    assert!(mesh_to_bytes(&mesh, Format::Medit, &bin).is_err());
    assert!(io::write_mesh(Path::new("x.stl"), &mesh, &WriteOptions::default()).is_err());
}

// ------------------------------------------------------------------ foreign node orders

/// A straight reference tet whose mid nodes sit at their edge midpoints, listed in the
/// node order of `edges`; returns (points, 10 node indices) with the nodes shuffled so
/// that no index equals its position.
fn straight_tet_in_order(edges: &[[usize; 2]; 6]) -> (Vec<[f64; 3]>, [usize; 10]) {
    let c = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 4.0, 0.0],
        [0.0, 0.0, 8.0],
    ];
    let mut pts: Vec<[f64; 3]> = c.to_vec();
    for [a, b] in edges {
        pts.push(std::array::from_fn(|d| 0.5 * (c[*a][d] + c[*b][d])));
    }
    // Store points in reverse so indices differ from positions.
    let rev: Vec<[f64; 3]> = pts.iter().rev().copied().collect();
    let idx: [usize; 10] = std::array::from_fn(|k| 9 - k);
    (rev, idx)
}

/// Each Gmsh-order mid node of every tet read is the midpoint of its Gmsh edge, and each
/// triangle mid node the midpoint of its Gmsh edge.
fn assert_gmsh_order(what: &str, m: &RawMesh) {
    assert!(!m.tet10.is_empty() || !m.tri6.is_empty(), "{what}");
    for t in &m.tet10 {
        let x = tet_xyz(&m.nodes, t);
        for (k, [a, b]) in curvetet::geom::shape::TET10_EDGES.iter().enumerate() {
            let mid: [f64; 3] = std::array::from_fn(|d| 0.5 * (x[*a][d] + x[*b][d]));
            assert_eq!(x[4 + k], mid, "{what}: tet node {}", 4 + k);
        }
    }
    for t in &m.tri6 {
        let x = tri_xyz(&m.nodes, t);
        for (k, [a, b]) in curvetet::geom::shape::TRI6_EDGES.iter().enumerate() {
            let mid: [f64; 3] = std::array::from_fn(|d| 0.5 * (x[*a][d] + x[*b][d]));
            assert_eq!(x[3 + k], mid, "{what}: triangle node {}", 3 + k);
        }
    }
}

const VTK_TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
const GMSH_TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]];

fn pts_text(pts: &[[f64; 3]], suffix: &str) -> String {
    pts.iter()
        .map(|p| format!("{} {} {}{suffix}\n", p[0], p[1], p[2]))
        .collect()
}
fn idx_text(idx: &[usize], base: usize) -> String {
    idx.iter()
        .map(|i| (i + base).to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn hand_written_vtk_files_in_vtk_order() {
    let (pts, idx) = straight_tet_in_order(&VTK_TET_EDGES);
    // The face (0,1,2) of that tet as a quadratic triangle: corners 9,8,7 (positions of
    // corners 0,1,2) and mids of (0,1), (1,2), (2,0) = tet nodes 4, 5, 6.
    let tri = [idx[0], idx[1], idx[2], idx[4], idx[5], idx[6]];
    let legacy = format!(
        "# vtk DataFile Version 5.1\nhand\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 10 double\n{}\
         CELLS 3 16\nOFFSETS vtktypeint64\n0 10 16\nCONNECTIVITY vtktypeint64\n{}\n{}\n\
         CELL_TYPES 2\n24\n22\nCELL_DATA 2\nFIELD FieldData 1\ngmsh:physical 1 2 int\n0 17\n",
        pts_text(&pts, ""),
        idx_text(&idx, 0),
        idx_text(&tri, 0)
    );
    let m = read_bytes(legacy.as_bytes(), Format::Vtk, "hand.vtk").unwrap();
    assert_gmsh_order("legacy 5.1", &m);
    assert_eq!(m.tri6_tags, vec![17]);
    let vtu = format!(
        r#"<?xml version="1.0"?>
<!-- hand written -->
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
 <UnstructuredGrid><Piece NumberOfPoints="10" NumberOfCells="2">
  <PointData><DataArray type="Float32" Name="junk" format="ascii">1 2 3 4 5 6 7 8 9 10</DataArray></PointData>
  <Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">{}</DataArray></Points>
  <Cells>
   <DataArray type="Int32" Name="connectivity" format="ascii">{} {}</DataArray>
   <DataArray type="Int32" Name="offsets" format="ascii">10 16</DataArray>
   <DataArray type="UInt8" Name="types" format="ascii">24 22</DataArray>
  </Cells>
  <CellData><DataArray type="Int32" Name="medit:ref" format="ascii">3 4</DataArray>
   <DataArray type="Int64" Name="BoundaryTag" format="ascii">0 21</DataArray></CellData>
 </Piece></UnstructuredGrid>
</VTKFile>"#,
        pts_text(&pts, ""),
        idx_text(&idx, 0),
        idx_text(&tri, 0)
    );
    let m = read_bytes(vtu.as_bytes(), Format::Vtu, "hand.vtu").unwrap();
    assert_gmsh_order("vtu", &m);
    assert_eq!(
        m.tri6_tags,
        vec![21],
        "BoundaryTag preferred over medit:ref"
    );
}

#[test]
fn hand_written_medit_file_in_george_order() {
    let (pts, idx) = straight_tet_in_order(&VTK_TET_EDGES);
    let tri = [idx[0], idx[1], idx[2], idx[4], idx[5], idx[6]];
    let text = format!(
        "MeshVersionFormatted 2\n# comment\nDimension\n3\nVertices\n10\n{}\
         TrianglesP2\n1\n{} 8\nTetrahedraP2\n1\n{} 1\nEnd\n",
        pts_text(&pts, " 0"),
        idx_text(&tri, 1),
        idx_text(&idx, 1)
    );
    let m = read_bytes(text.as_bytes(), Format::Medit, "hand.mesh").unwrap();
    assert_gmsh_order("medit", &m);
    assert_eq!(m.tri6_tags, vec![8]);
}

#[test]
fn hand_written_msh_files_in_gmsh_order() {
    let (pts, idx) = straight_tet_in_order(&GMSH_TET_EDGES);
    let tri = [idx[0], idx[1], idx[2], idx[4], idx[5], idx[6]];
    // Sparse, unordered node tags: tag of point i is 1000 - 7 i.
    let tag = |i: usize| 1000 - 7 * i;
    let tags_of = |ix: &[usize]| {
        ix.iter()
            .map(|&i| tag(i).to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let nodes22: String = pts
        .iter()
        .enumerate()
        .map(|(i, p)| format!("{} {} {} {}\n", tag(i), p[0], p[1], p[2]))
        .collect();
    let msh22 = format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 5 \"wall $End\"\n$EndPhysicalNames\n\
         $Nodes\n10\n{nodes22}$EndNodes\n$Elements\n4\n\
         1 15 2 0 1 {}\n2 1 2 0 1 {} {}\n3 9 2 5 1 {}\n4 11 2 0 3 {}\n$EndElements\n$Junk\nabc\n$EndJunk\n",
        tag(0),
        tag(0),
        tag(1),
        tags_of(&tri),
        tags_of(&idx)
    );
    let m = read_bytes(msh22.as_bytes(), Format::Msh, "hand22.msh").unwrap();
    assert_gmsh_order("msh 2.2", &m);
    assert_eq!(m.tri6_tags, vec![5], "physical tag");
    assert_eq!(m.tet10_tags, vec![3], "elementary tag when physical is 0");
    assert_eq!(m.ignored_elements, 2);

    let ntags: String = (0..10).map(|i| format!("{}\n", tag(i))).collect();
    let coords: String = pts
        .iter()
        .map(|p| format!("{} {} {} 0.5 0.25\n", p[0], p[1], p[2]))
        .collect();
    let msh41 = format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
         $Entities\n1 0 2 1\n7 0 0 0 0\n11 0 0 0 1 1 1 1 42 0\n12 0 0 0 1 1 1 2 1 2 0\n\
         5 0 0 0 1 1 1 1 77 2 11 -12\n$EndEntities\n\
         $Nodes\n1 10 {} {}\n2 12 1 10\n{ntags}{coords}$EndNodes\n\
         $Elements\n4 3 1 3\n0 7 15 1\n1 {}\n2 11 9 1\n2 {}\n2 12 2 0\n3 5 11 1\n3 {}\n$EndElements\n",
        tag(9),
        tag(0),
        tag(0),
        tags_of(&tri),
        tags_of(&idx)
    );
    let m = read_bytes(msh41.as_bytes(), Format::Msh, "hand41.msh").unwrap();
    assert_gmsh_order("msh 4.1", &m);
    assert_eq!(m.tri6_tags, vec![42], "single physical group");
    assert_eq!(m.tet10_tags, vec![77]);
    assert_eq!(m.ignored_elements, 1);
}

// ------------------------------------------------------------------ external readers

fn has_python_meshio() -> bool {
    Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

const MESHIO_CHECK: &str = r#"
import json, sys
import numpy as np
import meshio
spec = json.loads(sys.argv[1])
EDGES = {"tetra10": [(0,1),(1,2),(2,0),(0,3),(1,3),(2,3)], "triangle6": [(0,1),(1,2),(2,0)]}
for f in spec:
    m = meshio.read(f["path"])
    counts = {}
    for b in m.cells:
        counts[b.type] = counts.get(b.type, 0) + len(b.data)
    assert counts == f["cells"], (f["path"], counts, f["cells"])
    for b in m.cells:
        e = EDGES.get(b.type)
        if e is None:
            continue
        nc = len(e) + (4 if b.type == "tetra10" else 3)
        ncorner = nc - len(e)
        for c in b.data:
            P = m.points[c]
            for k, (i, j) in enumerate(e):
                d = np.linalg.norm(P[ncorner:] - (P[i] + P[j]) / 2, axis=1)
                assert int(np.argmin(d)) == k, (f["path"], b.type, k, d)
    key = f.get("tag_key")
    if key:
        got = []
        for b, d in zip(m.cells, m.cell_data[key]):
            if b.type in ("triangle6", "triangle"):
                got += [int(x) for x in np.asarray(d).reshape(-1)]
        assert got == f["tags"], (f["path"], got, f["tags"])
print("meshio ok", len(spec))
"#;

#[test]
fn meshio_reads_what_we_write() {
    if !has_python_meshio() {
        skip("python3 with meshio not available; skipped (pip install meshio)");
        return;
    }
    let mesh = curved_mesh();
    let dir = out_dir("meshio");
    let mut spec = Vec::new();
    let mut files: Vec<(String, Format, WriteOptions)> = variants()
        .into_iter()
        .filter(|v| v.1 != Format::Medit)
        .collect();
    files.push((
        "linear.mesh".into(),
        Format::Medit,
        WriteOptions::default().with_medit_linear(true),
    ));
    for (file, format, opts) in files {
        let path = dir.join(&file);
        io::write_mesh(&path, &mesh, &opts).unwrap();
        let (cells, key) = match format {
            Format::Medit => (r#"{"triangle": 6, "tetra": 2}"#, "medit:ref"),
            Format::Msh => (r#"{"triangle6": 6, "tetra10": 2}"#, "gmsh:physical"),
            _ => (r#"{"triangle6": 6, "tetra10": 2}"#, "BoundaryTag"),
        };
        spec.push(format!(
            r#"{{"path": "{}", "cells": {cells}, "tag_key": "{key}", "tags": {:?}}}"#,
            path.display(),
            mesh.boundary_tags
        ));
    }
    let arg = format!("[{}]", spec.join(","));
    let out = Command::new("python3")
        .args(["-c", MESHIO_CHECK, &arg])
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "meshio failed:\n{text}");
    assert!(
        !text.to_lowercase().contains("warn"),
        "meshio warned:\n{text}"
    );
}

fn has_gmsh() -> bool {
    Command::new("gmsh")
        .arg("-version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

#[test]
fn gmsh_checks_what_we_write_without_warnings() {
    if !has_gmsh() {
        skip("gmsh not available; skipped");
        return;
    }
    let mesh = curved_mesh();
    let dir = out_dir("gmsh");
    let mut files: Vec<(String, Vec<u8>, usize)> = Vec::new();
    for (file, format, opts) in variants() {
        if format == Format::Msh {
            files.push((file, mesh_to_bytes(&mesh, format, &opts).unwrap(), 8));
        }
    }
    // Tags that cannot be physical tags (entities without a physical group).
    let mut odd = mesh.clone();
    odd.boundary_tags = vec![0, 5, -3, 5, 0, 5];
    for ver in [MshVersion::V41, MshVersion::V22] {
        let opts = WriteOptions::default().with_msh_version(ver);
        let name = format!("odd_tags_{ver:?}.msh");
        files.push((name, mesh_to_bytes(&odd, Format::Msh, &opts).unwrap(), 8));
    }
    let sphere = io::read(&data("sphere_p2.msh")).unwrap();
    let tags: Vec<i32> = (0..sphere.tri6.len()).map(|i| 1 + (i as i32 % 3)).collect();
    for bin in [false, true] {
        let p = dir.join(format!("sphere_{bin}.msh"));
        let opts = WriteOptions::default().with_binary(bin);
        io::write_surface(&p, &sphere.nodes, &sphere.tri6, &tags, &opts).unwrap();
        files.push((
            format!("sphere_{bin}.msh"),
            std::fs::read(&p).unwrap(),
            sphere.tri6.len(),
        ));
    }
    for (file, bytes, nelem) in files {
        let path = dir.join(&file);
        std::fs::write(&path, bytes).unwrap();
        let out = Command::new("gmsh")
            .arg("-check")
            .arg(&path)
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out.status.success(), "{file}: gmsh failed\n{text}");
        assert!(
            !text.contains("Warning") && !text.contains("Error"),
            "{file}: gmsh complained\n{text}"
        );
        assert!(
            text.contains(&format!(" {nelem} elements")),
            "{file}: expected {nelem} elements\n{text}"
        );
    }
}

/// Gmsh's own .msh -> .mesh conversion of a file we wrote reads back, with our medit
/// reader, as the same curved geometry: our medit P2 order is the one Gmsh writes.
#[test]
fn gmsh_medit_export_matches_our_medit_order() {
    if !has_gmsh() {
        skip("gmsh not available; skipped");
        return;
    }
    let mesh = curved_mesh();
    let dir = out_dir("gmsh_medit");
    let msh = dir.join("in.msh");
    io::write_mesh(&msh, &mesh, &WriteOptions::default()).unwrap();
    let out_mesh = dir.join("out.mesh");
    let out = Command::new("gmsh")
        .arg(&msh)
        .args(["-0", "-setnumber", "Mesh.ElementOrder", "2", "-o"])
        .arg(&out_mesh)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let back = io::read(&out_mesh).unwrap();
    // Gmsh numbers the nodes its own way and prints 14 significant digits: compare
    // each tet's ten node positions, in order, to 1e-12.
    assert_eq!(back.tet10.len(), mesh.tets.len(), "tets: {back:?}");
    for (a, b) in mesh.tets.iter().zip(&back.tet10) {
        let (xa, xb) = (tet_xyz(&mesh.nodes, a), tet_xyz(&back.nodes, b));
        for k in 0..10 {
            for d in 0..3 {
                assert!(
                    (xa[k][d] - xb[k][d]).abs() < 1e-12,
                    "node {k}: {xa:?} vs {xb:?}"
                );
            }
        }
    }
}

// ------------------------------------------------------------------ binary variants

/// A binary MSH 4.1 file built by hand: big- or little-endian, `size_t` of 4 or 8
/// bytes, one surface entity in physical group 9, sparse node tags, one 6-node triangle.
fn msh41_binary(big_endian: bool, ds: usize) -> Vec<u8> {
    let i32b = |v: i32| {
        if big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let f64b = |v: f64| {
        if big_endian {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let size = |v: u64| -> Vec<u8> {
        let mut b = if ds == 4 {
            (v as u32).to_le_bytes().to_vec()
        } else {
            v.to_le_bytes().to_vec()
        };
        if big_endian {
            b.reverse();
        }
        b
    };
    let mut v = format!("$MeshFormat\n4.1 1 {ds}\n").into_bytes();
    v.extend(i32b(1));
    v.extend(b"\n$EndMeshFormat\n$Entities\n");
    for n in [0, 0, 1, 0] {
        v.extend(size(n));
    }
    v.extend(i32b(3));
    for x in [0.0, 0.0, 0.0, 1.0, 1.0, 0.0] {
        v.extend(f64b(x));
    }
    v.extend(size(1));
    v.extend(i32b(9));
    v.extend(size(0));
    v.extend(b"\n$EndEntities\n$Nodes\n");
    for n in [1, 6, 10, 60] {
        v.extend(size(n));
    }
    v.extend(i32b(2));
    v.extend(i32b(3));
    v.extend(i32b(0));
    v.extend(size(6));
    for t in [60u64, 50, 40, 30, 20, 10] {
        v.extend(size(t));
    }
    let pts = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.0],
    ];
    for p in pts {
        for x in p {
            v.extend(f64b(x));
        }
    }
    v.extend(b"\n$EndNodes\n$Elements\n");
    for n in [1, 1, 1, 1] {
        v.extend(size(n));
    }
    v.extend(i32b(2));
    v.extend(i32b(3));
    v.extend(i32b(9));
    v.extend(size(1));
    v.extend(size(1));
    for t in [60u64, 50, 40, 30, 20, 10] {
        v.extend(size(t));
    }
    v.extend(b"\n$EndElements\n");
    v
}

#[test]
fn binary_msh_of_either_endianness_and_size_t() {
    for be in [false, true] {
        for ds in [4, 8] {
            let b = msh41_binary(be, ds);
            let m = read_bytes(&b, Format::Msh, "bin.msh").unwrap();
            // Nodes are numbered by ascending tag: tags 60..10 become indices 5..0.
            assert_eq!(m.tri6, vec![[5, 4, 3, 2, 1, 0]], "be={be} ds={ds}");
            assert_eq!(m.tri6_tags, vec![9]);
            assert_eq!(m.nodes[m.tri6[0][4] as usize], [0.5, 0.5, 0.0]);
            assert_gmsh_order("binary 4.1", &m);
        }
    }
    // MSH 2.2 binary, big-endian: 3 nodes, one 3-node triangle, physical 4.
    let mut v = b"$MeshFormat\n2.2 1 8\n".to_vec();
    v.extend(1i32.to_be_bytes());
    v.extend(b"\n$EndMeshFormat\n$Nodes\n3\n");
    for (t, p) in [
        (7i32, [0.0f64, 0.0, 1.0]),
        (8, [1.0, 0.0, 1.0]),
        (9, [0.0, 1.0, 1.0]),
    ] {
        v.extend(t.to_be_bytes());
        for x in p {
            v.extend(x.to_be_bytes());
        }
    }
    v.extend(b"\n$EndNodes\n$Elements\n1\n");
    for x in [2i32, 1, 2, 1, 4, 5, 9, 8, 7] {
        v.extend(x.to_be_bytes());
    }
    v.extend(b"\n$EndElements\n");
    let m = read_bytes(&v, Format::Msh, "be22.msh").unwrap();
    assert_eq!(m.tri3, vec![[2, 1, 0]]);
    assert_eq!(m.tri3_tags, vec![4]);
    assert_eq!(m.nodes[1], [1.0, 0.0, 1.0]);
}

#[test]
fn vtu_binary_header_styles_and_byte_orders() {
    use base64::Engine;
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let pts: [f64; 18] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.5, 0.0,
    ];
    for big in [false, true] {
        for header64 in [false, true] {
            for separate in [false, true] {
                // Encode an array the way VTK (separate header) or meshio (one stream) does.
                let enc = |data: Vec<u8>| -> String {
                    let n = data.len() as u64;
                    let mut h = if header64 {
                        n.to_le_bytes().to_vec()
                    } else {
                        (n as u32).to_le_bytes().to_vec()
                    };
                    if big {
                        h.reverse();
                    }
                    if separate {
                        format!("{}{}", b64(&h), b64(&data))
                    } else {
                        h.extend(data);
                        b64(&h)
                    }
                };
                let f = |x: f64| {
                    if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    }
                };
                let i = |x: i32| {
                    if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    }
                };
                let points = enc(pts.iter().flat_map(|&x| f(x)).collect());
                let conn = enc([0, 1, 2, 3, 4, 5].iter().flat_map(|&x| i(x)).collect());
                let offs = enc(i(6).to_vec());
                let types = enc(vec![22u8]);
                let tags = enc(i(-12).to_vec());
                let text = format!(
                    r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="{}" header_type="{}">
<UnstructuredGrid><Piece NumberOfPoints="6" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="binary">
   {points}
</DataArray></Points>
<Cells><DataArray type="Int32" Name="connectivity" format="binary">{conn}</DataArray>
<DataArray type="Int32" Name="offsets" format="binary">{offs}</DataArray>
<DataArray type="UInt8" Name="types" format="binary">{types}</DataArray></Cells>
<CellData><DataArray type="Int32" Name="tags" format="binary">{tags}</DataArray></CellData>
</Piece></UnstructuredGrid></VTKFile>"#,
                    if big { "BigEndian" } else { "LittleEndian" },
                    if header64 { "UInt64" } else { "UInt32" },
                );
                let what = format!("big={big} header64={header64} separate={separate}");
                let m = read_bytes(text.as_bytes(), Format::Vtu, "b.vtu")
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_eq!(m.tri6, vec![[0, 1, 2, 3, 4, 5]], "{what}");
                assert_eq!(m.tri6_tags, vec![-12], "{what}");
                assert_eq!(m.nodes[4], [0.5, 0.5, 0.0], "{what}");
            }
        }
    }
}

// ------------------------------------------------------------------ VTK itself

const VTK_CHECK: &str = r#"
import sys
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy
log = vtk.vtkStringOutputWindow()
vtk.vtkOutputWindow.SetInstance(log)
inputs, outdir = sys.argv[1].split(","), sys.argv[2]
for path in inputs:
    r = vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtk.vtkUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    P = vtk_to_numpy(g.GetPoints().GetData())
    types = sorted(set(g.GetCellType(i) for i in range(g.GetNumberOfCells())))
    assert types == [22, 24], (path, types)
    assert g.GetCellData().GetArray("BoundaryTag") is not None, path
    # VTK's own quadratic edges (end, end, mid) must match where our mid nodes are.
    for i in range(g.GetNumberOfCells()):
        c = g.GetCell(i)
        ids = [c.GetPointId(k) for k in range(c.GetNumberOfPoints())]
        for k in range(c.GetNumberOfEdges()):
            e = c.GetEdge(k)
            a, b, m = (e.GetPointId(j) for j in range(3))
            d = np.linalg.norm(P[ids] - (P[a] + P[b]) / 2, axis=1)
            assert ids[int(np.argmin(d))] == m, (path, i, k)
# Files written by VTK, for our readers.
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(inputs[0])
r.Update()
for mode, name in [("ascii", "vtk_ascii.vtu"), ("binary", "vtk_binary.vtu")]:
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(r.GetOutput())
    w.SetCompressorTypeToNone()
    w.SetDataModeToAscii() if mode == "ascii" else w.SetDataModeToBinary()
    w.SetFileName(outdir + "/" + name)
    assert w.Write() == 1
# The writer's default (appended raw data, zlib), and the other encodings, compressors,
# header types; small blocks so that arrays span several.
def xml(name, setup):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(r.GetOutput())
    setup(w)
    w.SetFileName(outdir + "/" + name)
    assert w.Write() == 1
xml("vtk_default.vtu", lambda w: None)
head = open(outdir + "/vtk_default.vtu", "rb").read(4000)
assert b'format="appended"' in head and b"vtkZLibDataCompressor" in head, head
assert b'encoding="base64"' in head, head
def appended_raw(w):
    w.EncodeAppendedDataOff()
    w.SetBlockSize(64)
xml("vtk_appended_raw.vtu", appended_raw)
def lz4_32(w):
    w.SetCompressorTypeToLZ4()
    w.EncodeAppendedDataOff()
    w.SetHeaderTypeToUInt32()
    w.SetBlockSize(64)
xml("vtk_lz4_u32.vtu", lz4_32)
def inline_zlib_64(w):
    w.SetDataModeToBinary()
    w.SetHeaderTypeToUInt64()
    w.SetBlockSize(64)
xml("vtk_inline_zlib_u64.vtu", inline_zlib_64)
def appended_plain(w):
    w.SetCompressorTypeToNone()
    w.EncodeAppendedDataOff()
xml("vtk_appended_plain.vtu", appended_plain)
w = vtk.vtkUnstructuredGridWriter()
w.SetInputData(r.GetOutput())
w.SetFileName(outdir + "/vtk_legacy.vtk")
assert w.Write() == 1
w = vtk.vtkUnstructuredGridWriter()
w.SetInputData(r.GetOutput())
w.SetFileTypeToBinary()
w.SetFileName(outdir + "/vtk_legacy_binary.vtk")
assert w.Write() == 1
assert log.GetOutput() == "", log.GetOutput()
print("vtk ok")
"#;

#[test]
fn vtk_reads_what_we_write_and_we_read_what_vtk_writes() {
    let has_vtk = Command::new("python3")
        .args(["-c", "import vtk"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !has_vtk {
        skip("python3 with vtk not available; skipped (pip install vtk)");
        return;
    }
    let mesh = curved_mesh();
    let dir = out_dir("vtk");
    let mut inputs = Vec::new();
    for (file, format, opts) in variants() {
        if matches!(format, Format::Vtu | Format::Vtk) {
            let p = dir.join(&file);
            io::write_mesh(&p, &mesh, &opts).unwrap();
            inputs.push(p.display().to_string());
        }
    }
    let out = Command::new("python3")
        .args([
            "-c",
            VTK_CHECK,
            &inputs.join(","),
            &dir.display().to_string(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "VTK check failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    for file in [
        "vtk_ascii.vtu",
        "vtk_binary.vtu",
        "vtk_default.vtu",
        "vtk_appended_raw.vtu",
        "vtk_lz4_u32.vtu",
        "vtk_inline_zlib_u64.vtu",
        "vtk_appended_plain.vtu",
        "vtk_legacy_binary.vtk",
    ] {
        let back = io::read(&dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_same_geometry(file, &mesh, &back, 0);
    }
    // VTK's legacy writer (5.1 layout) prints 11 significant digits.
    let back = io::read(&dir.join("vtk_legacy.vtk")).unwrap();
    assert_eq!(back.tet10, mesh.tets);
    assert_eq!(back.tri6, mesh.boundary);
    assert_eq!(back.tri6_tags, mesh.boundary_tags);
    for (p, q) in mesh.nodes.iter().zip(&back.nodes) {
        for d in 0..3 {
            assert!((p[d] - q[d]).abs() < 1e-10, "{p:?} vs {q:?}");
        }
    }
}

const MESHIO_WRITE: &str = r#"
import sys
import meshio
src, outdir = sys.argv[1], sys.argv[2]
m = meshio.read(src)
meshio.write(outdir + "/mio41.msh", m, file_format="gmsh", binary=False)
meshio.write(outdir + "/mio41b.msh", m, file_format="gmsh", binary=True)
meshio.write(outdir + "/mio22.msh", m, file_format="gmsh22", binary=False)
meshio.write(outdir + "/mio22b.msh", m, file_format="gmsh22", binary=True)
meshio.write(outdir + "/mio_b.vtu", m, binary=True, compression=None)
meshio.write(outdir + "/mio_a.vtu", m, binary=False)
meshio.write(outdir + "/mio_a.vtk", m, binary=False)
# meshio's defaults: binary, zlib-compressed; and a UInt64 header; binary legacy VTK.
meshio.write(outdir + "/mio_default.vtu", m)
assert b"vtkZLibDataCompressor" in open(outdir + "/mio_default.vtu", "rb").read(2000)
meshio.write(outdir + "/mio_zlib64.vtu", m, header_type="UInt64")
meshio.write(outdir + "/mio_b.vtk", m, binary=True)
"#;

/// Files meshio writes (from a surface we wrote) read back as the same surface.
#[test]
fn we_read_what_meshio_writes() {
    if !has_python_meshio() {
        skip("python3 with meshio not available; skipped (pip install meshio)");
        return;
    }
    let s = io::read(&data("sphere_p2.msh")).unwrap();
    let tags: Vec<i32> = (0..s.tri6.len()).map(|i| 1 + (i as i32 / 100)).collect();
    let dir = out_dir("from_meshio");
    let src = dir.join("src.msh");
    io::write_surface(&src, &s.nodes, &s.tri6, &tags, &WriteOptions::default()).unwrap();
    let out = Command::new("python3")
        .args(["-c", MESHIO_WRITE])
        .arg(&src)
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "meshio failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for file in [
        "mio41.msh",
        "mio41b.msh",
        "mio22.msh",
        "mio22b.msh",
        "mio_b.vtu",
        "mio_a.vtu",
        "mio_a.vtk",
        "mio_default.vtu",
        "mio_zlib64.vtu",
        "mio_b.vtk",
    ] {
        let back = io::read(&dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(back.tri6, s.tri6, "{file}");
        assert_eq!(back.tri6_tags, tags, "{file}");
        assert_eq!(back.nodes.len(), s.nodes.len(), "{file}");
        // meshio's ASCII VTK writers print 12 significant digits; the rest is exact.
        let tol = if file.starts_with("mio_a") {
            1e-11
        } else {
            0.0
        };
        for (i, (p, q)) in s.nodes.iter().zip(&back.nodes).enumerate() {
            for d in 0..3 {
                assert!(
                    (p[d] - q[d]).abs() <= tol,
                    "{file}: node {i}: {p:?} vs {q:?}"
                );
            }
        }
    }
}

/// Files Gmsh writes: a P2 box meshed with parametric node coordinates (4.1 ASCII and
/// binary), and conversions of a surface we wrote to 4.1 binary and 2.2 ASCII/binary.
#[test]
fn we_read_what_gmsh_writes() {
    if !has_gmsh() {
        skip("gmsh not available; skipped");
        return;
    }
    let dir = out_dir("from_gmsh");
    let geo = dir.join("box.geo");
    std::fs::write(
        &geo,
        "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 1, 2, 0.5};\n\
         Physical Surface(7) = {1, 2, 3};\nPhysical Surface(8) = {4, 5, 6};\n\
         Physical Volume(3) = {1};\nMesh.MeshSizeMax = 0.4;\n",
    )
    .unwrap();
    let gmsh = |args: &[&str], out: &Path| {
        let o = Command::new("gmsh")
            .args(args)
            .arg("-o")
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (a, b) = (dir.join("box.msh"), dir.join("box_bin.msh"));
    let g = geo.to_str().unwrap();
    gmsh(&[g, "-3", "-order", "2", "-parametric", "-save_all"], &a);
    gmsh(
        &[g, "-3", "-order", "2", "-parametric", "-save_all", "-bin"],
        &b,
    );
    let ma = io::read(&a).unwrap();
    let mb = io::read(&b).unwrap();
    // The same mesh; Gmsh prints 16 significant digits in ASCII (not always exact).
    assert_eq!(
        (&ma.tet10, &ma.tri6, &ma.tri6_tags),
        (&mb.tet10, &mb.tri6, &mb.tri6_tags)
    );
    assert_eq!(ma.ignored_elements, mb.ignored_elements);
    for (p, q) in ma.nodes.iter().zip(&mb.nodes) {
        assert!((0..3).all(|d| (p[d] - q[d]).abs() <= 1e-15 * p[d].abs().max(1.0)));
    }
    assert!(!ma.tet10.is_empty() && !ma.tri6.is_empty());
    assert!(ma.ignored_elements > 0, "points and lines are counted");
    assert!(ma.tet10_tags.iter().all(|&t| t == 3));
    assert!(ma.tri6_tags.iter().all(|&t| t == 7 || t == 8));
    let vol: f64 = ma
        .tet10
        .iter()
        .map(|t| {
            let [p, q, r, s] = [0, 1, 2, 3].map(|k| ma.nodes[t[k] as usize]);
            let (u, v, w) = (
                [q[0] - p[0], q[1] - p[1], q[2] - p[2]],
                [r[0] - p[0], r[1] - p[1], r[2] - p[2]],
                [s[0] - p[0], s[1] - p[1], s[2] - p[2]],
            );
            (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]))
                / 6.0
        })
        .sum();
    assert!((vol - 1.0).abs() < 1e-12, "box volume {vol}");
    assert_gmsh_order_straight(&ma);

    // Conversions of a surface we wrote.
    let s = io::read(&data("sphere_p2.msh")).unwrap();
    let tags: Vec<i32> = (0..s.tri6.len()).map(|i| 1 + (i as i32 / 100)).collect();
    let src = dir.join("src.msh");
    io::write_surface(&src, &s.nodes, &s.tri6, &tags, &WriteOptions::default()).unwrap();
    let src = src.to_str().unwrap();
    for (name, args) in [
        ("g41b.msh", vec![src, "-0", "-bin"]),
        ("g22.msh", vec![src, "-0", "-format", "msh22"]),
        ("g22b.msh", vec![src, "-0", "-format", "msh22", "-bin"]),
    ] {
        let out = dir.join(name);
        gmsh(&args, &out);
        let back = io::read(&out).unwrap();
        // Gmsh may renumber the nodes (MSH 2.2 export does) and prints 16 significant
        // digits in ASCII: compare each triangle's six points.
        let tol = if name.ends_with("b.msh") { 0.0 } else { 1e-15 };
        assert_eq!(back.tri6.len(), s.tri6.len(), "{name}");
        for (i, (a, b)) in s.tri6.iter().zip(&back.tri6).enumerate() {
            let (xa, xb) = (tri_xyz(&s.nodes, a), tri_xyz(&back.nodes, b));
            for k in 0..6 {
                assert!(
                    (0..3).all(|d| (xa[k][d] - xb[k][d]).abs() <= tol),
                    "{name}: triangle {i} node {k}: {:?} vs {:?}",
                    xa[k],
                    xb[k]
                );
            }
        }
        assert_eq!(back.tri6_tags, tags, "{name}");
    }
}

/// Straight-sided P2 elements (a box meshed by Gmsh): every mid node is at the midpoint
/// of its Gmsh edge, to rounding.
fn assert_gmsh_order_straight(m: &RawMesh) {
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|d| (a[d] - b[d]).abs() < 1e-12);
    for t in &m.tet10 {
        let x = tet_xyz(&m.nodes, t);
        for (k, [a, b]) in curvetet::geom::shape::TET10_EDGES.iter().enumerate() {
            let mid = std::array::from_fn(|d| 0.5 * (x[*a][d] + x[*b][d]));
            assert!(close(x[4 + k], mid), "tet node {}", 4 + k);
        }
    }
    for t in &m.tri6 {
        let x = tri_xyz(&m.nodes, t);
        for (k, [a, b]) in curvetet::geom::shape::TRI6_EDGES.iter().enumerate() {
            let mid = std::array::from_fn(|d| 0.5 * (x[*a][d] + x[*b][d]));
            assert!(close(x[3 + k], mid), "triangle node {}", 3 + k);
        }
    }
}

#[test]
fn empty_mesh_round_trips() {
    let empty = TetMesh::default();
    for (file, format, opts) in variants() {
        let bytes = mesh_to_bytes(&empty, format, &opts).unwrap();
        let back = read_bytes(&bytes, format, &file).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(back.nodes.is_empty() && back.tri6.is_empty() && back.tet10.is_empty());
    }
}

/// A check that needs an external tool the test script installs: without it, fail when
/// `CURVETET_REQUIRE_TOOLS` is set (scripts/test sets it, so CI never skips silently),
/// else print why it was skipped.
fn skip(why: &str) {
    if std::env::var_os("CURVETET_REQUIRE_TOOLS").is_some() {
        panic!("required tool missing: {why}");
    }
    println!("note: {why}");
}

/// The checked-in files VTK and meshio wrote (fuzz/seeds, from `fuzz/make-seeds`): VTK's
/// XML writer's default (appended base64, zlib), raw appended zlib and LZ4 (UInt32
/// header), inline zlib (UInt64 header) in blocks of 256 bytes, meshio's default (inline
/// zlib), and both tools' binary legacy VTK, read as the same mesh as our own ASCII .vtu
/// (without Python installed).
#[test]
fn checked_in_vtk_and_meshio_files_read_as_ours() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    let ours = io::read(&seeds.join("read_vtu/ico_tets.vtu")).unwrap();
    assert!(!ours.tet10.is_empty() && !ours.tri6.is_empty());
    for file in [
        "read_vtu/ico_tets_vtk_default.vtu",
        "read_vtu/ico_tets_vtk_raw_zlib.vtu",
        "read_vtu/ico_tets_vtk_raw_lz4_u32.vtu",
        "read_vtu/ico_tets_vtk_inline_zlib_u64.vtu",
        "read_vtu/ico_tets_meshio_default.vtu",
        "read_vtk/ico_tets_vtk_binary.vtk",
        "read_vtk/ico_tets_meshio_binary.vtk",
    ] {
        let back = io::read(&seeds.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(back.nodes, ours.nodes, "{file}");
        assert_eq!(back.tet10, ours.tet10, "{file}");
        assert_eq!(back.tri6, ours.tri6, "{file}");
        assert_eq!(back.tri6_tags, ours.tri6_tags, "{file}");
    }
}
