//! Can g be fitted from the rig's radial profile? The Fisher information of (σ′s, g, ln k) — k the
//! unknown scale of the HDR profile — with α′ known (from the spectrophotometer, the proposed
//! method), from the rings r ≥ the spot's edge up to the fit's cut-off, for the paper's rig and the
//! rig twin's noise model (ARCHITECTURE.md, "synth: the rig twin"). Prints sd(g) (and sd(σ′s)/σ′s,
//! and the correlation of σ′s with g) per α′.
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example g_fisher -- TABLE_DIR ETA G_LO G_HI [SIGMA_T]
//! ```
//! TABLE_DIR holds `mc-white-eta<η>-g<g>.json` tables (from `build_g_tables`) at G_LO and G_HI; the
//! model at g = (G_LO + G_HI)/2 interpolates ln Rd linearly in g between them at fixed σ′s, σa, and
//! ∂ ln Rd/∂g is their difference over G_HI − G_LO; ∂/∂σ′s (at fixed α′) by central differences.
//!
//! The measurement (paper rig: 0.05 mm/px, 1 mm uniform spot, r_max 300 px): each 1-px ring at
//! radius r averages n = 2πr/Δ pixels of the spot-convolved profile. A pixel's merged radiance
//! combines the 13 exposures 1/600 s … 3 s (geometric) by inverse variance over the frames whose
//! 8-bit code lies in [30, 250] (the merge's detection limit and clipping): in a frame of
//! e electrons the variance is e (shot) + 3² (read) + q² (8-bit rounding, q = Δe per code/√12
//! through the tone curve T(s) = 1.08 s/(s + 0.08)); the spot centre fills 80 % of the 20 000 e⁻
//! well at the shortest exposure (the brightest channel; others are dimmer). The profile is fitted
//! in ln Rd with weights 1/var(ln ring mean) — the Fisher information is Jᵀ W J.

use scatterfit_mc::model::{McProfile, McTable, McTableSet};
use scatterfit_optics::{OpticalProperties, ProfileModel};

const MM_PER_PX: f64 = 0.05;
const SPOT_RADIUS: f64 = 0.5;
const R_MAX_PX: usize = 300;
const WELL: f64 = 20_000.0;
const READ: f64 = 3.0;
const KNEE: f64 = 0.08;
/// A floor of independent relative error per 1-px ring standing for what is not camera noise (the
/// recovered response, the model's own noise): 0.5 %.
const FLOOR: f64 = 0.005;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = std::path::PathBuf::from(&args[1]);
    let eta: f64 = args[2].parse().expect("η");
    let g_lo: f64 = args[3].parse().expect("g");
    let g_hi: f64 = args[4].parse().expect("g");
    let sigma_t_prime: f64 = args.get(5).map_or(2.0, |s| s.parse().expect("σ′t"));
    let load = |g: f64| {
        let p = dir.join(format!("mc-white-eta{eta:.2}-g{g:.2}.json"));
        McTableSet::new(vec![McTable::load(&p).expect("table file")]).expect("set")
    };
    let (lo, hi) = (load(g_lo), load(g_hi));
    let g = 0.5 * (g_lo + g_hi);
    println!(
        "η {eta}, g {g} (tables {g_lo}, {g_hi}), σ′t {sigma_t_prime} mm⁻¹, paper rig: sd(g) with (σ′s, g, ln k) free, α′ known"
    );
    println!(
        "| α′ | rings used | sd(g), camera noise | sd(σ′s)/σ′s | corr(σ′s, g) | sd(g), + {:.1} % per ring | shape change of Δg = 0.05 after refit: RMS / max |",
        100.0 * FLOOR
    );
    println!("|---|---|---|---|---|---|---|");
    for ap in [0.3, 0.5, 0.7, 0.9, 0.95, 0.98, 0.99, 0.999, 0.9999] {
        let ssp = ap * sigma_t_prime;
        // ln of the spot-convolved profile at (σ′s, t = fraction of the way from g_lo to g_hi).
        let profile = |ssp: f64, t: f64| -> Option<Vec<f64>> {
            let sa = ssp * (1.0 / ap - 1.0);
            let props = OpticalProperties::new(ssp, sa, eta).ok()?;
            let (m0, m1) = (
                McProfile::new(&lo, &props).ok()?,
                McProfile::new(&hi, &props).ok()?,
            );
            let rd = |r: f64| ((1.0 - t) * m0.rd(r).ln() + t * m1.rd(r).ln()).exp();
            Some(
                (0..=R_MAX_PX)
                    .map(|i| spot_convolved(&rd, i as f64 * MM_PER_PX).ln())
                    .collect(),
            )
        };
        let Some(base) = profile(ssp, 0.5) else {
            println!("| {ap} | outside the tables |");
            continue;
        };
        let h = 1e-3 * ssp;
        let (Some(p_plus), Some(p_minus), Some(g1), Some(g0)) = (
            profile(ssp + h, 0.5),
            profile(ssp - h, 0.5),
            profile(ssp, 1.0),
            profile(ssp, 0.0),
        ) else {
            continue;
        };
        // Exposure: the spot centre (ring 0) fills 80 % of the well at 1/600 s.
        let peak = base[0].exp();
        let rate = 0.8 * WELL / (peak * (1.0 / 600.0));
        let times: Vec<f64> = (0..13)
            .map(|j| (1.0 / 600.0) * (3.0 * 600.0f64).powf(j as f64 / 12.0))
            .collect();
        let mut fisher = [[0.0f64; 3]; 3];
        let mut fisher_floor = [[0.0f64; 3]; 3];
        let mut rows: Vec<[f64; 3]> = Vec::new();
        let mut used = 0;
        for i in 0..=R_MAX_PX {
            let r = i as f64 * MM_PER_PX;
            if r < SPOT_RADIUS {
                continue;
            }
            let value = base[i].exp(); // Rd [mm⁻²] × rate [e⁻/s per Rd] below
            let Some(var_rel) = pixel_relative_variance(value * rate, &times) else {
                continue;
            };
            let pixels = (2.0 * std::f64::consts::PI * r / MM_PER_PX).max(1.0);
            let w = pixels / var_rel; // 1/var of ln(ring mean)
            let j = [
                (p_plus[i] - p_minus[i]) / (2.0 * h) * ssp, // ∂ ln Rd / ∂ ln σ′s
                g1[i] - g0[i],                              // ∂ ln Rd / ∂g × (g_hi − g_lo)
                1.0,                                        // ∂ ln Rd / ∂ ln k
            ];
            let j = [j[0], j[1] / (g_hi - g_lo), j[2]];
            let w_floor = 1.0 / (var_rel / pixels + FLOOR * FLOOR);
            for a in 0..3 {
                for b in 0..3 {
                    fisher[a][b] += w * j[a] * j[b];
                    fisher_floor[a][b] += w_floor * j[a] * j[b];
                }
            }
            rows.push(j);
            used += 1;
        }
        let cov = invert3(fisher);
        let sd_g = cov[1][1].sqrt();
        let sd_s = cov[0][0].sqrt();
        let corr = cov[0][1] / (sd_s * sd_g);
        let sd_g_floor = invert3(fisher_floor)[1][1].sqrt();
        // Shape signal: 0.05 × ∂lnRd/∂g minus its least-squares (unweighted) fit by a·∂lnRd/∂lnσ′s + b.
        let (mut sxx, mut sx1, mut s11, mut sxy, mut s1y) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for j in &rows {
            let (x, y) = (j[0], 0.05 * j[1]);
            sxx += x * x;
            sx1 += x;
            s11 += 1.0;
            sxy += x * y;
            s1y += y;
        }
        let det = sxx * s11 - sx1 * sx1;
        let (a, b) = ((sxy * s11 - sx1 * s1y) / det, (sxx * s1y - sx1 * sxy) / det);
        let resid: Vec<f64> = rows.iter().map(|j| 0.05 * j[1] - a * j[0] - b).collect();
        let rms = (resid.iter().map(|r| r * r).sum::<f64>() / resid.len() as f64).sqrt();
        let max = resid.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        println!(
            "| {ap} | {used} | {sd_g:.4} | {:.3}% | {corr:+.2} | {sd_g_floor:.3} | {:.2}% / {:.2}% |",
            100.0 * sd_s,
            100.0 * rms,
            100.0 * max
        );
    }
}

