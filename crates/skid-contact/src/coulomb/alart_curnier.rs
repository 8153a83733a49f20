//! The Alart–Curnier function of one contact and its generalized derivative.
//!
//! For a contact with forces `r = [r_N, r_T..]` (`r_N >= 0` compressive), local displacements
//! `u = [u_N, u_T..]` (gap at the end of the step, slip increment) and a weight `rho > 0` (force
//! per length), with `tau = r_N - rho u_N` and `v = r_T - rho u_T`:
//!
//! * open (`tau <= 0`): `Phi = r`;
//! * closed: `Phi_N = rho u_N` and `Phi_T = r_T - proj_{B(mu tau)}(v)`, that is
//!   * frictionless (`mu tau = 0`): `Phi_T = r_T`;
//!   * stick (`||v|| <= mu tau`): `Phi_T = rho u_T`;
//!   * slide: `Phi_T = r_T - mu tau d`, `d = v / ||v||`.
//!
//! (Alart & Curnier, CMAME 92, 1991.) `Phi = 0` exactly when the exact Coulomb law holds: open
//! with `r = 0`, `u_N >= 0`; stick with `u = 0`, `||r_T|| <= mu r_N`; or slide with `u_N = 0`,
//! `r_T = -mu r_N u_T / ||u_T||` (no dilation). Its solutions do not depend on `rho`.
//!
//! On the slide branch, with `P = I - d d^T` and `f = mu tau / ||v||`,
//! `dPhi_T = dr_T - mu d dtau - f P dv`, `dtau = dr_N - rho du_N`, `dv = dr_T - rho du_T`, so
//! `dPhi_T/dr = [-mu d | I - f P]` and `dPhi_T/du = [mu rho d | f rho P]` (columns N, T).

/// `Phi` of one contact at `(r, u)` and its generalized derivatives `dPhi/dr`, `dPhi/du`
/// (`dim x dim`, row-major in the first `dim` rows and columns).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalLaw {
    /// The branch the contact is on.
    pub branch: LocalBranch,
    /// `Phi` (force units).
    pub phi: [f64; 3],
    /// `dPhi/dr` (dimensionless).
    pub d_r: [[f64; 3]; 3],
    /// `dPhi/du` (force per length).
    pub d_u: [[f64; 3]; 3],
    /// On the slide branch, the sliding direction `d` and `f = mu tau / ||v||` (`< 1`).
    pub slide: Option<SlideFrame>,
}

/// The sliding direction `d = v / ||v||` (tangential components) and the ratio
/// `f = mu tau / ||v||` of a sliding contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlideFrame {
    /// `d`, unit length in the first `dim - 1` components.
    pub d: [f64; 2],
    /// `f`, in `(0, 1)`.
    pub f: f64,
}

/// Branch of the Alart–Curnier function at one contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LocalBranch {
    /// `tau <= 0`: no force.
    Open,
    /// Closed without friction radius (`mu = 0` or `tau = 0`).
    Frictionless,
    /// Closed and sticking.
    Stick,
    /// Closed and sliding.
    Slide,
}

impl LocalLaw {
    /// Evaluates the law of a contact with `dim` components (2 or 3; `r`, `u` of that length),
    /// friction coefficient `mu >= 0` and weight `rho > 0`.
    pub fn evaluate(dim: usize, mu: f64, rho: f64, r: &[f64], u: &[f64]) -> Self {
        Self::evaluate_at_kink(dim, mu, rho, r, u, LocalBranch::Open)
    }

