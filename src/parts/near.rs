//! Per triangle of the surfaces, the halo tetrahedra that may hide a point of it: the
//! renderer's question (is this point of a sheet hidden?) asked millions of times, one BVH
//! query per triangle instead of one per point.

use super::{HaloIndex, Parts, SurfacePart};
use crate::intersect::broad;
use crate::intersect::sos::orient3d;
use glam::DVec3;
use std::sync::OnceLock;

/// A tetrahedron that may hide points of a triangle, with its faces' planes: per face, a
/// unit normal pointing in and its offset less a margin (`[nx, ny, nz, c]`, a point `x`
/// with `n . x + c < 0` is clearly outside), so that most points outside are turned away
/// without the exact predicates. The margin is far above the rounding of the planes for
/// any point inside; a face with no clear normal (a sliver) turns nothing away.
#[derive(Clone, Copy, Debug)]
struct Near {
    g: u32,
    faces: [[f64; 4]; 4],
}

impl Near {
    /// The candidate `g` with corners `p`, or `None` where its corners are not positively
    /// oriented (exactly): then the weights of any point sum to a determinant that is not
    /// positive, one of them is negative or all are zero, and [`HaloIndex::depth_at`]
    /// finds it holds no point.
    fn new(g: u32, p: [DVec3; 4]) -> Option<Self> {
        if orient3d(p[0], p[1], p[2], p[3]) <= 0.0 {
            return None;
        }
        let (lo, hi) = (
            p[0].min(p[1]).min(p[2]).min(p[3]),
            p[0].max(p[1]).max(p[2]).max(p[3]),
        );
        let reach = (hi - lo).length();
        let size = lo.abs().max(hi.abs()).max_element();
        let faces = [0, 1, 2, 3].map(|i| {
            // Face i is opposite corner i; its weight vanishes on the face and grows to
            // the whole determinant at corner i.
            let [a, b, c] = [1, 2, 3].map(|k| p[(i + k) % 4]);
            let n = (b - a).cross(c - a);
            let length = n.length();
            // The normal's direction is good to about eps * |ab| |ac| / |n|: over the
            // tetrahedron's reach, with the rounding of the offset (eps times the
            // coordinates), the error is about 10^-7 of the margin, a billionth of both.
            let slack = (b - a).length() * (c - a).length() / length;
            let margin = 1e-9 * (reach * (1.0 + slack) + size);
            let n = n / length;
            let along = n.dot(p[i] - a);
            if !(length > 0.0 && slack.is_finite() && along.abs() > 2.0 * margin) {
                return [0.0, 0.0, 0.0, 1.0];
            }
            let n = n * along.signum();
            [n.x, n.y, n.z, margin - n.dot(a)]
        });
        Some(Near { g, faces })
    }

    /// Whether `x` may lie in the tetrahedron: no face has it clearly outside (without
    /// branches: a triangle has a score of candidates, and most turn its points away; the
    /// four comparisons joined by `&`, since `f64::min`'s care for NaN costs more than
    /// they do, and a finite point has none).
    #[inline]
    fn may_hold(&self, x: DVec3) -> bool {
        self.faces.iter().fold(true, |inside, f| {
            inside & (f[0] * x.x + f[1] * x.y + f[2] * x.z + f[3] >= 0.0)
        })
    }
}

/// Where a triangle's points lie: its box, the slab about its plane and the half-spaces
/// of its edges in that plane, all grown by a pad; and the tetrahedra that may meet that
/// region, less those of the triangle's own prisms ([`HaloIndex::within`]), which never
/// hide it.
#[derive(Debug)]
struct Hiders {
    lo: DVec3,
    hi: DVec3,
    /// The plane's unit normal and offset (zero for a triangle of no area).
    normal: DVec3,
    offset: f64,
    /// The slab's half-width: the pad, infinite for a triangle of no area (no slab).
    slab: f64,
    /// Per edge, the unit normal in the plane pointing in and the offset less the pad
    /// (`[nx, ny, nz, c]`, `n . x + c >= 0` inside); none for a triangle of no area.
    edges: [[f64; 4]; 3],
    near: Box<[Near]>,
}

