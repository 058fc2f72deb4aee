//! Image files, brackets and the imaging CSVs: round trips and every refusal, on files written to a
//! temporary folder by independent encoders (the `image` crate, a hand-made EXIF segment).

use std::path::{Path, PathBuf};

use scatterfit_imaging::ImageBuf;
use scatterfit_io::bracket::{BracketError, exif_exposure_time, read_bracket, read_exposures_csv};
use scatterfit_io::image_files::{
    CameraFrame, ImageFileError, read_camera_frame, read_radiance, write_radiance,
};
use scatterfit_io::profile_csv::{
    ProfileColumn, ProfileTable, read_profile_csv, write_profile_csv,
};
use scatterfit_io::response_csv::{
    ResponseCsvError, ResponseTable, read_response_csv, write_response_csv,
};

/// A radiance map spanning 6 decades with negative and zero samples too (an EXR must keep them).
fn radiance(width: usize, height: usize, channels: usize) -> ImageBuf<f32> {
    let data = (0..width * height * channels)
        .map(|i| {
            let t = i as f32 / (width * height * channels) as f32;
            if i == 5 {
                0.0
            } else if i == 7 {
                -0.25
            } else {
                10f32.powf(-3.0 + 6.0 * t) * (1.0 + 0.1 * (i % 3) as f32)
            }
        })
        .collect();
    ImageBuf::new(width, height, channels, data).unwrap()
}

#[test]
fn exr_round_trip_is_exact_for_rgb_and_grey() {
    let dir = tempfile::tempdir().unwrap();
    for channels in [3, 1] {
        let image = radiance(37, 21, channels);
        let path = dir.path().join(format!("map{channels}.exr"));
        write_radiance(&path, &image).unwrap();
        let back = read_radiance(&path).unwrap();
        assert_eq!(
            back, image,
            "EXR stores f32 losslessly ({channels} channels)"
        );
    }
}

#[test]
fn exr_written_by_the_image_crate_is_read() {
    // An independent writer: the `image` crate's own EXR encoder (RGBA f32).
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.exr");
    let (w, h) = (5u32, 4u32);
    let data: Vec<f32> = (0..w * h * 4)
        .map(|i| if i % 4 == 3 { 1.0 } else { i as f32 * 0.5 })
        .collect();
    image::Rgba32FImage::from_raw(w, h, data.clone())
        .unwrap()
        .save(&path)
        .unwrap();
    let back = read_radiance(&path).unwrap();
    assert_eq!((back.width(), back.height(), back.channels()), (5, 4, 3));
    let expected: Vec<f32> = data.chunks(4).flat_map(|p| p[..3].to_vec()).collect();
    assert_eq!(back.data(), &expected[..]);
}

#[test]
fn hdr_round_trip_keeps_rgbe_precision() {
    let dir = tempfile::tempdir().unwrap();
    let image = radiance(16, 9, 3);
    let path = dir.path().join("map.hdr");
    write_radiance(&path, &image).unwrap();
    let back = read_radiance(&path).unwrap();
    assert_eq!((back.width(), back.height(), back.channels()), (16, 9, 3));
    for (i, (a, b)) in image.data().iter().zip(back.data()).enumerate() {
        // RGBE shares one exponent per pixel: each sample keeps 8 bits relative to the pixel's
        // largest sample (and negatives clamp to 0).
        let px = &image.data()[i / 3 * 3..i / 3 * 3 + 3];
        let max = px.iter().fold(0f32, |m, v| m.max(*v));
        assert!(
            (a.max(0.0) - b).abs() <= max / 128.0,
            "sample {i}: wrote {a}, read {b}"
        );
    }
}

#[test]
fn radiance_refusals_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("frame.png");
    image::GrayImage::from_raw(2, 2, vec![1, 2, 3, 4])
        .unwrap()
        .save(&png)
        .unwrap();
    let err = read_radiance(&png).unwrap_err();
    assert!(matches!(err, ImageFileError::Unsupported { .. }));
    assert!(err.to_string().contains("frame.png") && err.to_string().contains("scatterfit merge"));
    let err = write_radiance(&dir.path().join("out.png"), &radiance(2, 2, 3)).unwrap_err();
    assert!(err.to_string().contains(".exr"), "{err}");
    assert!(!dir.path().join("out.png").exists());
}

