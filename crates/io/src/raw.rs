//! Camera RAW files: DNG and the vendors' formats (CR2, CR3, NEF, ARW, RAF, ORF, RW2, PEF, …)
//! decoded by `rawler` (the library of dnglab; ARCHITECTURE.md, "io: images", says why this one),
//! and a minimal DNG writer (the rig twin's RAW brackets, written with the `tiff` crate).
//!
//! A RAW frame is linear: the sensor's values with its black level still in them and its white
//! (clip) level, both read from the file's metadata ([`RawLevels`]), and the exposure time from its
//! EXIF. A colour-filter-array mosaic is demosaiced bilinearly into RGB (each channel the mean of
//! its own sites in the 3 × 3 neighbourhood: linear, so black levels and radial averages pass
//! through it unchanged); no white balance, no colour matrix — the pipeline measures each channel
//! on its own and fits its scale.

use std::io::Cursor;
use std::path::Path;

use scatterfit_imaging::ImageBuf;

use crate::image_files::error::ImageFileError;

/// File extensions read as camera RAW (lower case).
pub const RAW_EXTENSIONS: [&str; 20] = [
    "dng", "cr2", "cr3", "crw", "nef", "nrw", "arw", "srf", "sr2", "raf", "orf", "rw2", "pef",
    "srw", "3fr", "iiq", "erf", "mos", "mrw", "kdc",
];

/// True when `path` has a RAW extension ([`RAW_EXTENSIONS`], any case).
pub fn is_raw_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| RAW_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// A RAW file's levels, from its metadata \[DN\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawLevels {
    /// The black level per channel R, G, B (the mean over the channel's CFA sites).
    pub black: [f64; 3],
    /// The white (clip) level: the smallest over the channels.
    pub white: f64,
}

/// A decoded RAW frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RawFrame {
    /// RGB, linear, black level included.
    pub rgb: ImageBuf<u16>,
    /// Black and white levels.
    pub levels: RawLevels,
    /// The exposure time from the metadata \[s\], when there is one.
    pub exposure_time_s: Option<f64>,
    /// e.g. `Canon EOS R5, RGGB mosaic, 14-bit`.
    pub description: String,
}

fn unsupported(path: &Path, detail: String) -> ImageFileError {
    ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail,
    }
}

