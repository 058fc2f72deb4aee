//! What the checks found that a measurement keeps ([`crate::Measurement::image_checks`]).

use scatterfit_io::quality::Reason;

/// Checks that concern the whole sample (the image, the manifest), made once per measurement.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleChecks {
    /// Findings that apply to every channel.
    pub reasons: Vec<Reason>,
}
