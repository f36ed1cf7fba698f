//! Stipples: a progressive blue-noise point set fixed to a surface's 4D mesh (paper 003).
//!
//! Takes: a mesh's 4D vertex positions and triangles, a count and a seed. Gives:
//! [`Stipples`], points on the mesh's triangles (a triangle and barycentric coordinates each)
//! in rank order, so that every prefix of the ranking is itself a Poisson-disc set: the
//! smallest distance between the first n points is at least half the Poisson-disc radius
//! [`poisson_radius`] of n points on the mesh's area. A renderer draws the first n at a place
//! to reach a density there (paper 003's pre-generated point lists, from which "the stipples
//! that will be drawn" are selected each frame): the points never move on the surface, and a
//! small change of the view changes only how many of them are drawn.
//!
//! The set depends only on the 4D mesh, the count and the seed, not on the view: it is made
//! once per surface and reused for every view and camera. Distances are measured in 4D, so
//! the density is uniform over the surface's area (not over its parameters).
//!
//! How: area-weighted random candidates, `OVERSAMPLE` times the count, are accepted by
//! dart throwing at a radius that shrinks level by level by `LEVEL_RATIO` (an approximation
//! of farthest-point sampling that needs only local queries). A candidate is accepted at a
//! level when no accepted point lies nearer than that level's radius; a rejected one waits
//! for the level whose radius is below its distance to an accepted point nearer than the
//! radius, so each candidate is looked at only a few times. A point accepted at level j is at
//! least r_j from every earlier one, so a prefix ending in level j has all its distances at
//! least r_j. Candidates join when a level needs them, those of smallest priority (a random
//! number each) first. No crate gives ranked (progressive) Poisson-disc sets on a triangle
//! mesh in 4D, hence this module.
//!
//! Each level, on the cores: every waiting candidate is checked against the points of the
//! earlier levels (the first one found nearer than the radius rejects it); those that pass
//! are checked against each other, listing for each the ones before it in priority nearer
//! than the radius; then, in priority order, one is accepted when none it lists was (the
//! greedy dart throwing of the level, decided in one short pass over those lists). The
//! candidates are numbered along a Z curve (Morton order) of a fine 4D lattice, and a level's
//! grid has cells a power of two of the lattice's cells wide, so the points of one grid cell
//! are one run of a list sorted by that number: a grid is rebuilt each level from the
//! accepted points in that order, a queue is swept in that order, and neighbouring queries
//! read neighbouring memory.
//!
//! Deterministic: the same mesh, count and seed give the same points in the same order on any
//! number of threads (the random numbers are hashes of the seed and an index; every parallel
//! step computes per candidate what does not depend on the others, and the one decision that
//! does is taken in priority order).

use glam::DVec4;
use rayon::prelude::*;

/// Candidates drawn per stipple kept.
const OVERSAMPLE: usize = 4;
/// Ratio of one level's radius to the previous one's.
const LEVEL_RATIO: f64 = 0.917_004_043_204_671_2; // 2^(-1/8)
/// The least ratio of a grid's cell to the level's radius (the cell is the smallest power of
/// two of lattice cells at least this): a query looks up p's own cell and those its ball
/// reaches across a face into, on average about 2 of the 16 it can meet. Ratios of 2 and 2.8
/// looked up more cells and ranked slower, 5.6 and 8 tested more points and ranked slower.
const CELL: f64 = 4.0;

/// A progressive blue-noise point set on one surface's mesh, in rank order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stipples {
    /// The triangle of each stipple.
    pub triangle: Vec<u32>,
    /// Barycentric coordinates of each stipple in its triangle, for its three corners in the
    /// triangle's order (summing to 1).
    pub bary: Vec<[f64; 3]>,
    /// The 4D area of each triangle of the mesh.
    pub triangle_area: Vec<f64>,
    /// The mesh's 4D area.
    pub area: f64,
}

/// The Poisson-disc radius of `n` points spread over `area`: 0.75 of the spacing of the
/// densest (hexagonal) packing of n points, the relative radius of a well-spread Poisson-disc
/// set (Lagae and Dutré, *A comparison of methods for generating Poisson disk distributions*).
pub fn poisson_radius(n: usize, area: f64) -> f64 {
    0.75 * (2.0 * area / (3f64.sqrt() * n.max(1) as f64)).sqrt()
}

