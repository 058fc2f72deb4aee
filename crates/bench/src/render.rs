//! The renderer figures (`scatterfit bench render`): the validation renderer, stage by stage.

use std::time::Instant;

use rayon::prelude::*;
use scatterfit_render::{Material, Method, RenderOptions, Shape, render, studio, studio_lights};

use crate::{Figure, Result};

/// The reference case — the statue at about 100 000 triangles, 512 × 512, both methods, pink plastic
/// (Table 1) under the studio lights — with the time of each stage.
pub fn figures(quick: bool) -> Result<Vec<Figure>> {
    let (size, triangles) = if quick { (128, 20_000) } else { (512, 100_000) };
    let threads = rayon::current_num_threads();
    let m = &scatterfit_optics::materials::CHOI_2014[0];
    let material = Material::dipole(
        scatterfit_optics::Rgb::from_fn(|c| (m.sigma_s_prime[c.index()], m.sigma_a[c.index()])),
        m.eta,
    )?;
    let mut figures = Vec::new();
    let mut fig = |name: String, value: f64, unit: &str, note: String| {
        figures.push(Figure {
            name,
            value,
            unit: unit.into(),
            note,
        })
    };
    let t0 = Instant::now();
    let mesh = Shape::Statue.mesh(triangles)?;
    let tris = mesh.triangles().len();
    let mesh_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let scene = studio(mesh, studio_lights())?;
    let bvh_s = t0.elapsed().as_secs_f64();
    let ctx = format!("{tris} triangles, {threads} threads");
    fig(
        format!("render: statue mesh ({tris} triangles)"),
        mesh_s,
        "s",
        ctx.clone(),
    );
    fig(
        "render: BVH build (binned SAH)".into(),
        bvh_s,
        "s",
        ctx.clone(),
    );
    // Camera rays alone: what every method pays before shading.
    let t0 = Instant::now();
    let hits: usize = (0..size)
        .into_par_iter()
        .map(|j| {
            (0..size)
                .filter(|&i| {
                    let ray = scene
                        .camera()
                        .ray(i as f64 + 0.5, j as f64 + 0.5, size, size);
                    scene.intersect(&ray, f64::INFINITY).is_some()
                })
                .count()
        })
        .sum();
    let rays_s = t0.elapsed().as_secs_f64();
    fig(
        format!("render: camera rays only, {size}×{size}, 1 spp"),
        rays_s,
        "s",
        format!("{hits} hits; {ctx}"),
    );
    for spp in [1usize, 4] {
        let opts = RenderOptions {
            width: size,
            height: size,
            spp,
            ..RenderOptions::default()
        };
        let colour = render(&scene, &material, Method::Colour, &opts, &|_| {})?;
        let dipole = render(&scene, &material, Method::Dipole, &opts, &|_| {})?;
        let tag = format!("{size}×{size}, {spp} spp");
        fig(
            format!("render: subsurface colour shading, {tag}"),
            colour.timings.shading_s,
            "s",
            format!("camera + shadow + thickness rays; {ctx}"),
        );
        if spp == 1 {
            fig(
                "render: dipole irradiance points (light rays)".into(),
                dipole.timings.irradiance_s,
                "s",
                format!(
                    "{} rays, {} points",
                    dipole.stats.light_rays, dipole.stats.irradiance_points
                ),
            );
            fig(
                "render: dipole profile tables + point hierarchy".into(),
                dipole.timings.tree_s,
                "s",
                format!("{} nodes", dipole.stats.tree_nodes),
            );
        }
        fig(
            format!("render: dipole shading, {tag}"),
            dipole.timings.shading_s,
            "s",
            format!(
                "{:.0} nodes+points per sample; {ctx}",
                dipole.stats.mean_visited
            ),
        );
        let both = colour.timings.shading_s
            + dipole.timings.irradiance_s
            + dipole.timings.tree_s
            + dipole.timings.shading_s;
        fig(
            format!("render: both methods end to end, {tag}"),
            mesh_s + bvh_s + both,
            "s",
            if spp == 1 {
                format!("mesh + BVH + both renders; target < 5 s on 2 cores; {ctx}")
            } else {
                format!("the command's default spp; {ctx}")
            },
        );
    }
    Ok(figures)
}
