//! The stipple style (paper 003): dots whose density carries the tone, on the first sheet
//! the halos leave visible.
//!
//! Each surface carries a ranked blue-noise set fixed to its 4D mesh ([`Stipples`]). At a
//! stipple's place the Phong shading of a white surface (the shaded style's lights) gives the
//! ink the drawing aims for, `tone = 1 - luminance` ([`tone`]); [`density`] turns it into
//! stipples per square pixel for the stipple size; the triangle's screen area over its 4D
//! area turns that into a prefix of the ranking, and the stipple is drawn when its rank is
//! below it (paper 003's light and resolution enhancements: the ink follows the tone and stays
//! the same when the picture grows or the camera comes closer, and a small change of view
//! changes only how many stipples are drawn, never where they are). A drawn stipple must be
//! the first sheet the halos leave visible along its eye ray, decided as the shaded style
//! decides a hit (`exact` per hit, or `slices`): so the halos cut the same gaps. Stipples are
//! discs of `render.stipple.size` pixels, their union's coverage measured on 4 x 4 points per
//! pixel.

use super::camera::Camera;
use super::trace::{Hit, Primary};
use super::{RenderError, RenderMode, RibbonAxis, Scene, View, shade, slices};
use crate::stipple::Stipples;
use glam::DVec3;
use rayon::prelude::*;

/// A stipple a picture draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drawn {
    /// The surface it is on.
    pub surface: u32,
    /// Its rank in the surface's [`Stipples`].
    pub rank: u32,
    /// Where it is (3D).
    pub position: DVec3,
    /// Where it lands in the picture (pixel units, y down).
    pub pixel: [f64; 2],
    /// Its w-depth.
    pub w: f64,
    /// The ink aimed for there, in [0, 1].
    pub tone: f64,
    /// The set ran out there: the tone asked for more stipples than the surface has.
    pub saturated: bool,
    /// The radius of its disc in scene units at its place (half the stipple size in pixels
    /// there).
    pub radius: f64,
}

/// The ink a stipple drawing aims for on a surface of unit normal `n` seen along unit `dir`
/// through `cam`: one minus the luminance of a white surface under the shaded style's lights.
pub fn tone(n: DVec3, dir: DVec3, cam: &Camera) -> f64 {
    let lit = shade::phong(DVec3::ONE, n, dir, cam.right, cam.up);
    (1.0 - luminance(lit)).clamp(0.0, 1.0)
}

/// Linear RGB to luminance (Rec. 709).
pub fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Stipples per square pixel that cover a share `tone` of the picture with discs of diameter
/// `size` pixels, spread as a ranked blue-noise set spreads them. With x = density × disc
/// area, such discs barely overlap up to x = 0.4 and cover x; beyond, they crowd, and the
/// coverage saturates as 0.4 + 0.6 (1 - exp(-(x - 0.4) / 0.6)) (the same slope at 0.4, to 1).
/// The model is fitted to the ink measured on a lit sphere and checked there
/// (`tests/stipple.rs`: every tone band within 0.10 of its tone at two picture sizes). Tones
/// above 0.98 are drawn as 0.98.
pub fn density(tone: f64, size: f64) -> f64 {
    const APART: f64 = 0.4;
    let area = std::f64::consts::PI * size * size / 4.0;
    let t = tone.clamp(0.0, 0.98);
    let x = if t <= APART {
        t
    } else {
        APART - (1.0 - APART) * ((1.0 - t) / (1.0 - APART)).ln()
    };
    x / area
}

