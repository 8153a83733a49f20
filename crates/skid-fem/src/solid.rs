//! One-point (reduced-integration) solid element with hourglass control: the CPE4R role in 2D
//! plane strain (D = 2) and the C3D8R role in 3D (D = 3), one code path.
//!
//! An evaluation allocates nothing: its results live in fixed arrays sized for the largest
//! element (3D), and the tangent goes into a buffer of the caller's.

use nalgebra::{Matrix3, Matrix6, SVector, Vector3};

use crate::cell::{ReferenceGeometry, embed};
use crate::error::FemError;
use crate::hourglass::{Hourglass, HourglassStiffness};
use crate::kinematics::{
    CornerGradients, add_pair_stiffness, check_corners, check_inputs, check_parameter,
    corner_gradients, gradient_of,
};
use crate::material::Hyperelastic;

pub use crate::cell::{MAX_COMPONENTS, MAX_NODES};
pub use crate::response::{ElementResponse, Tangent};

/// A reduced-integration solid element: reference volume, mean gradients and hourglass data.
#[derive(Clone, Debug)]
pub struct OnePointSolid<const D: usize> {
    /// Reference volume `V0` (area times thickness in 2D).
    volume: f64,
    /// Mean gradients `b_I = (1/V0) int dN_I/dX dV`.
    mean_gradients: Vec<SVector<f64, D>>,
    /// The constant hourglass stiffness of the element's control.
    hourglass: HourglassStiffness<D>,
    /// Per corner of the cell, the reference gradients `grad_X N_I` there that do not vanish
    /// (those of the corner's node and of its D neighbours along the edges), with their node
    /// `I`, for the corner check of [`Self::respond`].
    corner_gradients: CornerGradients<D>,
}

impl<const D: usize> OnePointSolid<D> {
    /// Builds the element from its reference geometry.
    ///
    /// `x_ref`: the 2^D reference nodal coordinates in the cell corner order. `thickness`:
    /// out-of-plane thickness in 2D (plane strain; volume = area * thickness); ignored in 3D
    /// (pass 1.0). `material`: the element's material, whose small-strain stiffness sets the
    /// hourglass stiffness of the control `hourglass` (see [`Hourglass`] and the
    /// [`crate::hourglass`] module for the equations).
    ///
    /// # Errors
    /// [`FemError::UnsupportedDimension`] unless D is 2 or 3, [`FemError::LengthMismatch`],
    /// [`FemError::DegenerateElement`] for a reference Jacobian `det J <= 0`,
    /// [`FemError::InvalidParameter`] for a non-positive thickness (2D) or a negative or
    /// non-finite hourglass scale; for [`Hourglass::Enhanced`], those of the incompatible-mode
    /// element of the same geometry.
    pub fn new(
        x_ref: &[SVector<f64, D>],
        thickness: f64,
        material: &dyn Hyperelastic,
        hourglass: Hourglass,
    ) -> Result<Self, FemError> {
        let geometry = ReferenceGeometry::new(x_ref)?;
        let thickness = if D == 2 {
            check_parameter("thickness", thickness, thickness > 0.0, "finite and > 0")?
        } else {
            1.0
        };
        let hourglass = HourglassStiffness::new(x_ref, &geometry, thickness, material, hourglass)?;
        Ok(Self {
            volume: geometry.measure * thickness,
            mean_gradients: geometry.mean_gradients,
            hourglass,
            corner_gradients: corner_gradients(x_ref)?,
        })
    }

    /// Number of nodes `2^D`.
    pub fn node_count(&self) -> usize {
        self.mean_gradients.len()
    }

    /// Reference volume `V0` (area times thickness in 2D).
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// F = I + sum_I u_I (x) b_I, embedded in 3D (plane strain: F33 = 1,
    /// F13 = F23 = F31 = F32 = 0).
    ///
    /// `u` must hold one displacement per node; [`Self::respond`] checks this.
    pub fn deformation_gradient(&self, u: &[SVector<f64, D>]) -> Matrix3<f64> {
        gradient_of(self.mean_gradients.iter().zip(u))
    }

