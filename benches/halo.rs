//! Halo costs: thickening, splitting, fixing and checking a million prisms with each split,
//! and the independent checker alone. The flat torus on a 708 x 708 grid (1,002,528
//! triangles, four cross-caps) in the flat-torus fixture's view; throughput in prisms per
//! second.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use halo4d::check::check;
use halo4d::halo::build_halo;
use halo4d::internals::tets::Split;
use halo4d::{Scene, sample::sample_uniform};
use std::hint::black_box;
use std::path::Path;

fn halos(c: &mut Criterion) {
    let scene =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes/flat-torus.json"))
            .expect("the flat-torus fixture loads");
    let mesh = sample_uniform(scene.surfaces[0].surface.parametric().unwrap(), 708, 708);
    let projected = scene.view.project(&mesh).expect("the view projects");
    let (lo, hi) = projected.bounds().expect("a mesh");
    // The half-width of the flat torus's halo as the scene's own rho was (a share of the
    // diagonal), so that the figures stay comparable.
    let rho = scene.halo.rho.unwrap_or(0.01) * (hi - lo).length();
    let prisms = mesh.triangles.len() as u64;

    let mut group = c.benchmark_group("halo/flat_torus_1M");
    group.sample_size(10);
    group.throughput(Throughput::Elements(prisms));
    for split in [Split::GlobalOrder, Split::Paper, Split::Quality] {
        let params = halo4d::halo::HaloParams {
            split,
            ..scene.halo
        };
        group.bench_with_input(
            BenchmarkId::from_parameter(split.name()),
            &params,
            |b, p| b.iter(|| build_halo(black_box(&projected), &mesh.triangles, rho, p)),
        );
    }
    let (halo, _) = build_halo(&projected, &mesh.triangles, rho, &scene.halo);
    let tet_mesh = halo.tet_mesh(&mesh.triangles);
    group.bench_function("check", |b| b.iter(|| check(black_box(&tet_mesh))));
    group.finish();
}

criterion_group!(benches, halos);
criterion_main!(benches);
