//! TEMPORARY: dihedral angles and skewness until geom::quality lands (then removed).

use crate::geom::vec3::*;

pub fn dihedral_angles(c: &[P3; 4]) -> [f64; 6] {
    // outward normals of faces opposite each vertex
    let faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let mut n = [[0.0; 3]; 4];
    for (i, f) in faces.iter().enumerate() {
        n[i] = normalize(tri_normal(c[f[0]], c[f[1]], c[f[2]]));
    }
    let mut out = [0.0; 6];
    let pairs = [(2, 3), (0, 3), (1, 3), (1, 2), (0, 1), (0, 2)];
    for (k, (i, j)) in pairs.iter().enumerate() {
        let d = -dot(n[*i], n[*j]);
        out[k] = d.clamp(-1.0, 1.0).acos().to_degrees();
    }
    out
}

pub fn skewness(a: &[f64; 6]) -> f64 {
    let te = (1.0f64 / 3.0).acos().to_degrees();
    let mx = a.iter().cloned().fold(f64::MIN, f64::max);
    let mn = a.iter().cloned().fold(f64::MAX, f64::min);
    ((mx - te) / (180.0 - te)).max((te - mn) / te)
}
