//! Hourglass control of the one-point solid element ([`crate::OnePointSolid`]): a constant
//! stiffness on the element's hourglass modes, in one of two [`Hourglass`] controls.
//!
//! Notation, per displacement direction i and with `n = 2^D` nodes: `u_i` the nodal values of
//! the i-components, `X_j` the reference nodal coordinates in direction j, `b_j` the mean
//! gradient components (`b_j . X_k = delta_jk`, `b_j . 1 = 0`), `h_alpha` the hourglass base
//! vectors (`xi eta` in 2D; `xi eta`, `eta zeta`, `zeta xi`, `xi eta zeta` in 3D) and
//! `gamma_alpha = (1/n) [h_alpha - sum_j (h_alpha . X_j) b_j]` the Flanagan-Belytschko
//! hourglass vectors, so that `gamma . X_j = 0` and `gamma . 1 = 0`: affine fields, rigid motions
//! included, have no hourglass amplitude. The amplitudes `q_r = gamma_alpha . u_i`, one per
//! mode and direction (`r = alpha D + i`), carry the energy `E = 1/2 q^T H q`, the nodal force
//! `f_{iI} = sum_alpha (H q)_{alpha D + i} gamma_{alpha I}` and the constant tangent
//! `K_{(I i)(J k)} = sum_{alpha beta} gamma_{alpha I} H_{(alpha i)(beta k)} gamma_{beta J}`;
//! the controls differ in the symmetric matrix `H`.

use nalgebra::{DMatrix, DVector, SVector};

use crate::cell::{
    MAX_NODES, ReferenceGeometry, corner_count, hourglass_base_vectors, hourglass_mode_axes,
};
use crate::error::FemError;
use crate::integrated::{IntegratedSolid, Technology};
use crate::kinematics::{check_parameter, inverse_jacobian};
use crate::material::Hyperelastic;
use crate::response::Tangent;

/// Most hourglass amplitudes of an element: D directions times `2^D - D - 1` modes (12 in 3D).
const MAX_AMPLITUDES: usize = 12;

/// The hourglass control of a one-point element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hourglass {
    /// Flanagan-Belytschko stiffness from the initial shear modulus `mu0`, times `scale`
    /// (1 = default, 0 = no stabilisation); `H` is diagonal, one stiffness `k_{alpha i}` per
    /// mode and direction.
    ///
    /// `k_{alpha i}` is the energy `2 mu0 int eps:eps dV` of the mode's strain on a brick,
    /// without the parasitic shear of a bending mode. With `g_m = grad xi_m` at the centre
    /// (`|g_m| = 1/a_m` on a brick of half-widths `a_m`), the mode `h_alpha = prod_{k in S} xi_k`
    /// and `<.>` the mean over the parent cube, along the parametric axis m:
    /// - `m in S` (bending: `u_m = q h` stretches along m, `eps_mm = q |g_m| dh/dxi_m`):
    ///   `k = 2 mu0 V0 |g_m|^2 <(dh/dxi_m)^2>`, i.e. `(2/3) mu0 V0 / a_m^2` for `xi eta`;
    /// - `m not in S` (`u_m = q h` only shears, `eps_ml = q |g_l| dh/dxi_l / 2`):
    ///   `k = mu0 V0 sum_{l in S} |g_l|^2 <(dh/dxi_l)^2>`, i.e. `mu0 V0 (1/a_j^2 + 1/a_k^2)/3`
    ///   for `xi_j xi_k`.
    ///
    /// A Cartesian direction i takes the mean over the axes weighted by
    /// `w_mi = (g_m . e_i)^2 / |g_m|^2` (normalised), exact on a brick aligned with the axes.
    /// In 2D the single mode bends along both axes: `k_i = (2/3) mu0 V0 / a_i^2`. Only `mu0`
    /// enters, so the stabilisation does not stiffen with the bulk modulus.
    Stiffness {
        /// Dimensionless factor on the stiffness, finite and >= 0.
        scale: f64,
    },
    /// The small-strain stiffness that the incompatible-mode element (CPE4I / C3D8I,
    /// [`Technology::Incompatible`]) of the same reference geometry has for the hourglass modes:
    /// `H_{(alpha i)(beta k)} = psi_{(alpha i)}^T K_I psi_{(beta k)}`, with `K_I` that element's
    /// tangent at `u = 0` (its modes condensed; the material's tangent at `F = I`, for an
    /// isotropic law the linear elastic one with its initial moduli `mu0`, `K0`) and
    /// `psi_{(alpha i)}` the nodal displacement whose i-components are `psi_alpha` and whose
    /// other components vanish. The hourglass fields `psi_alpha` have no mean gradient and unit
    /// amplitude, `b_j . psi_alpha = 0` and `gamma_beta . psi_alpha = delta_{alpha beta}`:
    /// `psi_alpha = sum_beta phi_beta (M^{-1})_{beta alpha}` with
    /// `phi_beta = h_beta - sum_j (b_j . h_beta) X_j` and `M_{alpha beta} = gamma_alpha . h_beta`.
    ///
    /// Exact in the linear limit, in 2D and 3D and on any geometry: the small-strain
    /// one-point stiffness `K_R` plus this hourglass stiffness is `K_I`. Every `u` splits as
    /// `u_i = c_i 1 + sum_j (b_j . u_i) X_j + sum_alpha q_{alpha D + i} psi_alpha`; on the affine
    /// part `K_I` is `K_R` (the patch test: the modes' gradients have zero mean, so a constant
    /// strain does not excite them), the affine and hourglass parts do not couple in `K_I`
    /// (the constant stress of an affine field does no work on the zero-mean gradients of
    /// `psi` and of the modes) and `K_R` does not see the hourglass part (`b_j . psi = 0`).
    /// `H` keeps the couplings between modes and directions, which do not vanish in general:
    /// on a brick `u_x ~ zeta xi` and `u_y ~ eta zeta` couple through the bulk modulus, and the
    /// three twisting modes `u_x ~ eta zeta`, `u_y ~ zeta xi`, `u_z ~ xi eta` through the
    /// shear modulus. The `xi eta zeta` modes decouple on a brick; no incompatible mode relieves
    /// their dilatation, so their stiffness grows with the bulk modulus, as in C3D8I.
    Enhanced,
}

