//! `scatterfit render`: shows measured parameters on an object by the paper's two methods (Choi,
//! Lee & Chin 2014, §4.1–4.3, Figure 5) and compares the rendered reflectance profile with the
//! measured one (§4.4, Table 2). The renderer is `scatterfit_render`; this file reads the inputs,
//! lays out the panels and writes the files.
//!
//! Parameters come from a `result.json` of `scatterfit measure` (`--params`, or two with
//! `--compare`), or, by name, from the published values: Table 1 (`pink-plastic`, …, the proposed
//! method) and the existing method's values quoted with Figure 5 (`pink-plastic-existing`,
//! `blue-coating-existing`, `brown-leather-existing`, with Table 1's η).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use crate::output::{errln, outln};
use anyhow::{Context, bail};
use glam::DVec3;
use scatterfit_imaging::ImageBuf;
use scatterfit_io::image_files::{CameraFrame, write_camera_frame, write_radiance};
use scatterfit_io::mesh::read_mesh;
use scatterfit_io::profile_csv::read_profile_csv;
use scatterfit_io::result_json::{MeasurementResult, read_result_json};
use scatterfit_optics::{ModelName, Rgb};
use scatterfit_render::colour::ColourParams;
use scatterfit_render::figure::{FigureStyle, Panel, compose, compose_linear};
use scatterfit_render::texture_space::{DipoleParams, Evaluation};
use scatterfit_render::tonemap::{ToneMap, luminance_image, tone_map};
use scatterfit_render::validation::{
    SpotSetup, compare_profiles, interpolate, render_spot_profile,
};
use scatterfit_render::{
    Light, Material, Mesh, Method, RenderOptions, RenderStats, Rendered, Shape, Timings, render,
    studio, studio_lights,
};
use serde::Serialize;

/// The built-in models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ShapeArg {
    /// Sphere, 10 mm radius.
    Sphere,
    /// 30 × 30 × 4 mm slab.
    Slab,
    /// Goblet-shaped statue 40 mm tall: thick base and stem, bowl wall under 1 mm.
    Statue,
}

/// Which method(s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Subsurface colour method (§4.1, eqs. 3–5).
    Color,
    /// Texture-space dipole method (§4.2, eq. 6).
    Dipole,
    /// Both, side by side.
    Both,
}

/// Lighting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LightArg {
    /// Key light from the upper front left (irradiance 1) and a back light from behind (0.8).
    Studio,
    /// The key light alone.
    Key,
    /// The back light alone (irradiance 1): light through thin parts.
    Back,
    /// A point light above the front left, giving irradiance 1 at the model's centre.
    Point,
    /// A collimated spot of 2 mm radius from the key light's direction, aimed at the model's
    /// centre (irradiance 1), like the measurement rig's: light spreading under the surface.
    Spot,
}

