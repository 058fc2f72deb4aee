//! Henyey–Greenstein phase function: sampling and density of the scattering cosine, and the
//! anisotropic scattering step of the tracers (MCML `Spin` in vector form).

use std::sync::LazyLock;

use crate::rng::PhotonRng;

/// Azimuth table size: cos and sin at 2π i/`AZIMUTH_TABLE` (8 KB, L1-resident).
const AZIMUTH_TABLE: usize = 512;

/// (cos, sin) of 2π i / [`AZIMUTH_TABLE`], computed once per process.
static AZIMUTH: LazyLock<[[f64; 2]; AZIMUTH_TABLE]> = LazyLock::new(|| {
    let mut t = [[0.0; 2]; AZIMUTH_TABLE];
    for (i, e) in t.iter_mut().enumerate() {
        let (s, c) = (std::f64::consts::TAU * i as f64 / AZIMUTH_TABLE as f64).sin_cos();
        *e = [c, s];
    }
    t
});

/// (cos ψ, sin ψ) of an azimuth ψ uniform in [0, 2π) from 64 random bits, without trigonometry or
/// rejection: the top 9 bits pick one of 512 table angles 2πi/512, the next 44 bits an offset
/// δ ∈ [0, 2π/512) whose cosine and sine come from their Taylor series to δ⁶ and δ⁵ (truncation
/// below 1e-17 at δ < 0.0123), and the angle-sum formulas combine the two. ψ is uniform to 2⁻⁵³.
#[inline(always)]
pub(crate) fn azimuth(table: &[[f64; 2]; AZIMUTH_TABLE], bits: u64) -> (f64, f64) {
    const FRAC: f64 = std::f64::consts::TAU / AZIMUTH_TABLE as f64 / (1u64 << 44) as f64;
    let [c0, s0] = table[(bits >> 55) as usize];
    let delta = ((bits >> 11) & ((1 << 44) - 1)) as f64 * FRAC;
    let d2 = delta * delta;
    let cos_d = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)));
    let sin_d = delta * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0)));
    (c0 * cos_d - s0 * sin_d, s0 * cos_d + c0 * sin_d)
}

