//! Halos (paper 000, eq. 1-3): a projected surface thickened into a shell of tetrahedra.
//!
//! Takes: a projected surface (3D points, w-depths, unit normals from the view) and its
//! triangles. Gives: a [`Halo`]: the two offset surfaces v ± rho n̂ (t = 0 on the negative
//! side, 1 on the positive) and the surface itself between them (t = 1/2), each vertex
//! keeping t and d_orig (its w-depth), and the tetrahedra of the prisms between the offsets,
//! in two layers that meet at the surface triangle (`tets`). Inside the halo the
//! depth grows as d_new = d_orig + max(0, |2t - 1| - delta_t) delta_d, evaluated after
//! interpolating t and d_orig, so the halo carries those two and not d_new.
//!
//! The offset direction d of a vertex is the view's normal n̂ (eq. 1: the normalized cross
//! product of the projected tangents) where every triangle around the vertex faces it by a
//! margin; elsewhere (at cross-caps of the projection and the poles of spun spheres, where
//! the tangents are parallel, and where the mesh folds) it is the widest direction of the
//! triangles around the vertex ([`widest_direction`]), which depends on the mesh and the
//! view, not on the parametrization. Never NaN. Each vertex orients the triangles around it
//! by walking across their shared edges; where a non-orientable surface turns over, a prism's
//! corners disagree and the prism is twisted (see `tets`).
//!
//! Where no direction faces every triangle around a vertex (a cross-cap: the normals turn
//! through a full circle around it), no rho keeps its prisms valid: the vertex is singular
//! and its rho is 0. Where rho exceeds what the local geometry allows, the offsets fold and
//! prisms invert: with `fold: shrink` (the default) rho is halved at the corners of every
//! inverted tetrahedron, re-examining only the prisms around them, until none is inverted;
//! a vertex halved [`HALVINGS`] times collapses to 0. A collapsed vertex has both offsets at
//! the surface point, with t = 0.5, and only the negative one's index is used (for the
//! surface vertex too). With `fold: report` rho stays as asked and the inverted tetrahedra
//! are counted. Vertices are rounded to f32, what the files store, before they are checked.

use crate::check::{CheckStats, TetMesh, check_parts_until};
use crate::limits::{DELTA_D, DELTA_T, FieldError, HALO_GAP_PX, HALO_RHO, Number};
use crate::progress::Cancel;
use crate::tets::{self, Corners, Split, SplitStats};
use crate::view::Projected;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The parameters of the volumetric halos of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HaloParams {
    /// Half-width of the halo, relative to the diagonal of the projected scene's bounding
    /// box; when absent, the half-width is set by `gap_px` from the scene's picture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho: Option<f64>,
    /// Half-width of the halo in pixels of the scene's picture, at the depth of the point
    /// the camera looks at: about the width of the gap the halo cuts into the sheet
    /// passing under on each side of a crossing (`halo::DEFAULT_GAP_PX` when neither this nor
    /// `rho` is given). One of `rho` and `gap_px`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap_px: Option<f64>,
    /// Depth increment delta_d at the halo's outer surfaces (eq. 3), in w units.
    pub delta_d: f64,
    /// Dead zone delta_t in [0, 1) of |2t - 1| before the depth starts to grow (eq. 3).
    pub delta_t: f64,
    /// How prisms are split into tetrahedra.
    pub split: Split,
    /// What to do where the offsets fold.
    pub fold: Fold,
}

/// What to do where rho is too large for the local geometry and prisms invert.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fold {
    /// Shrink rho locally until every prism is valid, and count the vertices shrunk.
    #[default]
    Shrink,
    /// Keep rho and count the inverted tetrahedra.
    Report,
}

impl Default for HaloParams {
    fn default() -> Self {
        HaloParams {
            rho: None,
            gap_px: None,
            delta_d: 0.5,
            delta_t: 0.3,
            split: Split::default(),
            fold: Fold::default(),
        }
    }
}

/// The gap a halo cuts on each side of a crossing, in pixels of the scene's picture, when a
/// scene gives neither `halo.rho` nor `halo.gap_px`: wide enough to read at a glance beside
/// a curve line of the default width (2.5 px).
pub const DEFAULT_GAP_PX: f64 = 8.0;