/// Rd under a uniform disc spot of radius [`SPOT_RADIUS`] at distance r from its centre:
/// (1/πa²)∫ Rd(|r − p|) dp over the disc (Gauss–Legendre 12 in ρ² and 48 in φ: the midpoint rule).
fn spot_convolved(rd: &dyn Fn(f64) -> f64, r: f64) -> f64 {
    let (nr, nphi) = (12, 48);
    let mut sum = 0.0;
    for i in 0..nr {
        // Equal-area rings: ρ = a √((i + ½)/nr).
        let rho = SPOT_RADIUS * ((i as f64 + 0.5) / nr as f64).sqrt();
        for k in 0..nphi {
            let phi = std::f64::consts::TAU * (k as f64 + 0.5) / nphi as f64;
            let d = (r * r + rho * rho - 2.0 * r * rho * phi.cos())
                .max(0.0)
                .sqrt();
            sum += rd(d.max(1e-4));
        }
    }
    sum / (nr * nphi) as f64
}

/// Relative variance of one pixel's merged radiance, for `rate` electrons per second: inverse-
/// variance combination over the exposures whose code lies in [30, 250]; None below detection.
fn pixel_relative_variance(rate: f64, times: &[f64]) -> Option<f64> {
    let tone = |s: f64| (1.0 + KNEE) * s / (s + KNEE);
    let mut info = 0.0;
    for &t in times {
        let e = rate * t;
        let s = e / WELL;
        let code = 255.0 * tone(s.min(1.0));
        if !(30.0..=250.0).contains(&code) {
            continue;
        }
        let slope = 255.0 * (1.0 + KNEE) * KNEE / (s + KNEE).powi(2) / WELL; // codes per electron
        let q2 = 1.0 / (slope * slope * 12.0);
        let var_e = e + READ * READ + q2;
        info += e * e / var_e; // 1/relative variance of this frame's estimate
    }
    (info > 0.0).then(|| 1.0 / info)
}

/// Inverse of a symmetric positive definite 3×3 matrix (cofactors).
fn invert3(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = c(j, i) / det;
        }
    }
    inv
}
