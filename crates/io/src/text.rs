//! Text input shared by every reader of a text format (the spectro, exposures, response and profile
//! CSVs, `result.json`): bytes → text. The CSV dialect a lab's spreadsheet wrote is
//! [`crate::csv_dialect`]'s.
//!
//! What a lab's files commonly are, and what happens to them (RELIABILITY.md has the table):
//!
//! | the file | here |
//! |---|---|
//! | UTF-8, with or without a byte-order mark (BOM), LF or CRLF line ends | accepted |
//! | UTF-16 with a BOM (Excel's "Unicode text", Windows Notepad's "Unicode") | accepted |
//! | not UTF-8, no NUL byte (Latin-1 / Windows-1252 comments, `°`, `µ`, `ä` in a note) | accepted, decoded as Windows-1252 (every byte is a character there; the numbers and column names we read are ASCII) |
//! | `;`-separated with decimal commas (`400;0,0712;0,0301`: a spreadsheet's CSV export where the comma is the decimal mark) | accepted: the separator is read from the header line; with `;` or tab separators a number may use a decimal comma |
//! | tab-separated | accepted |
//! | UTF-16 without a BOM, UTF-32 | refused, naming it, with how to re-save as UTF-8 |
//! | a workbook (`.xlsx`, `.ods`, `.xls`), an image, a PDF, other binary data | refused, naming what it looks like |
//! | larger than [`MAX_TEXT_FILE_BYTES`] | refused before it is read |
//! | a decimal comma in a `,`-separated file (`400,0,07,0,03`) | the row has more fields than the header: refused by the reader with a hint to use `;` |
//! | thousands separators (`1.234,5`, `1,234.5`) | not a number: refused by the reader |
//!
//! Decoding is by hand rather than with `encoding_rs`: the two encodings we accept besides UTF-8 are
//! UTF-16 (in `std`) and Windows-1252 (a 32-entry table below), so a dependency would add build time
//! for nothing.

use std::path::{Path, PathBuf};

/// Largest text input read, in bytes (64 MiB). Every text file of a measurement is a few kilobytes
/// (a 24-MP profile CSV with 1-px rings to the image corner is under 2 MB); anything larger is not
/// one of ours and is refused before it is read into memory.
pub const MAX_TEXT_FILE_BYTES: u64 = scatterfit_safefs::MAX_TEXT_BYTES;

/// How the bytes of a text file were decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum TextEncoding {
    /// UTF-8 without a byte-order mark.
    Utf8,
    /// UTF-8 with a byte-order mark (removed).
    Utf8Bom,
    /// UTF-16, little-endian, with a byte-order mark.
    Utf16Le,
    /// UTF-16, big-endian, with a byte-order mark.
    Utf16Be,
    /// Not valid UTF-8: decoded as Windows-1252 (a superset of Latin-1's printable characters).
    Windows1252,
}

impl TextEncoding {
    /// A short name for messages, e.g. `UTF-16LE with BOM`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Utf8 => "UTF-8",
            Self::Utf8Bom => "UTF-8 with BOM",
            Self::Utf16Le => "UTF-16LE with BOM",
            Self::Utf16Be => "UTF-16BE with BOM",
            Self::Windows1252 => "Windows-1252 (Latin-1)",
        }
    }
}

/// Why a file could not be read as text. Every variant names the file, says what was seen and how
/// to re-save the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TextError {
    /// The file could not be opened or read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file is larger than [`MAX_TEXT_FILE_BYTES`].
    #[error(
        "{} is {bytes} bytes, more than the {limit} bytes a scatterfit text file can be; is this the \
         right file?",
        path.display()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size (at least this many bytes).
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// The bytes are not text in an encoding we read.
    #[error("{}: {seen}; {advice}", path.display())]
    NotText {
        /// The file.
        path: PathBuf,
        /// What the bytes look like, e.g. `an Excel workbook (.xlsx, a ZIP archive)`.
        seen: String,
        /// How to re-save it.
        advice: &'static str,
    },
}

/// What to tell a user holding a file we do not read as text.
pub const RESAVE_ADVICE: &str = "save it from the spreadsheet or editor as \"CSV UTF-8\" (or plain \
     text, UTF-8), with a comma or semicolon between columns";

