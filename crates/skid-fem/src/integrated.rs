//! Fully integrated solid elements (the `2^D`-point Gauss rule) in three technologies: the
//! displacement element (the CPE4 / C3D8 role), the hybrid constant-pressure element (CPE4H /
//! C3D8H) and the incompatible-mode element (CPE4I / C3D8I); 2D plane strain (D = 2,
//! thickness t, `F33 = 1`) and 3D (D = 3), one code path.
//!
//! With `dV_p = w_p det J(xi_p) t` the reference volume of Gauss point p (`t = 1` in 3D),
//! `V0 = sum_p dV_p` and `F_p = I + sum_a u_a (x) grad_X N_a(xi_p)`:
//! - [`Technology::Full`]: `Pi(u) = sum_p dV_p W(F_p)`.
//! - [`Technology::Hybrid`]: the constant-pressure mixed element (Q1/P0) with its pressure
//!   condensed, which for `U'' > 0` is the mean-dilatation potential
//!   `Pi(u) = sum_p dV_p W_iso(F_p) + V0 U(theta)`, `W_iso = W - U(J)`, with the element volume
//!   ratio `theta = v / V0 = (1/V0) sum_p dV_p J_p`.
//! - [`Technology::Incompatible`]: enhanced (incompatible-mode) deformation gradients
//!   `F_p = I + sum_a u_a (x) grad_X N_a + sum_m alpha_m (x) G_m(xi_p)` with the D modes
//!   `M_m = 1 - xi_m^2` and `G_m = (j0 / j(xi)) J0^{-T} dM_m/dxi` (`J0`, `j0`: reference
//!   Jacobian and its determinant at the centre), so that `sum_p dV_p G_m(xi_p) = 0` and the
//!   patch test passes on distorted elements; `Pi(u) = Pi(u, alpha*(u))` with
//!   `Pi(u, alpha) = sum_p dV_p W(F_p)` and the mode parameters `alpha_m in R^D` condensed:
//!   `alpha*(u)` solves `dPi/dalpha = 0` (a local Newton solve per evaluation).
//!
//! The modes enter the kinematics like extra nodes with reference gradients `G_m`: the force
//! and stiffness of the (nodes + modes) system have the structure of the standard ones, with
//! the spatial gradients `g_A = F^{-T} G_A`.
//!
//! An evaluation allocates nothing: its results live in fixed arrays sized for the largest
//! element (3D with modes: 24 + 9 unknowns), and the tangent goes into a buffer of the caller's.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use crate::cell::{
    MAX_COMPONENTS, MAX_NODES, ReferenceGeometry, corner_count, embed, gauss_points, jacobian,
    restrict, shape_functions,
};
use crate::error::FemError;
use crate::kinematics::{
    CornerGradients, MAX_GRADIENTS, add_pair_stiffness, check_corners, check_inputs,
    check_parameter, corner_gradients, gradient_of, reference_gradients,
};
use crate::material::Hyperelastic;
use crate::response::{ElementResponse, Tangent};

/// Most incompatible-mode parameters of an element: D modes of D components each.
const MAX_MODE_PARAMETERS: usize = 9;

/// Most unknowns of the (nodes + modes) system.
const MAX_UNKNOWNS: usize = MAX_COMPONENTS + MAX_MODE_PARAMETERS;

/// Most local Newton iterations for the mode parameters.
const MAX_LOCAL_ITERATIONS: usize = 25;

/// Most step halvings of one local Newton iteration.
const MAX_HALVINGS: usize = 30;

/// The local solve ends after a Newton step whose change of `F` is at most this (in norm, an
/// upper bound over the Gauss points): quadratic convergence leaves an error of its square.
const STEP_TOLERANCE: f64 = 1e-10;

/// The local solve ends when the mode residual is at most this times its round-off scale
/// `sum_p dV_p |tau_p| max_m |g_m|`.
const RESIDUAL_TOLERANCE: f64 = 1e-13;

/// The mode parameters (padded to 3D) and their square matrices; an unused block is the
/// identity.
type ModeVector = SVector<f64, MAX_MODE_PARAMETERS>;
type ModeMatrix = SMatrix<f64, MAX_MODE_PARAMETERS, MAX_MODE_PARAMETERS>;

/// The element technology of an [`IntegratedSolid`] (all with the `2^D`-point Gauss rule).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technology {
    /// The displacement element (CPE4 / C3D8): `Pi = sum_p dV_p W(F_p)`. Locks in bending
    /// (parasitic shear) and when nearly incompressible (volumetric locking).
    Full,
    /// The constant-pressure hybrid element (CPE4H / C3D8H), condensed to the mean-dilatation
    /// potential `Pi = sum_p dV_p W_iso(F_p) + V0 U(theta)`: free of volumetric locking.
    Hybrid,
    /// The incompatible-mode element (CPE4I / C3D8I): D enhanced modes `1 - xi_m^2`, exact in
    /// pure bending of a parallelogram (brick) and free of volumetric locking in bending.
    Incompatible,
}

/// One Gauss point: its reference volume and the reference gradients entering `F`.
#[derive(Clone, Debug)]
struct GaussPoint<const D: usize> {
    /// `dV_p = w_p det J(xi_p) t`.
    volume: f64,
    /// `grad_X N_a(xi_p)` of the `2^D` nodes, then `G_m(xi_p)` of the D modes (Incompatible).
    gradients: [SVector<f64, D>; MAX_GRADIENTS],
}

/// Kinematics at one Gauss point.
#[derive(Clone, Copy, Debug, Default)]
struct PointState {
    /// Deformation gradient, embedded in 3D.
    f: Matrix3<f64>,
    /// `J = det F > 0`.
    det_f: f64,
    /// Spatial gradients `g_A = F^{-T} G_A` of the nodes, then of the modes.
    g: [Vector3<f64>; MAX_GRADIENTS],
}

