//! The adaptive sampler: Delaunay refinement in the parameter domain until every triangle
//! meets a tolerance on its distance to the surface.
//!
//! Each patch is a constrained Delaunay triangulation (spade) of points in its normalized
//! rectangle (s, t) in [0, 1]^2, with the rectangle's sides as constraint edges. The
//! triangulation is taken in a warped plane (F(s), G(t)), with F and G monotone and piecewise
//! linear, chosen so that the local aspect ratio F'/G' follows sqrt(|∂ss p| / |∂tt p|), the
//! ratio of the curvature terms of the chordal error along the two parameter directions. A
//! triangle well shaped in that plane then has about the same error along all its edges:
//! the spun knots get triangles long along their tubes and short around them, and their
//! poles, where the circles shrink to a point, get triangles long around. A local anisotropy
//! that is conformal (the Fermat patches, whose metric is λ(x, y)^2 (dx^2 + dy^2) with λ
//! growing like e^{2|y|/n}) needs no warp, and gets none since |∂xx p| = |∂yy p| there: a
//! conformal metric is isotropic, so a Delaunay triangle stays well shaped on the surface and
//! the refinement grades its size with λ. A triangle that the warp folds over in (s, t) is
//! refined until it does not.
//!
//! Refinement works through a queue of triangles. A triangle passes when the surface at the
//! audit's edge and interior points ([`super::AUDIT_POINTS`]) lies within the tolerance of
//! its linear interpolant; otherwise one of its edges is split at its midpoint: the edge
//! whose error is largest, measured at its midpoint or predicted from the surface's second
//! derivatives at the centroid (|d^T H d| / 8 for the edge vector d, the curvature term of
//! the chordal error), or, when only interior points fail, the longest edge in the warped
//! plane. A midpoint that encroaches on a side segment (lies in the circle on it as a
//! diameter) splits that segment instead, as in Ruppert's refinement, so no sliver forms
//! against a side. The new point's triangles join the queue.
//!
//! The queue is worst first: a failing triangle waits on the level of its largest error,
//! counted in factors of 4 above the tolerance (what halving its edges gains), and the
//! refinement goes down the levels in rounds. So when the triangle budget stops it, every
//! triangle left is within a factor of about 4 of the best error the budget allows, not
//! fine in one place and coarse in another. At tolerances below [`TILE_BELOW`] of the
//! surface's extent each patch is cut into tiles (at least [`TILES`] per surface: a surface
//! of one patch, like the spun knots, refines on 16 cores); patches or tiles refine in
//! parallel, each a triangulation of its own within a share of the budget in proportion
//! to its failing triangles (the mesh does not depend on the number of threads); within
//! one, the triangles queued unchecked are checked in batches on the
//! cores, the splits staying in the queue's order (so the mesh is the same as one thread
//! checking them in turn). The seams between tiles are glued sides like those between
//! patches. Between rounds every new side point is inserted on the sides glued to it, so
//! seams conform: side points are dyadic fractions of the side (the starting grids have
//! powers of two of cells, tiles are powers of two per side, and splits halve), and the glue
//! maps (σ ↦ offset ± σ with offsets that are multiples of 1/2) send them to dyadic
//! fractions exactly. At the end the tiles are welded by the domain rules, as in the uniform
//! sampler, and numbered for the stages after it: vertices along a Z curve of each patch's
//! parameters, triangles by their smallest vertex.
//!
//! Guarantees: when `complete`, every triangle passes the audit's test at the tolerance;
//! closed surfaces give closed manifold meshes, welded by rule, consistently oriented where
//! the surface is orientable. When the triangle budget stops the refinement, the mesh is
//! still a valid mesh, only coarser than asked.

use super::{AUDIT_POINTS, Classes, ErrorBound, Mesh4, corner_error, triangle_bound};
use crate::limits::MIN_EDGE;
use crate::progress::Cancel;
use crate::surfaces::{Domain, Glue, Side, SideRule, Surface};
use glam::DVec4;
use rayon::prelude::*;
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::{BTreeSet, HashMap, VecDeque};

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The outcome of [`sample_adaptive`].
#[derive(Clone, Debug)]
pub struct AdaptiveMesh {
    /// The mesh.
    pub mesh: Mesh4,
    /// Whether every triangle met the tolerance (false when the triangle budget stopped the
    /// refinement, or an edge became too short to split: in floating point, or below
    /// [`MIN_EDGE`] of the surface's extent).
    pub complete: bool,
    /// Triangles that still failed the tolerance when refinement stopped.
    pub failing: usize,
}

/// One tile of a patch being refined (see [`tiles`]).
struct Patch {
    /// The surface's patch the tile is part of.
    of: usize,
    /// The tile's place in its patch, counted in tiles along s and t, and the tiles per
    /// side of the patch (1 for a patch refined whole).
    tile: ([usize; 2], usize),
    /// The tile's rectangle and its sides' rules (seams between tiles glued).
    domain: Domain,
    /// From normalized (s, t) to the triangulation's coordinates.
    warp: Warp,
    cdt: Cdt,
    /// Normalized parameters of each point, indexed by the spade vertex index.
    st: Vec<[f64; 2]>,
    /// The surface point of each point.
    p: Vec<DVec4>,
    /// Whether triangles are held to their proven bound ([`ErrorBound::Proven`]).
    proven: bool,
    /// The rectangles of this patch sampled to a finer tolerance than the surface's.
    finer: FinerIndex,
    /// Each point's own rounding ([`corner_error`]), when `proven`.
    error: Vec<f64>,
    /// Which sides are poles.
    pole: [bool; 4],
    /// The side coordinates of the points on each side (as bits: non-negative floats sort
    /// like their bits).
    sides: [BTreeSet<u64>; 4],
    /// New triangles, to check.
    pending: Vec<Face>,
    /// Triangles to refine, by [`level`]: on each level first in, first out.
    queue: Vec<VecDeque<Queued>>,
    /// New side points whose images on glued sides are still to be inserted.
    outbox: Vec<(Side, f64)>,
    /// Edges too short to split in floating point, or points spade refused.
    stuck: usize,
}

impl Patch {
    fn uv(&self, st: [f64; 2]) -> [f64; 2] {
        let lerp = |r: [f64; 2], x: f64| r[0] + (r[1] - r[0]) * x;
        [lerp(self.domain.u, st[0]), lerp(self.domain.v, st[1])]
    }

    /// Inserts a point, searching for its place from `near` when given (refinement jumps
    /// from the worst triangle to the next worst: a search from the last point inserted
    /// would walk across the patch); returns its vertex and whether it is new.
    fn insert(
        &mut self,
        surface: &Surface,
        st: [f64; 2],
        near: Option<FixedVertexHandle>,
    ) -> Option<(FixedVertexHandle, bool)> {
        let pos = self.warp.apply(st);
        let h = match near {
            Some(hint) => self.cdt.insert_with_hint(pos, hint),
            None => self.cdt.insert(pos),
        }
        .ok()?;
        if h.index() < self.st.len() {
            return Some((h, false));
        }
        debug_assert_eq!(h.index(), self.st.len());
        for (side, sigma) in sides_of_point(st) {
            self.sides[side as usize].insert(sigma.to_bits());
        }
        let [u, v] = self.uv(st);
        let p = surface.point(self.of, u, v);
        self.st.push(st);
        self.p.push(p);
        if self.proven {
            self.error.push(corner_error(surface, self.of, [u, v], p));
        }
        Some((h, true))
    }

