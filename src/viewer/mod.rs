//! The wgpu viewer and 4D explorer (`halo4d-view`, cargo feature `viewer`).
//!
//! Takes ([`Source::open`]): a scene, sampled in 4D and turned in 4D with its surfaces and
//! halos rebuilt on the GPU for every view ([`Model`], `turn.rs`); or a scene's `.glb` as
//! `halo4d build` writes it ([`crate::import::read_scene_glb`]: surfaces with w, halo
//! tetrahedra with t, d_orig and the eq. 3 parameters, curves), turned in 4D when it carries
//! the 4D mesh and its scene. Gives: pictures on the GPU, in a window ([`window`]) or
//! offscreen ([`screenshot_of`]), with the camera of [`crate::render`], so that the two
//! renderers can be compared pixel for pixel; the view found, as a scene file
//! ([`save_scene`]).
//!
//! A surface fragment at x with depth w is hidden when the halo depth there (paper 000 eq. 3)
//! is below w, by more than the sheet's own halo can be (see below). The halo depth comes
//! from the tetrahedra sliced into N planes in one of two ways ([`HaloMode`]):
//! - `grid` (the default): once per loaded asset and slice count, a compute pass writes the
//!   smallest halo depth at the centre of every voxel of a grid N voxels across the halos
//!   into a 3D texture (in bands of layers as large as one storage binding holds). The halos of an exported asset depend on the 4D view, not on the
//!   3D camera, so every camera angle reuses it; a fragment reads its nearest voxel.
//! - `view`: paper 000's method, per frame: N planes perpendicular to the view; per plane,
//!   the cut of every tetrahedron it crosses is drawn into a halo-depth image (the depth
//!   test keeping the smallest), then the surface fragments between that plane's neighbours
//!   are drawn against it, front slab first, sharing one depth buffer.
//!
//! A sheet's own halo: the CPU renderer leaves out the tetrahedra over the fragment's
//! triangle's vertices; a sample of the slices cannot tell whose halo it holds. Where a
//! sample taken at distance r from the fragment is the sheet's own halo, it holds d_orig of
//! a surface point about r away, so it can fall below w by |grad w| r; where flips and
//! inserted vertices made tetrahedra across neighbouring prisms, by up to |grad w| times a
//! fraction of an edge. A fragment is therefore hidden only where the sample is below
//! w - |grad w| (r + l / 4) - 1e-6 of the depth range, with r the largest distance from a
//! point to its sample (half a voxel's diagonal, or half a slab, stretched by the ray's
//! slant) and l the longest mesh edge at the fragment's triangle's vertices (both
//! interpolated from the vertices). The quarter is measured: the smallest fraction that
//! leaves no sheet hidden by its own halo on any fixture (the viewer tests compare every
//! fixture with the exact CPU render). Other sheets' halos hide as in the CPU renderer
//! except within that margin of where they start hiding.
//!
//! Curves and silhouettes are bands of the CPU renderer's line width, drawn after the
//! surfaces where their centre is in view: not behind the farthest surface within a pixel
//! of it (by more than half the width).
//!
//! In the stipple style (paper 003) the surfaces are drawn white and each surface's ranked
//! stipples, made once from the 4D mesh, are placed, thinned and tested against the
//! surfaces' depth on the GPU (`stipple.rs`, [`StippleSet`]).

mod gpu;
mod renderer;
mod stipple;
mod turn;
pub mod window;

pub use gpu::Gpu;
pub use renderer::{FrameTimes, OFFSCREEN_FORMAT, Renderer};
pub use stipple::StippleSet;
pub use turn::{Framing, Hyperplane, Model};

use crate::import::{ImportError, ImportedScene};
use crate::limits::{
    FieldError, PICTURE_SIDE, VIEWER_SLICES, VIEWER_TETRAHEDRA, VIEWER_TRIANGLES, check_samples,
};
use crate::progress::Job;
use crate::render::camera::{Camera, Placement, bounding_radius};
use crate::render::overlay::{AGREE, interior_edges};
use crate::render::{
    CameraSettings, Colormap, RenderError, RenderSettings, StippleSettings, Style,
};
use glam::{DMat4, DVec3, DVec4};
use std::path::Path;

/// The slice counts the viewer offers.
pub const SLICE_COUNTS: [u32; 4] = [64, 128, 256, 512];

/// How the halo depth is sliced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum HaloMode {
    /// Once per asset, into a 3D texture that every camera reuses.
    #[default]
    Grid,
    /// Per frame, on planes perpendicular to the view (paper 000 section 4.6).
    View,
}

impl HaloMode {
    /// The mode's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            HaloMode::Grid => "grid",
            HaloMode::View => "view",
        }
    }
}

