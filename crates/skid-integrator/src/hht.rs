//! HHT-alpha time integration (Hilber, Hughes & Taylor 1977), Abaqus sign convention, with
//! the contact forces integrated as impulses.
//!
//! With `alpha` in [-1/3, 0], `beta = (1 - alpha)^2 / 4` and `gamma = 1/2 - alpha`, the smooth
//! forces obey the HHT equation
//!
//! `M a_{n+1} + (1 + alpha) F(x_{n+1}) - alpha F(x_n) = 0`,  `F = f_int - f_ext`,
//!
//! where `a` is the *smooth* acceleration: it never contains a contact force. The contact
//! forces act through their mean value `p` over the increment, an impulse `h p` that changes the
//! velocity at the end of the increment and moves the positions by the trapezoidal rule
//! (half the velocity jump over the increment):
//!
//! `x_{n+1} = x_n + h v_n + h^2 [(1/2 - beta) a_n + beta a_{n+1}] + (h^2/2) M^{-1} H^T p`,
//! `v_{n+1} = v_n + h [(1 - gamma) a_n + gamma a_{n+1}] + h M^{-1} H^T p`.
//!
//! Eliminating `a_{n+1}` gives the increment's equation in the unknown positions,
//!
//! `M (x_{n+1} - x_n - h v_n - h^2 (1/2 - beta) a_n) / (beta h^2) + (1 + alpha) F(x_{n+1})
//!  - alpha F(x_n) - H^T r = 0`,  with `r = p / (2 beta)`,
//!
//! which is the plain HHT equation with `r` in the place of the contact force. The friction cone
//! is invariant under positive scaling, so the exact Coulomb law in `r` is the law in `p`.
//!
//! Why impulses: with the contact force inside `a_n` (plain HHT), the force of a contact that
//! opens during an increment keeps acting through `a_n` and does work `p_n dg / 2 > 0` on the
//! separating pad. Friction chatter (contacts opening and closing every few increments) then
//! pumps energy into the pad faster than light numerical damping removes it. With impulses a
//! contact never acts once it is open, and because the impulse moves the positions by half its
//! velocity jump, its work on the kinetic energy is exactly `p . H dx`: the normal part
//! `p_N dg <= 0` (a closing contact can only absorb energy), the tangential part the frictional
//! dissipation `-p_T . ds >= 0`. `H_N dx = dg` needs the normal row to be a discrete gradient of
//! the gap over the increment on a curved surface (see `crate::contact_rows::contact_rows`): along
//! the end-of-increment normal a loaded node sliding `ds` along a drum of radius R gains
//! `p_N ds^2 / (2 R)` per increment. Smooth forces keep the second-order accuracy and
//! unconditional linear stability of HHT, whose spectral radius at infinite frequency is
//! `(1 + alpha)/(1 - alpha)`; a node resting in contact keeps a zero velocity.

use nalgebra::DVector;

/// HHT parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hht {
    /// Numerical dissipation parameter, in [-1/3, 0].
    pub alpha: f64,
    /// Newmark beta = (1 - alpha)^2 / 4.
    pub beta: f64,
    /// Newmark gamma = 1/2 - alpha.
    pub gamma: f64,
}

impl Hht {
    /// Parameters for a given `alpha`.
    ///
    /// # Errors
    /// A message if `alpha` is outside [-1/3, 0].
    pub fn new(alpha: f64) -> Result<Self, String> {
        if !(alpha.is_finite() && (-1.0 / 3.0 - 1e-12..=0.0).contains(&alpha)) {
            return Err(format!("expected HHT alpha in [-1/3, 0], got {alpha}"));
        }
        Ok(Self {
            alpha,
            beta: (1.0 - alpha).powi(2) / 4.0,
            gamma: 0.5 - alpha,
        })
    }

    /// Spectral radius at infinite frequency, `(1 + alpha)/(1 - alpha)`.
    pub fn spectral_radius_at_infinity(&self) -> f64 {
        (1.0 + self.alpha) / (1.0 - self.alpha)
    }

    /// Factor of the mass matrix in the effective tangent, `da_{n+1}/dx_{n+1} = 1/(beta h^2)`.
    pub fn mass_factor(&self, h: f64) -> f64 {
        1.0 / (self.beta * h * h)
    }

