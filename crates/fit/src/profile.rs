//! A measured radial profile of one channel, and the choice of rings a fit may use.
//!
//! The HDR profile is in relative units (radiance per ring, unknown gain); each ring carries its
//! standard error and, when the bracket knows it, a detection limit: the radiance below which the
//! longest exposure cannot tell signal from its noise floor. Far rings of an absorbing channel sit
//! there; their mean is dominated by quantisation and noise, not by the sample, so they are
//! excluded and counted rather than fitted (fitting them as values biases σa).

use serde::{Deserialize, Serialize};

use crate::error::{FitError, Result, check};

/// One ring of a measured profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ring {
    /// Ring radius \[mm\] (mean distance of its pixels from the spot centre).
    pub r_mm: f64,
    /// Mean value of the ring's pixels [relative radiance]; NaN when there is none.
    pub value: f64,
    /// Standard error of `value` [same units]; NaN when undefined.
    pub stderr: f64,
    /// Pixels averaged.
    pub count: u64,
    /// Detection limit [same units as `value`]: below it the ring is not measured. NaN or 0 when
    /// unknown (then only non-positive values are excluded).
    pub detection_limit: f64,
}

/// A measured radial profile of one channel, rings from the centre out. Made by
/// [`ProfileData::new`] (also when read from JSON), so its radii are finite, ≥ 0 and increasing.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(try_from = "ProfileDataFields")]
pub struct ProfileData {
    rings: Vec<Ring>,
}

/// [`ProfileData`] as written, before its checks.
#[derive(Deserialize)]
struct ProfileDataFields {
    rings: Vec<Ring>,
}

impl TryFrom<ProfileDataFields> for ProfileData {
    type Error = FitError;
    fn try_from(f: ProfileDataFields) -> Result<Self> {
        Self::new(f.rings)
    }
}

impl ProfileData {
    /// A profile from its rings.
    ///
    /// # Errors
    /// [`FitError::Profile`] if a radius is negative, not finite, or not increasing.
    pub fn new(rings: Vec<Ring>) -> Result<Self> {
        for (i, w) in rings.windows(2).enumerate() {
            if w[1].r_mm <= w[0].r_mm || w[1].r_mm.is_nan() {
                return Err(FitError::Profile(format!(
                    "ring radii must increase: ring {} at {} mm follows {} mm",
                    i + 1,
                    w[1].r_mm,
                    w[0].r_mm
                )));
            }
        }
        if let Some(r) = rings
            .iter()
            .find(|r| !(r.r_mm.is_finite() && r.r_mm >= 0.0))
        {
            return Err(FitError::Profile(format!(
                "ring radius {} mm is not a finite number ≥ 0",
                r.r_mm
            )));
        }
        Ok(Self { rings })
    }

    /// The rings.
    pub fn rings(&self) -> &[Ring] {
        &self.rings
    }
}

/// Which rings a fit may use. Made by [`RingSelection::new`] or [`RingSelection::for_spot`] and
/// changed through the checked `with_*` methods (also when read from JSON), so it is always valid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RingSelectionFields")]
pub struct RingSelection {
    r_min_mm: f64,
    r_max_mm: f64,
    detection_factor: f64,
    relative_error_floor: f64,
}

/// [`RingSelection`] as written, before its checks.
#[derive(Deserialize)]
struct RingSelectionFields {
    r_min_mm: f64,
    r_max_mm: f64,
    detection_factor: f64,
    relative_error_floor: f64,
}

impl TryFrom<RingSelectionFields> for RingSelection {
    type Error = FitError;
    fn try_from(f: RingSelectionFields) -> Result<Self> {
        Self::new(
            f.r_min_mm,
            f.r_max_mm,
            f.detection_factor,
            f.relative_error_floor,
        )
    }
}

impl RingSelection {
    /// The default error floor: 0.5 % (calibration and merge accuracy).
    pub const DEFAULT_ERROR_FLOOR: f64 = 5e-3;

    /// [`RingSelection::for_spot`] of the default spot (radius [`crate::DEFAULT_SPOT_RADIUS_MM`]).
    pub const DEFAULT: Self = Self {
        r_min_mm: 2.0 * crate::DEFAULT_SPOT_RADIUS_MM,
        r_max_mm: f64::INFINITY,
        detection_factor: 1.0,
        relative_error_floor: Self::DEFAULT_ERROR_FLOOR,
    };

    /// Fit the rings from `r_min_mm` to `r_max_mm` (∞: every ring of the profile) \[mm\] whose value is
    /// at least `detection_factor` × their detection limit, each weighted with a relative standard
    /// error of at least `relative_error_floor` (a ring's weight never exceeds 1/floor² in the log
    /// residual).
    ///
    /// # Errors
    /// [`FitError::InvalidInput`] for r_min not finite and ≥ 0, r_max not above r_min, a factor not
    /// finite and ≥ 0, or a floor not finite and > 0.
    pub fn new(
        r_min_mm: f64,
        r_max_mm: f64,
        detection_factor: f64,
        relative_error_floor: f64,
    ) -> Result<Self> {
        let s = Self {
            r_min_mm,
            r_max_mm,
            detection_factor,
            relative_error_floor,
        };
        s.validate()?;
        Ok(s)
    }

