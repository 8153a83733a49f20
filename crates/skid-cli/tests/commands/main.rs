//! The `skid` command run as a user runs it: its subcommands, bad inputs, batches, reports,
//! reruns and kill-resume, and the module graph of every crate.
//! They are modules of one test binary, linked once.

mod common;

mod bad_input;
mod batch_report;
mod check;
mod cli;
mod determinism;
mod kill_resume;
mod model_files;
mod module_graph;
mod report_sections;
mod sweeps;
