//! Integration tests of `scatterfit spectro`: the real binary in a temporary folder.

use crate::common;

use common::{read_json, read_text, run, temp_dir};

use std::path::Path;

/// A flat reading: SCE = `sce`, SCI = SCE + `specular`, 400–700 nm every 10 nm.
fn write_reading(path: &Path, sce: f64, specular: f64) {
    let mut s = String::from("wavelength_nm,sci,sce\n");
    for i in 0..31 {
        s.push_str(&format!("{},{},{}\n", 400 + 10 * i, sce + specular, sce));
    }
    std::fs::write(path, s).unwrap();
}

/// docs/physics.md §5: a specular reflectance of 0.04 means η = 1.5 through Schlick; the JSON on
/// stdout and the file written with --out carry the same result.
#[test]
fn spectro_json_reports_eta_and_albedo() {
    let dir = temp_dir();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = run(
        dir.path(),
        &["spectro", "s.csv", "--json", "--out", "r.json"],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    assert!((v["eta"].as_f64().unwrap() - 1.5).abs() < 1e-6);
    // A flat 0.5 spectrum is a neutral grey: linear sRGB ≈ 0.5 in every channel.
    for c in ["r", "g", "b"].map(|k| &v["channels"][k]) {
        assert!((c["rd_total"].as_f64().unwrap() - 0.5).abs() < 2e-4);
        assert!(c["albedo_prime"].as_f64().unwrap() > 0.9);
    }
    let file: serde_json::Value = read_json(&dir.path().join("r.json"));
    assert_eq!(file["eta"], v["eta"]);
}

/// η = 1.3 given explicitly and Rd = 0.5: α′ must be docs/physics.md §1.6's 0.97258193 (grey, so
/// every channel; the sRGB matrix rounding moves Rd by < 2e-4, α′ by < 3e-5).
#[test]
fn given_eta_and_grey_match_inversion_vector() {
    let dir = temp_dir();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.0);
    let out = run(dir.path(), &["spectro", "s.csv", "--eta", "1.3", "--json"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let v: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    for c in ["r", "g", "b"].map(|k| &v["channels"][k]) {
        assert!(
            (c["albedo_prime"].as_f64().unwrap() - 0.97258193).abs() < 3e-5,
            "{c}"
        );
    }
}

#[test]
fn zero_specular_without_eta_is_bad_input() {
    let dir = temp_dir();
    write_reading(&dir.path().join("matte.csv"), 0.5, 0.0);
    let out = run(dir.path(), &["spectro", "matte.csv"]);
    assert_eq!(out.code, 2);
    let err = &out.stderr;
    assert!(err.contains("matte.csv") && err.contains("--eta"), "{err}");
}

#[test]
fn bad_files_and_arguments_exit_2_with_the_file_named() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("bad.csv"), "wavelength_nm,sci\n400,0.5\n").unwrap();
    let out = run(dir.path(), &["spectro", "bad.csv"]);
    assert_eq!(out.code, 2);
    assert!(out.stderr.contains("bad.csv"));
    let out = run(dir.path(), &["spectro", "missing.csv"]);
    assert_eq!(out.code, 2);
    assert!(out.stderr.contains("missing.csv"));
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = run(
        dir.path(),
        &[
            "spectro",
            "s.csv",
            "--observer",
            "5",
            "--lab",
            "50",
            "0",
            "0",
        ],
    );
    assert_eq!(out.code, 2);
    let out = run(dir.path(), &["spectro", "s.csv", "--out", "s.csv"]);
    assert_eq!(out.code, 2, "never overwrite the input");
    assert!(read_text(&dir.path().join("s.csv")).starts_with("wavelength_nm"));
}

/// An out-of-gamut colour is a failed measurement (exit 1) with the channel named.
#[test]
fn out_of_gamut_lab_is_a_failed_measurement() {
    let dir = temp_dir();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = run(
        dir.path(),
        &[
            "spectro",
            "s.csv",
            "--lab",
            "60",
            "-90",
            "80",
            "--observer",
            "2",
        ],
    );
    assert_eq!(out.code, 1);
    assert!(out.stdout.contains("channel R"));
}