fn save_rgb8(path: &Path, w: u32, h: u32, data: Vec<u8>) {
    image::RgbImage::from_raw(w, h, data)
        .unwrap()
        .save(path)
        .unwrap();
}

#[test]
fn camera_frames_keep_bit_depth_and_drop_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (4u32, 3u32);
    let rgb8: Vec<u8> = (0..w * h * 3).map(|i| (i * 7 % 256) as u8).collect();
    let rgba8: Vec<u8> = rgb8
        .chunks(3)
        .flat_map(|p| [p[0], p[1], p[2], 200])
        .collect();
    let grey16: Vec<u16> = (0..w * h).map(|i| (i * 5000) as u16).collect();
    let rgb16: Vec<u16> = (0..w * h * 3).map(|i| (i * 1777) as u16).collect();

    save_rgb8(&dir.path().join("a.png"), w, h, rgb8.clone());
    image::RgbaImage::from_raw(w, h, rgba8)
        .unwrap()
        .save(dir.path().join("b.png"))
        .unwrap();
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, grey16.clone())
        .unwrap()
        .save(dir.path().join("c.tif"))
        .unwrap();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, rgb16.clone())
        .unwrap()
        .save(dir.path().join("d.png"))
        .unwrap();
    save_rgb8(&dir.path().join("e.tiff"), w, h, rgb8.clone());

    let a = read_camera_frame(&dir.path().join("a.png")).unwrap();
    assert_eq!(
        a.frame,
        CameraFrame::U8(ImageBuf::new(4, 3, 3, rgb8.clone()).unwrap())
    );
    assert!(!a.dropped_alpha);
    let b = read_camera_frame(&dir.path().join("b.png")).unwrap();
    assert_eq!(b.frame, a.frame, "alpha dropped, colour kept");
    assert!(b.dropped_alpha);
    let c = read_camera_frame(&dir.path().join("c.tif")).unwrap();
    assert_eq!(
        c.frame,
        CameraFrame::U16(ImageBuf::new(4, 3, 1, grey16).unwrap())
    );
    let d = read_camera_frame(&dir.path().join("d.png")).unwrap();
    assert_eq!(
        d.frame,
        CameraFrame::U16(ImageBuf::new(4, 3, 3, rgb16).unwrap())
    );
    let e = read_camera_frame(&dir.path().join("e.tiff")).unwrap();
    assert_eq!(e.frame, a.frame);
}

#[test]
fn jpeg_frames_decode_close_to_what_was_encoded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flat.jpg");
    save_rgb8(&path, 16, 16, [90u8, 140, 200].repeat(256));
    let frame = read_camera_frame(&path).unwrap().frame;
    let CameraFrame::U8(buf) = frame else {
        panic!("JPEG is 8-bit")
    };
    assert_eq!((buf.width(), buf.height(), buf.channels()), (16, 16, 3));
    for px in buf.data().chunks(3) {
        for (got, want) in px.iter().zip([90u8, 140, 200]) {
            assert!(got.abs_diff(want) <= 3, "{px:?}");
        }
    }
}

#[test]
fn unreadable_and_corrupt_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.png");
    let err = read_camera_frame(&missing).unwrap_err();
    assert!(matches!(err, ImageFileError::Read { .. }) && err.to_string().contains("nope.png"));
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"\x89PNG\r\n\x1a\nthis is not really a png").unwrap();
    let err = read_camera_frame(&junk).unwrap_err();
    assert!(
        matches!(err, ImageFileError::Decode { .. }) && err.to_string().contains("junk.png"),
        "{err}"
    );
}