impl HaloParams {
    /// The halo's half-width in scene units, for a projected scene of bounding `diagonal`
    /// whose picture has pixels of side `pixel_size` (scene units) at the depth the camera
    /// looks at; within [`HALO_RHO`] of the diagonal.
    pub fn half_width(&self, diagonal: f64, pixel_size: f64) -> f64 {
        match self.rho {
            Some(rho) => rho * diagonal,
            None => (self.gap_px.unwrap_or(DEFAULT_GAP_PX) * pixel_size)
                .clamp(HALO_RHO.lo * diagonal, HALO_RHO.hi * diagonal),
        }
    }

    /// Checks the numbers: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        if self.rho.is_some() && self.gap_px.is_some() {
            return Err(FieldError::new(
                "gap_px",
                "give one of halo.rho (a share of the scene's diagonal) and halo.gap_px (pixels of the picture), not both".to_string(),
            ));
        }
        if let Some(rho) = self.rho {
            HALO_RHO.check_with(
                "rho",
                rho,
                &format!(
                    "below {} the two offsets round to one point in f32, which the files store",
                    HALO_RHO.lo.text()
                ),
            )?;
        }
        if let Some(gap) = self.gap_px {
            HALO_GAP_PX.check("gap_px", gap)?;
        }
        DELTA_D.check("delta_d", self.delta_d)?;
        DELTA_T.check("delta_t", self.delta_t)?;
        Ok(())
    }
}

/// A surface's halo: vertices (negative offsets, positive offsets, the surface vertices, then
/// inserted vertices) with t and d_orig, and tetrahedra.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Halo {
    /// Surface vertices n.
    pub surface_vertices: usize,
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// t of each vertex: 0 on the negative offset, 1 on the positive, 0.5 on the surface;
    /// an inserted vertex has the mean t of its layer's corners.
    pub t: Vec<f64>,
    /// w-depth of the surface point each vertex came from.
    pub d_orig: Vec<f64>,
    /// Tetrahedra, positively oriented (`robust::orient3d`).
    pub tets: Vec<[u32; 4]>,
    /// The half-width used at each surface vertex (rho, or less where it was shrunk).
    pub rho: Vec<f64>,
    /// The surface triangle whose prism each inserted vertex (from 3n on) is in.
    pub inserted_in: Vec<u32>,
}

impl Halo {
    /// The halo in the checker's terms, over the surface `triangles` it was built over.
    pub fn tet_mesh(&self, triangles: &[[u32; 3]]) -> TetMesh {
        TetMesh {
            positions: self.positions.iter().map(|p| p.to_array()).collect(),
            surface_vertices: self.surface_vertices,
            tets: self.tets.clone(),
            surface_triangles: triangles.to_vec(),
        }
    }
}

/// What `report.json` says of a halo.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HaloReport {
    /// The split used.
    pub split: &'static str,
    /// Prisms (surface triangles).
    pub prisms: usize,
    /// Tetrahedra.
    pub tets: usize,
    /// Half-width asked for, absolute.
    pub rho: f64,
    /// The builder's counts.
    #[serde(flatten)]
    pub split_stats: SplitStats,
    /// Inverted or flat tetrahedra, as the checker counts them.
    pub inverted: usize,
    /// Surface vertices whose rho was shrunk (collapsed ones included).
    pub shrunk_vertices: usize,
    /// Surface vertices whose rho shrank to zero: both offsets at the surface point.
    pub collapsed_vertices: usize,
    /// Surface vertices no offset direction fits: the normals of the triangles around them
    /// lie in no open hemisphere (a cross-cap of the projection, a fold of the mesh).
    pub singular_vertices: usize,
    /// Prisms whose corners' offsets lie on different sides of the surface's winding (where
    /// a non-orientable surface's offset directions turn over).
    pub twisted_prisms: usize,
    /// Smallest dihedral angle, degrees (checker).
    pub min_dihedral_deg: f64,
    /// The checker's full statistics.
    pub check: CheckStats,
    /// Milliseconds: thickening, splitting, fixing and checking.
    pub ms: f64,
    /// Where the milliseconds went.
    pub stage_ms: HaloStages,
}

