//! scatterfit-imaging: pure pixel work on buffers.
//!
//! Camera response recovery and HDR merging (Debevec & Malik 1997), the light spot's centre, and the
//! radial profile Rd(r). No file formats here: `scatterfit-io` decodes files into [`ImageBuf`]s.

pub mod buffer;

pub use buffer::{ImageBuf, ShapeError};