    /// Predictor, Newton's first iterate: `x_{n+1} = x_n + h v_n` (constant velocity).
    ///
    /// The stored acceleration is the smooth one, without the contact forces (see
    /// [`crate::increment`]); for a node held by contact it is the whole unbalanced elastic and
    /// pressure force over the nodal mass, far from its true acceleration. Extrapolating it
    /// (`+ h^2/2 a_n`) pushed loaded nodes into the drum by up to centimetres at millisecond
    /// steps, which cost iterations and cutbacks and could carry an iterate over a drum's rim
    /// onto another branch of the contact problem.
    pub fn predict(&self, h: f64, x: &DVector<f64>, v: &DVector<f64>) -> DVector<f64> {
        x + v * h
    }

    /// Factor `2 beta` that turns the increment's contact unknown `r` into the mean contact
    /// force `p` over the increment.
    pub fn impulse_force_factor(&self) -> f64 {
        2.0 * self.beta
    }

    /// Factor `1/(2 beta)` on the force rows of equations without inertia, so that the contact
    /// unknown `r` balances them as the mean force `p = 2 beta r` (see [`crate::increment`]).
    pub fn quasi_static_factor(&self) -> f64 {
        1.0 / self.impulse_force_factor()
    }

    /// Energy the scheme itself removes over one converged increment (J; positive when lost):
    /// what the work of the forces, the smooth ones by the trapezoidal rule and the contact
    /// impulse exactly (`dx . H^T p`), exceeds the kinetic energy change by, written with
    /// physical forces and Newmark kinematics only.
    ///
    /// With `dx = x_{n+1} - x_n`, `da = a_{n+1} - a_n`, `abar = (a_n + a_{n+1})/2`, the smooth
    /// force `F = f_int - f_ext` at both ends and `c = H^T p`, the Newmark relations give
    /// `h (v_n + v_{n+1})/2 = dx - h^2 (alpha^2/4) da` and
    /// `M (v_{n+1} - v_n)/h = M abar - alpha M da + c` exactly. With the HHT equations of this
    /// increment and the last, `M a_{n+1} = -[(1 + alpha) F_{n+1} - alpha F_n]` and the same at
    /// `n` (which gives `alpha F_{n-1} = M a_n + (1 + alpha) F_n`), an equation with inertia
    /// (mass `M_i`, possibly 0) loses
    ///
    /// `D_i = dx_i [alpha F_{n+1,i}/2 - (M_i a_{n,i} + (1 + alpha) F_{n,i})/2 + alpha M_i da_i]
    ///       + h^2 (alpha^2/4) da_i (M_i abar_i - alpha M_i da_i + c_i)`,
    ///
    /// zero at `alpha = 0`. A quasi-static equation, in equilibrium `F_{n+1} = c` at the end of
    /// the increment, loses `D_i = (F_{n+1,i} - F_{n,i}) dx_i / 2` (for a linear spring
    /// `k dx^2/2 >= 0`: the end-point equilibrium damps like backward Euler). Both are exact for
    /// linear forces whenever the equations hold, so the energy ledger closes with `D` counted
    /// only if every increment is in equilibrium.
    pub fn algorithmic_dissipation(&self, h: f64, ends: &IncrementEnds<'_>) -> f64 {
        let alpha = self.alpha;
        let c = h * h * alpha * alpha / 4.0;
        let mut dissipation = 0.0;
        for i in 0..ends.dx.len() {
            let (dx, f0, f1) = (ends.dx[i], ends.f0[i], ends.f1[i]);
            if ends.quasi_static[i] {
                dissipation += 0.5 * (f1 - f0) * dx;
                continue;
            }
            let (m, a0, a1) = (ends.mass[i], ends.a0[i], ends.a1[i]);
            let da = a1 - a0;
            let abar = 0.5 * (a0 + a1);
            dissipation += dx
                * (0.5 * alpha * f1 - 0.5 * (m * a0 + (1.0 + alpha) * f0) + alpha * m * da)
                + c * da * (m * abar - alpha * m * da + ends.contact[i]);
        }
        dissipation
    }

    /// End-of-increment smooth acceleration and velocity when the contact forces act as an
    /// impulse. `a_total` is the Newmark acceleration of the converged positions (which contains
    /// the contact term) and `contact = M^{-1} H^T r` the acceleration the contact unknown gives:
    /// `a_{n+1} = a_total - contact`,
    /// `v_{n+1} = v_n + h [(1 - gamma) a_n + gamma a_{n+1}] + 2 beta h contact`.
    pub fn split_impulse(
        &self,
        h: f64,
        v_n: &DVector<f64>,
        a_n: &DVector<f64>,
        a_total: &DVector<f64>,
        contact: &DVector<f64>,
    ) -> (DVector<f64>, DVector<f64>) {
        let a = a_total - contact;
        let v = v_n
            + (a_n * (1.0 - self.gamma) + &a * self.gamma) * h
            + contact * (h * self.impulse_force_factor());
        (v, a)
    }