/// What a frame shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// The picture, as a scene's `render` says it: the size, the samples per pixel (a
    /// square grid, the frame drawn that many times larger and averaged), the slices of the
    /// halo depth (N planes, N voxels across the grid), whether halos hide anything and
    /// whether the curves and silhouettes are drawn, the colour scale of w, the style
    /// (stipples on the first surface the halos leave visible, which must be given to the
    /// renderer: [`Renderer::set_stipples`]), the cutaway (what lies beyond every plane is
    /// not drawn, as the CPU renderer removes it) and the stipples' size and colour (their
    /// count and seed make the set: [`Source::stipples`]). The explorer draws those; the
    /// rest of `render` (opacity, lighting, ribbons, legend, stereo) is the CPU renderer's.
    pub render: RenderSettings,
    /// The camera, as in a scene file.
    pub camera: CameraSettings,
    /// How the halo depth is sliced.
    pub mode: HaloMode,
    /// Whether surfaces are half transparent (composited in any order, weighted by depth).
    pub transparent: bool,
    /// Colour by w (else one grey).
    pub colour_by_w: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            render: RenderSettings {
                width: 1024,
                height: 1024,
                slices: 256,
                samples: 1,
                halos: true,
                curves: true,
                silhouettes: true,
                colormap: Colormap::Diverging,
                style: Style::Shaded,
                clip: None,
                stipple: StippleSettings::default(),
                ..RenderSettings::default()
            },
            camera: CameraSettings::default(),
            mode: HaloMode::Grid,
            transparent: false,
            colour_by_w: true,
        }
    }
}

impl ViewSettings {
    /// Checks the settings, naming the one that is wrong.
    pub fn check(&self) -> Result<(), ViewerError> {
        let size = format!("{}x{}", self.render.width, self.render.height);
        PICTURE_SIDE
            .check_with("size", self.render.width, &format!("the width of {size}"))
            .and_then(|()| {
                PICTURE_SIDE.check_with(
                    "size",
                    self.render.height,
                    &format!("the height of {size}"),
                )
            })
            .and_then(|()| {
                VIEWER_SLICES.check_with(
                    "slices",
                    self.render.slices,
                    &format!("the viewer offers {SLICE_COUNTS:?}"),
                )
            })
            .and_then(|()| check_samples("samples", self.render.samples))
            .map_err(ViewerError::Setting)?;
        self.render
            .stipple
            .check()
            .map_err(|e| ViewerError::Setting(e.within("stipple")))?;
        self.camera
            .check()
            .map_err(|e| ViewerError::Setting(e.within("camera")))
    }
}

/// Why the viewer cannot show a file.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// The file is not a scene `.glb` the viewer can read.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: String,
        /// Why.
        source: ImportError,
    },
    /// The scene is too large for the viewer or the GPU.
    #[error(
        "{what}: {count} is more than {limit}, {why}; build the scene at a coarser tolerance (sampling.tolerance) or with fewer surfaces"
    )]
    TooLarge {
        /// What is counted.
        what: String,
        /// How many there are.
        count: u64,
        /// How many fit.
        limit: u64,
        /// Which limit.
        why: String,
    },
    /// A setting is out of range.
    #[error("{0}")]
    Setting(#[from] FieldError),
    /// No GPU adapter, or no device from it.
    #[error(
        "no GPU: {0}. On Linux without a GPU, install a software Vulkan driver (Debian: apt-get install mesa-vulkan-drivers)"
    )]
    NoAdapter(String),
    /// The GPU refused or lost the work.
    #[error("the GPU failed: {0}")]
    Gpu(String),
    /// A camera cannot be placed.
    #[error(transparent)]
    Camera(#[from] RenderError),
    /// The 4D view cannot be drawn (the surfaces behind the 4D eye, say).
    #[error("the 4D view: {0}")]
    View(String),
    /// The scene cannot be sampled or built.
    #[error(transparent)]
    Scene(#[from] crate::error::Error),
    /// An output could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

/// A surface vertex as the GPU reads it (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct SurfaceVertex {
    /// Position relative to the scene's centre.
    pub pos: [f32; 3],
    /// w-depth.
    pub w: f32,
    /// Unit normal.
    pub normal: [f32; 3],
    /// The largest |grad w| of the triangles around the vertex.
    pub slope: f32,
    /// `slope` times a quarter of the longest edge at the vertex: how far below w the
    /// halo depth of the tetrahedra around it can reach (see the module's documentation).
    pub spread: f32,
    /// Padding.
    pub pad: [f32; 3],
}

/// A halo vertex as the GPU reads it (32 bytes), with its halo's eq. 3 parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct HaloVertex {
    /// Position relative to the scene's centre.
    pub pos: [f32; 3],
    /// t.
    pub t: f32,
    /// d_orig.
    pub d: f32,
    /// delta_t of its halo.
    pub delta_t: f32,
    /// delta_d of its halo.
    pub delta_d: f32,
    /// Padding.
    pub pad: f32,
}

/// A scene ready for the GPU: every surface, halo and curve in one set of arrays, positions
/// relative to the centre of the surfaces' bounding box.
#[derive(Clone, Debug)]
pub struct Asset {
    /// The scene's name.
    pub name: String,
    /// The camera recorded with the scene, if any.
    pub camera: Option<CameraSettings>,
    /// The picture settings the scene records (`render`), the defaults where the file
    /// records no scene.
    pub render: RenderSettings,
    /// The surfaces' bounding box (absolute), as the CPU renderer computes it.
    pub bounds: (DVec3, DVec3),
    /// The surfaces' vertices (absolute, as the CPU renderer reads them), which a fitted
    /// camera frames.
    pub(crate) fit_points: Vec<DVec3>,
    /// The range of w over the surfaces.
    pub w_range: (f64, f64),
    /// The range of halo depth (eq. 3) the tetrahedra can reach, with the surfaces' w.
    pub depth_range: (f64, f64),
    pub(crate) vertices: Vec<SurfaceVertex>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) halo_vertices: Vec<HaloVertex>,
    pub(crate) tets: Vec<[u32; 4]>,
    /// Curve points: position relative to the centre, and w.
    pub(crate) curve_points: Vec<[f32; 4]>,
    pub(crate) curve_segments: Vec<[u32; 2]>,
    /// Interior edges: (a, b, triangle i, triangle j | 1 << 31 where their windings agree).
    pub(crate) edges: Vec<[u32; 4]>,
    /// Per triangle, its normal as wound (unnormalized).
    pub(crate) face_normals: Vec<[f32; 4]>,
    /// Surfaces without a halo, by name.
    pub surfaces_without_halo: Vec<String>,
}