    /// Internal force, energies, stress and volume ratio at displacement u (node-major
    /// ordering: index a*D + i).
    ///
    /// With `g_a = F^{-T} b_a` (the spatial gradient of `N_a`) and the Kirchhoff stress `tau`:
    /// material force `f_a = V0 tau g_a`. Hourglass (see [`crate::hourglass`]): amplitudes
    /// `q_{alpha D + i} = gamma_alpha . u_i`, energy `E_hg = 1/2 q^T H q`, force
    /// `f_{iI} = sum_alpha (H q)_{alpha D + i} gamma_{alpha I}`.
    ///
    /// The single integration point does not see an element folded by its hourglass modes (the
    /// mean `F` stays that of the affine part), so `J` is also checked at every corner of the
    /// cell: `J_c = det J(xi_c; X + u) / det J(xi_c; X)`, the volume ratio of the full bilinear
    /// (trilinear) field there.
    ///
    /// # Errors
    /// [`FemError::LengthMismatch`] if `u` does not hold one vector per node,
    /// [`FemError::NonFinite`] if `u` is not finite, [`FemError::InvertedElement`] if `J <= 0`
    /// at the centre or at a corner (`det_f` is the offending volume ratio).
    pub fn respond(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
    ) -> Result<ElementResponse, FemError> {
        self.evaluate(material, u, None)
    }

    /// As [`Self::respond`], and the requested tangent `d force / d u` into `stiffness`: the
    /// symmetric `n x n` matrix (`n = D 2^D`, node-major), all of its entries (column-major,
    /// which for a symmetric matrix is also row-major).
    ///
    /// `K_ab,ik = V0 [sum_jl g_aj c^tau_ijkl g_bl + (g_a . tau g_b) delta_ik]` (material +
    /// geometric), with only in-plane `i, k` in 2D, plus the constant hourglass stiffness
    /// `sum_{alpha beta} gamma_{alpha a} H_{(alpha i)(beta k)} gamma_{beta b}`. By the major symmetry of
    /// `c^tau`, `K_ba = K_ab^T`: each node pair is evaluated once.
    ///
    /// With [`Tangent::Mixed`] the stress `tau` of the geometric term and the tangent `c^tau`
    /// are those of the mixed formulation at the given pressure.
    ///
    /// # Errors
    /// As [`Self::respond`]; [`FemError::LengthMismatch`] if `stiffness` does not hold `n^2`
    /// entries.
    pub fn respond_with_tangent(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
        tangent: Tangent,
        stiffness: &mut [f64],
    ) -> Result<ElementResponse, FemError> {
        self.evaluate(material, u, Some((tangent, stiffness)))
    }

    /// [`Self::respond`], and [`Self::respond_with_tangent`] if a tangent is requested.
    fn evaluate(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
        tangent: Option<(Tangent, &mut [f64])>,
    ) -> Result<ElementResponse, FemError> {
        let n = self.node_count();
        let components = D * n;
        check_inputs(u, n, tangent.as_ref().map(|(_, k)| k.len()))?;
        let f = self.deformation_gradient(u);
        let det_f = f.determinant();
        let inverted = FemError::InvertedElement {
            det_f,
            corner: None,
        };
        if !(det_f > 0.0 && f.iter().all(|v| v.is_finite())) {
            return Err(inverted);
        }
        check_corners(&self.corner_gradients, u)?;
        let f_inv_t = f.try_inverse().ok_or(inverted)?.transpose();
        let tau = material.kirchhoff_stress(&f);
        let mut g = [Vector3::zeros(); MAX_NODES];
        for (g_a, b_a) in g.iter_mut().zip(&self.mean_gradients) {
            *g_a = f_inv_t * embed(b_a);
        }
        let g = &g[..n];

        let mut response = ElementResponse {
            components,
            strain_energy: self.volume * material.strain_energy(&f),
            cauchy_stress: tau / det_f,
            volume_ratio: det_f,
            ..ElementResponse::default()
        };
        for (a, g_a) in g.iter().enumerate() {
            let f_a = tau * g_a * self.volume;
            for i in 0..D {
                response.force[a * D + i] = f_a[i];
                response.volume_ratio_gradient[a * D + i] = det_f * g_a[i];
            }
        }
        response.hourglass_energy = self.hourglass.add_force(u, &mut response.force);
        if let Some((tangent, k)) = tangent {
            let (tau_k, c) = match tangent {
                Tangent::Consistent => material.stress_and_tangent(&f),
                Tangent::Mixed { pressure } => material.mixed_stress_and_tangent(&f, pressure),
            };
            self.stiffness(g, &(tau_k * self.volume), &(c.0 * self.volume), k);
        }
        Ok(response)
    }

