//! Halo verification: the intersection curves are the ground truth the halos must explain.
//!
//! Takes: the sheets (projected surfaces), their halos (tetrahedra with t and d_orig, in the
//! layout of [`crate::check`]) and the curves of [`crate::intersect`]. Gives:
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
//!   by the farther's (`correct`, else `wrong`). A sample is `ambiguous` where the two
//!   sheets' w differ by no more than w varies across their triangles there (what the mesh
//!   resolves), where the two triangles are within two rings of each other on one surface
//!   (a branch point, as at a cross-cap, where the halo must vanish), where the nearer
//!   sheet's triangle is on its mesh's boundary (where its halo ends in a side wall, whose
//!   split quads leave the boundary edge itself just inside or just outside), or where the
//!   nearer sheet's halo has zero width at a corner of its triangle (collapsed where the
//!   projection is singular or folds tighter than any halo fits: the halo vanishes there
//!   by construction, as at a cross-cap, and with all three corners collapsed the prism has
//!   no tetrahedron at all; such a sample is ambiguous only where the halo does not explain
//!   it, and correct where it does). Each ambiguous sample counts under its first
//!   reason in that order ([`Ambiguous`]). Where a
//!   third sheet's halo hides the nearer sheet (near triple points) the sample counts as
//!   `third_sheet`.
//! - Away from the curves: at every surface vertex and triangle centroid, a hidden point must
//!   be within rho of the sheet whose halo hides it (the distance to the surface points the
//!   tetrahedron was built over, against the largest half-width there); a point hidden with
//!   no such sheet near is `spurious`.

use crate::intersect::broad;
use crate::intersect::sos::orient3d;
use crate::intersect::{Curves, Face, Sheet};
use glam::DVec3;
use serde::Serialize;
use std::time::Instant;

/// A halo as the verification reads it.
#[derive(Clone, Copy, Debug)]
pub struct HaloInput<'a> {
    /// Vertex positions: offsets 0..n (t = 0), n..2n (t = 1), the surface 2n..3n (t = 1/2),
    /// inserted vertices after.
    pub positions: &'a [DVec3],
    /// t of each vertex.
    pub t: &'a [f64],
    /// d_orig of each vertex.
    pub d_orig: &'a [f64],
    /// Positively oriented tetrahedra.
    pub tets: &'a [[u32; 4]],
    /// Surface vertices n.
    pub surface_vertices: usize,
    /// Depth increment delta_d of eq. 3.
    pub delta_d: f64,
    /// Dead zone delta_t of eq. 3.
    pub delta_t: f64,
}

/// `report.json`'s `halo_verification`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Verification {
    /// Samples along the curves (events and segment midpoints).
    pub curve_samples: usize,
    /// Far sheet hidden by the near sheet's halo, near sheet not hidden.
    pub correct: usize,
    /// Far sheet not hidden by the near sheet's halo, or near sheet hidden by the far's.
    pub wrong: usize,
    /// The sheets' w differ by no more than the mesh resolves there, the sample is at a
    /// branch point or on the nearer sheet's boundary, or the nearer sheet's halo vanishes
    /// there.
    pub ambiguous: usize,
    /// The ambiguous samples by reason.
    pub ambiguous_reasons: Ambiguous,
    /// The near sheet hidden by a third sheet's halo (near triple points).
    pub third_sheet: usize,
    /// Samples away from the curves: surface vertices and triangle centroids.
    pub surface_samples: usize,
    /// Of those, hidden within rho of the sheet whose halo hides them.
    pub hidden_samples: usize,
    /// Of those, hidden where no sheet is within rho.
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

/// Why curve samples are ambiguous, one reason per sample (the first that applies, in the
/// order of the fields).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Ambiguous {
    /// The two triangles are within two rings of each other on one surface: a branch point
    /// (a cross-cap), where the halo must vanish.
    pub branch_point: usize,
    /// The nearer sheet's triangle is on its mesh's boundary, where its halo ends in a wall.
    pub boundary: usize,
    /// The sheets' w differ by no more than w varies across their triangles.
    pub resolution: usize,
    /// The halos do not explain the sample, and the nearer sheet's halo has zero width at a
    /// corner of its triangle (collapsed where the projection is singular or folds tighter
    /// than any halo fits).
    pub vanished_halo: usize,
}

