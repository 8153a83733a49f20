//! The linearised global contact system of one Newton iteration (see [`super`]): the matrix
//! `A` as an operator for GMRES, as explicit entries where an LU factorization needs them, and
//! its quasi-definite approximation `S` (see [`crate::quasi_definite`]) on a pattern built
//! once.
//!
//! `A`, with `n` equations followed by `dim` rows per candidate `c` (weight `rho_c`, branch
//! derivatives `Phi_u`, `Phi_r` of [`LocalLaw`]):
//!
//! ```text
//! A = [ K              -H^T diag(rho) ]
//!     [ Phi_u H         Phi_r diag(rho) ]
//! ```
//!
//! with `K` symmetric and held as its lower triangle. Applied as an operator, `A v` reads `K`
//! once (half the entries of the explicit matrix) and each candidate's rows from its own small
//! dense block of `H`.

use std::sync::Arc;

use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat};
use nalgebra::DVector;
use skid_contact::coulomb::alart_curnier::{LocalBranch, LocalLaw};

use crate::contact_rows::{ContactRows, contact_coordinates};
use crate::model::Model;
use crate::quasi_definite::CONSTRAINT_REGULARIZATION;
use crate::sparse::symmetric_times;

/// One candidate's part of the system.
#[derive(Debug)]
struct Candidate {
    /// The distinct equations, not held, that its rows involve.
    equations: Vec<usize>,
    /// `H[c dim + t, equations[k]]` at `t * equations.len() + k`.
    h: Vec<f64>,
    /// Its branch of the Alart–Curnier function and the derivatives there, with balanced
    /// sliding rows ([`LocalLaw::with_balanced_slide_rows`]).
    law: LocalLaw,
    /// Its weight `rho_c`.
    rho: f64,
}

impl Candidate {
    /// `H_t . v`: row `t` of the candidate's coefficients times `v` on its equations.
    fn row_times(&self, t: usize, v: &[f64]) -> f64 {
        let e = self.equations.len();
        self.h[t * e..(t + 1) * e]
            .iter()
            .zip(&self.equations)
            .map(|(h, &eq)| h * v[eq])
            .sum()
    }

    /// The coefficient of row `t` on its `k`-th equation.
    fn coefficient(&self, t: usize, k: usize) -> f64 {
        self.h[t * self.equations.len() + k]
    }
}

/// `A` of one Newton iteration: `K` (lower triangle) and every candidate's block.
#[derive(Debug)]
pub(super) struct LinearSystem<'a> {
    k: SparseColMatRef<'a, usize, f64>,
    /// Components per candidate.
    d: usize,
    candidates: Vec<Candidate>,
}

impl<'a> LinearSystem<'a> {
    /// The system at an iterate: `k` the lower triangle of the effective tangent, `rows` the
    /// contact rows, `r` the current forces, `rho` the candidates' weights, `held` the held
    /// equations (left out of the rows).
    pub(super) fn new<const D: usize>(
        model: &Model<D>,
        k: SparseColMatRef<'a, usize, f64>,
        rows: &ContactRows,
        r: &DVector<f64>,
        rho: &[f64],
        held: &[bool],
    ) -> Self {
        let d = rows.components;
        let pairs = model
            .contacts()
            .iter()
            .enumerate()
            .flat_map(|(p, pair)| pair.nodes.iter().map(move |&node| (p, node)));
        let candidates = pairs
            .enumerate()
            .take(rows.len())
            .map(|(c, (pair, node))| {
                let mut equations: Vec<usize> = contact_coordinates(model, pair, node)
                    .into_iter()
                    .flatten()
                    .filter(|&eq| !held[eq])
                    .collect();
                equations.sort_unstable();
                equations.dedup();
                let mut h = vec![0.0; d * equations.len()];
                for t in 0..d {
                    for &(eq, value) in &rows.rows[c * d + t] {
                        if let Ok(k) = equations.binary_search(&eq) {
                            h[t * equations.len() + k] += value;
                        }
                    }
                }
                let block = c * d..(c + 1) * d;
                // a candidate exactly at the kink (touching, no force yet) is taken as
                // closing: as open, the step would let it pass through the surface unresisted
                let law = LocalLaw::evaluate_at_kink(
                    d,
                    rows.mu[c],
                    rho[c],
                    &r.as_slice()[block.clone()],
                    &rows.u.as_slice()[block],
                    LocalBranch::Frictionless,
                )
                .with_balanced_slide_rows(d);
                Candidate {
                    equations,
                    h,
                    law,
                    rho: rho[c],
                }
            })
            .collect();
        Self { k, d, candidates }
    }

