//! The real-renderer check of `scatterfit export --to mitsuba`: Mitsuba 3 (the `mitsuba` Python package,
//! `scalar_rgb` variant) loads the exported fragment into a full scene and renders a slab of the
//! material under uniform light; its brightness must be the slab's reflectance.
//!
//! What a pixel measures (see `mitsuba_slab.py`): a constant environment of radiance 1 and an
//! orthographic camera looking along the normal give, by reciprocity, the slab's reflectance for
//! collimated light at normal incidence: the Fresnel specular R0 = ((η − 1)/(η + 1))² plus the diffuse
//! reflectance Rd (MCML's, docs/physics.md §4.3: "UR1" there includes R0). A thick slab of the
//! exported medium must therefore show `rd_total + R0` with `rd_total` exact transport's Rd for the
//! result's α′ and η — what a measurement with `albedo_model = "mc"` carries.
//!
//! Tolerance: 4 standard errors of the render (pixel-to-pixel spread; box filter, independent pixels)
//! plus 0.002 for what separates the render from the reference besides noise: float32 arithmetic and
//! Mitsuba's ray-spawn offset (≈ 1e-4 (1 + |p|) scene units, < 0.3 % of a mean free path here), light
//! reaching the face around the finite box (< 1e-4 at these sizes) and the reference's own quadrature
//! error (< 1e-4). The errors the test exists to catch are far larger: an albedo off by 1 % moves Rd by
//! 0.01–0.02 at these α′, a wrong η moves R0 and Rd by > 0.01, a unit conversion off by 1000 turns the
//! thin slab's 0.27 into 0.36 or 0.04.
//!
//! The interpreter is `$SCATTERFIT_MITSUBA_PYTHON`, else `.ci/venv/bin/python` (made by `.ci/run`).
//! Without it the tests are skipped with a message, unless `SCATTERFIT_REQUIRE_MITSUBA=1` (set by
//! `.ci/run`), which makes its absence a failure.
//!
//! `forward_models_against_mitsuba` (ignored; run by hand) is the higher-quality comparison of each
//! forward model's total Rd with the path tracer that BENCHMARKS.md reports.

mod common;

