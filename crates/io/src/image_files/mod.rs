//! Image files: camera frames (PNG, TIFF, JPEG; 8- or 16-bit; grey or RGB) and float radiance maps
//! (OpenEXR, Radiance HDR).
//!
//! Decoding only: no pixel maths happens here (that is `scatterfit-imaging`'s job). A camera frame is
//! kept at its stored bit depth ([`CameraFrame`]); an alpha channel is dropped and the caller is told
//! ([`DecodedFrame::dropped_alpha`]). Radiance maps are `ImageBuf<f32>` with 1 (grey, EXR channel
//! `Y`) or 3 (RGB) channels. Writes go through [`crate::atomic::write_atomic`].

use std::io::Cursor;
use std::path::Path;

use scatterfit_imaging::ImageBuf;

pub(crate) mod error;
mod jpeg;
mod radiance;

pub use error::ImageFileError;

pub use jpeg::jpeg_quality;

pub use radiance::{
    RadianceFormat, decode_radiance, read_radiance, read_radiance_within, write_radiance,
};

/// A camera frame at its stored bit depth.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraFrame {
    /// 8 bits per sample (PNG, TIFF, JPEG).
    U8(ImageBuf<u8>),
    /// 16 bits per sample (PNG, TIFF).
    U16(ImageBuf<u16>),
}

impl CameraFrame {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        match self {
            Self::U8(b) => b.width(),
            Self::U16(b) => b.width(),
        }
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        match self {
            Self::U8(b) => b.height(),
            Self::U16(b) => b.height(),
        }
    }

    /// Channels per pixel: 1 (grey) or 3 (RGB).
    pub fn channels(&self) -> usize {
        match self {
            Self::U8(b) => b.channels(),
            Self::U16(b) => b.channels(),
        }
    }

    /// Bits per sample: 8 or 16.
    pub fn bit_depth(&self) -> u32 {
        match self {
            Self::U8(_) => 8,
            Self::U16(_) => 16,
        }
    }

    /// A short description, e.g. `6000×4000 RGB 8-bit`.
    pub fn describe(&self) -> String {
        describe_shape(
            self.width(),
            self.height(),
            self.channels(),
            self.bit_depth(),
        )
    }
}

/// `6000×4000 RGB 8-bit`.
pub(crate) fn describe_shape(width: usize, height: usize, channels: usize, bits: u32) -> String {
    let kind = match channels {
        1 => "grey".to_string(),
        3 => "RGB".to_string(),
        n => format!("{n}-channel"),
    };
    format!("{width}×{height} {kind} {bits}-bit")
}

/// A decoded camera frame and what happened on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct DecodedFrame {
    /// The pixels.
    pub frame: CameraFrame,
    /// True if the file had an alpha channel, which was dropped.
    pub dropped_alpha: bool,
    /// A camera RAW file's levels and exposure time from its metadata (`None` for other files).
    pub raw: Option<RawInfo>,
}

/// What a camera RAW file's metadata say ([`crate::raw`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawInfo {
    /// Black and white levels \[DN\].
    pub levels: crate::raw::RawLevels,
    /// The exposure time \[s\], if the file records one.
    pub exposure_time_s: Option<f64>,
}

/// Reads a camera frame (PNG, TIFF or JPEG; 8- or 16-bit; grey, grey+alpha, RGB or RGBA).
///
/// # Errors
/// [`ImageFileError::Read`] if the file cannot be read, [`ImageFileError::Decode`] if it is not a
/// readable image, [`ImageFileError::Unsupported`] for float images.
pub fn read_camera_frame(path: &Path) -> Result<DecodedFrame, ImageFileError> {
    let bytes = read_bytes(path)?;
    decode_camera_frame(&bytes, path)
}

/// Decodes a camera frame from the bytes of a file within the memory budget
/// ([`crate::budget::memory_budget_bytes`]); `path` is only used in error messages.
///
/// # Errors
/// As [`read_camera_frame`], and [`ImageFileError::TooLarge`] when the header announces an image
/// larger than the budget.
pub fn decode_camera_frame(bytes: &[u8], path: &Path) -> Result<DecodedFrame, ImageFileError> {
    decode_camera_frame_within(bytes, path, crate::budget::memory_budget_bytes())
}