    /// The tangent of [`Self::respond_with_tangent`] for the spatial gradients `g` from the
    /// volume-scaled stress `tau = V0 tau` and tangent `c = V0 c^tau` (Voigt, tensor
    /// components): the node-pair blocks of [`add_pair_stiffness`] plus the hourglass stiffness
    /// `sum_{alpha beta} gamma_{alpha a} H_{(alpha i)(beta k)} gamma_{beta b}`, both exactly
    /// symmetric.
    fn stiffness(&self, g: &[Vector3<f64>], tau: &Matrix3<f64>, c: &Matrix6<f64>, k: &mut [f64]) {
        k.fill(0.0);
        add_pair_stiffness::<D>(g, tau, c, k);
        self.hourglass.add_tangent(g.len(), k);
    }

    /// Lumped (row-sum) mass per node: rho V0 / 2^D.
    pub fn lumped_node_mass(&self, density: f64) -> f64 {
        density * self.volume / self.node_count() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{corners, hourglass_base_vectors, hourglass_mode_axes, restrict};
    use crate::mesh::SolidMesh;
    use crate::test_fixtures::{
        self as fixtures, affine, dense_tangent, distorted, in_plane, jitter, material, perturb,
    };
    use nalgebra::{DMatrix, DVector, Rotation3, SymmetricEigen, Vector2, Vector3 as V3};

    /// Box element with half-widths `half`.
    fn brick<const D: usize>(half: [f64; 3]) -> Vec<SVector<f64, D>> {
        corners::<D>()
            .iter()
            .map(|c| SVector::from_fn(|k, _| half[k] * c[k]))
            .collect()
    }

    /// Homogeneous finite deformation gradient (in-plane block used in 2D).
    fn homogeneous_f<const D: usize>() -> Matrix3<f64> {
        in_plane::<D>(Matrix3::new(
            1.12, 0.15, -0.05, -0.08, 0.9, 0.1, 0.04, -0.06, 1.05,
        ))
    }

    /// A general finite deformation: affine part plus a non-affine (hourglass-exciting) part.
    fn general_u<const D: usize>(x: &[SVector<f64, D>]) -> Vec<SVector<f64, D>> {
        fixtures::general_u(x, &homogeneous_f::<D>(), 0.08)
    }

    /// The response with the consistent (or mixed) tangent, the tangent as a dense matrix.
    fn tangent<const D: usize>(
        element: &OnePointSolid<D>,
        m: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
        tangent: Tangent,
    ) -> Result<(ElementResponse, DMatrix<f64>), FemError> {
        dense_tangent(D * element.node_count(), |k| {
            element.respond_with_tangent(m, u, tangent, k)
        })
    }

    fn force(r: &ElementResponse) -> DVector<f64> {
        DVector::from_column_slice(r.force())
    }

    /// Both hourglass controls.
    const CONTROLS: [Hourglass; 2] = [Hourglass::Stiffness { scale: 1.0 }, Hourglass::Enhanced];

    fn check_tangent_and_energy<const D: usize>(control: Hourglass) -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = OnePointSolid::new(&x, 0.7, &m, control)?;
        let u = general_u(&x);
        let (r, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
        assert!(r.hourglass_energy > 0.0 && (r.volume_ratio - 1.0).abs() > 1e-2);
        assert!(k.iter().all(|v| v.is_finite()));
        assert!((&k - k.transpose()).amax() < 1e-10 * k.amax());
        let without = element.respond(&m, &u)?;
        assert_eq!(without.force(), r.force());
        let h = 1e-6;
        for dof in 0..D * element.node_count() {
            let plus = element.respond(&m, &perturb(&u, dof, h))?;
            let minus = element.respond(&m, &perturb(&u, dof, -h))?;
            let fd_column = (force(&plus) - force(&minus)) / (2.0 * h);
            let err = (fd_column - k.column(dof)).amax() / k.amax();
            assert!(
                err < 1e-6,
                "D = {D}, {control:?}, dof {dof}: tangent error {err}"
            );
            let energy = |r: &ElementResponse| r.strain_energy + r.hourglass_energy;
            let fd_force = (energy(&plus) - energy(&minus)) / (2.0 * h);
            let err = (fd_force - r.force()[dof]).abs() / force(&r).amax();
            assert!(
                err < 1e-6,
                "D = {D}, {control:?}, dof {dof}: force error {err}"
            );
        }
        Ok(())
    }

    #[test]
    fn tangent_and_force_match_finite_differences() -> Result<(), FemError> {
        for control in CONTROLS {
            check_tangent_and_energy::<2>(control)?;
            check_tangent_and_energy::<3>(control)?;
        }
        Ok(())
    }

    /// The tangent, each node pair evaluated once, is the definition entry by entry (here the
    /// mixed one): `K_ab,ik = V0 [sum_jl g_aj c_ijkl g_bl + (g_a . tau g_b) delta_ik] +
    /// sum_{alpha beta} gamma_{alpha a} H_{(alpha i)(beta l)} gamma_{beta b}`.
    fn check_tangent_against_definition<const D: usize>(
        control: Hourglass,
    ) -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = OnePointSolid::new(&x, 0.7, &m, control)?;
        let u = general_u(&x);
        let pressure = 3.0e5;
        let (_, k) = tangent(&element, &m, &u, Tangent::Mixed { pressure })?;
        let f = element.deformation_gradient(&u);
        let (tau, c) = m.mixed_stress_and_tangent(&f, pressure);
        let f_inv_t = f
            .try_inverse()
            .ok_or(FemError::InvalidMesh("singular F".into()))?
            .transpose();
        let g: Vec<V3<f64>> = (element.mean_gradients.iter())
            .map(|b| f_inv_t * embed(b))
            .collect();
        let v0 = element.volume();
        let expected = DMatrix::from_fn(k.nrows(), k.ncols(), |r, s| {
            let (a, i, b, l) = (r / D, r % D, s / D, s % D);
            let mut material = 0.0;
            for j in 0..D {
                for m in 0..D {
                    material += g[a][j] * c.get(i, j, l, m) * g[b][m];
                }
            }
            let gammas = &element.hourglass.vectors;
            let mut hourglass = 0.0;
            for (alpha, gamma_alpha) in gammas.iter().enumerate() {
                for (beta, gamma_beta) in gammas.iter().enumerate() {
                    let h = element.hourglass.entry(alpha * D + i, beta * D + l);
                    hourglass += gamma_alpha[a] * h * gamma_beta[b];
                }
            }
            let geometric = if i == l { g[a].dot(&(tau * g[b])) } else { 0.0 };
            v0 * (material + geometric) + hourglass
        });
        let err = (&k - &expected).amax() / expected.amax();
        assert!(
            err < 1e-13,
            "D = {D}, {control:?}: tangent differs from its definition by {err}"
        );
        assert_eq!(k, k.transpose());
        let mut short = vec![0.0; k.len() - 1];
        assert!(matches!(
            element.respond_with_tangent(&m, &u, Tangent::Consistent, &mut short),
            Err(FemError::LengthMismatch { .. })
        ));
        Ok(())
    }

