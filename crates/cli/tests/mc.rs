//! Integration tests of `scatterfit simulate` and `scatterfit table`: the real binary in a temporary
//! folder.

use std::process::Command;

fn scatterfit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_scatterfit"))
}

/// A small simulation writes a CSV profile and JSON whose totals obey R_sp + Rd + Tt + A = 1, and the
/// standard slab's Rd agrees with van de Hulst's 0.09739 (physics.md §4.2) within 4 s.e.
#[test]
fn simulate_writes_profile_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("profile.csv");
    // Standard slab in graphics units: σ′s = σs(1 − g) = 9 × 0.25 = 2.25 mm⁻¹, σa = 1, d = 0.2 mm.
    let out = scatterfit()
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    let text = std::fs::read_to_string(&csv).unwrap();
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
            "sigma_a",
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
        let out = scatterfit().arg("simulate").args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // η < 1 is accepted when asked for.
    let out = scatterfit()
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

/// `table` builds into the given cache folder, then reuses the file.
#[test]
fn table_builds_then_reuses_cache() {
    let dir = tempfile::tempdir().unwrap();
    let run = || {
        let out = scatterfit()
            .args([
                "table",
                "--eta",
                "1.3",
                "--albedos",
                "3",
                "--photons-per-albedo",
                "2000",
            ])
            .args(["--json", "--quiet", "--cache-dir"])
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let first = run();
    assert_eq!(first["status"], "built and cached");
    let second = run();
    assert_eq!(second["status"], "loaded from cache");
    assert_eq!(first["rd_total"], second["rd_total"]);
}
