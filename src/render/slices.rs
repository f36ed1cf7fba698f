//! Paper 000's multi-slice halos (section 4.6): N planes perpendicular to the view direction
//! across the scene; on each, every tetrahedron it cuts is sliced, t and d_orig are
//! interpolated across the cut and the halo depth of eq. 3 is written, keeping the smallest,
//! into that plane's halo-depth image. A surface hit is tested against the image of the plane
//! nearest its depth, at its pixel: hidden where the halo depth there is below its w (and the
//! smallest comes from another sheet's halo). The exact mode is its ground truth; the error
//! falls as N grows.

use super::camera::Camera;
use crate::parts::HaloIndex;
use glam::DVec3;
use rayon::prelude::*;

/// A hit to test: its pixel, position, w and triangle.
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    /// Pixel index (row-major).
    pub pixel: u32,
    /// Position.
    pub x: DVec3,
    /// w-depth of the sheet there.
    pub w: f64,
    /// Surface of the hit.
    pub surface: u32,
    /// The hit triangle's vertices.
    pub triangle: [u32; 3],
}

/// The most runs of consecutive slices [`hidden`] sweeps in parallel: each run starts by
/// scanning every tetrahedron for those its first slice cuts.
const SLICE_RUNS: usize = 32;

/// Which probes are hidden by the halos, with `slices` planes, for an image of `width` x
/// `height` through `cam`; the planes span depths `[near, far]` along the view direction.
pub fn hidden(
    index: &HaloIndex,
    cam: &Camera,
    (width, height): (u32, u32),
    slices: u32,
    (near, far): (f64, f64),
    probes: &[Probe],
) -> Vec<bool> {
    let n = slices as usize;
    let step = (far - near) / n as f64;
    let depth = |p: DVec3| (p - cam.eye).dot(cam.forward);
    let slice_of = |z: f64| (((z - near) / step).floor().max(0.0) as usize).min(n - 1);
    // Probes and tetrahedra bucketed by slice (CSR).
    let probe_slice: Vec<usize> = probes.iter().map(|p| slice_of(depth(p.x))).collect();
    let (probe_start, by_slice) = buckets(&probe_slice, n);
    let spans = tet_spans(index, depth, (near, step), n);
    let first_slice: Vec<usize> = spans.iter().map(|s| s.0 as usize).collect();
    let (tet_start, starting) = buckets(&first_slice, n);

    let (w, h) = (width as usize, height as usize);
    // Runs of `per` consecutive slices, each swept with one slice image and one active set;
    // the runs depend on the number of slices only, not on the number of threads (the order
    // of the active set decides ties in the image).
    let per = n.div_ceil(SLICE_RUNS);
    let mut out = vec![false; probes.len()];
    let hidden_lists: Vec<Vec<u32>> = (0..n)
        .into_par_iter()
        .step_by(per)
        .map_init(
            || (vec![(f64::INFINITY, u32::MAX); w * h], Vec::new()),
            |(image, active), k0| {
                let mut hidden = Vec::new();
                for k in k0..(k0 + per).min(n) {
                    // Active tetrahedra: those whose span holds k. Start from every span
                    // beginning at or before k0 on the first slice of the run.
                    if k == k0 {
                        active.clear();
                        active.extend(
                            spans
                                .iter()
                                .enumerate()
                                .filter(|(_, s)| s.0 as usize <= k && s.1 as usize >= k)
                                .map(|(i, _)| i as u32),
                        );
                    } else {
                        active.retain(|&i| spans[i as usize].1 as usize >= k);
                        active.extend_from_slice(
                            &starting[tet_start[k] as usize..tet_start[k + 1] as usize],
                        );
                    }
                    let probes_here =
                        &by_slice[probe_start[k] as usize..probe_start[k + 1] as usize];
                    if probes_here.is_empty() {
                        continue;
                    }
                    image.fill((f64::INFINITY, u32::MAX));
                    let plane = near + (k as f64 + 0.5) * step;
                    for &i in active.iter() {
                        let g = spans[i as usize].2;
                        cut(index, g, cam, plane, (width, height), image);
                    }
                    for &pi in probes_here {
                        let p = &probes[pi as usize];
                        let (d, g) = image[p.pixel as usize];
                        if d < p.w && !index.within(g, p.surface, &p.triangle) {
                            hidden.push(pi);
                        }
                    }
                }
                hidden
            },
        )
        .collect();
    for list in hidden_lists {
        for i in list {
            out[i as usize] = true;
        }
    }
    out
}

