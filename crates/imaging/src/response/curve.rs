//! The camera response curve: g(Z) = ln f⁻¹(Z) per channel as a table of [`LEVELS`] values
//! (Debevec & Malik 1997, eq. 2), in the gauge g(128) = 0.

use crate::error::{ImagingError, Result};

/// Number of code values of an 8-bit frame.
pub const LEVELS: usize = 256;

/// A camera response: per channel the 256 values g(z) = ln f⁻¹(z) (log exposure for code value z),
/// Debevec & Malik 1997, eq. (2). Values are defined up to an additive constant per curve (the gauge);
/// see [`ResponseCurve::gauge_offset`].
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseCurve {
    pub(super) g: Vec<[f64; LEVELS]>,
}

impl ResponseCurve {
    /// A response from log exposures g(z) = ln X(z), one table per channel (e.g. read from a
    /// `response.csv`). Any gauge is accepted.
    ///
    /// # Errors
    /// [`ImagingError::InvalidResponse`] if there are no channels, a value is not finite, or g
    /// decreases somewhere (a camera response is monotonic).
    pub fn from_log_exposure(g: Vec<[f64; LEVELS]>) -> Result<Self> {
        if g.is_empty() {
            return Err(ImagingError::InvalidResponse {
                channel: 0,
                z: 0,
                reason: "no channels given",
            });
        }
        for (channel, table) in g.iter().enumerate() {
            for (z, v) in table.iter().enumerate() {
                if !v.is_finite() {
                    return Err(ImagingError::InvalidResponse {
                        channel,
                        z,
                        reason: "value is not finite",
                    });
                }
                if z > 0 && *v < table[z - 1] {
                    return Err(ImagingError::InvalidResponse {
                        channel,
                        z,
                        reason: "g(z) decreases here; a camera response must be non-decreasing",
                    });
                }
            }
        }
        Ok(Self { g })
    }

    /// A response from linear exposures X(z) = f⁻¹(z) = exp g(z), the form OpenCV's
    /// `CalibrateDebevec` returns (docs/physics.md §7.2). Every value must be finite and > 0.
    ///
    /// # Errors
    /// [`ImagingError::InvalidResponse`] as for [`ResponseCurve::from_log_exposure`], or a value ≤ 0.
    pub fn from_linear_exposure(x: Vec<[f64; LEVELS]>) -> Result<Self> {
        let mut g = Vec::with_capacity(x.len());
        for (channel, table) in x.iter().enumerate() {
            let mut t = [0.0; LEVELS];
            for (z, v) in table.iter().enumerate() {
                if !(v.is_finite() && *v > 0.0) {
                    return Err(ImagingError::InvalidResponse {
                        channel,
                        z,
                        reason: "linear exposure must be finite and > 0",
                    });
                }
                t[z] = v.ln();
            }
            g.push(t);
        }
        Self::from_log_exposure(g)
    }

    /// The linear response X(z) = z / 128 (so g(128) = 0, the recovery gauge), with X(0) := X(1) as
    /// OpenCV's `MergeDebevec` does (code 0 has zero weight anyway). For frames that are already linear.
    ///
    /// # Errors
    /// [`ImagingError::InvalidResponse`] if `channels` is 0.
    pub fn linear(channels: usize) -> Result<Self> {
        let mut t = [0.0; LEVELS];
        for (z, v) in t.iter_mut().enumerate() {
            *v = (z.max(1) as f64 / 128.0).ln();
        }
        Self::from_log_exposure(vec![t; channels])
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.g.len()
    }

    /// The table g(0..=255) of channel `c`, or `None` if there is no such channel.
    pub fn log_exposure(&self, c: usize) -> Option<&[f64; LEVELS]> {
        self.g.get(c)
    }

    /// All tables, one per channel.
    pub fn tables(&self) -> &[[f64; LEVELS]] {
        &self.g
    }

    /// The gauge of channel `c`: the value g(128) (0 for recovered curves). Subtract it to compare two
    /// curves.
    pub fn gauge_offset(&self, c: usize) -> Option<f64> {
        self.g.get(c).map(|t| t[128])
    }
}
