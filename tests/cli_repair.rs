//! Unambiguous input repair on the command line (issue 28, item 4): inconsistently
//! oriented triangles are reoriented (each shell consistent, then out of the solid: a
//! cavity's shell into the cavity) and unused vertices dropped, each with a warning; the
//! repaired input meshes exactly as the clean one does (the same output file, byte for
//! byte). `--strict` refuses both with the old errors (exit code 4), in `mesh`, `curve`
//! and `check`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_curvetet"))
        .args(args)
        .output()
        .expect("curvetet runs")
}

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("curvetet-cli-repair-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `curvetet mesh INPUT -o OUTPUT -q` (plus `extra`), which must succeed; its stderr.
fn mesh(input: &Path, output: &Path, extra: &[&str]) -> String {
    let mut args = vec!["mesh", s(input), "-o", s(output), "-q"];
    args.extend_from_slice(extra);
    let out = run(&args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{}: {err}", input.display());
    err
}

/// `--strict` refuses `input` in `mesh`, `check` (and `curve`, for a linear input) with
/// exit code 4 and the defect `kind`.
fn strict_refuses(input: &Path, kind: &str, linear: bool) {
    let out_msh = tmp("strict_out.msh");
    let mut cmds: Vec<Vec<&str>> = vec![
        vec!["mesh", s(input), "-o", s(&out_msh), "-q", "--strict"],
        vec!["check", s(input), "--strict"],
    ];
    if linear {
        cmds.push(vec!["curve", s(input), "-o", s(&out_msh), "--strict"]);
    }
    for args in cmds {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(4), "{args:?}: {err}");
        assert!(
            err.contains(&format!("invalid surface ({kind})")),
            "{args:?}: {err}"
        );
        assert!(!out_msh.exists(), "{args:?} wrote an output");
    }
}

/// A deterministic pseudo-random choice of about a third of `n` items.
fn a_third(n: usize, seed: u64) -> Vec<bool> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 33) % 3 == 0
        })
        .collect()
}

/// The OFF file `text` with the faces marked in `flip` reversed (corners 0, 2, 1).
fn flip_off_faces(text: &str, flip: &[bool]) -> String {
    let mut out = String::new();
    let mut lines = text.lines().filter(|l| !l.trim_start().starts_with('#'));
    let header = lines.next().unwrap();
    let counts = lines.next().unwrap();
    let nv: usize = counts.split_whitespace().next().unwrap().parse().unwrap();
    writeln!(out, "{header}\n{counts}").unwrap();
    for _ in 0..nv {
        writeln!(out, "{}", lines.next().unwrap()).unwrap();
    }
    for (f, line) in lines.enumerate() {
        let w: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(w[0], "3", "{line}");
        if flip[f] {
            writeln!(out, "3 {} {} {}", w[1], w[3], w[2]).unwrap();
        } else {
            writeln!(out, "{line}").unwrap();
        }
    }
    out
}

/// An MSH 2.2 file of 6-node triangles (tag `tags[t]`).
fn write_p2_msh(path: &Path, nodes: &[[f64; 3]], tris: &[[u32; 6]], tags: &[i32]) {
    let mut t = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    writeln!(t, "{}", nodes.len()).unwrap();
    for (i, p) in nodes.iter().enumerate() {
        writeln!(t, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2]).unwrap();
    }
    write!(t, "$EndNodes\n$Elements\n{}\n", tris.len()).unwrap();
    for (i, (tri, tag)) in tris.iter().zip(tags).enumerate() {
        write!(t, "{} 9 2 {tag} {tag}", i + 1).unwrap();
        for v in tri {
            write!(t, " {}", v + 1).unwrap();
        }
        t.push('\n');
    }
    t.push_str("$EndElements\n");
    std::fs::write(path, t).unwrap();
}

fn same_bytes(a: &Path, b: &Path) {
    let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(
        x == y,
        "{} and {} differ ({} and {} bytes)",
        a.display(),
        b.display(),
        x.len(),
        y.len()
    );
}

