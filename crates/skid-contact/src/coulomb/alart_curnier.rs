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
}
