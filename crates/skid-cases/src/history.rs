//! The drum's history: one CSV row per converged increment, and the samples the summary is
//! computed from.
//!
//! `history.csv` has the columns [`COLUMNS`]: the step name as text, the counts (`increment`,
//! `active_contacts`, `sliding_contacts`, `newton_iterations`, `contact_solves`) as integers,
//! `load_factor` with six decimals, `max_penetration` with 4 significant digits, `dt` with 7, and
//! every other number with 10 (`1.234567890e-3`). It is written through [`PartialCsv`] (a step
//! name holding a comma, a quote or a line break is quoted) to `history.csv.partial`, renamed to
//! `history.csv` only when the run has ended (completed, or stopped with an error that the
//! summary reports), so an interrupted process never leaves a file that looks complete.

use std::path::Path;

use skid_integrator::Model;
use skid_integrator::state::EnergyLedger;
use skid_integrator::stepper::{IncrementReport, Observer};

use crate::contact_totals::pair_totals;
use crate::csv_out::{CsvMark, PartialCsv};
use crate::schema::{BACK_PLATE, DRUM};

/// Column names of `history.csv`.
pub const COLUMNS: [&str; 23] = [
    "time",
    "step",
    "increment",
    "load_factor",
    "drum_angle",
    "drum_omega",
    "plate_displacement",
    "normal_force",
    "friction_force",
    "friction_torque",
    "active_contacts",
    "sliding_contacts",
    "newton_iterations",
    "contact_solves",
    "max_penetration",
    "kinetic_energy",
    "strain_energy",
    "hourglass_energy",
    "external_work",
    "friction_dissipation",
    "normal_work",
    "algorithmic_dissipation",
    "dt",
];

/// What the summary needs of one converged increment.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sample {
    /// Time, s.
    pub time: f64,
    /// Whether it belongs to a dynamic step.
    pub dynamic: bool,
    /// Drum angle, rad.
    pub angle: f64,
    /// Drum angular velocity, rad/s.
    pub omega: f64,
    /// Total normal contact force, N.
    pub normal_force: f64,
    /// The energy ledger.
    pub energy: EnergyLedger,
    /// Deepest penetration among the contacts, m (0 if none).
    pub max_penetration: f64,
    /// Largest gap at a contact that carries force while sliding, m.
    pub sliding_separation: f64,
}

/// Observer writing `history.csv` and keeping the samples.
pub struct DrumRecorder {
    csv: PartialCsv,
    /// Samples of all converged increments (and the initial state).
    pub samples: Vec<Sample>,
}

impl DrumRecorder {
    /// Creates `dir/history.csv.partial` and writes the header.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(dir: &Path) -> std::io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::create(&dir.join("history.csv"), &COLUMNS)?,
            samples: Vec::new(),
        })
    }

    /// Continues the history of an interrupted run: `dir/history.csv.partial` reopened at
    /// `mark` ([`PartialCsv::reopen`]), with the samples up to that point.
    ///
    /// # Errors
    /// As [`PartialCsv::reopen`].
    pub fn reopen(dir: &Path, mark: &CsvMark, samples: Vec<Sample>) -> std::io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::reopen(&dir.join("history.csv"), mark)?,
            samples,
        })
    }

    /// Flushes the rows so far to disk and returns the file's mark, for a restart point.
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&mut self) -> std::io::Result<CsvMark> {
        self.csv.mark()
    }

    /// Flushes and renames the file to `history.csv`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> std::io::Result<Vec<Sample>> {
        self.csv.finish()?;
        Ok(self.samples)
    }
}

impl<const D: usize> Observer<D> for DrumRecorder {
    fn on_increment(
        &mut self,
        model: &Model<D>,
        report: &IncrementReport<'_>,
    ) -> std::io::Result<()> {
        let s = report.state;
        let dofs = model.dofs();
        let drum_eq = dofs.body_rotation(DRUM);
        let omega = drum_eq.map_or(0.0, |eq| s.v[eq]);
        let angle = drum_eq.map_or(0.0, |eq| s.x[eq]);
        let torque = drum_eq.map_or(0.0, |eq| s.contact_reaction[eq]);
        let plate = dofs.body_displacement(&s.x, BACK_PLATE)[1];
        let (mut normal, mut friction) = (0.0, 0.0);
        let (mut active, mut sliding) = (0, 0);
        let (mut penetration, mut separation) = (0.0_f64, 0.0_f64);
        for t in pair_totals(model, s) {
            normal += t.normal_force;
            friction += t.tangential_force[0];
            active += t.active;
            sliding += t.sliding;
            penetration = penetration.max(t.max_penetration);
            separation = separation.max(t.max_sliding_separation);
        }
        let e = &s.energy;
        self.csv.record([
            format!("{:.9e}", s.time),
            report.step.to_string(),
            report.increment.to_string(),
            format!("{:.6}", s.load_factor),
            format!("{angle:.9e}"),
            format!("{omega:.9e}"),
            format!("{plate:.9e}"),
            format!("{normal:.9e}"),
            format!("{friction:.9e}"),
            format!("{torque:.9e}"),
            active.to_string(),
            sliding.to_string(),
            report.counters.newton_iterations.to_string(),
            report.counters.contact_solves.to_string(),
            format!("{:.3e}", penetration.max(0.0)),
            format!("{:.9e}", e.kinetic),
            format!("{:.9e}", e.strain),
            format!("{:.9e}", e.hourglass),
            format!("{:.9e}", e.external_work),
            format!("{:.9e}", e.friction_dissipation),
            format!("{:.9e}", e.normal_work),
            format!("{:.9e}", e.algorithmic_dissipation),
            format!("{:.6e}", report.size),
        ])?;
        self.samples.push(Sample {
            time: s.time,
            dynamic: report.dynamic,
            angle,
            omega,
            normal_force: normal,
            energy: e.clone(),
            max_penetration: penetration.max(0.0),
            sliding_separation: separation,
        });
        Ok(())
    }
}
