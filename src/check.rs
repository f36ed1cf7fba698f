//! The independent checker of halo tetrahedra. It shares no code with the builder
//! (`tets`): it reads only vertex positions, the vertex layout and the tetrahedra,
//! and decides with exact predicates.
//!
//! Layout (the same in memory, in `.glb` and in `.vtk`): for a surface of n vertices, vertex
//! i < n is the negative offset (t = 0) of surface vertex i, vertex n + i its positive offset
//! (t = 1), vertex 2n + i the surface vertex itself (t = 1/2), and vertices from 3n on are
//! inserted inside prisms. A surface vertex whose two offsets have identical coordinates is
//! *collapsed*: its three indices (the surface vertex's too, at the same point) name one
//! vertex. A prism may take either offset of each corner as its bottom (twisted prisms, where
//! a non-orientable surface's offsets turn over); the surface triangle cuts it in two
//! layers.
//!
//! The checker reads the surface off the boundary: a boundary face whose three vertices are
//! offsets of three different surface vertices is an offset face over that surface triangle.
//! Where the surface's own triangles are given ([`TetMesh::surface_triangles`], as both of
//! halo4d's files carry them), each must be there too: read off the boundary alone, a halo
//! with whole prisms cut away is a valid shell of what is left.
//! What it checks, each as its own count:
//! - every tetrahedron positively oriented under exact `robust::orient3d` (`inverted`, `flat`),
//!   with four distinct vertices (`degenerate`) and no repeat (`duplicate_tets`); decided on
//!   the coordinates scaled as a whole by a power of two, so that the predicates neither
//!   overflow nor underflow, and counted `undecidable` where no scaling can do that;
//! - every face in one or two tetrahedra (`overshared_faces`), the fourth vertices of two on
//!   opposite sides of it (`folded_faces`, from the orientations already decided: two
//!   tetrahedra on one side of their face overlap, however each is listed);
//! - each half of every quad over a surface edge (offset edge to surface edge) split along
//!   one of its diagonals, the same way from both sides (`quad_mismatches`);
//! - every surface triangle has exactly two offset faces on the boundary, each vertex of one
//!   the other offset of a vertex of the other (`missing_offset_faces`), and every other
//!   boundary face is a side wall over an open edge of the surface
//!   (`unexpected_boundary_faces`);
//! - every surface triangle is itself a face between two tetrahedra, one of each layer
//!   (`missing_surface_faces`): what puts every surface point inside its own halo with
//!   t = 1/2;
//! - the tetrahedra's volumes add up to the volume the boundary encloses (`volume_defect`).
//!
//! Tetrahedra without the layout (another program's mesh) get the checks that need none
//! ([`check_tetrahedra`]): orientation, degenerate and repeated tetrahedra, overshared and
//! folded faces, and the volume; [`crate::certify`] goes on from there to the boundary.

use crate::limits::VOLUME_DEFECT;
use crate::progress::Cancel;
use rayon::prelude::*;
use serde::Serialize;

/// Layers of prisms in the halo layout (see the module documentation), written into every
/// file that carries a halo (`layers`) so that a reader never takes another layout for it.
pub const LAYERS: u32 = 2;

/// A tetrahedral mesh in the halo layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Surface vertices n: the first 3n vertices are the two offsets and the surface.
    pub surface_vertices: usize,
    /// Four vertex indices each.
    pub tets: Vec<[u32; 4]>,
    /// The surface's triangles (surface vertex indices, below `surface_vertices`), where the
    /// file gives them: every one must have its two offset faces and be a face between the
    /// two layers, so that a missing prism is seen. Empty where unknown: the surface is
    /// then read off the boundary, which cannot see a prism that is missing whole.
    pub surface_triangles: Vec<[u32; 3]>,
}

/// What the checker found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CheckStats {
    /// Vertices.
    pub vertices: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Tetrahedra with negative orientation.
    pub inverted: usize,
    /// Tetrahedra with zero volume (exactly).
    pub flat: usize,
    /// Tetrahedra whose orientation the exact predicates cannot decide: a coordinate so much
    /// smaller than the mesh's largest (by more than a factor of 1e80) that their products
    /// would underflow.
    pub undecidable: usize,
    /// Tetrahedra repeating a vertex or naming one that does not exist.
    pub degenerate: usize,
    /// Tetrahedra listed more than once.
    pub duplicate_tets: usize,
    /// Faces in more than two tetrahedra.
    pub overshared_faces: usize,
    /// Faces of two tetrahedra whose fourth vertices lie on the same side of it (exactly):
    /// the two overlap, however each is oriented.
    pub folded_faces: usize,
    /// Quads over surface edges not split along one diagonal, the same way from both sides.
    pub quad_mismatches: usize,
    /// Surface triangles whose boundary faces are not exactly two opposite offset faces.
    pub missing_offset_faces: usize,
    /// Boundary faces that are neither offset triangles nor side walls over an open edge.
    pub unexpected_boundary_faces: usize,
    /// Surface triangles (those with offset faces) that are not a face between two
    /// tetrahedra.
    pub missing_surface_faces: usize,
    /// Faces in exactly one tetrahedron.
    pub boundary_faces: usize,
    /// Faces in exactly two tetrahedra.
    pub interior_faces: usize,
    /// Collapsed surface vertices (both offsets at one point).
    pub collapsed_vertices: usize,
    /// Sum of the tetrahedra's absolute volumes.
    pub volume: f64,
    /// The base-10 logarithm of `volume`, finite wherever the volume is positive, also where
    /// it overflows an f64 (a mesh 1e300 across encloses about 1e900).
    pub volume_log10: f64,
    /// Volume enclosed by the boundary faces.
    pub boundary_volume: f64,
    /// |volume - boundary_volume| / boundary_volume.
    pub volume_defect: f64,
    /// Smallest tetrahedron volume (signed).
    pub min_volume: f64,
    /// Largest tetrahedron volume.
    pub max_volume: f64,
    /// Smallest dihedral angle of any tetrahedron, in degrees.
    pub min_dihedral_deg: f64,
}

impl CheckStats {
    /// Whether the mesh conforms: no mismatched, missing, extra, repeated or overshared face.
    pub fn conforms(&self) -> bool {
        self.degenerate == 0
            && self.duplicate_tets == 0
            && self.overshared_faces == 0
            && self.folded_faces == 0
            && self.quad_mismatches == 0
            && self.missing_offset_faces == 0
            && self.unexpected_boundary_faces == 0
            && self.missing_surface_faces == 0
    }