/// How many points a Poisson-disc set of radius `r` holds on `area` (the inverse of
/// [`poisson_radius`]).
fn poisson_count(r: f64, area: f64) -> f64 {
    2.0 * area * 0.75 * 0.75 / (3f64.sqrt() * r * r)
}

impl Stipples {
    /// Ranks up to `count` stipples on the mesh of 4D `positions` and `triangles`, with
    /// random numbers from `seed`. Fewer when the mesh has no area.
    pub fn generate(
        positions: &[DVec4],
        triangles: &[[u32; 3]],
        count: usize,
        seed: u64,
    ) -> Stipples {
        let triangle_area: Vec<f64> = triangles
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                area4(b - a, c - a)
            })
            .collect();
        let area: f64 = triangle_area.iter().sum();
        let mut out = Stipples {
            triangle: Vec::new(),
            bary: Vec::new(),
            triangle_area,
            area,
        };
        if !(area > 0.0 && area.is_finite()) || count == 0 {
            return out;
        }
        // Candidates: per triangle a share of the total by its area, the fraction decided
        // by a random number; uniform in the triangle. Candidate i is the k-th of triangle t
        // where `start[t] + k = i`, so it is made again from its index when it is ranked.
        let total = count.saturating_mul(OVERSAMPLE) as f64;
        let mut start: Vec<usize> = Vec::with_capacity(triangles.len() + 1);
        start.push(0);
        for (t, &a) in out.triangle_area.iter().enumerate() {
            let expected = total * a / area;
            let n = (expected + unit(seed, 3 * t as u64)).floor() as usize;
            start.push(start[t] + n);
        }
        let bary = |t: usize, k: usize| {
            let key = ((t as u64) << 20) ^ k as u64;
            let s = unit(seed ^ 0x5EED_0001, key).sqrt();
            let r = unit(seed ^ 0x5EED_0002, key);
            [1.0 - s, s * (1.0 - r), s * r]
        };
        // The triangle of candidate i.
        let triangle_of = |i: usize| start.partition_point(|&s| s <= i) - 1;
        let mut points = vec![DVec4::ZERO; start[triangles.len()]];
        const CHUNK: usize = 4096;
        points
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let mut t = triangle_of(c * CHUNK);
                for (i, slot) in (c * CHUNK..).zip(chunk) {
                    while start[t + 1] <= i {
                        t += 1;
                    }
                    let b = bary(t, i - start[t]);
                    let [p, q, r] = triangles[t].map(|v| positions[v as usize]);
                    *slot = p * b[0] + q * b[1] + r * b[2];
                }
            });
        // A random priority of each candidate.
        let priority = |i: u32| (hash(seed ^ 0x5EED_0003, u64::from(i)) >> 32) as u32;
        let ranked = rank(&points, priority, count, area);
        (out.triangle, out.bary) = ranked
            .par_iter()
            .map(|&i| {
                let t = triangle_of(i as usize);
                (t as u32, bary(t, i as usize - start[t]))
            })
            .unzip();
        out
    }

    /// How many stipples there are.
    pub fn len(&self) -> usize {
        self.triangle.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.triangle.is_empty()
    }

    /// Stipple `k` on the mesh whose vertices carry `values` (positions in any space, or any
    /// quantity that mixes linearly), with its triangles `triangles`.
    pub fn mix<T>(&self, k: usize, triangles: &[[u32; 3]], values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        let t = triangles[self.triangle[k] as usize];
        let b = self.bary[k];
        values[t[0] as usize] * b[0] + values[t[1] as usize] * b[1] + values[t[2] as usize] * b[2]
    }
}

/// The area of the triangle spanned by 4D edges `e` and `f`: half the norm of their
/// bivector, sqrt(|e|^2 |f|^2 - (e.f)^2) / 2.
fn area4(e: DVec4, f: DVec4) -> f64 {
    let g = e.length_squared() * f.length_squared() - e.dot(f).powi(2);
    0.5 * g.max(0.0).sqrt()
}

