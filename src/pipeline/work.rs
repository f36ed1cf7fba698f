//! The work a build is in for, measured before it is done: the curves, the verification and
//! the picture ask "which triangles or tetrahedra are near this point?" millions of times,
//! and each answer costs as many exact tests as there are boxes piled up at the point. Where
//! the boxes pile up far beyond a sound mesh's (sliver triangles fanning out from a point,
//! halos that keep their folds), the build would run for minutes; it is refused at once,
//! with what to change.
//!
//! The pile-up is measured at [`PROBES`] points spread over each surface by area
//! ([`probes`], the same points for the triangles and the halos): how many boxes hold each
//! point, each count cut at four times the limit ([`holding`]). The probes are bucketed in
//! a grid and every box visits the cells it covers, one pass over the boxes on the cores
//! with no index built: 0.2 s for the 6 million halo tetrahedra of a 1M-triangle build,
//! where a BVH over them took 5 s and a gigabyte.

use super::built::{InView, SurfaceProduct};
use crate::error::Error;
use crate::halo::Fold;
use crate::limits::{HALO_CROWDING, SURFACE_CROWDING};
use crate::sample::{Sampling, Source};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Points probed on each surface.
const PROBES: usize = 4096;

/// Per surface, how many triangles' boxes hold a point of it on average; refuses surfaces
/// whose boxes pile up beyond [`SURFACE_CROWDING`]: every ray of the picture and every
/// candidate pair of the curves would test hundreds of them.
pub(super) fn surface_crowding(
    scene: &Scene,
    projections: &[InView],
    probes: &[Vec<DVec3>],
) -> Result<Vec<f64>, Error> {
    let cap = 4 * SURFACE_CROWDING as usize;
    let mut out = Vec::with_capacity(projections.len());
    for (i, (view, probes)) in projections.iter().zip(probes).enumerate() {
        let positions = &view.projected.positions;
        let triangles = &view.sample.mesh.triangles;
        let counted = holding(
            &[probes.as_slice()],
            triangles.len(),
            |k| {
                let p = triangles[k].map(|v| positions[v as usize]);
                (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            },
            cap,
            SURFACE_CROWDING,
        );
        let crowding = counted.means[0];
        out.push(crowding);
        if crowding <= SURFACE_CROWDING {
            continue;
        }
        let field = match view.entry.sampling {
            Some(_) => format!("surfaces[{i}].sampling"),
            None => "sampling".to_string(),
        };
        let change = match (&view.entry.surface, scene.surface_sampling(i)) {
            (Source::Mesh(_), _) => {
                "they are the mesh file's: remesh it with triangles nearer equilateral".into()
            }
            (_, Sampling::Uniform { u, v }) => format!(
                "its grid of {u} x {v} cells per patch makes them long and thin: choose `{field}.u` and `{field}.v` nearer the patches' proportions, or sample adaptively (`{field}.method: adaptive`)"
            ),
            (_, Sampling::Adaptive { .. }) => {
                format!("ask for a finer `{field}.tolerance`, which splits them")
            }
        };
        return Err(Error::Work {
            scene: scene.name.clone(),
            message: format!(
                "the triangles of surface `{}` are slivers whose boxes pile up: a point on it lies in the boxes of {}{crowding:.0} triangles on average (counted up to {cap} at each point), more than the {SURFACE_CROWDING} that its curves and picture allow in reasonable time (well-shaped meshes: 2 to 4); {change}",
                view.sample.name,
                counted.at_least()
            ),
        });
    }
    Ok(out)
}

/// Per surface, how many halo tetrahedra's boxes (of all the halos) hold a point of it on
/// average; refuses halos so crowded that verifying and drawing them would take far longer
/// than for sound halos of their size ([`HALO_CROWDING`]).
pub(super) fn halo_crowding(
    scene: &Scene,
    products: &[SurfaceProduct],
    probes: &[Vec<DVec3>],
    diagonal: f64,
) -> Result<Vec<f64>, Error> {
    let halos: Vec<_> = products.iter().map(|p| &p.halo).collect();
    // Every halo's tetrahedra in one numbering: `first[s]` is surface s's first.
    let first: Vec<usize> = halos
        .iter()
        .scan(0, |n, h| {
            let at = *n;
            *n += h.tets.len();
            Some(at)
        })
        .collect();
    let groups: Vec<&[DVec3]> = probes.iter().map(Vec::as_slice).collect();
    let cap = 4 * HALO_CROWDING as usize;
    let counted = holding(
        &groups,
        halos.iter().map(|h| h.tets.len()).sum(),
        |g| {
            let s = first.partition_point(|&f| f <= g) - 1;
            let h = halos[s];
            let p = h.tets[g - first[s]].map(|v| h.positions[v as usize]);
            (
                p[0].min(p[1]).min(p[2]).min(p[3]),
                p[0].max(p[1]).max(p[2]).max(p[3]),
            )
        },
        cap,
        HALO_CROWDING,
    );
    let mut out = Vec::with_capacity(products.len());
    for (p, &crowding) in products.iter().zip(&counted.means) {
        out.push(crowding);
        if crowding <= HALO_CROWDING {
            continue;
        }
        let rho = p.halo_report.rho / diagonal;
        let change = match scene.halo.fold {
            Fold::Report => format!(
                "its half-width is {rho:.3} of the scene's diagonal and `halo.fold: report` keeps its folds: lower `halo.rho` or `halo.gap_px`, or set `halo.fold` to `shrink`"
            ),
            Fold::Shrink => format!(
                "its half-width is {rho:.3} of the scene's diagonal: lower `halo.rho` or `halo.gap_px`"
            ),
        };
        return Err(Error::Work {
            scene: scene.name.clone(),
            message: format!(
                "the halo of surface `{}` overlaps itself: a point on the surface lies in the boxes of {}{crowding:.0} halo tetrahedra on average (counted up to {cap} at each point), more than the {HALO_CROWDING} that verifying and drawing it in reasonable time allows (halos that do not fold: 10 to 23); {change}",
                p.name,
                counted.at_least()
            ),
        });
    }
    Ok(out)
}

/// Per surface, [`PROBES`] points spread over its triangles by area: the centroids of the
/// triangles where the running area passes each of [`PROBES`] evenly spaced shares of the
/// total.
pub(super) fn probes(projections: &[InView]) -> Vec<Vec<DVec3>> {
    projections
        .iter()
        .map(|view| {
            let positions = &view.projected.positions;
            let triangles = &view.sample.mesh.triangles;
            let corners = |t: &[u32; 3]| t.map(|v| positions[v as usize]);
            let mut running = Vec::with_capacity(triangles.len());
            let mut total = 0.0;
            for t in triangles {
                let p = corners(t);
                total += (p[1] - p[0]).cross(p[2] - p[0]).length();
                running.push(total);
            }
            if triangles.is_empty() {
                return Vec::new();
            }
            (0..PROBES)
                .map(|i| {
                    let share = (i as f64 + 0.5) / PROBES as f64 * total;
                    let k = running
                        .partition_point(|&r| r < share)
                        .min(triangles.len() - 1);
                    let p = corners(&triangles[k]);
                    (p[0] + p[1] + p[2]) / 3.0
                })
                .collect()
        })
        .collect()
}

/// How many boxes hold the probes, on average over each group of probes.
struct Holding {
    /// Per group, the mean of its probes' counts, each cut at the cap.
    means: Vec<f64>,
    /// Whether every box was counted: the count stops once a group's mean passes the
    /// limit, and the means are then lower bounds.
    complete: bool,
}

impl Holding {
    /// "at least " where the count stopped early.
    fn at_least(&self) -> &'static str {
        if self.complete { "" } else { "at least " }
    }
}