#[test]
fn a_linear_sphere_with_a_third_of_its_facets_flipped_meshes_as_the_clean_one() {
    let text = std::fs::read_to_string(data("sphere_lin.off")).unwrap();
    let mut flip = a_third(708, 28);
    flip[0] = true;
    let n = flip.iter().filter(|&&f| f).count();
    assert!((200..280).contains(&n), "{n}");
    let bad = tmp("sphere_flipped_lin.off");
    std::fs::write(&bad, flip_off_faces(&text, &flip)).unwrap();

    let (clean_out, bad_out) = (tmp("sphere_clean.msh"), tmp("sphere_flipped.msh"));
    let err = mesh(&data("sphere_lin.off"), &clean_out, &[]);
    assert!(!err.contains("warning"), "{err}");
    let report = tmp("sphere_flipped_report.json");
    let err = mesh(&bad, &bad_out, &["--report", s(&report)]);
    // The lowest facet is flipped, so the walk first turns the others its way, and the
    // whole shell is then found inward: net, exactly the flipped facets are turned back.
    assert!(
        err.contains(&format!(
            "warning: orientation was inconsistent: flipped {n} of 708 triangles in 1 of 1 \
             shell(s)"
        )),
        "{err}"
    );
    same_bytes(&clean_out, &bad_out);
    // The report keeps what was repaired.
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["input"]["strict"], false);
    let warnings = r["input"]["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with(&format!("orientation was inconsistent: flipped {n} of 708"))),
        "{warnings:?}"
    );
    strict_refuses(&bad, "inconsistent-orientation", true);

    // `curve` writes the clean surface.
    let (c1, c2) = (tmp("curved_clean.msh"), tmp("curved_flipped.msh"));
    for (i, o) in [(data("sphere_lin.off"), &c1), (bad.clone(), &c2)] {
        let out = run(&["curve", s(&i), "-o", s(o)]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    same_bytes(&c1, &c2);
}

#[test]
fn a_p2_sphere_with_flipped_triangles_meshes_as_the_clean_one() {
    let raw = curvetet::io::read(&data("sphere_p2.msh")).unwrap();
    let tags: Vec<i32> = (0..raw.tri6.len() as i32).map(|t| 1 + t % 3).collect();
    let mut flip = a_third(raw.tri6.len(), 7);
    flip[0] = false;
    let n = flip.iter().filter(|&&f| f).count();
    let flipped: Vec<[u32; 6]> = raw
        .tri6
        .iter()
        .zip(&flip)
        .map(|(t, &f)| {
            if f {
                // [a, b, c, ab, bc, ca] -> [a, c, b, ca, bc, ab]
                [t[0], t[2], t[1], t[5], t[4], t[3]]
            } else {
                *t
            }
        })
        .collect();
    let (clean, bad) = (tmp("sphere_clean_p2.msh"), tmp("sphere_flipped_p2.msh"));
    write_p2_msh(&clean, &raw.nodes, &raw.tri6, &tags);
    write_p2_msh(&bad, &raw.nodes, &flipped, &tags);

    let (clean_out, bad_out) = (
        tmp("sphere_p2_clean_out.msh"),
        tmp("sphere_p2_flip_out.msh"),
    );
    let err = mesh(&clean, &clean_out, &[]);
    assert!(!err.contains("warning"), "{err}");
    let err = mesh(&bad, &bad_out, &[]);
    assert!(
        err.contains(&format!(
            "warning: orientation was inconsistent: flipped {n} of {} triangles in 1 of 1",
            raw.tri6.len()
        )),
        "{err}"
    );
    // The same tets, boundary triangles (tags included: each triangle keeps its own) and
    // nodes.
    same_bytes(&clean_out, &bad_out);
    strict_refuses(&bad, "inconsistent-orientation", false);
}

/// The closed surface of the box [lo, hi]^3 with `n` x `n` squares per face, two
/// triangles each, facing out (or in, `inward`), as OFF vertices and faces (vertex ids
/// from `first`).
fn cube(
    lo: f64,
    hi: f64,
    n: usize,
    inward: bool,
    first: usize,
) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut id = |p: [i64; 3], verts: &mut Vec<[f64; 3]>| -> usize {
        *index.entry(p).or_insert_with(|| {
            let c = |i: i64| lo + (hi - lo) * i as f64 / n as f64;
            verts.push([c(p[0]), c(p[1]), c(p[2])]);
            first + verts.len() - 1
        })
    };
    let mut faces = Vec::new();
    let n = n as i64;
    for axis in 0..3 {
        for side in [0, n] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let at = |a: i64, b: i64| {
                        let mut p = [0i64; 3];
                        p[axis] = side;
                        p[u] = a;
                        p[v] = b;
                        p
                    };
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                        .map(|p| id(p, &mut verts));
                    // (u, v, axis) is right-handed: counterclockwise in (u, v) faces +axis.
                    let out_is_plus = side == n;
                    for mut t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                        if out_is_plus == inward {
                            t.swap(1, 2);
                        }
                        faces.push(t);
                    }
                }
            }
        }
    }
    (verts, faces)
}