impl Asset {
    /// Reads a scene's `.glb`.
    pub fn load(path: &Path) -> Result<Asset, ViewerError> {
        Asset::read(path).map(|(_, asset)| asset)
    }

    /// Reads a scene's `.glb`: the scene as imported, and the asset made from it.
    pub fn read(path: &Path) -> Result<(ImportedScene, Asset), ViewerError> {
        let file = |source: ImportError| ViewerError::File {
            path: path.display().to_string(),
            source,
        };
        let bytes = std::fs::read(path).map_err(|e| file(e.into()))?;
        let scene = crate::import::read_scene_glb(&bytes).map_err(file)?;
        let name = scene.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
        });
        let asset = Asset::new(&scene, name)?;
        Ok((scene, asset))
    }

    /// Gathers an imported scene, checking its size against [`VIEWER_TRIANGLES`] and
    /// [`VIEWER_TETRAHEDRA`].
    pub fn new(scene: &ImportedScene, name: String) -> Result<Asset, ViewerError> {
        let triangles: usize = scene.surfaces.iter().map(|s| s.triangles.len()).sum();
        let tets: usize = scene
            .surfaces
            .iter()
            .filter_map(|s| s.halo.as_ref())
            .map(|h| h.mesh.tets.len())
            .sum();
        check_size(triangles, tets)?;
        let bounds = crate::render::triangle_bounds(
            scene
                .surfaces
                .iter()
                .map(|s| (s.positions.as_slice(), s.triangles.as_slice())),
        )
        .ok_or(ViewerError::Camera(RenderError::Empty))?;
        let centre = (bounds.0 + bounds.1) * 0.5;
        let rel = |p: DVec3| (p - centre).as_vec3().to_array();
        let mut w_range = (f64::INFINITY, f64::NEG_INFINITY);
        let mut vertices = Vec::new();
        let mut all_triangles = Vec::with_capacity(triangles);
        let mut halo_vertices = Vec::new();
        let mut all_tets = Vec::with_capacity(tets);
        let mut without = Vec::new();
        let mut depth_hi = f64::NEG_INFINITY;
        let mut edges = Vec::new();
        let mut face_normals = Vec::with_capacity(triangles);
        for s in &scene.surfaces {
            let base = vertices.len() as u32;
            let first_triangle = face_normals.len() as u32;
            push_edges(&mut edges, &s.triangles, base, first_triangle);
            face_normals.extend(s.triangles.iter().map(|t| {
                let p = t.map(|v| s.positions[v as usize]);
                let [x, y, z] = (p[1] - p[0]).cross(p[2] - p[0]).as_vec3().to_array();
                [x, y, z, 0.0]
            }));
            for &w in &s.w {
                w_range = (w_range.0.min(w), w_range.1.max(w));
            }
            let normals = &s.normals;
            let (slopes, reach) = w_slopes(&s.positions, &s.w, &s.triangles);
            for (i, &p) in s.positions.iter().enumerate() {
                vertices.push(SurfaceVertex {
                    pos: rel(p),
                    w: s.w[i] as f32,
                    normal: normals[i].as_vec3().to_array(),
                    slope: slopes[i] as f32,
                    spread: (slopes[i] * reach[i] * 0.25) as f32,
                    pad: [0.0; 3],
                });
            }
            all_triangles.extend(s.triangles.iter().map(|t| t.map(|v| v + base)));
            let Some(h) = &s.halo else {
                without.push(s.name.clone());
                continue;
            };
            let (Some(t), Some(d), Some(delta_t), Some(delta_d)) =
                (&h.t, &h.d_orig, h.params.delta_t, h.params.delta_d)
            else {
                without.push(s.name.clone());
                continue;
            };
            let base = halo_vertices.len() as u32;
            for (i, p) in h.mesh.positions.iter().enumerate() {
                halo_vertices.push(HaloVertex {
                    pos: rel(DVec3::from(*p)),
                    t: t[i] as f32,
                    d: d[i] as f32,
                    delta_t: delta_t as f32,
                    delta_d: delta_d as f32,
                    pad: 0.0,
                });
                depth_hi = depth_hi.max(d[i] + (1.0 - delta_t).max(0.0) * delta_d.max(0.0));
            }
            all_tets.extend(h.mesh.tets.iter().map(|k| k.map(|v| v + base)));
        }
        let curve_points = scene.curves.as_ref().map_or_else(Vec::new, |c| {
            c.positions
                .iter()
                .zip(&c.w)
                .map(|(&p, &w)| {
                    let [x, y, z] = rel(p);
                    [x, y, z, w as f32]
                })
                .collect()
        });
        let curve_segments = scene
            .curves
            .as_ref()
            .map_or_else(Vec::new, |c| c.segments.clone());
        let depth_lo = halo_vertices
            .iter()
            .map(|v| f64::from(v.d))
            .fold(w_range.0, f64::min);
        let depth_hi = depth_hi.max(w_range.1);
        let fit_points = scene
            .surfaces
            .iter()
            .flat_map(|s| {
                let mut used = vec![false; s.positions.len()];
                for &v in s.triangles.iter().flatten() {
                    used[v as usize] = true;
                }
                s.positions
                    .iter()
                    .zip(used)
                    .filter_map(|(&p, used)| used.then_some(p))
                    .collect::<Vec<_>>()
            })
            .collect();
        Ok(Asset {
            name,
            camera: scene.camera,
            // Set by [`Source::open`], which reads the scene once.
            render: RenderSettings::default(),
            bounds,
            fit_points,
            w_range,
            depth_range: (depth_lo, depth_hi),
            vertices,
            triangles: all_triangles,
            halo_vertices,
            tets: all_tets,
            curve_points,
            curve_segments,
            edges,
            face_normals,
            surfaces_without_halo: without,
        })
    }

    /// The centre of the bounding box (the origin of the GPU's coordinates).
    pub fn centre(&self) -> DVec3 {
        (self.bounds.0 + self.bounds.1) * 0.5
    }

    /// Where the eye of `camera` stands for a picture of `width` x `height` of the asset as
    /// it is now, as the CPU renderer places it ([`Placement`]: the camera's distance, or
    /// fitted to the vertices).
    pub fn placement(&self, camera: &CameraSettings, width: u32, height: u32) -> Placement {
        Placement::new(
            camera,
            self.bounds,
            self.fit_points.iter().copied(),
            width,
            height,
            &[0.0],
        )
    }

    /// Surface triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Halo tetrahedra.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }
}