/// Reads a text file of at most [`MAX_TEXT_FILE_BYTES`] and decodes it ([`decode_text`]). Only a
/// regular file is read: a FIFO, a device (`/dev/zero`), a folder or a socket is refused at once
/// (`scatterfit_safefs::read`).
///
/// # Errors
/// [`TextError`] naming the file.
pub fn read_text_file(path: &Path) -> Result<DecodedText, TextError> {
    let bytes =
        scatterfit_safefs::read::read_limited(path, MAX_TEXT_FILE_BYTES).map_err(|source| {
            match scatterfit_safefs::UnsafeFile::of(&source) {
                Some(&scatterfit_safefs::UnsafeFile::TooLarge { bytes, limit }) => {
                    TextError::TooLarge {
                        path: path.to_path_buf(),
                        bytes,
                        limit,
                    }
                }
                _ => TextError::Io {
                    path: path.to_path_buf(),
                    source,
                },
            }
        })?;
    decode_text(&bytes, path)
}

/// A decoded text file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DecodedText {
    /// The text, without a byte-order mark.
    pub text: String,
    /// How the bytes were decoded.
    pub encoding: TextEncoding,
    /// SHA-256 of the bytes decoded (the file as read, byte-order mark included), lower-case hex
    /// ([`crate::digest::sha256_hex`]).
    pub sha256: String,
}

/// Decodes the bytes of a text file (see the module documentation for what is accepted); `path`
/// names the file in errors.
///
/// # Errors
/// [`TextError::NotText`] for UTF-16 without a BOM, UTF-32, invalid UTF-16, and binary data (a
/// workbook, an image, …), each named.
pub fn decode_text(bytes: &[u8], path: &Path) -> Result<DecodedText, TextError> {
    let (text, encoding) = decode(bytes, path)?;
    Ok(DecodedText {
        text,
        encoding,
        sha256: crate::digest::sha256_hex(bytes),
    })
}

/// The text of `bytes` and how it was decoded ([`decode_text`]).
fn decode(bytes: &[u8], path: &Path) -> Result<(String, TextEncoding), TextError> {
    let not_text = |seen: String| TextError::NotText {
        path: path.to_path_buf(),
        seen,
        advice: RESAVE_ADVICE,
    };
    if bytes.starts_with(&[0xFF, 0xFE, 0, 0]) || bytes.starts_with(&[0, 0, 0xFE, 0xFF]) {
        return Err(not_text("the text is UTF-32".into()));
    }
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]) {
        return match std::str::from_utf8(rest) {
            Ok(text) => Ok((text.to_owned(), TextEncoding::Utf8Bom)),
            Err(e) => Err(not_text(format!(
                "the file starts with a UTF-8 byte-order mark but byte {} is not UTF-8",
                e.valid_up_to() + 3
            ))),
        };
    }
    for (bom, encoding, little) in [
        ([0xFF, 0xFE], TextEncoding::Utf16Le, true),
        ([0xFE, 0xFF], TextEncoding::Utf16Be, false),
    ] {
        if let Some(rest) = bytes.strip_prefix(&bom) {
            return decode_utf16(rest, little)
                .map(|text| (text, encoding))
                .ok_or_else(|| {
                    not_text(format!(
                        "the file starts with a {} byte-order mark but is not valid UTF-16 (odd \
                         length or an unpaired surrogate: truncated?)",
                        encoding.name()
                    ))
                });
        }
    }
    if let Some(kind) = binary_kind(bytes) {
        return Err(not_text(format!("this is {kind}, not a text file")));
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(not_text(if looks_like_utf16(bytes) {
            "the text looks like UTF-16 without a byte-order mark (every other byte is 0)".into()
        } else {
            format!("byte {at} is a NUL (0x00): this is binary data, not text")
        }));
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok((text.to_owned(), TextEncoding::Utf8)),
        Err(_) => Ok((
            bytes.iter().map(|&b| windows_1252(b)).collect(),
            TextEncoding::Windows1252,
        )),
    }
}

fn decode_utf16(bytes: &[u8], little: bool) -> Option<String> {
    if !bytes.len().is_multiple_of(2) {
        return None;
    }
    let units = bytes.chunks_exact(2).map(|p| {
        if little {
            u16::from_le_bytes([p[0], p[1]])
        } else {
            u16::from_be_bytes([p[0], p[1]])
        }
    });
    char::decode_utf16(units)
        .collect::<Result<String, _>>()
        .ok()
}

/// UTF-16 of ASCII text without a BOM: in the first 64 bytes, a zero at every even or every odd
/// offset (and no zero at the other parity).
fn looks_like_utf16(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(64) & !1];
    if head.len() < 4 {
        return false;
    }
    let zeros = |parity: usize| head.iter().skip(parity).step_by(2).all(|&b| b == 0);
    let none = |parity: usize| head.iter().skip(parity).step_by(2).all(|&b| b != 0);
    (zeros(0) && none(1)) || (zeros(1) && none(0))
}

