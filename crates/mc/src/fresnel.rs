//! Fresnel reflectance at a boundary, in the form MCML uses in its hot path.

/// MCML's `COSZERO`: directions closer than this to the normal count as normal incidence.
pub(crate) const COSZERO: f64 = 1.0 - 1.0e-12;
/// MCML's `COS90D`: directions closer than this to grazing are totally reflected.
pub(crate) const COS90D: f64 = 1.0e-6;

/// Reflectance at a boundary and the cosine of the transmitted direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FresnelSample {
    /// Unpolarised Fresnel reflectance, 1 under total internal reflection.
    pub reflectance: f64,
    /// Cosine of the refraction angle (0 under total internal reflection).
    pub cos_t: f64,
}

/// Unpolarised Fresnel reflectance for light going from index `n_i` into index `n_t` with incidence
/// cosine `cos_i` ∈ [0, 1], and the transmitted cosine from Snell's law.
///
/// Wang, Jacques & Zheng 1995 (MCML), `RFresnel` in `mcmlgo.c` (docs/physics.md §4.1): the average of the
/// s and p reflectances written with the sum and difference angles a± = θi ± θt,
/// R = ½ sin²(a−)[cos²(a−) + cos²(a+)] / [sin²(a+) cos²(a−)], which is Hecht's
/// ½[sin²(θi−θt)/sin²(θi+θt) + tan²(θi−θt)/tan²(θi+θt)]. Normal incidence uses ((n_t−n_i)/(n_t+n_i))².
#[inline]
pub fn fresnel_mcml(n_i: f64, n_t: f64, cos_i: f64) -> FresnelSample {
    if n_i == n_t {
        return FresnelSample {
            reflectance: 0.0,
            cos_t: cos_i,
        };
    }
    if cos_i > COSZERO {
        let r = (n_t - n_i) / (n_t + n_i);
        return FresnelSample {
            reflectance: r * r,
            cos_t: cos_i,
        };
    }
    if cos_i < COS90D {
        return FresnelSample {
            reflectance: 1.0,
            cos_t: 0.0,
        };
    }
    let sa1 = (1.0 - cos_i * cos_i).sqrt();
    let sa2 = n_i * sa1 / n_t;
    if sa2 >= 1.0 {
        return FresnelSample {
            reflectance: 1.0,
            cos_t: 0.0,
        };
    }
    let ca1 = cos_i;
    let ca2 = (1.0 - sa2 * sa2).sqrt();
    let cap = ca1 * ca2 - sa1 * sa2; // cos(a+)
    let cam = ca1 * ca2 + sa1 * sa2; // cos(a−)
    let sap = sa1 * ca2 + ca1 * sa2; // sin(a+)
    let sam = sa1 * ca2 - ca1 * sa2; // sin(a−)
    let r = 0.5 * sam * sam * (cam * cam + cap * cap) / (sap * sap * cam * cam);
    FresnelSample {
        reflectance: r,
        cos_t: ca2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hecht's textbook form with explicit s and p amplitudes (an independent expression).
    fn hecht(n_i: f64, n_t: f64, cos_i: f64) -> f64 {
        let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).sqrt();
        if sin_t >= 1.0 {
            return 1.0;
        }
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
        let rp = (n_i * cos_t - n_t * cos_i) / (n_i * cos_t + n_t * cos_i);
        0.5 * (rs * rs + rp * rp)
    }

    #[test]
    fn matches_amplitude_form() {
        for &(ni, nt) in &[(1.0, 1.4), (1.4, 1.0), (1.33, 1.5), (1.5, 1.0)] {
            for k in 1..200 {
                let c = k as f64 / 200.0;
                let f = fresnel_mcml(ni, nt, c);
                assert!(
                    (f.reflectance - hecht(ni, nt, c)).abs() < 1e-12,
                    "{ni} {nt} {c}"
                );
                if f.reflectance < 1.0 {
                    // Snell: n_i sinθi = n_t sinθt.
                    let st = (1.0 - f.cos_t * f.cos_t).sqrt();
                    assert!((ni * (1.0 - c * c).sqrt() - nt * st).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn normal_incidence_and_critical_angle() {
        // ((1.4−1)/(2.4))² = 0.02777…, docs/physics.md §4.3's R_sp for n = 1.4.
        assert!((fresnel_mcml(1.0, 1.4, 1.0).reflectance - 0.027_777_777_777_777_8).abs() < 1e-15);
        // From 1.4 into air the critical cosine is sqrt(1 − 1/1.96) ≈ 0.69985.
        assert_eq!(fresnel_mcml(1.4, 1.0, 0.699).reflectance, 1.0);
        assert!(fresnel_mcml(1.4, 1.0, 0.701).reflectance < 1.0);
        assert_eq!(fresnel_mcml(1.2, 1.2, 0.3).reflectance, 0.0);
    }
}
