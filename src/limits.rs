//! Every limit a user can meet, in one home, and the one shape of a validation failure.
//!
//! The scene's checks, the command line's flags, the viewer and the table of limits in
//! docs/SCENES.md ([`table`], which a test compares with it) all take their numbers from here, so
//! that a limit written twice cannot drift. The range of a setting is a [`Bound`], and its
//! check reads the bound: a value outside is a [`FieldError`] naming the field, what is
//! allowed in the bound's own words and what was given, so that the message and the check
//! cannot disagree. [`all`] lists every limit with the settings it bounds, for the table.
//!
//! This module sits below every stage: it uses nothing of the crate.

use std::fmt;

/// A number as a limit's message and the table of limits write it: whole numbers without a
/// decimal point, very small or large ones in exponent form.
pub trait Number: Copy + PartialOrd + fmt::Display {
    /// The high end of a range with no limit above: the largest whole number, or infinity.
    const TOP: Self;
    /// Whether [`Number::TOP`] itself is allowed in such a range: every whole number is,
    /// infinity is not (a setting is finite).
    const TOP_INCLUDED: bool;
    /// The low end of a range with no limit below: the smallest whole number, or minus
    /// infinity.
    const BOTTOM: Self;
    /// Whether [`Number::BOTTOM`] itself is allowed in such a range: every whole number is,
    /// minus infinity is not.
    const BOTTOM_INCLUDED: bool;
    /// What a range without an end is made of when that needs saying: "a finite number"
    /// for reals, nothing for whole numbers.
    const ANY: &'static str;

    /// The number as text.
    fn text(self) -> String {
        self.to_string()
    }
}

impl Number for u32 {
    const TOP: Self = u32::MAX;
    const TOP_INCLUDED: bool = true;
    const BOTTOM: Self = u32::MIN;
    const BOTTOM_INCLUDED: bool = true;
    const ANY: &'static str = "";
}

impl Number for u64 {
    const TOP: Self = u64::MAX;
    const TOP_INCLUDED: bool = true;
    const BOTTOM: Self = u64::MIN;
    const BOTTOM_INCLUDED: bool = true;
    const ANY: &'static str = "";
}

impl Number for usize {
    const TOP: Self = usize::MAX;
    const TOP_INCLUDED: bool = true;
    const BOTTOM: Self = usize::MIN;
    const BOTTOM_INCLUDED: bool = true;
    const ANY: &'static str = "";
}

impl Number for f64 {
    const TOP: Self = f64::INFINITY;
    const TOP_INCLUDED: bool = false;
    const BOTTOM: Self = f64::NEG_INFINITY;
    const BOTTOM_INCLUDED: bool = false;
    const ANY: &'static str = "a finite number";

    fn text(self) -> String {
        let a = self.abs();
        if a != 0.0 && !(1e-3..1e6).contains(&a) {
            format!("{self:e}")
        } else {
            format!("{self}")
        }
    }
}

/// The range of a setting: from `lo` to `hi`, each end included or not, in `unit`. Its
/// [`Bound::check`] words the error from the range itself, so that the message says what
/// the check does (an excluded end reads "greater than", "less than"; a range with no high
/// end, [`Bound::at_least`] and [`Bound::greater_than`], says only its low end). A NaN is
/// in no range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound<T> {
    /// The low end.
    pub lo: T,
    /// Whether `lo` is allowed.
    pub lo_included: bool,
    /// The high end ([`Number::TOP`] for none).
    pub hi: T,
    /// Whether `hi` is allowed.
    pub hi_included: bool,
    /// What the numbers count ("degrees"; empty for none).
    pub unit: &'static str,
}

impl<T: Number> Bound<T> {
    /// `lo` to `hi`, both allowed.
    pub const fn closed(lo: T, hi: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: true,
            hi,
            hi_included: true,
            unit,
        }
    }

    /// Between `lo` and `hi`, neither allowed.
    pub const fn open(lo: T, hi: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: false,
            hi,
            hi_included: false,
            unit,
        }
    }

    /// Above `lo` (not allowed) up to `hi` (allowed).
    pub const fn above(lo: T, hi: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: false,
            hi,
            hi_included: true,
            unit,
        }
    }

    /// From `lo` (allowed) up to below `hi` (not allowed).
    pub const fn below(lo: T, hi: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: true,
            hi,
            hi_included: false,
            unit,
        }
    }

    /// `lo` or more, with no high end (a real must be finite).
    pub const fn at_least(lo: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: true,
            hi: T::TOP,
            hi_included: T::TOP_INCLUDED,
            unit,
        }
    }

    /// More than `lo`, with no high end (a real must be finite).
    pub const fn greater_than(lo: T, unit: &'static str) -> Self {
        Bound {
            lo,
            lo_included: false,
            hi: T::TOP,
            hi_included: T::TOP_INCLUDED,
            unit,
        }
    }

    /// Any number (a real must be finite).
    pub const fn any(unit: &'static str) -> Self {
        Bound {
            lo: T::BOTTOM,
            lo_included: T::BOTTOM_INCLUDED,
            hi: T::TOP,
            hi_included: T::TOP_INCLUDED,
            unit,
        }
    }

    /// Whether `v` is in the range (never a NaN).
    pub fn contains(&self, v: T) -> bool {
        let low = if self.lo_included {
            v >= self.lo
        } else {
            v > self.lo
        };
        let high = if self.hi_included {
            v <= self.hi
        } else {
            v < self.hi
        };
        low && high
    }

    /// The range in words, without the unit: `1 to 8192`, `greater than 1 and less than
    /// 170`, `a finite number greater than 0`.
    pub fn range_words(&self) -> String {
        let (lo, hi) = (self.lo.text(), self.hi.text());
        let low = if self.lo_included {
            format!("at least {lo}")
        } else {
            format!("greater than {lo}")
        };
        let high = if self.hi_included {
            format!("at most {hi}")
        } else {
            format!("less than {hi}")
        };
        // A range with an end missing says only the other, and of a real that it is finite.
        let one_end = |end: String, included: bool| match (T::ANY, included) {
            ("", _) => end,
            (any, true) => format!("{any} of {end}"),
            (any, false) => format!("{any} {end}"),
        };
        let no_low = self.lo == T::BOTTOM && !T::BOTTOM_INCLUDED;
        match (no_low, self.hi == T::TOP) {
            (true, true) if T::ANY.is_empty() => "any number".to_string(),
            (true, true) => T::ANY.to_string(),
            (false, true) => one_end(low, self.lo_included),
            (true, false) => one_end(high, self.hi_included),
            (false, false) if self.lo_included && self.hi_included => format!("{lo} to {hi}"),
            (false, false) => format!("{low} and {high}"),
        }
    }

    /// The range in words, with the unit: `1 to 8192 pixels`, `greater than 1 and less than
    /// 170 degrees`.
    pub fn words(&self) -> String {
        let range = self.range_words();
        if self.unit.is_empty() {
            range
        } else {
            format!("{range} {}", self.unit)
        }
    }

    /// `v` checked: outside, the error of `field` says the range and `v` ("must be 1 to
    /// 8192 pixels, got 0").
    pub fn check(&self, field: &str, v: T) -> Result<(), FieldError> {
        self.check_with(field, v, "")
    }

    /// `v` checked, as [`Bound::check`], with `advice` after the range and `v` when there
    /// is any ("...; make the lines thinner or the picture larger"): why the range is what it
    /// is, or what to do.
    pub fn check_with(&self, field: &str, v: T, advice: &str) -> Result<(), FieldError> {
        if self.contains(v) {
            return Ok(());
        }
        let mut message = format!("must be {}, got {}", self.words(), v.text());
        if !advice.is_empty() {
            message += "; ";
            message += advice;
        }
        Err(FieldError::new(field, message))
    }
}

