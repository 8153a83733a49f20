//! The Newton residual history (`newton.csv`): one row per convergence check of every converged
//! increment, so that the convergence rate of the Newton iteration can be read off any increment.
//!
//! Columns: `step`, `increment`, `time` (end of the increment, s), `size` (time increment, or
//! load-factor fraction in a static step), `iteration` (1 for the check after the first Newton
//! update), `force_residual` (`max_i |R_i - (H^T r)_i|` scaled by the largest force in play)
//! and `contact_residual` (largest difference between the actual and the linearised gaps and
//! slips, over the model size): the two measures the increment's convergence test compares with
//! its tolerances ([`skid_integrator::increment`]), and `status`: `converged` for the checks of
//! an increment that converged, or, for those of a failed attempt (before its cutback),
//! `rejected: ` and the kind of failure ([`skid_integrator::IncrementFailure::kind`]); an attempt
//! that failed before its first check has no rows. `time` has 10 significant digits, `size` and
//! the residuals 7. Written through [`PartialCsv`], which quotes a step name holding a comma, a
//! quote or a line break.

use std::path::Path;

use skid_integrator::Model;
use skid_integrator::stepper::{IncrementReport, Observer, RejectionReport};

use crate::append_file::FileMark;
use crate::csv_out::PartialCsv;

/// File name of the Newton residual history.
pub const NEWTON_CSV: &str = "newton.csv";

/// Column names of `newton.csv`.
pub const COLUMNS: [&str; 8] = [
    "step",
    "increment",
    "time",
    "size",
    "iteration",
    "force_residual",
    "contact_residual",
    "status",
];

/// `status` of the rows of a converged increment.
pub const CONVERGED: &str = "converged";

/// Observer writing `newton.csv`.
pub struct NewtonRecorder {
    csv: PartialCsv,
}

impl NewtonRecorder {
    /// Creates `dir/newton.csv.partial` and writes the header.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(dir: &Path) -> std::io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::create(&dir.join(NEWTON_CSV), &COLUMNS)?,
        })
    }

    /// Continues the residual history of an interrupted run: `dir/newton.csv.partial`
    /// reopened at `mark` ([`PartialCsv::reopen`]).
    ///
    /// # Errors
    /// As [`PartialCsv::reopen`].
    pub fn reopen(dir: &Path, mark: &FileMark) -> std::io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::reopen(&dir.join(NEWTON_CSV), mark)?,
        })
    }

    /// Flushes the rows so far to disk and returns the file's mark, for a restart point.
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&mut self) -> std::io::Result<FileMark> {
        self.csv.mark()
    }

    /// Flushes and renames the file to `newton.csv`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> std::io::Result<()> {
        self.csv.finish()
    }
}

impl NewtonRecorder {
    /// One row per convergence check of `residuals`.
    fn record(
        &mut self,
        (step, increment, time, size): (&str, usize, f64, f64),
        residuals: &[(f64, f64)],
        status: &str,
    ) -> std::io::Result<()> {
        for (k, (force, contact)) in residuals.iter().enumerate() {
            self.csv.record([
                step.to_string(),
                increment.to_string(),
                format!("{time:.9e}"),
                format!("{size:.6e}"),
                (k + 1).to_string(),
                format!("{force:.6e}"),
                format!("{contact:.6e}"),
                status.to_string(),
            ])?;
        }
        Ok(())
    }
}

impl<const D: usize> Observer<D> for NewtonRecorder {
    fn on_increment(
        &mut self,
        _model: &Model<D>,
        report: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        self.record(
            (
                report.step,
                report.increment,
                report.state.time,
                report.size,
            ),
            &report.counters.residuals,
            CONVERGED,
        )
    }

    fn on_rejection(
        &mut self,
        _model: &Model<D>,
        report: &RejectionReport<'_>,
    ) -> std::io::Result<()> {
        self.record(
            (report.step, report.increment, report.time, report.size),
            &report.rejection.residuals,
            &format!("rejected: {}", report.rejection.failure.kind()),
        )
    }
}
