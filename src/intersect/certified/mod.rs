//! Double curves certified on the true surfaces, not on their meshes: what the projections
//! of the analytic surfaces do, proven by interval arithmetic, and what could not be
//! decided, named.
//!
//! The double points of the projection f = P∘S of the surfaces are the pairs of parameter
//! points (p, q), on one surface or two, with f(p) = f(q) and p, q not the same point of
//! the surface. Every pair of boxes of parameters is examined, from each patch's rectangle
//! down (a box is cut at `far::SPLIT` of its extent, not in the middle, so that symmetric
//! points do not fall on the cuts):
//!
//! - boxes whose images (enclosed with [`Surface::enclose`]) do not meet hold no double
//!   point;
//! - boxes of one surface that touch (in the patch, across a glued side or corner, or
//!   around a pole) are proven free of double points by divided differences (`near`), or
//!   cut again;
//! - other boxes are decided by `far`: no double point, or exactly the arcs it finds, or
//!   cut again.
//!
//! The arcs are then joined into components (`graph`), each closed, or open with both ends
//! on the surfaces' boundary. Branch points (cross-caps, where the double curve ends) are
//! proven one by one in the boxes of one surface where the rank of Df may drop, and shown
//! absent in all others. A pair of boxes still undecided at the last depth (a tangency of
//! two sheets, the neighbourhood of a cross-cap, a point on a box's edge) is a region the
//! certificate names with its parameters and why, and its counts are then not claimed
//! (`complete` is false). Triple points are not certified here: the field says so.
//!
//! Everything runs on the cores level by level, each level's pairs in order, so that the
//! result does not depend on the number of threads.

mod far;
mod graph;
mod near;
mod system;

pub use graph::{Component, ComponentKind, SheetBox};

use crate::progress::Cancel;
use crate::surfaces::{Interval, Surface};
use crate::view::View;
use near::{Near, Poles, Rect};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;
use system::{I, Projector};

/// `report.json`'s `curves.certified`: the double curves of the true surfaces.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Certificate {
    /// Whether everything was decided: the counts of components and branch points are
    /// proven. False when a region is undecided (`regions`) or a component runs into one.
    pub complete: bool,
    /// Closed components of double curve.
    pub closed: usize,
    /// Open components: both ends on an open side of a patch (a surface's boundary).
    pub open: usize,
    /// Components with an end in an undecided region (not counted as closed or open).
    pub unfinished: usize,
    /// Branch points (cross-caps), each proven the only one in its box, when every other
    /// box is proven to have none; `null` otherwise.
    pub branch_points: Option<usize>,
    /// Branch points proven, whether or not all are.
    pub branch_points_proven: usize,
    /// Triple points: not certified by this version (`null`).
    pub triple_points: Option<usize>,
    /// Undecided regions, in all.
    pub undecided: usize,
    /// The first of them (at most 16), with their parameters and why.
    pub regions: Vec<Region>,
    /// Pairs of boxes examined.
    pub box_pairs: usize,
    /// Arcs proven (one per box a curve crosses).
    pub arcs: usize,
    /// Enclosures of the surfaces computed.
    pub enclosures: usize,
    /// Milliseconds.
    pub ms: f64,
    /// The components, with their points (for the library and the tests).
    #[serde(skip)]
    pub components: Vec<Component>,
    /// The branch points proven, each the only one in its box of parameters.
    pub branch_point_list: Vec<ProvenPoint>,
}

/// A point proven: where it is on its surface and in 3D.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProvenPoint {
    /// The surface (its index in the scene).
    pub surface: usize,
    /// The patch.
    pub patch: usize,
    /// Its parameters (the middle of their enclosure, on the patch by the glue rule).
    pub uv: [f64; 2],
    /// Its 3D point (the middle of its enclosure).
    pub position: [f64; 3],
    /// The widest of its enclosures (parameters and point).
    pub width: f64,
}