// The bounds of the settings: each checks a scene's field (or a flag, or the viewer's
// setting) through `Bound::check`, and `all` lists it for the table of docs/SCENES.md.

/// A sampling tolerance relative to the surface's 4D bounding diagonal (`sampling.tolerance`,
/// `halo4d sweep --tolerances`). Below 1e-9 the mesh's error is rounding; above a half the
/// mesh is no longer a picture of the surface.
pub const RELATIVE_TOLERANCE: Bound<f64> = Bound::closed(1e-9, 0.5, "of the 4D bounding diagonal");

/// An absolute sampling tolerance (`sampling.absolute_tolerance`), a length in R^4: any
/// length, for the surface's own scale sets what is fine.
pub const ABSOLUTE_TOLERANCE: Bound<f64> = Bound::greater_than(0.0, "");

/// Cells of a uniform grid along u or along v (`sampling.u`, `sampling.v`), also an even
/// number: a seam glued at half a side needs a node there.
pub const GRID_CELLS: Bound<usize> = Bound::closed(2, 4096, "cells");

/// Triangles of one adaptive budget (`sampling.max_triangles`, `halo4d sweep
/// --max-triangles`); the upper end also bounds all of a scene's uniform grids together.
pub const TRIANGLES: Bound<usize> = Bound::closed(64, 20_000_000, "triangles");

/// Surfaces in one scene (`surfaces`).
pub const SURFACES: Bound<usize> = Bound::closed(1, 64, "surfaces");

/// The length of a name (`name`, `surfaces[i].name`), which becomes a file name.
pub const NAME_LENGTH: Bound<usize> = Bound::closed(1, 64, "characters");

/// A catalogue surface's lengths (`r1`, `r2`, `radius`, `major_radius`, `minor_radius`,
/// `scale`, `size`, `spacing`): any length, for they set the surface's own scale.
pub const SURFACE_LENGTH: Bound<f64> = Bound::greater_than(0.0, "");

/// A Fermat surface's degree `n` (2: the quadratic Fermat surface, 4: a cross-section of
/// the Calabi-Yau quartic); the surface has n² patches.
pub const FERMAT_N: Bound<u32> = Bound::closed(2, 6, "");

/// A Fermat surface's `y_range` (the half-width a of its strips in the imaginary
/// direction): coordinates grow like e^(2a/n), and a narrower strip is a sliver with
/// nothing to show.
pub const FERMAT_Y_RANGE: Bound<f64> = Bound::closed(1e-6, 4.0, "");

/// A product polynomial's `u_range` (the half-range a of log |z1|): coordinates grow like
/// e^a.
pub const PRODUCT_U_RANGE: Bound<f64> = Bound::above(0.0, std::f64::consts::PI, "");

/// A twist-spun trefoil's `twists`: the 0-twist spin is `spun_trefoil`, and the 1-twist
/// spin is unknotted.
pub const TWISTS: Bound<u32> = Bound::closed(2, 12, "twists");

/// The coloured patches of the `patches` surface (`count`).
pub const PATCH_COUNT: Bound<usize> = Bound::closed(1, 16, "patches");

/// `view.projection.eye_distance`: the 4D eye sits on the w axis at w = -eye_distance.
pub const EYE_DISTANCE: Bound<f64> = Bound::greater_than(0.0, "");

/// `halo.rho`, the halo's half-width as a share of the projected scene's diagonal. At
/// least 1e-6: f32, which the files store, resolves about 6e-8 of the diagonal, and the
/// halo needs its two offsets apart. At most 0.49, so that a halo is thinner than the
/// scene it hides parts of. A half-width from `halo.gap_px` is clamped to it.
pub const HALO_RHO: Bound<f64> = Bound::closed(1e-6, 0.49, "of the scene's diagonal");

