//! The render passes: camera rays through the BVH, shading by one of the paper's two methods, in
//! parallel over rows (rayon), deterministic for a seed.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use scatterfit_imaging::ImageBuf;
use scatterfit_optics::Channel;
use scatterfit_optics::fresnel::fresnel_dielectric;

use crate::bvh::Ray;
use crate::colour::{ColourParams, Layer, rho_s, tangent, translucent_falloff, ward_specular};
use crate::error::{Result, invalid};
use crate::profile::{Material, RdTable};
use crate::rng::stream;
use crate::scene::{Scene, SurfacePoint};
use crate::texture_space::{
    DipoleParams, Evaluation, PointCloud, auto_light_rays, irradiance_points,
};

/// Which of the paper's methods shades the surface (written as its [`Method::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Method {
    /// Subsurface colour, §4.1, eqs. (3)–(5).
    #[serde(rename = "color")]
    Colour,
    /// Texture-space dipole, §4.2, eq. (6).
    #[serde(rename = "dipole")]
    Dipole,
}

impl Method {
    /// A short name: `color` or `dipole`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Colour => "color",
            Method::Dipole => "dipole",
        }
    }

    /// The paper's caption for the method.
    pub fn title(self) -> &'static str {
        match self {
            Method::Colour => "subsurface colour (§4.1)",
            Method::Dipole => "texture-space dipole (§4.2)",
        }
    }
}

/// Options of [`render`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Image width \[pixels\].
    pub width: usize,
    /// Image height \[pixels\].
    pub height: usize,
    /// Camera samples per pixel: 1 is the pixel centre; a perfect square is stratified (jittered
    /// grid); other counts are uniform random. Box filter. The texture-space method evaluates the
    /// subsurface sum B once per pixel and surface patch (samples within one pixel footprint of the
    /// first and facing the same way reuse it, as the paper's irradiance texture would) and the
    /// per-sample terms (Ft(ωo), specular) for every sample.
    pub spp: usize,
    /// Seed of every random stream.
    pub seed: u64,
    /// Subsurface colour method parameters.
    pub colour: ColourParams,
    /// Texture-space method parameters.
    pub dipole: DipoleParams,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            spp: 4,
            seed: 1,
            colour: ColourParams::default(),
            dipole: DipoleParams::default(),
        }
    }
}

/// Where the time went \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timings {
    /// Shooting the lights' rays for the irradiance points (dipole method).
    pub irradiance_s: f64,
    /// Tabulating the profiles and building the point hierarchy (dipole method).
    pub tree_s: f64,
    /// Camera rays and shading.
    pub shading_s: f64,
}

/// What a render reports besides its image.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RenderStats {
    /// Rays shot per light (dipole method).
    pub light_rays: usize,
    /// Irradiance points (dipole method).
    pub irradiance_points: usize,
    /// Nodes of the point hierarchy (dipole method).
    pub tree_nodes: usize,
    /// Mean nodes + points visited per camera sample that hit the mesh (dipole method; samples
    /// that reuse their pixel's B count 0).
    pub mean_visited: f64,
    /// Fraction of camera samples that hit the mesh.
    pub hit_fraction: f64,
    /// Samples whose radiance came out non-finite or negative and were set to 0 (should be 0;
    /// reported so that a numerical failure cannot hide).
    pub invalid_samples: usize,
}

/// A rendered image: linear sRGB radiance (relative units: an irradiance of 1 on a perfect white
/// Lambertian surface facing the light gives 1/π), background 0.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The method.
    pub method: Method,
    /// Linear radiance, 3 channels, row-major from the top.
    pub image: ImageBuf<f32>,
    /// Where the time went.
    pub timings: Timings,
    /// Counters.
    pub stats: RenderStats,
}

enum Shader<'a> {
    Colour {
        layers: [Layer; 3],
        rho_s: f64,
        params: ColourParams,
    },
    Dipole {
        cloud: PointCloud,
        material: &'a Material,
        eval: Evaluation,
        specular: Option<(f64, ColourParams)>,
    },
}

