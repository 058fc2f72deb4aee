//! A port's reading fraction F at one material: the `mc` model's (`Port::reading_of`, the form the
//! pipeline's correction uses) against a direct Monte Carlo twin of the port
//! (`mc::port::simulate_port_reading`: a disc lit uniformly, one bin over the aperture), and the
//! reading Rd·F beside it: is the correction's F right at the *true* material?
//!
//! ```text
//! cargo run --release -p scatterfit-mc --example port_point_check -- \
//!     SIGMA_S_PRIME SIGMA_A ETA G LIT_MM APERTURE_MM PHOTONS [SEED]
//! ```
//! Coefficients in mm⁻¹, port diameters in mm.

use scatterfit_mc::port::simulate_port_reading;
use scatterfit_mc::{Layer, Sample, bundled_grid};
use scatterfit_optics::port::Port;
use scatterfit_optics::{OpticalProperties, ProfileModel};

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a number"))
        .collect();
    let [sp, sa, eta, g, lit, ap, photons] = args[..7] else {
        panic!(
            "usage: port_point_check SIGMA_S_PRIME SIGMA_A ETA G LIT_MM APERTURE_MM PHOTONS [SEED]"
        )
    };
    let seed = args.get(7).map_or(1, |&s| s as u64);
    let port = Port::new(lit, ap).expect("port");
    let props = OpticalProperties::new(sp, sa, eta)
        .and_then(|p| p.with_g(g))
        .expect("props");
    let m = bundled_grid()
        .expect("grid")
        .profile(&props)
        .expect("model");
    let by_loss = port.reading_of(&m);
    let direct = port.reading(&|r| m.rd(r), m.rd_total());
    let sample = Sample::slab(
        Layer::from_reduced(sp, sa, g, eta, f64::INFINITY).expect("layer"),
        1.0,
    )
    .expect("sample");
    let t0 = std::time::Instant::now();
    let mc = simulate_port_reading(sample, &port, photons as u64, seed).expect("twin");
    let f = mc.reading_fraction;
    println!(
        "σ′s {sp} σa {sa} η {eta} g {g}, lit {lit} / aperture {ap} mm [{:.0} s]\n  \
         F: model (by loss) {:.5}, model (direct) {:.5}, engine {:.5} ± {:.5} \
         (model − engine {:+.3} % = {:+.1} s.e.)\n  \
         Rd: model {:.5}, engine {:.5} ± {:.5}\n  \
         reading Rd·F: model {:.5}, engine {:.5} ± {:.5} ({:+.3} %)",
        t0.elapsed().as_secs_f64(),
        by_loss.reading_fraction,
        direct.reading_fraction,
        f.value,
        f.stderr,
        100.0 * (by_loss.reading_fraction / f.value - 1.0),
        (by_loss.reading_fraction - f.value) / f.stderr,
        m.rd_total(),
        mc.rd_total.value,
        mc.rd_total.stderr,
        m.rd_total() * by_loss.reading_fraction,
        mc.rd_read.value,
        mc.rd_read.stderr,
        100.0 * (m.rd_total() * by_loss.reading_fraction / mc.rd_read.value - 1.0),
    );
    // The correction's fixed point with σ′s at the truth: the α′ whose model reading Rd(α′)·F(α′)
    // equals the engine's reading, and the σa = σ′s(1/α′ − 1) it implies; and the reading's
    // sensitivity d ln(Rd·F)/d ln(1 − α′) (near 0: the reading hardly determines α′).
    let grid = bundled_grid().expect("grid");
    let model_at = |a: f64| {
        let p = OpticalProperties::new(sp, sp * (1.0 / a - 1.0), eta)
            .and_then(|p| p.with_g(g))
            .expect("props");
        grid.profile(&p).expect("model")
    };
    let reading_at = |a: f64| {
        let m = model_at(a);
        m.rd_total() * port.reading_of(&m).reading_fraction
    };
    let a_true = sp / (sp + sa);
    let h = 0.01;
    let up = reading_at(1.0 - (1.0 - a_true) * (1.0 + h)).ln();
    let down = reading_at(1.0 - (1.0 - a_true) * (1.0 - h)).ln();
    let slope = (up - down) / (2.0 * h);
    let loss_free = (model_at(1.0 - (1.0 - a_true) * (1.0 + h)).rd_total().ln()
        - model_at(1.0 - (1.0 - a_true) * (1.0 - h)).rd_total().ln())
        / (2.0 * h);
    let want = mc.rd_read.value;
    // Secant iterations on u = ln(1 − α′).
    let mut u0 = (1.0 - a_true).ln();
    let mut u1 = u0 + 0.02;
    let f = |u: f64| reading_at(1.0 - u.exp()).ln() - want.ln();
    let (mut f0, mut f1) = (f(u0), f(u1));
    for _ in 0..30 {
        if (f1 - f0).abs() < 1e-15 {
            break;
        }
        let u2 = u1 - f1 * (u1 - u0) / (f1 - f0);
        (u0, f0) = (u1, f1);
        u1 = u2;
        f1 = f(u1);
        if f1.abs() < 1e-12 {
            break;
        }
    }
    let a_fix = 1.0 - u1.exp();
    let sa_fix = sp * (1.0 / a_fix - 1.0);
    // How F moves with σ′s at fixed α′ (Rd does not: a half-space's total depends on α′ and η
    // only), and so what a fit whose σ′s is 1 % off does to the corrected σa through F:
    // d ln(1 − α′) = −(d ln F/d ln σ′s)·δ/slope, d ln σa = δ + d ln(1 − α′).
    let f_at = |s: f64| {
        let p = OpticalProperties::new(s, s * (1.0 / a_true - 1.0), eta)
            .and_then(|p| p.with_g(g))
            .expect("props");
        port.reading_of(&grid.profile(&p).expect("model"))
            .reading_fraction
    };
    let dlnf_dlns = (f_at(sp * (1.0 + h)).ln() - f_at(sp * (1.0 - h)).ln()) / (2.0 * h);
    println!(
        "  d ln F/d ln σ′s (α′ fixed) = {dlnf_dlns:+.4}: a fitted σ′s 1 % high moves the \
         corrected σa by {:+.1} %",
        100.0 * (0.01 - dlnf_dlns * 0.01 / slope),
    );
    println!(
        "  d ln(Rd·F)/d ln(1 − α′) = {slope:+.4}, d ln Rd/d ln(1 − α′) = {loss_free:+.4} \
         (A = {:.2}); σ′s at the truth, the reading inverted: α′ {a_fix:.6} \
         (truth {a_true:.6}), σa {:+.2} % (1 s.e. of the reading: {:.2} %)",
        loss_free / slope,
        100.0 * (sa_fix / sa - 1.0),
        100.0 * mc.rd_read.stderr / mc.rd_read.value / slope.abs(),
    );
}
