//! Accuracy of Monte Carlo table lookups between the tabulated albedos and radii: the table that
//! `scatterfit table --eta 1.4` builds and `--model mc` uses (the shipped η = 1.4 table,
//! `McTableSpec::shipped`: 128 albedos, 216 radial bins, 4·10⁶ full-length photons), looked up
//! through `McProfile`, against direct simulations of the MCML engine (an independent tracer: implicit
//! capture and roulette instead of the white run's albedo weights) at off-node α′ and on radial grids
//! whose bins fall between the table's; and its total Rd and α′ inversion against adding-doubling
//! (docs/physics.md §4.3). Fixed seeds; tolerances in standard errors plus a stated interpolation
//! tolerance.

use std::sync::OnceLock;

use scatterfit_mc::{
    Beam, Layer, McProfile, McTable, McTableSet, RadialGrid, Sample, Simulation, SimulationResult,
};
use scatterfit_optics::{OpticalProperties, ProfileModel};

const ETA: f64 = 1.4;

/// Relative standard error of a table lookup: the smoothed model's own noise, 0.1–0.2 % RMS
/// (BENCHMARKS.md, "Model noise"); taken at its upper end.
const LOOKUP_REL_SE: f64 = 0.002;

/// The shipped η = 1.4 table.
fn table() -> &'static McTable {
    static T: OnceLock<McTable> = OnceLock::new();
    T.get_or_init(|| {
        let set = scatterfit_mc::bundled_tables().unwrap();
        let t = set.tables().iter().find(|t| t.spec().eta == ETA).unwrap();
        assert_eq!(t.spec(), &scatterfit_mc::McTableSpec::shipped(ETA).unwrap());
        t.clone()
    })
}

/// The table alone as a model (η = 1.4 exactly, no interpolation in η).
fn set() -> &'static McTableSet {
    static S: OnceLock<McTableSet> = OnceLock::new();
    S.get_or_init(|| McTableSet::new(vec![table().clone()]).unwrap())
}

fn direct(
    sigma_s_prime: f64,
    sigma_a: f64,
    grid: RadialGrid,
    photons: u64,
    seed: u64,
) -> SimulationResult {
    let half = Sample::slab(
        Layer::from_reduced(sigma_s_prime, sigma_a, 0.0, ETA, f64::INFINITY).unwrap(),
        1.0,
    )
    .unwrap();
    Simulation::new(half, Beam::pencil(), grid, photons, seed)
        .unwrap()
        .run()
}

/// χ²_p(k) by the Wilson–Hilferty approximation k(1 − 2/(9k) + z_p √(2/(9k)))³ (Johnson, Kotz &
/// Balakrishnan, Continuous Univariate Distributions vol. 1, eq. 18.24), z₀.₉₉₉ = 3.0902; within 1 %
/// of the exact quantile for k ≥ 10.
fn chi2_999(k: usize) -> f64 {
    let k = k as f64;
    let h = 2.0 / (9.0 * k);
    k * (1.0 - h + 3.0902 * h.sqrt()).powi(3)
}

/// The model's average over the annulus [a, b] (8-point Gauss–Legendre in r of 2πr Rd(r) over the
/// annulus area: the tally's definition of a bin).
fn bin_average(m: &dyn ProfileModel, a: f64, b: f64) -> f64 {
    const GL: [(f64, f64); 4] = [
        (0.183_434_642_495_650, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887),
        (0.796_666_477_413_627, 0.222_381_034_453_374),
        (0.960_289_856_497_536, 0.101_228_536_290_376),
    ];
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let s: f64 = GL
        .iter()
        .flat_map(|&(x, w)| [(mid - half * x, w), (mid + half * x, w)])
        .map(|(r, w)| w * half * 2.0 * std::f64::consts::PI * r * m.rd(r))
        .sum();
    s / (std::f64::consts::PI * (b * b - a * a))
}

/// Compares the model's bin averages with a direct profile on `grid`, in bins whose direct relative
/// s.e. is ≤ 5 % and whose optical radius (× σ′t) lies inside the Monte Carlo data of the table rows
/// `rows` (beyond it the model is the smoother's extrapolation): χ² with the combined s.e. below
/// χ²₀.₉₉₉, and each bin within 4 s.e. + `tol` (relative).
fn compare(
    what: &str,
    grid: &RadialGrid,
    d: &SimulationResult,
    m: &dyn ProfileModel,
    sigma_t: f64,
    rows: &[usize],
    tol: f64,
) {
    let t = table();
    let rho_lo = rows
        .iter()
        .map(|&k| t.rho_data_min()[k])
        .fold(0.0, f64::max);
    let rho_hi = rows
        .iter()
        .map(|&k| t.rho_data_max()[k])
        .fold(f64::INFINITY, f64::min);
    let edges = grid.edges();
    let (mut chi2, mut used) = (0.0, 0);
    for (i, e) in d.rd_profile.iter().enumerate() {
        let (a, b) = (edges[i], edges[i + 1]);
        if a * sigma_t < rho_lo
            || b * sigma_t > rho_hi
            || e.value <= 0.0
            || e.stderr > 0.05 * e.value
        {
            continue;
        }
        let v = bin_average(m, a, b);
        let se = (e.stderr.powi(2) + (v * LOOKUP_REL_SE).powi(2)).sqrt();
        assert!(
            (v - e.value).abs() <= 4.0 * se + tol * e.value,
            "{what}, r ∈ [{a}, {b}]: lookup {v} vs direct {e:?}"
        );
        chi2 += ((v - e.value) / se).powi(2);
        used += 1;
    }
    assert!(used >= 20, "{what}: only {used} bins");
    assert!(
        chi2 < chi2_999(used),
        "{what}: χ² = {chi2} over {used} bins"
    );
}

