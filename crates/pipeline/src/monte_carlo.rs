//! The Monte Carlo runs a user asks for by their numbers (`scatterfit simulate`, `scatterfit
//! table`): typed settings → a checked [`Simulation`] or [`McTableSpec`]. Every range is checked,
//! then the memory the settings size and the expected work (the engine's cost estimate,
//! `scatterfit_mc::CostEstimate`) against the budgets, before anything is allocated or traced; a
//! refusal names the setting by its command-line flag, its value and the valid range.

use scatterfit_io::budget::{OverBudget, check_memory, describe_seconds};
use scatterfit_io::escape::number as show;
#[cfg(feature = "clap")]
use scatterfit_io::flags::{parse_count, parse_finite, parse_size};
use scatterfit_mc::{
    Beam, BeamProfile, Layer, McError, McTableSpec, RadialGrid, Sample, Simulation,
};

/// Why the settings cannot run.
#[derive(Debug, thiserror::Error)]
pub enum MonteCarloSettingsError {
    /// A setting outside its range, or a run beyond the work budget: what to change.
    #[error("{0}")]
    Refused(String),
    /// The memory the settings size is beyond the budget.
    #[error(transparent)]
    OverBudget(#[from] OverBudget),
    /// The engine refused the settings, with what was being made.
    #[error("{what}")]
    Engine {
        /// What was being made, e.g. `bad material parameters`.
        what: String,
        /// The engine's reason.
        #[source]
        source: McError,
    },
    /// The engine refused the settings.
    #[error(transparent)]
    Mc(#[from] McError),
}

fn refuse(ok: bool, text: impl FnOnce() -> String) -> Result<(), MonteCarloSettingsError> {
    if ok {
        Ok(())
    } else {
        Err(MonteCarloSettingsError::Refused(text()))
    }
}

fn engine(what: &str) -> impl FnOnce(McError) -> MonteCarloSettingsError {
    let what = what.to_owned();
    |source| MonteCarloSettingsError::Engine { what, source }
}

/// Largest η a simulation accepts: beyond any solid's (diamond 2.42, germanium in the infrared 4).
pub const MAX_ETA: f64 = 10.0;

/// Help text of `--max-interactions`, the work budget of `scatterfit simulate` and `table`.
pub const MAX_INTERACTIONS_HELP: &str = "Work budget: the most photon interactions (scattering \
     events, all photons together) the run may be expected to take, estimated before it starts from \
     σs, σa, g, η and the thickness; a count (default 1e12: about 7 h on 2 cores at 2e7 \
     interactions/s per thread). Raise it to allow longer runs";

/// A simulation's settings (`scatterfit simulate`'s flags; their help is the field's text). Every
/// number is checked by [`SimulateSettings::configure`], not by the parser.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct SimulateSettings {
    /// Reduced scattering coefficient σ′s [mm⁻¹]: finite, ≥ 0.
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true, value_parser = parse_finite))]
    pub sigma_s_prime: f64,
    /// Absorption coefficient σa [mm⁻¹]: finite, ≥ 0; > 0 for a half-space (no --thickness-mm),
    /// where a photon without absorption never has to stop.
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true, value_parser = parse_finite))]
    pub sigma_a: f64,
    /// Relative refractive index η of the material (the outside is air, n = 1): 1 to 10 (below 1
    /// with --allow-eta-below-one).
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true, value_parser = parse_finite))]
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g, in (−1, 1); the scattering coefficient is σ′s/(1 − g), so the
    /// work grows like 1/(1 − g) as g → 1.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite))]
    pub g: f64,
    /// Slab thickness \[mm\]: finite, > 0; omit for a half-space.
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true, value_parser = parse_finite))]
    pub thickness_mm: Option<f64>,
    /// Number of photons: a count ≥ 1 (1e6 is fine); the expected work must fit --max-interactions.
    #[cfg_attr(feature = "clap", arg(long, default_value = "1000000", value_parser = parse_count))]
    pub photons: u64,
    /// Seed of the random streams, 0 to 2⁶⁴ − 1 (the result is identical for any thread count).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 1))]
    pub seed: u64,
    /// Beam: `pencil`, `disk:R` (uniform disk of radius R mm, R in (0, 1000]) or `gauss:R`
    /// (Gaussian, 1/e² radius R mm, R in (0, 1000]).
    #[cfg_attr(feature = "clap", arg(long, default_value = "pencil"))]
    pub beam: String,
    /// Angle of incidence \[degrees\] in air, in [0, 90) (0 = normal).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite))]
    pub incidence_deg: f64,
    /// Outer radius of the Rd(r) grid \[mm\]: in (0, 10⁶].
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 10.0, value_parser = parse_finite))]
    pub r_max_mm: f64,
    /// Number of radial bins (uniform width r_max/bins): a count ≥ 1, within the memory budget
    /// (about 1 KiB per bin; 8 GiB holds 8 million).
    #[cfg_attr(feature = "clap", arg(long, default_value = "200", value_parser = parse_size))]
    pub bins: usize,
    /// Also tally reflectance by exit angle in this many bins over [0°, 90°]: a count, 0 (off) or
    /// more, within the memory budget with --bins.
    #[cfg_attr(feature = "clap", arg(long, default_value = "0", value_parser = parse_size))]
    pub angle_bins: usize,
    /// Accept η < 1 (a material optically thinner than air).
    #[cfg_attr(feature = "clap", arg(long))]
    pub allow_eta_below_one: bool,
    /// The work budget: the most interactions the run may be expected to take.
    #[cfg_attr(feature = "clap", arg(long, default_value = "1e12", value_parser = parse_count, help = MAX_INTERACTIONS_HELP))]
    pub max_interactions: u64,
    /// The memory budget \[bytes\] (on the command line `--max-memory-mib`, set after parsing).
    #[cfg_attr(feature = "clap", arg(skip))]
    pub memory_budget: u64,
}