/// The mode equations `dPi/dalpha = 0` at one iterate.
struct ModeSystem {
    /// `R_m = sum_p dV_p tau_p g_m(xi_p)` (mode-major, padded with zeros).
    residual: ModeVector,
    /// `K_aa = dR/dalpha`, the mode-mode blocks of the (nodes + modes) stiffness (padded with
    /// the identity).
    stiffness: ModeMatrix,
    /// `|R|` (Euclidean).
    norm: f64,
    /// Round-off scale of `R`: `sum_p dV_p |tau_p| max_m |g_m(xi_p)|`.
    scale: f64,
}

/// A fully integrated quad (D = 2, plane strain) or hex (D = 3) of one [`Technology`].
#[derive(Clone, Debug)]
pub struct IntegratedSolid<const D: usize> {
    /// The element technology.
    technology: Technology,
    /// Reference volume `V0 = sum_p dV_p` (area times thickness in 2D).
    volume: f64,
    /// The `2^D` Gauss points.
    points: Vec<GaussPoint<D>>,
    /// `int N_a dV` per node (the first `2^D` entries).
    node_volumes: [f64; MAX_NODES],
    /// Reference gradients at the cell corners, for the corner inversion check.
    corner_gradients: CornerGradients<D>,
    /// `max_p max_m |G_m(xi_p)|` (zero without modes), bounding the change of `F` by a change
    /// of the mode parameters.
    mode_gradient_bound: f64,
}

impl<const D: usize> IntegratedSolid<D> {
    /// Builds the element from its reference geometry: `x_ref`, the `2^D` reference nodal
    /// coordinates in the cell corner order; `thickness`, the out-of-plane thickness in 2D
    /// (plane strain), ignored in 3D (pass 1.0).
    ///
    /// Per Gauss point `xi_p` (weight `w_p = 1`): `dV_p = w_p det J(xi_p) t`, the reference
    /// gradients `grad_X N_a = J(xi_p)^{-T} dN_a/dxi` and, for [`Technology::Incompatible`],
    /// `G_m(xi_p) = (j0 / det J(xi_p)) J0^{-T} (-2 xi_pm e_m)`.
    ///
    /// # Errors
    /// [`FemError::UnsupportedDimension`] unless D is 2 or 3, [`FemError::LengthMismatch`],
    /// [`FemError::DegenerateElement`] for a reference Jacobian `det J <= 0` at a corner or
    /// Gauss point, [`FemError::InvalidParameter`] for a non-positive thickness (2D).
    pub fn new(
        technology: Technology,
        x_ref: &[SVector<f64, D>],
        thickness: f64,
    ) -> Result<Self, FemError> {
        let geometry = ReferenceGeometry::new(x_ref)?;
        let thickness = if D == 2 {
            check_parameter("thickness", thickness, thickness > 0.0, "finite and > 0")?
        } else {
            1.0
        };
        let n = corner_count(D);
        let modes = if technology == Technology::Incompatible {
            D
        } else {
            0
        };
        let centre = jacobian(x_ref, &SVector::zeros());
        let j0 = centre.determinant();
        let j0_inv_t = centre
            .try_inverse()
            .ok_or(FemError::DegenerateElement { det_j: j0 })?
            .transpose();
        let mut node_volumes = [0.0; MAX_NODES];
        let mut mode_gradient_bound: f64 = 0.0;
        let mut points = Vec::with_capacity(n);
        for (xi, weight) in gauss_points::<D>() {
            let det_j = jacobian(x_ref, &xi).determinant();
            let volume = weight * det_j * thickness;
            let mut gradients = [SVector::zeros(); MAX_GRADIENTS];
            for (slot, g) in gradients.iter_mut().zip(reference_gradients(x_ref, &xi)?) {
                *slot = g;
            }
            for (m, slot) in gradients[n..n + modes].iter_mut().enumerate() {
                let mut dm_dxi = Vector3::zeros();
                dm_dxi[m] = -2.0 * xi[m];
                *slot = restrict(&(j0_inv_t * dm_dxi * (j0 / det_j)));
                mode_gradient_bound = mode_gradient_bound.max(slot.norm());
            }
            for (node_volume, n_a) in node_volumes.iter_mut().zip(shape_functions(&xi)) {
                *node_volume += n_a * volume;
            }
            points.push(GaussPoint { volume, gradients });
        }
        Ok(Self {
            technology,
            volume: geometry.measure * thickness,
            points,
            node_volumes,
            corner_gradients: corner_gradients(x_ref)?,
            mode_gradient_bound,
        })
    }

    /// The element technology.
    pub fn technology(&self) -> Technology {
        self.technology
    }

    /// Number of nodes `2^D`.
    pub fn node_count(&self) -> usize {
        corner_count(D)
    }

    /// Reference volume `V0` (area times thickness in 2D).
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// Lumped (row-sum) masses of the nodes, in the first `2^D` entries:
    /// `m_a = sum_b rho int N_a N_b dV = rho int N_a dV` (by `sum_b N_b = 1`), integrated with
    /// the Gauss rule; they sum to `rho V0`, and are equal on a parallelogram (brick).
    pub fn lumped_node_masses(&self, density: f64) -> [f64; MAX_NODES] {
        self.node_volumes.map(|v| density * v)
    }