/// Arguments of `scatterfit render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Parameters: a result.json of `scatterfit measure`, or a published material by name
    /// (pink-plastic, blue-coating, brown-leather, nephrite, wood-tile, sulfur, red-aluminum; and
    /// pink-plastic-existing, blue-coating-existing, brown-leather-existing).
    #[arg(long, value_name = "RESULT", required_unless_present = "compare")]
    pub params: Option<String>,
    /// Two parameter sets side by side, shaped like the paper's Figure 5 (A, B for each method),
    /// e.g. existing.json proposed.json.
    #[arg(long, num_args = 2, value_names = ["A", "B"], conflicts_with_all = ["params", "profile"])]
    pub compare: Option<Vec<String>>,
    /// A mesh file (.obj or .ply); its units are mm unless --mesh-scale says otherwise.
    #[arg(long, value_name = "FILE", conflicts_with = "shape")]
    pub mesh: Option<PathBuf>,
    /// mm per mesh-file unit (e.g. 10 for a file in cm), in (0, 10⁶].
    #[arg(long, default_value_t = 1.0, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub mesh_scale: f64,
    /// A built-in model (used when no --mesh is given).
    #[arg(long, value_enum, default_value_t = ShapeArg::Statue)]
    pub shape: ShapeArg,
    /// Triangles of the built-in sphere or statue (about): a count, 1000 to 1e7.
    #[arg(long, default_value = "100000", value_parser = crate::numeric::parse_size, value_name = "N")]
    pub triangles: usize,
    /// Which of the paper's rendering methods.
    #[arg(long, value_enum, default_value_t = MethodArg::Both)]
    pub method: MethodArg,
    /// The profile model of the texture-space method: dipole, better-dipole, pbd or mc (default: the
    /// model the result was fitted with; dipole for published parameters).
    #[arg(long, value_enum)]
    pub model: Option<crate::common::ModelArg>,
    /// Write the luminance (grey) instead of colour, like the paper's Figure 5.
    #[arg(long)]
    pub gray: bool,
    /// Image size in pixels, WxH (each 16–8192; with every panel within the memory budget).
    #[arg(long, default_value = "512x512", value_parser = parse_size, value_name = "WxH")]
    pub size: (usize, usize),
    /// Camera samples per pixel: a count, 1 to 4096 (1 = pixel centres; a square number is
    /// stratified); the time grows in proportion.
    #[arg(long, default_value = "4", value_parser = crate::numeric::parse_size, value_name = "N")]
    pub spp: usize,
    /// Seed of every random stream, 0 to 2⁶⁴ − 1 (the image is identical for a seed on any thread
    /// count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Lighting.
    #[arg(long, value_enum, default_value_t = LightArg::Studio)]
    pub light: LightArg,
    /// Rays each light shoots to sample the irradiance (texture-space method): a count, 1e3 to 1e8
    /// (default: a spacing of a third of the profile's half-width over the model, 65 536–2 097 152).
    #[arg(long, value_parser = crate::numeric::parse_size, value_name = "N")]
    pub light_rays: Option<usize>,
    /// Hierarchy threshold: a node is used whole below this angular size [rad], in (0, 1).
    #[arg(long, default_value_t = 0.5, value_name = "RAD", value_parser = crate::numeric::parse_finite)]
    pub max_angle: f64,
    /// Evaluate eq. 6 as a direct sum over every irradiance point (exact, slow).
    #[arg(long)]
    pub direct: bool,
    /// Evaluate the texture-space sum at every sample instead of on a grid of every second pixel
    /// interpolated where the surface is smooth.
    #[arg(long)]
    pub no_interpolation: bool,
    /// ρd, diffuse coefficient of eq. 5 (≥ 0).
    #[arg(long, default_value_t = 1.0)]
    pub rho_d: f64,
    /// ρs, specular coefficient of eq. 5 (≥ 0; default the Fresnel reflectance at normal
    /// incidence ((η−1)/(η+1))²).
    #[arg(long)]
    pub rho_s: Option<f64>,
    /// ρts, translucent coefficient of eq. 5 (≥ 0).
    #[arg(long, default_value_t = 1.0)]
    pub rho_ts: f64,
    /// α of the translucent fall-off (α d + β)^−γ [mm⁻¹, ≥ 0].
    #[arg(long, default_value_t = 1.0)]
    pub alpha: f64,
    /// β of the translucent fall-off (> 0).
    #[arg(long, default_value_t = 1.0)]
    pub beta: f64,
    /// γ of the translucent fall-off (≥ 0).
    #[arg(long, default_value_t = 1.0)]
    pub gamma: f64,
    /// αx, surface slope deviation along the tangent (Ward; > 0).
    #[arg(long, default_value_t = 0.15)]
    pub alpha_x: f64,
    /// αy, surface slope deviation along the bitangent (Ward; > 0).
    #[arg(long, default_value_t = 0.15)]
    pub alpha_y: f64,
    /// Henyey–Greenstein g of P(g) in eqs. 3–4, in (−1, 1).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub g: f64,
    /// Exposure [EV], in [−60, 60]; at 0 a white diffuser facing a light of irradiance 1 is the
    /// reference white.
    /// Default 0, except with --profile, where the slab image is exposed so that the glow at twice
    /// the spot radius shows as white.
    #[arg(long, allow_hyphen_values = true, value_name = "EV", value_parser = crate::numeric::parse_finite)]
    pub exposure: Option<f64>,
    /// Tone-curve white: the exposed luminance shown as display white, in [1, 10⁶].
    #[arg(long, default_value_t = 4.0, value_parser = crate::numeric::parse_finite)]
    pub white: f64,
    /// Validate against the measured profile (Table 2): render the measurement's slab and spot
    /// by the texture-space method, and report the MSE per channel against the result's
    /// `inputs.profile` divided by the fitted scale k.
    #[arg(long)]
    pub profile: bool,
    /// The measured profile CSV for --profile, instead of the result's `inputs.profile`.
    #[arg(long, value_name = "CSV", requires = "profile")]
    pub measured_profile: Option<PathBuf>,
    /// With --profile: follow a result's `inputs.profile` even when it leads outside the result's
    /// folder (`../x.csv`, an absolute path, a link that leaves it); refused otherwise.
    #[arg(long, requires = "profile")]
    pub allow_outside_paths: bool,
    /// Light-spot radius for --profile [mm], in (0, 10] (default: the result's
    /// `inputs.spot_radius_mm`).
    #[arg(long, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub spot_radius_mm: Option<f64>,
    /// Output files, repeatable: .png (tone-mapped sRGB, with captions when there are several
    /// panels), .exr (linear radiance, PIZ lossless), and with --profile .csv (rendered vs
    /// measured). Checked before rendering; existing files only with --force.
    #[arg(short, long = "output", value_name = "FILE", required = true)]
    pub output: Vec<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    #[arg(long, value_parser = crate::numeric::parse_mib, help = crate::numeric::MAX_MEMORY_HELP)]
    pub max_memory_mib: Option<u64>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Memory per pixel and panel [bytes], an upper bound: the linear image (3 × f32), its grey or
