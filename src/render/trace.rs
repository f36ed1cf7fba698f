//! Every intersection of a ray with the projected triangles, through an obvhs BVH.

use crate::intersect::broad;
use glam::{DVec3, Vec3A};
use obvhs::bvh2::Bvh2;
use obvhs::ray::Ray;

/// One surface's triangles as the tracer reads them.
#[derive(Clone, Copy, Debug)]
pub struct TraceSurface<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
}

/// A ray's hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// Surface index.
    pub surface: u32,
    /// Triangle index in that surface.
    pub triangle: u32,
    /// Barycentric coordinates of the hit on the triangle's corners.
    pub bary: [f64; 3],
}

/// The triangles of all surfaces in one BVH.
pub struct Tracer<'a> {
    surfaces: Vec<TraceSurface<'a>>,
    /// Per BVH slot, its triangle's (surface, triangle) and corners: read in the order the
    /// traversal meets them, with no lookup through the surfaces.
    tris: Vec<(u32, u32)>,
    corners: Vec<[DVec3; 3]>,
    bvh: Bvh2,
    /// Hits closer than this along the ray are one hit on a shared edge or vertex.
    same: f64,
}

impl<'a> Tracer<'a> {
    /// Indexes the triangles of `surfaces`; `scale` is the scene's size, for telling one
    /// hit on an edge from two.
    pub fn new(surfaces: Vec<TraceSurface<'a>>, scale: f64) -> Self {
        let mut boxes = Vec::new();
        let mut tris = Vec::new();
        // The f32 ray-box test can slip past a box corner (a ray through a mesh vertex, past
        // the boxes of every triangle around it): boxes grow by a millionth of the scene, and
        // the exact test decides.
        let pad = DVec3::splat(1e-6 * scale);
        for (s, surf) in surfaces.iter().enumerate() {
            for (i, t) in surf.triangles.iter().enumerate() {
                let p = t.map(|v| surf.positions[v as usize]);
                boxes.push(broad::outward(
                    p[0].min(p[1]).min(p[2]) - pad,
                    p[0].max(p[1]).max(p[2]) + pad,
                ));
                tris.push((s as u32, i as u32));
            }
        }
        let bvh = broad::build(&boxes, 4);
        let tris: Vec<(u32, u32)> = bvh
            .primitive_indices
            .iter()
            .map(|&g| tris[g as usize])
            .collect();
        let corners = tris
            .iter()
            .map(|&(s, i)| {
                let surf = &surfaces[s as usize];
                surf.triangles[i as usize].map(|v| surf.positions[v as usize])
            })
            .collect();
        Tracer {
            surfaces,
            tris,
            corners,
            bvh,
            same: 1e-12 * scale,
        }
    }

    /// Every hit along the ray from `origin` in unit direction `dir` with t > `t_min`, in
    /// order of t, into `hits` (cleared first). A ray through an edge or vertex shared by
    /// triangles of one surface hits it once.
    pub fn hits(&self, origin: DVec3, dir: DVec3, t_min: f64, hits: &mut Vec<Hit>) {
        hits.clear();
        let shear = Shear::new(origin, dir);
        self.bvh
            .ray_traverse_anyhit(self.ray(origin, dir), |_, slot| {
                if let Some(hit) = self.hit(&shear, slot)
                    && hit.t > t_min
                {
                    hits.push(hit);
                }
            });
        self.order(hits);
    }

    /// The hits of the ray beyond `t_min` no farther than `slack` past the nearest one, in
    /// order: the start of what [`Tracer::hits`] gives, by a closest-hit traversal, which
    /// visits far fewer boxes where many sheets lie along the ray.
    pub fn nearest_hits(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        slack: f64,
        hits: &mut Vec<Hit>,
    ) {
        hits.clear();
        let mut nearest = f64::INFINITY;
        let mut found = obvhs::ray::RayHit::none();
        let shear = Shear::new(origin, dir);
        self.bvh
            .ray_traverse(self.ray(origin, dir), &mut found, |_, slot| {
                match self.hit(&shear, slot) {
                    Some(hit) if hit.t > t_min && hit.t <= nearest + slack => {
                        nearest = nearest.min(hit.t);
                        hits.push(hit);
                        // Rounded up past the slack, so that the boxes of every hit within
                        // it are still visited.
                        ((nearest + slack) as f32).next_up()
                    }
                    _ => f32::INFINITY,
                }
            });
        hits.retain(|h| h.t <= nearest + slack);
        self.order(hits);
    }