    /// Internal force, strain energy, stress and volume ratio at the nodal displacements `u`
    /// (node-major ordering: index `a * D + i`).
    ///
    /// Force `f_a = sum_p dV_p tau_p g_a(xi_p)`, `g_a = F_p^{-T} grad_X N_a`, with the Kirchhoff
    /// stress `tau_p = tau(F_p)` (Full, Incompatible at the condensed modes `alpha*(u)`) or
    /// `tau_p = tau_iso(F_p) + J_p U'(theta) I` (Hybrid). `strain_energy` is the element
    /// potential `Pi` (see the module documentation), `hourglass_energy = 0`.
    /// `cauchy_stress` is the current-volume mean `sum_p dV_p tau_p / (V0 theta)`, i.e.
    /// `(1/v) int sigma dv` with `sigma_p = tau_p / J_p`. `volume_ratio` is `theta = v / V0`
    /// and `volume_ratio_gradient` its total derivative `dtheta/du`: `(1/V0) sum_p dV_p J_p
    /// g_a(xi_p)`, for Incompatible with the modes following `u`
    /// (`dtheta/du - K_ua K_aa^{-1} dtheta/dalpha`).
    ///
    /// Inversion: `J_p` is checked at every Gauss point, and `J_c` of the multilinear
    /// displacement field (without the modes) at every cell corner, as for the one-point
    /// element. The Incompatible element solves its modes by a local Newton iteration started
    /// at `alpha = 0` on every call (a pure function of `u`), with step halving where a step
    /// would invert a Gauss point or not reduce `|dPi/dalpha|`. It assembles and condenses its
    /// (nodes + modes) stiffness here as well, for the mode part of `dtheta/du`.
    ///
    /// # Errors
    /// [`FemError::LengthMismatch`] if `u` does not hold one vector per node,
    /// [`FemError::NonFinite`] if `u` is not finite, [`FemError::InvertedElement`] if `J <= 0`
    /// at a Gauss point (`corner: None`) or a corner, [`FemError::IncompatibleModesNotConverged`]
    /// if the local solve fails.
    pub fn respond(
        &self,
        material: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
    ) -> Result<ElementResponse, FemError> {
        self.evaluate(material, u, None)
    }

    /// As [`Self::respond`], and the tangent `d force / d u` into `stiffness`: the exactly
    /// symmetric `n x n` matrix (`n = D 2^D`, node-major), all of its entries.
    ///
    /// Per Gauss point, `K_ab,ik += dV_p [sum_jl g_aj c_ijkl g_bl + (g_a . tau g_b) delta_ik]`
    /// (only in-plane `i, k` in 2D), with:
    /// - Full and Incompatible: `tau`, `c = c^tau` of the material at `F_p`. For Incompatible
    ///   this is assembled over nodes and modes and condensed,
    ///   `K = K_uu - K_ua K_aa^{-1} K_au` (symmetrised entrywise to round-off).
    /// - Hybrid: `tau`, `c` of [`Hyperelastic::mixed_stress_and_tangent`] at the pressure
    ///   `pbar = U'(theta)` minus the point's volumetric stiffness `J_p^2 U''(J_p) I (x) I`,
    ///   plus the element's `V0 U''(theta) (dtheta/du) (x) (dtheta/du)`.
    ///
    /// [`Tangent::Mixed`] `{ pressure }` replaces `pbar` by `pressure` in the stress-dependent
    /// point terms of the Hybrid element (the geometric term and `J p (I (x) I - 2 II)`), which
    /// adds `V0 (pressure - pbar) d^2 theta / du^2`; it equals the consistent tangent when
    /// `pressure = U'(theta)`. The Full and Incompatible elements have no element-constant
    /// pressure to substitute (theirs varies over the Gauss points), so they return the
    /// consistent tangent for either request. The force is the same in every case.
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

    /// Number of incompatible modes: D for [`Technology::Incompatible`], else 0.
    fn mode_count(&self) -> usize {
        if self.technology == Technology::Incompatible {
            D
        } else {
            0
        }
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
        check_corners(&self.corner_gradients, u)?;
        let modes = self.mode_count();
        let mut unknowns = [SVector::zeros(); MAX_GRADIENTS];
        unknowns[..n].copy_from_slice(u);
        if modes > 0 {
            self.solve_modes(material, &mut unknowns)?;
        }
        let unknowns = &unknowns[..n + modes];
        let size = D * unknowns.len();
        let mut states = [PointState::default(); MAX_NODES];
        for (state, point) in states.iter_mut().zip(&self.points) {
            *state = point_state(point, unknowns)?;
        }
        let states = &states[..self.points.len()];
        let theta = (states.iter().zip(&self.points))
            .map(|(state, point)| point.volume * state.det_f)
            .sum::<f64>()
            / self.volume;

        let hybrid = self.technology == Technology::Hybrid;
        let pbar = material.volumetric_pressure(theta);
        let mut force = [0.0; MAX_UNKNOWNS];
        let mut theta_gradient = [0.0; MAX_UNKNOWNS];
        let mut energy = 0.0;
        let mut weighted_stress = Matrix3::zeros();
        for (state, point) in states.iter().zip(&self.points) {
            let (j, dv) = (state.det_f, point.volume);
            let mut tau = material.kirchhoff_stress(&state.f);
            energy += dv * material.strain_energy(&state.f);
            if hybrid {
                tau += Matrix3::identity() * (j * (pbar - material.volumetric_pressure(j)));
                energy -= dv * material.volumetric_energy(j);
            }
            weighted_stress += tau * dv;
            for (a, g_a) in state.g[..unknowns.len()].iter().enumerate() {
                let f_a = tau * g_a * dv;
                for i in 0..D {
                    force[a * D + i] += f_a[i];
                    theta_gradient[a * D + i] += dv * j * g_a[i] / self.volume;
                }
            }
        }
        if hybrid {
            energy += self.volume * material.volumetric_energy(theta);
        }
        let mut response = ElementResponse {
            components,
            strain_energy: energy,
            cauchy_stress: weighted_stress / (self.volume * theta),
            volume_ratio: theta,
            ..ElementResponse::default()
        };
        response.force[..components].copy_from_slice(&force[..components]);
        response.volume_ratio_gradient[..components].copy_from_slice(&theta_gradient[..components]);

        if modes == 0 {
            if let Some((tangent, k)) = tangent {
                k.fill(0.0);
                self.add_stiffness(material, states, tangent, theta, &theta_gradient[..size], k);
            }
            return Ok(response);
        }
        // Incompatible: the (nodes + modes) stiffness, condensed
        let mut extended = [0.0; MAX_UNKNOWNS * MAX_UNKNOWNS];
        let extended = &mut extended[..size * size];
        let consistent = Tangent::Consistent;
        self.add_stiffness(material, states, consistent, theta, &[], extended);
        let na = size - components;
        let k_aa = ModeMatrix::from_fn(|r, c| match (r < na, c < na) {
            (true, true) => extended[(components + c) * size + components + r],
            _ if r == c => 1.0,
            _ => 0.0,
        });
        let k_au = SMatrix::<f64, MAX_MODE_PARAMETERS, MAX_COMPONENTS>::from_fn(|r, c| {
            if r < na && c < components {
                extended[c * size + components + r]
            } else {
                0.0
            }
        });
        // X = K_aa^{-1} K_au = -dalpha/du
        let x = k_aa
            .lu()
            .solve(&k_au)
            .ok_or(FemError::IncompatibleModesNotConverged {
                residual: f64::NAN,
                iterations: 0,
            })?;
        for (c, gradient) in response.volume_ratio_gradient[..components]
            .iter_mut()
            .enumerate()
        {
            *gradient -= (0..na)
                .map(|m| x[(m, c)] * theta_gradient[components + m])
                .sum::<f64>();
        }
        if let Some((_, k)) = tangent {
            // S = K_uu - K_ua X, symmetrised: (S_rc + S_cr) / 2 to both entries
            let schur = |r: usize, c: usize| {
                extended[c * size + r] - (0..na).map(|m| k_au[(m, r)] * x[(m, c)]).sum::<f64>()
            };
            for c in 0..components {
                for r in 0..=c {
                    let value = 0.5 * (schur(r, c) + schur(c, r));
                    k[c * components + r] = value;
                    k[r * components + c] = value;
                }
            }
        }
        Ok(response)
    }

