//! Per triangle of the surfaces, the halo tetrahedra that may hide a point of it: the
//! renderer's question (is this point of a sheet hidden?) asked millions of times, one BVH
//! query per triangle instead of one per point.

use super::{HaloIndex, Parts, SurfacePart};
use crate::intersect::broad;
use glam::DVec3;
use std::sync::OnceLock;

/// A tetrahedron that may hide points of a triangle, with its exact box.
#[derive(Clone, Copy, Debug)]
struct Near {
    g: u32,
    lo: DVec3,
    hi: DVec3,
}

/// Where a triangle's points lie: its box and the slab about its plane, both grown by a
/// pad, and the tetrahedra that meet both, less those of the triangle's own prisms
/// ([`HaloIndex::within`]), which never hide it.
#[derive(Debug)]
struct Hiders {
    lo: DVec3,
    hi: DVec3,
    /// The plane's unit normal and offset (zero for a triangle of no area).
    normal: DVec3,
    offset: f64,
    /// The slab's half-width: the pad, infinite for a triangle of no area (no slab).
    slab: f64,
    near: Box<[Near]>,
}

impl Hiders {
    /// Whether `x` lies in the triangle's grown box and slab.
    fn holds(&self, x: DVec3) -> bool {
        x.cmpge(self.lo).all()
            && x.cmple(self.hi).all()
            && (self.normal.dot(x) - self.offset).abs() <= self.slab
    }
}

/// [`HaloIndex::hidden`] for points of the surfaces' triangles, with the same answers: each
/// triangle's candidates are found by one box query the first time a point of it is asked
/// about (from any thread), then every point of it is tested against them alone, most often
/// none (a triangle far from the other sheets). A point outside its triangle's grown box or
/// slab (a ray's hit rounded far off the triangle) asks the index directly.
pub(crate) struct TriangleHiders<'a> {
    index: HaloIndex<'a>,
    surfaces: &'a [SurfacePart<'a>],
    /// Per surface and triangle, its candidates once found.
    found: Vec<Vec<OnceLock<Hiders>>>,
}

impl<'a> TriangleHiders<'a> {
    /// The halos of `parts` indexed, to be asked about points of its surfaces' triangles.
    pub(crate) fn new(parts: &'a Parts<'a>) -> Self {
        TriangleHiders {
            index: HaloIndex::new(&parts.halos),
            found: parts
                .surfaces
                .iter()
                .map(|s| (0..s.triangles.len()).map(|_| OnceLock::new()).collect())
                .collect(),
            surfaces: &parts.surfaces,
        }
    }

