//! Cook's membrane in the linear limit on a 2 x 2 mesh: the trapezoid with corners (0, 0),
//! (48, 44), (48, 60), (0, 44), clamped on x = 0 and sheared by a load `F` along y on x = 48,
//! plane strain with `E' = 1`, `nu' = 1/4` and `t = 1`. The deflection `v` of the loaded edge's
//! mid-point is normalised by the converged `23.96 / (E t)`, `E = E' (1 + nu)^2 / (1 + 2 nu)`
//! with `nu = nu' / (1 - nu') = 1/3` (the plane-stress benchmark through the plane-strain
//! moduli). On so coarse a mesh the bending stiffness of the elements decides the deflection:
//! the enhanced hourglass control gives the one-point element the incompatible-mode element's.

use nalgebra::{DMatrix, DVector, Vector2};
use skid_fem::{FemError, Formulation, Hourglass, PolynomialN1, SolidElement, Tangent};

/// Elements per side.
const N: usize = 2;

/// Node number of grid point (i, j), i along x.
fn node(i: usize, j: usize) -> usize {
    j * (N + 1) + i
}

/// The grid's nodes: x = 48 i / N, y between the lower edge `44 x / 48` and the upper edge
/// `44 + 16 x / 48`.
fn nodes() -> Vec<Vector2<f64>> {
    let mut nodes = vec![Vector2::zeros(); (N + 1) * (N + 1)];
    for j in 0..=N {
        for i in 0..=N {
            let x = 48.0 * i as f64 / N as f64;
            let (low, high) = (44.0 * x / 48.0, 44.0 + 16.0 * x / 48.0);
            nodes[node(i, j)] = Vector2::new(x, low + (high - low) * j as f64 / N as f64);
        }
    }
    nodes
}

/// The normalised tip deflection with elements of `formulation` and hourglass control
/// `hourglass`, from the linear system of the tangents at `u = 0`.
fn normalised_deflection(formulation: Formulation, hourglass: Hourglass) -> Result<f64, FemError> {
    let (e, nu) = (1.0, 0.25);
    let (mu, bulk) = (e / (2.0 * (1.0 + nu)), e / (3.0 * (1.0 - 2.0 * nu)));
    let material = PolynomialN1::new(mu / 2.0, 0.0, 2.0 / bulk)?;
    let x = nodes();
    let dofs = 2 * x.len();
    let mut k = DMatrix::zeros(dofs, dofs);
    for j in 0..N {
        for i in 0..N {
            let corners = [
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ];
            let x_e: Vec<Vector2<f64>> = corners.iter().map(|&c| x[c]).collect();
            let element = SolidElement::new(formulation, &x_e, 1.0, &material, hourglass)?;
            let mut k_e = vec![0.0; 64];
            let zero = vec![Vector2::zeros(); 4];
            element.respond_with_tangent(&material, &zero, Tangent::Consistent, &mut k_e)?;
            for (a, &na) in corners.iter().enumerate() {
                for (b, &nb) in corners.iter().enumerate() {
                    for (r, s) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                        k[(2 * na + r, 2 * nb + s)] += k_e[(2 * b + s) * 8 + 2 * a + r];
                    }
                }
            }
        }
    }
    // unit load along y on x = 48, lumped: 1/4, 1/2, 1/4 of it at the edge's nodes
    let mut f = DVector::zeros(dofs);
    for j in 0..=N {
        let share = if j == 0 || j == N { 0.5 } else { 1.0 };
        f[2 * node(N, j) + 1] = share / N as f64;
    }
    let free: Vec<usize> = (0..dofs).filter(|&d| (d / 2) % (N + 1) != 0).collect();
    let k_ff = DMatrix::from_fn(free.len(), free.len(), |r, s| k[(free[r], free[s])]);
    let f_f = DVector::from_iterator(free.len(), free.iter().map(|&d| f[d]));
    let u_f = k_ff
        .lu()
        .solve(&f_f)
        .ok_or(FemError::InvalidMesh("singular stiffness".into()))?;
    let tip = free
        .iter()
        .position(|&d| d == 2 * node(N, N / 2) + 1)
        .ok_or(FemError::InvalidMesh("no tip".into()))?;
    let plane_stress_e = e * (1.0 + 1.0 / 3.0_f64).powi(2) / (1.0 + 2.0 / 3.0);
    Ok(u_f[tip] / (23.96 / plane_stress_e))
}

#[test]
fn enhanced_hourglass_control_bends_like_the_incompatible_modes() -> Result<(), FemError> {
    let stiffness = normalised_deflection(Formulation::Reduced, Hourglass::default())?;
    let enhanced = normalised_deflection(Formulation::Reduced, Hourglass::Enhanced)?;
    let incompatible = normalised_deflection(Formulation::Incompatible, Hourglass::default())?;
    let full = normalised_deflection(Formulation::Full, Hourglass::default())?;
    println!(
        "Cook 2 x 2: CPE4R stiffness {stiffness:.4}, enhanced {enhanced:.4}, \
         CPE4I {incompatible:.4}, CPE4 {full:.4}"
    );
    assert!((enhanced - incompatible).abs() < 1e-10 * incompatible);
    assert!((0.87..0.89).contains(&enhanced), "{enhanced}");
    assert!((0.70..0.72).contains(&stiffness), "{stiffness}");
    // the fully integrated displacement element is stiffer still (parasitic shear)
    assert!(full < stiffness, "{full}");
    Ok(())
}
