//! Property-based fuzzing of the image decode path (RELIABILITY.md): `decode_camera_frame_within`
//! (PNG, TIFF, JPEG) and `decode_radiance` (OpenEXR, Radiance HDR) on arbitrary bytes behind each
//! format's magic number, and on mutations of small valid files written by the `image` crate and by
//! our own EXR writer (bit flips, overwritten bytes, truncation, header sizes set to huge values).
//! Every case must give `Ok` or a typed error within a time bound, and an image whose header asks
//! for more than the memory budget must be refused before its pixels are allocated.
//!
//! CI runs [`CI_CASES`] cases per property; `PROPTEST_CASES=20000 cargo test --release -p
//! scatterfit-io --test suite fuzz_images::` runs a long campaign (RELIABILITY.md).

use std::io::Cursor;
use std::path::Path;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::{
    ImageFileError, decode_camera_frame_within, decode_radiance, write_radiance,
};

const CI_CASES: u32 = 48;
const MAGICS: &[&[u8]] = &[
    b"",
    b"\x89PNG\r\n\x1a\n",
    b"\xFF\xD8\xFF",
    b"II*\0",
    b"MM\0*",
    b"\x76\x2f\x31\x01",
    b"#?RADIANCE\n",
];
/// The budget the fuzzed decodes run under: far below what a corrupt header can ask for.
const BUDGET: u64 = 64 << 20;
const TIME_BOUND: Duration = Duration::from_secs(5);

fn config() -> ProptestConfig {
    let mut config = ProptestConfig::default();
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = CI_CASES;
    }
    config.failure_persistence = None;
    config
}

fn encode(image: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    image.write_to(&mut out, format).unwrap();
    out.into_inner()
}

/// Small valid files of every format we read.
fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let (w, h) = (13u32, 7u32);
    let rgb8 =
        image::RgbImage::from_fn(w, h, |x, y| image::Rgb([(x * 19) as u8, (y * 31) as u8, 7]));
    let grey16 = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(w, h, |x, y| {
        image::Luma([(x * 977 + y * 3) as u16])
    });
    let rgba8 = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba([x as u8, y as u8, 3, 200]));
    let hdr = image::Rgb32FImage::from_fn(w, h, |x, y| image::Rgb([x as f32 * 0.5, y as f32, 1e3]));
    let dir = tempfile::tempdir().unwrap();
    let exr_path = dir.path().join("r.exr");
    let data: Vec<f32> = (0..w * h * 3)
        .map(|i| (i as f32 * 0.37).exp2() * 1e-3)
        .collect();
    write_radiance(
        &exr_path,
        &ImageBuf::new(w as usize, h as usize, 3, data).unwrap(),
    )
    .unwrap();
    vec![
        ("png", encode(rgb8.clone().into(), image::ImageFormat::Png)),
        (
            "png16",
            encode(grey16.clone().into(), image::ImageFormat::Png),
        ),
        ("pnga", encode(rgba8.into(), image::ImageFormat::Png)),
        (
            "tiff",
            encode(rgb8.clone().into(), image::ImageFormat::Tiff),
        ),
        ("tiff16", encode(grey16.into(), image::ImageFormat::Tiff)),
        ("jpeg", encode(rgb8.into(), image::ImageFormat::Jpeg)),
        ("hdr", encode(hdr.into(), image::ImageFormat::Hdr)),
        ("exr", std::fs::read(&exr_path).unwrap()),
    ]
}

fn decode_all(bytes: &[u8]) {
    let start = Instant::now();
    let frame = decode_camera_frame_within(bytes, Path::new("f.img"), BUDGET);
    let radiance = decode_radiance(bytes, Path::new("f.img"), BUDGET);
    let elapsed = start.elapsed();
    assert!(
        elapsed < TIME_BOUND,
        "decode of {} bytes took {elapsed:?}",
        bytes.len()
    );
    // Whatever decoded fits the budget.
    if let Ok(f) = frame {
        let n = (f.frame.width() * f.frame.height() * f.frame.channels()) as u64;
        assert!(n * u64::from(f.frame.bit_depth() / 8) <= BUDGET);
    }
    if let Ok(r) = radiance {
        assert!((r.data().len() * 4) as u64 <= BUDGET);
    }
}