impl Default for Hourglass {
    /// The Flanagan-Belytschko stiffness at scale 1.
    fn default() -> Self {
        Self::Stiffness { scale: 1.0 }
    }
}

/// The constant hourglass stiffness of one element: its hourglass vectors `gamma_alpha` and
/// the matrix `H` of the module documentation.
#[derive(Clone, Debug)]
pub(crate) struct HourglassStiffness<const D: usize> {
    /// `gamma_alpha`, one per mode (node values; the first `2^D` used).
    pub(crate) vectors: Vec<[f64; MAX_NODES]>,
    /// `H`, symmetric, over the amplitudes `r = alpha D + i`, row-major.
    matrix: Vec<f64>,
}

impl<const D: usize> HourglassStiffness<D> {
    /// The hourglass stiffness of the control `control` for the element with the reference
    /// nodal coordinates `x_ref`, its `geometry` and plane-strain `thickness` (1 in 3D), of the
    /// material `material`.
    ///
    /// # Errors
    /// [`FemError::InvalidParameter`] for a negative or non-finite scale, those of
    /// [`IntegratedSolid::new`] and its tangent (Enhanced), [`FemError::DegenerateElement`] if
    /// the centre Jacobian or `M` is singular.
    pub(crate) fn new(
        x_ref: &[SVector<f64, D>],
        geometry: &ReferenceGeometry<D>,
        thickness: f64,
        material: &dyn Hyperelastic,
        control: Hourglass,
    ) -> Result<Self, FemError> {
        let n = corner_count(D);
        let coordinates: Vec<DVector<f64>> = (0..D)
            .map(|j| DVector::from_iterator(n, x_ref.iter().map(|x| x[j])))
            .collect();
        let gradients: Vec<DVector<f64>> = (0..D)
            .map(|j| DVector::from_iterator(n, geometry.mean_gradients.iter().map(|g| g[j])))
            .collect();
        let bases = hourglass_base_vectors::<D>()?;
        let vectors: Vec<DVector<f64>> = bases
            .iter()
            .map(|h| {
                let mut gamma = h.clone();
                for (x_j, b_j) in coordinates.iter().zip(&gradients) {
                    gamma.axpy(-h.dot(x_j), b_j, 1.0);
                }
                gamma.map(|gamma_a| gamma_a / n as f64)
            })
            .collect();
        let volume = geometry.measure * thickness;
        let amplitudes = D * bases.len();
        let mut matrix = vec![0.0; amplitudes * amplitudes];
        match control {
            Hourglass::Stiffness { scale } => {
                check_parameter("hourglass_scale", scale, scale >= 0.0, "finite and >= 0")?;
                let c = scale * material.initial_shear_modulus() * volume;
                let stiffness = mode_stiffness::<D>(&geometry_gradients(x_ref)?, c)?;
                for (alpha, k) in stiffness.iter().enumerate() {
                    for (i, k_i) in k.iter().enumerate() {
                        let r = alpha * D + i;
                        matrix[r * amplitudes + r] = *k_i;
                    }
                }
            }
            Hourglass::Enhanced => {
                let fields = hourglass_fields(&bases, &vectors, &coordinates, &gradients)?;
                let k_i = incompatible_stiffness(x_ref, thickness, material)?;
                let mut psi = DMatrix::zeros(D * n, amplitudes);
                for (alpha, field) in fields.iter().enumerate() {
                    for i in 0..D {
                        for (a, value) in field.iter().enumerate() {
                            psi[(a * D + i, alpha * D + i)] = *value;
                        }
                    }
                }
                let h = psi.transpose() * k_i * &psi;
                for (index, entry) in matrix.iter_mut().enumerate() {
                    let (r, s) = (index / amplitudes, index % amplitudes);
                    *entry = 0.5 * (h[(r, s)] + h[(s, r)]);
                }
            }
        }
        let vectors = vectors
            .iter()
            .map(|gamma| {
                let mut values = [0.0; MAX_NODES];
                values[..n].copy_from_slice(gamma.as_slice());
                values
            })
            .collect();
        Ok(Self { vectors, matrix })
    }

