//! Halo verification: the intersection curves are the ground truth the halos must explain.
//!
//! Takes: [`Parts`]: the sheets (projected surfaces), their halos (tetrahedra with t and
//! d_orig, in the layout of [`crate::check`]) and the curves of [`crate::intersect`]. Gives:
//! [`Verification`], counts of samples classified as below. A point x of a sheet at depth w
//! is *hidden* when it lies in a halo tetrahedron (exact `orient3d`, boundary included;
//! found by an obvhs query over the tetrahedra) whose halo depth there (paper 000 eq. 3,
//! evaluated after interpolating t and d_orig at x) is smaller than w. A sheet's own halo
//! around x does not count: tetrahedra of the same surface over a vertex of x's triangle
//! (the prisms of the triangles that share a vertex with it; a conforming halo covers the
//! surface near x with those alone).
//!
//! - Along every curve (at each event and each segment's midpoint) the sheet farther in w
//!   must be hidden by the halo of the nearer sheet, and the nearer sheet must not be hidden
//!   by the farther's (`correct`; `third_sheet` where a third sheet's halo also hides the
//!   nearer one, near triple points). A sample the halos do not explain is `wrong` unless a
//!   reason excuses it as `ambiguous`, the first that applies in the order of
//!   [`Ambiguous`]: within [`BRANCH_REACH`](crate::limits::BRANCH_REACH) halo widths of a curve's end at a branch point
//!   or at a boundary, where the nearer sheet's halo vanished at a corner of its triangle,
//!   or where the mesh does not separate the sheets. The reaches are geometry (the halo's
//!   width), not the mesh's size, so the verdict does not depend on the resolution.
//! - Away from the curves: no point of a sheet may be hidden by a tetrahedron farther than
//!   rho from the surface points it was built over (`spurious`, counted at every surface
//!   vertex and triangle centroid). Checked per tetrahedron corner (`far_tetrahedra`),
//!   which covers every point of the halo; only the tetrahedra that fail are searched.
//!
//! Linear in the input: no index over all tetrahedra is built; the curve samples see only
//! the tetrahedra whose boxes hold one.

use crate::intersect::broad;
use crate::intersect::{Curves, End, Face, Sheet};
use crate::parts::{HaloIndex, HaloPart, Parts, inserted_sets, tet_box};
use crate::progress::Cancel;
use glam::DVec3;
use obvhs::aabb::Aabb;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// `report.json`'s `halo_verification`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Verification {
    /// Samples along the curves (events and segment midpoints).
    pub curve_samples: usize,
    /// Far sheet hidden by the near sheet's halo, near sheet not hidden.
    pub correct: usize,
    /// Far sheet not hidden by the near sheet's halo, or near sheet hidden by the far's,
    /// where nothing below excuses it.
    pub wrong: usize,
    /// Samples the halos do not explain, within [`BRANCH_REACH`](crate::limits::BRANCH_REACH) halo widths of a curve's
    /// end at a branch point or a boundary, where the nearer sheet's halo vanished, or
    /// where the mesh does not separate the two sheets.
    pub ambiguous: usize,
    /// The ambiguous samples by reason.
    pub ambiguous_reasons: Ambiguous,
    /// The farthest that a sample excused as `branch_point` or `boundary` lies from the
    /// curve end that excuses it, in halo widths rho (at most [`BRANCH_REACH`](crate::limits::BRANCH_REACH); 0 when
    /// there is none): how far from the ends the halos fail to explain the curves.
    pub ambiguous_reach: f64,
    /// The near sheet hidden by a third sheet's halo (near triple points).
    pub third_sheet: usize,
    /// Samples away from the curves: surface vertices and triangle centroids.
    pub surface_samples: usize,
    /// Halo tetrahedra reaching farther than rho from the surface points they were built
    /// over; only these can hide a surface sample spuriously, and only these are searched.
    pub far_tetrahedra: usize,
    /// Surface samples hidden by such a tetrahedron where no sheet is within rho.
    pub spurious_hidden_samples: usize,
    /// Where the first wrong curve samples are (up to 8 distinct points: events that
    /// symbolic perturbation tells apart can share one point, as where the flat torus's
    /// curves pass through mesh vertices).
    pub wrong_at: Vec<[f64; 3]>,
    /// Where the first spurious samples are (up to 8 distinct points).
    pub spurious_at: Vec<[f64; 3]>,
    /// Milliseconds.
    pub ms: f64,
}

