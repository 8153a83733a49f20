//! Input files run end to end: drum case files, model files and decks, built into models and run.
//! They are modules of one test binary, so the solver is compiled and linked once; the fuzz
//! campaign (`fuzz_inputs`) stays a binary of its own, which `scripts/fuzz.sh` builds alone.

mod common;
mod deck_text;

mod amplitude_time;
mod analytical_surfaces;
mod case_files;
mod decks;
mod drum;
mod element_surfaces;
mod fields;
mod free_drum;
mod hourglass;
mod incompressible;
mod initial_velocity;
mod instances;
mod loads;
mod materials;
mod model_fields;
mod model_file;
mod node_motions;
mod parts;
mod prescribed;
mod reference;
mod two_pads;
