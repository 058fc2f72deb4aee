//! The detection limit per channel: the lowest code whose reading is told from noise, from pairs
//! of frames one exposure step apart.

use super::*;

/// The pixels [`PairCounts`] counts per frame pair: every s-th pixel in raster order, s the smallest
/// step that leaves at most this many (every pixel of a smaller frame). A code's scatter is judged
/// where at least 50 pixels read it; 65 536 pixels of a bracket's pairs give that for the codes
/// the scene fills.
pub(crate) const DETECTION_PIXELS: usize = 65_536;

/// The code pairs of consecutive frames that [`detection_codes`] reads, counted once for the
/// bracket: per channel and pair of frames (j, j + 1), how many pixels read (z_j, z_{j+1}), both
/// unclipped (neither 0 nor 255), over at most [`DETECTION_PIXELS`] pixels per frame pair (every
/// s-th pixel in raster order). The counts depend on the codes alone, so the response's rounds
/// reuse them.
pub(super) struct PairCounts {
    /// Per channel, per pair: the code pairs met and how often, (z_j, z_{j+1}, count), z_j
    /// ascending.
    cells: Vec<Vec<Vec<(u8, u8, u32)>>>,
}

impl PairCounts {
    pub(super) fn new(bufs: &[ImageBuf<u8>]) -> Self {
        use rayon::prelude::*;
        let ch = bufs[0].channels();
        let pairs = bufs.len().saturating_sub(1);
        let flat: Vec<Vec<(u8, u8, u32)>> = (0..ch * pairs)
            .into_par_iter()
            .map(|task| {
                let (c, j) = (task / pairs.max(1), task % pairs.max(1));
                let (a, b) = (bufs[j].data(), bufs[j + 1].data());
                let step = (a.len() / ch).div_ceil(DETECTION_PIXELS).max(1);
                let mut count = vec![0u32; 256 * 256];
                for i in (c..a.len()).step_by(ch * step) {
                    let (z1, z2) = (a[i], b[i]);
                    if z1 == 0 || z2 == u8::MAX || z1 == u8::MAX || z2 == 0 {
                        continue;
                    }
                    count[usize::from(z1) * 256 + usize::from(z2)] += 1;
                }
                count
                    .iter()
                    .enumerate()
                    .filter(|(_, n)| **n > 0)
                    .map(|(cell, &n)| ((cell / 256) as u8, (cell % 256) as u8, n))
                    .collect()
            })
            .collect();
        let mut cells: Vec<Vec<Vec<(u8, u8, u32)>>> = vec![Vec::with_capacity(pairs); ch];
        for (task, v) in flat.into_iter().enumerate() {
            cells[task / pairs.max(1)].push(v);
        }
        Self { cells }
    }
}

/// Per channel, the lowest code from [`DETECTION_CODE`] up from which the linearised signal's
/// relative noise stays within 1/[`DETECTION_SNR`] (codes 30–200 checked), measured on the bracket
/// itself in the manner of the photon-transfer method, which reads a sensor's noise from pairs of
/// frames (Janesick 2007, *Photon Transfer DN → λ*, SPIE Press, ch. 4): for every pair
/// of consecutive frames (exposure ratio k) and every pixel unclipped in both, q = ln X(z_{j+1}) −
/// ln X(z_j) − ln k; its scatter about its mean among the pixels with code z in the shorter frame
/// is σ²(z) + σ²(z_{j+1}) ≈ σ²(z)(1 + 1/k) for shot noise (the brighter reading's relative
/// variance a factor k smaller; for read noise it is 1 + 1/k², so σ is then overestimated by
/// ≤ 8 % for k ≈ 1.9), so σ²(z) = var(q | z)/(1 + 1/k). Codes with fewer than 50 pairs are
/// skipped; the pixels read are those of [`PairCounts`] (q depends on the two codes only, so
/// each code pair's q is weighted by its count).
pub(super) fn detection_codes(
    counts: &PairCounts,
    times: &[f64],
    response: &ResponseCurve,
) -> Vec<u8> {
    use rayon::prelude::*;
    counts
        .cells
        .par_iter()
        .enumerate()
        .map(|(c, pairs)| {
            let g = &response.tables()[if response.channels() == 1 { 0 } else { c }];
            let (mut n, mut s1, mut s2) = ([0f64; 256], [0f64; 256], [0f64; 256]);
            let mut kk = 0.0f64;
            let mut n_pairs = 0.0f64;
            for (j, cells) in pairs.iter().enumerate() {
                let ln_k = (times[j + 1] / times[j]).ln();
                kk += ln_k;
                n_pairs += 1.0;
                for &(z1, z2, m) in cells {
                    let q = g[usize::from(z2)] - g[usize::from(z1)] - ln_k;
                    let (z, m) = (usize::from(z1), f64::from(m));
                    n[z] += m;
                    s1[z] += m * q;
                    s2[z] += m * q * q;
                }
            }
            let k = (kk / n_pairs.max(1.0)).exp();
            let limit = 1.0 / (DETECTION_SNR * DETECTION_SNR);
            let ok = |z: usize| {
                if n[z] < 50.0 {
                    return None;
                }
                let m = s1[z] / n[z];
                let var = (s2[z] / n[z] - m * m).max(0.0) / (1.0 + 1.0 / k);
                Some(var <= limit)
            };
            // The lowest code from DETECTION_CODE up above which no measured code is too noisy.
            let mut code = DETECTION_CODE;
            for z in usize::from(DETECTION_CODE)..=200 {
                if ok(z) == Some(false) {
                    code = (z + 1) as u8;
                }
            }
            code
        })
        .collect()
}