/// Milliseconds per step of the halo stage.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct HaloStages {
    /// Offset directions (eq. 1 and the widest direction where it fails) and offsets.
    pub directions: f64,
    /// Planning the split (edge orientations, Dompierre's rule).
    pub plan: f64,
    /// Shrinking rho where tetrahedra invert.
    pub shrink: f64,
    /// Emitting the tetrahedra, t and d_orig.
    pub split: f64,
    /// The independent checker.
    pub check: f64,
}

/// The triangles around each vertex, as (triangle, corner); flat, vertex after vertex.
struct Stars {
    uses: Vec<(u32, u8)>,
    starts: Vec<usize>,
}

impl Stars {
    fn new(n: usize, triangles: &[[u32; 3]]) -> Stars {
        let mut starts = vec![0usize; n + 1];
        for &i in triangles.iter().flatten() {
            starts[i as usize + 1] += 1;
        }
        for i in 0..n {
            starts[i + 1] += starts[i];
        }
        let mut fill = starts.clone();
        let mut uses = vec![(0, 0); 3 * triangles.len()];
        for (t, tri) in triangles.iter().enumerate() {
            for (k, &i) in tri.iter().enumerate() {
                uses[fill[i as usize]] = (t as u32, k as u8);
                fill[i as usize] += 1;
            }
        }
        Stars { uses, starts }
    }

    fn of(&self, v: usize) -> &[(u32, u8)] {
        &self.uses[self.starts[v]..self.starts[v + 1]]
    }
}

/// For the triangles around a vertex (`star`), whether each is wound against the vertex's
/// reference orientation (into `scratch.reversed`): found by walking across the edges they share
/// (two triangles sharing an edge agree when they run along it in opposite directions), the
/// reference being the winding of the majority.
fn reversed_in_star(star: &[(u32, u8)], triangles: &[[u32; 3]], scratch: &mut Scratch) {
    let Scratch {
        ring,
        seen,
        reversed,
        stack,
        ..
    } = scratch;
    // The corners after and before the vertex in each triangle's winding.
    ring.clear();
    ring.extend(star.iter().map(|&(t, k)| {
        let tri = triangles[t as usize];
        (tri[(k as usize + 1) % 3], tri[(k as usize + 2) % 3])
    }));
    seen.clear();
    seen.resize(star.len(), false);
    reversed.clear();
    reversed.resize(star.len(), false);
    for seed in 0..star.len() {
        if seen[seed] {
            continue;
        }
        seen[seed] = true;
        stack.push(seed);
        while let Some(i) = stack.pop() {
            let (next, prev) = ring[i];
            for j in 0..star.len() {
                if seen[j] {
                    continue;
                }
                let (nj, pj) = ring[j];
                // Sharing the edge to `next` as j's `prev` (or `prev` as `next`): agree.
                let agree = nj == prev || pj == next;
                let disagree = nj == next || pj == prev;
                if agree || disagree {
                    seen[j] = true;
                    reversed[j] = reversed[i] ^ disagree;
                    stack.push(j);
                }
            }
        }
    }
    if 2 * reversed.iter().filter(|r| **r).count() > reversed.len() {
        reversed.iter_mut().for_each(|r| *r = !*r);
    }
}

/// Vertices per parallel task in [`frame`]: enough to make a task's bookkeeping
/// negligible, few enough to share a mesh of some thousands of vertices among the cores.
const FRAME_RUN: usize = 1024;

/// A run of vertices' share of a [`Frame`]: directions, singular flags and, along their
/// stars, which triangles are reversed.
#[derive(Default)]
struct FramePart {
    dir: Vec<DVec3>,
    singular: Vec<bool>,
    reversed: Vec<bool>,
}

/// Buffers reused from vertex to vertex.
#[derive(Default)]
struct Scratch {
    ring: Vec<(u32, u32)>,
    seen: Vec<bool>,
    reversed: Vec<bool>,
    stack: Vec<usize>,
    g: Vec<DVec3>,
}