    /// The side segment that `st` encroaches on, if any: the point lies inside the circle
    /// whose diameter is the segment (in the triangulation's coordinates). Inserting such a
    /// point would make a sliver against the side; Delaunay refinement (Ruppert) splits the
    /// segment instead. Returns the side and the segment's midpoint.
    fn encroached(&self, st: [f64; 2]) -> Option<(Side, f64)> {
        let p = self.warp.apply(st);
        for side in Side::ALL {
            let along = match side {
                Side::U0 | Side::U1 => st[1],
                Side::V0 | Side::V1 => st[0],
            };
            let set = &self.sides[side as usize];
            let key = along.to_bits();
            let (Some(lo), Some(hi)) = (set.range(..=key).next_back(), set.range(key..).next())
            else {
                continue;
            };
            let (lo, hi) = (f64::from_bits(*lo), f64::from_bits(*hi));
            let (a, b) = (
                self.warp.apply(side_st(side, lo)),
                self.warp.apply(side_st(side, hi)),
            );
            let (cx, cy) = ((a.x + b.x) / 2.0, (a.y + b.y) / 2.0);
            let r2 = ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)) / 4.0;
            if (p.x - cx).powi(2) + (p.y - cy).powi(2) < r2 {
                return Some((side, (lo + hi) / 2.0));
            }
        }
        None
    }

    /// The patch's normalized parameters of the tile's `st`.
    fn in_patch(&self, st: [f64; 2]) -> [f64; 2] {
        let ([i, j], k) = self.tile;
        let k = k as f64;
        [(st[0] + i as f64) / k, (st[1] + j as f64) / k]
    }

    /// Whether the triangle has an edge on a pole side (the weld collapses it).
    fn collapses(&self, t: [usize; 3]) -> bool {
        (0..3).any(|k| {
            let (a, b) = (self.st[t[k]], self.st[t[(k + 1) % 3]]);
            side_of_edge(a, b).is_some_and(|(side, _, _)| self.pole[side as usize])
        })
    }
}

/// The side an edge lies on, with the side coordinates of its ends.
fn side_of_edge(a: [f64; 2], b: [f64; 2]) -> Option<(Side, f64, f64)> {
    if a[0] == b[0] && (a[0] == 0.0 || a[0] == 1.0) {
        let side = if a[0] == 0.0 { Side::U0 } else { Side::U1 };
        return Some((side, a[1], b[1]));
    }
    if a[1] == b[1] && (a[1] == 0.0 || a[1] == 1.0) {
        let side = if a[1] == 0.0 { Side::V0 } else { Side::V1 };
        return Some((side, a[0], b[0]));
    }
    None
}

/// The sides a point lies on (two at a corner), with its side coordinate on each.
fn sides_of_point(st: [f64; 2]) -> impl Iterator<Item = (Side, f64)> {
    let [s, t] = st;
    [
        (s == 0.0).then_some((Side::U0, t)),
        (s == 1.0).then_some((Side::U1, t)),
        (t == 0.0).then_some((Side::V0, s)),
        (t == 1.0).then_some((Side::V1, s)),
    ]
    .into_iter()
    .flatten()
}

/// Normalized parameters of side coordinate `sigma` on `side`.
fn side_st(side: Side, sigma: f64) -> [f64; 2] {
    match side {
        Side::U0 => [0.0, sigma],
        Side::U1 => [1.0, sigma],
        Side::V0 => [sigma, 0.0],
        Side::V1 => [sigma, 1.0],
    }
}

/// The points a side point is glued to: `(patch, side, sigma)` on the other side of every
/// glue piece that contains it.
fn glued_images(domain: &Domain, side: Side, sigma: f64) -> Vec<(usize, Side, f64)> {
    match domain.side(side) {
        SideRule::Glued(pieces) => pieces
            .iter()
            .filter(|g| g.from <= sigma && sigma <= g.to)
            .map(|g| (g.patch, g.side, g.map(sigma)))
            .collect(),
        SideRule::Open | SideRule::Pole => Vec::new(),
    }
}

/// Tiles per surface, at least, where it is cut: enough for the refinement of a surface of
/// one patch (the spun knots) to keep 16 cores busy. Each patch is cut into k x k tiles, k
/// a power of two with patches x k^2 at least this, the same k for every patch.
const TILES: usize = 16;

/// The relative tolerance (of the surface's bounding diagonal) below which a surface is cut
/// into tiles: the catalogue's surfaces then sample into 40,000 to 175,000 triangles or
/// more, and the seams cost nothing that shows. Above it a mesh samples in a fraction of
/// a second on one core, and stays as it always was (the fixtures' meshes, at 1e-3).
const TILE_BELOW: f64 = 1e-4;

/// Triangles of the budget per tile, at least, for a surface to be cut: the tiles' starting
/// grids (about 32 triangles each) must leave the budget to the refinement.
const TILE_BUDGET: usize = 4096;

/// A tile of a patch: its rectangle and side rules, its patch, its place in the patch (in
/// tiles) and the tiles per side of the patch.
struct Tile {
    domain: Domain,
    of: usize,
    corner: [usize; 2],
    k: usize,
}

/// The surface's patches cut into tiles refined side by side ([`Tile`]) where the
/// tolerance is below [`TILE_BELOW`] of its extent and the budget allows. Tile
/// (i, j) of patch p is number (p k + j) k + i. The seams between tiles are glued straight
/// (σ to σ); a patch's glued sides are glued tile to tile, each piece's map σ ↦ offset ±
/// σ carried onto the tiles' side coordinates (k σ - m) as k offset - m' ± m, exact since
/// the offsets are multiples of 1/2 and k a power of two. Where a glue's image would not
/// fall in one tile (an offset that is not a multiple of 1/k), the patches are not cut.
/// The tiles' seams are sides like any other: their points are exchanged between rounds
/// and welded at the end, so the mesh conforms across them and is the same on any number
/// of threads (k does not depend on it).
fn tiles(surface: &Surface, tolerance: f64, max_triangles: usize) -> Vec<Tile> {
    let patches = surface.patch_count();
    let domains: Vec<Domain> = (0..patches).map(|p| surface.domain(p)).collect();
    let mut k = 1;
    if tolerance < TILE_BELOW * super::bounding_diagonal(surface) {
        while patches * k * k < TILES && patches * 4 * k * k * TILE_BUDGET <= max_triangles {
            k *= 2;
        }
    }
    cut(&domains, k).unwrap_or_else(|| cut(&domains, 1).expect("one tile per patch"))
}