    /// The verdict of a build and of `halo4d check`: the mesh conforms, has no inverted,
    /// flat or undecidable tetrahedron, and its tetrahedra fill the volume its boundary
    /// encloses to within [`crate::limits::VOLUME_DEFECT`].
    pub fn passes(&self) -> bool {
        self.failures().is_empty()
    }

    /// What keeps the mesh from passing ([`Self::passes`]): no tetrahedron at all, each
    /// non-zero failure count as `<count> <name>` (the conformity counts are
    /// [`Self::conforms`]'s, so a mesh that does not conform always has one), and a volume
    /// defect above [`crate::limits::VOLUME_DEFECT`].
    pub fn failures(&self) -> Vec<String> {
        let counts = [
            ("inverted", self.inverted),
            ("flat", self.flat),
            ("undecidable", self.undecidable),
            ("degenerate", self.degenerate),
            ("duplicate_tets", self.duplicate_tets),
            ("overshared_faces", self.overshared_faces),
            ("folded_faces", self.folded_faces),
            ("quad_mismatches", self.quad_mismatches),
            ("missing_offset_faces", self.missing_offset_faces),
            ("unexpected_boundary_faces", self.unexpected_boundary_faces),
            ("missing_surface_faces", self.missing_surface_faces),
        ];
        let mut out: Vec<String> = Vec::new();
        // An empty mesh is vacuously valid, and almost surely not what was meant.
        if self.tets == 0 {
            out.push("0 tetrahedra (the file holds none to check)".into());
        }
        out.extend(
            counts
                .iter()
                .filter(|(_, c)| *c > 0)
                .map(|(k, c)| format!("{c} {k}")),
        );
        // A NaN defect fails too.
        if self.volume_defect.is_nan() || self.volume_defect > VOLUME_DEFECT {
            out.push(format!(
                "volume_defect {:.3e} (the tetrahedra overlap or leave gaps)",
                self.volume_defect
            ));
        }
        out
    }

    /// The verdict as one line naming the mesh, `None` when it passes.
    pub fn verdict(&self, name: &str) -> Option<String> {
        let failures = self.failures();
        (!failures.is_empty()).then(|| format!("{name}: {}", failures.join(", ")))
    }
}

fn c3(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Volume of a tetrahedron, positive when `orient3d` is.
fn volume(p: [[f64; 3]; 4]) -> f64 {
    -dot(cross(sub(p[1], p[0]), sub(p[2], p[0])), sub(p[3], p[0])) / 6.0
}

/// The cosine of a tetrahedron's smallest dihedral angle (1 for a flat one).
fn smallest_dihedral_cosine(p: [[f64; 3]; 4]) -> f64 {
    let mut normals = [[0.0; 3]; 4];
    for (i, n) in normals.iter_mut().enumerate() {
        let [a, b, c] = [(i + 1) % 4, (i + 2) % 4, (i + 3) % 4].map(|k| p[k]);
        let m = cross(sub(b, a), sub(c, a));
        let len = dot(m, m).sqrt();
        if len == 0.0 || !len.is_finite() {
            return 1.0;
        }
        // Outward: away from the vertex opposite the face.
        let sign = if dot(m, sub(p[i], a)) > 0.0 {
            -1.0
        } else {
            1.0
        };
        *n = m.map(|x| sign * x / len);
    }
    // The dihedral angle between faces i and j is pi minus the angle of their normals.
    let mut largest = -1.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            largest = largest.max(-dot(normals[i], normals[j]));
        }
    }
    largest.min(1.0)
}

/// A face as its sorted vertex triple.
fn key(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// Tetrahedra per parallel task of the checker: a fixed number, so that the volume (summed
/// task after task) comes out the same on any number of threads.
const CHECK_RUN: usize = 1 << 14;

/// How far below the largest coordinate (as a factor) a coordinate may be for
/// `robust::orient3d` to stay exact: its determinants multiply three coordinate differences,
/// and with every coordinate scaled into [2^-266, 1) those stay above f64's smallest normal
/// number, where the exact arithmetic's assumption of no underflow holds.
pub const SAFE_RANGE: f64 = 1e80;

/// The positions as the checker decides on them ([`scaled`]).
pub(crate) struct Scaled {
    /// Every vertex that a tetrahedron uses, scaled as a whole by the power of two that
    /// brings the largest coordinate of those into [0.5, 1) (exact: every orientation is
    /// kept, and `robust::orient3d` cannot overflow); the vertices no tetrahedron uses at
    /// the origin, so that they take no part in the scaling.
    pub(crate) positions: Vec<[f64; 3]>,
    /// The power of two that scales volumes back (2^volume_exp2 may overflow an f64 where
    /// the volumes it scales do not).
    pub(crate) volume_exp2: i32,
    /// Which vertices have a coordinate too small for the predicates to stay exact
    /// ([`SAFE_RANGE`]).
    pub(crate) tiny: Vec<bool>,
    /// The middle of the box of the used vertices (scaled): the origin volumes are summed
    /// from, so that they do not cancel wherever the mesh stands.
    pub(crate) centre: [f64; 3],
}

/// The positions the checker decides on ([`Scaled`]), with the vertices that `tets` use.
pub(crate) fn scaled<P: Copy + Into<[f64; 3]> + Sync>(
    positions: &[P],
    tets: &[[u32; 4]],
) -> Scaled {
    use std::sync::atomic::{AtomicBool, Ordering::Relaxed};
    let marks: Vec<AtomicBool> = (0..positions.len())
        .map(|_| AtomicBool::new(false))
        .collect();
    // In runs, not index by index: rayon's `flatten` of a million-triangle halo's 24
    // million indices took 0.33 s, the runs 0.02 s.
    tets.par_chunks(CHECK_RUN).for_each(|run| {
        for &i in run.iter().flatten() {
            if let Some(u) = marks.get(i as usize) {
                u.store(true, Relaxed);
            }
        }
    });
    let used: Vec<bool> = marks.into_iter().map(AtomicBool::into_inner).collect();
    let at = |i: usize| -> [f64; 3] {
        if used[i] {
            positions[i].into()
        } else {
            [0.0; 3]
        }
    };
    let largest = (0..positions.len())
        .into_par_iter()
        .map(|i| at(i).map(f64::abs).into_iter().fold(0.0, f64::max))
        .reduce(|| 0.0, f64::max);
    let (out, volume_exp2, tiny): (Vec<[f64; 3]>, i32, Vec<bool>) =
        if !(largest.is_finite() && largest > 0.0) {
            let out = (0..positions.len()).map(at).collect();
            (out, 0, vec![false; positions.len()])
        } else {
            // 2^-e with largest = m 2^e, m in [0.5, 1); in two steps, each a normal power of two.
            let e = largest.log2().floor() as i32 + 1;
            let (a, b) = (-e / 2, -e - (-e / 2));
            let scale = |x: f64| x * 2f64.powi(a) * 2f64.powi(b);
            let out: Vec<[f64; 3]> = (0..positions.len())
                .into_par_iter()
                .map(|i| at(i).map(scale))
                .collect();
            let tiny = out
                .iter()
                .map(|p| p.iter().any(|&x| x != 0.0 && x.abs() * SAFE_RANGE < 1.0))
                .collect();
            (out, 3 * e, tiny)
        };
    let (lo, hi) = out
        .par_iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|(p, _)| (*p, *p))
        .reduce(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(a, b), (c, d)| {
                (
                    [0, 1, 2].map(|k| a[k].min(c[k])),
                    [0, 1, 2].map(|k| b[k].max(d[k])),
                )
            },
        );
    let centre = [0, 1, 2].map(|k| {
        let m = 0.5 * lo[k] + 0.5 * hi[k];
        if m.is_finite() { m } else { 0.0 }
    });
    Scaled {
        positions: out,
        volume_exp2,
        tiny,
        centre,
    }
}

