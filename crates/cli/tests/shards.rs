//! `--shard K/N`, `scatterfit combine` and `scatterfit slurm` through the real binary: a table
//! built in 3 shards and combined is the one-machine table's file byte for byte; a shard already
//! done is skipped; a missing, duplicated or foreign shard is refused, naming the file; a batch in
//! 2 shards combines to the one-machine summary, and a batch does not measure again a sample whose
//! result files match its inputs (unless --force); the Slurm script holds the job array and the
//! dependent combine job. (A real Slurm cluster runs the scripts in `.ci/slurm-test.sh`.)

use crate::common;

use std::path::Path;

use common::{Run, run, run_cached, synth_quick, temp_dir};

const TABLE: [&str; 7] = [
    "table",
    "--eta",
    "1.3",
    "--albedos",
    "8",
    "--photons",
    "5000",
];

fn table(cwd: &Path, extra: &[&str]) -> Run {
    let mut args: Vec<&str> = TABLE.to_vec();
    args.extend(extra);
    args.push("--quiet");
    run(cwd, &args)
}

fn parts(dir: &Path) -> Vec<String> {
    // (Not the folder's ledger of what scatterfit wrote, `.scatterfit-written.json`.)
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .map(|e| e.path().to_string_lossy().into_owned())
        .filter(|p| p.ends_with(".json"))
        .collect();
    v.sort();
    v
}

