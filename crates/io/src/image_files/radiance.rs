//! Radiance maps: reading and writing OpenEXR (exrs) and Radiance HDR (image), within a memory
//! budget checked from the header before anything is decoded.

use super::*;

/// File formats for float radiance maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadianceFormat {
    /// OpenEXR, 32-bit float samples, channels `R,G,B` or `Y`, uncompressed scan lines (exact, and
    /// the same bytes for the same image).
    Exr,
    /// Radiance RGBE (`.hdr`): RGB only (a grey map is written as three equal channels), about 1 %
    /// precision (8-bit mantissa, shared exponent).
    Hdr,
}

impl RadianceFormat {
    /// The format a file name asks for: `.exr` or `.hdr` (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "exr" => Some(Self::Exr),
            "hdr" | "rgbe" | "pic" => Some(Self::Hdr),
            _ => None,
        }
    }
}

/// Reads a float radiance map: OpenEXR (channels `R,G,B` → 3 channels, or `Y` → 1) or Radiance HDR
/// (3 channels). Float TIFF is accepted too (through the `image` crate).
///
/// # Errors
/// [`ImageFileError`] naming the file: unreadable, not a float image, or unsupported EXR channels.
pub fn read_radiance(path: &Path) -> Result<ImageBuf<f32>, ImageFileError> {
    read_radiance_within(path, crate::budget::memory_budget_bytes())
}

/// [`read_radiance`] within a memory budget \[bytes\] (a command's `--max-memory-mib`) instead of
/// the environment's.
///
/// # Errors
/// As [`read_radiance`], and [`ImageFileError::TooLarge`].
pub fn read_radiance_within(path: &Path, budget: u64) -> Result<ImageBuf<f32>, ImageFileError> {
    let bytes = read_image_bytes(path, budget)?;
    decode_radiance(&bytes, path, budget)
}

/// [`read_radiance`] on the bytes of a file, within a memory budget \[bytes\] checked from the header
/// before any pixel is decoded; `path` is only used in error messages.
///
/// # Errors
/// As [`read_radiance`], and [`ImageFileError::TooLarge`].
pub fn decode_radiance(
    bytes: &[u8],
    path: &Path,
    budget: u64,
) -> Result<ImageBuf<f32>, ImageFileError> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return read_exr(bytes, path, budget);
    }
    use image::DynamicImage as D;
    let image = decode_any(bytes, path, budget)?;
    let (w, h) = (image.width() as usize, image.height() as usize);
    let buf_err = |e: scatterfit_imaging::ShapeError| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail: format!("decoder returned an inconsistent buffer: {e}"),
    };
    match image {
        D::ImageRgb32F(b) => ImageBuf::new(w, h, 3, b.into_raw()).map_err(buf_err),
        D::ImageRgba32F(b) => ImageBuf::new(w, h, 3, drop_alpha(b.as_raw(), 4)).map_err(buf_err),
        other => Err(ImageFileError::Unsupported {
            path: path.to_path_buf(),
            detail: format!(
                "expected a floating-point radiance map (EXR or HDR) but found {:?} integer pixels; \
                 merge camera frames into a radiance map with `scatterfit merge` first",
                other.color()
            ),
        }),
    }
}

