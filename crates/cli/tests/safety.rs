//! Files and paths: the attacks and accidents of a shared sample folder, tried on the
//! real binary. Each test plants the hostile thing in a copy of one quick rig-twin sample and checks
//! that nothing outside is touched, nothing is read that should not be, nothing is echoed that did
//! not parse, and no input is destroyed (RELIABILITY.md, "Files and paths").

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant, SystemTime};

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

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

const SECRET: &str = "root:$6$SECRETHASH0123456789:19000:0:99999:7:::\n";

/// A symbolic link planted at any of measure's output names (result files, the set manifest) is
/// refused before the measurement; the file it points to is untouched. Links at the temporary
/// names of the old scheme (`.NAME.tmp-<pid>`, the probe's) are never followed: a measurement
/// beside them succeeds and leaves them and their targets as they were.
#[cfg(unix)]
#[test]
fn planted_links_never_redirect_a_write() {
    use std::os::unix::fs::symlink;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let victim = d.join("victim");
    fs::write(&victim, SECRET).unwrap();
    for out in [
        "result.json",
        "fit.png",
        "profile.csv",
        "result.md",
        "report.html",
        "result-files.json",
    ] {
        let s = sample(d, &format!("s-{out}"));
        symlink(&victim, s.join(out)).unwrap();
        let r = scatterfit(d, &["measure", s.to_str().unwrap(), "--quiet"]);
        assert_eq!(r.code, 2, "{out}: {}", r.stderr);
        assert!(r.stderr.contains("symbolic link"), "{}", r.stderr);
        assert_eq!(fs::read_to_string(&victim).unwrap(), SECRET, "{out}");
        assert!(!s.join("result.csv").exists(), "nothing was written");
    }
    // The old temporary and probe names, for every pid a run could get: links planted there are
    // not followed (names are random now), and the measurement goes through.
    let s = sample(d, "s-tmp");
    for pid in 1..200 {
        for name in [
            format!(".result.json.tmp-{pid}"),
            format!(".scatterfit-probe.tmp-{pid}"),
        ] {
            symlink(&victim, s.join(name)).unwrap();
        }
    }
    let r = scatterfit(d, &["measure", s.to_str().unwrap(), "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(fs::read_to_string(&victim).unwrap(), SECRET);
    assert!(
        fs::read_to_string(s.join("result.json"))
            .unwrap()
            .contains("wood-tile")
    );
    // -o FILE of the single-file commands: a link there is refused too.
    let link = d.join("p.csv");
    symlink(&victim, &link).unwrap();
    let r = scatterfit(
        d,
        &[
            "profile",
            "x.exr",
            "--mm-per-pixel",
            "0.1",
            "-o",
            "p.csv",
            "--force",
        ],
    );
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("symbolic link"), "{}", r.stderr);
    assert_eq!(fs::read_to_string(&victim).unwrap(), SECRET);
}

/// A killed run's temporary (a regular file of our prefix, old, unlocked) is removed by the next
/// measurement into that folder; a link of that prefix is left alone, and its target untouched.
#[cfg(unix)]
#[test]
fn stale_temporaries_are_cleaned_safely_by_a_later_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = sample(d, "s");
    let victim = d.join("victim");
    fs::write(&victim, SECRET).unwrap();
    let old = SystemTime::now() - Duration::from_secs(3600);
    let stale = s.join(".scatterfit-tmp-Ab3dEf6hIj9k-result.json");
    fs::write(&stale, b"half a result").unwrap();
    fs::File::options()
        .write(true)
        .open(&stale)
        .unwrap()
        .set_modified(old)
        .unwrap();
    let young = s.join(".scatterfit-tmp-Zz3dEf6hIj9k-fit.png");
    fs::write(&young, b"a write in progress").unwrap();
    let link = s.join(".scatterfit-tmp-Lk3dEf6hIj9k-result.csv");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(!stale.exists(), "the stale temporary is removed");
    assert!(young.exists(), "a young one may be another run's: kept");
    assert!(fs::symlink_metadata(&link).is_ok(), "a link is never ours");
    assert_eq!(fs::read_to_string(&victim).unwrap(), SECRET);
}