fn write_off(path: &Path, verts: &[[f64; 3]], faces: &[[usize; 3]]) {
    let mut t = format!("OFF\n{} {} 0\n", verts.len(), faces.len());
    for p in verts {
        writeln!(t, "{:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    for f in faces {
        writeln!(t, "3 {} {} {}", f[0], f[1], f[2]).unwrap();
    }
    std::fs::write(path, t).unwrap();
}

/// A box with a box-shaped cavity, the cavity's shell given facing out (like its
/// container: the wrong way) is fixed; the result meshes as the right one, volume 26.
#[test]
fn a_cavity_shell_facing_the_wrong_way_is_flipped() {
    let (mut v, mut f) = cube(0.0, 3.0, 6, false, 0);
    let (vi, fi) = cube(1.0, 2.0, 2, false, v.len());
    let n_inner = fi.len();
    v.extend(vi);
    let (good_f, bad_f) = {
        let mut good = f.clone();
        good.extend(fi.iter().map(|t| [t[0], t[2], t[1]]));
        f.extend(fi);
        (good, f)
    };
    let (good, bad) = (tmp("cavity_good_lin.off"), tmp("cavity_bad_lin.off"));
    write_off(&good, &v, &good_f);
    write_off(&bad, &v, &bad_f);

    let out = run(&["check", s(&good), "--json", "--strict"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["shells"], 2);
    assert!((j["enclosed_volume_linear"].as_f64().unwrap() - 26.0).abs() < 1e-12);

    let (good_out, bad_out) = (tmp("cavity_good.msh"), tmp("cavity_bad.msh"));
    mesh(&good, &good_out, &[]);
    let err = mesh(&bad, &bad_out, &[]);
    assert!(
        err.contains(&format!(
            "warning: orientation was inconsistent: flipped {n_inner} of {} triangles in 1 of \
             2 shell(s)",
            good_f.len()
        )),
        "{err}"
    );
    same_bytes(&good_out, &bad_out);
    let out = run(&["check", s(&bad_out), "--json"]);
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["valid"], true, "{j}");
    let tets = j["conformity"]["volume_linear"].as_f64().unwrap();
    assert!((tets - 26.0).abs() < 1e-9, "{tets}");
    strict_refuses(&bad, "inconsistent-orientation", true);
}

#[test]
fn unused_vertices_are_dropped_with_a_warning() {
    // The sphere with one vertex no facet uses in front (every index moves up by one)
    // and two at the end.
    let text = std::fs::read_to_string(data("sphere_lin.off")).unwrap();
    let mut lines = text.lines().filter(|l| !l.trim_start().starts_with('#'));
    let header = lines.next().unwrap();
    let counts: Vec<usize> = lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    let (nv, nf) = (counts[0], counts[1]);
    let mut t = format!("{header}\n{} {nf} 0\n7 7 7\n", nv + 3);
    for _ in 0..nv {
        writeln!(t, "{}", lines.next().unwrap()).unwrap();
    }
    t.push_str("0.25 0.25 0.25\n-9 -9 -9\n");
    for line in lines {
        let w: Vec<usize> = line
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        writeln!(t, "3 {} {} {}", w[1] + 1, w[2] + 1, w[3] + 1).unwrap();
    }
    let bad = tmp("sphere_unused_lin.off");
    std::fs::write(&bad, t).unwrap();

    let (clean_out, bad_out) = (tmp("unused_clean.msh"), tmp("unused_bad.msh"));
    mesh(&data("sphere_lin.off"), &clean_out, &[]);
    let err = mesh(&bad, &bad_out, &[]);
    assert!(
        err.contains(&format!(
            "warning: 3 of {} vertices used by no triangle: dropped, the others renumbered",
            nv + 3
        )),
        "{err}"
    );
    same_bytes(&clean_out, &bad_out);
    strict_refuses(&bad, "unused-node", true);

    // A P2 surface with an unused node: the same.
    let raw = curvetet::io::read(&data("sphere_p2.msh")).unwrap();
    let mut nodes = raw.nodes.clone();
    nodes.push([3.0, 3.0, 3.0]);
    let tags = vec![1; raw.tri6.len()];
    let (clean, bad) = (tmp("p2_clean.msh"), tmp("p2_unused.msh"));
    write_p2_msh(&clean, &raw.nodes, &raw.tri6, &tags);
    write_p2_msh(&bad, &nodes, &raw.tri6, &tags);
    let (clean_out, bad_out) = (tmp("p2_unused_clean_out.msh"), tmp("p2_unused_out.msh"));
    mesh(&clean, &clean_out, &[]);
    let err = mesh(&bad, &bad_out, &[]);
    assert!(
        err.contains(&format!(
            "warning: 1 of {} nodes used by no triangle",
            nodes.len()
        )),
        "{err}"
    );
    same_bytes(&clean_out, &bad_out);
    strict_refuses(&bad, "unused-node", false);
}