    /// Number of equations `n` before the contact rows.
    pub(super) fn equations(&self) -> usize {
        self.k.ncols()
    }

    /// Dimension of `A`.
    pub(super) fn dim(&self) -> usize {
        self.equations() + self.d * self.candidates.len()
    }

    /// Number of candidates.
    pub(super) fn candidates(&self) -> usize {
        self.candidates.len()
    }

    /// The branch of candidate `c`.
    pub(super) fn branch(&self, c: usize) -> LocalBranch {
        self.candidates[c].law.branch
    }

    /// The sliding candidates and their laws.
    pub(super) fn sliding(&self) -> impl Iterator<Item = (usize, &LocalLaw)> {
        (self.candidates.iter().enumerate())
            .filter(|(_, c)| c.law.branch == LocalBranch::Slide)
            .map(|(c, candidate)| (c, &candidate.law))
    }

    /// The right-hand side `[-(R - H^T r), -Phi]` for the residual `residual` without contact
    /// and the current forces `r`.
    pub(super) fn right_hand_side(
        &self,
        residual: &DVector<f64>,
        r: &DVector<f64>,
    ) -> DVector<f64> {
        let (n, d) = (self.equations(), self.d);
        let mut rhs = DVector::zeros(self.dim());
        for i in 0..n {
            rhs[i] = -residual[i];
        }
        for (c, candidate) in self.candidates.iter().enumerate() {
            for t in 0..d {
                rhs[n + c * d + t] = -candidate.law.phi[t];
                for (k, &eq) in candidate.equations.iter().enumerate() {
                    rhs[eq] += candidate.coefficient(t, k) * r[c * d + t];
                }
            }
        }
        rhs
    }

    /// `out = A v`.
    pub(super) fn apply(&self, v: &DVector<f64>, out: &mut DVector<f64>) {
        let (n, d) = (self.equations(), self.d);
        symmetric_times(self.k, &v.as_slice()[..n], &mut out.as_mut_slice()[..n]);
        let v = v.as_slice();
        for (c, candidate) in self.candidates.iter().enumerate() {
            let rows = n + c * d;
            let mut h_v = [0.0; 3];
            for (t, h_t) in h_v.iter_mut().enumerate().take(d) {
                *h_t = candidate.row_times(t, v);
                let force = candidate.rho * v[rows + t];
                let e = candidate.equations.len();
                for (h, &eq) in candidate.h[t * e..(t + 1) * e]
                    .iter()
                    .zip(&candidate.equations)
                {
                    out[eq] -= h * force;
                }
            }
            let law = &candidate.law;
            for t in 0..d {
                out[rows + t] = (0..d)
                    .map(|s| law.d_u[t][s] * h_v[s] + law.d_r[t][s] * candidate.rho * v[rows + s])
                    .sum();
            }
        }
    }

