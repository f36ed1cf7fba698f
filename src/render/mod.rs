//! The CPU reference renderer: pictures of the projected surfaces with their halos.
//!
//! Takes: the projected surfaces (positions, w, normals, parameters), their halos and the
//! intersection curves, a [`CameraSettings`] and [`RenderSettings`]. Gives: an RGB image.
//! Eye rays are cast through an obvhs BVH over all triangles and every hit along a ray is
//! kept (`trace`), so transparency composites in exact depth order. A hit is hidden where
//! it lies in a halo of another sheet whose halo depth (paper 000 eq. 3) is below its own
//! w: decided per hit by a query over the tetrahedra (`exact`, the reference), or by the
//! paper's multi-slice method (`slices`). Shading is Phong with two lights over a colour by
//! w-depth, with paper 001's depth cues (opacity by w, silhouette opacity, hither clipping,
//! ribbons), and the self-intersection curves and silhouettes are drawn as lines of exact
//! width broadened through the FFT (paper 002, `lines`). Renders are deterministic.

pub(crate) mod camera;
pub(crate) mod clip;
pub(crate) mod compare;
mod contour;
pub mod diagram;
pub(crate) mod lines;
pub(crate) mod overlay;
pub(crate) mod shade;
pub(crate) mod slices;
pub(crate) mod stipple;
pub(crate) mod svg;
pub(crate) mod text;
pub(crate) mod trace;
pub(crate) mod visible;

use crate::limits::{
    CAMERA_DISTANCE, COLOUR, ELEVATION, EYE_SEPARATION, FINITE, FOV, FieldError, HITHER, OPACITY,
    PICTURE_SIDE, RIBBON_COUNT, RIBBON_GAP, SLICES, STIPPLE_SIZE, STIPPLES, check_samples,
    line_width,
};
pub use clip::{Clip, ClipPlane};
pub use compare::Comparison;

use crate::parts::{HaloIndex, Parts, TriangleHiders};
use crate::progress::{Cancel, Cancelled};
use camera::Camera;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trace::{Hit, Primary, Tracer};

/// Perspective or orthographic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CameraProjection {
    /// Rays from the eye through the pixels.
    #[default]
    Perspective,
    /// Parallel rays along the view direction.
    Orthographic,
}

/// The 3D orbit camera of a scene (`camera` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraSettings {
    /// Degrees about the z axis, from +x.
    pub azimuth: f64,
    /// Degrees above the xy plane (z is up), in [-89, 89].
    pub elevation: f64,
    /// Distance of the eye from the centre of the projected scene's bounding box, in units
    /// of half its diagonal; when absent the camera is fitted so that the surfaces fill the
    /// picture ([`camera::Placement`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance: Option<f64>,
    /// Vertical field of view in degrees (perspective).
    pub fov: f64,
    /// Perspective or orthographic.
    pub projection: CameraProjection,
}

impl Default for CameraSettings {
    fn default() -> Self {
        CameraSettings {
            azimuth: 35.0,
            elevation: 25.0,
            distance: None,
            fov: 38.0,
            projection: CameraProjection::Perspective,
        }
    }
}

/// How halos hide sheets in a picture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum RenderMode {
    /// Each hit asks the tetrahedra whether it is hidden (the reference).
    #[default]
    Exact,
    /// Paper 000's multi-slice method: halo depth images on `slices` planes perpendicular
    /// to the view.
    Slices,
}

/// The colour scale of w-depth.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Colormap {
    /// Blue (near) through light grey to orange (far).
    #[default]
    Diverging,
    /// Viridis: dark blue (near) to yellow (far).
    Viridis,
    /// Dark (near) to light (far).
    Gray,
}

/// Which surface parameter ribbons run along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RibbonAxis {
    /// Bands of constant u are cut away.
    U,
    /// Bands of constant v are cut away.
    V,
}

/// Paper 001's ribbons: the surface cut into `count` bands along a parameter, a `gap` share
/// of each removed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ribbons {
    /// The parameter the gaps are spaced along.
    pub along: RibbonAxis,
    /// Bands per unit of the parameter (patch parameters run over their domains).
    pub count: f64,
    /// Share of each band cut away, in (0, 1).
    pub gap: f64,
}

/// How surfaces are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Style {
    /// Phong shading over a colour by w-depth, composited through every sheet.
    #[default]
    Shaded,
    /// Paper 003's stipples: black (or coloured) dots whose density carries the tone, on
    /// the first sheet the halos leave visible.
    Stipple,
}

/// How shaded surfaces are lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Lighting {
    /// Phong shading with the 3D normals of the projected surfaces (`render::shade::phong`).
    #[default]
    #[serde(rename = "3d")]
    ThreeD,
    /// Illumination in 4D (`render::shade::phong4`): the lights leaned into w, lighting the
    /// surface by its plane of normals in 4D, so that the shade shows how the surface leans
    /// in w (the fully 4D-lit rendering of paper 000's fig. 5c).
    #[serde(rename = "4d")]
    FourD,
}

/// The stipple style's settings (`render.stipple` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StippleSettings {
    /// A stipple's diameter in pixels.
    pub size: f64,
    /// Stipples ranked per surface: the most a picture can draw of each. A place where the
    /// tone asks for more is drawn lighter (`halo4d render` warns); about 0.6 stipples per
    /// pixel of the picture are enough for the darkest tones of a surface that fills it.
    pub count: usize,
    /// Seed of the stipples' random numbers.
    pub seed: u64,
    /// Stipples in the colour of their w-depth (paper 003's coloured stipples with tone
    /// shading) instead of black.
    pub colour: bool,
}

impl StippleSettings {
    /// Checks the size and the count ([`crate::limits::STIPPLE_SIZE`],
    /// [`crate::limits::STIPPLES`]): the renderer's and the explorer's one check.
    pub fn check(&self) -> Result<(), FieldError> {
        STIPPLE_SIZE.check("size", self.size)?;
        STIPPLES.check("count", self.count)
    }
}

impl Default for StippleSettings {
    fn default() -> Self {
        StippleSettings {
            size: 2.0,
            count: 600_000,
            seed: 1,
            colour: false,
        }
    }
}