/// [`decode_camera_frame`] with an explicit memory budget \[bytes\]: the decoded image and the copy
/// without alpha must fit in it, checked from the header before any pixel is decoded.
///
/// # Errors
/// As [`decode_camera_frame`].
pub fn decode_camera_frame_within(
    bytes: &[u8],
    path: &Path,
    budget: u64,
) -> Result<DecodedFrame, ImageFileError> {
    use image::DynamicImage as D;
    if crate::raw::is_raw_path(path) {
        let raw = crate::raw::decode_raw(bytes, path)?;
        let needed = (raw.rgb.data().len() * 2) as u64;
        if needed > budget {
            return Err(ImageFileError::TooLarge {
                path: path.to_path_buf(),
                what: format!("a {}×{} RAW image", raw.rgb.width(), raw.rgb.height()),
                needed,
                budget,
            });
        }
        return Ok(DecodedFrame {
            frame: CameraFrame::U16(raw.rgb),
            dropped_alpha: false,
            raw: Some(RawInfo {
                levels: raw.levels,
                exposure_time_s: raw.exposure_time_s,
            }),
        });
    }
    let image = decode_any(bytes, path, budget)?;
    let (w, h) = (image.width() as usize, image.height() as usize);
    let buf_err = |e: scatterfit_imaging::ShapeError| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail: format!("the decoded image is empty or inconsistent ({e}); give a non-empty frame"),
    };
    let (frame, dropped_alpha) = match image {
        D::ImageLuma8(b) => (
            CameraFrame::U8(ImageBuf::new(w, h, 1, b.into_raw()).map_err(buf_err)?),
            false,
        ),
        D::ImageRgb8(b) => (
            CameraFrame::U8(ImageBuf::new(w, h, 3, b.into_raw()).map_err(buf_err)?),
            false,
        ),
        D::ImageLuma16(b) => (
            CameraFrame::U16(ImageBuf::new(w, h, 1, b.into_raw()).map_err(buf_err)?),
            false,
        ),
        D::ImageRgb16(b) => (
            CameraFrame::U16(ImageBuf::new(w, h, 3, b.into_raw()).map_err(buf_err)?),
            false,
        ),
        D::ImageLumaA8(b) => {
            let data = drop_alpha(b.as_raw(), 2);
            (
                CameraFrame::U8(ImageBuf::new(w, h, 1, data).map_err(buf_err)?),
                true,
            )
        }
        D::ImageRgba8(b) => {
            let data = drop_alpha(b.as_raw(), 4);
            (
                CameraFrame::U8(ImageBuf::new(w, h, 3, data).map_err(buf_err)?),
                true,
            )
        }
        D::ImageLumaA16(b) => {
            let data = drop_alpha(b.as_raw(), 2);
            (
                CameraFrame::U16(ImageBuf::new(w, h, 1, data).map_err(buf_err)?),
                true,
            )
        }
        D::ImageRgba16(b) => {
            let data = drop_alpha(b.as_raw(), 4);
            (
                CameraFrame::U16(ImageBuf::new(w, h, 3, data).map_err(buf_err)?),
                true,
            )
        }
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            return Err(ImageFileError::Unsupported {
                path: path.to_path_buf(),
                detail: "this is a floating-point image, not a camera frame; an already merged \
                         radiance map goes straight to `scatterfit profile`"
                    .into(),
            });
        }
        other => {
            return Err(ImageFileError::Unsupported {
                path: path.to_path_buf(),
                detail: format!(
                    "pixel layout {:?} is not supported; save the frame as 8- or 16-bit grey or RGB",
                    other.color()
                ),
            });
        }
    };
    Ok(DecodedFrame {
        frame,
        dropped_alpha,
        raw: None,
    })
}