/// An input named like an output — a spectro file called result.csv, a frame called fit.png, the
/// exposures list called result.md, a hard link of a frame as profile.csv — is refused, exit 2,
/// before anything is written; the input is intact.
#[test]
fn a_run_never_destroys_its_own_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let edit = |s: &Path, file: &str, from: &str, to: &str| {
        let p = s.join(file);
        let t = fs::read_to_string(&p).unwrap().replace(from, to);
        fs::write(p, t).unwrap();
    };
    let cases: [(&str, &str, &str, &str); 3] = [
        ("spectro.csv", "result.csv", "sample.toml", "spectro.csv"),
        ("frame_05.png", "fit.png", "exposures.csv", "frame_05.png"),
        ("exposures.csv", "result.md", "sample.toml", "exposures.csv"),
    ];
    for (input, renamed, named_in, old) in cases {
        let s = sample(d, &format!("s-{renamed}"));
        fs::rename(s.join(input), s.join(renamed)).unwrap();
        edit(&s, named_in, old, renamed);
        let before = fs::read(s.join(renamed)).unwrap();
        let listed = listing(&s);
        let r = scatterfit(d, &["measure", s.to_str().unwrap(), "--quiet"]);
        assert_eq!(r.code, 2, "{renamed}: {}", r.stderr);
        assert!(
            r.stderr.contains("is an input of the sample") && r.stderr.contains(renamed),
            "{}",
            r.stderr
        );
        assert_eq!(fs::read(s.join(renamed)).unwrap(), before);
        assert_eq!(listing(&s), listed, "nothing written");
        // batch refuses the same before any sample is measured.
        let r = scatterfit(
            d,
            &["batch", s.to_str().unwrap(), "-o", d.to_str().unwrap()],
        );
        assert_eq!(r.code, 2, "{}", r.stderr);
        assert_eq!(listing(&s), listed);
    }
    // A hard link is the same file under another name.
    let s = sample(d, "s-hard");
    fs::hard_link(s.join("frame_00.png"), s.join("profile.csv")).unwrap();
    let r = scatterfit(d, &["measure", "s-hard", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
}

/// `measure A -o B`: B holding another sample's results, or being another sample's folder, is
/// refused without --force and says what is there; A's own earlier results in B are replaced.
#[test]
fn another_samples_results_are_not_replaced_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sample(d, "a");
    let b = sample(d, "b");
    fs::write(
        b.join("sample.toml"),
        fs::read_to_string(b.join("sample.toml"))
            .unwrap()
            .replace("name = \"wood-tile\"", "name = \"other-sample\""),
    )
    .unwrap();
    fs::create_dir(d.join("out")).unwrap();
    let r = scatterfit(d, &["measure", "b", "-o", "out", "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let r = scatterfit(d, &["measure", "a", "-o", "out", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("other-sample") && r.stderr.contains("--force"),
        "{}",
        r.stderr
    );
    assert!(
        fs::read_to_string(d.join("out/result.json"))
            .unwrap()
            .contains("other-sample")
    );
    let r = scatterfit(d, &["measure", "a", "-o", "b", "--quiet"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("another sample"), "{}", r.stderr);
    let r = scatterfit(d, &["measure", "a", "-o", "out", "--quiet", "--force"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    // Now they are a's: measured again without --force.
    let r = scatterfit(d, &["measure", "./a/", "-o", "out", "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
}

/// Manifest paths stay inside the sample folder (`../x`, absolute, links out) unless
/// --allow-outside-paths; and whatever is allowed, a file that does not parse as what it should be
/// is never echoed.
#[cfg(unix)]
#[test]
fn manifest_paths_stay_inside_and_secrets_are_never_echoed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let secret = d.join("shadow");
    fs::write(&secret, SECRET).unwrap();
    let secret_s = secret.to_str().unwrap();
    let manifest_with = |s: &Path, value: &str| {
        let p = s.join("sample.toml");
        let t = fs::read_to_string(&p)
            .unwrap()
            .replace("\"spectro.csv\"", &format!("\"{value}\""));
        fs::write(p, t).unwrap();
    };
    let s1 = sample(d, "s1");
    manifest_with(&s1, "../shadow");
    let s2 = sample(d, "s2");
    manifest_with(&s2, secret_s);
    let s3 = sample(d, "s3");
    fs::remove_file(s3.join("spectro.csv")).unwrap();
    std::os::unix::fs::symlink(&secret, s3.join("spectro.csv")).unwrap();
    let s4 = sample(d, "s4");
    fs::remove_file(s4.join("sample.toml")).unwrap();
    std::os::unix::fs::symlink(&secret, s4.join("sample.toml")).unwrap();
    let s5 = sample(d, "s5");
    let e = fs::read_to_string(s5.join("exposures.csv"))
        .unwrap()
        .replace("frame_03.png", secret_s);
    fs::write(s5.join("exposures.csv"), e).unwrap();
    for s in ["s1", "s2", "s3", "s4", "s5"] {
        let r = scatterfit(d, &["measure", s, "--quiet"]);
        assert_eq!(r.code, 2, "{s}: {}", r.stderr);
        assert!(
            r.stderr.contains("outside") && r.stderr.contains("--allow-outside-paths"),
            "{s}: {}",
            r.stderr
        );
        assert!(!r.stderr.contains("SECRET"), "{}", r.stderr);
        // Allowed: the file is read, does not parse, and is still not shown.
        let r = scatterfit(d, &["measure", s, "--quiet", "--allow-outside-paths"]);
        assert_eq!(r.code, 2, "{s}: {}", r.stderr);
        assert!(!r.stderr.contains("SECRET"), "{s}: {}", r.stderr);
        assert!(!r.stderr.contains("root:"), "{s}: {}", r.stderr);
    }
    // batch and compare follow the same policy.
    let r = scatterfit(d, &["batch", "s1", "--quiet"]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("outside"), "{}", r.stderr);
}

/// FIFOs, devices, folders and sockets as any input are refused at once with a clear message:
/// nothing blocks, nothing is read without bound.
#[cfg(unix)]
#[test]
fn special_files_as_inputs_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mkfifo = |p: &Path| {
        let ok = Command::new("mkfifo").arg(p).status().unwrap().success();
        assert!(ok);
    };
    let cases: [(&str, &str); 5] = [
        ("spectro.csv", "FIFO"),
        ("frame_02.png", "FIFO"),
        ("sample.toml", "FIFO"),
        ("exposures.csv", "FIFO"),
        ("spectro.csv", "folder"),
    ];
    for (k, (file, kind)) in cases.iter().enumerate() {
        let s = sample(d, &format!("s{k}"));
        fs::remove_file(s.join(file)).unwrap();
        if *kind == "FIFO" {
            mkfifo(&s.join(file));
        } else {
            fs::create_dir(s.join(file)).unwrap();
        }
        let t = Instant::now();
        let r = scatterfit(d, &["measure", s.to_str().unwrap(), "--quiet"]);
        assert_eq!(r.code, 2, "{file}: {}", r.stderr);
        assert!(r.stderr.contains(kind), "{file}: {}", r.stderr);
        assert!(t.elapsed() < Duration::from_secs(10), "{file}");
    }
    // /dev/zero as the manifest (allowed outside, so the device check itself is what stops it).
    let s = sample(d, "zero");
    fs::remove_file(s.join("sample.toml")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", s.join("sample.toml")).unwrap();
    let t = Instant::now();
    let r = scatterfit(d, &["measure", "zero", "--quiet", "--allow-outside-paths"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("character device"), "{}", r.stderr);
    assert!(t.elapsed() < Duration::from_secs(10));
    // As the result of render/export and the profile of fit.
    for args in [
        vec!["export", "/dev/zero", "--to", "json"],
        vec!["fit", "/dev/zero", "--eta", "1.4", "--method", "existing"],
    ] {
        let r = scatterfit(d, &args);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(
            r.stderr.contains("character device"),
            "{args:?}: {}",
            r.stderr
        );
    }
}

/// batch: one folder named four ways is measured once; folders whose manifest is spelt
/// differently are reported (exit 1), not skipped silently.
#[cfg(unix)]
#[test]
fn batch_measures_a_folder_once_and_reports_misspelt_manifests() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sample(d, "a");
    std::os::unix::fs::symlink(d.join("a"), d.join("link")).unwrap();
    let r = scatterfit(d, &["batch", "a", "./a", "a/", "link", "-o", "."]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("1 of 1 samples"), "{}", r.stdout);
    let rows = fs::read_to_string(d.join("summary.csv")).unwrap();
    assert_eq!(rows.lines().count(), 4, "header + R, G, B: {rows}");
    let m = sample(d, "m");
    fs::rename(m.join("sample.toml"), m.join("Sample.toml")).unwrap();
    let t = sample(d, "t");
    fs::rename(t.join("sample.toml"), t.join("sample.toml.txt")).unwrap();
    let r = scatterfit(d, &["batch", "a", "m", "t", "-o", "."]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(
        r.stderr.contains("Sample.toml") && r.stderr.contains("sample.toml.txt"),
        "{}",
        r.stderr
    );
    assert!(r.stdout.contains("1 of 3 samples"), "{}", r.stdout);
    let r = scatterfit(d, &["measure", "m", "--quiet"]);
    assert_eq!(r.code, 2);
    assert!(r.stderr.contains("Sample.toml"), "{}", r.stderr);
}

/// A sample name full of terminal escapes, line breaks, formula starts and markup: the terminal
/// sees no escape character, result.csv no formula, result.md no broken row or HTML, fit.svg stays
/// well-formed XML.
#[test]
fn hostile_names_are_escaped_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = sample(d, "s");
    let name = "=HYPERLINK(\\\"x\\\")\\u001b]0;owned\\u0007\\u001b[2J\\r| a |<b>\\u0001\\u009b";
    let p = s.join("sample.toml");
    let t = fs::read_to_string(&p)
        .unwrap()
        .replace("name = \"wood-tile\"", &format!("name = \"{name}\""));
    fs::write(&p, t).unwrap();
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    for text in [&r.stdout, &r.stderr] {
        assert!(
            !text.contains(['\u{1b}', '\u{7}', '\r', '\u{1}', '\u{9b}']),
            "{text:?}"
        );
    }
    assert!(r.stdout.contains("\\u{1b}]0;owned"), "{}", r.stdout);
    let r = scatterfit(d, &["measure", "s", "--quiet", "--json"]);
    assert!(!r.stdout.contains(['\u{1b}', '\u{9b}']), "{:?}", r.stdout);
    let back: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert!(back["name"].as_str().unwrap().contains('\u{9b}'));
    let csv = fs::read_to_string(s.join("result.csv")).unwrap();
    for line in csv.lines().skip(1) {
        assert!(line.starts_with("\"'=") || line.starts_with("'="), "{line}");
    }
    let md = fs::read_to_string(s.join("result.md")).unwrap();
    assert!(!md.contains("<b>") && !md.contains('\u{1b}'), "{md}");
    let svg = fs::read_to_string(s.join("fit.svg")).unwrap();
    roxmltree::Document::parse(&svg).expect("fit.svg is well-formed XML");
    // The page: the name shown escaped (title, heading, Figure 4's inline SVG), never as markup
    // or a control.
    let page = fs::read_to_string(s.join("report.html")).unwrap();
    assert!(!page.contains("<b>"), "raw markup in report.html");
    assert!(page.contains("&lt;b&gt;"), "the name is not shown");
    if let Some(i) = page.find(['\u{1b}', '\u{7}', '\r', '\u{1}', '\u{9b}']) {
        let around: String = page[i.saturating_sub(200)..].chars().take(260).collect();
        panic!("a control in report.html: {around:?}");
    }
}

/// A folder holding files of two runs is not taken for one run's results: render --profile
/// refuses a result.json beside another run's profile.csv.
#[test]
fn a_mix_of_two_runs_is_refused_by_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = sample(d, "s");
    let r = scatterfit(d, &["measure", "s", "--quiet"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(s.join("result-files.json").exists());
    // Another run (another method) wrote its profile.csv, then died before its set manifest: put
    // back the first run's manifest to make the mix look complete.
    let set = fs::read(s.join("result-files.json")).unwrap();
    let other = sample(d, "other");
    let r = scatterfit(d, &["measure", "other", "--quiet", "--method", "existing"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mut profile = fs::read_to_string(other.join("profile.csv")).unwrap();
    profile.push_str("# another run\n");
    fs::write(s.join("profile.csv"), profile).unwrap();
    fs::write(s.join("result-files.json"), set).unwrap();
    let quick = ["--size", "16x16", "--spp", "1", "--quiet", "-o", "p.csv"];
    let mut args = vec!["render", "--params", "s/result.json", "--profile"];
    args.extend(quick);
    let r = scatterfit(d, &args);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("different runs"), "{}", r.stderr);
    assert!(!d.join("p.csv").exists());
}
