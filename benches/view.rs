//! The view search (`halo4d view`): the default scene's search on both cores, with the
//! visible share of the curves it finds printed beside the scene's own view's.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn view_search(c: &mut Criterion) {
    let scene = halo4d::Scene::default_scene();
    let found = halo4d::search_view(&scene, halo4d::progress::Job::SILENT)
        .expect("the default scene has a view");
    eprintln!(
        "view search of the default scene: {} 4D views on {} triangles, visible share of the curves {:.3} (the scene's own view {:.3}), score {:.0} ({:.0})",
        found.views,
        found.triangles,
        found.visible_curve_share,
        found.start_share,
        found.score,
        found.start_score
    );
    let mut group = c.benchmark_group("view_search");
    group.sample_size(10);
    group.bench_function("default", |b| {
        b.iter(|| {
            halo4d::search_view(black_box(&scene), halo4d::progress::Job::SILENT).expect("a view")
        })
    });
    group.finish();
}

criterion_group!(benches, view_search);
criterion_main!(benches);