/// Decodes a RAW file's bytes (`path` names it in messages and gives the format by extension).
///
/// # Errors
/// [`ImageFileError::Unsupported`] when the decoder cannot read the file (an unknown camera, a
/// corrupt file) or its data are not a 2 × 2 colour mosaic or linear RGB of integers; the message
/// says to convert it to DNG (Adobe DNG Converter, dnglab) or to 16-bit TIFF.
pub fn decode_raw(bytes: &[u8], path: &Path) -> Result<RawFrame, ImageFileError> {
    use rawler::decoders::RawDecodeParams;
    use rawler::rawimage::RawPhotometricInterpretation as P;
    let src = rawler::rawsource::RawSource::new_from_slice(bytes);
    let params = RawDecodeParams::default();
    let advice = "convert it to DNG (Adobe DNG Converter, dnglab) or to a linear 16-bit TIFF";
    let raw = rawler::decode(&src, &params).map_err(|e| {
        unsupported(
            path,
            format!("the RAW decoder (rawler) cannot read it ({e}); {advice}"),
        )
    })?;
    let exposure_time_s = rawler::get_decoder(&src)
        .ok()
        .and_then(|d| d.raw_metadata(&src, &params).ok())
        .and_then(|m| m.exif.exposure_time)
        .filter(|r| r.d != 0 && r.n != 0)
        .map(|r| f64::from(r.n) / f64::from(r.d));
    let (w, h, cpp) = (raw.width, raw.height, raw.cpp);
    let data = match &raw.data {
        rawler::RawImageData::Integer(v) => v,
        rawler::RawImageData::Float(_) => {
            return Err(unsupported(
                path,
                format!(
                    "its raw data are floating point, which this reader does not take; {advice}"
                ),
            ));
        }
    };
    if w == 0 || h == 0 || data.len() < w * h * cpp {
        return Err(unsupported(
            path,
            format!(
                "the decoder returned {w}×{h}×{cpp} samples but {}",
                data.len()
            ),
        ));
    }
    let whites = &raw.whitelevel.0;
    let white = whites.iter().copied().min().unwrap_or(u32::from(u16::MAX)) as f64;
    let bl = &raw.blacklevel;
    let black_at = |row: usize, col: usize, s: usize| -> f64 {
        if bl.levels.is_empty() || bl.width == 0 || bl.height == 0 {
            return 0.0;
        }
        let i = ((row % bl.height) * bl.width + col % bl.width) * bl.cpp.max(1) + s % bl.cpp.max(1);
        bl.levels.get(i).map_or(0.0, |r| f64::from(r.as_f32()))
    };
    let make = format!("{} {}", raw.clean_make, raw.clean_model);
    match (&raw.photometric, cpp) {
        (P::Cfa(cfg), 1) => {
            let cfa = &cfg.cfa;
            if cfa.width != 2 || cfa.height != 2 {
                return Err(unsupported(
                    path,
                    format!(
                        "its colour filter array is {}×{} ({}), not a 2 × 2 Bayer mosaic; {advice}",
                        cfa.width, cfa.height, cfa.name
                    ),
                ));
            }
            let colour = |r: usize, c: usize| cfa.color_at(r, c);
            if (0..2).any(|r| (0..2).any(|c| colour(r, c) > 2)) {
                return Err(unsupported(
                    path,
                    format!(
                        "its mosaic {} has colours other than R, G, B; {advice}",
                        cfa.name
                    ),
                ));
            }
            let mut black = [0.0f64; 3];
            let mut count = [0usize; 3];
            for r in 0..2 {
                for c in 0..2 {
                    black[colour(r, c)] += black_at(r, c, 0);
                    count[colour(r, c)] += 1;
                }
            }
            if count.contains(&0) {
                return Err(unsupported(
                    path,
                    format!("its mosaic {} lacks a colour; {advice}", cfa.name),
                ));
            }
            for k in 0..3 {
                black[k] /= count[k] as f64;
            }
            let rgb = demosaic_bilinear(data, w, h, &colour);
            Ok(RawFrame {
                rgb: ImageBuf::new(w, h, 3, rgb)
                    .map_err(|e| unsupported(path, format!("inconsistent image ({e})")))?,
                levels: RawLevels { black, white },
                exposure_time_s,
                description: format!("{make}, {} mosaic, {} bits", cfa.name, raw.bps),
            })
        }
        (P::LinearRaw | P::BlackIsZero, 3) => {
            let black = [0, 1, 2].map(|s| black_at(0, 0, s));
            Ok(RawFrame {
                rgb: ImageBuf::new(w, h, 3, data[..w * h * 3].to_vec())
                    .map_err(|e| unsupported(path, format!("inconsistent image ({e})")))?,
                levels: RawLevels { black, white },
                exposure_time_s,
                description: format!("{make}, linear RGB, {} bits", raw.bps),
            })
        }
        (p, n) => Err(unsupported(
            path,
            format!(
                "its data are {n} sample(s) per pixel ({p:?}), neither a 2 × 2 mosaic nor linear RGB; {advice}"
            ),
        )),
    }
}

