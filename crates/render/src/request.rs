//! What `scatterfit render` asks, as a library: a figure of parameter sets on an object by the
//! paper's methods (Figure 5's layout, §4.1–4.3), or a validation against the measured profile
//! (§4.4, Table 2). Typed requests in ([`FigureRequest`], [`ProfileRequest`]), renders and summary
//! records out, the files written through `scatterfit_io`.

use std::path::{Path, PathBuf};

use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::{CameraFrame, write_camera_frame, write_radiance};
use scatterfit_optics::{Channel, ModelName};
use serde::Serialize;

use crate::error::{RenderError, Result};
use crate::figure::{FigureStyle, Panel, compose, compose_linear};
use crate::params::ParameterSet;
use crate::render::{Method, RenderOptions, RenderStats, Rendered, Timings, render};
use crate::scene::Scene;
use crate::setup::{LightRig, MeshSource};
use crate::tonemap::{ToneMap, luminance_image, tone_map};
use crate::validation::{MeasuredProfile, ProfileValidation, validate_profile};

/// Which of the paper's rendering methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Methods {
    /// Subsurface colour (§4.1).
    #[cfg_attr(
        feature = "clap",
        value(name = "color", help = "Subsurface colour method (§4.1, eqs. 3–5)")
    )]
    Colour,
    /// Texture-space dipole (§4.2).
    #[cfg_attr(
        feature = "clap",
        value(help = "Texture-space dipole method (§4.2, eq. 6)")
    )]
    Dipole,
    /// Both, colour first (Figure 5's order).
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Both, side by side"))]
    Both,
}

impl Methods {
    /// The methods in Figure 5's order.
    pub fn list(self) -> Vec<Method> {
        match self {
            Methods::Colour => vec![Method::Colour],
            Methods::Dipole => vec![Method::Dipole],
            Methods::Both => vec![Method::Colour, Method::Dipole],
        }
    }
}

/// A figure: every parameter set by every method on one object.
#[derive(Debug)]
pub struct FigureRequest {
    /// The parameter sets (one, or two side by side like Figure 5's A and B).
    pub params: Vec<ParameterSet>,
    /// The object.
    pub mesh: MeshSource,
    /// The lighting.
    pub lights: LightRig,
    /// The methods.
    pub methods: Methods,
    /// The texture-space method's profile model instead of each set's fitted one.
    pub model: Option<ModelName>,
    /// Image size, samples, seed and the methods' parameters.
    pub options: RenderOptions,
}

impl FigureRequest {
    /// The summary record of the figure's `panels` rendered on `studio` into `outputs` with
    /// `threads` threads (written as `render --json` prints it).
    pub fn summary(
        &self,
        studio: &crate::setup::StudioScene,
        panels: &[PanelRender],
        outputs: &[PathBuf],
        threads: usize,
    ) -> Summary {
        Summary {
            mesh: MeshSummary {
                source: studio.source.clone(),
                triangles: studio.triangles,
                size_mm: studio.size_mm,
                bvh_build_s: studio.build_s,
            },
            renders: panels
                .iter()
                .map(|p| RenderSummary::new(&self.params[p.set], &p.rendered, &self.options))
                .collect(),
            profile: None,
            outputs: outputs.to_vec(),
            threads,
        }
    }

    /// The panels in Figure 5's order: for each method, every parameter set (by index).
    pub fn panels(&self) -> Vec<(Method, usize)> {
        self.methods
            .list()
            .into_iter()
            .flat_map(|m| (0..self.params.len()).map(move |k| (m, k)))
            .collect()
    }
}

/// What a figure's render reports as it goes.
#[derive(Debug, Clone, Copy)]
pub enum RenderEvent<'a> {
    /// A panel starts: its method and material.
    Panel {
        /// The method.
        method: Method,
        /// The parameter set's name.
        material: &'a str,
    },
    /// Image rows finished (from any thread).
    Rows(usize),
}

/// One rendered panel.
#[derive(Debug, Clone)]
pub struct PanelRender {
    /// The method.
    pub method: Method,
    /// The parameter set (index into the request's).
    pub set: usize,
    /// The render.
    pub rendered: Rendered,
}

