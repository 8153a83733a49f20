//! Why the sliding block chatters: steady Coulomb sliding of an elastic block is a flutter
//! instability of the discretized system, not an artefact of the time integration.
//!
//! The block of `scripts/sliding.py` (0.02 x 0.005 m, 0.01 m thick, neo-Hookean with
//! Poisson's ratio 0, 1000 kg/m^3; n x n one-point elements), its top tied to a plate that only
//! translates, slides along +x on a rigid flat with every bottom node in contact. Linearised
//! about the unstressed state (the block's stresses are 1e-5 of E there): the bottom nodes
//! keep `u_y = 0` with the reaction `N_i = (K u)_{y_i}`, and sliding puts the friction
//! `-mu N_i` on their x rows, so the equations of motion are `M u'' + C u' + (K + mu B) u = 0`
//! with `B` the bottom y rows of `K` moved to the x rows: not symmetric. Where two modes
//! meet, the pair turns complex and grows as `exp(s t)`, `Re s > 0` (mode-coupling flutter,
//! the mechanism of brake squeal; Martins, Guimaraes and Faria 1995 show growing surface
//! waves for a half-space). Massless contact nodes (their x rows static, condensed) raise the
//! friction coefficient at which it starts on a coarse mesh, but the threshold falls as the
//! mesh is refined, the signature of a continuum problem that is ill-posed without damping.
//! Stiffness-proportional damping `C = beta K` with the loss of a real rubber (`beta = 1e-5 s`:
//! 6 % of critical on the block's first mode) removes it for mu up to 1 on every mesh.
//!
//! Measured growth rates agree with the dynamic runs: 4 x 4, massless contact nodes, mu = 0.85
//! grows at 694/s here and at 620-680/s in `skid run` (dt 1e-5 and 5e-6 s, HHT alpha = -0.3).

use nalgebra::{DMatrix, SVector, Vector2};
use skid_fem::material::PolynomialN1;
use skid_fem::solid::Tangent;
use skid_fem::{Formulation, Hourglass, SolidElement};

/// How the contact nodes and the section are treated.
#[derive(Clone, Copy)]
struct Variant {
    /// The contact nodes' mass moved to the nodes above them (their x rows condensed).
    massless: bool,
    /// Stiffness-proportional damping factor, s (only with lumped contact nodes).
    beta: f64,
}

/// The largest growth rate `max Re s` (1/s) of the sliding n x n block at friction `mu`:
/// 0 or less where steady sliding is stable.
fn growth_rate(n: usize, mu: f64, variant: Variant) -> f64 {
    let (width, height, thickness, density) = (0.02, 0.005, 0.01, 1000.0);
    let shear = 1.38e6;
    let material = PolynomialN1::new(0.552e6, 0.138e6, 3.0 / shear).expect("material");
    let node = |i: usize, j: usize| j * (n + 1) + i;
    let nodes = (n + 1) * (n + 1);
    let mut k = DMatrix::<f64>::zeros(2 * nodes, 2 * nodes);
    let mut mass = vec![0.0; nodes];
    for j in 0..n {
        for i in 0..n {
            let ids = [
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ];
            let x: Vec<SVector<f64, 2>> = ids
                .iter()
                .map(|&a| {
                    let (ia, ja) = (a % (n + 1), a / (n + 1));
                    Vector2::new(
                        -width / 2.0 + width * ia as f64 / n as f64,
                        height * ja as f64 / n as f64,
                    )
                })
                .collect();
            let element = SolidElement::<2>::new(
                Formulation::Reduced,
                &x,
                thickness,
                &material,
                Hourglass::default(),
            )
            .expect("element");
            let u = [SVector::<f64, 2>::zeros(); 4];
            let mut ke = [0.0; 64];
            element
                .respond_with_tangent(&material, &u, Tangent::Consistent, &mut ke)
                .expect("tangent");
            for a in 0..8 {
                for b in 0..8 {
                    k[(2 * ids[a / 2] + a % 2, 2 * ids[b / 2] + b % 2)] += ke[a + 8 * b];
                }
            }
            // lumped mass; massless contact nodes give theirs to the element's other nodes
            let m = element.lumped_node_masses(density);
            let contact = |a: usize| variant.massless && ids[a] / (n + 1) == 0;
            let moved: f64 = (0..4).filter(|&a| contact(a)).map(|a| m[a]).sum();
            let keep = (0..4).filter(|&a| !contact(a)).count() as f64;
            for a in (0..4).filter(|&a| !contact(a)) {
                mass[ids[a]] += m[a] + moved / keep;
            }
        }
    }
    // unknowns q: the bottom nodes' x, the inner nodes' x and y, the plate's x and y (the top
    // nodes tied to it); the bottom nodes' y is held by the contact
    let mut index = vec![[None; 2]; nodes];
    let mut count = 0;
    let mut next = || {
        count += 1;
        Some(count - 1)
    };
    for i in 0..=n {
        index[node(i, 0)][0] = next();
    }
    let bottom = n + 1;
    for j in 1..n {
        for i in 0..=n {
            index[node(i, j)] = [next(), next()];
        }
    }
    let plate = [next(), next()];
    for i in 0..=n {
        index[node(i, n)] = plate;
    }
    let nq = count;
    let mut t = DMatrix::<f64>::zeros(2 * nodes, nq);
    for (a, eqs) in index.iter().enumerate() {
        for (c, eq) in eqs.iter().enumerate() {
            if let Some(q) = eq {
                t[(2 * a + c, *q)] = 1.0;
            }
        }
    }
    let kt = &k * &t;
    let mut stiffness = t.transpose() * &kt;
    for i in 0..=n {
        let row = index[node(i, 0)][0].expect("bottom x");
        for c in 0..nq {
            stiffness[(row, c)] += mu * kt[(2 * node(i, 0) + 1, c)];
        }
    }
    let mut m = vec![0.0; nq];
    for (a, eqs) in index.iter().enumerate() {
        for q in eqs.iter().flatten() {
            m[*q] += mass[a];
        }
    }
    if variant.beta > 0.0 {
        assert!(!variant.massless, "damping with lumped contact nodes only");
        // first order: z = (q, v), z' = [[0, I], [-M^-1 (K + mu B), -M^-1 beta (K + mu B)]] z
        // (the damping force enters the reaction, and so the friction, as the elastic one)
        let mut a = DMatrix::<f64>::zeros(2 * nq, 2 * nq);
        for i in 0..nq {
            a[(i, nq + i)] = 1.0;
            for j in 0..nq {
                a[(nq + i, j)] = -stiffness[(i, j)] / m[i];
                a[(nq + i, nq + j)] = -variant.beta * stiffness[(i, j)] / m[i];
            }
        }
        return (a.complex_eigenvalues().iter())
            .filter(|s| s.im.abs() > 1.0)
            .map(|s| s.re)
            .fold(f64::NEG_INFINITY, f64::max);
    }
    // massless rows condensed statically; then s^2 = -lambda of M^-1 K
    let (statics, dynamics): (Vec<usize>, Vec<usize>) = if variant.massless {
        ((0..bottom).collect(), (bottom..nq).collect())
    } else {
        (Vec::new(), (0..nq).collect())
    };
    let block = |r: &[usize], c: &[usize]| {
        DMatrix::from_fn(r.len(), c.len(), |i, j| stiffness[(r[i], c[j])])
    };
    let mut condensed = block(&dynamics, &dynamics);
    if !statics.is_empty() {
        let coupling = block(&statics, &dynamics);
        let solved = block(&statics, &statics)
            .lu()
            .solve(&coupling)
            .expect("regular");
        condensed -= block(&dynamics, &statics) * solved;
    }
    let a = DMatrix::from_fn(dynamics.len(), dynamics.len(), |i, j| {
        condensed[(i, j)] / m[dynamics[i]]
    });
    (a.complex_eigenvalues().iter())
        .map(|lambda| (-lambda).sqrt().re.abs())
        .fold(0.0, f64::max)
}