/// [`tiles`] with k tiles per side, or `None` where a glue does not map tiles to tiles.
fn cut(domains: &[Domain], k: usize) -> Option<Vec<Tile>> {
    let index = |patch: usize, [i, j]: [usize; 2]| (patch * k + j) * k + i;
    // The tile on `side` of a patch at place m along it.
    let on_side = |side: Side, m: usize| match side {
        Side::U0 => [0, m],
        Side::U1 => [k - 1, m],
        Side::V0 => [m, 0],
        Side::V1 => [m, k - 1],
    };
    let kf = k as f64;
    let part = |r: [f64; 2], a: usize| {
        let at = |a: usize| {
            if a == k {
                r[1]
            } else {
                r[0] + (r[1] - r[0]) * (a as f64 / kf)
            }
        };
        [at(a), at(a + 1)]
    };
    let mut out = Vec::with_capacity(domains.len() * k * k);
    for (patch, domain) in domains.iter().enumerate() {
        for j in 0..k {
            for i in 0..k {
                let mut sides = domain.sides.clone();
                for side in Side::ALL {
                    let (inside, neighbour, along) = match side {
                        Side::U0 => (i > 0, [i.wrapping_sub(1), j], j),
                        Side::U1 => (i + 1 < k, [i + 1, j], j),
                        Side::V0 => (j > 0, [i, j.wrapping_sub(1)], i),
                        Side::V1 => (j + 1 < k, [i, j + 1], i),
                    };
                    let opposite = match side {
                        Side::U0 => Side::U1,
                        Side::U1 => Side::U0,
                        Side::V0 => Side::V1,
                        Side::V1 => Side::V0,
                    };
                    sides[side as usize] = if inside {
                        SideRule::Glued(vec![Glue::whole(index(patch, neighbour), opposite, false)])
                    } else {
                        match domain.side(side) {
                            SideRule::Glued(pieces) => {
                                let mut glued = Vec::new();
                                let (a, b) = (along as f64 / kf, (along + 1) as f64 / kf);
                                for g in pieces {
                                    let (lo, hi) = (g.from.max(a), g.to.min(b));
                                    if lo >= hi {
                                        continue;
                                    }
                                    let (x, y) = (g.map(lo), g.map(hi));
                                    let first = x.min(y);
                                    let m = ((first * kf).floor().max(0.0) as usize).min(k - 1);
                                    if x.max(y) > (m + 1) as f64 / kf || first < m as f64 / kf {
                                        return None;
                                    }
                                    let shift = along as f64;
                                    glued.push(Glue {
                                        from: lo * kf - shift,
                                        to: hi * kf - shift,
                                        patch: index(g.patch, on_side(g.side, m)),
                                        side: g.side,
                                        offset: kf * g.offset - m as f64
                                            + if g.reversed { -shift } else { shift },
                                        reversed: g.reversed,
                                    });
                                }
                                if glued.is_empty() {
                                    SideRule::Open
                                } else {
                                    SideRule::Glued(glued)
                                }
                            }
                            rule => rule.clone(),
                        }
                    };
                }
                out.push(Tile {
                    domain: Domain {
                        u: part(domain.u, i),
                        v: part(domain.v, j),
                        sides,
                    },
                    of: patch,
                    corner: [i, j],
                    k,
                });
            }
        }
    }
    Some(out)
}

/// A monotone piecewise-linear map of [0, 1] onto [0, end], in equal pieces. It maps 0 to
/// 0 and 1 to `end` exactly, so the points of a side stay exactly collinear.
#[derive(Clone, Debug)]
struct Axis {
    knots: Vec<f64>,
}

impl Axis {
    fn from_slopes(slopes: &[f64]) -> Axis {
        let n = slopes.len() as f64;
        let mut knots = vec![0.0];
        for s in slopes {
            knots.push(knots[knots.len() - 1] + s / n);
        }
        Axis { knots }
    }

    fn end(&self) -> f64 {
        self.knots[self.knots.len() - 1]
    }

    fn scaled(mut self, k: f64) -> Axis {
        self.knots.iter_mut().for_each(|x| *x *= k);
        self
    }

    fn at(&self, x: f64) -> f64 {
        let n = self.knots.len() - 1;
        if x <= 0.0 {
            return 0.0;
        }
        if x >= 1.0 {
            return self.knots[n];
        }
        let y = x * n as f64;
        let i = (y as usize).min(n - 1);
        self.knots[i] + (self.knots[i + 1] - self.knots[i]) * (y - i as f64)
    }
}

/// The map from a patch's normalized parameters to the plane where it is triangulated: a
/// separable warp (F(s), G(t)) whose local aspect ratio F'/G' follows the ratio of the
/// curvature terms of the chordal error, sqrt(|∂ss p| / |∂tt p|), so that a triangle that is
/// well shaped in the plane has about the same error along all its edges.
#[derive(Clone, Debug)]
struct Warp {
    s: Axis,
    t: Axis,
}

impl Warp {
    fn apply(&self, st: [f64; 2]) -> Point2<f64> {
        Point2::new(self.s.at(st[0]), self.t.at(st[1]))
    }
}

/// Builds a patch's warp from the second derivatives at the cell centres of a 32 x 32 grid
/// (branch points lie on sides, so the centres avoid them). The log of the local ratio is
/// split into a part in s and a part in t (a two-way additive fit), limited to a factor 30
/// around its median and a factor 2 from one piece to the next, so the warp stays gentle.
fn patch_warp(surface: &Surface, patch: usize, domain: &Domain) -> Warp {
    const N: usize = 32;
    let (lu, lv) = (domain.u[1] - domain.u[0], domain.v[1] - domain.v[0]);
    let mut q = vec![[f64::NAN; 2]; N * N];
    let (mut sum, mut count) = (0.0, 0usize);
    for j in 0..N {
        for i in 0..N {
            let s = (i as f64 + 0.5) / N as f64;
            let t = (j as f64 + 0.5) / N as f64;
            let e = surface.eval(patch, domain.u[0] + lu * s, domain.v[0] + lv * t);
            let pair = [e.duu.length() * lu * lu, e.dvv.length() * lv * lv];
            if pair[0].is_finite() && pair[1].is_finite() {
                q[j * N + i] = pair;
                sum += pair[0] + pair[1];
                count += 1;
            }
        }
    }
    let floor = 0.05 * sum / (2 * count.max(1)) as f64 + f64::MIN_POSITIVE;
    let r = |i: usize, j: usize| {
        let [a, b] = q[j * N + i];
        (a.is_finite() && b.is_finite()).then(|| 0.5 * ((a + floor) / (b + floor)).ln())
    };
    let mean = |it: &mut dyn Iterator<Item = Option<f64>>| {
        let (s, n) = it.flatten().fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        if n == 0 { 0.0 } else { s / n as f64 }
    };
    let all = mean(&mut (0..N * N).map(|k| r(k % N, k / N)));
    let a: Vec<f64> = (0..N)
        .map(|i| mean(&mut (0..N).map(|j| r(i, j))) - all / 2.0)
        .collect();
    let b: Vec<f64> = (0..N)
        .map(|j| all / 2.0 - mean(&mut (0..N).map(|i| r(i, j))))
        .collect();
    let slopes = |logs: Vec<f64>| -> Vec<f64> {
        let mut sorted = logs.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[N / 2];
        let mut l: Vec<f64> = logs
            .iter()
            .map(|x| x.clamp(median - 30f64.ln(), median + 30f64.ln()))
            .collect();
        for k in 1..N {
            l[k] = l[k].clamp(l[k - 1] - 2f64.ln(), l[k - 1] + 2f64.ln());
        }
        for k in (0..N - 1).rev() {
            l[k] = l[k].clamp(l[k + 1] - 2f64.ln(), l[k + 1] + 2f64.ln());
        }
        l.into_iter().map(f64::exp).collect()
    };
    let (s, t) = (Axis::from_slopes(&slopes(a)), Axis::from_slopes(&slopes(b)));
    let m = s.end().max(t.end());
    Warp {
        s: s.scaled(1.0 / m),
        t: t.scaled(1.0 / m),
    }
}

