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
//! for the level whose radius is below its distance to the nearest accepted point, so each
//! candidate is looked at only a few times. A point accepted at level j is at least r_j from
//! every earlier one, so a prefix ending in level j has all its distances at least r_j. No
//! crate gives ranked (progressive) Poisson-disc sets on a triangle mesh in 4D, hence this
//! module.
//!
//! Deterministic: the same mesh, count and seed give the same points in the same order on any
//! number of threads (the random numbers are hashes of the seed and an index).

use glam::DVec4;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Candidates drawn per stipple kept.
const OVERSAMPLE: usize = 4;
/// Ratio of one level's radius to the previous one's.
const LEVEL_RATIO: f64 = 0.917_004_043_204_671_2; // 2^(-1/8)
/// Levels between rebuilds of the neighbour grid.
const LEVELS_PER_GRID: usize = 4;
/// The grid's cell over the radius when it is built: a query looks up p's own cell and those
/// its ball reaches across a face into, on average about 4 of the 16 it can meet.
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
        // by a random number; uniform in the triangle.
        let total = count.saturating_mul(OVERSAMPLE) as f64;
        let candidates: Vec<(u32, [f64; 3])> = out
            .triangle_area
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, &a)| {
                let expected = total * a / area;
                let n = (expected + unit(seed, 3 * t as u64)).floor() as usize;
                (0..n).map(move |k| {
                    let key = ((t as u64) << 20) ^ k as u64;
                    let s = unit(seed ^ 0x5EED_0001, key).sqrt();
                    let r = unit(seed ^ 0x5EED_0002, key);
                    (t as u32, [1.0 - s, s * (1.0 - r), s * r])
                })
            })
            .collect();
        let point = |&(t, b): &(u32, [f64; 3])| {
            let [p, q, r] = triangles[t as usize].map(|v| positions[v as usize]);
            p * b[0] + q * b[1] + r * b[2]
        };
        let points: Vec<DVec4> = candidates.par_iter().map(point).collect();
        // A random order of the candidates.
        let mut order: Vec<(u64, u32)> = (0..candidates.len() as u32)
            .map(|i| (hash(seed ^ 0x5EED_0003, u64::from(i)), i))
            .collect();
        order.par_sort_unstable();
        let ranked = rank(&points, order.into_iter().map(|(_, i)| i), count, area);
        out.triangle = ranked.iter().map(|&i| candidates[i as usize].0).collect();
        out.bary = ranked.iter().map(|&i| candidates[i as usize].1).collect();
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