/// The candidates ranked level by level into a ranking of at most `count` (indices into
/// `points`); `priority` orders them (a random number each, ties broken by place).
fn rank(
    points: &[DVec4],
    priority: impl Fn(u32) -> u32 + Sync,
    count: usize,
    area: f64,
) -> Vec<u32> {
    let (lo, hi, radii) = radii(points, area);
    let levels = radii.len();
    // The first level after j whose radius is at most d (at most a few levels on).
    let level_after = |j: usize, d: f64| {
        let mut k = j + 1;
        while k < levels && radii[k] > d {
            k += 1;
        }
        k
    };
    let lattice = Lattice::new(lo, hi, CELL * radii[levels - 1]);
    let candidates = Candidates::new(&lattice, points, priority);
    let mut waiting = joining(&candidates, &radii, area);
    let mut accepted: Vec<u32> = Vec::with_capacity(count);
    // The accepted candidates of the earlier levels in candidate order.
    let mut earlier: Vec<u32> = Vec::new();
    let mut grid = Grid::default();
    let mut own = Grid::default();
    for (j, &r) in radii.iter().enumerate() {
        if accepted.len() >= count {
            break;
        }
        let shift = lattice.shift(CELL * r);
        grid.build(&candidates, shift, &earlier);
        // The queue is a few runs in candidate order (those that joined, those each earlier
        // level sent): a sort merges them, so that it is swept in one pass.
        let mut queue = std::mem::take(&mut waiting[j]);
        queue.par_sort();
        // Where each goes: the level after the distance of an earlier point nearer than r,
        // or past the last level when none is. Their points are gathered first, in a loop
        // that waits on many loads at once.
        let queued: Vec<DVec4> = queue
            .par_iter()
            .map(|&z| candidates.point[z as usize])
            .collect();
        let next: Vec<usize> = queued
            .par_iter()
            .map(|&p| match grid.near(&lattice, p, r) {
                Some(d) => level_after(j, d),
                None => usize::MAX,
            })
            .collect();
        let mut pass: Vec<u32> = Vec::new();
        for (&z, k) in queue.iter().zip(next) {
            if k == usize::MAX {
                pass.push(z);
            } else if let Some(list) = waiting.get_mut(k) {
                list.push(z);
            }
        }
        own.build(&candidates, shift, &pass);
        let (taken, nearest) = accept(&candidates, &lattice, &own, &pass, r, count, &mut accepted);
        // The rejected wait in candidate order.
        let mut new = Vec::new();
        for (k, &z) in pass.iter().enumerate() {
            if taken[k] {
                new.push(z);
            } else if nearest[k].is_finite()
                && let Some(list) = waiting.get_mut(level_after(j, nearest[k]))
            {
                list.push(z);
            }
        }
        earlier = merge(&earlier, &new);
    }
    accepted
        .iter()
        .map(|&z| candidates.index[z as usize])
        .collect()
}

