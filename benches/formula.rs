//! Formula surfaces against the same built-in surfaces: sampling (a uniform grid and the
//! adaptive sampler, which evaluates points and derivatives) of the flat torus, the Klein
//! bottle and the projective plane, each read from its fixture scene pair
//! (`fixtures/scenes/<name>.json` and `formula-<name>.json`).

use criterion::{Criterion, criterion_group, criterion_main};
use halo4d::{Scene, sample::Sampling, sample::sample, sample::sample_uniform, surfaces::Surface};
use std::hint::black_box;
use std::path::PathBuf;

fn surface(file: &str) -> Surface {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/scenes")
        .join(file);
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.surfaces[0]
        .surface
        .parametric()
        .cloned()
        .expect("a parametric surface")
}

fn sampling(c: &mut Criterion) {
    for name in ["flat-torus", "klein-bottle", "projective-plane"] {
        let pair = [
            ("built-in", surface(&format!("{name}.json"))),
            ("formula", surface(&format!("formula-{name}.json"))),
        ];
        let mut group = c.benchmark_group(format!("formula/{name}"));
        group.sample_size(20);
        for (kind, s) in &pair {
            group.bench_function(format!("uniform-256/{kind}"), |b| {
                b.iter(|| sample_uniform(black_box(s), 256, 256))
            });
            group.bench_function(format!("adaptive-1e-4/{kind}"), |b| {
                b.iter(|| sample(black_box(s), &Sampling::adaptive(1e-4)))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, sampling);
criterion_main!(benches);
