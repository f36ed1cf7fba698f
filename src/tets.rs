//! Prisms to tetrahedra: every triangle of a thickened surface is a prism between its two
//! offsets, cut by the surface triangle itself into two layers (bottom to surface, surface
//! to top), each split into three tetrahedra so that neighbouring prisms agree on the
//! diagonal of the quads they share.
//!
//! Takes: the surface's triangles as [`Corners`] and the halo's vertices (offset vertex i of
//! the negative side at index i, of the positive side at n + i, the surface vertex itself at
//! 2n + i). Gives: tetrahedra, oriented so that `robust::orient3d` is positive when the prism
//! is not inverted, and vertices inserted inside layers that no consistent split fits.
//!
//! Why two layers: the surface triangle is then a face of the tetrahedra, so every surface
//! point lies in its own prism's tetrahedra with t = 1/2 exactly. In one layer of three
//! tetrahedra the mid-section of a prism whose corners' offset directions differ is not the
//! triangle: its split quads bend across it, and a surface point can fall outside its own
//! prism or get a t far from 1/2 (on the twist-spun knots, up to tens of crossings a halo
//! failed to explain).
//!
//! A prism's bottom is the side its triangle's winding turns away from. At each corner that
//! is the negative offset, unless the corner is *flipped* (its offset direction disagrees
//! with the winding: on a non-orientable surface some prisms must be twisted this way), and a
//! *collapsed* corner (rho shrunk to zero) is one vertex at the bottom and the top.
//!
//! A quad's diagonal runs from the bottom of one end of its surface edge to the top of the
//! other: an orientation of the edge within the prism. Both layers take their prism's
//! orientations, so each half of a quad is split parallel to the whole quad's diagonal and
//! neighbours that agree on a quad agree on both its halves. A layer splits into three
//! tetrahedra exactly when the orientations of its three edges are acyclic (a source p, a
//! middle q and a sink r: tetrahedra {p0 q0 r0 r1}, {p0 q0 q1 r1}, {p0 p1 q1 r1}); the two
//! cyclic patterns need a new vertex, here one at the layer's centre joined to its eight
//! boundary triangles. Tetrahedra that repeat a collapsed corner (whose offsets and surface
//! vertex are one vertex) are left out. Neighbours agree on a quad when both split it
//! through the same global vertex; "up" means through the negative offset of the edge's
//! lower-index end. Three ways to choose ([`Split`]):
//! - `global_order`: every quad up, i.e. through its lowest-index vertex. Acyclic
//!   everywhere (the prism's lowest vertex is a source or a sink), conforming, blind to
//!   geometry.
//! - `paper` (paper 000, 5.1): each triangle first orients its edges by its own corner order,
//!   as a per-triangle GPU program does; the shared quads where two prisms disagree are then
//!   fixed by flipping one prism's diagonal where that keeps it splittable (fig. 4b), and
//!   where neither prism can flip, one of them gets an inserted vertex (fig. 4d).
//! - `quality`: from the global order, flip an edge's diagonal when both its prisms stay
//!   splittable and their worst tetrahedron (smallest dihedral angle, inverted counts worst)
//!   gets better.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// How prisms are split into tetrahedra.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Split {
    /// Per-triangle start, then flips and inserted vertices (paper 000).
    Paper,
    /// Each quad split through its lowest-index vertex (Dompierre et al. 1999). The default:
    /// conforming with no inserted vertex and the fastest; on the default scene (`halo4d
    /// build` with each split) `quality` takes 432 ms against 88 and does not raise the
    /// smallest dihedral angle, which the prisms around cross-caps decide.
    #[default]
    GlobalOrder,
    /// The global order, improved by flips towards larger dihedral angles.
    Quality,
}

impl Split {
    /// The name used in scene files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Split::Paper => "paper",
            Split::GlobalOrder => "global_order",
            Split::Quality => "quality",
        }
    }
}

/// What the split did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SplitStats {
    /// Shared quads whose two prisms disagreed at the start.
    pub mismatches_initial: usize,
    /// Diagonals flipped to fix them (paper) or to improve the tetrahedra (quality).
    pub flips: usize,
    /// Vertices inserted inside prisms that no consistent split fits.
    pub inserted_vertices: usize,
    /// Shared quads whose prisms still disagree (the builder's own count; the checker decides).
    pub mismatches_final: usize,
}

