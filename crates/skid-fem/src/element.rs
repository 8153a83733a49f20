//! The solid element of a mesh in any of its formulations: the one-point element with
//! hourglass control ([`OnePointSolid`]) or a fully integrated one ([`IntegratedSolid`]).

use nalgebra::SVector;

use crate::error::FemError;
use crate::hourglass::Hourglass;
use crate::integrated::{IntegratedSolid, Technology};
use crate::material::Hyperelastic;
use crate::solid::{ElementResponse, MAX_NODES, OnePointSolid, Tangent};

/// The formulation of a quad (plane strain) or hex solid element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Formulation {
    /// One-point integration with hourglass stiffness (CPE4R / C3D8R).
    Reduced,
    /// Full integration, displacement formulation (CPE4 / C3D8).
    Full,
    /// Full integration, constant-pressure hybrid (CPE4H / C3D8H).
    Hybrid,
    /// Full integration with incompatible modes (CPE4I / C3D8I).
    Incompatible,
}

impl Formulation {
    /// Every formulation.
    pub const ALL: [Self; 4] = [Self::Reduced, Self::Full, Self::Hybrid, Self::Incompatible];

    /// The Abaqus name of the element: `CPE4R`, `CPE4`, `CPE4H`, `CPE4I` for `dim = 2` (plane
    /// strain), `C3D8R`, `C3D8`, `C3D8H`, `C3D8I` otherwise.
    pub fn abaqus_name(self, dim: usize) -> &'static str {
        match (self, dim == 2) {
            (Self::Reduced, true) => "CPE4R",
            (Self::Full, true) => "CPE4",
            (Self::Hybrid, true) => "CPE4H",
            (Self::Incompatible, true) => "CPE4I",
            (Self::Reduced, false) => "C3D8R",
            (Self::Full, false) => "C3D8",
            (Self::Hybrid, false) => "C3D8H",
            (Self::Incompatible, false) => "C3D8I",
        }
    }

    /// The technology of a fully integrated formulation, `None` for [`Self::Reduced`].
    pub fn technology(self) -> Option<Technology> {
        match self {
            Self::Reduced => None,
            Self::Full => Some(Technology::Full),
            Self::Hybrid => Some(Technology::Hybrid),
            Self::Incompatible => Some(Technology::Incompatible),
        }
    }
}

/// A quad (D = 2) or hex (D = 3) solid element of any [`Formulation`].
#[derive(Clone, Debug)]
pub enum SolidElement<const D: usize> {
    /// The one-point element with hourglass stiffness.
    Reduced(OnePointSolid<D>),
    /// A fully integrated element.
    Integrated(IntegratedSolid<D>),
}

impl<const D: usize> SolidElement<D> {
    /// Builds the element: `x_ref`, the `2^D` reference nodal coordinates in the cell corner
    /// order; `thickness`, the plane-strain thickness (2D; ignored in 3D); `material` and
    /// `hourglass`, the hourglass control's parameters of [`OnePointSolid::new`] (used only by
    /// [`Formulation::Reduced`]).
    ///
    /// # Errors
    /// Those of [`OnePointSolid::new`] or [`IntegratedSolid::new`].
    pub fn new(
        formulation: Formulation,
        x_ref: &[SVector<f64, D>],
        thickness: f64,
        material: &dyn Hyperelastic,
        hourglass: Hourglass,
    ) -> Result<Self, FemError> {
        Ok(match formulation.technology() {
            None => Self::Reduced(OnePointSolid::new(x_ref, thickness, material, hourglass)?),
            Some(technology) => {
                Self::Integrated(IntegratedSolid::new(technology, x_ref, thickness)?)
            }
        })
    }

    /// The element's formulation.
    pub fn formulation(&self) -> Formulation {
        match self {
            Self::Reduced(_) => Formulation::Reduced,
            Self::Integrated(e) => match e.technology() {
                Technology::Full => Formulation::Full,
                Technology::Hybrid => Formulation::Hybrid,
                Technology::Incompatible => Formulation::Incompatible,
            },
        }
    }

    /// Number of nodes `2^D`.
    pub fn node_count(&self) -> usize {
        match self {
            Self::Reduced(e) => e.node_count(),
            Self::Integrated(e) => e.node_count(),
        }
    }

