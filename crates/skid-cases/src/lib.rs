//! Inputs and runs: the formats (case files, model files, decks) read into the scene that is
//! run, the run itself, and the outputs it writes.
//!
//! - [`schema`]: the JSON case-file format;
//! - [`validate`]: reading a case with field-level error messages and overrides;
//! - [`deck`]: Abaqus-style input decks (the keyword subset of the scenes) read into a model
//!   file, and models written as decks;
//! - [`model_spec`]: the general model format (any scene), the serialization of `ModelSpec`;
//! - [`model_file`]: reading model files and building them into a model, and their outputs;
//! - [`drum`]: the drum scene of a case (any idealization, 2D or 3D) as a model file or deck;
//! - [`history`]: the per-increment history of the drum (`history.csv`);
//! - [`contact_totals`]: every contact pair's resultants in a state, for any history;
//! - [`newton`]: the Newton residuals of every increment (`newton.csv`);
//! - [`atomic`]: output files that are complete or absent (written aside, then renamed);
//! - [`csv_out`]: CSV tables, written quoted and complete-or-absent, read by column name;
//! - [`spin_down`]: stop time, deceleration and post-stop motion from a body's rotation;
//! - [`summary`]: stop time, spin-down straightness, post-stop motion, energy balance;
//! - [`fields`]: ParaView field output (VTU frames and a PVD collection);
//! - [`scene`]: any input read and built into the scene that is run;
//! - [`runner`]: running one case into an output directory, or resuming an interrupted run;
//! - [`restart`]: the restart files an interrupted run is resumed from;
//! - [`fingerprint`]: the hash that tells whether a file is the one a restart was made with;
//! - [`sweep`]: parameter sweeps over the fields of a case, model file or deck;
//! - [`batch`]: running many cases in parallel, sweeps expanded, one shard of them or all;
//! - [`peak_memory`]: the peak resident memory of this process, and of one piece of work;
//! - [`check`]: reading and building an input without running it;
//! - [`reference`]: the JSON Schemas of case and model files and their markdown reference,
//!   generated from the types;
//!
//! The reports made from the runs' outputs are the crate `skid-report`'s.

pub mod append_file;
pub mod atomic;
pub mod batch;
pub mod check;
pub mod contact_totals;
pub mod csv_out;
pub mod deck;
pub mod drum;
pub mod fields;
pub mod fingerprint;
pub mod history;
pub mod model_file;
pub mod model_spec;
pub mod newton;
pub mod peak_memory;
pub mod reference;
pub mod restart;
pub mod runner;
pub mod scene;
pub mod schema;
pub mod spin_down;
pub mod summary;
pub mod sweep;
pub mod validate;

pub use batch::{BatchEntry, BatchError, BatchStatus, Shard, collect_case_files, run_batch};
pub use runner::{
    Resumed, RunSummary, default_output_dir, resume_run, run_case, run_case_file, run_file,
};
pub use scene::read_deck_model;
pub use schema::Case;
pub use summary::Summary;
pub use validate::{CaseError, load_case, parse_case};
