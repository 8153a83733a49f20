//! The memory a case needs, estimated from its counts before anything is allocated, against
//! the memory the machine has free.
//!
//! The estimate counts what the run cannot do without, from the element, facet and increment
//! counts alone:
//!
//! - the pad mesh: [`NODE_BYTES_PER_DOF`] per degree of freedom (coordinates, displacement,
//!   velocity, acceleration, forces, Newton update), [`ELEMENT_BYTES_PER_NODE`] per element
//!   node;
//! - the stiffness matrix (a node couples with its `3^D` neighbours, `D^2` entries each) at
//!   [`SPARSE_ENTRY_BYTES`], and its factorization: at least the matrix's entries, and in 3D
//!   [`FACTOR_BYTES_3D`] `n^(4/3)` for `n` equations, the growth of a nested-dissection
//!   factor's fill on a 3D mesh (2D fill, `n log n`, is not counted);
//! - on the reduced contact path (the one the run takes,
//!   [`crate::schema::SolverSpec::contact_solve_with`]: `reduced`, or `auto` on a pad that is
//!   not quasi-static, under `skid_integrator::global_contact::QUASI_DEFINITE_FROM` unknowns)
//!   the dense contact block: the inverse of the stiffness on the contact equations, its
//!   product with the contact rows and the Delassus operator, three dense squares of `D`
//!   equations per front-face node;
//! - a tetrahedral drum: its nodes and six tetrahedra per cell;
//! - the history: one [`Sample`] per increment (static increments, and `duration / dt` per
//!   dynamic step, `duration / max_dt` if adaptive), kept for the summary.
//!
//! The estimate is meant as a lower bound, so that no case that fits is refused: on the 3D drum
//! of `scripts/scaling.py` the peak resident memory measured is 1.06 to 6.0 times it from
//! 1,262 to 101,810 equations (6.0 at 49,574, where the global path's sparse LU fills in more
//! than a nested-dissection factor), and up to 24 times on the smallest pads (the process's own
//! 14 MB). A case whose estimate exceeds the available memory is refused
//! before the run, naming the field whose term is the largest.

use skid_integrator::settings::ContactSolve;

use crate::history::Sample;
use crate::schema::{Case, DrumSurfaceSpec, StepSpec};

/// Bytes per degree of freedom of the pad: eight vectors of one `f64` each.
pub const NODE_BYTES_PER_DOF: f64 = 64.0;
/// Bytes per node of an element: its index.
pub const ELEMENT_BYTES_PER_NODE: f64 = 8.0;
/// Bytes per entry of a sparse matrix: the value and its row index.
pub const SPARSE_ENTRY_BYTES: f64 = 16.0;
/// Bytes of a 3D mesh's factorization per `n^(4/3)` (`n` equations): 40 entries of
/// [`SPARSE_ENTRY_BYTES`], the largest round coefficient that keeps the estimate below the peak
/// resident memory measured at every level of `scripts/scaling.py` (tightest at 19,034
/// equations on the reduced path, 1.06 times the estimate; at 101,810 equations the measured
/// 5.25 GB is 1.5 times it). The preconditioner's nested-dissection factor alone holds about
/// 18 `n^(4/3)` entries at 1e5 equations.
pub const FACTOR_BYTES_3D: f64 = 40.0 * SPARSE_ENTRY_BYTES;
/// Memory assumed available where the system does not say (no `/proc/meminfo`), bytes.
pub const DEFAULT_AVAILABLE: u64 = 16_000_000_000;

/// One term of the estimate: which field governs it, what it is, its size in bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The field of the case that sets it, e.g. `pad.elements`.
    pub field: &'static str,
    /// What it counts, e.g. `the pad mesh (1e12 elements)`.
    pub what: String,
    /// Bytes.
    pub bytes: f64,
}

