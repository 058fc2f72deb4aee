//! `result.json`'s `inputs` record the SHA-256 of the bytes the measurement read: a file replaced
//! after the measurement (a rig re-exporting a frame, a colleague editing the manifest) must not
//! change the hashes of a result made afterwards, nor its paths or order.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;

use scatterfit_io::result_json::{FileRef, MeasurementResult};
use scatterfit_io::sample_folder::SampleFiles;
use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_synth::RigSpec;
use sha2::{Digest, Sha256};

fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Every regular file of `dir` by name, with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.file_type().unwrap().is_file())
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// `reference` is `name` with the hash of its bytes in `before`.
fn assert_recorded(reference: Option<&FileRef>, name: &str, before: &BTreeMap<String, Vec<u8>>) {
    let r = reference.unwrap_or_else(|| panic!("{name} is not recorded"));
    assert_eq!(r.path, name);
    assert_eq!(
        r.sha256,
        sha256(&before[name]),
        "{name}: not the bytes measured"
    );
}

/// Replaces `name` in `dir` with other bytes (written whole, as a re-export would).
fn replace(dir: &Path, name: &str, bytes: &[u8]) {
    let path = dir.join(name);
    assert_ne!(std::fs::read(&path).unwrap(), bytes);
    std::fs::write(path, bytes).unwrap();
}

fn results(m: &scatterfit_pipeline::Measurement) -> [MeasurementResult; 2] {
    // Twice: each call records the same inputs (the report writer and the Python binding call it
    // more than once).
    [m.to_result(Some("profile.csv")), m.to_result(None)]
}

#[test]
fn inputs_replaced_after_the_measurement_keep_the_hashes_of_the_bytes_measured() {
    let twin = common::quick_twin("pink-plastic", 1);
    let rig = RigSpec::quick();
    let top = tempfile::tempdir().unwrap();
    let bracket_dir = top.path().join("bracket");
    SampleFiles::new("hashed", &twin.reading)
        .bracket(&twin.bracket.frames, &twin.bracket.times_s)
        .mm_per_pixel(rig.mm_per_pixel)
        .spot_diameter_mm(2.0 * rig.spot_radius_mm)
        .provenance("test")
        .write(&bracket_dir)
        .unwrap();
    let before = snapshot(&bracket_dir);
    let m = measure_sample(&bracket_dir, &Overrides::default(), &|_| {}).unwrap();
    let frame_names: Vec<String> = m
        .hdr
        .frames
        .iter()
        .map(|f| f.file.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(frame_names.len() >= 2, "{frame_names:?}");

    // After the measurement: the shortest frame becomes a copy of the longest (a valid PNG of
    // other content), the spectro file and the manifest gain a line.
    let (first, last) = (&frame_names[0], frame_names.last().unwrap());
    replace(&bracket_dir, first, &before[last]);
    let mut spectro = before["spectro.csv"].clone();
    spectro.extend_from_slice(b"\n");
    replace(&bracket_dir, "spectro.csv", &spectro);
    let mut manifest = before["sample.toml"].clone();
    manifest.extend_from_slice(b"# edited after the measurement\n");
    replace(&bracket_dir, "sample.toml", &manifest);

    for r in results(&m) {
        let i = &r.inputs;
        assert_recorded(i.manifest.as_ref(), "sample.toml", &before);
        assert_recorded(i.spectro.as_ref(), "spectro.csv", &before);
        assert!(i.hdr.is_none());
        // Every frame, in the merge's order (shortest first), by its name in the folder.
        let recorded: Vec<&str> = i.frames.iter().map(|f| f.path.as_str()).collect();
        assert_eq!(recorded, frame_names);
        for f in &i.frames {
            assert_recorded(Some(f), &f.path, &before);
        }
        assert_ne!(i.frames[0].sha256, sha256(&before[last]));
    }

    // A merged radiance map (`camera.hdr`) instead of a bracket, replaced after the measurement.
    let map_dir = top.path().join("map");
    std::fs::create_dir(&map_dir).unwrap();
    std::fs::write(map_dir.join("spectro.csv"), &before["spectro.csv"]).unwrap();
    scatterfit_io::image_files::write_radiance(&map_dir.join("radiance.exr"), &m.hdr.hdr.radiance)
        .unwrap();
    std::fs::write(
        map_dir.join("sample.toml"),
        format!(
            "name = \"hashed map\"\n[spectro]\nfile = \"spectro.csv\"\n[camera]\nhdr = \
             \"radiance.exr\"\nmm_per_pixel = {}\nspot_diameter_mm = {}\n",
            rig.mm_per_pixel,
            2.0 * rig.spot_radius_mm
        ),
    )
    .unwrap();
    let before = snapshot(&map_dir);
    let m = measure_sample(&map_dir, &Overrides::default(), &|_| {}).unwrap();
    let mut dimmer = m.hdr.hdr.radiance.clone();
    dimmer.data_mut().iter_mut().for_each(|v| *v *= 0.5);
    scatterfit_io::image_files::write_radiance(&map_dir.join("radiance.exr"), &dimmer).unwrap();
    assert_ne!(
        std::fs::read(map_dir.join("radiance.exr")).unwrap(),
        before["radiance.exr"]
    );
    for r in results(&m) {
        let i = &r.inputs;
        assert_recorded(i.manifest.as_ref(), "sample.toml", &before);
        assert_recorded(i.spectro.as_ref(), "spectro.csv", &before);
        assert_recorded(i.hdr.as_ref(), "radiance.exr", &before);
        assert!(i.frames.is_empty());
    }

    // A manifest given as a file of another name is recorded under that name.
    std::fs::write(map_dir.join("other.toml"), &before["sample.toml"]).unwrap();
    let before = snapshot(&map_dir);
    let m = measure_sample(&map_dir.join("other.toml"), &Overrides::default(), &|_| {}).unwrap();
    assert_recorded(
        m.to_result(None).inputs.manifest.as_ref(),
        "other.toml",
        &before,
    );
}
