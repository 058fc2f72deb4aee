//! The checks of the image, the bracket and the manifest that no fit enters ([`image_checks`],
//! made once per measurement), the sample-wide findings they give every channel
//! ([`sample_checks`]), and the spot's size in the image against the fitted model's
//! ([`spot_scale`]).

use scatterfit_imaging::{CenterOptions, find_spot_center};
use scatterfit_io::quality::ReasonKind;
use scatterfit_optics::{Channel, OpticalProperties};

use super::ambient::ambient_light_reasons;
use super::evidence::{SpotScale, hwhm_of};
use super::findings::SampleChecks;
use super::frames::{
    black_level_reasons, bracket_reasons, code_reasons, compression_reasons,
    frame_agreement_reasons, registration_reasons,
};
use super::{
    MAX_LAB_DELTA_E, SECOND_SPOT_RATIO, SECOND_SPOT_Z, SPOT_FACTOR_RANGE, SPOT_SIZE_RATIO, suspect,
};
use crate::fit::outcome::ChannelOutcome;
use crate::measurement::Measurement;
use crate::settings::SpotShape;

/// The sample's checks: the spot inside the frame with its fitted rings complete (or cut
/// symmetrically), the measurement's image checks ([`Measurement::image_checks`], made once when
/// the bracket was merged), and the spot's size in the image against the one the fitted model
/// predicts at the manifest's scale ([`spot_scale`], made with the measurement:
/// [`Evidence::spot_scale`](super::evidence::Evidence::spot_scale)).
pub fn sample_checks(m: &Measurement) -> SampleChecks {
    let mut reasons = Vec::new();
    let radiance = &m.hdr.hdr.radiance;
    let [cx, cy] = m.profile.center.xy();
    let mmpp = m.profile.profile.mm_per_pixel;
    // (b) Rings complete to the fitted radius, or cut by the frame the same on both sides.
    let r_fit_px = m
        .fits
        .iter()
        .filter_map(ChannelOutcome::report)
        .flat_map(|r| r.fitted.iter().map(|f| f.r_mm / mmpp))
        .fold(0.0f64, f64::max);
    if let Some(msg) = incomplete_rings(radiance.width(), radiance.height(), [cx, cy], r_fit_px) {
        reasons.push(suspect(ReasonKind::IncompleteRings, msg));
    }
    reasons.extend(m.image_checks.reasons.iter().cloned());
    if let Some(scale) = m.evidence.spot_scale
        && !(SPOT_FACTOR_RANGE.0..=SPOT_FACTOR_RANGE.1).contains(&scale.factor)
        && scale.every_channel_agrees(scale.factor > 1.0)
    {
        let factor = scale.factor;
        reasons.push(suspect(
            ReasonKind::SpotSize,
            format!(
                "the spot in the image is {factor:.3}× the size the fitted model predicts for a \
                 {:.3} mm spot at {mmpp} mm per pixel (expected {}–{}; each channel alone: {}): \
                 camera.mm_per_pixel or camera.spot_diameter_mm is about {:.0} % off (the true \
                 scale is near {:.4} mm per pixel if the diameter is right); σ′s and σa scale \
                 with it",
                2.0 * m.settings.spot_radius_mm,
                SPOT_FACTOR_RANGE.0,
                SPOT_FACTOR_RANGE.1,
                scale
                    .channels
                    .iter()
                    .map(|c| c.map_or("–".into(), |f| format!("{f:.3}")))
                    .collect::<Vec<_>>()
                    .join(", "),
                100.0 * (1.0 / factor - 1.0),
                mmpp / factor,
            ),
        ));
    }
    SampleChecks { reasons }
}