/// Refuses a scene of more than [`VIEWER_TRIANGLES`] triangles or [`VIEWER_TETRAHEDRA`]
/// tetrahedra.
fn check_size(triangles: usize, tets: usize) -> Result<(), ViewerError> {
    for (what, count, limit) in [
        ("surface triangles", triangles, VIEWER_TRIANGLES),
        ("halo tetrahedra", tets, VIEWER_TETRAHEDRA),
    ] {
        if count > limit {
            return Err(ViewerError::TooLarge {
                what: format!("the scene's {what}"),
                count: count as u64,
                limit: limit as u64,
                why: "the most the viewer loads".into(),
            });
        }
    }
    Ok(())
}

/// Appends the interior edges of a surface's `triangles` (see
/// [`interior_edges`]) whose first vertex and triangle are `base` and `first_triangle` in the
/// asset.
fn push_edges(edges: &mut Vec<[u32; 4]>, triangles: &[[u32; 3]], base: u32, first_triangle: u32) {
    edges.extend(interior_edges(triangles).into_iter().map(|[a, b, i, j]| {
        let agree = j & AGREE;
        [
            a + base,
            b + base,
            i + first_triangle,
            ((j & !AGREE) + first_triangle) | agree,
        ]
    }));
}

/// Per vertex, the largest |grad w| over the triangles around it (w linear on each), and
/// the longest edge there.
fn w_slopes(positions: &[DVec3], w: &[f64], triangles: &[[u32; 3]]) -> (Vec<f64>, Vec<f64>) {
    let mut out = vec![0.0f64; positions.len()];
    let mut reach = vec![0.0f64; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| v as usize);
        let longest = [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(i, j)| positions[i].distance(positions[j]))
            .fold(0.0, f64::max);
        for v in [a, b, c] {
            reach[v] = reach[v].max(longest);
        }
        let (e1, e2) = (positions[b] - positions[a], positions[c] - positions[a]);
        let (d1, d2) = (w[b] - w[a], w[c] - w[a]);
        let area2 = e1.cross(e2).length_squared();
        if area2 <= 0.0 {
            continue;
        }
        let g2 = (d1 * d1 * e2.length_squared() - 2.0 * d1 * d2 * e1.dot(e2)
            + d2 * d2 * e1.length_squared())
            / area2;
        let g = g2.max(0.0).sqrt();
        if g.is_finite() {
            for v in [a, b, c] {
                out[v] = out[v].max(g);
            }
        }
    }
    (out, reach)
}

/// The camera of `settings` as the GPU uses it: the CPU renderer's [`Camera`] with a clip
/// matrix from coordinates relative to `centre`, and its near and far depths.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GpuCamera {
    /// The CPU renderer's camera.
    pub cam: Camera,
    /// Clip from centre-relative coordinates.
    pub clip: DMat4,
    /// Eye relative to the centre.
    pub eye: DVec3,
    /// The view depth the clip matrix maps to depth 0.
    pub near: f64,
    /// The view depth it maps to depth 1.
    pub far: f64,
}

