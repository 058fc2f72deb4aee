//! SHA-256 of the bytes an input was read from: the readers hash what they decode, so a record of
//! an input (`result.json`'s `inputs`) names the bytes that were measured, not the file as it is
//! later.

use std::path::PathBuf;

use sha2::{Digest, Sha256};

/// SHA-256 of `bytes`, 64 lower-case hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut hex = String::with_capacity(2 * digest.len());
    for b in digest {
        hex.push(char::from(HEX[usize::from(b >> 4)]));
        hex.push(char::from(HEX[usize::from(b & 0xF)]));
    }
    hex
}

const HEX: &[u8; 16] = b"0123456789abcdef";

/// A file as it was read: its path and the SHA-256 of the bytes read ([`sha256_hex`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadFile {
    /// The path it was read from.
    pub path: PathBuf,
    /// SHA-256 of the bytes read, lower-case hex.
    pub sha256: String,
}

impl ReadFile {
    /// The record of `bytes` read from `path`.
    pub fn of(path: impl Into<PathBuf>, bytes: &[u8]) -> Self {
        Self {
            path: path.into(),
            sha256: sha256_hex(bytes),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FIPS 180-2's test vectors, in the lower-case hex `result.json` records.
    #[test]
    fn sha256_hex_matches_the_standard_vectors() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let r = ReadFile::of("a/b.png", b"abc");
        assert_eq!(r.path, PathBuf::from("a/b.png"));
        assert_eq!(r.sha256, sha256_hex(b"abc"));
    }
}
