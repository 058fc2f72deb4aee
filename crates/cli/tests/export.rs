//! Integration tests of `scatterfit export`: the real binary in a temporary folder.

use std::path::Path;
use std::process::{Command, Output};

fn scatterfit(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_scatterfit"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A result file as `scatterfit measure` writes it (the stable names of ARCHITECTURE.md), with
/// Jensen et al. 2001's skin1 coefficients (physics.md §1.5): σ′s = 0.74, 0.88, 1.01 and σa = 0.032,
/// 0.17, 0.48 mm⁻¹. `b` is overridden by `b_channel` when given.
fn write_result(path: &Path, b_channel: Option<&str>) {
    let ch = |sp: f64, sa: f64| {
        format!(
            r#"{{ "status": "ok", "sigma_s_prime": {sp}, "sigma_s_prime_stderr": 0.01, "sigma_a": {sa},
                 "sigma_a_stderr": 0.001, "albedo_prime": {}, "rd_total": 0.4, "mse": 1e-6 }}"#,
            sp / (sp + sa)
        )
    };
    let b = b_channel.map_or_else(|| ch(1.01, 0.48), str::to_string);
    let text = format!(
        r#"{{ "name": "skin1", "eta": 1.4, "eta_source": "given", "method": "proposed", "model": "dipole",
             "albedo_model": "diffusion",
             "channels": {{ "r": {}, "g": {}, "b": {b} }}, "version": "0.1.0" }}"#,
        ch(0.74, 0.032),
        ch(0.88, 0.17),
    );
    std::fs::write(path, text).unwrap();
}

/// Without -o the export goes to stdout; with --scale m every coefficient is 1000× the mm⁻¹ one.
#[test]
fn json_to_stdout_in_both_units() {
    let dir = tempfile::tempdir().unwrap();
    write_result(&dir.path().join("result.json"), None);
    let mm = scatterfit(&["export", "result.json", "--to", "json"], dir.path());
    assert!(mm.status.success(), "{}", stderr(&mm));
    let m = scatterfit(
        &["export", "result.json", "--to", "json", "--scale", "m"],
        dir.path(),
    );
    assert!(m.status.success(), "{}", stderr(&m));
    let mm: serde_json::Value = serde_json::from_slice(&mm.stdout).unwrap();
    let m: serde_json::Value = serde_json::from_slice(&m.stdout).unwrap();
    assert_eq!(mm["unit"], "mm");
    assert_eq!(m["unit"], "m");
    for c in ["r", "g", "b"] {
        let a_mm = mm["channels"][c]["sigma_a"].as_f64().unwrap();
        let a_m = m["channels"][c]["sigma_a"].as_f64().unwrap();
        assert!((a_m - 1000.0 * a_mm).abs() < 1e-9 * a_m);
        let l_mm = mm["channels"][c]["mfp"].as_f64().unwrap();
        let l_m = m["channels"][c]["mfp"].as_f64().unwrap();
        assert!((l_mm - 1000.0 * l_m).abs() < 1e-9 * l_mm);
    }
    assert!((mm["channels"]["g"]["sigma_s"].as_f64().unwrap() - 0.88).abs() < 1e-12);
    // Nothing was written.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// -o writes the file; its extension must match the format; an existing file needs --force; the
/// input is never overwritten.
#[test]
fn output_file_rules() {
    let dir = tempfile::tempdir().unwrap();
    write_result(&dir.path().join("result.json"), None);
    let ok = scatterfit(
        &["export", "result.json", "--to", "pbrt", "-o", "skin.pbrt"],
        dir.path(),
    );
    assert!(ok.status.success(), "{}", stderr(&ok));
    let text = std::fs::read_to_string(dir.path().join("skin.pbrt")).unwrap();
    assert!(
        text.contains("\"rgb sigma_a\" [ 0.032 0.17 0.48 ]"),
        "{text}"
    );
    assert!(ok.stdout.is_empty());

    let wrong = scatterfit(
        &[
            "export",
            "result.json",
            "--to",
            "mitsuba",
            "-o",
            "skin.pbrt",
        ],
        dir.path(),
    );
    assert_eq!(wrong.status.code(), Some(2));
    assert!(stderr(&wrong).contains(".xml"), "{}", stderr(&wrong));

    let exists = scatterfit(
        &["export", "result.json", "--to", "pbrt", "-o", "skin.pbrt"],
        dir.path(),
    );
    assert_eq!(exists.status.code(), Some(2));
    assert!(stderr(&exists).contains("--force"), "{}", stderr(&exists));
    // The refusal left the file as it was.
    assert_eq!(
        std::fs::read_to_string(dir.path().join("skin.pbrt")).unwrap(),
        text
    );
    let forced = scatterfit(
        &[
            "export",
            "result.json",
            "--to",
            "pbrt",
            "-o",
            "skin.pbrt",
            "--force",
            "--scale",
            "m",
        ],
        dir.path(),
    );
    assert!(forced.status.success(), "{}", stderr(&forced));
    assert!(
        std::fs::read_to_string(dir.path().join("skin.pbrt"))
            .unwrap()
            .contains("\"rgb sigma_a\" [ 32 170 480 ]")
    );

    let input_before = std::fs::read(dir.path().join("result.json")).unwrap();
    let onto_input = scatterfit(
        &[
            "export",
            "result.json",
            "--to",
            "json",
            "-o",
            "./result.json",
            "--force",
        ],
        dir.path(),
    );
    assert_eq!(onto_input.status.code(), Some(2));
    assert!(stderr(&onto_input).contains("is the input"));
    assert_eq!(
        std::fs::read(dir.path().join("result.json")).unwrap(),
        input_before
    );
}

/// A failed channel: nothing is exported, exit 1, the message names the channel and its problem.
#[test]
fn failed_channel_exits_1_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let failed = r#"{ "status": "failed", "sigma_s_prime": null, "sigma_s_prime_stderr": null,
        "sigma_a": null, "sigma_a_stderr": null, "albedo_prime": null, "rd_total": null, "mse": null,
        "problem": "linear sRGB Rd is 0: out of gamut" }"#;
    write_result(&dir.path().join("result.json"), Some(failed));
    let out = scatterfit(
        &["export", "result.json", "--to", "mitsuba", "-o", "m.xml"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("result.json"), "{err}");
    assert!(err.contains("channel b"), "{err}");
    assert!(err.contains("out of gamut"), "{err}");
    assert!(!dir.path().join("m.xml").exists());
}

