//! Narrow phase: what two triangles' intersection is, decided with perturbed `orient3d`.
//!
//! In the perturbed mesh (see [`super::sos`]) no four vertices are coplanar, so two
//! triangles that share no vertex meet in nothing or in a segment whose two ends are each
//! an edge of one crossing the other; two that share one vertex P meet in P alone or in a
//! segment from P to one such crossing (a branch point of the projection, as at a
//! cross-cap, ends there); two that share an edge meet only along it.

use super::sos::{orient3d, orient3d_filtered, orient3d_sign};
use glam::DVec3;

/// A curve vertex, named by what it is rather than where it is: global vertex and
/// triangle indices over all sheets together.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Node {
    /// The edge (its two vertices, smaller first) crosses the triangle `face`.
    Crossing {
        /// The edge's vertices, smaller first.
        edge: [u32; 2],
        /// The triangle it crosses.
        face: u32,
    },
    /// A mesh vertex where two triangles of its star meet along a segment that ends there.
    Vertex(u32),
}

/// Part of a curve: the intersection of two triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Its two ends.
    pub ends: [Node; 2],
    /// The two triangles, smaller first.
    pub tris: [u32; 2],
}

/// What a pair of triangles gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pair {
    /// They do not cross (possibly they share a vertex or an edge).
    Apart,
    /// They cross along a segment.
    Cross(Segment),
    /// The perturbed predicates gave a number of crossings that no segment has: a broken
    /// predicate or degenerate input such as a zero-area triangle. Counted, never dropped.
    Inconsistent(u32, u32),
}

/// All sheets' vertices and triangles with global indices.
#[derive(Clone, Debug, Default)]
pub struct Soup {
    /// Positions.
    pub positions: Vec<DVec3>,
    /// w-depth of each vertex.
    pub w: Vec<f64>,
    /// Triangles.
    pub tris: Vec<[u32; 3]>,
    /// Each triangle's plane for the floating-point filter ([`Soup::prepare`]); computed
    /// on the fly when empty.
    planes: Vec<FilteredPlane>,
}

impl Soup {
    /// Computes every triangle's filtered plane once, for the many pairs each is in.
    pub fn prepare(&mut self) {
        let p = &self.positions;
        self.planes = self
            .tris
            .iter()
            .map(|t| FilteredPlane::new(t.map(|v| p[v as usize])))
            .collect();
    }

    /// The perturbed sign of `orient3d`: floating point where its error bound allows,
    /// else exact arithmetic and the perturbation.
    #[inline]
    fn sign(&self, a: u32, b: u32, c: u32, d: u32) -> i8 {
        let p = &self.positions;
        let q = [p[a as usize], p[b as usize], p[c as usize], p[d as usize]];
        match orient3d_filtered(q[0], q[1], q[2], q[3]) {
            0 => orient3d_sign(q, [a, b, c, d]).1,
            s => s,
        }
    }

    /// Whether the edge (p, q), whose ends lie on opposite sides of the plane of `t`, passes
    /// through the triangle `t`.
    #[inline]
    fn through(&self, p: u32, q: u32, t: [u32; 3]) -> bool {
        let s0 = self.sign(p, q, t[0], t[1]);
        s0 == self.sign(p, q, t[1], t[2]) && s0 == self.sign(p, q, t[2], t[0])
    }

    /// The intersection of triangles `a` < `b`. A triangle naming one vertex twice has no
    /// interior and crosses nothing.
    pub fn pair(&self, a: u32, b: u32) -> Pair {
        let (ta, tb) = (self.tris[a as usize], self.tris[b as usize]);
        let proper = |t: [u32; 3]| t[0] != t[1] && t[1] != t[2] && t[2] != t[0];
        if !proper(ta) || !proper(tb) {
            return Pair::Apart;
        }
        let mut shared = 0;
        let mut at = [0usize; 2];
        for (i, va) in ta.iter().enumerate() {
            for (j, vb) in tb.iter().enumerate() {
                if va == vb {
                    shared += 1;
                    at = [i, j];
                }
            }
        }
        if shared < 2 && (self.clearly_aside(b, ta) || self.clearly_aside(a, tb)) {
            return Pair::Apart;
        }
        match shared {
            0 => self.disjoint(a, b, ta, tb),
            1 => self.fan(a, b, ta, tb, at),
            _ => Pair::Apart,
        }
    }