impl Ambiguous {
    fn add(&mut self, other: &Ambiguous) {
        self.branch_point += other.branch_point;
        self.boundary += other.boundary;
        self.resolution += other.resolution;
        self.vanished_halo += other.vanished_halo;
    }
}

/// Verifies `halos` (one per sheet, `None` for a sheet without one) against `curves`.
pub fn verify(sheets: &[Sheet], halos: &[Option<HaloInput>], curves: &Curves) -> Verification {
    let start = Instant::now();
    let index = Index::new(sheets, halos);
    let scale = sheets
        .iter()
        .flat_map(|s| s.positions.iter())
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tolerance = 1e-6 * scale.max(f64::MIN_POSITIVE);

    let mut curve_samples: Vec<CurveSample> = Vec::new();
    for c in &curves.curves {
        let n = c.points.len();
        let segments = if c.closed { n } else { n.saturating_sub(1) };
        for (k, p) in c.points.iter().enumerate() {
            curve_samples.push(CurveSample {
                x: p.position,
                w: p.w,
                faces: p.faces,
            });
            if k < segments {
                let q = &c.points[(k + 1) % n];
                curve_samples.push(CurveSample {
                    x: (p.position + q.position) * 0.5,
                    w: [(p.w[0] + q.w[0]) * 0.5, (p.w[1] + q.w[1]) * 0.5],
                    faces: p.faces,
                });
            }
        }
    }
    let mut surface_samples: Vec<(DVec3, f64, Face)> = Vec::new();
    for (s, sheet) in sheets.iter().enumerate() {
        for (t, tri) in sheet.triangles.iter().enumerate() {
            let face = Face {
                surface: s as u32,
                triangle: t as u32,
            };
            let p = tri.map(|v| sheet.positions[v as usize]);
            let w = tri.map(|v| sheet.w[v as usize]);
            surface_samples.push(((p[0] + p[1] + p[2]) / 3.0, (w[0] + w[1] + w[2]) / 3.0, face));
        }
        // Each vertex once, with the first triangle that has it.
        let mut seen = vec![false; sheet.positions.len()];
        for (t, tri) in sheet.triangles.iter().enumerate() {
            for &v in tri {
                if !std::mem::replace(&mut seen[v as usize], true) {
                    let face = Face {
                        surface: s as u32,
                        triangle: t as u32,
                    };
                    surface_samples.push((sheet.positions[v as usize], sheet.w[v as usize], face));
                }
            }
        }
    }

    let mut out = parallel(&curve_samples, |chunk| {
        let mut v = Verification::default();
        for s in chunk {
            index.classify_curve_sample(s, &mut v);
        }
        v
    });
    let surface = parallel(&surface_samples, |chunk| {
        let mut v = Verification::default();
        for &(x, w, face) in chunk {
            index.classify_surface_sample(x, w, face, tolerance, &mut v);
        }
        v
    });
    out.surface_samples = surface.surface_samples;
    out.hidden_samples = surface.hidden_samples;
    out.spurious_hidden_samples = surface.spurious_hidden_samples;
    out.spurious_at = surface.spurious_at;
    out.ms = start.elapsed().as_secs_f64() * 1e3;
    out
}