/// The unit direction d maximising min_i d·g_i, and that minimum: the directions from the
/// origin to the nearest point of the convex hull of the g_i, found among the candidates
/// each g_i, the bisector of each pair and the direction equidistant from each triple. The
/// minimum is at most 0 when no open hemisphere holds every g_i.
pub fn widest_direction(g: &[DVec3]) -> (DVec3, f64) {
    let score = |d: DVec3| g.iter().map(|x| x.dot(d)).fold(f64::INFINITY, f64::min);
    let mut best = (DVec3::ZERO, f64::NEG_INFINITY);
    let mut consider = |d: DVec3| {
        if let Some(d) = d.try_normalize() {
            let s = score(d);
            if s > best.1 {
                best = (d, s);
            }
        }
    };
    for i in 0..g.len() {
        consider(g[i]);
        for j in i + 1..g.len() {
            consider(g[i] + g[j]);
            for k in j + 1..g.len() {
                let d = (g[j] - g[i]).cross(g[k] - g[i]);
                consider(if d.dot(g[i]) >= 0.0 { d } else { -d });
            }
        }
    }
    best
}

/// Where the view's normal is at least this close to every triangle around a vertex
/// (cosine), it is the offset direction; elsewhere the widest direction is, if wider.
const NORMAL_MARGIN: f64 = 0.25;

/// Offset directions and how each prism's corners sit.
struct Frame {
    dir: Vec<DVec3>,
    /// Per triangle, the corners whose offset direction disagrees with its winding.
    flip: Vec<[bool; 3]>,
    /// Vertices no direction fits.
    singular: Vec<bool>,
}

/// The offset direction of every vertex: the view's normal n̂ (eq. 1) where every triangle
/// around the vertex faces its way by a margin, otherwise the direction that faces the
/// triangles around it best ([`widest_direction`] of their unit normals, each turned to the
/// vertex's reference winding); both depend on the mesh and the view, not on the
/// parametrization. n̂'s sign follows the triangles' winding (eq. 3 depends on |2t - 1|
/// only). Where no direction faces every triangle, the vertex is singular.
fn frame(p: &Projected, triangles: &[[u32; 3]], stars: &Stars) -> Frame {
    let n = p.positions.len();
    let unit_normals: Vec<DVec3> = triangles
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| p.positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    // Per vertex: its direction, whether it is singular, and (flat, along the stars)
    // whether each triangle around it is reversed; vertices shared among threads.
    let vertex = |v: usize, scratch: &mut Scratch| {
        let star = stars.of(v);
        reversed_in_star(star, triangles, scratch);
        let g = &mut scratch.g;
        g.clear();
        g.extend(star.iter().zip(&scratch.reversed).map(|(&(t, _), &r)| {
            let f = unit_normals[t as usize];
            if r { -f } else { f }
        }));
        let normal = if g.iter().map(|x| x.dot(p.normals[v])).sum::<f64>() >= 0.0 {
            p.normals[v]
        } else {
            -p.normals[v]
        };
        let margin = g
            .iter()
            .map(|x| x.dot(normal))
            .fold(f64::INFINITY, f64::min);
        if star.is_empty() || margin >= NORMAL_MARGIN {
            return (normal, false);
        }
        let (wide, wide_margin) = widest_direction(g);
        let dir = if wide_margin > margin { wide } else { normal };
        (dir, wide_margin.max(margin) <= 0.0)
    };
    // Runs of FRAME_RUN vertices, each with its scratch buffers, joined in vertex order.
    let parts: Vec<FramePart> = (0..n)
        .into_par_iter()
        .step_by(FRAME_RUN)
        .map_init(Scratch::default, |scratch, first| {
            let mut part = FramePart::default();
            for v in first..(first + FRAME_RUN).min(n) {
                let (dir, singular) = vertex(v, scratch);
                part.dir.push(dir);
                part.singular.push(singular);
                part.reversed.extend_from_slice(&scratch.reversed);
            }
            part
        })
        .collect();
    let mut frame = Frame {
        dir: Vec::with_capacity(n),
        flip: vec![[false; 3]; triangles.len()],
        singular: Vec::with_capacity(n),
    };
    let mut reversed = Vec::with_capacity(stars.uses.len());
    for part in parts {
        frame.dir.extend(part.dir);
        frame.singular.extend(part.singular);
        reversed.extend(part.reversed);
    }
    for (&(t, k), r) in stars.uses.iter().zip(reversed) {
        frame.flip[t as usize][k as usize] = r;
    }
    frame
}