/// How a scene is drawn (`render` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderSettings {
    /// `shaded` or `stipple`.
    pub style: Style,
    /// The stipple style's settings.
    pub stipple: StippleSettings,
    /// Image width in pixels (each half of a stereo pair).
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// `exact` or `slices`.
    pub mode: RenderMode,
    /// Slices for `slices` mode.
    pub slices: u32,
    /// Samples per pixel on a square grid: 1, 4, 9 or 16.
    pub samples: u32,
    /// In `exact` mode, every sample only in the pixels where the picture changes (an edge,
    /// a gap, a crossing, a change of shade: where a pixel's centre sample differs from a
    /// neighbour's), the centre sample alone elsewhere; `false` takes every sample of every
    /// pixel (the reference).
    pub adaptive: bool,
    /// Whether halos hide anything.
    pub halos: bool,
    /// Surface opacity at the near end of w (1 is opaque).
    pub opacity: f64,
    /// Surface opacity at the far end of w (paper 001's opacity by w); the near value when
    /// absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub opacity_far: Option<f64>,
    /// Paper 001's silhouette opacity 1 - (1 - alpha)^(1/d) for transparent surfaces.
    pub silhouette_opacity: bool,
    /// Colour of w-depth.
    pub colormap: Colormap,
    /// `3d` (Phong with the projected surfaces' normals) or `4d` (lit in 4D by the plane
    /// of normals: the shade shows how the surface leans in w).
    pub lighting: Lighting,
    /// A colour bar of the w scale along the bottom of the image (near w at the left).
    pub legend: bool,
    /// Hither clipping: surfaces nearer the eye than this (in units of half the scene's
    /// diagonal) are cut away.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hither: Option<f64>,
    /// Ribbons.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ribbons: Option<Ribbons>,
    /// A cutaway: one plane `{"normal": [x, y, z], "offset": d}` or a list of two (a
    /// wedge), removing the points of the projected scene where `normal · p > d` holds for
    /// every plane (see [`Clip`]); the cut edges are drawn as lines.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clip: Option<clip::Clip>,
    /// Draw the self-intersection curves.
    pub curves: bool,
    /// Draw each piece of a curve in a dark shade of the colour of the sheet that passes
    /// over it (nearer in w; [`overlay::curve_ink`]), so that the reader sees which sheet
    /// is over and which is broken; `false` draws the curves in the silhouettes'
    /// near-black ink.
    pub curve_colours: bool,
    /// Draw silhouettes (where the eye ray lies in the tangent plane).
    pub silhouettes: bool,
    /// Draw the broken edges of the sheets passing under: the outline, in the picture, of
    /// where a halo hides the first surface (the gaps' edges), thinner than the curves.
    pub broken_edges: bool,
    /// The colour of the broken edges, RGB in [0, 1] (paper 000's fig. 8 outlines the
    /// halos in green); the silhouettes' near-black ink when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub broken_edge_colour: Option<[f64; 3]>,
    /// Line width in pixels.
    pub line_width: f64,
    /// Line width at the far side of the scene, for lines that thin with distance; the
    /// same width everywhere when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line_width_far: Option<f64>,
    /// A cross-eyed stereo pair side by side (the left image for the right eye).
    pub stereo: bool,
    /// Angle between the two eyes of a stereo pair, in degrees.
    pub eye_separation: f64,
    /// Background colour, RGB in [0, 1].
    pub background: [f64; 3],
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            style: Style::Shaded,
            stipple: StippleSettings::default(),
            width: 1024,
            height: 1024,
            mode: RenderMode::Exact,
            slices: 256,
            samples: 4,
            adaptive: true,
            halos: true,
            opacity: 1.0,
            opacity_far: None,
            silhouette_opacity: true,
            colormap: Colormap::Diverging,
            lighting: Lighting::ThreeD,
            legend: false,
            hither: None,
            ribbons: None,
            clip: None,
            curves: true,
            curve_colours: true,
            silhouettes: true,
            broken_edges: true,
            broken_edge_colour: None,
            line_width: 2.5,
            line_width_far: None,
            stereo: false,
            eye_separation: 5.0,
            background: [1.0, 1.0, 1.0],
        }
    }
}

impl RenderSettings {
    /// Checks the numbers: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        PICTURE_SIDE.check("width", self.width)?;
        PICTURE_SIDE.check("height", self.height)?;
        SLICES.check("slices", self.slices)?;
        check_samples("samples", self.samples)?;
        self.stipple.check().map_err(|e| e.within("stipple"))?;
        OPACITY.check("opacity", self.opacity)?;
        if let Some(o) = self.opacity_far {
            OPACITY.check("opacity_far", o)?;
        }
        if let Some(h) = self.hither {
            HITHER.check("hither", h)?;
        }
        if let Some(r) = self.ribbons {
            RIBBON_COUNT.check("ribbons.count", r.count)?;
            RIBBON_GAP.check("ribbons.gap", r.gap)?;
        }
        if let Some(c) = &self.clip {
            c.check().map_err(|e| e.within("clip"))?;
        }
        let side = self.width.min(self.height);
        let width = line_width(side);
        for (field, w) in [
            ("line_width", Some(self.line_width)),
            ("line_width_far", self.line_width_far),
        ] {
            if let Some(w) = w {
                width.check_with(
                    field,
                    w,
                    &format!(
                        "at most a quarter of the picture's smaller side ({side} pixels); make the lines thinner or the picture larger"
                    ),
                )?;
            }
        }
        EYE_SEPARATION.check("eye_separation", self.eye_separation)?;
        for (field, colour) in [
            ("background", Some(self.background)),
            ("broken_edge_colour", self.broken_edge_colour),
        ] {
            for (i, &c) in colour.iter().flatten().enumerate() {
                COLOUR.check(&format!("{field}[{i}]"), c)?;
            }
        }
        Ok(())
    }
}

impl CameraSettings {
    /// Checks the numbers: names the first bad field.
    pub fn check(&self) -> Result<(), FieldError> {
        FINITE.check("azimuth", self.azimuth)?;
        ELEVATION.check("elevation", self.elevation)?;
        if let Some(d) = self.distance {
            CAMERA_DISTANCE.check_with(
                "distance",
                d,
                "or absent, for a camera fitted to the surfaces",
            )?;
        }
        FOV.check("fov", self.fov)
    }
}

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A setting is out of range.
    #[error("{0}")]
    Setting(FieldError),
    /// An orthographic eye inside the scene sees nothing sensible.
    #[error(
        "camera.distance: the eye at {distance} half-diagonals is inside the scene's bounding box; an orthographic camera must be outside it (raise camera.distance above 1)"
    )]
    CameraInside {
        /// The distance asked for.
        distance: f64,
    },
    /// Nothing to draw.
    #[error("the scene has no triangles to render")]
    Empty,
    /// The caller cancelled the picture ([`render_until`]).
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// The stipple style asked of a surface without stipples.
    #[error(
        "render.style stipple: surface {surface} has no stipples (they are made from its 4D mesh by a build; a file read back without its 4D mesh has none): use render.style shaded"
    )]
    NoStipples {
        /// The surface's index.
        surface: usize,
    },
    /// The picture would need more memory than the limit (`HALO4D_MAX_MEMORY` gigabytes, or
    /// three quarters of the machine's memory).
    #[error(
        "the picture would need about {:.2} GB ({what}), more than the limit of {:.2} GB ({source_of_limit}); lower render.width and render.height or render.samples, or use render.mode exact, which needs no per-sample store",
        needed / crate::memory::GB,
        limit / crate::memory::GB
    )]
    Memory {
        /// Estimated bytes.
        needed: f64,
        /// What the estimate counts.
        what: String,
        /// The limit in bytes.
        limit: f64,
        /// Where the limit comes from.
        source_of_limit: &'static str,
    },
    /// The memory limit is set wrong.
    #[error("{0}")]
    MemoryLimit(String),
    /// Something that cannot fail did (a bug, not bad input).
    #[error("internal error in the renderer: {0}")]
    Internal(String),
}

