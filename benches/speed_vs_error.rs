//! Speed against error of the samplers.
//!
//! First the sweep: for the quartic Fermat, the spun and twist-spun trefoils, the Klein
//! bottle and the flat torus, at relative tolerances 1e-2 to 1e-5, the adaptive sampler and
//! the coarsest uniform grid that meets each tolerance, audited alike. It prints the table
//! (with the ratio of uniform to adaptive triangles) and writes
//! `exports/reports/speed_vs_error.csv`, `exports/reports/speed_vs_error.png` and
//! `exports/reports/curves_vs_error.png`, the same files `halo4d sweep` writes for a scene
//! (each mesh's curves in the default scene's view). Then criterion times adaptive sampling plus
//! audit at 1e-3 and 1e-4 for every surface, and at 1e-5 for the quartic Fermat.
//!
//! `cargo bench --bench speed_vs_error` (several minutes: the uniform grids that reach
//! 1e-5 have millions of triangles).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use halo4d::sample::bounding_diagonal;
use halo4d::surfaces::Surface;
use halo4d::sweep;
use halo4d::{sample::audit, sample::sample_adaptive};
use halo4d::{
    surfaces::Fermat, surfaces::FlatTorus, surfaces::KleinBottle, surfaces::SpunTrefoil,
    surfaces::TwistSpunTrefoil,
};
use std::hint::black_box;
use std::path::PathBuf;

fn surfaces() -> Vec<(String, Surface)> {
    vec![
        ("fermat-quartic".into(), Surface::Fermat(Fermat::default())),
        (
            "spun-trefoil".into(),
            Surface::SpunTrefoil(SpunTrefoil::default()),
        ),
        (
            "twist-spun-trefoil".into(),
            Surface::TwistSpunTrefoil(TwistSpunTrefoil::default()),
        ),
        (
            "klein-bottle".into(),
            Surface::KleinBottle(KleinBottle::default()),
        ),
        (
            "flat-torus".into(),
            Surface::FlatTorus(FlatTorus::default()),
        ),
    ]
}

fn speed_vs_error(c: &mut Criterion) {
    let out = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("exports/reports");
    let (rows, files) = sweep::run(&surfaces(), &sweep::Settings::default(), &out, &mut |m| {
        eprintln!("{m}")
    })
    .expect("the sweep writes its report");
    println!("{}", sweep::table(&rows));
    for f in files {
        println!("wrote {}", f.display());
    }

    let mut group = c.benchmark_group("adaptive_sample_and_audit");
    group.sample_size(10);
    for (name, surface) in surfaces() {
        let d = bounding_diagonal(&surface);
        let tolerances: &[f64] = if name == "fermat-quartic" {
            &[1e-3, 1e-4, 1e-5]
        } else {
            &[1e-3, 1e-4]
        };
        for &tol in tolerances {
            group.bench_with_input(BenchmarkId::new(&name, tol), &tol, |b, &tol| {
                b.iter(|| {
                    let out = sample_adaptive(black_box(&surface), tol * d, 20_000_000);
                    audit(&surface, &out.mesh)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, speed_vs_error);
criterion_main!(benches);
