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
//! the gap over the increment on a curved surface (see `crate::coupling::contact_rows`): along
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
