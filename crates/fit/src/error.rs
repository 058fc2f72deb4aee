//! The fit crate's error type: inputs a fit cannot start from. A fit that starts and then does not
//! converge is not an error; it is a [`crate::FitReport`] with its termination reason.

/// What makes a fit impossible to start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// An option or input value outside its domain.
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidInput {
        /// The quantity, as the user knows it.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why, and the accepted range.
        reason: &'static str,
    },
    /// The profile's columns disagree in length, or a radius is not increasing.
    #[error("profile: {0}")]
    Profile(String),
    /// Too few rings survive the selection to constrain the unknowns.
    #[error(
        "only {usable} ring(s) of the profile can be fitted (need at least {needed} for {unknowns} \
         unknowns): {inside_spot} inside the light spot, {below_detection} below the detection limit, \
         {invalid} without valid pixels — {hint}"
    )]
    TooFewRings {
        /// Rings left.
        usable: usize,
        /// Rings needed.
        needed: usize,
        /// Unknowns of the method.
        unknowns: usize,
        /// Rings excluded as inside the spot.
        inside_spot: usize,
        /// Rings excluded as below detection.
        below_detection: usize,
        /// Rings without valid data.
        invalid: usize,
        /// What to do.
        hint: &'static str,
    },
}

/// Result with [`FitError`].
pub type Result<T> = std::result::Result<T, FitError>;

pub(crate) fn check(ok: bool, name: &'static str, value: f64, reason: &'static str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(FitError::InvalidInput {
            name,
            value,
            reason,
        })
    }
}