/// A face (sorted vertex triple) with the vertex opposite it in its tetrahedron.
type Face = ([u32; 3], u32);

/// A boundary face over a surface triangle: the triangle's surface vertices (sorted) and the
/// face's own vertices.
type OffsetFace = ([u32; 3], [u32; 3]);

/// What stands for a degenerate tetrahedron among the sorted ones: no vertex index can be
/// this large (a mesh of 2^32 vertices would need 96 GiB of positions).
const DEGENERATE: [u32; 4] = [u32::MAX; 4];

/// A tetrahedron's vertices in increasing order and whether that order is an odd
/// permutation of the given one (its orientation turned over); [`DEGENERATE`] when it
/// repeats a vertex or names one past the last of `vertices`.
fn sorted_tet(tet: [u32; 4], vertices: usize) -> ([u32; 4], bool) {
    let (mut s, mut odd) = (tet, false);
    // A sorting network for four, each exchange one transposition.
    for (i, j) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
        if s[i] > s[j] {
            s.swap(i, j);
            odd = !odd;
        }
    }
    if s[0] < s[1] && s[1] < s[2] && s[2] < s[3] && (s[3] as usize) < vertices {
        (s, odd)
    } else {
        (DEGENERATE, false)
    }
}

/// Orientation, volume and angle of `tets` (sorted, with their parities), on positions
/// [`scaled`], with which vertices are too small to decide; writes each sorted
/// tetrahedron's exact orientation (the sign of `orient3d` of its vertices in increasing
/// order; 0 where flat, degenerate or undecidable) into `signs`.
fn examine(
    tets: &[[u32; 4]],
    odd: &[bool],
    positions: &[[f64; 3]],
    tiny: &[bool],
    signs: &mut [i8],
) -> CheckStats {
    let mut s = CheckStats {
        min_volume: f64::INFINITY,
        max_volume: f64::NEG_INFINITY,
        min_dihedral_deg: 180.0,
        ..CheckStats::default()
    };
    let mut dihedral_cosine = -1.0f64;
    for ((tet, &odd), out) in tets.iter().zip(odd).zip(signs) {
        if *tet == DEGENERATE {
            s.degenerate += 1;
            continue;
        }
        let sign = if odd { -1.0 } else { 1.0 };
        let p = tet.map(|i| positions[i as usize]);
        // Exact, so its sign turns over exactly with the vertex order.
        let sorted = robust::orient3d(c3(p[0]), c3(p[1]), c3(p[2]), c3(p[3]));
        let o = sign * sorted;
        if tet.iter().any(|&i| tiny[i as usize]) {
            s.undecidable += 1;
        } else {
            *out = if sorted > 0.0 {
                1
            } else if sorted < 0.0 {
                -1
            } else {
                0
            };
            if o < 0.0 {
                s.inverted += 1;
            } else if o == 0.0 {
                s.flat += 1;
            }
        }
        let v = sign * volume(p);
        s.volume += v.abs();
        s.min_volume = s.min_volume.min(v);
        s.max_volume = s.max_volume.max(v);
        dihedral_cosine = dihedral_cosine.max(smallest_dihedral_cosine(p));
    }
    s.min_dihedral_deg = dihedral_cosine.clamp(-1.0, 1.0).acos().to_degrees();
    s
}

/// Sorts `items` whose first sort field is a vertex index below `vertices`: a counting sort
/// on that vertex, then each (small) bucket by the rest, the buckets shared among threads.
fn bucket_sort<T: Ord + Copy + Default + Send>(
    items: Vec<T>,
    vertices: usize,
    first: impl Fn(&T) -> u32 + Sync,
) -> Vec<T> {
    let mut starts = vec![0usize; vertices + 1];
    for item in &items {
        starts[first(item) as usize + 1] += 1;
    }
    for i in 0..vertices {
        starts[i + 1] += starts[i];
    }
    let mut fill = starts.clone();
    let mut out = vec![T::default(); items.len()];
    for item in items {
        let slot = &mut fill[first(&item) as usize];
        out[*slot] = item;
        *slot += 1;
    }
    // Every bucket (a run of one first vertex) sorted on its own, the buckets shared
    // among the cores.
    out.par_chunk_by_mut(|a, b| first(a) == first(b))
        .for_each(|bucket| bucket.sort_unstable());
    out
}

/// The tetrahedra that can hold a face whose smallest vertex is v: those whose smallest or
/// second smallest vertex is v, each listed under v by its other three vertices in
/// increasing order (every tetrahedron is listed twice, degenerate ones never), with the
/// tetrahedron's exact orientation in that order. A face is found by its smallest vertex
/// among a few entries side by side in memory, with no list of all faces (at a million
/// triangles that list would be 24 million faces, sorted).
struct Incidence {
    starts: Vec<usize>,
    others: Vec<[u32; 3]>,
    /// The sign of `orient3d` of each entry's tetrahedron, its vertices in increasing order
    /// (0 where flat or undecidable).
    signs: Vec<i8>,
}