impl Scene<'_> {
    /// The stipples the picture of `primary`'s camera draws, in the order of their surfaces
    /// and ranks.
    pub(super) fn stipples(&self, primary: &Primary) -> Result<Vec<Drawn>, RenderError> {
        let cam = primary.camera();
        let s = self.settings;
        let (w, h) = (s.width, s.height);
        let margin = s.stipple.size;
        let mut candidates = Vec::new();
        for (index, surf) in self.input.surfaces.iter().enumerate() {
            let set = surf
                .stipples
                .ok_or(RenderError::NoStipples { surface: index })?;
            if set.area <= 0.0 {
                continue;
            }
            // Per triangle, the prefix of the ranking per stipple per square pixel.
            let scale: Vec<f64> = surf
                .triangles
                .par_iter()
                .zip(&set.triangle_area)
                .map(|(t, &a4)| {
                    let p = t.map(|v| cam.project(surf.positions[v as usize], w, h));
                    let [Some((a, _)), Some((b, _)), Some((c, _))] = p else {
                        return 0.0;
                    };
                    let screen =
                        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
                    if a4 > 0.0 {
                        set.area * screen / a4
                    } else {
                        0.0
                    }
                })
                .collect();
            let t_min = s.hither.map_or(0.0, |h| h * self.radius);
            // The side of a pixel in scene units at a point.
            let pixel_size = |x: DVec3| {
                let across = 2.0 * cam.half_height / f64::from(h);
                match cam.projection {
                    super::CameraProjection::Perspective => across * (x - cam.eye).dot(cam.forward),
                    super::CameraProjection::Orthographic => across,
                }
            };
            let found: Vec<Drawn> = (0..set.len())
                .into_par_iter()
                .filter_map(|k| {
                    let ti = set.triangle[k] as usize;
                    let tri = surf.triangles[ti];
                    let x = set.mix(k, surf.triangles, surf.positions);
                    let (pixel, _) = cam.project(x, w, h)?;
                    let inside = pixel[0] > -margin
                        && pixel[1] > -margin
                        && pixel[0] < f64::from(w) + margin
                        && pixel[1] < f64::from(h) + margin;
                    let clipped = s.clip.is_some_and(|c| c.removes(x));
                    if !inside
                        || clipped
                        || cam.ray_distance(x) < t_min
                        || self.in_ribbon_gap(surf, set, k)
                    {
                        return None;
                    }
                    let dir = cam.ray_to(x).1;
                    let n = super::shade::shading_normal(
                        tri.map(|v| surf.positions[v as usize]),
                        tri.map(|v| surf.normals[v as usize]),
                        set.bary[k],
                    );
                    let tone = tone(n, dir, cam);
                    let prefix = density(tone, s.stipple.size) * scale[ti];
                    ((k as f64) < prefix).then(|| Drawn {
                        surface: index as u32,
                        rank: k as u32,
                        position: x,
                        pixel,
                        w: set.mix(k, surf.triangles, surf.w),
                        tone,
                        saturated: prefix > set.len() as f64,
                        radius: 0.5 * s.stipple.size * pixel_size(x),
                    })
                })
                .collect();
            candidates.extend(found);
        }
        let visible = self.stipples_visible(primary, &candidates);
        Ok(candidates
            .into_iter()
            .zip(visible)
            .filter_map(|(d, v)| v.then_some(d))
            .collect())
    }

    /// Whether each candidate is the first sheet the halos leave visible along its eye ray.
    fn stipples_visible(&self, primary: &Primary, candidates: &[Drawn]) -> Vec<bool> {
        let cam = primary.camera();
        let triangle_index = |d: &Drawn| {
            let set = self.input.surfaces[d.surface as usize]
                .stipples
                .expect("candidates come from surfaces with stipples");
            set.triangle[d.rank as usize]
        };
        let triangle = |d: &Drawn| {
            self.input.surfaces[d.surface as usize].triangles[triangle_index(d) as usize]
        };
        let Some(hiders) = &self.halos else {
            return candidates
                .par_iter()
                .map_init(Vec::new, |hits, d| {
                    self.hits_before(primary, d.position, hits);
                    hits.is_empty()
                })
                .collect();
        };
        match self.settings.mode {
            RenderMode::Exact => candidates
                .par_iter()
                .map_init(Vec::new, |hits, d| {
                    !hiders.hidden(d.position, d.w, d.surface, triangle_index(d))
                        && !self.occluded(primary, d.position, hits)
                })
                .collect(),
            RenderMode::Slices => {
                // Every candidate and every hit before it, as probes of its pixel.
                let (w, h) = (self.settings.width, self.settings.height);
                let pixel_of = |p: [f64; 2]| {
                    let x = (p[0].floor().max(0.0) as u32).min(w - 1);
                    let y = (p[1].floor().max(0.0) as u32).min(h - 1);
                    y * w + x
                };
                let per: Vec<Vec<slices::Probe>> = candidates
                    .par_iter()
                    .map_init(Vec::new, |hits, d| {
                        let pixel = pixel_of(d.pixel);
                        let (origin, dir) = self.hits_before(primary, d.position, hits);
                        let mut probes = vec![slices::Probe {
                            pixel,
                            x: d.position,
                            w: d.w,
                            surface: d.surface,
                            triangle: triangle(d),
                        }];
                        probes.extend(hits.iter().map(|hit| {
                            let (x, w, triangle) = self.at_hit(origin, dir, hit);
                            slices::Probe {
                                pixel,
                                x,
                                w,
                                surface: hit.surface,
                                triangle,
                            }
                        }));
                        probes
                    })
                    .collect();
                let starts: Vec<usize> = per
                    .iter()
                    .scan(0, |at, p| {
                        let start = *at;
                        *at += p.len();
                        Some(start)
                    })
                    .collect();
                let probes: Vec<slices::Probe> = per.iter().flatten().copied().collect();
                let depth = (self.centre - cam.eye).dot(cam.forward);
                let hidden = slices::hidden(
                    hiders.index(),
                    cam,
                    (w, h),
                    self.settings.slices,
                    (depth - self.radius, depth + self.radius),
                    &probes,
                );
                per.iter()
                    .zip(starts)
                    .map(|(p, start)| {
                        !hidden[start] && hidden[start + 1..start + p.len()].iter().all(|&h| h)
                    })
                    .collect()
            }
        }
    }

    /// Whether stipple `k` of `set` on `surf` falls in a gap between the ribbons.
    fn in_ribbon_gap(&self, surf: &crate::parts::SurfacePart, set: &Stipples, k: usize) -> bool {
        let (Some(r), Some(uv)) = (self.settings.ribbons, surf.uv) else {
            return false;
        };
        let axis = match r.along {
            RibbonAxis::U => 0,
            RibbonAxis::V => 1,
        };
        let t = surf.triangles[set.triangle[k] as usize];
        let b = set.bary[k];
        let param: f64 = (0..3).map(|i| b[i] * uv[t[i] as usize][axis]).sum();
        (param * r.count).rem_euclid(1.0) < r.gap
    }

    /// One eye's stipple drawing: the stipples as discs over the background, and per pixel
    /// the distance of the first visible surface along its centre ray when `depth` asks for
    /// it (infinite otherwise).
    pub(super) fn view_stipples(
        &self,
        primary: &Primary,
        depth: bool,
    ) -> Result<View, RenderError> {
        let drawn = self.stipples(primary)?;
        let s = self.settings;
        let (w, h) = (s.width as usize, s.height as usize);
        let (w0, w1) = self.w_range;
        let span = if w1 > w0 { w1 - w0 } else { 1.0 };
        let ink = |d: &Drawn| {
            if s.stipple.colour {
                shade::colormap(s.colormap, (d.w - w0) / span) * 0.75
            } else {
                super::overlay::INK
            }
        };
        let splat = splat(&drawn, w, h, s.stipple.size * 0.5, ink);
        let rgb = splat
            .into_iter()
            .map(|(cover, colour)| self.background.lerp(colour, cover))
            .collect();
        let front = if depth {
            self.front_distances(primary)
        } else {
            vec![f64::INFINITY; w * h]
        };
        Ok(View {
            rgb,
            front,
            gap: Vec::new(),
        })
    }

    /// Per pixel the distance of the first surface the halos leave visible along its centre
    /// ray (infinite where none), as the shaded style reports it.
    fn front_distances(&self, primary: &Primary) -> Vec<f64> {
        let cam = primary.camera();
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        (0..w * h)
            .into_par_iter()
            .map_init(Vec::new, |hits: &mut Vec<Hit>, pixel| {
                let (sx, sy) = self.sample_point(pixel % w, pixel / w, [0.5, 0.5]);
                let (origin, dir) = cam.ray(sx, sy);
                self.trace_primary(primary, [sx, sy], origin, dir, hits);
                hits.iter()
                    .find(|hit| !self.hidden_hit(origin, dir, hit))
                    .map_or(f64::INFINITY, |hit| hit.t)
            })
            .collect()
    }
}