/// Inserts an EXIF APP1 segment with `ExposureTime = num/den` after a JPEG's SOI marker.
fn jpeg_with_exposure(jpeg: &[u8], num: u32, den: u32) -> Vec<u8> {
    let field = exif::Field {
        tag: exif::Tag::ExposureTime,
        ifd_num: exif::In::PRIMARY,
        value: exif::Value::Rational(vec![exif::Rational { num, denom: den }]),
    };
    let mut writer = exif::experimental::Writer::new();
    writer.push_field(&field);
    let mut tiff = std::io::Cursor::new(Vec::new());
    writer.write(&mut tiff, false).unwrap();
    let tiff = tiff.into_inner();
    let len = u16::try_from(2 + 6 + tiff.len()).unwrap();
    let mut out = jpeg[..2].to_vec();
    out.extend_from_slice(&[0xff, 0xe1]);
    out.extend_from_slice(&len.to_be_bytes());
    out.extend_from_slice(b"Exif\0\0");
    out.extend_from_slice(&tiff);
    out.extend_from_slice(&jpeg[2..]);
    out
}

fn write_jpeg_frames(dir: &Path, times: &[(u32, u32)]) -> Vec<PathBuf> {
    let plain = dir.join("plain.jpg");
    save_rgb8(&plain, 8, 8, vec![100; 8 * 8 * 3]);
    let jpeg = std::fs::read(&plain).unwrap();
    times
        .iter()
        .enumerate()
        .map(|(i, &(num, den))| {
            let path = dir.join(format!("exif_{i}.jpg"));
            std::fs::write(&path, jpeg_with_exposure(&jpeg, num, den)).unwrap();
            path
        })
        .collect()
}

#[test]
fn exif_exposure_times_are_read_and_sorted() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_jpeg_frames(dir.path(), &[(1, 60), (1, 600), (2, 1)]);
    let t = exif_exposure_time(&std::fs::read(&paths[1]).unwrap(), &paths[1]).unwrap();
    assert_eq!(t, 1.0 / 600.0);
    let bracket = read_bracket(&paths, None, &|_| {}).unwrap();
    assert_eq!(bracket.times_s(), vec![1.0 / 600.0, 1.0 / 60.0, 2.0]);
    assert_eq!(bracket.frames()[0].path, paths[1]);
}

#[test]
fn missing_or_zero_exif_time_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_jpeg_frames(dir.path(), &[(1, 60), (0, 1)]);
    let err = read_bracket(&paths, None, &|_| {}).unwrap_err();
    assert!(
        matches!(err, BracketError::NonPositiveTime { .. })
            && err.to_string().contains("exif_1.jpg"),
        "{err}"
    );
    let plain = vec![paths[0].clone(), dir.path().join("plain.jpg")];
    let err = read_bracket(&plain, None, &|_| {}).unwrap_err();
    assert!(matches!(err, BracketError::MissingTime { .. }), "{err}");
    assert!(
        err.to_string().contains("plain.jpg") && err.to_string().contains("--exposures"),
        "{err}"
    );
}

/// Writes `n` 6×4 RGB PNG frames and returns their names.
fn png_frames(dir: &Path, n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let name = format!("f{i}.png");
            save_rgb8(&dir.join(&name), 6, 4, vec![(10 + 40 * i) as u8; 6 * 4 * 3]);
            name
        })
        .collect()
}

#[test]
fn exposures_csv_resolves_paths_against_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("shots");
    std::fs::create_dir(&sub).unwrap();
    let names = png_frames(&sub, 3);
    let csv = sub.join("exposures.csv");
    std::fs::write(
        &csv,
        format!(
            "file,time_s\n{},1/100\n{},0.04\n\n{},1e-3\n",
            names[0], names[1], names[2]
        ),
    )
    .unwrap();
    let entries = read_exposures_csv(&csv).unwrap();
    assert_eq!(entries.len(), 3);
    assert_eq!(entries[0].path, sub.join("f0.png"));
    assert_eq!(entries[2].line, 5);
    let bracket = read_bracket(&[], Some(&csv), &|_| {}).unwrap();
    assert_eq!(bracket.times_s(), vec![1e-3, 0.01, 0.04]);
    assert_eq!(bracket.frames()[0].path, sub.join("f2.png"));
    // Each frame carries the hash of the bytes it was decoded from.
    for f in bracket.frames() {
        let bytes = std::fs::read(&f.path).unwrap();
        assert_eq!(f.sha256, scatterfit_io::digest::sha256_hex(&bytes));
    }
    assert_ne!(bracket.frames()[0].sha256, bracket.frames()[1].sha256);
    // Images named on the command line (another spelling of the same files) take their times from the CSV.
    let given = vec![
        dir.path().join("shots/./f1.png"),
        dir.path().join("shots/f0.png"),
    ];
    let bracket = read_bracket(&given, Some(&csv), &|_| {}).unwrap();
    assert_eq!(bracket.times_s(), vec![0.01, 0.04]);
}