impl Certificate {
    /// One line for `halo4d build` and `halo4d check`.
    pub fn summary(&self) -> String {
        let branch = match self.branch_points {
            Some(n) => format!("{n} branch points"),
            None => format!(
                "{} branch points proven, others not excluded",
                self.branch_points_proven
            ),
        };
        let head = format!(
            "{} closed, {} open, {} unfinished; {branch}; triple points not certified; {} box pairs, {:.0} ms",
            self.closed, self.open, self.unfinished, self.box_pairs, self.ms
        );
        match self.regions.first() {
            None if self.complete => format!("complete: {head}"),
            None => format!("not complete: {head}"),
            Some(r) => format!(
                "not complete: {head}; {} regions undecided, the first: {r}",
                self.undecided
            ),
        }
    }
}

/// A region of pairs of parameter points the certificate did not decide.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Region {
    /// The two surfaces (their indices in the scene).
    pub surfaces: [usize; 2],
    /// Their patches.
    pub patches: [usize; 2],
    /// The first point's (u, v) ranges.
    pub p: [[f64; 2]; 2],
    /// The second point's.
    pub q: [[f64; 2]; 2],
    /// Why it is undecided.
    pub reason: Reason,
}

/// Why a region is undecided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reason {
    /// The two sheets may be tangent there (their normals' enclosures are parallel).
    Tangency,
    /// Around a proven branch point, where the double curve ends: its path there is not
    /// certified.
    BranchPoint,
    /// The rank of Df may drop there, and no branch point was proven.
    RankDrop,
    /// A double point on an edge of the boxes, or too many in one box, at the last depth.
    Edge,
    /// The last depth was reached with the sheets' Jacobian not shown regular.
    Depth,
    /// The work budget ran out.
    Budget,
    /// A surface read from a mesh file: it has no parametrization to certify.
    Mesh,
}

impl std::fmt::Display for Reason {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            Reason::Tangency => "a tangency: the two sheets may touch without crossing",
            Reason::BranchPoint => "the neighbourhood of a branch point (cross-cap)",
            Reason::RankDrop => "the projection's rank may drop (no branch point proven)",
            Reason::Edge => "a double point on an edge of the boxes at the last depth",
            Reason::Depth => "the last depth, the sheets' Jacobian not shown regular",
            Reason::Budget => "the work budget ran out",
            Reason::Mesh => "a surface read from a mesh file (no parametrization)",
        })
    }
}

impl std::fmt::Display for Region {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let r = |x: [f64; 2]| format!("[{:.6}, {:.6}]", x[0], x[1]);
        write!(
            f,
            "{} at surface {} patch {} (u {}, v {}) against surface {} patch {} (u {}, v {})",
            self.reason,
            self.surfaces[0],
            self.patches[0],
            r(self.p[0]),
            r(self.p[1]),
            self.surfaces[1],
            self.patches[1],
            r(self.q[0]),
            r(self.q[1]),
        )
    }
}

/// Depth of the first pairs (each patch cut into 4 × 4 boxes).
const START: usize = 2;

/// The last depth of boxes of one surface that touch (a cross-cap's neighbourhood).
const NEAR_DEPTH: usize = 14;

/// The last depth of other boxes.
const FAR_DEPTH: usize = 26;

/// Enclosures at most, all levels together, checked between levels (4 to 16 s on two
/// cores, by the surface).
pub const BUDGET: usize = 1_500_000;

/// Pairs of boxes waiting at one level, at most (their memory).
const PENDING: usize = 400_000;

/// Regions listed in the report at most.
const LISTED: usize = 16;

/// A box of one of the certificate's surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    surface: usize,
    rect: Rect,
}

impl Piece {
    /// Its four boxes, cut at [`far::SPLIT`] (the first pieces).
    fn children(&self) -> Vec<Piece> {
        self.cut([true, true])
    }