const LUMPED: Variant = Variant {
    massless: false,
    beta: 0.0,
};
const MASSLESS: Variant = Variant {
    massless: true,
    beta: 0.0,
};

#[test]
fn steady_sliding_flutters_above_a_friction_coefficient_that_falls_with_the_mesh() {
    // without friction the block only vibrates
    assert!(growth_rate(4, 0.0, LUMPED) < 1e-6);
    // lumped contact nodes: stable at mu = 0.1, flutter from below 0.3 (the chatter that grows
    // as the time step shrinks, where HHT's damping falls below the growth)
    assert!(growth_rate(4, 0.1, LUMPED) < 1e-6);
    let lumped = growth_rate(4, 0.3, LUMPED);
    assert!(
        (150.0..250.0).contains(&lumped),
        "4 x 4 lumped, mu 0.3: {lumped}/s"
    );
    // massless contact nodes: stable to mu = 0.6 on 4 x 4, flutter at 0.7 and beyond
    assert!(growth_rate(4, 0.6, MASSLESS) < 1e-6);
    let at = |mu| growth_rate(4, mu, MASSLESS);
    let (g07, g085) = (at(0.7), at(0.85));
    assert!(
        (300.0..420.0).contains(&g07),
        "4 x 4 massless, mu 0.7: {g07}/s"
    );
    assert!(
        (600.0..800.0).contains(&g085),
        "4 x 4 massless, mu 0.85: {g085}/s"
    );
    // on 8 x 8 it flutters at mu = 0.3 already, and faster than 4 x 4 at mu = 0.85
    let fine = growth_rate(8, 0.3, MASSLESS);
    assert!(fine > 300.0, "8 x 8 massless, mu 0.3: {fine}/s");
    assert!(growth_rate(8, 0.85, MASSLESS) > 2.0 * g085);
}

#[test]
fn stiffness_damping_with_the_loss_of_rubber_keeps_sliding_steady_to_mu_1() {
    let damped = Variant {
        massless: false,
        beta: 1e-5,
    };
    for n in [4, 8] {
        let rate = growth_rate(n, 1.0, damped);
        assert!(rate < -500.0, "{n} x {n}, mu 1, beta 1e-5 s: {rate}/s");
    }
    // too little damping does not: beta = 1e-6 s leaves mu = 0.7 unstable
    let weak = Variant {
        massless: false,
        beta: 1e-6,
    };
    assert!(growth_rate(4, 0.7, weak) > 0.0);
}
