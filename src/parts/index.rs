//! The halos' tetrahedra in one obvhs BVH: is this point of a sheet hidden?

use super::HaloPart;
use crate::intersect::broad;
use crate::intersect::sos::orient3d;
use glam::DVec3;
use obvhs::aabb::Aabb;
use rayon::prelude::*;

/// A tetrahedron (global index into [`HaloIndex`]) containing a point whose halo depth
/// there is below the point's w.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hider(pub(crate) u32);

/// The halo tetrahedra of several surfaces in one obvhs BVH, for the question the halo
/// verification and the renderer's exact mode both ask: is this point of a sheet hidden?
pub struct HaloIndex<'a> {
    pub(crate) halos: &'a [Option<HaloPart<'a>>],
    /// Global tetrahedron -> (surface, tet).
    pub(crate) tets: Vec<(u32, u32)>,
    /// Per global tetrahedron, the surface vertices it is built over (an inserted vertex
    /// stands for those of the tetrahedra around it), sorted, padded with `u32::MAX`.
    over: Vec<[u32; 6]>,
    /// Per global tetrahedron, a lower bound of its halo depth anywhere in it ([`floor`]):
    /// a point at a depth below it is hidden by nothing there, so its corners need no
    /// exact test.
    floor: Vec<f64>,
    bvh: obvhs::bvh2::Bvh2,
}