/// Why curve samples the halos do not explain are ambiguous, one reason per sample (the
/// first that applies, in the order of the fields).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Ambiguous {
    /// Within [`BRANCH_REACH`](crate::limits::BRANCH_REACH) halo widths of a curve's end at a branch point (a cross-cap),
    /// where the two sheets are one surface folded over and the halo must vanish.
    pub branch_point: usize,
    /// Within [`BRANCH_REACH`](crate::limits::BRANCH_REACH) halo widths of a curve's end at a mesh boundary, where the
    /// nearer sheet's halo ends in a side wall.
    pub boundary: usize,
    /// The nearer sheet's halo has zero width at a corner of its triangle (collapsed where
    /// the projection is singular or folds tighter than any halo fits).
    pub vanished_halo: usize,
    /// The mesh does not separate the sheets there: their triangles are within two rings of
    /// each other on one surface, or their w differ by no more than w varies across the
    /// triangles. Only coarse meshes leave such samples; refining removes them.
    pub resolution: usize,
}

impl Verification {
    /// The verdict of a build and of `halo4d check DIR`: what the halos do not explain (a
    /// wrong curve sample, a spuriously hidden surface sample), empty when they explain
    /// everything.
    pub fn failures(&self) -> Vec<String> {
        let first = |at: &[[f64; 3]]| {
            at.first()
                .map(|p| format!(" (the first at ({:.6}, {:.6}, {:.6}))", p[0], p[1], p[2]))
                .unwrap_or_default()
        };
        let mut out = Vec::new();
        if self.wrong > 0 {
            out.push(format!(
                "halo verification: {} of {} curve samples wrong{}",
                self.wrong,
                self.curve_samples,
                first(&self.wrong_at)
            ));
        }
        if self.spurious_hidden_samples > 0 {
            out.push(format!(
                "halo verification: {} of {} surface samples spuriously hidden{}",
                self.spurious_hidden_samples,
                self.surface_samples,
                first(&self.spurious_at)
            ));
        }
        out
    }

