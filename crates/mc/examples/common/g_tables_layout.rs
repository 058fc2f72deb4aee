//! The layout of the anisotropic `mc` tables, shared by the `build_g_tables` and
//! `g_table_study` examples (included with `#[path]`; not an example of its own).
#![allow(dead_code)]

use scatterfit_mc::model::McTableSpec;

/// Smallest and largest reduced albedo α′ a g ≠ 0 table must serve (0.3–0.9999, with a
/// margin so that Catmull-Rom has a node on each side).
pub const ALBEDO_PRIME_RANGE: (f64, f64) = (0.2, 0.99995);

/// Smallest reduced albedo α′ of the low-albedo nodes ([`scatterfit_mc::LowAlbedoRun`]) below
/// [`ALBEDO_PRIME_RANGE`]: every channel the g = 0 tables answer (from α′ 0.01; a food's green and
/// blue, such as ketchup's 0.07 and 0.02) then has its g ≠ 0 tables too.
pub const LOW_ALBEDO_PRIME: f64 = 0.01;

/// Photons of the low-albedo run per full-length photon of the main run (1.6·10⁸ for 10⁶): the
/// run stops its photons after a few dozen interactions (about 100 CPU-s at g 0.9), and its rows'
/// data reach farther with each photon. With 16 per photon (the main run's shortest stratum) the
/// far field at α′ 0.07, g 0.9 was 4.5–6.6 % high beyond 5 mean free paths, and the twin's blue
/// channel there +1.5 % in σ′s; with 160, 0.0 % (BENCHMARKS.md, "Low albedo at g ≠ 0").
pub const LOW_ALBEDO_PHOTONS_PER_PHOTON: u64 = 160;

/// `spec` with its low-albedo nodes down to α′ = [`LOW_ALBEDO_PRIME`]
/// ([`scatterfit_mc::McTableSpec::with_low_albedos_to`]), `photons` in their run.
pub fn with_low_albedos(spec: McTableSpec, photons: u64) -> McTableSpec {
    let a = albedo_from_reduced(LOW_ALBEDO_PRIME, spec.g);
    spec.with_low_albedos_to(a, photons)
        .expect("valid low-albedo run")
}

/// Single-scattering albedo a with reduced albedo α′ at asymmetry g: α′ = a(1 − g)/(1 − ag) ⇔
/// a = α′/(1 − g + gα′) (σ′s = σs(1 − g), σ′t = σa + σ′s).
pub fn albedo_from_reduced(albedo_prime: f64, g: f64) -> f64 {
    albedo_prime / (1.0 - g + g * albedo_prime)
}

/// The spec of the (η, g) table with `photons` full-length photons: the default layout of
/// [`McTableSpec::new`] (64 albedos equally spaced in √(1 − a), 216 log bins 0.01–500 mean free
/// paths, strata 16:4:1), with two changes for g ≠ 0:
/// - the albedo nodes span a(α′ = 0.2) … a(α′ = 0.99995) instead of 0.02 … 0.9999 (at g = 0.9 the
///   default would end at α′ = 0.999 and put 40 of its 64 nodes below α′ = 0.2);
/// - the strata end at 64/(1 − g) and 1024/(1 − g) interactions instead of 64 and 1024, the same
///   number of transport mean free paths (an anisotropic walk needs 1/(1 − g) events per transport
///   step), so the short-path strata cover the same near field in reduced units.
///
/// At g = 0 this is exactly `McTableSpec::new(eta, 0, photons)` (the shipped tables).
pub fn g_spec(eta: f64, g: f64, photons: u64) -> McTableSpec {
    if g == 0.0 {
        return McTableSpec::new(eta, 0.0, photons).expect("valid spec");
    }
    let scale = 1.0 / (1.0 - g);
    let bounds = vec![
        (64.0 * scale).round() as u64,
        (1024.0 * scale).round() as u64,
    ];
    let mut spec =
        McTableSpec::with_strata(eta, g, vec![16 * photons, 4 * photons, photons], bounds)
            .expect("valid spec");
    spec.albedo_min = albedo_from_reduced(ALBEDO_PRIME_RANGE.0, g);
    spec.albedo_max = albedo_from_reduced(ALBEDO_PRIME_RANGE.1, g);
    spec.white().expect("valid white spec");
    spec
}