/// The checks of the image, the bracket and the manifest that no fit enters: a given centre on
/// the spot, the codes the frames use, the black level, the frames registered, the bracket's
/// order and exposures, each frame against the merged radiance, the JPEG compression, the
/// manifest's L\*a\*b\* against its spectrum, one spot, and the spot's half width against the
/// manifest's scale. They read every frame's pixels, so a measurement makes them once
/// ([`Measurement::image_checks`]) and every refit of the same bracket keeps them.
pub fn image_checks(m: &Measurement) -> SampleChecks {
    let mut reasons = Vec::new();
    let radiance = &m.hdr.hdr.radiance;
    let [cx, cy] = m.profile.center.xy();
    let mmpp = m.profile.profile.mm_per_pixel;
    let a_px = m.settings.spot_radius_mm / mmpp;
    // A given centre must lie on the spot the image shows.
    if m.profile.center_source == crate::profile::CenterSource::Given
        && let Ok(found) = find_spot_center(radiance, &CenterOptions::default())
    {
        let [fx, fy] = found.xy();
        let d = (fx - cx).hypot(fy - cy);
        let tol = (0.5 * a_px).max(3.0);
        if d > tol {
            reasons.push(suspect(
                ReasonKind::CenterOffSpot,
                format!(
                    "the given spot centre ({cx:.1}, {cy:.1}) px is {d:.0} px from the spot the \
                     image shows at ({fx:.1}, {fy:.1}) px (more than {tol:.0} px): correct \
                     camera.center_px or drop it"
                ),
            ));
        }
    }
    // (e) The codes the frames use; (f) the frames registered.
    reasons.extend(code_reasons(m));
    if let Some(b) = &m.hdr.corrections.black_level_check {
        reasons.extend(black_level_reasons(b));
    }
    reasons.extend(registration_reasons(m));
    reasons.extend(bracket_reasons(m));
    reasons.extend(frame_agreement_reasons(m));
    reasons.extend(ambient_light_reasons(m));
    reasons.extend(compression_reasons(m));
    if let Some(msg) = lab_disagreement(m) {
        reasons.push(suspect(ReasonKind::LabDisagrees, msg));
    }
    // (d) Exactly one spot.
    if let Some(msg) = second_spot(m, a_px) {
        reasons.push(suspect(ReasonKind::SecondSpot, msg));
    }
    // (c) The spot's size in the image against the manifest's scale and spot: its half width at
    // half maximum (a disk's radius; a Gaussian's or a spot image's is well inside the radius
    // holding 99 % of its power, which the other checks use).
    let half_width_mm = m.settings.spot_half_width_mm();
    let hw_px = half_width_mm / mmpp;
    if let Some(hwhm) = spot_hwhm_px(m)
        && hw_px.is_finite()
        && hw_px > 0.0
    {
        let ratio = hwhm / hw_px;
        if !(SPOT_SIZE_RATIO.0..=SPOT_SIZE_RATIO.1).contains(&ratio) {
            let stated = match m.settings.spot {
                SpotShape::Disk => "spot_diameter_mm / 2".to_string(),
                SpotShape::Radial(_) => {
                    "the stated spot's half width at half maximum (camera.spot_diameter_mm \
                     with camera.spot_profile, or camera.spot_image)"
                        .to_string()
                }
            };
            reasons.push(suspect(
                ReasonKind::SpotSize,
                format!(
                    "the spot's half width in the image is {hwhm:.1} px, but {stated} / \
                     mm_per_pixel = {half_width_mm:.3} / {mmpp} = {hw_px:.1} px (ratio {ratio:.2}, \
                     expected {}–{}): check camera.mm_per_pixel and camera.spot_diameter_mm (a \
                     scale {:.2}× off makes σ′s and σa as many times off)",
                    SPOT_SIZE_RATIO.0, SPOT_SIZE_RATIO.1, ratio
                ),
            ));
        }
    }
    SampleChecks { reasons }
}

