//! Several regions, one conforming mesh (issue 30): a sphere inside a larger sphere and a
//! box split by an internal wall, meshed through the library into one mesh whose
//! interface triangles are faces of one tet of each region, with region volumes equal to
//! the volumes the region boundaries enclose, written as MSH 4.1 with one physical volume
//! per region.

use curvetet::geom::quadrature::enclosed_volume_linear;
use curvetet::geom::shape::TET_OUT_FACES;
use curvetet::surface::demo::{nested_spheres, split_box};
use curvetet::{
    generate_input, generate_regions, io, Generated, MeshInput, Options, RegionMode, Regions,
    Repair, SizeMode, WriteOptions,
};
use std::collections::HashMap;

fn opts() -> Options {
    Options::default().with_threads(1)
}

/// Sorted corner triple of a face.
fn key(a: u32, b: u32, c: u32) -> [u32; 3] {
    let mut k = [a, b, c];
    k.sort_unstable();
    k
}

/// Linear volume of the tets of region `r`.
fn region_volume(g: &Generated, r: i32) -> f64 {
    let m = &g.mesh;
    m.tets
        .iter()
        .zip(&m.tet_regions)
        .filter(|x| *x.1 == r)
        .map(|(t, _)| {
            let p = |k: usize| m.nodes[t[k] as usize];
            curvetet::geom::vec3::tet_det(p(0), p(1), p(2), p(3)) / 6.0
        })
        .sum()
}

/// Asserts the interface triangles (given by their input indices' corner triples) are
/// each a face of exactly one tet of each of two regions, and every other boundary
/// triangle a face of exactly one tet; returns the number of interface triangles.
fn assert_conforming(g: &Generated) -> usize {
    let m = &g.mesh;
    let mut faces: HashMap<[u32; 3], Vec<i32>> = HashMap::new();
    for (t, &r) in m.tets.iter().zip(&m.tet_regions) {
        for f in TET_OUT_FACES {
            faces
                .entry(key(t[f[0]], t[f[1]], t[f[2]]))
                .or_default()
                .push(r);
        }
    }
    let mut interfaces = 0;
    for (i, b) in m.boundary.iter().enumerate() {
        let owners = &faces[&key(b[0], b[1], b[2])];
        match owners.len() {
            1 => {}
            2 => {
                assert_ne!(owners[0], owners[1], "boundary triangle {i}: {owners:?}");
                interfaces += 1;
            }
            n => panic!("boundary triangle {i} is a face of {n} tets"),
        }
    }
    // Every face of one tet is a boundary triangle.
    let listed: std::collections::HashSet<[u32; 3]> =
        m.boundary.iter().map(|b| key(b[0], b[1], b[2])).collect();
    for (f, owners) in &faces {
        if owners.len() == 1 {
            assert!(listed.contains(f), "face {f:?} of one tet is not listed");
        } else {
            assert_eq!(owners.len(), 2, "face {f:?}");
        }
    }
    interfaces
}

/// The msh 4.1 output (ASCII and binary) holds one physical volume per region, named.
fn assert_msh_regions(g: &Generated, regions: &[i32]) {
    for binary in [false, true] {
        let bytes = io::mesh_to_bytes(
            &g.mesh,
            io::Format::Msh,
            &WriteOptions::default().with_binary(binary),
        )
        .expect("writes");
        let raw = io::read_bytes(&bytes, io::Format::Msh, "out.msh").expect("reads back");
        assert_eq!(raw.tet10_tags, g.mesh.tet_regions);
        for &r in regions {
            assert!(
                raw.physical_names
                    .iter()
                    .any(|n| n.dim == 3 && n.tag == r && n.name == format!("region_{r}")),
                "{:?}",
                raw.physical_names
            );
        }
        let back = raw.into_tet_mesh().expect("a tet mesh");
        assert_eq!(back.tet_regions, g.mesh.tet_regions);
        curvetet::mesh::check::check_conformity_regions(&back, &back.tet_regions)
            .expect("conforming when read back");
    }
}