    /// Adds the point terms of the tangent (see [`Self::respond_with_tangent`]) over the
    /// gradients of `states` (nodes, and modes if any) to the zeroed matrix `k`, and for the
    /// Hybrid element the rank-one term `V0 U''(theta) dtheta (x) dtheta` with the gradient
    /// `theta_gradient` over the same unknowns.
    fn add_stiffness(
        &self,
        material: &dyn Hyperelastic,
        states: &[PointState],
        tangent: Tangent,
        theta: f64,
        theta_gradient: &[f64],
        k: &mut [f64],
    ) {
        let unknowns = self.node_count() + self.mode_count();
        let hybrid = self.technology == Technology::Hybrid;
        for (state, point) in states.iter().zip(&self.points) {
            let (tau, c) = if hybrid {
                let pressure = match tangent {
                    Tangent::Consistent => material.volumetric_pressure(theta),
                    Tangent::Mixed { pressure } => pressure,
                };
                let (tau, c) = material.mixed_stress_and_tangent(&state.f, pressure);
                // the point's own volumetric stiffness J^2 U''(J) I (x) I is replaced by the
                // element's rank-one term
                let j = state.det_f;
                let volumetric = j * j * material.volumetric_stiffness(j);
                let mut c = c.0;
                for r in 0..3 {
                    for s in 0..3 {
                        c[(r, s)] -= volumetric;
                    }
                }
                (tau, c)
            } else {
                let (tau, c) = material.stress_and_tangent(&state.f);
                (tau, c.0)
            };
            let dv = point.volume;
            add_pair_stiffness::<D>(&state.g[..unknowns], &(tau * dv), &(c * dv), k);
        }
        if hybrid {
            let size = theta_gradient.len();
            let scale = self.volume * material.volumetric_stiffness(theta);
            for (c, dtheta_c) in theta_gradient.iter().enumerate() {
                for (r, dtheta_r) in theta_gradient.iter().enumerate().take(c + 1) {
                    let value = scale * dtheta_r * dtheta_c;
                    k[c * size + r] += value;
                    if r != c {
                        k[r * size + c] += value;
                    }
                }
            }
        }
    }

    /// The residual `R = dPi/dalpha` and stiffness `K_aa` of the mode equations at the
    /// unknowns `v` (nodal displacements, then mode parameters).
    ///
    /// # Errors
    /// [`FemError::InvertedElement`] if `J <= 0` at a Gauss point.
    fn mode_system(
        &self,
        material: &dyn Hyperelastic,
        v: &[SVector<f64, D>],
    ) -> Result<ModeSystem, FemError> {
        let n = self.node_count();
        let na = D * D;
        let mut residual = ModeVector::zeros();
        let mut k = [0.0; MAX_MODE_PARAMETERS * MAX_MODE_PARAMETERS];
        let mut scale = 0.0;
        for point in &self.points {
            let state = point_state(point, v)?;
            let (tau, c) = material.stress_and_tangent(&state.f);
            let g_modes = &state.g[n..n + D];
            let mut largest: f64 = 0.0;
            for (m, g_m) in g_modes.iter().enumerate() {
                let r_m = tau * g_m * point.volume;
                for i in 0..D {
                    residual[m * D + i] += r_m[i];
                }
                largest = largest.max(g_m.norm());
            }
            scale += point.volume * tau.norm() * largest;
            let dv = point.volume;
            add_pair_stiffness::<D>(g_modes, &(tau * dv), &(c.0 * dv), &mut k[..na * na]);
        }
        Ok(ModeSystem {
            norm: residual.norm(),
            residual,
            stiffness: ModeMatrix::from_fn(|r, c| match (r < na, c < na) {
                (true, true) => k[c * na + r],
                _ if r == c => 1.0,
                _ => 0.0,
            }),
            scale,
        })
    }