impl Incidence {
    /// From sorted tetrahedra and their orientations ([`examine`]'s signs).
    fn new(tets: &[[u32; 4]], tet_signs: &[i8], vertices: usize) -> Self {
        let mut starts = vec![0usize; vertices + 1];
        for t in tets.iter().filter(|&t| *t != DEGENERATE) {
            starts[t[0] as usize + 1] += 1;
            starts[t[1] as usize + 1] += 1;
        }
        for i in 0..vertices {
            starts[i + 1] += starts[i];
        }
        let entries = starts[vertices];
        let mut others = vec![[0u32; 3]; entries];
        let mut signs = vec![0i8; entries];
        // Filled on the cores: the vertices cut into one run per thread of about as many
        // entries, each run's lists a slice of their own that its task fills in one pass
        // over the tetrahedra, keeping those of its vertices. Every list is in the
        // tetrahedra's order, as one core fills it, whatever the number of threads.
        let runs = rayon::current_num_threads().max(1);
        let mut cuts: Vec<usize> = (1..runs)
            .map(|k| {
                starts
                    .partition_point(|&e| e * runs < k * entries)
                    .min(vertices)
            })
            .collect();
        cuts.insert(0, 0);
        cuts.push(vertices);
        cuts.dedup();
        let mut slices = Vec::with_capacity(cuts.len());
        let (mut o, mut g) = (others.as_mut_slice(), signs.as_mut_slice());
        for w in cuts.windows(2) {
            let len = starts[w[1]] - starts[w[0]];
            let (here, rest) = std::mem::take(&mut o).split_at_mut(len);
            let (here_signs, rest_signs) = std::mem::take(&mut g).split_at_mut(len);
            slices.push((w[0]..w[1], here, here_signs));
            (o, g) = (rest, rest_signs);
        }
        slices.into_par_iter().for_each(|(run, others, signs)| {
            let base = starts[run.start];
            let mut fill: Vec<usize> = starts[run.clone()].iter().map(|s| s - base).collect();
            for (&[a, b, c, d], &sign) in tets.iter().zip(tet_signs) {
                if [a, b, c, d] == DEGENERATE {
                    continue;
                }
                for (v, rest) in [(a, [b, c, d]), (b, [a, c, d])] {
                    let v = v as usize;
                    if run.contains(&v) {
                        let at = &mut fill[v - run.start];
                        others[*at] = rest;
                        signs[*at] = sign;
                        *at += 1;
                    }
                }
            }
        });
        Incidence {
            starts,
            others,
            signs,
        }
    }

    fn at(&self, v: u32) -> &[[u32; 3]] {
        &self.others[self.starts[v as usize]..self.starts[v as usize + 1]]
    }

    /// The orientations of [`Self::at`]'s entries.
    fn signs_at(&self, v: u32) -> &[i8] {
        &self.signs[self.starts[v as usize]..self.starts[v as usize + 1]]
    }

    /// How many tetrahedra hold face f.
    fn count(&self, f: [u32; 3]) -> usize {
        let [a, b, c] = key(f);
        if a as usize + 1 >= self.starts.len() {
            return 0;
        }
        if b == c {
            return self.at(a).iter().filter(|e| e.contains(&b)).count();
        }
        // An entry is sorted, and so are b < c: it holds both as its first and second,
        // first and third, or second and third vertex (tested without branches: this
        // count is most of the quads' time).
        self.at(a)
            .iter()
            .map(|e| {
                usize::from(
                    ((e[0] == b) & ((e[1] == c) | (e[2] == c))) | ((e[1] == b) & (e[2] == c)),
                )
            })
            .sum()
    }
}

/// Vertices per parallel task of the face count: a fixed number, so that the boundary faces
/// come out in the same order on any number of threads.
const FACE_RUN: usize = 1 << 12;

/// A face (sorted vertex triple) whose tetrahedra break conformity: more than two hold it,
/// or its two tetrahedra lie on the same side of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FaceFault {
    /// In more than two tetrahedra.
    Overshared([u32; 3]),
    /// Its two tetrahedra's fourth vertices on the same side of it.
    Folded([u32; 3]),
}

/// What the faces of sorted tetrahedra are: counts of interior, overshared and folded faces
/// and of repeated tetrahedra, the boundary faces in increasing order with the vertex
/// opposite each, and the faulty faces.
#[derive(Default)]
struct Faces {
    stats: CheckStats,
    boundary: Vec<Face>,
    faults: Vec<FaceFault>,
}

/// The faces whose smallest vertex is in `vertices`, grouped ([`Faces`]).
fn faces_from(vertices: std::ops::Range<usize>, incidence: &Incidence) -> Faces {
    let mut out = Faces::default();
    // Each face with the vertex opposite it and the side that vertex lies on (the sign of
    // `orient3d` of the face's sorted vertices and it; 0 where unknown).
    let mut faces: Vec<([u32; 3], u32, i8)> = Vec::new();
    for v in vertices {
        let v = v as u32;
        faces.clear();
        for (&[a, b, c], &sign) in incidence.at(v).iter().zip(incidence.signs_at(v)) {
            // Moving the opposite vertex from place k of the sorted tetrahedron to its end
            // takes 3 - k exchanges, each turning the orientation over.
            if a > v {
                // The tetrahedron is (v, a, b, c).
                faces.extend([
                    ([v, b, c], a, sign),
                    ([v, a, c], b, -sign),
                    ([v, a, b], c, sign),
                ]);
            } else {
                // The tetrahedron is (a, v, b, c).
                faces.push(([v, b, c], a, -sign));
            }
        }
        faces.sort_unstable();
        for group in faces.chunk_by(|a, b| a.0 == b.0) {
            let k = group[0].0;
            // A repeated tetrahedron repeats every face with the same opposite vertex; count
            // it once, at the face opposite its largest vertex.
            for (i, &(_, o, _)) in group.iter().enumerate() {
                if o > k[2] && group[..i].iter().any(|&(_, other, _)| other == o) {
                    out.stats.duplicate_tets += 1;
                }
            }
            match group {
                [(_, o, _)] => out.boundary.push((k, *o)),
                [(_, o1, s1), (_, o2, s2)] => {
                    out.stats.interior_faces += 1;
                    // Exact sides; a repeated tetrahedron is counted as that instead.
                    if o1 != o2 && *s1 != 0 && s1 == s2 {
                        out.stats.folded_faces += 1;
                        out.faults.push(FaceFault::Folded(k));
                    }
                }
                _ => {
                    out.stats.overshared_faces += 1;
                    out.faults.push(FaceFault::Overshared(k));
                }
            }
        }
    }
    out
}