impl GpuCamera {
    /// The camera of `settings` framing `asset`, as the CPU renderer places it.
    pub fn new(settings: &ViewSettings, asset: &Asset) -> Result<GpuCamera, ViewerError> {
        let placement = asset.placement(
            &settings.camera,
            settings.render.width,
            settings.render.height,
        );
        let cam = Camera::new(
            &settings.camera,
            &placement,
            settings.render.width,
            settings.render.height,
            0.0,
        )?;
        let bounds = asset.bounds;
        let centre = (bounds.0 + bounds.1) * 0.5;
        let radius = bounding_radius(bounds);
        let eye = cam.eye - centre;
        // The centre's depth along the view (a fitted camera may look past the centre).
        let dist = (-eye).dot(cam.forward);
        let sx = 1.0 / (cam.half_height * cam.aspect);
        let sy = 1.0 / cam.half_height;
        // Rows of the clip matrix acting on (p, 1), p relative to the centre.
        let row = |axis: DVec3, scale: f64, add: f64| {
            DVec4::new(axis.x, axis.y, axis.z, -axis.dot(eye)) * scale + DVec4::W * add
        };
        let far = dist + radius * 1.01;
        let near = match settings.camera.projection {
            crate::render::CameraProjection::Perspective => {
                (dist - radius * 1.01).max(radius * 1e-3)
            }
            crate::render::CameraProjection::Orthographic => dist - radius * 1.01,
        };
        let rows = match settings.camera.projection {
            crate::render::CameraProjection::Perspective => {
                let a = far / (far - near);
                [
                    row(cam.right, sx, 0.0),
                    row(cam.up, sy, 0.0),
                    row(cam.forward, a, -near * a),
                    row(cam.forward, 1.0, 0.0),
                ]
            }
            crate::render::CameraProjection::Orthographic => {
                let a = 1.0 / (far - near);
                [
                    row(cam.right, sx, 0.0),
                    row(cam.up, sy, 0.0),
                    row(cam.forward, a, -near * a),
                    DVec4::W,
                ]
            }
        };
        let clip = DMat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        Ok(GpuCamera {
            cam,
            clip,
            eye,
            near,
            far,
        })
    }
}

/// A rendered picture with, per pixel, the distance along the camera ray to the first
/// visible surface (infinite where none), as [`crate::render::render_with_depth`] reports.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The picture.
    pub picture: crate::render::Picture,
    /// Distances, row-major from the top.
    pub distance: Vec<f32>,
    /// What the frame cost.
    pub times: FrameTimes,
}

/// Renders one frame offscreen (no window, no display).
pub fn screenshot(gpu: &Gpu, asset: &Asset, settings: &ViewSettings) -> Result<Frame, ViewerError> {
    settings.check()?;
    let mut renderer = Renderer::new(gpu, asset, renderer::OFFSCREEN_FORMAT)?;
    renderer.read_frame(gpu, settings)
}

/// What the viewer shows: a scene sampled in 4D (turned in 4D and 3D), or a scene's `.glb`
/// (turned in 3D only).
#[derive(Clone, Debug)]
pub enum Source {
    /// A scene, sampled in 4D.
    Model(std::sync::Arc<Model>),
    /// A scene's `.glb`: as imported, and as drawn.
    Asset(Box<(ImportedScene, Asset)>),
}