    /// Its boxes cut across u, v or both (`along`), at [`far::SPLIT`].
    fn cut(&self, along: [bool; 2]) -> Vec<Piece> {
        let halves = |x: I, cut: bool| {
            if !cut {
                return vec![x];
            }
            let c = x.lo() + (x.hi() - x.lo()) * far::SPLIT;
            vec![I::new(x.lo(), c), I::new(c, x.hi())]
        };
        let mut out = Vec::with_capacity(4);
        for u in halves(self.rect.u, along[0]) {
            for v in halves(self.rect.v, along[1]) {
                out.push(Piece {
                    surface: self.surface,
                    rect: Rect {
                        patch: self.rect.patch,
                        u,
                        v,
                    },
                });
            }
        }
        out
    }

    /// Its boxes one level down: cut across the parameter along which its image is the
    /// longer (both when neither is twice the other), so that a parametrization that
    /// stretches one way gets boxes of about equal sides in 3D.
    fn split(&self, image: &system::Image) -> Vec<Piece> {
        let reach = |d: &system::V3, w: f64| d.iter().fold(0.0f64, |m, c| m.max(c.mag())) * w;
        let (lu, lv) = (
            reach(&image.du, self.rect.u.width()),
            reach(&image.dv, self.rect.v.width()),
        );
        // Unbounded derivatives (a branch point) say nothing: cut both.
        if !(lu.is_finite() && lv.is_finite()) {
            return self.children();
        }
        self.cut([lu * 2.0 > lv, lv * 2.0 > lu])
    }
}

/// What became of a pair of boxes at one level.
enum Step {
    /// No double point.
    Free,
    /// These arcs, all of them.
    Arcs(Vec<graph::Arc>),
    /// Cut into these pairs.
    Cut(Vec<(Piece, Piece)>),
    /// Left undecided.
    Undecided(Reason),
}

/// The surfaces, each seen through the view.
struct Setting<'a> {
    projectors: Vec<Option<Projector<'a>>>,
    poles: Vec<Option<Poles>>,
}

/// The pairs of `a`'s and `b`'s boxes one level down (a pair of one box with itself gives
/// each unordered pair of its boxes once), from their images.
fn cut(a: &Piece, ia: &system::Image, b: &Piece, ib: &system::Image) -> Vec<(Piece, Piece)> {
    let (ca, cb) = (a.split(ia), b.split(ib));
    let mut out = Vec::with_capacity(ca.len() * cb.len());
    for (i, x) in ca.iter().enumerate() {
        for (j, y) in cb.iter().enumerate() {
            if a != b || i <= j {
                out.push((*x, *y));
            }
        }
    }
    out
}

/// The first-order test of a pair: in the direction n of f(a's centre) - f(b's centre),
/// n·G over the boxes lies in n·G(c) + Σ (n·∂G/∂x_k)(x_k - c_k) (the mean-value theorem); when
/// that excludes 0 the boxes hold no double point. It decides what the images' boxes do
/// not where the surface runs slanted to the axes.
fn apart(
    pa: &Projector,
    a: &Rect,
    ia: &system::Image,
    pb: &Projector,
    b: &Rect,
    ib: &system::Image,
) -> bool {
    let ca = pa.image(a.patch, I::point(a.u.mid()), I::point(a.v.mid()));
    let cb = pb.image(b.patch, I::point(b.u.mid()), I::point(b.v.mid()));
    let g = system::sub(ca.p, cb.p);
    let n = g.map(I::mid);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return false;
    }
    let n = n.map(|c| I::point(c / len));
    let dot = |x: &system::V3| x[0] * n[0] + x[1] * n[1] + x[2] * n[2];
    let off = |x: I| x - I::point(x.mid());
    let value = dot(&g) + dot(&ia.du) * off(a.u) + dot(&ia.dv) * off(a.v)
        - dot(&ib.du) * off(b.u)
        - dot(&ib.dv) * off(b.v);
    !value.contains(0.0)
}