    /// Whether floating point alone shows every vertex of `t` strictly on one side of the
    /// plane of triangle `of` (then the two cannot cross, whatever the perturbation).
    /// Vertices of `of` itself lie in its plane and do not count.
    #[inline]
    fn clearly_aside(&self, of: u32, t: [u32; 3]) -> bool {
        let p = &self.positions;
        let plane = self.tris[of as usize];
        let f = match self.planes.get(of as usize) {
            Some(f) => *f,
            None => FilteredPlane::new(plane.map(|v| p[v as usize])),
        };
        let mut side = 0;
        for v in t {
            if v == plane[0] || v == plane[1] || v == plane[2] {
                continue;
            }
            match f.side(p[v as usize]) {
                0 => return false,
                x if side == 0 => side = x,
                x if x != side => return false,
                _ => {}
            }
        }
        side != 0
    }

    fn disjoint(&self, a: u32, b: u32, ta: [u32; 3], tb: [u32; 3]) -> Pair {
        let side_a = ta.map(|v| self.sign(tb[0], tb[1], tb[2], v));
        if side_a[0] == side_a[1] && side_a[1] == side_a[2] {
            return Pair::Apart;
        }
        let side_b = tb.map(|v| self.sign(ta[0], ta[1], ta[2], v));
        if side_b[0] == side_b[1] && side_b[1] == side_b[2] {
            return Pair::Apart;
        }
        let mut ends = [Node::Vertex(u32::MAX); 2];
        let mut found = 0;
        for (t, side, other, face) in [(ta, side_a, tb, b), (tb, side_b, ta, a)] {
            for k in 0..3 {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                if side[k] != side[(k + 1) % 3] && self.through(p, q, other) {
                    if found < 2 {
                        ends[found] = crossing(p, q, face);
                    }
                    found += 1;
                }
            }
        }
        match found {
            0 => Pair::Apart,
            2 => Pair::Cross(Segment { ends, tris: [a, b] }),
            _ => Pair::Inconsistent(a, b),
        }
    }

    /// Triangles sharing the vertex at `ta[at[0]]` = `tb[at[1]]`.
    fn fan(&self, a: u32, b: u32, ta: [u32; 3], tb: [u32; 3], at: [usize; 2]) -> Pair {
        let apex = ta[at[0]];
        let (q, r) = (ta[(at[0] + 1) % 3], ta[(at[0] + 2) % 3]);
        let (s, u) = (tb[(at[1] + 1) % 3], tb[(at[1] + 2) % 3]);
        let end = if self.sign(tb[0], tb[1], tb[2], q) != self.sign(tb[0], tb[1], tb[2], r)
            && self.through(q, r, tb)
        {
            crossing(q, r, b)
        } else if self.sign(ta[0], ta[1], ta[2], s) != self.sign(ta[0], ta[1], ta[2], u)
            && self.through(s, u, ta)
        {
            crossing(s, u, a)
        } else {
            return Pair::Apart;
        };
        Pair::Cross(Segment {
            ends: [Node::Vertex(apex), end],
            tris: [a, b],
        })
    }