/// Runs `f` on two halves of `items` on two threads and adds up the counts.
fn parallel<T: Sync>(items: &[T], f: impl Fn(&[T]) -> Verification + Sync) -> Verification {
    let mid = items.len() / 2;
    let (a, b) = std::thread::scope(|scope| {
        let first = scope.spawn(|| f(&items[..mid]));
        let second = f(&items[mid..]);
        (first.join().expect("verification thread"), second)
    });
    let mut v = a;
    v.curve_samples += b.curve_samples;
    v.correct += b.correct;
    v.wrong += b.wrong;
    v.ambiguous += b.ambiguous;
    v.ambiguous_reasons.add(&b.ambiguous_reasons);
    v.third_sheet += b.third_sheet;
    v.surface_samples += b.surface_samples;
    v.hidden_samples += b.hidden_samples;
    v.spurious_hidden_samples += b.spurious_hidden_samples;
    for (to, from) in [
        (&mut v.wrong_at, b.wrong_at),
        (&mut v.spurious_at, b.spurious_at),
    ] {
        for x in from {
            example(to, x);
        }
    }
    v
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

/// A tetrahedron (global index into [`HaloIndex`]) containing a point whose halo depth
/// there is below the point's w.
#[derive(Clone, Copy, Debug)]
struct Hider(u32);

/// The halo tetrahedra of several surfaces in one obvhs BVH, for the question the halo
/// verification and the renderer's exact mode both ask: is this point of a sheet hidden?
pub struct HaloIndex<'a> {
    halos: &'a [Option<HaloInput<'a>>],
    /// Global tetrahedron -> (surface, tet).
    tets: Vec<(u32, u32)>,
    /// Per global tetrahedron, the surface vertices it is built over (an inserted vertex
    /// stands for those of the tetrahedra around it), sorted, padded with `u32::MAX`.
    over: Vec<[u32; 6]>,
    bvh: obvhs::bvh2::Bvh2,
}