#[test]
fn a_sphere_inside_a_sphere_meshes_into_two_conforming_regions() {
    let (nodes, tris) = nested_spheres(1, 0.5, 1.0);
    let half = tris.len() / 2;
    let input = nodes.clone();
    let regions =
        Regions::new(nodes.clone(), tris.clone(), vec![], Repair::Strict).expect("two regions");
    assert_eq!(regions.regions().len(), 2);
    let g = generate_regions(&regions, &opts(), &mut |_, _| false).expect("meshes");
    // The input nodes keep their indices and coordinates.
    assert_eq!(&g.mesh.nodes[..input.len()], &input[..]);
    assert_eq!(g.mesh.boundary.len(), tris.len());
    assert_eq!(g.mesh.region_ids(), vec![1, 2]);
    // The inner sphere is the interface: 80 triangles.
    assert_eq!(assert_conforming(&g), half);
    let inner = enclosed_volume_linear(&nodes, &tris[..half]);
    let outer = enclosed_volume_linear(&nodes, &tris[half..]);
    let (v1, v2) = (region_volume(&g, 1), region_volume(&g, 2));
    assert!((v1 - inner).abs() <= 1e-10 * inner, "{v1} vs {inner}");
    assert!(
        (v2 - (outer - inner)).abs() <= 1e-10 * (outer - inner),
        "{v2} vs {}",
        outer - inner
    );
    assert_eq!(g.regions.len(), 2);
    assert_eq!(
        g.regions[0].report.num_tets + g.regions[1].report.num_tets,
        g.mesh.tets.len()
    );
    assert_eq!(g.report.num_invalid, 0);
    // The interface has its own tag, named.
    let names = io::region_names(&g.mesh);
    assert_eq!(names, vec![(1, "region_1".into()), (2, "region_2".into())]);
    assert!(g.mesh.boundary_tags[..half].iter().all(|&t| t == 2));
    assert!(g.mesh.boundary_tags[half..].iter().all(|&t| t == 0));
    assert_eq!(g.mesh.groups.name(2, 2), Some("interface_1_2"));
    assert_msh_regions(&g, &[1, 2]);
    // Each volume entity lists the surfaces bounding it: the ball only the interface.
    assert_eq!(
        msh_volume_bounds(&g),
        vec![(1, vec![2]), (2, surface_entities_of(&g))]
    );
}

/// The entity lines of the ASCII msh 4.1 output, by dimension (0 to 3).
fn msh_entity_lines(g: &Generated) -> [Vec<String>; 4] {
    let bytes =
        io::mesh_to_bytes(&g.mesh, io::Format::Msh, &WriteOptions::default()).expect("writes");
    let text = String::from_utf8(bytes).expect("ASCII");
    let mut lines = text.lines().skip_while(|l| *l != "$Entities").skip(1);
    let counts: Vec<usize> = lines
        .next()
        .expect("counts")
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let mut out: [Vec<String>; 4] = Default::default();
    for (dim, &n) in counts.iter().enumerate().take(4) {
        out[dim] = lines.by_ref().take(n).map(str::to_string).collect();
    }
    out
}

/// The (volume entity, bounding surface entities) of the ASCII msh 4.1 output.
fn msh_volume_bounds(g: &Generated) -> Vec<(i32, Vec<i32>)> {
    msh_entity_lines(g)[3]
        .iter()
        .map(|l| {
            let w: Vec<i64> = l
                .split_whitespace()
                .map(|x| x.parse::<f64>().unwrap() as i64)
                .collect();
            let nphys = w[7] as usize;
            let nb = w[8 + nphys] as usize;
            let b = w[9 + nphys..9 + nphys + nb]
                .iter()
                .map(|&x| x as i32)
                .collect();
            (w[0] as i32, b)
        })
        .collect()
}

/// The surface entity tags of the ASCII msh 4.1 output, ascending.
fn surface_entities_of(g: &Generated) -> Vec<i32> {
    let mut s: Vec<i32> = msh_entity_lines(g)[2]
        .iter()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    s.sort_unstable();
    s
}

#[test]
fn a_box_split_by_a_wall_meshes_into_two_conforming_regions() {
    let (nodes, tris) = split_box(2);
    let raw = io::RawMesh {
        nodes: nodes.clone(),
        tri6: tris.clone(),
        tri6_tags: vec![0; tris.len()],
        ..Default::default()
    };
    // Junction edges: several regions without being asked.
    let input =
        MeshInput::from_raw(raw, "box", &Default::default(), RegionMode::Auto).expect("splits");
    assert_eq!(input.num_regions(), 2);
    let o = opts().with_size(SizeMode::Fixed(0.5));
    let g = generate_input(&input, &o, &mut |_, _| false).expect("meshes");
    assert_eq!(&g.mesh.nodes[..nodes.len()], &nodes[..]);
    assert_eq!(assert_conforming(&g), 8);
    for r in [1, 2] {
        let v = region_volume(&g, r);
        assert!((v - 1.0).abs() <= 1e-10, "region {r}: {v}");
    }
    assert_msh_regions(&g, &[1, 2]);
}