impl Source {
    /// Opens `path`: a scene file (sampled in 4D), a scene's `.glb` (turned in 4D when it
    /// carries the 4D mesh and the scene, else in 3D, with a note saying why), or with no
    /// path the default scene. Gives the source and the notes for the user.
    pub fn open(path: Option<&Path>, job: Job) -> Result<(Source, Vec<String>), ViewerError> {
        use crate::scene::Scene;
        let Some(path) = path else {
            return Ok((
                Source::Model(Model::new(Scene::default_scene())?.into()),
                vec![],
            ));
        };
        if !path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            let mut scene = Scene::load(path).map_err(crate::error::Error::from)?;
            // A view left to the search ("view": "auto") opens on the view it finds.
            let notes = crate::viewsearch::resolve(&mut scene, job)
                .map_err(|e| ViewerError::View(e.to_string()))?
                .map(|found| found.summary())
                .into_iter()
                .collect();
            return Ok((Source::Model(Model::new(scene)?.into()), notes));
        }
        let (imported, mut asset) = Asset::read(path)?;
        let mut notes = Vec::new();
        if !asset.surfaces_without_halo.is_empty() {
            notes.push(format!(
                "no halo for {}: those surfaces are never hidden (build with halo.enabled)",
                asset.surfaces_without_halo.join(", ")
            ));
        }
        let scene = imported
            .scene
            .as_ref()
            .ok_or_else(|| "no scene recorded in asset.extras.halo4d.scene".to_string())
            .and_then(|json| {
                Scene::parse(
                    &json.to_string(),
                    &format!("{} (asset.extras.halo4d.scene)", path.display()),
                )
                .map_err(|e| e.to_string())
            });
        let meshes: Result<Vec<(String, crate::sample::Mesh4)>, String> = imported
            .surfaces
            .iter()
            .map(|s| {
                s.mesh_4d
                    .clone()
                    .map(|m| (s.name.clone(), m))
                    .map_err(|e| format!("surface {}: {e}", s.name))
            })
            .collect();
        if let Ok(scene) = &scene {
            asset.render = scene.render;
        }
        let why = match (scene, meshes) {
            (Ok(scene), Ok(meshes)) if meshes.len() == scene.surfaces.len() => {
                return Ok((
                    Source::Model(Model::with_meshes(scene, meshes)?.into()),
                    notes,
                ));
            }
            (Err(e), _) | (_, Err(e)) => e,
            (Ok(scene), Ok(meshes)) => format!(
                "{} surfaces in the file, {} in its scene",
                meshes.len(),
                scene.surfaces.len()
            ),
        };
        notes.push(format!("{} turns in 3D only: {why}", path.display()));
        Ok((Source::Asset(Box::new((imported, asset))), notes))
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        match self {
            Source::Model(m) => &m.scene.name,
            Source::Asset(a) => &a.1.name,
        }
    }

    /// The picture settings the scene records (`render`: the style and the stipples' size,
    /// count, seed and colour); the defaults where a `.glb` records no scene.
    pub fn render_settings(&self) -> RenderSettings {
        match self {
            Source::Model(m) => m.scene.render,
            Source::Asset(a) => a.1.render,
        }
    }

    /// Each surface's stipples (`count` per surface, random numbers from `seed`), made on the
    /// CPU from the 4D mesh (a scene's sampled mesh, or the `.glb`'s 4D mesh); refused, with
    /// the reason, for a `.glb` without its 4D mesh. Takes as long as a build's stipples: a
    /// window makes them in the background.
    pub fn stipples(&self, count: usize, seed: u64) -> Result<StippleSet, ViewerError> {
        crate::limits::STIPPLES
            .check("stipple.count", count)
            .map_err(ViewerError::Setting)?;
        match self {
            Source::Model(m) => {
                let meshes: Vec<_> = m
                    .surfaces
                    .iter()
                    .map(|(_, mesh)| (mesh.positions.as_slice(), mesh.triangles.as_slice()))
                    .collect();
                Ok(StippleSet::generate(&meshes, count, seed))
            }
            Source::Asset(a) => {
                let meshes =
                    a.0.surfaces
                        .iter()
                        .map(|s| match &s.mesh_4d {
                            Ok(mesh) if mesh.triangles.len() == s.triangles.len() => {
                                Ok((mesh.positions.as_slice(), mesh.triangles.as_slice()))
                            }
                            Ok(mesh) => Err(format!(
                                "surface {}: its 4D mesh has {} triangles, its 3D mesh {}",
                                s.name,
                                mesh.triangles.len(),
                                s.triangles.len()
                            )),
                            Err(e) => Err(format!(
                                "{} carries no 4D mesh of surface {}: {e}",
                                a.1.name, s.name
                            )),
                        })
                        .collect::<Result<Vec<_>, String>>()
                        .map_err(stipple::refused)?;
                Ok(StippleSet::generate(&meshes, count, seed))
            }
        }
    }

    /// The hyperplane of a model's scene at `level` ([`Model::hyperplane`]); refused for
    /// an asset, which has no 4D mesh to slice.
    pub fn hyperplane(&self, level: Option<f64>) -> Result<Hyperplane, ViewerError> {
        match self {
            Source::Model(m) => m.hyperplane(level),
            Source::Asset(a) => Err(ViewerError::Setting(FieldError::new(
                "hyperplane",
                format!(
                    "{} carries no 4D mesh to slice; open its scene file",
                    a.1.name
                ),
            ))),
        }
    }

    /// The camera the scene records (the default where a `.glb` records none).
    pub fn camera(&self) -> CameraSettings {
        match self {
            Source::Model(m) => m.scene.camera,
            Source::Asset(a) => a.1.camera.unwrap_or_default(),
        }
    }

    /// A renderer of the source into `format`: a model turned to `view` (its scene's when
    /// `None`), with its curves in that view when `curves` (computed here, on the CPU).
    pub fn renderer(
        &self,
        gpu: &Gpu,
        view: Option<&crate::view::View>,
        curves: bool,
        format: wgpu::TextureFormat,
    ) -> Result<Renderer, ViewerError> {
        match self {
            Source::Asset(a) => Renderer::new(gpu, &a.1, format),
            Source::Model(m) => {
                let view = view.unwrap_or(&m.scene.view);
                let mut renderer = Renderer::for_model(gpu, m, view, format)?;
                if curves {
                    renderer.set_curves(gpu, &m.curves(view)?)?;
                }
                Ok(renderer)
            }
        }
    }
}

/// Renders one frame of `source` offscreen (a model in `view`, with its curves, and the
/// slice by its scene's hyperplane at level `hyperplane` where one is given).
pub fn screenshot_of(
    gpu: &Gpu,
    source: &Source,
    view: Option<&crate::view::View>,
    settings: &ViewSettings,
    hyperplane: Option<f64>,
) -> Result<Frame, ViewerError> {
    settings.check()?;
    let mut renderer = source.renderer(
        gpu,
        view,
        settings.render.curves,
        renderer::OFFSCREEN_FORMAT,
    )?;
    if let Some(level) = hyperplane {
        let plane = source.hyperplane(Some(level))?;
        if let Source::Model(m) = source {
            renderer.set_slice(gpu, &plane.polylines(view.unwrap_or(&m.scene.view)))?;
        }
    }
    if settings.render.style == Style::Stipple {
        let st = settings.render.stipple;
        renderer.set_stipples(gpu, &source.stipples(st.count, st.seed)?)?;
    }
    renderer.read_frame(gpu, settings)
}

/// Writes `scene` with `view` and `camera` to `path` (atomically), named after the file
/// where that is a valid scene name (else `<name>-view`), so that `halo4d build` builds the
/// verified asset of that view. The scene written.
pub fn save_scene(
    scene: &crate::scene::Scene,
    view: &crate::view::View,
    camera: &CameraSettings,
    path: &Path,
) -> Result<crate::scene::Scene, ViewerError> {
    let mut saved = crate::scene::Scene {
        view: *view,
        camera: *camera,
        ..scene.clone()
    };
    saved.name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|stem| {
            let named = crate::scene::Scene {
                name: stem.clone(),
                ..saved.clone()
            };
            named.validate().is_ok()
        })
        .unwrap_or_else(|| format!("{}-view", scene.name));
    saved.validate()?;
    let text = serde_json::to_string_pretty(&saved).map_err(|e| ViewerError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    crate::export::write_atomic(path, format!("{text}\n").as_bytes()).map_err(|e| {
        ViewerError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })?;
    Ok(saved)
}