/// `halo.gap_px`, the halo's half-width in pixels of the scene's picture.
pub const HALO_GAP_PX: Bound<f64> = Bound::above(0.0, 1000.0, "pixels");

/// `halo.delta_d`, the depth the halo's outer surfaces gain (eq. 3), in units of w.
pub const DELTA_D: Bound<f64> = Bound::at_least(0.0, "");

/// `halo.delta_t`, the dead zone of |2t - 1| before the depth grows (eq. 3): |2t - 1| is
/// at most 1, so from 1 on the depth would never grow.
pub const DELTA_T: Bound<f64> = Bound::below(0.0, 1.0, "");

/// A picture's width or height in pixels (`render.width`, `render.height`, `halo4d render
/// --width`, the viewer's window and offscreen frames), so that a typo cannot ask for
/// gigabytes.
pub const PICTURE_SIDE: Bound<u32> = Bound::closed(1, 8192, "pixels");

/// Slices of the halo depth in the CPU renderer (`render.slices`, `halo4d sweep --render
/// --slices`).
pub const SLICES: Bound<u32> = Bound::closed(1, 4096, "slices");

/// Stipples per surface (`render.stipple.count`): the set ranks four candidates per
/// stipple, about 70 bytes each.
pub const STIPPLES: Bound<usize> = Bound::closed(1, 4_194_304, "stipples per surface");

/// A stipple's diameter in pixels (`render.stipple.size`).
pub const STIPPLE_SIZE: Bound<f64> = Bound::closed(0.5, 16.0, "pixels");

/// `render.opacity` and `render.opacity_far`: 1 is opaque, and at 0 a surface would be
/// gone.
pub const OPACITY: Bound<f64> = Bound::above(0.0, 1.0, "");

/// `render.hither`: surfaces nearer the eye than this are cut away.
pub const HITHER: Bound<f64> = Bound::at_least(0.0, "half-diagonals of the scene");

/// `render.line_width` and `render.line_width_far`: at least half a pixel, and at most a
/// quarter of the picture's smaller side. The widest here is that of the largest picture;
/// [`line_width`] gives a picture's own.
pub const LINE_WIDTH: Bound<f64> = Bound::closed(0.5, PICTURE_SIDE.hi as f64 / 4.0, "pixels");

/// [`LINE_WIDTH`] in a picture whose smaller side is `side` pixels: at most a quarter of
/// it, and never below half a pixel.
pub fn line_width(side: u32) -> Bound<f64> {
    Bound {
        hi: (f64::from(side) / 4.0).max(LINE_WIDTH.lo),
        ..LINE_WIDTH
    }
}

/// A real setting with no range of its own (`view.rotation`'s angles, `view.translation`,
/// `camera.azimuth`, a clip plane's `offset`, a formula's `parameters`, `halo4d-view
/// --rotate`): finite, as every number the stages compute with.
pub const FINITE: Bound<f64> = Bound::any("");

/// Each of red, green and blue of a colour (`render.background`,
/// `render.broken_edge_colour`).
pub const COLOUR: Bound<f64> = Bound::closed(0.0, 1.0, "");

/// `render.eye_separation`: the angle between the eyes of a stereo pair.
pub const EYE_SEPARATION: Bound<f64> = Bound::closed(0.0, 30.0, "degrees");

/// `render.ribbons.count`: bands per unit of the parameter.
pub const RIBBON_COUNT: Bound<f64> = Bound::above(0.0, 1e4, "bands per unit");

/// `render.ribbons.gap`: the share of each band cut away.
pub const RIBBON_GAP: Bound<f64> = Bound::open(0.0, 1.0, "of each band");

/// `camera.elevation`: above or below the xy plane, short of the poles.
pub const ELEVATION: Bound<f64> = Bound::closed(-89.0, 89.0, "degrees");

/// `camera.fov`: the vertical field of view of a perspective camera.
pub const FOV: Bound<f64> = Bound::open(1.0, 170.0, "degrees");

/// `camera.distance`: the eye's distance from the scene's centre.
pub const CAMERA_DISTANCE: Bound<f64> = Bound::above(0.0, 1e4, "half-diagonals of the scene");

/// `outputs.curve_radius`, the radius of the curves' tubes in the `.glb`, a share of the
/// projected scene's diagonal (as `halo.rho`).
pub const TUBE_RADIUS: Bound<f64> = Bound::above(0.0, 0.05, "of the scene's diagonal");

/// Frames of an animation (`animation.frames`): frame files are numbered with five digits.
pub const ANIMATION_FRAMES: Bound<u32> = Bound::closed(1, 99_999, "frames");

/// Keyframes of an animation (`animation.keyframes`).
pub const KEYFRAMES: Bound<usize> = Bound::closed(1, 10_000, "keyframes");

/// A keyframe's time (`animation.keyframes[i].time`): 0 is the animation's start, 1 its end.
pub const KEYFRAME_TIME: Bound<f64> = Bound::closed(0.0, 1.0, "");

/// Frames per second of an assembled animation (`animation.fps`).
pub const FPS: Bound<u32> = Bound::closed(1, 240, "frames per second");

/// The number N of processes that share an animation's frames (`halo4d animate --shard
/// I/N`).
pub const SHARDS: Bound<u32> = Bound::at_least(1, "");

/// Evenly spaced stills a motion picture adds to one per interval between critical levels.
pub const MOTION_LEVELS: Bound<usize> = Bound::closed(0, 64, "stills");

/// Frames of a motion picture's film through the levels (0: no film).
pub const FILM_FRAMES: Bound<u32> = Bound::closed(0, 2400, "frames");

/// The tilt of a motion picture's direction that makes its height a Morse function.
pub const PERTURB: Bound<f64> = Bound::closed(0.0, 10.0, "degrees");