/// The geometric mean over the patches of the ratio of the scaled lengths of the u and v
/// sides (see the module documentation): the shape of a grid whose cells are square on the
/// surface on average.
pub fn metric_aspect(surface: &Surface) -> f64 {
    let n = surface.patch_count();
    let log_sum: f64 = (0..n)
        .map(|patch| {
            let w = patch_warp(surface, patch, &surface.domain(patch));
            (w.s.end() / w.t.end()).ln()
        })
        .sum();
    (log_sum / n.max(1) as f64).exp()
}

/// A power of two of cells, at least `min` and 2, near `x`. Powers of two keep every side
/// point a dyadic fraction, which the glue maps (σ ↦ offset ± σ, offsets multiples of 1/2)
/// send to dyadic fractions exactly, so glued points meet bit for bit.
fn grid_cells(x: f64, min: usize) -> usize {
    (x.round() as usize).max(min).max(2).next_power_of_two()
}

/// The verdict on one triangle.
enum Verdict {
    Pass,
    /// Split the edges from corner k to corner k + 1, for each listed k; `score` is the
    /// triangle's largest error at the audit points (infinite for a folded triangle).
    Split {
        edges: Vec<usize>,
        score: f64,
    },
}

/// A triangle in the refinement's queue. A triangle made by a split is queued unchecked on
/// its parent's level, behind the triangles already there. When the first of them comes to
/// the front, the unchecked triangles still standing among the level's first
/// [`CHECK_BATCH`] are checked at once, on the cores (a check reads the triangulation and
/// evaluates the surface, and changes nothing; the splits that follow stay in the queue's
/// order, so the mesh does not depend on the number of threads).
#[derive(Clone, Copy)]
struct Queued {
    face: Face,
    check: Check,
}

/// What a queued triangle's check found.
#[derive(Clone, Copy)]
enum Check {
    /// Not checked yet.
    Due,
    /// It passes.
    Passed,
    /// It fails: the edges to split (bit k for the edge from corner k) and its level.
    Failed { edges: u8, level: usize },
}

impl Check {
    fn of(verdict: Verdict, tolerance: f64) -> Check {
        match verdict {
            Verdict::Pass => Check::Passed,
            Verdict::Split { edges, score } => Check::Failed {
                edges: edges.iter().fold(0, |m, &k| m | 1 << k),
                level: level(score, tolerance),
            },
        }
    }
}

/// A triangle of a patch's triangulation: the face that held it and its corners (the face
/// holds another triangle once a split has changed it).
type Face = (FixedFaceHandle<InnerTag>, [FixedVertexHandle; 3]);

/// Queued triangles checked together: enough to keep the cores busy, few enough that not
/// many of them are split away by the triangles ahead of them before their turn (their
/// check is then wasted).
const CHECK_BATCH: usize = 2048;

/// Levels of the refinement's queue.
const LEVELS: usize = 64;

/// The queue level of a triangle whose largest error is `score`: 0 when it passes, else the
/// number of factors of 4 (what halving a triangle's edges gains on its chordal error) by
/// which the score exceeds the tolerance, rounded up; the top level for a folded triangle
/// (an infinite score).
fn level(score: f64, tolerance: f64) -> usize {
    if score <= tolerance {
        0
    } else if !score.is_finite() {
        LEVELS - 1
    } else {
        ((score / tolerance).log(4.0).ceil() as usize).clamp(1, LEVELS - 2)
    }
}

/// Samples `surface` so that every triangle lies within `tolerance` (an absolute length in
/// R^4) of the surface at the audit points, stopping when the mesh would exceed
/// `max_triangles` triangles. Patches are refined in parallel.
pub fn sample_adaptive(surface: &Surface, tolerance: f64, max_triangles: usize) -> AdaptiveMesh {
    sample_adaptive_to(surface, tolerance, ErrorBound::Audited, max_triangles)
}

/// [`sample_adaptive`], holding every triangle to the `bound` of its error: the audit's
/// points, or the proven bound over the whole triangle ([`triangle_bound`]).
pub fn sample_adaptive_to(
    surface: &Surface,
    tolerance: f64,
    bound: ErrorBound,
    max_triangles: usize,
) -> AdaptiveMesh {
    sample_adaptive_through(surface, tolerance, bound, max_triangles, &[])
}

/// [`sample_adaptive_to`] with a vertex at each of the points `through` (a patch and its
/// parameters) that lies inside a tile or on an open side: inserted into the starting
/// grids, so that the refinement grades the mesh around them. A point on a glued side of a
/// tile (a seam, a pole) or at a corner is left out: a side point off the sides' dyadic
/// fractions would not weld.
/// The motion pictures sample through the critical points of their heights, so that the
/// mesh's slices change at the surface's critical levels.
pub fn sample_adaptive_through(
    surface: &Surface,
    tolerance: f64,
    bound: ErrorBound,
    max_triangles: usize,
    through: &[(usize, [f64; 2])],
) -> AdaptiveMesh {
    let guides = Guides {
        through,
        ..Guides::default()
    };
    sample_adaptive_with(surface, tolerance, bound, max_triangles, guides)
}

/// The share of a tolerance the sampler holds triangles to: slightly under, so that a
/// triangle measured at the tolerance passes.
const UNDER: f64 = 1.0 - 1e-9;

/// What guides the adaptive sampler besides its tolerance, and what stops it.
#[derive(Clone, Copy)]
struct Guides<'a> {
    /// Points to pass through.
    through: &'a [(usize, [f64; 2])],
    /// Rectangles held to a finer tolerance.
    finer: &'a [Finer],
    /// Checked between the refinement's batches: once cancelled, the sampler stops and
    /// gives the mesh it has.
    cancel: &'a Cancel,
}

impl Default for Guides<'_> {
    fn default() -> Self {
        Guides {
            through: &[],
            finer: &[],
            cancel: Cancel::never(),
        }
    }
}

/// The adaptive sampler with its guides.
fn sample_adaptive_with(
    surface: &Surface,
    tolerance: f64,
    bound: ErrorBound,
    max_triangles: usize,
    guides: Guides,
) -> AdaptiveMesh {
    let mut sampler = Sampler::new(surface, tolerance * UNDER, bound, max_triangles, guides);
    sampler.insert_through(guides.through);
    let complete = sampler.refine(max_triangles);
    let failing = if complete || guides.cancel.is_cancelled() {
        0
    } else {
        sampler.count_failing()
    };
    AdaptiveMesh {
        mesh: sampler.weld(),
        complete: complete && failing == 0,
        failing,
    }
}

/// A rectangle of a patch's parameters to sample to a finer tolerance than the rest of its
/// surface (see [`sample_adaptive_finer`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finer {
    /// The patch.
    pub patch: usize,
    /// The range of u.
    pub u: [f64; 2],
    /// The range of v.
    pub v: [f64; 2],
    /// The tolerance (an absolute length) of the triangles that meet the rectangle.
    pub tolerance: f64,
}

/// A tile's [`Finer`] rectangles, bucketed in a grid over the tile's parameters, so that a
/// triangle looks only at those near it (a long curve's rectangles can number in the
/// thousands).
#[derive(Default)]
struct FinerIndex {
    rects: Vec<Finer>,
    u: [f64; 2],
    v: [f64; 2],
    /// Cells per side.
    n: usize,
    /// Each cell's rectangles (indices into `rects`), row by row along u.
    cells: Vec<Vec<u32>>,
}

