//! Options of [`crate::generate`], with the paper's defaults.

use crate::{Error, Result};

/// How the target element size is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum SizeMode {
    /// Graded from the boundary (default): local size at each surface vertex from its
    /// edges, extended inward with a limited growth rate, never above the largest
    /// boundary size. Works on surfaces with mixed triangle sizes.
    Graded,
    /// The paper's uniform size: tetrahedron height from the mean curved triangle area
    /// (paper eq. 1, with the square root that makes it dimensionally a length).
    Uniform,
    /// A uniform target edge length given by the user.
    Fixed(f64),
}

/// In JSON (`curvetet mesh --report`): `"graded"`, `"uniform"`, or the fixed size.
impl serde::Serialize for SizeMode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            SizeMode::Graded => s.serialize_str("graded"),
            SizeMode::Uniform => s.serialize_str("uniform"),
            SizeMode::Fixed(h) => s.serialize_f64(*h),
        }
    }
}

/// What the graded size field measures each surface vertex's local size from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum SizeFrom {
    /// Areas when most of the surface's triangles are elongated (the median vertex's
    /// area size is below [`crate::front::size::AREAS_BELOW`] times its edge size),
    /// else edges: every benchmark surface (medians 0.99-1.00) keeps edges.
    Auto,
    /// The mean length of the vertex's edges.
    Edges,
    /// The edge of the equilateral triangle whose area is the mean area of the vertex's
    /// triangles: smaller than the mean edge on elongated triangles, where tets of the
    /// mean edge's size leave the front stuck (a torus of triangles of aspect ratio
    /// about 2 needed a minute and three failed attempts with edges, a second with
    /// areas).
    Areas,
}

/// Options of mesh generation. `Options::default()` gives the paper's settings; the
/// `with_*` methods change one setting each (new settings can be added without breaking
/// callers, hence `#[non_exhaustive]`: build from the default, not with a struct literal).
///
/// | setting | default | raise it for | lower it for |
/// |---|---|---|---|
/// | [`size`](Self::with_size) | graded from the boundary | fewer, larger tets ([`SizeMode::Fixed`]) | — |
/// | [`gradation`](Self::with_gradation) | 0.2 | faster growth inward: fewer tets | a smoother size field |
/// | [`alpha`](Self::with_alpha) | 1.5 | more candidate points per face | faster candidate search |
/// | [`min_dihedral_deg`](Self::with_min_dihedral_deg) | 15 | better tets, a harder front | an easier front |
/// | [`threads`](Self::with_threads) | 0 (all cores) | — | sharing the machine (results never change) |
///
/// ```
/// use curvetet::{Options, SizeMode};
///
/// let opts = Options::default()
///     .with_size(SizeMode::Fixed(0.3))
///     .with_threads(2)
///     .with_thorough(true);
/// assert!(opts.validate().is_ok());
/// assert!(Options::default().with_alpha(-1.0).validate().is_err());
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Options {
    /// Search radius factor: candidates within `alpha * h` of the ideal point (paper: 1.5).
    pub alpha: f64,
    /// How the target size is chosen.
    pub size: SizeMode,
    /// Growth rate of the graded size field (size increase per unit distance / size).
    pub gradation: f64,
    /// What the graded size field measures local sizes from.
    pub size_from: SizeFrom,
    /// Run the quality improvement and high-order optimization after generation.
    pub optimize: bool,
    /// Where some element starts poor (the screw, the hinge), run the high-order stage's
    /// thorough rounds ([`HighOrderParams::thorough`](crate::optimize::HighOrderParams::thorough)):
    /// two to three times its work there, for fewer elements left between the worst and
    /// the threshold (screw: 78 instead of 204 of 734 below min J / max J 0.85); the
    /// worst element is about as good either way.
    pub thorough: bool,
    /// Worker threads for parallel stages; 0 = all cores. Results never depend on it. At
    /// most [`crate::threads::max_threads`] (4 per CPU, at most 1024).
    pub threads: usize,
    /// Keep each worker of a pool with one worker per CPU on its own CPU (see
    /// [`crate::threads`]). Off by default: a host application (VTK, ParaView, Gmsh,
    /// MeshLab) places its own threads, and a library must not pin them behind its back.
    /// The `curvetet` command turns it on; `CURVETET_PIN_THREADS` (`1` or `0`) overrides
    /// it either way. Results never depend on it.
    pub pin_threads: bool,
    /// Minimum dihedral angle of a candidate, degrees (paper: 15).
    pub min_dihedral_deg: f64,
    /// Maximum equiangular skewness of a candidate unless nothing better exists (paper: 0.9).
    pub max_skewness: f64,
    /// Minimum angle between a new face and a front face sharing its edge, degrees
    /// (paper's edge-face angle: 10).
    pub min_edge_face_angle_deg: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            alpha: 1.5,
            size: SizeMode::Graded,
            gradation: 0.2,
            size_from: SizeFrom::Auto,
            optimize: true,
            thorough: false,
            threads: 0,
            pin_threads: false,
            min_dihedral_deg: 15.0,
            max_skewness: 0.9,
            min_edge_face_angle_deg: 10.0,
        }
    }
}