/// Renders `request`'s panels of `scene` (every material is made before the first render, so a
/// set the model cannot take fails at once).
///
/// # Errors
/// [`ParameterSet::material`]'s and [`render`]'s.
pub fn render_figure(
    scene: &Scene,
    request: &FigureRequest,
    progress: &(dyn Fn(RenderEvent<'_>) + Sync),
) -> Result<Vec<PanelRender>> {
    let materials = request
        .params
        .iter()
        .map(|p| p.material(request.model))
        .collect::<Result<Vec<_>>>()?;
    let mut panels = Vec::new();
    for (method, set) in request.panels() {
        progress(RenderEvent::Panel {
            method,
            material: &request.params[set].name,
        });
        let rendered = render(scene, &materials[set], method, &request.options, &|n| {
            progress(RenderEvent::Rows(n))
        })?;
        panels.push(PanelRender {
            method,
            set,
            rendered,
        });
    }
    Ok(panels)
}

/// Writes a figure's panels to each of `outputs`: `.exr` a linear grid without text, otherwise a
/// PNG — the one picture tone-mapped, or the panels with captions in Figure 5's layout. `gray`
/// writes luminance.
///
/// # Errors
/// [`RenderError::Write`] naming the file, or the image operations' errors.
pub fn write_figure(
    request: &FigureRequest,
    panels: &[PanelRender],
    outputs: &[PathBuf],
    tone: &ToneMap,
    gray: bool,
) -> Result<()> {
    let images: Vec<ImageBuf<f32>> = panels
        .iter()
        .map(|p| {
            if gray {
                luminance_image(&p.rendered.image)
            } else {
                Ok(p.rendered.image.clone())
            }
        })
        .collect::<Result<_>>()?;
    for out in outputs {
        if extension(out) == "exr" {
            let refs: Vec<&ImageBuf<f32>> = images.iter().collect();
            write_radiance(out, &compose_linear(&refs, images.len(), 8)?)?;
        } else if images.len() == 1 {
            write_png(out, &tone_map(&images[0], tone)?)?;
        } else {
            write_png(out, &captioned(request, panels, &images, tone)?)?;
        }
    }
    Ok(())
}

/// Figure 5's layout: panels with "(1) method" and "material · method" captions, and a title
/// naming the two sets when there are two.
fn captioned(
    request: &FigureRequest,
    panels: &[PanelRender],
    images: &[ImageBuf<f32>],
    tone: &ToneMap,
) -> Result<ImageBuf<u8>> {
    let letters = ["1", "2", "3", "4"];
    let params = &request.params;
    let captioned: Vec<Panel> = panels
        .iter()
        .zip(images)
        .enumerate()
        .map(|(i, (panel, img))| {
            let p = &params[panel.set];
            let model = p.model_or(request.model);
            // The texture-space method with another profile model says which.
            let (title, profile) = if panel.method == Method::Dipole && model != ModelName::Dipole {
                ("texture-space method (§4.2)", format!(" · {model} profile"))
            } else {
                (panel.method.title(), String::new())
            };
            Ok(Panel {
                image: rgb8(tone_map(img, tone)?),
                caption: vec![
                    format!("({}) {title}", letters[i.min(3)]),
                    format!("{} · {}{profile}", p.name, p.method),
                ],
            })
        })
        .collect::<Result<_>>()?;
    let title = (params.len() == 2).then(|| {
        format!(
            "{} ({}) vs {} ({}) — Choi et al. 2014, Figure 5 layout",
            params[0].name, params[0].method, params[1].name, params[1].method
        )
    });
    let style = FigureStyle {
        columns: panels.len(),
        title,
        ..FigureStyle::default()
    };
    compose(&captioned, &style)
}

/// A validation against the measured profile (§4.4).
#[derive(Debug)]
pub struct ProfileRequest {
    /// The parameters (read from a result).
    pub params: ParameterSet,
    /// The measured profile with the result's scales and geometry (`crate::measured`).
    pub measured: MeasuredProfile,
    /// The texture-space method's profile model instead of the fitted one.
    pub model: Option<ModelName>,
    /// Render options (the slab render uses one sample per pixel).
    pub options: RenderOptions,
}

impl ProfileRequest {
    /// Checks the measurement geometry, makes the material and runs [`validate_profile`].
    ///
    /// # Errors
    /// [`RenderError::Geometry`], [`ParameterSet::material`]'s and [`validate_profile`]'s.
    pub fn run(&self, progress: &(dyn Fn(usize) + Sync)) -> Result<ProfileValidation> {
        self.measured
            .setup()
            .validate()
            .map_err(|e| RenderError::Geometry(Box::new(e)))?;
        let material = self.params.material(self.model)?;
        validate_profile(&material, &self.measured, &self.options, progress)
    }

    /// Writes the validation to each of `outputs`: `.csv` the comparison at the measured rings,
    /// `.exr` the slab's linear radiance, otherwise a PNG exposed by `tone`, or — unless
    /// `exposure_given` — so that the glow at twice the spot radius shows as white.
    ///
    /// # Errors
    /// [`RenderError::Write`] naming the file, or the image operations' errors.
    pub fn write(
        &self,
        v: &ProfileValidation,
        outputs: &[PathBuf],
        tone: &ToneMap,
        exposure_given: bool,
    ) -> Result<()> {
        for out in outputs {
            match extension(out).as_str() {
                "csv" => scatterfit_io::atomic::write_atomic(
                    out,
                    v.comparison_csv(&self.measured).as_bytes(),
                )
                .map_err(|e| RenderError::Write {
                    path: out.clone(),
                    source: Box::new(e),
                })?,
                "exr" => write_radiance(out, &v.rendered.image)?,
                _ => {
                    let tone = if exposure_given {
                        *tone
                    } else {
                        v.glow_exposure(tone)
                    };
                    write_png(out, &tone_map(&v.rendered.image, &tone)?)?
                }
            }
        }
        Ok(())
    }

    /// The summary record of the validation (written as `render --json` prints it).
    pub fn summary(&self, v: &ProfileValidation, outputs: &[PathBuf], threads: usize) -> Summary {
        let m = &self.measured;
        let side = v.setup.image_size() as f64 * m.mm_per_pixel + 20.0;
        Summary {
            mesh: MeshSummary {
                source: "built-in slab (measurement geometry)".into(),
                triangles: 12,
                size_mm: [side, 50.0, side],
                bvh_build_s: 0.0,
            },
            renders: vec![RenderSummary::new(
                &self.params,
                &v.rendered,
                &RenderOptions {
                    spp: 1,
                    ..self.options
                },
            )],
            profile: Some(ProfileSummary {
                measured: m.file.clone(),
                mm_per_pixel: m.mm_per_pixel,
                spot_radius_mm: m.spot_radius_mm,
                r_max_mm: m.r_max_mm(),
                render_s: v.render_s,
                channels: Channel::ALL
                    .iter()
                    .map(|&c| ChannelMse {
                        channel: c.key(),
                        mse: v.channels[c].mse,
                        rms_log: v.channels[c].rms_log,
                        rings: v.channels[c].rings,
                        fit_mse: m.fit_mse[c],
                    })
                    .collect(),
            }),
            outputs: outputs.to_vec(),
            threads,
        }
    }
}

/// What `scatterfit render` reports (and prints as JSON with `--json`).
#[derive(Debug, Serialize)]
pub struct Summary {
    /// The object.
    pub mesh: MeshSummary,
    /// Every panel, in Figure 5's order.
    pub renders: Vec<RenderSummary>,
    /// The validation against the measured profile, with `--profile`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileSummary>,
    /// The files written.
    pub outputs: Vec<PathBuf>,
    /// Worker threads.
    pub threads: usize,
}

impl Summary {
    /// The summary as `scatterfit render` prints it: the object, one line per panel (with the
    /// texture-space method's irradiance and hierarchy figures), the validation's table, the
    /// files written.
    pub fn text(&self) -> String {
        use std::fmt::Write as _;
        let mut t = String::new();
        let m = &self.mesh;
        let _ = writeln!(
            t,
            "mesh     {} ({} triangles, {:.1} × {:.1} × {:.1} mm), BVH {:.3} s",
            m.source, m.triangles, m.size_mm[0], m.size_mm[1], m.size_mm[2], m.bvh_build_s
        );
        for r in &self.renders {
            let extra = if r.method == Method::Dipole {
                format!(
                    " (irradiance {:.3} s, {} rays, {} points; hierarchy {:.3} s; {:.0} nodes per \
                     sample)",
                    r.irradiance_s,
                    r.light_rays,
                    r.irradiance_points,
                    r.tree_s,
                    r.mean_nodes_visited
                )
            } else {
                String::new()
            };
            let _ = writeln!(
                t,
                "render   {:<6} {} ({}): {}x{}, {} spp, shading {:.3} s{extra}",
                r.method.name(),
                r.material,
                r.parameters,
                r.width,
                r.height,
                r.spp,
                r.shading_s
            );
            if r.invalid_samples > 0 {
                let _ = writeln!(
                    t,
                    "warning  {} samples were non-finite or negative and were set to 0",
                    r.invalid_samples
                );
            }
        }
        if let Some(p) = &self.profile {
            let _ = writeln!(
                t,
                "profile  {} : {:.4} mm/px, spot radius {:.3} mm, out to {:.2} mm; render {:.2} s",
                p.measured.display(),
                p.mm_per_pixel,
                p.spot_radius_mm,
                p.r_max_mm,
                p.render_s
            );
            let _ = writeln!(
                t,
                "         {:<8} {:>6} {:>14} {:>10} {:>14}",
                "channel", "rings", "MSE [mm⁻⁴]", "rms ln", "fit MSE"
            );
            for c in &p.channels {
                let _ = writeln!(
                    t,
                    "         {:<8} {:>6} {:>14.4e} {:>10.4} {:>14}",
                    c.channel,
                    c.rings,
                    c.mse,
                    c.rms_log,
                    c.fit_mse.map_or("—".into(), |m| format!("{m:.4e}"))
                );
            }
        }
        for o in &self.outputs {
            let _ = writeln!(t, "wrote    {}", o.display());
        }
        t
    }
}

/// Memory per pixel and panel [bytes], an upper bound: the linear image (3 × f32), its grey or
/// composed copy and the figure grid (3 × f32 each), the tone-mapped bytes and the PNG encoder's.
const BYTES_PER_PIXEL_PANEL: u64 = 48;
/// Memory per triangle [bytes], an upper bound: positions, normals, indices, the BVH.
const BYTES_PER_TRIANGLE: u64 = 256;
/// Memory per light ray of the texture-space method [bytes]: its irradiance point and tree share.
const BYTES_PER_LIGHT_RAY: u64 = 160;

/// An upper bound of a render's memory \[bytes\], known before anything is allocated: `panels`
/// images of `width` × `height` pixels, `triangles` triangles and two lights' `light_rays` each
/// (default: the automatic count's maximum, 2²¹).
pub fn memory_bytes(
    width: usize,
    height: usize,
    panels: usize,
    triangles: usize,
    light_rays: Option<usize>,
) -> u64 {
    let pixels = (width * height) as u64;
    let rays = light_rays.unwrap_or(1 << 21) as u64 * 2;
    pixels * BYTES_PER_PIXEL_PANEL * panels as u64
        + triangles as u64 * BYTES_PER_TRIANGLE
        + rays * BYTES_PER_LIGHT_RAY
}

/// The object rendered.
#[derive(Debug, Serialize)]
pub struct MeshSummary {
    /// Where it came from.
    pub source: String,
    /// Triangles.
    pub triangles: usize,
    /// Bounding-box size \[mm\].
    pub size_mm: [f64; 3],
    /// Reading the mesh and building the BVH \[s\].
    pub bvh_build_s: f64,
}

/// One panel's render.
#[derive(Debug, Serialize)]
pub struct RenderSummary {
    /// The parameter set's name.
    pub material: String,
    /// Where the parameters came from.
    pub parameters: String,
    /// `color` or `dipole`.
    pub method: Method,
    /// η.
    pub eta: f64,
    /// σ′s per channel [mm⁻¹].
    pub sigma_s_prime: [f64; 3],
    /// σa per channel [mm⁻¹].
    pub sigma_a: [f64; 3],
    /// Width \[px\].
    pub width: usize,
    /// Height \[px\].
    pub height: usize,
    /// Samples per pixel.
    pub spp: usize,
    /// Seed.
    pub seed: u64,
    /// Irradiance sampling \[s\].
    pub irradiance_s: f64,
    /// Profile tables and hierarchy \[s\].
    pub tree_s: f64,
    /// Camera rays and shading \[s\].
    pub shading_s: f64,
    /// Rays per light (texture-space method).
    pub light_rays: usize,
    /// Irradiance points (texture-space method).
    pub irradiance_points: usize,
    /// Mean hierarchy nodes visited per sample.
    pub mean_nodes_visited: f64,
    /// Fraction of samples that hit the object.
    pub hit_fraction: f64,
    /// Samples set to 0 as non-finite or negative.
    pub invalid_samples: usize,
    /// Largest pixel radiance per channel.
    pub max_radiance: [f32; 3],
}

impl RenderSummary {
    /// The record of `r`, a render of `p` with `opts`.
    pub fn new(p: &ParameterSet, r: &Rendered, opts: &RenderOptions) -> Self {
        let Timings {
            irradiance_s,
            tree_s,
            shading_s,
        } = r.timings;
        let RenderStats {
            light_rays,
            irradiance_points,
            mean_visited,
            hit_fraction,
            invalid_samples,
            ..
        } = r.stats;
        let mut max_radiance = [0f32; 3];
        for px in r.image.data().chunks_exact(3) {
            for c in 0..3 {
                max_radiance[c] = max_radiance[c].max(px[c]);
            }
        }
        let coefficients = p.coefficients.into_array();
        Self {
            material: p.name.clone(),
            parameters: p.source.clone(),
            method: r.method,
            eta: p.eta,
            sigma_s_prime: coefficients.map(|c| c.0),
            sigma_a: coefficients.map(|c| c.1),
            width: r.image.width(),
            height: r.image.height(),
            spp: opts.spp,
            seed: opts.seed,
            irradiance_s,
            tree_s,
            shading_s,
            light_rays,
            irradiance_points,
            mean_nodes_visited: mean_visited,
            hit_fraction,
            invalid_samples,
            max_radiance,
        }
    }
}

/// The validation against the measured profile.
#[derive(Debug, Serialize)]
pub struct ProfileSummary {
    /// The measured profile's file.
    pub measured: PathBuf,
    /// Image scale [mm/px].
    pub mm_per_pixel: f64,
    /// Spot radius \[mm\].
    pub spot_radius_mm: f64,
    /// Largest measured ring radius \[mm\].
    pub r_max_mm: f64,
    /// The slab render \[s\].
    pub render_s: f64,
    /// Per channel.
    pub channels: Vec<ChannelMse>,
}

/// One channel's comparison.
#[derive(Debug, Serialize)]
pub struct ChannelMse {
    /// `r`, `g` or `b`.
    pub channel: &'static str,
    /// Table 2's quantity computed from the render [mm⁻⁴].
    pub mse: f64,
    /// Root mean square of ln(rendered/measured).
    pub rms_log: f64,
    /// Rings compared.
    pub rings: usize,
    /// The fit's own MSE from result.json, for reference [mm⁻⁴].
    pub fit_mse: Option<f64>,
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

fn rgb8(img: ImageBuf<u8>) -> ImageBuf<u8> {
    if img.channels() == 3 {
        return img;
    }
    let data = img.data().iter().flat_map(|&v| [v, v, v]).collect();
    ImageBuf::new(img.width(), img.height(), 3, data).expect("same size")
}

fn write_png(path: &Path, img: &ImageBuf<u8>) -> Result<()> {
    write_camera_frame(path, &CameraFrame::U8(img.clone())).map_err(|e| RenderError::Write {
        path: path.to_path_buf(),
        source: Box::new(e),
    })
}