impl FinerIndex {
    fn new<'a>(rects: impl Iterator<Item = &'a Finer>, domain: &Domain) -> FinerIndex {
        let rects: Vec<Finer> = rects
            .map(|f| Finer {
                tolerance: f.tolerance * UNDER,
                ..*f
            })
            .collect();
        if rects.is_empty() {
            return FinerIndex::default();
        }
        let n = (rects.len() as f64).sqrt().ceil().clamp(1.0, 64.0) as usize;
        let mut index = FinerIndex {
            rects,
            u: domain.u,
            v: domain.v,
            n,
            cells: vec![Vec::new(); n * n],
        };
        for (k, r) in index.rects.iter().enumerate() {
            let ([i0, i1], [j0, j1]) = (index.span(r.u, index.u), index.span(r.v, index.v));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    index.cells[j * n + i].push(k as u32);
                }
            }
        }
        index
    }

    /// The cells a range of parameters `r` over the tile's `domain` range covers (clamped to
    /// the grid: what lies beyond the tile falls into its edge cells).
    fn span(&self, r: [f64; 2], domain: [f64; 2]) -> [usize; 2] {
        let cell = |x: f64| {
            let t = (x - domain[0]) / (domain[1] - domain[0]) * self.n as f64;
            if t.is_nan() {
                0
            } else {
                (t.floor().max(0.0) as usize).min(self.n - 1)
            }
        };
        [cell(r[0]), cell(r[1])]
    }

    /// The finest tolerance of the rectangles that meet the box `u` x `v`, else `global`.
    fn finest(&self, u: [f64; 2], v: [f64; 2], global: f64) -> f64 {
        if self.rects.is_empty() {
            return global;
        }
        let ([i0, i1], [j0, j1]) = (self.span(u, self.u), self.span(v, self.v));
        let mut out = global;
        for j in j0..=j1 {
            for i in i0..=i1 {
                for &k in &self.cells[j * self.n + i] {
                    let r = &self.rects[k as usize];
                    if r.u[0] <= u[1] && u[0] <= r.u[1] && r.v[0] <= v[1] && v[0] <= r.v[1] {
                        out = out.min(r.tolerance);
                    }
                }
            }
        }
        out
    }
}

/// [`sample_adaptive_to`] with every triangle that meets one of the rectangles `finer`
/// held to that rectangle's tolerance: the build samples a surface again so, around the
/// double curves its mesh missed ([`crate::intersect::certified`]). Once `cancel` is
/// cancelled it stops refining and gives the mesh it has, which the caller drops.
pub fn sample_adaptive_finer(
    surface: &Surface,
    tolerance: f64,
    bound: ErrorBound,
    max_triangles: usize,
    finer: &[Finer],
    cancel: &Cancel,
) -> AdaptiveMesh {
    let guides = Guides {
        finer,
        cancel,
        ..Guides::default()
    };
    sample_adaptive_with(surface, tolerance, bound, max_triangles, guides)
}

/// What a patch needs to refine itself.
struct Context<'a> {
    surface: &'a Surface,
    tolerance: f64,
    cancel: &'a Cancel,
    /// Edges shorter than this (4D) are not split: [`MIN_EDGE`] of the extent.
    min_edge: f64,
}

impl Patch {
    fn queue_around(&mut self, h: FixedVertexHandle) {
        for e in self.cdt.vertex(h).out_edges() {
            if let Some(f) = e.face().as_inner() {
                self.pending.push((f.fix(), f.vertices().map(|v| v.fix())));
            }
        }
    }

    /// Checks the new triangles and queues those that fail.
    fn settle(&mut self, surface: &Surface, tolerance: f64) {
        let pending = std::mem::take(&mut self.pending);
        for &face in &pending {
            if self.alive(face) {
                self.queue_checked(surface, tolerance, face);
            }
        }
        self.pending = pending;
        self.pending.clear();
    }

    /// Checks a triangle and queues it on its level when it fails.
    fn queue_checked(&mut self, surface: &Surface, tolerance: f64, face: Face) {
        let t = face.1.map(|h| h.index());
        let check = Check::of(self.check(surface, tolerance, t), tolerance);
        if let Check::Failed { level, .. } = check {
            self.queue[level].push_back(Queued { face, check });
        }
    }

    /// Triangles queued above level `floor`.
    fn work(&self, floor: usize) -> usize {
        self.queue[floor + 1..].iter().map(VecDeque::len).sum()
    }

    /// Whether the triangle is still one of the triangulation's: its face still has its
    /// corners (in some rotation).
    fn alive(&self, (face, [a, b, c]): Face) -> bool {
        let now = self.cdt.face(face).vertices().map(|v| v.fix());
        now == [a, b, c] || now == [b, c, a] || now == [c, a, b]
    }

    /// Inserts a point and queues its triangles; records it in the outbox when it is a new
    /// side point, for the sides glued to it. Returns whether the point is new.
    fn add(&mut self, surface: &Surface, st: [f64; 2], near: Option<FixedVertexHandle>) -> bool {
        match self.insert(surface, st, near) {
            Some((h, true)) => {
                self.queue_around(h);
                self.outbox.extend(sides_of_point(st));
                true
            }
            Some((h, false)) => {
                // Another point at the same place in the plane: the warp rounded two
                // parameters together, and this split cannot be made.
                if self.st[h.index()] != st {
                    self.stuck += 1;
                }
                false
            }
            None => {
                self.stuck += 1;
                false
            }
        }
    }

    /// Refines this patch, worst level first, until no triangle is queued above level
    /// `floor` (true) or the next split could take it past `share` more triangles (false).
    fn refine(&mut self, cx: &Context, floor: usize, share: usize) -> bool {
        let mut used = 0usize;
        // The level worked on: nothing is queued above it again (new triangles go on it or
        // below), so it only goes down.
        let mut at = LEVELS - 1;
        loop {
            while at > floor && self.queue[at].is_empty() {
                at -= 1;
            }
            if at == floor {
                return true;
            }
            let Some(q) = self.queue[at].pop_front() else {
                continue;
            };
            let (t, tri) = (q.face.1.map(|h| h.index()), q.face.1);
            if !self.alive(q.face) {
                continue;
            }
            let split = match q.check {
                Check::Due if cx.cancel.is_cancelled() => return true,
                Check::Due => {
                    self.queue[at].push_front(q);
                    self.check_level(cx, at);
                    continue;
                }
                Check::Passed => continue,
                Check::Failed { level, .. } if level < at => {
                    self.queue[level].push_back(q);
                    continue;
                }
                Check::Failed { edges, .. } => edges,
            };
            let mut edges: Vec<usize> = (0..3).filter(|k| split & 1 << k != 0).collect();
            edges.retain(|&k| (self.p[t[k]] - self.p[t[(k + 1) % 3]]).length() >= cx.min_edge);
            if edges.is_empty() {
                self.stuck += 1;
                continue;
            }
            // What the splits can add: per edge, two triangles here and, for a side point,
            // four on the sides glued to it (inserted after this round).
            let reserve = 6 * edges.len();
            if used + reserve > share {
                self.queue[at].push_front(q);
                return false;
            }
            let (faces, sent) = (self.cdt.num_inner_faces(), self.outbox.len());
            let ends: Vec<_> = edges
                .iter()
                .map(|&k| (self.st[t[k]], self.st[t[(k + 1) % 3]]))
                .collect();
            let mut added = false;
            for (a, b) in ends {
                added |= self.split(cx.surface, a, b, tri[0]);
            }
            used += self.cdt.num_inner_faces() - faces + 4 * (self.outbox.len() - sent);
            // A split elsewhere (an encroached side) may leave this triangle standing; one
            // that added no point is stuck, and counted so.
            if added {
                self.pending.push(q.face);
            }
            for face in self.pending.drain(..) {
                self.queue[at].push_back(Queued {
                    face,
                    check: Check::Due,
                });
            }
        }
    }