/// composed copy and the figure grid (3 × f32 each), the tone-mapped bytes and the PNG encoder's.
const BYTES_PER_PIXEL_PANEL: u64 = 48;
/// Memory per triangle [bytes], an upper bound: positions, normals, indices, the BVH.
const BYTES_PER_TRIANGLE: u64 = 256;
/// Memory per light ray of the texture-space method [bytes]: its irradiance point and tree share.
const BYTES_PER_LIGHT_RAY: u64 = 160;

/// Checks the numbers that no library checks, then the memory the flags size, before any work.
fn check_numbers(args: &Args, panels: usize) -> anyhow::Result<()> {
    use crate::numeric::ensure;
    ensure(
        (1..=4096).contains(&args.spp),
        "--spp",
        args.spp,
        "the samples per pixel must lie in 1–4096",
    )?;
    ensure(
        args.mesh_scale > 0.0 && args.mesh_scale <= 1e6,
        "--mesh-scale",
        args.mesh_scale,
        "the mesh scale must lie in (0, 1e6] mm per file unit",
    )?;
    if let Some(ev) = args.exposure {
        ensure(
            (-60.0..=60.0).contains(&ev),
            "--exposure",
            ev,
            "the exposure must lie in [−60, 60] EV",
        )?;
    }
    ensure(
        (1.0..=1e6).contains(&args.white),
        "--white",
        args.white,
        "the tone-curve white must lie in [1, 1e6]",
    )?;
    if let Some(r) = args.spot_radius_mm {
        ensure(
            r > 0.0 && r <= 10.0,
            "--spot-radius-mm",
            r,
            "the light spot's radius must lie in (0, 10] mm",
        )?;
    }
    let (w, h) = args.size;
    let pixels = (w * h) as u64;
    let rays = args.light_rays.unwrap_or(1 << 21) as u64 * 2;
    let needed = pixels * BYTES_PER_PIXEL_PANEL * panels as u64
        + args.triangles as u64 * BYTES_PER_TRIANGLE
        + rays * BYTES_PER_LIGHT_RAY;
    crate::numeric::check_memory(
        &format!("rendering {panels} panel(s) of {w}×{h} px"),
        needed,
        crate::numeric::memory_budget(args.max_memory_mib),
    )
}

fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("`{text}` is not WxH; write the size in pixels, e.g. 512x512");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h) = (
        w.trim().parse::<usize>().map_err(|_| bad())?,
        h.trim().parse::<usize>().map_err(|_| bad())?,
    );
    if !(16..=8192).contains(&w) || !(16..=8192).contains(&h) {
        return Err(format!(
            "{w}x{h}: width and height must each be 16–8192 pixels"
        ));
    }
    Ok((w, h))
}

/// One parameter set, wherever it came from.
struct Params {
    /// Display name.
    name: String,
    /// The forward model the parameters were fitted with (`dipole` for published ones).
    model: ModelName,
    /// `proposed`, `existing`, or the result's method.
    method: String,
    /// Where it came from (a path or "published …").
    source: String,
    eta: f64,
    coefficients: [(f64, f64); 3],
    /// The result file and its folder, when read from one.
    result: Option<(MeasurementResult, PathBuf)>,
}

/// The renderer's material for `p` with its profile model (`model` overrides the fitted one), made
/// by the one name → model factory.
fn material_for(p: &Params, model: Option<ModelName>) -> anyhow::Result<Material> {
    let model = model.unwrap_or(p.model);
    let family = scatterfit_mc::family(model)?;
    Material::new(family, Rgb::from_array(p.coefficients), p.eta, 0.0)
        .with_context(|| p.name.clone())
}

fn load_params(spec: &str, model: Option<ModelName>) -> anyhow::Result<Params> {
    let path = Path::new(spec);
    if !path.exists() {
        // Choi et al.'s published sets (scatterfit_synth::materials: Table 1, and the existing
        // method's quoted with Figure 5).
        if let Some(set) = scatterfit_synth::materials::choi_2014_set(spec) {
            let m = set.material;
            return Ok(Params {
                model: ModelName::Dipole,
                name: m.name.replace('-', " "),
                method: set.method.name().into(),
                source: format!("published: {}", set.citation()),
                eta: m.eta,
                coefficients: std::array::from_fn(|c| (m.sigma_s_prime[c], m.sigma_a[c])),
                result: None,
            });
        }
        let (proposed, existing): (Vec<_>, Vec<_>) = scatterfit_synth::materials::choi_2014_sets()
            .partition(|s| s.method == scatterfit_optics::Method::Proposed);
        let names = |v: Vec<scatterfit_synth::materials::PublishedSet>| {
            v.iter().map(|s| s.key()).collect::<Vec<_>>().join(", ")
        };
        bail!(
            "{spec}: no such file, and not a published material; give a result.json of \
             `scatterfit measure` or one of: {}, and {}",
            names(proposed),
            names(existing)
        );
    }
    let result = read_result_json(path)?;
    let fitted = match result
        .model
        .trim()
        .to_ascii_lowercase()
        .parse::<ModelName>()
    {
        Ok(m) => m,
        Err(_) => match model {
            Some(m) => m,
            None => bail!(
                "{spec}: the parameters were fitted with a model render does not know (`{}`); \
                 pass --model dipole|better-dipole|pbd|mc",
                scatterfit_io::escape::token(result.model.trim())
            ),
        },
    };
    let coefficients = result.coefficients().map_err(|ch| -> anyhow::Error {
        let c = match ch {
            "r" => &result.channels.r,
            "g" => &result.channels.g,
            _ => &result.channels.b,
        };
        // A measurement that failed (exit 1), as `export` says of the same result.
        crate::common::MeasurementFailed(format!(
            "{spec}: channel {ch} has no σ′s/σa (status {:?}{}); render needs all three channels — \
             re-run the measurement or fix that channel",
            c.status,
            c.problem
                .as_deref()
                .map(|p| format!(": {p}"))
                .unwrap_or_default()
        ))
        .into()
    })?;
    let folder = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    Ok(Params {
        model: fitted,
        name: result.name.clone(),
        method: result.method.clone(),
        source: path.display().to_string(),
        eta: result.eta,
        coefficients,
        result: Some((result, folder)),
    })
}