/// Every face of sorted tetrahedra (with their orientations) counted at its smallest
/// vertex: the incidence and the faces ([`Faces`]).
fn face_uses(tets: &[[u32; 4]], signs: &[i8], vertices: usize) -> (Incidence, Faces) {
    let incidence = Incidence::new(tets, signs, vertices);
    let runs: Vec<Faces> = (0..vertices.div_ceil(FACE_RUN))
        .into_par_iter()
        .map(|r| faces_from(r * FACE_RUN..vertices.min((r + 1) * FACE_RUN), &incidence))
        .collect();
    let mut out = Faces {
        boundary: Vec::with_capacity(runs.iter().map(|r| r.boundary.len()).sum()),
        ..Faces::default()
    };
    for run in runs {
        out.stats.duplicate_tets += run.stats.duplicate_tets;
        out.stats.interior_faces += run.stats.interior_faces;
        out.stats.overshared_faces += run.stats.overshared_faces;
        out.stats.folded_faces += run.stats.folded_faces;
        out.boundary.extend(run.boundary);
        out.faults.extend(run.faults);
    }
    (incidence, out)
}

/// The faces of `tets` that belong to exactly one of them (degenerate tetrahedra left out),
/// each as its sorted vertex triple with the fourth vertex of its tetrahedron, in increasing
/// order: what an exporter draws of a tetrahedral mesh, found as the checker finds it.
pub fn boundary_faces(tets: &[[u32; 4]], vertices: usize) -> Vec<([u32; 3], u32)> {
    let sorted: Vec<[u32; 4]> = tets
        .par_iter()
        .map(|&t| sorted_tet(t, vertices).0)
        .collect();
    // Orientations are not needed for the boundary: every one 0.
    face_uses(&sorted, &vec![0; sorted.len()], vertices)
        .1
        .boundary
}

/// Checks a tetrahedral halo (see the module documentation).
pub fn check(mesh: &TetMesh) -> CheckStats {
    check_parts(
        &mesh.positions,
        mesh.surface_vertices,
        &mesh.tets,
        &mesh.surface_triangles,
    )
}

/// The checks that need no halo layout, on any tetrahedra (another program's mesh): every
/// tetrahedron positively oriented, with four distinct vertices and no repeat; every face in
/// one or two tetrahedra, two on opposite sides of it; the volumes adding up to the volume
/// the boundary encloses. The counts only a halo has (offset faces, quads, surface faces,
/// collapsed vertices) are 0.
pub fn check_tetrahedra<P: Copy + Into<[f64; 3]> + Sync>(
    positions: &[P],
    tets: &[[u32; 4]],
) -> CheckStats {
    examine_tetrahedra(positions, tets).stats
}

/// What [`check_tetrahedra`] found, with what a closer look at the mesh
/// ([`crate::certify`]) goes on from.
#[derive(Clone, Debug, Default)]
pub struct Examined {
    /// The counts.
    pub stats: CheckStats,
    /// The positions scaled as a whole by the power of two that brings the largest
    /// coordinate into [0.5, 1): every orientation as it was, and no exact predicate
    /// overflows.
    pub scaled: Vec<[f64; 3]>,
    /// Which vertices have a coordinate too small, against the largest, for the exact
    /// predicates ([`SAFE_RANGE`]).
    pub tiny: Vec<bool>,
    /// The middle of the box of the vertices the tetrahedra use (scaled): an origin near
    /// the mesh, from which nothing summed over it cancels wherever the mesh stands.
    pub centre: [f64; 3],
    /// Each tetrahedron's exact orientation as given: 1 positive, -1 inverted, 0 flat,
    /// degenerate or undecidable.
    pub orientation: Vec<i8>,
    /// The faces of exactly one tetrahedron, each as its sorted vertex triple with the
    /// fourth vertex of its tetrahedron, in increasing order.
    pub boundary: Vec<([u32; 3], u32)>,
    /// The faces in more than two tetrahedra, or between two on the same side of it.
    pub face_faults: Vec<FaceFault>,
}

/// [`check_tetrahedra`], keeping what it found on the way ([`Examined`]).
pub fn examine_tetrahedra<P: Copy + Into<[f64; 3]> + Sync>(
    positions: &[P],
    tets: &[[u32; 4]],
) -> Examined {
    let nv = positions.len();
    let (sorted, odd): (Vec<[u32; 4]>, Vec<bool>) =
        tets.par_iter().map(|&t| sorted_tet(t, nv)).unzip();
    let Scaled {
        positions: scaled,
        volume_exp2,
        tiny,
        centre,
    } = scaled(positions, tets);
    let (mut s, signs) = tet_stats(&sorted, &odd, &scaled, &tiny);
    let (_, faces) = face_uses(&sorted, &signs, nv);
    drop(sorted);
    let orientation = signs
        .par_iter()
        .zip(&odd)
        .map(|(&sign, &odd)| if odd { -sign } else { sign })
        .collect();
    merge_faces(&mut s, &faces);
    s.boundary_volume = faces
        .boundary
        .par_chunks(CHECK_RUN)
        .map(|part| {
            part.iter()
                .map(|&f| enclosed(f, &scaled, centre))
                .sum::<f64>()
        })
        .collect::<Vec<f64>>()
        .iter()
        .sum();
    finish_volumes(&mut s, volume_exp2);
    Examined {
        stats: s,
        scaled,
        tiny,
        centre,
        orientation,
        boundary: faces.boundary,
        face_faults: faces.faults,
    }
}

/// The face counts of [`face_uses`] into `s`.
fn merge_faces(s: &mut CheckStats, faces: &Faces) {
    s.duplicate_tets = faces.stats.duplicate_tets;
    s.interior_faces = faces.stats.interior_faces;
    s.overshared_faces = faces.stats.overshared_faces;
    s.folded_faces = faces.stats.folded_faces;
    s.boundary_faces = faces.boundary.len();
}

/// A boundary face's share of the volume the boundary encloses (the divergence theorem, from
/// the origin `centre`, any point near the mesh: the shares of a mesh far from 0 then do
/// not cancel), the face turned outward: away from its tetrahedron's fourth vertex.
fn enclosed((face, opposite): Face, positions: &[[f64; 3]], centre: [f64; 3]) -> f64 {
    let mut f = face;
    let [pa, pb, pc, po] = [f[0], f[1], f[2], opposite].map(|i| c3(positions[i as usize]));
    if robust::orient3d(pa, pb, pc, po) > 0.0 {
        f.swap(1, 2);
    }
    let [a, b, c] = f.map(|i| sub(positions[i as usize], centre));
    -dot(a, cross(b, c)) / 6.0
}

