//! `Surface::new` on arbitrary arrays: either raw arrays decoded from the bytes, or a valid
//! P2 icosphere damaged by byte-driven edits (moved, merged, NaN or huge nodes, changed
//! indices, swapped corners, dropped or repeated triangles), so the later checks
//! (topology, orientation, intersections) are reached too.
#![no_main]
use curvetet::surface::demo::icosphere;
use curvetet::Surface;
use libfuzzer_sys::fuzz_target;

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

fuzz_target!(|data: &[u8]| {
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
            assert!(s.volume() > 0.0, "accepted surface has volume {}", s.volume());
        }
        Err(e) => curvetet_fuzz::check_error(&e),
    }
});

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
                    tags.remove(a % nt);
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