    /// Checks the unchecked triangles still standing among the first [`CHECK_BATCH`] of level
    /// `at`, on the cores.
    fn check_level(&mut self, cx: &Context, at: usize) {
        let mut queue = std::mem::take(&mut self.queue[at]);
        let this = &*self;
        queue
            .par_iter_mut()
            .take(CHECK_BATCH)
            .filter(|q| matches!(q.check, Check::Due) && this.alive(q.face))
            .for_each(|q| {
                let t = q.face.1.map(|h| h.index());
                q.check = Check::of(this.check(cx.surface, cx.tolerance, t), cx.tolerance);
            });
        self.queue[at] = queue;
    }

    /// Splits the edge from `sa` to `sb` (normalized parameters) at its midpoint, or the
    /// side segment that midpoint encroaches on. Returns whether a point was added.
    fn split(
        &mut self,
        surface: &Surface,
        sa: [f64; 2],
        sb: [f64; 2],
        near: FixedVertexHandle,
    ) -> bool {
        let mid = [(sa[0] + sb[0]) / 2.0, (sa[1] + sb[1]) / 2.0];
        if mid == sa || mid == sb {
            self.stuck += 1;
            return false;
        }
        let at = if side_of_edge(sa, sb).is_some() {
            mid
        } else if let Some((side, sigma)) = self.encroached(mid) {
            side_st(side, sigma)
        } else {
            mid
        };
        self.add(surface, at, Some(near))
    }

    /// Tests a triangle at the audit's edge and interior points.
    fn check(&self, surface: &Surface, global: f64, t: [usize; 3]) -> Verdict {
        let patch = self.of;
        if self.collapses(t) {
            return Verdict::Pass;
        }
        let uv = t.map(|i| self.uv(self.st[i]));
        let tolerance = self.tolerance_at(&uv, global);
        let corners = t.map(|i| self.p[i]);
        let mut worst = 0.0f64;
        let mut edge_error = [0.0f64; 3];
        for (k, b) in AUDIT_POINTS.iter().enumerate().skip(3) {
            let u = b[0] * uv[0][0] + b[1] * uv[1][0] + b[2] * uv[2][0];
            let v = b[0] * uv[0][1] + b[1] * uv[1][1] + b[2] * uv[2][1];
            let chord = corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2];
            let d = (surface.point(patch, u, v) - chord).length();
            let d = if d.is_finite() { d } else { f64::INFINITY };
            worst = worst.max(d);
            if k < 6 {
                // The midpoints of the edges from corner k - 3 to the next corner.
                edge_error[k - 3] = d;
            }
        }
        // The proof is only worth its enclosure where the audit's points pass: a triangle
        // failing them is split either way, waiting on the level of its measured error.
        if self.proven && worst <= tolerance {
            let bound = triangle_bound(surface, patch, uv, corners, t.map(|i| self.error[i]));
            worst = worst.max(bound);
        }
        // The warp is curved, so a triangle counter-clockwise in the warped plane can be
        // folded over in (u, v); refinement straightens the warp until it is not.
        let [a, b, c] = t.map(|i| {
            let [x, y] = self.st[i];
            robust::Coord { x, y }
        });
        let folded = robust::orient2d(a, b, c) <= 0.0;
        if worst <= tolerance && !folded {
            return Verdict::Pass;
        }
        let score = if folded { f64::INFINITY } else { worst };
        // The curvature term of each edge's chordal error, from the centroid's Hessian.
        let c = [
            (uv[0][0] + uv[1][0] + uv[2][0]) / 3.0,
            (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0,
        ];
        let e = surface.eval(patch, c[0], c[1]);
        let mut edge_score = [0.0f64; 3];
        let mut longest = (0.0f64, 0usize);
        for k in 0..3 {
            let (a, b) = (uv[k], uv[(k + 1) % 3]);
            let (du, dv) = (b[0] - a[0], b[1] - a[1]);
            let predicted =
                (e.duu * (du * du) + e.duv * (2.0 * du * dv) + e.dvv * (dv * dv)).length() / 8.0;
            edge_score[k] = edge_error[k].max(if predicted.is_finite() {
                predicted
            } else {
                0.0
            });
            let (wa, wb) = (
                self.warp.apply(self.st[t[k]]),
                self.warp.apply(self.st[t[(k + 1) % 3]]),
            );
            let len = (wb.x - wa.x).hypot(wb.y - wa.y);
            if len > longest.0 {
                longest = (len, k);
            }
        }
        let over: Vec<usize> = (0..3)
            .filter(|&k| edge_score[k] > tolerance && !folded)
            .collect();
        let edges = match over.len() {
            0 => vec![longest.1],
            // Every edge too long: split all three (a 1-to-4 refinement, one check for
            // what single splits would take two levels of checks to reach).
            3 => over,
            _ => vec![(0..3).fold(0, |m, k| if edge_score[k] > edge_score[m] { k } else { m })],
        };
        // The score in units of the surface's tolerance, which the queue's levels count in.
        let score = score * (global / tolerance);
        Verdict::Split { edges, score }
    }

    /// The tolerance a triangle of parameters `uv` is held to: the finest of the [`Finer`]
    /// rectangles its parameters' box meets, else the surface's `global` one.
    fn tolerance_at(&self, uv: &[[f64; 2]; 3], global: f64) -> f64 {
        let lo = |k: usize| uv[0][k].min(uv[1][k]).min(uv[2][k]);
        let hi = |k: usize| uv[0][k].max(uv[1][k]).max(uv[2][k]);
        self.finer.finest([lo(0), hi(0)], [lo(1), hi(1)], global)
    }
}

struct Sampler<'a> {
    surface: &'a Surface,
    tolerance: f64,
    patches: Vec<Patch>,
    cancel: &'a Cancel,
}

