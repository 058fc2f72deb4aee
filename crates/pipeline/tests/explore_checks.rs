//! Exploration (temporary): the cases on a quick twin, before any check.
use std::path::Path;

use scatterfit_io::image_files::{CameraFrame, write_camera_frame};
use scatterfit_io::sample_folder::{SampleFiles, write_sample_folder};
use scatterfit_pipeline::{Overrides, measure_sample};
use scatterfit_synth::materials::by_name;
use scatterfit_synth::mishaps;
use scatterfit_synth::{CameraModel, RigSpec, synthesize};
use scatterfit_imaging::ImageBuf;

fn write(dir: &Path, s: &scatterfit_synth::SyntheticSample, frames: &[ImageBuf<u8>], times: &[f64], mmpp: f64) {
    write_sample_folder(dir, &SampleFiles {
        name: "x", reading: &s.reading, lab10: None, frames, times_s: times,
        mm_per_pixel: mmpp, spot_diameter_mm: 1.0, truth_json: None, provenance: "t", fit: Default::default(),
    }).unwrap();
}

fn report(label: &str, dir: &Path, truth: [f64; 3]) {
    match measure_sample(dir, &Overrides::default(), &|_| {}) {
        Ok(m) => {
            let r = m.to_result(None);
            let mut line = format!("{label:28} c=({:.1},{:.1})", m.profile.center.x(), m.profile.center.y());
            for (c, ch) in r.channels.as_array().iter().enumerate() {
                line += &format!(" | {:?} {:+.0}% rms {:.3} chi2 {:.0} n{}", ch.status,
                    100.0 * (ch.sigma_s_prime.unwrap_or(f64::NAN) / truth[c] - 1.0),
                    ch.rms_log_residual.unwrap_or(f64::NAN), ch.chi2_reduced.unwrap_or(f64::NAN), ch.rings_used);
            }
            println!("{line}");
        }
        Err(e) => println!("{label:28} ERROR {e}"),
    }
}

#[test]
#[ignore]
fn explore() {
    let root = Path::new("/tmp/ck/explore");
    let _ = std::fs::remove_dir_all(root);
    std::fs::create_dir_all(root).unwrap();
    let cache = Path::new("/tmp/ck/cache");
    let rig = RigSpec::quick();
    let cam = CameraModel::default();
    for name in ["wood-tile", "pink-plastic", "nephrite"] {
        let m = by_name(name).unwrap();
        let s = synthesize(m.name, m.sigma_s_prime, m.sigma_a, m.eta, &rig, 1, Some(cache), &|_, _, _| {}).unwrap();
        let f = &s.bracket.frames;
        let t = &s.bracket.times_s;
        println!("== {name} centre {:?}", s.bracket.center_px);
        let d = root.join(format!("{name}-good")); write(&d, &s, f, t, 0.1); report("good", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-corner")); write(&d, &s, &mishaps::crop(f, 98, 98, 158, 158), t, 0.1); report("corner (30px)", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-edge")); write(&d, &s, &mishaps::crop(f, 113, 0, 143, 256), t, 0.1); report("edge (15px)", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-half")); write(&d, &s, &mishaps::crop(f, 128, 0, 128, 256), t, 0.1); report("half outside", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-quarter")); write(&d, &s, &mishaps::crop(f, 128, 128, 128, 128), t, 0.1); report("corner quarter", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-two")); write(&d, &s, &mishaps::second_spot(f, &cam, 60, 20, 1.0), t, 0.1); report("two spots 63px", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-two-weak")); write(&d, &s, &mishaps::second_spot(f, &cam, 60, 20, 0.1), t, 0.1); report("two spots 0.1", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-bump")); write(&d, &s, &mishaps::bump(f, 6, 8, 0), t, 0.1); report("bump 8px at 6", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-mm10")); write(&d, &s, f, t, 1.0); report("mm_per_pixel 10x", &d, m.sigma_s_prime);
        let d = root.join(format!("{name}-mm01")); write(&d, &s, f, t, 0.01); report("mm_per_pixel 0.1x", &d, m.sigma_s_prime);
        let two: Vec<_> = vec![f[0].clone(), f[12].clone()];
        let d = root.join(format!("{name}-2frames")); write(&d, &s, &two, &[t[0], t[12]], 0.1); report("2 frames 1/600-3", &d, m.sigma_s_prime);
        let mut wrong = t.clone(); for (k, v) in wrong.iter_mut().enumerate() { *v = t[0] * (1.0 + k as f64); }
        let d = root.join(format!("{name}-times-lin")); write(&d, &s, f, &wrong, 0.1); report("times linear", &d, m.sigma_s_prime);
        let mut wrong = t.clone(); wrong[6] *= 1.8; wrong[6] = wrong[6].min(t[7]*0.99);
        let d = root.join(format!("{name}-times-one")); write(&d, &s, f, &wrong, 0.1); report("time 6 off", &d, m.sigma_s_prime);
        let wrong: Vec<f64> = t.iter().map(|v| v.powf(0.7)).collect();
        let d = root.join(format!("{name}-times-pow")); write(&d, &s, f, &wrong, 0.1); report("times^0.7", &d, m.sigma_s_prime);
        for (label, fr) in [("12-in-16 low", mishaps::linear_u16(f, &cam, 12, mishaps::Alignment::Low)),
                            ("12-in-16 high", mishaps::linear_u16(f, &cam, 12, mishaps::Alignment::High)),
                            ("16-bit", mishaps::linear_u16(f, &cam, 16, mishaps::Alignment::Low)),
                            ("8-in-16 x257", mishaps::scaled_to_u16(f)),
                            ("8-in-16 low", mishaps::linear_u16(f, &cam, 8, mishaps::Alignment::Low))] {
            let d = root.join(format!("{name}-{}", label.replace(' ', "_")));
            write(&d, &s, f, t, 0.1);
            for (j, fr) in fr.iter().enumerate() {
                write_camera_frame(&d.join(format!("frame_{j:02}.png")), &CameraFrame::U16(fr.clone())).unwrap();
            }
            report(label, &d, m.sigma_s_prime);
        }
    }
}