    #[test]
    fn tangent_is_its_definition() -> Result<(), FemError> {
        for control in CONTROLS {
            check_tangent_against_definition::<2>(control)?;
            check_tangent_against_definition::<3>(control)?;
        }
        Ok(())
    }

    /// The mixed tangent differs from the consistent one by the pressure difference times the
    /// Hessian of the volume: `K_m - K = V0 (p_m - U'(J)) d^2 J / du^2` (the force `V0 J p g_a` at
    /// fixed pressure), and `volume_ratio_gradient` is `dJ/du`.
    fn check_mixed_tangent<const D: usize>() -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = OnePointSolid::new(&x, 0.7, &m, Hourglass::Enhanced)?;
        let u = general_u(&x);
        let (consistent, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
        let p_m = m.volumetric_pressure(consistent.volume_ratio) - 4.0e6;
        let (mixed, k_m) = tangent(&element, &m, &u, Tangent::Mixed { pressure: p_m })?;
        assert_eq!(mixed.force(), consistent.force());
        let shift = element.volume() * (p_m - m.volumetric_pressure(consistent.volume_ratio));
        let h = 1e-6;
        for dof in 0..D * element.node_count() {
            let plus = element.respond(&m, &perturb(&u, dof, h))?;
            let minus = element.respond(&m, &perturb(&u, dof, -h))?;
            let dj = (plus.volume_ratio - minus.volume_ratio) / (2.0 * h);
            assert!((dj - consistent.volume_ratio_gradient()[dof]).abs() < 1e-8);
            let hessian_column = (DVector::from_column_slice(plus.volume_ratio_gradient())
                - DVector::from_column_slice(minus.volume_ratio_gradient()))
                / (2.0 * h);
            let expected = k.column(dof) + hessian_column * shift;
            let err = (expected - k_m.column(dof)).amax() / k.amax();
            assert!(err < 1e-7, "D = {D}, dof {dof}: mixed tangent error {err}");
        }
        Ok(())
    }