    /// Number of amplitudes, D times the number of modes.
    fn amplitude_count(&self) -> usize {
        D * self.vectors.len()
    }

    /// `H_{rs}`.
    #[cfg(test)]
    pub(crate) fn entry(&self, r: usize, s: usize) -> f64 {
        self.matrix[r * self.amplitude_count() + s]
    }

    /// Row r of `H`.
    fn row(&self, r: usize) -> &[f64] {
        let amplitudes = self.amplitude_count();
        &self.matrix[r * amplitudes..(r + 1) * amplitudes]
    }

    /// Adds the hourglass force `f_{iI} = sum_alpha (H q)_{alpha D + i} gamma_{alpha I}` at the
    /// nodal displacements `u` to `force` (node-major, index `I D + i`) and returns the energy
    /// `E = 1/2 q^T H q`, `q_{alpha D + i} = gamma_alpha . u_i`.
    pub(crate) fn add_force(&self, u: &[SVector<f64, D>], force: &mut [f64]) -> f64 {
        let mut q = [0.0; MAX_AMPLITUDES];
        for (alpha, gamma) in self.vectors.iter().enumerate() {
            for i in 0..D {
                q[alpha * D + i] = gamma.iter().zip(u).map(|(g, u_a)| g * u_a[i]).sum();
            }
        }
        let mut energy = 0.0;
        for i in 0..D {
            let mut f_i = [0.0; MAX_NODES];
            for (alpha, gamma) in self.vectors.iter().enumerate() {
                let r = alpha * D + i;
                let generalized: f64 = self.row(r).iter().zip(&q).map(|(h, q_s)| h * q_s).sum();
                energy += 0.5 * generalized * q[r];
                for (f_ia, gamma_a) in f_i.iter_mut().zip(gamma) {
                    *f_ia += generalized * gamma_a;
                }
            }
            for (a, f_ia) in f_i.iter().enumerate().take(u.len()) {
                force[a * D + i] += f_ia;
            }
        }
        energy
    }

    /// Adds the constant tangent `K_{(I i)(J k)} = sum_{alpha beta} gamma_{alpha I}
    /// H_{(alpha i)(beta k)} gamma_{beta J}` (the terms of nonzero `H` only) to the `c x c`
    /// matrix `k` (`c = D nodes`, node-major, column-major storage), each entry evaluated once
    /// for `(J k) >= (I i)` and written to both halves, so that it adds an exactly symmetric
    /// matrix.
    pub(crate) fn add_tangent(&self, nodes: usize, k: &mut [f64]) {
        let components = D * nodes;
        for row in 0..components {
            let (a, i) = (row / D, row % D);
            for column in row..components {
                let (b, l) = (column / D, column % D);
                let mut value = 0.0;
                for (alpha, gamma_alpha) in self.vectors.iter().enumerate() {
                    let h_row = self.row(alpha * D + i);
                    for (beta, gamma_beta) in self.vectors.iter().enumerate() {
                        let h = h_row[beta * D + l];
                        if h != 0.0 {
                            value += h * gamma_alpha[a] * gamma_beta[b];
                        }
                    }
                }
                if value != 0.0 {
                    k[column * components + row] += value;
                    if column != row {
                        k[row * components + column] += value;
                    }
                }
            }
        }
    }
}

