//! The hostile and careless cases of a shared lab, tried on the real binary: one input-path policy
//! for every manifest key, one output policy for every command that writes, bounds before work,
//! downstream honesty about results the data checks did not trust, and flags whose extreme values
//! once gave NaN, black images or 309-digit messages (RELIABILITY.md, "Paths, outputs, bounds,
//! honesty").

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::common;

use common::{run_cached as scatterfit, synth_quick};

/// One quick twin sample, made once; tests work on copies.
fn pristine() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = common::temp_dir();
        synth_quick(d.path(), "wood-tile", "s");
        d
    })
    .path()
}

/// A copy of the pristine sample at `dir/name`.
fn sample(dir: &Path, name: &str) -> PathBuf {
    let to = dir.join(name);
    fs::create_dir_all(&to).unwrap();
    for e in fs::read_dir(pristine().join("s")).unwrap().flatten() {
        fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    to
}

/// `key = "value"` added to the manifest's `[camera]` section.
fn camera_key(s: &Path, key: &str, value: &str) {
    let p = s.join("sample.toml");
    let t = fs::read_to_string(&p)
        .unwrap()
        .replace("[camera]\n", &format!("[camera]\n{key} = \"{value}\"\n"));
    fs::write(p, t).unwrap();
}

/// The longest run of decimal digits in `text`.
fn longest_digit_run(text: &str) -> usize {
    text.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

/// Every key that names a file — including `camera.flat` and `camera.spot_image`, which once read
/// absolute and `../` paths — is refused the same way when it leads out of the sample folder, and
/// the refusal reads the same whether or not the file outside exists (no existence oracle).
#[test]
fn every_manifest_path_follows_one_policy_without_an_existence_oracle() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::copy(pristine().join("s/frame_00.png"), d.join("there.png")).unwrap();
    let there = d.join("there.png");
    let missing = d.join("nowhere/missing.png");
    let values = [
        ("../there.png", "../nowhere/missing.png"),
        (there.to_str().unwrap(), missing.to_str().unwrap()),
    ];
    for key in ["flat", "spot_image", "dark", "response"] {
        for (exists, absent) in values {
            let mut texts = Vec::new();
            for value in [exists, absent] {
                let s = sample(d, &format!("s-{key}"));
                camera_key(&s, key, value);
                let r = scatterfit(d, &["measure", s.to_str().unwrap(), "--quiet"]);
                assert_eq!(r.code, 2, "{key} = {value}: {}", r.stderr);
                assert!(
                    r.stderr.contains("--allow-outside-paths")
                        && r.stderr.contains(&format!("camera.{key}")),
                    "{key} = {value}: {}",
                    r.stderr
                );
                texts.push(r.stderr.replace(value, "VALUE"));
                fs::remove_dir_all(&s).unwrap();
            }
            assert_eq!(texts[0], texts[1], "{key}: {exists} / {absent}");
        }
    }
}

/// A frame named `../x` in the exposures list is refused like a manifest key, even when it would
/// lead back inside.
#[test]
fn a_frame_that_goes_up_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = sample(d, "s");
    let csv = s.join("exposures.csv");
    let t = fs::read_to_string(&csv)
        .unwrap()
        .replace("frame_02.png", "../s/frame_02.png");
    fs::write(&csv, t).unwrap();
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("goes up with `..`"), "{}", r.stderr);
}