    #[test]
    fn mixed_tangent_adds_pressure_times_volume_hessian() -> Result<(), FemError> {
        check_mixed_tangent::<2>()?;
        check_mixed_tangent::<3>()
    }

    /// Patch of distorted elements: affine displacement on the boundary, Newton on the interior
    /// nodes must reproduce the affine field and the homogeneous stress exactly.
    fn check_patch<const D: usize>(
        divisions: [usize; D],
        control: Hourglass,
    ) -> Result<(), FemError> {
        let m = material()?;
        let mut mesh =
            SolidMesh::<D>::structured_block(SVector::zeros(), SVector::repeat(3.0), divisions)?;
        let boundary: std::collections::BTreeSet<usize> =
            mesh.node_sets.values().flatten().copied().collect();
        for (id, x) in mesh.nodes.iter_mut().enumerate() {
            *x += SVector::from_fn(|k, _| 0.3 * jitter(7 * id + k));
        }
        mesh.validate()?;
        let elements = mesh
            .elements
            .iter()
            .map(|e| {
                let x: Vec<_> = e.iter().map(|&id| mesh.nodes[id]).collect();
                OnePointSolid::new(&x, 1.0, &m, control)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let f = homogeneous_f::<D>();
        let exact = affine(&f, &mesh.nodes);
        let free: Vec<usize> = (0..mesh.nodes.len() * D)
            .filter(|dof| !boundary.contains(&(dof / D)))
            .collect();
        assert!(!free.is_empty());
        let mut u = exact.clone();
        for &dof in &free {
            u[dof / D][dof % D] += 0.05 * jitter(dof + 999);
        }
        let tolerance = 1e-12 * m.initial_shear_modulus();
        let mut converged = false;
        for _ in 0..30 {
            let (mut force, mut stiffness) = (
                DVector::zeros(u.len() * D),
                DMatrix::zeros(u.len() * D, u.len() * D),
            );
            for (element, nodes) in elements.iter().zip(&mesh.elements) {
                let u_e: Vec<_> = nodes.iter().map(|&id| u[id]).collect();
                let (r, k) = tangent(element, &m, &u_e, Tangent::Consistent)?;
                for (a, &na) in nodes.iter().enumerate() {
                    for i in 0..D {
                        force[na * D + i] += r.force()[a * D + i];
                        for (b, &nb) in nodes.iter().enumerate() {
                            for j in 0..D {
                                stiffness[(na * D + i, nb * D + j)] += k[(a * D + i, b * D + j)];
                            }
                        }
                    }
                }
            }
            let residual = DVector::from_iterator(free.len(), free.iter().map(|&d| force[d]));
            if residual.amax() < tolerance {
                converged = true;
                break;
            }
            let k_ff =
                DMatrix::from_fn(free.len(), free.len(), |r, c| stiffness[(free[r], free[c])]);
            let du = k_ff
                .lu()
                .solve(&(-residual))
                .ok_or(FemError::InvalidMesh("singular".into()))?;
            for (&dof, step) in free.iter().zip(du.iter()) {
                u[dof / D][dof % D] += step;
            }
        }
        assert!(converged, "D = {D}, {control:?}: Newton did not converge");
        for (ui, ei) in u.iter().zip(&exact) {
            assert!(
                (ui - ei).norm() < 1e-9,
                "D = {D}, {control:?}: {ui} vs {ei}"
            );
        }
        let sigma = m.kirchhoff_stress(&f) / f.determinant();
        for (element, nodes) in elements.iter().zip(&mesh.elements) {
            let u_e: Vec<_> = nodes.iter().map(|&id| u[id]).collect();
            let r = element.respond(&m, &u_e)?;
            assert!((r.cauchy_stress - sigma).norm() < 1e-8 * sigma.norm());
            assert!(r.hourglass_energy < 1e-12 * r.strain_energy);
        }
        Ok(())
    }

    #[test]
    fn patch_of_distorted_elements_reproduces_homogeneous_deformation() -> Result<(), FemError> {
        for control in CONTROLS {
            check_patch::<2>([3, 3], control)?;
            check_patch::<3>([3, 3, 2], control)?;
        }
        Ok(())
    }

    fn check_rigid_rotation<const D: usize>(rotation: Matrix3<f64>) -> Result<(), FemError> {
        for control in CONTROLS {
            check_rigid_rotation_with::<D>(rotation, control)?;
        }
        Ok(())
    }

    fn check_rigid_rotation_with<const D: usize>(
        rotation: Matrix3<f64>,
        control: Hourglass,
    ) -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = OnePointSolid::new(&x, 1.0, &m, control)?;
        let u = affine(&rotation, &x);
        let r = element.respond(&m, &u)?;
        let mu = m.initial_shear_modulus();
        assert!((r.volume_ratio - 1.0).abs() < 1e-14);
        assert!(r.cauchy_stress.norm() < 1e-8 * mu, "{}", r.cauchy_stress);
        assert!(force(&r).amax() < 1e-8 * mu * element.volume());
        assert!(r.hourglass_energy < 1e-20 * mu * element.volume());
        assert!(r.strain_energy.abs() < 1e-12 * mu * element.volume());
        Ok(())
    }

    #[test]
    fn large_rigid_rotation_is_stress_and_force_free() -> Result<(), FemError> {
        let angle = 60f64.to_radians();
        check_rigid_rotation::<2>(*Rotation3::from_axis_angle(&V3::z_axis(), angle).matrix())?;
        let axis = nalgebra::Unit::new_normalize(V3::new(1.0, -2.0, 0.5));
        check_rigid_rotation::<3>(*Rotation3::from_axis_angle(&axis, angle).matrix())
    }

    fn zero_eigenvalues<const D: usize>(control: Hourglass) -> Result<usize, FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = OnePointSolid::new(&x, 1.0, &m, control)?;
        let u = vec![SVector::zeros(); element.node_count()];
        let (_, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
        let eigenvalues = SymmetricEigen::new(k).eigenvalues;
        let largest = eigenvalues.amax();
        assert!(eigenvalues.min() > -1e-10 * largest);
        Ok(eigenvalues
            .iter()
            .filter(|l| l.abs() < 1e-10 * largest)
            .count())
    }

    #[test]
    fn stabilised_element_has_only_rigid_zero_modes() -> Result<(), FemError> {
        for control in CONTROLS {
            assert_eq!(zero_eigenvalues::<2>(control)?, 3);
            assert_eq!(zero_eigenvalues::<3>(control)?, 6);
        }
        // Without stabilisation: 2 hourglass modes in 2D, 12 in 3D.
        let none = Hourglass::Stiffness { scale: 0.0 };
        assert_eq!(zero_eigenvalues::<2>(none)?, 3 + 2);
        assert_eq!(zero_eigenvalues::<3>(none)?, 6 + 12);
        Ok(())
    }

    fn check_hourglass_mode_energy<const D: usize>() -> Result<(), FemError> {
        let m = material()?;
        let mu = m.initial_shear_modulus();
        let half = [1.5, 0.5, 0.8];
        let element = OnePointSolid::new(&brick::<D>(half), 1.0, &m, Hourglass::default())?;
        let q = 1e-3;
        let v = element.volume();
        for (h, axes) in hourglass_base_vectors::<D>()?
            .iter()
            .zip(hourglass_mode_axes::<D>()?)
        {
            for (i, a_i) in half.iter().enumerate().take(D) {
                let u: Vec<SVector<f64, D>> = h
                    .iter()
                    .map(|&v| SVector::from_fn(|k, _| if k == i { q * v } else { 0.0 }))
                    .collect();
                let r = element.respond(&m, &u)?;
                // The mode has no mean strain, so the one-point material part does not see it...
                assert!(r.strain_energy.abs() < 1e-20 * mu * v);
                // ...and the stabilisation energy is mu0 int 2 eps:eps of the mode's strain:
                // bending eps_ii = q h / xi_i / a_i when h involves xi_i (mu0 q^2 V0 / (3 a_i^2)
                // for xi eta, a third of it for xi eta zeta), otherwise the shears
                // eps_il = q (dh/dxi_l) / (2 a_l), l in the mode's axes.
                let expected = if axes.contains(&i) {
                    mu * q * q * v / (a_i * a_i) * (1.0_f64 / 3.0).powi(axes.len() as i32 - 1)
                } else {
                    let (j, k) = (half[axes[0]], half[axes[1]]);
                    mu * q * q * v * (1.0 / (j * j) + 1.0 / (k * k)) / 6.0
                };
                assert!(
                    (r.hourglass_energy - expected).abs() < 1e-12 * expected,
                    "{D}D mode {axes:?} along {i}: {} vs {expected}",
                    r.hourglass_energy
                );
            }
        }
        // an element rotated in its plane gives every direction the mean of both axes
        if D == 2 {
            let turn = Rotation3::from_axis_angle(&V3::z_axis(), std::f64::consts::FRAC_PI_4);
            let turned: Vec<SVector<f64, D>> = brick::<D>(half)
                .iter()
                .map(|x| restrict(&(turn * embed(x))))
                .collect();
            let element = OnePointSolid::new(&turned, 1.0, &m, Hourglass::default())?;
            let (a, b) = (half[0], half[1]);
            let mean = mu * v * (1.0 / (a * a) + 1.0 / (b * b)) / 3.0;
            for i in 0..D {
                let k = element.hourglass.entry(i, i);
                assert!((k - mean).abs() < 1e-12 * mean, "{k} vs {mean}");
            }
        }
        Ok(())
    }

    #[test]
    fn hourglass_modes_carry_the_bending_or_shear_energy_of_a_brick() -> Result<(), FemError> {
        check_hourglass_mode_energy::<2>()?;
        check_hourglass_mode_energy::<3>()
    }

    #[test]
    fn volume_includes_thickness_and_lumped_mass_sums_to_total() -> Result<(), FemError> {
        let m = material()?;
        let control = Hourglass::default();
        let rect = OnePointSolid::<2>::new(&brick([1.0, 1.5, 0.0]), 0.5, &m, control)?;
        assert!((rect.volume() - 2.0 * 3.0 * 0.5).abs() < 1e-14);
        let hex = OnePointSolid::<3>::new(&brick([1.0, 1.5, 0.25]), 7.0, &m, control)?;
        assert!((hex.volume() - 2.0 * 3.0 * 0.5).abs() < 1e-14);
        let rho = 7800.0;
        let quad = OnePointSolid::<2>::new(&distorted(), 0.3, &m, control)?;
        let total = quad.lumped_node_mass(rho) * quad.node_count() as f64;
        assert!((total - rho * quad.volume()).abs() < 1e-12 * total);
        assert_eq!(quad.node_count(), 4);
        let hex = OnePointSolid::<3>::new(&distorted(), 1.0, &m, control)?;
        let total = hex.lumped_node_mass(rho) * hex.node_count() as f64;
        assert!((total - rho * hex.volume()).abs() < 1e-12 * total);
        Ok(())
    }

    #[test]
    fn inverted_and_degenerate_elements_are_errors() -> Result<(), FemError> {
        let m = material()?;
        let control = Hourglass::default();
        let quad = OnePointSolid::<2>::new(&distorted(), 1.0, &m, control)?;
        let flip = Matrix3::from_diagonal(&V3::new(-0.5, 1.0, 1.0));
        let u = affine(&flip, &distorted::<2>());
        assert!(
            matches!(tangent(&quad, &m, &u, Tangent::Consistent), Err(FemError::InvertedElement { det_f, corner: None }) if det_f < 0.0)
        );
        let hex = OnePointSolid::<3>::new(&distorted(), 1.0, &m, control)?;
        let flip = Matrix3::from_diagonal(&V3::new(1.0, 1.0, -0.5));
        let u = affine(&flip, &distorted::<3>());
        assert!(matches!(
            hex.respond(&m, &u),
            Err(FemError::InvertedElement { .. })
        ));
        // folded by its hourglass mode u_x = q xi eta: F at the centre is the identity, but at
        // the corners eta = -1 the bilinear field has dx/dX = 1 - 2q < 0
        let square: Vec<Vector2<f64>> = corners::<2>()
            .iter()
            .map(|xi| (xi.add_scalar(1.0)) * 0.5)
            .collect();
        let quad = OnePointSolid::<2>::new(&square, 1.0, &m, control)?;
        let fold = |q: f64| -> Vec<Vector2<f64>> {
            corners::<2>()
                .iter()
                .map(|xi| Vector2::new(q * xi[0] * xi[1], 0.0))
                .collect()
        };
        assert!((quad.deformation_gradient(&fold(0.6)) - Matrix3::identity()).amax() < 1e-15);
        assert!(matches!(
            quad.respond(&m, &fold(0.6)),
            Err(FemError::InvertedElement { det_f, corner: Some(_) }) if (det_f + 0.2).abs() < 1e-12
        ));
        let message = quad
            .respond(&m, &fold(0.6))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            message.contains("corner") && message.contains("folded"),
            "{message}"
        );
        assert!(quad.respond(&m, &fold(0.4)).is_ok());
        let mut nan = vec![V3::zeros(); 8];
        nan[3].x = f64::NAN;
        // a NaN displacement is not an inverted element
        assert!(matches!(
            hex.respond(&m, &nan),
            Err(FemError::NonFinite { .. })
        ));
        assert!(matches!(
            hex.respond(&m, &nan[..7]),
            Err(FemError::LengthMismatch { .. })
        ));

        let mut clockwise = distorted::<2>();
        clockwise.swap(1, 3);
        assert!(matches!(
            OnePointSolid::new(&clockwise, 1.0, &m, control),
            Err(FemError::DegenerateElement { det_j }) if det_j < 0.0
        ));
        let mut upside_down = distorted::<3>();
        upside_down.rotate_left(4);
        assert!(matches!(
            OnePointSolid::new(&upside_down, 1.0, &m, control),
            Err(FemError::DegenerateElement { .. })
        ));
        assert!(matches!(
            OnePointSolid::new(&[Vector2::new(1.0, 1.0); 4], 1.0, &m, control),
            Err(FemError::DegenerateElement { .. })
        ));
        assert!(matches!(
            OnePointSolid::<2>::new(&distorted(), 0.0, &m, control),
            Err(FemError::InvalidParameter {
                name: "thickness",
                ..
            })
        ));
        assert!(matches!(
            OnePointSolid::<3>::new(&distorted(), 1.0, &m, Hourglass::Stiffness { scale: -1.0 }),
            Err(FemError::InvalidParameter {
                name: "hourglass_scale",
                ..
            })
        ));
        Ok(())
    }
}
