//! Robustness, with the real binary: a closed stdout ends every command quietly, the
//! exit-code classes of the imaging, Monte Carlo and renderer families (the measurement family's and
//! spectro's are pinned in measure.rs, spectro.rs and export.rs), outputs checked before the work,
//! never overwritten without --force, and Ctrl-C ending a run with 130 and no temporary file.

use crate::common;

use common::{Run, cached_command, read_json, read_text, run_cached, synth_quick, temp_dir, text};

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// A quick rig-twin sample, measured once (result.json, profile.csv), shared by the tests:
/// `synth --quick` makes it in about a second.
fn sample() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = temp_dir();
        synth_quick(dir.path(), "wood-tile", "wood");
        let o = run_cached(dir.path(), &["measure", "wood", "--quiet"]);
        assert_eq!(o.code, 0, "{}", o.stderr);
        dir
    })
    .path()
}

/// A spectro reading: flat SCE 0.5 and SCI 0.54 at 400–700 nm.
fn spectro_csv(dir: &Path) -> PathBuf {
    let p = dir.join("spectro.csv");
    let mut t = String::from("wavelength_nm,sci,sce\n");
    for i in 0..31 {
        t.push_str(&format!("{},0.54,0.5\n", 400 + 10 * i));
    }
    std::fs::write(&p, t).unwrap();
    p
}

/// Runs `args` with stdout a pipe whose reader is already closed, so the first write meets
/// EPIPE: before this round every command panicked ("failed printing to stdout: Broken pipe",
/// exit 101).
fn into_closed_pipe(cwd: &Path, args: &[&str]) -> Run {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    cached_command()
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap()
        .into()
}

/// Every command, `| true` style: exit 0, nothing about a broken pipe or a panic on stderr, and
/// the files are still written.
#[test]
fn a_closed_stdout_ends_every_command_quietly() {
    let s = sample();
    let dir = temp_dir();
    let d = dir.path();
    std::fs::create_dir(d.join("tab")).unwrap();
    let spectro = spectro_csv(d);
    let wood = s.join("wood");
    let w = |p: &str| wood.join(p).to_string_lossy().into_owned();
    let out = |p: &str| d.join(p).to_string_lossy().into_owned();
    let cases: Vec<Vec<String>> = vec![
        vec!["--help".into()],
        vec!["bench".into(), "optics".into(), "--quick".into()],
        vec!["spectro".into(), spectro.to_string_lossy().into_owned()],
        vec![
            "simulate".into(),
            "--sigma-s-prime".into(),
            "1".into(),
            "--sigma-a".into(),
            "0.1".into(),
            "--eta".into(),
            "1.4".into(),
            "--photons".into(),
            "2e3".into(),
            "-o".into(),
            out("sim.csv"),
        ],
        vec![
            "table".into(),
            "--eta".into(),
            "1.4".into(),
            "--albedos".into(),
            "8".into(),
            "--photons".into(),
            "5000".into(),
            "--cache-dir".into(),
            out("tab"),
        ],
        vec![
            "merge".into(),
            "--exposures".into(),
            w("exposures.csv"),
            "-o".into(),
            out("r.exr"),
        ],
        vec![
            "synth".into(),
            "--material".into(),
            "wood-tile".into(),
            "--quick".into(),
            "-o".into(),
            out("synth"),
        ],
        vec!["measure".into(), w(""), "-o".into(), out("m")],
        vec![
            "fit".into(),
            w("profile.csv"),
            "--eta".into(),
            "1.31".into(),
            "--method".into(),
            "existing".into(),
            "-o".into(),
            out("fit.json"),
        ],
        vec!["batch".into(), w(""), "-o".into(), out("b")],
        vec![
            "demo".into(),
            "--quick".into(),
            "-o".into(),
            out("demo"),
            "--quiet".into(),
        ],
        vec!["compare".into(), w(""), "-o".into(), out("c")],
        vec![
            "export".into(),
            w("result.json"),
            "--to".into(),
            "pbrt".into(),
        ],
        vec![
            "render".into(),
            "--params".into(),
            "pink-plastic".into(),
            "--shape".into(),
            "sphere".into(),
            "--triangles".into(),
            "1000".into(),
            "--size".into(),
            "16x16".into(),
            "--spp".into(),
            "1".into(),
            "--method".into(),
            "color".into(),
            "-o".into(),
            out("x.png"),
        ],
    ];
    for args in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = into_closed_pipe(d, &args);
        let err = &o.stderr;
        assert_eq!(o.code, 0, "{args:?}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains("Broken pipe"),
            "{args:?}: {err}"
        );
    }
    // The outputs were written although nothing could be printed.
    for f in [
        "sim.csv",
        "r.exr",
        "synth/sample.toml",
        "m/result.json",
        "fit.json",
    ] {
        assert!(d.join(f).exists(), "{f}");
    }
    // A profile of the merged map, into a closed pipe too.
    let o = into_closed_pipe(
        d,
        &["profile", "r.exr", "--mm-per-pixel", "0.1", "-o", "p.csv"],
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(d.join("p.csv").exists());
}

