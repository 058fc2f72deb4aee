//! What a simulation and a table build report, as `scatterfit simulate` and `scatterfit table`
//! print them: [`SimulationReport`] (the result with its inputs and timing, as JSON or text, and
//! its profile as CSV) and [`TableSummary`] (a table's totals per albedo, as JSON or text).

use std::fmt::Write as _;
use std::path::PathBuf;

use serde::Serialize;

use crate::cache::CacheStatus;
use crate::{McMean, McTable, McTableSpec, SimulationResult};

/// A simulation's result with its inputs and timing (`simulate --json` prints it as is).
#[derive(Debug, Serialize)]
pub struct SimulationReport<'a> {
    /// Reduced scattering coefficient σ′s \[mm⁻¹\].
    pub sigma_s_prime: f64,
    /// Absorption coefficient σa \[mm⁻¹\].
    pub sigma_a: f64,
    /// Relative refractive index η.
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g.
    pub g: f64,
    /// Slab thickness \[mm\]; `None` for a half-space.
    pub thickness_mm: Option<f64>,
    /// The beam as given (`pencil`, `disk:R`, `gauss:R`).
    pub beam: &'a str,
    /// Angle of incidence in air \[degrees\].
    pub incidence_deg: f64,
    /// Wall time \[s\].
    pub elapsed_s: f64,
    /// Photons traced per second.
    pub photons_per_s: f64,
    /// Threads used.
    pub threads: usize,
    /// The result.
    pub result: &'a SimulationResult,
}

impl SimulationReport<'_> {
    /// The summary as `scatterfit simulate` prints it: photons, interactions, the four fractions
    /// of the energy balance with their standard errors, and the speed; one line each.
    pub fn text(&self) -> String {
        let r = self.result;
        let e = |x: McMean| format!("{:.6} ± {:.6}", x.value, x.stderr);
        let mut s = String::new();
        let _ = writeln!(s, "photons            {}", r.photons);
        let _ = writeln!(
            s,
            "interactions       {} ({:.1} per photon)",
            r.interactions,
            r.interactions as f64 / r.photons as f64
        );
        let _ = writeln!(s, "specular R_sp      {:.6}", r.specular);
        let _ = writeln!(s, "diffuse Rd         {}", e(r.rd_total));
        let _ = writeln!(s, "transmitted Tt     {}", e(r.transmittance));
        let _ = writeln!(s, "absorbed A         {}", e(r.absorbed));
        let _ = writeln!(s, "sum (should be 1)  {}", e(r.conservation));
        let _ = writeln!(
            s,
            "speed              {:.3e} photons/s on {} threads ({:.2} s)",
            self.photons_per_s, self.threads, self.elapsed_s
        );
        s
    }
}

impl SimulationResult {
    /// Rd(r) as CSV: `r_inner_mm,r_outer_mm,r_mm,rd_per_mm2,rd_stderr_per_mm2`, one row per annulus
    /// of the grid (radii in mm, Rd(r) in mm⁻²).
    pub fn profile_csv(&self) -> String {
        let mut csv = String::from("r_inner_mm,r_outer_mm,r_mm,rd_per_mm2,rd_stderr_per_mm2\n");
        let g = &self.grid;
        for (i, e) in self.rd_profile.iter().enumerate() {
            let (inner, outer, mid) = (g.edges()[i], g.edges()[i + 1], g.center(i));
            let _ = writeln!(csv, "{inner},{outer},{mid},{:e},{:e}", e.value, e.stderr);
        }
        csv
    }
}

/// A Monte Carlo table, loaded or built, as `scatterfit table` reports it (`--json` prints it as
/// is).
#[derive(Debug, Serialize)]
pub struct TableSummary {
    /// The cache file.
    pub path: PathBuf,
    /// `loaded from cache` or `built and cached`.
    pub status: &'static str,
    /// The file the table was also written to, if any.
    pub output: Option<PathBuf>,
    /// Relative refractive index η.
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g.
    pub g: f64,
    /// The albedo nodes (single-scattering albedo a; α′ for g = 0).
    pub albedos: Vec<f64>,
    /// Total diffuse reflectance at each albedo.
    pub rd_total: Vec<f64>,
    /// Its standard error.
    pub rd_total_stderr: Vec<f64>,
    /// Radial bins of the profiles.
    pub radial_bins: usize,
    /// Photons per stratum: paths cut at 64 and 1024 interactions, and full length.
    pub photons: Vec<u64>,
}

impl TableSummary {
    /// The summary of `table`, made to `spec`, found in the cache at `path` (`status`) and written
    /// to `output`.
    pub fn new(
        table: &McTable,
        spec: &McTableSpec,
        status: CacheStatus,
        path: PathBuf,
        output: Option<PathBuf>,
    ) -> Self {
        let (tot, se) = table.totals();
        Self {
            path,
            status: match status {
                CacheStatus::Loaded => "loaded from cache",
                _ => "built and cached",
            },
            output,
            eta: spec.eta,
            g: spec.g,
            albedos: table.albedos().to_vec(),
            rd_total: tot.to_vec(),
            rd_total_stderr: se.to_vec(),
            radial_bins: spec.radial_bins,
            photons: spec.photons.clone(),
        }
    }

    /// The summary as `scatterfit table` prints it: the file, the spec, and Rd total ± its standard
    /// error per albedo; one line each.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "table   {} ({})", self.path.display(), self.status);
        if let Some(out) = &self.output {
            let _ = writeln!(s, "wrote   {}", out.display());
        }
        let photons: Vec<String> = self.photons.iter().map(u64::to_string).collect();
        let _ = writeln!(
            s,
            "eta {}  g {}  {} radial bins  photons {}",
            self.eta,
            self.g,
            self.radial_bins,
            photons.join(" + ")
        );
        let head = if self.g == 0.0 { "albedo'" } else { "albedo" };
        let _ = writeln!(s, "{head:>10} {:>12} {:>10}", "Rd total", "s.e.");
        for ((a, r), e) in self
            .albedos
            .iter()
            .zip(&self.rd_total)
            .zip(&self.rd_total_stderr)
        {
            let _ = writeln!(s, "{a:>10.6} {r:>12.6} {e:>10.6}");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use crate::{Beam, Layer, RadialGrid, Sample, Simulation};

    /// The profile CSV has one row per annulus, its edges those of the grid, and Rd(r) read back
    /// from it integrates (Σ Rd(r) × annulus area) to the result's total Rd.
    #[test]
    fn profile_csv_holds_the_grid_and_the_total() {
        let sample = Sample::slab(Layer::new(0.1, 1.0, 0.0, 1.4, f64::INFINITY).unwrap(), 1.0);
        let grid = RadialGrid::uniform(0.5, 40).unwrap();
        let sim = Simulation::new(sample.unwrap(), Beam::pencil(), grid, 2000, 3).unwrap();
        let r = sim.run();
        let csv = r.profile_csv();
        let rows: Vec<Vec<f64>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 40);
        assert_eq!((rows[0][0], rows[39][1]), (0.0, 20.0));
        let inside: f64 = rows
            .iter()
            .map(|c| c[3] * std::f64::consts::PI * (c[1] * c[1] - c[0] * c[0]))
            .sum();
        // Light leaving beyond 20 mm is not in the profile: at most the total, and most of it.
        assert!(inside <= r.rd_total.value * (1.0 + 1e-9), "{inside}");
        assert!(inside > 0.9 * r.rd_total.value, "{inside}");
    }
}