/// The summary printed (or written as JSON).
#[derive(Debug, Serialize)]
struct Summary {
    mesh: MeshSummary,
    renders: Vec<RenderSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    profile: Option<ProfileSummary>,
    outputs: Vec<PathBuf>,
    threads: usize,
}

#[derive(Debug, Serialize)]
struct MeshSummary {
    source: String,
    triangles: usize,
    size_mm: [f64; 3],
    bvh_build_s: f64,
}

#[derive(Debug, Serialize)]
struct RenderSummary {
    material: String,
    parameters: String,
    method: &'static str,
    eta: f64,
    sigma_s_prime: [f64; 3],
    sigma_a: [f64; 3],
    width: usize,
    height: usize,
    spp: usize,
    seed: u64,
    irradiance_s: f64,
    tree_s: f64,
    shading_s: f64,
    light_rays: usize,
    irradiance_points: usize,
    mean_nodes_visited: f64,
    hit_fraction: f64,
    invalid_samples: usize,
    /// Largest pixel radiance per channel.
    max_radiance: [f32; 3],
}

#[derive(Debug, Serialize)]
struct ProfileSummary {
    measured: PathBuf,
    mm_per_pixel: f64,
    spot_radius_mm: f64,
    r_max_mm: f64,
    render_s: f64,
    channels: Vec<ChannelMse>,
}

#[derive(Debug, Serialize)]
struct ChannelMse {
    channel: &'static str,
    /// Table 2's quantity computed from the render [mm⁻⁴].
    mse: f64,
    rms_log: f64,
    rings: usize,
    /// The fit's own MSE from result.json, for reference [mm⁻⁴].
    fit_mse: Option<f64>,
}