/// Renders `scene` with `material` by `method`. `progress` is called with the number of rows
/// finished (from any thread).
///
/// # Errors
/// [`crate::RenderError::InvalidOption`] for a zero image size or samples, or invalid parameters.
pub fn render(
    scene: &Scene,
    material: &Material,
    method: Method,
    opts: &RenderOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Rendered> {
    if opts.width == 0 || opts.height == 0 || opts.width * opts.height > 1 << 28 {
        return Err(invalid(
            "image size",
            format!("{}x{}", opts.width, opts.height),
            "width and height must be ≥ 1 and the image at most 2^28 pixels",
        ));
    }
    if opts.spp == 0 || opts.spp > 4096 {
        return Err(invalid("spp", opts.spp, "must be 1–4096"));
    }
    opts.colour.validate()?;
    opts.dipole.validate()?;
    let eta = material.eta();
    let mut timings = Timings::default();
    let mut stats = RenderStats::default();
    let shader = match method {
        Method::Colour => Shader::Colour {
            layers: material
                .coefficients()
                .map(|(sp, sa)| Layer::new(sp, sa, eta, opts.colour.g))
                .into_array(),
            rho_s: rho_s(&opts.colour, eta),
            params: opts.colour,
        },
        Method::Dipole => {
            let t0 = Instant::now();
            // Distances between surface points never exceed the mesh's bounding-box diagonal.
            let diameter = scene.bvh().bounds().extent().length();
            let tables = Channel::ALL.map(|c| RdTable::new(material.profile(c), diameter));
            let tables_s = t0.elapsed().as_secs_f64();
            let rays = opts
                .dipole
                .light_rays
                .unwrap_or_else(|| auto_light_rays(scene, &tables));
            stats.light_rays = rays;
            let t0 = Instant::now();
            let points = irradiance_points(scene, eta, rays, opts.seed);
            timings.irradiance_s = t0.elapsed().as_secs_f64();
            stats.irradiance_points = points.len();
            let t0 = Instant::now();
            let cloud = PointCloud::with_tables(points, tables);
            timings.tree_s = tables_s + t0.elapsed().as_secs_f64();
            stats.tree_nodes = cloud.node_count();
            Shader::Dipole {
                cloud,
                material,
                eval: opts.dipole.evaluation,
                specular: opts
                    .dipole
                    .specular
                    .then(|| (rho_s(&opts.colour, eta), opts.colour)),
            }
        }
    };
    let (w, h, spp) = (opts.width, opts.height, opts.spp);
    let grid = (spp as f64).sqrt().round() as usize;
    let stratified = grid * grid == spp && spp > 1;
    let t0 = Instant::now();
    // The texture-space method's B on a grid of anchors every second pixel (the paper's irradiance
    // texture, in screen space), interpolated where the surface is continuous.
    let anchors = match &shader {
        Shader::Dipole {
            cloud,
            material,
            eval,
            ..
        } if opts.dipole.interpolate => Some(Anchors::new(scene, cloud, material, *eval, w, h)),
        _ => None,
    };
    let mut data = vec![0f32; w * h * 3];
    // Per row: (samples that hit, nodes visited, invalid samples).
    let counters: Vec<(usize, usize, usize)> = data
        .par_chunks_mut(w * 3)
        .enumerate()
        .map(|(j, row)| {
            let mut counts = (0, 0, 0);
            for i in 0..w {
                let mut rng = stream(opts.seed, (j * w + i) as u64);
                let mut sum = [0.0f64; 3];
                // (position, normal, footprint², B) of the pixel's first dipole evaluation.
                let mut cache: Option<(DVec3, DVec3, f64, [f64; 3])> = None;
                for s in 0..spp {
                    let (dx, dy) = if spp == 1 {
                        (0.5, 0.5)
                    } else if stratified {
                        (
                            ((s % grid) as f64 + rng.uniform()) / grid as f64,
                            ((s / grid) as f64 + rng.uniform()) / grid as f64,
                        )
                    } else {
                        (rng.uniform(), rng.uniform())
                    };
                    let ray = scene.camera().ray(i as f64 + dx, j as f64 + dy, w, h);
                    let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                        continue;
                    };
                    counts.0 += 1;
                    let mut sp = scene.surface(&ray, &hit);
                    let wo = -ray.dir;
                    if sp.ng.dot(wo) < 0.0 {
                        // Seen from behind (an open mesh): shade the side facing the camera.
                        sp.ng = -sp.ng;
                        sp.ns = -sp.ns;
                        sp.p_shadow = sp.p;
                    }
                    let (l, visited) = match &shader {
                        Shader::Colour {
                            layers,
                            rho_s,
                            params,
                        } => (shade_colour(scene, layers, *rho_s, params, &sp, wo), 0),
                        Shader::Dipole {
                            cloud,
                            material,
                            eval,
                            specular,
                        } => {
                            let f = scene.camera().pixel_footprint(hit.t, h);
                            let reuse = anchors
                                .as_ref()
                                .and_then(|a| a.interpolate(i as f64 + dx, j as f64 + dy, &sp, f))
                                .or_else(|| {
                                    cache
                                        .filter(|(p, n, f2, _)| {
                                            (sp.p - *p).length_squared() <= *f2
                                                && sp.ns.dot(*n) > 0.9
                                        })
                                        .map(|c| c.3)
                                });
                            let (b, visited) = match reuse {
                                Some(b) => (b, 0),
                                None => {
                                    let (b, v) = subsurface(cloud, material, *eval, sp.p);
                                    cache = Some((sp.p, sp.ns, f * f, b));
                                    (b, v)
                                }
                            };
                            (shade_dipole(scene, material, b, specular, &sp, wo), visited)
                        }
                    };
                    counts.1 += visited;
                    for c in 0..3 {
                        if l[c].is_finite() && l[c] >= 0.0 {
                            sum[c] += l[c];
                        } else {
                            counts.2 += 1;
                        }
                    }
                }
                for c in 0..3 {
                    row[3 * i + c] = (sum[c] / spp as f64) as f32;
                }
            }
            progress(1);
            counts
        })
        .collect();
    timings.shading_s = t0.elapsed().as_secs_f64();
    let hits: usize = counters.iter().map(|c| c.0).sum();
    stats.hit_fraction = hits as f64 / (w * h * spp) as f64;
    let anchor_visits = anchors.as_ref().map_or(0, |a| a.visited);
    stats.mean_visited = if hits > 0 {
        (counters.iter().map(|c| c.1).sum::<usize>() + anchor_visits) as f64 / hits as f64
    } else {
        0.0
    };
    stats.invalid_samples = counters.iter().map(|c| c.2).sum();
    Ok(Rendered {
        method,
        image: ImageBuf::new(w, h, 3, data)?,
        timings,
        stats,
    })
}

