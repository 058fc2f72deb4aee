//! Integration tests of `scatterfit spectro`: the real binary in a temporary folder.

use std::path::Path;
use std::process::{Command, Output};

fn scatterfit(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scatterfit"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

/// A flat reading: SCE = `sce`, SCI = SCE + `specular`, 400–700 nm every 10 nm.
fn write_reading(path: &Path, sce: f64, specular: f64) {
    let mut s = String::from("wavelength_nm,sci,sce\n");
    for i in 0..31 {
        s.push_str(&format!("{},{},{}\n", 400 + 10 * i, sce + specular, sce));
    }
    std::fs::write(path, s).unwrap();
}

/// physics.md §5: a specular reflectance of 0.04 means η = 1.5 through Schlick; the JSON on stdout
/// and the file written with --out carry the same result.
#[test]
fn spectro_json_reports_eta_and_albedo() {
    let dir = tempfile::tempdir().unwrap();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = scatterfit(
        &["spectro", "s.csv", "--json", "--out", "r.json"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((v["eta"].as_f64().unwrap() - 1.5).abs() < 1e-6);
    // A flat 0.5 spectrum is a neutral grey: linear sRGB ≈ 0.5 in every channel.
    for c in ["r", "g", "b"].map(|k| &v["channels"][k]) {
        assert!((c["rd_total"].as_f64().unwrap() - 0.5).abs() < 2e-4);
        assert!(c["albedo_prime"].as_f64().unwrap() > 0.9);
    }
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(file["eta"], v["eta"]);
}

/// η = 1.3 given explicitly and Rd = 0.5: α′ must be physics.md §1.6's 0.97258193 (grey, so every
/// channel; the sRGB matrix rounding moves Rd by < 2e-4, α′ by < 3e-5).
#[test]
fn given_eta_and_grey_match_inversion_vector() {
    let dir = tempfile::tempdir().unwrap();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.0);
    let out = scatterfit(&["spectro", "s.csv", "--eta", "1.3", "--json"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for c in ["r", "g", "b"].map(|k| &v["channels"][k]) {
        assert!(
            (c["albedo_prime"].as_f64().unwrap() - 0.97258193).abs() < 3e-5,
            "{c}"
        );
    }
}

#[test]
fn zero_specular_without_eta_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    write_reading(&dir.path().join("matte.csv"), 0.5, 0.0);
    let out = scatterfit(&["spectro", "matte.csv"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("matte.csv") && err.contains("--eta"), "{err}");
}

#[test]
fn bad_files_and_arguments_exit_2_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.csv"), "wavelength_nm,sci\n400,0.5\n").unwrap();
    let out = scatterfit(&["spectro", "bad.csv"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.csv"));
    let out = scatterfit(&["spectro", "missing.csv"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.csv"));
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = scatterfit(
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
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    let out = scatterfit(&["spectro", "s.csv", "--out", "s.csv"], dir.path());
    assert_eq!(out.status.code(), Some(2), "never overwrite the input");
    assert!(
        std::fs::read_to_string(dir.path().join("s.csv"))
            .unwrap()
            .starts_with("wavelength_nm")
    );
}

/// An out-of-gamut colour is a failed measurement (exit 1) with the channel named.
#[test]
fn out_of_gamut_lab_is_a_failed_measurement() {
    let dir = tempfile::tempdir().unwrap();
    write_reading(&dir.path().join("s.csv"), 0.5, 0.04);
    let out = scatterfit(
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
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("channel R"));
}
