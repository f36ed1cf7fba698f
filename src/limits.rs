//! Every limit a user can meet, in one home, and the one shape of a validation failure.
//!
//! The scene's checks, the command line's flags, the viewer and the README's table of limits
//! ([`table`], which a test compares with the README) all take their numbers from here, so
//! that a limit written twice cannot drift. A setting outside its limit is a [`FieldError`]
//! naming the field, what is allowed and what was given.
//!
//! This module sits below every stage: it uses nothing of the crate.

use std::fmt;
use std::ops::RangeInclusive;

/// A sampling tolerance relative to the surface's 4D bounding diagonal (`sampling.tolerance`,
/// `halo4d sweep --tolerances`). Below 1e-9 the mesh's error is rounding; above a half the
/// mesh is no longer a picture of the surface.
pub const RELATIVE_TOLERANCE: RangeInclusive<f64> = 1e-9..=0.5;

/// Cells of a uniform grid along u or along v (`sampling.u`, `sampling.v`), an even number: a
/// seam glued at half a side needs a node there.
pub const GRID_CELLS: RangeInclusive<usize> = 2..=4096;

/// Triangles of one adaptive budget (`sampling.max_triangles`, `halo4d sweep
/// --max-triangles`); the upper end also bounds all of a scene's uniform grids together.
pub const TRIANGLES: RangeInclusive<usize> = 64..=20_000_000;

/// The default of `halo4d sweep --max-triangles`: the most triangles of any one of its
/// meshes.
pub const SWEEP_TRIANGLES: usize = 8_000_000;

/// Surfaces in one scene.
pub const SURFACES: RangeInclusive<usize> = 1..=64;

/// The length of a name (the scene's, a surface's), which becomes a file name.
pub const NAME_LENGTH: RangeInclusive<usize> = 1..=64;

/// A picture's width or height in pixels (`render.width`, `render.height`, `halo4d render
/// --width`, the viewer's window and offscreen frames), so that a typo cannot ask for
/// gigabytes.
pub const PICTURE_SIDE: RangeInclusive<u32> = 1..=8192;

/// Triangles of all surfaces together on the coarse grid the view search measures views
/// on (`halo4d view`).
pub const SEARCH_TRIANGLES: usize = 6000;

/// The most 4D views the view search evaluates (each with several camera orbits).
pub const SEARCH_VIEWS: usize = 160;

/// The widest `halo.gap_px`, in pixels.
pub const MAX_GAP_PX: f64 = 1000.0;

/// Samples per pixel: a square grid.
pub const SAMPLES: [u32; 4] = [1, 4, 9, 16];

/// Slices of the halo depth in the CPU renderer (`render.slices`, `halo4d sweep --render
/// --slices`).
pub const SLICES: RangeInclusive<u32> = 1..=4096;

/// Stipples per surface (`render.stipple.count`): the set ranks four candidates per
/// stipple, about 70 bytes each.
pub const STIPPLES: Bound<usize> = Bound::closed(1, 4_194_304, "stipples per surface");

/// A stipple's diameter in pixels (`render.stipple.size`).
pub const STIPPLE_SIZE: Bound<f64> = Bound::closed(0.5, 16.0, "pixels (a stipple's diameter)");

/// Slices of the halo depth in the viewer, whose slice textures live on the GPU.
pub const VIEWER_SLICES: RangeInclusive<u32> = 2..=1024;

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

/// Frames of an animation (`animation.frames`): frame files are numbered with five digits.
pub const ANIMATION_FRAMES: RangeInclusive<u32> = 1..=99_999;

/// Keyframes of an animation (`animation.keyframes`).
pub const KEYFRAMES: RangeInclusive<usize> = 1..=10_000;

/// Frames per second of an assembled animation (`animation.fps`).
pub const FPS: RangeInclusive<u32> = 1..=240;

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

/// A number as a limit's message and the README's table write it: whole numbers without a
/// decimal point, very small or large ones in exponent form.
pub trait Number: Copy + PartialOrd + fmt::Display {
    /// The number as text.
    fn text(self) -> String {
        self.to_string()
    }
}

