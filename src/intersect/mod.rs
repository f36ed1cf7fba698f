//! The exact self-intersection curves of projected surfaces, with over and under.
//!
//! Takes: sheets (projected surfaces: 3D positions, w-depth, triangles), all of a scene
//! together, so curves between surfaces are found as well as self-intersections. Gives:
//! [`Curves`], polylines whose vertices are *events*, "edge e crosses triangle f", each
//! carrying the w-depth of both sheets there.
//!
//! - Broad phase: an obvhs BVH over the triangles' boxes, traversed against itself
//!   (`broad`).
//! - Narrow phase: exact `robust::orient3d` under Simulation of Simplicity (`sos`), so
//!   coplanar overlaps, vertices exactly on triangles and edges through edges are decided
//!   consistently rather than skipped (`exact`). Triangles sharing an edge never cross;
//!   triangles sharing a vertex cross only along a segment that ends at that vertex, which
//!   is how a curve ends at a cross-cap (a branch point of the projection).
//! - Chaining by shared events, without a distance tolerance (`chain.rs`): closed curves
//!   close, open ones end at a mesh boundary or a branch point.
//!
//! Only the coordinates of the points are rounded; every decision is exact. What the
//! perturbation decided is counted (`perturbed`, `coplanar` in [`CurvesReport`]), as is
//! anything that could not be resolved.

pub(crate) mod broad;
pub mod certified;
mod chain;
pub(crate) mod exact;
pub(crate) mod refine;
pub(crate) mod sos;

use crate::progress::Cancel;
pub use exact::Node;
use exact::{Pair, Segment, Soup};
use glam::DVec3;
use obvhs::aabb::Aabb;
use rayon::prelude::*;
pub use refine::{Analytic, CurveSettings, Refinement, refine};
use serde::Serialize;
use std::time::Instant;

/// One projected surface.
#[derive(Clone, Copy, Debug)]
pub struct Sheet<'a> {
    /// Vertex positions in 3D.
    pub positions: &'a [DVec3],
    /// w-depth of each vertex (smaller is nearer).
    pub w: &'a [f64],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
}

/// A triangle of one of the sheets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Face {
    /// Index of the sheet (surface) in the input.
    pub surface: u32,
    /// Triangle index in that sheet.
    pub triangle: u32,
}

/// A vertex of a curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// Where it is.
    pub position: DVec3,
    /// Where the mesh's curve has it: `position` for the mesh's own curves; for refined
    /// ones, the mesh point it was moved from, on both sheets' triangles (the picture
    /// decides there what hides the curve, so that a point moved off the mesh by its error
    /// is not hidden by its own sheets).
    pub on_mesh: DVec3,
    /// w-depth of the curve's two sheets here, labelled consistently along the curve.
    pub w: [f64; 2],
    /// A triangle of each sheet that contains the point.
    pub faces: [Face; 2],
    /// The event, in global indices (vertices and triangles of all sheets in order).
    pub node: Node,
    /// The event's edge lies in its face's plane (a coplanar overlap decided by the
    /// perturbation; the point is placed in the middle of the overlap).
    pub coplanar: bool,
    /// A vertex of the event's edge lies exactly in its face's plane: the perturbation
    /// decided which side it is on.
    pub perturbed: bool,
}

impl CurvePoint {
    /// Which sheet (0 or 1) is nearer in w here (0 on a tie).
    pub fn near(&self) -> usize {
        usize::from(self.w[1] < self.w[0])
    }

    /// w of the far sheet minus w of the near sheet (>= 0).
    pub fn dw(&self) -> f64 {
        (self.w[0] - self.w[1]).abs()
    }
}

/// A point where three sheets cross.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriplePoint {
    /// Where it is.
    pub position: DVec3,
    /// w-depth of the three sheets here.
    pub w: [f64; 3],
    /// A triangle of each sheet that contains the point.
    pub faces: [Face; 3],
}

/// How an open curve ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum End {
    /// The curve is closed.
    Closed,
    /// At a boundary edge of a mesh.
    Boundary,
    /// At a mesh vertex where the projection folds (a cross-cap) or where several curves meet
    /// at a singular point of the projection.
    BranchPoint,
    /// Where an edge crosses a triangle in more than two segments; counted as unresolved.
    Branch,
}