/// Between albedo nodes: α′ midway (in √(1 − α′)) between the nodes around 0.794, 0.988 and 0.998
/// (where the profile changes fastest between nodes: R̂ ∝ exp(−√(3(1 − α′))ρ) far out), σ′t = 1,
/// direct simulation on the table's own radial bins. Interpolation tolerance 3 % per bin on top of
/// 4 s.e.; χ² with s.e. only. (Linear interpolation of R̂ in √(1 − α′), the scheme of the first table
/// system, failed this at α′ ≈ 0.998 with χ²/dof ≈ 12 and a 53 % error at ρ ≈ 48.)
#[test]
fn profile_between_albedos_matches_direct_simulation() {
    let t = table();
    let a = t.albedos();
    let grid = RadialGrid::from_edges(t.spec().radial_edges()).unwrap();
    for (target, seed) in [(0.794, 71u64), (0.988, 72), (0.998, 73)] {
        let k = a.partition_point(|&x| x < target) - 1;
        let u = 0.5 * ((1.0 - a[k]).sqrt() + (1.0 - a[k + 1]).sqrt());
        let alpha = 1.0 - u * u;
        let d = direct(alpha, 1.0 - alpha, grid.clone(), 300_000, seed);
        let m = McProfile::new(
            set(),
            &OpticalProperties::new(alpha, 1.0 - alpha, ETA).unwrap(),
        )
        .unwrap();
        compare(
            &format!("α′ = {alpha}"),
            &grid,
            &d,
            &m,
            1.0,
            &[k, k + 1],
            0.03,
        );
    }
}

/// Between radial bins: at tabulated albedos (the nodes nearest 0.48, 0.88, 0.98) and σ′t = 2 mm⁻¹,
/// a direct simulation whose bin edges are the table's geometric bin midpoints / σ′t, so every
/// direct bin straddles two of the table's. Tolerance as above (3 % per bin).
#[test]
fn profile_between_radii_matches_direct_simulation() {
    let t = table();
    let st = 2.0;
    let e = t.spec().radial_edges();
    let mut edges = vec![0.0];
    edges.extend((1..e.len() - 1).map(|j| (e[j] * e[j + 1]).sqrt() / st));
    let grid = RadialGrid::from_edges(edges).unwrap();
    for (target, seed) in [(0.48, 81u64), (0.88, 82), (0.98, 83)] {
        let a = t.albedos();
        let k = a.partition_point(|&x| x < target);
        let k = if k > 0 && target - a[k - 1] < a[k] - target {
            k - 1
        } else {
            k
        };
        let alpha = a[k];
        // σ′t = 2: σ′s = 2α′, σa = 2(1 − α′).
        let d = direct(
            2.0 * alpha,
            2.0 * (1.0 - alpha),
            grid.clone(),
            300_000,
            seed,
        );
        let props = OpticalProperties::new(2.0 * alpha, 2.0 * (1.0 - alpha), ETA).unwrap();
        let m = McProfile::new(set(), &props).unwrap();
        compare(
            &format!("α′ = {alpha}, σ′t = {st}"),
            &grid,
            &d,
            &m,
            st,
            &[k],
            0.03,
        );
    }
}

/// Total Rd at off-node α′ (0.5, 0.8, 0.9, 0.95, 0.99: each at least a tenth of a node interval
/// from the nodes) against adding-doubling,
/// n = 1.4, g = 0 (docs/physics.md §4.3: iadpython Q = 40 UR1 − R_sp, quadrature uncertainty 5e-5),
/// within 3 s.e. (the larger s.e. of the two bracketing nodes) + an interpolation tolerance of 5e-4;
/// and α′ from that Rd (the table's inversion, as `--albedo-model mc` runs it) within the same
/// tolerance divided by the slope dRd/dα′ (central difference of the table's Rd(α′)).
#[test]
fn total_rd_and_inversion_match_adding_doubling() {
    let t = table();
    let (_, se) = t.totals();
    let a = t.albedos();
    for (alpha, reference) in [
        (0.5, 0.052305),
        (0.8, 0.153054),
        (0.9, 0.250608),
        (0.95, 0.359139),
        (0.99, 0.603603),
    ] {
        let i = a.partition_point(|&x| x < alpha);
        // At least a tenth of the node interval (in √(1 − α′), the interpolation's coordinate) from
        // either node: a lookup between nodes, not at one.
        let u = |v: f64| (1.0 - v).sqrt();
        let frac = (u(a[i - 1]) - u(alpha)) / (u(a[i - 1]) - u(a[i]));
        assert!(
            (0.1..=0.9).contains(&frac),
            "α′ = {alpha} is (nearly) a node"
        );
        let s = se[i - 1].max(se[i]);
        let tol = 3.0 * (s * s + 5e-5f64.powi(2)).sqrt() + 5e-4;
        let rd = t.rd_total(alpha).unwrap();
        assert!(
            (rd - reference).abs() <= tol,
            "α′ = {alpha}: Rd {rd} vs adding-doubling {reference} (tolerance {tol})"
        );
        let h = 1e-4;
        let slope = (t.rd_total(alpha + h).unwrap() - t.rd_total(alpha - h).unwrap()) / (2.0 * h);
        let inverted = set().albedo_from_rd_total(reference, ETA).unwrap();
        assert!(
            (inverted - alpha).abs() <= tol / slope,
            "Rd {reference}: α′ {inverted} vs {alpha} (tolerance {})",
            tol / slope
        );
    }
}
