//! The boundary of a tetrahedral mesh, judged exactly: each face turned outward, its edges
//! and vertices manifold and consistently oriented, its components and which are cavities,
//! no vertex on a face not its own, no two faces meeting beyond what they share, and the
//! winding number just inside each component.

use super::exact::{P, orient, point_in_triangle, segment_meets_triangle, triangles_meet};
use crate::intersect::broad;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;
use serde::Serialize;

/// How many faces of a component the winding number is tried from before it is left
/// undecided: each try fails only where all six rays from a point inside the face's
/// tetrahedron pass exactly through an edge or a vertex of the boundary, or a face lies
/// between the point and the face.
const WINDING_TRIES: usize = 32;

/// What the boundary is.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Boundary {
    /// Faces of exactly one tetrahedron.
    pub faces: usize,
    /// Its connected pieces (faces joined across their edges).
    pub components: usize,
    /// Components that bound a hole inside the mesh (their faces turned into it): the
    /// mesh winds 0 times around it. Reported, not a fault.
    pub cavities: usize,
    /// Edges in more than two boundary faces (any set of tetrahedra puts an even number
    /// of boundary faces at every edge: the boundary is closed).
    pub nonmanifold_edges: usize,
    /// Edges of two boundary faces that run the same way along it: the two faces, turned
    /// away from their tetrahedra, face opposite ways.
    pub misoriented_edges: usize,
    /// Boundary vertices whose boundary faces form more than one fan (two pieces of the
    /// mesh touching at a point).
    pub nonmanifold_vertices: usize,
    /// Vertices lying on a boundary face or edge that is not their own (a T-junction: a
    /// face of one tetrahedron against smaller faces of others).
    pub hanging_vertices: usize,
    /// Pairs of boundary faces that meet beyond the vertices they share.
    pub self_intersections: usize,
    /// Components whose winding number just inside is not 1: where the mesh covers space
    /// twice (or turns inside out).
    pub wrong_winding: usize,
    /// Components whose winding number could not be decided.
    pub undecided_windings: usize,
    /// Faces with a vertex too small, against the mesh's largest coordinate, for the exact
    /// predicates: no fault is claimed of them (their tetrahedra are `undecidable`).
    pub undecided_faces: usize,
    /// The winding number of the whole boundary just inside each component (`None` where
    /// undecided), in the order of each component's first face.
    pub windings: Vec<Option<i64>>,
}

impl Boundary {
    /// The counts that fail a mesh, each with its name (as [`super::Certificate::failures`]
    /// and `halo4d check`'s table write it) and what it counts: declared once, here.
    pub fn fault_counts(&self) -> [(&'static str, usize, &'static str); 7] {
        [
            (
                "nonmanifold_edges",
                self.nonmanifold_edges,
                "edges in more than two boundary faces",
            ),
            (
                "misoriented_edges",
                self.misoriented_edges,
                "boundary edges whose faces face opposite ways",
            ),
            (
                "nonmanifold_vertices",
                self.nonmanifold_vertices,
                "boundary vertices where pieces touch",
            ),
            (
                "hanging_vertices",
                self.hanging_vertices,
                "vertices on a face or edge not their own",
            ),
            (
                "self_intersections",
                self.self_intersections,
                "pairs of boundary faces that meet",
            ),
            (
                "wrong_winding",
                self.wrong_winding,
                "boundary components around which the mesh does not wind once",
            ),
            (
                "undecided_windings",
                self.undecided_windings,
                "components whose winding number could not be decided",
            ),
        ]
    }
}

/// Fault bits of boundary faces ([`super::Fault`]), by boundary face (in the order given).
pub type FaceMarks = Vec<u32>;

/// A union-find over `n` items.
struct Sets(Vec<u32>);

impl Sets {
    fn new(n: usize) -> Self {
        Sets((0..n as u32).collect())
    }

    fn find(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let up = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = up;
            i = up;
        }
        i
    }

    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        // The smaller root wins, so that the sets do not depend on the order of unions.
        if a < b {
            self.0[b as usize] = a;
        } else {
            self.0[a as usize] = b;
        }
    }
}