/// `g_m = grad_X xi_m` at the cell centre: the rows of the inverse reference Jacobian there.
///
/// # Errors
/// [`FemError::DegenerateElement`] if that Jacobian is singular.
fn geometry_gradients<const D: usize>(
    x_ref: &[SVector<f64, D>],
) -> Result<Vec<SVector<f64, D>>, FemError> {
    let inverse = inverse_jacobian(x_ref, &SVector::zeros())?;
    Ok((0..D)
        .map(|m| SVector::from_fn(|i, _| inverse[(m, i)]))
        .collect())
}

/// `k_{alpha i}` of [`Hourglass::Stiffness`] from the parametric gradients `g_m` and the
/// factor `c = s mu0 V0`, one vector over the directions i per mode alpha.
///
/// # Errors
/// [`FemError::UnsupportedDimension`] unless D is 2 or 3.
fn mode_stiffness<const D: usize>(
    g: &[SVector<f64, D>],
    c: f64,
) -> Result<Vec<SVector<f64, D>>, FemError> {
    // w_mi = (g_m . e_i)^2 / |g_m|^2, normalised over m
    let weights = DMatrix::from_fn(D, D, |m, i| g[m][i] * g[m][i] / g[m].norm_squared());
    Ok(hourglass_mode_axes::<D>()?
        .iter()
        .map(|axes| {
            // <(dh/dxi_l)^2> = (1/3)^(|S| - 1) for every l in S
            let mean_square = (1.0_f64 / 3.0).powi(axes.len() as i32 - 1);
            let along_axis = |m: usize| {
                if axes.contains(&m) {
                    2.0 * g[m].norm_squared() * mean_square
                } else {
                    axes.iter().map(|&l| g[l].norm_squared()).sum::<f64>() * mean_square
                }
            };
            SVector::from_fn(|i, _| {
                let column = weights.column(i);
                c * (0..D).map(|m| column[m] * along_axis(m)).sum::<f64>() / column.sum()
            })
        })
        .collect())
}

/// The hourglass fields `psi_alpha = sum_beta phi_beta (M^{-1})_{beta alpha}` of
/// [`Hourglass::Enhanced`], `phi_beta = h_beta - sum_j (b_j . h_beta) X_j`,
/// `M_{alpha beta} = gamma_alpha . h_beta`, from the base vectors `h`, the hourglass vectors
/// `gamma`, the nodal coordinates `X_j` and the mean gradient components `b_j`.
///
/// # Errors
/// [`FemError::DegenerateElement`] if `M` is singular.
fn hourglass_fields(
    h: &[DVector<f64>],
    gamma: &[DVector<f64>],
    coordinates: &[DVector<f64>],
    gradients: &[DVector<f64>],
) -> Result<Vec<DVector<f64>>, FemError> {
    let phi: Vec<DVector<f64>> = h
        .iter()
        .map(|h| {
            let mut phi = h.clone();
            for (x_j, b_j) in coordinates.iter().zip(gradients) {
                phi.axpy(-b_j.dot(h), x_j, 1.0);
            }
            phi
        })
        .collect();
    let m = DMatrix::from_fn(h.len(), h.len(), |alpha, beta| gamma[alpha].dot(&h[beta]));
    let det = m.determinant();
    let inverse = m
        .try_inverse()
        .ok_or(FemError::DegenerateElement { det_j: det })?;
    Ok((0..h.len())
        .map(|alpha| {
            (phi.iter().enumerate()).fold(DVector::zeros(h[0].len()), |sum, (beta, phi_beta)| {
                sum + phi_beta * inverse[(beta, alpha)]
            })
        })
        .collect())
}