/// The manifest's L\*a\*b\* against the spectrum beside it ([`MAX_LAB_DELTA_E`]): the message
/// when they disagree, `None` when they agree or only one of them is given.
pub fn lab_disagreement(m: &Measurement) -> Option<String> {
    use scatterfit_optics::colour::{Lab, Observer, spectrum_to_xyz, xyz_to_lab};
    let [l, a, b] = m.manifest.spectro.lab?;
    let analysis = m.spectro.analysis.as_ref()?;
    let observer = match m.manifest.spectro.lab_observer {
        Some(2) => Observer::TwoDegree,
        _ => Observer::TenDegree,
    };
    let wl: Vec<f64> = analysis.spectral.iter().map(|p| p.wavelength_nm).collect();
    let lab_of = |values: Vec<f64>| -> Option<Lab> {
        spectrum_to_xyz(&wl, &values, observer)
            .ok()
            .map(|xyz| xyz_to_lab(xyz, observer.d65_white()))
    };
    let sce = lab_of(analysis.spectral.iter().map(|p| p.sce).collect())?;
    let sci = lab_of(analysis.spectral.iter().map(|p| p.sci).collect());
    // CIE 1976 colour difference ΔE*ab: the Euclidean distance in L*a*b*.
    let delta = |x: &Lab| ((x.l - l).powi(2) + (x.a - a).powi(2) + (x.b - b).powi(2)).sqrt();
    let (d_sce, d_sci) = (delta(&sce), sci.as_ref().map_or(f64::INFINITY, delta));
    let d = d_sce.min(d_sci);
    (d > MAX_LAB_DELTA_E).then(|| {
        format!(
            "spectro.lab = [{l}, {a}, {b}] is ΔE*ab {d:.1} from the colour of the spectrum in \
             the spectro file (SCE L*a*b* [{:.1}, {:.1}, {:.1}]{}; more than {MAX_LAB_DELTA_E}): \
             they are not one reading of one sample — α′ and σa follow the L*a*b*; check that \
             both are this sample's, or drop spectro.lab to use the spectrum",
            sce.l,
            sce.a,
            sce.b,
            sci.map_or(String::new(), |s| format!(
                ", SCI [{:.1}, {:.1}, {:.1}]",
                s.l, s.a, s.b
            )),
        )
    })
}

/// Whether rings to `r_fit_px` around `c` in a `w × h` frame are cut by its edges on one side
/// more than on the other (a spot near an edge or a corner). A centred spot whose outer rings are
/// cut the same on both sides keeps an unbiased ring mean; an off-centre one does not (its centre
/// is also found from a truncated image). Tolerance: 10 % of the nearer margin + 2 px.
pub fn incomplete_rings(w: usize, h: usize, c: [f64; 2], r_fit_px: f64) -> Option<String> {
    let [cx, cy] = c;
    let mut bad = Vec::new();
    for (axis, lo, hi) in [
        ("left/right", cx + 0.5, w as f64 - 0.5 - cx),
        ("top/bottom", cy + 0.5, h as f64 - 0.5 - cy),
    ] {
        let near = lo.min(hi);
        if r_fit_px > near && (lo - hi).abs() > 0.1 * near + 2.0 {
            bad.push(format!("{axis} margins {lo:.0} and {hi:.0} px"));
        }
    }
    (!bad.is_empty()).then(|| {
        format!(
            "the spot at ({cx:.1}, {cy:.1}) px lies off the frame's centre ({}) and the fit used \
             rings to {r_fit_px:.0} px, which the frame cuts on one side only: centre the spot \
             in the frame, or lower fit.r_max_px below the nearer margin",
            bad.join(", ")
        )
    })
}

/// The profile's half width at half maximum \[px\], on the channel sum (the first ring where the
/// sum falls below half the maximum of the first rings, linearly interpolated).
pub fn spot_hwhm_px(m: &Measurement) -> Option<f64> {
    let rings = &m.profile.profile.rings;
    let sum: Vec<f64> = rings
        .iter()
        .map(|r| r.channels.iter().map(|c| c.mean).sum())
        .collect();
    let radii: Vec<f64> = rings.iter().map(|r| r.r_px).collect();
    hwhm_of(&sum, &radii)
}