impl Options {
    /// With search radius factor `alpha` ([`Options::alpha`]).
    pub fn with_alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// With target size `size` ([`Options::size`]).
    pub fn with_size(mut self, size: SizeMode) -> Self {
        self.size = size;
        self
    }

    /// With growth rate `gradation` of the graded size field ([`Options::gradation`]).
    pub fn with_gradation(mut self, gradation: f64) -> Self {
        self.gradation = gradation;
        self
    }

    /// With the graded size field measuring local sizes from `from` ([`Options::size_from`]).
    pub fn with_size_from(mut self, from: SizeFrom) -> Self {
        self.size_from = from;
        self
    }

    /// With or without the optimization stages ([`Options::optimize`]). Without them the
    /// mesh is still certified valid, only of lower quality.
    pub fn with_optimize(mut self, optimize: bool) -> Self {
        self.optimize = optimize;
        self
    }

    /// With or without the high-order stage's thorough rounds ([`Options::thorough`]).
    pub fn with_thorough(mut self, thorough: bool) -> Self {
        self.thorough = thorough;
        self
    }

    /// With `threads` worker threads, 0 = all cores ([`Options::threads`]).
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// With or without pinning workers to CPUs ([`Options::pin_threads`]).
    pub fn with_pin_threads(mut self, pin: bool) -> Self {
        self.pin_threads = pin;
        self
    }

    /// With minimum candidate dihedral angle `deg` ([`Options::min_dihedral_deg`]).
    pub fn with_min_dihedral_deg(mut self, deg: f64) -> Self {
        self.min_dihedral_deg = deg;
        self
    }

    /// With maximum candidate skewness `skewness` ([`Options::max_skewness`]).
    pub fn with_max_skewness(mut self, skewness: f64) -> Self {
        self.max_skewness = skewness;
        self
    }

    /// With minimum edge-face angle `deg` ([`Options::min_edge_face_angle_deg`]).
    pub fn with_min_edge_face_angle_deg(mut self, deg: f64) -> Self {
        self.min_edge_face_angle_deg = deg;
        self
    }

    /// Check every option; a bad one is an [`Error::InvalidArgument`] naming it.
    pub fn validate(&self) -> Result<()> {
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "alpha must be a finite number > 0 (got {})",
                self.alpha
            )));
        }
        if let SizeMode::Fixed(h) = self.size {
            if !(h.is_finite() && h > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "size must be a finite number > 0 (got {h})"
                )));
            }
        }
        crate::threads::check_threads(self.threads)?;
        if !(self.gradation.is_finite() && self.gradation > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "gradation must be a finite number > 0 (got {})",
                self.gradation
            )));
        }
        for (name, v, lo, hi) in [
            ("min dihedral angle", self.min_dihedral_deg, 0.0, 70.0),
            ("max skewness", self.max_skewness, 0.0, 1.0),
            (
                "min edge-face angle",
                self.min_edge_face_angle_deg,
                0.0,
                60.0,
            ),
        ] {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(Error::InvalidArgument(format!(
                    "{name} must be in [{lo}, {hi}] (got {v})"
                )));
            }
        }
        Ok(())
    }
}