fn bracket_error(csv_text: &str, setup: impl FnOnce(&Path)) -> String {
    let dir = tempfile::tempdir().unwrap();
    png_frames(dir.path(), 3);
    setup(dir.path());
    let csv = dir.path().join("exposures.csv");
    std::fs::write(&csv, csv_text).unwrap();
    read_bracket(&[], Some(&csv), &|_| {})
        .unwrap_err()
        .to_string()
}

#[test]
fn every_bracket_refusal_names_the_culprit() {
    let e = bracket_error("file,time_s\nf0.png,0.01\nf1.png,0\n", |_| {});
    assert!(
        e.contains("exposures.csv, line 3") && e.contains("not positive"),
        "{e}"
    );
    let e = bracket_error("file,time_s\nf0.png,0.01\nf1.png,-2\n", |_| {});
    assert!(e.contains("line 3") && e.contains("-2"), "{e}");
    let e = bracket_error("file,time_s\nf0.png,0.01\nf1.png,\n", |_| {});
    assert!(
        e.contains("line 3") && e.contains("no `time_s` for f1.png"),
        "{e}"
    );
    let e = bracket_error("file,time_s\nf0.png,0.01\nf1.png,fast\n", |_| {});
    assert!(e.contains("line 3") && e.contains("not a number"), "{e}");
    // A header without any of our columns is not echoed (the content rule: the file may not be an
    // exposures CSV at all); one with some of them is.
    let e = bracket_error("name,seconds\nf0.png,0.01\n", |_| {});
    assert!(
        e.contains("`file` and `time_s`") && e.contains("2 field(s)") && !e.contains("seconds"),
        "{e}"
    );
    let e = bracket_error("file,seconds\nf0.png,0.01\n", |_| {});
    assert!(e.contains("file,seconds"), "{e}");
    let e = bracket_error(
        "file,time_s\nf0.png,0.01\nf1.png,0.02\nf2.png,0.01\n",
        |_| {},
    );
    assert!(
        e.contains("f0.png") && e.contains("f2.png") && e.contains("same exposure time"),
        "{e}"
    );
    let e = bracket_error("file,time_s\nf0.png,0.01\n", |_| {});
    assert!(e.contains("at least 2 images, got 1"), "{e}");
    let e = bracket_error("file,time_s\nf0.png,0.01\nf0.png,0.02\n", |_| {});
    assert!(e.contains("f0.png is listed twice"), "{e}");
    let e = bracket_error("file,time_s\nf0.png,0.01\ngone.png,0.02\n", |_| {});
    assert!(e.contains("gone.png") && e.contains("cannot read"), "{e}");
    // Different size.
    let e = bracket_error("file,time_s\nf0.png,0.01\nbig.png,0.02\n", |d| {
        save_rgb8(&d.join("big.png"), 7, 4, vec![0; 7 * 4 * 3])
    });
    assert!(
        e.contains("big.png is 7×4 RGB 8-bit") && e.contains("6×4 RGB 8-bit"),
        "{e}"
    );
    // Different channel count.
    let e = bracket_error("file,time_s\nf0.png,0.01\ngrey.png,0.02\n", |d| {
        image::GrayImage::from_raw(6, 4, vec![0; 24])
            .unwrap()
            .save(d.join("grey.png"))
            .unwrap();
    });
    assert!(e.contains("grey.png is 6×4 grey 8-bit"), "{e}");
    // Different bit depth.
    let e = bracket_error("file,time_s\nf0.png,0.01\ndeep.png,0.02\n", |d| {
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(6, 4, vec![0u16; 72])
            .unwrap()
            .save(d.join("deep.png"))
            .unwrap();
    });
    assert!(e.contains("deep.png is 6×4 RGB 16-bit"), "{e}");
}