/// Keeps the first `stride − 1` samples of every `stride` (drops a trailing alpha sample).
fn drop_alpha<T: Copy>(data: &[T], stride: usize) -> Vec<T> {
    let keep = stride - 1;
    let mut out = Vec::with_capacity(data.len() / stride * keep);
    for px in data.chunks_exact(stride) {
        out.extend_from_slice(&px[..keep]);
    }
    out
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, ImageFileError> {
    read_image_bytes(path, crate::budget::memory_budget_bytes())
}

/// The bytes of an image file: a regular file only (a FIFO or a device is refused at once) of at
/// most `budget` bytes (a compressed image is never larger than what it decodes to, which the
/// budget bounds too).
///
/// # Errors
/// [`ImageFileError::Read`] naming the file.
pub fn read_image_bytes(path: &Path, budget: u64) -> Result<Vec<u8>, ImageFileError> {
    scatterfit_safefs::read::read_limited(path, budget).map_err(|source| ImageFileError::Read {
        path: path.to_path_buf(),
        source,
    })
}

/// The most a decoder may allocate while reading an image's header and ancillary chunks \[bytes\]
/// (64 MiB; a camera's ICC profile is under 1 MiB).
const HEADER_ALLOC: u64 = 64 << 20;

/// The largest ratio of decoded to file bytes any accepted format reaches: deflate (PNG, TIFF)
/// stops at 1032:1 (RFC 1951: 258 bytes per 2-bit code at best), LZW (TIFF) near 1365:1, a JPEG
/// needs at least a few bits per 8 × 8 block per component (≤ 512:1). 4096 leaves room.
const MAX_COMPRESSION: u64 = 4096;

/// What decoding an image of this header allocates at most [bytes]: the decoded buffer, plus a
/// copy without alpha (or a float conversion) of at most the same size.
fn decode_cost(width: u32, height: u32, color: image::ColorType) -> u64 {
    u64::from(width)
        .saturating_mul(u64::from(height))
        .saturating_mul(u64::from(color.bytes_per_pixel()))
        .saturating_mul(2)
}

fn decode_any(
    bytes: &[u8],
    path: &Path,
    budget: u64,
) -> Result<image::DynamicImage, ImageFileError> {
    use image::ImageDecoder;
    let decode_err = |source| ImageFileError::Decode {
        path: path.to_path_buf(),
        source,
    };
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|source| ImageFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    if reader.format().is_none()
        && let Ok(format) = image::ImageFormat::from_path(path)
    {
        reader.set_format(format);
    }
    // The `image` crate checks every allocation of the decoders against `max_alloc`. Reading the
    // header may inflate ancillary chunks (a PNG's compressed ICC profile, zTXt text): bounded by
    // HEADER_ALLOC, far above any real profile, so a small file cannot make it allocate gigabytes.
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(budget.min(HEADER_ALLOC));
    reader.limits(limits);
    let mut decoder = reader.into_decoder().map_err(decode_err)?;
    let (w, h) = decoder.dimensions();
    let color = decoder.color_type();
    let needed = decode_cost(w, h, color);
    if needed > budget {
        return Err(ImageFileError::TooLarge {
            path: path.to_path_buf(),
            what: format!("a {w}×{h} {color:?} image"),
            needed,
            budget,
        });
    }
    // The header against the file: no image codec packs more than MAX_COMPRESSION decoded bytes
    // into one byte of file, so a header that claims more is corrupt or crafted (a 10 KB JPEG
    // announcing 30000 × 30000 pixels) — refused before its pixels are allocated.
    let pixels_bytes = u64::from(w)
        .saturating_mul(u64::from(h))
        .saturating_mul(u64::from(color.bytes_per_pixel()));
    let plausible = (bytes.len() as u64)
        .saturating_mul(MAX_COMPRESSION)
        .saturating_add(1 << 20);
    if pixels_bytes > plausible {
        return Err(ImageFileError::Unsupported {
            path: path.to_path_buf(),
            detail: format!(
                "the header announces a {w}×{h} image ({}), but the file has only {} bytes — no \
                 image format compresses {MAX_COMPRESSION}:1; the file is truncated or its header \
                 is corrupt. Export the frame again",
                crate::budget::describe_bytes(pixels_bytes),
                bytes.len()
            ),
        });
    }
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(budget);
    decoder.set_limits(limits).map_err(decode_err)?;
    image::DynamicImage::from_decoder(decoder).map_err(decode_err)
}

/// Writes a camera frame atomically, in the format its extension names: `.png` (8 or 16-bit, fast
/// compression), `.tif`/`.tiff` (8 or 16-bit) or `.jpg`/`.jpeg` (8-bit, quality 95). For test data,
/// synthetic brackets and exports; the measurement's own frames are only ever read.
///
/// # Errors
/// [`ImageFileError::Unsupported`] for another extension, a 16-bit JPEG or a channel count other
/// than 1 or 3; [`ImageFileError::Decode`] (encoder) or [`ImageFileError::Write`] if writing fails.
pub fn write_camera_frame(path: &Path, frame: &CameraFrame) -> Result<(), ImageFileError> {
    use image::ExtendedColorType as C;
    use image::ImageEncoder;
    let unsupported = |detail: String| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let (w, h) = (frame.width() as u32, frame.height() as u32);
    let (bytes, color): (std::borrow::Cow<'_, [u8]>, C) = match (frame, frame.channels()) {
        (CameraFrame::U8(b), 1) => (b.data().into(), C::L8),
        (CameraFrame::U8(b), 3) => (b.data().into(), C::Rgb8),
        (CameraFrame::U16(b), c @ (1 | 3)) => {
            // The encoders take 16-bit samples as native-endian bytes.
            let raw: Vec<u8> = b.data().iter().flat_map(|v| v.to_ne_bytes()).collect();
            (raw.into(), if c == 1 { C::L16 } else { C::Rgb16 })
        }
        (_, c) => {
            return Err(unsupported(format!(
                "a camera frame has 1 or 3 channels, not {c}"
            )));
        }
    };
    let enc_err = |source| ImageFileError::Decode {
        path: path.to_path_buf(),
        source,
    };
    let mut out = Vec::new();
    match ext.as_str() {
        "png" => image::codecs::png::PngEncoder::new_with_quality(
            &mut out,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(&bytes, w, h, color)
        .map_err(enc_err)?,
        "tif" | "tiff" => image::codecs::tiff::TiffEncoder::new(Cursor::new(&mut out))
            .write_image(&bytes, w, h, color)
            .map_err(enc_err)?,
        "jpg" | "jpeg" if frame.bit_depth() == 8 => {
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 95)
                .write_image(&bytes, w, h, color)
                .map_err(enc_err)?
        }
        "jpg" | "jpeg" => {
            return Err(unsupported(
                "JPEG holds 8-bit data only; save 16-bit frames as PNG or TIFF".into(),
            ));
        }
        _ => {
            return Err(unsupported(
                "cannot tell the image format from the file name; end it in .png, .tif or .jpg"
                    .into(),
            ));
        }
    }
    crate::atomic::write_atomic(path, &out).map_err(|source| ImageFileError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Writes an 8-bit grey or RGB camera frame atomically as a baseline JPEG of the given quality
/// (1–100; [`write_camera_frame`] uses 95), whatever the file's extension. For synthetic brackets
/// and benchmarks that need a camera-like compression level.
///
/// # Errors
/// [`ImageFileError::Unsupported`] for a channel count other than 1 or 3 or a quality outside
/// 1..=100; [`ImageFileError::Decode`] (encoder) or [`ImageFileError::Write`] if writing fails.
pub fn write_jpeg(path: &Path, frame: &ImageBuf<u8>, quality: u8) -> Result<(), ImageFileError> {
    use image::ExtendedColorType as C;
    use image::ImageEncoder;
    let unsupported = |detail: String| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail,
    };
    let color = match frame.channels() {
        1 => C::L8,
        3 => C::Rgb8,
        c => {
            return Err(unsupported(format!(
                "a camera frame has 1 or 3 channels, not {c}"
            )));
        }
    };
    if !(1..=100).contains(&quality) {
        return Err(unsupported(format!(
            "JPEG quality must be 1–100, not {quality}"
        )));
    }
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality)
        .write_image(
            frame.data(),
            frame.width() as u32,
            frame.height() as u32,
            color,
        )
        .map_err(|source| ImageFileError::Decode {
            path: path.to_path_buf(),
            source,
        })?;
    crate::atomic::write_atomic(path, &out).map_err(|source| ImageFileError::Write {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drop_alpha_keeps_colour_samples_in_order() {
        assert_eq!(
            drop_alpha(&[1u8, 2, 3, 255, 4, 5, 6, 0], 4),
            vec![1, 2, 3, 4, 5, 6]
        );
        assert_eq!(drop_alpha(&[7u16, 1, 9, 1], 2), vec![7, 9]);
    }

    /// CRC-32 (ISO 3309, the PNG chunk checksum), bit by bit: enough for a test's few chunks.
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
    }

    /// A PNG whose header claims `w`×`h` 8-bit RGB and whose data is a few bytes.
    fn lying_png(w: u32, h: u32) -> Vec<u8> {
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&w.to_be_bytes());
        ihdr.extend_from_slice(&h.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
        chunk(&mut png, b"IHDR", &ihdr);
        // A zlib stream of a few zero bytes (stored block), far short of the image.
        chunk(
            &mut png,
            b"IDAT",
            &[
                0x78, 0x01, 0x01, 0x04, 0x00, 0xfb, 0xff, 0, 0, 0, 0, 0, 0x04, 0x00, 0x01,
            ],
        );
        chunk(&mut png, b"IEND", &[]);
        png
    }

    /// A header that announces far more pixels than the file could hold (a 100-byte PNG claiming
    /// 30000 × 30000) is refused from the header, before a buffer is allocated — however large
    /// the budget. A small image whose header fits its file still decodes.
    #[test]
    fn a_header_that_its_file_cannot_hold_is_refused_before_decoding() {
        let png = lying_png(30_000, 30_000);
        let e = decode_camera_frame_within(&png, Path::new("frame.png"), 1 << 40).unwrap_err();
        assert!(e.to_string().contains("header announces"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ok.png");
        let frame = ImageBuf::new(64, 48, 3, vec![9u8; 64 * 48 * 3]).unwrap();
        write_camera_frame(&p, &CameraFrame::U8(frame)).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        let d = decode_camera_frame_within(&bytes, &p, 1 << 30).unwrap();
        assert_eq!((d.frame.width(), d.frame.height()), (64, 48));
    }

    /// A zlib stream of `1 + 258 k` zero bytes in fixed-Huffman deflate (RFC 1950/1951): a
    /// literal 0, then `k` copies of (length 258, distance 1) at 13 bits each.
    fn zlib_zeros(k: usize) -> Vec<u8> {
        let mut out = vec![0x78, 0x01];
        let (mut acc, mut n) = (0u64, 0u32);
        let mut bits = |value: u32, count: u32, out: &mut Vec<u8>| {
            acc |= u64::from(value) << n;
            n += count;
            while n >= 8 {
                out.push(acc as u8);
                acc >>= 8;
                n -= 8;
            }
        };
        // Huffman codes go most significant bit first.
        let code =
            |c: u32, len: u32| (0..len).fold(0, |r, i| r | (((c >> i) & 1) << (len - 1 - i)));
        bits(1, 1, &mut out); // BFINAL
        bits(1, 2, &mut out); // BTYPE = 01, fixed Huffman
        bits(code(0x30, 8), 8, &mut out); // literal 0
        for _ in 0..k {
            bits(code(0xC5, 8), 8, &mut out); // length 258 (symbol 285)
            bits(0, 5, &mut out); // distance 1 (code 0)
        }
        bits(0, 7, &mut out); // end of block (symbol 256)
        bits(0, 7, &mut out); // flush
        let len = 1 + 258 * k as u64;
        let adler = ((len % 65_521) << 16) | 1;
        out.extend_from_slice(&(adler as u32).to_be_bytes());
        out
    }

    /// The peak resident memory of this process \[KiB\] (`VmHWM`), where /proc has it.
    fn peak_kib() -> Option<u64> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        line.split_whitespace().nth(1)?.parse().ok()
    }

    /// An ICC profile chunk that inflates to 1 GiB from a 7 MB file is not inflated past the
    /// decoder's header bound (64 MiB): the image decodes, the peak memory stays far below a GiB.
    #[test]
    fn an_inflating_icc_chunk_is_bounded() {
        use image::ImageEncoder;
        let mut plain = Vec::new();
        image::codecs::png::PngEncoder::new(&mut plain)
            .write_image(&[7u8; 16 * 16 * 3], 16, 16, image::ExtendedColorType::Rgb8)
            .unwrap();
        let mut iccp = b"bomb\0\0".to_vec();
        iccp.extend(zlib_zeros(4_161_600));
        // The signature and IHDR (8 + 25 bytes), the iCCP chunk, the rest.
        let mut png = plain[..33].to_vec();
        chunk(&mut png, b"iCCP", &iccp);
        png.extend_from_slice(&plain[33..]);
        assert!(png.len() < 8 << 20, "{} bytes", png.len());
        let before = peak_kib();
        let d = decode_camera_frame_within(&png, Path::new("icc.png"), 1 << 40).unwrap();
        assert_eq!(d.frame.width(), 16);
        if let (Some(a), Some(b)) = (before, peak_kib()) {
            assert!(
                b - a < 512 << 10,
                "peak memory rose by {} MiB",
                (b - a) >> 10
            );
        }
    }

    #[test]
    fn radiance_format_follows_the_extension() {
        assert_eq!(
            RadianceFormat::from_path(Path::new("a/B.EXR")),
            Some(RadianceFormat::Exr)
        );
        assert_eq!(
            RadianceFormat::from_path(Path::new("x.hdr")),
            Some(RadianceFormat::Hdr)
        );
        assert_eq!(RadianceFormat::from_path(Path::new("x.png")), None);
    }
}