#[test]
fn a_single_sphere_and_nested_shells_by_default_take_the_one_surface_path() {
    let (nodes, tris) = nested_spheres(1, 0.5, 1.0);
    let raw = io::RawMesh {
        nodes,
        tri6: tris,
        tri6_tags: vec![0; 160],
        ..Default::default()
    };
    let auto = MeshInput::from_raw(raw.clone(), "s", &Default::default(), RegionMode::Auto)
        .expect("a body with a cavity");
    assert!(matches!(auto, MeshInput::Surface(_)));
    let every = MeshInput::from_raw(raw, "s", &Default::default(), RegionMode::EveryShell)
        .expect("two regions");
    assert_eq!(every.num_regions(), 2);
}

#[test]
fn a_linear_split_box_is_meshed_flat_with_a_warning() {
    let (nodes, tris) = split_box(1);
    // Corners only: renumber them and drop the mid nodes.
    let mut ids = HashMap::new();
    let mut lin_nodes = Vec::new();
    let tri3: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            [0, 1, 2].map(|k| {
                *ids.entry(t[k]).or_insert_with(|| {
                    lin_nodes.push(nodes[t[k] as usize]);
                    lin_nodes.len() as u32 - 1
                })
            })
        })
        .collect();
    let raw = io::RawMesh {
        nodes: lin_nodes,
        tri3_tags: vec![5; tri3.len()],
        tri3,
        ..Default::default()
    };
    let input =
        MeshInput::from_raw(raw, "box.off", &Default::default(), RegionMode::Auto).expect("splits");
    assert_eq!(input.num_regions(), 2);
    assert!(
        input.warnings()[0].contains("not curved"),
        "{:?}",
        input.warnings()
    );
    let g = generate_input(&input, &opts(), &mut |_, _| false).expect("meshes");
    assert_eq!(assert_conforming(&g), 2);
    // Input tags are kept, interfaces included.
    assert!(g.mesh.boundary_tags.iter().all(|&t| t == 5));
    for r in [1, 2] {
        assert!((region_volume(&g, r) - 1.0).abs() <= 1e-10);
    }
}