/// The bounds of `points` and the radii of the ranking's levels, from the bounds' diagonal
/// down by [`LEVEL_RATIO`] to a quarter of the candidates' own spacing (below which nothing
/// is gained).
fn radii(points: &[DVec4], area: f64) -> (DVec4, DVec4, Vec<f64>) {
    let (lo, hi) = points
        .par_iter()
        .fold(
            || (DVec4::INFINITY, DVec4::NEG_INFINITY),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
        .reduce(
            || (DVec4::INFINITY, DVec4::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let first = (hi - lo).length().max(f64::MIN_POSITIVE);
    let last = 0.25 * poisson_radius(points.len(), area) / 0.75;
    let levels = ((last / first).ln() / LEVEL_RATIO.ln()).ceil().max(1.0) as usize + 1;
    let radii = (0..levels)
        .map(|j| first * LEVEL_RATIO.powi(j as i32))
        .collect();
    (lo, hi, radii)
}

/// Each level's list of the candidates (their places, in candidate order) that join it.
/// Candidates join when a level needs them: [`OVERSAMPLE`] times as many as a Poisson-disc
/// set of its radius holds, those of smallest priority first, so that the early levels,
/// which accept few, do not look at every candidate again and again.
fn joining(candidates: &Candidates, radii: &[f64], area: f64) -> Vec<Vec<u32>> {
    let n = candidates.index.len() as f64;
    let joins: Vec<u64> = radii
        .iter()
        .map(|&r| {
            let wanted = OVERSAMPLE as f64 * poisson_count(r, area) / n;
            (wanted.min(1.0) * 2f64.powi(32)) as u64
        })
        .collect();
    let join: Vec<usize> = candidates
        .priority
        .par_iter()
        .map(|&p| joins.partition_point(|&t| t <= u64::from(p)))
        .collect();
    let mut waiting: Vec<Vec<u32>> = vec![Vec::new(); radii.len()];
    for (z, &j) in join.iter().enumerate() {
        if let Some(list) = waiting.get_mut(j) {
            list.push(z as u32);
        }
    }
    waiting
}

/// The candidates of one level that no earlier point is nearer than `r` to (`pass`, in
/// candidate order, indexed by `own`), judged against each other in priority order: each is
/// accepted (pushed onto `accepted`, up to `count`) when none before it nearer than `r`
/// was. Gives which were taken and, for each rejected one, its distance to the nearest
/// taken one before it.
fn accept(
    candidates: &Candidates,
    lattice: &Lattice,
    own: &Grid,
    pass: &[u32],
    r: f64,
    count: usize,
    accepted: &mut Vec<u32>,
) -> (Vec<bool>, Vec<f64>) {
    // Their order in priority (ties in candidate order, as `pass` is), and each one's place
    // in it.
    let mut by_priority: Vec<(u32, u32)> = pass
        .par_iter()
        .enumerate()
        .map(|(k, &z)| (candidates.priority[z as usize], k as u32))
        .collect();
    by_priority.par_sort_unstable();
    let mut place = vec![0u32; pass.len()];
    for (n, &(_, k)) in (0u32..).zip(&by_priority) {
        place[k as usize] = n;
    }
    // For each, those before it in priority nearer than r (pairs of places in `pass`, with
    // their distance, grouped by the first).
    let pairs: Vec<(u32, u32, f64)> = (0..pass.len())
        .into_par_iter()
        .fold(Vec::new, |mut found, k| {
            own.visit(lattice, own.points[k], r, |m, d| {
                if place[m as usize] < place[k] {
                    found.push((k as u32, m, d));
                }
                false
            });
            found
        })
        .flatten_iter()
        .collect();
    let mut from = vec![0u32; pass.len() + 1];
    for &(k, _, _) in &pairs {
        from[k as usize + 1] += 1;
    }
    for k in 0..pass.len() {
        from[k + 1] += from[k];
    }
    let mut taken = vec![false; pass.len()];
    let mut nearest = vec![f64::INFINITY; pass.len()];
    for &(_, k) in &by_priority {
        let k = k as usize;
        nearest[k] = pairs[from[k] as usize..from[k + 1] as usize]
            .iter()
            .filter(|&&(_, m, _)| taken[m as usize])
            .map(|&(_, _, d)| d)
            .fold(f64::INFINITY, f64::min);
        if nearest[k].is_infinite() {
            taken[k] = true;
            accepted.push(pass[k]);
            if accepted.len() >= count {
                break;
            }
        }
    }
    (taken, nearest)
}

/// The candidates in the order of their fine cells along the Z curve (candidate order): for
/// each its index among the points, its point, its priority and its cell's Z code. The ranking
/// refers to a candidate by its place in this order, so its lists are of 32-bit places, not
/// of points.
struct Candidates {
    index: Vec<u32>,
    point: Vec<DVec4>,
    priority: Vec<u32>,
    code: Vec<u64>,
}

impl Candidates {
    fn new(
        lattice: &Lattice,
        points: &[DVec4],
        priority: impl Fn(u32) -> u32 + Sync,
    ) -> Candidates {
        // The indices are distinct, so the unstable sort of (code, index) is the stable order.
        let mut keyed: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, &p)| (lattice.code(p), i as u32))
            .collect();
        keyed.par_sort_unstable();
        let index: Vec<u32> = keyed.par_iter().map(|&(_, i)| i).collect();
        Candidates {
            point: index.par_iter().map(|&i| points[i as usize]).collect(),
            priority: index.par_iter().map(|&i| priority(i)).collect(),
            code: keyed.into_par_iter().map(|(k, _)| k).collect(),
            index,
        }
    }
}

/// Two lists sorted ascending merged.
fn merge(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut x, mut y) = (0, 0);
    while x < a.len() && y < b.len() {
        if a[x] < b[y] {
            out.push(a[x]);
            x += 1;
        } else {
            out.push(b[y]);
            y += 1;
        }
    }
    out.extend_from_slice(&a[x..]);
    out.extend_from_slice(&b[y..]);
    out
}

/// The finest cells of the grids: a lattice over the candidates' box whose cells are
/// numbered along the Z curve (Morton order), 16 bits per axis. A grid's cell is 2^s of them
/// along each axis, so the points of one grid cell lie in a row of the candidates sorted by
/// their fine cell.
struct Lattice {
    /// The box's lower corner.
    lo: DVec4,
    /// The cell's side, and its inverse.
    cell: f64,
    inverse: f64,
}