    /// Solves `dPi/dalpha = 0` for the mode parameters `v[2^D..2^D + D]` (which must hold zero
    /// on entry: the solve starts at `alpha = 0`) by Newton's method with step halving, and
    /// returns the number of Newton steps.
    ///
    /// A step `d = -K_aa^{-1} R` is halved until no Gauss point inverts and `|R|` decreases.
    /// Converged when `|R| <= 1e-13 sum_p dV_p |tau_p| max_m |g_m|` or after a full step
    /// changing `F` by at most `1e-10` (`sum_m |d_m| max |G_m|`).
    ///
    /// # Errors
    /// [`FemError::InvertedElement`] if the compatible field (`alpha = 0`) inverts a Gauss
    /// point; [`FemError::IncompatibleModesNotConverged`] after 25 iterations, when 30 halvings
    /// do not find an admissible step, or for a singular `K_aa`.
    fn solve_modes(
        &self,
        material: &dyn Hyperelastic,
        v: &mut [SVector<f64, D>; MAX_GRADIENTS],
    ) -> Result<usize, FemError> {
        let n = self.node_count();
        let unknowns = n + D;
        let failure = |residual, iterations| FemError::IncompatibleModesNotConverged {
            residual,
            iterations,
        };
        let mut system = self.mode_system(material, &v[..unknowns])?;
        for iteration in 0..MAX_LOCAL_ITERATIONS {
            if system.norm <= RESIDUAL_TOLERANCE * system.scale {
                return Ok(iteration);
            }
            let step = (system.stiffness.lu())
                .solve(&(-system.residual))
                .ok_or_else(|| failure(system.norm, iteration))?;
            let step_of = |m: usize| SVector::<f64, D>::from_fn(|i, _| step[m * D + i]);
            let change: f64 = (0..D).map(|m| step_of(m).norm()).sum::<f64>();
            let mut alpha = [SVector::<f64, D>::zeros(); 3];
            alpha[..D].copy_from_slice(&v[n..unknowns]);
            if change * self.mode_gradient_bound <= STEP_TOLERANCE {
                for m in 0..D {
                    v[n + m] = alpha[m] + step_of(m);
                }
                return Ok(iteration + 1);
            }
            let mut length = 1.0;
            let mut accepted = None;
            for _ in 0..MAX_HALVINGS {
                for m in 0..D {
                    v[n + m] = alpha[m] + step_of(m) * length;
                }
                match self.mode_system(material, &v[..unknowns]) {
                    Ok(trial) if trial.norm < system.norm => {
                        accepted = Some(trial);
                        break;
                    }
                    _ => length *= 0.5,
                }
            }
            match accepted {
                Some(trial) => system = trial,
                None => return Err(failure(system.norm, iteration + 1)),
            }
        }
        Err(failure(system.norm, MAX_LOCAL_ITERATIONS))
    }
}

