//! Exact tests of closed segments and triangles in 3D, unperturbed: where the curves
//! (`intersect`) perturb every degeneracy away, a mesh's boundary must be judged as it is,
//! a vertex exactly on a face or two faces lying on one another being faults. Every
//! decision is a sign of `robust::orient3d` or of `robust::orient2d` on coordinates dropped
//! to a plane (dropping a coordinate is exact, and keeps the signs of coplanar points'
//! orientations where the dropped axis is not parallel to their plane).

use robust::{Coord, Coord3D};

/// A point.
pub type P = [f64; 3];

fn c3(p: P) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// The sign of `orient3d(a, b, c, d)`: 1 when d lies on the side of plane abc that abc,
/// seen from it, turns clockwise; -1 on the other; 0 on the plane.
pub fn orient(a: P, b: P, c: P, d: P) -> i8 {
    sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// A plane's points seen along one coordinate axis.
#[derive(Clone, Copy)]
struct Flat(usize);

impl Flat {
    /// The axis along which triangle abc (not degenerate) projects to a triangle that is
    /// not degenerate either; `None` for a degenerate triangle.
    fn of(a: P, b: P, c: P) -> Option<Self> {
        (0..3).map(Flat).find(|f| f.orient(a, b, c) != 0)
    }

    fn at(self, p: P) -> Coord<f64> {
        let (i, j) = match self.0 {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        Coord { x: p[i], y: p[j] }
    }

    fn orient(self, a: P, b: P, c: P) -> i8 {
        sign(robust::orient2d(self.at(a), self.at(b), self.at(c)))
    }

    /// Whether p (in the plane) lies in the closed triangle abc.
    fn in_triangle(self, p: P, [a, b, c]: [P; 3]) -> bool {
        let s = [
            self.orient(a, b, p),
            self.orient(b, c, p),
            self.orient(c, a, p),
        ];
        s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
    }

    /// Whether p (collinear with a and b) lies in the closed segment ab.
    fn in_segment(self, p: P, a: P, b: P) -> bool {
        let (p, a, b) = (self.at(p), self.at(a), self.at(b));
        p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
    }

    /// Whether the closed segments pq and ab (in the plane) meet.
    fn segments_meet(self, p: P, q: P, a: P, b: P) -> bool {
        let [d1, d2, d3, d4] = [
            self.orient(a, b, p),
            self.orient(a, b, q),
            self.orient(p, q, a),
            self.orient(p, q, b),
        ];
        if d1 * d2 < 0 && d3 * d4 < 0 {
            return true;
        }
        (d1 == 0 && self.in_segment(p, a, b))
            || (d2 == 0 && self.in_segment(q, a, b))
            || (d3 == 0 && self.in_segment(a, p, q))
            || (d4 == 0 && self.in_segment(b, p, q))
    }
}

/// Whether p lies in the closed triangle t (not degenerate).
pub fn point_in_triangle(p: P, t: [P; 3]) -> bool {
    let [a, b, c] = t;
    orient(a, b, c, p) == 0 && Flat::of(a, b, c).is_some_and(|f| f.in_triangle(p, t))
}

/// Whether the closed segment pq meets the closed triangle t (not degenerate).
pub fn segment_meets_triangle(p: P, q: P, t: [P; 3]) -> bool {
    let [a, b, c] = t;
    let (op, oq) = (orient(a, b, c, p), orient(a, b, c, q));
    if op * oq > 0 {
        return false;
    }
    if op == 0 && oq == 0 {
        let Some(f) = Flat::of(a, b, c) else {
            return false;
        };
        return f.in_triangle(p, t)
            || f.in_triangle(q, t)
            || f.segments_meet(p, q, a, b)
            || f.segments_meet(p, q, b, c)
            || f.segments_meet(p, q, c, a);
    }
    // The segment meets the plane in one point; the line pq passes through the closed
    // triangle when it passes each edge on the same side (or through it).
    let s = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
}

/// Whether x, in the plane of triangle t (seen along `f`), lies in t's closed angle at
/// corner `at`: the segment from that corner to x runs into t.
fn in_corner(f: Flat, t: [P; 3], at: usize, x: P) -> bool {
    let (p, u, v) = (t[at], t[(at + 1) % 3], t[(at + 2) % 3]);
    let s = f.orient(p, u, v);
    f.orient(p, u, x) * s >= 0 && f.orient(p, x, v) * s >= 0
}

/// Whether two closed triangles (given by vertex indices into `positions`, neither
/// degenerate, not the same triangle) meet anywhere beyond the hull of the vertices they
/// share: nothing when they share none, that vertex when they share one, that edge when
/// they share two. Anything more is the boundary crossing or touching itself.
pub fn triangles_meet(t: [u32; 3], u: [u32; 3], positions: &[P]) -> bool {
    let at = |i: u32| positions[i as usize];
    let (pt, pu) = (t.map(at), u.map(at));
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| t[i] == u[j])
        .collect();
    // Where u's corners lie against t's plane (a shared corner in it).
    let sides = [0, 1, 2].map(|j| {
        if t.contains(&u[j]) {
            0
        } else {
            orient(pt[0], pt[1], pt[2], pu[j])
        }
    });
    if sides.iter().all(|&s| s == 0) {
        let Some(f) = Flat::of(pt[0], pt[1], pt[2]) else {
            return false;
        };
        return coplanar_meet(f, pt, pu, &shared);
    }
    // The corners u does not share strictly on one side: u meets t's plane at most in
    // what they share.
    let own = (0..3).filter(|&j| !t.contains(&u[j]));
    if own.clone().all(|j| sides[j] > 0) || own.clone().all(|j| sides[j] < 0) {
        return false;
    }
    match shared.as_slice() {
        [] => {
            (0..3).any(|i| segment_meets_triangle(pt[i], pt[(i + 1) % 3], pu))
                || (0..3).any(|j| segment_meets_triangle(pu[j], pu[(j + 1) % 3], pt))
        }
        &[(i, j)] => {
            // The edges opposite the shared corner; the edges from it leave the other
            // triangle at once unless they lie in its plane, within its angle there.
            let (ti, uj) = ([(i + 1) % 3, (i + 2) % 3], [(j + 1) % 3, (j + 2) % 3]);
            let into = |tri: [P; 3], corner: usize, x: P| {
                orient(tri[0], tri[1], tri[2], x) == 0
                    && Flat::of(tri[0], tri[1], tri[2])
                        .is_some_and(|f| in_corner(f, tri, corner, x))
            };
            segment_meets_triangle(pt[ti[0]], pt[ti[1]], pu)
                || segment_meets_triangle(pu[uj[0]], pu[uj[1]], pt)
                || ti.iter().any(|&k| into(pu, j, pt[k]))
                || uj.iter().any(|&k| into(pt, i, pu[k]))
        }
        // Sharing an edge, not in one plane: they meet only along it.
        _ => false,
    }
}

/// [`triangles_meet`] for two triangles in one plane, seen along `f`.
fn coplanar_meet(f: Flat, pt: [P; 3], pu: [P; 3], shared: &[(usize, usize)]) -> bool {
    let edges = |p: [P; 3]| [0, 1, 2].map(|i| (p[i], p[(i + 1) % 3]));
    match *shared {
        [] => {
            edges(pt)
                .iter()
                .any(|&(a, b)| edges(pu).iter().any(|&(c, d)| f.segments_meet(a, b, c, d)))
                || pu.iter().any(|&x| f.in_triangle(x, pt))
                || pt.iter().any(|&x| f.in_triangle(x, pu))
        }
        // Each lies in its angle at the shared corner: they meet beyond it exactly where
        // the two angles overlap, where an edge of one runs into the other's angle.
        [(i, j)] => {
            [(i + 1) % 3, (i + 2) % 3]
                .iter()
                .any(|&k| in_corner(f, pu, j, pt[k]))
                || [(j + 1) % 3, (j + 2) % 3]
                    .iter()
                    .any(|&k| in_corner(f, pt, i, pu[k]))
        }
        // Sharing an edge: they overlap where the third corners are on the same side of it.
        [(i1, _), (i2, _)] => {
            let (a, b) = (pt[i1], pt[i2]);
            let x = pt[3 - i1 - i2];
            let y = pu
                .iter()
                .zip(0..3)
                .find(|&(_, j)| shared.iter().all(|&(_, sj)| sj != j))
                .map_or(x, |(&y, _)| y);
            f.orient(a, b, x) == f.orient(a, b, y)
        }
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [P; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn points_on_the_closed_triangle_are_in_it_exactly() {
        assert!(point_in_triangle([0.25, 0.25, 0.0], T));
        assert!(point_in_triangle([0.5, 0.5, 0.0], T), "on the hypotenuse");
        assert!(point_in_triangle([1.0, 0.0, 0.0], T), "a corner");
        assert!(!point_in_triangle([0.5, 0.5 + 1e-16, 0.0], T));
        assert!(!point_in_triangle([0.25, 0.25, 1e-300], T), "off the plane");
    }

    #[test]
    fn segments_through_touching_and_beside_the_triangle() {
        let up = |x: f64, y: f64| ([x, y, -1.0], [x, y, 1.0]);
        let (p, q) = up(0.2, 0.2);
        assert!(segment_meets_triangle(p, q, T));
        let (p, q) = up(0.5, 0.5);
        assert!(segment_meets_triangle(p, q, T), "through the edge");
        let (p, q) = up(0.6, 0.6);
        assert!(!segment_meets_triangle(p, q, T));
        // Ending on the plane inside, and short of it.
        assert!(segment_meets_triangle([0.2, 0.2, 0.0], [0.2, 0.2, 1.0], T));
        assert!(!segment_meets_triangle(
            [0.2, 0.2, 1e-200],
            [0.2, 0.2, 1.0],
            T
        ));
        // In the plane: crossing, touching a corner, beside.
        assert!(segment_meets_triangle([-1.0, 0.5, 0.0], [1.0, 0.5, 0.0], T));
        assert!(segment_meets_triangle([1.0, 0.0, 0.0], [2.0, 0.0, 0.0], T));
        assert!(!segment_meets_triangle([1.1, 0.0, 0.0], [2.0, 0.0, 0.0], T));
    }

    #[test]
    fn triangles_sharing_vertices_meet_only_beyond_them_when_they_overlap() {
        let pos: Vec<P> = vec![
            [0.0, 0.0, 0.0],  // 0
            [1.0, 0.0, 0.0],  // 1
            [0.0, 1.0, 0.0],  // 2
            [1.0, 1.0, 0.0],  // 3: flat beyond edge 1-2
            [0.2, 0.2, 0.0],  // 4: inside 0-1-2
            [0.0, 0.0, 1.0],  // 5: above 0
            [0.3, 0.3, -1.0], // 6
            [0.3, 0.3, 1.0],  // 7
            [2.0, 2.0, 0.0],  // 8
            [-1.0, 0.5, 0.0], // 9: beside 0's corner
        ];
        // Sharing an edge: flat on either side is fine, folded onto each other is not.
        assert!(!triangles_meet([0, 1, 2], [1, 3, 2], &pos));
        assert!(triangles_meet([0, 1, 2], [1, 4, 2], &pos));
        assert!(!triangles_meet([0, 1, 2], [1, 2, 5], &pos));
        // Sharing a corner: standing up, or lying in the plane outside, is fine; lying
        // inside the other, or piercing it, is not.
        assert!(!triangles_meet([0, 1, 2], [0, 5, 9], &pos));
        assert!(
            triangles_meet([0, 1, 2], [0, 5, 3], &pos),
            "an edge along the diagonal"
        );
        assert!(!triangles_meet([1, 2, 0], [2, 3, 8], &pos));
        assert!(
            triangles_meet([0, 1, 2], [0, 4, 5], &pos),
            "an edge into the corner"
        );
        assert!(triangles_meet([0, 1, 2], [1, 6, 7], &pos), "pierced");
        // Sharing nothing: pierced, touched by a corner, apart.
        assert!(triangles_meet([0, 1, 2], [5, 6, 7], &pos));
        assert!(
            triangles_meet([0, 1, 2], [4, 5, 8], &pos),
            "a corner on the face"
        );
        assert!(!triangles_meet([0, 1, 2], [3, 5, 8], &pos));
    }
}