/// The candidates `order` lists, accepted level by level into a ranking of at most `count`
/// (indices into `points`).
fn rank(
    points: &[DVec4],
    mut order: impl Iterator<Item = u32>,
    count: usize,
    area: f64,
) -> Vec<u32> {
    let (lo, hi) = points
        .iter()
        .fold((DVec4::INFINITY, DVec4::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let first = (hi - lo).length().max(f64::MIN_POSITIVE);
    // Below a quarter of the candidates' own spacing nothing is gained.
    let last = 0.25 * poisson_radius(points.len(), area) / 0.75;
    let levels = ((last / first).ln() / LEVEL_RATIO.ln()).ceil().max(1.0) as usize + 1;
    let radius = |j: usize| first * LEVEL_RATIO.powi(j as i32);
    let mut waiting: Vec<Vec<u32>> = vec![Vec::new(); levels];
    let mut accepted: Vec<u32> = Vec::with_capacity(count);
    let mut grid = Grid::new(CELL * radius(0));
    let mut active = 0usize;
    // The distance each candidate was last found from an earlier level's point (an upper
    // bound of its nearest), infinite where none was within the radius.
    let mut near = vec![f64::INFINITY; points.len()];
    let mut level = Grid::new(CELL * radius(0));
    for j in 0..levels {
        if accepted.len() >= count {
            break;
        }
        let r = radius(j);
        if j % LEVELS_PER_GRID == 0 {
            grid = Grid::of(
                CELL * r,
                accepted.iter().map(|&i| points[i as usize]).collect(),
            );
        }
        // Candidates join when a level needs them: OVERSAMPLE times as many as a
        // Poisson-disc set of this radius holds, so that the early levels, which accept few,
        // do not look at every candidate again and again.
        let wanted = (OVERSAMPLE as f64 * poisson_count(r, area)).min(points.len() as f64);
        let mut queue = std::mem::take(&mut waiting[j]);
        while (active as f64) < wanted {
            let Some(i) = order.next() else { break };
            queue.push(i);
            active += 1;
        }
        // First each candidate against the points of the earlier levels, on the cores (the
        // grid does not change while they read it; the candidates in index order, which is
        // the mesh's triangle order, so that neighbours query neighbouring cells one after
        // another), then, in the queue's order, those that pass against the points accepted
        // at this level.
        let mut sorted = queue.clone();
        sorted.par_sort_unstable();
        let found: Vec<f64> = sorted
            .par_iter()
            .map(|&i| {
                grid.near_within(points[i as usize], r)
                    .unwrap_or(f64::INFINITY)
            })
            .collect();
        for (&i, d) in sorted.iter().zip(found) {
            near[i as usize] = d;
        }
        level.clear(CELL * r);
        let start = accepted.len();
        for i in queue {
            let p = points[i as usize];
            let d = near[i as usize];
            match (d.is_finite())
                .then_some(d)
                .or_else(|| level.near_within(p, r))
            {
                None => {
                    level.insert(p);
                    accepted.push(i);
                    if accepted.len() >= count {
                        break;
                    }
                }
                Some(d) => {
                    // The first level whose radius is at most d.
                    let k = ((d / first).ln() / LEVEL_RATIO.ln()).ceil();
                    let k = if k.is_finite() { k as usize } else { levels };
                    if let Some(list) = waiting.get_mut(k.max(j + 1)) {
                        list.push(i);
                    }
                }
            }
        }
        for &i in &accepted[start..] {
            grid.insert(points[i as usize]);
        }
    }
    accepted
}

/// A hash grid over 4D points, holding the points themselves (a query reads each cell's
/// points in a row of memory, not scattered over the candidates).
struct Grid {
    cell: f64,
    cells: HashMap<Cell, Vec<DVec4>, BuildHasherDefault<CellHasher>>,
}

impl Grid {
    fn new(cell: f64) -> Grid {
        Grid {
            cell,
            cells: HashMap::default(),
        }
    }

    /// The cell of `p`: its four integer coordinates, whole (packed into fewer bits, cells
    /// far apart would share a key, and a mesh reaching 1e29 along w would pile its stipples
    /// into one).
    fn key(&self, p: DVec4) -> Cell {
        Cell(std::array::from_fn(|axis| {
            Self::whole((p[axis] / self.cell).floor())
        }))
    }

    /// A cell coordinate as an integer. Beyond 2^62 cells (a coordinate of 1e30 over a cell
    /// of 1e-12) the cells merge, which costs distance tests, never a wrong answer.
    fn whole(c: f64) -> i64 {
        const FAR: f64 = (1u64 << 62) as f64;
        c.clamp(-FAR, FAR) as i64
    }

    /// The grid of cell `cell` over `points`, built at once: the points sorted by cell on
    /// the cores, then each cell's run moved into the map (a cell's order does not matter:
    /// a query takes the nearest of a cell's points).
    fn of(cell: f64, points: Vec<DVec4>) -> Grid {
        let mut grid = Grid::new(cell);
        let mut keyed: Vec<(Cell, DVec4)> =
            points.into_par_iter().map(|p| (grid.key(p), p)).collect();
        keyed.par_sort_unstable_by_key(|&(key, _)| key.0);
        let runs: Vec<&[(Cell, DVec4)]> = keyed.chunk_by(|a, b| a.0 == b.0).collect();
        grid.cells.reserve(runs.len());
        for run in runs {
            grid.cells
                .insert(run[0].0, run.iter().map(|&(_, p)| p).collect());
        }
        grid
    }

    /// Empties the grid and sets its cell, keeping its memory.
    fn clear(&mut self, cell: f64) {
        self.cell = cell;
        self.cells.clear();
    }

    fn insert(&mut self, p: DVec4) {
        let key = self.key(p);
        self.cells.entry(key).or_default().push(p);
    }

    /// The distance to a point nearer than `r` to `p` (`r` at most half a cell), or `None`
    /// when there is none. Cells are searched from `p`'s own outwards, and the search stops
    /// at the first that holds one: the distance is the nearest of that cell's, an upper
    /// bound of the nearest distance (a rejected candidate only comes back sooner).
    fn near_within(&self, p: DVec4, r: f64) -> Option<f64> {
        // The ball of radius r meets at most two cells per axis: p's own, and the next one
        // down or up where it reaches across a face (floor(y) < c exactly when y < c, for
        // a whole c: one floor per axis).
        let mut own = [0i64; 4];
        let mut step = [0i64; 4];
        let mut reach = 0u32;
        for axis in 0..4 {
            let c = (p[axis] / self.cell).floor();
            own[axis] = Self::whole(c);
            if (p[axis] - r) / self.cell < c {
                (step[axis], reach) = (-1, reach | 1 << axis);
            } else if (p[axis] + r) / self.cell >= c + 1.0 {
                (step[axis], reach) = (1, reach | 1 << axis);
            }
        }
        // Every subset of the axes it reaches across, p's own cell first.
        let mut subset = 0u32;
        loop {
            let key = Cell(std::array::from_fn(|axis| {
                own[axis]
                    + if subset >> axis & 1 != 0 {
                        step[axis]
                    } else {
                        0
                    }
            }));
            let best = self
                .cells
                .get(&key)
                .into_iter()
                .flatten()
                .map(|q| q.distance_squared(p))
                .fold(f64::INFINITY, f64::min);
            if best < r * r {
                return Some(best.sqrt());
            }
            // The next subset of `reach`.
            subset = subset.wrapping_sub(reach) & reach;
            if subset == 0 {
                return None;
            }
        }
    }
}

/// A cell of the grid: its integer coordinates, hashed as one word (four words through
/// the hasher cost more than the distance tests).
#[derive(Clone, Copy, PartialEq, Eq)]
struct Cell([i64; 4]);

impl std::hash::Hash for Cell {
    fn hash<H: Hasher>(&self, state: &mut H) {
        let [a, b, c, d] = self.0.map(|k| k as u64);
        state.write_u64(
            a.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                ^ b.wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
                ^ c.wrapping_mul(0x1656_67B1_9E37_79F9)
                ^ d.wrapping_mul(0x27D4_EB2F_1656_67C5),
        );
    }
}

/// A multiplicative hash for grid cells (std's SipHash costs more than the distance tests
/// it guards, and the keys are not adversarial).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        // SplitMix64's finaliser: every bit of the state reaches the bucket bits.
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0 ^ i)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(29);
    }
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
    fn a_mesh_without_area_has_no_stipples() {
        let p = vec![DVec4::ZERO, DVec4::X, DVec4::X * 2.0];
        let s = Stipples::generate(&p, &[[0, 1, 2]], 100, 0);
        assert!(s.is_empty());
        assert_eq!(s.area, 0.0);
    }
}