/// Subsurface colour method at one surface point (see [`crate::colour`] for the reading of eqs.
/// 3–5): radiance per channel.
fn shade_colour(
    scene: &Scene,
    layers: &[Layer; 3],
    rho_s: f64,
    params: &ColourParams,
    sp: &SurfacePoint,
    wo: DVec3,
) -> [f64; 3] {
    let eps = scene.eps();
    let mut out = [0.0; 3];
    let inv_pi = std::f64::consts::FRAC_1_PI;
    for light in scene.lights() {
        let Some(inc) = light.incident(sp.p) else {
            continue;
        };
        let l = inc.l;
        if sp.ng.dot(l) > 0.0 {
            // Facing the light: lit unless shadowed; the layer under it is the chord along −l.
            let origin = sp.p_shadow + sp.ng * eps;
            if scene.occluded(origin, l, inc.dist) {
                continue;
            }
            let cos_t = sp.ns.dot(l).max(0.0);
            let inward = Ray {
                origin: sp.p - sp.ng * eps,
                dir: -l,
            };
            let d = scene
                .intersect(&inward, f64::INFINITY)
                .map_or(f64::INFINITY, |h| h.t);
            let spec = ward_specular(
                sp.ns,
                tangent(sp.ns),
                l,
                wo,
                rho_s,
                params.alpha_x,
                params.alpha_y,
            ) * cos_t;
            for c in 0..3 {
                out[c] +=
                    inc.e[c] * (params.rho_d * cos_t * layers[c].reflectance(d) * inv_pi + spec);
            }
        } else {
            // Facing away: light that entered where the ray towards the light leaves the object.
            let toward = Ray {
                origin: sp.p - sp.ng * eps,
                dir: l,
            };
            let Some(hit) = scene.intersect(&toward, inc.dist) else {
                continue;
            };
            let entry = scene.surface(&toward, &hit);
            let cos_e = entry.ng.dot(l);
            if cos_e <= 0.0 {
                continue; // the ray meets an inner face first (another part of the object)
            }
            let Some(inc_e) = light.incident(entry.p) else {
                continue;
            };
            if scene.occluded(entry.p_shadow + entry.ng * eps, l, inc_e.dist) {
                continue;
            }
            let d = hit.t;
            let fall = translucent_falloff(params, d);
            for c in 0..3 {
                out[c] += inc_e.e[c] * cos_e * fall * layers[c].transmittance(d) * inv_pi;
            }
        }
    }
    out
}

/// Anchors whose B differ by more than this factor in a channel are not interpolated (1.05: half
/// the error, 1.5× the time; no limit: twice the error at the 99th percentile, 3× at the worst).
const MAX_ANCHOR_RATIO: f64 = 1.2;

/// One anchor: position, shading normal, B.
type Anchor = (DVec3, DVec3, [f64; 3]);

/// B at the centres of pixels (2i, 2j).
struct Anchors {
    aw: usize,
    ah: usize,
    data: Vec<Option<Anchor>>,
    visited: usize,
}