impl Setting<'_> {
    fn projector(&self, p: &Piece) -> &Projector<'_> {
        self.projectors[p.surface]
            .as_ref()
            .expect("pieces only of parametric surfaces")
    }

    /// One pair at one level; `work` counts the enclosures computed.
    fn step(&self, a: &Piece, b: &Piece, depth: usize, work: &mut usize) -> Step {
        let (pa, pb) = (self.projector(a), self.projector(b));
        let ia = pa.image(a.rect.patch, a.rect.u, a.rect.v);
        let ib = pb.image(b.rect.patch, b.rect.u, b.rect.v);
        *work += 2;
        if !(0..3).all(|k| ia.p[k].meets(ib.p[k])) {
            return Step::Free;
        }
        *work += 2;
        if apart(pa, &a.rect, &ia, pb, &b.rect, &ib) {
            return Step::Free;
        }
        if a.surface == b.surface {
            let poles = self.poles[a.surface]
                .as_ref()
                .expect("poles of each surface");
            match near::near(pa, &a.rect, &b.rect, poles) {
                Near::Free => return Step::Free,
                Near::Unsure if depth < NEAR_DEPTH => return Step::Cut(cut(a, &ia, b, &ib)),
                Near::Unsure => return Step::Undecided(Reason::RankDrop),
                Near::Apart => {}
            }
        }
        let pair = far::Pair {
            a: pa,
            pa: a.rect.patch,
            b: pb,
            pb: b.rect.patch,
        };
        let x = [a.rect.u, a.rect.v, b.rect.u, b.rect.v];
        match far::arcs(&pair, x, &ia, &ib, work) {
            far::Outcome::Empty => Step::Free,
            far::Outcome::Arcs(arcs) => Step::Arcs(
                arcs.into_iter()
                    .map(|ends| graph::Arc {
                        surfaces: [a.surface, b.surface],
                        patches: [a.rect.patch, b.rect.patch],
                        ends,
                    })
                    .collect(),
            ),
            far::Outcome::Split(_) if depth < FAR_DEPTH => Step::Cut(cut(a, &ia, b, &ib)),
            far::Outcome::Split(why) => {
                let normals = (system::cross(ia.du, ia.dv), system::cross(ib.du, ib.dv));
                if !system::nonzero(&system::cross(normals.0, normals.1)) {
                    Step::Undecided(Reason::Tangency)
                } else if why == far::Why::Face {
                    Step::Undecided(Reason::Edge)
                } else {
                    Step::Undecided(Reason::Depth)
                }
            }
        }
    }
}

/// Certifies the double curves of `surfaces` (in the scene's order; `None` for a mesh read
/// from a file) seen through `view` (see the module documentation).
pub fn certify(surfaces: &[Option<&Surface>], view: &View) -> Certificate {
    certify_within(surfaces, view, BUDGET)
}

/// [`certify`], stopping at its next level of boxes once `cancel` is cancelled (with a
/// certificate that decides nothing more, which the caller drops).
pub fn certify_until(surfaces: &[Option<&Surface>], view: &View, cancel: &Cancel) -> Certificate {
    certify_of(surfaces, view, BUDGET, cancel)
}

/// [`certify`] within `budget` enclosures of the surfaces (and 400,000 pairs of boxes
/// waiting at a level): what is left when either runs out is undecided (`budget`).
pub fn certify_within(surfaces: &[Option<&Surface>], view: &View, budget: usize) -> Certificate {
    certify_of(surfaces, view, budget, Cancel::never())
}

