//! Small tables for the model's tests: they build in a fraction of a second.

use super::set::McTableSet;
use super::table::McTable;
use crate::spec::McTableSpec;

/// A table that builds in a fraction of a second: 8 albedos 0.3–0.99, 120 bins to 60 mean free
/// paths, 30 000 + 6 000 photons.
pub(super) fn small_spec(eta: f64) -> McTableSpec {
    small_spec_g(eta, 0.0)
}

pub(super) fn small_spec_g(eta: f64, g: f64) -> McTableSpec {
    let mut spec = McTableSpec::with_strata(eta, g, vec![30_000, 6_000], vec![64]).unwrap();
    spec.albedo_count = 8;
    // Forward scattering (g > 0) sends low-albedo photons deep: start higher there.
    spec.albedo_min = if g == 0.0 { 0.3 } else { 0.7 };
    spec.albedo_max = 0.99;
    spec.radial_bins = 120;
    spec.rho_max = 60.0;
    spec
}

pub(super) fn small_set(etas: &[f64]) -> McTableSet {
    McTableSet::new(
        etas.iter()
            .map(|&e| McTable::build(&small_spec(e), &|_, _| {}).unwrap())
            .collect(),
    )
    .unwrap()
}
