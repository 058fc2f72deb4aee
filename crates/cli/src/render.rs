//! `scatterfit render`: shows measured parameters on an object by the paper's two methods (Choi,
//! Lee & Chin 2014, §4.1–4.3, Figure 5) and compares the rendered reflectance profile with the
//! measured one (§4.4, Table 2). The renderer is `scatterfit_render`; this file reads the inputs,
//! lays out the panels and writes the files.
//!
//! Parameters come from a `result.json` of `scatterfit measure` (`--params`, or two with
//! `--compare`), or, by name, from the published values: Table 1 (`pink-plastic`, …, the proposed
//! method) and the existing method's values quoted with Figure 5 (`pink-plastic-existing`,
//! `blue-coating-existing`, `brown-leather-existing`, with Table 1's η).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use crate::output::errln;
use anyhow::bail;
use scatterfit_optics::ModelName;
use scatterfit_render::colour::ColourParams;
use scatterfit_render::measured::{profile_path, read_measured};
use scatterfit_render::request::{RenderEvent, render_figure, write_figure};
use scatterfit_render::settings::{RenderSettings, check_output_kind};
use scatterfit_render::tonemap::ToneMap;
use scatterfit_render::{
    FigureRequest, LightRig, MeshSource, Methods, ParameterSet, ProfileRequest, RenderError,
    RenderOptions, Shape, StudioScene, Summary,
};

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
    #[arg(long, value_enum, default_value_t = Shape::Statue)]
    pub shape: Shape,
    /// Triangles of the built-in sphere or statue (about): a count, 1000 to 1e7.
    #[arg(long, default_value = "100000", value_parser = crate::numeric::parse_size, value_name = "N")]
    pub triangles: usize,
    /// Which of the paper's rendering methods.
    #[arg(long, value_enum, default_value_t = Methods::Both)]
    pub method: Methods,
    /// The profile model of the texture-space method: dipole, better-dipole, pbd or mc (default: the
    /// model the result was fitted with; dipole for published parameters).
    #[arg(long, value_enum)]
    pub model: Option<ModelName>,
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
    #[arg(long, value_enum, default_value_t = LightRig::Studio)]
    pub light: LightRig,
    /// Rays each light shoots to sample the irradiance (texture-space method): a count, 1e3 to 1e8
    /// (default: a spacing of a third of the profile's half-width over the model, 65 536–2 097 152).
    #[arg(long, value_parser = crate::numeric::parse_size, value_name = "N")]
    pub light_rays: Option<usize>,
    /// Hierarchy threshold: a node is used whole below this angular size \[rad\], in (0, 1).
    #[arg(long, default_value_t = 0.5, value_name = "RAD", value_parser = crate::numeric::parse_finite)]
    pub max_angle: f64,
    /// Evaluate eq. 6 as a direct sum over every irradiance point (exact, slow).
    #[arg(long)]
    pub direct: bool,
    /// Evaluate the texture-space sum at every sample instead of on a grid of every second pixel
    /// interpolated where the surface is smooth.
    #[arg(long)]
    pub no_interpolation: bool,
    #[command(flatten)]
    pub colour: ColourParams,
    /// Exposure \[EV\], in [−60, 60]; at 0 a white diffuser facing a light of irradiance 1 is the
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
    /// Light-spot radius for --profile \[mm\], in (0, 10] (default: the result's
    /// `inputs.spot_radius_mm`).
    #[arg(long, value_name = "MM", value_parser = crate::numeric::parse_finite)]
    pub spot_radius_mm: Option<f64>,
    /// Output files, repeatable: .png (tone-mapped sRGB, with captions when there are several
    /// panels), .exr (linear radiance, 32-bit float, uncompressed), and with --profile .csv (rendered vs
    /// measured). Checked before rendering; existing files only with --force.
    #[arg(short, long = "output", value_name = "FILE", required = true)]
    pub output: Vec<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Exit 0 when a result's data checks found a channel suspect (the warning is still printed).
    #[arg(long)]
    pub allow_suspect: bool,
    #[command(flatten)]
    pub memory: crate::numeric::MemoryArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// The render's settings from the flags (checked by [`RenderSettings::check`]).