/// Items bucketed by their key below `n` (compressed rows): where each key's items start
/// (n + 1 entries), and the items' indices, key after key, each key's in their order.
fn buckets(keys: &[usize], n: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for &k in keys {
        start[k + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut order = vec![0u32; keys.len()];
    for (i, &k) in keys.iter().enumerate() {
        order[fill[k] as usize] = i as u32;
        fill[k] += 1;
    }
    (start, order)
}

/// The slices that cut each tetrahedron, the planes (k + 1/2) `step` past `near` between
/// its view depths (`depth`), of the `n`: (first, last, tetrahedron), for those some plane
/// cuts.
fn tet_spans(
    index: &HaloIndex,
    depth: impl Fn(DVec3) -> f64,
    (near, step): (f64, f64),
    n: usize,
) -> Vec<(u32, u32, u32)> {
    (0..index.len() as u32)
        .filter_map(|g| {
            let z = index.tet(g).0.map(&depth);
            let lo = z.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let first = ((lo - near) / step - 0.5).ceil().max(0.0);
            let last = ((hi - near) / step - 0.5).floor().min(n as f64 - 1.0);
            (first <= last).then_some((first as u32, last as u32, g))
        })
        .collect()
}

/// Writes the cut of tetrahedron `g` by the plane at view depth `plane` into `image`:
/// per pixel centre inside it, the smallest halo depth and its tetrahedron.
fn cut(
    index: &HaloIndex,
    g: u32,
    cam: &Camera,
    plane: f64,
    (width, height): (u32, u32),
    image: &mut [(f64, u32)],
) {
    let (p, t, d, (delta_t, delta_d)) = index.tet(g);
    let z = p.map(|q| (q - cam.eye).dot(cam.forward) - plane);
    // Where the plane crosses the tetrahedron's edges: screen point, t, d_orig.
    let mut pts: Vec<([f64; 2], f64, f64)> = Vec::with_capacity(4);
    for a in 0..4 {
        for b in a + 1..4 {
            if (z[a] < 0.0) != (z[b] < 0.0) {
                let s = z[a] / (z[a] - z[b]);
                let q = p[a] + (p[b] - p[a]) * s;
                if let Some((xy, _)) = cam.project(q, width, height) {
                    pts.push((xy, t[a] + (t[b] - t[a]) * s, d[a] + (d[b] - d[a]) * s));
                }
            }
        }
    }
    if pts.len() < 3 {
        return;
    }
    // Order the cut's corners around their centroid (it is convex).
    let c = pts
        .iter()
        .fold([0.0, 0.0], |c, p| [c[0] + p.0[0], c[1] + p.0[1]]);
    let c = [c[0] / pts.len() as f64, c[1] / pts.len() as f64];
    pts.sort_by(|a, b| {
        let ang = |p: &[f64; 2]| (p[1] - c[1]).atan2(p[0] - c[0]);
        ang(&a.0).total_cmp(&ang(&b.0))
    });
    for i in 1..pts.len() - 1 {
        fill_triangle(
            [pts[0], pts[i], pts[i + 1]],
            g,
            (delta_t, delta_d),
            (width, height),
            image,
        );
    }
}

/// Rasterizes one triangle of a cut (pixel centres inside it, edges included), with t and
/// d_orig interpolated in screen space (exact on a plane of constant view depth).
fn fill_triangle(
    v: [([f64; 2], f64, f64); 3],
    g: u32,
    (delta_t, delta_d): (f64, f64),
    (width, height): (u32, u32),
    image: &mut [(f64, u32)],
) {
    let [a, b, c] = [v[0].0, v[1].0, v[2].0];
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let x0 = (a[0].min(b[0]).min(c[0]) - 0.5).ceil().max(0.0) as i64;
    let x1 = (a[0].max(b[0]).max(c[0]) - 0.5)
        .floor()
        .min(width as f64 - 1.0) as i64;
    let y0 = (a[1].min(b[1]).min(c[1]) - 0.5).ceil().max(0.0) as i64;
    let y1 = (a[1].max(b[1]).max(c[1]) - 0.5)
        .floor()
        .min(height as f64 - 1.0) as i64;
    for y in y0..=y1 {
        for x in x0..=x1 {
            let q = [x as f64 + 0.5, y as f64 + 0.5];
            let e = |p: [f64; 2], r: [f64; 2]| {
                ((r[0] - p[0]) * (q[1] - p[1]) - (r[1] - p[1]) * (q[0] - p[0])) / area
            };
            let l = [e(b, c), e(c, a), e(a, b)];
            if l.iter().any(|&s| s < 0.0) {
                continue;
            }
            let t = l[0] * v[0].1 + l[1] * v[1].1 + l[2] * v[2].1;
            let d = l[0] * v[0].2 + l[1] * v[1].2 + l[2] * v[2].2;
            let depth = d + ((2.0 * t - 1.0).abs() - delta_t).max(0.0) * delta_d;
            let px = &mut image[y as usize * width as usize + x as usize];
            if depth < px.0 {
                *px = (depth, g);
            }
        }
    }
}
