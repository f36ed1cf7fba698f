//! One-pixel lines broadened to an exact width.
//!
//! Takes segments in pixel coordinates, each with the width its band should have; gives a
//! coverage image in [0, 1] in which every straight line has become a band of exactly that
//! width, with a one-pixel anti-aliased edge. Silhouettes and intersection curves are drawn
//! this way so that their width is a number the picture keeps, not an accident of
//! rasterization.
//!
//! Pixel (x, y) covers [x, x + 1) × [y, y + 1), its centre at (x + 0.5, y + 0.5); images are
//! row-major, `y * width + x`.
//!
//! # Method (Nagy and Klein, paper 002, section 4)
//!
//! Segments are first drawn one pixel wide into a [`Mask`]. The mask is blurred with a
//! Gaussian of standard deviation sigma (eqs. 2 and 3). Across a straight line the blurred
//! value is then the one-dimensional profile `p(d) = k0 exp(-d² / (2 sigma²))` of the
//! distance d from the line, where k0 is the kernel's centre weight, so a pixel lies in a
//! band of width w exactly when `p⁻¹(v) < w / 2` (eq. 5). Here p is inverted in closed form,
//! `d = sigma sqrt(2 ln(k0 / v))`, and a pixel's coverage is the share of the unit interval
//! [d - 1/2, d + 1/2] inside the band [-w/2, w/2]. For w ≥ 1 px that is
//! `clamp(w/2 + 1/2 - d, 0, 1)`: half coverage lies exactly at distance w/2 from the line and
//! the edge ramps over one pixel. Thinner bands cover their line's pixels by w. Across a line
//! along an axis the coverage of a column adds up to exactly w.
//!
//! **Ink.** A line drawn with one pixel per column (or row) puts `cos θ` pixels on each unit
//! of its length at angle θ to the axis, so its blurred profile would be `cos θ` times lower
//! at 45° than along an axis and its band up to `sigma sqrt(ln 2)` narrower. Each drawn pixel
//! therefore holds the length of line it stands for (its *ink*: 1 along the axes, up to √2
//! on diagonals), which makes the profile of every straight line the same `p(d)`.
//!
//! **Sigma.** `sigma = max(width / 4, 0.8 px)`: the threshold sits at d = 2 sigma, where the
//! profile has fallen to e⁻² = 0.135 of its peak. A narrower Gaussian (the threshold further
//! out in its tail) makes the band closer to the true set of points within w/2 of the line
//! at ends, corners and near other lines: with w = 4 sigma a band reaches 0.55 w/2 beyond the
//! middle of a line's last pixel (a round cap would reach w/2), and the bands of two parallel
//! lines merge only when the gap between them is less than 0.32 w/2. But sigma must stay near
//! a pixel or more, or the staircase of a slanted line shows through: where it steps, the
//! blur of two half-lines a pixel apart is wider than one line's, and the band widens there
//! by about 0.375 / sigma px (measured at sigma = 0.8 px: up to 0.35 px on straight lines,
//! 0.5 px on a polygonal circle). Below 0.8 px the sampled Gaussian also starts to depart from
//! the continuous one. The threshold at e⁻² of the peak is far above the f32 rounding of the
//! FFT.
//!
//! **FFT and zero padding.** The blur is separable: each row is convolved with the sampled,
//! normalized 1D Gaussian by an FFT (eq. 6), then each column, which is the same as the 2D
//! convolution and costs one 1D transform pair per row and per column. A row of length L is
//! placed in an FFT of length `N >= L + 6 sigma` (the next length whose factors are 2, 3
//! and 5), so the zeros after it pad it by at least 3 sigma on each side of the circular
//! buffer: the nearest wrapped copy of a line lies more than 6 sigma away, where its profile
//! is below e⁻¹⁸ of the peak and cannot reach the threshold. Two real rows travel as the
//! real and imaginary parts of one complex transform (the kernel's spectrum is real, so they
//! do not mix), rows that are all zero are skipped, and rows are shared among threads. A
//! [`Broadener`] keeps its FFT plans, kernel spectra and work images, so repeated calls at
//! one size and width plan nothing.
//!
//! **Widths that vary** (nearer lines drawn wider, paper 002's atmospheric depth cue): the
//! mask also records each pixel's desired width. [`Broadener::broaden_varying`] blurs the
//! ink and the ink times the width with one Gaussian (sigma from the largest width) and
//! thresholds each pixel at half the local width, the blurred ink-weighted width divided by
//! the blurred ink. This is an approximation: the local width is an average over a few sigma
//! of line, so where lines of different widths come close their widths mix, and a band
//! narrower than the largest is cut from a Gaussian wider than its own sigma would be, so
//! its ends recede (a line a fifth of the largest width ends about 1.4 sigma before its last
//! pixel). Along a single line whose width changes slowly the band is exact.