#[test]
fn an_image_missing_from_the_csv_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let names = png_frames(dir.path(), 3);
    let csv = dir.path().join("exposures.csv");
    std::fs::write(
        &csv,
        format!("file,time_s\n{},0.01\n{},0.02\n", names[0], names[1]),
    )
    .unwrap();
    let images: Vec<PathBuf> = names.iter().map(|n| dir.path().join(n)).collect();
    let err = read_bracket(&images, Some(&csv), &|_| {}).unwrap_err();
    assert!(matches!(err, BracketError::MissingTime { .. }));
    assert!(
        err.to_string().contains("f2.png") && err.to_string().contains("not listed"),
        "{err}"
    );
}

#[test]
fn response_csv_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let g: Vec<Vec<f64>> = (0..3)
        .map(|c| {
            (0..256)
                .map(|z| 2.2 * ((z as f64 + 0.5) / 128.5).ln() + 0.01 * c as f64)
                .collect()
        })
        .collect();
    let table = ResponseTable { g };
    let path = dir.path().join("response.csv");
    write_response_csv(&path, &table).unwrap();
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .starts_with("z,g_r,g_g,g_b\n0,")
    );
    assert_eq!(read_response_csv(&path).unwrap(), table);
    let grey = ResponseTable {
        g: vec![vec![-1.0, 0.0, 0.5]],
    };
    write_response_csv(&path, &grey).unwrap();
    assert_eq!(read_response_csv(&path).unwrap(), grey);
}

#[test]
fn response_csv_refusals_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.csv");
    std::fs::write(&path, "z,g_r,g_g,g_b\n0,1,1,1\n2,1,1,1\n").unwrap();
    let e = read_response_csv(&path).unwrap_err().to_string();
    assert!(e.contains("line 3") && e.contains("expected 1"), "{e}");
    std::fs::write(&path, "z,g_r,g_g,g_b\n0,1,1,1\n1,1,NaN,1\n").unwrap();
    let e = read_response_csv(&path).unwrap_err().to_string();
    assert!(e.contains("line 3") && e.contains("g_g"), "{e}");
    std::fs::write(&path, "z,red\n0,1\n").unwrap();
    assert!(matches!(
        read_response_csv(&path).unwrap_err(),
        ResponseCsvError::Header { .. }
    ));
}

#[test]
fn profile_csv_round_trip_keeps_empty_rings() {
    let dir = tempfile::tempdir().unwrap();
    let column = |name: &str, k: f64| ProfileColumn {
        name: name.into(),
        value: vec![k * 1.5, k * 0.25, f64::NAN],
        stderr: vec![0.01, 0.002, f64::NAN],
        count: vec![8, 16, 0],
        limit: vec![],
    };
    let table = ProfileTable {
        r_mm: vec![0.05, 0.15, 0.25],
        r_px: vec![0.5, 1.5, 2.5],
        channels: vec![column("r", 1.0), column("g", 2.0), column("b", 3.0)],
    };
    let path = dir.path().join("profile.csv");
    write_profile_csv(&path, &table).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("r_mm,r_px,value_r,stderr_r,count_r,value_g"),
        "{text}"
    );
    assert!(text.lines().nth(3).unwrap().ends_with(",,,0"), "{text}");
    let back = read_profile_csv(&path).unwrap();
    assert_eq!(back.r_mm, table.r_mm);
    assert_eq!(back.channels[1].value[..2], table.channels[1].value[..2]);
    assert!(back.channels[2].value[2].is_nan());
    assert_eq!(back.channels[2].count, vec![8, 16, 0]);
    assert!(
        back.channels[0].limit.is_empty(),
        "no limit column was written"
    );
    // With detection limits: a `limit_<c>` column that reads back exactly.
    let mut with_limit = table.clone();
    for c in &mut with_limit.channels {
        c.limit = vec![1e-3, 1e-3, 1e-3];
    }
    write_profile_csv(&path, &with_limit).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("r_mm,r_px,value_r,stderr_r,count_r,limit_r,value_g"),
        "{text}"
    );
    assert_eq!(
        read_profile_csv(&path).unwrap().channels[2].limit,
        vec![1e-3; 3]
    );
}

