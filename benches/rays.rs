//! Primary rays against Embree: the default scene's projected triangles and the rays of its
//! 1024 x 1024 picture, one through each pixel's centre.
//!
//! Criterion times, on every core, with the rays per second as its throughput:
//! - `nearest`: the tracer alone ([`Tracer::nearest_hits`]: the nearest hit, with the hits
//!   within the tracer's same-hit distance of it), what Embree's closest-hit query does,
//!   through the BVH; `nearest_tiles`, the same hits through the picture's tiles
//!   ([`Primary`], what the renderer's primary rays use);
//! - `picture_surfaces` and `picture_halos`: the exact picture at one sample a pixel (no
//!   lines), without and with the halos' exact hiding test: each ray traced, decided and
//!   shaded, the colours turned into bytes.
//!
//! It also writes `exports/rays/default-scene.bin` (the triangles, the rays and the nearest
//! distance this tracer finds on each) for `benches/embree/rays.c`, which traces the same
//! rays with Embree and checks its hits against these. `benches/embree/run.sh` runs both in
//! one go; the figures are in docs/PERFORMANCE.md.
//!
//! `cargo bench --bench rays`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use halo4d::SurfacePart;
use halo4d::internals::{Camera, Primary, Tracer};
use halo4d::render::{Prober, RenderMode, RenderSettings};
use rayon::prelude::*;
use std::hint::black_box;
use std::path::PathBuf;

/// The picture's side in pixels.
const SIDE: u32 = 1024;

/// A primary ray: its image point, origin and unit direction.
type PrimaryRay = ([f64; 2], DVec3, DVec3);

/// The ray through the centre of each pixel, row by row from the top, as the renderer
/// makes it.
fn rays(cam: &Camera) -> Vec<PrimaryRay> {
    let side = f64::from(SIDE);
    (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = (f64::from(i % SIDE) + 0.5, f64::from(i / SIDE) + 0.5);
            let at = [2.0 * x / side - 1.0, 1.0 - 2.0 * y / side];
            let (origin, dir) = cam.ray(at[0], at[1]);
            (at, origin, dir)
        })
        .collect()
}

/// Writes the triangles (f32 corners, one vertex list for all surfaces), the rays (f32
/// origin and direction) and the nearest distance of each (infinity for a miss), little
/// endian after the magic `H4DRAYS1` and the three counts.
fn write_rays(
    surfaces: &[SurfacePart],
    rays: &[PrimaryRay],
    nearest: &[f64],
    path: &PathBuf,
) -> std::io::Result<()> {
    let vertices: usize = surfaces.iter().map(|s| s.positions.len()).sum();
    let triangles: usize = surfaces.iter().map(|s| s.triangles.len()).sum();
    let mut out = b"H4DRAYS1".to_vec();
    for count in [vertices, triangles, rays.len()] {
        out.extend(u32::try_from(count).expect("counts fit u32").to_le_bytes());
    }
    let f32s = |out: &mut Vec<u8>, v: DVec3| {
        for x in v.to_array() {
            out.extend((x as f32).to_le_bytes());
        }
    };
    for s in surfaces {
        s.positions.iter().for_each(|&p| f32s(&mut out, p));
    }
    let mut base = 0u32;
    for s in surfaces {
        for t in s.triangles {
            t.iter().for_each(|&v| out.extend((v + base).to_le_bytes()));
        }
        base += s.positions.len() as u32;
    }
    for &(_, origin, dir) in rays {
        f32s(&mut out, origin);
        f32s(&mut out, dir);
    }
    for &t in nearest {
        out.extend((t as f32).to_le_bytes());
    }
    std::fs::create_dir_all(path.parent().expect("a folder"))?;
    std::fs::write(path, out)
}

fn primary_rays(c: &mut Criterion) {
    let scene = halo4d::Scene::default_scene();
    let built = halo4d::Sampled::of(&scene)
        .into_built(&scene, halo4d::Stages::of(&scene))
        .expect("the default scene builds");
    let parts = built.parts(&scene.halo);
    let picture = |halos: bool| RenderSettings {
        width: SIDE,
        height: SIDE,
        mode: RenderMode::Exact,
        samples: 1,
        halos,
        curves: false,
        silhouettes: false,
        broken_edges: false,
        ..scene.render
    };
    let with_halos = picture(true);
    let cam = *Prober::new(&parts, &with_halos, &scene.camera)
        .expect("the default scene's camera")
        .camera();
    let rays = rays(&cam);
    // The renderer's tracer and slack (twice the same-hit distance).
    let tracer = Tracer::of_parts(&parts);
    let slack = 2.0 * tracer.same();
    let trace_all = || -> Vec<f64> {
        rays.par_iter()
            .map_init(Vec::new, |hits, &(_, origin, dir)| {
                tracer.nearest_hits(origin, dir, 0.0, slack, hits);
                hits.first().map_or(f64::INFINITY, |h| h.t)
            })
            .collect()
    };
    let primary = Primary::new(&tracer, &cam, SIDE, SIDE);
    let trace_tiles = || -> Vec<f64> {
        rays.par_iter()
            .map_init(Vec::new, |hits, &(at, origin, dir)| {
                primary.nearest_hits(at, origin, dir, 0.0, slack, hits);
                hits.first().map_or(f64::INFINITY, |h| h.t)
            })
            .collect()
    };
    let nearest = trace_all();
    assert_eq!(trace_tiles(), nearest, "the tiles find the BVH's hits");
    let hit = nearest.iter().filter(|t| t.is_finite()).count();
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("exports/rays/default-scene.bin");
    write_rays(&parts.surfaces, &rays, &nearest, &file).expect("the rays file is written");
    let triangles: usize = parts.surfaces.iter().map(|s| s.triangles.len()).sum();
    println!(
        "{} rays, {hit} hitting {triangles} triangles; wrote {}",
        rays.len(),
        file.display()
    );

    let mut group = c.benchmark_group("rays/default_scene_1024");
    group.sample_size(20);
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("nearest", |b| b.iter(|| black_box(trace_all())));
    group.bench_function("nearest_tiles", |b| b.iter(|| black_box(trace_tiles())));
    let without_halos = picture(false);
    for (name, settings) in [
        ("picture_surfaces", &without_halos),
        ("picture_halos", &with_halos),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                built
                    .render(&scene.halo, black_box(settings), &scene.camera)
                    .expect("the default scene renders")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, primary_rays);
criterion_main!(benches);