fn hwhm_px(m: &scatterfit_pipeline::Measurement, c: usize) -> f64 {
    let rings = &m.profile.profile.rings;
    let peak = rings[0].channels[c].mean;
    for k in 1..rings.len() {
        let v = rings[k].channels[c].mean;
        if v < 0.5 * peak {
            let u = rings[k - 1].channels[c].mean;
            let (r0, r1) = (rings[k - 1].r_px, rings[k].r_px);
            return r0 + (u - 0.5 * peak) / (u - v) * (r1 - r0);
        }
    }
    f64::NAN
}

fn model_hwhm_mm(m: &scatterfit_pipeline::Measurement, c: usize) -> f64 {
    use scatterfit_optics::OpticalProperties;
    let Some(r) = m.fits[c].report() else { return f64::NAN };
    let props = OpticalProperties::new(r.sigma_s_prime.value, r.sigma_a.value, r.eta).unwrap();
    let a = m.settings.spot_radius_mm;
    let radii: Vec<f64> = (0..4000).map(|i| i as f64 * a / 200.0).collect();
    let fam = scatterfit_pipeline::family(m.settings.model).unwrap();
    let v = scatterfit_fit::model_profile(fam, &props, scatterfit_fit::Spot::Disk { radius_mm: a }, &radii).unwrap();
    let peak = v[0];
    radii.iter().zip(&v).find(|&(_, &y)| y < 0.5 * peak).map_or(f64::NAN, |(r, _)| *r)
}

#[test]
#[ignore]
fn explore_spot_size() {
    let root = Path::new("/tmp/ck/explore-size");
    let _ = std::fs::remove_dir_all(root);
    std::fs::create_dir_all(root).unwrap();
    let cache = Path::new("/tmp/ck/cache");
    for (rigname, rig) in [("quick", RigSpec::quick()), ("paper", RigSpec::paper())] {
    for m in scatterfit_synth::materials::all() {
        let s = synthesize(m.name, m.sigma_s_prime, m.sigma_a, m.eta, &rig, 1, Some(cache), &|_, _, _| {}).unwrap();
        for scale in [1.0, 10.0, 0.1, 2.0, 0.5] {
            let d = root.join(format!("{rigname}-{}-{scale}", m.name));
            write(&d, &s, &s.bracket.frames, &s.bracket.times_s, rig.mm_per_pixel * scale);
            let meas = measure_sample(&d, &Overrides::default(), &|_| {}).unwrap();
            let mut line = format!("{rigname} {:14} ×{scale:<4}", m.name);
            for c in 0..3 {
                let h = hwhm_px(&meas, c) * rig.mm_per_pixel * scale / 0.5;
                let hm = model_hwhm_mm(&meas, c) / 0.5;
                line += &format!(" | meas {h:6.2} model {hm:6.2} ratio {:5.2}", h / hm);
            }
            println!("{line}");
        }
    }
    }
}