/// `batch` and `compare -o` into another sample's folder are refused (as `measure -o` is); their
/// default `-o .` never replaces a file scatterfit did not write there; a sample's own notes named
/// like a result file are kept unless --force; nothing is written through a link out of a drop
/// folder.
#[test]
fn outputs_never_replace_what_scatterfit_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = sample(d, "a");
    let other = sample(d, "other");
    let listing = |p: &Path| {
        let mut v: Vec<String> = fs::read_dir(p)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let before = listing(&other);
    for cmd in ["batch", "compare"] {
        let r = scatterfit(d, &[cmd, "a", "-o", "other", "--quiet"]);
        assert_eq!(r.code, 2, "{cmd}: {}", r.stderr);
        assert!(r.stderr.contains("another sample"), "{cmd}: {}", r.stderr);
        assert_eq!(listing(&other), before, "{cmd}: nothing written");
    }
    // The working folder's own index.html and summary.md.
    let work = d.join("work");
    fs::create_dir(&work).unwrap();
    fs::write(work.join("index.html"), "the lab's page").unwrap();
    let r = scatterfit(&work, &["batch", a.to_str().unwrap(), "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("not written by scatterfit") && r.stderr.contains("--force"),
        "{}",
        r.stderr
    );
    assert_eq!(
        fs::read_to_string(work.join("index.html")).unwrap(),
        "the lab's page"
    );
    assert!(!a.join("result.json").exists(), "refused before any work");
    // A sample's own notes called result.md.
    fs::write(a.join("result.md"), "my notes").unwrap();
    let r = scatterfit(d, &["measure", "a", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("not written by scatterfit"),
        "{}",
        r.stderr
    );
    assert_eq!(fs::read_to_string(a.join("result.md")).unwrap(), "my notes");
    // The user insists: replaced, and recorded, so the next run needs no --force.
    let r = scatterfit(d, &["measure", "a", "--quiet", "--force"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    assert_ne!(fs::read_to_string(a.join("result.md")).unwrap(), "my notes");
    let r = scatterfit(d, &["measure", "a", "--quiet"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    // A drop folder holding a link to a sample folder elsewhere: not followed, nothing written
    // there.
    #[cfg(unix)]
    {
        let drop = d.join("drop");
        fs::create_dir(&drop).unwrap();
        let elsewhere = sample(d, "elsewhere");
        std::os::unix::fs::symlink(&elsewhere, drop.join("linked")).unwrap();
        let before = listing(&elsewhere);
        let r = scatterfit(d, &["batch", "drop", "-o", "drop", "--quiet"]);
        assert_eq!(r.code, 1, "{}", r.stderr);
        assert!(r.stderr.contains("leads out of"), "{}", r.stderr);
        assert_eq!(listing(&elsewhere), before);
    }
}

/// A result whose channels the data checks did not trust: `export` says so on stderr and in the
/// file's header and exits 1 unless --allow-suspect; `render` the same on stderr.
#[test]
fn downstream_commands_say_a_result_is_not_trusted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sample(d, "s");
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    // The same result, its G channel marked suspect as a data check would.
    let mut v: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(d.join("s/result.json")).unwrap()).unwrap();
    let q = &mut v["channels"]["g"]["quality"];
    assert!(q.is_object(), "{q}");
    q["verdict"] = "suspect".into();
    fs::write(d.join("suspect.json"), v.to_string()).unwrap();
    // The trusted original exports with exit 0 and no warning (when every check passed).
    let r = scatterfit(d, &["export", "s/result.json", "--to", "json"]);
    let trusted = !r.stdout.contains("not_trusted");
    if trusted {
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    for (to, ext) in [("mitsuba", "xml"), ("pbrt", "pbrt"), ("json", "json")] {
        let out = format!("m.{ext}");
        let r = scatterfit(d, &["export", "suspect.json", "--to", to, "-o", &out]);
        assert_eq!(r.code, 1, "{to}: {}", r.stderr);
        assert!(
            r.stderr.contains("G suspect") && r.stderr.contains("--allow-suspect"),
            "{to}: {}",
            r.stderr
        );
        let text = fs::read_to_string(d.join(&out)).unwrap();
        assert!(
            text.contains("WARNING") || text.contains("not_trusted"),
            "{to}: {text}"
        );
        let r = scatterfit(
            d,
            &[
                "export",
                "suspect.json",
                "--to",
                to,
                "-o",
                &out,
                "--force",
                "--allow-suspect",
            ],
        );
        assert_eq!(r.code, 0, "{to}: {}", r.stderr);
        assert!(r.stderr.contains("G suspect"), "{to}: {}", r.stderr);
    }
    let r = scatterfit(
        d,
        &[
            "render",
            "--params",
            "suspect.json",
            "-o",
            "r.png",
            "--size",
            "32x32",
            "--spp",
            "1",
            "--method",
            "color",
            "--quiet",
        ],
    );
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("G suspect"), "{}", r.stderr);
}

/// Extreme flag values are refused with readable numbers: a vanishing tally radius (once NaN with
/// exit 0), an overflowing shading coefficient (once a black image).
#[test]
fn extreme_flags_are_refused_with_readable_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [&[&str]; 3] = [
        &[
            "simulate",
            "--sigma-s-prime",
            "1",
            "--sigma-a",
            "0.1",
            "--r-max-mm",
            "1e-300",
            "--photons",
            "100",
        ],
        &[
            "render",
            "--params",
            "pink-plastic",
            "--rho-d",
            "1e300",
            "-o",
            "x.png",
        ],
        &[
            "render",
            "--params",
            "pink-plastic",
            "--alpha",
            "1e300",
            "-o",
            "x.png",
        ],
    ];
    for args in cases {
        let r = scatterfit(d, args);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(longest_digit_run(&r.stderr) < 20, "{args:?}: {}", r.stderr);
        assert!(!d.join("x.png").exists());
    }
}

/// Extra numbers in `center_px` or `lab` are refused, not dropped; an overlong name, too many
/// frames are refused before any work.
#[test]
fn manifests_beyond_their_bounds_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = sample(d, "s");
    let manifest = fs::read_to_string(s.join("sample.toml")).unwrap();
    let with = |t: &str| fs::write(s.join("sample.toml"), t).unwrap();
    with(&manifest.replace("[camera]\n", "[camera]\ncenter_px = [320, 240, 7]\n"));
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("center_px") && r.stderr.contains("exactly 2"),
        "{}",
        r.stderr
    );
    let long = "n".repeat(100_000);
    with(&format!("name = \"{long}\"\n{manifest}").replace("name = \"wood-tile\"\n", ""));
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("100000 characters"), "{}", r.stderr);
    assert!(r.stderr.len() < 2000, "the name is not echoed whole");
    with(&manifest);
    let csv = fs::read_to_string(s.join("exposures.csv")).unwrap();
    let mut many = csv.clone();
    let line = csv.lines().nth(1).unwrap();
    for _ in 0..70 {
        many.push_str(line);
        many.push('\n');
    }
    fs::write(s.join("exposures.csv"), many).unwrap();
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("more than 64 frames"), "{}", r.stderr);
}

/// `render --params NAME` where NAME is also a folder (the demo's sample folders beside the
/// published sets' names): the folder's result, or the published set when it holds none.
#[test]
fn render_params_name_of_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("pink-plastic")).unwrap();
    fs::write(d.join("pink-plastic/notes.txt"), "x").unwrap();
    let r = scatterfit(
        d,
        &[
            "render",
            "--params",
            "pink-plastic",
            "-o",
            "p.png",
            "--size",
            "32x32",
            "--spp",
            "1",
            "--method",
            "color",
            "--quiet",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(d.join("p.png").is_file());
}

/// A `synth` whose stderr is not a terminal (a log, a pipe) says how far it is: status lines, not
/// silence for minutes.
#[test]
fn synth_reports_progress_when_piped() {
    let dir = tempfile::tempdir().unwrap();
    let r = common::run(
        dir.path(),
        &[
            "synth",
            "--material",
            "wood-tile",
            "--quick",
            "-o",
            "s",
            "--cache-dir",
            "cache",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("Monte Carlo") && r.stderr.contains('%'),
        "{}",
        r.stderr
    );
}