/// What a bench row times.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchMotion {
    /// The 3D camera orbits; the halos stay.
    Orbit,
    /// The 4D view turns (zw swinging 30 degrees either way): every frame rebuilds the
    /// surfaces and halos on the GPU (and the grid, in grid mode).
    Turn4d,
}

impl BenchMotion {
    /// Its name in the bench's table.
    pub fn name(self) -> &'static str {
        match self {
            BenchMotion::Orbit => "3D orbit",
            BenchMotion::Turn4d => "4D turn",
        }
    }
}

/// One line of [`bench()`]: a motion, a style, a mode and a slice count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchRow {
    /// What moves.
    pub motion: BenchMotion,
    /// Shaded surfaces or stipples.
    pub style: Style,
    /// How the halo depth was sliced.
    pub mode: HaloMode,
    /// Slices.
    pub slices: u32,
    /// Building the grid (grid mode): once before an orbit; the mean per frame of a 4D turn.
    pub grid_ms: Option<f64>,
    /// The mean per frame of rebuilding the surfaces and halos (a 4D turn).
    pub turn_ms: Option<f64>,
    /// Frames rendered.
    pub frames: u32,
    /// Mean milliseconds per frame, from the first command to the GPU finishing it (the
    /// rebuild and the grid included for a 4D turn).
    pub mean_ms: f64,
    /// Median milliseconds per frame.
    pub median_ms: f64,
}

