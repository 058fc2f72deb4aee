//! Writing a manifest: `manifest_to_toml` (every key the reader takes, commented) and
//! `write_manifest` (atomically).

use super::*;

pub(super) fn toml_string(s: &str) -> String {
    // A TOML basic string: JSON's escaping is a subset TOML accepts.
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

pub(super) fn toml_path(p: &Path) -> String {
    toml_string(&p.to_string_lossy())
}

/// The manifest as TOML with the comments of the format's documentation, for a folder a person
/// will read (e.g. one written by `scatterfit synth`). `extra_comment` lines go at the top.
pub fn manifest_to_toml(m: &SampleManifest, extra_comment: &str) -> String {
    let mut t = String::new();
    for line in extra_comment.lines() {
        t.push_str(&format!("# {line}\n"));
    }
    if let Some(n) = &m.name {
        t.push_str(&format!("name = {}\n", toml_string(n)));
    }
    t.push_str("\n[spectro]\n");
    if let Some(f) = &m.spectro.file {
        t.push_str(&format!(
            "file = {}          # header: wavelength_nm,sci,sce (fractions 0..1)\n",
            toml_path(f)
        ));
    }
    if let Some([l, a, b]) = m.spectro.lab {
        t.push_str(&format!("lab = [{l:.2}, {a:.2}, {b:.2}]\n"));
    }
    if let Some(o) = m.spectro.lab_observer {
        t.push_str(&format!("lab_observer = {o}\n"));
    }
    if let Some(e) = m.spectro.eta {
        t.push_str(&format!("eta = {e}\n"));
    }
    if let Some(r) = m.spectro.repeatability {
        t.push_str(&format!("repeatability = {r}\n"));
    }
    if let Some(d) = m.spectro.aperture_mm {
        t.push_str(&format!("aperture_mm = {d}\n"));
    }
    if let Some(d) = m.spectro.illuminated_mm {
        t.push_str(&format!("illuminated_mm = {d}\n"));
    }
    t.push_str("\n[camera]\n");
    if let Some(f) = &m.camera.exposures {
        t.push_str(&format!(
            "exposures = {}   # header: file,time_s\n",
            toml_path(f)
        ));
    }
    if let Some(list) = &m.camera.images {
        let items: Vec<String> = list.iter().map(|p| toml_path(p)).collect();
        t.push_str(&format!("images = [{}]\n", items.join(", ")));
    }
    if let Some(v) = m.camera.mm_per_pixel {
        t.push_str(&format!(
            "mm_per_pixel = {v}            # image scale on the sample surface\n"
        ));
    }
    for (key, p) in [
        ("hdr", &m.camera.hdr),
        ("response", &m.camera.response),
        ("dark", &m.camera.dark),
    ] {
        if let Some(p) = p {
            t.push_str(&format!("{key} = {}\n", toml_path(p)));
        }
    }
    if let Some([x, y]) = m.camera.center_px {
        t.push_str(&format!("center_px = [{x}, {y}]\n"));
    }
    if let Some(d) = m.camera.spot_diameter_mm {
        t.push_str(&format!(
            "spot_diameter_mm = {d}        # the light spot on the sample\n"
        ));
    }
    if let Some(p) = m.camera.spot_profile {
        t.push_str(&format!("spot_profile = \"{}\"\n", p.as_str()));
    }
    for (key, p) in [
        ("spot_image", &m.camera.spot_image),
        ("flat", &m.camera.flat),
    ] {
        if let Some(p) = p {
            t.push_str(&format!("{key} = {}\n", toml_path(p)));
        }
    }
    match m.camera.black_level {
        Some(BlackLevelSetting::Mode(AutoOrNone::Auto)) => {
            t.push_str("black_level = \"auto\"\n");
        }
        Some(BlackLevelSetting::Mode(AutoOrNone::None)) => {
            t.push_str("black_level = \"none\"\n");
        }
        Some(BlackLevelSetting::One(v)) => t.push_str(&format!("black_level = {v}\n")),
        Some(BlackLevelSetting::PerChannel([r, g, b])) => {
            t.push_str(&format!("black_level = [{r}, {g}, {b}]\n"));
        }
        None => {}
    }
    if let Some(b) = m.camera.background {
        t.push_str(&format!(
            "background = \"{}\"\n",
            if b == AutoOrNone::Auto {
                "auto"
            } else {
                "none"
            }
        ));
    }
    if let Some(e) = m.camera.exposure_correction {
        t.push_str(&format!(
            "exposure_correction = \"{}\"\n",
            match e {
                ExposureCorrection::Auto => "auto",
                ExposureCorrection::Always => "always",
                ExposureCorrection::Never => "never",
            }
        ));
    }
    if let Some(s) = m.camera.saturation {
        t.push_str(&format!("saturation = {s}\n"));
    }
    t.push_str("\n[fit]                         # every key optional\n");
    t.push_str(&format!(
        "method = \"{}\"           # proposed | existing\n",
        m.fit.method.unwrap_or_default().name()
    ));
    t.push_str(&format!(
        "model = \"{}\"              # dipole | better-dipole | pbd | mc\n",
        m.fit.model.unwrap_or_default().name()
    ));
    t.push_str(&format!(
        "r_max_px = {}                # the paper's cut-off\n",
        m.fit.r_max_px.unwrap_or(300.0)
    ));
    if let Some(r) = m.fit.r_min_mm {
        t.push_str(&format!("r_min_mm = {r}\n"));
    }
    if let Some(a) = m.fit.albedo_model {
        t.push_str(&format!("albedo_model = \"{}\"\n", a.name()));
    }
    if let Some(b) = m.fit.normalise_with_spectro {
        t.push_str(&format!("normalise_with_spectro = {b}\n"));
    }
    if let Some(g) = m.fit.g {
        // A number, or "fit" (quoted).
        t.push_str(&format!("g = {g}\n"));
    }
    if let Some([lo, hi]) = m.fit.g_range {
        t.push_str(&format!("g_range = [{lo}, {hi}]\n"));
    }
    t
}

/// Writes [`manifest_to_toml`] atomically to `path`.
///
/// # Errors
/// [`ManifestError::Write`].
pub fn write_manifest(
    path: &Path,
    m: &SampleManifest,
    extra_comment: &str,
) -> Result<(), ManifestError> {
    crate::atomic::write_atomic(path, manifest_to_toml(m, extra_comment).as_bytes()).map_err(
        |source| ManifestError::Write {
            path: path.to_path_buf(),
            source,
        },
    )
}