/// Runs `scatterfit render`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let specs: Vec<String> = match (&args.params, &args.compare) {
        (Some(p), None) => vec![p.clone()],
        (None, Some(c)) => c.clone(),
        _ => bail!("give --params RESULT or --compare A B"),
    };
    let mut inputs: Vec<PathBuf> = specs.iter().map(PathBuf::from).collect();
    if let Some(m) = &args.mesh {
        inputs.push(m.clone());
    }
    if let Some(m) = &args.measured_profile {
        inputs.push(m.clone());
    }
    for out in &args.output {
        let ext = out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match ext.as_str() {
            "png" | "exr" => {}
            "csv" if args.profile => {}
            "csv" => bail!(
                "-o {}: a .csv output is the profile comparison; add --profile, or write .png/.exr",
                out.display()
            ),
            _ => bail!(
                "-o {}: write .png (tone-mapped sRGB) or .exr (linear radiance){}",
                out.display(),
                if args.profile { " or .csv" } else { "" }
            ),
        }
        crate::common::check_destination(out, "-o")?;
        if out.exists() && !args.force {
            bail!(
                "-o {}: the file exists; nothing was done — pass --force to replace it, or choose \
                 another name",
                out.display()
            );
        }
        let refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        crate::common::refuse_overwrite(out, "-o", &refs)?;
        if out.is_dir() {
            bail!("-o {}: is a folder; name a file", out.display());
        }
        crate::common::check_output_folder(out, "-o")?;
    }
    let panels = if args.profile {
        1
    } else {
        specs.len()
            * match args.method {
                MethodArg::Both => 2,
                _ => 1,
            }
    };
    check_numbers(&args, panels)?;
    if !(args.mesh_scale.is_finite() && args.mesh_scale > 0.0) {
        bail!(
            "--mesh-scale {} must be a positive number (mm per file unit)",
            crate::numeric::show(args.mesh_scale)
        );
    }
    if !(1000..=10_000_000).contains(&args.triangles) {
        bail!("--triangles {} must lie in 1000–1e7", args.triangles);
    }
    if let Some(n) = args.light_rays
        && !(1000..=100_000_000).contains(&n)
    {
        bail!("--light-rays {n} must lie in 1e3–1e8");
    }
    let params: Vec<Params> = specs
        .iter()
        .map(|s| load_params(s, args.model.map(Into::into)))
        .collect::<anyhow::Result<_>>()?;
    let opts = RenderOptions {
        width: args.size.0,
        height: args.size.1,
        spp: args.spp,
        seed: args.seed,
        colour: ColourParams {
            rho_d: args.rho_d,
            rho_ts: args.rho_ts,
            rho_s: args.rho_s,
            alpha: args.alpha,
            beta: args.beta,
            gamma: args.gamma,
            alpha_x: args.alpha_x,
            alpha_y: args.alpha_y,
            g: args.g,
        },
        dipole: DipoleParams {
            light_rays: args.light_rays,
            evaluation: if args.direct {
                Evaluation::Direct
            } else {
                Evaluation::Hierarchical {
                    max_angle: args.max_angle,
                }
            },
            specular: true,
            interpolate: !args.no_interpolation,
        },
    };
    opts.colour.validate().context("shading coefficients")?;
    opts.dipole.validate().context("texture-space options")?;
    let tone = ToneMap {
        exposure_ev: args.exposure.unwrap_or(0.0),
        white: args.white,
    };
    if args.profile {
        return run_profile(&args, &params[0], &opts, &tone);
    }

    // The scene.
    let t0 = Instant::now();
    let (mesh, source) = match &args.mesh {
        Some(path) => {
            let data = read_mesh(path)?;
            let r = data.report;
            if !args.quiet {
                if r.boundary_edges > 0 {
                    errln!(
                        "warning: {}: the surface is open ({} border edges); thickness through it \
                         is measured to the far side where there is one",
                        path.display(),
                        r.boundary_edges
                    );
                }
                if r.inconsistent_edges > 0 {
                    errln!(
                        "warning: {}: {} edges join triangles wound inconsistently; computed \
                         normals may be wrong there",
                        path.display(),
                        r.inconsistent_edges
                    );
                }
                if r.degenerate_dropped > 0 {
                    errln!(
                        "note: {}: dropped {} degenerate triangles",
                        path.display(),
                        r.degenerate_dropped
                    );
                }
            }
            let mesh = Mesh::new(data.positions, data.normals, data.triangles)
                .with_context(|| format!("mesh {}", path.display()))?
                .scaled(args.mesh_scale);
            (mesh, path.display().to_string())
        }
        None => {
            let shape = match args.shape {
                ShapeArg::Sphere => Shape::Sphere,
                ShapeArg::Slab => Shape::Slab,
                ShapeArg::Statue => Shape::Statue,
            };
            let mut mesh = shape.mesh(args.triangles)?;
            if shape == Shape::Slab {
                // Stand the slab up a little so that its top faces the camera's side.
                mesh = tilt(mesh, 35f64.to_radians());
            }
            (mesh, format!("built-in {}", shape.name()))
        }
    };
    let bounds = mesh.bounds();
    let triangles = mesh.triangles().len();
    let scene = studio(mesh, lights(args.light, &bounds))?;
    let bvh_build_s = t0.elapsed().as_secs_f64();

    let methods: Vec<Method> = match args.method {
        MethodArg::Color => vec![Method::Colour],
        MethodArg::Dipole => vec![Method::Dipole],
        MethodArg::Both => vec![Method::Colour, Method::Dipole],
    };
    // Figure 5's order: for each method, every parameter set.
    let jobs: Vec<(Method, usize)> = methods
        .iter()
        .flat_map(|&m| (0..params.len()).map(move |k| (m, k)))
        .collect();
    let bar = progress_bar(&args, (jobs.len() * opts.height) as u64);
    let materials: Vec<Material> = params
        .iter()
        .map(|p| material_for(p, args.model.map(Into::into)))
        .collect::<anyhow::Result<_>>()?;
    let mut renders = Vec::new();
    let mut summaries = Vec::new();
    for &(method, k) in &jobs {
        bar.set_message(format!("{} · {}", method.name(), params[k].name));
        let r = render(&scene, &materials[k], method, &opts, &|n| bar.inc(n as u64))?;
        summaries.push(render_summary(&params[k], &r, &opts));
        renders.push(r);
    }
    bar.finish_and_clear();

    let letters = ["1", "2", "3", "4"];
    let images: Vec<ImageBuf<f32>> = renders
        .iter()
        .map(|r| {
            if args.gray {
                luminance_image(&r.image)
            } else {
                Ok(r.image.clone())
            }
        })
        .collect::<Result<_, _>>()?;
    for out in &args.output {
        let ext = out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        if ext == "exr" {
            let refs: Vec<&ImageBuf<f32>> = images.iter().collect();
            let grid = compose_linear(&refs, images.len(), 8)?;
            write_radiance(out, &grid)?;
        } else if images.len() == 1 {
            write_png(out, &tone_map(&images[0], &tone)?)?;
        } else {
            let panels: Vec<Panel> = jobs
                .iter()
                .zip(&images)
                .enumerate()
                .map(|(i, (&(method, k), img))| {
                    let p = &params[k];
                    let model = args.model.map(ModelName::from).unwrap_or(p.model);
                    // The texture-space method with another profile model says which.
                    let (title, profile) = if method == Method::Dipole && model != ModelName::Dipole
                    {
                        ("texture-space method (§4.2)", format!(" · {model} profile"))
                    } else {
                        (method.title(), String::new())
                    };
                    Ok(Panel {
                        image: rgb8(tone_map(img, &tone)?),
                        caption: vec![
                            format!("({}) {title}", letters[i.min(3)]),
                            format!("{} · {}{profile}", p.name, p.method),
                        ],
                    })
                })
                .collect::<anyhow::Result<_>>()?;
            let title = (params.len() == 2).then(|| {
                format!(
                    "{} ({}) vs {} ({}) — Choi et al. 2014, Figure 5 layout",
                    params[0].name, params[0].method, params[1].name, params[1].method
                )
            });
            let style = FigureStyle {
                columns: jobs.len(),
                title,
                ..FigureStyle::default()
            };
            write_png(out, &compose(&panels, &style)?)?;
        }
    }
    let summary = Summary {
        mesh: MeshSummary {
            source,
            triangles,
            size_mm: bounds.extent().to_array(),
            bvh_build_s,
        },
        renders: summaries,
        profile: None,
        outputs: args.output.clone(),
        threads: rayon::current_num_threads(),
    };
    print_summary(&args, &summary)?;
    Ok(ExitCode::SUCCESS)
}

