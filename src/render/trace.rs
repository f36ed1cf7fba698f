//! Every intersection of a ray with the projected triangles, through an obvhs BVH, or for a
//! picture's primary rays through the tiles of the picture ([`Primary`]).

use super::CameraProjection;
use super::camera::Camera;
use crate::intersect::broad;
use crate::parts::Parts;
use glam::{DVec3, Vec3A};
use obvhs::bvh2::Bvh2;
use obvhs::ray::Ray;
use rayon::prelude::*;

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

    /// The tracer of the surfaces of `parts`, as the renderer makes it: their triangles,
    /// with the box of the triangles' corners as the scene's size.
    pub fn of_parts(parts: &'a Parts<'a>) -> Self {
        let surfaces: Vec<TraceSurface> = parts
            .surfaces
            .iter()
            .map(|s| TraceSurface {
                positions: s.positions,
                triangles: s.triangles,
            })
            .collect();
        let size = super::triangle_bounds(surfaces.iter().map(|s| (s.positions, s.triangles)))
            .map_or(1.0, |(lo, hi)| (hi - lo).length());
        Tracer::new(surfaces, size)
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

    /// Sorts hits by t (then surface and triangle, so that the order the triangles were
    /// met in does not matter) and drops the second of two at one t on neighbouring
    /// triangles of one surface (a ray through their shared edge or vertex).
    fn order(&self, hits: &mut Vec<Hit>) {
        hits.sort_by(|a, b| {
            a.t.total_cmp(&b.t)
                .then(a.surface.cmp(&b.surface))
                .then(a.triangle.cmp(&b.triangle))
        });
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

/// Pixels on a side of a tile of [`Primary`].
const TILE: f64 = 8.0;

/// How many tile entries, per triangle and per tile, binning may make before the BVH is
/// the better way (long slivers across the picture).
const MOST_ENTRIES: usize = 16;

/// A triangle of one tile: its BVH slot and its projection as three edge lines in image
/// coordinates, each `[a, b, c]` with `a x + b y + c` the signed distance of image point
/// (x, y) from the line (positive inside) plus a margin: how far outside a point may lie
/// and still be hit, far more than the rounding of the projection and of the exact test's
/// shear (a millionth of the projection's box and a billionth of its coordinates, as
/// [`projected_box`]'s pad). The lines are kept in f32, half the memory a ray reads, with a
/// millionth of `1 + |c|` more margin, and a ray's point adds a millionth of `|x| + |y|`:
/// together well above three times the rounding of f32 (six parts in 10^8 an operation,
/// |a| and |b| at most 1). A triangle whose projection has (almost) no area, or none (it
/// reaches a perspective eye's plane), keeps every point (zero lines): the exact test
/// decides.
#[derive(Clone, Copy, Debug)]
struct Entry {
    slot: u32,
    lines: [[f32; 3]; 3],
}

impl Entry {
    /// The entry of the triangle in `slot` with the projection `q` (image coordinates),
    /// if it has one.
    fn new(slot: u32, q: Option<[[f64; 2]; 3]>) -> Self {
        let every = Entry {
            slot,
            lines: [[0.0; 3]; 3],
        };
        let Some(q) = q else { return every };
        let (lo, hi) = (
            [0, 1].map(|k| q[0][k].min(q[1][k]).min(q[2][k])),
            [0, 1].map(|k| q[0][k].max(q[1][k]).max(q[2][k])),
        );
        let diagonal = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let size = [lo[0], lo[1], hi[0], hi[1]]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let margin = 1e-6 * diagonal + 1e-9 * (1.0 + size);
        let twice_area =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
        if !twice_area.is_finite() || twice_area.abs() <= 1e-12 * diagonal * diagonal {
            return every;
        }
        let sign = twice_area.signum();
        let lines = [0, 1, 2].map(|i| {
            let (from, to) = (q[(i + 1) % 3], q[(i + 2) % 3]);
            let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
            let length = dx.hypot(dy);
            let (a, b) = (-sign * dy / length, sign * dx / length);
            let c = margin - (a * from[0] + b * from[1]);
            [a as f32, b as f32, (c + 1e-6 * (1.0 + c.abs())) as f32]
        });
        Entry { slot, lines }
    }
}

/// Entries side by side in a [`Block`].
const LANES: usize = 8;

/// [`LANES`] entries of one tile, their lines' coefficients lane by lane (`lines[edge][k]`
/// holds coefficient k of that edge of every lane), so that one ray tests them all at once
/// in the processor's vector registers. A tile's last block is filled with lanes that turn
/// every point away.
#[derive(Clone, Copy, Debug)]
struct Block {
    slots: [u32; LANES],
    lines: [[[f32; LANES]; 3]; 3],
}

impl Block {
    /// A block of lanes that hold no triangle.
    const EMPTY: Block = Block {
        slots: [u32::MAX; LANES],
        lines: [[[0.0; LANES], [0.0; LANES], [f32::NEG_INFINITY; LANES]]; 3],
    };

    /// Puts `entry` in lane `lane`.
    fn set(&mut self, lane: usize, entry: &Entry) {
        self.slots[lane] = entry.slot;
        for (edge, line) in self.lines.iter_mut().zip(&entry.lines) {
            for (coefficient, &value) in edge.iter_mut().zip(line) {
                coefficient[lane] = value;
            }
        }
    }

    /// Bit `i` set where image point `at` (in f32, with its slack: [`Entry`]) lies within
    /// the margin of lane `i`'s projected triangle. No lane's line gives NaN for a finite
    /// point (their coefficients are finite but for the empty lanes' `c`, minus infinity).
    #[inline]
    fn near(&self, [x, y, slack]: [f32; 3]) -> u32 {
        let mut inside = [true; LANES];
        for [a, b, c] in &self.lines {
            for i in 0..LANES {
                inside[i] &= a[i] * x + b[i] * y + c[i] >= -slack;
            }
        }
        inside
            .iter()
            .enumerate()
            .fold(0, |mask, (i, &t)| mask | (u32::from(t) << i))
    }
}

/// The triangles of a [`Tracer`] as one camera's picture sees them, for its primary rays
/// (through image points (sx, sy) in [-1, 1]^2, y up, as [`Camera::ray`] takes them): each
/// triangle listed in the square tiles of the picture its projected box meets (grown by far
/// more than rounding), so that a ray tests the few triangles of its tile whose projections
/// come near its image point (tested in f32 with a margin far above its rounding), with the
/// tracer's exact test. A triangle whose projection is unbounded (it reaches the plane of a
/// perspective eye) is in every tile. The hits are the tracer's own, ordered alike: a
/// triangle a ray meets projects to a triangle that holds the ray's image point, within
/// rounding. Where binning would make too many entries (slivers across the picture) the
/// rays go through the BVH.
pub struct Primary<'t, 'a> {
    tracer: &'t Tracer<'a>,
    cam: Camera,
    tiles: Option<Tiles>,
}

struct Tiles {
    /// Tiles across and down; image units per tile along x and y.
    cols: usize,
    rows: usize,
    step: [f64; 2],
    /// Each tile's entries in blocks: `blocks[starts[i]..starts[i + 1]]`, tiles row by row
    /// from the bottom (sy = -1).
    starts: Vec<usize>,
    blocks: Vec<Block>,
    /// Triangles in every tile, in blocks.
    everywhere: Vec<Block>,
}

impl<'t, 'a> Primary<'t, 'a> {
    /// The triangles of `tracer` binned for `cam`'s picture of `width` x `height` pixels.
    pub fn new(tracer: &'t Tracer<'a>, cam: &Camera, width: u32, height: u32) -> Self {
        Primary {
            tracer,
            cam: *cam,
            tiles: Tiles::new(tracer, cam, width, height),
        }
    }

    /// The camera whose picture the triangles are binned for.
    pub fn camera(&self) -> &Camera {
        &self.cam
    }

    /// [`Tracer::hits`] of the ray from the camera's eye to `p` ([`Camera::ray_to`]),
    /// which is a primary ray where `p` is in the picture: through the tiles there, through
    /// the BVH elsewhere. Gives the ray (origin, unit direction).
    pub fn hits_towards(&self, p: DVec3, t_min: f64, hits: &mut Vec<Hit>) -> (DVec3, DVec3) {
        let (origin, dir) = self.cam.ray_to(p);
        match image_point(&self.cam, p) {
            Some(at) if at[0].abs() <= 1.0 && at[1].abs() <= 1.0 => {
                self.hits(at, origin, dir, t_min, hits)
            }
            _ => self.tracer.hits(origin, dir, t_min, hits),
        }
        (origin, dir)
    }

    /// [`Tracer::hits`] of the primary ray through image point `at`.
    pub fn hits(&self, at: [f64; 2], origin: DVec3, dir: DVec3, t_min: f64, hits: &mut Vec<Hit>) {
        let Some(tiles) = &self.tiles else {
            return self.tracer.hits(origin, dir, t_min, hits);
        };
        tiles.collect(self.tracer, at, origin, dir, t_min, hits);
        self.tracer.order(hits);
    }

    /// The hits of the primary ray through image point `at` from its start, ordered:
    /// [`Primary::hits`] through the tiles (which find them all at once), of which the
    /// first `count` are [`Primary::nearest_hits`] within `slack`; through the BVH, those
    /// nearest hits alone, found by its closest-hit traversal.
    pub fn nearest_first(
        &self,
        at: [f64; 2],
        origin: DVec3,
        dir: DVec3,
        slack: f64,
        hits: &mut Vec<Hit>,
    ) -> Nearest {
        let Some(tiles) = &self.tiles else {
            self.tracer.nearest_hits(origin, dir, 0.0, slack, hits);
            return Nearest {
                count: hits.len(),
                all: false,
            };
        };
        tiles.collect(self.tracer, at, origin, dir, 0.0, hits);
        // Ordering keeps the hits by t, and drops a hit only for one before it: the
        // nearest hits' order is the start of this one.
        self.tracer.order(hits);
        let reach = hits.first().map_or(f64::NEG_INFINITY, |h| h.t + slack);
        Nearest {
            count: hits.partition_point(|h| h.t <= reach),
            all: true,
        }
    }

    /// [`Tracer::nearest_hits`] of the primary ray through image point `at`.
    pub fn nearest_hits(
        &self,
        at: [f64; 2],
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        slack: f64,
        hits: &mut Vec<Hit>,
    ) {
        let Some(tiles) = &self.tiles else {
            return self.tracer.nearest_hits(origin, dir, t_min, slack, hits);
        };
        tiles.collect(self.tracer, at, origin, dir, t_min, hits);
        let nearest = hits.iter().map(|h| h.t).fold(f64::INFINITY, f64::min);
        hits.retain(|h| h.t <= nearest + slack);
        self.tracer.order(hits);
    }
}

/// The tiles a triangle's box meets: its first and last column, then its first and last
/// row.
type Span = [[usize; 2]; 2];

/// A box in image coordinates: its least and greatest corners.
type ImageBox = ([f64; 2], [f64; 2]);

/// What [`Primary::nearest_first`] found.
#[derive(Clone, Copy, Debug)]
pub struct Nearest {
    /// How many of the hits lie no farther than the slack past the nearest one.
    pub count: usize,
    /// Whether the hits are every hit of the ray (through the tiles), not those alone
    /// (through the BVH).
    pub all: bool,
}

/// The tile along one axis that image coordinate `x` falls in, for tiles of `step` image
/// units and `count` tiles (a coordinate outside the picture goes to the nearest).
fn tile_index(x: f64, step: f64, count: usize) -> usize {
    (((x + 1.0) / step).floor().max(0.0) as usize).min(count - 1)
}

impl Tiles {
    fn new(tracer: &Tracer, cam: &Camera, width: u32, height: u32) -> Option<Tiles> {
        let cols = (f64::from(width) / TILE).ceil() as usize;
        let rows = (f64::from(height) / TILE).ceil() as usize;
        // Image units per tile: the picture spans 2 along each axis.
        let step = [
            2.0 * TILE / f64::from(width),
            2.0 * TILE / f64::from(height),
        ];
        // Each triangle in the picture with its entry and the tiles its box meets (columns,
        // then rows, inclusive), projected on the cores; those that reach the eye's plane
        // in every tile.
        let projected: Vec<Option<(Entry, Option<Span>)>> = tracer
            .corners
            .par_iter()
            .enumerate()
            .map(|(slot, corners)| {
                let slot = slot as u32;
                let Some((image, (lo, hi))) = projected_box(cam, corners) else {
                    return Some((Entry::new(slot, None), None));
                };
                if hi[0] < -1.0 || lo[0] > 1.0 || hi[1] < -1.0 || lo[1] > 1.0 {
                    return None; // outside the picture: no primary ray meets it
                }
                let span = [0, 1].map(|k| {
                    let count = [cols, rows][k];
                    [
                        tile_index(lo[k], step[k], count),
                        tile_index(hi[k], step[k], count),
                    ]
                });
                Some((Entry::new(slot, Some(image)), Some(span)))
            })
            .collect();
        let mut placed = Vec::new();
        let mut everywhere = Vec::new();
        let mut counts = vec![0usize; cols * rows + 1];
        let mut total = 0usize;
        for (entry, span) in projected.into_iter().flatten() {
            let Some(span) = span else {
                everywhere.push(entry);
                continue;
            };
            for j in span[1][0]..=span[1][1] {
                for i in span[0][0]..=span[0][1] {
                    counts[j * cols + i + 1] += 1;
                    total += 1;
                }
            }
            placed.push((entry, span));
            if total > MOST_ENTRIES * (tracer.corners.len() + cols * rows) {
                return None;
            }
        }
        // Each tile's entries laid out in its blocks, in the order of the triangles.
        let mut starts = vec![0usize; cols * rows + 1];
        for i in 0..cols * rows {
            starts[i + 1] = starts[i] + counts[i + 1].div_ceil(LANES);
        }
        let mut fill: Vec<usize> = starts[..cols * rows].iter().map(|s| s * LANES).collect();
        let mut blocks = vec![Block::EMPTY; starts[cols * rows]];
        for (entry, span) in placed {
            for j in span[1][0]..=span[1][1] {
                for i in span[0][0]..=span[0][1] {
                    let k = &mut fill[j * cols + i];
                    blocks[*k / LANES].set(*k % LANES, &entry);
                    *k += 1;
                }
            }
        }
        Some(Tiles {
            cols,
            rows,
            step,
            starts,
            blocks,
            everywhere: in_blocks(&everywhere),
        })
    }

    /// Every hit beyond `t_min` of the ray through image point `at` on the triangles of its
    /// tile whose projections come near the point ([`Block::near`]: the exact test of a
    /// triangle farther away would miss), unordered, into `hits` (cleared first).
    fn collect(
        &self,
        tracer: &Tracer,
        at: [f64; 2],
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        hits: &mut Vec<Hit>,
    ) {
        hits.clear();
        let i = tile_index(at[0], self.step[0], self.cols);
        let j = tile_index(at[1], self.step[1], self.rows);
        let tile = j * self.cols + i;
        let shear = Shear::new(origin, dir);
        let blocks = &self.blocks[self.starts[tile]..self.starts[tile + 1]];
        let point = [
            at[0] as f32,
            at[1] as f32,
            (1e-6 * (at[0].abs() + at[1].abs())) as f32,
        ];
        for block in blocks.iter().chain(&self.everywhere) {
            let mut near = block.near(point);
            while near != 0 {
                let lane = near.trailing_zeros() as usize;
                near &= near - 1;
                if let Some(hit) = tracer.hit(&shear, block.slots[lane] as usize)
                    && hit.t > t_min
                {
                    hits.push(hit);
                }
            }
        }
    }
}

/// `entries` in blocks of [`LANES`], in order.
fn in_blocks(entries: &[Entry]) -> Vec<Block> {
    entries
        .chunks(LANES)
        .map(|chunk| {
            let mut block = Block::EMPTY;
            for (lane, entry) in chunk.iter().enumerate() {
                block.set(lane, entry);
            }
            block
        })
        .collect()
}

/// Triangle `p`'s projection by `cam` in image coordinates, and its box grown by far more
/// than the rounding of a hit's image point (a millionth of the box's size, and a
/// billionth of the picture); `None` where a perspective eye's plane comes near the
/// triangle (its projection is unbounded).
fn projected_box(cam: &Camera, p: &[DVec3; 3]) -> Option<([[f64; 2]; 3], ImageBox)> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut images = [[0.0; 2]; 3];
    for (&q, out) in p.iter().zip(&mut images) {
        let image = image_point(cam, q)?;
        *out = image;
        for k in 0..2 {
            lo[k] = lo[k].min(image[k]);
            hi[k] = hi[k].max(image[k]);
        }
    }
    if !(lo[0].is_finite() && lo[1].is_finite() && hi[0].is_finite() && hi[1].is_finite()) {
        return None;
    }
    let pad = |k: usize| 1e-6 * (hi[k] - lo[k]) + 1e-9;
    Some((
        images,
        (
            [lo[0] - pad(0), lo[1] - pad(1)],
            [hi[0] + pad(0), hi[1] + pad(1)],
        ),
    ))
}

/// Where `q` lies in `cam`'s picture, in image coordinates ([-1, 1]^2 across it, y up);
/// `None` where it is not far enough in front of a perspective eye for the division to be
/// well conditioned.
fn image_point(cam: &Camera, q: DVec3) -> Option<[f64; 2]> {
    let (hw, hh) = (cam.half_height * cam.aspect, cam.half_height);
    let d = q - cam.eye;
    let (x, y, z) = (d.dot(cam.right), d.dot(cam.up), d.dot(cam.forward));
    match cam.projection {
        CameraProjection::Perspective => {
            // A NaN compares false and is refused too.
            if z.partial_cmp(&(1e-9 * d.length())) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            Some([x / (z * hw), y / (z * hh)])
        }
        CameraProjection::Orthographic => Some([x / hw, y / hh]),
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

#[cfg(test)]
mod primary_tests {
    use super::*;
    use crate::render::{Prober, RenderSettings};

    #[test]
    fn a_block_answers_for_each_lane_alone() {
        // The triangle (0, 0), (1, 0), (0, 1) in lanes 2 and 7, a triangle with no area
        // (every point near) in lane 5, the rest empty: each lane's bit is its own entry's
        // answer, and an empty lane turns every point away.
        let triangle = Entry::new(3, Some([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]));
        let flat = Entry::new(9, Some([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]));
        let mut block = Block::EMPTY;
        for (lane, entry) in [(2, &triangle), (5, &flat), (7, &triangle)] {
            block.set(lane, entry);
        }
        assert_eq!(block.slots[7], 3);
        let inside = [0.25, 0.25, 0.0];
        let outside = [0.75, 0.75, 0.0];
        let far = [-1e6, 3e6, 4.0];
        assert_eq!(block.near(inside), 1 << 2 | 1 << 5 | 1 << 7);
        assert_eq!(block.near(outside), 1 << 5);
        assert_eq!(block.near(far), 1 << 5);
        assert_eq!(Block::EMPTY.near(inside), 0);
        // On an edge, within the margin.
        assert_eq!(block.near([0.5, 0.5, 0.0]), 1 << 2 | 1 << 5 | 1 << 7);
    }

    #[test]
    fn the_tiles_find_the_hits_the_bvh_finds() {
        // The default scene through the rays of a 96 x 80 picture (pixel centres and
        // points between them), from its own perspective camera, an orthographic camera
        // along the same axis, and a perspective eye inside the scene (triangles reach its
        // plane and are in every tile; others project across the picture): every ray's
        // hits, from the start and past a distance, and its nearest hits (alone, and as
        // the start of all its hits), are the tracer's own; and so are the hits of rays
        // towards points of the surfaces.
        let scene = crate::Scene::default_scene();
        let built = crate::Sampled::of(&scene)
            .into_built(&scene, crate::Stages::of(&scene))
            .unwrap();
        let parts = built.parts(&scene.halo);
        let (width, height) = (96, 80);
        let settings = RenderSettings {
            width,
            height,
            ..scene.render
        };
        let cam = *Prober::new(&parts, &settings, &scene.camera)
            .unwrap()
            .camera();
        let tracer = Tracer::of_parts(&parts);
        let (lo, hi) = crate::render::triangle_bounds(
            parts.surfaces.iter().map(|s| (s.positions, s.triangles)),
        )
        .unwrap();
        let size = (hi - lo).length();
        let centre = (lo + hi) / 2.0;
        let orthographic = Camera {
            projection: CameraProjection::Orthographic,
            half_height: 0.3 * size,
            ..cam
        };
        let inside = Camera {
            eye: centre - cam.forward * (0.05 * size),
            ..cam
        };
        let slack = 2.0 * tracer.same();
        let (mut expected, mut got) = (Vec::new(), Vec::new());
        for (name, cam) in [
            ("perspective", cam),
            ("orthographic", orthographic),
            ("inside", inside),
        ] {
            let primary = Primary::new(&tracer, &cam, width, height);
            let (mut rays, mut hit) = (0, 0);
            for j in 0..2 * height {
                for i in 0..2 * width {
                    let at = [
                        (f64::from(i) + 0.5) / f64::from(width) - 1.0,
                        1.0 - (f64::from(j) + 0.5) / f64::from(height),
                    ];
                    let (origin, dir) = cam.ray(at[0], at[1]);
                    for t_min in [0.0, 0.3 * size] {
                        tracer.hits(origin, dir, t_min, &mut expected);
                        primary.hits(at, origin, dir, t_min, &mut got);
                        assert_eq!(got, expected, "{name}: hits at {at:?} past {t_min}");
                    }
                    tracer.nearest_hits(origin, dir, 0.0, slack, &mut expected);
                    primary.nearest_hits(at, origin, dir, 0.0, slack, &mut got);
                    assert_eq!(got, expected, "{name}: nearest hits at {at:?}");
                    let near = primary.nearest_first(at, origin, dir, slack, &mut got);
                    assert!(near.all);
                    assert_eq!(
                        got[..near.count],
                        expected,
                        "{name}: nearest first at {at:?}"
                    );
                    tracer.hits(origin, dir, 0.0, &mut expected);
                    assert_eq!(got, expected, "{name}: all hits, nearest first, at {at:?}");
                    hit += usize::from(!expected.is_empty());
                    rays += 1;
                }
            }
            // Most rays of each camera meet the scene: the comparison is not of misses.
            assert!(hit * 3 > rays, "{name}: {hit} of {rays} rays hit");
            // Rays aimed at triangles' corners and the midpoints of their edges, where the
            // exact test and the tiles' edge lines are both at their limits: the same hits.
            let mut aimed = 0;
            for (slot, p) in tracer.corners.iter().enumerate().step_by(7) {
                let Some((image, _)) = projected_box(&cam, p) else {
                    continue;
                };
                for k in 0..3 {
                    let (a, b) = (image[k], image[(k + 1) % 3]);
                    for at in [a, [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]] {
                        if at.iter().any(|v| v.abs() > 1.0) {
                            continue;
                        }
                        let (origin, dir) = cam.ray(at[0], at[1]);
                        tracer.hits(origin, dir, 0.0, &mut expected);
                        primary.hits(at, origin, dir, 0.0, &mut got);
                        assert_eq!(got, expected, "{name}: hits at corner {k} of {slot}");
                        aimed += usize::from(!expected.is_empty());
                    }
                }
            }
            assert!(aimed > 40, "{name}: {aimed} aimed rays hit");
            // Rays from the eye towards points of the surfaces (their vertices and the
            // centres of their triangles, in the picture or out of it, behind the eye
            // too): the same hits through the tiles or the BVH.
            let mut towards = 0;
            for surf in &parts.surfaces {
                for (k, t) in surf.triangles.iter().enumerate().step_by(5) {
                    let q = t.map(|v| surf.positions[v as usize]);
                    for p in [q[k % 3], (q[0] + q[1] + q[2]) / 3.0] {
                        let (origin, dir) = primary.hits_towards(p, 0.0, &mut got);
                        assert_eq!((origin, dir), cam.ray_to(p));
                        tracer.hits(origin, dir, 0.0, &mut expected);
                        assert_eq!(got, expected, "{name}: hits towards {p}");
                        towards += usize::from(!expected.is_empty());
                    }
                }
            }
            assert!(
                towards > 2000,
                "{name}: {towards} rays towards the surfaces hit"
            );
        }
    }
}

#[cfg(test)]
mod fallback_tests {
    use super::*;

    #[test]
    fn triangles_across_the_whole_picture_go_through_the_bvh_with_the_same_hits() {
        // 64 sheets facing the eye, each covering the picture: listing each in all 16,384
        // tiles would be past the limit, so the rays go through the BVH.
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..64u32 {
            let z = 1.0 + f64::from(k) * 0.01;
            positions.extend([
                DVec3::new(-10.0, -10.0, z),
                DVec3::new(10.0, -10.0, z),
                DVec3::new(0.0, 10.0, z),
            ]);
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let tracer = Tracer::new(
            vec![TraceSurface {
                positions: &positions,
                triangles: &triangles,
            }],
            30.0,
        );
        let cam = Camera {
            eye: DVec3::new(0.0, 0.0, -1.0),
            forward: DVec3::Z,
            right: DVec3::X,
            up: DVec3::Y,
            projection: CameraProjection::Perspective,
            half_height: 0.5,
            aspect: 1.0,
        };
        let primary = Primary::new(&tracer, &cam, 1024, 1024);
        assert!(primary.tiles.is_none());
        let (mut expected, mut got) = (Vec::new(), Vec::new());
        for at in [[0.0, 0.0], [-0.9, 0.7], [0.5, -0.95]] {
            let (origin, dir) = cam.ray(at[0], at[1]);
            tracer.hits(origin, dir, 0.0, &mut expected);
            primary.hits(at, origin, dir, 0.0, &mut got);
            assert_eq!(expected.len(), 64);
            assert_eq!(got, expected);
            let near = primary.nearest_first(at, origin, dir, tracer.same(), &mut got);
            tracer.nearest_hits(origin, dir, 0.0, tracer.same(), &mut expected);
            assert!(!near.all && near.count == got.len());
            assert_eq!(got, expected);
        }
    }
}