/// A self-intersection curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Its vertices in order; a closed curve returns from the last to the first.
    pub points: Vec<CurvePoint>,
    /// Whether it closes.
    pub closed: bool,
    /// How it ends at its first and last point.
    pub ends: [End; 2],
}

/// Which pairs of triangles reach the exact tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BroadPhase {
    /// Pairs whose boxes touch, from the BVH.
    #[default]
    Bvh,
    /// Every pair (for testing the BVH; quadratic).
    AllPairs,
}

/// `report.json`'s `curves`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CurvesReport {
    /// Curves.
    pub count: usize,
    /// Closed curves.
    pub closed: usize,
    /// Open curves.
    pub open: usize,
    /// Curve vertices (events).
    pub points: usize,
    /// Open-curve ends at a mesh boundary.
    pub boundary_ends: usize,
    /// Open-curve ends at a branch point: a mesh vertex where the projection is singular
    /// (a cross-cap, or where several curves meet).
    pub branch_point_ends: usize,
    /// Points where three sheets cross.
    pub triple_points: usize,
    /// Events whose edge lies in the plane of its face (coplanar overlaps).
    pub coplanar: usize,
    /// Events with a vertex exactly on the other triangle's plane, decided by the
    /// perturbation.
    pub perturbed: usize,
    /// What could not be resolved: crossings where more than two segments meet, curves ending
    /// at an edge that is not a boundary, and triangle pairs whose predicates disagreed.
    pub unresolved: usize,
    /// Triangles, all sheets.
    pub triangles: usize,
    /// Triangles naming one vertex twice, left out (they have no interior to cross).
    pub degenerate_triangles: usize,
    /// Triangle pairs the broad phase passed on.
    pub candidate_pairs: usize,
    /// Crossing triangle pairs (curve segments).
    pub segments: usize,
    /// Milliseconds in all.
    pub ms: f64,
    /// Of which merging the sheets, computing boxes and planes and building the BVH.
    pub bvh_ms: f64,
    /// Traversing it with the exact tests of the pairs it finds, on the cores (wall clock).
    pub traverse_ms: f64,
    /// The exact tests, summed over the cores (more than `traverse_ms` on several cores).
    pub exact_ms: f64,
    /// Placing, chaining and counting.
    pub chain_ms: f64,
    /// What moving the points onto the analytic surfaces did ([`refine()`](fn@refine)), when it ran.
    #[serde(flatten)]
    pub refinement: Option<Refinement>,
    /// The double curves certified on the true surfaces ([`certified::certify`]), when the
    /// scene asks (`curves.certify`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certified: Option<certified::Certificate>,
    /// The rounds in which the build sampled the surfaces again, finer around the certified
    /// curves, for the meshes' curves to count as the certificate's (0: none needed).
    #[serde(skip_serializing_if = "is_zero")]
    pub sampled_finer: usize,
}