/// Slices of the halo depth in the viewer, whose slice textures live on the GPU.
pub const VIEWER_SLICES: Bound<u32> = Bound::closed(2, 1024, "slices");

/// Frames timed per motion by the viewer's benchmark (`halo4d-view --bench --frames`).
pub const BENCH_FRAMES: Bound<u32> = Bound::at_least(1, "frames");

/// The memory a command may use (`HALO4D_MAX_MEMORY`), in gigabytes.
pub const MAX_MEMORY: Bound<f64> = Bound::greater_than(0.0, "gigabytes");

// Other limits: sizes and tolerances that no setting sets.

/// The default of `halo4d sweep --max-triangles`: the most triangles of any one of its
/// meshes.
pub const SWEEP_TRIANGLES: usize = 8_000_000;

/// Triangles of all surfaces together on the coarse grid the view search measures views
/// on (`halo4d view`).
pub const SEARCH_TRIANGLES: usize = 6000;

/// The most 4D views the view search evaluates (each with several camera orbits).
pub const SEARCH_VIEWS: usize = 160;

/// Samples per pixel (`render.samples`, the viewer's samples): a square grid. A set, not a
/// range: [`check_samples`] checks it.
pub const SAMPLES: [u32; 4] = [1, 4, 9, 16];

/// `samples` checked against [`SAMPLES`]: outside, the error of `field` lists them.
pub fn check_samples(field: &str, samples: u32) -> Result<(), FieldError> {
    if SAMPLES.contains(&samples) {
        return Ok(());
    }
    let (last, rest) = SAMPLES.split_last().expect("samples to choose from");
    let rest: Vec<String> = rest.iter().map(u32::to_string).collect();
    Err(FieldError::new(
        field,
        format!(
            "must be {} or {last} (a square grid), got {samples}",
            rest.join(", ")
        ),
    ))
}

/// The most surface triangles the viewer loads (its vertex buffers are sized for them).
pub const VIEWER_TRIANGLES: usize = 4 << 20;

/// The most halo tetrahedra the viewer loads.
pub const VIEWER_TETRAHEDRA: usize = 16 << 20;

/// The shortest edge adaptive sampling splits, as a share of the surface's extent (the
/// diagonal of the 4D box of its starting grids). f32, which the files store, resolves about
/// 6e-8 of it, and the later stages need distinct points: at a singular point of a surface,
/// where the chordal error does not shrink with the triangles (a many-twist knot's tangle),
/// the refinement would otherwise pile hundreds of thousands of triangles onto one f32
/// point. Such triangles stay failing, and the sampling is reported incomplete.
pub const MIN_EDGE: f64 = 1e-6;

/// The largest coordinate (x, y, z or w) a projected surface may reach. The files and the GPU
/// hold f32 (up to 3.4e38), and the exact predicates multiply three coordinate differences
/// (`robust::orient3d` overflows from about 1e100); 1e30 leaves room for both, and for the
/// halos' offsets around the surface.
pub const MAX_COORDINATE: f64 = 1e30;

/// The smallest extent (bounding-box diagonal) of a projected scene: below it f32 files lose
/// their digits to subnormals and the predicates' products of three differences underflow.
pub const MIN_EXTENT: f64 = 1e-30;

/// The most triangles whose boxes may hold a point of a surface, on average over points
/// spread by area: what each ray of the picture and each candidate pair of the curves
/// costs (`report.json`'s `crowding.triangles`). Well-shaped meshes have 1.6 to 4.4 on the
/// fixtures, the sliver fixture 65 (a grid of 4 x 1024 cells); the Fermat quartic on a grid
/// of 1024 x 8 cells, whose slivers fan out from the patches' common corners, 140, and its
/// picture alone takes over a minute. A build whose surfaces pile up more is refused after
/// the projection.
pub const SURFACE_CROWDING: f64 = 100.0;

/// The most halo tetrahedra whose boxes may hold a point of a surface, on average over
/// points spread by area: what each query of the verification and of the picture costs
/// (`report.json`'s `crowding.halos`). Sound halos have 9.6 to 23 on the fixtures (404 on
/// the sliver fixture); halos that keep their folds (`halo.fold: report`) a fifth of the
/// scene wide, 955, and take 45 s to verify and draw. A build whose halos pile up more is
/// refused before the curves.
pub const HALO_CROWDING: f64 = 600.0;

/// How far from a branch point or a boundary end, in widths of the nearer sheet's halo
/// (its largest half-width rho), a sample the halos do not explain is ambiguous rather
/// than wrong. At a branch point the two sheets are one surface folded over; `fold:
/// shrink` narrows the halo to zero there, and a sheet's own halo never hides it, so up
/// to rho from the fold on either sheet (2 rho in all) the gap is the fold's, not the
/// crossing's. On every fixture the farthest such sample is 1.27 rho away, and on fine
/// meshes they all come within a few triangles.
pub const BRANCH_REACH: f64 = 2.0;

/// The largest relative difference between a halo's total tetrahedron volume and the volume
/// its boundary encloses that the checker passes: rounding, never an overlap (the
/// catalogue's halos stay below 1e-13).
pub const VOLUME_DEFECT: f64 = 1e-9;

/// The longest formula of a `formula` surface, in bytes.
pub const FORMULA_LENGTH: usize = 4096;

/// How deep a formula may nest parentheses, powers and signs: the parser recurses once per
/// level, and hostile input like `((((...` must not overflow the stack.
pub const FORMULA_DEPTH: usize = 256;

/// The largest size of a constant exponent in a formula (`x^k`). x^k changes by a factor e
/// when x changes by 1/k of itself, so beyond 1e6 its features are narrower than the
/// shortest edge the sampler splits ([`MIN_EDGE`]): `sin(u)^1e9` is a spike of width 3e-5
/// rad that the check grid misses and no mesh resolves.
pub const FORMULA_EXPONENT: f64 = 1e6;