/// Halvings of rho at a vertex before it collapses to zero.
pub const HALVINGS: u32 = 10;

/// How fast rho may grow along the surface away from where it is lowered (a shrunk,
/// collapsed or singular vertex): at most this much per unit of distance along the mesh's
/// edges. Halved at single vertices and kept at their neighbours, rho would jump from vertex
/// to vertex, and the gap the halo cuts into a sheet passing under would follow the mesh in
/// a staircase; graded, the gap's edge runs smoothly and shrinks no faster than this.
pub const RHO_SLOPE: f64 = 0.25;

/// Lowers `rho` to its graded envelope, the largest field below it that grows by at most
/// [`RHO_SLOPE`] times the length of every mesh edge, where `rho` was graded but at
/// `sources` (the vertices lowered since; all of them where unknown): only a path from one
/// of those can lower a vertex. Dijkstra from the sources at once, in one deterministic
/// order. Gives the vertices it lowered.
fn grade(
    rho: &mut [f64],
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    stars: &Stars,
    sources: &[u32],
) -> Vec<u32> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    /// A vertex and its rho, ordered by rho, then by index.
    #[derive(PartialEq)]
    struct Entry(f64, u32);
    impl Eq for Entry {}
    impl PartialOrd for Entry {
        fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(other))
        }
    }
    impl Ord for Entry {
        fn cmp(&self, other: &Self) -> std::cmp::Ordering {
            self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
        }
    }
    let before = rho.to_vec();
    let mut heap: BinaryHeap<Reverse<Entry>> = sources
        .iter()
        .map(|&v| Reverse(Entry(rho[v as usize], v)))
        .collect();
    while let Some(Reverse(Entry(r, v))) = heap.pop() {
        if r > rho[v as usize] {
            continue;
        }
        for &(t, _) in stars.of(v as usize) {
            for u in triangles[t as usize] {
                let reach =
                    r + RHO_SLOPE * (positions[u as usize] - positions[v as usize]).length();
                if reach < rho[u as usize] {
                    rho[u as usize] = reach;
                    heap.push(Reverse(Entry(reach, u)));
                }
            }
        }
    }
    (0..rho.len() as u32)
        .filter(|&v| rho[v as usize] < before[v as usize])
        .collect()
}

/// Rounds to f32, the precision of the exported files, so that the checked halo is the
/// exported one.
fn f32_exact(p: DVec3) -> DVec3 {
    p.as_vec3().as_dvec3()
}

/// The halo's offset and surface vertices as rho changes, and which corners collapsed.
struct Offsets<'a> {
    projected: &'a Projected,
    dir: Vec<DVec3>,
    rho: Vec<f64>,
    positions: Vec<DVec3>,
    collapsed: Vec<bool>,
}

impl<'a> Offsets<'a> {
    /// Every vertex's offsets placed at `rho` along its direction `dir`, or at 0 where the
    /// vertex is `singular` and folds are shrunk.
    fn new(
        projected: &'a Projected,
        dir: Vec<DVec3>,
        singular: &[bool],
        rho: f64,
        shrink: bool,
    ) -> Self {
        let n = projected.positions.len();
        let mut offsets = Offsets {
            projected,
            rho: (0..n)
                .map(|v| if shrink && singular[v] { 0.0 } else { rho })
                .collect(),
            dir,
            positions: [vec![DVec3::ZERO; 2 * n], projected.positions.clone()].concat(),
            collapsed: vec![false; n],
        };
        for v in 0..n {
            offsets.place(v);
        }
        offsets
    }

    /// Places vertex v's two offsets at ∓rho[v] along its direction; where they round to one
    /// point, the vertex collapses.
    fn place(&mut self, v: usize) {
        let n = self.rho.len();
        let (p, d) = (self.projected.positions[v], self.dir[v]);
        let (below, above) = (
            f32_exact(p - d * self.rho[v]),
            f32_exact(p + d * self.rho[v]),
        );
        self.collapsed[v] = below == above;
        if self.collapsed[v] {
            self.rho[v] = 0.0;
        }
        (self.positions[v], self.positions[n + v]) = (below, above);
    }