fn settings(args: &Args) -> RenderSettings {
    RenderSettings {
        size: args.size,
        spp: args.spp,
        seed: args.seed,
        colour: args.colour,
        light_rays: args.light_rays,
        max_angle: args.max_angle,
        direct: args.direct,
        interpolate: !args.no_interpolation,
        mesh_scale: args.mesh_scale,
        triangles: args.triangles,
        exposure: args.exposure,
        white: args.white,
        spot_radius_mm: args.spot_radius_mm,
    }
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

/// A render error for `main`: a result with a failed channel is a failed measurement (exit 1), as
/// `export` says of the same result; everything else is bad input (exit 2).
fn cli_error(e: RenderError) -> anyhow::Error {
    if e.is_measurement_failure() {
        crate::common::MeasurementFailed(e.to_string()).into()
    } else {
        e.into()
    }
}

/// Checks the outputs before any work: extension, not an input, not a link or folder, not an
/// existing file unless --force, a writable folder.
fn check_outputs(args: &Args, inputs: &[PathBuf]) -> anyhow::Result<()> {
    let refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    for out in &args.output {
        check_output_kind(out, args.profile)?;
        crate::common::check_new_output(out, "-o", &refs, args.force)?;
    }
    Ok(())
}

/// Runs `scatterfit render`.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let specs: Vec<String> = match (&args.params, &args.compare) {
        (Some(p), None) => vec![p.clone()],
        (None, Some(c)) => c.clone(),
        _ => bail!("give --params RESULT or --compare A B"),
    };
    let mut inputs: Vec<PathBuf> = specs.iter().map(PathBuf::from).collect();
    inputs.extend(args.mesh.iter().cloned());
    inputs.extend(args.measured_profile.iter().cloned());
    check_outputs(&args, &inputs)?;
    let methods = args.method;
    let panels = if args.profile {
        1
    } else {
        specs.len() * methods.list().len()
    };
    let settings = settings(&args);
    settings.check(panels, args.memory.budget())?;
    let model = args.model;
    let mut params: Vec<ParameterSet> = specs
        .iter()
        .map(|s| ParameterSet::load(s, model).map_err(cli_error))
        .collect::<anyhow::Result<_>>()?;
    // Downstream honesty: a result the data checks did not trust is said so before the work, and
    // the exit code says it after.
    let mut code = ExitCode::SUCCESS;
    for (result, json, _) in params.iter().filter_map(ParameterSet::result) {
        let c = crate::common::suspect_exit(json, result, args.allow_suspect);
        if c != ExitCode::SUCCESS {
            code = c;
        }
    }
    let options = settings.options()?;
    let tone = settings.tone();
    if args.profile {
        return run_profile(&args, params.remove(0), model, options, &tone)
            .map(|c| if c == ExitCode::SUCCESS { code } else { c });
    }

    // The scene: the object read or built, then lit (mesh warnings in between).
    let t0 = Instant::now();
    let mesh = match &args.mesh {
        Some(path) => MeshSource::File {
            path: path.clone(),
            scale: args.mesh_scale,
        },
        None => MeshSource::Builtin {
            shape: args.shape,
            triangles: args.triangles,
        },
    };
    let loaded = mesh.load()?;
    if !args.quiet {
        for note in loaded.notes() {
            errln!("{note}");
        }
    }
    let studio = StudioScene::new(loaded, args.light, t0)?;
    let request = FigureRequest {
        params,
        mesh,
        lights: args.light,
        methods,
        model,
        options,
    };
    let bar = progress_bar(&args, (request.panels().len() * options.height) as u64);
    let panels = render_figure(&studio.scene, &request, &|event| match event {
        RenderEvent::Panel { method, material } => {
            bar.set_message(format!("{} · {material}", method.name()));
        }
        RenderEvent::Rows(n) => bar.inc(n as u64),
    })?;
    bar.finish_and_clear();
    write_figure(&request, &panels, &args.output, &tone, args.gray)?;
    let summary = request.summary(&studio, &panels, &args.output, rayon::current_num_threads());
    print_summary(&args, &summary)?;
    Ok(code)
}

/// `--profile`: the measurement's slab and spot rendered by the texture-space method, compared ring
/// by ring with the measured profile divided by the fitted scale k (Table 2's MSE, §4.4).
fn run_profile(
    args: &Args,
    params: ParameterSet,
    model: Option<ModelName>,
    options: RenderOptions,
    tone: &ToneMap,
) -> anyhow::Result<ExitCode> {
    let (csv, unchecked) = profile_path(
        &params,
        args.measured_profile.as_deref(),
        args.allow_outside_paths,
    )?;
    if let Some(note) = unchecked
        && !args.quiet
    {
        errln!("note: {note}");
    }
    // The profile is an input too: no output may replace it (with --force it could).
    for out in &args.output {
        crate::common::refuse_overwrite(out, "-o", &[csv.as_path()])?;
    }
    let measured = read_measured(&params, &csv, args.spot_radius_mm)?;
    let request = ProfileRequest {
        params,
        measured,
        model,
        options,
    };
    let bar = progress_bar(args, request.measured.setup().image_size() as u64);
    bar.set_message("slab + spot, texture-space dipole");
    let validation = request.run(&|k| bar.inc(k as u64))?;
    bar.finish_and_clear();
    request.write(&validation, &args.output, tone, args.exposure.is_some())?;
    let summary = request.summary(&validation, &args.output, rayon::current_num_threads());
    print_summary(args, &summary)?;
    Ok(ExitCode::SUCCESS)
}

fn print_summary(args: &Args, s: &Summary) -> anyhow::Result<()> {
    if args.json {
        crate::output::print_json(s)
    } else {
        crate::output::out!("{}", s.text())
    }
}

fn progress_bar(args: &Args, len: u64) -> indicatif::ProgressBar {
    crate::common::bar(
        len,
        "{bar:40} {pos}/{len} rows  {msg}  ETA {eta}",
        args.quiet,
    )
}