/// An RGB picture, 8 bits per channel, row-major from the top.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Three bytes per pixel.
    pub rgb: Vec<u8>,
}

impl Picture {
    /// The PNG file's bytes.
    pub fn png(&self) -> Vec<u8> {
        use image::ImageEncoder;
        let mut out = Vec::new();
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(
                &self.rgb,
                self.width,
                self.height,
                image::ExtendedColorType::Rgb8,
            )
            .expect("an in-memory PNG of a valid size encodes");
        out
    }
}

/// The image of one eye: linear RGB per pixel, and per pixel the ray distance of the
/// first visible surface (infinite where none) for the lines' occlusion.
struct View {
    rgb: Vec<DVec3>,
    front: Vec<f64>,
    /// Per pixel, whether a halo hides the first surface along its centre ray (empty where
    /// not known): its outline is the broken edges of the sheets passing under.
    gap: Vec<bool>,
}

/// Renders a picture.
pub fn render(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<Picture, RenderError> {
    render_until(input, settings, camera, Cancel::never())
}

/// [`render`], stopping between rows of pixels once `cancel` is cancelled
/// ([`RenderError::Cancelled`]).
pub fn render_until(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
    cancel: &Cancel,
) -> Result<Picture, RenderError> {
    Ok(render_eyes(input, settings, camera, Want::default(), cancel)?.picture)
}

/// [`render`], and per pixel of the first eye the ray distance of the first surface the
/// halos leave visible along the pixel's centre sample (infinite where none), which tells
/// where two renders disagree on what is hidden.
pub fn render_with_depth(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<(Picture, Vec<f64>), RenderError> {
    let eyes = render_eyes(
        input,
        settings,
        camera,
        Want {
            depth: true,
            ..Want::default()
        },
        Cancel::never(),
    )?;
    Ok((eyes.picture, eyes.depth))
}

/// A picture and what a build reports of it.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The picture.
    pub picture: Picture,
    /// The first eye's lines as an SVG document (when asked for): the same runs the
    /// picture's lines are drawn from (`svg`).
    pub svg: Option<String>,
    /// The first eye's camera.
    pub camera: visible::PictureCamera,
    /// How much of the curves the first eye's picture shows.
    pub curves: visible::CurveVisibility,
}

/// [`render`], with its line art when `svg` asks for it, its camera and the share of the
/// curves it shows, from one indexing of the scene.
pub fn render_for_build(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
    svg: bool,
    cancel: &Cancel,
) -> Result<Rendered, RenderError> {
    let eyes = render_eyes(
        input,
        settings,
        camera,
        Want {
            svg,
            seen: true,
            ..Want::default()
        },
        cancel,
    )?;
    let (camera, curves) = eyes
        .seen
        .ok_or_else(|| RenderError::Internal("the first eye measured no curves".into()))?;
    Ok(Rendered {
        picture: eyes.picture,
        svg: eyes.svg,
        camera,
        curves,
    })
}

/// What a picture is made with besides its pixels, of the first eye.
#[derive(Clone, Copy, Debug, Default)]
struct Want {
    /// The distances of the first visible surfaces (the stipple style traces them apart).
    depth: bool,
    /// The line art.
    svg: bool,
    /// The camera and the share of the curves in view.
    seen: bool,
}

/// A picture and what [`Want`] asked for (empty or `None` otherwise).
struct Eyes {
    picture: Picture,
    depth: Vec<f64>,
    svg: Option<String>,
    seen: Option<(visible::PictureCamera, visible::CurveVisibility)>,
}

/// The bytes a picture of these settings holds whatever the scene: per pixel, the image and
/// its distances (48 bytes), each eye's colours (3) and the samples' colours while a tile
/// is drawn (12 per sample; the default scene's picture of 1024 x 1024 pixels and 4 samples
/// adds 0.10 GB to its build's peak). Its `slices` mode adds its store of hits, estimated
/// when it is drawn.
pub fn picture_bytes(settings: &RenderSettings) -> f64 {
    let pixels = f64::from(settings.width) * f64::from(settings.height);
    pixels * (48.0 + 3.0 * eyes(settings).len() as f64 + 12.0 * f64::from(settings.samples))
}

/// The picture of every eye, and of the first eye what `want` asks for; stopped between
/// rows once `cancel` is cancelled.
fn render_eyes<'a>(
    input: &'a Parts<'a>,
    settings: &'a RenderSettings,
    camera: &CameraSettings,
    want: Want,
    cancel: &'a Cancel,
) -> Result<Eyes, RenderError> {
    // Before the indexes too: the halos' takes seconds at millions of tetrahedra, and obvhs
    // cannot be stopped inside it.
    cancel.check()?;
    let (placement, mut scene) = prepare(input, settings, camera)?;
    scene.cancel = cancel;
    cancel.check()?;
    let eyes = eyes(settings);
    let mut depth = Vec::new();
    let (mut svg, mut seen) = (None, None);
    let (w, h) = (settings.width, settings.height);
    scene.check_memory(&Camera::new(camera, &placement, w, h, eyes[0])?)?;
    let mut rgb = vec![0u8; 3 * (w as usize * eyes.len()) * h as usize];
    for (e, &offset) in eyes.iter().enumerate() {
        let cam = Camera::new(camera, &placement, w, h, offset)?;
        let primary = scene.primary(&cam);
        let mut view = match settings.style {
            Style::Shaded => scene.view(&primary),
            Style::Stipple => scene.view_stipples(&primary, want.depth && e == 0)?,
        };
        cancel.check()?;
        if e == 0 && want.depth {
            depth.clone_from(&view.front);
        }
        let runs = scene.runs(&primary, &view.gap)?;
        for lines in scene.rasterize(&runs)? {
            view.rgb
                .par_iter_mut()
                .zip(lines.coverage.values())
                .for_each(|(c, &k)| *c = c.lerp(lines.ink, f64::from(k)));
        }
        if e == 0 && want.svg {
            svg = Some(svg::document(w, h, scene.background, &runs));
        }
        if e == 0 && want.seen {
            let camera = visible::PictureCamera::of(&cam, placement.target, w, h);
            seen = Some((camera, scene.curve_visibility(&primary)));
        }
        if settings.legend {
            legend(
                &mut view.rgb,
                (w as usize, h as usize),
                settings,
                scene.w_range,
            )?;
        }
        // This eye's part of each row of the picture, on the cores.
        let row = 3 * w as usize;
        rgb.par_chunks_mut(row * eyes.len())
            .zip(view.rgb.par_chunks(w as usize))
            .for_each(|(out, colours)| {
                for (bytes, c) in out[e * row..(e + 1) * row].chunks_mut(3).zip(colours) {
                    for k in 0..3 {
                        bytes[k] = to_srgb8(c[k]);
                    }
                }
            });
    }
    Ok(Eyes {
        picture: Picture {
            width: w * eyes.len() as u32,
            height: h,
            rgb,
        },
        depth,
        svg,
        seen,
    })
}

