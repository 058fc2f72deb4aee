//! What Ctrl-C does to writes in flight (`atomic::remove_in_flight`, called by the command-line
//! tool's interrupt handler before it exits). A file of its own: the interruption is process-wide and
//! stops every later write, so no other test may share this process.

use std::path::{Path, PathBuf};
use std::sync::mpsc;

use scatterfit_io::atomic::{
    TEMP_PREFIX, in_flight, is_temporary_name, remove_in_flight, write_atomic, write_atomic_with,
};

fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| is_temporary_name(&e.file_name()))
        .map(|e| e.path())
        .collect()
}

/// A large write is interrupted half-way: its temporary file is removed at once (the writer's later
/// bytes go to the unlinked file and its rename fails), the target is never created, another
/// process's temporary (a concurrent run's) is not touched, and no write after the interruption
/// creates a file.
#[test]
fn interruption_removes_temporaries_and_stops_writes() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("big.exr");
    let theirs = dir
        .path()
        .join(format!("{TEMP_PREFIX}000000000000-mc-table.json"));
    std::fs::write(&theirs, b"another process").unwrap();

    let (started, wait_started) = mpsc::channel();
    let (resume, wait_resume) = mpsc::channel::<()>();
    let writer = {
        let target = target.clone();
        std::thread::spawn(move || {
            write_atomic_with(&target, |w| {
                w.write_all(&vec![1u8; 1 << 20])?;
                w.flush()?;
                started.send(()).unwrap();
                wait_resume.recv().unwrap();
                w.write_all(&vec![2u8; 1 << 20])
            })
        })
    };
    wait_started.recv().unwrap();
    let tmp: Vec<PathBuf> = temporaries(dir.path())
        .into_iter()
        .filter(|p| *p != theirs)
        .collect();
    assert_eq!(tmp.len(), 1, "the temporary file is being written");
    let tmp = tmp[0].clone();
    assert_eq!(in_flight(), vec![tmp.clone()]);

    let removed = remove_in_flight();
    assert_eq!(removed, vec![tmp.clone()]);
    assert!(!tmp.exists());
    assert!(
        theirs.exists(),
        "another process's temporary is not ours to remove"
    );

    resume.send(()).unwrap();
    let result = writer.join().unwrap();
    assert!(result.is_err(), "the interrupted write must not land");
    assert!(!target.exists());
    assert!(!tmp.exists());

    let later = dir.path().join("later.csv");
    let err = write_atomic(&later, b"x").unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::Interrupted);
    assert!(!later.exists());
    assert_eq!(temporaries(dir.path()), vec![theirs]);
}