/// Each boundary face turned outward: away from its tetrahedron's fourth vertex (as it is
/// where that tetrahedron is flat).
fn outward(faces: &[([u32; 3], u32)], positions: &[P]) -> Vec<[u32; 3]> {
    let at = |i: u32| positions[i as usize];
    faces
        .par_iter()
        .map(|&(k, o)| {
            if orient(at(k[0]), at(k[1]), at(k[2]), at(o)) < 0 {
                [k[0], k[2], k[1]]
            } else {
                k
            }
        })
        .collect()
}

/// A box around the points from `a` to `b`, as the BVH holds it: taken from `centre`, a
/// point near the mesh, so that the f32 boxes of a mesh far from the origin still tell its
/// faces apart, and rounded outward (no point of the box is left out: the difference is
/// moved a step outward before f32 rounds it outward again).
fn boxed(a: P, b: P, centre: P) -> Aabb {
    let lo = [0, 1, 2].map(|k| (a[k].min(b[k]) - centre[k]).next_down());
    let hi = [0, 1, 2].map(|k| (a[k].max(b[k]) - centre[k]).next_up());
    broad::outward(glam::DVec3::from(lo), glam::DVec3::from(hi))
}

/// Judges the boundary faces (each a sorted vertex triple with the fourth vertex of its
/// tetrahedron) on `positions` (scaled, as the checker's), with `centre` a point near them
/// (the boxes' origin) and which vertices are too small to decide on (`tiny`, see
/// [`crate::check::SAFE_RANGE`]): the [`Boundary`] and each face's fault bits. A face with
/// such a vertex is *undecided*: no fault is claimed of it or of a pair it is in (its
/// tetrahedron is counted `undecidable` already), and a winding number that would need it
/// is left undecided.
pub fn judge(
    faces: &[([u32; 3], u32)],
    positions: &[P],
    centre: P,
    tiny: &[bool],
) -> (Boundary, FaceMarks) {
    use super::Fault;
    let at = |i: u32| positions[i as usize];
    let outward = outward(faces, positions);
    let undecided: Vec<bool> = outward
        .iter()
        .map(|t| t.iter().any(|&i| tiny[i as usize]))
        .collect();
    let mut b = Boundary {
        faces: faces.len(),
        undecided_faces: undecided.iter().filter(|&&u| u).count(),
        ..Boundary::default()
    };
    let mut marks = vec![0u32; faces.len()];

    // Edges: each face's three, with the way it runs along it.
    let mut edges: Vec<([u32; 2], bool, u32)> = outward
        .iter()
        .enumerate()
        .flat_map(|(f, t)| {
            (0..3).map(move |i| {
                let (a, c) = (t[i], t[(i + 1) % 3]);
                ([a.min(c), a.max(c)], a < c, f as u32)
            })
        })
        .collect();
    edges.par_sort_unstable();
    let mut sets = Sets::new(faces.len());
    for group in edges.chunk_by(|x, y| x.0 == y.0) {
        let fault = match group {
            // An undecided face's way along the edge is not known.
            [(_, d1, f1), (_, d2, f2)]
                if d1 == d2 && !undecided[*f1 as usize] && !undecided[*f2 as usize] =>
            {
                b.misoriented_edges += 1;
                Fault::NONMANIFOLD
            }
            [_, _] => 0,
            _ => {
                b.nonmanifold_edges += 1;
                Fault::NONMANIFOLD
            }
        };
        for &(_, _, f) in group {
            marks[f as usize] |= fault;
            sets.union(group[0].2, f);
        }
    }
    drop(edges);

    // Vertices: the link of each (the opposite edges of its faces) one cycle, or one path
    // where the edges already fail.
    let mut fans: Vec<(u32, [u32; 2], u32)> = outward
        .iter()
        .enumerate()
        .flat_map(|(f, t)| (0..3).map(move |i| (t[i], [t[(i + 1) % 3], t[(i + 2) % 3]], f as u32)))
        .collect();
    fans.par_sort_unstable();
    let split: Vec<Vec<u32>> = fans
        .par_chunk_by(|x, y| x.0 == y.0)
        .filter_map(|group| (fan_pieces(group) > 1).then(|| group.iter().map(|g| g.2).collect()))
        .collect();
    b.nonmanifold_vertices = split.len();
    for f in split.into_iter().flatten() {
        marks[f as usize] |= Fault::NONMANIFOLD;
    }
    drop(fans);

    // Components, numbered in the order of their first face.
    let roots: Vec<u32> = (0..faces.len() as u32).map(|f| sets.find(f)).collect();
    let mut number = vec![u32::MAX; faces.len()];
    let mut component = vec![0u32; faces.len()];
    for (f, &r) in roots.iter().enumerate() {
        if number[r as usize] == u32::MAX {
            number[r as usize] = b.components as u32;
            b.components += 1;
        }
        component[f] = number[r as usize];
    }

    let tris: Vec<[P; 3]> = outward.iter().map(|t| t.map(at)).collect();
    let boxes: Vec<Aabb> = tris
        .iter()
        .map(|&[a, b, c]| {
            let lo = [0, 1, 2].map(|k| a[k].min(b[k]).min(c[k]));
            let hi = [0, 1, 2].map(|k| a[k].max(b[k]).max(c[k]));
            boxed(lo, hi, centre)
        })
        .collect();
    let bvh = broad::build(&boxes, 4);
    let shell = Shell {
        centre,
        undecided: &undecided,
        tris: &tris,
        component: &component,
        bvh: &bvh,
        boxes: &boxes,
    };

    // Hanging vertices: a boundary vertex on a boundary face that is not its own.
    let mut vertices: Vec<u32> = outward.iter().flatten().copied().collect();
    vertices.par_sort_unstable();
    vertices.dedup();
    let hanging: Vec<Vec<u32>> = vertices
        .par_iter()
        .filter(|&&v| !tiny[v as usize])
        .filter_map(|&v| {
            let x = at(v);
            let on: Vec<u32> = shell
                .near(x, x)
                .into_iter()
                .filter(|&f| {
                    !undecided[f as usize]
                        && !outward[f as usize].contains(&v)
                        && point_in_triangle(x, tris[f as usize])
                })
                .collect();
            (!on.is_empty()).then_some(on)
        })
        .collect();
    b.hanging_vertices = hanging.len();
    for f in hanging.into_iter().flatten() {
        marks[f as usize] |= Fault::HANGING;
    }

    // Faces meeting beyond what they share.
    let crossing: Vec<Vec<(u32, u32)>> =
        broad::self_pairs_par(&bvh, &boxes, Vec::new, |out, f, g| {
            if !undecided[f as usize]
                && !undecided[g as usize]
                && triangles_meet(outward[f as usize], outward[g as usize], positions)
            {
                out.push((f, g));
            }
        });
    for (f, g) in crossing.into_iter().flatten() {
        b.self_intersections += 1;
        marks[f as usize] |= Fault::SELF_INTERSECTION;
        marks[g as usize] |= Fault::SELF_INTERSECTION;
    }

    // The winding number just inside each component, and which are cavities.
    let mut firsts: Vec<Vec<u32>> = vec![Vec::new(); b.components];
    for (f, &c) in component.iter().enumerate() {
        if firsts[c as usize].len() < WINDING_TRIES && !undecided[f] && !tiny[faces[f].1 as usize] {
            firsts[c as usize].push(f as u32);
        }
    }
    let windings: Vec<Option<(i64, i64)>> = firsts
        .par_iter()
        .map(|tries| {
            tries
                .iter()
                .find_map(|&f| winding(f as usize, faces[f as usize].1, &shell, positions))
        })
        .collect();
    let mut component_marks = Vec::with_capacity(windings.len());
    for w in &windings {
        b.windings.push(w.map(|(total, _)| total));
        match w {
            Some((1, 0)) => b.cavities += 1,
            Some((1, _)) => {}
            Some(_) => b.wrong_winding += 1,
            None => b.undecided_windings += 1,
        }
        component_marks.push(match w {
            Some((1, 0)) => Fault::CAVITY,
            Some((1, _)) => 0,
            _ => Fault::WINDING,
        });
    }
    for (mark, &c) in marks.iter_mut().zip(&component) {
        *mark |= component_marks[c as usize];
    }
    (b, marks)
}

