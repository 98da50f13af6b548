//! Test meshes for the optimizer: a cube cut into `k^3` cells of six (Kuhn) tets, its
//! boundary triangles as the P2 surface (surface nodes first, as the front delivers).

use crate::geom::predicates::orient3d;
use crate::geom::vec3::{mid, P3};
use crate::mesh::TetMesh;
use crate::optimize::Boundary;
use std::collections::HashMap;

/// A linear cube mesh in the front's layout plus its P2 surface.
pub(crate) struct CubeMesh {
    /// Surface corners and mid nodes first (`n_surf` of them), then interior vertices.
    pub pts: Vec<P3>,
    /// Positive tets on `pts`.
    pub tets: Vec<[u32; 4]>,
    /// Surface nodes count.
    pub n_surf: usize,
    /// Outward 6-node boundary triangles.
    pub tris: Vec<[u32; 6]>,
}

impl CubeMesh {
    /// The boundary of this mesh.
    pub fn boundary(&self) -> Boundary {
        Boundary::new(self.n_surf, &self.tris)
    }

    /// The assembled P2 mesh (interior mids at midpoints).
    pub fn p2(&self) -> TetMesh {
        crate::mesh::build::assemble(&self.pts, &self.tets, self.n_surf, &self.tris, &[])
    }

    /// [`CubeMesh::p2`] with every interior mid node moved by a random offset of up to
    /// `amp` per coordinate (seeded: the same mesh every time), for the high-order stage
    /// to work on.
    pub fn p2_perturbed(&self, seed: u64, amp: f64) -> TetMesh {
        use rand::{Rng, SeedableRng};
        let mut m = self.p2();
        let mut is_vertex = vec![false; m.nodes.len()];
        for t in &m.tets {
            for &v in &t[..4] {
                is_vertex[v as usize] = true;
            }
        }
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        for (x, &v) in m.nodes.iter_mut().zip(&is_vertex).skip(self.n_surf) {
            if !v {
                for c in x.iter_mut() {
                    *c += rng.random_range(-amp..amp);
                }
            }
        }
        m
    }
}

/// The points of `c` with every interior vertex moved by a random offset of up to `amp`
/// per coordinate (seeded), for the linear stage's operations to work on.
pub(crate) fn jittered(c: &CubeMesh, seed: u64, amp: f64) -> Vec<P3> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut pts = c.pts.clone();
    for p in pts.iter_mut().skip(c.n_surf) {
        for x in p.iter_mut() {
            *x += rng.random_range(-amp..amp);
        }
    }
    pts
}

/// The edges of `tets`, each once as (smaller id, larger id), sorted.
pub(crate) fn edges(tets: &[[u32; 4]]) -> Vec<(u32, u32)> {
    let mut e: Vec<(u32, u32)> = tets
        .iter()
        .flat_map(|t| {
            crate::geom::shape::TET10_EDGES.map(|[i, j]| (t[i].min(t[j]), t[i].max(t[j])))
        })
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// The unit cube in `k^3` cells, each split into six tets around its main diagonal.
/// `bulge` pushes every boundary mid node outward by `bulge` times its edge length
/// along the face normal (0: straight boundary).
pub(crate) fn cube(k: usize, bulge: f64) -> CubeMesh {
    let n = k + 1;
    let id = |i: usize, j: usize, l: usize| (i * n * n + j * n + l) as u32;
    let h = 1.0 / k as f64;
    let mut grid: Vec<P3> = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for l in 0..n {
                grid.push([i as f64 * h, j as f64 * h, l as f64 * h]);
            }
        }
    }
    // Kuhn triangulation: the six paths from corner 000 to 111 of each cell.
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                for p in perms {
                    let mut c = [i, j, l];
                    let mut t = [id(c[0], c[1], c[2]); 4];
                    for (s, &axis) in p.iter().enumerate() {
                        c[axis] += 1;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    let x = t.map(|v| grid[v as usize]);
                    if orient3d(x[0], x[1], x[2], x[3]) < 0 {
                        t.swap(2, 3);
                    }
                    tets.push(t);
                }
            }
        }
    }
    // Boundary faces: faces of one tet, turned outward.
    let mut faces: HashMap<[u32; 3], (u32, [u32; 3])> = HashMap::new();
    let mut count: HashMap<[u32; 3], u32> = HashMap::new();
    for t in &tets {
        for f in [
            [t[1], t[2], t[3]],
            [t[0], t[3], t[2]],
            [t[0], t[1], t[3]],
            [t[0], t[2], t[1]],
        ] {
            let mut key = f;
            key.sort_unstable();
            *count.entry(key).or_insert(0) += 1;
            faces.insert(key, (0, f));
        }
    }
    let mut bfaces: Vec<[u32; 3]> = count
        .iter()
        .filter(|(_, &c)| c == 1)
        .map(|(k, _)| faces[k].1)
        .collect();
    bfaces.sort_unstable();
    // Renumber: boundary vertices first, then one mid node per boundary edge, then the rest.
    let mut remap = vec![u32::MAX; grid.len()];
    let mut pts: Vec<P3> = Vec::new();
    for f in &bfaces {
        for &v in f {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = pts.len() as u32;
                pts.push(grid[v as usize]);
            }
        }
    }
    let mut emid: HashMap<(u32, u32), u32> = HashMap::new();
    let mut tris = Vec::new();
    for f in &bfaces {
        let c = f.map(|v| remap[v as usize]);
        let a = pts[c[0] as usize];
        let nrm = crate::geom::vec3::normalize(crate::geom::vec3::tri_normal(
            a,
            pts[c[1] as usize],
            pts[c[2] as usize],
        ));
        let mut t = [c[0], c[1], c[2], 0, 0, 0];
        for (e, [i, j]) in crate::geom::shape::TRI6_EDGES.iter().enumerate() {
            let (u, v) = (c[*i], c[*j]);
            let key = (u.min(v), u.max(v));
            let m = *emid.entry(key).or_insert_with(|| {
                let (pu, pv) = (pts[u as usize], pts[v as usize]);
                let len = crate::geom::vec3::dist(pu, pv);
                let p = crate::geom::vec3::axpy(mid(pu, pv), bulge * len, nrm);
                pts.push(p);
                (pts.len() - 1) as u32
            });
            t[3 + e] = m;
        }
        tris.push(t);
    }
    let n_surf = pts.len();
    for (v, r) in remap.iter_mut().enumerate() {
        if *r == u32::MAX {
            *r = pts.len() as u32;
            pts.push(grid[v]);
        }
    }
    let tets = tets.iter().map(|t| t.map(|v| remap[v as usize])).collect();
    CubeMesh {
        pts,
        tets,
        n_surf,
        tris,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn cube_is_conforming() {
        for bulge in [0.0, 0.05] {
            let c = super::cube(3, bulge);
            let m = c.p2();
            let conf = crate::mesh::check::check_conformity(&m).unwrap();
            assert!((conf.volume_linear - 1.0).abs() < 1e-12);
            assert!(crate::mesh::report::uncertified(&m).is_empty());
        }
    }
}
