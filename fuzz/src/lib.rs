//! Shared checks of the curvetet fuzz targets (see README.md).

use curvetet::io::{read_bytes, Format, RawMesh};
use curvetet::mesh::check::check_conformity;
use curvetet::mesh::report::uncertified;
use curvetet::surface::curve::CurveOptions;
use curvetet::surface::demo::icosphere;
use curvetet::{generate, Error, MeshInput, Options, RegionMode, SizeMode, Surface};

/// Fuzz one reader: never panic; whatever it accepts has indices in range and one tag per
/// element, and becomes a surface, surfaces of several regions or a clean error (the
/// path `curvetet mesh` takes: [`MeshInput::from_raw`], which splits regions).
pub fn read(data: &[u8], format: Format) {
    let raw = match read_bytes(data, format, "fuzz") {
        Ok(raw) => raw,
        Err(e) => {
            check_error(&e);
            return;
        }
    };
    check_raw(&raw);
    // The region split, the surface checks (and, for a linear file, the curving) on what
    // was read.
    if let Err(e) = MeshInput::from_raw(raw, "fuzz", &CurveOptions::default(), RegionMode::Auto) {
        check_error(&e);
    }
}

/// A read error or a surface error; never an internal failure of the pipeline.
pub fn check_error(e: &Error) {
    match e {
        Error::Parse { .. } | Error::InvalidSurface { .. } | Error::InvalidArgument(_) => {}
        other => panic!("unexpected error kind from a reader/surface check: {other:?}"),
    }
    let msg = e.to_string();
    assert!(!msg.is_empty());
}

fn check_raw(m: &RawMesh) {
    let n = m.nodes.len() as u64;
    let ok = |s: &[u32]| s.iter().all(|&i| u64::from(i) < n);
    assert!(m.tri3.iter().all(|e| ok(e)), "tri3 index out of range");
    assert!(m.tri6.iter().all(|e| ok(e)), "tri6 index out of range");
    assert!(m.tet4.iter().all(|e| ok(e)), "tet4 index out of range");
    assert!(m.tet10.iter().all(|e| ok(e)), "tet10 index out of range");
    assert_eq!(m.tri3.len(), m.tri3_tags.len());
    assert_eq!(m.tri6.len(), m.tri6_tags.len());
    assert_eq!(m.tet4.len(), m.tet4_tags.len());
    assert_eq!(m.tet10.len(), m.tet10_tags.len());
}

/// `surface_arrays`: `Surface::new` on raw arrays decoded from the bytes (first byte even)
/// or on a valid P2 icosphere damaged by byte-driven edits (odd; bit 7: 80 triangles), so
/// the later checks (topology, orientation, intersections) are reached too.
pub fn surface_arrays(data: &[u8]) {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let (nodes, tris, tags) = if mode & 1 == 0 {
        raw_arrays(rest)
    } else {
        damaged_icosphere(mode, rest)
    };
    let n_nodes = nodes.len();
    let n_tris = tris.len();
    match Surface::new(nodes, tris, tags) {
        Ok(s) => {
            assert_eq!(s.nodes().len(), n_nodes);
            assert_eq!(s.triangles().len(), n_tris);
            assert_eq!(s.tags().len(), n_tris);
            assert!(s.shell_count() >= 1);
            assert!(
                s.volume() > 0.0,
                "accepted surface has volume {}",
                s.volume()
            );
        }
        Err(e) => check_error(&e),
    }
}

fn coord(b: u8) -> f64 {
    match b {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => 1e300,
        3 => 1e-300,
        4 => -0.0,
        _ => (b as f64 - 128.0) / 16.0,
    }
}

type Arrays = (Vec<[f64; 3]>, Vec<[u32; 6]>, Vec<i32>);

fn raw_arrays(d: &[u8]) -> Arrays {
    let Some((&nn, d)) = d.split_first() else {
        return (vec![], vec![], vec![]);
    };
    let nn = (nn as usize).min(d.len() / 3);
    let nodes: Vec<[f64; 3]> = d[..3 * nn]
        .chunks_exact(3)
        .map(|c| [coord(c[0]), coord(c[1]), coord(c[2])])
        .collect();
    let d = &d[3 * nn..];
    let m = nn.max(1) as u32 + 1; // one index past the end is reachable
    let tris: Vec<[u32; 6]> = d
        .chunks_exact(6)
        .map(|c| std::array::from_fn(|k| c[k] as u32 % m))
        .collect();
    let tags = if d.len() % 6 == 1 {
        vec![]
    } else {
        (0..tris.len() as i32).collect()
    };
    (nodes, tris, tags)
}

