//! Times the 13 × 24 MP merge and the 24 MP profile by wall clock *and* process CPU time (from
//! /proc/self/stat), so figures taken on a shared, busy machine can be told apart from contention,
//! and reports peak resident memory (VmHWM) against the decoded bracket's size.
//!
//! Run: `cargo run --release -p scatterfit-imaging --example merge_cpu_time`

use std::time::Instant;

use scatterfit_imaging::{
    ImageBuf, MergeOptions, ProfileOptions, ResponseCurve, merge, radial_profile,
};

fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // utime and stime are fields 14 and 15 of stat, i.e. 11 and 12 after the command name.
    (ticks(11) + ticks(12)) / 100.0
}

fn vm_hwm_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(0.0)
        / 1024.0
}

fn main() {
    let (w, h) = (6000, 4000);
    let times: Vec<f64> = (0..13)
        .map(|j| (1.0 / 600.0) * 1800f64.powf(j as f64 / 12.0))
        .collect();
    // Cheap synthetic codes (the content does not change the merge's cost).
    let frames: Vec<ImageBuf<u8>> = (0..13)
        .map(|j| {
            let data = (0..w * h * 3)
                .map(|i| ((i * 7 + j * 31 + i / 6001) % 256) as u8)
                .collect();
            ImageBuf::new(w, h, 3, data).unwrap()
        })
        .collect();
    let bracket_mb = (13 * w * h * 3) as f64 / 1e6 / 1.048576;
    let before = vm_hwm_mb();
    let g = std::array::from_fn(|z| 2.2 * ((z.max(1) as f64) / 128.0).ln());
    let resp = ResponseCurve::from_log_exposure(vec![g; 3]).unwrap();
    let threads = rayon::current_num_threads();
    for _ in 0..3 {
        let (t0, c0) = (Instant::now(), cpu_s());
        let hdr = merge(&frames, &times, &resp, None, &MergeOptions::default()).unwrap();
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_s() - c0);
        println!(
            "merge 13×24 MP RGB: wall {wall:.3} s, CPU {cpu:.2} s ({threads} threads), clipped {}",
            hdr.clipped_count
        );
        let t0 = Instant::now();
        let img = &hdr.radiance;
        let p =
            radial_profile(img, [3000.3, 2000.7], None, 0.1, &ProfileOptions::default()).unwrap();
        println!(
            "profile 24 MP, r_max 300: wall {:.2} ms ({} rings)",
            t0.elapsed().as_secs_f64() * 1e3,
            p.rings.len()
        );
    }
    println!(
        "decoded bracket {bracket_mb:.0} MiB; peak RSS before merging {before:.0} MiB, after {:.0} MiB \
         ({:.2}× the bracket)",
        vm_hwm_mb(),
        vm_hwm_mb() / bracket_mb
    );
}