impl<'a> HaloIndex<'a> {
    /// Indexes the tetrahedra of `halos` (one per surface, `None` for none).
    pub fn new(halos: &'a [Option<HaloInput<'a>>]) -> Self {
        let mut boxes = Vec::new();
        let mut tets = Vec::new();
        let mut over = Vec::new();
        for (s, halo) in halos.iter().enumerate() {
            let Some(h) = halo else { continue };
            let n = h.surface_vertices;
            // The surface vertices around each inserted vertex.
            let mut sets: Vec<Vec<u32>> = vec![Vec::new(); h.positions.len().saturating_sub(3 * n)];
            for tet in h.tets {
                for &k in tet.iter().filter(|&&k| k as usize >= 3 * n) {
                    for &v in tet.iter().filter(|&&v| (v as usize) < 3 * n) {
                        sets[k as usize - 3 * n].push(v % n as u32);
                    }
                }
            }
            for (i, tet) in h.tets.iter().enumerate() {
                let p = tet.map(|v| h.positions[v as usize]);
                boxes.push(broad::outward(
                    p[0].min(p[1]).min(p[2]).min(p[3]),
                    p[0].max(p[1]).max(p[2]).max(p[3]),
                ));
                tets.push((s as u32, i as u32));
                let mut vs: Vec<u32> = Vec::with_capacity(8);
                for &k in tet {
                    if (k as usize) < 3 * n {
                        vs.push(k % n as u32);
                    } else {
                        vs.extend_from_slice(&sets[k as usize - 3 * n]);
                    }
                }
                vs.sort_unstable();
                vs.dedup();
                let mut padded = [u32::MAX; 6];
                for (slot, v) in padded.iter_mut().zip(vs) {
                    *slot = v;
                }
                over.push(padded);
            }
        }
        HaloIndex {
            halos,
            tets,
            over,
            bvh: broad::build(&boxes, 4),
        }
    }

    /// Whether the point `x` of a triangle (with vertices `own`) of surface `surface`, at
    /// depth `w`, is hidden: inside a tetrahedron whose halo depth there is below `w`,
    /// other than those of the prisms of the triangles sharing a vertex with it.
    pub fn hidden(&self, x: DVec3, w: f64, surface: u32, own: [u32; 3]) -> bool {
        let mut hidden = false;
        self.visit(x, |g| {
            if !self.within(g, surface, &own) && self.depth_at(g, x).is_some_and(|depth| depth < w)
            {
                hidden = true;
            }
            !hidden
        });
        hidden
    }

    /// Whether the halo of `surface` has zero width at a vertex of `triangle` (its two
    /// offsets coincide there: collapsed). False where the surface has no halo: then
    /// nothing vanished, nothing was built.
    fn vanishes(&self, surface: u32, triangle: &[u32; 3]) -> bool {
        self.halos[surface as usize].as_ref().is_some_and(|h| {
            let n = h.surface_vertices;
            triangle
                .iter()
                .any(|&k| h.positions[k as usize] == h.positions[k as usize + n])
        })
    }

    /// The number of tetrahedra.
    pub(crate) fn len(&self) -> usize {
        self.tets.len()
    }

    /// Tetrahedron `g`'s corners, t and d_orig at them, and its halo's (delta_t, delta_d).
    pub(crate) fn tet(&self, g: u32) -> ([DVec3; 4], [f64; 4], [f64; 4], (f64, f64)) {
        let (surface, tet) = self.tets[g as usize];
        let h = self.halos[surface as usize]
            .as_ref()
            .expect("an indexed tetrahedron has a halo");
        let k = h.tets[tet as usize];
        (
            k.map(|v| h.positions[v as usize]),
            k.map(|v| h.t[v as usize]),
            k.map(|v| h.d_orig[v as usize]),
            (h.delta_t, h.delta_d),
        )
    }

    /// Calls `f` with each tetrahedron whose box contains `x`, until it returns false.
    fn visit(&self, x: DVec3, mut f: impl FnMut(u32) -> bool) {
        self.bvh.aabb_traverse(broad::outward(x, x), |bvh, node| {
            let node = &bvh.nodes[node as usize];
            let first = node.first_index as usize;
            bvh.primitive_indices[first..first + node.prim_count as usize]
                .iter()
                .all(|&g| f(g))
        });
    }

    /// The surface vertices tetrahedron `g` is built over.
    fn over(&self, g: u32) -> impl Iterator<Item = u32> + '_ {
        self.over[g as usize]
            .iter()
            .copied()
            .take_while(|&v| v != u32::MAX)
    }

    /// Whether tetrahedron `g` is over a vertex of `ring` on `surface` (with a triangle's
    /// vertices: whether it belongs to the sheet's own halo there, which never hides it).
    pub(crate) fn within(&self, g: u32, surface: u32, ring: &[u32]) -> bool {
        self.tets[g as usize].0 == surface && self.over(g).any(|v| ring.contains(&v))
    }

    /// The tetrahedra containing `x` whose halo depth there is below `w`, except those of
    /// `own` (its surface and ring).
    fn hiders(&self, x: DVec3, w: f64, own: (u32, &[u32])) -> Vec<Hider> {
        let mut out = Vec::new();
        self.visit(x, |g| {
            if !self.within(g, own.0, own.1) && self.depth_at(g, x).is_some_and(|depth| depth < w) {
                out.push(Hider(g));
            }
            true
        });
        out
    }

    /// Halo depth (eq. 3) at `x` if tetrahedron `g` contains it (boundary included).
    fn depth_at(&self, g: u32, x: DVec3) -> Option<f64> {
        let (surface, tet) = self.tets[g as usize];
        let h = self.halos[surface as usize].as_ref()?;
        let k = h.tets[tet as usize];
        let p = k.map(|v| h.positions[v as usize]);
        let l = [
            orient3d(x, p[1], p[2], p[3]),
            orient3d(p[0], x, p[2], p[3]),
            orient3d(p[0], p[1], x, p[3]),
            orient3d(p[0], p[1], p[2], x),
        ];
        if l.iter().any(|&v| v < 0.0) {
            return None;
        }
        let total: f64 = l.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let interp = |f: &[f64]| (0..4).map(|i| l[i] * f[k[i] as usize]).sum::<f64>() / total;
        let t = interp(h.t);
        let d = interp(h.d_orig);
        Some(d + ((2.0 * t - 1.0).abs() - h.delta_t).max(0.0) * h.delta_d)
    }
}

/// What the classification needs of each surface, with the halos' index.
struct Index<'a> {
    sheets: &'a [Sheet<'a>],
    halos: HaloIndex<'a>,
    /// Per surface: the triangles around each vertex (CSR).
    vertex_tris: Vec<(Vec<u32>, Vec<u32>)>,
    /// Per surface: whether each triangle has an edge on the mesh boundary.
    at_boundary: Vec<Vec<bool>>,
}

