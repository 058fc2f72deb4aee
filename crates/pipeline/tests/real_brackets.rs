//! Brackets photographed by real cameras (scanned film, phones, compacts, DSLRs; PNG and JPEG):
//! every good one merges with the default settings, and one whose times truly disagree with its
//! frames is still refused.
//!
//! Two places hold brackets, each folder `NAME/` with its frames and `exposures.csv`:
//! - `data/brackets/` in this repository: always merged; each folder there has a `SOURCE.md` (where
//!   the frames came from and the licence that allows the copy; a folder without one fails the
//!   test). Its README says what may be committed;
//! - the folder named by `SCATTERFIT_REAL_BRACKETS=DIR`: a corpus kept outside the repository
//!   (sources that give no licence to copy, or copies that may not be committed; BENCHMARKS.md,
//!   "Real brackets", names them); skipped without the variable.
//!
//! A folder holding a file `EXPECT_REFUSED` is a bracket whose listed times disagree with its
//! frames (the shutter did not change): it must be refused, saying so. Every merge prints its
//! self-consistency score (`imaging::self_consistency` over a regular pixel subsample, in code
//! values, as `scatterfit merge` prints it) and its time.

use std::path::{Path, PathBuf};
use std::time::Instant;

use scatterfit_imaging::{ImageBuf, ImagingError, check_bracket_order};
use scatterfit_io::image_files::{CameraFrame, read_camera_frame};
use scatterfit_pipeline::hdr::{HdrInputs, read_and_merge};

fn brackets_in(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("exposures.csv").is_file())
        .collect();
    v.sort();
    v
}

/// The repository's root.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn committed() -> Vec<PathBuf> {
    brackets_in(&workspace().join("data/brackets"))
}

fn corpus() -> Option<PathBuf> {
    std::env::var_os("SCATTERFIT_REAL_BRACKETS").map(PathBuf::from)
}

/// Merges `dir` with the default settings; `Ok(consistency)` or the error's text.
fn merge(dir: &Path) -> Result<f64, String> {
    let inputs = HdrInputs::new(Some(dir.join("exposures.csv")), Vec::new());
    let stage = read_and_merge(&inputs, &|_| {}).map_err(|e| format!("{e:#}"))?;
    // Any static scene keeps Debevec & Malik's relation between two frames, so the far corners'
    // frame-against-frame check (made for the spot's far field) finds no light switched on here.
    let r = &stage.hdr.radiance;
    let centre = [0.5 * r.width() as f64, 0.5 * r.height() as f64];
    if let Some(fields) = scatterfit_pipeline::checks::far_field_agreement_in(&stage, centre) {
        let darkest = fields
            .iter()
            .min_by(|a, b| a.difference.total_cmp(&b.difference));
        eprintln!("  far corners, frame against frame: most below the prediction {darkest:?}");
        if let Some(f) = fields.iter().find(|f| f.disagrees()) {
            return Err(format!(
                "the far corners' check finds light switched on during the bracket: {f:?}"
            ));
        }
    }
    Ok(stage
        .corrections
        .self_consistency
        .as_ref()
        .map_or(f64::NAN, |c| c.rms))
}

#[test]
fn every_good_real_bracket_merges_and_a_wrong_one_is_refused() {
    let mut dirs = committed();
    let n_committed = dirs.len();
    if let Some(c) = corpus() {
        dirs.extend(brackets_in(&c));
    } else {
        eprintln!("SCATTERFIT_REAL_BRACKETS not set: the uncommitted corpus is skipped");
    }
    eprintln!(
        "{} brackets: {n_committed} committed, {} outside",
        dirs.len(),
        dirs.len() - n_committed
    );
    let mut failures = Vec::new();
    for (i, dir) in dirs.iter().enumerate() {
        let name = dir
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into());
        // A copy committed with the project names its source and the licence that allows it.
        if i < n_committed && !dir.join("SOURCE.md").is_file() {
            failures.push(format!(
                "{name}: no SOURCE.md (where the frames came from and the licence that allows \
                 the copy)"
            ));
        }
        let expect_refused = dir.join("EXPECT_REFUSED").is_file();
        let start = Instant::now();
        let outcome = merge(dir);
        let secs = start.elapsed().as_secs_f64();
        match (outcome, expect_refused) {
            (Ok(rms), false) => {
                eprintln!("{name}: merged, self-consistency {rms:.2} code values ({secs:.2} s)");
            }
            (Err(e), true) => {
                eprintln!("{name}: refused as expected ({secs:.2} s): {e}");
                if !(e.contains("do not brighten") || e.contains("right file for that time")) {
                    failures.push(format!("{name}: refused for another reason: {e}"));
                }
            }
            (Ok(rms), true) => failures.push(format!("{name}: merged ({rms:.2}), not refused")),
            (Err(e), false) => failures.push(format!("{name}: refused: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The memorial's frames, longest first as listed, as 8-bit buffers and times.
fn memorial() -> Option<(Vec<ImageBuf<u8>>, Vec<f64>)> {
    let dir = corpus()?.join("memorial");
    let list = scatterfit_io::bracket::read_exposures_csv(&dir.join("exposures.csv")).ok()?;
    let mut frames = Vec::new();
    let mut times = Vec::new();
    for e in list {
        match read_camera_frame(&e.path).ok()?.frame {
            CameraFrame::U8(b) => frames.push(b),
            CameraFrame::U16(_) => return None,
        }
        times.push(e.time_s);
    }
    Some((frames, times))
}

/// Debevec's memorial: its two shortest frames (1/1024 s, 1/512 s) sit on the film's pedestal
/// (mean code 19, darker in sum at 1/512 s than at 1/1024 s); they are no evidence of disorder —
/// the whole bracket passes — while a deliberately reversed pair of well-exposed frames (1/4 s and
/// 1 s swapped) is refused.
#[test]
fn the_memorials_noise_floor_is_not_evidence_and_a_reversed_pair_is() {
    let Some((frames, times)) = memorial() else {
        eprintln!("SCATTERFIT_REAL_BRACKETS/memorial not found: skipped");
        return;
    };
    check_bracket_order(&frames, &times, u8::MAX).expect("the memorial is in order");
    let mut swapped = times.clone();
    let a = times.iter().position(|&t| t == 0.25).unwrap();
    let b = times.iter().position(|&t| t == 1.0).unwrap();
    swapped.swap(a, b);
    let err = check_bracket_order(&frames, &swapped, u8::MAX).unwrap_err();
    assert!(
        matches!(err, ImagingError::BracketOutOfOrder { .. }),
        "{err:?}"
    );
}