/// Bilinear demosaic of a 2 × 2 mosaic: each output channel at each pixel is the mean of that
/// channel's sites in the 3 × 3 neighbourhood (the site itself when it is one), rounded.
fn demosaic_bilinear(
    data: &[u16],
    w: usize,
    h: usize,
    colour: &dyn Fn(usize, usize) -> usize,
) -> Vec<u16> {
    let mut out = vec![0u16; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let own = colour(y % 2, x % 2);
            let (mut sum, mut n) = ([0u32; 3], [0u32; 3]);
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (yy, xx) = (y as i64 + dy, x as i64 + dx);
                    if yy < 0 || xx < 0 || yy >= h as i64 || xx >= w as i64 {
                        continue;
                    }
                    let (yy, xx) = (yy as usize, xx as usize);
                    let c = colour(yy % 2, xx % 2);
                    sum[c] += u32::from(data[yy * w + xx]);
                    n[c] += 1;
                }
            }
            for c in 0..3 {
                out[(y * w + x) * 3 + c] = if c == own {
                    data[y * w + x]
                } else {
                    (sum[c] + n[c] / 2).checked_div(n[c]).unwrap_or(0) as u16
                };
            }
        }
    }
    out
}

/// What [`write_dng`] puts in the file's metadata.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DngInfo {
    /// Black level per channel R, G, B \[DN\].
    pub black_level: [u16; 3],
    /// White level \[DN\].
    pub white_level: u16,
    /// Exposure time \[s\].
    pub exposure_time_s: f64,
}