/// The statistics only a halo has ([`check_tetrahedra`] leaves them 0): `halo4d check`
/// leaves them out for tetrahedra without halo4d's layout.
pub const HALO_ONLY: [&str; 5] = [
    "quad_mismatches",
    "missing_offset_faces",
    "unexpected_boundary_faces",
    "missing_surface_faces",
    "collapsed_vertices",
];

/// [`check`] on borrowed parts: vertex positions, the number n of surface vertices, the
/// tetrahedra and the surface's triangles (empty where unknown; what [`TetMesh`] holds), so
/// that a halo is checked without a copy of it.
pub fn check_parts<P: Copy + Into<[f64; 3]> + Sync>(
    positions: &[P],
    surface_vertices: usize,
    tets: &[[u32; 4]],
    surface_triangles: &[[u32; 3]],
) -> CheckStats {
    check_parts_until(
        positions,
        surface_vertices,
        tets,
        surface_triangles,
        Cancel::never(),
    )
}

/// [`check_parts`], stopping between its passes once `cancel` is cancelled (with empty
/// statistics, which the caller drops).
pub fn check_parts_until<P: Copy + Into<[f64; 3]> + Sync>(
    positions: &[P],
    surface_vertices: usize,
    tets: &[[u32; 4]],
    surface_triangles: &[[u32; 3]],
    cancel: &Cancel,
) -> CheckStats {
    let stopped = || cancel.is_cancelled();
    let n = surface_vertices;
    let nv = positions.len();
    let layout = Layout::new(positions, n);

    // Every tetrahedron under canonical indices, sorted, with its parity.
    let (tets, odd): (Vec<[u32; 4]>, Vec<bool>) = tets
        .par_iter()
        .map(|t| sorted_tet(t.map(|i| layout.canon(i)), nv))
        .unzip();
    let Scaled {
        positions: scaled,
        volume_exp2,
        tiny,
        centre,
    } = scaled(positions, &tets);
    if stopped() {
        return CheckStats::default();
    }
    let (mut s, signs) = tet_stats(&tets, &odd, &scaled, &tiny);
    drop(odd);
    if stopped() {
        return CheckStats::default();
    }
    s.collapsed_vertices = layout.collapsed.iter().filter(|&&c| c).count();

    // Every face counted at its smallest vertex; boundary faces kept with their
    // tetrahedron's fourth vertex, in increasing order.
    let (incidence, faces) = face_uses(&tets, &signs, nv);
    drop((tets, signs));
    merge_faces(&mut s, &faces);
    let boundary = faces.boundary;
    if stopped() {
        return CheckStats::default();
    }

    let (boundary_volume, offset_faces, others) =
        classify_boundary(boundary, &scaled, centre, &layout);
    s.boundary_volume = boundary_volume;
    let offset_faces = bucket_sort(offset_faces, n, |f| f.0[0]);
    if stopped() {
        return CheckStats::default();
    }
    if !surface_triangles.is_empty() {
        count_missing_given(
            &mut s,
            surface_triangles,
            &offset_faces,
            &layout,
            &incidence,
        );
    }
    let edges = surface_edges(&mut s, offset_faces, &layout, &incidence);
    if stopped() {
        return CheckStats::default();
    }
    let open = check_quads(&mut s, edges, &layout, &incidence);
    s.unexpected_boundary_faces = unexpected_boundary_faces(&others, &open, &layout);
    finish_volumes(&mut s, volume_exp2);
    s
}

/// The halo layout of a mesh's vertices (see the module documentation): which surface
/// vertices are collapsed, and the maps between a vertex, its partner and its surface vertex.
struct Layout<'a, P> {
    /// Surface vertices n.
    n: usize,
    /// The positions as given (not scaled): collapsed vertices are found by equality.
    positions: &'a [P],
    /// For each surface vertex, whether its two offsets have identical coordinates.
    collapsed: Vec<bool>,
}

impl<'a, P: Copy + Into<[f64; 3]>> Layout<'a, P> {
    fn new(positions: &'a [P], n: usize) -> Self {
        let nv = positions.len();
        let at = |i: usize| -> [f64; 3] { positions[i].into() };
        let collapsed: Vec<bool> = (0..n).map(|v| n + v < nv && at(v) == at(n + v)).collect();
        Layout {
            n,
            positions,
            collapsed,
        }
    }

    fn at(&self, i: usize) -> [f64; 3] {
        self.positions[i].into()
    }

    /// Vertex i with collapsed vertices under one index, the negative offset's (a surface
    /// vertex at another point than its collapsed offsets keeps its own).
    fn canon(&self, i: u32) -> u32 {
        let (n, nv) = (self.n, self.positions.len());
        let i = i as usize;
        if i < n || i >= 3 * n {
            return i as u32;
        }
        let v = if i < 2 * n { i - n } else { i - 2 * n };
        let folded = self.collapsed[v] && (i < 2 * n || (i < nv && self.at(i) == self.at(v)));
        if folded { v as u32 } else { i as u32 }
    }

    /// Surface vertex x's own vertex (2n + x) under its [`Self::canon`] index.
    fn mid(&self, x: u32) -> u32 {
        self.canon(2 * self.n as u32 + x)
    }

    /// The offset of the same surface vertex on the other side (itself when collapsed).
    fn partner(&self, i: u32) -> u32 {
        let n = self.n;
        let i = i as usize;
        match i {
            _ if i < n && self.collapsed[i] => i as u32,
            _ if i < n => (i + n) as u32,
            _ => (i - n) as u32,
        }
    }

    /// Whether vertex i is an offset.
    fn offset(&self, i: u32) -> bool {
        (i as usize) < 2 * self.n
    }

    /// The surface vertex an offset or surface vertex stands for.
    fn surface_vertex(&self, i: u32) -> Option<u32> {
        let n = self.n;
        ((i as usize) < 3 * n).then(|| (i as usize % n.max(1)) as u32)
    }

    /// Whether two offsets lie on the same side (both negative or both positive).
    fn same_side(&self, a: u32, b: u32) -> bool {
        let n = self.n as u32;
        (a < n) == (b < n)
    }
}

