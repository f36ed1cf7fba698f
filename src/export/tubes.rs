//! Tubes around the intersection curves: triangle meshes that every renderer draws. Blender's
//! Cycles and EEVEE do not render loose edges, and MeshLab mishandles glTF LINES, so the
//! `.glb` carries the curves as tubes (and their exact polylines as data, see
//! [`super::to_glb`]).
//!
//! Each curve point gets a ring of [`SIDES`] vertices in the plane across the curve there
//! (across the mean of the two segments' directions), turned from point to point by parallel
//! transport so that the tube does not twist; consecutive rings are joined by quads, a closed
//! curve's last ring to its first at the rotation that fits best, and an open curve's ends
//! are closed by flat caps. Every tube is thus a closed surface, its triangles
//! counter-clockwise seen from outside (glTF's front face). A curve whose points all coincide
//! gets no tube.

use crate::intersect::Curves;
use crate::motion::Polyline;
use glam::DVec3;
use std::f64::consts::TAU;

/// Vertices around each ring.
pub const SIDES: usize = 8;

/// The tubes of a scene's curves.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tubes {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Unit outward normals (across the curve on rings, along it on caps).
    pub normals: Vec<DVec3>,
    /// The curve point of each vertex, numbered through all curves in order.
    pub point: Vec<u32>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Tubes of `radius` (absolute) around every curve of `curves` with two or more distinct
/// points.
pub fn tubes(curves: &Curves, radius: f64) -> Tubes {
    let polylines: Vec<Polyline> = curves
        .curves
        .iter()
        .map(|c| (c.points.iter().map(|p| p.position).collect(), c.closed))
        .collect();
    tubes_of(&polylines, radius)
}

/// [`tubes`] of polylines given as their points and whether they close.
pub(crate) fn tubes_of(polylines: &[Polyline], radius: f64) -> Tubes {
    let mut out = Tubes::default();
    let mut first_point = 0u32;
    for (points, closed) in polylines {
        if let Some(frames) = frames(points, *closed) {
            out.tube(points, &frames, *closed, radius, first_point);
        }
        first_point += points.len() as u32;
    }
    out
}

/// The tangent and the transported normal at each point, or `None` when the points all
/// coincide (or are not finite).
fn frames(points: &[DVec3], closed: bool) -> Option<Vec<(DVec3, DVec3)>> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    // Unit direction of the segment from point k to the next (zero for a repeated point).
    let segments = if closed { n } else { n - 1 };
    let dir: Vec<DVec3> = (0..segments)
        .map(|k| (points[(k + 1) % n] - points[k]).normalize_or_zero())
        .collect();
    let first = dir.iter().copied().find(|d| *d != DVec3::ZERO)?;
    let mut tangents = Vec::with_capacity(n);
    let mut last = first;
    for k in 0..n {
        let before = if k > 0 || closed {
            dir[(k + segments - 1) % segments]
        } else {
            DVec3::ZERO
        };
        let after = dir.get(k).copied().unwrap_or(DVec3::ZERO);
        // At a reversal the two directions cancel: keep the last tangent.
        let t = (before + after).try_normalize().unwrap_or(last);
        tangents.push(t);
        last = t;
    }
    let mut normal = tangents[0].any_orthonormal_vector();
    let mut out = Vec::with_capacity(n);
    for t in tangents {
        normal = (normal - normal.dot(t) * t)
            .try_normalize()
            .unwrap_or_else(|| t.any_orthonormal_vector());
        out.push((t, normal));
    }
    Some(out)
}