/// One prism: its triangle and how each corner's offsets sit (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Corners {
    /// The surface triangle.
    pub tri: [u32; 3],
    /// Corners whose bottom is the positive offset.
    pub flip: [bool; 3],
    /// Corners whose two offsets are one vertex, the negative offset's index.
    pub collapsed: [bool; 3],
}

impl Corners {
    /// A prism with every bottom on the negative offset and no collapsed corner.
    pub fn plain(tri: [u32; 3]) -> Corners {
        Corners {
            tri,
            ..Corners::default()
        }
    }

    /// Global indices of the bottom corners, then of the top corners, for a surface of `n`
    /// vertices.
    pub fn vertices(&self, n: u32) -> [u32; 6] {
        let mut out = [0; 6];
        for i in 0..3 {
            let v = self.tri[i];
            let (bottom, top) = match (self.collapsed[i], self.flip[i]) {
                (true, _) => (v, v),
                (false, false) => (v, v + n),
                (false, true) => (v + n, v),
            };
            (out[i], out[i + 3]) = (bottom, top);
        }
        out
    }

    /// The prism's two layers, bottom to surface and surface to top, each as global indices
    /// of its bottom corners, then its top corners; a collapsed corner is one vertex, the
    /// negative offset's index, in both.
    pub fn layers(&self, n: u32) -> [[u32; 6]; 2] {
        let v = self.vertices(n);
        let mid = |i: usize| {
            if self.collapsed[i] {
                v[i]
            } else {
                2 * n + self.tri[i]
            }
        };
        let m = [mid(0), mid(1), mid(2)];
        [
            [v[0], v[1], v[2], m[0], m[1], m[2]],
            [m[0], m[1], m[2], v[3], v[4], v[5]],
        ]
    }

    /// Whether the quad over edge k, oriented `forward` in this prism, is split through the
    /// negative offset of the edge's lower-index end. Its own inverse: the orientation that
    /// splits the quad `up` is `self.up(k, up)`.
    fn up(&self, k: usize, forward: bool) -> bool {
        let (i, j) = (k, (k + 1) % 3);
        let lower_is_j = self.tri[j] < self.tri[i];
        forward ^ self.flip[if lower_is_j { j } else { i }] ^ lower_is_j
    }

    /// Whether the quad over edge k degenerates to a triangle (or a segment): an end of the
    /// edge collapsed, so either diagonal gives the same faces.
    fn degenerate(&self, k: usize) -> bool {
        self.collapsed[k] || self.collapsed[(k + 1) % 3]
    }

    /// The pattern in effect: a cyclic pattern with a collapsed corner is made acyclic by
    /// turning an edge at that corner, which changes no face.
    pub fn effective(&self, mut forward: [bool; 3]) -> [bool; 3] {
        if cyclic(forward)
            && let Some(k) = (0..3).find(|&k| self.degenerate(k))
        {
            forward[k] = !forward[k];
        }
        forward
    }

    /// Whether the prism splits into tetrahedra with no inserted vertex.
    fn splittable(&self, forward: [bool; 3]) -> bool {
        !cyclic(self.effective(forward))
    }
}

/// Tetrahedra of a halo, with the vertices inserted for them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tetrahedra {
    /// Four vertex indices each, into the halo's vertices followed by `inserted`.
    pub tets: Vec<[u32; 4]>,
    /// Inserted vertices, each at the centre of a layer of a prism.
    pub inserted: Vec<DVec3>,
    /// The triangle whose prism each inserted vertex is in.
    pub inserted_in: Vec<u32>,
    /// The six vertices of the layer each inserted vertex is the centre of.
    pub inserted_over: Vec<[u32; 6]>,
    /// What the split did.
    pub stats: SplitStats,
}

/// The triangles using each undirected edge of a triangle mesh, as (triangle, k) with edge k
/// of a triangle running from corner k to corner k + 1; flat, edge after edge.
struct Edges {
    uses: Vec<(u32, u8)>,
    /// Where each edge's uses start in `uses` (one more entry than edges).
    starts: Vec<usize>,
}