impl<'a> Sampler<'a> {
    /// Starts every tile of every patch ([`tiles`], within the budget of `max_triangles`)
    /// from a coarse grid shaped like its
    /// warped rectangle, with the rectangle's sides as constraint edges, and makes the
    /// glued sides conform.
    fn new(
        surface: &'a Surface,
        tolerance: f64,
        bound: ErrorBound,
        max_triangles: usize,
        guides: Guides<'a>,
    ) -> Self {
        let [min_u, min_v] = surface.min_cells();
        let mut patches = Vec::new();
        for Tile {
            domain,
            of,
            corner,
            k,
        } in tiles(surface, tolerance, max_triangles)
        {
            let warp = patch_warp(surface, of, &domain);
            let pole = Side::ALL.map(|s| matches!(domain.side(s), SideRule::Pole));
            // About 16 cells, shaped like the warped rectangle.
            let aspect = warp.s.end() / warp.t.end();
            let nu = grid_cells(4.0 * aspect.sqrt(), min_u.div_ceil(k));
            let nv = grid_cells(4.0 / aspect.sqrt(), min_v.div_ceil(k));
            let rects = FinerIndex::new(guides.finer.iter().filter(|f| f.patch == of), &domain);
            let mut p = Patch {
                of,
                tile: (corner, k),
                domain,
                warp,
                cdt: Cdt::new(),
                st: Vec::new(),
                p: Vec::new(),
                proven: bound == ErrorBound::Proven,
                finer: rects,
                error: Vec::new(),
                pole,
                sides: Default::default(),
                pending: Vec::new(),
                queue: vec![VecDeque::new(); LEVELS],
                outbox: Vec::new(),
                stuck: 0,
            };
            let mut handles = vec![vec![None; nu + 1]; nv + 1];
            for (j, row) in handles.iter_mut().enumerate() {
                for (i, h) in row.iter_mut().enumerate() {
                    let st = [i as f64 / nu as f64, j as f64 / nv as f64];
                    *h = p.insert(surface, st, None).map(|(h, _)| h);
                    p.outbox.extend(sides_of_point(st));
                }
            }
            let mut boundary = Vec::new();
            boundary.extend((0..nu).map(|i| (handles[0][i], handles[0][i + 1])));
            boundary.extend((0..nu).map(|i| (handles[nv][i], handles[nv][i + 1])));
            boundary.extend((0..nv).map(|j| (handles[j][0], handles[j + 1][0])));
            boundary.extend((0..nv).map(|j| (handles[j][nu], handles[j + 1][nu])));
            for (a, b) in boundary {
                if let (Some(a), Some(b)) = (a, b) {
                    p.cdt.add_constraint(a, b);
                }
            }
            let faces: Vec<_> = p
                .cdt
                .inner_faces()
                .map(|f| (f.fix(), f.vertices().map(|v| v.fix())))
                .collect();
            p.pending.extend(faces);
            patches.push(p);
        }
        let mut sampler = Sampler {
            surface,
            tolerance,
            patches,
            cancel: guides.cancel,
        };
        sampler.exchange();
        sampler
    }

    fn triangles(&self) -> usize {
        self.patches.iter().map(|p| p.cdt.num_inner_faces()).sum()
    }

    /// Inserts each of the points `through` that lies strictly inside a tile
    /// ([`sample_adaptive_through`]), and checks the triangles around it.
    fn insert_through(&mut self, through: &[(usize, [f64; 2])]) {
        if through.is_empty() {
            return;
        }
        for &(patch, [u, v]) in through {
            let inside = |r: [f64; 2], x: f64| (x - r[0]) / (r[1] - r[0]);
            let tile = self.patches.iter_mut().find_map(|p| {
                let st = [inside(p.domain.u, u), inside(p.domain.v, v)];
                // Strictly inside, or on an open side (which welds to nothing) and
                // strictly inside along it.
                let open = |s: Side| matches!(p.domain.side(s), SideRule::Open);
                let within = |x: f64| x > 0.0 && x < 1.0;
                let on = |x: f64, low: Side, high: Side| {
                    within(x) || (x == 0.0 && open(low)) || (x == 1.0 && open(high))
                };
                let fits = (within(st[0]) && on(st[1], Side::V0, Side::V1))
                    || (within(st[1]) && on(st[0], Side::U0, Side::U1));
                (p.of == patch && fits).then_some((p, st))
            });
            if let Some((p, st)) = tile {
                p.add(self.surface, st, None);
            }
        }
        let (surface, tolerance) = (self.surface, self.tolerance);
        self.patches
            .par_iter_mut()
            .for_each(|p| p.settle(surface, tolerance));
    }

    /// Empties the outboxes: inserts the images of every new side point on the sides glued
    /// to it, recursively (an image on a piece end has images of its own).
    fn exchange(&mut self) {
        let mut work: Vec<(usize, Side, f64)> = Vec::new();
        for p in &mut self.patches {
            for (side, sigma) in p.outbox.drain(..) {
                work.extend(glued_images(&p.domain, side, sigma));
            }
        }
        while let Some((patch, side, sigma)) = work.pop() {
            let p = &mut self.patches[patch];
            if p.add(self.surface, side_st(side, sigma), None) {
                work.extend(glued_images(&p.domain, side, sigma));
            }
            p.outbox.clear();
        }
        let (surface, tolerance) = (self.surface, self.tolerance);
        self.patches
            .par_iter_mut()
            .for_each(|p| p.settle(surface, tolerance));
    }

    /// Refines until every triangle passes (true), or the budget or floating point stops it
    /// (false). Worst first, in rounds: each round refines every triangle queued above a
    /// floor level, one level (a factor 4 of error) lower than the round before, down to
    /// the tolerance; so when the budget stops the refinement, the worst triangle left is as
    /// good as the budget allows, within that factor. In a round every patch refines on its
    /// own, in parallel, within a share of the budget left in proportion to its work above
    /// the floor; then the new side points cross the seams, which queues the triangles they
    /// split on the other side. The shares, not the threads' timing, decide where the budget
    /// goes: the mesh is the same on any number of threads.
    fn refine(&mut self, max_triangles: usize) -> bool {
        let (lo, hi) = self
            .patches
            .iter()
            .flat_map(|p| &p.p)
            .fold((DVec4::INFINITY, DVec4::NEG_INFINITY), |(lo, hi), &q| {
                (lo.min(q), hi.max(q))
            });
        let extent = (hi - lo).length();
        let cx = Context {
            surface: self.surface,
            tolerance: self.tolerance,
            cancel: self.cancel,
            min_edge: MIN_EDGE * if extent.is_finite() { extent } else { 0.0 },
        };
        // Below the highest level of a finite error (folded triangles, on the top level,
        // are above every floor).
        let mut floor = self
            .patches
            .iter()
            .filter_map(|p| (1..LEVELS - 1).rev().find(|&l| !p.queue[l].is_empty()))
            .max()
            .unwrap_or(1)
            - 1;
        loop {
            if self.cancel.is_cancelled() {
                return false;
            }
            let work: Vec<usize> = self.patches.iter().map(|p| p.work(floor)).collect();
            let total: usize = work.iter().sum();
            if total == 0 {
                if floor == 0 {
                    return self.patches.iter().all(|p| p.stuck == 0);
                }
                floor -= 1;
                continue;
            }
            let before = self.triangles();
            let left = max_triangles.saturating_sub(before) as u128;
            let done: Vec<bool> = self
                .patches
                .par_iter_mut()
                .zip(work)
                .map(|(p, w)| {
                    let share = (left * w as u128 / total as u128) as usize;
                    p.refine(&cx, floor, share)
                })
                .collect();
            // The seams conform even when the budget stopped the round.
            self.exchange();
            if !done.into_iter().all(|d| d) && self.triangles() == before {
                // The budget left is too small for any split.
                return false;
            }
        }
    }

    /// Triangles that fail the test now (after the budget stopped refinement).
    fn count_failing(&self) -> usize {
        self.patches
            .iter()
            .map(|p| {
                p.cdt
                    .inner_faces()
                    .filter(|f| {
                        let t = f.vertices().map(|v| v.fix().index());
                        matches!(
                            p.check(self.surface, self.tolerance, t),
                            Verdict::Split { .. }
                        )
                    })
                    .count()
            })
            .sum()
    }

