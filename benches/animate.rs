//! One frame of an animation: the default scene turning in xw
//! (`fixtures/animations/spun-trefoil-xw.json`, frame 90) at 512 x 512 on both cores, from
//! the samples every frame shares: the build in the frame's view (projection, halos,
//! curves, refinement, verification), its picture (rendered and encoded as PNG), and the
//! two together, which is what `halo4d animate` spends per frame.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn frame(c: &mut Criterion) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/animations/spun-trefoil-xw.json"
    );
    let scene = halo4d::Scene::load(std::path::Path::new(path)).expect("the fixture loads");
    let samples = halo4d::Sampled::of(&scene);
    let frame = scene.frame(90).expect("the animation has a frame 90");
    let stages = halo4d::Stages::verified_picture(&frame);
    let built = samples.build(&frame, stages).expect("the frame builds");
    assert!(built.failures().is_empty(), "{:?}", built.failures());
    let picture = || {
        built
            .render(&frame.halo, &frame.render, &frame.camera)
            .expect("the frame renders")
            .png()
    };
    let mut group = c.benchmark_group("animate/default_scene_512");
    group.sample_size(10);
    group.bench_function("build", |b| {
        b.iter(|| samples.build(black_box(&frame), stages).expect("builds"))
    });
    group.bench_function("picture", |b| b.iter(picture));
    group.bench_function("frame", |b| {
        b.iter(|| {
            let built = samples.build(black_box(&frame), stages).expect("builds");
            built
                .render(&frame.halo, &frame.render, &frame.camera)
                .expect("renders")
                .png()
        })
    });
    group.finish();
}

criterion_group!(benches, frame);
criterion_main!(benches);