    /// The counts as rows (name, count), the reasons of the ambiguous ones indented, in
    /// the order `halo4d check DIR` prints them.
    pub fn rows(&self) -> [(&'static str, usize); 12] {
        let r = &self.ambiguous_reasons;
        [
            ("curve_samples", self.curve_samples),
            ("correct", self.correct),
            ("wrong", self.wrong),
            ("ambiguous", self.ambiguous),
            ("  branch_point", r.branch_point),
            ("  boundary", r.boundary),
            ("  vanished_halo", r.vanished_halo),
            ("  resolution", r.resolution),
            ("third_sheet", self.third_sheet),
            ("surface_samples", self.surface_samples),
            ("far_tetrahedra", self.far_tetrahedra),
            ("spurious_hidden_samples", self.spurious_hidden_samples),
        ]
    }

    /// Adds `other`'s counts, and its examples after this one's.
    fn add(mut self, other: Verification) -> Verification {
        self.curve_samples += other.curve_samples;
        self.correct += other.correct;
        self.wrong += other.wrong;
        self.ambiguous += other.ambiguous;
        let (a, b) = (&mut self.ambiguous_reasons, &other.ambiguous_reasons);
        a.branch_point += b.branch_point;
        a.boundary += b.boundary;
        a.vanished_halo += b.vanished_halo;
        a.resolution += b.resolution;
        self.ambiguous_reach = self.ambiguous_reach.max(other.ambiguous_reach);
        self.third_sheet += other.third_sheet;
        self.surface_samples += other.surface_samples;
        self.spurious_hidden_samples += other.spurious_hidden_samples;
        for (to, from) in [
            (&mut self.wrong_at, other.wrong_at),
            (&mut self.spurious_at, other.spurious_at),
        ] {
            for x in from {
                example(to, x);
            }
        }
        self
    }
}

/// Verifies `halos` (one per sheet, `None` for a sheet without one) against `curves`.
///
/// Linear in the input: the curve samples are tested against the tetrahedra of the prisms
/// whose boxes hold a curve sample, found by one pass over the triangles; the surface
/// samples only against the tetrahedra that reach farther than rho from their sheet
/// (none, in a sound halo), because a tetrahedron whose corners are all within rho of the
/// surface points it is built over lies within rho of them everywhere (the distance to a
/// convex set is convex).
pub fn verify(parts: &Parts) -> Verification {
    verify_until(parts, Cancel::never())
}

/// [`verify`], stopping once `cancel` is cancelled (with partial counts, which the caller
/// drops).
pub fn verify_until(parts: &Parts, cancel: &Cancel) -> Verification {
    let start = Instant::now();
    let sheets = &parts.sheets();
    let (halos, curves) = (&parts.halos, parts.curves);
    let scale = sheets
        .iter()
        .flat_map(|s| s.positions.iter())
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tolerance = 1e-6 * scale.max(f64::MIN_POSITIVE);
    let samples = curve_samples(curves);
    let points: Vec<DVec3> = samples.iter().map(|s| s.x).collect();
    let index = Index::new(sheets, halos, curves, &points);
    let mut out = samples
        .par_iter()
        .fold(Verification::default, |mut v, s| {
            if !cancel.is_cancelled() {
                index.classify_curve_sample(s, &mut v);
            }
            v
        })
        .reduce(Verification::default, Verification::add);

    let far = far_tetrahedra(sheets, halos, tolerance);
    out.far_tetrahedra = far.iter().map(Vec::len).sum();
    out.surface_samples = sheets
        .iter()
        .map(|s| s.triangles.len() + used_vertices(s).count())
        .sum();
    if out.far_tetrahedra > 0 && !cancel.is_cancelled() {
        let far_index = HaloIndex::with(halos, |s, i| far[s].binary_search(&i).is_ok());
        let surface = surface_samples(sheets)
            .par_iter()
            .fold(Verification::default, |mut v, &(x, w, face)| {
                if !cancel.is_cancelled() {
                    index.classify_surface_sample(&far_index, x, w, face, tolerance, &mut v);
                }
                v
            })
            .reduce(Verification::default, Verification::add);
        out.spurious_hidden_samples = surface.spurious_hidden_samples;
        out.spurious_at = surface.spurious_at;
    }
    out.ms = start.elapsed().as_secs_f64() * 1e3;
    out
}

/// Each curve's events and the midpoints of its segments.
fn curve_samples(curves: &Curves) -> Vec<CurveSample> {
    let mut out = Vec::new();
    for c in &curves.curves {
        let n = c.points.len();
        let segments = if c.closed { n } else { n.saturating_sub(1) };
        for (k, p) in c.points.iter().enumerate() {
            out.push(CurveSample {
                x: p.position,
                w: p.w,
                faces: p.faces,
            });
            if k < segments {
                let q = &c.points[(k + 1) % n];
                out.push(CurveSample {
                    x: (p.position + q.position) * 0.5,
                    w: [(p.w[0] + q.w[0]) * 0.5, (p.w[1] + q.w[1]) * 0.5],
                    faces: p.faces,
                });
            }
        }
    }
    out
}

/// The vertices some triangle of `sheet` uses, each once, with the first triangle that
/// has it.
fn used_vertices<'a>(sheet: &'a Sheet) -> impl Iterator<Item = (u32, u32)> + 'a {
    let mut seen = vec![false; sheet.positions.len()];
    sheet
        .triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| tri.map(|v| (v, t as u32)))
        .filter(move |&(v, _)| !std::mem::replace(&mut seen[v as usize], true))
}