/// Samples cos θ of the Henyey–Greenstein phase function with asymmetry `g` from a uniform `u` ∈ [0, 1).
///
/// Henyey & Greenstein 1941; the inversion of MCML `SpinTheta` (Wang, Jacques & Zheng 1995,
/// eq. 3.28; docs/physics.md §4.1), cos θ = [1 + g² − ((1 − g²)/(1 − g + 2gu))²] / (2g), written as one
/// fraction (`HgSampler`) so that it costs one division and stays accurate as g → 0 (where it
/// tends to 2u − 1, the g = 0 case, which is returned exactly).
#[inline]
pub fn sample_hg_cos(g: f64, u: f64) -> f64 {
    if g == 0.0 {
        2.0 * u - 1.0
    } else {
        HgSampler::new(g).sample(u).cos_theta
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

/// A sampled scattering cosine as a fraction: cos θ = `num`/`den`, with sin²θ = (den − num)(den + num)/den²
/// available without cancellation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HgSample {
    /// cos θ, clamped to [−1, 1].
    pub cos_theta: f64,
    num: f64,
    den: f64,
}

/// Henyey–Greenstein sampling with its constants computed once per layer (not per event).
///
/// With d = 1 − g + 2gu, MCML's inversion (Wang, Jacques & Zheng 1995, eq. 3.28) is
/// cos θ = [(1 + g²) d² − (1 − g²)²] / (2g d²); expanding d² and cancelling the common factor 2g
/// (an identity, checked in the tests against the textbook form) gives
///
/// cos θ = [2(1 + g²) u (1 − g + g u) − (1 − g)²] / (1 − g + 2g u)²,
///
/// exact at both ends (u = 0 → −1, u → 1 → 1) and at g = 0 (2u − 1), with one division and no
/// cancellation between large terms when g is small.
#[derive(Debug, Clone, Copy)]
pub(crate) struct HgSampler {
    g: f64,
    /// 1 − g.
    one_minus_g: f64,
    /// 2g.
    two_g: f64,
    /// 2(1 + g²).
    c_num: f64,
    /// (1 − g)².
    c_sub: f64,
    /// The azimuth table ([`azimuth`]).
    azimuth: &'static [[f64; 2]; AZIMUTH_TABLE],
}

impl HgSampler {
    /// The sampler of asymmetry `g` ∈ (−1, 1).
    pub(crate) fn new(g: f64) -> Self {
        Self {
            g,
            one_minus_g: 1.0 - g,
            two_g: 2.0 * g,
            c_num: 2.0 * (1.0 + g * g),
            c_sub: (1.0 - g) * (1.0 - g),
            azimuth: &AZIMUTH,
        }
    }

    /// cos θ (and its fraction) from a uniform `u` ∈ [0, 1).
    #[inline(always)]
    pub(crate) fn sample(&self, u: f64) -> HgSample {
        let d = self.one_minus_g + self.two_g * u;
        let den = d * d;
        let num = self.c_num * u * (self.one_minus_g + self.g * u) - self.c_sub;
        HgSample {
            cos_theta: (num / den).clamp(-1.0, 1.0),
            num,
            den,
        }
    }
}

/// The new unit direction after a Henyey–Greenstein scattering event from the unit direction `u`
/// (MCML `Spin`, Wang, Jacques & Zheng 1995, eqs. 3.28–3.31, in vector form):
///
/// u′ = cos θ u + sin θ (cos ψ e1 + sin ψ e2),
///
/// cos θ from [`HgSampler`], ψ uniform from [`azimuth`], and (e1, e2) the branchless orthonormal
/// basis of u of Duff et al. 2017 ("Building an orthonormal basis, revisited", JCGT 6(1), listing 3:
/// with σ = sign u_z, k = −1/(σ + u_z), m = u_x u_y k: e1 = (1 + σ u_x² k, σ m, −σ u_x),
/// e2 = (m, σ + u_y² k, −u_y)). MCML's form needs 1/√(1 − u_z²) of the old direction, a square root
/// and a division on the chain from one event to the next (the tracer's bound at g ≠ 0); here one
/// division by σ + u_z (|σ + u_z| ≥ 1, no singular direction) remains on it, and the square root and
/// division of sin θ depend on the random numbers only. Any basis of u gives the same distribution,
/// since ψ is uniform. Measured effect: BENCHMARKS.md, "Monte Carlo: speed against MCML".
#[inline(always)]
pub(crate) fn scatter_hg(u: [f64; 3], hg: &HgSampler, rng: &mut PhotonRng) -> [f64; 3] {
    let t = hg.sample(rng.uniform());
    let (cos_p, sin_p) = azimuth(hg.azimuth, rng.bits());
    let cos_t = t.cos_theta;
    let sin_t = ((t.den - t.num) * (t.den + t.num)).max(0.0).sqrt() / t.den;
    let c = cos_p * sin_t;
    let d = sin_p * sin_t;
    let sign = 1.0f64.copysign(u[2]);
    let k = -1.0 / (sign + u[2]);
    let m = u[0] * u[1] * k;
    let e1 = [1.0 + sign * u[0] * u[0] * k, sign * m, -sign * u[0]];
    let e2 = [m, sign + u[1] * u[1] * k, -u[1]];
    [
        cos_t * u[0] + c * e1[0] + d * e2[0],
        cos_t * u[1] + c * e1[1] + d * e2[1],
        cos_t * u[2] + c * e1[2] + d * e2[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    /// The one-fraction form equals MCML's textbook inversion (Wang, Jacques & Zheng 1995, eq. 3.28)
    /// to rounding over g and u.
    #[test]
    fn one_fraction_form_is_mcmls_inversion() {
        for &g in &[-0.9, -0.3, 0.01, 0.3, 0.75, 0.9, 0.95, 0.99] {
            for k in 0..=1000 {
                let u = k as f64 / 1000.0 * (1.0 - 1e-12);
                let t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
                let mcml = ((1.0 + g * g - t * t) / (2.0 * g)).clamp(-1.0, 1.0);
                let ours = sample_hg_cos(g, u);
                assert!((ours - mcml).abs() < 1e-12, "g {g} u {u}: {ours} vs {mcml}");
            }
        }
        assert_eq!(sample_hg_cos(0.9, 0.0), -1.0);
        assert_eq!(sample_hg_cos(0.0, 0.25), -0.5);
    }

    /// Duff et al.'s basis is orthonormal for directions all over the sphere (poles included), and
    /// the scattered direction is a unit vector.
    #[test]
    fn basis_is_orthonormal_and_scattered_directions_unit() {
        let hg = HgSampler::new(0.9);
        let mut rng = stream(3, 7);
        let mut u = [0.0, 0.0, -1.0];
        for _ in 0..100_000 {
            let v = scatter_hg(u, &hg, &mut rng);
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            assert!((n - 1.0).abs() < 1e-13, "|u′| = {n}");
            u = [v[0] / n, v[1] / n, v[2] / n];
        }
        // The azimuth's cos and sin are a unit pair and cover the circle.
        for k in 0..4096u64 {
            let bits = k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let (c, s) = azimuth(&AZIMUTH, bits);
            assert!((c * c + s * s - 1.0).abs() < 1e-15);
            let psi = s.atan2(c).rem_euclid(std::f64::consts::TAU);
            let want = (bits >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
            assert!(
                (psi - want).abs() < 1e-13 || (psi - want).abs() > 6.0,
                "{psi} {want}"
            );
        }
    }
}