impl Hiders {
    /// Whether `x` lies in the triangle's grown box, slab and edges.
    fn holds(&self, x: DVec3) -> bool {
        x.cmpge(self.lo).all()
            && x.cmple(self.hi).all()
            && (self.normal.dot(x) - self.offset).abs() <= self.slab
            && self
                .edges
                .iter()
                .all(|e| e[0] * x.x + e[1] * x.y + e[2] * x.z + e[3] >= 0.0)
    }
}

/// The in-plane edge half-spaces of triangle `p` (unit `normal`) grown by `pad`, and how
/// far from the triangle a point of them within `pad` of its plane may lie: the grown
/// triangle reaches `pad / sin(angle / 2)` past each corner. `None` where the triangle has
/// no clear corners.
fn edge_spaces(p: [DVec3; 3], normal: DVec3, pad: f64) -> Option<([[f64; 4]; 3], f64)> {
    let mut edges = [[0.0; 4]; 3];
    let mut reach = 0.0f64;
    for i in 0..3 {
        let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
        // The edge from a to b, its normal in the plane towards c.
        let n = normal.cross(b - a).normalize_or_zero();
        let n = if n.dot(c - a) < 0.0 { -n } else { n };
        edges[i] = [n.x, n.y, n.z, pad - n.dot(a)];
        // The corner at a, between the edges to b and to c.
        let cos = (b - a).normalize_or_zero().dot((c - a).normalize_or_zero());
        reach = reach.max(pad / ((1.0 - cos) / 2.0).sqrt());
    }
    (normal != DVec3::ZERO && reach.is_finite()).then_some((edges, reach + pad))
}

/// [`HaloIndex::hidden`] for points of the surfaces' triangles, with the same answers: each
/// triangle's candidates are found by one box query the first time a point of it is asked
/// about (from any thread), then every point of it is tested against them alone, most often
/// none (a triangle far from the other sheets). A point outside its triangle's grown box,
/// slab or edges (a ray's hit rounded far off the triangle) asks the index directly.
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
        hiders.near.iter().any(|n| {
            n.may_hold(x)
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
        let spaces = edge_spaces(p, normal, pad);
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
            if g_lo.cmple(hi).all()
                && g_hi.cmpge(lo).all()
                && !off_slab
                && let Some(n) = Near::new(g, corners)
                // Kept unless one of its faces has the whole grown triangle clearly
                // outside: its corners farther out than twice the grown triangle's reach
                // (the second for the rounding of their distances, far below the pad).
                && spaces.is_none_or(|(_, reach)| {
                    n.faces.iter().all(|f| {
                        p.iter()
                            .map(|q| f[0] * q.x + f[1] * q.y + f[2] * q.z + f[3])
                            .fold(f64::NEG_INFINITY, f64::max)
                            >= -2.0 * reach
                    })
                })
            {
                near.push(n);
            }
            true
        });
        Hiders {
            lo,
            hi,
            normal,
            offset,
            slab,
            edges: spaces.map_or([[0.0, 0.0, 0.0, 1.0]; 3], |(edges, _)| edges),
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
        // neighbours) and the twist-spun trefoil: points at the corners, on the edges,
        // inside every triangle and just past it, at the surface's w and at depths above
        // and below it, and points off the triangle's plane or far past an edge (asked of
        // the index directly), all answered as the index answers them.
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
                        // Just past an edge and a corner, within the grown triangle, and
                        // far past an edge (asked of the index directly).
                        [-1e-7, 0.5 + 5e-8, 0.5 + 5e-8],
                        [1.0 + 2e-7, -1e-7, -1e-7],
                        [-1e-3, 0.5005, 0.5],
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