fn certify_of(
    surfaces: &[Option<&Surface>],
    view: &View,
    budget: usize,
    cancel: &Cancel,
) -> Certificate {
    let start = Instant::now();
    let setting = Setting {
        projectors: surfaces
            .iter()
            .map(|s| s.map(|s| Projector::new(s, view)))
            .collect(),
        poles: surfaces.iter().map(|s| s.map(Poles::new)).collect(),
    };
    let (pending, mesh_regions) = first_pairs(surfaces);
    let Levels {
        arcs,
        mut undecided,
        box_pairs,
        work,
    } = setting.levels(pending, budget, cancel);
    let (branch, all_branch_points) = setting.branch_points(&mut undecided);
    let projectors: Vec<&Projector> = setting.projectors.iter().flatten().collect();
    let index: Vec<usize> = (0..surfaces.len())
        .map(|s| surfaces[..s].iter().filter(|x| x.is_some()).count())
        .collect();
    let local: Vec<graph::Arc> = arcs
        .iter()
        .map(|a: &graph::Arc| graph::Arc {
            surfaces: a.surfaces.map(|s| index[s]),
            ..*a
        })
        .collect();
    let components = graph::components(&local, &projectors);
    let count = |k: ComponentKind| components.iter().filter(|c| c.kind == k).count();
    let mut regions: Vec<Region> = mesh_regions;
    undecided.sort_by_key(|x| x.2);
    let total = regions.len() + undecided.len();
    regions.extend(undecided.iter().take(LISTED).map(|(a, b, reason)| {
        let range = |x: Interval| [x.lo(), x.hi()];
        Region {
            surfaces: [a.surface, b.surface],
            patches: [a.rect.patch, b.rect.patch],
            p: [range(a.rect.u), range(a.rect.v)],
            q: [range(b.rect.u), range(b.rect.v)],
            reason: *reason,
        }
    }));
    regions.truncate(LISTED);
    let unfinished = count(ComponentKind::Unfinished);
    Certificate {
        complete: total == 0 && unfinished == 0 && all_branch_points,
        closed: count(ComponentKind::Closed),
        open: count(ComponentKind::Open),
        unfinished,
        branch_points: all_branch_points.then_some(branch.len()),
        branch_points_proven: branch.len(),
        triple_points: None,
        undecided: total,
        regions,
        box_pairs,
        arcs: arcs.len(),
        enclosures: work,
        ms: start.elapsed().as_secs_f64() * 1e3,
        components,
        branch_point_list: branch.iter().map(|(s, b)| setting.proven(*s, b)).collect(),
    }
}

/// Every pair of the first boxes of the parametric surfaces, and a region for each surface
/// read from a mesh file.
fn first_pairs(surfaces: &[Option<&Surface>]) -> (Vec<(Piece, Piece)>, Vec<Region>) {
    let mut mesh_regions = Vec::new();
    let mut pieces = Vec::new();
    for (s, surface) in surfaces.iter().enumerate() {
        let Some(surface) = surface else {
            mesh_regions.push(Region {
                surfaces: [s, s],
                patches: [0, 0],
                p: [[0.0; 2]; 2],
                q: [[0.0; 2]; 2],
                reason: Reason::Mesh,
            });
            continue;
        };
        for patch in 0..surface.patch_count() {
            let d = surface.domain(patch);
            let mut level = vec![Piece {
                surface: s,
                rect: Rect {
                    patch,
                    u: I::new(d.u[0], d.u[1]),
                    v: I::new(d.v[0], d.v[1]),
                },
            }];
            for _ in 0..START {
                level = level.iter().flat_map(Piece::children).collect();
            }
            pieces.extend(level);
        }
    }
    let mut pending = Vec::new();
    for i in 0..pieces.len() {
        for j in i..pieces.len() {
            pending.push((pieces[i], pieces[j]));
        }
    }
    (pending, mesh_regions)
}

/// What the levels of pairs found.
struct Levels {
    arcs: Vec<graph::Arc>,
    undecided: Vec<(Piece, Piece, Reason)>,
    box_pairs: usize,
    work: usize,
}