fn render_summary(p: &Params, r: &Rendered, opts: &RenderOptions) -> RenderSummary {
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
    RenderSummary {
        material: p.name.clone(),
        parameters: p.source.clone(),
        method: r.method.name(),
        eta: p.eta,
        sigma_s_prime: p.coefficients.map(|c| c.0),
        sigma_a: p.coefficients.map(|c| c.1),
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

fn print_summary(args: &Args, s: &Summary) -> anyhow::Result<()> {
    if args.json {
        return crate::output::print_json(s);
    }
    outln!(
        "mesh     {} ({} triangles, {:.1} × {:.1} × {:.1} mm), BVH {:.3} s",
        s.mesh.source,
        s.mesh.triangles,
        s.mesh.size_mm[0],
        s.mesh.size_mm[1],
        s.mesh.size_mm[2],
        s.mesh.bvh_build_s
    )?;
    for r in &s.renders {
        let extra = if r.method == "dipole" {
            format!(
                " (irradiance {:.3} s, {} rays, {} points; hierarchy {:.3} s; {:.0} nodes per \
                 sample)",
                r.irradiance_s, r.light_rays, r.irradiance_points, r.tree_s, r.mean_nodes_visited
            )
        } else {
            String::new()
        };
        outln!(
            "render   {:<6} {} ({}): {}x{}, {} spp, shading {:.3} s{extra}",
            r.method,
            r.material,
            r.parameters,
            r.width,
            r.height,
            r.spp,
            r.shading_s
        )?;
        if r.invalid_samples > 0 {
            outln!(
                "warning  {} samples were non-finite or negative and were set to 0",
                r.invalid_samples
            )?;
        }
    }
    if let Some(p) = &s.profile {
        outln!(
            "profile  {} : {:.4} mm/px, spot radius {:.3} mm, out to {:.2} mm; render {:.2} s",
            p.measured.display(),
            p.mm_per_pixel,
            p.spot_radius_mm,
            p.r_max_mm,
            p.render_s
        )?;
        outln!(
            "         {:<8} {:>6} {:>14} {:>10} {:>14}",
            "channel",
            "rings",
            "MSE [mm⁻⁴]",
            "rms ln",
            "fit MSE"
        )?;
        for c in &p.channels {
            outln!(
                "         {:<8} {:>6} {:>14.4e} {:>10.4} {:>14}",
                c.channel,
                c.rings,
                c.mse,
                c.rms_log,
                c.fit_mse.map_or("—".into(), |m| format!("{m:.4e}"))
            )?;
        }
    }
    for o in &s.outputs {
        outln!("wrote    {}", o.display())?;
    }
    Ok(())
}

fn progress_bar(args: &Args, len: u64) -> indicatif::ProgressBar {
    if args.quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} rows  {msg}  ETA {eta}")
            .expect("valid template"),
    );
    bar
}

fn lights(kind: LightArg, bounds: &scatterfit_render::mesh::Aabb) -> Vec<Light> {
    let studio = studio_lights();
    match kind {
        LightArg::Studio => studio,
        LightArg::Key => vec![studio[0]],
        LightArg::Back => match studio[1] {
            Light::Directional { direction, .. } => vec![Light::Directional {
                direction,
                irradiance: [1.0; 3],
            }],
            other => vec![other],
        },
        LightArg::Point => {
            let c = bounds.center();
            let r = 0.5 * bounds.extent().length();
            let position = c + DVec3::new(-0.55, 0.7, 0.45).normalize() * (3.0 * r);
            let d2 = (position - c).length_squared();
            vec![Light::Point {
                position,
                intensity: [d2; 3],
            }]
        }
        LightArg::Spot => match studio[0] {
            Light::Directional { direction, .. } => vec![Light::Spot {
                center: bounds.center(),
                direction,
                radius: 2.0,
                irradiance: [1.0; 3],
            }],
            other => vec![other],
        },
    }
}