/// Whether a count is 0 (left out of `report.json`).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl CurvesReport {
    /// The verdict of a build and of `halo4d check DIR` on the curves the halos are
    /// verified against: nothing unresolved.
    pub fn failures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.unresolved > 0 {
            out.push(format!(
                "curves: {} unresolved (more than two segments meet at a point)",
                self.unresolved
            ));
        }
        if let Some(c) = self
            .certified
            .as_ref()
            .filter(|c| c.complete && (c.closed, c.open) != (self.closed, self.open))
        {
            let through = c
                .components
                .iter()
                .find_map(|k| k.points.first())
                .map(|p| {
                    format!(
                        " (a certified curve passes through ({:.6}, {:.6}, {:.6}))",
                        p[0], p[1], p[2]
                    )
                })
                .unwrap_or_default();
            let tried = match self.sampled_finer {
                0 => String::new(),
                n => format!(", after {n} rounds of sampling finer around the certified curves"),
            };
            out.push(format!(
                "curves: the true surfaces cross in {} closed and {} open curves (certified), the meshes in {} closed and {} open{tried}: sample finer where they differ{through}",
                c.closed, c.open, self.closed, self.open
            ));
        }
        out
    }

    /// The summary `halo4d build` and `halo4d check DIR` print: one line, and one more on
    /// the refinement when it ran.
    pub fn summary(&self) -> String {
        let mut out = format!(
            "curves: {} ({} closed, {} open), {} points, {} triple points, {} unresolved",
            self.count, self.closed, self.open, self.points, self.triple_points, self.unresolved
        );
        if let Some(c) = &self.certified {
            out += &format!("\ncurves certified: {}", c.summary());
            if self.sampled_finer > 0 {
                out += &format!(
                    "\ncurves held to the certificate: the surfaces sampled finer around the certified curves in {} rounds",
                    self.sampled_finer
                );
            }
        }
        if let Some(r) = &self.refinement {
            out += &format!(
                "\ncurves refined onto the surfaces: {} points ({} cross-caps, {} trimmed beyond them), {} not converged, {} pole ends kept; max residual {:.1e}, max shift {:.1e}; triple points {} refined, {} not",
                r.refined,
                r.cross_caps,
                r.trimmed,
                r.not_converged,
                r.pole_ends,
                r.max_residual,
                r.max_shift,
                r.triple_points_refined,
                r.triple_points_not_converged
            );
            if r.on_meshes > 0 {
                out += &format!(
                    "; {} points on mesh files kept (the mesh is the surface)",
                    r.on_meshes
                );
            }
        }
        out
    }
}

/// The curves and what they cost.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curves {
    /// The curves.
    pub curves: Vec<Curve>,
    /// Where three sheets cross.
    pub triple_points: Vec<TriplePoint>,
    /// Counts and timings.
    pub report: CurvesReport,
}

impl Curves {
    /// The line segments of the curves as pairs of indices into their points, numbered curve
    /// after curve: consecutive points, and for a closed curve the last back to the first.
    pub fn segments(&self) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        let mut base = 0u32;
        for c in &self.curves {
            let n = c.points.len() as u32;
            out.extend((1..n).map(|k| [base + k - 1, base + k]));
            if c.closed && n > 1 {
                out.push([base + n - 1, base]);
            }
            base += n;
        }
        out
    }
}

/// The intersection curves of `sheets`, with the BVH broad phase.
pub fn curves(sheets: &[Sheet]) -> Curves {
    curves_with(sheets, BroadPhase::Bvh)
}

/// [`curves`], stopping once `cancel` is cancelled (with no curve, which the caller drops).
pub fn curves_until(sheets: &[Sheet], cancel: &Cancel) -> Curves {
    curves_of(sheets, BroadPhase::Bvh, cancel)
}

/// The intersection curves of `sheets`, with the given broad phase.
pub fn curves_with(sheets: &[Sheet], broad_phase: BroadPhase) -> Curves {
    curves_of(sheets, broad_phase, Cancel::never())
}

fn curves_of(sheets: &[Sheet], broad_phase: BroadPhase, cancel: &Cancel) -> Curves {
    let start = Instant::now();
    let mut report = CurvesReport::default();
    let (mut soup, tri_start) = merge(sheets);
    soup.prepare();
    report.triangles = soup.tris.len();
    report.degenerate_triangles = soup.tris.iter().filter(|t| !proper(t)).count();

    // Candidate pairs go to the exact tests as the broad phase finds them, on the cores,
    // each task keeping only the segments: the memory they take is bounded however many
    // candidates there are (slivers and many-twist knots give thousands per triangle). The
    // tasks' results are joined in the order a descent on one core finds them, so the curves
    // do not depend on the number of threads.
    let found = match broad_phase {
        BroadPhase::Bvh => bvh_segments(&soup, start, &mut report, cancel),
        BroadPhase::AllPairs => all_pairs_segments(&soup),
    };
    if cancel.is_cancelled() {
        return Curves::default();
    }
    let Found {
        candidates,
        segments,
        inconsistent,
        exact_ms,
        ..
    } = found;
    report.candidate_pairs = candidates;
    report.unresolved += inconsistent;
    report.exact_ms = exact_ms;
    report.segments = segments.len();

    let t = Instant::now();
    let face = |g: u32| {
        let surface = tri_start.partition_point(|&s| s <= g) - 1;
        Face {
            surface: surface as u32,
            triangle: g - tri_start[surface],
        }
    };
    let (curves, branches) = chain::chain(&soup, &segments, face);
    report.unresolved += branches;
    count_curves(&curves, &soup, &mut report);
    let triple_points = triple_points(&soup, &segments, face);
    report.triple_points = triple_points.len();
    report.chain_ms = ms(t);
    report.ms = ms(start);
    Curves {
        curves,
        triple_points,
        report,
    }
}

