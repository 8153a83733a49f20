//! Restart files: how an interrupted run is continued (`skid run --resume DIR`).
//!
//! A run writes `restart.json` into its output directory every [`DEFAULT_RESTART_EVERY`]
//! converged increments (or as asked; 0 writes none), at the initial state and at the end of
//! every step, each time whole ([`crate::atomic`]). It holds:
//!
//! - the integrator's [`Checkpoint`]: the state (every vector, the contact candidates, the
//!   warm-start forces, the energy ledger), the stepper's position in its step (progress,
//!   next increment size, growth counter, an adaptive step's last mean acceleration), the
//!   counters for the summary and the solver's memory (the last factorized matrix);
//! - what the outputs hold at that point: the length and hash of `history.csv.partial` and
//!   `newton.csv.partial` ([`FileMark`]), what the summary is computed from (a drum case's
//!   samples, as the mark of their journal [`crate::history::SAMPLES_JOURNAL`], so that a
//!   restart file does not grow with the run; a model file's record), the field frames written;
//! - the identity of the run: the hash of the input as run (`case.json` or `model.json` in the
//!   same directory), the skid version and the restart interval.
//!
//! Numbers are JSON numbers written in the shortest form that reads back to the same bits
//! (`serde_json`'s `float_roundtrip`); a non-finite one, which no converged state holds, is
//! written as `null` and refused on reading. The continued run writes the same `history.csv`,
//! `newton.csv`, `summary.json` (wall times aside) and field frames, byte for byte, as the
//! uninterrupted run, at one factorization thread (`--threads 1`).

use std::path::Path;

use serde::{Deserialize, Serialize};
use skid_integrator::stepper::Checkpoint;

use crate::append_file::FileMark;
use crate::atomic::write_atomic;
use crate::fields::FieldMemory;
use crate::model_file::history::RunRecord;

/// File name of the restart file in a run's output directory.
pub const RESTART_JSON: &str = "restart.json";
/// Converged increments between restart files when the command line does not say.
pub const DEFAULT_RESTART_EVERY: usize = 100;
/// Version of the restart file's layout.
pub const RESTART_FORMAT: u32 = 6;

/// The input a run was started with: the file in its output directory and its hash.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputIdentity {
    /// `case.json` or `model.json`.
    pub file: String,
    /// FNV-1a hash of that file's text ([`crate::fingerprint::Fnv1a`]).
    pub fnv1a: String,
}

/// What the history observer has accumulated for the summary.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RecorderMemory {
    /// A drum case: how much of its journal of samples is on disk.
    Drum(FileMark),
    /// A model file: its record so far.
    Model(Box<RunRecord>),
}

/// The contents of `restart.json` (see the module documentation).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RestartFile {
    /// [`RESTART_FORMAT`].
    pub format: u32,
    /// The skid version that wrote it: another may take another path through the run.
    pub skid_version: String,
    /// The input as run.
    pub input: InputIdentity,
    /// Converged increments between restart files (0: none but the one at the start).
    pub restart_every: usize,
    /// `history.csv.partial` at this point.
    pub history: FileMark,
    /// `newton.csv.partial` at this point.
    pub newton: FileMark,
    /// The history observer's memory.
    pub recorder: RecorderMemory,
    /// The field writer's memory, if the run writes fields.
    pub fields: Option<FieldMemory>,
    /// The integrator's checkpoint.
    pub checkpoint: Checkpoint,
}

impl RestartFile {
    /// Writes this restart file into `dir`, whole or not at all.
    ///
    /// # Errors
    /// I/O errors, or a value serde cannot write.
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string(self).map_err(std::io::Error::other)?;
        write_atomic(&dir.join(RESTART_JSON), text)
    }

    /// Reads `dir/restart.json`, checking that this version of skid wrote it in this layout.
    ///
    /// # Errors
    /// A message saying why the file cannot be used.
    pub fn read(dir: &Path) -> Result<Self, String> {
        let path = dir.join(RESTART_JSON);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(format!(
                    "no {RESTART_JSON}: the run was interrupted before its first restart point \
                     or writes none (--restart-every 0); start it again without --resume"
                ));
            }
            Err(e) => return Err(format!("{}: {e}", path.display())),
        };
        #[derive(Deserialize)]
        struct Header {
            format: u32,
            skid_version: String,
        }
        let header: Header = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a restart file: {e}", path.display()))?;
        if header.format != RESTART_FORMAT || header.skid_version != env!("CARGO_PKG_VERSION") {
            return Err(format!(
                "{}: written by skid {} (format {}), this is skid {} (format {RESTART_FORMAT})",
                path.display(),
                header.skid_version,
                header.format,
                env!("CARGO_PKG_VERSION")
            ));
        }
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f64_survives_the_restart_json_bit_for_bit() {
        // serde_json with `float_roundtrip` writes the shortest decimal that reads back exactly
        let mut bits = 0x9e37_79b9_7f4a_7c15_u64;
        let mut values = vec![0.0, -0.0, f64::MIN_POSITIVE, 5e-324, f64::MAX, 1.0 / 3.0];
        for _ in 0..10_000 {
            bits ^= bits << 13;
            bits ^= bits >> 7;
            bits ^= bits << 17;
            let v = f64::from_bits(bits);
            if v.is_finite() {
                values.push(v);
            }
        }
        let text = serde_json::to_string(&values).expect("write");
        let back: Vec<f64> = serde_json::from_str(&text).expect("read");
        for (a, b) in values.iter().zip(&back) {
            assert_eq!(a.to_bits(), b.to_bits(), "{a:e} came back as {b:e}");
        }
    }

    #[test]
    fn a_non_finite_number_is_refused_on_reading_not_a_panic() {
        let text = serde_json::to_string(&[1.0, f64::NAN, f64::INFINITY]).expect("write");
        assert_eq!(text, "[1.0,null,null]");
        assert!(serde_json::from_str::<Vec<f64>>(&text).is_err());
    }

    #[test]
    fn a_missing_or_foreign_restart_file_is_a_message() {
        let dir = tempfile::tempdir().expect("tempdir");
        let missing = RestartFile::read(dir.path()).expect_err("no file");
        assert!(missing.contains("no restart.json"), "{missing}");
        std::fs::write(
            dir.path().join(RESTART_JSON),
            r#"{"format": 1, "skid_version": "0.0.0-other"}"#,
        )
        .expect("write");
        let foreign = RestartFile::read(dir.path()).expect_err("other version");
        assert!(foreign.contains("written by skid 0.0.0-other"), "{foreign}");
        std::fs::write(dir.path().join(RESTART_JSON), "{\"format\": 1, ").expect("write");
        let cut = RestartFile::read(dir.path()).expect_err("cut short");
        assert!(cut.contains("not a restart file"), "{cut}");
    }
}