/// The largest fine cell coordinate.
const SIDE: f64 = 65535.0;

impl Lattice {
    /// The lattice over the box from `lo` to `hi` whose cell is `smallest`, or larger where
    /// the box is more than 65,536 of those wide.
    fn new(lo: DVec4, hi: DVec4, smallest: f64) -> Lattice {
        let extent = (hi - lo).max_element();
        let cell = smallest.max(extent / SIDE).max(f64::MIN_POSITIVE);
        Lattice {
            lo,
            cell,
            inverse: 1.0 / cell,
        }
    }

    /// The shift of the grid whose cell is the smallest power of two fine cells at least
    /// `cell`.
    fn shift(&self, cell: f64) -> u32 {
        let mut s = 0;
        while s < 16 && self.cell * f64::from(1u32 << s) < cell {
            s += 1;
        }
        s
    }

    /// The fine cell coordinate of `x` along `axis` (clamped to the lattice: cells at its
    /// edge hold what lies beyond, which costs distance tests, never a wrong answer).
    #[inline]
    fn at(&self, x: f64, axis: usize) -> u32 {
        let t = ((x - self.lo[axis]) * self.inverse).clamp(0.0, SIDE);
        t as u32
    }

    /// The Z code of the fine cell of `p`.
    fn code(&self, p: DVec4) -> u64 {
        interleave(std::array::from_fn(|axis| self.at(p[axis], axis)))
    }
}

/// Four 16-bit coordinates interleaved bit by bit (the Z curve in 4D).
#[inline]
fn interleave(c: [u32; 4]) -> u64 {
    let spread = |x: u32| {
        let mut x = u64::from(x & 0xFFFF);
        x = (x | x << 24) & 0x0000_00FF_0000_00FF;
        x = (x | x << 12) & 0x000F_000F_000F_000F;
        x = (x | x << 6) & 0x0303_0303_0303_0303;
        (x | x << 3) & 0x1111_1111_1111_1111
    };
    spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2 | spread(c[3]) << 3
}

/// A grid over some of the candidates: their points in candidate order (so by fine cell), the
/// runs of its grid cells in that order, and a hash table from each cell to its run (a flat
/// table of a few megabytes rebuilt in one pass each level, where a map of cells to vectors
/// was rebuilt point by point and scattered the points over the heap).
#[derive(Default)]
struct Grid {
    /// A cell is 2^shift fine cells wide.
    shift: u32,
    points: Vec<DVec4>,
    /// Each run's cell (its Z code) and start; a last one marks the end.
    runs: Vec<(u64, u32)>,
    /// Open addressing: one more than a run's index, 0 where empty.
    table: Vec<u32>,
    /// The table's size less one (a power of two less one).
    mask: usize,
}

impl Grid {
    /// Rebuilds the grid of cells 2^shift fine cells wide over the candidates at places
    /// `list` (ascending), keeping its memory.
    fn build(&mut self, candidates: &Candidates, shift: u32, list: &[u32]) {
        self.shift = shift;
        self.points.clear();
        self.points
            .par_extend(list.par_iter().map(|&z| candidates.point[z as usize]));
        let keys: Vec<u64> = list
            .par_iter()
            .map(|&z| {
                candidates.code[z as usize]
                    .checked_shr(4 * shift)
                    .unwrap_or(0)
            })
            .collect();
        self.runs.clear();
        for (s, &k) in keys.iter().enumerate() {
            if self.runs.last().is_none_or(|&(last, _)| last != k) {
                self.runs.push((k, s as u32));
            }
        }
        let cells = self.runs.len();
        self.runs.push((u64::MAX, list.len() as u32));
        let size = (2 * cells).next_power_of_two().max(2);
        self.mask = size - 1;
        self.table.clear();
        self.table.resize(size, 0);
        for (n, &(k, _)) in self.runs[..cells].iter().enumerate() {
            let mut at = slot(k) & self.mask;
            while self.table[at] != 0 {
                at = (at + 1) & self.mask;
            }
            self.table[at] = n as u32 + 1;
        }
    }

