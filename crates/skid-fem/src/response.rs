//! What an element evaluation returns ([`ElementResponse`]) and which tangent it is asked for
//! ([`Tangent`]), shared by every solid element.

use nalgebra::Matrix3;

use crate::cell::MAX_COMPONENTS;

/// Response of one element at a given displacement. Vectors are node-major (index `a * D + i`)
/// with `D * 2^D` components.
#[derive(Clone, Copy, Debug, Default)]
pub struct ElementResponse {
    /// `D * 2^D`, the length of [`Self::force`] and [`Self::volume_ratio_gradient`].
    pub(crate) components: usize,
    /// Internal nodal forces in the first `components` entries.
    pub(crate) force: [f64; MAX_COMPONENTS],
    /// `dJ/du` in the first `components` entries.
    pub(crate) volume_ratio_gradient: [f64; MAX_COMPONENTS],
    /// Material strain energy `V0 W(F)`.
    pub strain_energy: f64,
    /// Hourglass stabilisation energy.
    pub hourglass_energy: f64,
    /// Cauchy stress `sigma = tau / J` (3D; in plane strain `sigma33` included).
    pub cauchy_stress: Matrix3<f64>,
    /// Volume ratio `J = det F`.
    pub volume_ratio: f64,
}

impl ElementResponse {
    /// Internal nodal forces, length `D * 2^D`, node-major (index `a * D + i`).
    pub fn force(&self) -> &[f64] {
        &self.force[..self.components]
    }

    /// `dJ/du`, same ordering as the force: `J g_a` for node `a` (`g_a = F^{-T} b_a`).
    pub fn volume_ratio_gradient(&self) -> &[f64] {
        &self.volume_ratio_gradient[..self.components]
    }
}

/// Which tangent stiffness an element's `respond_with_tangent` returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tangent {
    /// The consistent tangent `d force / d u` of the displacement formulation.
    Consistent,
    /// The tangent of the condensed one-point mixed (u-p) formulation at the element pressure
    /// `pressure` (see [`crate::material::Hyperelastic::mixed_stress_and_tangent`]); equal to
    /// the consistent one when `pressure = U'(J)`. The force is the displacement formulation's in every case.
    Mixed {
        /// The element's mixed pressure `p_m` (Pa).
        pressure: f64,
    },
}