/// The largest bend of a formula surface at a point of its check grid: a second derivative
/// times the squared extent of its parameter ranges, in bounding diagonals. A grid of
/// parameter step s (a share of the range) has a chordal error of about this bend times
/// s²/8 diagonals, so at 1e8 the default tolerance (1e-3) already needs steps of 1e-5 of
/// the domain, ten times the sampler's shortest edge ([`MIN_EDGE`]); beyond, the sampler
/// would stop at its floor with a wrong surface.
pub const FORMULA_BEND: f64 = 1e8;

/// How close, relative to a formula surface's bounding diagonal, two points that its side
/// rules glue (or a pole's points) must be: rounding of the formulas, never a gap.
pub const FORMULA_GLUE: f64 = 1e-9;

/// The most bytes of one run of text without whitespace an error message echoes.
pub const ECHO_RUN: usize = 60;

/// The most bytes of user text one error message echoes.
pub const ECHO_TOTAL: usize = 300;

/// User text (a name, a key, a line of a file) as an error message echoes it: a run of
/// more than 60 bytes without whitespace, and text of more than 300 bytes, keep their ends
/// (whole characters) and say how much was left out, so that a long name or binary data
/// read as text cannot bury the message.
pub fn shorten(text: &str) -> String {
    fn cut(s: &str, keep: usize) -> String {
        if s.len() <= keep {
            return s.to_string();
        }
        let mut head = keep / 2;
        while !s.is_char_boundary(head) {
            head -= 1;
        }
        let mut tail = s.len() - keep / 2;
        while !s.is_char_boundary(tail) {
            tail += 1;
        }
        format!(
            "{}...({} bytes left out)...{}",
            &s[..head],
            tail - head,
            &s[tail..]
        )
    }
    let mut out = String::with_capacity(text.len().min(2 * ECHO_TOTAL));
    let mut run = String::new();
    for c in text.chars().chain(std::iter::once(' ')) {
        if c.is_whitespace() {
            out.push_str(&cut(&run, ECHO_RUN));
            run.clear();
            out.push(c);
        } else {
            run.push(c);
        }
    }
    out.pop();
    cut(&out, ECHO_TOTAL)
}

/// A setting outside its limits, or inconsistent with another: the field's path (like
/// `surfaces[0].sampling.u`) and what is wrong, with what is allowed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldError {
    /// Path of the field, from the settings value that was checked.
    pub field: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl FieldError {
    /// A failure of `field`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        FieldError {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The same failure seen from the value that holds the checked one at `parent`: the
    /// field `u` of `sampling` becomes `sampling.u`, the field `[1].normal` of `clip`
    /// becomes `clip[1].normal`.
    pub fn within(self, parent: &str) -> Self {
        let field = if self.field.is_empty() {
            parent.to_string()
        } else if self.field.starts_with('[') {
            format!("{parent}{}", self.field)
        } else {
            format!("{parent}.{}", self.field)
        };
        FieldError { field, ..self }
    }

    /// A failure that serde reports at `path` (serde_path_to_error's path, `.` at the top)
    /// with `message`. A value that reads its own fields in its `Deserialize` (a surface, a
    /// formula, a mesh file's settings) reports a failure of one of them as a
    /// [`FieldError`]'s text, `x: message`, which serde carries as its message: that field
    /// joins `path`, so that the error names `surfaces[0].surface.x` as the checks do. Any
    /// other message stays at `path`.
    pub fn from_serde(path: &str, message: &str) -> FieldError {
        let at = |field: &str, message: &str| {
            let e = FieldError::new(field, message);
            if path == "." { e } else { e.within(path) }
        };
        match message.split_once(": ") {
            Some((field, rest)) if is_path(field) => at(field, rest),
            _ => at("", message),
        }
    }
}