/// The stipples the first eye's picture in the stipple style draws (whatever
/// `settings.style` says), in the order of their surfaces and ranks.
pub fn stipples_drawn(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<Vec<stipple::Drawn>, RenderError> {
    let (placement, scene) = prepare(input, settings, camera)?;
    let cam = first_camera(settings, camera, &placement)?;
    scene.stipples(&scene.primary(&cam))
}

/// The coverage in [0, 1] of the lines (curves and silhouettes, as the settings ask) in the
/// first eye's image, row-major; all zero when there are none. Where the lines are drawn in
/// several inks, their coverages `c` combine as the picture lays them over each other,
/// 1 - prod(1 - c).
pub fn line_coverage(
    input: &Parts,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<Vec<f32>, RenderError> {
    let (placement, scene) = prepare(input, settings, camera)?;
    let cam = first_camera(settings, camera, &placement)?;
    let mut inks = scene.lines(&cam, &[])?.into_iter();
    let Some(first) = inks.next() else {
        return Ok(vec![
            0.0;
            settings.width as usize * settings.height as usize
        ]);
    };
    let mut total = first.coverage.values().to_vec();
    for lines in inks {
        for (t, &c) in total.iter_mut().zip(lines.coverage.values()) {
            *t += c - *t * c;
        }
    }
    Ok(total)
}

/// What the centre ray of a pixel sees first, for probing a picture at known places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seen {
    /// Surface index.
    pub surface: u32,
    /// Triangle index in that surface.
    pub triangle: u32,
    /// Where.
    pub position: DVec3,
    /// Its w-depth.
    pub w: f64,
}

/// Probes a picture: what the ray through an image point sees first that the halos do not
/// hide (with the exact test), as [`render`] decides it for the first eye.
pub struct Prober<'a> {
    scene: Scene<'a>,
    cam: Camera,
}

impl<'a> Prober<'a> {
    /// Indexes the scene for probing.
    pub fn new(
        input: &'a Parts<'a>,
        settings: &'a RenderSettings,
        camera: &CameraSettings,
    ) -> Result<Self, RenderError> {
        let (placement, scene) = prepare(input, settings, camera)?;
        let cam = first_camera(settings, camera, &placement)?;
        Ok(Prober { scene, cam })
    }

    /// The camera of the first eye.
    pub fn camera(&self) -> &Camera {
        &self.cam
    }

    /// What the ray through image point `p` (pixel units, y down; a pixel's centre is at
    /// +0.5) sees first.
    pub fn seen(&self, p: [f64; 2]) -> Option<Seen> {
        let s = self.scene.settings;
        let (w, h) = (f64::from(s.width), f64::from(s.height));
        let (origin, dir) = self.cam.ray(2.0 * p[0] / w - 1.0, 1.0 - 2.0 * p[1] / h);
        let mut hits = Vec::new();
        self.scene.trace(origin, dir, &mut hits);
        hits.iter().find_map(|hit| {
            let (x, wd, _) = self.scene.at_hit(origin, dir, hit);
            (!self.scene.hidden_hit(origin, dir, hit)).then_some(Seen {
                surface: hit.surface,
                triangle: hit.triangle,
                position: x,
                w: wd,
            })
        })
    }
}

/// The camera of the first (left) image of a picture placed by `placement`.
fn first_camera(
    settings: &RenderSettings,
    camera: &CameraSettings,
    placement: &camera::Placement,
) -> Result<Camera, RenderError> {
    Camera::new(
        camera,
        placement,
        settings.width,
        settings.height,
        first_eye(settings),
    )
}

/// The azimuth offset of the first (left) image.
fn first_eye(settings: &RenderSettings) -> f64 {
    if settings.stereo {
        settings.eye_separation * 0.5
    } else {
        0.0
    }
}

/// The azimuth offset of each image, left to right. Cross-eyed: the left image is the right
/// eye's (turned right, +azimuth).
fn eyes(settings: &RenderSettings) -> Vec<f64> {
    if settings.stereo {
        vec![first_eye(settings), -first_eye(settings)]
    } else {
        vec![0.0]
    }
}

/// Checks the settings, places the camera (one placement for both eyes of a stereo pair)
/// and indexes the scene.
fn prepare<'a>(
    input: &'a Parts<'a>,
    settings: &'a RenderSettings,
    camera: &CameraSettings,
) -> Result<(camera::Placement, Scene<'a>), RenderError> {
    let surfaces = input.surfaces.iter().map(|s| (s.positions, s.triangles));
    let (placement, bounds) = place(surfaces, settings, camera)?;
    Ok((placement, Scene::new(input, settings, bounds)))
}

/// Checks the settings and places the camera around the projected surfaces (positions,
/// triangles): the placement and the box of the triangles' corners.
fn place<'a>(
    surfaces: impl Iterator<Item = (&'a [DVec3], &'a [[u32; 3]])> + Clone,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<(camera::Placement, (DVec3, DVec3)), RenderError> {
    settings
        .check()
        .map_err(|e| RenderError::Setting(e.within("render")))?;
    camera
        .check()
        .map_err(|e| RenderError::Setting(e.within("camera")))?;
    let bounds = triangle_bounds(surfaces.clone()).ok_or(RenderError::Empty)?;
    let corners = surfaces.flat_map(|(positions, triangles)| {
        triangles
            .iter()
            .flatten()
            .map(move |&v| positions[v as usize])
    });
    let placement = camera::Placement::new(
        camera,
        bounds,
        corners,
        settings.width,
        settings.height,
        &eyes(settings),
    );
    Ok((placement, bounds))
}

/// The side of a pixel of the picture of the projected surfaces (positions, triangles),
/// in scene units at the depth of the point its camera looks at: what `halo.gap_px`
/// multiplies. The settings are checked first.
pub fn picture_pixel_size<'a>(
    surfaces: impl Iterator<Item = (&'a [DVec3], &'a [[u32; 3]])> + Clone,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<f64, RenderError> {
    let (placement, _) = place(surfaces, settings, camera)?;
    let cam = first_camera(settings, camera, &placement)?;
    let depth = (placement.target - cam.eye).dot(cam.forward);
    Ok(visible::pixel_size(&cam, depth, settings.height))
}

/// The camera of the picture of the projected surfaces (positions, triangles), its first eye
/// (what the build's report gives as `picture.camera`), without rendering it: where the eye
/// stands, what it looks at, its field of view and the picture's size. The settings are
/// checked first.
pub fn picture_camera<'a>(
    surfaces: impl Iterator<Item = (&'a [DVec3], &'a [[u32; 3]])> + Clone,
    settings: &RenderSettings,
    camera: &CameraSettings,
) -> Result<visible::PictureCamera, RenderError> {
    let (placement, _) = place(surfaces, settings, camera)?;
    let cam = first_camera(settings, camera, &placement)?;
    Ok(visible::PictureCamera::of(
        &cam,
        placement.target,
        settings.width,
        settings.height,
    ))
}

/// The box around every vertex of a triangle of the surfaces (positions, triangles), which
/// the camera frames; `None` when there is no triangle.
pub fn triangle_bounds<'a>(
    surfaces: impl Iterator<Item = (&'a [DVec3], &'a [[u32; 3]])>,
) -> Option<(DVec3, DVec3)> {
    surfaces
        .flat_map(|(positions, triangles)| {
            triangles
                .iter()
                .flatten()
                .map(move |&v| positions[v as usize])
        })
        .fold(None, |b: Option<(DVec3, DVec3)>, p| {
            Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
        })
}