/// How many pieces the link of a vertex falls into: its faces' opposite edges joined at
/// shared ends.
fn fan_pieces(group: &[(u32, [u32; 2], u32)]) -> usize {
    let mut ends: Vec<u32> = group.iter().flat_map(|g| g.1).collect();
    ends.sort_unstable();
    ends.dedup();
    let index = |v: u32| ends.binary_search(&v).unwrap_or(0) as u32;
    let mut sets = Sets::new(ends.len());
    for (_, [x, y], _) in group {
        sets.union(index(*x), index(*y));
    }
    (0..ends.len() as u32)
        .filter(|&i| sets.find(i) == i)
        .count()
}

/// The boundary faces as the winding number reads them: their corners, their components,
/// and a BVH of their boxes.
struct Shell<'a> {
    centre: P,
    undecided: &'a [bool],
    tris: &'a [[P; 3]],
    component: &'a [u32],
    bvh: &'a Bvh2,
    boxes: &'a [Aabb],
}

impl Shell<'_> {
    /// The faces whose boxes meet the box of `a` and `b` (rounded outward: none is missed).
    fn near(&self, a: P, b: P) -> Vec<u32> {
        let query = boxed(a, b, self.centre);
        let mut out = Vec::new();
        self.bvh.aabb_traverse(query, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            let first = node.first_index as usize;
            out.extend(
                bvh.primitive_indices[first..first + node.prim_count as usize]
                    .iter()
                    .filter(|&&f| self.boxes[f as usize].intersect_aabb(&query)),
            );
            true
        });
        out
    }
}