impl Setting<'_> {
    /// The pairs level by level, each level's on the cores and taken in order, until none
    /// is left or the budget runs out.
    fn levels(&self, mut pending: Vec<(Piece, Piece)>, budget: usize, cancel: &Cancel) -> Levels {
        let mut out = Levels {
            arcs: Vec::new(),
            undecided: Vec::new(),
            box_pairs: 0,
            work: 0,
        };
        let mut depth = START;
        while !pending.is_empty() {
            if out.work > budget || pending.len() > PENDING || cancel.is_cancelled() {
                let left = pending.drain(..).map(|(a, b)| (a, b, Reason::Budget));
                out.undecided.extend(left);
                break;
            }
            out.box_pairs += pending.len();
            let steps: Vec<(Step, usize)> = pending
                .par_iter()
                .with_min_len(4)
                .map(|(a, b)| {
                    let mut w = 0;
                    if cancel.is_cancelled() {
                        return (Step::Free, w);
                    }
                    let s = self.step(a, b, depth, &mut w);
                    (s, w)
                })
                .collect();
            let mut next = Vec::new();
            for ((a, b), (step, w)) in pending.iter().zip(steps) {
                out.work += w;
                match step {
                    Step::Free => {}
                    Step::Arcs(found) => out.arcs.extend(found),
                    Step::Cut(pairs) => next.extend(pairs),
                    Step::Undecided(reason) => out.undecided.push((*a, *b, reason)),
                }
            }
            pending = next;
            depth += 1;
        }
        out
    }

    /// The branch points proven in the boxes of one surface left undecided with themselves,
    /// and whether every such box has one or none (no count is claimed otherwise, nor when
    /// the budget ran out); the undecided regions around one say so.
    fn branch_points(
        &self,
        undecided: &mut [(Piece, Piece, Reason)],
    ) -> (Vec<(usize, near::BranchPoint)>, bool) {
        let selves: Vec<Piece> = undecided
            .iter()
            .filter(|(a, b, r)| a == b && *r == Reason::RankDrop)
            .map(|(a, _, _)| *a)
            .collect();
        let found: Vec<(bool, Option<near::BranchPoint>)> = selves
            .par_iter()
            .map(|a| {
                let proj = self.projector(a);
                (
                    near::regular_box(proj, &a.rect),
                    near::branch_point(proj, &a.rect),
                )
            })
            .collect();
        let mut branch: Vec<(usize, near::BranchPoint)> = Vec::new();
        let mut all = !undecided.iter().any(|(_, _, r)| *r == Reason::Budget);
        for (a, (regular, point)) in selves.iter().zip(&found) {
            match point {
                Some(bp) => {
                    // The same cross-cap proven from two boxes (in two frames of the
                    // patch's continued chart, across a seam): one point of R^3, enclosed
                    // to rounding.
                    let known = branch.iter().any(|(s, k)| {
                        *s == a.surface && (0..3).all(|c| k.point[c].meets(bp.point[c]))
                    });
                    if !known {
                        branch.push((a.surface, *bp));
                    }
                }
                None if *regular => {}
                None => all = false,
            }
        }
        let around = |p: &Piece| {
            branch.iter().any(|(s, bp)| {
                *s == p.surface
                    && bp.patch == p.rect.patch
                    && bp.unique.u.meets(p.rect.u)
                    && bp.unique.v.meets(p.rect.v)
            })
        };
        for (a, b, reason) in undecided.iter_mut() {
            if *reason == Reason::RankDrop && (around(a) || around(b)) {
                *reason = Reason::BranchPoint;
            }
        }
        (branch, all)
    }

    /// A proven branch point of surface `s` as the report gives it.
    fn proven(&self, s: usize, b: &near::BranchPoint) -> ProvenPoint {
        let surface = self.projectors[s].as_ref().expect("parametric").surface;
        let (patch, u, v, _) = surface.chart(b.patch, b.u.mid(), b.v.mid());
        let width = b
            .point
            .iter()
            .fold(b.u.width().max(b.v.width()), |w, c| w.max(c.width()));
        ProvenPoint {
            surface: s,
            patch,
            uv: [u, v],
            position: b.point.map(I::mid),
            width,
        }
    }
}
