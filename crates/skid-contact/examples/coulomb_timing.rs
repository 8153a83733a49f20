//! Time `solve_coulomb` on dense SPD Delassus operators: 11 contacts in 2D and 22 in 3D (the
//! drum benchmark's contact sizes), mu = 0.15, with a mix of open, sticking and sliding contacts.
//!
//! Run with `cargo run --release -p skid-contact --example coulomb_timing`.

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use skid_contact::{CoulombSettings, FrictionProblem, solve_coulomb};

/// Deterministic pseudo-random numbers (SplitMix64), uniform in `[low, high)`.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, low: f64, high: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        low + (high - low) * (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn time_case(dim: usize, n_contacts: usize, repetitions: usize) {
    let m = dim * n_contacts;
    let mut rng = Rng(2024);
    let b = DMatrix::from_fn(m, m, |_, _| rng.uniform(-1.0, 1.0));
    // compliance ~1e-6 m/N, free penetration ~1 mm, slip ~12 mm per step
    let w = (&b * b.transpose() / m as f64 + DMatrix::identity(m, m) * 0.1) * 1e-6;
    let q = DVector::from_fn(m, |k, _| {
        if k % dim == 0 {
            rng.uniform(-1e-3, 2e-4)
        } else {
            rng.uniform(-12e-3, 12e-3)
        }
    });
    let mu = vec![0.15; n_contacts];
    let problem = FrictionProblem {
        dim,
        w: &w,
        q: &q,
        mu: &mu,
    };
    let settings = CoulombSettings::default();
    let mut forces = None;
    for warm in [false, true] {
        let start = Instant::now();
        let mut last = None;
        for _ in 0..repetitions {
            match solve_coulomb(
                &problem,
                &settings,
                if warm { forces.as_ref() } else { None },
            ) {
                Ok(solution) => last = Some(solution),
                Err(e) => {
                    println!("{dim}D, {n_contacts} contacts: solve failed: {e}");
                    return;
                }
            }
        }
        let per_solve = start.elapsed().as_secs_f64() / repetitions as f64;
        if let Some(solution) = last {
            println!(
                "{dim}D, {n_contacts:2} contacts ({m:2} unknowns), {}: {:.3} ms per solve, \
                 {} conic solve(s), {} Newton step(s), natural-map error {:.1e}",
                if warm { "warm forces" } else { "cold       " },
                per_solve * 1e3,
                solution.conic_solves,
                solution.newton_steps,
                solution.natural_map_error
            );
            forces = Some(solution.r);
        }
    }
}

fn main() {
    time_case(2, 11, 500);
    time_case(3, 22, 200);
}