fn damaged_icosphere(mode: u8, d: &[u8]) -> Arrays {
    let (mut nodes, mut tris) = icosphere(u32::from(mode >> 7));
    let mut tags = vec![1; tris.len()];
    for op in d.chunks_exact(4) {
        let nn = nodes.len();
        let nt = tris.len().max(1);
        let (a, b, c) = (op[1] as usize, op[2] as usize, op[3]);
        match op[0] % 10 {
            0 => {
                let p = &mut nodes[a % nn];
                p[b % 3] += (c as f64 - 128.0) / 64.0;
            }
            1 => nodes[a % nn][b % 3] = coord(c),
            2 => nodes[a % nn] = nodes[b % nn],
            3 => {
                if let Some(t) = tris.get_mut(a % nt) {
                    t[b % 6] = (c as u32) % (nn as u32 + 1);
                }
            }
            4 => {
                if let Some(t) = tris.get_mut(a % nt) {
                    t.swap(0, 1);
                    t.swap(4, 5);
                }
            }
            5 => {
                if !tris.is_empty() {
                    tris.remove(a % nt);
                    if a % nt < tags.len() {
                        tags.remove(a % nt);
                    }
                }
            }
            6 => {
                if let Some(&t) = tris.get(a % nt) {
                    tris.push(t);
                    tags.push(c as i32);
                }
            }
            7 => {
                // Scale the whole model.
                let s = 10f64.powi(c as i32 - 128);
                for p in nodes.iter_mut() {
                    for x in p.iter_mut() {
                        *x *= s;
                    }
                }
            }
            8 => {
                // Move a mid node off its edge (curving, folding).
                let p = &mut nodes[a % nn];
                let r = (c as f64 - 128.0) / 32.0;
                p[b % 3] *= 1.0 + r;
            }
            _ => tags.truncate(a % (tags.len() + 1)),
        }
    }
    (nodes, tris, tags)
}

/// `mesh_icosphere`: `generate` (1 thread) on a P2 icosphere (20 or 80 triangles) whose
/// nodes the bytes move, with byte-chosen size mode, alpha and optimization. The result is
/// a conforming, certified mesh of that surface or `MeshingFailed`; `InvalidMesh` (the bug
/// guard fired) is accepted unless CURVETET_FUZZ_STRICT asks otherwise (see below); a
/// panic, a returned invalid mesh or another error kind is a failure.
pub fn mesh_icosphere(data: &[u8]) {
    // CURVETET_FUZZ_STRICT=1: every refusal fails; =optimized: only where the optimizer
    // ran (without it nothing can untangle a curved tet the front had to take).
    let strict = match std::env::var("CURVETET_FUZZ_STRICT").ok().as_deref() {
        None => false,
        Some("optimized") => data.first().is_some_and(|&m| m & 8 != 0),
        Some(_) => true,
    };
    mesh_icosphere_strict(data, strict);
}

/// [`mesh_icosphere`], with `strict` deciding whether the mesher refusing its own mesh
/// (`InvalidMesh`) fails the input.
pub fn mesh_icosphere_strict(data: &[u8], strict: bool) {
    let Some((&mode, d)) = data.split_first() else {
        return;
    };
    let (mut nodes, tris) = icosphere(u32::from(mode & 1));
    let amp = [0.05, 0.15, 0.3, 0.6][(mode as usize >> 1) & 3];
    for (p, c) in nodes.iter_mut().zip(d.chunks_exact(3)) {
        for k in 0..3 {
            p[k] += amp * signed(c[k]);
        }
    }
    let surface = match Surface::new(nodes, tris, vec![]) {
        Ok(s) => s,
        Err(e) => return check_error(&e),
    };
    let mut opts = Options::default()
        .with_threads(1)
        .with_optimize(mode & 8 != 0);
    match (mode >> 4) & 3 {
        0 => opts.size = SizeMode::Graded,
        1 => opts.size = SizeMode::Uniform,
        2 => opts.size = SizeMode::Fixed(0.3 + 0.5 * signed(*d.last().unwrap_or(&200)).abs()),
        _ => opts.alpha = 1.0 + signed(*d.last().unwrap_or(&128)).abs(),
    }
    match generate(&surface, &opts) {
        Ok(g) => {
            let conf = check_conformity(&g.mesh).expect("generate returned a non-conforming mesh");
            assert_eq!(conf.boundary_faces, surface.triangles().len());
            let bad = uncertified(&g.mesh);
            assert!(
                bad.is_empty(),
                "generate returned uncertified elements {bad:?}"
            );
            assert_eq!(g.mesh.boundary.len(), surface.triangles().len());
        }
        Err(Error::MeshingFailed { .. }) => {}
        // The final check caught an invalid mesh and refused it: the guarantee holds, but
        // the mesher made a bad element. `strict` makes it a failure, to collect such
        // inputs for the mesher.
        Err(Error::InvalidMesh { msg, .. }) => {
            if strict {
                panic!("generate refused its own mesh: {msg}");
            }
        }
        Err(e) => panic!("generate failed: {e}"),
    }
}

fn signed(b: u8) -> f64 {
    (b as f64 - 128.0) / 128.0
}

/// The targets by name, for replaying saved inputs (`tests/fuzz_regressions.rs`).
pub const TARGETS: [&str; 10] = [
    "read_msh",
    "read_vtu",
    "read_vtk",
    "read_medit",
    "read_stl",
    "read_off",
    "read_obj",
    "read_ply",
    "surface_arrays",
    "mesh_icosphere",
];

/// Run target `name` on `data`; panics on an unknown name.
pub fn run(name: &str, data: &[u8]) {
    match name {
        "read_msh" => read(data, Format::Msh),
        "read_vtu" => read(data, Format::Vtu),
        "read_vtk" => read(data, Format::Vtk),
        "read_medit" => read(data, Format::Medit),
        "read_stl" => read(data, Format::Stl),
        "read_off" => read(data, Format::Off),
        "read_obj" => read(data, Format::Obj),
        "read_ply" => read(data, Format::Ply),
        "surface_arrays" => surface_arrays(data),
        "mesh_icosphere" => mesh_icosphere(data),
        _ => panic!("unknown fuzz target {name}"),
    }
}