/// The winding number of the boundary at a point just inside face f (its tetrahedron's
/// centroid, whose fourth vertex is `apex`), and that of f's own component alone; `None`
/// when the centroid is not strictly inside its tetrahedron (rounded onto a face of a
/// sliver), a boundary face lies between it and f's centroid, or each of the six rays from
/// it along the axes passes exactly through an edge or vertex. A ray along an axis meets
/// only the faces whose boxes its line crosses, found in the BVH: each component costs a
/// few queries, not a pass over every face.
fn winding(f: usize, apex: u32, shell: &Shell, positions: &[P]) -> Option<(i64, i64)> {
    let [a, b, c] = shell.tris[f];
    let d = positions[apex as usize];
    let mean = |ps: &[P]| {
        let n = ps.len() as f64;
        [0, 1, 2].map(|k| ps.iter().map(|p| p[k]).sum::<f64>() / n)
    };
    let p = mean(&[a, b, c, d]);
    // Strictly inside: on the tetrahedron's side of each of its four faces.
    let inside = [(a, b, c, d), (a, b, d, c), (a, c, d, b), (b, c, d, a)]
        .iter()
        .all(|&(x, y, z, w)| {
            let side = orient(x, y, z, w);
            side != 0 && orient(x, y, z, p) == side
        });
    if !inside {
        return None;
    }
    let g = mean(&[a, b, c]);
    let blocked = shell.near(p, g).into_iter().any(|j| {
        j as usize != f
            && (shell.undecided[j as usize] || segment_meets_triangle(p, g, shell.tris[j as usize]))
    });
    if blocked {
        return None;
    }
    let own = shell.component[f];
    'rays: for (axis, sign) in [
        (0, 1.0),
        (1, 1.0),
        (2, 1.0),
        (0, -1.0),
        (1, -1.0),
        (2, -1.0),
    ] {
        // The positions lie within [-1, 1]^3: 2 is past every face.
        let mut q = p;
        q[axis] = 2.0 * sign;
        let (mut total, mut mine) = (0, 0);
        for j in shell.near(p, q) {
            if shell.undecided[j as usize] {
                continue 'rays;
            }
            let t = shell.tris[j as usize];
            let (op, oq) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
            if op * oq > 0 {
                continue;
            }
            if op == 0 || oq == 0 {
                if segment_meets_triangle(p, q, t) {
                    continue 'rays;
                }
                continue;
            }
            let s = [
                orient(p, q, t[0], t[1]),
                orient(p, q, t[1], t[2]),
                orient(p, q, t[2], t[0]),
            ];
            if s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0) {
                // Leaving through an outward face counts +1.
                let w = i64::from(op);
                total += w;
                if shell.component[j as usize] == own {
                    mine += w;
                }
            } else if s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0) {
                continue 'rays;
            }
        }
        return Some((total, mine));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::kuhn_cube;
    use crate::check::examine_tetrahedra;

    /// Two Kuhn cubes, the second moved by `by`, as one mesh examined: its boundary faces,
    /// scaled positions and centre.
    fn two_cubes(by: [f64; 3]) -> crate::check::Examined {
        let (mut p, mut t) = kuhn_cube(3);
        let (q, s) = kuhn_cube(2);
        let n = p.len() as u32;
        p.extend(q.iter().map(|x| [x[0] + by[0], x[1] + by[1], x[2] + by[2]]));
        t.extend(s.iter().map(|x| x.map(|i| i + n)));
        examine_tetrahedra(&p, &t)
    }

    /// The solid angle of triangle abc seen from x (Van Oosterom and Strackee), over 4 pi:
    /// the generalized winding number's share of the face, in floating point.
    fn solid_angle(x: P, [a, b, c]: [P; 3]) -> f64 {
        let d = |p: P| [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        let (a, b, c) = (d(a), d(b), d(c));
        let len = |v: P| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dot = |u: P, v: P| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        let (la, lb, lc) = (len(a), len(b), len(c));
        let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        2.0 * det.atan2(den) / (4.0 * std::f64::consts::PI)
    }

    #[test]
    fn the_bvh_finds_every_crossing_pair_that_all_pairs_find() {
        for by in [
            [1.5, 0.5, 0.5],
            [3.0, 0.0, 0.0],
            [0.5, 0.5, 0.5],
            [10.0, 0.0, 0.0],
        ] {
            let e = two_cubes(by);
            let (faces, positions, centre) = (e.boundary, e.scaled, e.centre);
            let (b, _) = judge(&faces, &positions, centre, &vec![false; positions.len()]);
            let outward = outward(&faces, &positions);
            let mut all = 0;
            for i in 0..outward.len() {
                for j in i + 1..outward.len() {
                    all += usize::from(triangles_meet(outward[i], outward[j], &positions));
                }
            }
            assert_eq!(b.self_intersections, all, "{by:?}");
            // Crossing, and touching face to face, meet; inside or apart, they do not.
            let meet = by[0] == 1.5 || by[0] == 3.0;
            assert_eq!(all > 0, meet, "{by:?}: {all}");
        }
    }

    #[test]
    fn the_exact_winding_numbers_are_the_solid_angles_sums() {
        // Nested (the second cube inside the first), touching face to face, apart: at the
        // centroid of every boundary face's tetrahedron.
        for by in [[0.5, 0.5, 0.5], [3.0, 0.0, 0.0], [10.0, 0.0, 0.0]] {
            let e = two_cubes(by);
            let (faces, positions, centre) = (e.boundary, e.scaled, e.centre);
            let (b, _) = judge(&faces, &positions, centre, &vec![false; positions.len()]);
            assert_eq!(b.undecided_windings, 0);
            let mut seen = Vec::new();
            let out = outward(&faces, &positions);
            let at = |i: u32| positions[i as usize];
            for &(k, o) in &faces {
                let t = [k[0], k[1], k[2], o].map(at);
                let x = [0, 1, 2].map(|c| t.iter().map(|p| p[c]).sum::<f64>() / 4.0);
                let sum: f64 = out.iter().map(|f| solid_angle(x, f.map(at))).sum();
                seen.push(sum.round() as i64);
            }
            let mut expected: Vec<i64> = b.windings.iter().map(|w| w.unwrap()).collect();
            expected.sort_unstable();
            seen.sort_unstable();
            seen.dedup();
            expected.dedup();
            assert_eq!(seen, expected, "{by:?}");
        }
    }
}