impl Anchors {
    fn new(
        scene: &Scene,
        cloud: &PointCloud,
        material: &Material,
        eval: Evaluation,
        w: usize,
        h: usize,
    ) -> Self {
        let (aw, ah) = (w / 2 + 2, h / 2 + 2);
        let rows: Vec<(Vec<Option<Anchor>>, usize)> = (0..ah)
            .into_par_iter()
            .map(|aj| {
                let mut visited = 0;
                let row = (0..aw)
                    .map(|ai| {
                        let (x, y) = (2.0 * ai as f64 + 0.5, 2.0 * aj as f64 + 0.5);
                        let ray = scene.camera().ray(x, y, w, h);
                        let hit = scene.intersect(&ray, f64::INFINITY)?;
                        let mut sp = scene.surface(&ray, &hit);
                        if sp.ng.dot(ray.dir) > 0.0 {
                            sp.ns = -sp.ns;
                        }
                        let (b, v) = subsurface(cloud, material, eval, sp.p);
                        visited += v;
                        Some((sp.p, sp.ns, b))
                    })
                    .collect();
                (row, visited)
            })
            .collect();
        let visited = rows.iter().map(|r| r.1).sum();
        Self {
            aw,
            ah,
            data: rows.into_iter().flat_map(|r| r.0).collect(),
            visited,
        }
    }

    /// Bilinear interpolation of B at image position (x, y) from the four surrounding anchors, if
    /// all four see the same smooth surface as `sp` (within 6 pixel footprints `f` of it, normals
    /// within 18°) and their B agree within 20 % in every channel; None otherwise (the caller
    /// evaluates B itself).
    fn interpolate(&self, x: f64, y: f64, sp: &SurfacePoint, f: f64) -> Option<[f64; 3]> {
        let (u, v) = (((x - 0.5) / 2.0).max(0.0), ((y - 0.5) / 2.0).max(0.0));
        let (i, j) = (u as usize, v as usize);
        if i + 1 >= self.aw || j + 1 >= self.ah {
            return None;
        }
        let (fu, fv) = (u - i as f64, v - j as f64);
        let reach2 = (6.0 * f).powi(2);
        let mut out = [0.0; 3];
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [0.0f64; 3]);
        for (di, dj, wgt) in [
            (0, 0, (1.0 - fu) * (1.0 - fv)),
            (1, 0, fu * (1.0 - fv)),
            (0, 1, (1.0 - fu) * fv),
            (1, 1, fu * fv),
        ] {
            let (p, n, b) = self.data[(j + dj) * self.aw + i + di]?;
            if (p - sp.p).length_squared() > reach2 || n.dot(sp.ns) < 0.95 {
                return None;
            }
            for c in 0..3 {
                out[c] += wgt * b[c];
                lo[c] = lo[c].min(b[c]);
                hi[c] = hi[c].max(b[c]);
            }
        }
        // Where B changes fast (shadow edges seen through short profiles) evaluate instead.
        (0..3)
            .all(|c| hi[c] <= MAX_ANCHOR_RATIO * lo[c])
            .then_some(out)
    }
}

/// B(xo) = Σ Φk Rd(‖xk − xo‖) and the number of nodes and points visited.
fn subsurface(
    cloud: &PointCloud,
    material: &Material,
    eval: Evaluation,
    x: DVec3,
) -> ([f64; 3], usize) {
    match eval {
        Evaluation::Direct => (cloud.eval_direct(x, material), cloud.points().len()),
        Evaluation::Hierarchical { max_angle } => cloud.eval_hierarchical(x, max_angle),
    }
}

/// Texture-space dipole at one surface point: Ft(η, ωo)·B(xo)/π (+ the specular term).
fn shade_dipole(
    scene: &Scene,
    material: &Material,
    b: [f64; 3],
    specular: &Option<(f64, ColourParams)>,
    sp: &SurfacePoint,
    wo: DVec3,
) -> [f64; 3] {
    let cos_o = sp.ns.dot(wo).clamp(0.0, 1.0);
    let ft = 1.0 - fresnel_dielectric(cos_o, material.eta());
    let mut out = b.map(|v| ft * v * std::f64::consts::FRAC_1_PI);
    if let Some((rho_s, params)) = specular {
        let eps = scene.eps();
        for light in scene.lights() {
            let Some(inc) = light.incident(sp.p) else {
                continue;
            };
            if sp.ng.dot(inc.l) <= 0.0 || scene.occluded(sp.p_shadow + sp.ng * eps, inc.l, inc.dist)
            {
                continue;
            }
            let cos_t = sp.ns.dot(inc.l).max(0.0);
            let f = ward_specular(
                sp.ns,
                tangent(sp.ns),
                inc.l,
                wo,
                *rho_s,
                params.alpha_x,
                params.alpha_y,
            ) * cos_t;
            for (o, e) in out.iter_mut().zip(inc.e) {
                *o += e * f;
            }
        }
    }
    out
}