use crate::limits::PICTURE_SIDE;
use glam::DVec2;
use rayon::prelude::*;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// The largest image side accepted, in pixels: a picture's
/// ([`crate::limits::PICTURE_SIDE`]). Broadening holds about six f32 images of the mask's
/// size.
pub const MAX_SIDE: usize = PICTURE_SIDE.hi as usize;

/// The farthest a segment's endpoint may lie from the origin, in pixels. Further out, f64
/// cannot place the clipped segment to a small fraction of a pixel.
pub const MAX_COORDINATE: f64 = 1e12;

/// Sigma as a share of the band's width: the threshold sits at `width / 2 = 2 sigma`.
pub const SIGMA_PER_WIDTH: f64 = 0.25;

/// The smallest sigma, in pixels: thinner Gaussians let a slanted line's staircase show.
pub const MIN_SIGMA: f64 = 0.8;

/// Zero padding on each side of a row or column, in sigmas.
const PAD_SIGMAS: f64 = 3.0;

/// Plans (lengths and sigmas) a [`Broadener`] keeps before forgetting the oldest.
const KEPT_PLANS: usize = 8;

/// The fewest samples worth a parallel task of their own: below, handing the work to
/// another thread costs more than it saves.
const TASK_SAMPLES: usize = 1 << 16;

/// Why a mask could not be made, drawn into or broadened. All are bad input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinesError {
    /// The image has a side of 0 or more than [`MAX_SIDE`] pixels.
    #[error(
        "image of {width} x {height} px: each side must be {}",
        PICTURE_SIDE.words()
    )]
    BadSize {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
    },
    /// A width that is NaN, infinite, zero or negative.
    #[error("line width {width} px: it must be a finite number of pixels greater than 0")]
    BadWidth {
        /// The width given.
        width: f64,
    },
    /// A width larger than the image, which would cover all of it.
    #[error(
        "line width {width} px is larger than the {image_width} x {image_height} px image; \
         give at most {limit} px"
    )]
    WidthTooLarge {
        /// The width given.
        width: f64,
        /// The image's width.
        image_width: usize,
        /// The image's height.
        image_height: usize,
        /// The largest width accepted: the image's larger side.
        limit: f64,
    },
    /// A segment endpoint that is NaN, infinite or farther than [`MAX_COORDINATE`].
    #[error(
        "segment endpoint ({x}, {y}): coordinates must be finite and within ±{MAX_COORDINATE} \
         px; clip the segment before drawing it"
    )]
    BadPoint {
        /// The endpoint's x.
        x: f64,
        /// The endpoint's y.
        y: f64,
    },
}

/// Sigma of the Gaussian that broadens lines to `width` pixels: `max(width / 4, 0.8)`.
pub fn sigma_for_width(width: f64) -> f64 {
    (SIGMA_PER_WIDTH * width).max(MIN_SIGMA)
}

/// One-pixel lines: per pixel, the ink of the lines through it and the width wanted there.
#[derive(Clone, Debug, PartialEq)]
pub struct Mask {
    width: usize,
    height: usize,
    ink: Vec<f32>,
    widths: Vec<f32>,
}