    /// Where a node is, the w-depth of the sheet of its edge and of its face there (the
    /// same for a vertex), and how degenerate it is.
    pub fn place(&self, node: Node) -> Placed {
        let p = &self.positions;
        match node {
            Node::Vertex(v) => Placed {
                position: p[v as usize],
                w: [self.w[v as usize]; 2],
                coplanar: false,
                on_plane: false,
            },
            Node::Crossing { edge, face } => {
                let f = self.tris[face as usize].map(|v| p[v as usize]);
                let (a, b) = (p[edge[0] as usize], p[edge[1] as usize]);
                let oa = orient3d(f[0], f[1], f[2], a);
                let ob = orient3d(f[0], f[1], f[2], b);
                let coplanar = oa == 0.0 && ob == 0.0;
                let t = if coplanar {
                    clip_middle(a, b, f)
                } else {
                    (oa / (oa - ob)).clamp(0.0, 1.0)
                };
                let x = a + (b - a) * t;
                let (wa, wb) = (self.w[edge[0] as usize], self.w[edge[1] as usize]);
                let wf = self.tris[face as usize].map(|v| self.w[v as usize]);
                let l = barycentric(x, f);
                Placed {
                    position: x,
                    w: [
                        wa + (wb - wa) * t,
                        l[0] * wf[0] + l[1] * wf[1] + l[2] * wf[2],
                    ],
                    coplanar,
                    on_plane: oa == 0.0 || ob == 0.0,
                }
            }
        }
    }
}

/// A triangle's plane for floating-point side tests: the determinant
/// det[f1 - f0; f2 - f0; p - f0] expanded along its last row, with Shewchuk's error bound
/// for a determinant of three differences (the same computation as `orient3d`'s first
/// stage, with the cofactors computed once for every point tested).
#[derive(Clone, Copy, Debug)]
struct FilteredPlane {
    base: DVec3,
    normal: DVec3,
    permanent: DVec3,
}

impl FilteredPlane {
    #[inline]
    fn new(f: [DVec3; 3]) -> Self {
        let (e1, e2) = (f[1] - f[0], f[2] - f[0]);
        let c = [
            e1.y * e2.z,
            e1.z * e2.y,
            e1.z * e2.x,
            e1.x * e2.z,
            e1.x * e2.y,
            e1.y * e2.x,
        ];
        FilteredPlane {
            base: f[0],
            normal: DVec3::new(c[0] - c[1], c[2] - c[3], c[4] - c[5]),
            permanent: DVec3::new(
                c[0].abs() + c[1].abs(),
                c[2].abs() + c[3].abs(),
                c[4].abs() + c[5].abs(),
            ),
        }
    }

    /// The sign of `orient3d(f0, f1, f2, p)` when floating point decides it, else 0.
    #[inline]
    fn side(&self, p: DVec3) -> i8 {
        const BOUND: f64 = 7.771_561_172_376_103e-16;
        let d = p - self.base;
        let det = self.normal.dot(d);
        let bound = BOUND * self.permanent.dot(d.abs());
        // orient3d(f0, f1, f2, p) = -det[f1 - f0; f2 - f0; p - f0].
        if det > bound {
            -1
        } else if -det > bound {
            1
        } else {
            0
        }
    }
}

/// A node placed: [`Soup::place`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// Where it is.
    pub position: DVec3,
    /// w of the sheet of its edge and of its face there.
    pub w: [f64; 2],
    /// Its edge lies in its face's plane (the point then stands for a coplanar overlap and
    /// is placed in the middle of it).
    pub coplanar: bool,
    /// A vertex of its edge lies exactly in its face's plane: the perturbation decided it.
    pub on_plane: bool,
}

fn crossing(p: u32, q: u32, face: u32) -> Node {
    Node::Crossing {
        edge: [p.min(q), p.max(q)],
        face,
    }
}