    /// The defaults for a uniform light spot of radius `spot_radius_mm`: fit from one spot diameter
    /// out, every ring above its detection limit, 0.5 % error floor.
    ///
    /// # Errors
    /// As [`RingSelection::new`] (a radius that is not finite and ≥ 0).
    pub fn for_spot(spot_radius_mm: f64) -> Result<Self> {
        Self::new(
            2.0 * spot_radius_mm,
            f64::INFINITY,
            1.0,
            Self::DEFAULT_ERROR_FLOOR,
        )
    }

    /// The same with another innermost radius \[mm\].
    ///
    /// # Errors
    /// As [`RingSelection::new`].
    pub fn with_r_min_mm(self, r_min_mm: f64) -> Result<Self> {
        Self::new(
            r_min_mm,
            self.r_max_mm,
            self.detection_factor,
            self.relative_error_floor,
        )
    }

    /// The same with another outermost radius \[mm\].
    ///
    /// # Errors
    /// As [`RingSelection::new`].
    pub fn with_r_max_mm(self, r_max_mm: f64) -> Result<Self> {
        Self::new(
            self.r_min_mm,
            r_max_mm,
            self.detection_factor,
            self.relative_error_floor,
        )
    }

    /// The same with another detection factor (0: fit rings below their detection limit too).
    ///
    /// # Errors
    /// As [`RingSelection::new`].
    pub fn with_detection_factor(self, detection_factor: f64) -> Result<Self> {
        Self::new(
            self.r_min_mm,
            self.r_max_mm,
            detection_factor,
            self.relative_error_floor,
        )
    }

    /// Innermost radius fitted \[mm\]; rings inside are counted as "inside the spot".
    pub fn r_min_mm(&self) -> f64 {
        self.r_min_mm
    }

    /// Outermost radius fitted \[mm\] (∞: every ring of the profile).
    pub fn r_max_mm(&self) -> f64 {
        self.r_max_mm
    }

    /// A ring is fitted only if its value is at least this multiple of its detection limit.
    pub fn detection_factor(&self) -> f64 {
        self.detection_factor
    }

    /// Relative standard error floor of a ring.
    pub fn relative_error_floor(&self) -> f64 {
        self.relative_error_floor
    }

    fn validate(&self) -> Result<()> {
        check(
            self.r_min_mm.is_finite() && self.r_min_mm >= 0.0,
            "r_min_mm",
            self.r_min_mm,
            "the innermost fitted radius must be a finite number ≥ 0 mm",
        )?;
        check(
            self.r_max_mm > self.r_min_mm,
            "r_max_mm",
            self.r_max_mm,
            "the outermost fitted radius must exceed the innermost",
        )?;
        check(
            self.detection_factor.is_finite() && self.detection_factor >= 0.0,
            "detection_factor",
            self.detection_factor,
            "must be a finite number ≥ 0",
        )?;
        check(
            self.relative_error_floor.is_finite() && self.relative_error_floor > 0.0,
            "relative_error_floor",
            self.relative_error_floor,
            "must be a finite number > 0",
        )
    }
}

/// The rings a fit uses, with the counts of those it left out and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Selected {
    /// Radii of the fitted rings \[mm\].
    pub r_mm: Vec<f64>,
    /// Their values \[relative\].
    pub value: Vec<f64>,
    /// Standard deviation of ln(value) per ring (relative error, floored).
    pub sigma_ln: Vec<f64>,
    /// Pixels each ring averages.
    pub count: Vec<u64>,
    /// Indices of the fitted rings in the profile.
    pub index: Vec<usize>,
    /// Rings left out because r < r_min (inside the spot).
    pub inside_spot: usize,
    /// Rings left out because their value is below the detection limit.
    pub below_detection: usize,
    /// Rings left out for having no finite positive value (no valid pixel) or lying beyond r_max.
    pub invalid: usize,
}

