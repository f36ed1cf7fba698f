//! Intersection curves: all curves of the flat-torus fixture's view, chained, on uniform
//! grids of 316 x 316 (199,712 triangles) and 708 x 708 (1,002,528 triangles), on every
//! core (`RAYON_NUM_THREADS=1` for one). Before the timed runs, prints how one run splits
//! between building the BVH, traversing it with the exact tests (and the exact tests' time
//! summed over the cores) and chaining.
//!
//! Refinement (`refine/...`): moving those curves onto the analytic surfaces, on the flat
//! torus at 316 x 316 and on the default scene's spun trefoil on a grid of about 200,000
//! triangles; before the timed runs, prints its time against the curve stage's.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use halo4d::{
    Scene, intersect::Analytic, intersect::Curves, sample::Mesh4, sample::sample_uniform,
    view::Projected,
};
use halo4d::{intersect::Sheet, intersect::curves, intersect::refine};
use std::hint::black_box;
use std::path::Path;

fn curve_costs(c: &mut Criterion) {
    let scene =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes/flat-torus.json"))
            .expect("the flat-torus fixture loads");
    let mut group = c.benchmark_group("curves/flat_torus");
    group.sample_size(10);
    for n in [316, 708] {
        let mesh = sample_uniform(scene.surfaces[0].surface.parametric().unwrap(), n, n);
        let projected = scene.view.project(&mesh).expect("the view projects");
        let sheets = [Sheet {
            positions: &projected.positions,
            w: &projected.w,
            triangles: &mesh.triangles,
        }];
        let r = curves(&sheets).report;
        eprintln!(
            "{} triangles on {} threads: {:.1} ms = BVH {:.1} + traversal with the exact tests {:.1} \
             (exact tests {:.1} summed over the threads) + chaining {:.1}; \
             {} candidate pairs, {} segments, {} curves, {:.2} M triangles/s",
            r.triangles,
            rayon::current_num_threads(),
            r.ms,
            r.bvh_ms,
            r.traverse_ms,
            r.exact_ms,
            r.chain_ms,
            r.candidate_pairs,
            r.segments,
            r.count,
            r.triangles as f64 / r.ms / 1e3,
        );
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        group.bench_with_input(
            BenchmarkId::from_parameter(mesh.triangles.len()),
            &sheets,
            |b, s| b.iter(|| curves(black_box(s))),
        );
    }
    group.finish();
}

/// A scene's first surface on an n x n grid, projected: the mesh and its projection.
fn grid(scene: &Scene, n: usize) -> (Mesh4, Projected) {
    let mesh = sample_uniform(scene.surfaces[0].surface.parametric().unwrap(), n, n);
    let projected = scene.view.project(&mesh).expect("the view projects");
    (mesh, projected)
}

fn refine_costs(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes");
    let mut group = c.benchmark_group("refine");
    group.sample_size(10);
    for (file, n) in [("flat-torus.json", 316), ("default.json", 316)] {
        let scene = Scene::load(&dir.join(file)).expect("the fixture loads");
        let (mesh, projected) = grid(&scene, n);
        let sheets = [Sheet {
            positions: &projected.positions,
            w: &projected.w,
            triangles: &mesh.triangles,
        }];
        let analytic = [Analytic {
            surface: scene.surfaces[0].surface.parametric(),
            mesh: &mesh,
        }];
        let (lo, hi) = projected.bounds().expect("a mesh");
        let diagonal = (hi - lo).length();
        let found: Curves = curves(&sheets);
        let refined = refine(&found, &sheets, &analytic, &scene.view, diagonal);
        let r = refined.report.refinement.as_ref().expect("refined");
        eprintln!(
            "{}: {} triangles, {} curve points: curves {:.1} ms, refinement {:.1} ms ({:.1}% of the curves); \
             {} refined, {} not converged, {} trimmed, max shift {:.1e}, max residual {:.1e}",
            scene.name,
            mesh.triangles.len(),
            found.report.points,
            found.report.ms,
            r.refine_ms,
            100.0 * r.refine_ms / found.report.ms,
            r.refined,
            r.not_converged,
            r.trimmed,
            r.max_shift,
            r.max_residual,
        );
        group.bench_with_input(
            BenchmarkId::new(scene.name.clone(), mesh.triangles.len()),
            &found,
            |b, found| {
                b.iter(|| refine(black_box(found), &sheets, &analytic, &scene.view, diagonal))
            },
        );
    }
    group.finish();
}

criterion_group!(benches, curve_costs, refine_costs);
criterion_main!(benches);
