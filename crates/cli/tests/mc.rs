//! Integration tests of `scatterfit simulate` and `scatterfit table`: the real binary in a temporary
//! folder.

use crate::common;

use common::{command, read_text, temp_dir, text};

/// A small simulation writes a CSV profile and JSON whose totals obey R_sp + Rd + Tt + A = 1, and the
/// standard slab's Rd agrees with van de Hulst's 0.09739 (docs/physics.md §4.2) within 4 s.e.
#[test]
fn simulate_writes_profile_and_json() {
    let dir = temp_dir();
    let csv = dir.path().join("profile.csv");
    // Standard slab in graphics units: σ′s = σs(1 − g) = 9 × 0.25 = 2.25 mm⁻¹, σa = 1, d = 0.2 mm.
    let out = command()
        .args([
            "simulate",
            "--sigma-s-prime",
            "2.25",
            "--sigma-a",
            "1",
            "--eta",
            "1",
            "--g",
            "0.75",
        ])
        .args([
            "--thickness-mm",
            "0.2",
            "--photons",
            "200000",
            "--json",
            "--quiet",
            "--out",
        ])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &v["result"];
    let rd = r["rd_total"]["value"].as_f64().unwrap();
    let se = r["rd_total"]["stderr"].as_f64().unwrap();
    assert!((rd - 0.09739).abs() < 4.0 * se, "Rd = {rd} ± {se}");
    let sum = r["specular"].as_f64().unwrap()
        + rd
        + r["transmittance"]["value"].as_f64().unwrap()
        + r["absorbed"]["value"].as_f64().unwrap();
    assert!((sum - 1.0).abs() < 1e-3);
    let text = read_text(&csv);
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "r_inner_mm,r_outer_mm,r_mm,rd_per_mm2,rd_stderr_per_mm2"
    );
    assert_eq!(lines.count(), 200);
}

/// Bad input exits with code 2 and a message naming the problem.
#[test]
fn simulate_refuses_bad_input() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["--sigma-s-prime", "1", "--sigma-a", "-0.1", "--eta", "1.3"],
            "--sigma-a",
        ),
        (
            &[
                "--sigma-s-prime",
                "1",
                "--sigma-a",
                "0.1",
                "--eta",
                "1.3",
                "--g",
                "1",
            ],
            "g",
        ),
        (
            &["--sigma-s-prime", "1", "--sigma-a", "0.1", "--eta", "0.8"],
            "allow-eta-below-one",
        ),
        (
            &[
                "--sigma-s-prime",
                "1",
                "--sigma-a",
                "0.1",
                "--eta",
                "1.3",
                "--photons",
                "0",
            ],
            "photons",
        ),
        (
            &[
                "--sigma-s-prime",
                "1",
                "--sigma-a",
                "0.1",
                "--eta",
                "1.3",
                "--beam",
                "disk:-1",
            ],
            "radius",
        ),
        (
            &[
                "--sigma-s-prime",
                "1",
                "--sigma-a",
                "0.1",
                "--eta",
                "1.3",
                "--beam",
                "laser",
            ],
            "--beam",
        ),
    ];
    for (args, needle) in cases {
        let out = command().arg("simulate").args(args).output().unwrap();
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // η < 1 is accepted when asked for.
    let out = command()
        .args([
            "simulate",
            "--sigma-s-prime",
            "1",
            "--sigma-a",
            "0.1",
            "--eta",
            "0.8",
        ])
        .args(["--allow-eta-below-one", "--photons", "1000", "--quiet"])
        .output()
        .unwrap();
    assert!(out.status.success());
}