/// The terms of the memory a case needs (see the module documentation); counts are taken as
/// `f64` so that no product overflows.
pub fn estimate(case: &Case) -> Vec<Term> {
    let d = case.dimension.clamp(2, 3);
    let counts = [
        case.pad.elements.circumferential,
        case.pad.elements.radial,
        case.pad.elements.axial,
    ];
    let counts = &counts[..d];
    let elements: f64 = counts.iter().map(|&c| c as f64).product();
    let nodes: f64 = counts.iter().map(|&c| c as f64 + 1.0).product();
    let dofs = d as f64 * nodes;
    let corners = (1usize << d) as f64;
    let entries = nodes * 3f64.powi(d as i32) * (d * d) as f64;
    let front_nodes = if d == 2 {
        counts[0] as f64 + 1.0
    } else {
        (counts[0] as f64 + 1.0) * (counts[2] as f64 + 1.0)
    };
    let contact_equations = d as f64 * front_nodes;
    let factor = if d == 3 {
        (entries * SPARSE_ENTRY_BYTES).max(FACTOR_BYTES_3D * dofs.powf(4.0 / 3.0))
    } else {
        entries * SPARSE_ENTRY_BYTES
    };
    let mut terms = vec![
        Term {
            field: "pad.elements",
            what: format!("the pad mesh ({elements:.3e} elements, {nodes:.3e} nodes)"),
            bytes: dofs * NODE_BYTES_PER_DOF + elements * corners * ELEMENT_BYTES_PER_NODE,
        },
        Term {
            field: "pad.elements",
            what: format!(
                "the stiffness matrix ({entries:.3e} entries) and its factorization ({dofs:.3e} \
                 equations)"
            ),
            bytes: entries * SPARSE_ENTRY_BYTES + factor,
        },
    ];
    // the unknowns as the model will count them (`as` saturates on absurd counts)
    let unknowns = (dofs + contact_equations) as usize;
    let preferred = ContactSolve::preferred(case.pad.quasi_static, unknowns);
    if case.solver.contact_solve_with(preferred) == ContactSolve::Reduced {
        terms.push(Term {
            field: "pad.elements",
            what: format!(
                "the dense contact block ({contact_equations:.3e} equations of {front_nodes:.3e} \
                 front-face nodes)"
            ),
            bytes: 3.0 * contact_equations * contact_equations * 8.0,
        });
    }
    if let DrumSurfaceSpec::Tetrahedra {
        sectors,
        rings,
        layers,
        ..
    } = case.drum.surface
    {
        let (s, r, l) = (sectors as f64, rings as f64, layers as f64);
        let tets = 6.0 * s * r * l;
        terms.push(Term {
            field: "drum.surface",
            what: format!("the tetrahedral drum ({tets:.3e} tetrahedra)"),
            bytes: s * (r + 1.0) * (l + 1.0) * 24.0 + tets * 32.0,
        });
    }
    let increments: f64 = case
        .steps
        .iter()
        .map(|step| match step {
            StepSpec::Static { increments, .. } => *increments as f64,
            StepSpec::Dynamic {
                duration,
                dt,
                adaptive,
                ..
            } => (duration / adaptive.map_or(*dt, |a| a.max_dt)).ceil(),
        })
        .sum();
    terms.push(Term {
        field: "steps",
        what: format!("the history ({increments:.3e} increments)"),
        bytes: increments * std::mem::size_of::<Sample>() as f64,
    });
    terms
}

/// The total of [`estimate`], bytes.
pub fn needed(case: &Case) -> f64 {
    estimate(case).iter().map(|t| t.bytes).sum()
}

/// The memory available to a new process, bytes: `MemAvailable` of `/proc/meminfo`, or
/// [`DEFAULT_AVAILABLE`] where it cannot be read.
pub fn available() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| mem_available(&text))
        .unwrap_or(DEFAULT_AVAILABLE)
}

/// `MemAvailable` of a `/proc/meminfo` text, bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?;
    let kib: u64 = line.trim().strip_suffix("kB")?.trim().parse().ok()?;
    kib.checked_mul(1024)
}