/// A colour bar of the w scale along the bottom of an image, near w at the left, far at the
/// right, framed in black, with the w of its ends and middle above it where they fit
/// ([`text::label_bar`]): in the lines' ink on a light background, in white on a dark one,
/// outlined in the background's colour.
fn legend(
    rgb: &mut [DVec3],
    (w, h): (usize, usize),
    settings: &RenderSettings,
    (w0, w1): (f64, f64),
) -> Result<(), RenderError> {
    let margin = (w.min(h) / 40).max(2);
    let bar = (h / 40).max(4);
    if w <= 2 * margin + 2 || h <= 2 * margin + bar + 2 {
        return Ok(());
    }
    let (x0, x1) = (margin, w - margin);
    let (y0, y1) = (h - margin - bar, h - margin);
    for y in y0..y1 {
        for x in x0..x1 {
            let frame = x == x0 || x == x1 - 1 || y == y0 || y == y1 - 1;
            rgb[y * w + x] = if frame {
                DVec3::ZERO
            } else {
                shade::colormap(settings.colormap, (x - x0) as f64 / (x1 - x0 - 1) as f64)
            };
        }
    }
    // The colours span w0 to w0 + span ([`Scene::shade`]).
    let span = if w1 > w0 { w1 - w0 } else { 1.0 };
    let background = DVec3::from(settings.background);
    let light = background.dot(DVec3::new(0.2126, 0.7152, 0.0722)) > 0.18;
    let ink = if light { overlay::INK } else { DVec3::ONE };
    text::label_bar(
        rgb,
        (w, h),
        y0,
        (x0, x1),
        [w0, w0 + 0.5 * span, w0 + span],
        ink,
        background,
    )
    .map_err(RenderError::Internal)?;
    Ok(())
}

/// Linear [0, 1] to an 8-bit sRGB value: [`srgb8_formula`]'s byte, found among the values
/// where it steps up (instead of a power per channel): the byte at the start of `c`'s
/// 4096th of [0, 1], then the step within it, if any (the steps lie more than a 4096th
/// apart).
fn to_srgb8(c: f64) -> u8 {
    let (steps, starts) = srgb8_steps();
    // Exact (a power of two), saturating: below 0 and NaN to 0, above 1 to the last.
    let k = ((c * SRGB8_BUCKETS as f64) as usize).min(SRGB8_BUCKETS);
    let mut b = usize::from(starts[k]);
    while b < steps.len() && steps[b] <= c {
        b += 1;
    }
    b as u8
}

/// The buckets of [0, 1] in [`to_srgb8`]'s table.
const SRGB8_BUCKETS: usize = 4096;

/// The least linear value of each byte 1 to 255 in [`srgb8_formula`], found once by
/// bisection over the bit patterns of [0, 1] (the formula never falls as its value grows,
/// and the bits of non-negative f64 order as the values do); and the byte at `k / 4096`
/// for each `k` to 4096.
fn srgb8_steps() -> (&'static [f64], &'static [u8]) {
    static STEPS: std::sync::OnceLock<(Vec<f64>, Vec<u8>)> = std::sync::OnceLock::new();
    let (steps, starts) = STEPS.get_or_init(|| {
        let steps: Vec<f64> = (1..=255u8)
            .map(|b| {
                let (mut lo, mut hi) = (0u64, 1f64.to_bits());
                while lo < hi {
                    let mid = lo + (hi - lo) / 2;
                    if srgb8_formula(f64::from_bits(mid)) >= b {
                        hi = mid;
                    } else {
                        lo = mid + 1;
                    }
                }
                f64::from_bits(lo)
            })
            .collect();
        let starts = (0..=SRGB8_BUCKETS)
            .map(|k| {
                let c = k as f64 / SRGB8_BUCKETS as f64;
                steps.partition_point(|&t| t <= c) as u8
            })
            .collect();
        (steps, starts)
    });
    (steps, starts)
}

/// Linear [0, 1] to an 8-bit sRGB value, by the sRGB formula.
fn srgb8_formula(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// What every ray of one render shares.
struct Scene<'a> {
    input: &'a Parts<'a>,
    settings: &'a RenderSettings,
    tracer: Tracer<'a>,
    /// The halos' tetrahedra, asked per triangle hit.
    halos: Option<TriangleHiders<'a>>,
    /// Per surface and vertex, the tangent plane in 4D ([`shade::vertex_tangent_projectors`])
    /// when the lighting is 4D; empty otherwise.
    planes: Vec<Vec<glam::DMat4>>,
    w_range: (f64, f64),
    centre: DVec3,
    radius: f64,
    background: DVec3,
    /// Checked before each row of pixels: once cancelled, the rows left are not drawn (and
    /// the caller drops the picture).
    cancel: &'a Cancel,
}

