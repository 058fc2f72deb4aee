//! Henyey–Greenstein phase function: sampling and density of the scattering cosine.

/// Samples cos θ of the Henyey–Greenstein phase function with asymmetry `g` from a uniform `u` ∈ [0, 1).
///
/// Henyey & Greenstein 1941; inversion as in MCML `SpinTheta` (Wang, Jacques & Zheng 1995, eq. 3.28;
/// physics.md §4.1): g = 0 → cos θ = 2u − 1, else
/// cos θ = [1 + g² − ((1 − g²)/(1 − g + 2gu))²] / (2g), clamped to [−1, 1].
#[inline(always)]
pub fn sample_hg_cos(g: f64, u: f64) -> f64 {
    if g == 0.0 {
        2.0 * u - 1.0
    } else {
        let t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        ((1.0 + g * g - t * t) / (2.0 * g)).clamp(-1.0, 1.0)
    }
}

/// Density of μ = cos θ under Henyey–Greenstein: p(μ) = ½ (1 − g²) / (1 + g² − 2gμ)^{3/2},
/// normalised on [−1, 1] (Henyey & Greenstein 1941; 2π × the per-steradian phase function).
pub fn hg_pdf_cos(g: f64, mu: f64) -> f64 {
    0.5 * (1.0 - g * g) / (1.0 + g * g - 2.0 * g * mu).powf(1.5)
}

/// Cumulative distribution of μ = cos θ under Henyey–Greenstein, the integral of [`hg_pdf_cos`] from −1:
/// F(μ) = (1 − g²)/(2g) · [1/√(1 + g² − 2gμ) − 1/(1 + g)], and (μ + 1)/2 for g = 0.
pub fn hg_cdf_cos(g: f64, mu: f64) -> f64 {
    if g == 0.0 {
        0.5 * (mu + 1.0)
    } else {
        (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g - 2.0 * g * mu).sqrt() - 1.0 / (1.0 + g))
    }
}
