//! Reports written from real runs: verification scenes, model runs and their outputs.

mod model_runs;
mod outputs;
mod verification;