/// Whether `s` is a field's path as [`FieldError`] and serde_path_to_error write it
/// (`x`, `sides.u_min`, `u[0]`, `[1].normal`): serde's own messages begin with words.
fn is_path(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_' || c == '[')
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_.[]".contains(c))
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for FieldError {}

/// What a limit allows.
#[derive(Clone, Debug, PartialEq)]
pub enum Allowed {
    /// A range of reals.
    F64(Bound<f64>),
    /// A range of `u32` settings.
    U32(Bound<u32>),
    /// A range of counts.
    Usize(Bound<usize>),
    /// A limit that is not a setting's range (a size, a tolerance, a set): what it allows
    /// and its unit, in words.
    Other(String, &'static str),
}

impl From<Bound<f64>> for Allowed {
    fn from(b: Bound<f64>) -> Self {
        Allowed::F64(b)
    }
}

impl From<Bound<u32>> for Allowed {
    fn from(b: Bound<u32>) -> Self {
        Allowed::U32(b)
    }
}

impl From<Bound<usize>> for Allowed {
    fn from(b: Bound<usize>) -> Self {
        Allowed::Usize(b)
    }
}

/// One limit, as the table of docs/SCENES.md lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// The constant's name in this module.
    pub name: &'static str,
    /// The settings it bounds, as a scene file, a flag or the viewer names them, or what
    /// else it limits.
    pub settings: &'static str,
    /// What it allows.
    pub allowed: Allowed,
}

impl Limit {
    /// The limit's row of the table: settings, what is allowed, unit.
    pub fn row(&self) -> String {
        let (allowed, unit) = match &self.allowed {
            Allowed::F64(b) => (b.range_words(), b.unit),
            Allowed::U32(b) => (b.range_words(), b.unit),
            Allowed::Usize(b) => (b.range_words(), b.unit),
            Allowed::Other(allowed, unit) => (allowed.clone(), *unit),
        };
        format!("| {} | {allowed} | {unit} |", self.settings)
    }
}

/// A [`Limit`] of the constant `$name`: a bound, or any other limit with its words.
macro_rules! limit {
    ($name:ident, $settings:expr) => {
        Limit {
            name: stringify!($name),
            settings: $settings,
            allowed: $name.into(),
        }
    };
    ($name:ident, $settings:expr, $allowed:expr, $unit:expr) => {
        Limit {
            name: stringify!($name),
            settings: $settings,
            allowed: Allowed::Other($allowed, $unit),
        }
    };
}

/// Every limit, in the order of the table of docs/SCENES.md: each [`Bound`] with the settings it
/// bounds, then the sizes and tolerances that no setting sets.
pub fn all() -> Vec<Limit> {
    let mut out = settings();
    out.extend(fixed());
    out
}

/// The ranges of the settings, the flags and the environment, each a [`Bound`].
fn settings() -> Vec<Limit> {
    vec![
        limit!(
            RELATIVE_TOLERANCE,
            "`sampling.tolerance`, `halo4d sweep --tolerances`"
        ),
        limit!(
            ABSOLUTE_TOLERANCE,
            "`sampling.absolute_tolerance` (a length in R^4)"
        ),
        limit!(GRID_CELLS, "`sampling.u`, `sampling.v` (even)"),
        limit!(
            TRIANGLES,
            "`sampling.max_triangles`, `halo4d sweep --max-triangles`; all uniform grids of a scene"
        ),
        limit!(SURFACES, "`surfaces`"),
        limit!(NAME_LENGTH, "`name`, `surfaces[i].name`"),
        limit!(
            SURFACE_LENGTH,
            "a surface's `r1`, `r2`, `radius`, `major_radius`, `minor_radius` (and less than `major_radius`), `scale`, `size`, `spacing`"
        ),
        limit!(FERMAT_N, "a Fermat surface's `n`"),
        limit!(FERMAT_Y_RANGE, "a Fermat surface's `y_range`"),
        limit!(PRODUCT_U_RANGE, "a product polynomial's `u_range`"),
        limit!(TWISTS, "a twist-spun trefoil's `twists`"),
        limit!(PATCH_COUNT, "the `patches` surface's `count`"),
        limit!(
            FINITE,
            "`view.rotation`'s angles, `view.translation`, `camera.azimuth`, `render.clip`'s offsets, a formula's `parameters`, `halo4d-view --rotate`"
        ),
        limit!(EYE_DISTANCE, "`view.projection.eye_distance`"),
        limit!(HALO_RHO, "`halo.rho`"),
        limit!(HALO_GAP_PX, "`halo.gap_px`"),
        limit!(DELTA_D, "`halo.delta_d` (in units of w)"),
        limit!(DELTA_T, "`halo.delta_t`"),
        limit!(
            PICTURE_SIDE,
            "`render.width`, `render.height`, the viewer's size"
        ),
        limit!(SLICES, "`render.slices`, `halo4d sweep --render --slices`"),
        limit!(STIPPLES, "`render.stipple.count`"),
        limit!(STIPPLE_SIZE, "`render.stipple.size` (a stipple's diameter)"),
        limit!(OPACITY, "`render.opacity`, `render.opacity_far`"),
        limit!(HITHER, "`render.hither`"),
        limit!(
            LINE_WIDTH,
            "`render.line_width`, `render.line_width_far` (at most a quarter of the picture's smaller side)"
        ),
        limit!(
            COLOUR,
            "red, green and blue of `render.background`, `render.broken_edge_colour`"
        ),
        limit!(EYE_SEPARATION, "`render.eye_separation`"),
        limit!(RIBBON_COUNT, "`render.ribbons.count`"),
        limit!(RIBBON_GAP, "`render.ribbons.gap`"),
        limit!(ELEVATION, "`camera.elevation`"),
        limit!(FOV, "`camera.fov`"),
        limit!(CAMERA_DISTANCE, "`camera.distance` (absent: fitted)"),
        limit!(TUBE_RADIUS, "`outputs.curve_radius`"),
        limit!(
            ANIMATION_FRAMES,
            "`animation.frames`, `halo4d animate --frames`"
        ),
        limit!(KEYFRAMES, "`animation.keyframes`"),
        limit!(KEYFRAME_TIME, "`animation.keyframes[i].time`"),
        limit!(FPS, "`animation.fps`"),
        limit!(SHARDS, "N of `halo4d animate --shard I/N`"),
        limit!(MOTION_LEVELS, "`halo4d slice --levels`"),
        limit!(PERTURB, "`halo4d slice --perturb`"),
        limit!(FILM_FRAMES, "`halo4d slice --film`"),
        limit!(VIEWER_SLICES, "the viewer's slices"),
        limit!(BENCH_FRAMES, "`halo4d-view --bench --frames`"),
        limit!(MAX_MEMORY, "`HALO4D_MAX_MEMORY`"),
    ]
}

/// The sizes and tolerances that no setting sets.
fn fixed() -> Vec<Limit> {
    vec![
        limit!(
            SAMPLES,
            "`render.samples`, the viewer's samples",
            SAMPLES.map(|s| s.to_string()).join(", "),
            "per pixel"
        ),
        limit!(
            SWEEP_TRIANGLES,
            "`halo4d sweep --max-triangles` default",
            SWEEP_TRIANGLES.to_string(),
            "triangles"
        ),
        limit!(
            MIN_EDGE,
            "the shortest edge adaptive sampling splits",
            format!("{MIN_EDGE:?}"),
            "of the surface's 4D extent"
        ),
        limit!(
            SEARCH_TRIANGLES,
            "the view search's mesh (`halo4d view`)",
            format!("about {SEARCH_TRIANGLES}"),
            "triangles"
        ),
        limit!(
            SEARCH_VIEWS,
            "4D views the view search evaluates",
            format!("up to {SEARCH_VIEWS}"),
            "4D views"
        ),
        limit!(
            VIEWER_TRIANGLES,
            "surface triangles the viewer loads",
            format!("up to {VIEWER_TRIANGLES}"),
            "triangles"
        ),
        limit!(
            VIEWER_TETRAHEDRA,
            "halo tetrahedra the viewer loads",
            format!("up to {VIEWER_TETRAHEDRA}"),
            "tetrahedra"
        ),
        limit!(
            MAX_COORDINATE,
            "a projected coordinate (x, y, z or w)",
            format!("up to {MAX_COORDINATE:e}"),
            "scene units"
        ),
        limit!(
            MIN_EXTENT,
            "a projected scene's bounding diagonal",
            format!("at least {MIN_EXTENT:e}"),
            "scene units"
        ),
        limit!(
            SURFACE_CROWDING,
            "triangles whose boxes hold a point of a surface, on average",
            format!("up to {SURFACE_CROWDING}"),
            "triangles"
        ),
        limit!(
            HALO_CROWDING,
            "halo tetrahedra whose boxes hold a point of a surface, on average",
            format!("up to {HALO_CROWDING}"),
            "tetrahedra"
        ),
        limit!(
            FORMULA_LENGTH,
            "a formula's length (`surfaces[i].surface.x`, ...)",
            format!("up to {FORMULA_LENGTH}"),
            "bytes"
        ),
        limit!(
            FORMULA_DEPTH,
            "a formula's nesting of parentheses, powers and signs",
            format!("up to {FORMULA_DEPTH}"),
            "levels"
        ),
        limit!(
            FORMULA_EXPONENT,
            "a constant exponent in a formula",
            format!("up to {FORMULA_EXPONENT:e}"),
            "in size"
        ),
        limit!(
            FORMULA_BEND,
            "a formula surface's second derivative times its squared parameter extent",
            format!("up to {FORMULA_BEND:e}"),
            "bounding diagonals"
        ),
        limit!(
            FORMULA_GLUE,
            "the gap between points a formula surface's sides glue",
            format!("at most {FORMULA_GLUE:e}"),
            "of the bounding diagonal"
        ),
        limit!(
            BRANCH_REACH,
            "a curve sample the halos do not explain is ambiguous, not wrong, this near a branch point or a boundary end",
            format!("{BRANCH_REACH:?}"),
            "halo widths rho"
        ),
        limit!(
            VOLUME_DEFECT,
            "a halo's volume defect (`halo4d check`, a build's verdict)",
            format!("at most {VOLUME_DEFECT:e}"),
            "relative"
        ),
    ]
}

/// The limits as the table of docs/SCENES.md (Markdown), one row per limit of [`all`].
pub fn table() -> String {
    let mut out = String::from("| setting | allowed | unit |\n| --- | --- | --- |\n");
    for limit in all() {
        out += &limit.row();
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_error_names_its_path_from_the_outermost_value() {
        let e = FieldError::new("u", "must be even")
            .within("sampling")
            .within("surfaces[0]");
        assert_eq!(e.to_string(), "surfaces[0].sampling.u: must be even");
        let e = FieldError::new("[1].normal", "must be three numbers").within("clip");
        assert_eq!(e.field, "clip[1].normal");
    }

    #[test]
    fn a_nested_value_s_failure_joins_serde_s_path() {
        let text = FieldError::new("x", "cannot read the formula at character 7: unmatched `)`")
            .to_string();
        assert_eq!(
            FieldError::from_serde("surfaces[0].surface", &text).to_string(),
            "surfaces[0].surface.x: cannot read the formula at character 7: unmatched `)`"
        );
        let e = FieldError::from_serde("surfaces[0].surface", "v[1]: not u or v");
        assert_eq!(e.field, "surfaces[0].surface.v[1]");
        for message in [
            "invalid type: string \"a\", expected f64",
            "missing field `w`",
            "unknown field `a: b`, expected `x`",
        ] {
            let e = FieldError::from_serde("surfaces[0].surface", message);
            assert_eq!(
                (e.field.as_str(), e.message.as_str()),
                ("surfaces[0].surface", message)
            );
        }
        assert_eq!(FieldError::from_serde(".", "x: bad").field, "x");
        assert_eq!(FieldError::from_serde(".", "trailing characters").field, "");
    }

    #[test]
    fn a_bound_words_its_error_as_it_checks() {
        assert_eq!(
            FOV.check("fov", 1.0).unwrap_err().to_string(),
            "fov: must be greater than 1 and less than 170 degrees, got 1"
        );
        assert!(FOV.check("fov", 1.5).is_ok() && FOV.check("fov", f64::NAN).is_err());
        assert_eq!(
            ELEVATION.check("elevation", 90.0).unwrap_err().message,
            "must be -89 to 89 degrees, got 90"
        );
        assert!(ELEVATION.contains(-89.0) && ELEVATION.contains(89.0));
        assert_eq!(
            CAMERA_DISTANCE.check("distance", 0.0).unwrap_err().message,
            "must be greater than 0 and at most 10000 half-diagonals of the scene, got 0"
        );
        assert_eq!(
            Bound::closed(1e-9, 0.5, "").words(),
            "1e-9 to 0.5",
            "small numbers in exponent form"
        );
        let ends = Bound {
            lo_included: true,
            ..RIBBON_GAP
        };
        assert_eq!(ends.range_words(), "at least 0 and less than 1");
        assert_eq!(
            Bound::closed(1u32, 8192, "pixels").words(),
            "1 to 8192 pixels"
        );
        assert_eq!(
            MAX_MEMORY.check("m", f64::INFINITY).unwrap_err().message,
            "must be a finite number greater than 0 gigabytes, got inf"
        );
        assert_eq!(DELTA_D.words(), "a finite number of at least 0");
        assert_eq!(SHARDS.words(), "at least 1");
        assert_eq!(FINITE.words(), "a finite number");
        assert!(FINITE.contains(f64::MAX) && !FINITE.contains(f64::NEG_INFINITY));
        assert_eq!(
            Bound { hi: 2.0, ..FINITE }.words(),
            "a finite number less than 2"
        );
        assert!(SHARDS.contains(u32::MAX));
        assert_eq!(
            line_width(64)
                .check_with("w", 20.0, "make the lines thinner")
                .unwrap_err()
                .message,
            "must be 0.5 to 16 pixels, got 20; make the lines thinner"
        );
        assert_eq!(line_width(1).hi, 0.5);
        assert_eq!(
            check_samples("samples", 3).unwrap_err().message,
            "must be 1, 4, 9 or 16 (a square grid), got 3"
        );
    }

    /// The ends of a bound are allowed as it says, and so are the numbers just inside; the
    /// numbers just outside are not.
    fn ends_hold<T: Number + fmt::Debug>(
        name: &str,
        b: &Bound<T>,
        inside: [T; 2],
        outside: [Option<T>; 2],
    ) {
        assert!(b.lo < b.hi, "{name}: {b:?}");
        assert_eq!(
            b.check("f", b.lo).is_ok(),
            b.lo_included,
            "{name}: the low end"
        );
        assert_eq!(
            b.check("f", b.hi).is_ok(),
            b.hi_included,
            "{name}: the high end"
        );
        for v in inside {
            assert!(b.check("f", v).is_ok(), "{name}: {v:?} is inside");
        }
        for v in outside.into_iter().flatten() {
            assert!(b.check("f", v).is_err(), "{name}: {v:?} is outside");
        }
    }

    #[test]
    fn every_bound_allows_its_ends_as_it_says_and_refuses_nan() {
        let mut bounds = 0;
        for limit in all() {
            let name = limit.name;
            match limit.allowed {
                Allowed::F64(b) => {
                    let inside = [
                        if b.lo_included { b.lo } else { b.lo.next_up() },
                        if b.hi_included {
                            b.hi
                        } else {
                            b.hi.next_down()
                        },
                    ];
                    let outside = [
                        Some(if b.lo_included {
                            b.lo.next_down()
                        } else {
                            b.lo
                        }),
                        Some(if b.hi_included { b.hi.next_up() } else { b.hi }),
                    ];
                    ends_hold(name, &b, inside, outside);
                    assert!(b.check("f", f64::NAN).is_err(), "{name}: NaN");
                    assert!(b.check("f", f64::INFINITY).is_err(), "{name}: infinity");
                    assert!(
                        b.check("f", f64::NEG_INFINITY).is_err(),
                        "{name}: -infinity"
                    );
                }
                Allowed::U32(b) => {
                    let inside = [
                        if b.lo_included { b.lo } else { b.lo + 1 },
                        if b.hi_included { b.hi } else { b.hi - 1 },
                    ];
                    let outside = [
                        if b.lo_included {
                            b.lo.checked_sub(1)
                        } else {
                            Some(b.lo)
                        },
                        if b.hi_included {
                            b.hi.checked_add(1)
                        } else {
                            Some(b.hi)
                        },
                    ];
                    ends_hold(name, &b, inside, outside);
                }
                Allowed::Usize(b) => {
                    let inside = [
                        if b.lo_included { b.lo } else { b.lo + 1 },
                        if b.hi_included { b.hi } else { b.hi - 1 },
                    ];
                    let outside = [
                        if b.lo_included {
                            b.lo.checked_sub(1)
                        } else {
                            Some(b.lo)
                        },
                        if b.hi_included {
                            b.hi.checked_add(1)
                        } else {
                            Some(b.hi)
                        },
                    ];
                    ends_hold(name, &b, inside, outside);
                }
                Allowed::Other(..) => continue,
            }
            bounds += 1;
        }
        assert!(bounds > 30, "{bounds} bounds");
    }

    #[test]
    fn the_table_lists_every_bound_of_this_module() {
        let table = table();
        let all = all();
        let declared: Vec<&str> = include_str!("limits.rs")
            .lines()
            .filter_map(|l| l.strip_prefix("pub const "))
            .filter_map(|l| l.split_once(": Bound<"))
            .map(|(name, _)| name)
            .collect();
        assert!(declared.len() > 30, "{declared:?}");
        for name in declared {
            let limit = all
                .iter()
                .find(|l| l.name == name)
                .unwrap_or_else(|| panic!("{name} is not in limits::all()"));
            assert!(!matches!(limit.allowed, Allowed::Other(..)), "{name}");
            assert!(table.contains(&limit.row()), "{name}: {}", limit.row());
        }
        for (i, a) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|b| b.name != a.name),
                "{} is listed twice",
                a.name
            );
        }
    }

    #[test]
    fn long_runs_and_long_texts_keep_their_ends() {
        assert_eq!(shorten("a short message"), "a short message");
        let long = format!("name `{}` is bad", "x".repeat(1000));
        let s = shorten(&long);
        assert!(s.starts_with("name `xxx") && s.ends_with("` is bad"), "{s}");
        assert!(s.contains("(942 bytes left out)"), "{s}");
        let emoji = "\u{1F600} ".repeat(400);
        let s = shorten(&emoji);
        assert!(s.len() < 400 && s.is_char_boundary(s.len()), "{s}");
        let words = "word ".repeat(500);
        let s = shorten(words.trim_end());
        assert!(
            s.len() < 500 && s.starts_with("word word") && s.ends_with("word"),
            "{s}"
        );
        assert_eq!(
            shorten("tabs\tand\nnewlines  stay"),
            "tabs\tand\nnewlines  stay"
        );
    }
}