/// The checks of each tetrahedron on its own (sorted, with its parity, on the positions
/// [`scaled`]): orientation, degeneracy, volume and angles, with the vertex and tetrahedron
/// counts; and each sorted tetrahedron's orientation ([`examine`]'s signs).
fn tet_stats(
    tets: &[[u32; 4]],
    odd: &[bool],
    positions: &[[f64; 3]],
    tiny: &[bool],
) -> (CheckStats, Vec<i8>) {
    // Runs of CHECK_RUN tetrahedra on the cores, summed in order: the volume's rounding
    // depends on the runs only, not on the number of threads.
    let mut signs = vec![0i8; tets.len()];
    let partials: Vec<CheckStats> = tets
        .par_chunks(CHECK_RUN)
        .zip(odd.par_chunks(CHECK_RUN))
        .zip(signs.par_chunks_mut(CHECK_RUN))
        .map(|((part, odd), signs)| examine(part, odd, positions, tiny, signs))
        .collect();
    let mut s = CheckStats {
        vertices: positions.len(),
        tets: tets.len(),
        min_volume: f64::INFINITY,
        max_volume: f64::NEG_INFINITY,
        min_dihedral_deg: 180.0,
        ..CheckStats::default()
    };
    for q in partials {
        s.degenerate += q.degenerate;
        s.inverted += q.inverted;
        s.flat += q.flat;
        s.undecidable += q.undecidable;
        s.volume += q.volume;
        s.min_volume = s.min_volume.min(q.min_volume);
        s.max_volume = s.max_volume.max(q.max_volume);
        s.min_dihedral_deg = s.min_dihedral_deg.min(q.min_dihedral_deg);
    }
    if s.tets == s.degenerate {
        (s.min_volume, s.max_volume, s.min_dihedral_deg) = (0.0, 0.0, 0.0);
    }
    (s, signs)
}

/// Sorts the boundary faces into offset faces (three offsets of three surface vertices), by
/// surface triangle, and the other faces, to classify once the open edges are known; gives
/// the volume the boundary encloses, on the positions [`scaled`], with them. In runs of a
/// fixed size, the volume summed in order.
fn classify_boundary<P: Copy + Into<[f64; 3]> + Sync>(
    boundary: Vec<Face>,
    positions: &[[f64; 3]],
    centre: [f64; 3],
    layout: &Layout<P>,
) -> (f64, Vec<OffsetFace>, Vec<[u32; 3]>) {
    let classified: Vec<(f64, Vec<OffsetFace>, Vec<[u32; 3]>)> = boundary
        .par_chunks(CHECK_RUN)
        .map(|part| {
            let (mut volume, mut offset_faces, mut others) = (0.0, Vec::new(), Vec::new());
            for &(k, o) in part {
                volume += enclosed((k, o), positions, centre);
                match k.map(|i| layout.surface_vertex(i)) {
                    [Some(x), Some(y), Some(z)]
                        if x != y && y != z && x != z && k.iter().all(|&i| layout.offset(i)) =>
                    {
                        offset_faces.push((key([x, y, z]), k));
                    }
                    _ => others.push(k),
                }
            }
            (volume, offset_faces, others)
        })
        .collect();
    drop(boundary);
    let (mut boundary_volume, mut offset_faces, mut others) = (0.0, Vec::new(), Vec::new());
    for (volume, o, k) in classified {
        boundary_volume += volume;
        offset_faces.extend(o);
        others.extend(k);
    }
    (boundary_volume, offset_faces, others)
}