    /// [`Self::evaluate`], with the branch taken at the kink `tau = 0` (`Open` or, for a
    /// contact that is about to close, such as a node resting on the surface with no force
    /// yet, a closed one). `Phi` is continuous there, and either derivative is a valid
    /// generalized one; they differ in the Newton step they give.
    #[allow(clippy::needless_range_loop)] // component indices of r, u, Phi and its derivatives
    pub fn evaluate_at_kink(
        dim: usize,
        mu: f64,
        rho: f64,
        r: &[f64],
        u: &[f64],
        at_kink: LocalBranch,
    ) -> Self {
        let mut law = Self {
            branch: LocalBranch::Open,
            phi: [0.0; 3],
            d_r: [[0.0; 3]; 3],
            d_u: [[0.0; 3]; 3],
            slide: None,
        };
        let tau = r[0] - rho * u[0];
        if tau < 0.0 || (tau == 0.0 && at_kink == LocalBranch::Open) {
            for k in 0..dim {
                law.phi[k] = r[k];
                law.d_r[k][k] = 1.0;
            }
            return law;
        }
        law.phi[0] = rho * u[0];
        law.d_u[0][0] = rho;
        let mut v = [0.0; 2];
        for t in 1..dim {
            v[t - 1] = r[t] - rho * u[t];
        }
        let norm = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        let radius = mu * tau;
        if radius == 0.0 {
            law.branch = LocalBranch::Frictionless;
            for t in 1..dim {
                law.phi[t] = r[t];
                law.d_r[t][t] = 1.0;
            }
        } else if norm <= radius {
            law.branch = LocalBranch::Stick;
            for t in 1..dim {
                law.phi[t] = rho * u[t];
                law.d_u[t][t] = rho;
            }
        } else {
            law.branch = LocalBranch::Slide;
            let d = v.map(|c| c / norm);
            let factor = radius / norm;
            law.slide = Some(SlideFrame { d, f: factor });
            for t in 1..dim {
                law.phi[t] = r[t] - radius * d[t - 1];
                law.d_r[t][0] = -mu * d[t - 1];
                law.d_u[t][0] = mu * rho * d[t - 1];
                for s in 1..dim {
                    let projector = f64::from(u8::from(s == t)) - d[t - 1] * d[s - 1];
                    law.d_r[t][s] = f64::from(u8::from(s == t)) - factor * projector;
                    law.d_u[t][s] = factor * rho * projector;
                }
            }
        }
        law
    }