/// `F_p = I + sum_A v_A (x) G_A(xi_p)` over the unknowns `v` (nodes, then modes), its
/// determinant and the spatial gradients `g_A = F_p^{-T} G_A`.
///
/// # Errors
/// [`FemError::InvertedElement`] (`corner: None`) if `J <= 0` or `F` is not finite.
fn point_state<const D: usize>(
    point: &GaussPoint<D>,
    v: &[SVector<f64, D>],
) -> Result<PointState, FemError> {
    let f = gradient_of(point.gradients.iter().zip(v));
    let det_f = f.determinant();
    let inverted = || FemError::InvertedElement {
        det_f,
        corner: None,
    };
    if !(det_f > 0.0 && f.iter().all(|c| c.is_finite())) {
        return Err(inverted());
    }
    let f_inv_t = f.try_inverse().ok_or_else(inverted)?.transpose();
    let mut g = [Vector3::zeros(); MAX_GRADIENTS];
    for (g_a, reference) in g.iter_mut().zip(&point.gradients).take(v.len()) {
        *g_a = f_inv_t * embed(reference);
    }
    Ok(PointState { f, det_f, g })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::corners;
    use crate::material::PolynomialN1;
    use crate::mesh::SolidMesh;
    use crate::test_fixtures::{
        self as fixtures, affine, dense_tangent, distorted, in_plane, jitter, material, perturb,
    };
    use nalgebra::{DMatrix, DVector, Rotation3, SymmetricEigen, Vector3 as V3};

    const TECHNOLOGIES: [Technology; 3] = [
        Technology::Full,
        Technology::Hybrid,
        Technology::Incompatible,
    ];

    /// Homogeneous finite deformation gradient of 15-25 % strain (in-plane block in 2D).
    fn homogeneous_f<const D: usize>() -> Matrix3<f64> {
        in_plane::<D>(Matrix3::new(
            1.25, 0.18, -0.06, -0.1, 0.85, 0.12, 0.05, -0.07, 1.1,
        ))
    }

    /// A general large deformation: the homogeneous one plus a non-affine part.
    fn general_u<const D: usize>(x: &[SVector<f64, D>]) -> Vec<SVector<f64, D>> {
        fixtures::general_u(x, &homogeneous_f::<D>(), 0.1)
    }

    fn tangent<const D: usize>(
        element: &IntegratedSolid<D>,
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

    /// Central differences: force = d energy / du, tangent = d force / du,
    /// volume_ratio_gradient = d theta / du; returns the largest relative errors.
    fn fd_errors<const D: usize>(technology: Technology) -> Result<[f64; 3], FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = IntegratedSolid::new(technology, &x, 0.7)?;
        let u = general_u(&x);
        let (r, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
        assert!((r.volume_ratio - 1.0).abs() > 1e-2);
        assert_eq!(r.hourglass_energy, 0.0);
        assert_eq!(
            k,
            k.transpose(),
            "{technology:?} {D}D: not exactly symmetric"
        );
        assert_eq!(element.respond(&m, &u)?.force(), r.force());
        let h = 1e-6;
        let mut errors = [0.0_f64; 3];
        for dof in 0..D * element.node_count() {
            let plus = element.respond(&m, &perturb(&u, dof, h))?;
            let minus = element.respond(&m, &perturb(&u, dof, -h))?;
            let fd_column = (force(&plus) - force(&minus)) / (2.0 * h);
            errors[0] = errors[0].max((fd_column - k.column(dof)).amax() / k.amax());
            let fd_force = (plus.strain_energy - minus.strain_energy) / (2.0 * h);
            errors[1] = errors[1].max((fd_force - r.force()[dof]).abs() / force(&r).amax());
            let fd_theta = (plus.volume_ratio - minus.volume_ratio) / (2.0 * h);
            let gradient = DVector::from_column_slice(r.volume_ratio_gradient());
            errors[2] =
                errors[2].max((fd_theta - r.volume_ratio_gradient()[dof]).abs() / gradient.amax());
        }
        eprintln!(
            "{technology:?} {D}D: FD errors tangent/force/dtheta {:.1e} {:.1e} {:.1e}",
            errors[0], errors[1], errors[2]
        );
        Ok(errors)
    }

    #[test]
    fn force_tangent_and_volume_gradient_match_finite_differences() -> Result<(), FemError> {
        for technology in TECHNOLOGIES {
            for errors in [fd_errors::<2>(technology)?, fd_errors::<3>(technology)?] {
                assert!(
                    errors.iter().all(|e| *e < 1e-6),
                    "{technology:?}: {errors:?}"
                );
            }
        }
        Ok(())
    }

    /// Hybrid: the mixed tangent at `p = U'(theta)` is the consistent one, and at another
    /// pressure it adds `V0 (p - U'(theta)) d^2 theta / du^2`.
    fn check_hybrid_mixed_tangent<const D: usize>() -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = IntegratedSolid::new(Technology::Hybrid, &x, 0.7)?;
        let u = general_u(&x);
        let (r, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
        let pbar = m.volumetric_pressure(r.volume_ratio);
        let (same, k_same) = tangent(&element, &m, &u, Tangent::Mixed { pressure: pbar })?;
        assert_eq!(same.force(), r.force());
        assert!((&k_same - &k).amax() < 1e-13 * k.amax());
        let p_m = pbar - 4.0e6;
        let (_, k_m) = tangent(&element, &m, &u, Tangent::Mixed { pressure: p_m })?;
        assert_eq!(k_m, k_m.transpose());
        let h = 1e-6;
        for dof in 0..D * element.node_count() {
            let plus = element.respond(&m, &perturb(&u, dof, h))?;
            let minus = element.respond(&m, &perturb(&u, dof, -h))?;
            let hessian_column = (DVector::from_column_slice(plus.volume_ratio_gradient())
                - DVector::from_column_slice(minus.volume_ratio_gradient()))
                / (2.0 * h);
            let expected = k.column(dof) + hessian_column * (element.volume() * (p_m - pbar));
            let err = (expected - k_m.column(dof)).amax() / k.amax();
            assert!(err < 1e-7, "D = {D}, dof {dof}: mixed tangent error {err}");
        }
        // Full and Incompatible return the consistent tangent for a mixed request
        for technology in [Technology::Full, Technology::Incompatible] {
            let element = IntegratedSolid::new(technology, &x, 0.7)?;
            let (_, k) = tangent(&element, &m, &u, Tangent::Consistent)?;
            let (_, k_m) = tangent(&element, &m, &u, Tangent::Mixed { pressure: p_m })?;
            assert_eq!(k, k_m);
        }
        Ok(())
    }

    #[test]
    fn hybrid_mixed_tangent_substitutes_the_element_pressure() -> Result<(), FemError> {
        check_hybrid_mixed_tangent::<2>()?;
        check_hybrid_mixed_tangent::<3>()
    }

    /// Assembled force and stiffness of a mesh of elements at the nodal displacements `u`.
    fn assemble<const D: usize>(
        elements: &[IntegratedSolid<D>],
        connectivity: &[Vec<usize>],
        m: &dyn Hyperelastic,
        u: &[SVector<f64, D>],
    ) -> Result<(DVector<f64>, DMatrix<f64>), FemError> {
        let size = u.len() * D;
        let (mut force, mut stiffness) = (DVector::zeros(size), DMatrix::zeros(size, size));
        for (element, nodes) in elements.iter().zip(connectivity) {
            let u_e: Vec<_> = nodes.iter().map(|&id| u[id]).collect();
            let (r, k) = tangent(element, m, &u_e, Tangent::Consistent)?;
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
        Ok((force, stiffness))
    }

    /// Distorted 2 x 2 (x 2) patch: the affine displacement gives zero interior forces and the
    /// homogeneous stress in every element, and Newton on the interior node from a perturbed
    /// start returns to it.
    fn check_patch<const D: usize>(technology: Technology) -> Result<(), FemError> {
        let m = material()?;
        let mut mesh =
            SolidMesh::<D>::structured_block(SVector::zeros(), SVector::repeat(3.0), [2; D])?;
        let boundary: std::collections::BTreeSet<usize> =
            mesh.node_sets.values().flatten().copied().collect();
        for (id, x) in mesh.nodes.iter_mut().enumerate() {
            *x += SVector::from_fn(|k, _| 0.5 * jitter(7 * id + k));
        }
        mesh.validate()?;
        let elements = (mesh.elements.iter())
            .map(|e| {
                let x: Vec<_> = e.iter().map(|&id| mesh.nodes[id]).collect();
                IntegratedSolid::new(technology, &x, 1.0)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let f = homogeneous_f::<D>();
        let exact = affine(&f, &mesh.nodes);
        let free: Vec<usize> = (0..mesh.nodes.len() * D)
            .filter(|dof| !boundary.contains(&(dof / D)))
            .collect();
        assert_eq!(free.len(), D);
        let sigma = m.kirchhoff_stress(&f) / f.determinant();
        let (force, _) = assemble(&elements, &mesh.elements, &m, &exact)?;
        let scale = sigma.norm() * 3.0_f64.powi(D as i32 - 1);
        for &dof in &free {
            assert!(
                force[dof].abs() < 1e-12 * scale,
                "{technology:?} {D}D: {}",
                force[dof]
            );
        }
        for (element, nodes) in elements.iter().zip(&mesh.elements) {
            let u_e: Vec<_> = nodes.iter().map(|&id| exact[id]).collect();
            let r = element.respond(&m, &u_e)?;
            assert!((r.cauchy_stress - sigma).norm() < 1e-10 * sigma.norm());
            assert!((r.volume_ratio - f.determinant()).abs() < 1e-13);
        }
        let mut u = exact.clone();
        for &dof in &free {
            u[dof / D][dof % D] += 0.05 * jitter(dof + 999);
        }
        for _ in 0..20 {
            let (force, stiffness) = assemble(&elements, &mesh.elements, &m, &u)?;
            let residual = DVector::from_iterator(free.len(), free.iter().map(|&d| force[d]));
            if residual.amax() < 1e-12 * scale {
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
        for (ui, ei) in u.iter().zip(&exact) {
            assert!(
                (ui - ei).norm() < 1e-10,
                "{technology:?} {D}D: {ui} vs {ei}"
            );
        }
        Ok(())
    }

    #[test]
    fn distorted_patch_passes_the_constant_stress_patch_test() -> Result<(), FemError> {
        for technology in TECHNOLOGIES {
            check_patch::<2>(technology)?;
            check_patch::<3>(technology)?;
        }
        Ok(())
    }

    fn check_rigid_rotation<const D: usize>(rotation: Matrix3<f64>) -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let mu = m.initial_shear_modulus();
        for technology in TECHNOLOGIES {
            let element = IntegratedSolid::new(technology, &x, 1.0)?;
            let r = element.respond(&m, &affine(&rotation, &x))?;
            assert!((r.volume_ratio - 1.0).abs() < 1e-14);
            assert!(r.cauchy_stress.norm() < 1e-8 * mu, "{}", r.cauchy_stress);
            assert!(force(&r).amax() < 1e-8 * mu * element.volume());
            assert!(r.strain_energy.abs() < 1e-12 * mu * element.volume());
        }
        Ok(())
    }

    #[test]
    fn large_rigid_rotation_is_stress_and_force_free() -> Result<(), FemError> {
        let angle = 60f64.to_radians();
        check_rigid_rotation::<2>(*Rotation3::from_axis_angle(&V3::z_axis(), angle).matrix())?;
        let axis = nalgebra::Unit::new_normalize(V3::new(1.0, -2.0, 0.5));
        check_rigid_rotation::<3>(*Rotation3::from_axis_angle(&axis, angle).matrix())
    }

    fn zero_eigenvalues<const D: usize>(technology: Technology) -> Result<usize, FemError> {
        let m = material()?;
        let element = IntegratedSolid::new(technology, &distorted::<D>(), 1.0)?;
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
    fn reference_tangent_has_only_rigid_zero_modes() -> Result<(), FemError> {
        for technology in TECHNOLOGIES {
            assert_eq!(zero_eigenvalues::<2>(technology)?, 3, "{technology:?}");
            assert_eq!(zero_eigenvalues::<3>(technology)?, 6, "{technology:?}");
        }
        Ok(())
    }

    /// Linear pure bending of a strip `[0, 4] x [-h, h] (x [-w, w])` of 4 rectangular elements:
    /// end `x = 0` on rollers (`u_x = 0`, a minimal set of further supports), end `x = 4`
    /// loaded by the consistent nodal forces of `sigma_xx = s y / h`; `plane`: in 3D, `u_z = 0`
    /// everywhere (plane strain; always so in 2D). Returns the tip `u_x` at `y = h` over the
    /// beam solution `s L / E'` (`E' = E / (1 - nu^2)` in plane strain, `E` otherwise).
    fn bending_ratio<const D: usize>(
        technology: Technology,
        d1: f64,
        plane: bool,
    ) -> Result<f64, FemError> {
        let plane = plane || D == 2;
        let m = PolynomialN1::new(0.552e6, 0.138e6, d1)?;
        let (length, h, w) = (4.0, 0.5, 0.4);
        let size = SVector::<f64, D>::from_fn(|k, _| [length, 2.0 * h, 2.0 * w][k]);
        let origin = SVector::<f64, D>::from_fn(|k, _| [0.0, -h, -w][k]);
        let mut divisions = [1; D];
        divisions[0] = 4;
        let mesh = SolidMesh::<D>::structured_block(origin, size, divisions)?;
        let elements = (mesh.elements.iter())
            .map(|e| {
                let x: Vec<_> = e.iter().map(|&id| mesh.nodes[id]).collect();
                IntegratedSolid::new(technology, &x, 1.0)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let u = vec![SVector::zeros(); mesh.nodes.len()];
        let (_, k) = assemble(&elements, &mesh.elements, &m, &u)?;
        let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
        let depth = if D == 2 { 1.0 } else { 2.0 * w };
        let s = 1.0e3;
        let per_level = (1 << (D - 1)) as f64 / 2.0;
        let mut fixed = Vec::new();
        let mut load = DVector::zeros(mesh.nodes.len() * D);
        for (id, x) in mesh.nodes.iter().enumerate() {
            let lower_corner = (1..D).all(|k| near(x[k], origin[k]));
            if near(x[0], 0.0) {
                fixed.push(id * D);
                if lower_corner {
                    fixed.extend((1..D).map(|k| id * D + k));
                }
                if D == 3 && near(x[1], h) && near(x[2], w) {
                    fixed.push(id * D + 2);
                }
            }
            if D == 3 && plane && !fixed.contains(&(id * D + 2)) {
                fixed.push(id * D + 2);
            }
            if near(x[0], length) {
                load[id * D] = x[1].signum() * s * depth * h / 3.0 / per_level;
            }
        }
        let free: Vec<usize> = (0..load.len()).filter(|d| !fixed.contains(d)).collect();
        let k_ff = DMatrix::from_fn(free.len(), free.len(), |r, c| k[(free[r], free[c])]);
        let f_f = DVector::from_iterator(free.len(), free.iter().map(|&d| load[d]));
        let solution = k_ff
            .lu()
            .solve(&f_f)
            .ok_or(FemError::InvalidMesh("singular".into()))?;
        let (mu, kappa) = (m.initial_shear_modulus(), m.initial_bulk_modulus());
        let young = 9.0 * kappa * mu / (3.0 * kappa + mu);
        let poisson = (3.0 * kappa - 2.0 * mu) / (2.0 * (3.0 * kappa + mu));
        let modulus = if plane {
            young / (1.0 - poisson * poisson)
        } else {
            young
        };
        let exact = s * length / modulus;
        let tips: Vec<f64> = (free.iter().zip(solution.iter()))
            .filter(|(d, _)| {
                let x = mesh.nodes[**d / D];
                **d % D == 0 && near(x[0], length) && near(x[1], h)
            })
            .map(|(_, u)| u / exact)
            .collect();
        assert_eq!(tips.len(), 1 << (D - 2));
        Ok(tips.iter().sum::<f64>() / tips.len() as f64)
    }

    fn check_bending<const D: usize>() -> Result<(), FemError> {
        // K/mu = 10 (the benchmark) and K/mu = 1.4e5; in 3D also with free lateral faces
        for plane in [true, false].into_iter().take(D - 1) {
            for d1 in [0.145e-6, 1e-11] {
                let full = bending_ratio::<D>(Technology::Full, d1, plane)?;
                let hybrid = bending_ratio::<D>(Technology::Hybrid, d1, plane)?;
                let incompatible = bending_ratio::<D>(Technology::Incompatible, d1, plane)?;
                eprintln!(
                    "{D}D bending (plane strain {plane}), D1 = {d1:e}: tip / exact: Full \
                     {full:.3e}, Hybrid {hybrid:.4}, Incompatible {incompatible:.10}"
                );
                assert!((incompatible - 1.0).abs() < 1e-8, "{incompatible}");
                // parasitic shear
                assert!(full < 0.6, "{full}");
            }
        }
        // volumetric locking in plane strain: the displacement element all but freezes, the
        // hybrid one does not (it is soft: the mean dilatation misses the bending mode's
        // volumetric stiffness)
        let locked = bending_ratio::<D>(Technology::Full, 1e-11, true)?;
        let hybrid = bending_ratio::<D>(Technology::Hybrid, 1e-11, true)?;
        assert!(locked < 1e-3 && hybrid > 0.5, "{locked} vs {hybrid}");
        Ok(())
    }

    #[test]
    fn incompatible_modes_bend_exactly_and_hybrid_does_not_lock() -> Result<(), FemError> {
        check_bending::<2>()?;
        check_bending::<3>()
    }

    fn check_masses<const D: usize>() -> Result<(), FemError> {
        let rho = 7800.0;
        for technology in TECHNOLOGIES {
            let element = IntegratedSolid::<D>::new(technology, &distorted(), 0.3)?;
            let masses = element.lumped_node_masses(rho);
            let total: f64 = masses[..element.node_count()].iter().sum();
            assert!((total - rho * element.volume()).abs() < 1e-12 * total);
            assert!(masses[..element.node_count()].iter().all(|m| *m > 0.0));
            assert!(masses[element.node_count()..].iter().all(|m| *m == 0.0));
        }
        let brick: Vec<SVector<f64, D>> = corners::<D>().iter().map(|c| c * 0.5).collect();
        let element = IntegratedSolid::<D>::new(Technology::Full, &brick, 0.5)?;
        let expected = if D == 2 { 0.5 } else { 1.0 };
        assert!((element.volume() - expected).abs() < 1e-14);
        for m in &element.lumped_node_masses(rho)[..element.node_count()] {
            assert!((m - rho * expected / element.node_count() as f64).abs() < 1e-9);
        }
        Ok(())
    }

    #[test]
    fn lumped_masses_sum_to_the_element_mass() -> Result<(), FemError> {
        check_masses::<2>()?;
        check_masses::<3>()
    }

    /// Local Newton iterations of the incompatible modes on the distorted element at the
    /// general (about 20 %) deformation, and the mode residual left.
    fn local_iterations<const D: usize>(scale: f64) -> Result<usize, FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let element = IntegratedSolid::new(Technology::Incompatible, &x, 1.0)?;
        let u: Vec<_> = general_u(&x).iter().map(|u| u * scale).collect();
        let mut v = [SVector::zeros(); MAX_GRADIENTS];
        v[..u.len()].copy_from_slice(&u);
        let iterations = element.solve_modes(&m, &mut v)?;
        let system = element.mode_system(&m, &v[..u.len() + D])?;
        eprintln!(
            "{D}D Incompatible, displacement scale {scale}: {iterations} local iterations, \
             residual {:.1e} of scale {:.1e}",
            system.norm, system.scale
        );
        assert!(system.norm <= 1e-11 * system.scale);
        Ok(iterations)
    }

    #[test]
    fn incompatible_modes_converge_in_few_local_iterations() -> Result<(), FemError> {
        for scale in [0.0, 0.01, 1.0, 1.5] {
            assert!(local_iterations::<2>(scale)? <= 6);
            assert!(local_iterations::<3>(scale)? <= 6);
        }
        assert_eq!(local_iterations::<3>(0.0)?, 0);
        Ok(())
    }

    fn check_inversion<const D: usize>() -> Result<(), FemError> {
        let m = material()?;
        let x = distorted::<D>();
        let mut flip = Matrix3::identity();
        flip[(D - 1, D - 1)] = -0.5;
        let u = affine(&flip, &x);
        for technology in TECHNOLOGIES {
            let element = IntegratedSolid::new(technology, &x, 1.0)?;
            assert!(matches!(
                element.respond(&m, &u),
                Err(FemError::InvertedElement { det_f, .. }) if det_f < 0.0
            ));
            let n = D * element.node_count();
            let mut short = vec![0.0; n * n - 1];
            assert!(matches!(
                element.respond_with_tangent(&m, &u, Tangent::Consistent, &mut short),
                Err(FemError::LengthMismatch { .. })
            ));
            let mut nan = vec![SVector::zeros(); element.node_count()];
            nan[1][0] = f64::NAN;
            assert!(matches!(
                element.respond(&m, &nan),
                Err(FemError::NonFinite { .. })
            ));
        }
        let mut clockwise = x.clone();
        clockwise.swap(1, 3);
        assert!(matches!(
            IntegratedSolid::new(Technology::Full, &clockwise, 1.0),
            Err(FemError::DegenerateElement { .. })
        ));
        Ok(())
    }

    #[test]
    fn local_solve_failure_names_residual_and_iterations() {
        let message = FemError::IncompatibleModesNotConverged {
            residual: 2.5e-3,
            iterations: 25,
        }
        .to_string();
        assert!(
            message.contains("incompatible modes")
                && message.contains("2.500e-3")
                && message.contains("25"),
            "{message}"
        );
    }

    #[test]
    fn inverted_elements_and_bad_inputs_are_errors() -> Result<(), FemError> {
        check_inversion::<2>()?;
        check_inversion::<3>()?;
        assert!(matches!(
            IntegratedSolid::<2>::new(Technology::Hybrid, &distorted(), 0.0),
            Err(FemError::InvalidParameter {
                name: "thickness",
                ..
            })
        ));
        Ok(())
    }
}