impl<'a> Scene<'a> {
    fn new(input: &'a Parts<'a>, settings: &'a RenderSettings, (lo, hi): (DVec3, DVec3)) -> Self {
        let w_range = input
            .surfaces
            .iter()
            .flat_map(|s| s.triangles.iter().flatten().map(|&v| s.w[v as usize]))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| {
                (a.min(w), b.max(w))
            });
        // The triangles' BVH and the halos' side by side on the cores.
        let (tracer, halos) = rayon::join(
            || Tracer::of_parts(input),
            || settings.halos.then(|| TriangleHiders::new(input)),
        );
        Scene {
            input,
            settings,
            tracer,
            halos,
            planes: match settings.lighting {
                Lighting::ThreeD => Vec::new(),
                Lighting::FourD => input
                    .surfaces
                    .par_iter()
                    .map(|s| shade::vertex_tangent_projectors(s.positions, s.w, s.triangles))
                    .collect(),
            },
            w_range,
            centre: (lo + hi) * 0.5,
            radius: (hi - lo).length() * 0.5,
            background: DVec3::from(settings.background),
            cancel: Cancel::never(),
        }
    }

    /// Estimates the memory of the picture before anything is allocated, and refuses it
    /// above the memory limit (`HALO4D_MAX_MEMORY` gigabytes, or three quarters of the
    /// machine's memory). Per pixel: the image and its distances (48 bytes). In `slices`
    /// mode also every hit of every sample ([`slices::Probe`]) with its verdict, and a
    /// slice image per thread; the hits per ray are counted on a grid of up to 64 x 64 rays
    /// through the picture.
    fn check_memory(&self, cam: &Camera) -> Result<(), RenderError> {
        let s = self.settings;
        let pixels = f64::from(s.width) * f64::from(s.height);
        let mut needed = picture_bytes(s);
        let mut what = format!("{} x {} pixels", s.width, s.height);
        if s.mode == RenderMode::Slices && self.halos.is_some() {
            let grid = 64.min(s.width).min(s.height);
            let mut hits = Vec::new();
            let mut total = 0usize;
            for j in 0..grid {
                for i in 0..grid {
                    let x = 2.0 * (f64::from(i) + 0.5) / f64::from(grid) - 1.0;
                    let y = 2.0 * (f64::from(j) + 0.5) / f64::from(grid) - 1.0;
                    let (origin, dir) = cam.ray(x, y);
                    self.trace(origin, dir, &mut hits);
                    total += hits.len();
                }
            }
            let per_ray = total as f64 / f64::from(grid * grid);
            let threads = rayon::current_num_threads() as f64;
            let probe = (std::mem::size_of::<slices::Probe>() + 1) as f64;
            needed += pixels * (f64::from(s.samples) * per_ray * probe + 4.0 + 16.0 * threads);
            what = format!(
                "{what} x {} samples x {per_ray:.1} surfaces per ray, kept for the slices",
                s.samples
            );
        }
        let (limit, source_of_limit) = crate::memory::limit().map_err(RenderError::MemoryLimit)?;
        if needed > limit {
            return Err(RenderError::Memory {
                needed,
                what,
                limit,
                source_of_limit,
            });
        }
        Ok(())
    }

    /// The side of the square grid of samples in a pixel.
    fn grid_side(&self) -> usize {
        (self.settings.samples as f64).sqrt().round() as usize
    }

    /// Where the samples of a pixel lie in it, in order: sample `k` in row `k / n`, column
    /// `k % n` of the pixel's n x n grid, as its offset from the pixel's corner in pixels.
    fn sample_offsets(&self) -> Vec<[f64; 2]> {
        let n = self.grid_side();
        (0..n * n)
            .map(|k| [k % n, k / n].map(|i| (i as f64 + 0.5) / n as f64))
            .collect()
    }

    /// The point `offset` pixels from the corner of pixel (x, y), in [-1, 1]^2 (y up).
    fn sample_point(&self, x: usize, y: usize, [dx, dy]: [f64; 2]) -> (f64, f64) {
        let (w, h) = (self.settings.width as f64, self.settings.height as f64);
        let px = x as f64 + dx;
        let py = y as f64 + dy;
        (2.0 * px / w - 1.0, 1.0 - 2.0 * py / h)
    }

    /// Where `hit` of the ray (`origin`, `dir`) is, its w and its triangle's vertices.
    fn at_hit(&self, origin: DVec3, dir: DVec3, hit: &Hit) -> (DVec3, f64, [u32; 3]) {
        let surf = &self.input.surfaces[hit.surface as usize];
        let tri = surf.triangles[hit.triangle as usize];
        let w = (0..3).map(|i| hit.bary[i] * surf.w[tri[i] as usize]).sum();
        (origin + dir * hit.t, w, tri)
    }

    /// Whether the halos hide `hit` of the ray (`origin`, `dir`), asking the tetrahedra.
    fn hidden_hit(&self, origin: DVec3, dir: DVec3, hit: &Hit) -> bool {
        let (x, w, _) = self.at_hit(origin, dir, hit);
        self.hidden_at(hit, x, w)
    }

    /// Whether the halos hide the point `x` at depth `w` of `hit`'s triangle.
    fn hidden_at(&self, hit: &Hit, x: DVec3, w: f64) -> bool {
        self.halos
            .as_ref()
            .is_some_and(|h| h.hidden(x, w, hit.surface, hit.triangle))
    }

    /// One eye's image.
    fn view(&self, primary: &Primary) -> View {
        match (self.settings.mode, &self.halos) {
            (RenderMode::Slices, Some(h)) => self.view_slices(primary, h.index()),
            _ => self.view_with(
                primary,
                self.opaque_and_uncut(),
                self.settings.adaptive,
                |_, _, hit, x, w| self.hidden_at(hit, x, w),
            ),
        }
    }

    /// One eye's image with `hidden(pixel, hit number in the pixel, hit, x, w)` deciding
    /// which hits the halos hide; rows shared between the cores. With `nearest_first`
    /// (for a `hidden` that does not number the hits), each ray first finds its nearest
    /// surface, with the hits as near ([`Tracer::nearest_hits`]); where the first of them
    /// is hidden, it traces every hit, so the picture is the same either way. With
    /// `adaptive` (also for a `hidden` that does not number the hits), every pixel's centre
    /// sample is traced first and only the pixels where it differs from a neighbour's
    /// ([`Scene::differs`]: an edge, a gap, a crossing, a change of shade) take their other
    /// samples; the rest are their centre sample.
    fn view_with(
        &self,
        primary: &Primary,
        nearest_first: bool,
        adaptive: bool,
        hidden: impl Fn(usize, usize, &Hit, DVec3, f64) -> bool + Sync,
    ) -> View {
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let offsets = self.sample_offsets();
        let n = self.grid_side();
        let centre = (n / 2) * n + n / 2;
        let cam = primary.camera();
        // Sample `k` of pixel (x, y), its hits numbered from `numbered` on (which it
        // advances).
        let sample = |hits: &mut Vec<Hit>, (x, y), k: usize, numbered: &mut usize| {
            let pixel = y * w + x;
            let (sx, sy) = self.sample_point(x, y, offsets[k]);
            let (origin, dir) = cam.ray(sx, sy);
            // Opaque and uncut: where the nearest surface is visible it is all the ray
            // shows, and only the hits that near are traced.
            if nearest_first {
                let slack = 2.0 * self.tracer.same();
                let near = primary.nearest_first([sx, sy], origin, dir, slack, hits);
                let shown = self.shade(cam, origin, dir, &hits[..near.count], |j, hit, x, wd| {
                    hidden(pixel, j, hit, x, wd)
                });
                if !shown.first_hidden {
                    return shown;
                }
                // Uncut: the hits the tiles found are all of the ray's hits.
                if !near.all {
                    self.trace_primary(primary, [sx, sy], origin, dir, hits);
                }
            } else {
                self.trace_primary(primary, [sx, sy], origin, dir, hits);
            }
            let base = *numbered;
            *numbered += hits.len();
            self.shade(cam, origin, dir, hits, |j, hit, x, wd| {
                hidden(pixel, base + j, hit, x, wd)
            })
        };
        // The centre samples first, where the pixels are sampled adaptively; row by row.
        let mut probes = vec![Shown::default(); if adaptive && n > 1 { w * h } else { 0 }];
        probes
            .par_chunks_mut(w)
            .enumerate()
            .for_each_init(Vec::new, |hits, (y, row)| {
                if self.cancel.is_cancelled() {
                    return;
                }
                for (x, probe) in row.iter_mut().enumerate() {
                    *probe = sample(hits, (x, y), centre, &mut 0);
                }
            });
        let changes = self.changes(&probes, (w, h));
        let mut rgb = vec![DVec3::ZERO; w * h];
        let mut front = vec![f64::INFINITY; w * h];
        let mut gap = vec![false; w * h];
        // Row by row on the cores, each thread with its own hit buffer.
        rgb.par_chunks_mut(w)
            .zip(front.par_chunks_mut(w))
            .zip(gap.par_chunks_mut(w))
            .enumerate()
            .for_each_init(Vec::new, |hits, (y, ((rgb, front), gap))| {
                if self.cancel.is_cancelled() {
                    return;
                }
                for (x, ((c, f), g)) in rgb
                    .iter_mut()
                    .zip(front.iter_mut())
                    .zip(gap.iter_mut())
                    .enumerate()
                {
                    let pixel = y * w + x;
                    let probe = probes.get(pixel);
                    if let Some(p) = probe
                        && !changes[pixel]
                    {
                        (*c, *f, *g) = (p.colour, p.first, p.first_hidden);
                        continue;
                    }
                    let mut sum = DVec3::ZERO;
                    let mut numbered = 0;
                    for k in 0..n * n {
                        let shown = match probe {
                            Some(&p) if k == centre => p,
                            _ => sample(hits, (x, y), k, &mut numbered),
                        };
                        sum += shown.colour;
                        if k == centre {
                            (*f, *g) = (shown.first, shown.first_hidden);
                        }
                    }
                    *c = sum / (n * n) as f64;
                }
            });
        View { rgb, front, gap }
    }

    /// Per pixel of an image of `(w, h)` pixels, whether its centre sample differs from
    /// that of a pixel around it ([`Scene::differs`], which is symmetric: each pair of
    /// neighbours is compared once, by the first of the two, row by row on the cores).
    fn changes(&self, probes: &[Shown], (w, h): (usize, usize)) -> Vec<bool> {
        // The neighbours after a pixel (dx, dy): right, below left, below, below right.
        const AFTER: [(isize, usize); 4] = [(1, 0), (-1, 1), (0, 1), (1, 1)];
        let mut after = vec![0u8; probes.len()];
        after.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, bits) in row.iter_mut().enumerate() {
                for (k, (dx, dy)) in AFTER.into_iter().enumerate() {
                    let (i, j) = (x.checked_add_signed(dx), y + dy);
                    if let Some(i) = i.filter(|&i| i < w && j < h)
                        && self.differs(&probes[y * w + x], &probes[j * w + i])
                    {
                        *bits |= 1 << k;
                    }
                }
            }
        });
        let mut changes = vec![false; probes.len()];
        changes.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, change) in row.iter_mut().enumerate() {
                // The pixel after which this one lies as neighbour `k` of AFTER.
                let before = |k: usize| {
                    let (dx, dy) = AFTER[k];
                    let i = x.checked_add_signed(-dx).filter(|&i| i < w)?;
                    let j = y.checked_sub(dy)?;
                    Some(after[j * w + i] >> k & 1 == 1)
                };
                *change = after[y * w + x] != 0 || (0..4).any(|k| before(k) == Some(true));
            }
        });
        changes
    }

    /// Whether what two neighbouring rays show differs enough that the pixels between them
    /// need all their samples: another surface or none, a gap on one and not the other, a
    /// jump in distance (one sheet behind another), or a change of colour above
    /// [`ADAPTIVE_COLOUR_STEP`].
    fn differs(&self, a: &Shown, b: &Shown) -> bool {
        a.surface != b.surface
            || a.first_hidden != b.first_hidden
            || (a.first - b.first).abs() > ADAPTIVE_DEPTH_JUMP * self.radius
            || (a.colour - b.colour).abs().max_element() > ADAPTIVE_COLOUR_STEP
    }

    /// Whether every surface is opaque and nothing cuts hits away (hither, clip, ribbons):
    /// then the first hit the halos leave visible is all a ray shows.
    fn opaque_and_uncut(&self) -> bool {
        let s = self.settings;
        s.opacity >= 1.0
            && s.opacity_far.is_none_or(|o| o >= 1.0)
            && s.hither.is_none()
            && s.clip.is_none()
            && s.ribbons.is_none()
    }

    /// The triangles binned for the primary rays of `cam`'s picture.
    fn primary(&self, cam: &Camera) -> Primary<'_, 'a> {
        Primary::new(&self.tracer, cam, self.settings.width, self.settings.height)
    }

    /// Every hit of a ray that is not clipped away (hither, ribbons), in order.
    fn trace(&self, origin: DVec3, dir: DVec3, hits: &mut Vec<Hit>) {
        self.tracer.hits(origin, dir, self.t_min(), hits);
        self.cut(origin, dir, hits);
    }

    /// [`Scene::trace`] of the primary ray through image point `at`, through `primary`.
    fn trace_primary(
        &self,
        primary: &Primary,
        at: [f64; 2],
        origin: DVec3,
        dir: DVec3,
        hits: &mut Vec<Hit>,
    ) {
        primary.hits(at, origin, dir, self.t_min(), hits);
        self.cut(origin, dir, hits);
    }

    /// Where a ray's hits start: the hither distance, if any.
    fn t_min(&self) -> f64 {
        self.settings.hither.map_or(0.0, |h| h * self.radius)
    }

    /// Drops the hits that the clip and the ribbons cut away.
    fn cut(&self, origin: DVec3, dir: DVec3, hits: &mut Vec<Hit>) {
        let s = self.settings;
        if let Some(c) = &s.clip {
            hits.retain(|hit| !c.removes(origin + dir * hit.t));
        }
        if let Some(r) = s.ribbons {
            let k = match r.along {
                RibbonAxis::U => 0,
                RibbonAxis::V => 1,
            };
            hits.retain(|hit| {
                let surf = &self.input.surfaces[hit.surface as usize];
                // A surface read from a file without its parameters has no ribbons.
                let Some(uv) = surf.uv else { return true };
                let tri = surf.triangles[hit.triangle as usize];
                let param: f64 = (0..3).map(|i| hit.bary[i] * uv[tri[i] as usize][k]).sum();
                (param * r.count).rem_euclid(1.0) >= r.gap
            });
        }
    }

    /// The multi-slice image: every hit of every sample first, then the slices decide which
    /// are hidden, then the samples are composited.
    fn view_slices(&self, primary: &Primary, index: &HaloIndex) -> View {
        let cam = primary.camera();
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let offsets = self.sample_offsets();
        // Per pixel, its hits over all its samples, in sample order; row by row on the
        // cores, joined in order.
        let rows: Vec<(Vec<u32>, Vec<slices::Probe>)> = (0..h)
            .into_par_iter()
            .map_init(Vec::new, |hits, y| {
                let mut counts = Vec::with_capacity(w);
                let mut probes = Vec::new();
                if self.cancel.is_cancelled() {
                    return (vec![0; w], probes);
                }
                for x in 0..w {
                    let pixel = y * w + x;
                    let before = probes.len();
                    for &offset in &offsets {
                        let (sx, sy) = self.sample_point(x, y, offset);
                        let (origin, dir) = cam.ray(sx, sy);
                        self.trace(origin, dir, hits);
                        for hit in hits.iter() {
                            let surf = &self.input.surfaces[hit.surface as usize];
                            let tri = surf.triangles[hit.triangle as usize];
                            probes.push(slices::Probe {
                                pixel: pixel as u32,
                                x: origin + dir * hit.t,
                                w: (0..3).map(|i| hit.bary[i] * surf.w[tri[i] as usize]).sum(),
                                surface: hit.surface,
                                triangle: tri,
                            });
                        }
                    }
                    counts.push((probes.len() - before) as u32);
                }
                (counts, probes)
            })
            .collect();
        let mut starts = vec![0u32; w * h + 1];
        let mut probes = Vec::new();
        let mut pixel = 0;
        for (counts, row) in rows {
            for c in counts {
                starts[pixel + 1] = starts[pixel] + c;
                pixel += 1;
            }
            probes.extend(row);
        }
        if self.cancel.is_cancelled() {
            // Every row is left undrawn: the caller drops the picture.
            return self.view_with(primary, false, false, |_, _, _, _, _| false);
        }
        let depth = (self.centre - cam.eye).dot(cam.forward);
        let hidden = slices::hidden(
            index,
            cam,
            (self.settings.width, self.settings.height),
            self.settings.slices,
            (depth - self.radius, depth + self.radius),
            &probes,
        );
        drop(probes);
        self.view_with(primary, false, false, |pixel, k, _, _, _| {
            hidden[starts[pixel] as usize + k]
        })
    }

    /// Composites the hits of one ray front to back, leaving out those `hidden(k, hit, x,
    /// w)` says the halos hide.
    fn shade(
        &self,
        cam: &Camera,
        origin: DVec3,
        dir: DVec3,
        hits: &[Hit],
        hidden: impl Fn(usize, &Hit, DVec3, f64) -> bool,
    ) -> Shown {
        let s = self.settings;
        let (w0, w1) = self.w_range;
        let span = if w1 > w0 { w1 - w0 } else { 1.0 };
        let mut colour = DVec3::ZERO;
        let mut alpha = 0.0;
        let mut first = f64::INFINITY;
        let mut surface = u32::MAX;
        let mut first_hidden = false;
        for (k, hit) in hits.iter().enumerate() {
            let surf = &self.input.surfaces[hit.surface as usize];
            let tri = surf.triangles[hit.triangle as usize];
            let b = hit.bary;
            let mix = |f: &dyn Fn(usize) -> f64| {
                b[0] * f(tri[0] as usize) + b[1] * f(tri[1] as usize) + b[2] * f(tri[2] as usize)
            };
            let x = origin + dir * hit.t;
            let w = mix(&|v| surf.w[v]);
            if hidden(k, hit, x, w) {
                first_hidden |= k == 0;
                continue;
            }
            if first.is_infinite() {
                (first, surface) = (hit.t, hit.surface);
            }
            let n = shade::shading_normal(
                tri.map(|v| surf.positions[v as usize]),
                tri.map(|v| surf.normals[v as usize]),
                b,
            );
            let depth = (w - w0) / span;
            let base = shade::colormap(s.colormap, depth);
            let lit = match self.planes.get(hit.surface as usize) {
                Some(planes) => {
                    let plane = mix_planes(tri.map(|v| planes[v as usize]), b);
                    shade::phong4(base, plane, dir, cam.right, cam.up)
                }
                None => shade::phong(base, n, dir, cam.right, cam.up),
            };
            let mut a = self.opacity_at(hit);
            if s.silhouette_opacity {
                a = shade::silhouette_opacity(a, n.dot(dir));
            }
            colour += lit * ((1.0 - alpha) * a);
            alpha += (1.0 - alpha) * a;
            if alpha > 0.999 {
                break;
            }
        }
        Shown {
            colour: colour + self.background * (1.0 - alpha),
            first,
            surface,
            first_hidden,
        }
    }
}

