//! Hyperelastic constitutive laws in spatial (Kirchhoff-stress) form.
//!
//! All laws are written once in 3D; plane strain simply passes a deformation gradient with
//! `F33 = 1` and vanishing out-of-plane shear components.

use nalgebra::{Matrix3, Matrix6, SMatrix, Vector6};

use crate::error::FemError;

/// Voigt order of the symmetric index pairs: `[11, 22, 33, 12, 23, 13]` (zero-based).
pub const VOIGT_PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// Position `VOIGT_INDEX[i][j]` of the symmetric index pair `(i, j)` in [`VOIGT_PAIRS`].
pub const VOIGT_INDEX: [[usize; 3]; 3] = [[0, 3, 5], [3, 1, 4], [5, 4, 2]];

/// A hyperelastic material described by its strain energy per unit reference volume `W(F)`.
pub trait Hyperelastic: Send + Sync + std::fmt::Debug {
    /// Strain energy per unit reference volume W(F).
    fn strain_energy(&self, f: &Matrix3<f64>) -> f64;
    /// Kirchhoff stress tau = J sigma.
    fn kirchhoff_stress(&self, f: &Matrix3<f64>) -> Matrix3<f64>;
    /// tau and the spatial tangent c^tau such that the Lie (Truesdell-type) derivative of tau
    /// satisfies L_v tau = c^tau : d, d = sym(grad_x v).
    fn stress_and_tangent(&self, f: &Matrix3<f64>) -> (Matrix3<f64>, SpatialTangent);
    /// Initial shear modulus mu0 (used to scale hourglass stabilisation).
    fn initial_shear_modulus(&self) -> f64;
    /// Initial bulk modulus K0.
    fn initial_bulk_modulus(&self) -> f64;
    /// Pressure `p = U'(J)` of the volumetric energy `U(J)` of a law whose Kirchhoff stress
    /// splits as `tau = tau_iso + J p I`.
    fn volumetric_pressure(&self, j: f64) -> f64;
    /// `U''(J)`, the derivative of [`Self::volumetric_pressure`].
    fn volumetric_stiffness(&self, j: f64) -> f64;
    /// The volumetric energy `U(J)` per unit reference volume, with `U(1) = 0`: the part of
    /// [`Self::strain_energy`] whose derivative is [`Self::volumetric_pressure`], so that
    /// `W_iso(F) = W(F) - U(det F)` depends on the isochoric deformation only.
    fn volumetric_energy(&self, j: f64) -> f64;

    /// The stress-dependent terms of the tangent with a given pressure `p_m` in place of
    /// `p = U'(J)`: returns `tau_m = tau + J (p_m - p) I` (for the geometric stiffness) and
    /// `c_m = c^tau + J (p_m - p) (I (x) I - 2 II)`.
    ///
    /// This is the tangent of the one-point mixed (u-p, Q1/P0) formulation after the
    /// element-constant pressure is condensed out: its volumetric part is
    /// `J (p_m + J U'') I (x) I - 2 J p_m II`, the displacement formulation's with `p` replaced by
    /// the mixed pressure. Both agree when `p_m = U'(J)`.
    fn mixed_stress_and_tangent(
        &self,
        f: &Matrix3<f64>,
        pressure: f64,
    ) -> (Matrix3<f64>, SpatialTangent) {
        let (tau, c) = self.stress_and_tangent(f);
        let j = f.determinant();
        let shift = j * (pressure - self.volumetric_pressure(j));
        let identity = Matrix3::identity();
        let correction = dyad(&identity, &identity) - symmetric_product(&identity) * 2.0;
        (
            tau + identity * shift,
            SpatialTangent(c.0 + correction * shift),
        )
    }
}

/// Fourth-order spatial tangent with major and minor symmetry, stored in Voigt form, order
/// [11, 22, 33, 12, 23, 13] (tensor components, no factors of 2: `self.0[(I, J)] = c_ijkl`).
#[derive(Clone, Debug)]
pub struct SpatialTangent(pub SMatrix<f64, 6, 6>);

impl SpatialTangent {
    /// Tensor component `c_ijkl` (zero-based indices).
    ///
    /// # Panics
    /// If any index exceeds 2 (a programming error, like out-of-bounds indexing).
    pub fn get(&self, i: usize, j: usize, k: usize, l: usize) -> f64 {
        self.0[(VOIGT_INDEX[i][j], VOIGT_INDEX[k][l])]
    }

