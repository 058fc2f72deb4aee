//! Windowed comparison of a profile model with a reference's radial bins (the `mc` examples that
//! check the model against MCML or the engine).

use scatterfit_mc::SimulationResult;
use scatterfit_optics::ProfileModel;

pub const WINDOWS: [(f64, f64); 9] = [
    (0.1, 0.5),
    (0.5, 1.0),
    (1.0, 2.0),
    (2.0, 5.0),
    (5.0, 10.0),
    (10.0, 20.0),
    (20.0, 50.0),
    (50.0, 100.0),
    (100.0, 200.0),
];

/// The model averaged over the annulus [a, b] (8-point Gauss–Legendre in ln r).
fn annulus_average(m: &dyn ProfileModel, a: f64, b: f64) -> f64 {
    const GL4: [(f64, f64); 4] = [
        (-0.861_136_311_594_053, 0.347_854_845_137_454),
        (-0.339_981_043_584_856, 0.652_145_154_862_546),
        (0.339_981_043_584_856, 0.652_145_154_862_546),
        (0.861_136_311_594_053, 0.347_854_845_137_454),
    ];
    let mut s = 0.0;
    // Two panels, so that tiny inner annuli and wide outer ones are both integrated well.
    let mid = 0.5 * (a + b);
    for (lo, hi) in [(a, mid), (mid, b)] {
        for (x, w) in GL4 {
            let r = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
            s += w * 0.5 * (hi - lo) * 2.0 * std::f64::consts::PI * r * m.rd(r);
        }
    }
    s / (std::f64::consts::PI * (b * b - a * a))
}

/// Prints windowed comparisons: per bin (r_lo, r_hi, reference value, its relative s.e.).
pub fn windows(model: &dyn ProfileModel, bins: &[(f64, f64, f64, f64)]) -> String {
    windows_in(model, bins, &WINDOWS)
}

/// [`windows`] over the given windows (r_lo, r_hi).
pub fn windows_in(
    model: &dyn ProfileModel,
    bins: &[(f64, f64, f64, f64)],
    list: &[(f64, f64)],
) -> String {
    let mut line = String::new();
    for &(lo, hi) in list {
        let (mut sw, mut swd, mut chi2, mut n) = (0.0, 0.0, 0.0, 0);
        for &(a, b, v, rel) in bins {
            let c = 0.5 * (a + b);
            if c < lo || c >= hi || v <= 0.0 || rel > 0.3 {
                continue;
            }
            let d = annulus_average(model, a, b) / v - 1.0;
            let w = 1.0 / (rel * rel);
            sw += w;
            swd += w * d;
            chi2 += d * d * w;
            n += 1;
        }
        if n > 0 {
            line += &format!(
                " [{lo},{hi}): {:+.2}±{:.2}% ({:.0}/{n})",
                100.0 * swd / sw,
                100.0 / sw.sqrt(),
                chi2
            );
        }
    }
    line
}

/// A simulation's profile as bins (r_lo, r_hi, value, relative standard error) over `edges`.
pub fn engine_bins(d: &SimulationResult, edges: &[f64]) -> Vec<(f64, f64, f64, f64)> {
    d.rd_profile
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let rel = if e.value > 0.0 {
                e.stderr / e.value
            } else {
                f64::INFINITY
            };
            (edges[i], edges[i + 1], e.value, rel)
        })
        .collect()
}