/// A second spot: pixels (channel sum) well above their ring's median (a spot on a ring leaves its
/// median alone; [`SECOND_SPOT_RATIO`], [`SECOND_SPOT_Z`]), away from the spot (beyond 3 spot
/// radii), on rings whose median is well above the detection limit, with at least 6 of their 8
/// neighbours nearly as far above (not a hot pixel). Returns the message for the brightest.
fn second_spot(m: &Measurement, a_px: f64) -> Option<String> {
    let img = &m.hdr.hdr.radiance;
    let prof = &m.profile.profile;
    let width = prof.options.ring_width_px();
    let n_rings = prof.rings.len();
    let [cx, cy] = m.profile.center.xy();
    let ch = img.channels();
    let (w, h) = (img.width(), img.height());
    let limit: f64 = m
        .profile
        .detection_limit
        .iter()
        .map(|l| if l.is_finite() { *l } else { 0.0 })
        .sum();
    let ring_of =
        |x: usize, y: usize| -> usize { ((x as f64 - cx).hypot(y as f64 - cy) / width) as usize };
    let value = |x: usize, y: usize| -> f64 {
        img.pixel(x, y).map_or(f64::NAN, |p| {
            p.iter().take(ch).map(|&v| f64::from(v)).sum::<f64>()
        })
    };
    let mut per_ring: Vec<Vec<f64>> = vec![Vec::new(); n_rings];
    for y in 0..h {
        for x in 0..w {
            let k = ring_of(x, y);
            let v = value(x, y);
            if k < n_rings && v.is_finite() {
                per_ring[k].push(v);
            }
        }
    }
    // Per ring: the median and the robust spread (1.4826 × the median absolute deviation).
    let stats: Vec<(f64, f64)> = per_ring
        .into_iter()
        .map(|mut v| {
            if v.len() < 8 {
                return (f64::NAN, f64::NAN);
            }
            let mid = v.len() / 2;
            let med = *v.select_nth_unstable_by(mid, f64::total_cmp).1;
            let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
            let mad = *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
            if med > 3.0 * limit && med > 0.0 {
                (med, 1.4826 * mad)
            } else {
                (f64::NAN, f64::NAN)
            }
        })
        .collect();
    // (ratio to the ring's median, robust z-score) of a pixel.
    let score = |x: usize, y: usize| -> (f64, f64) {
        stats
            .get(ring_of(x, y))
            .map_or((f64::NAN, f64::NAN), |&(med, spread)| {
                let v = value(x, y);
                (v / med, (v - med) / spread.max(1e-3 * med))
            })
    };
    let spot_like = |(q, z): (f64, f64), strict: bool| -> bool {
        if strict {
            q >= SECOND_SPOT_RATIO && z >= SECOND_SPOT_Z
        } else {
            q >= 1.0 + 0.6 * (SECOND_SPOT_RATIO - 1.0) && z >= 0.6 * SECOND_SPOT_Z
        }
    };
    let r_min = (3.0 * a_px).max(6.0);
    let mut best: Option<(f64, usize, usize)> = None;
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            if (x as f64 - cx).hypot(y as f64 - cy) < r_min {
                continue;
            }
            let sc = score(x, y);
            if !spot_like(sc, true) || best.is_some_and(|(b, ..)| sc.0 <= b) {
                continue;
            }
            let bright = [
                (0, 0),
                (1, 0),
                (2, 0),
                (0, 1),
                (2, 1),
                (0, 2),
                (1, 2),
                (2, 2),
            ]
            .iter()
            .filter(|&&(dx, dy)| spot_like(score(x + dx - 1, y + dy - 1), false))
            .count();
            if bright >= 6 {
                best = Some((sc.0, x, y));
            }
        }
    }
    best.map(|(q, x, y)| {
        let d = (x as f64 - cx).hypot(y as f64 - cy);
        format!(
            "a second bright spot at ({x}, {y}) px, {d:.0} px from the spot centre ({cx:.1}, \
             {cy:.1}): {q:.1}× its ring's median (a reflection off the rig, a second light?); \
             the rings through it are not the sample's profile — remove it and measure again"
        )
    })
}

