//! Image files: camera frames (PNG, TIFF, JPEG; 8- or 16-bit; grey or RGB) and float radiance maps
//! (OpenEXR, Radiance HDR).
//!
//! Decoding only: no pixel maths happens here (that is `scatterfit-imaging`'s job). A camera frame is
//! kept at its stored bit depth ([`CameraFrame`]); an alpha channel is dropped and the caller is told
//! ([`DecodedFrame::dropped_alpha`]). Radiance maps are `ImageBuf<f32>` with 1 (grey, EXR channel
//! `Y`) or 3 (RGB) channels. Writes go through [`crate::atomic::write_atomic`].

use std::io::Cursor;
use std::path::{Path, PathBuf};

use scatterfit_imaging::ImageBuf;

mod radiance;

pub use radiance::{
    RadianceFormat, decode_radiance, read_radiance, read_radiance_within, write_radiance,
};

/// What can go wrong reading or writing an image file. Every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImageFileError {
    /// The file could not be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file could not be written (the target is left untouched).
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The bytes are not an image of a format we read, or the image is corrupt.
    #[error(
        "cannot decode {} as an image ({source}); give a PNG, TIFF or JPEG camera frame \
         (or an EXR/HDR radiance map where one is expected)",
        path.display()
    )]
    Decode {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: image::ImageError,
    },
    /// The OpenEXR library rejected the file.
    #[error("cannot read or write {} as OpenEXR: {source}", path.display())]
    Exr {
        /// The file.
        path: PathBuf,
        /// The OpenEXR library's error.
        source: exr::error::Error,
    },
    /// Decoding the image would need more memory than the budget allows ([`crate::budget`]).
    #[error(
        "{}: {what} needs {} to decode, more than the memory budget of {}; {}",
        path.display(),
        crate::budget::describe_bytes(*needed),
        crate::budget::describe_bytes(*budget),
        crate::budget::how_to_raise()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// What the header says, e.g. `a 60000×40000 RGB 16-bit image`.
        what: String,
        /// Bytes the decode would allocate.
        needed: u64,
        /// The budget.
        budget: u64,
    },
    /// The image decodes but its kind is not the one expected here (e.g. float data as a camera
    /// frame, 8-bit data as a radiance map, EXR channels that are neither `R,G,B` nor `Y`).
    #[error("{}: {detail}", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What was found and what to do.
        detail: String,
    },
}

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
    // The `image` crate checks every allocation of the decoders against `max_alloc`; the whole
    // decode is checked against the budget from the header first.
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(budget);
    reader.limits(limits);
    let decoder = reader.into_decoder().map_err(decode_err)?;
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