/// Parses a beam: `pencil`, `disk:R`, `gauss:R` (R in mm, (0, 1000]).
///
/// # Errors
/// Anything else, or a radius out of range.
pub fn parse_beam(text: &str) -> Result<BeamProfile, MonteCarloSettingsError> {
    let radius = |r: &str| -> Result<f64, MonteCarloSettingsError> {
        let v = r.trim().parse::<f64>().map_err(|e| {
            MonteCarloSettingsError::Refused(format!(
                "--beam {text}: `{r}` is not a radius in mm: {e}"
            ))
        })?;
        refuse(v > 0.0 && v <= 1000.0, || {
            format!("--beam {text}: the beam radius must lie in (0, 1000] mm")
        })?;
        Ok(v)
    };
    match text.split_once(':') {
        None if text == "pencil" => Ok(BeamProfile::Pencil),
        Some(("disk", r)) => Ok(BeamProfile::Disk { radius: radius(r)? }),
        Some(("gauss" | "gaussian", r)) => Ok(BeamProfile::Gaussian { radius: radius(r)? }),
        _ => Err(MonteCarloSettingsError::Refused(format!(
            "--beam {text}: expected pencil, disk:R or gauss:R (R in mm)"
        ))),
    }
}

impl SimulateSettings {
    /// The simulation: every range, then the memory of the tallies (before the grid is made) and
    /// the expected work (before any photon is traced) on `threads` threads.
    ///
    /// # Errors
    /// The first setting out of range, the memory or the work over its budget.
    pub fn configure(&self, threads: usize) -> Result<Simulation, MonteCarloSettingsError> {
        let range = |ok: bool, flag: &str, value: f64, rule: &str| {
            refuse(ok, || format!("{flag} {}: {rule}", show(value)))
        };
        range(
            self.sigma_s_prime >= 0.0,
            "--sigma-s-prime",
            self.sigma_s_prime,
            "the reduced scattering coefficient must be ≥ 0 mm⁻¹",
        )?;
        range(
            self.sigma_a >= 0.0,
            "--sigma-a",
            self.sigma_a,
            "the absorption coefficient must be ≥ 0 mm⁻¹",
        )?;
        range(
            self.eta > 0.0 && self.eta <= MAX_ETA,
            "--eta",
            self.eta,
            "the relative refractive index must lie in (0, 10]",
        )?;
        refuse(self.eta >= 1.0 || self.allow_eta_below_one, || {
            format!(
                "--eta {}: below 1 means the material is optically thinner than air, which is \
                 unusual for a solid; pass --allow-eta-below-one if you mean it",
                show(self.eta)
            )
        })?;
        range(
            self.g > -1.0 && self.g < 1.0,
            "--g",
            self.g,
            "the Henyey–Greenstein asymmetry must lie in (−1, 1)",
        )?;
        if let Some(t) = self.thickness_mm {
            range(
                t > 0.0,
                "--thickness-mm",
                t,
                "the slab thickness must be > 0 mm (omit it for a half-space)",
            )?;
        }
        range(
            (0.0..90.0).contains(&self.incidence_deg),
            "--incidence-deg",
            self.incidence_deg,
            "the angle of incidence must lie in [0, 90) degrees",
        )?;
        // Below a micrometre the bins' areas (π r², down to 1e-600 mm² for 1e-300) underflow to 0
        // and the tallies divide by them: NaN. No measurement resolves less than a micrometre.
        range(
            (1e-3..=1e6).contains(&self.r_max_mm),
            "--r-max-mm",
            self.r_max_mm,
            "the outer radius must lie in [1e-3, 1e6] mm (a micrometre to a kilometre)",
        )?;
        refuse(self.photons > 0, || {
            "--photons 0: trace at least one photon".into()
        })?;
        refuse(self.bins > 0, || {
            "--bins 0: the radial grid needs at least one bin".into()
        })?;
        check_memory(
            &format!(
                "tallying {} radial and {} angular bins",
                self.bins, self.angle_bins
            ),
            Simulation::tally_memory_bytes(self.bins, self.angle_bins),
            self.memory_budget,
        )?;
        refuse(self.sigma_a != 0.0 || self.thickness_mm.is_some(), || {
            "--sigma-a 0 without --thickness-mm: in a half-space a photon without absorption has \
             no finite mean path (it must wander back to the surface), so the simulation would \
             never end; give a slab thickness with --thickness-mm, or a small absorption such as \
             --sigma-a 1e-4 (the run's cost is then estimated and checked before it starts)"
                .into()
        })?;
        let layer = Layer::from_reduced(
            self.sigma_s_prime,
            self.sigma_a,
            self.g,
            self.eta,
            self.thickness_mm.unwrap_or(f64::INFINITY),
        )
        .map_err(engine("bad material parameters"))?;
        let sample = Sample::slab(layer, 1.0)?;
        let beam = Beam::new(parse_beam(&self.beam)?)
            .map_err(engine("bad --beam"))?
            .with_incidence(self.incidence_deg.to_radians())
            .map_err(engine("bad --incidence-deg (must lie in [0, 90))"))?;
        let grid = RadialGrid::uniform(self.r_max_mm / self.bins as f64, self.bins)?;
        let sim = Simulation::new(sample, beam, grid, self.photons, self.seed)?
            .with_angle_bins(self.angle_bins);
        let cost = sim.cost_estimate();
        refuse(cost.interactions <= self.max_interactions as f64, || {
            format!(
                "this run is expected to take about {:.1e} interactions ({:.3e} per photon × {} \
                 photons; σs = σ′s/(1 − g) = {:.4e} mm⁻¹, σa = {} mm⁻¹{}), about {} on {threads} \
                 threads, more than the work budget of {:.1e} (--max-interactions); use fewer \
                 photons, a larger σa{}, a g further from 1, or raise --max-interactions if you \
                 mean it",
                cost.interactions,
                cost.interactions_per_photon,
                self.photons,
                layer.sigma_s(),
                self.sigma_a,
                self.thickness_mm
                    .map_or_else(|| ", half-space".to_owned(), |t| format!(", {t} mm thick")),
                describe_seconds(cost.seconds(threads)),
                self.max_interactions as f64,
                if self.thickness_mm.is_some() {
                    ", a thinner slab"
                } else {
                    ""
                },
            )
        })?;
        Ok(sim)
    }
}