/// Regression: two runs on the same inputs wrote EXR files that differed byte-wise (RLE tiles in
/// completion order). Now two writes of the same map are identical, and the map reads back exactly.
#[test]
fn exr_output_is_byte_reproducible_and_lossless() {
    let dir = tempfile::tempdir().unwrap();
    let image = radiance(301, 203, 3);
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    write_radiance(&a, &image).unwrap();
    write_radiance(&b, &image).unwrap();
    let (ba, bb) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(ba == bb, "two writes of the same map differ");
    assert_eq!(read_radiance(&a).unwrap(), image);
    // Uncompressed scan lines: 4 bytes per sample plus the header and the line offsets (8 bytes
    // per scan line), nothing more; the first line's offset points past the header and the table.
    let samples = 301 * 203 * 3 * 4;
    assert!(
        ba.len() >= samples && ba.len() < samples + 203 * (8 + 8) + 1024,
        "{} bytes for {samples} bytes of samples",
        ba.len()
    );
    // Bit for bit, NaN and signed zero included: the file holds the samples as they are.
    let mut odd = radiance(7, 5, 1);
    let d = odd.data_mut();
    (d[0], d[1], d[2]) = (f32::NAN, -0.0, f32::MIN_POSITIVE / 2.0);
    write_radiance(&a, &odd).unwrap();
    let back = read_radiance(&a).unwrap();
    assert!(
        back.data()
            .iter()
            .zip(odd.data())
            .all(|(x, y)| x.to_bits() == y.to_bits()),
        "{:?}",
        &back.data()[..3]
    );
}

/// A 12-MP noisy radiance map (a spot falling off over 5 decades, 2 % multiplicative noise): EXR
/// size and write time uncompressed (as written now), for PIZ in scan lines (before), RLE tiles
/// (before that), ZIP and others, and the sizes the choice rests on checked. A measurement of seconds, run by hand:
/// `cargo test --release -p scatterfit-io --test suite -- --ignored --nocapture images::exr_size`.
#[test]
#[ignore = "a measurement (12 MP, seconds): run by hand"]
fn exr_size_12_mp() {
    use exr::prelude::*;
    let (w, h) = (4240usize, 2832usize);
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let r = ((x as f64 - 2120.0).powi(2) + (y as f64 - 1416.0).powi(2)).sqrt();
            for c in 0..3 {
                let v = 1e3 * (-r / (200.0 + 60.0 * c as f64)).exp() + 1e-2;
                data.push((v * (1.0 + 0.04 * noise())) as f32);
            }
        }
    }
    let image = ImageBuf::new(w, h, 3, data).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zip.exr");
    let t = std::time::Instant::now();
    write_radiance(&path, &image).unwrap();
    let zip_s = t.elapsed().as_secs_f64();
    let zip = std::fs::metadata(&path).unwrap().len();
    let t = std::time::Instant::now();
    let back = read_radiance(&path).unwrap();
    let read_s = t.elapsed().as_secs_f64();
    assert_eq!(back, image);
    eprintln!(
        "12 MP RGB f32 ({} MB raw): as written (uncompressed) {:.1} MB in {zip_s:.2} s, read {read_s:.2} s",
        w * h * 12 / 1_000_000,
        zip as f64 / 1e6
    );
    let mut sizes = Vec::new();
    for (name, encoding) in [
        ("RLE tiles (former)", Encoding::FAST_LOSSLESS),
        ("ZIP scan lines, increasing", Encoding::SMALL_LOSSLESS),
        ("PIZ tiles (unordered)", Encoding::SMALL_FAST_LOSSLESS),
        (
            "PIZ scan lines, increasing",
            Encoding {
                compression: Compression::PIZ,
                blocks: Blocks::ScanLines,
                line_order: LineOrder::Increasing,
            },
        ),
        ("uncompressed", Encoding::UNCOMPRESSED),
    ] {
        let (bytes, secs) = encode_exr(&image, encoding);
        eprintln!(
            "  {name}: {:.1} MB in {secs:.2} s",
            bytes.len() as f64 / 1e6
        );
        sizes.push((name, bytes.len() as f64));
    }
    // As written (uncompressed scan lines): the uncompressed encoding's size, and the lossless
    // codecs save at most a third of it on such a map (BENCHMARKS.md, "EXR output": PIZ −27 %,
    // at ten times the write time).
    let uncompressed = sizes.iter().find(|s| s.0 == "uncompressed").unwrap().1;
    let written = zip as f64;
    assert!(
        (written - uncompressed).abs() <= 0.01 * uncompressed,
        "as written {written:.3e} B against {uncompressed:.3e} uncompressed"
    );
    for (name, size) in &sizes {
        assert!(
            *size >= 0.6 * uncompressed,
            "{name} {size:.3e} B against {uncompressed:.3e} uncompressed"
        );
    }
}

