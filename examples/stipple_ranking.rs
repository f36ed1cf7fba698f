//! The stipple ranking of the default scene: how long ranking its 600,000 stipples takes, a
//! hash of the ranking (to tell whether a change kept it bit for bit), and how good a
//! Poisson-disc set every prefix of it is: the worst ratio of a prefix's smallest distance
//! to the Poisson-disc radius of its count (over all prefixes, over those of 1,000 points or
//! more, and for the whole set). The figures of `docs/PERFORMANCE.md` § Stipples.
//!
//! ```sh
//! cargo run --release --example stipple_ranking          # three rankings, then the prefixes
//! cargo run --release --example stipple_ranking -- 5 0   # five rankings, no prefixes
//! ```

use glam::DVec4;
use halo4d::stipple::{Stipples, poisson_radius};
use halo4d::{Sampled, Scene, Stages};
use std::collections::HashMap;
use std::process::ExitCode;
use std::time::Instant;

/// The stipples ranked, as the default build ranks them.
const COUNT: usize = 600_000;

fn main() -> ExitCode {
    let arg = |k: usize, default: usize| match std::env::args().nth(k) {
        None => Ok(default),
        Some(s) => s
            .parse::<usize>()
            .map_err(|_| format!("argument {k} must be a whole number, not {s:?}")),
    };
    let (rankings, prefixes) = match (arg(1, 3), arg(2, 1)) {
        (Ok(r), Ok(p)) if r > 0 => (r, p != 0),
        (Err(e), _) | (_, Err(e)) => return fail(&e),
        _ => return fail("at least one ranking"),
    };
    let scene = Scene::default_scene();
    let built = match Sampled::of(&scene).into_built(&scene, Stages::of(&scene)) {
        Ok(built) => built,
        Err(e) => return fail(&e.to_string()),
    };
    let mesh = &built.surfaces[0].mesh;
    let mut ranked = Stipples::default();
    for n in 1..=rankings {
        let t = Instant::now();
        ranked = Stipples::generate(&mesh.positions, &mesh.triangles, COUNT, 1);
        println!("ranking {n}: {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
    }
    let hash = ranked
        .triangle
        .iter()
        .zip(&ranked.bary)
        .fold(0u64, |h, (t, b)| {
            b.iter().fold(h ^ u64::from(*t), |h, x| {
                h.wrapping_mul(0x0100_0000_01b3) ^ x.to_bits()
            })
        });
    println!("{} stipples, hash {hash:016x}", ranked.len());
    if prefixes {
        let points: Vec<DVec4> = (0..ranked.len())
            .map(|k| ranked.mix(k, &mesh.triangles, &mesh.positions))
            .collect();
        let [all, from_1000, whole] = worst_prefixes(&points, ranked.area);
        println!(
            "worst prefix {:.4} (of {} points), of 1,000 or more {:.4} (of {}), all {:.4}",
            all.0, all.1, from_1000.0, from_1000.1, whole.0
        );
    }
    ExitCode::SUCCESS
}

fn fail(message: &str) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::FAILURE
}

/// The worst ratio of a prefix's smallest distance to [`poisson_radius`] of its count, with
/// that count: over the prefixes of 3 points or more, over those of 1,000 or more, and for
/// all the points. Each point's distance to those before it is looked up in a grid whose cell
/// is the smallest distance so far, rebuilt each time the count doubles (the smallest
/// distance only shrinks, so the 3^4 cells around a point hold every nearer one).
fn worst_prefixes(points: &[DVec4], area: f64) -> [(f64, usize); 3] {
    const BRUTE: usize = 2000;
    let cell_of = |p: DVec4, c: f64| [0, 1, 2, 3].map(|a| (p[a] / c).floor() as i64);
    let mut grid: HashMap<[i64; 4], Vec<usize>> = HashMap::new();
    let (mut cell, mut rebuild) = (0.0, BRUTE);
    let mut smallest = f64::INFINITY;
    let mut worst = [(f64::INFINITY, 0); 3];
    for (k, &p) in points.iter().enumerate() {
        if k == rebuild {
            cell = smallest;
            grid.clear();
            for (m, &q) in points[..k].iter().enumerate() {
                grid.entry(cell_of(q, cell)).or_default().push(m);
            }
            rebuild *= 2;
        }
        if k < BRUTE {
            for q in &points[..k] {
                smallest = smallest.min(q.distance(p));
            }
        } else {
            let c = cell_of(p, cell);
            for d in 0..81 {
                let at = [d % 3, d / 3 % 3, d / 9 % 3, d / 27].map(|x| x - 1);
                let key = [0, 1, 2, 3].map(|a| c[a] + at[a]);
                for &m in grid.get(&key).into_iter().flatten() {
                    smallest = smallest.min(points[m].distance(p));
                }
            }
            grid.entry(c).or_default().push(k);
        }
        let n = k + 1;
        let ratio = smallest / poisson_radius(n, area);
        if n >= 3 && ratio < worst[0].0 {
            worst[0] = (ratio, n);
        }
        if n >= 1000 && ratio < worst[1].0 {
            worst[1] = (ratio, n);
        }
        worst[2] = (ratio, n);
    }
    worst
}