/// Subsamples per pixel side of a splat.
const SUB: usize = 4;

/// Discs of `radius` pixels at the drawn stipples, in an image of `w` x `h`: per pixel the
/// share of its 4 x 4 points some disc covers, and the mean ink of the discs that cover
/// them (each point takes the ink of the first disc, in the order given, that covers it).
/// Rows in bands on the cores; the same result on any number of threads.
fn splat(
    drawn: &[Drawn],
    w: usize,
    h: usize,
    radius: f64,
    ink: impl Fn(&Drawn) -> DVec3 + Sync,
) -> Vec<(f64, DVec3)> {
    const BAND: usize = 16;
    let bands = h.div_ceil(BAND);
    // The stipples each band of rows meets.
    let mut by_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, d) in drawn.iter().enumerate() {
        let y0 = ((d.pixel[1] - radius).floor().max(0.0) as usize) / BAND;
        let y1 = ((d.pixel[1] + radius).floor().max(0.0) as usize).min(h.saturating_sub(1)) / BAND;
        for band in by_band.iter_mut().take(y1 + 1).skip(y0) {
            band.push(i as u32);
        }
    }
    let mut out = vec![(0.0, DVec3::ZERO); w * h];
    out.par_chunks_mut(BAND * w)
        .zip(by_band)
        .enumerate()
        .for_each(|(band, (rows, list))| {
            let y_start = band * BAND;
            let n_rows = rows.len() / w;
            let mut mask = vec![0u16; rows.len()];
            let mut colour = vec![DVec3::ZERO; rows.len()];
            for i in list {
                let d = &drawn[i as usize];
                let c = ink(d);
                let [px, py] = d.pixel;
                let x0 = (px - radius).floor().max(0.0) as usize;
                let x1 = ((px + radius).floor().max(0.0) as usize).min(w - 1);
                let ya = ((py - radius).floor().max(y_start as f64) as usize).max(y_start);
                let yb = ((py + radius).floor().max(0.0) as usize).min(y_start + n_rows - 1);
                for y in ya..=yb {
                    for x in x0..=x1 {
                        let mut bits = 0u16;
                        for j in 0..SUB {
                            for k in 0..SUB {
                                let sx = x as f64 + (k as f64 + 0.5) / SUB as f64 - px;
                                let sy = y as f64 + (j as f64 + 0.5) / SUB as f64 - py;
                                if sx * sx + sy * sy <= radius * radius {
                                    bits |= 1 << (j * SUB + k);
                                }
                            }
                        }
                        let at = (y - y_start) * w + x;
                        let new = bits & !mask[at];
                        mask[at] |= new;
                        colour[at] += c * f64::from(new.count_ones());
                    }
                }
            }
            for ((o, m), c) in rows.iter_mut().zip(mask).zip(colour) {
                let n = m.count_ones();
                *o = if n == 0 {
                    (0.0, DVec3::ZERO)
                } else {
                    (f64::from(n) / (SUB * SUB) as f64, c / f64::from(n))
                };
            }
        });
    out
}