use common::{command, temp_dir, workspace_root};

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Slab reflectance at normal incidence from exact transport (iadpython adding-doubling;
/// docs/physics.md §4.3, "n=1.4 R_d = UR1(Q40) − 0.027778"): a = α′ and Rd, semi-infinite, η = 1.4,
/// g = 0.
const THICK_ETA: f64 = 1.4;
const THICK_CASES: [(f64, f64); 3] = [(0.8, 0.153054), (0.9, 0.250608), (0.95, 0.359139)];

/// Finite slab (docs/physics.md §4.4, "thin isotropic"): α = 0.95, optical thickness τ = 1, g = 0,
/// η = 1.5 with air on both sides; total reflectance at normal incidence UR1 (R0 included) from
/// iadpython, 0.27452 (Q = 32; 0.27453 at Q = 24; MC 0.27484 ± 0.0004).
const THIN_ETA: f64 = 1.5;
const THIN_ALBEDO: f64 = 0.95;
const THIN_UR1: f64 = 0.27452;

fn required() -> bool {
    std::env::var("SCATTERFIT_REQUIRE_MITSUBA").is_ok_and(|v| v == "1")
}

/// The Python that has `mitsuba`, or `None` (after saying why) when the test is to be skipped.
fn mitsuba_python(test: &str) -> Option<PathBuf> {
    let python = std::env::var_os("SCATTERFIT_MITSUBA_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join(".ci/venv/bin/python"));
    let home = temp_dir();
    let ok = python.exists()
        && Command::new(&python)
            .args(["-c", "import mitsuba"])
            .env("HOME", home.path())
            .output()
            .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    let why = format!(
        "{test}: no Python with the `mitsuba` package at {} (make one with `python3 -m venv .ci/venv && \
         .ci/venv/bin/pip install mitsuba`, or set SCATTERFIT_MITSUBA_PYTHON)",
        python.display()
    );
    assert!(
        !required(),
        "{why}; SCATTERFIT_REQUIRE_MITSUBA=1 makes this test required"
    );
    // Written past the test harness's output capture, so that a skip is visible in `cargo test`.
    let _ = writeln!(std::io::stderr(), "skipped {why}");
    None
}

/// A result file with per-channel (σ′s, σa, Rd) [mm⁻¹, mm⁻¹, 1].
fn write_result(path: &Path, eta: f64, channels: [(f64, f64, Option<f64>); 3]) {
    let ch = |(sp, sa, rd): (f64, f64, Option<f64>)| {
        serde_json::json!({
            "status": "ok", "sigma_s_prime": sp, "sigma_s_prime_stderr": null, "sigma_a": sa,
            "sigma_a_stderr": null, "albedo_prime": sp / (sp + sa), "rd_total": rd, "mse": null
        })
    };
    let result = serde_json::json!({
        "name": "mitsuba test slab", "eta": eta, "eta_source": "given", "method": "proposed",
        "model": "mc", "albedo_model": "mc",
        "channels": { "r": ch(channels[0]), "g": ch(channels[1]), "b": ch(channels[2]) },
        "version": "0.1.0"
    });
    std::fs::write(path, serde_json::to_string_pretty(&result).unwrap()).unwrap();
}

/// `scatterfit export RESULT --to mitsuba --scale UNIT -o OUT` (the real binary).
fn export(dir: &Path, unit: &str) -> PathBuf {
    let out = dir.join(format!("material-{unit}.xml"));
    let o = command()
        .args([
            "export",
            "result.json",
            "--to",
            "mitsuba",
            "--scale",
            unit,
            "-o",
        ])
        .arg(&out)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// What `mitsuba_slab.py` prints.
#[derive(Debug, serde::Deserialize)]
struct Render {
    mean: [f64; 3],
    stderr: [f64; 3],
    spp: u32,
    pixels: u32,
    seconds: f64,
    mitsuba: String,
}

fn render(
    python: &Path,
    fragment: &Path,
    width: f64,
    thickness: f64,
    backing: bool,
    spp: u32,
) -> Render {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mitsuba_slab.py");
    let mut cmd = Command::new(python);
    // Dr.Jit makes a kernel-cache folder in $HOME on import: keep it in the test's temporary folder.
    let home = fragment.parent().unwrap_or(Path::new("."));
    cmd.env("HOME", home)
        .arg(&script)
        .arg(fragment)
        .args(["--width", &width.to_string()])
        .args(["--thickness", &thickness.to_string()])
        .args(["--spp", &spp.to_string(), "--res", "16", "--seed", "7"]);
    if backing {
        cmd.arg("--backing");
    }
    let o = cmd.output().unwrap();
    assert!(
        o.status.success(),
        "mitsuba_slab.py failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "mitsuba_slab.py printed no result ({e}):\n{}",
            String::from_utf8_lossy(&o.stdout)
        )
    })
}

/// Normal-incidence Fresnel reflectance ((η − 1)/(η + 1))² (Born & Wolf §1.5.2 at θ = 0).
fn r0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

fn check(label: &str, got: f64, stderr: f64, want: f64) {
    let tol = 4.0 * stderr + 0.002;
    eprintln!(
        "{label}: Mitsuba {got:.5} ± {stderr:.5}, expected {want:.5} (|Δ| = {:.5}, tolerance {tol:.5})",
        (got - want).abs()
    );
    assert!(
        (got - want).abs() <= tol,
        "{label}: Mitsuba renders {got:.5} ± {stderr:.5}, the reflectance is {want:.5}"
    );
}

/// A thick slab (200 mean free paths, 400 wide) in a millimetre scene: every channel must show
/// rd_total + R0, with α′ = 0.8, 0.9, 0.95 and η = 1.4 (σ′t = 1 mm⁻¹).
#[test]
fn thick_slab_shows_total_diffuse_reflectance() {
    let Some(python) = mitsuba_python("thick_slab_shows_total_diffuse_reflectance") else {
        return;
    };
    let dir = temp_dir();
    write_result(
        &dir.path().join("result.json"),
        THICK_ETA,
        THICK_CASES.map(|(a, rd)| (a, 1.0 - a, Some(rd))),
    );
    let fragment = export(dir.path(), "mm");
    let r = render(&python, &fragment, 400.0, 200.0, false, 256);
    eprintln!(
        "Mitsuba {}: {} px × {} spp in {:.2} s",
        r.mitsuba, r.pixels, r.spp, r.seconds
    );
    for (k, (albedo, rd)) in THICK_CASES.iter().enumerate() {
        check(
            &format!("thick slab, α′ = {albedo}, η = {THICK_ETA}"),
            r.mean[k],
            r.stderr[k],
            rd + r0(THICK_ETA),
        );
    }
}

/// A slab of optical thickness 1 on a black backing, exported with `--scale m` (σt = 10 m⁻¹, 0.1 m
/// thick): checks the unit conversion, which a half-space cannot see.
#[test]
fn thin_slab_in_metres_matches_adding_doubling() {
    let Some(python) = mitsuba_python("thin_slab_in_metres_matches_adding_doubling") else {
        return;
    };
    let dir = temp_dir();
    // σt = 0.01 mm⁻¹ = 10 m⁻¹: τ = 1 at 0.1 m.
    let sigma_t_mm = 0.01;
    let c = (
        THIN_ALBEDO * sigma_t_mm,
        (1.0 - THIN_ALBEDO) * sigma_t_mm,
        None,
    );
    write_result(&dir.path().join("result.json"), THIN_ETA, [c, c, c]);
    let fragment = export(dir.path(), "m");
    let r = render(&python, &fragment, 4.0, 0.1, true, 256);
    check(
        "thin slab (τ = 1, α = 0.95, η = 1.5), metres",
        r.mean[1],
        r.stderr[1],
        THIN_UR1,
    );
}

/// BENCHMARKS.md "exports": each forward model's total Rd against Mitsuba's volumetric path tracer
/// on half-spaces, at high sample counts. Run by hand (minutes):
/// `cargo test -p scatterfit --test mitsuba -- --ignored --nocapture`.
#[test]
#[ignore = "benchmark: minutes of rendering; BENCHMARKS.md reports its output"]
fn forward_models_against_mitsuba() {
    use scatterfit_optics::{DiffusionModel, ModelFamily, ModelName};
    let Some(python) = mitsuba_python("forward_models_against_mitsuba") else {
        return;
    };
    let spp: u32 = std::env::var("SCATTERFIT_BENCH_SPP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1024);
    // The `mc` model's tables (the shipped set; η 1.0, 1.4 and 2.0 are table nodes).
    let mc_family = scatterfit_mc::family(ModelName::Mc).unwrap();
    println!(
        "| η | α′ | Mitsuba Rd (± s.e.) | dipole Rd | dipole error | MC table Rd | MC table error | \
         better dipole | PBD |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for eta in [1.0, 1.4, 2.0] {
        for a in [0.3, 0.6, 0.9, 0.95, 0.99, 0.999] {
            let dir = temp_dir();
            // σ′t = 1 mm⁻¹, the same α′ in every channel (one albedo per render: Mitsuba samples
            // distances and roulette on all channels at once, and mixed albedos add variance); a
            // half-space: 400 mm deep (400 mean free paths, 22 diffusion lengths at α′ = 0.999), 2000
            // mm wide.
            write_result(
                &dir.path().join("result.json"),
                eta,
                [(a, 1.0 - a, None); 3],
            );
            let fragment = export(dir.path(), "mm");
            let r = render(&python, &fragment, 2000.0, 400.0, false, spp);
            let truth = r.mean[1] - r0(eta);
            let dipole = scatterfit_optics::dipole::rd_total(a, eta);
            let mc = mc_family.rd_total(a, eta, 0.0).unwrap();
            let pct = |x: f64| format!("{:+.1} %", 100.0 * (x / truth - 1.0));
            let improved = |m: DiffusionModel| {
                m.rd_total(a, eta, 0.0)
                    .map_or_else(|e| e.to_string(), |v| format!("{v:.4} ({})", pct(v)))
            };
            println!(
                "| {eta} | {a} | {truth:.4} ± {:.4} | {dipole:.4} | {} | {mc:.4} | {} | {} | {} |",
                r.stderr[1],
                pct(dipole),
                pct(mc),
                improved(DiffusionModel::BetterDipole),
                improved(DiffusionModel::Pbd),
            );
            eprintln!(
                "η = {eta}, α′ = {a}: {} px × {} spp in {:.1} s (Mitsuba {})",
                r.pixels, r.spp, r.seconds, r.mitsuba
            );
        }
    }
}
