//! η interpolation of the `mc` model in isolation: a table built at ETA (default layout, PHOTONS
//! full-length photons) against the shipped set interpolated to ETA, per albedo, RMS and largest
//! relative difference over ρ ∈ [0.3, 50] where R̂ > 1e-6 R̂(0.5), and the totals.
//! Run: `cargo run --release -p scatterfit-mc --example mc_eta_check -- ETA PHOTONS CACHE_DIR`
use scatterfit_mc::model::{McProfile, McTable, McTableSet, McTableSpec};
use scatterfit_optics::{OpticalProperties, ProfileModel};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let eta: f64 = args[1].parse().expect("η");
    let photons = args[2].parse::<f64>().expect("photons") as u64;
    let spec = McTableSpec::new(eta, 0.0, photons).expect("spec");
    let t0 = std::time::Instant::now();
    let (table, status, _) =
        McTable::load_or_build(&spec, std::path::Path::new(&args[3]), &|_, _| {}).expect("table");
    println!(
        "table at η {eta}: {status:?} in {:.0} s",
        t0.elapsed().as_secs_f64()
    );
    let direct = McTableSet::new(vec![table]).expect("set");
    let shipped = McTableSet::bundled().expect("bundled");
    for a in [0.3, 0.6, 0.9, 0.97, 0.99, 0.999, 0.9995, 0.9999] {
        let p = OpticalProperties::new(a, 1.0 - a, eta).expect("props");
        let (d, m) = (
            McProfile::new(&direct, &p).expect("model"),
            McProfile::new(&shipped, &p).expect("model"),
        );
        let (mut s2, mut mx, mut n) = (0.0f64, 0.0f64, 0);
        let mut rho = 0.3;
        while rho < 50.0 {
            if d.rd(rho) > 1e-6 * d.rd(0.5) {
                let e = m.rd(rho) / d.rd(rho) - 1.0;
                s2 += e * e;
                mx = mx.max(e.abs());
                n += 1;
            }
            rho *= 1.02;
        }
        println!(
            "α′ {a:<6}: RMS {:.3} % max {:.3} %, total {:.5} vs {:.5} ({:+.3} %)",
            100.0 * (s2 / n as f64).sqrt(),
            100.0 * mx,
            m.rd_total(),
            d.rd_total(),
            100.0 * (m.rd_total() / d.rd_total() - 1.0)
        );
    }
}
