//! scatterfit-synth: the synthetic twin of the measuring rig.
//!
//! From known optical parameters it produces what the instruments would record, so that the whole
//! pipeline can be run and tested end to end against a known truth. So far: the spectrophotometer
//! reading ([`spectro`]) and the published materials that drive the demo ([`materials`]). The exposure
//! bracket of the imaging rig follows with the Monte Carlo engine.

pub mod materials;
pub mod spectro;