impl Mask {
    /// An empty mask of `width` × `height` pixels.
    pub fn new(width: usize, height: usize) -> Result<Self, LinesError> {
        let side = |n: usize| u32::try_from(n).is_ok_and(|n| PICTURE_SIDE.contains(n));
        if !side(width) || !side(height) {
            return Err(LinesError::BadSize { width, height });
        }
        Ok(Self {
            width,
            height,
            ink: vec![0.0; width * height],
            widths: vec![0.0; width * height],
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Per pixel, row-major: 0 off the lines; on them the length of line the pixel stands
    /// for, 1 for lines along an axis and up to √2 for diagonals (see the module docs).
    pub fn ink(&self) -> &[f32] {
        &self.ink
    }

    /// Per pixel, row-major: the band width wanted there in pixels, 0 off the lines.
    pub fn widths(&self) -> &[f32] {
        &self.widths
    }

    /// Whether no line has been drawn.
    pub fn is_empty(&self) -> bool {
        self.ink.iter().all(|&v| v == 0.0)
    }

    /// The largest width drawn, 0 for an empty mask.
    pub fn max_width(&self) -> f64 {
        f64::from(self.widths.iter().fold(0.0_f32, |m, &w| m.max(w)))
    }

    /// Erases every line, keeping the size.
    pub fn clear(&mut self) {
        self.ink.fill(0.0);
        self.widths.fill(0.0);
    }

    /// Draws the segment from `a` to `b` (pixel coordinates), to be broadened to `width`
    /// pixels: [`Mask::draw_polyline`] through the two points.
    pub fn draw_segment(&mut self, a: DVec2, b: DVec2, width: f64) -> Result<usize, LinesError> {
        self.draw_polyline(&[(a, width), (b, width)])
    }

    /// Draws the polyline through `points` (pixel coordinates, each with the band width
    /// wanted there, which goes linearly along each segment) one pixel wide, clipped to the
    /// image's closed rectangle [0, width] × [0, height]. Returns how many pixels it set (a
    /// pixel the polyline comes back to counts again). To close it, repeat the first point.
    /// A single point sets its pixel. Nothing is drawn unless every point and width is valid.
    ///
    /// Each segment takes one pixel per column (per row where it is steeper than 45°), from
    /// the column of one clipped endpoint to the column of the other: the pixel it crosses
    /// at the column's centre, or at its endpoint in an end column whose centre it does not
    /// reach. So a segment is one pixel wide and 8-connected at every slope and its end
    /// pixels are those of its endpoints or their neighbours. Where segments meet, a pixel
    /// whose neighbours along the polyline touch each other is left out, so that joints
    /// stay one pixel wide and connected (separate [`Mask::draw_segment`] calls meeting at a
    /// point can leave a two-pixel clump there, which broadens a little wider).
    ///
    /// Each pixel's ink is the length of line it stands for: the segment's length over the
    /// columns (rows) it spans, 1 along the axes and up to √2 on diagonals. A pixel drawn
    /// twice keeps the larger ink and the larger width.
    pub fn draw_polyline(&mut self, points: &[(DVec2, f64)]) -> Result<usize, LinesError> {
        for &(p, width) in points {
            if !(p.x.abs() <= MAX_COORDINATE && p.y.abs() <= MAX_COORDINATE) {
                return Err(LinesError::BadPoint { x: p.x, y: p.y });
            }
            check_width(width, self.width, self.height)?;
        }
        let (w, h) = (self.width, self.height);
        let mut chain: Vec<Step> = Vec::new();
        let single;
        let path = match points {
            [p] => {
                single = [*p, *p];
                &single[..]
            }
            _ => points,
        };
        for pair in path.windows(2) {
            let ((a, wa), (b, wb)) = (pair[0], pair[1]);
            let d = b - a;
            let major = d.x.abs().max(d.y.abs());
            let ink = if major > 0.0 { d.length() / major } else { 1.0 } as f32;
            let Some((t0, t1)) = clip(a, b, w as f64, h as f64) else {
                continue;
            };
            walk(a, b, t0, t1, w, h, |x, y, t| {
                let width = (wa + t * (wb - wa)) as f32;
                push_thinned(&mut chain, Step { x, y, ink, width });
            });
        }
        if points.len() > 2 && points[0].0 == points[points.len() - 1].0 {
            close_thinned(&mut chain);
        }
        for s in &chain {
            let i = s.y * w + s.x;
            self.ink[i] = self.ink[i].max(s.ink);
            self.widths[i] = self.widths[i].max(s.width);
        }
        Ok(chain.len())
    }
}

/// A pixel of a polyline's walk, with its ink and width.
#[derive(Clone, Copy, Debug)]
struct Step {
    x: usize,
    y: usize,
    ink: f32,
    width: f32,
}

impl Step {
    fn at(self) -> (usize, usize) {
        (self.x, self.y)
    }
}

/// Whether two pixels are 8-neighbours (or the same).
fn touch(a: Step, b: Step) -> bool {
    a.x.abs_diff(b.x) <= 1 && a.y.abs_diff(b.y) <= 1
}

/// Appends the next pixel of a walk: merged into the last if it is the same pixel, and
/// replacing the last if that only joined two pixels that touch anyway (the corner of an L
/// that segments meeting at a joint can leave).
fn push_thinned(chain: &mut Vec<Step>, s: Step) {
    if let Some(last) = chain.last_mut()
        && last.at() == s.at()
    {
        last.ink = last.ink.max(s.ink);
        last.width = last.width.max(s.width);
        return;
    }
    if let [.., before, last] = chain[..]
        && touch(last, s)
        && touch(before, s)
        && before.at() != s.at()
    {
        chain.pop();
    }
    chain.push(s);
}

/// Thins the joint where a closed polyline's walk comes back to its start, as
/// [`push_thinned`] does at the others.
fn close_thinned(chain: &mut Vec<Step>) {
    let start = chain.first().map(|s| s.at());
    if chain.len() > 3
        && let Some(end) = chain.pop_if(|end| Some(end.at()) == start)
    {
        chain[0].ink = chain[0].ink.max(end.ink);
        chain[0].width = chain[0].width.max(end.width);
    }
    let n = chain.len();
    if n > 3 && touch(chain[n - 2], chain[0]) && touch(chain[n - 1], chain[0]) {
        chain.pop();
    }
    let n = chain.len();
    if n > 3 && touch(chain[n - 1], chain[1]) && touch(chain[n - 1], chain[0]) {
        chain.remove(0);
    }
}

/// A broadened mask: per pixel, row-major, the share of it the bands cover, in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

impl Coverage {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The coverage of every pixel, row-major.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The coverage of pixel (x, y), `None` outside the image.
    pub fn get(&self, x: usize, y: usize) -> Option<f32> {
        (x < self.width && y < self.height).then(|| self.values[y * self.width + x])
    }
}

/// Broadens masks, keeping FFT plans, kernel spectra and work images between calls.
pub struct Broadener {
    planner: FftPlanner<f32>,
    /// Most recently made last.
    plans: Vec<Arc<Plan>>,
    /// Ink, ink times width, and the two transposed.
    work: [Vec<f32>; 4],
    /// Zero padding on each side, in sigmas ([`PAD_SIGMAS`]; 0 only in tests that show why
    /// it is needed).
    pad_sigmas: f64,
}

impl Default for Broadener {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Debug for Broadener {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Broadener")
            .field(
                "plans",
                &self
                    .plans
                    .iter()
                    .map(|p| (p.len, p.sigma))
                    .collect::<Vec<_>>(),
            )
            .finish_non_exhaustive()
    }
}

impl Broadener {
    /// A broadener with nothing planned yet; it plans on first use at each size and width.
    pub fn new() -> Self {
        Self {
            planner: FftPlanner::new(),
            plans: Vec::new(),
            work: Default::default(),
            pad_sigmas: PAD_SIGMAS,
        }
    }

    /// Broadens every line of `mask` into a band `width` pixels wide, ignoring the widths
    /// drawn with the lines.
    pub fn broaden(&mut self, mask: &Mask, width: f64) -> Result<Coverage, LinesError> {
        check_width(width, mask.width, mask.height)?;
        let sigma = sigma_for_width(width);
        let peak = self.blur(mask, sigma, false);
        let profile = Profile { sigma, peak };
        let half = 0.5 * width;
        let zero_below = profile.value(half + 0.5);
        let one_above = if half > 0.5 {
            profile.value(half - 0.5)
        } else {
            f64::INFINITY
        };
        let blurred = &mut self.work[2];
        for_line_chunks(blurred, mask.height, |_, chunk| {
            for c in chunk {
                let v = f64::from(*c);
                *c = if v <= zero_below {
                    0.0
                } else if v >= one_above {
                    1.0
                } else {
                    profile.coverage(v, half)
                };
            }
        });
        Ok(self.coverage(mask))
    }

    /// Broadens every line of `mask` into a band as wide as the widths drawn with it,
    /// thresholding each pixel at half the local average width (see the module docs for
    /// the approximation).
    pub fn broaden_varying(&mut self, mask: &Mask) -> Result<Coverage, LinesError> {
        let widest = mask.max_width();
        if widest == 0.0 {
            return Ok(Coverage {
                width: mask.width,
                height: mask.height,
                values: vec![0.0; mask.width * mask.height],
            });
        }
        check_width(widest, mask.width, mask.height)?;
        let sigma = sigma_for_width(widest);
        let peak = self.blur(mask, sigma, true);
        let profile = Profile { sigma, peak };
        let zero_below = profile.value(0.5 * widest + 0.5);
        let h = mask.height;
        let [.., blurred, weighted] = &mut self.work;
        for_line_chunks(blurred, h, |first, chunk| {
            let weighted = &weighted[first * h..first * h + chunk.len()];
            for (c, &u) in chunk.iter_mut().zip(weighted) {
                let v = f64::from(*c);
                *c = if v <= zero_below {
                    0.0
                } else {
                    let local = (f64::from(u) / v).clamp(0.0, widest);
                    profile.coverage(v, 0.5 * local)
                };
            }
        });
        Ok(self.coverage(mask))
    }

    /// The coverage left column-major in `work[2]`, turned row-major.
    fn coverage(&self, mask: &Mask) -> Coverage {
        let mut values = Vec::new();
        transpose(&self.work[2], mask.height, mask.width, &mut values);
        Coverage {
            width: mask.width,
            height: mask.height,
            values,
        }
    }

    /// Blurs the mask's ink (and with `weighted` its ink times width) with a Gaussian of
    /// `sigma`, leaving the results transposed (column-major) in `work[2]` and `work[3]`.
    /// Returns the centre weight of the 2D blur of a line, k0.
    fn blur(&mut self, mask: &Mask, sigma: f64, weighted: bool) -> f64 {
        let (w, h) = (mask.width, mask.height);
        let (rows, columns) = (self.plan(w, sigma), self.plan(h, sigma));
        let [ink, ink_width, ink_t, ink_width_t] = &mut self.work;
        ink.clear();
        ink.extend_from_slice(&mask.ink);
        if weighted {
            ink_width.clear();
            ink_width.extend(mask.ink.iter().zip(&mask.widths).map(|(&i, &w)| i * w));
            blur_lines(ink, ink_width, w, &rows);
        } else {
            let (top, bottom) = ink.split_at_mut(h.div_ceil(2) * w);
            blur_lines(top, bottom, w, &rows);
        }
        transpose(ink, w, h, ink_t);
        if weighted {
            transpose(ink_width, w, h, ink_width_t);
            blur_lines(ink_t, ink_width_t, h, &columns);
        } else {
            let (left, right) = ink_t.split_at_mut(w.div_ceil(2) * h);
            blur_lines(left, right, h, &columns);
        }
        (rows.peak * columns.peak).sqrt()
    }

    /// The plan for lines of `len` samples blurred with `sigma`, made if new.
    fn plan(&mut self, len: usize, sigma: f64) -> Arc<Plan> {
        let pad = (self.pad_sigmas * sigma).ceil() as usize;
        let n = fast_len(len + 2 * pad);
        if let Some(plan) = self.plans.iter().find(|p| p.len == n && p.sigma == sigma) {
            return Arc::clone(plan);
        }
        if self.plans.len() == KEPT_PLANS {
            self.plans.remove(0);
        }
        let plan = Arc::new(Plan::new(&mut self.planner, n, sigma));
        self.plans.push(Arc::clone(&plan));
        plan
    }
}

/// Broadens every line of `mask` into a band `width` pixels wide; a [`Broadener`] kept
/// between calls saves planning.
pub fn broaden(mask: &Mask, width: f64) -> Result<Coverage, LinesError> {
    Broadener::new().broaden(mask, width)
}

/// The blurred profile across a straight line: `peak exp(-d² / (2 sigma²))`.
#[derive(Clone, Copy)]
struct Profile {
    sigma: f64,
    peak: f64,
}

impl Profile {
    /// The blurred value at distance `d` from a line.
    fn value(self, d: f64) -> f64 {
        self.peak * (-0.5 * (d / self.sigma).powi(2)).exp()
    }

    /// Coverage of a pixel of blurred value `v` by a band of half-width `half`: the distance
    /// d the profile puts it at (eq. 5), then the overlap of [d - 1/2, d + 1/2] with the
    /// band [-half, half], as if the pixel were a unit square across a line along an axis.
    /// For bands a pixel or more wide that is a one-pixel ramp centred on `half`.
    fn coverage(self, v: f64, half: f64) -> f32 {
        let d = if v >= self.peak {
            0.0
        } else {
            self.sigma * (2.0 * (self.peak / v).ln()).sqrt()
        };
        ((d + 0.5).min(half) - (d - 0.5).max(-half)).clamp(0.0, 1.0) as f32
    }
}

/// FFTs of one padded length and the spectrum of the Gaussian at one sigma.
struct Plan {
    len: usize,
    sigma: f64,
    forward: Arc<dyn Fft<f32>>,
    inverse: Arc<dyn Fft<f32>>,
    /// The kernel's DFT (real: the kernel is even), divided by `len` for the inverse FFT.
    spectrum: Vec<f32>,
    /// The kernel's centre weight.
    peak: f64,
    scratch_len: usize,
}

impl Plan {
    fn new(planner: &mut FftPlanner<f32>, len: usize, sigma: f64) -> Self {
        // The Gaussian sampled at integer offsets, wrapped onto the circular buffer at the
        // nearest copy and normalized to sum 1, so a line along an axis blurs to exactly
        // peak exp(-d² / (2 sigma²)) at integer d; transformed in f64 once per plan.
        let mut kernel: Vec<Complex<f64>> = (0..len)
            .map(|m| {
                let d = m.min(len - m) as f64 / sigma;
                Complex::new((-0.5 * d * d).exp(), 0.0)
            })
            .collect();
        let total: f64 = kernel.iter().map(|c| c.re).sum();
        FftPlanner::<f64>::new()
            .plan_fft_forward(len)
            .process(&mut kernel);
        let spectrum = kernel
            .iter()
            .map(|c| (c.re / (total * len as f64)) as f32)
            .collect();
        let forward = planner.plan_fft_forward(len);
        let inverse = planner.plan_fft_inverse(len);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        Self {
            len,
            sigma,
            forward,
            inverse,
            spectrum,
            peak: 1.0 / total,
            scratch_len,
        }
    }
}

/// Blurs in place each line (`len` samples) of `p` and of `q`, line i of `q` travelling with
/// line i of `p` as the imaginary part of one transform; `q` may hold one line fewer. Runs
/// of lines on the cores, each thread with its own FFT buffers.
fn blur_lines(p: &mut [f32], q: &mut [f32], len: usize, plan: &Plan) {
    let zero = Complex::new(0.0, 0.0);
    // Line i of `q`, or none for the last line of `p` where `q` is one line short (`zip`
    // drops the `None` when it is not).
    let q_lines = q
        .par_chunks_exact_mut(len)
        .map(Some)
        .chain(rayon::iter::once(None));
    p.par_chunks_exact_mut(len)
        .zip(q_lines)
        .with_min_len(lines_per_task(len))
        .for_each_init(
            || (vec![zero; plan.len], vec![zero; plan.scratch_len]),
            |(buffer, scratch), (p_line, q_line)| blur_line(p_line, q_line, plan, buffer, scratch),
        );
}

/// [`blur_lines`] on one line of `p` and its partner in `q`, with the FFT's `buffer` and
/// `scratch`.
fn blur_line(
    p_line: &mut [f32],
    q_line: Option<&mut [f32]>,
    plan: &Plan,
    buffer: &mut [Complex<f32>],
    scratch: &mut [Complex<f32>],
) {
    let zero = Complex::new(0.0, 0.0);
    let len = p_line.len();
    let empty = |l: &[f32]| l.iter().all(|&v| v == 0.0);
    if empty(p_line) && q_line.as_deref().is_none_or(empty) {
        return;
    }
    match q_line.as_deref() {
        Some(q_line) => {
            for ((b, &re), &im) in buffer.iter_mut().zip(p_line.iter()).zip(q_line) {
                *b = Complex::new(re, im);
            }
        }
        None => {
            for (b, &re) in buffer.iter_mut().zip(p_line.iter()) {
                *b = Complex::new(re, 0.0);
            }
        }
    }
    buffer[len..].fill(zero);
    plan.forward.process_with_scratch(buffer, scratch);
    for (b, &k) in buffer.iter_mut().zip(&plan.spectrum) {
        *b *= k;
    }
    plan.inverse.process_with_scratch(buffer, scratch);
    for (v, b) in p_line.iter_mut().zip(buffer.iter()) {
        *v = b.re;
    }
    if let Some(q_line) = q_line {
        for (v, b) in q_line.iter_mut().zip(buffer.iter()) {
            *v = b.im;
        }
    }
}

/// Square tiles for transposing: eight lines of the strided side stay in cache even when
/// the stride is a power of two.
const TILE: usize = 8;

/// Writes the `w` × `h` row-major image `src` into `dst` column-major (as an `h` × `w`
/// row-major image).
fn transpose(src: &[f32], w: usize, h: usize, dst: &mut Vec<f32>) {
    dst.clear();
    dst.resize(w * h, 0.0);
    for_line_chunks(dst, h, |first, chunk| {
        let columns = chunk.len() / h;
        for x0 in (0..columns).step_by(TILE) {
            for y0 in (0..h).step_by(TILE) {
                for x in x0..(x0 + TILE).min(columns) {
                    let column = &mut chunk[x * h..(x + 1) * h];
                    for y in y0..(y0 + TILE).min(h) {
                        column[y] = src[y * w + first + x];
                    }
                }
            }
        }
    });
}

/// Runs `f(first_line, lines)` on consecutive runs of the lines (`len` samples each) of
/// `data`, the runs on the cores.
fn for_line_chunks(data: &mut [f32], len: usize, f: impl Fn(usize, &mut [f32]) + Sync) {
    let lines = lines_per_task(len);
    data.par_chunks_mut(lines * len)
        .enumerate()
        .for_each(|(i, chunk)| f(i * lines, chunk));
}

/// Lines of `len` samples worth a parallel task: at least [`TASK_SAMPLES`] samples.
fn lines_per_task(len: usize) -> usize {
    TASK_SAMPLES.div_ceil(len)
}

/// The smallest length at least `n` whose only prime factors are 2, 3 and 5.
fn fast_len(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut r = m;
            for f in [2, 3, 5] {
                while r % f == 0 {
                    r /= f;
                }
            }
            r == 1
        })
        .unwrap_or(n)
}

fn check_width(width: f64, image_width: usize, image_height: usize) -> Result<(), LinesError> {
    if !(width.is_finite() && width > 0.0) {
        return Err(LinesError::BadWidth { width });
    }
    let limit = image_width.max(image_height) as f64;
    if width > limit {
        return Err(LinesError::WidthTooLarge {
            width,
            image_width,
            image_height,
            limit,
        });
    }
    Ok(())
}

/// The part of the segment `a + t (b - a)`, t in [0, 1], inside [0, w] × [0, h], as its
/// range of t (Liang and Barsky).
fn clip(a: DVec2, b: DVec2, w: f64, h: f64) -> Option<(f64, f64)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [(-d.x, a.x), (d.x, w - a.x), (-d.y, a.y), (d.y, h - a.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Visits the pixels of the segment `a + t (b - a)`, t in [t0, t1] (already clipped to the
/// image), in order from `a` towards `b`, with the t at which the walk crossed each.
fn walk(
    a: DVec2,
    b: DVec2,
    t0: f64,
    t1: f64,
    w: usize,
    h: usize,
    mut visit: impl FnMut(usize, usize, f64),
) {
    let d = b - a;
    let x_major = d.x.abs() >= d.y.abs();
    // Coordinates as (major, minor).
    let swap = |p: DVec2| if x_major { p } else { DVec2::new(p.y, p.x) };
    let (major_size, minor_size) = if x_major { (w, h) } else { (h, w) };
    let (s, e) = (swap(a + d * t0), swap(a + d * t1));
    let pixel = |v: f64, size: usize| (v.floor().max(0.0) as usize).min(size - 1);
    let (first, last) = (pixel(s.x, major_size), pixel(e.x, major_size));
    let (low, high) = (s.x.min(e.x), s.x.max(e.x));
    let run = e.x - s.x;
    let columns = last.abs_diff(first);
    for k in 0..=columns {
        let i = if last >= first { first + k } else { first - k };
        let c = (i as f64 + 0.5).clamp(low, high);
        let f = if run != 0.0 { (c - s.x) / run } else { 0.0 };
        let j = pixel(s.y + f * (e.y - s.y), minor_size);
        let t = t0 + f * (t1 - t0);
        if x_major {
            visit(i, j, t);
        } else {
            visit(j, i, t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_lengths_have_only_factors_2_3_5() {
        let lengths: Vec<usize> = [1, 7, 11, 64, 65, 1031, 1037].map(fast_len).into();
        assert_eq!(lengths, [1, 8, 12, 64, 72, 1080, 1080]);
    }

    #[test]
    fn clipping_keeps_the_part_inside() {
        let (w, h) = (10.0, 5.0);
        let clip = |a: [f64; 2], b: [f64; 2]| clip(DVec2::from(a), DVec2::from(b), w, h);
        assert_eq!(clip([1.0, 1.0], [9.0, 4.0]), Some((0.0, 1.0)));
        assert_eq!(
            clip([-10.0, 2.0], [20.0, 2.0]),
            Some((1.0 / 3.0, 2.0 / 3.0))
        );
        assert_eq!(clip([-1.0, -1.0], [-1.0, 9.0]), None);
        assert_eq!(clip([0.0, 6.0], [11.0, 6.0]), None);
        assert_eq!(
            clip([-2.0, 3.0], [3.0, 8.0]),
            Some((0.4, 0.4)),
            "touches a corner"
        );
    }

    /// The blurred ink, row-major, before thresholding.
    fn blurred(broadener: &mut Broadener, mask: &Mask, sigma: f64) -> (Vec<f32>, f64) {
        let peak = broadener.blur(mask, sigma, false);
        let mut rows = Vec::new();
        transpose(&broadener.work[2], mask.height, mask.width, &mut rows);
        (rows, peak)
    }

    #[test]
    fn a_line_along_an_axis_blurs_to_the_gaussian_profile() {
        let (w, h) = (90, 70);
        let mut mask = Mask::new(w, h).expect("a valid size");
        mask.draw_segment(DVec2::new(-5.0, 30.5), DVec2::new(95.0, 30.5), 4.0)
            .expect("a valid segment");
        let mut broadener = Broadener::new();
        for sigma in [0.8, 1.7, 3.0] {
            let (v, peak) = blurred(&mut broadener, &mask, sigma);
            let profile = Profile { sigma, peak };
            for y in 0..h {
                let d = (y as f64 - 30.0).abs();
                let want = profile.value(d);
                let got = f64::from(v[y * w + 45]);
                assert!(
                    (got - want).abs() < 2e-6 * peak,
                    "sigma {sigma}, row {y}: {got}, want {want}"
                );
            }
        }
    }

    #[test]
    fn unpadded_blur_wraps_around() {
        // The same line along the top edge, blurred with and without zero padding: only
        // the unpadded blur reaches the bottom rows, so the padding is what keeps them clear.
        let (n, width) = (64, 8.0);
        let mut mask = Mask::new(n, n).expect("a valid size");
        mask.draw_segment(DVec2::new(0.0, 0.5), DVec2::new(64.0, 0.5), width)
            .expect("a valid segment");
        let mut unpadded = Broadener {
            pad_sigmas: 0.0,
            ..Broadener::new()
        };
        let wrapped = unpadded.broaden(&mask, width).expect("a valid width");
        assert_eq!(unpadded.plans[0].len, n, "circular on exactly the image");
        let padded = Broadener::new()
            .broaden(&mask, width)
            .expect("a valid width");
        for y in [n - 1, n - 2, n - 3] {
            assert_eq!(wrapped.get(10, y), Some(1.0), "row {y} wrapped");
            assert_eq!(padded.get(10, y), Some(0.0), "row {y} clear");
        }
    }
}