/// Drops the coordinate along which the triangle's normal is largest.
fn flatten(f: [DVec3; 3]) -> impl Fn(DVec3) -> [f64; 2] {
    let n = (f[1] - f[0]).cross(f[2] - f[0]).abs();
    let axis = if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    };
    move |p: DVec3| match axis {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

/// Barycentric coordinates of `x` (a point in or near the triangle's plane), clamped to
/// the triangle.
pub fn barycentric(x: DVec3, f: [DVec3; 3]) -> [f64; 3] {
    let flat = flatten(f);
    let [a, b, c, x] = [flat(f[0]), flat(f[1]), flat(f[2]), flat(x)];
    let area = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let total = area(a, b, c);
    let l = [area(x, b, c), area(a, x, c), area(a, b, x)].map(|v| (v / total).max(0.0));
    let sum = l[0] + l[1] + l[2];
    if total == 0.0 || !sum.is_finite() || sum == 0.0 {
        return [1.0 / 3.0; 3];
    }
    l.map(|v| v / sum)
}

/// For a segment lying in the triangle's plane: the parameter of the middle of the part of
/// it inside the triangle (Cyrus-Beck clipping in the triangle's flattened plane).
fn clip_middle(a: DVec3, b: DVec3, f: [DVec3; 3]) -> f64 {
    let flat = flatten(f);
    let [pa, pb] = [flat(a), flat(b)];
    let t = [flat(f[0]), flat(f[1]), flat(f[2])];
    let orientation = {
        let e = [t[1][0] - t[0][0], t[1][1] - t[0][1]];
        let g = [t[2][0] - t[0][0], t[2][1] - t[0][1]];
        (e[0] * g[1] - e[1] * g[0]).signum()
    };
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        // Inside is where orientation * cross(q - p, x - p) >= 0.
        let side = |x: [f64; 2]| {
            orientation * ((q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0]))
        };
        let (sa, sb) = (side(pa), side(pb));
        if sa < 0.0 && sb < 0.0 {
            return 0.5;
        }
        if sa < 0.0 {
            lo = lo.max(sa / (sa - sb));
        } else if sb < 0.0 {
            hi = hi.min(sa / (sa - sb));
        }
    }
    if lo <= hi { 0.5 * (lo + hi) } else { 0.5 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soup(points: &[[f64; 3]], tris: &[[u32; 3]]) -> Soup {
        Soup {
            positions: points.iter().map(|&p| DVec3::from(p)).collect(),
            w: points.iter().map(|p| p[0]).collect(),
            tris: tris.to_vec(),
            planes: Vec::new(),
        }
    }

    #[test]
    fn two_crossing_triangles_meet_in_one_segment() {
        let s = soup(
            &[
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [0.5, 0.5, -1.0],
                [0.5, 0.5, 1.0],
                [3.0, 3.0, 0.5],
            ],
            &[[0, 1, 2], [3, 4, 5]],
        );
        let Pair::Cross(seg) = s.pair(0, 1) else {
            panic!("no crossing")
        };
        let mut ends = seg.ends;
        ends.sort();
        // Edge 3-4 pierces triangle 0; triangle 0's edge 1-2 pierces triangle 1.
        assert_eq!(
            ends,
            [
                Node::Crossing {
                    edge: [1, 2],
                    face: 1
                },
                Node::Crossing {
                    edge: [3, 4],
                    face: 0
                },
            ]
        );
        let placed = s.place(ends[1]);
        assert!(!placed.coplanar && !placed.on_plane);
        assert!((placed.position - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
    }

    #[test]
    fn the_plane_filter_agrees_with_orient3d() {
        let mut unit = crate::intersect::lcg(11);
        let mut next = || unit() - 0.5;
        let mut decided = 0;
        for k in 0..20000 {
            let f = [(); 3].map(|_| DVec3::new(next(), next(), next()));
            let mut p = DVec3::new(next(), next(), next());
            if k % 2 == 0 {
                p = f[0] + (f[1] - f[0]) * next() + (f[2] - f[0]) * next();
            }
            let s = FilteredPlane::new(f).side(p);
            if s != 0 {
                decided += 1;
                let exact = orient3d(f[0], f[1], f[2], p);
                assert_eq!(s as f64, exact.signum(), "{f:?} {p:?}");
            }
        }
        assert!(decided > 10000, "decided only {decided}");
    }

    #[test]
    fn neighbours_meet_only_where_they_share() {
        let s = soup(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.3],
                [-1.0, -1.0, 0.2],
            ],
            &[[0, 1, 2], [1, 3, 2], [0, 4, 1]],
        );
        assert_eq!(s.pair(0, 1), Pair::Apart);
        assert_eq!(s.pair(0, 2), Pair::Apart);
    }
}
