//! scatterfit-io: every file format of scatterfit.
//!
//! Parsing lives here, at the edge; the physics crates (`scatterfit-optics`, `scatterfit-imaging`,
//! `scatterfit-mc`) take typed values and buffers and never touch files. Every error names the file,
//! and where it can the line, column or field, what was wrong and what to do about it.
//!
//! Outputs are written atomically ([`atomic::write_atomic`]); inputs are only ever read.

pub mod atomic;
pub mod bracket;
pub mod budget;
pub mod csv_dialect;
pub mod digest;
pub mod escape;
pub mod export;
pub mod flags;
pub mod image_files;
pub mod inputs;
pub mod manifest;
pub mod mesh;
pub mod profile_csv;
pub mod quality;
pub mod raw;
pub mod response_csv;
pub mod result_json;
pub mod result_set;
pub mod result_table;
pub mod sample_folder;
pub mod spectro;
pub mod text;