    fn corners(&self, tri: [u32; 3], flip: [bool; 3]) -> Corners {
        Corners {
            tri,
            flip,
            collapsed: tri.map(|i| self.collapsed[i as usize]),
        }
    }
}

/// The surface vertices of prism `c`'s inverted or flat tetrahedra (exact orientation), in
/// either layer.
fn inverted_corners(c: &Corners, forward: [bool; 3], positions: &[DVec3], out: &mut Vec<u32>) {
    let n = (positions.len() / 3) as u32;
    let forward = c.effective(forward);
    for v in c.layers(n) {
        let centre = tets::cyclic(forward).then(|| tets::centre(v, positions));
        let at = |i: u32| {
            let p = if i == u32::MAX {
                centre.unwrap_or_default()
            } else {
                positions[i as usize]
            };
            robust::Coord3D {
                x: p.x,
                y: p.y,
                z: p.z,
            }
        };
        for tet in tets::prism_tets(v, forward, u32::MAX) {
            if robust::orient3d(at(tet[0]), at(tet[1]), at(tet[2]), at(tet[3])) <= 0.0 {
                out.extend(tet.iter().filter(|&&i| i < 3 * n).map(|&i| i % n));
            }
        }
    }
}

/// Thickens a projected surface by `rho` (absolute) and splits it into tetrahedra, then
/// checks the result with the independent checker.
pub fn build_halo(
    projected: &Projected,
    triangles: &[[u32; 3]],
    rho: f64,
    params: &HaloParams,
) -> (Halo, HaloReport) {
    build_halo_until(projected, triangles, rho, params, Cancel::never())
}

/// [`build_halo`], stopping between its steps once `cancel` is cancelled (with an empty
/// halo, which the caller drops).
pub fn build_halo_until(
    projected: &Projected,
    triangles: &[[u32; 3]],
    rho: f64,
    params: &HaloParams,
    cancel: &Cancel,
) -> (Halo, HaloReport) {
    let start = Instant::now();
    let mut stage_ms = HaloStages::default();
    let mut lap = {
        let mut last = Instant::now();
        move |to: &mut f64| {
            *to = last.elapsed().as_secs_f64() * 1e3;
            last = Instant::now();
        }
    };
    let n = projected.positions.len();
    let stars = Stars::new(n, triangles);
    let frame = frame(projected, triangles, &stars);
    let shrink = params.fold == Fold::Shrink;
    let mut offsets = Offsets::new(projected, frame.dir, &frame.singular, rho, shrink);
    let mut corners: Vec<Corners> = triangles
        .iter()
        .zip(&frame.flip)
        .map(|(&tri, &flip)| offsets.corners(tri, flip))
        .collect();
    lap(&mut stage_ms.directions);
    if cancel.is_cancelled() {
        return Default::default();
    }
    let (forward, stats) = tets::plan(&corners, &offsets.positions, n, params.split);
    lap(&mut stage_ms.plan);
    if cancel.is_cancelled() {
        return Default::default();
    }

    if shrink {
        let surface = Surface {
            triangles,
            stars: &stars,
            flip: &frame.flip,
        };
        shrink_folds(&mut offsets, &mut corners, &forward, &surface, rho);
    }
    lap(&mut stage_ms.shrink);
    if cancel.is_cancelled() {
        return Default::default();
    }
    let tets = tets::emit(&corners, &forward, &offsets.positions, n, stats);

    let (t, d_orig) = t_and_depth(&offsets.collapsed, &projected.w, triangles, &tets);
    let mut positions = offsets.positions;
    positions.extend_from_slice(&tets.inserted);
    let halo = Halo {
        surface_vertices: n,
        positions,
        t,
        d_orig,
        tets: tets.tets,
        rho: offsets.rho,
        inserted_in: tets.inserted_in,
    };
    lap(&mut stage_ms.split);
    if cancel.is_cancelled() {
        return Default::default();
    }
    let checked = check_parts_until(&halo.positions, n, &halo.tets, triangles, cancel);
    lap(&mut stage_ms.check);
    let report = HaloReport {
        split: params.split.name(),
        prisms: triangles.len(),
        tets: halo.tets.len(),
        rho,
        split_stats: tets.stats,
        inverted: checked.inverted + checked.flat,
        shrunk_vertices: halo.rho.iter().filter(|&&r| r < rho).count(),
        collapsed_vertices: offsets.collapsed.iter().filter(|&&c| c).count(),
        singular_vertices: frame.singular.iter().filter(|&&s| s).count(),
        twisted_prisms: frame
            .flip
            .iter()
            .filter(|f| !(f[0] == f[1] && f[1] == f[2]))
            .count(),
        min_dihedral_deg: checked.min_dihedral_deg,
        check: checked,
        ms: start.elapsed().as_secs_f64() * 1e3,
        stage_ms,
    };
    (halo, report)
}