#[derive(Debug, Clone)]
enum Mutation {
    Flip(f64, u8),
    Set(f64, u8),
    /// Overwrite 4 bytes with 0xFF or a big-endian / little-endian large size.
    Big(f64, u32, bool),
    Truncate(f64),
    Insert(f64, Vec<u8>),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64, 0..8u8).prop_map(|(f, b)| Mutation::Flip(f, b)),
        (0.0..1.0f64, any::<u8>()).prop_map(|(f, b)| Mutation::Set(f, b)),
        (
            0.0..0.3f64,
            prop_oneof![
                Just(u32::MAX),
                Just(1 << 20),
                Just(60_000),
                Just(0),
                any::<u32>()
            ],
            any::<bool>()
        )
            .prop_map(|(f, v, be)| Mutation::Big(f, v, be)),
        (0.0..1.0f64).prop_map(Mutation::Truncate),
        (0.0..1.0f64, proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(f, b)| Mutation::Insert(f, b)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let at = |f: f64, len: usize| ((f * len as f64) as usize).min(len.saturating_sub(1));
    if bytes.is_empty() {
        return;
    }
    match m {
        Mutation::Flip(f, bit) => {
            let i = at(*f, bytes.len());
            bytes[i] ^= 1 << bit;
        }
        Mutation::Set(f, b) => {
            let i = at(*f, bytes.len());
            bytes[i] = *b;
        }
        Mutation::Big(f, v, be) => {
            let i = at(*f, bytes.len());
            let v = if *be {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            for (k, b) in v.iter().enumerate() {
                if let Some(x) = bytes.get_mut(i + k) {
                    *x = *b;
                }
            }
        }
        Mutation::Truncate(f) => bytes.truncate(at(*f, bytes.len())),
        Mutation::Insert(f, b) => {
            let i = at(*f, bytes.len());
            bytes.splice(i..i, b.iter().copied());
        }
    }
}

#[test]
fn seeds_decode() {
    for (name, bytes) in seeds() {
        let ok = if matches!(name, "hdr" | "exr") {
            decode_radiance(&bytes, Path::new("x"), BUDGET).is_ok()
        } else {
            decode_camera_frame_within(&bytes, Path::new("x"), BUDGET).is_ok()
        };
        assert!(ok, "{name}");
    }
}

proptest! {
    #![proptest_config(config())]

    /// Arbitrary bytes behind each format's magic number.
    #[test]
    fn arbitrary_bytes_never_panic(
        magic in proptest::sample::select(MAGICS),
        tail in proptest::collection::vec(any::<u8>(), 0..1024),
    ) {
        let bytes = [magic, &tail[..]].concat();
        decode_all(&bytes);
    }

    /// Mutations of valid files of every format.
    #[test]
    fn mutated_files_never_panic(
        seed in 0..8usize,
        mutations in proptest::collection::vec(mutation(), 1..5),
    ) {
        let mut bytes = seeds()[seed].1.clone();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        decode_all(&bytes);
    }
}

/// A header that announces a huge image is refused from the header, before any allocation: a PNG
/// whose IHDR says 60 000 × 60 000 RGB 16-bit (21.6 GB) and an EXR whose data window is huge.
#[test]
fn huge_headers_are_refused_before_allocation() {
    let seeds = seeds();
    let mut png = seeds[0].1.clone();
    // IHDR data starts at byte 16: width, height (big-endian), bit depth, colour type.
    png[16..20].copy_from_slice(&60_000u32.to_be_bytes());
    png[20..24].copy_from_slice(&60_000u32.to_be_bytes());
    png[24] = 16;
    let start = Instant::now();
    let err = decode_camera_frame_within(&png, Path::new("huge.png"), BUDGET).unwrap_err();
    assert!(start.elapsed() < Duration::from_secs(1));
    // The CRC of the patched chunk no longer matches; either refusal is fine, but a header
    // that checks out must hit the budget: recompute the CRC.
    let mut fixed = png.clone();
    let crc = crc32(&fixed[12..29]);
    fixed[29..33].copy_from_slice(&crc.to_be_bytes());
    let err2 = decode_camera_frame_within(&fixed, Path::new("huge.png"), BUDGET).unwrap_err();
    assert!(
        matches!(err2, ImageFileError::TooLarge { .. }),
        "{err2} (first: {err})"
    );
    let msg = err2.to_string();
    assert!(
        msg.contains("huge.png") && msg.contains("SCATTERFIT_MAX_MEMORY_MIB"),
        "{msg}"
    );

    // A real (small) EXR read with a budget smaller than it needs: refused from the header.
    let exr = &seeds[7].1;
    let err = decode_radiance(exr, Path::new("r.exr"), 100).unwrap_err();
    assert!(matches!(err, ImageFileError::TooLarge { .. }), "{err}");
}

/// CRC-32 (ISO 3309, as PNG uses), bitwise: only for patching a test header.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}