impl Number for u32 {}
impl Number for u64 {}
impl Number for usize {}
impl Number for f64 {
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
/// the check does (an excluded end reads "greater than", "less than").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound<T> {
    /// The low end.
    pub lo: T,
    /// Whether `lo` is allowed.
    pub lo_included: bool,
    /// The high end.
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

    /// The range in words: `1 to 8192 pixels`, `greater than 1 and less than 170 degrees`.
    pub fn words(&self) -> String {
        let (lo, hi) = (self.lo.text(), self.hi.text());
        let range = match (self.lo_included, self.hi_included) {
            (true, true) => format!("{lo} to {hi}"),
            (false, false) => format!("greater than {lo} and less than {hi}"),
            (false, true) => format!("greater than {lo} and at most {hi}"),
            (true, false) => format!("at least {lo} and less than {hi}"),
        };
        if self.unit.is_empty() {
            range
        } else {
            format!("{range} {}", self.unit)
        }
    }

    /// `v` checked: outside, the error of `field` says the range and `v`.
    pub fn check(&self, field: &str, v: T) -> Result<(), FieldError> {
        if self.contains(v) {
            return Ok(());
        }
        Err(FieldError::new(
            field,
            format!("must be {}, got {}", self.words(), v.text()),
        ))
    }
}

/// A Fermat surface's `y_range` (the half-width a of its strips in the imaginary
/// direction).
pub const FERMAT_Y_RANGE: Bound<f64> = Bound::closed(1e-6, 4.0, "");

/// `render.eye_separation`: the angle between the eyes of a stereo pair.
pub const EYE_SEPARATION: Bound<f64> = Bound::closed(0.0, 30.0, "degrees");

/// `camera.elevation`: above or below the xy plane, short of the poles.
pub const ELEVATION: Bound<f64> = Bound::closed(-89.0, 89.0, "degrees");

/// `camera.fov`: the vertical field of view of a perspective camera.
pub const FOV: Bound<f64> = Bound::open(1.0, 170.0, "degrees");

/// `camera.distance`: the eye's distance from the scene's centre.
pub const CAMERA_DISTANCE: Bound<f64> = Bound::above(0.0, 1e4, "half-diagonals of the scene");

/// `render.ribbons.count`: bands per unit of the parameter.
pub const RIBBON_COUNT: Bound<f64> = Bound::above(0.0, 1e4, "bands per unit");

/// `render.ribbons.gap`: the share of each band cut away.
pub const RIBBON_GAP: Bound<f64> = Bound::open(0.0, 1.0, "");

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