    /// The run of cell `k`.
    #[inline]
    fn run(&self, k: u64) -> (usize, usize) {
        let mut at = slot(k) & self.mask;
        loop {
            let n = self.table[at] as usize;
            if n == 0 {
                return (0, 0);
            }
            if self.runs[n - 1].0 == k {
                return (self.runs[n - 1].1 as usize, self.runs[n].1 as usize);
            }
            at = (at + 1) & self.mask;
        }
    }

    /// Calls `f` with the place in the list and distance of each point nearer than `r` to
    /// `p` (`r` at most half a cell), p's own cell first, until `f` returns true.
    #[inline]
    fn visit(&self, lattice: &Lattice, p: DVec4, r: f64, mut f: impl FnMut(u32, f64) -> bool) {
        if self.points.is_empty() {
            return;
        }
        // The ball of radius r meets at most two cells per axis: p's own, and the next one
        // down or up where it reaches across a face.
        let s = self.shift;
        let mut own = [0u32; 4];
        let mut step = [0u32; 4];
        let mut reach = 0u32;
        for axis in 0..4 {
            own[axis] = lattice.at(p[axis], axis) >> s;
            if lattice.at(p[axis] - r, axis) >> s < own[axis] {
                (step[axis], reach) = (u32::MAX, reach | 1 << axis);
            } else if lattice.at(p[axis] + r, axis) >> s > own[axis] {
                (step[axis], reach) = (1, reach | 1 << axis);
            }
        }
        let mut subset = 0u32;
        loop {
            let key = interleave(std::array::from_fn(|axis| {
                own[axis].wrapping_add(if subset >> axis & 1 != 0 {
                    step[axis]
                } else {
                    0
                })
            }));
            let (from, to) = self.run(key);
            for (m, q) in self.points[from..to].iter().enumerate() {
                let d = q.distance_squared(p);
                if d < r * r && f((from + m) as u32, d.sqrt()) {
                    return;
                }
            }
            subset = subset.wrapping_sub(reach) & reach;
            if subset == 0 {
                return;
            }
        }
    }

    /// The distance to a point nearer than `r` to `p`, the first one found (an upper bound
    /// of the nearest: a rejected candidate comes back sooner, to be rejected again, and
    /// the ranking is the same), or `None` when there is none.
    fn near(&self, lattice: &Lattice, p: DVec4, r: f64) -> Option<f64> {
        let mut found = None;
        self.visit(lattice, p, r, |_, d| {
            found = Some(d);
            true
        });
        found
    }
}