/// Names a binary format from its first bytes.
fn binary_kind(bytes: &[u8]) -> Option<&'static str> {
    const KINDS: &[(&[u8], &str)] = &[
        (
            b"PK\x03\x04",
            "a ZIP archive (an Excel .xlsx or OpenDocument .ods workbook?)",
        ),
        (
            &[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1],
            "a legacy Office file (an Excel .xls workbook?)",
        ),
        (b"\x89PNG\r\n\x1a\n", "a PNG image"),
        (&[0xFF, 0xD8, 0xFF], "a JPEG image"),
        (b"II*\0", "a TIFF image"),
        (b"MM\0*", "a TIFF image"),
        (&[0x76, 0x2F, 0x31, 0x01], "an OpenEXR image"),
        (b"#?RADIANCE", "a Radiance HDR image"),
        (b"%PDF", "a PDF document"),
        (&[0x1F, 0x8B], "a gzip-compressed file"),
    ];
    KINDS
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map(|(_, kind)| *kind)
}

/// Windows-1252 byte → character: Latin-1 except 0x80–0x9F, which hold typographic characters.
fn windows_1252(b: u8) -> char {
    const HIGH: [char; 32] = [
        '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8D}', 'Ž',
        '\u{8F}', '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9D}',
        'ž', 'Ÿ',
    ];
    match b {
        0x80..=0x9F => HIGH[usize::from(b - 0x80)],
        _ => char::from(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(bytes: &[u8]) -> Result<DecodedText, TextError> {
        decode_text(bytes, Path::new("x.csv"))
    }

    fn utf16(text: &str, little: bool, bom: bool) -> Vec<u8> {
        let mut out = Vec::new();
        if bom {
            out.extend(if little { [0xFF, 0xFE] } else { [0xFE, 0xFF] });
        }
        for u in text.encode_utf16() {
            out.extend(if little {
                u.to_le_bytes()
            } else {
                u.to_be_bytes()
            });
        }
        out
    }

    #[test]
    fn accepted_encodings_decode_to_the_same_text() {
        let text = "# Probe grün, 23 °C\nwavelength_nm,sci,sce\r\n400,0.5,0.4\r\n";
        let plain = decode(text.as_bytes()).unwrap();
        assert_eq!(
            (plain.text.as_str(), plain.encoding),
            (text, TextEncoding::Utf8)
        );
        let bom = [&[0xEF, 0xBB, 0xBF][..], text.as_bytes()].concat();
        assert_eq!(decode(&bom).unwrap().text, text);
        for little in [true, false] {
            let d = decode(&utf16(text, little, true)).unwrap();
            assert_eq!(d.text, text);
        }
        // Latin-1 (ü = 0xFC, ° = 0xB0) and a Windows-1252 euro sign.
        let latin1: Vec<u8> = "# Probe gr\u{fc}n, 23 \u{b0}C \u{20ac}\n400,0.5,0.4\n"
            .chars()
            .map(|c| if c == '€' { 0x80 } else { c as u32 as u8 })
            .collect();
        let d = decode(&latin1).unwrap();
        assert_eq!(d.encoding, TextEncoding::Windows1252);
        assert_eq!(d.text, "# Probe grün, 23 °C €\n400,0.5,0.4\n");
    }

    #[test]
    fn refusals_name_what_was_seen_and_how_to_resave() {
        let msg = |bytes: &[u8]| decode(bytes).unwrap_err().to_string();
        let m = msg(&utf16("wavelength_nm,sci,sce\n", true, false));
        assert!(
            m.contains("UTF-16 without a byte-order mark") && m.contains("CSV UTF-8"),
            "{m}"
        );
        let m = msg(b"PK\x03\x04\x14\x00\x06\x00");
        assert!(m.contains("xlsx") && m.contains("CSV UTF-8"), "{m}");
        assert!(msg(&[0xFF, 0xFE, 0, 0, b'a', 0, 0, 0]).contains("UTF-32"));
        assert!(msg(&[0xFF, 0xFE, b'a']).contains("not valid UTF-16"));
        assert!(msg(b"abc\0def").contains("NUL"));
        assert!(msg(b"\x89PNG\r\n\x1a\n....").contains("PNG image"));
    }
}