/// The limits as the README's table (Markdown), one row per limit.
pub fn table() -> String {
    let rows = [
        (
            "`sampling.tolerance`, `halo4d sweep --tolerances`",
            range(&RELATIVE_TOLERANCE),
            "of the 4D bounding diagonal",
        ),
        (
            "`sampling.u`, `sampling.v`",
            range(&GRID_CELLS),
            "cells, even",
        ),
        (
            "`sampling.max_triangles`, `halo4d sweep --max-triangles`; all uniform grids of a scene",
            range(&TRIANGLES),
            "triangles",
        ),
        (
            "`halo4d sweep --max-triangles` default",
            SWEEP_TRIANGLES.to_string(),
            "triangles",
        ),
        (
            "the shortest edge adaptive sampling splits",
            format!("{MIN_EDGE:?}"),
            "of the surface's 4D extent",
        ),
        ("`surfaces`", range(&SURFACES), "surfaces"),
        (
            "`name`, `surfaces[i].name`",
            range(&NAME_LENGTH),
            "characters",
        ),
        (
            "`render.width`, `render.height`, the viewer's size",
            range(&PICTURE_SIDE),
            "pixels",
        ),
        ("a Fermat surface's `y_range`", FERMAT_Y_RANGE.words(), ""),
        ("`camera.elevation`", ELEVATION.words(), ""),
        ("`camera.fov`", FOV.words(), ""),
        (
            "`camera.distance` (absent: fitted)",
            CAMERA_DISTANCE.words(),
            "",
        ),
        ("`render.eye_separation`", EYE_SEPARATION.words(), ""),
        ("`render.ribbons.count`", RIBBON_COUNT.words(), ""),
        ("`render.ribbons.gap`", RIBBON_GAP.words(), "of each band"),
        (
            "`halo.gap_px`",
            format!("more than 0, up to {MAX_GAP_PX}"),
            "pixels",
        ),
        (
            "the view search's mesh (`halo4d view`)",
            format!("about {SEARCH_TRIANGLES}"),
            "triangles",
        ),
        (
            "4D views the view search evaluates",
            format!("up to {SEARCH_VIEWS}"),
            "4D views",
        ),
        (
            "`render.samples`, the viewer's samples",
            SAMPLES.map(|s| s.to_string()).join(", "),
            "per pixel",
        ),
        (
            "`render.slices`, `halo4d sweep --render --slices`",
            range(&SLICES),
            "slices",
        ),
        ("the viewer's slices", range(&VIEWER_SLICES), "slices"),
        ("`render.stipple.count`", STIPPLES.words(), ""),
        ("`render.stipple.size`", STIPPLE_SIZE.words(), ""),
        (
            "surface triangles the viewer loads",
            format!("up to {VIEWER_TRIANGLES}"),
            "triangles",
        ),
        (
            "halo tetrahedra the viewer loads",
            format!("up to {VIEWER_TETRAHEDRA}"),
            "tetrahedra",
        ),
        (
            "a projected coordinate (x, y, z or w)",
            format!("up to {MAX_COORDINATE:e}"),
            "scene units",
        ),
        (
            "a projected scene's bounding diagonal",
            format!("at least {MIN_EXTENT:e}"),
            "scene units",
        ),
        (
            "`animation.frames`, `halo4d animate --frames`",
            range(&ANIMATION_FRAMES),
            "frames",
        ),
        ("`animation.keyframes`", range(&KEYFRAMES), "keyframes"),
        ("`animation.fps`", range(&FPS), "frames per second"),
        (
            "a formula's length (`surfaces[i].surface.x`, ...)",
            format!("up to {FORMULA_LENGTH}"),
            "bytes",
        ),
        (
            "a formula's nesting of parentheses, powers and signs",
            format!("up to {FORMULA_DEPTH}"),
            "levels",
        ),
        (
            "a constant exponent in a formula",
            format!("up to {FORMULA_EXPONENT:e}"),
            "in size",
        ),
        (
            "a formula surface's second derivative times its squared parameter extent",
            format!("up to {FORMULA_BEND:e}"),
            "bounding diagonals",
        ),
        (
            "the gap between points a formula surface's sides glue",
            format!("at most {FORMULA_GLUE:e}"),
            "of the bounding diagonal",
        ),
        (
            "a curve sample the halos do not explain is ambiguous, not wrong, this near a branch point or a boundary end",
            format!("{BRANCH_REACH:?}"),
            "halo widths rho",
        ),
        (
            "a halo's volume defect (`halo4d check`, a build's verdict)",
            format!("at most {VOLUME_DEFECT:e}"),
            "relative",
        ),
    ];
    let mut out = String::from("| setting | allowed | unit |\n| --- | --- | --- |\n");
    for (setting, allowed, unit) in rows {
        out += &format!("| {setting} | {allowed} | {unit} |\n");
    }
    out
}

fn range<T: fmt::Debug>(r: &RangeInclusive<T>) -> String {
    // Debug writes 1e-9 as `1e-9`, where Display writes 0.000000001.
    format!("{:?} to {:?}", r.start(), r.end())
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
        assert_eq!(ends.words(), "at least 0 and less than 1");
        assert_eq!(
            Bound::closed(1u32, 8192, "pixels").words(),
            "1 to 8192 pixels"
        );
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
