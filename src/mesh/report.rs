//! Per-element quality and certification of a whole P2 mesh, and the report built on it.
//!
//! Elements are measured in parallel (rayon) into a vector in element order, then folded
//! sequentially, so the report is bit-identical whatever the thread count.

use super::TetMesh;
use crate::geom::bezier::certify;
use crate::geom::quadrature::{tet10_volume, CompensatedSum};
use crate::geom::tet_quality::{tet_quality, TetQuality, TetQualitySummary};
use crate::geom::P3;
use rayon::prelude::*;

/// The ten node positions of tet `t`.
#[inline]
pub fn tet_nodes(m: &TetMesh, t: usize) -> [P3; 10] {
    let e = &m.tets[t];
    std::array::from_fn(|k| m.nodes[e[k] as usize])
}

/// Quality of every element, in element order.
pub fn element_qualities(m: &TetMesh) -> Vec<TetQuality> {
    (0..m.tets.len())
        .into_par_iter()
        .map(|t| tet_quality(&tet_nodes(m, t)))
        .collect()
}

/// Indices of elements whose Jacobian is not certified positive (invalid or undecided).
pub fn uncertified(m: &TetMesh) -> Vec<usize> {
    (0..m.tets.len())
        .into_par_iter()
        .filter(|&t| !certify(&tet_nodes(m, t)).is_valid())
        .collect()
}

/// What users and the paper measure on a mesh.
#[derive(Debug, Clone, serde::Serialize)]
#[non_exhaustive]
pub struct QualityReport {
    /// Number of 10-node tets.
    pub num_tets: usize,
    /// Number of nodes (corner and mid).
    pub num_nodes: usize,
    /// Number of boundary triangles.
    pub num_boundary_faces: usize,
    /// Elements whose Jacobian is not certified positive.
    pub num_invalid: usize,
    /// Elements with equiangular skewness above 0.85.
    pub skew_above_085: usize,
    /// Elements with equiangular skewness above 0.9.
    pub skew_above_09: usize,
    /// Sum of straight-sided (corner) volumes.
    pub volume_linear: f64,
    /// Sum of curved volumes (exact quadrature of det J).
    pub volume_curved: f64,
    /// Min/max/mean and histograms of each measure.
    pub quality: TetQualitySummary,
    /// Tets with a dihedral angle below 10°, forced by the input's triangles or not.
    pub slivers: super::slivers::SliverCensus,
}

impl QualityReport {
    /// Measure a mesh.
    pub fn of(m: &TetMesh) -> QualityReport {
        Self::with_invalid(m, uncertified(m).len())
    }

    /// Measure a mesh whose count of uncertified elements ([`uncertified`]) is known
    /// already (the final check of `generate` has it; certifying again costs about a
    /// quarter of the report's time).
    pub fn with_invalid(m: &TetMesh, invalid: usize) -> QualityReport {
        // One pass per element (its nodes loaded once): quality, straight and curved
        // volume.
        let per: Vec<(TetQuality, f64, f64)> = (0..m.tets.len())
            .into_par_iter()
            .map(|t| {
                let x = tet_nodes(m, t);
                (
                    tet_quality(&x),
                    crate::geom::vec3::tet_det(x[0], x[1], x[2], x[3]) / 6.0,
                    tet10_volume(&x),
                )
            })
            .collect();
        let mut summary = TetQualitySummary::new();
        for e in &per {
            summary.add(&e.0);
        }
        let q = || per.iter().map(|e| &e.0);
        QualityReport {
            num_tets: m.tets.len(),
            num_nodes: m.nodes.len(),
            num_boundary_faces: m.boundary.len(),
            num_invalid: invalid,
            skew_above_085: q().filter(|e| e.skewness > 0.85).count(),
            skew_above_09: q().filter(|e| e.skewness > 0.9).count(),
            volume_linear: per.iter().map(|v| v.1).collect::<CompensatedSum>().value(),
            volume_curved: per.iter().map(|v| v.2).collect::<CompensatedSum>().value(),
            quality: summary,
            slivers: super::slivers::census(m),
        }
    }
}
