//! The Coulomb friction cone `K_mu = {(r_N, r_T) : ||r_T|| <= mu r_N}` of one contact, whose
//! components are stored `[N, T]` (2D) or `[N, T1, T2]` (3D).

/// Euclidean norm of the tangential part `r_T` of a contact block `[N, T..]`.
pub(crate) fn tangential_norm(block: &[f64]) -> f64 {
    block
        .iter()
        .skip(1)
        .map(|component| component * component)
        .sum::<f64>()
        .sqrt()
}

/// Euclidean projection of `v` onto `K_mu`, written into `out` (same length as `v`).
///
/// With `t = ||v_T||`: `v` itself if `t <= mu v_N`; `0` if `mu t <= -v_N`; otherwise
/// `p_N = (mu t + v_N) / (1 + mu^2)`, `p_T = mu p_N v_T / t`.
pub(crate) fn project_onto_friction_cone(mu: f64, v: &[f64], out: &mut [f64]) {
    let normal = v[0];
    let t = tangential_norm(v);
    if t <= mu * normal {
        out.copy_from_slice(v);
    } else if mu * t <= -normal {
        out.fill(0.0);
    } else {
        // here t > 0: t = 0 would need both mu v_N < 0 and v_N > 0
        let projected_normal = (mu * t + normal) / (1.0 + mu * mu);
        out[0] = projected_normal;
        let factor = mu * projected_normal / t;
        for (o, component) in out.iter_mut().zip(v).skip(1) {
            *o = factor * component;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn projection_cases() {
        let mut out = [0.0; 3];
        project_onto_friction_cone(0.5, &[2.0, 0.6, -0.8], &mut out);
        assert_eq!(out, [2.0, 0.6, -0.8]);
        project_onto_friction_cone(0.5, &[-2.0, 0.6, -0.8], &mut out);
        assert_eq!(out, [0.0, 0.0, 0.0]);
        // outside, towards the boundary: the residual is orthogonal to the projection
        let v = [1.0, 3.0, 4.0];
        project_onto_friction_cone(0.5, &v, &mut out);
        assert_relative_eq!(tangential_norm(&out), 0.5 * out[0], epsilon = 1e-14);
        let dot: f64 = out.iter().zip(&v).map(|(p, v)| p * (v - p)).sum();
        assert_relative_eq!(dot, 0.0, epsilon = 1e-13);
        // frictionless cone: keep the non-negative normal part only
        let mut out2 = [0.0; 2];
        project_onto_friction_cone(0.0, &[1.5, 2.0], &mut out2);
        assert_eq!(out2, [1.5, 0.0]);
        project_onto_friction_cone(0.0, &[-1.5, 2.0], &mut out2);
        assert_eq!(out2, [0.0, 0.0]);
    }
}