    /// The law with the tangential rows of a sliding contact multiplied by the invertible
    /// `T = d d^T + P / f` (unchanged on other branches), which has the same zeros and the
    /// same Newton step. With `c = (1 - f) / f` the tangential rows become
    /// `dPhi'_T/dr = [-mu d | d d^T + c P]`, `dPhi'_T/du = [mu rho d | rho P]`: across the
    /// sliding direction a constraint `rho P du_T` softened by `c rho P dr_T`, symmetric with
    /// the contact's column `-H_T^T` of the global system, and along it `dr_d = mu dr_N` plus
    /// the normal coupling that makes friction unsymmetric.
    #[must_use]
    pub fn with_balanced_slide_rows(mut self, dim: usize) -> Self {
        let Some(SlideFrame { d, f }) = self.slide else {
            return self;
        };
        let t_matrix = |t: usize, s: usize| {
            let delta = f64::from(u8::from(s == t));
            d[t] * d[s] + (delta - d[t] * d[s]) / f
        };
        let tangential = dim - 1;
        let rows = |m: &[[f64; 3]; 3]| {
            let mut out = *m;
            for t in 0..tangential {
                for col in 0..dim {
                    out[t + 1][col] = (0..tangential)
                        .map(|s| t_matrix(t, s) * m[s + 1][col])
                        .sum();
                }
            }
            out
        };
        self.d_r = rows(&self.d_r);
        self.d_u = rows(&self.d_u);
        let phi = self.phi;
        for t in 0..tangential {
            self.phi[t + 1] = (0..tangential).map(|s| t_matrix(t, s) * phi[s + 1]).sum();
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Away from the branch switches the derivatives are those of `Phi`: central differences
    /// in `r` and `u` on each branch, 2D and 3D.
    #[test]
    fn derivatives_match_finite_differences() {
        let cases: [(f64, [f64; 3], [f64; 3], LocalBranch); 4] = [
            (0.3, [0.1, 0.05, 0.02], [1.0, 0.3, 0.1], LocalBranch::Open),
            (0.3, [1.0, 0.1, 0.05], [0.0, 0.01, 0.0], LocalBranch::Stick),
            (0.3, [1.0, 0.2, -0.3], [0.01, 1.5, 0.8], LocalBranch::Slide),
            (
                0.0,
                [1.0, 0.1, 0.2],
                [0.05, 0.3, 0.1],
                LocalBranch::Frictionless,
            ),
        ];
        let rho = 0.7;
        let h = 1e-7;
        for dim in [2, 3] {
            for (mu, r, u, branch) in cases {
                let law = LocalLaw::evaluate(dim, mu, rho, &r, &u);
                assert_eq!(law.branch, branch, "{dim}D");
                for j in 0..dim {
                    let shifted = |which: usize, sign: f64| {
                        let (mut r, mut u) = (r, u);
                        let target = if which == 0 { &mut r } else { &mut u };
                        target[j] += sign * h;
                        LocalLaw::evaluate(dim, mu, rho, &r, &u).phi
                    };
                    for (which, analytic) in [(0, &law.d_r), (1, &law.d_u)] {
                        let (plus, minus) = (shifted(which, 1.0), shifted(which, -1.0));
                        for i in 0..dim {
                            let numeric = (plus[i] - minus[i]) / (2.0 * h);
                            assert!(
                                (numeric - analytic[i][j]).abs() < 1e-6,
                                "{dim}D {branch:?}: d Phi_{i} / d {}_{j}: {numeric} vs {}",
                                ["r", "u"][which],
                                analytic[i][j]
                            );
                        }
                    }
                }
            }
        }
    }

    /// `Phi = 0` at the three states of the exact law, and not at a dilating slide.
    #[test]
    fn zero_exactly_on_the_coulomb_law() {
        let (mu, rho) = (0.5, 3.0);
        let open = LocalLaw::evaluate(3, mu, rho, &[0.0; 3], &[1e-3, 0.2, 0.0]);
        let stick = LocalLaw::evaluate(3, mu, rho, &[2.0, 0.3, -0.4], &[0.0; 3]);
        let slide = LocalLaw::evaluate(3, mu, rho, &[2.0, -0.6, -0.8], &[0.0, 0.3, 0.4]);
        for law in [open, stick, slide] {
            assert!(law.phi.iter().all(|p| p.abs() < 1e-15), "{law:?}");
        }
        // the convex relaxation's solution lifts off by mu ||u_T||: not a zero of Phi
        let dilated = LocalLaw::evaluate(3, mu, rho, &[2.0, -0.6, -0.8], &[0.25, 0.3, 0.4]);
        assert!(dilated.phi[0].abs() > 0.5);
    }

    /// The balanced slide rows are `T` times the rows of `Phi` and its derivatives, and take
    /// the closed form `[-mu d | d d^T + c P]`, `[mu rho d | rho P]` of their documentation;
    /// other branches are unchanged.
    #[test]
    fn balanced_slide_rows_have_the_symmetric_form() {
        let (mu, rho) = (0.3, 0.7);
        let (r, u) = ([1.0, 0.2, -0.3], [0.01, 1.5, 0.8]);
        let law = LocalLaw::evaluate(3, mu, rho, &r, &u);
        let Some(SlideFrame { d, f }) = law.slide else {
            panic!("not sliding: {law:?}");
        };
        let balanced = law.with_balanced_slide_rows(3);
        let c = (1.0 - f) / f;
        for t in 0..2 {
            assert!((balanced.d_r[t + 1][0] + mu * d[t]).abs() < 1e-14);
            assert!((balanced.d_u[t + 1][0] - mu * rho * d[t]).abs() < 1e-14);
            for s in 0..2 {
                let p = f64::from(u8::from(s == t)) - d[t] * d[s];
                assert!((balanced.d_r[t + 1][s + 1] - d[t] * d[s] - c * p).abs() < 1e-14);
                assert!((balanced.d_u[t + 1][s + 1] - rho * p).abs() < 1e-14);
            }
            // T phi_T, with T d = d and T e = e / f
            let e = [-d[1], d[0]];
            let along: f64 = (0..2).map(|s| d[s] * law.phi[s + 1]).sum();
            let across: f64 = (0..2).map(|s| e[s] * law.phi[s + 1]).sum();
            let expected = along * d[t] + across * e[t] / f;
            assert!((balanced.phi[t + 1] - expected).abs() < 1e-14);
        }
        assert_eq!(balanced.d_r[0], law.d_r[0]);
        let stick = LocalLaw::evaluate(3, mu, rho, &[1.0, 0.1, 0.05], &[0.0, 0.01, 0.0]);
        assert_eq!(stick.with_balanced_slide_rows(3), stick);
    }
}