pub(super) fn read_exr(
    bytes: &[u8],
    path: &Path,
    budget: u64,
) -> Result<ImageBuf<f32>, ImageFileError> {
    use exr::prelude::*;
    let exr_err = |source| ImageFileError::Exr {
        path: path.to_path_buf(),
        source,
    };
    // The headers first: every layer's samples (as stored) plus our f32 copy must fit the budget.
    let meta =
        exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_err)?;
    let mut needed = 0u64;
    let mut what = String::new();
    for header in &meta.headers {
        let size = header.layer_size;
        let pixels = (size.width() as u64).saturating_mul(size.height() as u64);
        let stored: u64 = header
            .channels
            .list
            .iter()
            .map(|c| pixels.saturating_mul(c.sample_type.bytes_per_sample() as u64))
            .fold(0, u64::saturating_add);
        needed = needed
            .saturating_add(stored)
            .saturating_add(pixels.saturating_mul(3 * 4));
        if what.is_empty() {
            what = format!(
                "an OpenEXR image of {}×{} pixels and {} channels",
                size.width(),
                size.height(),
                header.channels.list.len()
            );
        }
    }
    if needed > budget {
        return Err(ImageFileError::TooLarge {
            path: path.to_path_buf(),
            what,
            needed,
            budget,
        });
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(exr_err)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let list = &layer.channel_data.list;
    let find = |name: &str| list.iter().find(|c| c.name.eq_case_insensitive(name));
    let names: Vec<String> = list.iter().map(|c| c.name.to_string()).collect();
    let picked: Vec<_> = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => vec![r, g, b],
        (None, None, None, Some(y)) => vec![y],
        _ => {
            return Err(ImageFileError::Unsupported {
                path: path.to_path_buf(),
                detail: format!(
                    "OpenEXR channels [{}] are neither R,G,B nor Y; save the radiance map with \
                     R,G,B (or a single Y) channels",
                    names.join(", ")
                ),
            });
        }
    };
    let channels = picked.len();
    let mut data = vec![0f32; w * h * channels];
    for (c, channel) in picked.iter().enumerate() {
        for (dst, v) in data
            .iter_mut()
            .skip(c)
            .step_by(channels)
            .zip(channel.sample_data.values_as_f32())
        {
            *dst = v;
        }
    }
    ImageBuf::new(w, h, channels, data).map_err(|e| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail: format!("inconsistent OpenEXR data window: {e}"),
    })
}

/// Writes a float radiance map atomically, in the format its extension names (`.exr` or `.hdr`).
///
/// EXR keeps 32-bit floats exactly, with channels `R,G,B` (3 channels) or `Y` (1 channel). HDR
/// (RGBE) keeps about 1 % precision and only RGB: a grey map is written as three equal channels.
///
/// # Errors
/// [`ImageFileError::Unsupported`] for another extension or a channel count other than 1 or 3;
/// [`ImageFileError::Write`], [`ImageFileError::Exr`] or [`ImageFileError::Decode`] (encoder) if
/// writing fails, in which case an existing file at `path` is left untouched.
pub fn write_radiance(path: &Path, image: &ImageBuf<f32>) -> Result<(), ImageFileError> {
    let format = RadianceFormat::from_path(path).ok_or_else(|| ImageFileError::Unsupported {
        path: path.to_path_buf(),
        detail: "cannot tell the radiance format from the file name; end it in .exr or .hdr".into(),
    })?;
    if image.channels() != 1 && image.channels() != 3 {
        return Err(ImageFileError::Unsupported {
            path: path.to_path_buf(),
            detail: format!(
                "a radiance map has 1 or 3 channels, not {}",
                image.channels()
            ),
        });
    }
    let bytes = match format {
        RadianceFormat::Exr => encode_exr(image, path)?,
        RadianceFormat::Hdr => encode_hdr(image, path)?,
    };
    crate::atomic::write_atomic(path, &bytes).map_err(|source| ImageFileError::Write {
        path: path.to_path_buf(),
        source,
    })
}

pub(super) fn encode_exr(image: &ImageBuf<f32>, path: &Path) -> Result<Vec<u8>, ImageFileError> {
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
    // Uncompressed scan lines in increasing order: the same image gives the same bytes (the former
    // RLE tiles in `Unspecified` order came out in whatever order the threads finished), and every
    // EXR reader reads them. A merged map's low mantissa bits are noise, which no lossless codec
    // packs: PIZ saved 10 % of the memorial's map and 8 % of a 1-MP twin's at 20–50 times the
    // write time (0.19 s and 0.45 s against 0.009 s, a fifth of the memorial's whole merge;
    // BENCHMARKS.md, "EXR output").
    let encoding = Encoding {
        compression: Compression::Uncompressed,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("radiance"),
        encoding,
        AnyChannels::sort(list),
    );
    let mut out = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|source| ImageFileError::Exr {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(out.into_inner())
}

pub(super) fn encode_hdr(image: &ImageBuf<f32>, path: &Path) -> Result<Vec<u8>, ImageFileError> {
    let (w, h, n) = (image.width(), image.height(), image.channels());
    let pixels: Vec<image::Rgb<f32>> = image
        .data()
        .chunks_exact(n)
        .map(|px| {
            if n == 1 {
                image::Rgb([px[0]; 3])
            } else {
                image::Rgb([px[0], px[1], px[2]])
            }
        })
        .collect();
    let mut out = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut out)
        .encode(&pixels, w, h)
        .map_err(|source| ImageFileError::Decode {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(out)
}
