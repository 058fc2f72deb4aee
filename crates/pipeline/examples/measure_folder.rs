//! One sample folder measured through the library, with exact transport as the forward model:
//! `cargo run --release -p scatterfit-pipeline --example measure_folder -- SAMPLE_DIR`
//! (a folder with a `sample.toml`, e.g. one that `scatterfit demo` or `scatterfit synth` wrote).
use scatterfit_pipeline::{ModelName, Overrides, measure_sample};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .ok_or("usage: measure_folder SAMPLE_DIR")?;
    // The manifest's [fit] choices, with the Monte Carlo model instead of the paper's dipole.
    let overrides = Overrides::default().model(ModelName::Mc);
    let m = measure_sample(dir.as_ref(), &overrides, &|_stage| {})?;
    println!("η = {:.4}", m.eta().value);
    for (channel, fit) in m.fits.iter_channels() {
        let Some(s) = fit.sigma_s_prime() else {
            println!("{channel}: not fitted");
            continue;
        };
        // The total is the quadrature sum of the known terms (the fit's, the spectrophotometer's).
        let total = s.total().unwrap_or(f64::NAN);
        println!("{channel}: σ′s = {:.4} ± {total:.4} mm⁻¹", s.value);
    }
    Ok(())
}