/// Size and write time of each lossless encoding the exr crate writes (scan lines, increasing
/// order) for real merged maps: the EXR files listed in `SCATTERFIT_EXR_MAPS` (separated by `:`),
/// each written three times per encoding (the fastest time printed) and read back exactly. A
/// measurement, run by hand (BENCHMARKS.md, "EXR output"):
/// `SCATTERFIT_EXR_MAPS=a.exr:b.exr cargo test --release -p scatterfit-io --test suite -- --ignored
/// --nocapture images::exr_encodings_of_maps`.
#[test]
#[ignore = "a measurement on maps named in SCATTERFIT_EXR_MAPS: run by hand"]
fn exr_encodings_of_maps() {
    use exr::prelude::*;
    let Some(list) = std::env::var_os("SCATTERFIT_EXR_MAPS") else {
        eprintln!("SCATTERFIT_EXR_MAPS is not set: nothing measured");
        return;
    };
    for path in std::env::split_paths(&list) {
        let image = read_radiance(&path).unwrap();
        let (w, h, n) = (image.width(), image.height(), image.channels());
        eprintln!(
            "{}: {w} × {h} × {n} f32 ({:.2} MB of samples)",
            path.display(),
            (w * h * n * 4) as f64 / 1e6
        );
        for (name, compression) in [
            ("uncompressed", Compression::Uncompressed),
            ("RLE", Compression::RLE),
            ("ZIPS (1 line)", Compression::ZIP1),
            ("ZIP (16 lines)", Compression::ZIP16),
            ("PIZ (32 lines)", Compression::PIZ),
        ] {
            let encoding = Encoding {
                compression,
                blocks: Blocks::ScanLines,
                line_order: LineOrder::Increasing,
            };
            let (mut best, mut bytes) = (f64::INFINITY, Vec::new());
            for _ in 0..3 {
                let (b, secs) = encode_exr(&image, encoding);
                best = best.min(secs);
                bytes = b;
            }
            let dir = tempfile::tempdir().unwrap();
            let back_path = dir.path().join("back.exr");
            std::fs::write(&back_path, &bytes).unwrap();
            let back = read_radiance(&back_path).unwrap();
            assert!(
                back.data()
                    .iter()
                    .zip(image.data())
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{name}: not lossless"
            );
            eprintln!(
                "  {name}: {:.2} MB ({:.0} % of the samples) in {:.3} s",
                bytes.len() as f64 / 1e6,
                100.0 * bytes.len() as f64 / (w * h * n * 4) as f64,
                best
            );
        }
    }
}

/// `image` (grey or RGB f32) written as a one-layer EXR with `encoding`, in memory: the bytes and
/// the seconds the write took (the measurements below compare encodings the exr crate writes).
fn encode_exr(image: &ImageBuf<f32>, encoding: exr::prelude::Encoding) -> (Vec<u8>, f64) {
    use exr::prelude::*;
    let (w, h, n) = (image.width(), image.height(), image.channels());
    let plane =
        |c: usize| -> Vec<f32> { image.data().iter().skip(c).step_by(n).copied().collect() };
    let names: &[&str] = if n == 1 { &["Y"] } else { &["R", "G", "B"] };
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = names
        .iter()
        .enumerate()
        .map(|(c, name)| AnyChannel::new(*name, FlatSamples::F32(plane(c))))
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("radiance"),
        encoding,
        AnyChannels::sort(list),
    );
    let mut out = std::io::Cursor::new(Vec::new());
    let t = std::time::Instant::now();
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .unwrap();
    (out.into_inner(), t.elapsed().as_secs_f64())
}