/// Every triangle centroid and used vertex of every sheet, with its depth and triangle.
fn surface_samples(sheets: &[Sheet]) -> Vec<(DVec3, f64, Face)> {
    let mut out = Vec::new();
    for (s, sheet) in sheets.iter().enumerate() {
        let face = |t: u32| Face {
            surface: s as u32,
            triangle: t,
        };
        for (t, tri) in sheet.triangles.iter().enumerate() {
            let p = tri.map(|v| sheet.positions[v as usize]);
            let w = tri.map(|v| sheet.w[v as usize]);
            let centroid = (p[0] + p[1] + p[2]) / 3.0;
            out.push((centroid, (w[0] + w[1] + w[2]) / 3.0, face(t as u32)));
        }
        for (v, t) in used_vertices(sheet) {
            out.push((sheet.positions[v as usize], sheet.w[v as usize], face(t)));
        }
    }
    out
}

/// Per surface, the tetrahedra (sorted) with a corner farther from the surface points it
/// stands for than the largest half-width rho among them, plus `tolerance`. An offset
/// vertex stands for its own surface point, an inserted vertex for the surface points of
/// the tetrahedra around it (measured to their hull). Every point of any other
/// tetrahedron is within its rho of the hull of the surface points it is built over.
fn far_tetrahedra(sheets: &[Sheet], halos: &[Option<HaloPart>], tolerance: f64) -> Vec<Vec<u32>> {
    sheets
        .iter()
        .zip(halos)
        .map(|(sheet, halo)| {
            let Some(h) = halo else { return Vec::new() };
            let n = h.surface_vertices;
            let inserted = inserted_sets(h);
            // Per halo vertex: (distance to what it stands for, largest rho there).
            let reach: Vec<(f64, f64)> = (0..h.positions.len())
                .into_par_iter()
                .map(|k| {
                    if k < 3 * n {
                        let v = k % n;
                        (
                            (h.positions[k] - sheet.positions[v]).length(),
                            h.half_width(v),
                        )
                    } else {
                        let set = &inserted[k - 3 * n];
                        let points: Vec<DVec3> =
                            set.iter().map(|&v| sheet.positions[v as usize]).collect();
                        let rho = set
                            .iter()
                            .map(|&v| h.half_width(v as usize))
                            .fold(0.0, f64::max);
                        (distance_to_hull(h.positions[k], &points), rho)
                    }
                })
                .collect();
            h.tets
                .par_iter()
                .enumerate()
                .filter(|(_, tet)| {
                    let (d, rho) = tet.iter().fold((0.0f64, 0.0f64), |(d, rho), &k| {
                        let r = reach[k as usize];
                        (d.max(r.0), rho.max(r.1))
                    });
                    d > rho + tolerance
                })
                .map(|(i, _)| i as u32)
                .collect()
        })
        .collect()
}

const EXAMPLES: usize = 8;

/// Adds `x` to a list of examples unless it is full or has `x` already.
fn example(list: &mut Vec<[f64; 3]>, x: [f64; 3]) {
    if list.len() < EXAMPLES && !list.contains(&x) {
        list.push(x);
    }
}

struct CurveSample {
    x: DVec3,
    w: [f64; 2],
    faces: [Face; 2],
}

/// What the classification needs of each surface, with the halos' index.
struct Index<'a> {
    sheets: &'a [Sheet<'a>],
    /// The tetrahedra whose boxes hold a curve sample.
    halos: HaloIndex<'a>,
    /// Per surface: the triangles around each vertex (CSR).
    vertex_tris: Vec<(Vec<u32>, Vec<u32>)>,
    /// Per surface: its halo's largest half-width rho (0 without a halo).
    rho: Vec<f64>,
    /// Where curves end at a branch point.
    branch_points: Vec<DVec3>,
    /// Where curves end at a mesh boundary.
    boundary_ends: Vec<DVec3>,
}

