//! Quadrature rules: 8-point Gauss–Legendre (Abramowitz & Stegun 1964, table 25.4) and the
//! doubling panels of the radial integrals.
//!
//! Two tables of the same rule stand here, each with the digits its callers have always used: the
//! 17-digit nodes and weights ([`GL8`], numpy's `leggauss(8)`) of the doubling integrator, and
//! Abramowitz & Stegun's 15 digits ([`GL8_AS_X`], [`GL8_AS_W`]) of the port's panels and the spot
//! convolution (`scatterfit-fit`). They differ in the outer node (1 unit in the last place) and in
//! every weight (3 to 55 units, up to 7.5e-16 relative): one table for all would move those
//! integrals in their last digits, so each keeps its own.

/// Nodes and weights of 8-point Gauss–Legendre quadrature on [−1, 1] (numpy 2.4
/// `polynomial.legendre.leggauss(8)`, printed to 17 digits; Abramowitz & Stegun table 25.4 to 15).
pub const GL8: [(f64, f64); 8] = [
    (-9.602_898_564_975_362e-1, 1.012_285_362_903_770_6e-1),
    (-7.966_664_774_136_267e-1, 2.223_810_344_533_744_3e-1),
    (-5.255_324_099_163_29e-1, 3.137_066_458_778_869e-1),
    (-1.834_346_424_956_498e-1, 3.626_837_833_783_616_6e-1),
    (1.834_346_424_956_498e-1, 3.626_837_833_783_616_6e-1),
    (5.255_324_099_163_29e-1, 3.137_066_458_778_869e-1),
    (7.966_664_774_136_267e-1, 2.223_810_344_533_744_3e-1),
    (9.602_898_564_975_362e-1, 1.012_285_362_903_770_6e-1),
];

/// ∫₀^{L·2^{p−1}} f(r) dr by 8-point Gauss–Legendre on the panels [0, L], [L, 2L], [2L, 4L], …
/// (`panels` panels, first width `first`): doubling panels resolve a radial integrand whose
/// features scale with the distance from the source, and an exponential tail. f is called
/// 8·`panels` times.
pub fn integrate_doubling(first: f64, panels: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let mut sum = 0.0;
    let (mut a, mut b) = (0.0, first);
    for _ in 0..panels {
        let (h, m) = (0.5 * (b - a), 0.5 * (a + b));
        sum += h * GL8.iter().map(|&(x, w)| w * f(m + h * x)).sum::<f64>();
        a = b;
        b *= 2.0;
    }
    sum
}

/// The positive nodes of 8-point Gauss–Legendre on [−1, 1] (Abramowitz & Stegun 1964, table 25.4,
/// 15 digits), smallest first; the rule is symmetric (±x with the same weight).
pub const GL8_AS_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];

/// The weights of [`GL8_AS_X`]'s nodes (Abramowitz & Stegun 1964, table 25.4).
pub const GL8_AS_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀^∞ r e^{−r} dr = 1 and ∫₀^∞ 2πr e^{−√(r² + 1)}/√(r² + 1) dr = 2π e^{−1} (substitute d).
    #[test]
    fn doubling_quadrature_integrates_known_integrals() {
        let i1 = integrate_doubling(1.0 / 1024.0, 17, |r| r * (-r).exp());
        assert!((i1 - 1.0).abs() < 1e-11, "{i1}");
        let i2 = integrate_doubling(1.0 / 1024.0, 17, |r| {
            let d = (r * r + 1.0).sqrt();
            2.0 * std::f64::consts::PI * r * (-d).exp() / d
        });
        assert!((i2 - 2.0 * std::f64::consts::PI * (-1.0f64).exp()).abs() < 1e-11);
    }
}