    /// The entries `(row, column)` and values of `A`, duplicates to be summed: both triangles
    /// of `K`, then each candidate's rows and force columns, every coefficient of its
    /// equations included (zero or not), so that the pattern depends only on which equations
    /// each candidate involves.
    pub(super) fn entries(&self) -> (Vec<Pair<usize, usize>>, Vec<f64>) {
        let (n, d, k) = (self.equations(), self.d, self.k);
        let lower = k.compute_nnz();
        let coefficients: usize = self.candidates.iter().map(|c| d * c.equations.len()).sum();
        let capacity = 2 * lower + 2 * coefficients + self.candidates.len() * d * d;
        let mut pairs = Vec::with_capacity(capacity);
        let mut values = Vec::with_capacity(capacity);
        let mut push = |i: usize, j: usize, v: f64| {
            pairs.push(Pair::new(i, j));
            values.push(v);
        };
        for j in 0..n {
            for (&i, &v) in k.row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                push(i, j, v);
                if i != j {
                    push(j, i, v);
                }
            }
        }
        for (c, candidate) in self.candidates.iter().enumerate() {
            let law = &candidate.law;
            for t in 0..d {
                let row = n + c * d + t;
                for (k, &eq) in candidate.equations.iter().enumerate() {
                    push(eq, row, -candidate.rho * candidate.coefficient(t, k));
                    let du = (0..d)
                        .map(|s| law.d_u[t][s] * candidate.coefficient(s, k))
                        .sum();
                    push(row, eq, du);
                }
                for s in 0..d {
                    push(row, n + c * d + s, law.d_r[t][s] * candidate.rho);
                }
            }
        }
        (pairs, values)
    }

    /// True if `layout` is the pattern of this system's `S`.
    fn fits(&self, layout: &ApproximationLayout) -> bool {
        let k = self.k.symbolic();
        layout.d == self.d
            && layout.k_col_ptr == k.col_ptr()
            && layout.equations.len() == self.candidates.len()
            && (layout.equations.iter().zip(&self.candidates))
                .all(|(equations, c)| *equations == c.equations)
            && (0..self.equations()).all(|j| {
                let start = layout.symbolic.col_ptr()[j];
                let rows = k.row_idx_of_col_raw(j);
                layout.symbolic.row_idx()[start..start + rows.len()] == *rows
            })
    }

    /// Writes into `values` those of `S` (see [`crate::quasi_definite`]) on `layout`, which
    /// must fit this system.
    fn approximation(&self, layout: &ApproximationLayout, values: &mut Vec<f64>) {
        let (n, d, k) = (self.equations(), self.d, self.k);
        values.clear();
        values.resize(layout.symbolic.row_idx().len(), 0.0);
        for j in 0..n {
            let start = layout.symbolic.col_ptr()[j];
            let column = k.val_of_col(j);
            values[start..start + column.len()].copy_from_slice(column);
        }
        let mut coupling = layout.coupling.iter();
        let mut diagonal = layout.diagonal.iter();
        for candidate in &self.candidates {
            let (law, rho) = (&candidate.law, candidate.rho);
            // across a sliding direction, the softened constraint of the balanced rows
            let slide = law.slide.filter(|_| d == 3);
            let projector = |t: usize, s: usize| match slide {
                Some(frame) => f64::from(u8::from(s == t)) - frame.d[t - 1] * frame.d[s - 1],
                None => 0.0,
            };
            let constraint = |t: usize| match law.branch {
                LocalBranch::Open => false,
                LocalBranch::Stick => true,
                LocalBranch::Frictionless | LocalBranch::Slide => t == 0,
            };
            for t in 0..d {
                for k in 0..candidate.equations.len() {
                    let value = if constraint(t) {
                        -rho * candidate.coefficient(t, k)
                    } else if t > 0 && slide.is_some() {
                        -rho * (1..d)
                            .map(|s| projector(t, s) * candidate.coefficient(s, k))
                            .sum::<f64>()
                    } else {
                        0.0
                    };
                    if let Some(&position) = coupling.next() {
                        values[position] = value;
                    }
                }
            }
            for (t, s) in block_entries(d) {
                let value = match slide {
                    Some(frame) if t > 0 => {
                        let along = frame.d[t - 1] * frame.d[s - 1];
                        let c_soft = (1.0 - frame.f) / frame.f + CONSTRAINT_REGULARIZATION;
                        along + c_soft * projector(t, s)
                    }
                    _ if s == t && constraint(t) => CONSTRAINT_REGULARIZATION,
                    _ if s == t => 1.0,
                    _ => 0.0,
                };
                if let Some(&position) = diagonal.next() {
                    values[position] = -value * rho;
                }
            }
        }
    }
}

/// The entries `(t, s)` of a candidate's diagonal block in the lower triangle of `S`, row by
/// row: each row's own diagonal and, in 3D, the coupling `(2, 1)` of the tangential rows (their
/// `d d^T + (c + eps) P` while sliding).
fn block_entries(d: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..d).flat_map(move |t| {
        let columns = if t > 0 && d == 3 { 1..=t } else { t..=t };
        columns.map(move |s| (t, s))
    })
}