/// The surface as the shrinking walks it: its triangles, the triangles around each vertex,
/// and each triangle's corners whose offset direction disagrees with its winding.
struct Surface<'a> {
    triangles: &'a [[u32; 3]],
    stars: &'a Stars,
    flip: &'a [[bool; 3]],
}

/// `fold: shrink`: halves rho (from `rho`, the asked one) at the corners of inverted
/// tetrahedra, re-examining only the prisms around them, until none is left (a vertex halved
/// [`HALVINGS`] times collapses), then grades rho and starts again where that inverts a
/// tetrahedron. Updates the offsets and the prisms' corners; the diagonals (`forward`) stay.
fn shrink_folds(
    offsets: &mut Offsets,
    corners: &mut [Corners],
    forward: &[[bool; 3]],
    surface: &Surface,
    rho: f64,
) {
    let Surface {
        triangles,
        stars,
        flip,
    } = *surface;
    let floor = rho * 0.5f64.powi(HALVINGS as i32);
    let mut bad = corners
        .par_iter()
        .zip(forward)
        .fold(Vec::new, |mut bad, (c, f)| {
            inverted_corners(c, *f, &offsets.positions, &mut bad);
            bad
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    // The vertices lowered since rho was last graded: at first the singular ones, zero
    // from the start (the rest, all at `rho`, are graded).
    let mut lowered_since: Vec<u32> = (0..offsets.rho.len() as u32)
        .filter(|&v| offsets.rho[v as usize] < rho)
        .collect();
    let mut stamp = vec![usize::MAX; triangles.len()];
    let mut round = 0;
    let mut reexamine = |touched: &[u32], offsets: &Offsets, bad: &mut Vec<u32>| {
        round += 1;
        for &v in touched {
            for &(t, _) in stars.of(v as usize) {
                let t = t as usize;
                if stamp[t] != round {
                    stamp[t] = round;
                    corners[t] = offsets.corners(triangles[t], flip[t]);
                    inverted_corners(&corners[t], forward[t], &offsets.positions, bad);
                }
            }
        }
    };
    // Each round lowers the rho of every corner of an inverted tetrahedron (halved, or
    // zero from the floor on), so the loop ends: every vertex can be lowered at most
    // HALVINGS + 1 times. A round that lowers nothing (every corner already collapsed:
    // the prism is as thin as it can be) ends it too, and the checker counts what is
    // left. No grading of rho between neighbours is needed: the surface triangle is a
    // face of both layers, so however rho varies the surface keeps t = 1/2.
    // Then rho is graded around every lowered vertex ([`grade`]); where that inverts a
    // tetrahedron (rho only falls, but unevenly), the halving starts again. Both only
    // lower rho, so this ends too.
    loop {
        loop {
            bad.sort_unstable();
            bad.dedup();
            bad.retain(|&v| offsets.rho[v as usize] > 0.0);
            if bad.is_empty() {
                break;
            }
            for &v in &bad {
                let v = v as usize;
                offsets.rho[v] = if offsets.rho[v] > floor {
                    0.5 * offsets.rho[v]
                } else {
                    0.0
                };
                offsets.place(v);
            }
            lowered_since.extend_from_slice(&bad);
            let touched = std::mem::take(&mut bad);
            reexamine(&touched, offsets, &mut bad);
        }
        lowered_since.sort_unstable();
        lowered_since.dedup();
        let lowered = grade(
            &mut offsets.rho,
            &offsets.projected.positions,
            triangles,
            stars,
            &lowered_since,
        );
        lowered_since.clear();
        if lowered.is_empty() {
            break;
        }
        for &v in &lowered {
            offsets.place(v as usize);
        }
        reexamine(&lowered, offsets, &mut bad);
    }
}

/// The t and d_orig of every halo vertex: t = 0, 1 and 1/2 on the negative offsets, the
/// positive offsets and the surface (1/2 at both offsets of a `collapsed` vertex), the
/// w-depth `w` of the surface vertex; at a vertex inserted in a prism, the mean t of its layer
/// and the mean depth of its triangle, rounded to f32 like every value the files store.
fn t_and_depth(
    collapsed: &[bool],
    w: &[f64],
    triangles: &[[u32; 3]],
    tets: &tets::Tetrahedra,
) -> (Vec<f64>, Vec<f64>) {
    let n = collapsed.len();
    let mut t = [vec![0.0; n], vec![1.0; n], vec![0.5; n]].concat();
    for v in (0..n).filter(|&v| collapsed[v]) {
        (t[v], t[n + v]) = (0.5, 0.5);
    }
    let mut d_orig = w.repeat(3);
    for (&tri, over) in tets.inserted_in.iter().zip(&tets.inserted_over) {
        let layer_t = over.iter().map(|&i| t[i as usize]).sum::<f64>() / 6.0;
        let corners = triangles[tri as usize];
        let mean = corners.iter().map(|&i| w[i as usize]).sum::<f64>() / 3.0;
        t.push(layer_t as f32 as f64);
        d_orig.push(mean as f32 as f64);
    }
    (t, d_orig)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grading_lowers_rho_to_its_envelope_and_nothing_else() {
        // A strip of 2 x 6 vertices a unit apart along x: one vertex at 0 (a collapsed
        // vertex) lowers its neighbours by RHO_SLOPE per unit of distance, up to the
        // given rho.
        let positions: Vec<DVec3> = (0..12)
            .map(|i| DVec3::new((i % 6) as f64, (i / 6) as f64, 0.0))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..5)
            .flat_map(|i| [[i, i + 1, i + 7], [i, i + 7, i + 6]])
            .collect();
        let stars = Stars::new(12, &triangles);
        let all: Vec<u32> = (0..12).collect();
        let mut rho = vec![1.0; 12];
        rho[0] = 0.0;
        // From its one lowered vertex, as from all: the same field.
        let mut from_all = rho.clone();
        let lowered = grade(&mut rho, &positions, &triangles, &stars, &[0]);
        grade(&mut from_all, &positions, &triangles, &stars, &all);
        assert_eq!(rho, from_all);
        for (v, &r) in rho.iter().enumerate() {
            // The graph distance from vertex 0 along the strip's edges.
            let (x, y) = ((v % 6) as f64, (v / 6) as f64);
            let distance = if y == 0.0 {
                x
            } else {
                (x - 1.0).max(0.0) + std::f64::consts::SQRT_2.min(1.0 + x)
            };
            let expect = (RHO_SLOPE * distance).min(1.0);
            assert!(
                (r - expect).abs() < 1e-12,
                "vertex {v}: {r} against {expect}"
            );
        }
        assert_eq!(
            lowered,
            (1..12u32)
                .filter(|&v| rho[v as usize] < 1.0)
                .collect::<Vec<_>>()
        );
        // Graded once, it is its own envelope.
        let again = rho.clone();
        assert!(grade(&mut rho, &positions, &triangles, &stars, &all).is_empty());
        assert_eq!(rho, again);
        // Lowered again at the far end, graded from there alone as from all.
        rho[11] = 0.0;
        from_all = rho.clone();
        let lowered = grade(&mut rho, &positions, &triangles, &stars, &[11]);
        assert_eq!(
            lowered,
            grade(&mut from_all, &positions, &triangles, &stars, &all)
        );
        assert_eq!(rho, from_all);
        assert!(lowered.contains(&10) && !lowered.contains(&0));
    }
}
