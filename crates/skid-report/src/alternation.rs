//! Node-to-node alternation of a nodal profile (a contact traction along a row of nodes): the
//! part of it that flips sign from one node to the next, the zero-energy pattern a mesh can lock
//! into, measured by finite differences over consecutive counted nodes.
//!
//! A pattern `+A, -A, +A, ...` measures `A` by either measure; a smooth profile sampled at
//! spacing `h` measures its derivative's share: `h^2 f'' / 4` by [`second_difference`] and
//! `h^4 f'''' / 16` by [`fourth_difference`].

/// `max |e_(i-1) - 2 e_i + e_(i+1)| / 4` over the `i` with `counted` at `i - 1`, `i` and
/// `i + 1`; `None` if there is none. For the error `e` against a known profile, whose smooth
/// part cancels; an affine `e` measures 0.
pub fn second_difference(errors: &[f64], counted: &[bool]) -> Option<f64> {
    (1..errors.len().saturating_sub(1))
        .filter(|&i| counted[i - 1..=i + 1].iter().all(|&c| c))
        .map(|i| (errors[i - 1] - 2.0 * errors[i] + errors[i + 1]).abs() / 4.0)
        .reduce(f64::max)
}

/// `max |f_(i-2) - 4 f_(i-1) + 6 f_i - 4 f_(i+1) + f_(i+2)| / 16` over the `i` with `counted`
/// from `i - 2` to `i + 2`; `None` if there is none. For a profile `f` with no known reference:
/// a cubic measures 0, a smooth profile its fourth derivative's share.
pub fn fourth_difference(values: &[f64], counted: &[bool]) -> Option<f64> {
    (2..values.len().saturating_sub(2))
        .filter(|&i| counted[i - 2..=i + 2].iter().all(|&c| c))
        .map(|i| {
            let f = &values[i - 2..=i + 2];
            (f[0] - 4.0 * f[1] + 6.0 * f[2] - 4.0 * f[3] + f[4]).abs() / 16.0
        })
        .reduce(f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_zigzag_measures_its_amplitude_and_polynomials_nothing() {
        let zigzag: Vec<f64> = (0..7)
            .map(|i| if i % 2 == 0 { 0.3 } else { -0.3 })
            .collect();
        let all = [true; 7];
        assert!((second_difference(&zigzag, &all).expect("counted") - 0.3).abs() < 1e-15);
        assert!((fourth_difference(&zigzag, &all).expect("counted") - 0.3).abs() < 1e-15);
        let affine: Vec<f64> = (0..7).map(|i| 0.5 + 0.1 * f64::from(i)).collect();
        assert!(second_difference(&affine, &all).expect("counted") < 1e-15);
        let cubic: Vec<f64> = (0..7)
            .map(|i| {
                let x = f64::from(i);
                1.0 - 0.2 * x + 0.05 * x * x - 0.01 * x * x * x
            })
            .collect();
        assert!(fourth_difference(&cubic, &all).expect("counted") < 1e-14);
    }

    #[test]
    fn only_stencils_of_counted_nodes_count() {
        let zigzag = [1.0, -1.0, 1.0, -1.0, 1.0];
        assert_eq!(
            second_difference(&zigzag, &[true, true, false, true, true]),
            None
        );
        assert_eq!(
            fourth_difference(&zigzag, &[true, true, true, true, false]),
            None
        );
        assert_eq!(second_difference(&[1.0], &[true]), None);
        assert_eq!(fourth_difference(&[1.0, 2.0], &[true, true]), None);
    }
}
