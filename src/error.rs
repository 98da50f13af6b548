//! The one error type of curvetet. Every variant has a stable C status code
//! (see `capi`) and a message that names the offending element, node, edge or line.

use crate::mesh::TetMesh;

/// What is wrong with an input surface. Tests and bindings match on this kind; the
/// message in [`Error::InvalidSurface`] says where.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum SurfaceDefect {
    /// No triangles at all.
    Empty,
    /// A triangle refers to a node that does not exist.
    IndexOutOfRange,
    /// A triangle uses the same node twice.
    RepeatedNode,
    /// A coordinate is NaN or infinite.
    NonFiniteCoordinate,
    /// A coordinate is too large or the model too small for exact predicates in f64.
    CoordinateRange,
    /// Two nodes have identical coordinates.
    DuplicateNode,
    /// A node is used by no triangle (dropped with a warning unless
    /// [`Repair::Strict`](crate::surface::Repair::Strict)).
    UnusedNode,
    /// An edge belongs to only one triangle.
    NotClosed,
    /// An edge belongs to more than two triangles, or twice in the same direction.
    NonManifoldEdge,
    /// The triangles around a vertex form more than one fan.
    NonManifoldVertex,
    /// Neighbouring triangles have opposite orientations (or the shells disagree); on a
    /// closed manifold orientable surface reoriented with a warning unless
    /// [`Repair::Strict`](crate::surface::Repair::Strict).
    InconsistentOrientation,
    /// Two triangles share an edge but not its mid-edge node, a mid node is shared wrongly,
    /// or a mid node lies more than an edge length from its edge's midpoint.
    MidNodeMismatch,
    /// A triangle has zero area (collinear corners).
    DegenerateTriangle,
    /// A curved triangle folds over: its normal turns against its chord triangle's normal.
    FoldedTriangle,
    /// Two triangles intersect away from their shared vertices and edges.
    SelfIntersection,
    /// The surface is linear (3-node triangles) where a quadratic one is needed.
    LinearSurface,
}

impl SurfaceDefect {
    /// A short stable name, used in JSON reports and test expectations.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceDefect::Empty => "empty",
            SurfaceDefect::IndexOutOfRange => "index-out-of-range",
            SurfaceDefect::RepeatedNode => "repeated-node",
            SurfaceDefect::NonFiniteCoordinate => "non-finite-coordinate",
            SurfaceDefect::CoordinateRange => "coordinate-range",
            SurfaceDefect::DuplicateNode => "duplicate-node",
            SurfaceDefect::UnusedNode => "unused-node",
            SurfaceDefect::NotClosed => "not-closed",
            SurfaceDefect::NonManifoldEdge => "non-manifold-edge",
            SurfaceDefect::NonManifoldVertex => "non-manifold-vertex",
            SurfaceDefect::InconsistentOrientation => "inconsistent-orientation",
            SurfaceDefect::MidNodeMismatch => "mid-node-mismatch",
            SurfaceDefect::DegenerateTriangle => "degenerate-triangle",
            SurfaceDefect::FoldedTriangle => "folded-triangle",
            SurfaceDefect::SelfIntersection => "self-intersection",
            SurfaceDefect::LinearSurface => "linear-surface",
        }
    }
}

/// Every way a curvetet call can fail. New kinds may be added (`#[non_exhaustive]`): a
/// `match` needs a `_` arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A caller passed a bad option or argument (alpha <= 0, NaN size, NULL pointer...).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// Reading or writing a file failed at the OS level.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A file is malformed; `location` is `file:line` or `file: byte N`.
    #[error("{location}: {msg}")]
    Parse {
        /// Where: file and line (text) or byte offset (binary).
        location: String,
        /// What is wrong there.
        msg: String,
    },
    /// The input surface fails a check; the message names the element.
    #[error("invalid surface ({}): {msg}", kind.name())]
    InvalidSurface {
        /// Which check failed.
        kind: SurfaceDefect,
        /// Which triangle/edge/node, and why.
        msg: String,
    },
    /// The advancing front could not be closed; the message names the open region.
    #[error("meshing failed: {msg}")]
    MeshingFailed {
        /// What failed and where.
        msg: String,
        /// What was meshed, for debugging (`--keep-partial`).
        partial: Option<Box<TetMesh>>,
    },
    /// The produced mesh failed its final check (conformity or certified Jacobian).
    /// This is a bug guard: the mesh is kept for inspection, never returned as valid.
    #[error("invalid mesh: {msg}")]
    InvalidMesh {
        /// Indices of failing elements (first few).
        elements: Vec<usize>,
        /// What failed.
        msg: String,
        /// The mesh that failed, for inspection.
        mesh: Option<Box<TetMesh>>,
    },
    /// A progress callback asked to stop.
    #[error("cancelled")]
    Cancelled,
}

impl Error {
    /// Shorthand for a surface defect error.
    pub fn surface(kind: SurfaceDefect, msg: impl Into<String>) -> Error {
        Error::InvalidSurface {
            kind,
            msg: msg.into(),
        }
    }

    /// Shorthand for a parse error.
    pub fn parse(location: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::Parse {
            location: location.into(),
            msg: msg.into(),
        }
    }

    /// Shorthand for an I/O error on a path.
    pub fn io(path: impl AsRef<std::path::Path>, source: std::io::Error) -> Error {
        Error::Io {
            path: path.as_ref().display().to_string(),
            source,
        }
    }

    /// The surface defect kind, if this is a surface error.
    pub fn surface_defect(&self) -> Option<SurfaceDefect> {
        match self {
            Error::InvalidSurface { kind, .. } => Some(*kind),
            _ => None,
        }
    }
}

/// Result with curvetet's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