/// The imaging family: merge 0 / 1 (exposure times reversed: the response runs downward) / 2
/// (too few samples for the response; a profile named .exr), with nothing written on failure — in
/// particular no response CSV without its radiance map.
#[test]
fn merge_and_profile_exit_classes() {
    let wood = sample().join("wood");
    let dir = temp_dir();
    let d = dir.path();
    // Reversed times: the same frames, the times read bottom up.
    let csv = read_text(&wood.join("exposures.csv"));
    let rows: Vec<(&str, &str)> = csv
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_once(',').unwrap())
        .collect();
    let mut reversed = String::from("file,time_s\n");
    for (k, (file, _)) in rows.iter().enumerate() {
        let frame = wood.join(file);
        reversed.push_str(&format!(
            "{},{}\n",
            frame.display(),
            rows[rows.len() - 1 - k].1
        ));
    }
    std::fs::write(d.join("reversed.csv"), reversed).unwrap();
    let o = run_cached(
        d,
        &["merge", "--exposures", "reversed.csv", "-o", "rev.exr"],
    );
    let err = &o.stderr;
    assert_eq!(o.code, 1, "{err}");
    assert!(err.contains("right order"), "{err}");
    assert!(!d.join("rev.exr").exists() && !d.join("rev.response.csv").exists());

    let exposures = wood.join("exposures.csv");
    let exposures = exposures.to_str().unwrap();
    let o = run_cached(
        d,
        &[
            "merge",
            "--exposures",
            exposures,
            "--samples",
            "1",
            "-o",
            "a.exr",
        ],
    );
    let err = &o.stderr;
    assert_eq!(o.code, 2, "{err}");
    assert!(err.contains("22 to 1000"), "{err}");
    // An unwritable map (its folder is a file): refused before reading a frame, no orphan CSV.
    std::fs::write(d.join("plain"), b"x").unwrap();
    let o = run_cached(
        d,
        &[
            "merge",
            "--exposures",
            exposures,
            "-o",
            "plain/a.exr",
            "--response-out",
            "a.response.csv",
        ],
    );
    assert_eq!(o.code, 2, "{}", o.stderr);
    assert!(!d.join("a.response.csv").exists());

    let o = run_cached(d, &["merge", "--exposures", exposures, "-o", "a.exr"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    // An existing output is refused without --force and replaced with it.
    let o = run_cached(d, &["merge", "--exposures", exposures, "-o", "a.exr"]);
    assert_eq!(o.code, 2);
    assert!(o.stderr.contains("--force"), "{}", o.stderr);
    let o = run_cached(
        d,
        &["merge", "--exposures", exposures, "-o", "a.exr", "--force"],
    );
    assert_eq!(o.code, 0, "{}", o.stderr);

    for (args, needle) in [
        (
            vec!["profile", "a.exr", "--mm-per-pixel", "0.1", "-o", "p.exr"],
            "CSV",
        ),
        (
            vec![
                "profile",
                "a.exr",
                "--mm-per-pixel",
                "0.1",
                "--ring-width-px",
                "1e-300",
                "-o",
                "p.csv",
            ],
            "10⁶",
        ),
        (
            vec![
                "profile",
                "a.exr",
                "--mm-per-pixel",
                "0.1",
                "--r-max-px",
                "1e13",
                "-o",
                "p.csv",
            ],
            "(0, 1e6] px",
        ),
    ] {
        let o = run_cached(d, &args);
        let err = &o.stderr;
        assert_eq!(o.code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let o = run_cached(
        d,
        &["profile", "a.exr", "--mm-per-pixel", "0.1", "-o", "p.csv"],
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
}

/// The Monte Carlo family has no failed-measurement class (nothing is measured): 0, or 2 for bad
/// usage, with `simulate -o` checked against what it writes and before the run, `--out` still
/// accepted, and counts written as `1e6`.
#[test]
fn simulate_outputs_and_exit_classes() {
    let dir = temp_dir();
    let d = dir.path();
    let base = [
        "simulate",
        "--sigma-s-prime",
        "1",
        "--sigma-a",
        "0.1",
        "--eta",
        "1.4",
        "--quiet",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|s| (*s).to_string()).collect()
    };
    let go = |extra: &[&str]| {
        let args = with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        run_cached(d, &args)
    };
    let o = go(&["--photons", "2e3", "-o", "p.json"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let json: serde_json::Value = read_json(&d.join("p.json"));
    assert_eq!(json["result"]["photons"], 2000);
    let o = go(&["--photons", "2e3", "--out", "p.csv"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(read_text(&d.join("p.csv")).starts_with("r_inner_mm"));
    // Refused in milliseconds although the run would take minutes: the output first.
    for (extra, needle) in [
        (vec!["--photons", "1e8", "-o", "p.csv"], "--force"),
        (vec!["--photons", "1e8", "-o", "p.txt"], ".csv or .json"),
        (
            vec!["--photons", "1e8", "-o", "nowhere/p.csv"],
            "does not exist",
        ),
        (
            vec!["--photons", "1e8", "-o", "p.csv/x.csv"],
            "not a folder",
        ),
        (
            vec!["--photons", "1e8", "--max-memory-mib", "0"],
            "at least 1",
        ),
    ] {
        let t0 = Instant::now();
        let o = go(&extra);
        let err = &o.stderr;
        assert_eq!(o.code, 2, "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(t0.elapsed() < Duration::from_secs(5), "{extra:?}");
    }
    let o = go(&["--photons", "2e3", "-o", "p.csv", "--force"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    // No temporary file was left by any of these.
    let left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-") || n.starts_with(".scatterfit-tmp-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Ctrl-C: a long `simulate` ends within a second with the shell's 130, writes nothing and leaves
/// no temporary file. (Whether an interrupted *write* removes its temporary file is pinned by
/// crates/io/tests/atomic_interrupt.rs, which interrupts a write half-way; a real signal cannot be
/// timed to land inside a write of a few milliseconds.)
#[cfg(unix)]
#[test]
fn ctrl_c_ends_a_run_with_130_and_no_temporary() {
    let dir = temp_dir();
    let mut child = cached_command()
        .args([
            "simulate",
            "--sigma-s-prime",
            "10",
            "--sigma-a",
            "0.001",
            "--eta",
            "1.4",
            "--photons",
            "1e9",
            "--max-interactions",
            "1e15",
            "-o",
            "long.csv",
        ])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Let it start tracing (the handler is installed first thing in main).
    std::thread::sleep(Duration::from_millis(700));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the run must still be going"
    );
    let t0 = Instant::now();
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert!(t0.elapsed() < Duration::from_secs(5));
    assert_eq!(out.status.code(), Some(130), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("interrupted"));
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "nothing is written: {left:?}");
}

/// The renderer family: 0, 1 (a result whose channel failed: nothing to render, as `export`
/// says of it), 2 (bad usage), with the memory of the panels checked before rendering.
#[test]
fn render_exit_classes_and_memory() {
    let dir = temp_dir();
    let d = dir.path();
    let result = sample().join("wood").join("result.json");
    let mut json: serde_json::Value = read_json(&result);
    let quick = [
        "--shape",
        "sphere",
        "--triangles",
        "1000",
        "--size",
        "16x16",
        "--spp",
        "1",
        "--quiet",
    ];
    let render = |params: &str, out: &str, extra: &[&str]| {
        let mut args = vec!["render", "--params", params, "-o", out];
        // The quick settings, less those the case gives itself (clap refuses a flag twice).
        for pair in quick[..8].chunks(2) {
            if !extra.contains(&pair[0]) {
                args.extend(pair);
            }
        }
        args.push("--quiet");
        args.extend(extra);
        run_cached(d, &args)
    };
    let o = render(result.to_str().unwrap(), "ok.png", &[]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    json["channels"]["b"]["status"] = "failed".into();
    json["channels"]["b"]["sigma_s_prime"] = serde_json::Value::Null;
    json["channels"]["b"]["sigma_a"] = serde_json::Value::Null;
    json["channels"]["b"]["problem"] = "no α′".into();
    std::fs::write(d.join("failed.json"), json.to_string()).unwrap();
    let o = render("failed.json", "f.png", &[]);
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(!d.join("f.png").exists());
    for (extra, needle) in [
        (vec!["--spp", "0"], "1–4096"),
        (vec!["--white", "0.5"], "[1, 1e6]"),
        (
            vec!["--size", "8192x8192", "--max-memory-mib", "64"],
            "memory",
        ),
    ] {
        let o = render("pink-plastic", "b.png", &extra);
        let err = &o.stderr;
        assert_eq!(o.code, 2, "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
}
