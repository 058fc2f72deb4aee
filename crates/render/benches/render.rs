//! Renderer hot paths on the reference case: the statue at about 100 000 triangles, 512 × 512, pink
//! plastic (Choi et al. 2014, Table 1) under the studio lights, 1 sample per pixel.
//! Run: `cargo bench -p scatterfit-render --bench render`.

use divan::{Bencher, black_box};
use scatterfit_optics::Rgb;
use scatterfit_render::{
    Material, Method, RenderOptions, Scene, Shape, render, studio, studio_lights,
};

fn main() {
    divan::main();
}

const SIZE: usize = 512;

fn material() -> Material {
    Material::dipole(
        Rgb::from_array([(1.979, 0.000792), (1.893, 0.0496), (1.992, 0.0227)]),
        1.2886,
    )
    .unwrap()
}

fn scene() -> Scene {
    studio(Shape::Statue.mesh(100_000).unwrap(), studio_lights()).unwrap()
}

fn options() -> RenderOptions {
    RenderOptions {
        width: SIZE,
        height: SIZE,
        spp: 1,
        ..RenderOptions::default()
    }
}

#[divan::bench(name = "BVH build, statue 99 540 triangles", sample_count = 10)]
fn bvh_build(bencher: Bencher) {
    let mesh = Shape::Statue.mesh(100_000).unwrap();
    bencher.bench_local(|| black_box(scatterfit_render::bvh::Bvh::new(black_box(&mesh))));
}

#[divan::bench(name = "camera rays, 512×512", sample_count = 5)]
fn camera_rays(bencher: Bencher) {
    use rayon::prelude::*;
    let scene = scene();
    bencher.bench_local(|| {
        (0..SIZE)
            .into_par_iter()
            .map(|j| {
                (0..SIZE)
                    .filter(|&i| {
                        let ray = scene
                            .camera()
                            .ray(i as f64 + 0.5, j as f64 + 0.5, SIZE, SIZE);
                        scene.intersect(&ray, f64::INFINITY).is_some()
                    })
                    .count()
            })
            .sum::<usize>()
    });
}

#[divan::bench(name = "subsurface colour method, 512×512, 1 spp", sample_count = 5)]
fn colour_method(bencher: Bencher) {
    let (scene, material, opts) = (scene(), material(), options());
    bencher.bench_local(|| render(&scene, &material, Method::Colour, &opts, &|_| {}).unwrap());
}

#[divan::bench(name = "texture-space dipole method, 512×512, 1 spp", sample_count = 5)]
fn dipole_method(bencher: Bencher) {
    let (scene, material, opts) = (scene(), material(), options());
    bencher.bench_local(|| render(&scene, &material, Method::Dipole, &opts, &|_| {}).unwrap());
}
