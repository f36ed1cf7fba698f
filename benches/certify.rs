//! The certified check of any tetrahedral mesh at scale: Kuhn's cube of about 1M and 10M
//! tetrahedra, certified in memory, and read from a binary `.vtu` and certified as `halo4d
//! check FILE` does (the target: 10M tetrahedra in at most 15 s and 4 GB on two
//! cores). Throughput in tetrahedra per second; the peak resident memory of the whole
//! bench (the 10M file's reading and checking included) is printed at the end.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use halo4d::certify::{certify, kuhn_cube};
use halo4d::export::write_tetrahedra_vtu;
use halo4d::internals::file_order;
use std::hint::black_box;

/// Cubes a side: 6 n^3 tetrahedra (998,250 and 10,110,954).
const SIDES: [u32; 2] = [55, 119];

fn certify_meshes(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut group = c.benchmark_group("certify");
    group.sample_size(10);
    for n in SIDES {
        let (positions, tets) = kuhn_cube(n);
        group.throughput(Throughput::Elements(tets.len() as u64));
        group.bench_with_input(
            BenchmarkId::new("in_memory", tets.len()),
            &(&positions, &tets),
            |b, (p, t)| b.iter(|| certify(black_box(p), black_box(t))),
        );
        let file = dir.path().join(format!("kuhn-{n}.vtu"));
        let in_file: Vec<[u32; 4]> = tets.iter().map(|&t| file_order(t)).collect();
        write_tetrahedra_vtu(&file, &positions, &in_file, &[], &[]).expect("the .vtu is written");
        drop((positions, tets, in_file));
        group.bench_with_input(BenchmarkId::new("vtu_file", 6 * n.pow(3)), &file, |b, f| {
            b.iter(|| {
                let checked = halo4d::check_file(black_box(f)).expect("the .vtu reads");
                assert!(checked.failures().is_empty());
            })
        });
    }
    group.finish();
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    if let Some(line) = status.lines().find(|l| l.starts_with("VmHWM")) {
        println!("peak resident memory of the bench: {}", line[6..].trim());
    }
}

criterion_group!(benches, certify_meshes);
criterion_main!(benches);