/// Writes an RGB linear frame as a DNG 1.4 file of a Bayer sensor (RGGB): each pixel keeps the
/// channel of its mosaic site; uncompressed 16-bit CFA data, `BlackLevel` per site (repeat 2 × 2),
/// `WhiteLevel`, `ExposureTime`, an identity-like colour matrix (sRGB primaries, D65) and neutral
/// white balance. Written atomically. What the rig twin's `--camera dng` writes.
///
/// # Errors
/// [`ImageFileError::Unsupported`] for a frame that is not RGB or an encoder error,
/// [`ImageFileError::Write`] when the file cannot be written.
pub fn write_dng(path: &Path, rgb: &ImageBuf<u16>, info: &DngInfo) -> Result<(), ImageFileError> {
    use tiff::encoder::{Rational, SRational, TiffEncoder, colortype};
    use tiff::tags::Tag;
    if rgb.channels() != 3 {
        return Err(unsupported(
            path,
            "a DNG is written from an RGB frame".into(),
        ));
    }
    let (w, h) = (rgb.width(), rgb.height());
    // RGGB: (even row, even col) R, (even, odd) G, (odd, even) G, (odd, odd) B.
    let site = |y: usize, x: usize| [[0usize, 1], [1, 2]][y % 2][x % 2];
    let mosaic: Vec<u16> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (y, x)))
        .map(|(y, x)| rgb.data()[(y * w + x) * 3 + site(y, x)])
        .collect();
    let err = |e: tiff::TiffError| unsupported(path, format!("cannot encode the DNG ({e})"));
    let mut bytes = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut bytes).map_err(err)?;
        let mut image = enc
            .new_image::<colortype::Gray16>(w as u32, h as u32)
            .map_err(err)?;
        let t = info.exposure_time_s;
        let (n, d) = if t >= 1.0 {
            ((t * 1000.0).round() as u32, 1000)
        } else {
            (1_000_000, (1_000_000.0 / t).round() as u32)
        };
        let b = info.black_level;
        // XYZ → camera for a camera with sRGB primaries (the inverse of sRGB's camera → XYZ).
        let m: [f64; 9] = [
            3.2406, -1.5372, -0.4986, -0.9689, 1.8758, 0.0415, 0.0557, -0.2040, 1.0570,
        ];
        let matrix: Vec<SRational> = m
            .iter()
            .map(|v| SRational {
                n: (v * 10000.0).round() as i32,
                d: 10000,
            })
            .collect();
        let e = image.encoder();
        e.write_tag(Tag::NewSubfileType, 0u32).map_err(err)?;
        e.write_tag(Tag::PhotometricInterpretation, 32803u16)
            .map_err(err)?;
        e.write_tag(Tag::Make, "scatterfit").map_err(err)?;
        e.write_tag(Tag::Model, "rig twin").map_err(err)?;
        e.write_tag(Tag::Unknown(33421), &[2u16, 2][..])
            .map_err(err)?; // CFARepeatPatternDim
        e.write_tag(Tag::Unknown(33422), &[0u8, 1, 1, 2][..])
            .map_err(err)?; // CFAPattern RGGB
        e.write_tag(Tag::Unknown(33434), Rational { n, d })
            .map_err(err)?; // ExposureTime
        e.write_tag(Tag::Unknown(50706), &[1u8, 4, 0, 0][..])
            .map_err(err)?; // DNGVersion
        e.write_tag(Tag::Unknown(50707), &[1u8, 1, 0, 0][..])
            .map_err(err)?; // DNGBackwardVersion
        e.write_tag(Tag::Unknown(50708), "scatterfit rig twin")
            .map_err(err)?; // UniqueCameraModel
        e.write_tag(Tag::Unknown(50710), &[0u8, 1, 2][..])
            .map_err(err)?; // CFAPlaneColor
        e.write_tag(Tag::Unknown(50711), 1u16).map_err(err)?; // CFALayout: rectangular
        e.write_tag(Tag::Unknown(50713), &[2u16, 2][..])
            .map_err(err)?; // BlackLevelRepeatDim
        e.write_tag(Tag::Unknown(50714), &[b[0], b[1], b[1], b[2]][..])
            .map_err(err)?; // BlackLevel
        e.write_tag(Tag::Unknown(50717), info.white_level)
            .map_err(err)?; // WhiteLevel
        e.write_tag(Tag::Unknown(50721), &matrix[..]).map_err(err)?; // ColorMatrix1
        e.write_tag(
            Tag::Unknown(50728),
            &[
                Rational { n: 1, d: 1 },
                Rational { n: 1, d: 1 },
                Rational { n: 1, d: 1 },
            ][..],
        )
        .map_err(err)?; // AsShotNeutral
        e.write_tag(Tag::Unknown(50778), 21u16).map_err(err)?; // CalibrationIlluminant1: D65
        image.write_data(&mosaic).map_err(err)?;
    }
    crate::atomic::write_atomic(path, bytes.get_ref()).map_err(|source| ImageFileError::Write {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A DNG written here opens in rawler with its mosaic, levels and exposure time intact: the
    /// demosaiced value at each pixel's own site is the value written, and the levels come back.
    #[test]
    fn dng_round_trip_through_rawler() {
        let (w, h) = (32, 24);
        let data: Vec<u16> = (0..w * h * 3)
            .map(|i| 512 + ((i * 37) % 15000) as u16)
            .collect();
        let rgb = ImageBuf::new(w, h, 3, data).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.dng");
        let info = DngInfo {
            black_level: [512, 520, 530],
            white_level: 16383,
            exposure_time_s: 1.0 / 125.0,
        };
        write_dng(&path, &rgb, &info).unwrap();
        assert!(is_raw_path(&path));
        let bytes = std::fs::read(&path).unwrap();
        let f = decode_raw(&bytes, &path).unwrap();
        assert_eq!((f.rgb.width(), f.rgb.height()), (w, h));
        assert_eq!(f.levels.white, 16383.0);
        assert_eq!(f.levels.black, [512.0, 520.0, 530.0]);
        let t = f.exposure_time_s.unwrap();
        assert!((t - 1.0 / 125.0).abs() < 1e-9, "{t}");
        for y in 0..h {
            for x in 0..w {
                let c = [[0usize, 1], [1, 2]][y % 2][x % 2];
                assert_eq!(
                    f.rgb.data()[(y * w + x) * 3 + c],
                    rgb.data()[(y * w + x) * 3 + c]
                );
            }
        }
    }

    /// A file that is not a raw image is refused by name with what to do, not a panic.
    #[test]
    fn garbage_is_refused() {
        let err = decode_raw(b"not a raw file at all", Path::new("x.cr2")).unwrap_err();
        assert!(err.to_string().contains("convert it to DNG"), "{err}");
    }
}