impl<'a> Index<'a> {
    fn new(sheets: &'a [Sheet<'a>], halos: &'a [Option<HaloInput<'a>>]) -> Self {
        let vertex_tris: Vec<_> = sheets.iter().map(vertex_triangles).collect();
        let at_boundary = sheets
            .iter()
            .zip(&vertex_tris)
            .map(|(s, (starts, tris))| {
                s.triangles
                    .iter()
                    .map(|t| {
                        (0..3).any(|k| {
                            let (a, b) = (t[k], t[(k + 1) % 3]);
                            tris[starts[a as usize] as usize..starts[a as usize + 1] as usize]
                                .iter()
                                .filter(|&&o| s.triangles[o as usize].contains(&b))
                                .count()
                                == 1
                        })
                    })
                    .collect()
            })
            .collect();
        Index {
            sheets,
            halos: HaloIndex::new(halos),
            vertex_tris,
            at_boundary,
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

    fn classify_curve_sample(&self, s: &CurveSample, v: &mut Verification) {
        v.curve_samples += 1;
        let near = usize::from(s.w[1] < s.w[0]);
        let far = 1 - near;
        let (fn_, ff) = (s.faces[near], s.faces[far]);
        let (ring_near, ring_far) = (self.vertices(fn_), self.vertices(ff));
        let spread = |f: Face| {
            let sheet = &self.sheets[f.surface as usize];
            let w = sheet.triangles[f.triangle as usize].map(|k| sheet.w[k as usize]);
            w[0].max(w[1]).max(w[2]) - w[0].min(w[1]).min(w[2])
        };
        let dw = s.w[far] - s.w[near];
        let halos = &self.halos;
        let reason = &mut v.ambiguous_reasons;
        let counter = if self.close(fn_, ff) {
            Some(&mut reason.branch_point)
        } else if self.at_boundary[fn_.surface as usize][fn_.triangle as usize] {
            Some(&mut reason.boundary)
        } else if dw <= spread(fn_).max(spread(ff)) {
            Some(&mut reason.resolution)
        } else {
            None
        };
        if let Some(counter) = counter {
            *counter += 1;
            v.ambiguous += 1;
            return;
        }
        let far_hidden = halos
            .hiders(s.x, s.w[far], (ff.surface, &ring_far))
            .into_iter()
            .any(|h| halos.within(h.0, fn_.surface, &ring_near));
        let near_hiders = halos.hiders(s.x, s.w[near], (fn_.surface, &ring_near));
        let by_far = near_hiders
            .iter()
            .any(|h| halos.within(h.0, ff.surface, &ring_far));
        if (!far_hidden || by_far) && halos.vanishes(fn_.surface, &ring_near) {
            v.ambiguous_reasons.vanished_halo += 1;
            v.ambiguous += 1;
        } else if !far_hidden || by_far {
            v.wrong += 1;
            example(&mut v.wrong_at, s.x.to_array());
        } else if !near_hiders.is_empty() {
            v.third_sheet += 1;
        } else {
            v.correct += 1;
        }
    }

    fn classify_surface_sample(
        &self,
        x: DVec3,
        w: f64,
        face: Face,
        tolerance: f64,
        v: &mut Verification,
    ) {
        v.surface_samples += 1;
        let ring = self.vertices(face);
        let halos = &self.halos;
        let hiders = halos.hiders(x, w, (face.surface, &ring));
        if hiders.is_empty() {
            return;
        }
        let near_its_sheet = hiders.iter().all(|h| {
            let surface = halos.tets[h.0 as usize].0 as usize;
            let sheet = &self.sheets[surface];
            let halo = halos.halos[surface].as_ref().expect("tet of a halo");
            let n = halo.surface_vertices;
            let rho = halos
                .over(h.0)
                .map(|k| {
                    (halo.positions[k as usize + n] - halo.positions[k as usize]).length() * 0.5
                })
                .fold(0.0, f64::max);
            let points: Vec<DVec3> = halos
                .over(h.0)
                .map(|k| sheet.positions[k as usize])
                .collect();
            distance_to_hull(x, &points) <= rho + tolerance
        });
        if near_its_sheet {
            v.hidden_samples += 1;
        } else {
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
