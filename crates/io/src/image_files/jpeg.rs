//! The compression level a JPEG file was saved at, from its header.

/// ITU-T T.81 Annex K, Table K.1 (the luminance quantisation table), in the zig-zag order a DQT
/// segment stores.
const K1_ZIGZAG: [u16; 64] = [
    16, 11, 12, 14, 12, 10, 16, 14, 13, 14, 18, 17, 16, 19, 24, 40, 26, 24, 22, 22, 24, 49, 35, 37,
    29, 40, 58, 51, 61, 60, 57, 51, 56, 55, 64, 72, 92, 78, 64, 68, 87, 69, 55, 56, 80, 109, 81,
    87, 95, 98, 103, 104, 103, 62, 77, 113, 121, 112, 100, 120, 92, 101, 103, 99,
];

/// The IJG quality of a baseline JPEG's first (luminance) quantisation table: the integer quality
/// whose libjpeg table it is, entry for entry (libjpeg, Pillow and most encoders write those); for
/// any other table the mean ratio S of
/// its entries to the standard table of ITU-T T.81 Annex K (Table K.1) in percent, and quality
/// (200 − S)/2 for S ≤ 100, 5000/S above (libjpeg's `jpeg_quality_scaling`, inverted). `None` for
/// bytes that are not a JPEG or whose table is not among the segments before the scan.
/// Hand-written: the image crate decodes JPEGs but does not expose their quantisation tables.
#[must_use]
pub fn jpeg_quality(bytes: &[u8]) -> Option<f64> {
    if bytes.get(..2)? != [0xFF, 0xD8] {
        return None;
    }
    let mut i = 2;
    while i + 4 <= bytes.len() {
        if bytes[i] != 0xFF {
            return None;
        }
        let marker = bytes[i + 1];
        let len = usize::from(u16::from_be_bytes([bytes[i + 2], bytes[i + 3]]));
        if marker == 0xDB {
            let seg = bytes.get(i + 4..i + 2 + len)?;
            let (pq, tq) = (seg.first()? >> 4, seg.first()? & 0x0F);
            if tq != 0 {
                i += 2 + len;
                continue;
            }
            let q: Vec<u16> = if pq == 0 {
                seg.get(1..65)?.iter().map(|&v| u16::from(v)).collect()
            } else {
                seg.get(1..129)?
                    .chunks(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]))
                    .collect()
            };
            // libjpeg's own tables (`jpeg_set_quality`, baseline) at an integer quality: read
            // exactly (the mean ratio below puts its quality 75 at 74.7: each odd entry of K.1
            // rounds up).
            if let Some(exact) = (1..=100u32).find(|&quality| {
                let scale = if quality < 50 {
                    5000 / quality
                } else {
                    200 - 2 * quality
                };
                q.iter().zip(K1_ZIGZAG).all(|(&a, b)| {
                    u32::from(a) == ((u32::from(b) * scale + 50) / 100).clamp(1, 255)
                })
            }) {
                return Some(f64::from(exact));
            }
            let s = 100.0
                * q.iter()
                    .zip(K1_ZIGZAG)
                    .map(|(&a, b)| f64::from(a) / f64::from(b))
                    .sum::<f64>()
                / 64.0;
            return Some(if s <= 100.0 {
                (200.0 - s) / 2.0
            } else {
                5000.0 / s
            });
        }
        if marker == 0xDA {
            return None;
        }
        i += 2 + len;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A JPEG header whose luminance table libjpeg's `jpeg_quality_scaling` made for quality q
    /// (S = 5000/q below 50, 200 − 2q above; entries (K.1 · S + 50) / 100, at least 1) reads
    /// back as q exactly; a PNG, or a JPEG without a table, reads as none.
    #[test]
    fn the_jpeg_quality_comes_back_from_the_quantisation_table() {
        for q in [30u32, 50, 75, 90, 95] {
            let s = if q < 50 { 5000 / q } else { 200 - 2 * q };
            let mut bytes = vec![0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0x00, 0x00];
            bytes.extend([0xFF, 0xDB, 0x00, 67, 0x00]);
            bytes.extend(K1_ZIGZAG.map(|k| ((u32::from(k) * s + 50) / 100).clamp(1, 255) as u8));
            bytes.extend([0xFF, 0xDA, 0x00, 0x02]);
            assert_eq!(jpeg_quality(&bytes), Some(f64::from(q)));
            // A table of no libjpeg quality (every entry one step coarser) reads by its mean
            // ratio, within the table's rounding.
            let at = bytes.len() - 4 - 64;
            for b in &mut bytes[at..at + 64] {
                *b = b.saturating_add(1);
            }
            let got = jpeg_quality(&bytes).unwrap();
            assert!((got - f64::from(q)).abs() < 5.0, "quality {q}: read {got}");
        }
        assert_eq!(jpeg_quality(b"\x89PNG\r\n\x1a\n...."), None);
        assert_eq!(jpeg_quality(&[0xFF, 0xD8, 0xFF, 0xDA, 0x00, 0x02]), None);
        // A segment length running past the end is no table, not a panic.
        assert_eq!(
            jpeg_quality(&[0xFF, 0xD8, 0xFF, 0xDB, 0xFF, 0xFF, 0x00]),
            None
        );
    }

    /// A real encoder's output: the image crate's JPEG encoder at quality 60 and 92 reads back
    /// within the table's rounding.
    #[test]
    fn an_encoded_jpeg_reads_back_its_quality() {
        use image::ImageEncoder;
        let pixels: Vec<u8> = (0..64 * 64 * 3).map(|i| (i * 7 % 251) as u8).collect();
        for q in [60u8, 92] {
            let mut out = Vec::new();
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, q)
                .write_image(&pixels, 64, 64, image::ExtendedColorType::Rgb8)
                .unwrap();
            let got = jpeg_quality(&out).unwrap();
            assert!((got - f64::from(q)).abs() < 2.5, "quality {q}: read {got}");
        }
    }
}