/// Three spheres (radii 0.4, 0.7, 1) as a Gmsh MSH 4.1 surface file whose entities list two
/// volumes: "ball" (physical 20, bounded by the inner sphere) and "shell" (physical 10,
/// bounded by the outer two). The region between the inner two spheres is no volume: a
/// hole.
fn three_spheres_msh(volumes: &str) -> (Vec<u8>, [f64; 3]) {
    use std::fmt::Write;
    let (v, t) = curvetet::surface::demo::icosphere(1);
    let radii = [0.4, 0.7, 1.0];
    let mut nodes = Vec::new();
    let mut tris: Vec<Vec<[u32; 6]>> = Vec::new();
    let mut vols = [0.0; 3];
    for (k, r) in radii.iter().enumerate() {
        let base = nodes.len() as u32;
        nodes.extend(v.iter().map(|p| p.map(|x| x * r)));
        let sphere: Vec<[u32; 6]> = t.iter().map(|x| x.map(|i| i + base)).collect();
        vols[k] = enclosed_volume_linear(&nodes, &sphere);
        tris.push(sphere);
    }
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    s += "$PhysicalNames\n2\n3 10 \"shell\"\n3 20 \"ball\"\n$EndPhysicalNames\n";
    writeln!(s, "$Entities\n0 0 3 {}", volumes.lines().count()).unwrap();
    for e in 1..=3 {
        writeln!(s, "{e} -1 -1 -1 1 1 1 0 0").unwrap();
    }
    s += volumes;
    s += "$EndEntities\n$Nodes\n";
    let n = nodes.len();
    writeln!(s, "1 {n} 1 {n}\n2 1 0 {n}").unwrap();
    for i in 1..=n {
        writeln!(s, "{i}").unwrap();
    }
    for p in &nodes {
        writeln!(s, "{:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    s += "$EndNodes\n$Elements\n";
    let m: usize = tris.iter().map(Vec::len).sum();
    writeln!(s, "3 {m} 1 {m}").unwrap();
    let mut id = 1;
    for (e, sphere) in tris.iter().enumerate() {
        writeln!(s, "2 {} 9 {}", e + 1, sphere.len()).unwrap();
        for x in sphere {
            let x: Vec<String> = x.iter().map(|v| (v + 1).to_string()).collect();
            writeln!(s, "{id} {}", x.join(" ")).unwrap();
            id += 1;
        }
    }
    s += "$EndElements\n";
    (s.into_bytes(), vols)
}

#[test]
fn gmsh_volumes_number_and_name_the_regions_and_leave_holes_empty() {
    let (bytes, vols) =
        three_spheres_msh("1 -1 -1 -1 1 1 1 1 10 2 3 -2\n2 -1 -1 -1 1 1 1 1 20 1 1\n");
    let raw = io::read_bytes(&bytes, io::Format::Msh, "three.msh").expect("reads");
    assert_eq!(raw.volumes.len(), 2);
    assert_eq!(raw.tri6_entities.len(), raw.tri6.len());
    let input = MeshInput::from_raw(raw, "three.msh", &Default::default(), RegionMode::Auto)
        .expect("splits");
    assert_eq!(input.num_regions(), 2);
    assert!(
        input
            .warnings()
            .iter()
            .any(|w| w.contains("1 of 3 regions are holes")),
        "{:?}",
        input.warnings()
    );
    let g = generate_input(&input, &opts(), &mut |_, _| false).expect("meshes");
    assert_eq!(g.mesh.region_ids(), vec![10, 20]);
    let ball = region_volume(&g, 20);
    let shell = region_volume(&g, 10);
    assert!(
        (ball - vols[0]).abs() <= 1e-10 * vols[0],
        "{ball} vs {}",
        vols[0]
    );
    let want = vols[2] - vols[1];
    assert!((shell - want).abs() <= 1e-10 * want, "{shell} vs {want}");
    // No interface: the hole separates the regions; every input triangle is a boundary.
    assert_eq!(assert_conforming(&g), 0);
    assert_eq!(g.mesh.boundary.len(), 3 * 80);
    assert_eq!(
        io::region_names(&g.mesh),
        vec![(10, "shell".to_string()), (20, "ball".to_string())]
    );
    let bytes = io::mesh_to_bytes(&g.mesh, io::Format::Msh, &WriteOptions::default()).unwrap();
    let back = io::read_bytes(&bytes, io::Format::Msh, "out.msh").unwrap();
    let mut tags = back.tet10_tags.clone();
    tags.sort_unstable();
    tags.dedup();
    assert_eq!(tags, vec![10, 20]);
    assert!(back
        .physical_names
        .iter()
        .any(|n| n.dim == 3 && n.tag == 20 && n.name == "ball"));
}

/// Three volumes in one physical volume: one region id, the surfaces between them interior
/// faces (not boundary triangles), the whole ball filled.
#[test]
fn gmsh_volumes_of_one_physical_volume_are_one_region() {
    let (bytes, vols) = three_spheres_msh(
        "1 -1 -1 -1 1 1 1 1 10 2 3 -2\n2 -1 -1 -1 1 1 1 1 10 2 2 -1\n3 -1 -1 -1 1 1 1 1 10 1 1\n",
    );
    let raw = io::read_bytes(&bytes, io::Format::Msh, "three.msh").expect("reads");
    let input = MeshInput::from_raw(raw, "three.msh", &Default::default(), RegionMode::Auto)
        .expect("splits");
    assert_eq!(input.num_regions(), 3);
    assert!(input.warnings().is_empty(), "{:?}", input.warnings());
    let g = generate_input(&input, &opts(), &mut |_, _| false).expect("meshes");
    assert_eq!(g.mesh.region_ids(), vec![10]);
    // Only the outer sphere bounds the mesh.
    assert_eq!(g.mesh.boundary.len(), 80);
    assert_eq!(assert_conforming(&g), 0);
    let v = region_volume(&g, 10);
    assert!((v - vols[2]).abs() <= 1e-10 * vols[2], "{v} vs {}", vols[2]);
}