    /// Velocity and acceleration at the end of the increment from the Newmark relations.
    pub fn velocity_and_acceleration(
        &self,
        h: f64,
        x_n: &DVector<f64>,
        v_n: &DVector<f64>,
        a_n: &DVector<f64>,
        x: &DVector<f64>,
    ) -> (DVector<f64>, DVector<f64>) {
        let a = (x - x_n - v_n * h) / (self.beta * h * h) - a_n * (0.5 / self.beta - 1.0);
        let v = v_n + (a_n * (1.0 - self.gamma) + &a * self.gamma) * h;
        (v, a)
    }
}

/// What [`Hht::algorithmic_dissipation`] reads of an increment, per equation.
pub struct IncrementEnds<'a> {
    /// Lumped mass (0 where the equation has no inertia).
    pub mass: &'a DVector<f64>,
    /// Whether the equation is quasi-static (in equilibrium at the end of the increment).
    pub quasi_static: &'a [bool],
    /// `x_{n+1} - x_n`.
    pub dx: &'a DVector<f64>,
    /// Smooth force `f_int - f_ext` at the start.
    pub f0: &'a DVector<f64>,
    /// Smooth force at the end.
    pub f1: &'a DVector<f64>,
    /// Smooth acceleration at the start.
    pub a0: &'a DVector<f64>,
    /// Smooth acceleration at the end.
    pub a1: &'a DVector<f64>,
    /// Contact force `H^T p` (mean force of the impulse).
    pub contact: &'a DVector<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// One HHT step of m x'' + k x = 0 (m = k = 1) through [`Hht`]: the residual
    /// `a_{n+1} + (1+alpha) x_{n+1} - alpha x_n` is linear in `x_{n+1}`, so one Newton step solves it.
    fn step(hht: &Hht, h: f64, (x, v, a): (f64, f64, f64)) -> (f64, f64, f64) {
        let one = |z: f64| DVector::from_element(1, z);
        let (_, a_at_zero) = hht.velocity_and_acceleration(h, &one(x), &one(v), &one(a), &one(0.0));
        let r0 = a_at_zero[0] - hht.alpha * x;
        let x1 = -r0 / (hht.mass_factor(h) + 1.0 + hht.alpha);
        let (v1, a1) = hht.velocity_and_acceleration(h, &one(x), &one(v), &one(a), &one(x1));
        (x1, v1[0], a1[0])
    }

    /// A free mass (no smooth force) given a contact unknown `r`: the velocity jumps by the
    /// impulse `h p / m` with `p = 2 beta r`, and the position moves by the trapezoidal rule,
    /// `x_{n+1} - x_n = h (v_n + v_{n+1}) / 2`, so the impulse's work `p (x_{n+1} - x_n)` equals
    /// the kinetic energy change.
    #[test]
    fn contact_impulse_moves_by_the_trapezoidal_rule() {
        let one = |z: f64| DVector::from_element(1, z);
        let (h, m, r, v0) = (1e-3, 2.0, 50.0, -3.0);
        for alpha in [0.0, -0.05, -0.3] {
            let hht = Hht::new(alpha).expect("alpha");
            // The increment's equation m (x1 - x0 - h v0) / (beta h^2) - r = 0.
            let x1 = h * v0 + r * hht.beta * h * h / m;
            let (_, a_total) =
                hht.velocity_and_acceleration(h, &one(0.0), &one(v0), &one(0.0), &one(x1));
            let (v1, a1) = hht.split_impulse(h, &one(v0), &one(0.0), &a_total, &one(r / m));
            let p = hht.impulse_force_factor() * r;
            assert!(
                a1[0].abs() < 1e-9,
                "no smooth force, no smooth acceleration: {}",
                a1[0]
            );
            assert!((v1[0] - (v0 + h * p / m)).abs() < 1e-12);
            assert!((x1 - h * (v0 + v1[0]) / 2.0).abs() < 1e-15);
            let work = p * x1;
            let kinetic = 0.5 * m * (v1[0] * v1[0] - v0 * v0);
            assert!(
                (work - kinetic).abs() < 1e-12 * kinetic.abs(),
                "{work} vs {kinetic}"
            );
        }
    }

    /// Two masses on springs under a constant load and a contact force that changes at random
    /// each increment, integrated with HHT: the kinetic and strain energy change, less the work
    /// of the load and of the contact impulse, is minus the algorithmic dissipation, to
    /// round-off, increment by increment; a quasi-static spring in end-point equilibrium loses
    /// `k dx^2 / 2`.
    #[test]
    fn the_algorithmic_dissipation_closes_the_energy_balance_of_a_linear_system() {
        use nalgebra::{Matrix2, Vector2};
        let mass = Vector2::new(2.0, 0.5);
        let k = Matrix2::new(30.0, -10.0, -10.0, 10.0);
        let load = Vector2::new(0.0, 1.0);
        let force = |x: &Vector2<f64>| k * x - load;
        let energy = |x: &Vector2<f64>, v: &Vector2<f64>| {
            0.5 * v.component_mul(v).dot(&mass) + 0.5 * x.dot(&(k * x))
        };
        let h = 0.05;
        let column = |v: &Vector2<f64>| DVector::from_column_slice(v.as_slice());
        let mut seed = 0x2545_f491_u64;
        for alpha in [0.0, -0.1, -1.0 / 3.0] {
            let hht = Hht::new(alpha).expect("alpha");
            let (beta, gamma) = (hht.beta, hht.gamma);
            let m = Matrix2::from_diagonal(&mass);
            let mut x = Vector2::new(0.1, -0.2);
            let mut v = Vector2::new(0.3, 0.0);
            let mut a = -force(&x).component_div(&mass);
            let mut total = 0.0;
            for _ in 0..60 {
                seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                let p = Vector2::new((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5, 0.0);
                let f0 = force(&x);
                // M a1 + (1 + alpha) F(x1) - alpha F0 = 0 with
                // x1 = x + h v + h^2 [(1/2 - beta) a + beta a1] + h^2/2 M^-1 p
                let free =
                    x + v * h + a * (h * h * (0.5 - beta)) + p.component_div(&mass) * (h * h / 2.0);
                let lhs = m / (beta * h * h) + k * (1.0 + alpha);
                let rhs = m * free / (beta * h * h) + load * (1.0 + alpha) + f0 * alpha;
                let x1 = lhs.lu().solve(&rhs).expect("regular");
                let a1 = (x1 - free) / (beta * h * h);
                let v1 = v + (a * (1.0 - gamma) + a1 * gamma) * h + p.component_div(&mass) * h;
                let dx = x1 - x;
                let lost = energy(&x, &v) - energy(&x1, &v1) + load.dot(&dx) + p.dot(&dx);
                let d = hht.algorithmic_dissipation(
                    h,
                    &IncrementEnds {
                        mass: &column(&mass),
                        quasi_static: &[false, false],
                        dx: &column(&dx),
                        f0: &column(&f0),
                        f1: &column(&force(&x1)),
                        a0: &column(&a),
                        a1: &column(&a1),
                        contact: &column(&p),
                    },
                );
                assert!(
                    (lost - d).abs() < 1e-13,
                    "alpha {alpha}: lost {lost}, D {d}"
                );
                total += d;
                (x, v, a) = (x1, v1, a1);
            }
            if alpha == 0.0 {
                assert!(total.abs() < 1e-13, "the trapezoidal rule loses {total}");
            } else {
                assert!(total > 1e-4, "alpha {alpha}: HHT damps, lost {total}");
            }
        }
        // A quasi-static spring k = 4 moved from 0.1 to 0.3 by its contact force 4 x1.
        let one = |z: f64| DVector::from_element(1, z);
        let d = Hht::new(-0.2).expect("alpha").algorithmic_dissipation(
            1e-3,
            &IncrementEnds {
                mass: &one(0.0),
                quasi_static: &[true],
                dx: &one(0.2),
                f0: &one(0.4),
                f1: &one(1.2),
                a0: &one(0.0),
                a1: &one(0.0),
                contact: &one(1.2),
            },
        );
        let lost = 1.2 * 0.2 - 0.5 * 4.0 * (0.3 * 0.3 - 0.1 * 0.1);
        assert!((d - lost).abs() < 1e-15 && (d - 0.5 * 4.0 * 0.04).abs() < 1e-15);
    }

    fn oscillate(alpha: f64, h: f64, steps: usize) -> Vec<(f64, f64)> {
        let hht = Hht::new(alpha).expect("alpha");
        let mut s = (1.0, 0.0, -1.0);
        let mut out = vec![(0.0, 1.0)];
        for n in 1..=steps {
            s = step(&hht, h, s);
            out.push((n as f64 * h, s.0));
        }
        out
    }

    /// Eigenvalues of the one-step map (x, v, a) -> (x, v, a) of the scheme.
    fn amplification_eigenvalues(alpha: f64, h: f64) -> Vec<nalgebra::Complex<f64>> {
        let hht = Hht::new(alpha).expect("alpha");
        let mut amp = nalgebra::Matrix3::zeros();
        for j in 0..3 {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            let (x, v, a) = step(&hht, h, (e[0], e[1], e[2]));
            amp[(0, j)] = x;
            amp[(1, j)] = v;
            amp[(2, j)] = a;
        }
        amp.complex_eigenvalues().iter().copied().collect()
    }

    /// Times of upward zero crossings (linear interpolation).
    fn crossings(history: &[(f64, f64)]) -> Vec<f64> {
        history
            .windows(2)
            .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
            .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
            .collect()
    }

    fn mean_period(history: &[(f64, f64)]) -> f64 {
        let c = crossings(history);
        (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64
    }

    #[test]
    fn trapezoidal_limit_conserves_amplitude_with_known_period_elongation() {
        // alpha = 0 is the trapezoidal rule: no dissipation, numerical frequency
        // Omega_bar = 2 atan(Omega/2), i.e. period ratio Omega / (2 atan(Omega / 2)).
        let h = 2.0 * PI / 20.0;
        let hist = oscillate(0.0, h, 2000);
        let expected = 2.0 * PI * h / (2.0 * (h / 2.0).atan());
        let period = mean_period(&hist);
        assert!(
            (period - expected).abs() < 1e-3 * expected,
            "{period} vs {expected}"
        );
        let late_max = hist[1800..].iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        assert!((late_max - 1.0).abs() < 0.01, "amplitude {late_max}");
    }

    #[test]
    fn hht_damping_and_period_match_the_amplification_matrix() {
        let (alpha, h) = (-0.3, 0.4);
        let principal = amplification_eigenvalues(alpha, h)
            .into_iter()
            .max_by(|p, q| p.im.abs().total_cmp(&q.im.abs()))
            .expect("eigenvalue");
        let omega_bar = principal.im.abs().atan2(principal.re);
        let hist = oscillate(alpha, h, 2400);
        // Period: 2 pi h / Omega_bar, longer than the exact 2 pi (period elongation).
        let expected_period = 2.0 * PI * h / omega_bar;
        let period = mean_period(&hist);
        assert!((period - expected_period).abs() < 1e-3 * expected_period);
        assert!(
            period > 2.0 * PI * 1.005,
            "HHT lengthens the period: {period}"
        );
        // Decay: |lambda|^n, measured on peaks one period apart at both ends of the run.
        let peak = |from: usize| {
            hist[from..from + 17]
                .iter()
                .map(|p| p.1.abs())
                .fold(0.0, f64::max)
        };
        let measured = (peak(2300) / peak(300)).ln() / 2000.0;
        let expected = principal.norm().ln();
        assert!(
            (measured - expected).abs() < 0.05 * expected.abs(),
            "{measured} vs {expected}"
        );
        // Algorithmic damping ratio xi = -ln|lambda| / Omega_bar: present but small for resolved
        // modes, and growing much faster than linearly with Omega (HHT damps selectively the
        // high frequencies).
        let xi = |h: f64| {
            let l = amplification_eigenvalues(alpha, h)
                .into_iter()
                .max_by(|p, q| p.im.abs().total_cmp(&q.im.abs()))
                .expect("eigenvalue");
            -l.norm().ln() / l.im.abs().atan2(l.re)
        };
        let (coarse, fine) = (xi(0.4), xi(0.2));
        assert!((coarse - (-expected / omega_bar)).abs() < 1e-12);
        assert!(coarse > 0.0 && coarse < 0.01, "damping ratio {coarse}");
        assert!(
            coarse / fine > 4.0,
            "super-linear growth: {coarse} / {fine}"
        );
    }

    #[test]
    fn high_frequency_spectral_radius_is_the_design_value() {
        for alpha in [-0.05, -0.3, -1.0 / 3.0] {
            let rho = amplification_eigenvalues(alpha, 1e6)
                .iter()
                .map(|l| l.norm())
                .fold(0.0, f64::max);
            let design = Hht::new(alpha)
                .expect("alpha")
                .spectral_radius_at_infinity();
            assert!(
                (rho - design).abs() < 1e-3,
                "alpha {alpha}: {rho} vs {design}"
            );
        }
    }

    #[test]
    fn alpha_outside_range_is_rejected() {
        assert!(Hht::new(0.1).is_err());
        assert!(Hht::new(-0.5).is_err());
        assert!(Hht::new(f64::NAN).is_err());
    }
}