/// Rotates a mesh about the x axis by `angle` (towards the camera at +z).
fn tilt(mesh: Mesh, angle: f64) -> Mesh {
    let rot = glam::DMat3::from_rotation_x(angle);
    let positions = mesh
        .positions()
        .iter()
        .map(|p| (rot * *p).to_array())
        .collect();
    let normals = mesh
        .normals()
        .iter()
        .map(|n| (rot * *n).to_array())
        .collect();
    Mesh::new(positions, Some(normals), mesh.triangles().to_vec())
        .expect("a rotated valid mesh is valid")
}

fn rgb8(img: ImageBuf<u8>) -> ImageBuf<u8> {
    if img.channels() == 3 {
        return img;
    }
    let data = img.data().iter().flat_map(|&v| [v, v, v]).collect();
    ImageBuf::new(img.width(), img.height(), 3, data).expect("same size")
}

fn write_png(path: &Path, img: &ImageBuf<u8>) -> anyhow::Result<()> {
    write_camera_frame(path, &CameraFrame::U8(img.clone()))
        .with_context(|| format!("writing {}", path.display()))
}

/// The result `json` and the profile `csv` it names, when they share a folder: listed in the
/// folder's result set with the hashes they have now (one run's files), else refused; a folder
/// without a set (an older scatterfit, an interrupted run) is noted on stderr.
fn check_one_run(json: &Path, csv: &Path, quiet: bool) -> anyhow::Result<()> {
    let folder = json.parent().unwrap_or(Path::new(""));
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let (Some(j), Some(c)) = (json.file_name(), csv.file_name()) else {
        return Ok(());
    };
    if !crate::common::same_file(csv.parent().unwrap_or(Path::new(".")), folder) {
        return Ok(());
    }
    let (j, c) = (j.to_string_lossy(), c.to_string_lossy());
    match scatterfit_io::result_set::verify(folder, &[&j, &c])? {
        scatterfit_io::result_set::SetStatus::Unknown if !quiet => errln!(
            "note: {} has no {}: {j} and {c} cannot be checked to come from one run (results of an \
             older scatterfit, or of a run that was interrupted — then measure again)",
            folder.display(),
            scatterfit_io::result_set::SET_FILE
        ),
        _ => {}
    }
    Ok(())
}