impl<'a> Index<'a> {
    /// The index for the curve samples at `points`.
    fn new(
        sheets: &'a [Sheet<'a>],
        halos: &'a [Option<HaloPart<'a>>],
        curves: &Curves,
        points: &[DVec3],
    ) -> Self {
        let boxes: Vec<Aabb> = points.iter().map(|&x| broad::outward(x, x)).collect();
        let samples = broad::build(&boxes, 4);
        // Whether the box of tetrahedron i of surface s holds a curve sample.
        let near_curve = |s: usize, i: u32| {
            let aabb = tet_box(halos[s].as_ref().expect("a tetrahedron of a halo"), i);
            let mut found = false;
            samples.aabb_traverse(aabb, |bvh, node| {
                let node = &bvh.nodes[node as usize];
                let first = node.first_index as usize;
                found = bvh.primitive_indices[first..first + node.prim_count as usize]
                    .iter()
                    .any(|&k| aabb.contains_point(boxes[k as usize].min));
                !found
            });
            found
        };
        let rho = halos
            .iter()
            .map(|h| {
                h.as_ref().map_or(0.0, |h| {
                    (0..h.surface_vertices)
                        .into_par_iter()
                        .map(|v| h.half_width(v))
                        .reduce(|| 0.0, f64::max)
                })
            })
            .collect();
        let ends = |kind: End| {
            curves
                .curves
                .iter()
                .flat_map(|c| [(c.ends[0], c.points.first()), (c.ends[1], c.points.last())])
                .filter_map(|(end, p)| p.filter(|_| end == kind).map(|p| p.position))
                .collect()
        };
        Index {
            sheets,
            halos: HaloIndex::with(halos, near_curve),
            vertex_tris: sheets.iter().map(vertex_triangles).collect(),
            rho,
            branch_points: ends(End::BranchPoint),
            boundary_ends: ends(End::Boundary),
        }
    }

    /// The vertices of `face`: a tetrahedron over one of them belongs to the halo of a
    /// triangle that shares a vertex with `face`.
    fn vertices(&self, face: Face) -> [u32; 3] {
        self.sheets[face.surface as usize].triangles[face.triangle as usize]
    }

    /// Whether `other` has a vertex on a triangle around a vertex of `face` (both on one
    /// surface): the two are within two rings of each other.
    fn close(&self, face: Face, other: Face) -> bool {
        if face.surface != other.surface {
            return false;
        }
        let s = face.surface as usize;
        let (starts, tris) = &self.vertex_tris[s];
        let sheet = &self.sheets[s];
        let theirs = sheet.triangles[other.triangle as usize];
        sheet.triangles[face.triangle as usize].iter().any(|&v| {
            tris[starts[v as usize] as usize..starts[v as usize + 1] as usize]
                .iter()
                .any(|&t| {
                    sheet.triangles[t as usize]
                        .iter()
                        .any(|k| theirs.contains(k))
                })
        })
    }

    /// Classifies a curve sample: by the halos first, then, where they do not explain it,
    /// by the first reason that excuses it ([`Ambiguous`]), else `wrong`.
    fn classify_curve_sample(&self, s: &CurveSample, v: &mut Verification) {
        v.curve_samples += 1;
        let near = usize::from(s.w[1] < s.w[0]);
        let far = 1 - near;
        let (fn_, ff) = (s.faces[near], s.faces[far]);
        let (ring_near, ring_far) = (self.vertices(fn_), self.vertices(ff));
        let halos = &self.halos;
        // One search answers both sheets: the far sheet is hidden by the near sheet's halo
        // (not its own) where the depth is below its w, the near sheet by any halo but its
        // own where the depth is below its (smaller) w.
        let containing = halos.containing(s.x);
        let far_hidden = containing.iter().any(|&(g, depth)| {
            depth < s.w[far]
                && !halos.within(g, ff.surface, &ring_far)
                && halos.within(g, fn_.surface, &ring_near)
        });
        let near_hiders: Vec<u32> = containing
            .iter()
            .filter(|&&(g, depth)| depth < s.w[near] && !halos.within(g, fn_.surface, &ring_near))
            .map(|&(g, _)| g)
            .collect();
        let by_far = near_hiders
            .iter()
            .any(|&g| halos.within(g, ff.surface, &ring_far));
        if far_hidden && !by_far {
            if near_hiders.is_empty() {
                v.correct += 1;
            } else {
                v.third_sheet += 1;
            }
            return;
        }
        let rho = self.rho[fn_.surface as usize];
        // Whether the sample is within reach of one of `ends`; if so, how far in rho.
        let mut within = |ends: &[DVec3]| {
            let nearest = ends
                .iter()
                .map(|e| e.distance(s.x))
                .fold(f64::INFINITY, f64::min);
            let inside = nearest <= crate::limits::BRANCH_REACH * rho;
            if inside && rho > 0.0 {
                v.ambiguous_reach = v.ambiguous_reach.max(nearest / rho);
            }
            inside
        };
        let spread = |f: Face| {
            let sheet = &self.sheets[f.surface as usize];
            let w = sheet.triangles[f.triangle as usize].map(|k| sheet.w[k as usize]);
            w[0].max(w[1]).max(w[2]) - w[0].min(w[1]).min(w[2])
        };
        let reason = if within(&self.branch_points) {
            &mut v.ambiguous_reasons.branch_point
        } else if within(&self.boundary_ends) {
            &mut v.ambiguous_reasons.boundary
        } else if halos.vanishes(fn_.surface, &ring_near) {
            &mut v.ambiguous_reasons.vanished_halo
        } else if self.close(fn_, ff) || s.w[far] - s.w[near] <= spread(fn_).max(spread(ff)) {
            &mut v.ambiguous_reasons.resolution
        } else {
            v.wrong += 1;
            example(&mut v.wrong_at, s.x.to_array());
            return;
        };
        *reason += 1;
        v.ambiguous += 1;
    }

    /// Classifies a surface sample against `far`, the tetrahedra that reach farther than
    /// rho from their sheet: spurious where one of them hides it and no sheet is near.
    fn classify_surface_sample(
        &self,
        far: &HaloIndex,
        x: DVec3,
        w: f64,
        face: Face,
        tolerance: f64,
        v: &mut Verification,
    ) {
        let ring = self.vertices(face);
        let spurious = far.hiders(x, w, (face.surface, &ring)).iter().any(|h| {
            let surface = far.tets[h.0 as usize].0 as usize;
            let sheet = &self.sheets[surface];
            let halo = far.halos[surface].as_ref().expect("tet of a halo");
            let rho = far
                .over(h.0)
                .map(|k| halo.half_width(k as usize))
                .fold(0.0, f64::max);
            let points: Vec<DVec3> = far.over(h.0).map(|k| sheet.positions[k as usize]).collect();
            distance_to_hull(x, &points) > rho + tolerance
        });
        if spurious {
            v.spurious_hidden_samples += 1;
            example(&mut v.spurious_at, x.to_array());
        }
    }
}