/// Most albedo nodes of a table: far more than interpolation needs.
pub const MAX_TABLE_ALBEDOS: usize = 1000;

/// Albedo nodes of a table built with other settings than the shipped g = 0 ones
/// (`McTableSpec::new`'s layout).
pub const DEFAULT_TABLE_ALBEDOS: usize = 64;

/// Full-length photons of a table built with other settings than the shipped ones.
pub const DEFAULT_TABLE_PHOTONS: u64 = 2_000_000;

/// A table's settings (`scatterfit table`'s flags; their help is the field's text), checked by
/// [`TableSettings::spec`].
#[derive(Debug, Clone)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct TableSettings {
    /// Relative refractive index η of the material: 1 to 10.
    #[cfg_attr(feature = "clap", arg(long, allow_hyphen_values = true, value_parser = parse_finite))]
    pub eta: f64,
    /// Henyey–Greenstein asymmetry g, in (−1, 1). The table is in the single-scattering albedo
    /// a = σs/σt (0.02 … 0.9999), so for g > 0 it covers α′ = a(1 − g)/(1 − ag) up to less than
    /// 0.9999.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite))]
    pub g: f64,
    /// Number of albedo nodes (equally spaced in √(1 − a) from a = 0.02 to 0.9999): a count, 4 to
    /// 1000 (default 64; without --albedos and --photons a g = 0 table is built exactly as the
    /// shipped ones: 128 albedos, 4·10⁶ full-length photons, 4× and 8× as many in the shorter
    /// strata, a seed per η, and a node at a = 0.01 from 6.4·10⁸ short photons — 2–8 min on two
    /// cores).
    #[cfg_attr(feature = "clap", arg(long, value_parser = parse_size))]
    pub albedos: Option<usize>,
    /// Full-length photons: a count ≥ 1; 4× and 16× as many photons trace the paths shorter than
    /// 1024 and 64 interactions (default 2e6); the expected work must fit --max-interactions.
    #[cfg_attr(feature = "clap", arg(long, value_parser = parse_count))]
    pub photons: Option<u64>,
    /// A coarse table that builds in seconds (20 000 full-length photons, the default albedos);
    /// overrides --photons and --albedos. Enough for g = 0 and 0.5; at g ≳ 0.7 the lowest albedos
    /// then reflect too little light to smooth: use --photons 2e5 or more.
    #[cfg_attr(feature = "clap", arg(long))]
    pub coarse: bool,
    /// The work budget of one shard: the most interactions it may be expected to take (on the
    /// command line `--max-interactions`, set after parsing).
    #[cfg_attr(feature = "clap", arg(skip))]
    pub max_interactions: u64,
    /// The memory budget \[bytes\] (on the command line `--max-memory-mib`, set after parsing).
    #[cfg_attr(feature = "clap", arg(skip))]
    pub memory_budget: u64,
}