/// The table slot of a cell's Z code: the 16 cells of a block two cells wide along each axis
/// share a row of 16 slots (one cache line), so that a query's cells, mostly in one or two
/// such blocks, read few lines; the blocks are hashed.
#[inline]
fn slot(k: u64) -> usize {
    let s = k >> 4;
    let z = (s ^ (s >> 31)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((z >> 28) as usize & !15) | (k & 15) as usize
}

/// SplitMix64 of a seed and an index: the random numbers of the set.
fn hash(seed: u64, i: u64) -> u64 {
    let mut z = seed
        .wrapping_add(i.wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A number in [0, 1) from a seed and an index.
fn unit(seed: u64, i: u64) -> f64 {
    (hash(seed, i) >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat square of side 1 in the xw plane, cut into 2 n^2 triangles.
    fn square(n: u32) -> (Vec<DVec4>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push(DVec4::new(
                    f64::from(i) / f64::from(n),
                    0.0,
                    0.0,
                    f64::from(j) / f64::from(n),
                ));
            }
        }
        let mut t = Vec::new();
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (p, t)
    }

    #[test]
    fn every_prefix_is_a_poisson_disc_set() {
        let (p, t) = square(16);
        let s = Stipples::generate(&p, &t, 4000, 7);
        assert_eq!(s.len(), 4000);
        assert!((s.area - 1.0).abs() < 1e-12);
        let pts: Vec<DVec4> = (0..s.len()).map(|k| s.mix(k, &t, &p)).collect();
        // The distance of each point to those ranked before it; a prefix's smallest
        // distance is the smallest of these up to its end.
        let mut smallest = f64::INFINITY;
        let mut worst: f64 = f64::INFINITY;
        for n in 1..pts.len() {
            let d = (0..n)
                .map(|m| pts[m].distance(pts[n]))
                .fold(f64::INFINITY, f64::min);
            smallest = smallest.min(d);
            worst = worst.min(smallest / poisson_radius(n + 1, s.area));
        }
        assert!(worst >= 0.5, "worst prefix: {worst} of the Poisson radius");
    }

    #[test]
    fn the_same_seed_gives_the_same_set_and_another_seed_another() {
        let (p, t) = square(8);
        let a = Stipples::generate(&p, &t, 500, 1);
        assert_eq!(a, Stipples::generate(&p, &t, 500, 1));
        assert_ne!(a.bary, Stipples::generate(&p, &t, 500, 2).bary);
    }

    #[test]
    fn the_ranking_does_not_depend_on_the_number_of_threads() {
        let (p, t) = square(12);
        let on = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Stipples::generate(&p, &t, 3000, 5))
        };
        let one = on(1);
        assert_eq!(one.len(), 3000);
        assert_eq!(one, on(3));
    }

    #[test]
    fn density_is_uniform_over_area_not_over_triangles() {
        // Squash the left half of the square's columns: triangles of unequal area.
        let (mut p, t) = square(8);
        for q in &mut p {
            q.x = if q.x <= 0.5 {
                q.x * 0.4
            } else {
                0.2 + (q.x - 0.5) * 1.6
            };
        }
        let s = Stipples::generate(&p, &t, 2000, 3);
        let left = (0..s.len()).filter(|&k| s.mix(k, &t, &p).x < 0.2).count();
        // The left strip holds 0.2 of the area.
        let share = left as f64 / s.len() as f64;
        assert!((share - 0.2).abs() < 0.02, "share {share}");
    }

    #[test]
    fn the_grid_finds_what_brute_force_finds() {
        // Random points near a curved sheet in 4D, queried at radii from a tenth of the box
        // to a thousandth, against all pairs.
        let points: Vec<DVec4> = (0..3000u64)
            .map(|i| {
                let (u, v) = (unit(1, i), unit(2, i));
                DVec4::new(u, v, (3.0 * u).sin() * 0.3, u * v + 1e-3 * unit(3, i))
            })
            .collect();
        let (lo, hi) = (DVec4::ZERO, DVec4::ONE);
        let lattice = Lattice::new(lo, hi, CELL * 1e-3);
        let candidates = Candidates::new(&lattice, &points, |_| 0);
        let list: Vec<u32> = (0..points.len() as u32).collect();
        let mut grid = Grid::default();
        for r in [0.1, 0.03, 0.01, 0.003, 0.001] {
            grid.build(&candidates, lattice.shift(CELL * r), &list);
            for k in (0..list.len()).step_by(7) {
                let p = candidates.point[k];
                let mut found = Vec::new();
                grid.visit(&lattice, p, r, |m, _| {
                    found.push(m as usize);
                    false
                });
                found.sort_unstable();
                let all: Vec<usize> = (0..list.len())
                    .filter(|&m| candidates.point[m].distance_squared(p) < r * r)
                    .collect();
                assert_eq!(found, all, "point {k} at radius {r}");
                assert_eq!(grid.near(&lattice, p, r).is_some(), !all.is_empty());
            }
        }
    }

    #[test]
    fn the_candidates_are_in_z_order_ties_by_index() {
        let points: Vec<DVec4> = (0..5000u64)
            .map(|i| DVec4::new(unit(1, i), unit(2, i % 40), 0.5, unit(3, i % 7)))
            .collect();
        let lattice = Lattice::new(DVec4::ZERO, DVec4::ONE, 0.01);
        let priority: Vec<u32> = (0..points.len() as u32).map(|i| i * 7).collect();
        let c = Candidates::new(&lattice, &points, |i| priority[i as usize]);
        let mut sorted: Vec<u32> = (0..points.len() as u32).collect();
        sorted.sort_by_key(|&i| lattice.code(points[i as usize]));
        assert_eq!(c.index, sorted);
        for (z, &i) in c.index.iter().enumerate() {
            assert_eq!(c.point[z], points[i as usize]);
            assert_eq!(c.priority[z], priority[i as usize]);
            assert_eq!(c.code[z], lattice.code(points[i as usize]));
        }
    }

    #[test]
    fn a_mesh_without_area_has_no_stipples() {
        let p = vec![DVec4::ZERO, DVec4::X, DVec4::X * 2.0];
        let s = Stipples::generate(&p, &[[0, 1, 2]], 100, 0);
        assert!(s.is_empty());
        assert_eq!(s.area, 0.0);
    }
}
