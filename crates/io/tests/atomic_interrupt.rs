//! What Ctrl-C does to writes in flight (`atomic::remove_in_flight`, called by the command-line
//! tool's interrupt handler before it exits). A file of its own: the interruption is process-wide and
//! stops every later write, so no other test may share this process.

use std::sync::mpsc;

use scatterfit_io::atomic::{
    in_flight, remove_in_flight, sweep_on_interrupt, temporary_path, write_atomic,
    write_atomic_with,
};

/// A large write is interrupted half-way: its temporary file is removed at once (the writer's later
/// bytes go to the unlinked file and its rename fails), the target is never created, this process's
/// temporaries in a swept cache folder are removed (another process's are not), and no write after
/// the interruption creates a file.
#[test]
fn interruption_removes_temporaries_and_stops_writes() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("big.exr");
    let tmp = temporary_path(&target).unwrap();
    let cache = dir.path().join("cache");
    std::fs::create_dir(&cache).unwrap();
    let ours = cache.join(format!(".mc-table.json.tmp-{}", std::process::id()));
    let theirs = cache.join(".mc-table.json.tmp-1");
    std::fs::write(&ours, b"partial").unwrap();
    std::fs::write(&theirs, b"another process").unwrap();
    sweep_on_interrupt(&cache);

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
    assert!(tmp.exists(), "the temporary file is being written");
    assert_eq!(in_flight(), vec![tmp.clone()]);

    let removed = remove_in_flight();
    assert!(removed.contains(&tmp), "{removed:?}");
    assert!(removed.contains(&ours), "{removed:?}");
    assert!(!tmp.exists() && !ours.exists());
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
    assert!(!later.exists() && !temporary_path(&later).unwrap().exists());
    let mut left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["cache"]);
}