/// Renders `frames` frames of each motion the source allows (a 3D orbit, azimuth in equal
/// steps from the settings'; for a model also a 4D turn from `view`) for each mode and each
/// of `slices`, offscreen, after one frame that is not counted (and before each mode's
/// first slice count, a whole orbit that is not), shaded; then, given `stipples`, the same
/// motions in the stipple style in the settings' mode and slice count. `progress` hears of
/// each row.
#[allow(clippy::too_many_arguments)]
pub fn bench(
    gpu: &Gpu,
    source: &Source,
    view: Option<&crate::view::View>,
    settings: &ViewSettings,
    slices: &[u32],
    frames: u32,
    stipples: Option<&StippleSet>,
    progress: &mut dyn FnMut(&BenchRow),
) -> Result<Vec<BenchRow>, ViewerError> {
    settings.check()?;
    let mut renderer = source.renderer(
        gpu,
        view,
        settings.render.curves,
        renderer::OFFSCREEN_FORMAT,
    )?;
    if let Some(set) = stipples {
        renderer.set_stipples(gpu, set)?;
    }
    let target = renderer::frame_texture(
        gpu,
        "bench frame",
        (settings.render.width, settings.render.height),
        renderer::OFFSCREEN_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let target = target.create_view(&Default::default());
    let mut rows = Vec::new();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let shaded = [HaloMode::Grid, HaloMode::View]
        .into_iter()
        .flat_map(|mode| slices.iter().map(move |&n| (Style::Shaded, mode, n)));
    let stippled =
        stipples
            .is_some()
            .then_some((Style::Stipple, settings.mode, settings.render.slices));
    for (style, mode, n) in shaded.chain(stippled) {
        let mut s = ViewSettings { mode, ..*settings };
        s.render.slices = n;
        s.render.style = style;
        let grid_ms = renderer.render(gpu, &target, &s)?.grid_ms;
        let orbit = |f: u32| settings.camera.azimuth + 360.0 * f64::from(f) / f64::from(frames);
        if slices.first() == Some(&n) || style == Style::Stipple {
            // A whole orbit first, untimed: drivers finish compiling shaders on the
            // first frames that need them (lavapipe does, over several frames).
            for f in 0..frames {
                s.camera.azimuth = orbit(f);
                renderer.render(gpu, &target, &s)?;
            }
        }
        let mut times = Vec::with_capacity(frames as usize);
        for f in 0..frames {
            s.camera.azimuth = orbit(f);
            times.push(renderer.render(gpu, &target, &s)?.frame_ms);
        }
        let row = BenchRow {
            motion: BenchMotion::Orbit,
            style,
            mode,
            slices: n,
            grid_ms,
            turn_ms: None,
            frames,
            mean_ms: mean(&times),
            median_ms: median(&mut times),
        };
        progress(&row);
        rows.push(row);
        let Source::Model(model) = source else {
            continue;
        };
        let start = *view.unwrap_or(&model.scene.view);
        s.camera = settings.camera;
        let (mut times, mut turns, mut grids) = (Vec::new(), Vec::new(), Vec::new());
        for f in 0..frames {
            let mut v = start;
            v.rotation.zw +=
                30.0 * (std::f64::consts::TAU * f64::from(f + 1) / f64::from(frames)).sin();
            let clock = std::time::Instant::now();
            turns.push(renderer.turn(gpu, model, &v)?);
            let frame = renderer.render(gpu, &target, &s)?;
            grids.push(frame.grid_ms.unwrap_or(0.0));
            times.push(clock.elapsed().as_secs_f64() * 1e3);
        }
        renderer.turn(gpu, model, &start)?;
        let row = BenchRow {
            motion: BenchMotion::Turn4d,
            style,
            mode,
            slices: n,
            grid_ms: (mode == HaloMode::Grid).then(|| mean(&grids)),
            turn_ms: Some(mean(&turns)),
            frames,
            mean_ms: mean(&times),
            median_ms: median(&mut times),
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// The median of `v` (sorted in place); 0 when empty.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// One line of [`compare`]: a mode and slice count against the exact CPU render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompareRow {
    /// How the halo depth was sliced.
    pub mode: HaloMode,
    /// Slices.
    pub slices: u32,
    /// Share of covered pixels whose first visible surface differs from the exact render's.
    pub verdict_differs: f64,
    /// Milliseconds for the GPU frame (a grid built for it included).
    pub ms: f64,
}

/// Renders `scene` (as [`Asset::read`] gives it, with `asset` made from it) with the CPU
/// renderer's exact mode (one sample per pixel, at the pixel centres where the GPU
/// rasterizes, no lines) and on the GPU with each mode and each of `slices`, at the
/// settings' camera and size, and compares what is visible ([`verdict_differs`] of the
/// distances, to 1e-4). Gives the CPU's milliseconds and a row per GPU frame; `progress`
/// hears of each row.
///
/// [`verdict_differs`]: crate::render::compare::verdict_differs
pub fn compare(
    gpu: &Gpu,
    scene: &ImportedScene,
    asset: &Asset,
    settings: &ViewSettings,
    slices: &[u32],
    progress: &mut dyn FnMut(&CompareRow),
) -> Result<(f64, Vec<CompareRow>), ViewerError> {
    settings.check()?;
    let no_curves = crate::intersect::Curves::default();
    let (exact, cpu_ms) = exact_distances(&scene.parts(&no_curves), settings)?;
    let mut renderer = Renderer::new(gpu, asset, renderer::OFFSCREEN_FORMAT)?;
    let rows = compare_rows(gpu, &mut renderer, &exact, settings, slices, progress)?;
    Ok((cpu_ms, rows))
}

/// What [`compare_turned`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct TurnedComparison {
    /// The CPU's milliseconds: building the scene in the view and its exact render.
    pub cpu_ms: f64,
    /// One row per GPU mode and slice count.
    pub rows: Vec<CompareRow>,
    /// Surface vertices, all surfaces.
    pub vertices: usize,
    /// Of those, where the build shrank rho (or collapsed it, or found no offset direction):
    /// the only places the GPU's halos (rho everywhere) may differ from the build's.
    pub shrunk: usize,
}

/// [`compare`] for a model turned to `view` on the GPU, against `halo4d render --mode
/// exact` of the model's scene with `view` written into it (built from scratch).
pub fn compare_turned(
    gpu: &Gpu,
    model: &Model,
    view: &crate::view::View,
    settings: &ViewSettings,
    slices: &[u32],
    progress: &mut dyn FnMut(&CompareRow),
) -> Result<TurnedComparison, ViewerError> {
    settings.check()?;
    let start = std::time::Instant::now();
    let scene = crate::scene::Scene {
        view: *view,
        ..model.scene.clone()
    };
    let built = crate::pipeline::Sampled::of(&scene)
        .into_built(&scene, crate::pipeline::Stages::picture(&scene))?;
    let parts = built.parts(&scene.halo);
    let (exact, _) = exact_distances(&parts, settings)?;
    let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut renderer = Renderer::for_model(gpu, model, view, renderer::OFFSCREEN_FORMAT)?;
    let rows = compare_rows(gpu, &mut renderer, &exact, settings, slices, progress)?;
    let reports = built.surfaces.iter().map(|s| &s.halo_report);
    Ok(TurnedComparison {
        cpu_ms,
        rows,
        vertices: model.vertex_count(),
        shrunk: reports
            .map(|r| r.shrunk_vertices + r.singular_vertices)
            .sum(),
    })
}

/// The CPU renderer's exact mode at the settings' size and camera, one sample per pixel,
/// no lines: per pixel the distance to the first visible surface; and its milliseconds.
fn exact_distances(
    parts: &crate::parts::Parts,
    settings: &ViewSettings,
) -> Result<(Vec<f64>, f64), ViewerError> {
    let cpu_settings = crate::render::RenderSettings {
        width: settings.render.width,
        height: settings.render.height,
        samples: 1,
        mode: crate::render::RenderMode::Exact,
        halos: settings.render.halos,
        curves: false,
        silhouettes: false,
        colormap: settings.render.colormap,
        ..Default::default()
    };
    let start = std::time::Instant::now();
    let exact = crate::render::render_with_depth(parts, &cpu_settings, &settings.camera)?;
    Ok((exact.1, start.elapsed().as_secs_f64() * 1e3))
}

/// Renders with `renderer` in each mode and each of `slices` (no lines, one sample per
/// pixel) and compares each frame's distances with `exact`.
fn compare_rows(
    gpu: &Gpu,
    renderer: &mut Renderer,
    exact: &[f64],
    settings: &ViewSettings,
    slices: &[u32],
    progress: &mut dyn FnMut(&CompareRow),
) -> Result<Vec<CompareRow>, ViewerError> {
    let mut rows = Vec::new();
    for mode in [HaloMode::Grid, HaloMode::View] {
        for &n in slices {
            let mut s = ViewSettings { mode, ..*settings };
            s.render = RenderSettings {
                slices: n,
                curves: false,
                silhouettes: false,
                samples: 1,
                ..s.render
            };
            let start = std::time::Instant::now();
            let frame = renderer.read_frame(gpu, &s)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let distance: Vec<f64> = frame.distance.iter().map(|&d| f64::from(d)).collect();
            let row = CompareRow {
                mode,
                slices: n,
                verdict_differs: crate::render::compare::verdict_differs(exact, &distance, 1e-4),
                ms,
            };
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}