impl TableSettings {
    /// The table's spec with its work split into `shards` shards (the work budget is per shard):
    /// the shipped tables' spec for g = 0 without `albedos` and `photons`; every range, then the
    /// expected work and memory, checked before anything is built.
    ///
    /// # Errors
    /// A setting out of range, the memory or the work over its budget.
    pub fn spec(
        &self,
        shards: u64,
        threads: usize,
    ) -> Result<McTableSpec, MonteCarloSettingsError> {
        refuse(self.eta >= 1.0 && self.eta <= 10.0, || {
            format!(
                "--eta {}: the relative refractive index must lie in [1, 10]",
                show(self.eta)
            )
        })?;
        refuse(self.g > -1.0 && self.g < 1.0, || {
            format!(
                "--g {}: the Henyey–Greenstein asymmetry must lie in (−1, 1)",
                show(self.g)
            )
        })?;
        if !self.coarse {
            if let Some(n) = self.albedos {
                refuse((4..=MAX_TABLE_ALBEDOS).contains(&n), || {
                    format!("--albedos {n}: a table has 4 to {MAX_TABLE_ALBEDOS} albedos")
                })?;
            }
            refuse(self.photons != Some(0), || {
                "--photons 0: trace at least one photon".into()
            })?;
        }
        let spec = if self.coarse {
            McTableSpec::coarse(self.eta, self.g)
        } else if self.g == 0.0 && self.albedos.is_none() && self.photons.is_none() {
            McTableSpec::shipped(self.eta)
        } else {
            McTableSpec::new(
                self.eta,
                self.g,
                self.photons.unwrap_or(DEFAULT_TABLE_PHOTONS),
            )
            .map(|mut s| {
                s.albedo_count = self.albedos.unwrap_or(DEFAULT_TABLE_ALBEDOS);
                s
            })
        }
        .map_err(engine("bad table parameters"))?;
        let mut cost = spec.cost_estimate()?;
        // A shard does its share of the work.
        cost.interactions /= shards as f64;
        // The table itself beside the tallies: coefficients and raw profiles, and the JSON text.
        let table_bytes = (spec.albedo_count as u64) * (spec.radial_bins as u64 + 64) * 8 * 6;
        check_memory(
            "the table",
            cost.memory_bytes + table_bytes,
            self.memory_budget,
        )?;
        refuse(cost.interactions <= self.max_interactions as f64, || {
            format!(
                "building this table is expected to take about {:.1e} interactions ({} photons, \
                 {:.3e} per photon on average; η and g lengthen the walks), about {} on {threads} \
                 threads, more than the work budget of {:.1e} (--max-interactions); use fewer \
                 photons, or raise --max-interactions",
                cost.interactions,
                spec.photons.iter().sum::<u64>(),
                cost.interactions_per_photon,
                describe_seconds(cost.seconds(threads)),
                self.max_interactions as f64,
            )
        })?;
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simulate() -> SimulateSettings {
        SimulateSettings {
            sigma_s_prime: 1.0,
            sigma_a: 0.1,
            eta: 1.3,
            g: 0.0,
            thickness_mm: None,
            photons: 1000,
            seed: 1,
            beam: "pencil".into(),
            incidence_deg: 0.0,
            r_max_mm: 10.0,
            bins: 200,
            angle_bins: 0,
            allow_eta_below_one: false,
            max_interactions: 1_000_000_000_000,
            memory_budget: 1 << 30,
        }
    }

    fn table() -> TableSettings {
        TableSettings {
            eta: 1.3,
            g: 0.0,
            albedos: None,
            photons: None,
            coarse: false,
            max_interactions: 1_000_000_000_000,
            memory_budget: 1 << 32,
        }
    }

    #[test]
    fn beams_parse_and_bad_ones_are_named() {
        assert!(matches!(parse_beam("pencil"), Ok(BeamProfile::Pencil)));
        assert!(matches!(
            parse_beam("gauss:0.5"),
            Ok(BeamProfile::Gaussian { radius }) if radius == 0.5
        ));
        let e = parse_beam("disk:0").unwrap_err().to_string();
        assert_eq!(e, "--beam disk:0: the beam radius must lie in (0, 1000] mm");
        let e = parse_beam("laser").unwrap_err().to_string();
        assert!(e.contains("expected pencil, disk:R or gauss:R"), "{e}");
        let e = parse_beam("disk:wide").unwrap_err().to_string();
        assert!(
            e.starts_with("--beam disk:wide: `wide` is not a radius in mm"),
            "{e}"
        );
    }

    #[test]
    fn a_simulation_takes_its_settings() {
        let s = SimulateSettings {
            beam: "disk:1".into(),
            thickness_mm: Some(2.0),
            bins: 50,
            ..simulate()
        };
        let sim = s.configure(2).unwrap();
        assert_eq!(sim.photons(), 1000);
        assert_eq!(sim.memory_bytes(), Simulation::tally_memory_bytes(50, 0));
    }

    #[test]
    fn a_simulation_out_of_range_or_budget_is_refused_naming_the_flag() {
        let e = |s: SimulateSettings| s.configure(2).unwrap_err().to_string();
        assert_eq!(
            e(SimulateSettings {
                g: 1.0,
                ..simulate()
            }),
            "--g 1: the Henyey–Greenstein asymmetry must lie in (−1, 1)"
        );
        assert!(
            e(SimulateSettings {
                eta: 0.9,
                ..simulate()
            })
            .contains("--allow-eta-below-one")
        );
        assert!(
            e(SimulateSettings {
                sigma_a: 0.0,
                ..simulate()
            })
            .starts_with("--sigma-a 0 without --thickness-mm")
        );
        assert!(
            e(SimulateSettings {
                memory_budget: 1024,
                ..simulate()
            })
            .starts_with("tallying 200 radial and 0 angular bins needs")
        );
        assert!(
            e(SimulateSettings {
                max_interactions: 10,
                ..simulate()
            })
            .contains("more than the work budget of 1.0e1 (--max-interactions)")
        );
    }

    #[test]
    fn a_table_spec_is_the_shipped_one_unless_asked_otherwise() {
        let shipped = table().spec(1, 2).unwrap();
        assert_eq!(shipped, McTableSpec::shipped(1.3).unwrap());
        let custom = TableSettings {
            albedos: Some(16),
            photons: Some(1000),
            ..table()
        }
        .spec(1, 2)
        .unwrap();
        assert_eq!(custom.albedo_count, 16);
        assert_ne!(custom, shipped);
        let coarse = TableSettings {
            coarse: true,
            albedos: Some(1),
            ..table()
        }
        .spec(1, 2)
        .unwrap();
        assert_eq!(coarse, McTableSpec::coarse(1.3, 0.0).unwrap());
    }

    #[test]
    fn a_table_out_of_range_or_budget_is_refused_and_shards_share_the_work() {
        let e = |t: TableSettings, shards| t.spec(shards, 2).unwrap_err().to_string();
        assert_eq!(
            e(
                TableSettings {
                    eta: 0.5,
                    ..table()
                },
                1
            ),
            "--eta 0.5: the relative refractive index must lie in [1, 10]"
        );
        assert_eq!(
            e(
                TableSettings {
                    albedos: Some(3),
                    ..table()
                },
                1
            ),
            "--albedos 3: a table has 4 to 1000 albedos"
        );
        let interactions = table()
            .spec(1, 2)
            .unwrap()
            .cost_estimate()
            .unwrap()
            .interactions;
        let budget = (interactions / 4.0) as u64;
        let over = TableSettings {
            max_interactions: budget,
            ..table()
        };
        assert!(e(over.clone(), 1).starts_with("building this table is expected to take"));
        assert!(
            over.spec(8, 2).is_ok(),
            "an eighth of the work fits a quarter"
        );
    }
}
