//! Stage costs of the build: uniform sampling, projection and export (with the halo and the
//! intersection curves), on a sweep of grid sizes, for the default scene's spun trefoil and
//! the quartic Fermat.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use halo4d::export::to_glb;
use halo4d::{export::SurfaceData, export::to_ply, export::write_vtk};
use halo4d::{halo::HaloParams, halo::build_halo};
use halo4d::{sample::sample_uniform, surfaces::Surface, view::View};
use halo4d::{surfaces::Fermat, surfaces::SpunTrefoil};
use std::hint::black_box;

fn surfaces() -> [(&'static str, Surface); 2] {
    [
        ("spun_trefoil", Surface::SpunTrefoil(SpunTrefoil::default())),
        ("fermat_quartic", Surface::Fermat(Fermat::default())),
    ]
}

fn stages(c: &mut Criterion) {
    let view = halo4d::Scene::default_scene().view;
    for (name, surface) in surfaces() {
        let mut group = c.benchmark_group(format!("sample/{name}"));
        for cells in [16, 64, 256] {
            group.bench_with_input(BenchmarkId::from_parameter(cells), &cells, |b, &n| {
                b.iter(|| sample_uniform(black_box(&surface), n, n))
            });
        }
        group.finish();

        let mesh = sample_uniform(&surface, 128, 128);
        c.bench_function(&format!("view/{name}/128"), |b| {
            b.iter(|| black_box(&view).project(&mesh).unwrap())
        });

        let projected = View::project(&view, &mesh).unwrap();
        let params = HaloParams::default();
        let rho = 0.01;
        let (halo, _) = build_halo(&projected, &mesh.triangles, rho, &params);
        let data = [SurfaceData {
            name,
            surface_type: surface.type_name(),
            patches: surface.patch_count(),
            mesh: &mesh,
            projected: &projected,
            halo: &halo,
            halo_params: &params,
            rho,
        }];
        let curves = halo4d::intersect::curves(&[halo4d::intersect::Sheet {
            positions: &projected.positions,
            w: &projected.w,
            triangles: &mesh.triangles,
        }]);
        c.bench_function(&format!("export_glb/{name}/128"), |b| {
            b.iter(|| to_glb(black_box(&data), &curves, 0.01, &serde_json::Value::Null).unwrap())
        });
        c.bench_function(&format!("export_ply/{name}/128"), |b| {
            b.iter(|| to_ply(black_box(&data), name))
        });
        c.bench_function(&format!("export_vtk/{name}/128"), |b| {
            b.iter(|| {
                let mut bytes = Vec::new();
                write_vtk(&mut bytes, black_box(&data[0]), name).unwrap();
                bytes
            })
        });
    }
}

criterion_group!(benches, stages);
criterion_main!(benches);
