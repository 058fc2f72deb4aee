//! Prints the cross-checks behind each sample's verdict (`checks::evidence`, the frame
//! agreement): the numbers the thresholds in `checks` are set against.
//!
//! `cargo run --release -p scatterfit-pipeline --example evidence -- DIR...`

use scatterfit_pipeline::checks::{frame_agreement, spot_scale};
use scatterfit_pipeline::{Channel, Overrides, measure_sample};

fn main() {
    for dir in std::env::args().skip(1) {
        let m = match measure_sample(std::path::Path::new(&dir), &Overrides::default(), &|_| {}) {
            Ok(m) => m,
            Err(e) => {
                println!("{dir}: {e}");
                continue;
            }
        };
        let q = m.quality();
        println!(
            "{dir}: spot factor {:?}; verdicts {} {} {}",
            spot_scale(&m),
            q.r.verdict,
            q.g.verdict,
            q.b.verdict
        );
        for c in Channel::ALL {
            if let Some(a) = m.evidence.albedo[c] {
                println!(
                    "  {}: α′ profile {:.5} (se_ln {:.3}) spectro {:.5} (se_ln {:.3}) z {:.1} χ² {:.2} / {:.2}",
                    c.name(),
                    a.profile,
                    a.profile_se_ln,
                    a.spectro,
                    a.spectro_se_ln,
                    a.z,
                    a.chi2_proposed,
                    a.chi2_profile
                );
            }
        }
        if let Some(frames) = frame_agreement(&m) {
            let line: Vec<String> = frames
                .iter()
                .map(|f| format!("{}:{:+.3}/{:.3}", f.frame, f.offset_ln, f.spread_ln))
                .collect();
            println!("  frames (offset/spread ln): {}", line.join(" "));
        }
        for c in Channel::ALL {
            for r in &q[c].reasons {
                println!("  {} {:?}: {}", c.name(), r.kind, r.message);
            }
        }
    }
}