    /// The index asked.
    pub(crate) fn index(&self) -> &HaloIndex<'a> {
        &self.index
    }

    /// Whether the point `x` of triangle `triangle` of surface `surface`, at depth `w`, is
    /// hidden: [`HaloIndex::hidden`] with the triangle's vertices as `own`.
    pub(crate) fn hidden(&self, x: DVec3, w: f64, surface: u32, triangle: u32) -> bool {
        let hiders = self.found[surface as usize][triangle as usize]
            .get_or_init(|| self.find(surface, triangle));
        if !hiders.holds(x) {
            let own = self.surfaces[surface as usize].triangles[triangle as usize];
            return self.index.hidden(x, w, surface, own);
        }
        // Each candidate's exact box holds its tetrahedron, so a point outside it is not in it.
        hiders.near.iter().any(|n| {
            x.cmpge(n.lo).all()
                && x.cmple(n.hi).all()
                && self.index.may_hide(n.g, w)
                && self.index.depth_at(n.g, x).is_some_and(|depth| depth < w)
        })
    }

    /// The candidates of one triangle. Its points, as a ray's hit computes them, lie within
    /// rounding of the triangle: within a pad (a millionth of its diagonal and a billionth
    /// of its coordinates, far above any rounding) of its box and of its plane
    /// ([`Hiders::holds`] checks each point, and a point outside asks the index). A
    /// tetrahedron is a candidate where its box meets the grown box and its corners do not
    /// all lie on one side of the grown slab, with a margin of half the pad for the
    /// rounding of their distances.
    fn find(&self, surface: u32, triangle: u32) -> Hiders {
        let s = &self.surfaces[surface as usize];
        let own = s.triangles[triangle as usize];
        let p = own.map(|v| s.positions[v as usize]);
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        let pad = 1e-6 * (hi - lo).length() + 1e-9 * lo.abs().max(hi.abs()).max_element();
        let (lo, hi) = (lo - pad, hi + pad);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        let offset = normal.dot(p[0]);
        // A triangle of no area has no slab: its points are only bounded by the box.
        let slab = if normal == DVec3::ZERO {
            f64::INFINITY
        } else {
            pad
        };
        let mut near = Vec::new();
        self.index.visit_box(broad::outward(lo, hi), |g| {
            if self.index.within(g, surface, &own) {
                return true;
            }
            let (corners, ..) = self.index.tet(g);
            let [a, b, c, d] = corners;
            let (g_lo, g_hi) = (a.min(b).min(c).min(d), a.max(b).max(c).max(d));
            let side = corners.map(|q| normal.dot(q) - offset);
            let clear = 1.5 * slab;
            let off_slab = side.iter().all(|&h| h > clear) || side.iter().all(|&h| h < -clear);
            if g_lo.cmple(hi).all() && g_hi.cmpge(lo).all() && !off_slab {
                near.push(Near {
                    g,
                    lo: g_lo,
                    hi: g_hi,
                });
            }
            true
        });
        Hiders {
            lo,
            hi,
            normal,
            offset,
            slab,
            near: near.into_boxed_slice(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_answer_is_the_index_s() {
        // The default scene (sheets nested along most rays, each halo crowded by its
        // neighbours) and the twist-spun trefoil: points at the corners, on the edges and
        // inside every triangle, at the surface's w and at depths above and below it, and
        // points off the triangle's plane (asked of the index directly), all answered as
        // the index answers them.
        for scene in [
            crate::Scene::default_scene(),
            crate::Scene::load(std::path::Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/fixtures/scenes/twist-spun-trefoil.json"
            )))
            .unwrap(),
        ] {
            let built = crate::Sampled::of(&scene)
                .into_built(&scene, crate::Stages::of(&scene))
                .unwrap();
            let parts = built.parts(&scene.halo);
            let index = HaloIndex::new(&parts.halos);
            let hiders = TriangleHiders::new(&parts);
            let (mut asked, mut hidden) = (0, 0);
            for (s, surf) in parts.surfaces.iter().enumerate() {
                let span = surf.w.iter().fold(0.0f64, |m, w| m.max(w.abs()));
                for (t, tri) in surf.triangles.iter().enumerate() {
                    let p = tri.map(|v| surf.positions[v as usize]);
                    let wv = tri.map(|v| surf.w[v as usize]);
                    let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
                    let size = (p[1] - p[0]).length().max((p[2] - p[0]).length());
                    for b in [
                        [1.0, 0.0, 0.0],
                        [0.5, 0.5, 0.0],
                        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
                        [0.7, 0.2, 0.1],
                        [0.05, 0.15, 0.8],
                    ] {
                        let x = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
                        let w = wv[0] * b[0] + wv[1] * b[1] + wv[2] * b[2];
                        for (x, w) in [
                            (x, w),
                            (x, w + 0.2 * span),
                            (x, w - 0.2 * span),
                            (x + normal * (1e-3 * size), w),
                        ] {
                            let expected = index.hidden(x, w, s as u32, *tri);
                            assert_eq!(
                                hiders.hidden(x, w, s as u32, t as u32),
                                expected,
                                "{}: surface {s} triangle {t} at {x} w {w}",
                                scene.name
                            );
                            asked += 1;
                            hidden += usize::from(expected);
                        }
                    }
                }
            }
            assert!(
                hidden > 100 && hidden < asked / 2,
                "{}: {hidden} of {asked} hidden",
                scene.name
            );
        }
    }
}