    /// Double contraction `(c : a)_ij = c_ijkl a_kl`; by minor symmetry only `sym(a)` enters.
    pub fn contract(&self, a: &Matrix3<f64>) -> Matrix3<f64> {
        let sym = a.symmetric_part();
        let engineering = Vector6::from_fn(|r, _| {
            let (i, j) = VOIGT_PAIRS[r];
            if i == j {
                sym[(i, j)]
            } else {
                2.0 * sym[(i, j)]
            }
        });
        let result = self.0 * engineering;
        Matrix3::from_fn(|i, j| result[VOIGT_INDEX[i][j]])
    }
}

/// Voigt vector of the (assumed symmetric) second-order tensor `a`.
fn voigt(a: &Matrix3<f64>) -> Vector6<f64> {
    Vector6::from_fn(|r, _| a[VOIGT_PAIRS[r]])
}

/// Dyadic product `(a (x) b)_ijkl = a_ij b_kl` of symmetric tensors, in Voigt form.
fn dyad(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix6<f64> {
    voigt(a) * voigt(b).transpose()
}

/// Symmetrised product `(II_a)_ijkl = (a_ik a_jl + a_il a_jk) / 2`, in Voigt form.
/// With `a = I` this is the fourth-order symmetric identity `II`.
fn symmetric_product(a: &Matrix3<f64>) -> Matrix6<f64> {
    Matrix6::from_fn(|r, c| {
        let (i, j) = VOIGT_PAIRS[r];
        let (k, l) = VOIGT_PAIRS[c];
        0.5 * (a[(i, k)] * a[(j, l)] + a[(i, l)] * a[(j, k)])
    })
}

/// `P : c : P` with the deviatoric projector `P = II - (1/3) I (x) I`, for a tangent `c` with
/// minor symmetry: `P : c : P = c - (1/3)(c:I)(x)I - (1/3) I(x)(I:c) + (1/9)(I:c:I) I(x)I`.
fn project_deviatoric(c: &Matrix6<f64>) -> Matrix6<f64> {
    let m = voigt(&Matrix3::identity());
    let c_m = c * m;
    let m_c = m.transpose() * c;
    let m_c_m = (m.transpose() * c_m)[0];
    c - (c_m * m.transpose()) / 3.0 - (m * m_c) / 3.0 + (m * m.transpose()) * (m_c_m / 9.0)
}

/// Deviatoric part `dev(a) = a - (tr a / 3) I`.
fn deviator(a: &Matrix3<f64>) -> Matrix3<f64> {
    a - Matrix3::identity() * (a.trace() / 3.0)
}

/// Polynomial hyperelastic law of order N = 1 (Mooney-Rivlin deviatoric part, Abaqus volumetric
/// term):
///
/// `U = C10 (I1bar - 3) + C01 (I2bar - 3) + (J - 1)^2 / D1`,
///
/// with `J = det F`, `b = F F^T`, `bbar = J^(-2/3) b`, `I1bar = tr bbar`,
/// `I2bar = ((tr bbar)^2 - tr(bbar^2)) / 2`.
#[derive(Clone, Debug)]
pub struct PolynomialN1 {
    c10: f64,
    c01: f64,
    d1: f64,
}

/// Isochoric kinematic quantities of a deformation gradient.
struct Isochoric {
    /// `J = det F`.
    j: f64,
    /// `bbar = J^(-2/3) F F^T`.
    bbar: Matrix3<f64>,
    /// `bbar^2`.
    bbar_sq: Matrix3<f64>,
    /// `I1bar = tr bbar`.
    i1: f64,
}

impl Isochoric {
    /// Kinematics of `F`; a non-positive `det F` yields NaN entries.
    fn new(f: &Matrix3<f64>) -> Self {
        let j = f.determinant();
        let bbar = (f * f.transpose()) * j.powf(-2.0 / 3.0);
        let bbar_sq = bbar * bbar;
        Self {
            j,
            i1: bbar.trace(),
            bbar,
            bbar_sq,
        }
    }

    /// `I2bar = ((tr bbar)^2 - tr(bbar^2)) / 2`.
    fn i2(&self) -> f64 {
        0.5 * (self.i1 * self.i1 - self.bbar_sq.trace())
    }
}

impl PolynomialN1 {
    /// Creates the law; requires finite constants with `C10 >= 0`, `C01 >= 0`,
    /// `C10 + C01 > 0` and `D1 > 0`.
    ///
    /// # Errors
    /// [`FemError::InvalidMaterial`] naming the offending constant.
    pub fn new(c10: f64, c01: f64, d1: f64) -> Result<Self, FemError> {
        let invalid = |field, value, expected| {
            Err(FemError::InvalidMaterial {
                field,
                value,
                expected,
            })
        };
        for (field, value) in [("C10", c10), ("C01", c01), ("D1", d1)] {
            if !value.is_finite() {
                return invalid(field, value, "a finite number");
            }
        }
        if c10 < 0.0 {
            return invalid("C10", c10, ">= 0");
        }
        if c01 < 0.0 {
            return invalid("C01", c01, ">= 0");
        }
        if c10 + c01 <= 0.0 {
            return invalid("C10 + C01", c10 + c01, "> 0");
        }
        if d1 <= 0.0 {
            return invalid("D1", d1, "> 0");
        }
        Ok(Self { c10, c01, d1 })
    }

    /// Deviatoric constant C10 (Pa).
    pub fn c10(&self) -> f64 {
        self.c10
    }

    /// Deviatoric constant C01 (Pa).
    pub fn c01(&self) -> f64 {
        self.c01
    }

    /// Compressibility D1 (1/Pa).
    pub fn d1(&self) -> f64 {
        self.d1
    }

    /// Fictitious Kirchhoff stress `tau_bar = 2 bbar dU/dbbar
    /// = 2 (C10 + C01 I1bar) bbar - 2 C01 bbar^2`.
    fn fictitious_stress(&self, k: &Isochoric) -> Matrix3<f64> {
        k.bbar * (2.0 * (self.c10 + self.c01 * k.i1)) - k.bbar_sq * (2.0 * self.c01)
    }

    /// Volumetric pressure `p = dU/dJ = 2 (J - 1) / D1`.
    fn pressure(&self, j: f64) -> f64 {
        2.0 * (j - 1.0) / self.d1
    }
}

impl Hyperelastic for PolynomialN1 {
    /// `W = C10 (I1bar - 3) + C01 (I2bar - 3) + (J - 1)^2 / D1` (NaN if `det F <= 0`).
    fn strain_energy(&self, f: &Matrix3<f64>) -> f64 {
        let k = Isochoric::new(f);
        self.c10 * (k.i1 - 3.0) + self.c01 * (k.i2() - 3.0) + (k.j - 1.0).powi(2) / self.d1
    }

    /// `tau = dev(tau_bar) + J p I` with `tau_bar = 2 (C10 + C01 I1bar) bbar - 2 C01 bbar^2`
    /// and `p = 2 (J - 1) / D1` (NaN if `det F <= 0`).
    fn kirchhoff_stress(&self, f: &Matrix3<f64>) -> Matrix3<f64> {
        let k = Isochoric::new(f);
        deviator(&self.fictitious_stress(&k)) + Matrix3::identity() * (k.j * self.pressure(k.j))
    }

    /// Kirchhoff stress (see [`Self::kirchhoff_stress`]) and the tangent
    ///
    /// `c^tau = P:cbar:P + (2/3) tr(tau_bar) P - (2/3) (tau_iso (x) I + I (x) tau_iso)
    ///          + J (p + J p') I (x) I - 2 J p II`,
    ///
    /// with `cbar = 4 C01 (bbar (x) bbar - II_bbar)`, `(II_a)_ijkl = (a_ik a_jl + a_il a_jk)/2`,
    /// `P = II - (1/3) I (x) I`, `tau_iso = dev(tau_bar)`, `p' = 2 / D1`.
    fn stress_and_tangent(&self, f: &Matrix3<f64>) -> (Matrix3<f64>, SpatialTangent) {
        let k = Isochoric::new(f);
        let identity = Matrix3::identity();
        let tau_bar = self.fictitious_stress(&k);
        let tau_iso = deviator(&tau_bar);
        let p = self.pressure(k.j);
        let dp_dj = 2.0 / self.d1;
        let tau = tau_iso + identity * (k.j * p);

        let ii = symmetric_product(&identity);
        let i_i = dyad(&identity, &identity);
        let projector = ii - i_i / 3.0;
        let c_bar = (dyad(&k.bbar, &k.bbar) - symmetric_product(&k.bbar)) * (4.0 * self.c01);
        let c_iso = project_deviatoric(&c_bar) + projector * (2.0 / 3.0 * tau_bar.trace())
            - (dyad(&tau_iso, &identity) + dyad(&identity, &tau_iso)) * (2.0 / 3.0);
        let c_vol = i_i * (k.j * (p + k.j * dp_dj)) - ii * (2.0 * k.j * p);
        (tau, SpatialTangent(c_iso + c_vol))
    }

    /// `mu0 = 2 (C10 + C01)`.
    fn initial_shear_modulus(&self) -> f64 {
        2.0 * (self.c10 + self.c01)
    }

    /// `K0 = 2 / D1`.
    fn initial_bulk_modulus(&self) -> f64 {
        2.0 / self.d1
    }

    /// `p = U'(J) = 2 (J - 1) / D1`.
    fn volumetric_pressure(&self, j: f64) -> f64 {
        self.pressure(j)
    }

    /// `U''(J) = 2 / D1`.
    fn volumetric_stiffness(&self, _j: f64) -> f64 {
        2.0 / self.d1
    }

    /// `U(J) = (J - 1)^2 / D1`.
    fn volumetric_energy(&self, j: f64) -> f64 {
        (j - 1.0).powi(2) / self.d1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const C10: f64 = 0.552e6;
    const C01: f64 = 0.138e6;
    const D1: f64 = 0.145e-6;

    fn benchmark() -> Result<PolynomialN1, FemError> {
        PolynomialN1::new(C10, C01, D1)
    }

    /// A general non-symmetric deformation gradient with `J != 1`.
    fn general_f() -> Matrix3<f64> {
        Matrix3::new(1.1, 0.2, -0.1, 0.05, 0.93, 0.15, -0.08, 0.12, 1.12)
    }

    fn unit(i: usize, j: usize) -> Matrix3<f64> {
        Matrix3::from_fn(|r, c| if (r, c) == (i, j) { 1.0 } else { 0.0 })
    }

    fn relative_error(a: &Matrix3<f64>, b: &Matrix3<f64>, scale: f64) -> f64 {
        (a - b).norm() / scale
    }

    #[test]
    fn voigt_index_inverts_the_voigt_pairs() {
        for (r, &(i, j)) in VOIGT_PAIRS.iter().enumerate() {
            assert_eq!((VOIGT_INDEX[i][j], VOIGT_INDEX[j][i]), (r, r));
        }
    }

    #[test]
    fn kirchhoff_stress_is_energy_derivative() -> Result<(), FemError> {
        let m = benchmark()?;
        let f = general_f();
        assert!(
            (f.determinant() - 1.0).abs() > 0.05,
            "J = {}",
            f.determinant()
        );
        let h = 1e-6;
        let dw_df = Matrix3::from_fn(|i, j| {
            let df = unit(i, j) * h;
            (m.strain_energy(&(f + df)) - m.strain_energy(&(f - df))) / (2.0 * h)
        });
        let tau = m.kirchhoff_stress(&f);
        let tau_fd = dw_df * f.transpose();
        assert!(
            relative_error(&tau, &tau_fd, tau.norm()) < 1e-6,
            "{tau} vs {tau_fd}"
        );
        let (tau2, _) = m.stress_and_tangent(&f);
        assert!(relative_error(&tau, &tau2, tau.norm()) < 1e-14);
        Ok(())
    }

    #[test]
    fn tangent_matches_lie_derivative_of_stress() -> Result<(), FemError> {
        for m in [benchmark()?, PolynomialN1::new(0.3e6, 0.9e6, 2e-6)?] {
            for f in [
                general_f(),
                general_f().transpose() * 0.9,
                Matrix3::identity(),
            ] {
                let (tau, c) = m.stress_and_tangent(&f);
                let scale = c.0.norm();
                let h = 1e-6;
                for i in 0..3 {
                    for j in 0..3 {
                        let g = unit(i, j) + unit(j, (i + 1) % 3) * 0.3;
                        let plus = m.kirchhoff_stress(&((Matrix3::identity() + g * h) * f));
                        let minus = m.kirchhoff_stress(&((Matrix3::identity() - g * h) * f));
                        let fd = (plus - minus) / (2.0 * h);
                        let analytic = c.contract(&g) + g * tau + tau * g.transpose();
                        let err = relative_error(&fd, &analytic, scale);
                        assert!(err < 1e-6, "G = {g}: {fd} vs {analytic} (err {err})");
                    }
                }
            }
        }
        Ok(())
    }

    /// The mixed tangent is the Lie derivative of `tau_iso(F) + J(F) p_m I` at fixed `p_m`, plus
    /// the condensed volumetric stiffness `J^2 U'' I (x) I`; at `p_m = U'(J)` it is the
    /// consistent tangent.
    #[test]
    fn mixed_tangent_is_the_derivative_at_fixed_pressure() -> Result<(), FemError> {
        let m = benchmark()?;
        let f = general_f();
        let j = f.determinant();
        let (tau, c) = m.stress_and_tangent(&f);
        let (tau_m, c_m) = m.mixed_stress_and_tangent(&f, m.volumetric_pressure(j));
        assert!((tau_m - tau).norm() < 1e-12 * tau.norm());
        assert!((c_m.0 - c.0).norm() < 1e-12 * c.0.norm());
        let p_m = -3.0e6;
        let stress_at_fixed_pressure = |f: &Matrix3<f64>| {
            let j = f.determinant();
            m.kirchhoff_stress(f) + Matrix3::identity() * (j * (p_m - m.volumetric_pressure(j)))
        };
        let (tau_m, c_m) = m.mixed_stress_and_tangent(&f, p_m);
        assert!((stress_at_fixed_pressure(&f) - tau_m).norm() < 1e-9 * tau_m.norm());
        let identity = Matrix3::identity();
        let condensed = dyad(&identity, &identity) * (j * j * m.volumetric_stiffness(j));
        let h = 1e-6;
        for i in 0..3 {
            for k in 0..3 {
                let g = unit(i, k) + unit(k, (i + 2) % 3) * 0.4;
                let plus = stress_at_fixed_pressure(&((identity + g * h) * f));
                let minus = stress_at_fixed_pressure(&((identity - g * h) * f));
                let fd = (plus - minus) / (2.0 * h);
                let analytic = SpatialTangent(c_m.0 - condensed).contract(&g)
                    + g * tau_m
                    + tau_m * g.transpose();
                let err = relative_error(&fd, &analytic, c_m.0.norm());
                assert!(err < 1e-6, "G = {g}: {fd} vs {analytic} (err {err})");
            }
        }
        Ok(())
    }

    /// `U` is the volumetric part of `W` (`W - U` is unchanged by a dilatation) and `U' = p`.
    #[test]
    fn volumetric_energy_is_the_volumetric_part_of_the_strain_energy() -> Result<(), FemError> {
        let m = benchmark()?;
        let f = general_f();
        let iso = |f: &Matrix3<f64>| m.strain_energy(f) - m.volumetric_energy(f.determinant());
        assert!((iso(&(f * 1.07)) - iso(&f)).abs() < 1e-9 * C10);
        assert_eq!(m.volumetric_energy(1.0), 0.0);
        let (j, h) = (1.03, 1e-6);
        let fd = (m.volumetric_energy(j + h) - m.volumetric_energy(j - h)) / (2.0 * h);
        assert!((fd - m.volumetric_pressure(j)).abs() < 1e-7 * m.volumetric_pressure(j));
        Ok(())
    }

    #[test]
    fn tangent_has_major_and_minor_symmetry() -> Result<(), FemError> {
        let (_, c) = benchmark()?.stress_and_tangent(&general_f());
        assert!((c.0 - c.0.transpose()).norm() < 1e-12 * c.0.norm());
        assert_eq!(c.get(0, 1, 2, 1), c.get(1, 0, 1, 2));
        assert_eq!(c.get(0, 1, 2, 1), c.get(1, 2, 0, 1));
        Ok(())
    }

    #[test]
    fn simple_shear_matches_mooney_rivlin() -> Result<(), FemError> {
        let m = benchmark()?;
        for gamma in [0.05, 0.3, 0.6, 1.0] {
            let f = Matrix3::identity() + unit(0, 1) * gamma;
            let sigma = m.kirchhoff_stress(&f) / f.determinant();
            let tol = 1e-9 * m.initial_shear_modulus();
            let g2 = gamma * gamma;
            assert!((sigma[(0, 1)] - 2.0 * (C10 + C01) * gamma).abs() < tol);
            assert!((sigma[(0, 0)] - sigma[(1, 1)] - 2.0 * (C10 + C01) * g2).abs() < tol);
            assert!((sigma[(1, 1)] - sigma[(2, 2)] + 2.0 * C01 * g2).abs() < tol);
            assert!(sigma[(0, 2)].abs() < tol && sigma[(1, 2)].abs() < tol);
        }
        Ok(())
    }

    #[test]
    fn nearly_incompressible_uniaxial_tension_matches_mooney_rivlin() -> Result<(), FemError> {
        // K0 / mu0 = (2 / D1) / 1.38e6 ~ 1.4e8.
        let m = PolynomialN1::new(C10, C01, 1e-14)?;
        let lateral_stress = |lambda: f64, s: f64| {
            let f = Matrix3::from_diagonal(&nalgebra::Vector3::new(lambda, s, s));
            m.kirchhoff_stress(&f) / f.determinant()
        };
        for lambda in [0.7_f64, 0.8, 0.9, 0.95, 1.1, 1.25, 1.5] {
            // Bisection on the lateral stretch s: sigma22 increases with s.
            let guess = 1.0 / lambda.sqrt();
            let (mut lo, mut hi) = (0.99 * guess, 1.01 * guess);
            assert!(lateral_stress(lambda, lo)[(1, 1)] < 0.0);
            assert!(lateral_stress(lambda, hi)[(1, 1)] > 0.0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if lateral_stress(lambda, mid)[(1, 1)] > 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let sigma = lateral_stress(lambda, 0.5 * (lo + hi));
            let exact = 2.0 * (lambda * lambda - 1.0 / lambda) * (C10 + C01 / lambda);
            let err = (sigma[(0, 0)] - exact).abs() / exact.abs();
            assert!(err < 1e-5, "lambda {lambda}: {} vs {exact}", sigma[(0, 0)]);
        }
        Ok(())
    }

    #[test]
    fn reference_state_is_stress_free_with_linear_moduli() -> Result<(), FemError> {
        let m = benchmark()?;
        let (tau, c) = m.stress_and_tangent(&Matrix3::identity());
        assert!(tau.norm() < 1e-9 * C10);
        assert!(m.strain_energy(&Matrix3::identity()).abs() < 1e-9 * C10);
        let mu = 2.0 * (C10 + C01);
        let kappa = 2.0 / D1;
        assert!((m.initial_shear_modulus() - mu).abs() < 1e-9 * mu);
        assert!((m.initial_bulk_modulus() - kappa).abs() < 1e-9 * kappa);
        // c = K I(x)I + 2 mu (II - I(x)I / 3).
        for (i, j, k, l) in [(0, 1, 0, 1), (1, 2, 1, 2), (0, 2, 2, 0)] {
            assert!((c.get(i, j, k, l) - mu).abs() < 1e-9 * mu);
        }
        let bulk: f64 = (0..3)
            .flat_map(|i| (0..3).map(move |k| (i, k)))
            .map(|(i, k)| c.get(i, i, k, k))
            .sum::<f64>()
            / 9.0;
        assert!((bulk - kappa).abs() < 1e-9 * kappa);
        assert!((c.get(0, 0, 0, 0) - (kappa + 4.0 / 3.0 * mu)).abs() < 1e-9 * kappa);
        assert!((c.get(0, 0, 1, 1) - (kappa - 2.0 / 3.0 * mu)).abs() < 1e-9 * kappa);
        assert!(c.get(0, 0, 0, 1).abs() < 1e-9 * kappa);
        Ok(())
    }

    #[test]
    fn invalid_constants_are_rejected() {
        for (c10, c01, d1, name) in [
            (-1.0, 1.0, 1e-6, "C10"),
            (1.0, -1.0, 1e-6, "C01"),
            (0.0, 0.0, 1e-6, "C10 + C01"),
            (1.0, 1.0, 0.0, "D1"),
            (1.0, 1.0, -1e-6, "D1"),
            (f64::NAN, 1.0, 1e-6, "C10"),
            (1.0, f64::INFINITY, 1e-6, "C01"),
        ] {
            match PolynomialN1::new(c10, c01, d1) {
                Err(FemError::InvalidMaterial { field, .. }) => assert_eq!(field, name),
                other => panic!("expected InvalidMaterial for {name}, got {other:?}"),
            }
        }
    }
}