impl Edges {
    fn new(corners: &[Corners]) -> Edges {
        // A counting sort on the lower end, then each (small) bucket by the higher end.
        let vertices = corners
            .iter()
            .flat_map(|c| c.tri)
            .max()
            .map_or(0, |v| v as usize + 1);
        let ends = |c: &Corners, k: usize| {
            let (a, b) = (c.tri[k], c.tri[(k + 1) % 3]);
            (a.min(b), a.max(b))
        };
        let mut bucket = vec![0usize; vertices + 1];
        for c in corners {
            for k in 0..3 {
                bucket[ends(c, k).0 as usize + 1] += 1;
            }
        }
        for i in 0..vertices {
            bucket[i + 1] += bucket[i];
        }
        let mut fill = bucket.clone();
        let mut keyed = vec![(0u32, 0u32, 0u8); 3 * corners.len()];
        for (t, c) in corners.iter().enumerate() {
            for k in 0..3 {
                let (lo, hi) = ends(c, k);
                keyed[fill[lo as usize]] = (hi, t as u32, k as u8);
                fill[lo as usize] += 1;
            }
        }
        let mut starts = vec![0];
        for w in bucket.windows(2) {
            let run = &mut keyed[w[0]..w[1]];
            run.sort_unstable();
            for i in 1..run.len() {
                if run[i].0 != run[i - 1].0 {
                    starts.push(w[0] + i);
                }
            }
            if !run.is_empty() {
                starts.push(w[1]);
            }
        }
        Edges {
            uses: keyed.iter().map(|k| (k.1, k.2)).collect(),
            starts,
        }
    }

    fn iter(&self) -> impl Iterator<Item = &[(u32, u8)]> {
        self.starts.windows(2).map(|w| &self.uses[w[0]..w[1]])
    }
}

/// Whether a triangle's edge orientations (true: from corner k to corner k + 1) are cyclic.
pub fn cyclic(forward: [bool; 3]) -> bool {
    forward[0] == forward[1] && forward[1] == forward[2]
}

/// Reference coordinates of a prism's six vertices (corners 0, 1, 2 of the triangle at the
/// bottom, then at the top) and its centre: a right prism over a counter-clockwise triangle.
const REFERENCE: [[f64; 3]; 7] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0 / 3.0, 1.0 / 3.0, 0.5],
];

fn coord(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Orders four prism-local vertices (0-2 bottom, 3-5 top, 6 centre) so that the tetrahedron
/// is positive on the reference prism: positive on the real one when it is not inverted.
fn oriented(local: [usize; 4]) -> [usize; 4] {
    let [a, b, c, d] = local.map(|i| coord(REFERENCE[i]));
    if robust::orient3d(a, b, c, d) > 0.0 {
        local
    } else {
        [local[0], local[1], local[3], local[2]]
    }
}

/// The three tetrahedra of a prism from its corners' edge orientations (acyclic), in
/// prism-local indices.
fn acyclic_tets(forward: [bool; 3]) -> Vec<[usize; 4]> {
    // Out-degree of each corner: edge k runs k -> k+1 when forward, else k+1 -> k.
    let mut out = [0usize; 3];
    for (k, f) in forward.iter().enumerate() {
        out[if *f { k } else { (k + 1) % 3 }] += 1;
    }
    let p = (0..3).find(|&i| out[i] == 2).expect("acyclic: a source");
    let r = (0..3).find(|&i| out[i] == 0).expect("acyclic: a sink");
    let q = 3 - p - r;
    vec![
        oriented([p, q, r, r + 3]),
        oriented([p, q, q + 3, r + 3]),
        oriented([p, p + 3, q + 3, r + 3]),
    ]
}

/// The eight tetrahedra joining a prism's centre (local index 6) to its boundary, with each
/// quad split by its edge's orientation.
fn centre_tets(forward: [bool; 3]) -> Vec<[usize; 4]> {
    let mut tets = vec![oriented([0, 1, 2, 6]), oriented([3, 4, 5, 6])];
    for (k, f) in forward.iter().enumerate() {
        let (i, j) = (k, (k + 1) % 3);
        // Diagonal from the bottom of the edge's tail to the top of its head.
        let (tail, head) = if *f { (i, j) } else { (j, i) };
        tets.push(oriented([tail, head, head + 3, 6]));
        tets.push(oriented([tail, tail + 3, head + 3, 6]));
    }
    tets
}

/// The prism-local tetrahedra of each of the 8 patterns (bit k: edge k forward).
fn pattern(forward: [bool; 3]) -> &'static [[usize; 4]] {
    static TABLE: OnceLock<Vec<Vec<[usize; 4]>>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..8u8)
            .map(|bits| {
                let f = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
                if cyclic(f) {
                    centre_tets(f)
                } else {
                    acyclic_tets(f)
                }
            })
            .collect()
    });
    &table[forward.iter().rev().fold(0, |b, &f| 2 * b + usize::from(f))]
}