impl Tubes {
    /// Appends the tube of one curve; its points are numbered from `first_point`.
    fn tube(
        &mut self,
        points: &[DVec3],
        frames: &[(DVec3, DVec3)],
        closed: bool,
        radius: f64,
        first_point: u32,
    ) {
        let base = self.positions.len() as u32;
        let ring = |k: usize, j: usize| base + (k * SIDES + j % SIDES) as u32;
        for (k, (&p, &(t, n))) in points.iter().zip(frames).enumerate() {
            let b = t.cross(n);
            for j in 0..SIDES {
                let (sin, cos) = (TAU * j as f64 / SIDES as f64).sin_cos();
                let radial = cos * n + sin * b;
                self.positions.push(p + radius * radial);
                self.normals.push(radial);
                self.point.push(first_point + k as u32);
            }
        }
        let count = points.len();
        let mut join = |k: usize, next: usize, shift: usize| {
            for j in 0..SIDES {
                let (a, b) = (ring(k, j), ring(k, j + 1));
                let (c, d) = (ring(next, j + shift), ring(next, j + 1 + shift));
                self.triangles.push([a, b, c]);
                self.triangles.push([b, d, c]);
            }
        };
        for k in 1..count {
            join(k - 1, k, 0);
        }
        if closed {
            // The last normal, carried on to the first tangent, is the first normal turned by
            // some angle about it; join each vertex to the first ring's nearest one.
            let (t0, n0) = frames[0];
            let carried = frames[count - 1].1 - frames[count - 1].1.dot(t0) * t0;
            let angle = carried.dot(t0.cross(n0)).atan2(carried.dot(n0));
            let step = (angle / TAU * SIDES as f64).round() as i64;
            join(count - 1, 0, step.rem_euclid(SIDES as i64) as usize);
        } else {
            for (k, outward) in [(0, -1.0), (count - 1, 1.0)] {
                let centre = self.positions.len() as u32;
                self.positions.push(points[k]);
                self.normals.push(outward * frames[k].0);
                self.point.push(first_point + k as u32);
                for j in 0..SIDES {
                    let (a, b) = (ring(k, j), ring(k, j + 1));
                    self.triangles.push(if outward > 0.0 {
                        [centre, a, b]
                    } else {
                        [centre, b, a]
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Signed volume enclosed by triangles counter-clockwise seen from outside.
    fn enclosed(t: &Tubes) -> f64 {
        t.triangles
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| t.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Whether every edge is in exactly two triangles, once each way.
    fn closed_and_oriented(t: &Tubes) -> bool {
        let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
        for f in &t.triangles {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
            }
        }
        edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
    }

    fn tubes(points: &[DVec3], closed: bool, radius: f64) -> Tubes {
        tubes_of(&[(points.to_vec(), closed)], radius)
    }

    #[test]
    fn a_straight_tube_encloses_its_prism_exactly() {
        let (r, l) = (0.1, 2.0);
        let pts = [
            DVec3::ZERO,
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(l, 0.0, 0.0),
        ];
        let t = tubes(&pts, false, r);
        assert_eq!(t.positions.len(), 3 * SIDES + 2);
        assert_eq!(t.triangles.len(), 2 * 2 * SIDES + 2 * SIDES);
        assert!(closed_and_oriented(&t));
        // A regular octagon of circumradius r has area 4 r^2 sin(pi/4); flat caps add none.
        let exact = SIDES as f64 / 2.0 * r * r * (TAU / SIDES as f64).sin() * l;
        assert!((enclosed(&t) - exact).abs() < 1e-14, "{}", enclosed(&t));
        for (p, n) in t.positions.iter().zip(&t.normals) {
            assert!((n.length() - 1.0).abs() < 1e-12);
            assert!(p.is_finite());
        }
    }

    #[test]
    fn a_closed_curve_gives_a_closed_outward_torus_and_repeated_points_are_harmless() {
        let mut pts: Vec<DVec3> = (0..40)
            .map(|k| {
                let a = TAU * k as f64 / 40.0;
                DVec3::new(a.cos(), a.sin(), 0.3 * (3.0 * a).sin())
            })
            .collect();
        pts.insert(7, pts[7]);
        let t = tubes(&pts, true, 0.05);
        assert!(closed_and_oriented(&t));
        assert!(enclosed(&t) > 0.0);
        assert!(t.positions.iter().all(|p| p.is_finite()));
    }

    #[test]
    fn coincident_points_get_no_tube() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        assert!(tubes(&[p, p, p], false, 0.1).triangles.is_empty());
        assert!(tubes(&[p], false, 0.1).triangles.is_empty());
    }
}
