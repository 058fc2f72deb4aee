//! Integration tests of `scatterfit export`: the real binary in a temporary folder.

use crate::common;

use common::{read_text, run, temp_dir};

use std::path::Path;

/// A result file as `scatterfit measure` writes it (the stable names of ARCHITECTURE.md), with
/// Jensen et al. 2001's skin1 coefficients (docs/physics.md §1.5): σ′s = 0.74, 0.88, 1.01 and σa =
/// 0.032, 0.17, 0.48 mm⁻¹. `b` is overridden by `b_channel` when given.
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
    let dir = temp_dir();
    write_result(&dir.path().join("result.json"), None);
    let mm = run(dir.path(), &["export", "result.json", "--to", "json"]);
    assert_eq!(mm.code, 0, "{}", mm.stderr);
    let m = run(
        dir.path(),
        &["export", "result.json", "--to", "json", "--scale", "m"],
    );
    assert_eq!(m.code, 0, "{}", m.stderr);
    let mm: serde_json::Value = serde_json::from_str(&mm.stdout).unwrap();
    let m: serde_json::Value = serde_json::from_str(&m.stdout).unwrap();
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
    let dir = temp_dir();
    write_result(&dir.path().join("result.json"), None);
    let ok = run(
        dir.path(),
        &["export", "result.json", "--to", "pbrt", "-o", "skin.pbrt"],
    );
    assert_eq!(ok.code, 0, "{}", ok.stderr);
    let text = read_text(&dir.path().join("skin.pbrt"));
    assert!(
        text.contains("\"rgb sigma_a\" [ 0.032 0.17 0.48 ]"),
        "{text}"
    );
    assert!(ok.stdout.is_empty());

    let wrong = run(
        dir.path(),
        &[
            "export",
            "result.json",
            "--to",
            "mitsuba",
            "-o",
            "skin.pbrt",
        ],
    );
    assert_eq!(wrong.code, 2);
    assert!(wrong.stderr.contains(".xml"), "{}", wrong.stderr);

    let exists = run(
        dir.path(),
        &["export", "result.json", "--to", "pbrt", "-o", "skin.pbrt"],
    );
    assert_eq!(exists.code, 2);
    assert!(exists.stderr.contains("--force"), "{}", exists.stderr);
    // The refusal left the file as it was.
    assert_eq!(read_text(&dir.path().join("skin.pbrt")), text);
    let forced = run(
        dir.path(),
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
    );
    assert_eq!(forced.code, 0, "{}", forced.stderr);
    assert!(read_text(&dir.path().join("skin.pbrt")).contains("\"rgb sigma_a\" [ 32 170 480 ]"));

    let input_before = std::fs::read(dir.path().join("result.json")).unwrap();
    let onto_input = run(
        dir.path(),
        &[
            "export",
            "result.json",
            "--to",
            "json",
            "-o",
            "./result.json",
            "--force",
        ],
    );
    assert_eq!(onto_input.code, 2);
    assert!(onto_input.stderr.contains("is the input"));
    assert_eq!(
        std::fs::read(dir.path().join("result.json")).unwrap(),
        input_before
    );
}

/// A failed channel: nothing is exported, exit 1, the message names the channel and its problem.
#[test]
fn failed_channel_exits_1_naming_it() {
    let dir = temp_dir();
    let failed = r#"{ "status": "failed", "sigma_s_prime": null, "sigma_s_prime_stderr": null,
        "sigma_a": null, "sigma_a_stderr": null, "albedo_prime": null, "rd_total": null, "mse": null,
        "problem": "linear sRGB Rd is 0: out of gamut" }"#;
    write_result(&dir.path().join("result.json"), Some(failed));
    let out = run(
        dir.path(),
        &["export", "result.json", "--to", "mitsuba", "-o", "m.xml"],
    );
    assert_eq!(out.code, 1);
    let err = &out.stderr;
    assert!(err.contains("result.json"), "{err}");
    assert!(err.contains("channel b"), "{err}");
    assert!(err.contains("out of gamut"), "{err}");
    assert!(!dir.path().join("m.xml").exists());
}