/// `bytes` in the largest decimal unit that keeps it above 1: `7.2 TB`.
pub(crate) fn human(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < units.len() {
        value /= 1000.0;
        unit += 1;
    }
    if unit + 1 == units.len() && value >= 1000.0 {
        format!("{bytes:.3e} B")
    } else {
        format!("{value:.1} {}", units[unit])
    }
}

/// Whether `case` fits in `available` bytes.
///
/// # Errors
/// (field, message): the field of the largest term, the estimate term by term and the memory
/// available.
pub fn check(case: &Case, available: u64) -> Result<(), (String, String)> {
    let terms = estimate(case);
    let total: f64 = terms.iter().map(|t| t.bytes).sum();
    if total <= available as f64 {
        return Ok(());
    }
    let largest = terms
        .iter()
        .max_by(|a, b| a.bytes.total_cmp(&b.bytes))
        .map_or("pad.elements", |t| t.field);
    let detail: Vec<String> = terms
        .iter()
        .map(|t| format!("{} {}", t.what, human(t.bytes)))
        .collect();
    Err((
        largest.into(),
        format!(
            "expected a case that fits in memory: it needs an estimated {} ({}), {} available",
            human(total),
            detail.join(", "),
            human(available as f64)
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mem_available_is_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:   22000000 kB\n";
        assert_eq!(mem_available(text), Some(22_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 1 kB\n"), None);
        assert!(available() > 0);
    }

    /// The 3D drum case at `circumferential x radial x axial` with `sets`, as validated.
    fn drum_3d(mesh: [usize; 3], sets: &[&str]) -> Case {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../cases/drum/3d-analytic.json");
        let mut overrides: Vec<String> = ["circumferential", "radial", "axial"]
            .iter()
            .zip(mesh)
            .map(|(name, n)| format!("pad.elements.{name}={n}"))
            .collect();
        overrides.extend(sets.iter().map(|s| s.to_string()));
        crate::validate::load_case(&path, &overrides).expect("the drum case validates")
    }

    fn has_dense_block(case: &Case) -> bool {
        estimate(case)
            .iter()
            .any(|t| t.what.starts_with("the dense contact block"))
    }

    /// The dense contact block is counted where the run forms it: on the reduced path, chosen
    /// or taken by `auto` on a small pad that is not quasi-static.
    #[test]
    fn the_dense_contact_block_is_counted_on_the_reduced_path_only() {
        assert!(has_dense_block(&drum_3d([10, 1, 1], &[])));
        assert!(!has_dense_block(&drum_3d([100, 16, 20], &[])));
        assert!(has_dense_block(&drum_3d(
            [100, 16, 20],
            &["solver.contact_solve=\"reduced\""]
        )));
        assert!(has_dense_block(&drum_3d(
            [100, 16, 20],
            &["solver.coulomb_method=\"conic\""]
        )));
        assert!(!has_dense_block(&drum_3d(
            [10, 1, 1],
            &["solver.contact_solve=\"global\""]
        )));
    }

    /// On a large 3D pad the factorization's fill governs: the memory grows as the equations
    /// to the power 4/3, to within 10 % (the mesh and the matrix grow linearly).
    #[test]
    fn a_large_3d_pad_costs_its_fill() {
        let small = needed(&drum_3d([50, 8, 10], &[]));
        let large = needed(&drum_3d([100, 16, 20], &[]));
        let nodes = (101.0 * 17.0 * 21.0) / (51.0 * 9.0 * 11.0);
        let ratio = (large / small) / f64::powf(nodes, 4.0 / 3.0);
        assert!((0.9..=1.0).contains(&ratio), "{ratio}");
    }

    #[test]
    fn sizes_are_written_in_decimal_units() {
        assert_eq!(human(512.0), "512.0 B");
        assert_eq!(human(7.24e12), "7.2 TB");
        assert_eq!(human(3e21), "3.000e21 B");
    }
}
