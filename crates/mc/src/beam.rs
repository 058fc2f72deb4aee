//! The light source: a collimated beam with a transverse profile and an angle of incidence.

use serde::{Deserialize, Serialize};

use crate::error::{Result, check};

/// Transverse profile of the collimated beam, measured across the beam (perpendicular to its axis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum BeamProfile {
    /// An infinitely thin pencil beam (MCML's source).
    Pencil,
    /// Uniform irradiance over a disk of this radius \[mm\].
    Disk {
        /// Radius \[mm\].
        radius: f64,
    },
    /// Gaussian irradiance I(ρ) ∝ exp(−2ρ²/w²) with w the 1/e² radius \[mm\] (the laser convention).
    Gaussian {
        /// 1/e² intensity radius w \[mm\].
        radius: f64,
    },
}

/// A collimated beam: profile, and polar angle of incidence in the outside medium (0 = normal). The
/// beam axis hits the surface at the origin and is tilted in the x–z plane; an oblique beam's
/// footprint is stretched by 1/cos θ along x.
///
/// Built only through [`Beam::pencil`], [`Beam::new`] and [`Beam::with_incidence`]; JSON is read
/// through the same checks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawBeam")]
pub struct Beam {
    profile: BeamProfile,
    incidence: f64,
}

/// The unchecked shape of [`Beam`] in files.
#[derive(Deserialize)]
struct RawBeam {
    profile: BeamProfile,
    incidence: f64,
}

impl TryFrom<RawBeam> for Beam {
    type Error = crate::McError;
    fn try_from(raw: RawBeam) -> Result<Self> {
        Self::new(raw.profile)?.with_incidence(raw.incidence)
    }
}

impl Beam {
    /// A normally incident pencil beam.
    pub fn pencil() -> Self {
        Self {
            profile: BeamProfile::Pencil,
            incidence: 0.0,
        }
    }

    /// A beam with this profile, normally incident.
    ///
    /// # Errors
    /// `InvalidParameter` for a radius that is not finite and > 0.
    pub fn new(profile: BeamProfile) -> Result<Self> {
        match profile {
            BeamProfile::Pencil => {}
            BeamProfile::Disk { radius } | BeamProfile::Gaussian { radius } => check(
                radius.is_finite() && radius > 0.0,
                "beam radius",
                radius,
                "the beam radius must be finite and > 0 mm",
            )?,
        }
        Ok(Self {
            profile,
            incidence: 0.0,
        })
    }

    /// The same beam at polar incidence angle `theta` \[radians\] in [0, π/2).
    ///
    /// # Errors
    /// `InvalidParameter` for an angle outside [0, π/2).
    pub fn with_incidence(mut self, theta: f64) -> Result<Self> {
        check(
            (0.0..std::f64::consts::FRAC_PI_2).contains(&theta),
            "incidence",
            theta,
            "the angle of incidence must lie in [0, π/2) radians",
        )?;
        self.incidence = theta;
        Ok(self)
    }

    /// The transverse profile.
    pub fn profile(&self) -> BeamProfile {
        self.profile
    }
    /// Polar angle of incidence \[radians\].
    pub fn incidence(&self) -> f64 {
        self.incidence
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// JSON goes through the checks: a beam round-trips; a negative radius or a grazing angle in a
    /// file is refused.
    #[test]
    fn json_round_trip_goes_through_the_checks() {
        let beam = Beam::new(BeamProfile::Gaussian { radius: 0.5 })
            .unwrap()
            .with_incidence(0.3)
            .unwrap();
        let json = serde_json::to_string(&beam).unwrap();
        assert_eq!(serde_json::from_str::<Beam>(&json).unwrap(), beam);
        for bad in [
            r#"{"profile":{"Disk":{"radius":-1}},"incidence":0}"#,
            r#"{"profile":"Pencil","incidence":2}"#,
        ] {
            assert!(serde_json::from_str::<Beam>(bad).is_err(), "{bad}");
        }
    }
}
