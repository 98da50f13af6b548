//! High-order node optimization (placeholder).

use crate::mesh::TetMesh;
use crate::optimize::Boundary;

/// Tuning of the high-order stage.
#[derive(Clone, Debug, Default)]
pub struct HighOrderParams {}

/// What the high-order stage did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct HighOrderStats {}

/// Optimize the free nodes of `mesh`.
pub fn optimize_high_order(_mesh: &mut TetMesh, _bnd: &Boundary, _prm: &HighOrderParams) -> HighOrderStats {
    HighOrderStats {}
}
