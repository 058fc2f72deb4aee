//! `scatterfit demo`: the pipeline on built-in synthetic measurements of the seven materials of Choi,
//! Lee & Chin (2014, Table 1), with the truth printed beside what the tool recovers.
//!
//! So far the demo covers the spectrophotometer stage: for each material it synthesises a d/8 reading
//! (`scatterfit-synth`: SCE with the material's dipole diffuse colour, SCI adding the exact Fresnel
//! reflectance of its η), writes it as `<out>/<material>/spectro.csv`, reads it back through the same
//! parser as `scatterfit spectro`, and recovers η and α′ per channel.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use scatterfit_optics::dipole::rd_total;
use scatterfit_optics::spectro::{SpectroOptions, analyse};
use scatterfit_synth::materials::CHOI_2014;
use serde::Serialize;

/// Arguments of `scatterfit demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the synthetic measurements and the summary (created if missing).
    #[arg(long, default_value = "scatterfit-demo")]
    pub out_dir: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One material's row of the demo summary.
#[derive(Debug, Serialize)]
struct Row {
    name: &'static str,
    eta_true: f64,
    eta_recovered: f64,
    albedo_prime_true: [f64; 3],
    albedo_prime_recovered: [Option<f64>; 3],
    spectro_csv: String,
}

/// Runs `scatterfit demo`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating the demo folder {}", args.out_dir.display()))?;
    let mut rows = Vec::new();
    for m in &CHOI_2014 {
        let albedo = m.albedo_prime();
        let rd: [f64; 3] = std::array::from_fn(|c| rd_total(albedo[c], m.eta));
        let reading = scatterfit_synth::spectro::reading_for(rd, m.eta)
            .with_context(|| format!("synthesising the spectro reading of {}", m.name))?;
        let dir = args.out_dir.join(m.name);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let path = dir.join("spectro.csv");
        let mut text = format!(
            "# synthetic d/8 reading of {} (Choi, Lee & Chin 2014, Table 1), made by `scatterfit demo`\n\
             wavelength_nm,sci,sce\n",
            m.name
        );
        for i in 0..reading.wavelengths_nm.len() {
            writeln!(
                text,
                "{},{:.6},{:.6}",
                reading.wavelengths_nm[i], reading.sci[i], reading.sce[i]
            )?;
        }
        scatterfit_io::atomic::write_atomic(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        let back = scatterfit_io::spectro::read_spectro_csv(&path)?;
        let analysis = analyse(&back, &SpectroOptions::default())
            .with_context(|| format!("{}", path.display()))?;
        rows.push(Row {
            name: m.name,
            eta_true: m.eta,
            eta_recovered: analysis.eta,
            albedo_prime_true: albedo,
            albedo_prime_recovered: std::array::from_fn(|c| analysis.channels[c].albedo_prime),
            spectro_csv: path.display().to_string(),
        });
    }
    crate::output::write_json_file(&args.out_dir.join("demo-summary.json"), &rows)?;
    if args.json {
        crate::output::print_json(&rows)?;
    } else {
        println!(
            "Spectrophotometer stage on synthetic readings of Choi, Lee & Chin (2014), Table 1"
        );
        println!(
            "(readings in {}; run `scatterfit spectro FILE` on any of them)\n",
            args.out_dir.display()
        );
        println!(
            "{:<14} {:>7} {:>9}   {:<26} {:<26}",
            "material", "η true", "η found", "α′ true (R, G, B)", "α′ found (R, G, B)"
        );
        for r in &rows {
            let t = r.albedo_prime_true;
            let f =
                |c: usize| r.albedo_prime_recovered[c].map_or("—".into(), |v| format!("{v:.5}"));
            println!(
                "{:<14} {:>7.4} {:>9.4}   {:.5} {:.5} {:.5}    {} {} {}",
                r.name,
                r.eta_true,
                r.eta_recovered,
                t[0],
                t[1],
                t[2],
                f(0),
                f(1),
                f(2)
            );
        }
        println!(
            "\nsummary: {}",
            args.out_dir.join("demo-summary.json").display()
        );
    }
    let complete = rows
        .iter()
        .all(|r| r.albedo_prime_recovered.iter().all(Option::is_some));
    Ok(if complete {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