/// The ratio of the image's spot half width to the one the fitted model predicts at the stated
/// scale and spot ([`crate::checks::SPOT_FACTOR_RANGE`]): each fitted channel's model (convolved
/// with the spot, × its fitted scale) averaged over the same rings as the image (8 radii per
/// ring, equal areas), the channels summed as the image's half width is measured
/// ([`crate::checks::spot_hwhm_px`]), and each channel alone. About mm_per_pixel(stated) /
/// mm_per_pixel(true): 0.91 for a scale stated 10 % too large. With an approximate model the
/// exact fit of the same data ([`crate::fit::ExactFit`]) predicts the spot instead: a
/// diffusion model's near field, inside the spot, is its least accurate part (the dipole's spot
/// on red aluminium is 2.6× too wide). `None` without three fitted channels or a half width.
pub fn spot_scale(m: &Measurement) -> Option<SpotScale> {
    let rings = &m.profile.profile.rings;
    let mmpp = m.profile.profile.mm_per_pixel;
    if !(mmpp.is_finite() && mmpp > 0.0) {
        return None;
    }
    let spot = m.settings.options().ok()?.spot;
    let exact = m.settings.model == scatterfit_optics::ModelName::Mc;
    let family = scatterfit_mc::family(scatterfit_optics::ModelName::Mc).ok()?;
    let model = scatterfit_optics::AtG::new(family, m.settings.g).ok()?;
    const SUB: usize = 8;
    let radii: Vec<f64> = rings
        .iter()
        .flat_map(|ring| {
            let (a2, b2) = (ring.r_inner_px.powi(2), ring.r_outer_px.powi(2));
            (0..SUB).map(move |j| mmpp * (a2 + (j as f64 + 0.5) / SUB as f64 * (b2 - a2)).sqrt())
        })
        .collect();
    let r_px: Vec<f64> = rings.iter().map(|r| r.r_px).collect();
    let mut props = Vec::with_capacity(3);
    let mut scales = Vec::with_capacity(3);
    for c in Channel::ALL {
        let f = m.fits[c].fit().filter(|f| f.report.converged)?;
        let (s, a, scale) = if exact {
            let r = &f.report;
            (r.sigma_s_prime.value, r.sigma_a.value, r.scale.value)
        } else {
            let x = f.exact?;
            (x.sigma_s_prime, x.sigma_a, x.scale)
        };
        props.push(OpticalProperties::new(s, a, m.spectro.eta).ok()?);
        scales.push(scale);
    }
    // One spot kernel for the three channels (same rings, same spot).
    let per_channel: Vec<Vec<f64>> = scatterfit_fit::model_profiles(&model, &props, spot, &radii)
        .ok()?
        .into_iter()
        .zip(scales)
        .map(|(values, scale)| {
            values
                .chunks(SUB)
                .map(|chunk| scale * chunk.iter().sum::<f64>() / SUB as f64)
                .collect()
        })
        .collect();
    let sum: Vec<f64> = (0..rings.len())
        .map(|k| per_channel.iter().map(|v| v[k]).sum())
        .collect();
    let factor = crate::checks::spot_hwhm_px(m)? / hwhm_of(&sum, &r_px)?;
    let channels = std::array::from_fn(|c| {
        let data: Vec<f64> = rings
            .iter()
            .map(|r| r.channels.get(c).map_or(f64::NAN, |x| x.mean))
            .collect();
        Some(hwhm_of(&data, &r_px)? / hwhm_of(&per_channel[c], &r_px)?)
    });
    Some(SpotScale { factor, channels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_centred_spot_cut_on_both_sides_is_complete_an_off_centre_one_is_not() {
        assert!(incomplete_rings(256, 256, [130.2, 128.8], 180.0).is_none());
        assert!(incomplete_rings(1024, 1024, [512.0, 511.0], 300.0).is_none());
        assert!(incomplete_rings(158, 158, [32.2, 30.8], 170.0).is_some());
        assert!(incomplete_rings(143, 256, [18.0, 128.8], 100.0).is_some());
        // Rings inside the nearer margin are complete wherever the spot is.
        assert!(incomplete_rings(143, 256, [18.0, 128.8], 15.0).is_none());
    }
}
