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
//!
//! A run that writes restart files also appends each sample, as one line of JSON (numbers
//! that read back to the same bits), to [`SAMPLES_JOURNAL`]: a restart point marks how much of
//! it is on disk instead of holding the samples, so that writing one costs what was appended
//! since the last, and a resumed run reads the samples back from it.

use std::io::{self, BufWriter, Write};
use std::path::Path;

use skid_integrator::Model;
use skid_integrator::state::EnergyLedger;
use skid_integrator::stepper::{IncrementReport, Observer};

use crate::append_file::{AppendFile, FileMark};
use crate::contact_totals::pair_totals;
use crate::csv_out::PartialCsv;
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

/// File name of the journal of samples beside the restart file (see the module documentation).
pub const SAMPLES_JOURNAL: &str = "restart-samples.jsonl";

/// The journal of samples of an interrupted run, reopened at a restart point's mark.
pub struct SampleJournal {
    file: BufWriter<AppendFile>,
    samples: Vec<Sample>,
}

impl SampleJournal {
    /// Reopens `dir/`[`SAMPLES_JOURNAL`] at `mark` ([`AppendFile::reopen`]) and reads its
    /// samples back.
    ///
    /// # Errors
    /// As [`AppendFile::reopen`]; an `InvalidData` error naming the line of a sample that does
    /// not read back.
    pub fn reopen(dir: &Path, mark: &FileMark) -> io::Result<Self> {
        let (file, lines) = AppendFile::reopen(&dir.join(SAMPLES_JOURNAL), mark)?;
        let samples = lines
            .split(|&b| b == b'\n')
            .filter(|line| !line.is_empty())
            .enumerate()
            .map(|(k, line)| {
                serde_json::from_slice(line).map_err(|e| {
                    io::Error::new(io::ErrorKind::InvalidData, format!("line {}: {e}", k + 1))
                })
            })
            .collect::<io::Result<_>>()?;
        Ok(Self {
            file: BufWriter::new(file),
            samples,
        })
    }
}

/// Observer writing `history.csv` and keeping the samples.
pub struct DrumRecorder {
    csv: PartialCsv,
    /// Samples of all converged increments (and the initial state).
    pub samples: Vec<Sample>,
    /// The journal of the samples, in a run that writes restart files.
    journal: Option<BufWriter<AppendFile>>,
}

impl DrumRecorder {
    /// Creates `dir/history.csv.partial` and writes the header; with `journal`, also the
    /// journal of samples for restart points.
    ///
    /// # Errors
    /// I/O errors.
    pub fn create(dir: &Path, journal: bool) -> io::Result<Self> {
        let journal = if journal {
            Some(BufWriter::new(AppendFile::create(
                &dir.join(SAMPLES_JOURNAL),
            )?))
        } else {
            None
        };
        Ok(Self {
            csv: PartialCsv::create(&dir.join("history.csv"), &COLUMNS)?,
            samples: Vec::new(),
            journal,
        })
    }

    /// Continues the history of an interrupted run: `dir/history.csv.partial` reopened at
    /// `history` ([`PartialCsv::reopen`]), with the samples of `journal`.
    ///
    /// # Errors
    /// As [`PartialCsv::reopen`].
    pub fn reopen(dir: &Path, history: &FileMark, journal: SampleJournal) -> io::Result<Self> {
        Ok(Self {
            csv: PartialCsv::reopen(&dir.join("history.csv"), history)?,
            samples: journal.samples,
            journal: Some(journal.file),
        })
    }

    /// Flushes the rows so far to disk and returns the file's mark, for a restart point.
    ///
    /// # Errors
    /// I/O errors.
    pub fn mark(&mut self) -> io::Result<FileMark> {
        self.csv.mark()
    }

    /// Flushes the journal of samples to disk and returns its mark, for a restart point.
    ///
    /// # Errors
    /// I/O errors, or a recorder created without a journal.
    pub fn journal_mark(&mut self) -> io::Result<FileMark> {
        let journal = self
            .journal
            .as_mut()
            .ok_or_else(|| io::Error::other("a restart point in a run without restart files"))?;
        journal.flush()?;
        journal.get_ref().mark()
    }

    /// Flushes and renames the files to their final names (`history.csv`, and the journal's).
    ///
    /// # Errors
    /// I/O errors.
    pub fn finish(self) -> io::Result<Vec<Sample>> {
        self.csv.finish()?;
        if let Some(journal) = self.journal {
            journal.into_inner().map_err(|e| e.into_error())?.finish()?;
        }
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
        let sample = Sample {
            time: s.time,
            dynamic: report.dynamic,
            angle,
            omega,
            normal_force: normal,
            energy: e.clone(),
            max_penetration: penetration.max(0.0),
            sliding_separation: separation,
        };
        if let Some(journal) = self.journal.as_mut() {
            serde_json::to_writer(&mut *journal, &sample)?;
            journal.write_all(b"\n")?;
        }
        self.samples.push(sample);
        Ok(())
    }
}