/// Counts the surface's own triangles, as given, whose offset faces are not on the boundary
/// at all (their prism missing, or their faces buried) as missing, and their surface face
/// too unless two tetrahedra share it. A triangle whose three corners are collapsed has a
/// flat prism and no offset face.
fn count_missing_given<P: Copy + Into<[f64; 3]> + Sync>(
    s: &mut CheckStats,
    surface_triangles: &[[u32; 3]],
    offset_faces: &[OffsetFace],
    layout: &Layout<P>,
    incidence: &Incidence,
) {
    let n = layout.n;
    // Where the offset faces over each surface vertex start: they are sorted by their
    // triangle, whose smallest vertex is below n, so a triangle's offset faces are among
    // the few over its smallest vertex (a hash set of all of them, built on one core, took
    // a quarter of the checker's time at a million triangles).
    let mut starts = vec![0usize; n + 1];
    for f in offset_faces {
        starts[f.0[0] as usize + 1] += 1;
    }
    for v in 0..n {
        starts[v + 1] += starts[v];
    }
    let over = |k: [u32; 3]| {
        offset_faces[starts[k[0] as usize]..starts[k[0] as usize + 1]]
            .iter()
            .any(|f| f.0 == k)
    };
    let (offset, surface) = surface_triangles
        .par_iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < n))
        .map(|&t| {
            let k = key(t);
            let flat = t.iter().all(|&v| layout.collapsed[v as usize]);
            if flat || over(k) {
                return (0, 0);
            }
            let surface = incidence.count(k.map(|x| layout.mid(x))) != 2;
            (1, usize::from(surface))
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    s.missing_offset_faces += offset;
    s.missing_surface_faces += surface;
}

/// A surface edge with the side pairing of the offset face's edge over it: `true` when that
/// edge joins two offsets on the same side (its quad's perimeter runs straight, so the
/// diagonals cross sides), `None` at a collapsed end.
type Edge = ([u32; 2], Option<bool>);

/// The surface triangles of the offset faces (sorted by triangle): counts those without
/// exactly two opposite offset faces, or whose surface face is not between two tetrahedra,
/// as missing; gives their edges, sorted.
fn surface_edges<P: Copy + Into<[f64; 3]> + Sync>(
    s: &mut CheckStats,
    offset_faces: Vec<OffsetFace>,
    layout: &Layout<P>,
    incidence: &Incidence,
) -> Vec<Edge> {
    let triangles: Vec<(bool, bool, [Edge; 3])> = offset_faces
        .par_chunk_by(|a, b| a.0 == b.0)
        .map(|group| {
            let opposite =
                group.len() == 2 && key(group[0].1.map(|i| layout.partner(i))) == group[1].1;
            let face = group[0].1;
            let edges = [(0, 1), (0, 2), (1, 2)].map(|(i, j)| {
                let (a, b) = (face[i], face[j]);
                let (x, y) = (
                    layout.surface_vertex(a).unwrap_or(0),
                    layout.surface_vertex(b).unwrap_or(0),
                );
                let straight = (layout.partner(a) != a && layout.partner(b) != b)
                    .then(|| layout.same_side(a, b));
                ([x.min(y), x.max(y)], straight)
            });
            (
                !opposite,
                incidence.count(group[0].0.map(|x| layout.mid(x))) != 2,
                edges,
            )
        })
        .collect();
    drop(offset_faces);
    let mut edges: Vec<Edge> = Vec::with_capacity(3 * triangles.len());
    for (missing_offset, missing_surface, e) in triangles {
        s.missing_offset_faces += missing_offset as usize;
        s.missing_surface_faces += missing_surface as usize;
        edges.extend(e);
    }
    bucket_sort(edges, layout.n, |e| e.0[0])
}

/// Checks the quads over the surface edges (sorted), counting those not split right as
/// `quad_mismatches`; gives the open edges, those used by one surface triangle, in
/// increasing order.
fn check_quads<P: Copy + Into<[f64; 3]> + Sync>(
    s: &mut CheckStats,
    edges: Vec<Edge>,
    layout: &Layout<P>,
    incidence: &Incidence,
) -> Vec<[u32; 2]> {
    let quads: Vec<(bool, Option<[u32; 2]>)> = edges
        .par_chunk_by(|a, b| a.0 == b.0)
        .map(|group| {
            let open = (group.len() == 1).then_some(group[0].0);
            (quad_split_right(group, layout, incidence), open)
        })
        .collect();
    drop(edges);
    s.quad_mismatches = quads.iter().filter(|q| !q.0).count();
    quads.into_iter().filter_map(|q| q.1).collect()
}

/// Whether the quad over one surface edge (`group`: the edge once for each offset face over
/// it) is split right.
fn quad_split_right<P: Copy + Into<[f64; 3]> + Sync>(
    group: &[Edge],
    layout: &Layout<P>,
    incidence: &Incidence,
) -> bool {
    let count = |f: [u32; 3]| incidence.count(f);
    let mid = |x: u32| layout.mid(x);
    let [x, y] = group[0].0;
    let expected = if group.len() >= 2 { 2 } else { 1 };
    let (x1, y1) = (layout.partner(x), layout.partner(y));
    if x1 == x && y1 == y {
        return true;
    }
    // Each half of the quad, from an offset edge (a, b) to the surface edge: split along a
    // diagonal, the two faces on one of them each used `expected` times and the other two
    // unused, or, with a collapsed end, one triangle used `expected` times. The offset edges
    // join offsets on one side where the offset faces' edges do (else the halves cross
    // sides, at a twist); every prism over the edge must see the same.
    let straight = group[0].1;
    let agree = group.iter().all(|e| e.1 == straight);
    let split = |a: u32, b: u32, c: u32, d: u32| {
        // Diagonal (a, b); the other diagonal (c, d).
        count([a, b, c]) == expected
            && count([a, b, d]) == expected
            && count([c, d, a]) == 0
            && count([c, d, b]) == 0
    };
    let half = |a: u32, b: u32| {
        let (ma, mb) = (
            mid(layout.surface_vertex(a).unwrap_or(0)),
            mid(layout.surface_vertex(b).unwrap_or(0)),
        );
        match (ma == a, mb == b) {
            (true, true) => true,
            (true, false) => count([a, b, mb]) == expected,
            (false, true) => count([a, b, ma]) == expected,
            (false, false) => split(a, mb, b, ma) || split(b, ma, a, mb),
        }
    };
    agree
        && if straight == Some(false) {
            half(x, y1) && half(x1, y)
        } else {
            half(x, y) && half(x1, y1)
        }
}

/// How many of the boundary faces that are not offset faces are not side walls either: a
/// side wall lies over exactly two surface vertices, an edge among the `open` ones (sorted).
fn unexpected_boundary_faces<P: Copy + Into<[f64; 3]> + Sync>(
    others: &[[u32; 3]],
    open: &[[u32; 2]],
    layout: &Layout<P>,
) -> usize {
    others
        .par_iter()
        .filter(|k| {
            let wall = match k.map(|i| layout.surface_vertex(i)) {
                [Some(a), Some(b), Some(c)] => {
                    // Over exactly two surface vertices, an open edge.
                    let mut e = [a, b, c];
                    e.sort_unstable();
                    let pair = if e[0] == e[1] {
                        [e[0], e[2]]
                    } else {
                        [e[0], e[1]]
                    };
                    (e[0] == e[1] || e[1] == e[2])
                        && pair[0] != pair[1]
                        && open.binary_search(&pair).is_ok()
                }
                _ => false,
            };
            !wall
        })
        .count()
}

/// The volume defect, the volume's logarithm, then the volumes back in the mesh's own units
/// (infinite or zero where they do not fit an f64) by 2^`volume_exp2`, the power [`scaled`]
/// gives.
fn finish_volumes(s: &mut CheckStats, volume_exp2: i32) {
    let boundary_volume = s.boundary_volume;
    s.volume_log10 = s.volume.log10() + f64::from(volume_exp2) * std::f64::consts::LOG10_2;
    s.volume_defect = if boundary_volume.abs() > 0.0 {
        (s.volume - boundary_volume).abs() / boundary_volume.abs()
    } else if s.volume == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    for v in [
        &mut s.volume,
        &mut s.boundary_volume,
        &mut s.min_volume,
        &mut s.max_volume,
    ] {
        // In two steps: each power of two stays finite where the product does.
        let half = volume_exp2 / 2;
        *v = *v * 2f64.powi(half) * 2f64.powi(volume_exp2 - half);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_incidence_is_the_same_on_any_number_of_threads() {
        // Random tetrahedra over 500 vertices, some degenerate: every vertex's list in the
        // tetrahedra's order, as one core fills it, whatever the threads' runs.
        let mut next = crate::intersect::lcg(3);
        let tets: Vec<[u32; 4]> = (0..20_000)
            .map(|_| sorted_tet([0; 4].map(|_| (next() * 500.0) as u32), 500).0)
            .collect();
        let signs: Vec<i8> = (0..tets.len()).map(|i| [1, -1, 0][i % 3]).collect();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| Incidence::new(&tets, &signs, 500))
        };
        let one = on(1);
        assert!(tets.contains(&DEGENERATE));
        assert_eq!(
            one.starts[500],
            2 * tets.iter().filter(|&&t| t != DEGENERATE).count()
        );
        for threads in [2, 3, 7] {
            let many = on(threads);
            assert_eq!(
                (&many.starts, &many.others, &many.signs),
                (&one.starts, &one.others, &one.signs),
                "{threads} threads"
            );
        }
        // Each list holds the tetrahedra whose smallest or second vertex it is, in order.
        let v = 17;
        let expected: Vec<[u32; 3]> = tets
            .iter()
            .filter(|&&t| t != DEGENERATE)
            .flat_map(|&[a, b, c, d]| {
                [(a, [b, c, d]), (b, [a, c, d])]
                    .into_iter()
                    .filter(|&(w, _)| w == v)
                    .map(|(_, rest)| rest)
            })
            .collect();
        assert!(!expected.is_empty());
        assert_eq!(one.at(v), expected.as_slice());
    }
}