    /// Hits closer than this along the ray are compared for duplicates.
    pub fn same(&self) -> f64 {
        self.same
    }

    /// The ray in the BVH's f32.
    fn ray(&self, origin: DVec3, dir: DVec3) -> Ray {
        Ray::new(
            Vec3A::new(origin.x as f32, origin.y as f32, origin.z as f32),
            Vec3A::new(dir.x as f32, dir.y as f32, dir.z as f32),
            0.0,
            f32::INFINITY,
        )
    }

    /// Where the ray meets the triangle in BVH slot `slot`, if it does.
    fn hit(&self, shear: &Shear, slot: usize) -> Option<Hit> {
        let (s, i) = self.tris[slot];
        shear.intersect(&self.corners[slot]).map(|(t, bary)| Hit {
            t,
            surface: s,
            triangle: i,
            bary,
        })
    }

    /// Sorts hits by t and drops the second of two at one t on neighbouring triangles of
    /// one surface (a ray through their shared edge or vertex).
    fn order(&self, hits: &mut Vec<Hit>) {
        hits.sort_by(|a, b| a.t.total_cmp(&b.t));
        let mut kept = 0;
        for k in 0..hits.len() {
            let h = hits[k];
            let duplicate = hits[..kept]
                .iter()
                .rev()
                .take_while(|o| h.t - o.t <= self.same)
                .any(|o| {
                    o.surface == h.surface && {
                        let surf = &self.surfaces[h.surface as usize];
                        let (a, b) = (
                            surf.triangles[o.triangle as usize],
                            surf.triangles[h.triangle as usize],
                        );
                        a.iter().any(|v| b.contains(v))
                    }
                });
            if !duplicate {
                hits[kept] = h;
                kept += 1;
            }
        }
        hits.truncate(kept);
    }
}

/// A ray set up for watertight ray-triangle intersection (Woop, Benthin and Wald 2013) in
/// f64, edges included: the axis the ray runs most along and the shear that takes the ray to
/// that axis, found once per ray. A triangle is sheared into the ray's frame and tested with
/// 2D edge functions; a vertex shared by two triangles shears to the same point and a shared
/// edge's function is exactly negated between them, so a ray through an edge hits both
/// neighbours (one hit after [`Tracer::hits`] merges them), never neither.
struct Shear {
    origin: DVec3,
    k: [usize; 3],
    s: [f64; 3],
}

impl Shear {
    fn new(origin: DVec3, dir: DVec3) -> Self {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Shear {
            origin,
            k: [kx, ky, kz],
            s: [dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]],
        }
    }

    /// (t, barycentric coordinates) where the ray meets triangle `p`, if it does.
    #[inline]
    fn intersect(&self, p: &[DVec3; 3]) -> Option<(f64, [f64; 3])> {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.s;
        let shear = |q: DVec3| {
            let r = q - self.origin;
            (r[kx] - sx * r[kz], r[ky] - sy * r[kz], sz * r[kz])
        };
        let (ax, ay, az) = shear(p[0]);
        let (bx, by, bz) = shear(p[1]);
        let (cx, cy, cz) = shear(p[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let t = (u * az + v * bz + w * cz) / det;
        Some((t, [u / det, v / det, w / det]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_through_a_shared_edge_hits_once_and_stacked_sheets_in_order() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3]];
        let lifted: Vec<DVec3> = positions.iter().map(|p| *p + DVec3::Z).collect();
        let surfaces = [
            TraceSurface {
                positions: &positions,
                triangles: &triangles,
            },
            TraceSurface {
                positions: &lifted,
                triangles: &triangles,
            },
        ];
        let tracer = Tracer::new(surfaces.to_vec(), 1.0);
        let mut hits = Vec::new();
        // Straight down through the diagonal (0, 0)-(1, 1) of both squares.
        tracer.hits(DVec3::new(0.5, 0.5, 5.0), -DVec3::Z, 0.0, &mut hits);
        assert_eq!(hits.len(), 2, "{hits:?}");
        assert_eq!((hits[0].surface, hits[1].surface), (1, 0));
        assert!((hits[0].t - 4.0).abs() < 1e-12 && (hits[1].t - 5.0).abs() < 1e-12);
        tracer.hits(DVec3::new(2.0, 0.5, 5.0), -DVec3::Z, 0.0, &mut hits);
        assert!(hits.is_empty());
    }
}