/// An unconstrained channel is exported with a warning on stderr (silenced by --quiet).
#[test]
fn unconstrained_channel_warns() {
    let dir = tempfile::tempdir().unwrap();
    let unconstrained = r#"{ "status": "unconstrained", "unconstrained": ["sigma_a"],
        "sigma_s_prime": 1.01, "sigma_s_prime_stderr": 0.1, "sigma_a": 0.48, "sigma_a_stderr": 5.0,
        "albedo_prime": 0.68, "rd_total": 0.13, "mse": 1e-6 }"#;
    write_result(&dir.path().join("result.json"), Some(unconstrained));
    let out = scatterfit(&["export", "result.json", "--to", "blender"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("warning: channel b is unconstrained"), "{err}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("import bpy"));
    let quiet = scatterfit(
        &["export", "result.json", "--to", "blender", "--quiet"],
        dir.path(),
    );
    assert!(quiet.status.success());
    assert!(quiet.stderr.is_empty(), "{}", stderr(&quiet));
}

/// Bad input: a missing file and a file that is not a result are exit 2 with the file named.
#[test]
fn bad_input_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let missing = scatterfit(&["export", "nope.json", "--to", "json"], dir.path());
    assert_eq!(missing.status.code(), Some(2));
    assert!(stderr(&missing).contains("nope.json"));
    std::fs::write(dir.path().join("x.json"), "{\"a\": 1}").unwrap();
    let junk = scatterfit(&["export", "x.json", "--to", "json"], dir.path());
    assert_eq!(junk.status.code(), Some(2));
    assert!(
        stderr(&junk).contains("not a scatterfit result"),
        "{}",
        stderr(&junk)
    );
    let bad_format = scatterfit(&["export", "x.json", "--to", "povray"], dir.path());
    assert_eq!(bad_format.status.code(), Some(2));
}