    /// Reference volume `V0` (area times thickness in 2D).
    pub fn volume(&self) -> f64 {
        match self {
            Self::Reduced(e) => e.volume(),
            Self::Integrated(e) => e.volume(),
        }
    }

    /// See [`OnePointSolid::respond`] and [`IntegratedSolid::respond`].
    ///
    /// # Errors
    /// Those of the element's `respond`.
    pub fn respond(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
    ) -> Result<ElementResponse, FemError> {
        match self {
            Self::Reduced(e) => e.respond(material, u),
            Self::Integrated(e) => e.respond(material, u),
        }
    }

    /// See [`OnePointSolid::respond_with_tangent`] and
    /// [`IntegratedSolid::respond_with_tangent`].
    ///
    /// # Errors
    /// Those of the element's `respond_with_tangent`.
    pub fn respond_with_tangent(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
        tangent: Tangent,
        stiffness: &mut [f64],
    ) -> Result<ElementResponse, FemError> {
        match self {
            Self::Reduced(e) => e.respond_with_tangent(material, u, tangent, stiffness),
            Self::Integrated(e) => e.respond_with_tangent(material, u, tangent, stiffness),
        }
    }

    /// Lumped masses of the nodes, in the first `2^D` entries: `rho V0 / 2^D` each for the
    /// one-point element ([`OnePointSolid::lumped_node_mass`]), the row sums `rho int N_a dV`
    /// for a fully integrated one ([`IntegratedSolid::lumped_node_masses`]). Either way they
    /// sum to `rho V0`.
    pub fn lumped_node_masses(&self, density: f64) -> [f64; MAX_NODES] {
        match self {
            Self::Reduced(e) => {
                let mut masses = [0.0; MAX_NODES];
                masses[..e.node_count()].fill(e.lumped_node_mass(density));
                masses
            }
            Self::Integrated(e) => e.lumped_node_masses(density),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::corners;
    use crate::test_fixtures::material;

    fn square<const D: usize>() -> Vec<SVector<f64, D>> {
        corners::<D>()
            .iter()
            .enumerate()
            .map(|(a, c)| c * 0.5 + SVector::repeat(0.05 * a as f64))
            .collect()
    }

    fn check_formulations<const D: usize>() -> Result<(), FemError> {
        let m = material()?;
        let x = square::<D>();
        let u: Vec<SVector<f64, D>> = x
            .iter()
            .map(|x| x * 0.1 + x.map(|c| c * c) * 0.02)
            .collect();
        for formulation in Formulation::ALL {
            let element = SolidElement::new(formulation, &x, 0.4, &m, Hourglass::default())?;
            assert_eq!(element.formulation(), formulation);
            assert_eq!(element.node_count(), 1 << D);
            let n = D * element.node_count();
            let mut k = vec![0.0; n * n];
            let r = element.respond_with_tangent(&m, &u, Tangent::Consistent, &mut k)?;
            assert_eq!(r.force(), element.respond(&m, &u)?.force());
            let direct = match formulation.technology() {
                None => OnePointSolid::new(&x, 0.4, &m, Hourglass::default())?.respond(&m, &u)?,
                Some(t) => IntegratedSolid::new(t, &x, 0.4)?.respond(&m, &u)?,
            };
            assert_eq!(r.force(), direct.force());
            let rho = 1200.0;
            let total: f64 = element.lumped_node_masses(rho).iter().sum();
            assert!((total - rho * element.volume()).abs() < 1e-12 * total);
        }
        Ok(())
    }

    #[test]
    fn every_formulation_builds_and_responds() -> Result<(), FemError> {
        check_formulations::<2>()?;
        check_formulations::<3>()
    }

    #[test]
    fn abaqus_names() {
        let names: Vec<_> = Formulation::ALL
            .iter()
            .flat_map(|f| [f.abaqus_name(2), f.abaqus_name(3)])
            .collect();
        assert_eq!(
            names,
            [
                "CPE4R", "C3D8R", "CPE4", "C3D8", "CPE4H", "C3D8H", "CPE4I", "C3D8I"
            ]
        );
    }
}