impl<'a> HaloIndex<'a> {
    /// Indexes the tetrahedra of `halos` (one per surface, `None` for none).
    pub fn new(halos: &'a [Option<HaloPart<'a>>]) -> Self {
        Self::with(halos, |_, _| true)
    }

    /// Indexes the tetrahedra `i` of each surface `s` with `keep(s, i)`.
    pub(crate) fn with(
        halos: &'a [Option<HaloPart<'a>>],
        keep: impl Fn(usize, u32) -> bool + Sync,
    ) -> Self {
        let mut boxes = Vec::new();
        let mut tets = Vec::new();
        let mut over = Vec::new();
        let mut floors = Vec::new();
        for (s, halo) in halos.iter().enumerate() {
            let Some(h) = halo else { continue };
            let n = h.surface_vertices as u32;
            let inserted = inserted_sets(h);
            let kept: Vec<(u32, Aabb, [u32; 6], f64)> = (0..h.tets.len() as u32)
                .into_par_iter()
                .filter(|&i| keep(s, i))
                .map(|i| {
                    let tet = h.tets[i as usize];
                    let aabb = tet_box(h, i);
                    let mut vs: Vec<u32> = Vec::with_capacity(8);
                    for &k in &tet {
                        if k < 3 * n {
                            vs.push(k % n);
                        } else {
                            vs.extend_from_slice(&inserted[(k - 3 * n) as usize]);
                        }
                    }
                    vs.sort_unstable();
                    vs.dedup();
                    let mut padded = [u32::MAX; 6];
                    for (slot, v) in padded.iter_mut().zip(vs) {
                        *slot = v;
                    }
                    (i, aabb, padded, floor(h, i))
                })
                .collect();
            for (i, aabb, vs, f) in kept {
                boxes.push(aabb);
                tets.push((s as u32, i));
                over.push(vs);
                floors.push(f);
            }
        }
        HaloIndex {
            halos,
            tets,
            over,
            floor: floors,
            bvh: broad::build(&boxes, 4),
        }
    }

    /// Whether tetrahedron `g` may hide a point at depth `w`: its halo depth can be below
    /// `w` somewhere ([`floor`]).
    pub(crate) fn may_hide(&self, g: u32, w: f64) -> bool {
        self.floor[g as usize] < w
    }

    /// Whether the point `x` of a triangle (with vertices `own`) of surface `surface`, at
    /// depth `w`, is hidden: inside a tetrahedron whose halo depth there is below `w`,
    /// other than those of the prisms of the triangles sharing a vertex with it.
    pub fn hidden(&self, x: DVec3, w: f64, surface: u32, own: [u32; 3]) -> bool {
        let mut hidden = false;
        self.visit(x, |g| {
            if self.may_hide(g, w)
                && !self.within(g, surface, &own)
                && self.depth_at(g, x).is_some_and(|depth| depth < w)
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
    pub(crate) fn vanishes(&self, surface: u32, triangle: &[u32; 3]) -> bool {
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
    fn visit(&self, x: DVec3, f: impl FnMut(u32) -> bool) {
        self.visit_box(broad::outward(x, x), f);
    }

    /// Calls `f` with each tetrahedron whose box meets `aabb` (and the others in the BVH's
    /// leaves with one), until it returns false.
    pub(crate) fn visit_box(&self, aabb: Aabb, mut f: impl FnMut(u32) -> bool) {
        self.bvh.aabb_traverse(aabb, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            let first = node.first_index as usize;
            bvh.primitive_indices[first..first + node.prim_count as usize]
                .iter()
                .all(|&g| f(g))
        });
    }

    /// The surface vertices tetrahedron `g` is built over.
    pub(crate) fn over(&self, g: u32) -> impl Iterator<Item = u32> + '_ {
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
    pub(crate) fn hiders(&self, x: DVec3, w: f64, own: (u32, &[u32])) -> Vec<Hider> {
        let mut out = Vec::new();
        self.visit(x, |g| {
            if self.may_hide(g, w)
                && !self.within(g, own.0, own.1)
                && self.depth_at(g, x).is_some_and(|depth| depth < w)
            {
                out.push(Hider(g));
            }
            true
        });
        out
    }

    /// The tetrahedra containing `x` with their halo depth there.
    pub(crate) fn containing(&self, x: DVec3) -> Vec<(u32, f64)> {
        let mut out = Vec::new();
        self.visit(x, |g| {
            if let Some(depth) = self.depth_at(g, x) {
                out.push((g, depth));
            }
            true
        });
        out
    }

    /// Halo depth (eq. 3) at `x` if tetrahedron `g` contains it (boundary included).
    pub(crate) fn depth_at(&self, g: u32, x: DVec3) -> Option<f64> {
        let (surface, tet) = self.tets[g as usize];
        let h = self.halos[surface as usize].as_ref()?;
        let k = h.tets[tet as usize];
        let p = k.map(|v| h.positions[v as usize]);
        // Each barycentric weight in turn, the search ending at the first negative one: most
        // candidates (tetrahedra whose box holds x) do not hold it.
        let mut l = [0.0; 4];
        for (i, w) in l.iter_mut().enumerate() {
            let mut q = p;
            q[i] = x;
            *w = orient3d(q[0], q[1], q[2], q[3]);
            if *w < 0.0 {
                return None;
            }
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

/// The surface vertices (mod n, sorted, distinct) of the tetrahedra around each inserted
/// vertex of `h`.
pub(crate) fn inserted_sets(h: &HaloPart) -> Vec<Vec<u32>> {
    let n = h.surface_vertices;
    let mut sets: Vec<Vec<u32>> = vec![Vec::new(); h.positions.len().saturating_sub(3 * n)];
    for tet in h.tets {
        for &k in tet.iter().filter(|&&k| k as usize >= 3 * n) {
            for &v in tet.iter().filter(|&&v| (v as usize) < 3 * n) {
                sets[k as usize - 3 * n].push(v % n as u32);
            }
        }
    }
    for set in &mut sets {
        set.sort_unstable();
        set.dedup();
    }
    sets
}

/// A lower bound of the halo depth [`HaloIndex::depth_at`] computes anywhere in tetrahedron
/// `i` of `h`: the smallest d_orig of its corners (an interpolation of them) plus the most
/// eq. 3's term can take from it where delta_d is negative, lowered by a few units in the
/// last place for the rounding of the interpolation, so that no point it could hide is
/// skipped.
pub(crate) fn floor(h: &HaloPart, i: u32) -> f64 {
    let lowest = h.tets[i as usize]
        .iter()
        .map(|&v| h.d_orig[v as usize])
        .fold(f64::INFINITY, f64::min);
    let term = (1.0 - h.delta_t).max(0.0) * h.delta_d.min(0.0);
    let bound = lowest + term;
    bound - 8.0 * f64::EPSILON * (lowest.abs() + term.abs())
}

/// The f32 box around tetrahedron `i` of `h` (rounded outward).
pub(crate) fn tet_box(h: &HaloPart, i: u32) -> Aabb {
    let p = h.tets[i as usize].map(|v| h.positions[v as usize]);
    broad::outward(
        p[0].min(p[1]).min(p[2]).min(p[3]),
        p[0].max(p[1]).max(p[2]).max(p[3]),
    )
}
