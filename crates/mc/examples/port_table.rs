//! What a spectrophotometer port reads of a material: the reading fraction F = C/(K(0)·Rd)
//! (`scatterfit_optics::port`) of the shipped g = 0 `mc` model, for common d/8 ports over σ′t and α′
//! at η = 1.5 (BENCHMARKS.md, "The spectrophotometer port").
//!
//! Run: `cargo run --release -p scatterfit-mc --example port_table`

use scatterfit_mc::McTableSet;
use scatterfit_mc::model::McProfile;
use scatterfit_optics::OpticalProperties;
use scatterfit_optics::port::Port;

fn main() {
    let set = McTableSet::bundled().expect("bundled tables");
    let ports = [(8.0, 8.0), (14.0, 8.0), (25.0, 25.0)];
    println!("| σ′t [mm⁻¹] | α′ | F, 8 mm lit 8 | F, 8 mm lit 14 | F, 25 mm lit 25 |");
    println!("|---|---|---|---|---|");
    for sigma_t in [0.5, 1.0, 2.0, 5.0] {
        for ap in [0.9, 0.99, 0.999, 0.9999] {
            let props = OpticalProperties::new(ap * sigma_t, (1.0 - ap) * sigma_t, 1.5).unwrap();
            let m = McProfile::new(&set, &props).unwrap();
            let f: Vec<String> = ports
                .iter()
                .map(|&(ill, ap_mm)| {
                    let p = Port::new(ill, ap_mm).unwrap();
                    format!("{:.4}", p.reading_of(&m).reading_fraction)
                })
                .collect();
            println!("| {sigma_t} | {ap} | {} |", f.join(" | "));
        }
    }
}