/// `K_I`, the tangent at `u = 0` of the incompatible-mode element of the reference geometry
/// `x_ref` and `thickness` with `material` (its modes condensed).
///
/// # Errors
/// Those of [`IntegratedSolid::new`] and [`IntegratedSolid::respond_with_tangent`].
fn incompatible_stiffness<const D: usize>(
    x_ref: &[SVector<f64, D>],
    thickness: f64,
    material: &dyn Hyperelastic,
) -> Result<DMatrix<f64>, FemError> {
    let element = IntegratedSolid::new(Technology::Incompatible, x_ref, thickness)?;
    let components = D * x_ref.len();
    let mut k = vec![0.0; components * components];
    let zero = vec![SVector::<f64, D>::zeros(); x_ref.len()];
    element.respond_with_tangent(material, &zero, Tangent::Consistent, &mut k)?;
    Ok(DMatrix::from_vec(components, components, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::corners;
    use crate::material::PolynomialN1;
    use crate::solid::OnePointSolid;
    use crate::test_fixtures::{dense_tangent, distorted, material};

    /// The tangent at `u = 0` of the one-point element with `control`.
    fn reduced<const D: usize>(
        x: &[SVector<f64, D>],
        material: &dyn Hyperelastic,
        control: Hourglass,
    ) -> Result<DMatrix<f64>, FemError> {
        let element = OnePointSolid::new(x, 0.7, material, control)?;
        let zero = vec![SVector::zeros(); x.len()];
        let (_, k) = dense_tangent(D * x.len(), |k| {
            element.respond_with_tangent(material, &zero, Tangent::Consistent, k)
        })?;
        Ok(k)
    }

    /// `|K_R + K_hg - K_I| / |K_I|` (largest entries) at `u = 0` for the enhanced control.
    fn enhanced_error<const D: usize>(
        x: &[SVector<f64, D>],
        material: &dyn Hyperelastic,
    ) -> Result<f64, FemError> {
        let k_r = reduced(x, material, Hourglass::Enhanced)?;
        let k_i = incompatible_stiffness(x, 0.7, material)?;
        Ok((k_r - &k_i).amax() / k_i.amax())
    }

    /// A brick with half-widths 1.5, 0.5, 0.8.
    fn brick<const D: usize>() -> Vec<SVector<f64, D>> {
        let half = [1.5, 0.5, 0.8];
        corners::<D>()
            .iter()
            .map(|c| SVector::from_fn(|k, _| half[k] * c[k]))
            .collect()
    }

    #[test]
    fn enhanced_one_point_stiffness_is_the_incompatible_modes_one() -> Result<(), FemError> {
        // the drum pad's nearly incompressible material and a compressible one (nu = 0.3)
        let materials = [material()?, PolynomialN1::new(0.5, 0.0, 2.0 / 2.1667)?];
        for m in &materials {
            for (what, error) in [
                ("distorted quad", enhanced_error(&distorted::<2>(), m)?),
                ("distorted hex", enhanced_error(&distorted::<3>(), m)?),
                ("rectangle", enhanced_error(&brick::<2>(), m)?),
                ("brick", enhanced_error(&brick::<3>(), m)?),
            ] {
                assert!(
                    error < 1e-12,
                    "{what}: K_R + K_hg differs from K_I by {error}"
                );
            }
            // the Flanagan-Belytschko stiffness is not the incompatible-mode element's
            let k_r = reduced(&distorted::<2>(), m, Hourglass::default())?;
            let k_i = incompatible_stiffness(&distorted::<2>(), 0.7, m)?;
            assert!((k_r - &k_i).amax() > 1e-3 * k_i.amax());
        }
        Ok(())
    }

    #[test]
    fn enhanced_stiffness_couples_modes_and_directions_on_a_brick() -> Result<(), FemError> {
        let m = material()?;
        let x = brick::<3>();
        let geometry = ReferenceGeometry::new(&x)?;
        let h = HourglassStiffness::new(&x, &geometry, 1.0, &m, Hourglass::Enhanced)?;
        let entry = |r: usize, s: usize| h.entry(r, s) / (h.entry(r, r) * h.entry(s, s)).sqrt();
        // modes (xi eta, eta zeta, zeta xi, xi eta zeta), amplitude r = alpha 3 + i:
        // u_x ~ zeta xi (r = 6) with u_y ~ eta zeta (r = 4), through the bulk modulus
        assert!(entry(6, 4).abs() > 0.1, "{}", entry(6, 4));
        // u_x ~ eta zeta (3), u_y ~ zeta xi (7), u_z ~ xi eta (2): the twisting modes
        assert!(entry(3, 7).abs() > 0.1 && entry(7, 2).abs() > 0.1);
        // the xi eta zeta modes (9, 10, 11) decouple from every other amplitude
        for r in 9..12 {
            for s in (0..12).filter(|&s| s != r) {
                assert!(entry(r, s).abs() < 1e-12, "{r}, {s}: {}", entry(r, s));
            }
        }
        Ok(())
    }
}