/// Applies `sel` to `profile`: the rings inside r_min, beyond r_max or below the detection limit
/// are left out; each kept ring's relative error is its own, or for a ring of fewer than
/// [`THIN_RING_PIXELS`] at least its neighbours' per-pixel scatter over its √n, never below the
/// floor.
///
/// # Errors
/// None today (the selection is valid by construction); kept for future checks.
pub fn select_rings(profile: &ProfileData, sel: &RingSelection) -> Result<Selected> {
    let mut s = Selected {
        r_mm: Vec::new(),
        value: Vec::new(),
        sigma_ln: Vec::new(),
        count: Vec::new(),
        index: Vec::new(),
        inside_spot: 0,
        below_detection: 0,
        invalid: 0,
    };
    for (i, ring) in profile.rings.iter().enumerate() {
        if ring.r_mm < sel.r_min_mm {
            s.inside_spot += 1;
            continue;
        }
        if ring.r_mm > sel.r_max_mm || !(ring.value.is_finite()) || ring.count == 0 {
            s.invalid += 1;
            continue;
        }
        let limit = if ring.detection_limit.is_finite() {
            ring.detection_limit.max(0.0)
        } else {
            0.0
        };
        if ring.value <= 0.0 || ring.value < sel.detection_factor * limit {
            s.below_detection += 1;
            continue;
        }
        let rel = if ring.stderr.is_finite() && ring.stderr >= 0.0 {
            ring.stderr / ring.value
        } else {
            // One pixel: no scatter of its own (the thin rings are given their neighbours' below).
            f64::NAN
        };
        s.r_mm.push(ring.r_mm);
        s.value.push(ring.value);
        s.sigma_ln.push(rel);
        s.count.push(ring.count);
        s.index.push(i);
    }
    thin_rings_from_neighbours(&mut s.sigma_ln, &s.count);
    for rel in &mut s.sigma_ln {
        *rel = if rel.is_finite() {
            rel.max(sel.relative_error_floor)
        } else {
            // No ring to learn the pixels' scatter from: weight like a ring at ten times the floor.
            10.0 * sel.relative_error_floor
        };
    }
    Ok(s)
}

/// A ring of fewer pixels than this has its error from its neighbours' pixels: at least the
/// per-pixel relative scatter of the nearest ring with enough pixels over its own √n
/// ([`select_rings`]).
pub const THIN_RING_PIXELS: u64 = 8;

/// The relative error of the rings with fewer than [`THIN_RING_PIXELS`] pixels (the frame's
/// corners, the centre): a sample standard deviation of one to seven values says little (of two
/// nearly equal pixels it is nearly 0, and the ring would weigh as much as the floor allows; of one
/// it does not exist), so such a ring gets at least the per-pixel relative scatter of the nearest
/// ring with enough pixels, s·√n there, over its own √n — the standard error of a mean of n
/// values whose scatter is the neighbours' (the profile changes slowly from ring to ring). Rings
/// with enough pixels keep their own.
fn thin_rings_from_neighbours(rel: &mut [f64], count: &[u64]) {
    let per_pixel: Vec<Option<f64>> = rel
        .iter()
        .zip(count)
        .map(|(&r, &n)| (n >= THIN_RING_PIXELS && r.is_finite()).then(|| r * (n as f64).sqrt()))
        .collect();
    for i in 0..rel.len() {
        if count[i] >= THIN_RING_PIXELS && rel[i].is_finite() {
            continue;
        }
        // The nearest ring with enough pixels, on either side (the inner one on a tie).
        let nearest = (1..rel.len()).find_map(|d| {
            i.checked_sub(d)
                .and_then(|j| per_pixel[j])
                .or_else(|| per_pixel.get(i + d).copied().flatten())
        });
        if let Some(p) = nearest {
            let own = rel[i];
            let pooled = p / (count[i].max(1) as f64).sqrt();
            rel[i] = if own.is_finite() {
                own.max(pooled)
            } else {
                pooled
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(r_mm: f64, value: f64, stderr: f64, count: u64) -> Ring {
        Ring {
            r_mm,
            value,
            stderr,
            count,
            detection_limit: 0.0,
        }
    }

    /// Rings of one, two and three pixels take their error from the nearest ring of enough pixels:
    /// its per-pixel relative scatter (1 % × √100 = 10 %) over their own √n, never less than their
    /// own; rings of enough pixels keep theirs, and with no such ring the old rule (ten times the
    /// floor for an unknown error, the floor otherwise) holds.
    #[test]
    fn thin_rings_take_their_neighbours_pixel_scatter() {
        let data = ProfileData::new(vec![
            ring(1.0, 10.0, 0.1, 100),
            ring(2.0, 5.0, 0.0005, 2),
            ring(3.0, 4.0, f64::NAN, 1),
            ring(4.0, 3.0, 0.9, 3),
            ring(5.0, 2.0, 0.04, 400),
        ])
        .unwrap();
        let sel = RingSelection::new(0.5, 10.0, 0.0, RingSelection::DEFAULT_ERROR_FLOOR).unwrap();
        let s = select_rings(&data, &sel).unwrap();
        let expected = [0.01, 0.1 / 2f64.sqrt(), 0.1, 0.3, 0.02];
        for (got, want) in s.sigma_ln.iter().zip(expected) {
            assert!(
                (got - want).abs() < 1e-12,
                "{:?} against {expected:?}",
                s.sigma_ln
            );
        }
        let alone =
            ProfileData::new(vec![ring(1.0, 1.0, f64::NAN, 1), ring(2.0, 1.0, 0.0, 2)]).unwrap();
        let s = select_rings(&alone, &sel).unwrap();
        let floor = RingSelection::DEFAULT_ERROR_FLOOR;
        assert_eq!(s.sigma_ln, [10.0 * floor, floor]);
    }
}