/// The tetrahedra of a prism whose bottom and top corners are the vertices `v` (from
/// [`Corners::vertices`]), with edge orientations `forward` (in effect, see
/// [`Corners::effective`]) and, for a cyclic pattern, the inserted vertex `centre`.
/// Tetrahedra repeating a vertex (at collapsed corners) are left out.
pub fn prism_tets(v: [u32; 6], forward: [bool; 3], centre: u32) -> impl Iterator<Item = [u32; 4]> {
    let global = move |i: usize| if i < 6 { v[i] } else { centre };
    pattern(forward)
        .iter()
        .map(move |t| t.map(global))
        .filter(|t| {
            t[0] != t[1]
                && t[0] != t[2]
                && t[0] != t[3]
                && t[1] != t[2]
                && t[1] != t[3]
                && t[2] != t[3]
        })
}

/// The tetrahedra of one plain prism over triangle `tri` of a surface of `n` vertices, given
/// the orientation of its three edges (`forward[k]`: the quad over edge k is split from the
/// bottom of corner k to the top of corner k + 1): three tetrahedra in each layer, or, for
/// the two cyclic patterns, eight joined to the inserted vertex `centres[layer]`.
pub fn prism(tri: [u32; 3], n: u32, forward: [bool; 3], centres: [u32; 2]) -> Vec<[u32; 4]> {
    let layers = Corners::plain(tri).layers(n);
    (0..2)
        .flat_map(|l| prism_tets(layers[l], forward, centres[l]))
        .collect()
}

/// The centre of a layer with corners `v` (the inserted vertex of a cyclic pattern), rounded
/// to f32 like every halo vertex.
pub fn centre(v: [u32; 6], positions: &[DVec3]) -> DVec3 {
    let sum: DVec3 = v.iter().map(|&i| positions[i as usize]).sum();
    (sum / 6.0).as_vec3().as_dvec3()
}

/// Six times the volume of a tetrahedron, positive when `robust::orient3d` is (the fourth
/// vertex below the plane in which the first three turn counter-clockwise).
fn signed_volume(p: [DVec3; 4]) -> f64 {
    -(p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0])
}

/// The smallest dihedral angle of a tetrahedron, in radians; 0 when it is flat or inverted.
fn min_dihedral(p: [DVec3; 4]) -> f64 {
    if signed_volume(p) == 0.0 || !signed_volume(p).is_finite() {
        return 0.0;
    }
    // Outward normals of the faces opposite each vertex.
    let normal = |i: usize| {
        let (a, b, c) = match i {
            0 => (p[1], p[2], p[3]),
            1 => (p[0], p[2], p[3]),
            2 => (p[0], p[1], p[3]),
            _ => (p[0], p[1], p[2]),
        };
        let n = (b - a).cross(c - a).normalize_or_zero();
        if n.dot(p[i] - a) > 0.0 { -n } else { n }
    };
    let n = [normal(0), normal(1), normal(2), normal(3)];
    let mut min = std::f64::consts::PI;
    for i in 0..4 {
        for j in i + 1..4 {
            let angle = std::f64::consts::PI - n[i].dot(n[j]).clamp(-1.0, 1.0).acos();
            min = min.min(angle);
        }
    }
    min
}