#[test]
fn table_shards_combine_to_the_one_machine_file() {
    let d = temp_dir();
    let cwd = d.path();
    let one = table(cwd, &["--cache-dir", "c1", "-o", "one.json"]);
    assert_eq!(one.code, 0, "{}", one.stderr);
    for k in 1..=3 {
        let r = table(
            cwd,
            &["--shard", &format!("{k}/3"), "--partial-dir", "parts"],
        );
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    let files = parts(&cwd.join("parts"));
    assert_eq!(files.len(), 3);
    assert!(files[2].ends_with("-0003-of-0003.json"), "{files:?}");
    // Combined in another order than 1, 2, 3.
    let r = run(
        cwd,
        &[
            "combine",
            &files[2],
            &files[0],
            &files[1],
            "-o",
            "merged.json",
            "--cache-dir",
            "c2",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        std::fs::read(cwd.join("one.json")).unwrap()
            == std::fs::read(cwd.join("merged.json")).unwrap(),
        "the combined table differs from the one-machine table"
    );
    // The cache holds the same table as a one-machine build would have put there.
    let cached = |c: &str| {
        let dir = cwd.join(c);
        let f = std::fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .next()
            .unwrap()
            .path();
        std::fs::read(f).unwrap()
    };
    assert!(cached("c1") == cached("c2"));

    // A shard already done is not redone (a resubmitted array).
    let before = std::fs::metadata(&files[1]).unwrap().modified().unwrap();
    let again = run(
        cwd,
        &[
            "table",
            "--eta",
            "1.3",
            "--albedos",
            "8",
            "--photons",
            "5000",
            "--shard",
            "2/3",
            "--partial-dir",
            "parts",
        ],
    );
    assert_eq!(again.code, 0, "{}", again.stderr);
    assert!(
        again.stderr.contains("matches; nothing to do"),
        "{}",
        again.stderr
    );
    assert_eq!(
        std::fs::metadata(&files[1]).unwrap().modified().unwrap(),
        before
    );

    // Missing: named by the file the shard would write.
    let r = run(cwd, &["combine", &files[0], &files[1], "-o", "x.json"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("1 of 3 shards missing") && r.stderr.contains("-0003-of-0003.json"),
        "{}",
        r.stderr
    );
    // Duplicated: both files named.
    let r = run(
        cwd,
        &["combine", &files[0], &files[1], &files[1], "-o", "x.json"],
    );
    assert_eq!(r.code, 2);
    assert!(
        r.stderr.contains("shard 2/3 is given twice"),
        "{}",
        r.stderr
    );
    // Foreign: a shard of another table (other photons) among these.
    let r = run(
        cwd,
        &[
            "table",
            "--eta",
            "1.3",
            "--albedos",
            "8",
            "--photons",
            "6000",
            "--shard",
            "3/3",
            "--partial-dir",
            "other",
            "--quiet",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let foreign = &parts(&cwd.join("other"))[0];
    let r = run(
        cwd,
        &["combine", &files[0], &files[1], foreign, "-o", "x.json"],
    );
    assert_eq!(r.code, 2);
    assert!(
        r.stderr.contains("foreign shard") && r.stderr.contains(foreign.as_str()),
        "{}",
        r.stderr
    );
    assert!(!cwd.join("x.json").exists());
    // Bad shards are refused before any work.
    for bad in ["0/3", "4/3", "3"] {
        let r = table(cwd, &["--shard", bad, "--partial-dir", "parts"]);
        assert_eq!(r.code, 2, "{bad}: {}", r.stderr);
    }
    let r = table(cwd, &["--shard", "1/3"]);
    assert_eq!(r.code, 2);
    assert!(r.stderr.contains("--partial-dir"), "{}", r.stderr);
}

#[test]
fn slurm_script_has_the_array_and_the_dependent_combine() {
    let d = temp_dir();
    let cwd = d.path();
    let r = run(
        cwd,
        &[
            "slurm",
            "table",
            "--eta",
            "1.3",
            "--g",
            "0.9",
            "--photons",
            "2e5",
            "-o",
            "t.json",
            "--partial-dir",
            "parts",
            "--array",
            "8",
            "--script",
            "run.sh",
            "--time",
            "1:00:00",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let s = std::fs::read_to_string(cwd.join("run.sh")).unwrap();
    for want in [
        "#SBATCH --array=1-8",
        "--dependency=afterok:\"$array\"",
        "--shard \"${SLURM_ARRAY_TASK_ID}/8\"",
        " combine ",
        "-o t.json",
        "#SBATCH --time=1:00:00",
        "--partial-dir parts",
    ] {
        assert!(s.contains(want), "the script lacks {want:?}:\n{s}");
    }
    // The array tasks do not write the table, nor take slurm's own flags.
    let array_line = s.lines().find(|l| l.contains("--shard")).unwrap();
    assert!(!array_line.contains("t.json") && !array_line.contains("--array"));
    let sh = std::process::Command::new("bash")
        .arg("-n")
        .arg(cwd.join("run.sh"))
        .output()
        .unwrap();
    assert!(
        sh.status.success(),
        "{}",
        String::from_utf8_lossy(&sh.stderr)
    );
    // Without --partial-dir, or with --shard: refused.
    let r = run(
        cwd,
        &[
            "slurm", "table", "--eta", "1.3", "-o", "t.json", "--array", "8", "--script", "b.sh",
        ],
    );
    assert_eq!(r.code, 2);
    assert!(r.stderr.contains("--partial-dir"), "{}", r.stderr);
}

#[test]
fn batch_shards_combine_and_reuse_matching_results() {
    let d = temp_dir();
    let cwd = d.path();
    synth_quick(cwd, "pink-plastic", "one/pp");
    synth_quick(cwd, "marble", "one/marble");
    synth_quick(cwd, "sulfur", "one/sulfur");
    let copy = std::process::Command::new("cp")
        .args(["-r", "one", "sharded"])
        .current_dir(cwd)
        .status()
        .unwrap();
    assert!(copy.success());
    let samples = |root: &str| -> Vec<String> {
        ["marble", "pp", "sulfur"]
            .iter()
            .map(|s| format!("{root}/{s}"))
            .collect()
    };
    let mut args = vec!["batch".to_owned()];
    args.extend(samples("one"));
    args.extend(["-o".into(), "out-one".into(), "--quiet".into()]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let first = run_cached(cwd, &a);
    assert!(first.code == 0 || first.code == 1, "{}", first.stderr);
    // Again: nothing measured, the results reused.
    let again = run_cached(cwd, &a[..a.len() - 1]);
    assert!(
        again.stderr.contains("3 sample(s) not measured again"),
        "{}",
        again.stderr
    );
    // A changed input is measured again.
    let spectro = cwd.join("one/sulfur/spectro.csv");
    let mut text = std::fs::read_to_string(&spectro).unwrap();
    text.push('\n');
    std::fs::write(&spectro, text).unwrap();
    let changed = run_cached(cwd, &a[..a.len() - 1]);
    assert!(
        changed.stderr.contains("2 sample(s) not measured again"),
        "{}",
        changed.stderr
    );
    let mut forced: Vec<&str> = a[..a.len() - 1].to_vec();
    forced.push("--force");
    let forced = run_cached(cwd, &forced);
    assert!(
        !forced.stderr.contains("not measured again"),
        "{}",
        forced.stderr
    );

    // 2 shards, combined: the one-machine summary (the folders' names aside).
    std::fs::write(
        cwd.join("sharded/sulfur/spectro.csv"),
        std::fs::read(&spectro).unwrap(),
    )
    .unwrap();
    for k in 1..=2 {
        let mut args = vec!["batch".to_owned()];
        args.extend(samples("sharded"));
        args.extend(
            [
                "--shard",
                &format!("{k}/2"),
                "--partial-dir",
                "parts",
                "--quiet",
            ]
            .map(String::from),
        );
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let r = run_cached(cwd, &a);
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    let files = parts(&cwd.join("parts"));
    assert_eq!(files.len(), 2);
    let r = run(cwd, &["combine", &files[1], &files[0], "-o", "out-sharded"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    for f in ["summary.csv", "summary.md"] {
        let one = without_fit_time(&std::fs::read_to_string(cwd.join("out-one").join(f)).unwrap())
            .replace("one/", "X/");
        let sharded =
            without_fit_time(&std::fs::read_to_string(cwd.join("out-sharded").join(f)).unwrap())
                .replace("sharded/", "X/");
        assert_eq!(one, sharded, "{f}");
    }
}

/// Table 1 without its fitting-time column (a wall-clock measurement, different on every run):
/// `fit_time_s` in the CSV, "Fitting time" in the Markdown.
fn without_fit_time(text: &str) -> String {
    let header = text.lines().next().unwrap_or_default();
    if let Some(col) = header.split(',').position(|h| h == "fit_time_s") {
        return text
            .lines()
            .map(|l| {
                let mut cells: Vec<&str> = l.split(',').collect();
                if cells.len() > col {
                    cells.remove(col);
                }
                cells.join(",") + "\n"
            })
            .collect();
    }
    text.lines()
        .map(|l| {
            let mut cells: Vec<&str> = l.split('|').collect();
            // "| Material | Color | σ′s | σa | η | α′ | Fitting time [µs] | MSE |": cell 7.
            if cells.len() > 8 {
                cells.remove(7);
            }
            cells.join("|") + "\n"
        })
        .collect()
}

/// A study in 2 shards (one sample each), combined: the one-machine study's rows, study.csv and
/// study.md byte for byte.
#[test]
fn study_shards_combine_to_the_one_machine_rows() {
    let d = temp_dir();
    let cwd = d.path();
    let grid = [
        "study",
        "--quick",
        "--no-pbd",
        "--etas",
        "1.4",
        "--albedos",
        "0.5,0.9,0.99,0.999",
        "--quiet",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        grid.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let run_args = |a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        run_cached(cwd, &a)
    };
    let one = run_args(with(&["-o", "one"]));
    assert!(one.code == 0 || one.code == 1, "{}", one.stderr);
    for k in 1..=2 {
        let r = run_args(with(&[
            "-o",
            "sharded",
            "--shard",
            &format!("{k}/2"),
            "--partial-dir",
            "parts",
        ]));
        assert_eq!(r.code, 0, "{}", r.stderr);
    }
    let files = parts(&cwd.join("parts"));
    assert_eq!(files.len(), 2);
    assert!(files[0].contains("study-"), "{files:?}");
    let r = run(cwd, &["combine", &files[1], &files[0], "-o", "sharded"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    for f in ["study.csv", "study.md"] {
        let a = std::fs::read_to_string(cwd.join("one").join(f)).unwrap();
        let b = std::fs::read_to_string(cwd.join("sharded").join(f)).unwrap();
        assert_eq!(a, b, "{f}");
    }
}