/// The pattern of `S` (lower triangle) for a pattern of `K` and the equations of each
/// candidate, with the positions of its contact entries: column `j < n` holds `K`'s column `j`
/// followed by the rows of every candidate involving equation `j`; the contact columns hold
/// each candidate's diagonal block.
#[derive(Debug)]
pub(super) struct ApproximationLayout {
    d: usize,
    k_col_ptr: Vec<usize>,
    equations: Vec<Vec<usize>>,
    /// The pattern, shared with the factorization that analysed it.
    pub(super) symbolic: Arc<SymbolicSparseColMat<usize>>,
    /// Value positions of the coupling entries, by candidate, row and equation.
    coupling: Vec<usize>,
    /// Value positions of the diagonal blocks' entries, by candidate and row.
    diagonal: Vec<usize>,
}

impl ApproximationLayout {
    /// The layout of `system`'s `S`. Its columns list their rows in increasing order, since
    /// `K`'s columns do (faer's compressed format) and every contact row follows the equations.
    fn new(system: &LinearSystem<'_>) -> Self {
        let (n, d, k) = (system.equations(), system.d, system.k);
        let dim = system.dim();
        // per column j < n: the (candidate, row, index among its equations) coupling to it
        let mut coupled: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); n];
        for (c, candidate) in system.candidates.iter().enumerate() {
            for (index, &eq) in candidate.equations.iter().enumerate() {
                coupled[eq].extend((0..d).map(|t| (c, t, index)));
            }
        }
        let mut coupling: Vec<Vec<usize>> = (system.candidates.iter())
            .map(|c| vec![0; d * c.equations.len()])
            .collect();
        let mut col_ptr = Vec::with_capacity(dim + 1);
        let mut row_idx = Vec::with_capacity(k.compute_nnz() + 2 * d * n);
        col_ptr.push(0);
        for (j, couplings) in coupled.iter().enumerate() {
            row_idx.extend_from_slice(k.row_idx_of_col_raw(j));
            for &(c, t, index) in couplings {
                coupling[c][t * system.candidates[c].equations.len() + index] = row_idx.len();
                row_idx.push(n + c * d + t);
            }
            col_ptr.push(row_idx.len());
        }
        // the diagonal blocks, column by column; their positions listed row by row
        let entries: Vec<(usize, usize)> = block_entries(d).collect();
        let mut by_column = entries.clone();
        by_column.sort_by_key(|&(t, s)| (s, t));
        let offsets: Vec<usize> = (entries.iter())
            .map(|e| by_column.iter().position(|b| b == e).unwrap_or_default())
            .collect();
        let mut diagonal = Vec::new();
        for c in 0..system.candidates.len() {
            let first = row_idx.len();
            for s in 0..d {
                let rows = by_column.iter().filter(|&&(_, column)| column == s);
                row_idx.extend(rows.map(|&(t, _)| n + c * d + t));
                col_ptr.push(row_idx.len());
            }
            diagonal.extend(offsets.iter().map(|offset| first + offset));
        }
        Self {
            d,
            k_col_ptr: k.symbolic().col_ptr().to_vec(),
            equations: (system.candidates.iter())
                .map(|c| c.equations.clone())
                .collect(),
            symbolic: Arc::new(SymbolicSparseColMat::new_checked(
                dim, dim, col_ptr, None, row_idx,
            )),
            coupling: coupling.concat(),
            diagonal,
        }
    }
}

/// The layout of `S` kept across systems, rebuilt when a system's pattern differs, and the
/// storage of its values.
#[derive(Debug, Default)]
pub(super) struct Approximation {
    layout: Option<ApproximationLayout>,
    values: Vec<f64>,
}

impl Approximation {
    /// The pattern of `system`'s `S` and its values.
    pub(super) fn of(
        &mut self,
        system: &LinearSystem<'_>,
    ) -> (&Arc<SymbolicSparseColMat<usize>>, &[f64]) {
        let layout = match self.layout.take() {
            Some(layout) if system.fits(&layout) => layout,
            _ => ApproximationLayout::new(system),
        };
        system.approximation(&layout, &mut self.values);
        let layout = self.layout.insert(layout);
        (&layout.symbolic, &self.values)
    }
}