/// `--profile`: the measurement's slab and spot rendered by the texture-space method, compared ring
/// by ring with the measured profile divided by the fitted scale k (Table 2's MSE, §4.4).
fn run_profile(
    args: &Args,
    p: &Params,
    opts: &RenderOptions,
    tone: &ToneMap,
) -> anyhow::Result<ExitCode> {
    let given = args.measured_profile.as_ref();
    let Some((result, folder)) = &p.result else {
        bail!(
            "--profile needs a result.json (its fitted scales and measured profile); `{}` is a \
             published parameter set",
            p.source
        );
    };
    let csv = match given {
        Some(path) => path.clone(),
        None => {
            match &result.inputs.profile {
                Some(rel) => {
                    let csv = folder.join(rel);
                    // A result names files inside its folder (the input path policy), and the result
                    // and the profile it names must come from one run (the folder's result set).
                    scatterfit_io::inputs::InputPolicy::new(folder, args.allow_outside_paths)?
                        .check(Path::new(&p.source), "`inputs.profile`", &csv)?;
                    check_one_run(Path::new(&p.source), &csv, args.quiet)?;
                    csv
                }
                None => bail!(
                    "{}: no `inputs.profile`; give the measured profile with --measured-profile FILE.csv",
                    p.source
                ),
            }
        }
    };
    // The profile is an input too: no output may replace it (with --force it could).
    let refs = [csv.as_path()];
    for out in &args.output {
        crate::common::refuse_overwrite(out, "-o", &refs)?;
    }
    let table = read_profile_csv(&csv)?;
    let column = |name: &str| {
        table
            .channels
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: no value_{name} column; --profile compares an RGB profile \
                     (value_r, value_g, value_b)",
                    csv.display()
                )
            })
    };
    let cols = [column("r")?, column("g")?, column("b")?];
    let channels = result.channels.as_array();
    let names = ["r", "g", "b"];
    let mut scales = [0.0; 3];
    for c in 0..3 {
        scales[c] = channels[c]
            .scale
            .filter(|k| k.is_finite() && *k > 0.0)
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: `channels.{}.scale` (the fitted profile scale k) is missing or not \
                     positive; --profile needs it to put the measured profile in mm⁻²",
                    p.source,
                    names[c]
                )
            })?;
    }
    let mm_per_pixel = match result.inputs.mm_per_pixel {
        Some(v) => v,
        None => table
            .r_mm
            .iter()
            .zip(&table.r_px)
            .rev()
            .find(|(mm, px)| mm.is_finite() && px.is_finite() && **px > 0.0)
            .map(|(mm, px)| mm / px)
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: no `inputs.mm_per_pixel` and no r_px column to derive it",
                    p.source
                )
            })?,
    };
    let spot = match args.spot_radius_mm.or(result.inputs.spot_radius_mm) {
        Some(v) => v,
        None => bail!(
            "{}: no `inputs.spot_radius_mm`; give the light spot's radius with --spot-radius-mm",
            p.source
        ),
    };
    let r_max = table
        .r_mm
        .iter()
        .copied()
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max);
    let setup = SpotSetup {
        mm_per_pixel,
        r_max_mm: r_max + mm_per_pixel,
        spot_radius_mm: spot,
    };
    setup.validate().context("the measurement geometry")?;
    let material = material_for(p, args.model.map(Into::into))?;
    let n = setup.image_size();
    let bar = progress_bar(args, n as u64);
    bar.set_message("slab + spot, texture-space dipole");
    let t0 = Instant::now();
    let popts = RenderOptions { spp: 1, ..*opts };
    let (rendered, prof) = render_spot_profile(&material, &setup, &popts, &|k| bar.inc(k as u64))?;
    // Rd_render = norm · L (see scatterfit_render::validation).
    let ft = 1.0 - scatterfit_optics::fresnel::fresnel_dielectric(1.0, p.eta);
    let norm = 1.0 / (ft * ft * std::f64::consts::PI * spot * spot) * std::f64::consts::PI;
    let render_s = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let mut mses = Vec::new();
    for c in 0..3 {
        let cmp = compare_profiles(
            &prof.r_mm,
            &prof.rd[c],
            &table.r_mm,
            &cols[c].value,
            scales[c],
            spot,
        )
        .ok_or_else(|| {
            anyhow::anyhow!(
                "{}: no ring outside the spot ({spot} mm) with a positive value in channel {}",
                csv.display(),
                names[c]
            )
        })?;
        mses.push(ChannelMse {
            channel: names[c],
            mse: cmp.mse,
            rms_log: cmp.rms_log,
            rings: cmp.rings,
            fit_mse: channels[c].mse,
        });
    }
    for out in &args.output {
        let ext = out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match ext.as_str() {
            "csv" => {
                // At the measured rings: measured/k and the render interpolated there.
                let mut text = String::from(
                    "r_mm,rendered_r,rendered_g,rendered_b,measured_over_k_r,measured_over_k_g,\
                     measured_over_k_b\n",
                );
                for (k, &r) in table.r_mm.iter().enumerate() {
                    let cell = |v: Option<f64>| {
                        v.filter(|v| v.is_finite())
                            .map_or(String::new(), |v| v.to_string())
                    };
                    let rendered: Vec<String> = (0..3)
                        .map(|c| cell(interpolate(&prof.r_mm, &prof.rd[c], r)))
                        .collect();
                    let measured: Vec<String> = (0..3)
                        .map(|c| cell(cols[c].value.get(k).map(|v| v / scales[c])))
                        .collect();
                    text.push_str(&format!(
                        "{r},{},{},{},{},{},{}\n",
                        rendered[0],
                        rendered[1],
                        rendered[2],
                        measured[0],
                        measured[1],
                        measured[2]
                    ));
                }
                scatterfit_io::atomic::write_atomic(out, text.as_bytes())
                    .with_context(|| format!("writing {}", out.display()))?;
            }
            "exr" => write_radiance(out, &rendered.image)?,
            _ => {
                // Expose the spot's glow: the profile at twice the spot radius shows as white.
                let tone = match args.exposure {
                    Some(_) => *tone,
                    None => {
                        let w = scatterfit_render::tonemap::luminance_weights();
                        let k = ((2.0 * spot / mm_per_pixel) as usize).min(prof.r_mm.len() - 1);
                        let y: f64 = (0..3).map(|c| w[c] * prof.rd[c][k]).sum::<f64>() / norm;
                        ToneMap {
                            exposure_ev: if y > 0.0 {
                                (tone.white / (std::f64::consts::PI * y))
                                    .log2()
                                    .clamp(-60.0, 60.0)
                            } else {
                                0.0
                            },
                            ..*tone
                        }
                    }
                };
                write_png(out, &tone_map(&rendered.image, &tone)?)?
            }
        }
    }
    let summary = Summary {
        mesh: MeshSummary {
            source: "built-in slab (measurement geometry)".into(),
            triangles: 12,
            size_mm: {
                let side = setup.image_size() as f64 * mm_per_pixel + 20.0;
                [side, 50.0, side]
            },
            bvh_build_s: 0.0,
        },
        renders: vec![render_summary(p, &rendered, &popts)],
        profile: Some(ProfileSummary {
            measured: csv,
            mm_per_pixel,
            spot_radius_mm: spot,
            r_max_mm: r_max,
            render_s,
            channels: mses,
        }),
        outputs: args.output.clone(),
        threads: rayon::current_num_threads(),
    };
    print_summary(args, &summary)?;
    Ok(ExitCode::SUCCESS)
}