/// What one ray shows ([`Scene::shade`]).
#[derive(Clone, Copy, Debug, Default)]
struct Shown {
    /// The hits composited over the background.
    colour: DVec3,
    /// The distance of the first hit the halos leave visible (infinite where none).
    first: f64,
    /// Its surface (`u32::MAX` where none).
    surface: u32,
    /// Whether the halos hide the ray's first hit.
    first_hidden: bool,
}

/// Where two neighbouring centre samples are farther apart along their rays than this (in
/// units of half the scene's diagonal), the pixels around take all their samples: one sheet
/// seen past the edge of another.
const ADAPTIVE_DEPTH_JUMP: f64 = 0.01;

/// Where two neighbouring centre samples differ by more than this in any linear colour
/// channel, the pixels around take all their samples.
const ADAPTIVE_COLOUR_STEP: f64 = 0.04;

/// The tangent projectors of a triangle's corners interpolated at barycentric `b`.
fn mix_planes(p: [glam::DMat4; 3], b: [f64; 3]) -> glam::DMat4 {
    p[0] * b[0] + p[1] * b[1] + p[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_srgb_bytes_are_the_formula_s() {
        // Every step and the f64 on either side of it, and ten million values spread over
        // [-0.1, 1.1] by a fixed chaotic sequence, with NaN and the infinities.
        let mut values = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0, 1.0];
        let steps = srgb8_steps().0;
        assert!(
            steps
                .windows(2)
                .all(|s| s[1] - s[0] > 1.0 / SRGB8_BUCKETS as f64)
        );
        values.extend_from_slice(steps);
        values.extend((0..=SRGB8_BUCKETS).map(|k| k as f64 / SRGB8_BUCKETS as f64));
        let mut x = 0.5f64;
        for _ in 0..10_000_000 {
            x = (x * 3.999_999 * (1.0 - x)).clamp(1e-12, 1.0 - 1e-12);
            values.push(x * 1.2 - 0.1);
        }
        for c in values {
            for v in [c.next_down(), c, c.next_up()] {
                let (fast, formula) = (to_srgb8(v), srgb8_formula(v));
                assert_eq!(fast, formula, "{v:e}");
            }
        }
    }

    #[test]
    fn tracing_from_the_nearest_surface_first_draws_the_same_picture() {
        // The default scene (nested sheets along most rays, 9% of its pixels in gaps) and
        // the Klein bottle, at 200 x 200: every pixel the same with the shortcut and without.
        for scene in [
            crate::scene::Scene::default_scene(),
            crate::scene::Scene::load(std::path::Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/fixtures/scenes/klein-bottle.json"
            )))
            .unwrap(),
        ] {
            let mut scene = scene;
            (scene.render.width, scene.render.height) = (200, 200);
            let built = crate::Sampled::of(&scene)
                .into_built(&scene, crate::Stages::of(&scene))
                .unwrap();
            let parts = built.parts(&scene.halo);
            let (placement, prepared) = prepare(&parts, &scene.render, &scene.camera).unwrap();
            assert!(prepared.opaque_and_uncut());
            let cam = Camera::new(&scene.camera, &placement, 200, 200, 0.0).unwrap();
            let primary = prepared.primary(&cam);
            let hidden =
                |_: usize, _: usize, hit: &Hit, x: DVec3, w: f64| prepared.hidden_at(hit, x, w);
            let (fast, full) = (
                prepared.view_with(&primary, true, false, hidden),
                prepared.view_with(&primary, false, false, hidden),
            );
            assert_eq!(fast.rgb, full.rgb, "{}", scene.name);
            assert_eq!(fast.front, full.front, "{}", scene.name);
            assert_eq!(fast.gap, full.gap, "{}", scene.name);
            assert!(
                full.gap.iter().any(|&g| g),
                "{}: some pixel in a gap",
                scene.name
            );
        }
    }
}
