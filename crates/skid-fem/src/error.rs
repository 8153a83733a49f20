//! Error type of the finite-element kernels.

use thiserror::Error;

/// Everything that can go wrong while building or evaluating finite elements.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum FemError {
    /// An input holds NaN or infinite values.
    #[error("non-finite {what}")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// A material constant is out of its admissible range.
    #[error("invalid material constant {field} = {value}: expected {expected}")]
    InvalidMaterial {
        /// Name of the constant.
        field: &'static str,
        /// Offending value.
        value: f64,
        /// Admissible range, in words.
        expected: &'static str,
    },
    /// An element or load parameter (thickness, modulus, scale factor, ...) is out of range.
    #[error("invalid parameter {name} = {value}: expected {expected}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Admissible range, in words.
        expected: &'static str,
    },
    /// The deformation gradient has `J = det F <= 0` or non-finite entries, at an integration
    /// point of the element (the centre of a one-point element) or at one of its corners.
    #[error("inverted element: det F = {det_f} {}", inversion_point(*.corner))]
    InvertedElement {
        /// Determinant of the deformation gradient (the volume ratio) where it failed.
        det_f: f64,
        /// The corner where it failed (its index in the cell corner order), `None` for an
        /// integration point (the centre of a one-point element).
        corner: Option<usize>,
    },
    /// The local Newton solve for an element's incompatible-mode parameters (the condensed
    /// enhanced strains of [`crate::IntegratedSolid`]) did not converge, or its mode stiffness
    /// `K_aa` is singular (then `residual` is NaN when found at the converged modes).
    #[error(
        "incompatible modes not converged: residual {residual:.3e} after {iterations} local \
         Newton iterations"
    )]
    IncompatibleModesNotConverged {
        /// Euclidean norm of the mode residual `dPi/dalpha` (N) at the last iterate.
        residual: f64,
        /// Local Newton iterations done.
        iterations: usize,
    },
    /// The reference geometry has a non-positive (or non-finite) Jacobian determinant.
    #[error(
        "degenerate reference element: det J = {det_j} (negative: corners in the wrong order, \
         counter-clockwise expected; zero: a repeated or collinear corner)"
    )]
    DegenerateElement {
        /// Jacobian determinant of the isoparametric map at the offending point.
        det_j: f64,
    },
    /// Only the spatial dimensions 2 and 3 are supported.
    #[error("unsupported spatial dimension {dim}: expected 2 or 3")]
    UnsupportedDimension {
        /// Requested dimension.
        dim: usize,
    },
    /// A slice argument has the wrong number of entries.
    #[error("{what}: expected {expected} entries, found {found}")]
    LengthMismatch {
        /// What the slice holds.
        what: &'static str,
        /// Required length.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// An error raised while processing one element of a mesh.
    #[error("element {index}: {source}")]
    Element {
        /// Element index in the mesh.
        index: usize,
        /// Underlying error.
        source: Box<FemError>,
    },
    /// The mesh is inconsistent.
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A rigid body has unphysical inertia or an inadmissible axis.
    #[error("invalid rigid body {body}: {reason}")]
    InvalidRigidBody {
        /// Name of the body.
        body: String,
        /// What is wrong.
        reason: String,
    },
}

/// Where an element inverted, in words: at its centre, or at a corner while the centre is not
/// (the element is folded, typically by its hourglass modes).
pub fn inversion_point(corner: Option<usize>) -> String {
    match corner {
        None => "at its centre".into(),
        Some(k) => format!("at corner {k}; its centre is not, the element is folded"),
    }
}