/// The triangles around each vertex, as CSR (starts, triangles).
fn vertex_triangles(sheet: &Sheet) -> (Vec<u32>, Vec<u32>) {
    let n = sheet.positions.len();
    let mut starts = vec![0u32; n + 1];
    for t in sheet.triangles {
        for &v in t {
            starts[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    let mut fill = starts.clone();
    let mut tris = vec![0u32; starts[n] as usize];
    for (i, t) in sheet.triangles.iter().enumerate() {
        for &v in t {
            tris[fill[v as usize] as usize] = i as u32;
            fill[v as usize] += 1;
        }
    }
    (starts, tris)
}

/// Distance from `x` to the convex hull of up to a few points, as the smallest distance to
/// the triangles, segments and points they span (exact for one to three points, an upper
/// bound for more).
fn distance_to_hull(x: DVec3, points: &[DVec3]) -> f64 {
    let mut best = f64::INFINITY;
    for (i, &a) in points.iter().enumerate() {
        best = best.min((x - a).length());
        for (j, &b) in points.iter().enumerate().skip(i + 1) {
            best = best.min(segment_distance(x, a, b));
            for &c in &points[j + 1..] {
                best = best.min(triangle_distance(x, a, b, c));
            }
        }
    }
    best
}

fn segment_distance(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((x - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (x - (a + ab * t)).length()
}

/// Distance from `x` to the triangle abc (to its edges where x projects outside it).
fn triangle_distance(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let n = (b - a).cross(c - a);
    let len2 = n.length_squared();
    let edges = segment_distance(x, a, b)
        .min(segment_distance(x, b, c))
        .min(segment_distance(x, c, a));
    if len2 == 0.0 {
        return edges;
    }
    let foot = x - n * ((x - a).dot(n) / len2);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(p, q)| (q - p).cross(foot - p).dot(n) >= 0.0);
    if inside { (x - foot).length() } else { edges }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::Sampling;
    use crate::scene::Scene;
    use std::collections::HashSet;

    /// The flat torus fixture on a 48 x 48 grid: its sheets, halos and curves.
    fn flat_torus() -> (crate::Built, Scene) {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/fixtures/scenes/flat-torus.json"
        );
        let mut scene = Scene::load(std::path::Path::new(path)).unwrap();
        scene.sampling = Sampling::Uniform { u: 48, v: 48 };
        (
            crate::Sampled::of(&scene)
                .into_built(&scene, crate::Stages::of(&scene))
                .unwrap(),
            scene,
        )
    }

    #[test]
    fn the_tetrahedra_near_the_curves_hold_every_curve_sample() {
        // Brute force: every tetrahedron of every halo that contains a curve sample (exact
        // orient3d, boundary included) is among those the curve samples are tested against.
        let (built, scene) = flat_torus();
        let parts = built.parts(&scene.halo);
        let (sheets, halos) = (parts.sheets(), parts.halos);
        let points: Vec<DVec3> = curve_samples(&built.curves).iter().map(|s| s.x).collect();
        let index = Index::new(&sheets, &halos, &built.curves, &points);
        let kept: HashSet<(u32, u32)> = index.halos.tets.iter().copied().collect();
        let all = HaloIndex::new(&halos);
        assert!(
            kept.len() * 10 < all.len(),
            "{} of {}",
            kept.len(),
            all.len()
        );
        let mut containing = 0;
        for &x in &points {
            for g in 0..all.len() as u32 {
                if all.depth_at(g, x).is_some() {
                    containing += 1;
                    assert!(kept.contains(&all.tets[g as usize]), "{x} in {g}");
                }
            }
        }
        assert!(containing > points.len(), "{containing}");
    }

    #[test]
    fn searching_only_the_far_tetrahedra_finds_every_spurious_sample() {
        // A sound halo has no far tetrahedron; moved off its surface, every spurious sample
        // that a search over all tetrahedra finds, the search over the far ones finds too.
        let (mut built, scene) = flat_torus();
        let scale = 1.0; // the flat torus's largest coordinate
        let parts = built.parts(&scene.halo);
        assert!(far_tetrahedra(&parts.sheets(), &parts.halos, 1e-6 * scale)[0].is_empty());
        drop(parts);
        let n = built.surfaces[0].mesh.positions.len();
        let halo = &mut built.surfaces[0].halo;
        for (k, p) in halo.positions.iter_mut().enumerate() {
            // The halo over a quarter of the surface moved 0.1 along z, and all of it made
            // shallow in w.
            if k % n < n / 4 {
                p.z += 0.1;
            }
        }
        for d in &mut halo.d_orig {
            *d -= 10.0;
        }
        let parts = built.parts(&scene.halo);
        let (sheets, halos) = (parts.sheets(), parts.halos);
        let far = far_tetrahedra(&sheets, &halos, 1e-6 * scale);
        assert!(!far[0].is_empty() && far[0].len() < halos[0].unwrap().tets.len());
        let points: Vec<DVec3> = Vec::new();
        let index = Index::new(&sheets, &halos, &built.curves, &points);
        let count = |search: &HaloIndex| {
            let mut v = Verification::default();
            for (x, w, face) in surface_samples(&sheets) {
                index.classify_surface_sample(search, x, w, face, 1e-6 * scale, &mut v);
            }
            v.spurious_hidden_samples
        };
        let all = count(&HaloIndex::new(&halos));
        let fast = count(&HaloIndex::with(&halos, |s, i| {
            far[s].binary_search(&i).is_ok()
        }));
        assert!(all > 0);
        assert_eq!(fast, all);
    }
}