/// An unconstrained channel is exported with a warning on stderr (silenced by --quiet).
#[test]
fn unconstrained_channel_warns() {
    let dir = temp_dir();
    let unconstrained = r#"{ "status": "unconstrained", "unconstrained": ["sigma_a"],
        "sigma_s_prime": 1.01, "sigma_s_prime_stderr": 0.1, "sigma_a": 0.48, "sigma_a_stderr": 5.0,
        "albedo_prime": 0.68, "rd_total": 0.13, "mse": 1e-6 }"#;
    write_result(&dir.path().join("result.json"), Some(unconstrained));
    let out = run(dir.path(), &["export", "result.json", "--to", "blender"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let err = &out.stderr;
    assert!(err.contains("warning: channel b is unconstrained"), "{err}");
    assert!(out.stdout.contains("import bpy"));
    let quiet = run(
        dir.path(),
        &["export", "result.json", "--to", "blender", "--quiet"],
    );
    assert_eq!(quiet.code, 0);
    assert!(quiet.stderr.is_empty(), "{}", quiet.stderr);
}

/// Bad input: a missing file and a file that is not a result are exit 2 with the file named.
#[test]
fn bad_input_exits_2() {
    let dir = temp_dir();
    let missing = run(dir.path(), &["export", "nope.json", "--to", "json"]);
    assert_eq!(missing.code, 2);
    assert!(missing.stderr.contains("nope.json"));
    std::fs::write(dir.path().join("x.json"), "{\"a\": 1}").unwrap();
    let junk = run(dir.path(), &["export", "x.json", "--to", "json"]);
    assert_eq!(junk.code, 2);
    assert!(
        junk.stderr.contains("not a scatterfit result"),
        "{}",
        junk.stderr
    );
    let bad_format = run(dir.path(), &["export", "x.json", "--to", "povray"]);
    assert_eq!(bad_format.code, 2);
}

/// A number outside its documented range (here σ′s = 1e300, which is ∞ per metre and
/// beyond float32 either way) is refused with exit 2 naming the field, and nothing is written.
#[test]
fn out_of_range_value_exits_2_naming_the_field() {
    let dir = temp_dir();
    let huge = r#"{ "status": "ok", "sigma_s_prime": 1e300, "sigma_s_prime_stderr": 0.01,
        "sigma_a": 0.48, "sigma_a_stderr": 0.001, "albedo_prime": 1.0, "rd_total": 0.4, "mse": 1e-6 }"#;
    write_result(&dir.path().join("result.json"), Some(huge));
    for to in ["pbrt", "mitsuba", "blender", "json"] {
        let out = run(
            dir.path(),
            &["export", "result.json", "--to", to, "--scale", "m"],
        );
        assert_eq!(out.code, 2, "{}", out.stderr);
        assert!(
            out.stderr.contains("channels.b.sigma_s_prime"),
            "{}",
            out.stderr
        );
        assert!(out.stdout.is_empty());
    }
}

/// A dipole result exported for an exact renderer warns on stderr and in the header, with
/// exact transport's Rd (from the Monte Carlo tables) beside the measured one; the same numbers
/// labelled `mc` / `mc` do not warn.
#[test]
fn model_mismatch_warns_with_exact_transport_figures() {
    let dir = temp_dir();
    write_result(&dir.path().join("result.json"), None);
    let out = run(dir.path(), &["export", "result.json", "--to", "mitsuba"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("its diffuse reflectance Rd will differ from the measured one by R "),
        "{}",
        out.stderr
    );
    assert!(out.stdout.contains("MODEL WARNING for Mitsuba"));
    assert!(out.stdout.contains("Rd exact transport"));
    // Relabelled as an exact-model measurement: no warning.
    let text = std::fs::read_to_string(dir.path().join("result.json"))
        .unwrap()
        .replace("\"model\": \"dipole\"", "\"model\": \"mc\"")
        .replace(
            "\"albedo_model\": \"diffusion\"",
            "\"albedo_model\": \"mc\"",
        );
    std::fs::write(dir.path().join("mc.json"), text).unwrap();
    let mc = run(dir.path(), &["export", "mc.json", "--to", "mitsuba"]);
    assert_eq!(mc.code, 0, "{}", mc.stderr);
    assert!(mc.stderr.is_empty(), "{}", mc.stderr);
    assert!(!mc.stdout.contains("MODEL WARNING"));
}

/// The pbrt export says where to include it and what integrator the medium needs.
#[test]
fn pbrt_header_gives_the_integrator_and_placement() {
    let dir = temp_dir();
    write_result(&dir.path().join("result.json"), None);
    let out = run(dir.path(), &["export", "result.json", "--to", "pbrt"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let text = &out.stdout;
    assert!(text.contains("after WorldBegin"), "{text}");
    // skin1's largest albedo is R: 0.74/0.772 = 0.958549…; 2⌈ln 1e-6 / ln α⌉ = 2 · 327 = 654.
    assert!(
        text.contains("Integrator \"volpath\" \"integer maxdepth\" [ 654 ]"),
        "{text}"
    );
    assert!(text.contains("BLACK under point, spot and distant lights"));
}
