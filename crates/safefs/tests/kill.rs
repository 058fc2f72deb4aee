//! Fault injection: a writer killed (SIGKILL, no cleanup) in the middle of an atomic write leaves the
//! destination as it was (the old file, whole), a temporary that a later run recognises as stale and
//! removes, and nothing a reader could mistake for the new file.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use scatterfit_safefs::write::{
    TEMP_PREFIX, check_can_write_in, is_temporary_name, remove_stale_temporaries, write_atomic,
    write_atomic_with,
};

const CHILD_ENV: &str = "SCATTERFIT_SAFEFS_KILL_CHILD";

fn temporaries(dir: &Path) -> Vec<PathBuf> {
    fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| is_temporary_name(&e.file_name()))
        .map(|e| e.path())
        .collect()
}

/// The child's part: write half of a large file, say so, and wait to be killed.
#[test]
fn child_writer() {
    let Some(dir) = std::env::var_os(CHILD_ENV) else {
        return;
    };
    let dir = PathBuf::from(dir);
    let _ = write_atomic_with(&dir.join("result.json"), |w| {
        w.write_all(&[b'n'; 1 << 20])?;
        w.flush()?;
        fs::write(dir.join("ready"), b"")?;
        std::thread::sleep(Duration::from_secs(60));
        Ok(())
    });
}

#[test]
fn a_writer_killed_mid_write_leaves_the_old_file_and_a_sweepable_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let target = d.join("result.json");
    write_atomic(&target, b"old, complete").unwrap();
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "child_writer", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, d)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t = Instant::now();
    while !d.join("ready").exists() {
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "the child never wrote"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    // While the child is alive, its temporary is locked: a sweep (even with no age limit) keeps it.
    let tmps = temporaries(d);
    assert_eq!(tmps.len(), 1, "{tmps:?}");
    assert!(
        remove_stale_temporaries(d, Duration::ZERO)
            .unwrap()
            .is_empty()
    );
    child.kill().unwrap(); // SIGKILL: no handler, no cleanup
    child.wait().unwrap();
    assert_eq!(fs::read(&target).unwrap(), b"old, complete");
    let left = temporaries(d);
    assert_eq!(left, tmps, "the killed writer's temporary is left");
    assert!(
        left[0]
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with(TEMP_PREFIX)
    );
    // A later run: too young to be swept by the default rule…
    check_can_write_in(d).unwrap();
    assert_eq!(temporaries(d), left);
    // …and swept once it is old (its lock is free now that its writer is dead).
    let f = fs::OpenOptions::new().write(true).open(&left[0]).unwrap();
    f.set_modified(std::time::SystemTime::now() - Duration::from_secs(3600))
        .unwrap();
    drop(f);
    assert_eq!(
        remove_stale_temporaries(d, scatterfit_safefs::write::STALE_AFTER).unwrap(),
        left
    );
    assert!(temporaries(d).is_empty());
    assert_eq!(fs::read(&target).unwrap(), b"old, complete");
}