/// Boxes counted between two looks at the running means.
const BATCH: usize = 1 << 18;

/// How many of the `boxes` boxes `box_of(i)` (closed, `[lo, hi]`) hold each probe of each
/// group, each count cut at `cap`, on average per group; stops after the batch of boxes in
/// which a group's mean passes `limit`. The probes of all groups are bucketed in one grid of
/// about 64 cells along the longest side of their bounds; each box visits the cells it
/// covers and tests their probes exactly (a box of more cells than there are probes tests
/// every probe). One pass over the boxes, in batches on the cores; the counts are integers,
/// so the means do not depend on the number of threads.
fn holding(
    groups: &[&[DVec3]],
    boxes: usize,
    box_of: impl Fn(usize) -> (DVec3, DVec3) + Sync,
    cap: usize,
    limit: f64,
) -> Holding {
    let probes: Vec<DVec3> = groups.iter().flat_map(|g| g.iter().copied()).collect();
    let grid = ProbeGrid::new(&probes);
    let mut counts = vec![0u32; probes.len()];
    let means = |counts: &[u32]| -> Vec<f64> {
        let mut at = 0;
        groups
            .iter()
            .map(|g| {
                let cut: usize = counts[at..at + g.len()]
                    .iter()
                    .map(|&c| (c as usize).min(cap))
                    .sum();
                at += g.len();
                if g.is_empty() {
                    0.0
                } else {
                    cut as f64 / g.len() as f64
                }
            })
            .collect()
    };
    let mut start = 0;
    while start < boxes {
        let end = (start + BATCH).min(boxes);
        let batch = (start..end)
            .into_par_iter()
            .with_min_len(4096)
            .fold(
                || vec![0u32; probes.len()],
                |mut counts, i| {
                    let (lo, hi) = box_of(i);
                    grid.visit(lo, hi, |k| counts[k] += 1);
                    counts
                },
            )
            .reduce_with(|mut a, b| {
                a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
                a
            });
        if let Some(batch) = batch {
            counts.iter_mut().zip(&batch).for_each(|(c, b)| *c += b);
        }
        start = end;
        if start < boxes && means(&counts).iter().any(|&m| m > limit) {
            return Holding {
                means: means(&counts),
                complete: false,
            };
        }
    }
    Holding {
        means: means(&counts),
        complete: true,
    }
}