/// Chooses the orientation of every prism's edges by `split`, for a surface of `n` vertices
/// whose halo vertices (offsets) are `positions` (the geometry only matters to `quality`).
pub fn plan(
    corners: &[Corners],
    positions: &[DVec3],
    n: usize,
    split: Split,
) -> (Vec<[bool; 3]>, SplitStats) {
    let edges = Edges::new(corners);
    let mut stats = SplitStats::default();
    // Per prism, the orientation of its three edges.
    let mut forward: Vec<[bool; 3]> = match split {
        Split::Paper => vec![[true, true, false]; corners.len()],
        Split::GlobalOrder | Split::Quality => corners
            .iter()
            .map(|c| [0, 1, 2].map(|k| c.up(k, true)))
            .collect(),
    };
    stats.mismatches_initial = edges
        .iter()
        .filter(|u| mismatched(corners, &forward, u))
        .count();
    match split {
        Split::GlobalOrder => {}
        Split::Paper => paper_flips(corners, &edges, &mut forward, &mut stats),
        Split::Quality => quality_flips(corners, &edges, positions, n, &mut forward, &mut stats),
    }
    stats.mismatches_final = edges
        .iter()
        .filter(|u| mismatched(corners, &forward, u))
        .count();
    (forward, stats)
}

/// Whether edge k of prism t goes up, with the prisms' edges oriented by `forward`.
fn edge_up(corners: &[Corners], forward: &[[bool; 3]], t: u32, k: u8) -> bool {
    corners[t as usize].up(k as usize, forward[t as usize][k as usize])
}

/// Whether the prisms using one edge (`uses`) split its quad differently.
fn mismatched(corners: &[Corners], forward: &[[bool; 3]], uses: &[(u32, u8)]) -> bool {
    let (t0, k0) = uses[0];
    !corners[t0 as usize].degenerate(k0 as usize)
        && uses
            .iter()
            .any(|&(t, k)| edge_up(corners, forward, t, k) != edge_up(corners, forward, t0, k0))
}

/// `Split::Paper`: flips diagonals where prisms disagree and one of them stays splittable
/// (Fig. 4b), then makes the second prism of each edge still mismatched take the first's
/// diagonal, cyclic (Fig. 4d).
fn paper_flips(
    corners: &[Corners],
    edges: &Edges,
    forward: &mut [[bool; 3]],
    stats: &mut SplitStats,
) {
    let up = |forward: &[[bool; 3]], t: u32, k: u8| edge_up(corners, forward, t, k);
    // Fig. 4b: flip a prism's diagonal on the shared quad when it stays splittable.
    let mut changed = true;
    while changed {
        changed = false;
        for uses in edges.iter() {
            if !mismatched(corners, forward, uses) {
                continue;
            }
            let (t0, k0) = uses[0];
            for &(t, k) in &uses[1..] {
                if up(forward, t, k) == up(forward, t0, k0) {
                    continue;
                }
                let mut f = forward[t as usize];
                f[k as usize] = !f[k as usize];
                if corners[t as usize].splittable(f) {
                    forward[t as usize] = f;
                    stats.flips += 1;
                    changed = true;
                    continue;
                }
                // The first prism flips instead, if that leaves it and every other
                // user of the edge consistent.
                let mut f0 = forward[t0 as usize];
                f0[k0 as usize] = !f0[k0 as usize];
                if uses.len() == 2 && corners[t0 as usize].splittable(f0) {
                    forward[t0 as usize] = f0;
                    stats.flips += 1;
                    changed = true;
                }
            }
        }
    }
    // Fig. 4d: where neither prism can flip, the second takes the first's diagonal and
    // becomes cyclic; it gets an inserted vertex.
    for uses in edges.iter() {
        if !mismatched(corners, forward, uses) {
            continue;
        }
        let (t0, k0) = uses[0];
        for &(t, k) in &uses[1..] {
            if up(forward, t, k) != up(forward, t0, k0) {
                forward[t as usize][k as usize] = !forward[t as usize][k as usize];
            }
        }
    }
}