/// `table` builds into the given cache folder, then reuses the file; with `-o` it writes the table
/// (compact, no raw profiles) as a file the `mc` model reads (`McTable::from_json`), refuses to
/// replace it without `--force`, and replaces it with.
#[test]
fn table_builds_then_reuses_cache() {
    let dir = temp_dir();
    let file = dir.path().join("t.json");
    let run = |extra: &[&str]| {
        command()
            .args([
                "table",
                "--eta",
                "1.3",
                "--albedos",
                "8",
                "--photons",
                "5000",
            ])
            .args(["--json", "--quiet", "--cache-dir"])
            .arg(dir.path().join("cache"))
            .args(extra)
            .output()
            .unwrap()
    };
    let json = |out: std::process::Output| {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let first = json(run(&[]));
    assert_eq!(first["status"], "built and cached");
    assert_eq!(first["albedos"].as_array().unwrap().len(), 8);
    assert_eq!(first["photons"], serde_json::json!([80000, 20000, 5000]));
    let second = json(run(&["-o", file.to_str().unwrap()]));
    assert_eq!(second["status"], "loaded from cache");
    assert_eq!(first["rd_total"], second["rd_total"]);
    let table =
        scatterfit_mc::McTable::from_json(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert!(table.raw().is_none());
    assert_eq!(table.spec().eta, 1.3);
    let totals: Vec<f64> = serde_json::from_value(first["rd_total"].clone()).unwrap();
    for (a, b) in table.totals().0.iter().zip(&totals) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    let again = run(&["-o", file.to_str().unwrap()]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    json(run(&["-o", file.to_str().unwrap(), "--force"]));
}

/// `scatterfit table` builds the table `--model mc` uses: at the shipped tables' defaults
/// (`McTableSpec::shipped`) its `-o` file is the one compiled into the crate (`crates/mc/tables/`)
/// up to one unit of the compact form's 10⁻⁹ rounding: the shipped files were built before the
/// tallies became exact sums (`mc::exact`), which moves the raw tallies by a few ulps (≤ 2.2·10⁻¹⁵
/// relative on a coarse table, BENCHMARKS.md "Sharded tables"), so a value on a rounding edge may
/// round the other way. Minutes of work: run by hand,
/// `cargo test -p scatterfit --test suite -- --ignored mc::table_rebuilds_the_shipped_table`.
#[test]
#[ignore = "minutes: builds a full table (η = 1.0, the cheapest)"]
fn table_rebuilds_the_shipped_table() {
    let dir = temp_dir();
    let file = dir.path().join("eta1.json");
    let out = command()
        .args(["table", "--eta", "1.0", "--quiet", "--cache-dir"])
        .arg(dir.path())
        .arg("-o")
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let shipped = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../mc/tables/mc-white-eta1.00.json"
    );
    let built: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    let old: serde_json::Value = serde_json::from_slice(&std::fs::read(shipped).unwrap()).unwrap();
    for key in ["spec", "albedos", "knots"] {
        assert_eq!(built[key], old[key], "{key} differs from {shipped}");
    }
    for key in [
        "coefs",
        "rd_total",
        "rd_total_stderr",
        "chi2_per_bin",
        "rho_data_min",
        "rho_data_max",
    ] {
        let (a, b) = (built[key].as_array().unwrap(), old[key].as_array().unwrap());
        assert_eq!(a.len(), b.len(), "{key}");
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1.5e-9,
                "{key}[{i}]: built {x}, shipped {y} ({shipped})"
            );
        }
    }
}

/// Regression: runs that would never finish, or exhaust memory, are refused before any work with exit
/// 2 and a message giving the estimate and the way out; counts accept `1e4`.
#[test]
fn simulate_refuses_unbounded_work_and_memory_up_front() {
    let base = ["simulate", "--eta", "1.4"];
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["--sigma-a", "0"],
            &["never end", "--thickness-mm", "--sigma-a 1e-4"],
        ),
        (
            &["--sigma-a", "0.01", "--g", "0.9999999"],
            &["interactions", "days", "--max-interactions"],
        ),
        (
            &["--sigma-a", "0.01", "--sigma-s-prime", "1e12"],
            &["interactions", "--max-interactions"],
        ),
        (
            &["--sigma-a", "0.01", "--bins", "1e11"],
            &["TiB", "--max-memory-mib"],
        ),
        (
            &["--sigma-a", "0.01", "--angle-bins", "1e9"],
            &["GiB", "--max-memory-mib"],
        ),
        (
            &["--sigma-a", "0.01", "--photons", "1.5"],
            &["whole number"],
        ),
    ];
    for (args, needles) in cases {
        let start = std::time::Instant::now();
        let sp = if args.contains(&"--sigma-s-prime") {
            &[][..]
        } else {
            &["--sigma-s-prime", "1"][..]
        };
        let out = command().args(base).args(sp).args(args).output().unwrap();
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        for needle in needles {
            assert!(err.contains(needle), "{args:?}: {needle} not in {err}");
        }
        assert!(
            start.elapsed().as_secs() < 5,
            "{args:?} took {:?}",
            start.elapsed()
        );
    }
    // A slab without absorption is fine, and counts take scientific notation.
    let out = command()
        .args(base)
        .args([
            "--sigma-s-prime",
            "1",
            "--sigma-a",
            "0",
            "--thickness-mm",
            "1",
        ])
        .args(["--photons", "1e4", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["result"]["photons"], 10_000);
    assert!(json["result"]["interactions"].as_u64().unwrap() > 10_000);
    // The work budget can be lowered (and raised) explicitly.
    let out = command()
        .args(base)
        .args([
            "--sigma-s-prime",
            "1",
            "--sigma-a",
            "0.01",
            "--photons",
            "1e4",
        ])
        .args(["--max-interactions", "1e5"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// The same for `table`: work beyond the budget is refused with its cost; absurd sizes are refused
/// with their ranges; nothing is written to the cache. (Every white run is bounded — photons stop
/// after at most ⌈12/−ln a_max⌉ = 120 000 interactions — so the budget, not g, is what refuses.)
#[test]
fn table_refuses_unbounded_work_up_front() {
    let dir = temp_dir();
    let cases: [(&[&str], &str); 5] = [
        (&["--photons", "1e12"], "--max-interactions"),
        (
            &["--g", "0.9", "--max-interactions", "1e9"],
            "--max-interactions",
        ),
        (&["--albedos", "1e9"], "4 to 1000"),
        (&["--photons", "0"], "at least one photon"),
        (&["--g", "1"], "(−1, 1)"),
    ];
    for (args, needle) in cases {
        let start = std::time::Instant::now();
        let out = command()
            .args(["table", "--eta", "1.4", "--cache-dir"])
            .arg(dir.path())
            .args(args)
            .output()
            .unwrap();
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            start.elapsed().as_secs() < 5,
            "{args:?} took {:?}",
            start.elapsed()
        );
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