/// Points bucketed in a uniform grid over their bounds (cells in `start`/`ids`, row-major).
struct ProbeGrid<'a> {
    probes: &'a [DVec3],
    lo: DVec3,
    hi: DVec3,
    /// Cells per unit length.
    inv: f64,
    dims: [usize; 3],
    /// Cell c's probes are `ids[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    ids: Vec<u32>,
}

impl<'a> ProbeGrid<'a> {
    /// Cells along the longest side of the probes' bounds.
    const SIDE: f64 = 64.0;

    fn new(probes: &'a [DVec3]) -> Self {
        let (lo, hi) = probes
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let longest = (hi - lo).max_element();
        let inv = if longest > 0.0 {
            Self::SIDE / longest
        } else {
            1.0
        };
        let cells = |e: f64| ((e * inv) as usize + 1).min(Self::SIDE as usize + 1);
        let extent = if probes.is_empty() {
            DVec3::ZERO
        } else {
            hi - lo
        };
        let dims = [cells(extent.x), cells(extent.y), cells(extent.z)];
        let mut grid = ProbeGrid {
            probes,
            lo,
            hi,
            inv,
            dims,
            start: Vec::new(),
            ids: Vec::new(),
        };
        let cell_of: Vec<usize> = probes
            .iter()
            .map(|&p| {
                let [i, j, k] = grid.cell(p);
                (k * dims[1] + j) * dims[0] + i
            })
            .collect();
        let mut start = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for &c in &cell_of {
            start[c + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        let mut next = start.clone();
        let mut ids = vec![0u32; probes.len()];
        for (k, &c) in cell_of.iter().enumerate() {
            ids[next[c] as usize] = k as u32;
            next[c] += 1;
        }
        grid.start = start;
        grid.ids = ids;
        grid
    }

    /// The cell holding `p`, clamped into the grid.
    fn cell(&self, p: DVec3) -> [usize; 3] {
        let at = (p - self.lo) * self.inv;
        let axis = |x: f64, n: usize| (x.max(0.0) as usize).min(n - 1);
        [
            axis(at.x, self.dims[0]),
            axis(at.y, self.dims[1]),
            axis(at.z, self.dims[2]),
        ]
    }

    /// Calls `hit(k)` for every probe k in the closed box `[lo, hi]`.
    fn visit(&self, lo: DVec3, hi: DVec3, mut hit: impl FnMut(usize)) {
        if self.probes.is_empty() || lo.cmpgt(self.hi).any() || hi.cmplt(self.lo).any() {
            return;
        }
        let inside = |p: DVec3| lo.cmple(p).all() && p.cmple(hi).all();
        let (a, b) = (self.cell(lo), self.cell(hi));
        let cells = (b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1);
        if cells > self.probes.len() {
            for (k, &p) in self.probes.iter().enumerate() {
                if inside(p) {
                    hit(k);
                }
            }
            return;
        }
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                let row = (z * self.dims[1] + y) * self.dims[0];
                let ids =
                    &self.ids[self.start[row + a[0]] as usize..self.start[row + b[0] + 1] as usize];
                for &k in ids {
                    if inside(self.probes[k as usize]) {
                        hit(k as usize);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holding_counts_the_boxes_holding_each_probe_as_brute_force_does() {
        let mut next = crate::intersect::lcg(5);
        let mut point = || DVec3::new(next(), next(), next());
        // Small boxes, some flat or a point, and a few spanning everything (visited
        // through every probe rather than the cells).
        let mut boxes: Vec<(DVec3, DVec3)> = (0..3000)
            .map(|i| {
                let c = point();
                let h = point() * [0.02, 0.1, 0.0][i % 3];
                (c - h, c + h)
            })
            .collect();
        boxes.extend((0..5).map(|_| (DVec3::splat(-1.0), DVec3::splat(2.0))));
        // Probes in two groups, some on box corners (closed boxes hold them), one group flat.
        let mut a: Vec<DVec3> = (0..300).map(|_| point()).collect();
        a.extend(boxes.iter().step_by(97).map(|b| b.0));
        let b: Vec<DVec3> = (0..200)
            .map(|_| point() * DVec3::new(1.0, 1.0, 0.0))
            .collect();
        let brute = |probes: &[DVec3], cap: usize| {
            probes
                .iter()
                .map(|&p| {
                    let n = boxes
                        .iter()
                        .filter(|(lo, hi)| lo.cmple(p).all() && p.cmple(*hi).all())
                        .count();
                    n.min(cap)
                })
                .sum::<usize>() as f64
                / probes.len() as f64
        };
        for cap in [usize::MAX, 7] {
            let got = holding(
                &[&a, &b, &[]],
                boxes.len(),
                |i| boxes[i],
                cap,
                f64::INFINITY,
            );
            assert!(got.complete);
            assert_eq!(got.means, vec![brute(&a, cap), brute(&b, cap), 0.0]);
        }
        assert!(brute(&a, usize::MAX) > 5.5, "{}", brute(&a, usize::MAX));
        // All probes at one point: one cell.
        let one = [DVec3::splat(0.5); 10];
        let got = holding(
            &[&one],
            boxes.len(),
            |i| boxes[i],
            usize::MAX,
            f64::INFINITY,
        );
        assert_eq!(got.means, vec![brute(&one, usize::MAX)]);
        // A limit passed: stops after a batch, the mean a lower bound above the limit.
        let many: Vec<_> = (0..BATCH + 10).map(|_| (DVec3::ZERO, DVec3::ONE)).collect();
        let got = holding(&[&a], many.len(), |i| many[i], usize::MAX, 10.0);
        assert!(!got.complete && got.at_least() == "at least ");
        assert!(got.means[0] > 10.0 && got.means[0] < many.len() as f64);
    }
}
