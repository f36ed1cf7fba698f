//! Rendering costs: the default scene's picture at 1024 x 1024 in the exact mode and with 256
//! slices (both cores), in the stipple style, and ranking its stipples (once per surface);
//! and broadening one-pixel lines to bands (`render::lines`) with the
//! FFT plans kept between calls: masks of a few hundred seeded random segments, on a sweep of
//! image sizes and widths, and with widths that vary along the segments.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::DVec2;
use halo4d::internals::lines::{Broadener, Mask};
use std::hint::black_box;

/// SplitMix64: reproducible pseudo-random numbers in [0, 1).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` segments from random points in a `side`-pixel square, in random directions, a
/// tenth to a third of the side long, their widths tapering from `widths[0]` to
/// `widths[1]`.
fn random_mask(side: usize, count: usize, widths: [f64; 2]) -> Mask {
    let mut rng = Rng(0x11e5);
    let mut mask = Mask::new(side, side).expect("a valid size");
    let s = side as f64;
    for _ in 0..count {
        let a = DVec2::new(rng.unit() * s, rng.unit() * s);
        let angle = rng.unit() * std::f64::consts::TAU;
        let length = s * (0.1 + 0.23 * rng.unit());
        let b = a + length * DVec2::new(angle.cos(), angle.sin());
        mask.draw_polyline(&[(a, widths[0]), (b, widths[1])])
            .expect("finite points and valid widths");
    }
    mask
}

fn pictures(c: &mut Criterion) {
    let scene = halo4d::Scene::default_scene();
    let built = halo4d::Sampled::of(&scene)
        .into_built(&scene, halo4d::Stages::of(&scene))
        .expect("the default scene builds");
    let mut group = c.benchmark_group("render/default_scene_1024");
    group.sample_size(10);
    for (name, mode) in [
        ("exact", halo4d::render::RenderMode::Exact),
        ("slices_256", halo4d::render::RenderMode::Slices),
    ] {
        let settings = halo4d::render::RenderSettings {
            mode,
            slices: 256,
            ..scene.render
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                built
                    .render(&scene.halo, black_box(&settings), &scene.camera)
                    .expect("the default scene renders")
            })
        });
    }
    group.finish();
}

fn stipples(c: &mut Criterion) {
    let mut scene = halo4d::Scene::default_scene();
    scene.render.style = halo4d::render::Style::Stipple;
    let built = halo4d::Sampled::of(&scene)
        .into_built(&scene, halo4d::Stages::of(&scene))
        .expect("the default scene builds");
    let mut group = c.benchmark_group("render/default_scene_1024");
    group.sample_size(10);
    group.bench_function("stipple", |b| {
        b.iter(|| {
            built
                .render(&scene.halo, black_box(&scene.render), &scene.camera)
                .expect("the default scene renders")
        })
    });
    group.finish();
    let mesh = &built.surfaces[0].mesh;
    let count = scene.render.stipple.count;
    let mut group = c.benchmark_group("stipples/default_scene");
    group.sample_size(10);
    group.bench_function(format!("rank_{count}"), |b| {
        b.iter(|| {
            halo4d::stipple::Stipples::generate(
                black_box(&mesh.positions),
                &mesh.triangles,
                count,
                1,
            )
        })
    });
    group.finish();
}

fn broaden(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/broaden");
    group.sample_size(20);
    let mut broadener = Broadener::new();
    for (side, width) in [
        (256, 5.0),
        (512, 5.0),
        (1024, 1.5),
        (1024, 5.0),
        (1024, 8.0),
    ] {
        let mask = random_mask(side, 300, [width, width]);
        group.bench_with_input(
            BenchmarkId::new(format!("{side}x{side}"), format!("{width}px")),
            &mask,
            |b, mask| b.iter(|| broadener.broaden(black_box(mask), width)),
        );
    }
    let mask = random_mask(1024, 300, [8.0, 1.5]);
    group.bench_with_input(
        BenchmarkId::new("1024x1024", "varying_8_to_1.5px"),
        &mask,
        |b, mask| b.iter(|| broadener.broaden_varying(black_box(mask))),
    );
    group.finish();
}

criterion_group!(benches, pictures, stipples, broaden);
criterion_main!(benches);