/// Whether a triangle has three distinct vertices (a degenerate one touches nothing).
fn proper(t: &[u32; 3]) -> bool {
    t[0] != t[1] && t[1] != t[2] && t[2] != t[0]
}

/// The segments of the pairs of triangles whose boxes touch, found with a BVH over runs of
/// neighbouring triangles: within each run, then across the runs whose boxes touch. Puts
/// the time since `start` to build the BVH and the time to traverse it in the report.
fn bvh_segments(soup: &Soup, start: Instant, report: &mut CurvesReport, cancel: &Cancel) -> Found {
    let boxes: Vec<_> = soup
        .tris
        .iter()
        .map(|t| {
            if !proper(t) {
                // Touches nothing.
                return Aabb::INVALID;
            }
            let p = t.map(|v| soup.positions[v as usize]);
            broad::outward(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
        })
        .collect();
    let groups = groups(&soup.tris);
    let group_boxes: Vec<_> = groups
        .windows(2)
        .map(|g| {
            boxes[g[0] as usize..g[1] as usize]
                .iter()
                .fold(Aabb::INVALID, |u, b| u.union(b))
        })
        .collect();
    let bvh = broad::build(&group_boxes, 2);
    report.bvh_ms = ms(start);
    let t = Instant::now();
    let test = |found: &mut Found, a: u32, b: u32| {
        if !cancel.is_cancelled() && boxes[a as usize].intersect_aabb(&boxes[b as usize]) {
            found.push(soup, a.min(b), a.max(b));
        }
    };
    // Neighbours within a run of triangles, then the runs whose boxes touch.
    let within: Vec<Found> = groups
        .par_windows(2)
        .chunks(GROUPS_PER_TASK)
        .map(|chunk| {
            let mut found = Found::default();
            for g in chunk {
                for a in g[0]..g[1] {
                    for b in a + 1..g[1] {
                        test(&mut found, a, b);
                    }
                }
            }
            found
        })
        .collect();
    let across = broad::self_pairs_par(&bvh, &group_boxes, Found::default, |found, ga, gb| {
        for a in groups[ga as usize]..groups[ga as usize + 1] {
            for b in groups[gb as usize]..groups[gb as usize + 1] {
                test(found, a, b);
            }
        }
    });
    let found = Found::join(soup, within.into_iter().chain(across).collect());
    report.traverse_ms = ms(t);
    found
}

/// The segments of every pair of proper triangles, each tested exactly (a reference for
/// the BVH).
fn all_pairs_segments(soup: &Soup) -> Found {
    let ok: Vec<u32> = (0..soup.tris.len() as u32)
        .filter(|&t| proper(&soup.tris[t as usize]))
        .collect();
    let rows: Vec<Found> = (0..ok.len())
        .into_par_iter()
        .map(|i| {
            let mut found = Found::default();
            for &b in &ok[i + 1..] {
                found.push(soup, ok[i], b);
            }
            found
        })
        .collect();
    Found::join(soup, rows)
}

/// Counts the curves, their points and their ends in the report: closed and open curves,
/// ends on a mesh boundary or at a branch point, and ends that should be on a boundary but
/// are not (unresolved).
fn count_curves(curves: &[Curve], soup: &Soup, report: &mut CurvesReport) {
    let boundary = curves
        .iter()
        .any(|c| c.ends.contains(&End::Boundary))
        .then(|| BoundaryEdges::new(soup));
    for c in curves {
        report.points += c.points.len();
        for p in &c.points {
            report.coplanar += usize::from(p.coplanar);
            report.perturbed += usize::from(p.perturbed);
        }
        if c.closed {
            report.closed += 1;
            continue;
        }
        report.open += 1;
        for (end, point) in c
            .ends
            .iter()
            .zip([&c.points[0], &c.points[c.points.len() - 1]])
        {
            match *end {
                End::Boundary => {
                    if let Node::Crossing { edge, .. } = point.node
                        && boundary.as_ref().is_some_and(|b| b.contains(edge))
                    {
                        report.boundary_ends += 1;
                    } else {
                        report.unresolved += 1;
                    }
                }
                End::BranchPoint => report.branch_point_ends += 1,
                End::Branch | End::Closed => {}
            }
        }
    }
    report.count = curves.len();
}

/// Runs of triangles one task of the exact tests within runs takes.
const GROUPS_PER_TASK: usize = 4096;

/// What the exact tests of some candidate pairs found, in the order of the pairs. Pairs wait
/// in a small batch so that the tests are timed a batch at a time, not a pair at a time.
#[derive(Default)]
struct Found {
    batch: Vec<(u32, u32)>,
    candidates: usize,
    segments: Vec<Segment>,
    /// Pairs whose predicates disagreed.
    inconsistent: usize,
    /// Milliseconds in the tests.
    exact_ms: f64,
}

impl Found {
    /// Candidate pairs held before they are tested.
    const BATCH: usize = 1024;

    /// Triangles `a` and `b` of `soup` to be tested.
    fn push(&mut self, soup: &Soup, a: u32, b: u32) {
        self.batch.push((a, b));
        if self.batch.len() == Self::BATCH {
            self.flush(soup);
        }
    }

    /// The exact tests of the pairs waiting.
    fn flush(&mut self, soup: &Soup) {
        let t = Instant::now();
        self.candidates += self.batch.len();
        for &(a, b) in &self.batch {
            match soup.pair(a, b) {
                Pair::Apart => {}
                Pair::Cross(s) => self.segments.push(s),
                Pair::Inconsistent(..) => self.inconsistent += 1,
            }
        }
        self.batch.clear();
        self.exact_ms += ms(t);
    }

    /// The findings of consecutive runs of pairs, in order, every pair tested (the pairs
    /// still waiting in each, on the cores).
    fn join(soup: &Soup, mut parts: Vec<Found>) -> Found {
        parts.par_iter_mut().for_each(|f| f.flush(soup));
        parts.into_iter().fold(Found::default(), |mut all, f| {
            all.candidates += f.candidates;
            all.segments.extend(f.segments);
            all.inconsistent += f.inconsistent;
            all.exact_ms += f.exact_ms;
            all
        })
    }
}

/// Runs of up to four consecutive triangles that share a vertex with the run's first (as
/// samplers emit them, a quad's two triangles together), as the starts of the runs and the
/// end. The BVH is built over runs: a quarter of the primitives, and neighbours inside a
/// run need no traversal.
fn groups(tris: &[[u32; 3]]) -> Vec<u32> {
    let mut starts = Vec::with_capacity(tris.len() / 2 + 1);
    let mut i = 0;
    while i < tris.len() {
        starts.push(i as u32);
        let (start, first) = (i, tris[i]);
        i += 1;
        while i < tris.len() && i - start < 4 && tris[i].iter().any(|v| first.contains(v)) {
            i += 1;
        }
    }
    starts.push(tris.len() as u32);
    starts
}

/// All sheets in one soup with global indices, and the first global triangle of each sheet.
fn merge(sheets: &[Sheet]) -> (Soup, Vec<u32>) {
    let mut soup = Soup::default();
    let mut tri_start = Vec::with_capacity(sheets.len());
    for s in sheets {
        let base = soup.positions.len() as u32;
        tri_start.push(soup.tris.len() as u32);
        soup.positions.extend_from_slice(s.positions);
        soup.w.extend_from_slice(s.w);
        soup.tris
            .extend(s.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    (soup, tri_start)
}

/// The edges with one triangle.
struct BoundaryEdges(Vec<[u32; 2]>);

impl BoundaryEdges {
    fn new(soup: &Soup) -> Self {
        let mut edges: Vec<[u32; 2]> = soup
            .tris
            .iter()
            .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
            .collect();
        edges.sort_unstable();
        let mut single = Vec::new();
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] == edges[i] {
                j += 1;
            }
            if j - i == 1 {
                single.push(edges[i]);
            }
            i = j;
        }
        BoundaryEdges(single)
    }

    fn contains(&self, edge: [u32; 2]) -> bool {
        self.0.binary_search(&edge).is_ok()
    }
}

/// Triple points: in a triangle A crossed by B and by C, the segments A∩B and A∩C cross
/// where the ends of each lie on opposite sides of the other's plane. Found once, in the
/// triple's smallest triangle, and placed where A∩B crosses C's plane. The ends are
/// constructed points, and one can lie exactly in the other's plane where sheets meet in
/// symmetry (in the `two-surfaces` fixture a segment of one pair lies in the third sheet's
/// plane, its ends on that plane or off it by rounding alone, depending on the vertices'
/// numbering). An end on the plane counts as on its positive side, as if moved off it
/// along the normal by an infinitesimal, the same for every segment ending at that node: a
/// curve crossing the plane there is counted once, one touching it twice or not at all,
/// and a segment in the plane crosses nothing. Triangles of a triple that share a vertex,
/// or lie in one plane, are one sheet, and no triple point.
fn triple_points(
    soup: &Soup,
    segments: &[Segment],
    face: impl Fn(u32) -> Face,
) -> Vec<TriplePoint> {
    let places: Vec<[DVec3; 2]> = segments
        .iter()
        .map(|s| s.ends.map(|n| soup.place(n).position))
        .collect();
    let mut by_tri: Vec<(u32, u32, u32)> = segments
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            [
                (s.tris[0], s.tris[1], i as u32),
                (s.tris[1], s.tris[0], i as u32),
            ]
        })
        .collect();
    by_tri.sort_unstable();
    let side = |tri: u32, p: DVec3| {
        let f = soup.tris[tri as usize].map(|v| soup.positions[v as usize]);
        sos::orient3d(f[0], f[1], f[2], p)
    };
    let separated =
        |tri: u32, ends: [DVec3; 2]| (side(tri, ends[0]) >= 0.0) != (side(tri, ends[1]) >= 0.0);
    // Triangles that share a vertex are one sheet there, not two.
    let touch = |x: u32, y: u32| {
        let (tx, ty) = (soup.tris[x as usize], soup.tris[y as usize]);
        tx.iter().any(|v| ty.contains(v))
    };
    // Two triangles in one plane (of one flat sheet) are one sheet too.
    let coplanar = |x: u32, y: u32| {
        let f = soup.tris[x as usize].map(|v| soup.positions[v as usize]);
        soup.tris[y as usize]
            .iter()
            .all(|&v| sos::orient3d(f[0], f[1], f[2], soup.positions[v as usize]) == 0.0)
    };
    let mut triples = Vec::new();
    let mut i = 0;
    while i < by_tri.len() {
        let mut j = i;
        while j < by_tri.len() && by_tri[j].0 == by_tri[i].0 {
            j += 1;
        }
        let a = by_tri[i].0;
        for x in i..j {
            for y in x + 1..j {
                let ((_, b, sb), (_, c, sc)) = (by_tri[x], by_tri[y]);
                if b == c
                    || a > b
                    || a > c
                    || touch(b, c)
                    || touch(a, b)
                    || touch(a, c)
                    || coplanar(b, c)
                {
                    continue;
                }
                if separated(c, places[sb as usize]) && separated(b, places[sc as usize]) {
                    let [p, q] = places[sb as usize];
                    let (sp, sq) = (side(c, p), side(c, q));
                    let x = p + (q - p) * (sp / (sp - sq));
                    let w = [a, b, c].map(|t| {
                        let f = soup.tris[t as usize];
                        let l = exact::barycentric(x, f.map(|v| soup.positions[v as usize]));
                        (0..3).map(|k| l[k] * soup.w[f[k] as usize]).sum()
                    });
                    triples.push(TriplePoint {
                        position: x,
                        w,
                        faces: [a, b, c].map(&face),
                    });
                }
            }
        }
        i = j;
    }
    triples
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Reproducible numbers in [0, 1) for the unit tests (a 64-bit LCG).
#[cfg(test)]
pub(crate) fn lcg(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}
