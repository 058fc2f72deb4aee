//! The error of reading or writing an image file (camera frames, radiance maps and raw files:
//! [`crate::raw`] returns it too).

use std::path::PathBuf;

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