    /// Welds the patches by the domain rules into one mesh.
    fn weld(self) -> Mesh4 {
        let offsets: Vec<usize> = self
            .patches
            .iter()
            .scan(0, |acc, p| {
                let o = *acc;
                *acc += p.st.len();
                Some(o)
            })
            .collect();
        let total = offsets
            .last()
            .map_or(0, |o| o + self.patches.last().map_or(0, |p| p.st.len()));
        // Side points by exact parameters.
        let mut at: HashMap<(usize, u64, u64), usize> = HashMap::new();
        for (patch, p) in self.patches.iter().enumerate() {
            for (i, st) in p.st.iter().enumerate() {
                if sides_of_point(*st).next().is_some() {
                    at.insert(
                        (patch, st[0].to_bits(), st[1].to_bits()),
                        offsets[patch] + i,
                    );
                }
            }
        }
        let find = |patch: usize, st: [f64; 2]| {
            at.get(&(patch, st[0].to_bits(), st[1].to_bits())).copied()
        };
        let mut classes = Classes((0..total).collect());
        for (patch, p) in self.patches.iter().enumerate() {
            for (i, st) in p.st.iter().enumerate() {
                for (side, sigma) in sides_of_point(*st) {
                    let me = offsets[patch] + i;
                    if p.pole[side as usize]
                        && let Some(first) = find(patch, side_st(side, 0.0))
                    {
                        classes.union(me, first);
                    }
                    for (q, side_q, sigma_q) in glued_images(&p.domain, side, sigma) {
                        let other = find(q, side_st(side_q, sigma_q));
                        debug_assert!(other.is_some(), "seam point without its image");
                        if let Some(other) = other {
                            classes.union(me, other);
                        }
                    }
                }
            }
        }

        // Vertices numbered along a Z curve of each patch's (s, t), triangles by their
        // smallest vertex. The refinement inserts points worst first, anywhere in a patch:
        // numbered in that order, neighbours lie far apart in memory and every later stage
        // waits on its walks over them (what it cost: docs/PERFORMANCE.md § Halos).
        let locate = |id: usize| {
            let patch = offsets.partition_point(|&o| o <= id) - 1;
            (patch, id - offsets[patch])
        };
        let mut order: Vec<(usize, u64, usize)> = (0..total)
            .into_par_iter()
            .map(|id| {
                let (patch, i) = locate(id);
                let p = &self.patches[patch];
                (p.of, z_order(p.in_patch(p.st[i])), id)
            })
            .collect();
        order.par_sort_unstable();
        let mut vertex_of = vec![u32::MAX; total];
        let mut at = Vec::new();
        for id in order.into_iter().map(|(_, _, id)| id) {
            let rep = classes.find(id);
            if vertex_of[rep] == u32::MAX {
                let (patch, i) = locate(rep);
                let p = &self.patches[patch];
                let [u, v] = p.uv(p.st[i]);
                vertex_of[rep] = at.len() as u32;
                at.push((p.of, u, v));
            }
            vertex_of[id] = vertex_of[rep];
        }
        let mut mesh = Mesh4::default();
        mesh.push_vertices(self.surface, &at);
        let (vertex_of, offsets) = (&vertex_of, &offsets);
        let faces: Vec<([u32; 3], usize, [usize; 3])> = self
            .patches
            .iter()
            .enumerate()
            .flat_map(|(patch, p)| {
                p.cdt.inner_faces().map(move |f| {
                    let local = f.vertices().map(|v| v.fix().index());
                    (local.map(|i| vertex_of[offsets[patch] + i]), patch, local)
                })
            })
            .collect();
        // A counting sort by the smallest vertex, in the patches' order within one.
        let first = |t: &[u32; 3]| t[0].min(t[1]).min(t[2]) as usize;
        let mut next = vec![0usize; at.len() + 1];
        for (t, _, _) in &faces {
            next[first(t) + 1] += 1;
        }
        for v in 0..at.len() {
            next[v + 1] += next[v];
        }
        let mut sorted = vec![0u32; faces.len()];
        for (k, (t, _, _)) in faces.iter().enumerate() {
            sorted[next[first(t)]] = k as u32;
            next[first(t)] += 1;
        }
        for k in sorted {
            let (t, patch, local) = faces[k as usize];
            let p = &self.patches[patch];
            mesh.push_triangle(t, p.of, local.map(|i| p.uv(p.st[i])));
        }
        mesh
    }
}

/// The place of `st` (in [0, 1]^2) along a Z curve (Morton order) of the unit square, 32
/// bits per coordinate.
fn z_order(st: [f64; 2]) -> u64 {
    let spread = |x: f64| {
        let mut x = u64::from((x.clamp(0.0, 1.0) * f64::from(u32::MAX)) as u32);
        x = (x | x << 16) & 0x0000_FFFF_0000_FFFF;
        x = (x | x << 8) & 0x00FF_00FF_00FF_00FF;
        x = (x | x << 4) & 0x0F0F_0F0F_0F0F_0F0F;
        x = (x | x << 2) & 0x3333_3333_3333_3333;
        (x | x << 1) & 0x5555_5555_5555_5555
    };
    spread(st[0]) | spread(st[1]) << 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_glue_back_to_where_they_came_from() {
        // Every catalogue surface cut into tiles: at least TILES of them, their rectangles
        // covering each patch exactly, and every glued piece of a tile's side mapping its
        // points onto a side of another tile whose own glue maps them back, the ends of
        // each piece included.
        for surface in Surface::catalogue() {
            let fine = 1e-5 * crate::sample::bounding_diagonal(&surface);
            assert_eq!(
                tiles(&surface, 1e3 * fine, usize::MAX).len(),
                surface.patch_count()
            );
            assert_eq!(tiles(&surface, fine, 1000).len(), surface.patch_count());
            let tiles = tiles(&surface, fine, usize::MAX);
            let name = surface.type_name();
            assert!(tiles.len() >= TILES, "{name}: {} tiles", tiles.len());
            let k = tiles[0].k;
            assert_eq!(tiles.len(), surface.patch_count() * k * k, "{name}");
            for (n, tile) in tiles.iter().enumerate() {
                let domain = surface.domain(tile.of);
                let [i, j] = tile.corner;
                assert_eq!(n, (tile.of * k + j) * k + i, "{name}");
                if i == 0 {
                    assert_eq!(tile.domain.u[0], domain.u[0], "{name}");
                }
                if i + 1 == k {
                    assert_eq!(tile.domain.u[1], domain.u[1], "{name}");
                } else {
                    assert_eq!(tile.domain.u[1], tiles[n + 1].domain.u[0], "{name}");
                }
                for side in Side::ALL {
                    let SideRule::Glued(pieces) = tile.domain.side(side) else {
                        continue;
                    };
                    for g in pieces {
                        for sigma in [g.from, (g.from + g.to) / 2.0, g.to] {
                            let image = g.map(sigma);
                            assert!((0.0..=1.0).contains(&image), "{name}: {image}");
                            let back: Vec<_> = glued_images(&tiles[g.patch].domain, g.side, image)
                                .into_iter()
                                .filter(|&(t, s, x)| t == n && s == side && x == sigma)
                                .collect();
                            assert_eq!(back.len(), 1, "{name}: tile {n} {side:?} at {sigma}");
                        }
                    }
                }
            }
        }
    }
}
