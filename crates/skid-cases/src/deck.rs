//! Abaqus-style input decks, read into the same [`crate::model_file::ModelSpec`] as model files.
//!
//! - [`keywords`]: the keyword layer: keyword blocks with parameters and data lines, comments,
//!   continuation lines and `*INCLUDE`, each with its file and line.
//!
//! The semantic layer (the keyword subset of the drum scenes mapped onto a model) builds on it.

pub mod keywords;