/// `Split::Quality`: in two passes over the edges, flips an edge's diagonal in every prism
/// using it where that keeps them splittable and improves their worst tetrahedron (on the
/// halo vertices `positions` of a surface of `n` vertices).
fn quality_flips(
    corners: &[Corners],
    edges: &Edges,
    positions: &[DVec3],
    n: usize,
    forward: &mut [[bool; 3]],
    stats: &mut SplitStats,
) {
    let prism_quality = |t: usize, f: [bool; 3]| -> f64 {
        let f = corners[t].effective(f);
        corners[t]
            .layers(n as u32)
            .into_iter()
            .flat_map(|v| prism_tets(v, f, u32::MAX))
            .map(|tet| {
                let p = tet.map(|i| positions[i as usize]);
                // Inverted is worst.
                if signed_volume(p) <= 0.0 {
                    -1.0
                } else {
                    min_dihedral(p)
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    // Each prism's worst tetrahedron, kept up to date as diagonals flip.
    let mut quality: Vec<f64> = (0..corners.len())
        .map(|t| prism_quality(t, forward[t]))
        .collect();
    for _pass in 0..2 {
        for uses in edges.iter() {
            if corners[uses[0].0 as usize].degenerate(uses[0].1 as usize) {
                continue;
            }
            let flipped: Vec<(usize, [bool; 3])> = uses
                .iter()
                .map(|&(t, k)| {
                    let mut f = forward[t as usize];
                    f[k as usize] = !f[k as usize];
                    (t as usize, f)
                })
                .collect();
            if flipped.iter().any(|&(t, f)| !corners[t].splittable(f)) {
                continue;
            }
            let before = flipped
                .iter()
                .map(|&(t, _)| quality[t])
                .fold(f64::INFINITY, f64::min);
            let after: Vec<f64> = flipped.iter().map(|&(t, f)| prism_quality(t, f)).collect();
            if after.iter().copied().fold(f64::INFINITY, f64::min) > before + 1e-12 {
                for ((t, f), q) in flipped.into_iter().zip(after) {
                    forward[t] = f;
                    quality[t] = q;
                }
                stats.flips += 1;
            }
        }
    }
}

/// The tetrahedra of both layers of every prism, with a vertex inserted at the centre of each
/// layer whose pattern (in effect) is cyclic. `positions` are the halo's offset and surface
/// vertices.
pub fn emit(
    corners: &[Corners],
    forward: &[[bool; 3]],
    positions: &[DVec3],
    n: usize,
    stats: SplitStats,
) -> Tetrahedra {
    let mut out = Tetrahedra {
        stats,
        ..Tetrahedra::default()
    };
    out.tets.reserve(6 * corners.len());
    for (t, c) in corners.iter().enumerate() {
        let f = c.effective(forward[t]);
        for v in c.layers(n as u32) {
            let centre_index = (positions.len() + out.inserted.len()) as u32;
            out.tets.extend(prism_tets(v, f, centre_index));
            if cyclic(f) {
                out.inserted.push(centre(v, positions));
                out.inserted_in.push(t as u32);
                out.inserted_over.push(v);
            }
        }
    }
    out.stats.inserted_vertices = out.inserted.len();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acyclic_patterns_give_three_positive_tetrahedra_of_the_prism_volume() {
        let at = |i: usize| DVec3::from_array(REFERENCE[i]);
        for bits in 0..8u8 {
            let f = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
            let tets: Vec<[usize; 4]> = if cyclic(f) {
                centre_tets(f)
            } else {
                acyclic_tets(f)
            };
            let mut volume = 0.0;
            for tet in &tets {
                let p = tet.map(at);
                let v = signed_volume(p) / 6.0;
                let o = robust::orient3d(
                    coord(REFERENCE[tet[0]]),
                    coord(REFERENCE[tet[1]]),
                    coord(REFERENCE[tet[2]]),
                    coord(REFERENCE[tet[3]]),
                );
                assert!(o > 0.0 && v > 0.0, "{f:?} {tet:?}");
                volume += v;
            }
            assert!((volume - 0.5).abs() < 1e-15, "{f:?}: {volume}");
            assert_eq!(tets.len(), if cyclic(f) { 8 } else { 3 });
        }
    }
}
