//! Turning a scene in 4D: the 4D mesh sampled once on the CPU, each view's surfaces and
//! halos rebuilt on the GPU (paper 000, section 5).
//!
//! A [`Model`] is a scene's surfaces sampled in 4D (the mesh does not depend on the view) and
//! the halos' tetrahedra, which do not either: every prism is split with the global vertex
//! order (Dompierre et al.), a rule local to each prism that conforms with no search and no
//! flip, and the corners whose offset direction turns against the triangle's winding (where a
//! non-orientable surface turns over) are found once, in 4D: a corner is flipped when the
//! triangle's edges, as a bivector, point against its vertex's tangents u ∧ v (for a small
//! triangle that is the sign of its (u, v) orientation in the vertex's chart, which no view
//! changes). Where the tangents are parallel in 4D (the poles of spun spheres) no corner is
//! flipped.
//!
//! Per view ([`Renderer::turn`](super::Renderer::turn)) the CPU projects the positions alone
//! for what frames the picture (the bounding box, the w range, rho as a share of the
//! diagonal, exactly as the build does) and three compute passes (`turn.wgsl`) write the
//! projected surfaces, their normals and the halo vertices into the buffers the renderer
//! draws from. The build shrinks rho by halving it at the corners of inverted tetrahedra
//! until none is left, a search over the whole halo; the GPU limits it in the same pass that
//! places the offsets, from the vertex's own triangles: the offset may lean over a triangle
//! (by rho times the sine of the angle between the offset direction and the triangle's
//! normal) by at most half the triangle's shorter edge at the vertex. Local, so the halos
//! still conform; not a guarantee that no tetrahedron inverts. Measured on the fixtures
//! turned three ways each (`tests/viewer.rs`): with no limit, the twist-spun trefoil's
//! worst view differed from the exact render on 2.11% of the pixels (the build's own `.glb`
//! in the viewer: 1.16%); with it, 1.63% (with the camera at distance 3.2; fitted to the
//! picture, 1.64%).

use super::gpu::compute_pipeline;
use super::{HaloVertex, SurfaceVertex, ViewerError};
use crate::intersect::Curves;
use crate::limits::{FieldError, MAX_COORDINATE, MIN_EXTENT};
use crate::sample::Mesh4;
use crate::scene::Scene;
use crate::tets::{self, Corners, Split};
use crate::view::View;
use bytemuck::Zeroable;
use glam::{DVec3, DVec4};

/// A scene sampled in 4D, ready to be turned.
#[derive(Clone, Debug)]
pub struct Model {
    /// The scene; its `view` and `camera` are where the model starts.
    pub scene: Scene,
    /// Each surface's name and 4D mesh.
    pub(crate) surfaces: Vec<(String, Mesh4)>,
}

/// What frames one view: computed on the CPU from the positions alone.
#[derive(Clone, Debug, PartialEq)]
pub struct Framing {
    /// The projected surfaces' bounding box.
    pub bounds: (DVec3, DVec3),
    /// The projected positions (as the build rounds them), which a fitted camera frames.
    pub points: Vec<DVec3>,
    /// The range of w.
    pub w_range: (f64, f64),
    /// The range of halo depth (eq. 3) the halos reach.
    pub depth_range: (f64, f64),
    /// The halos' half-width (the scene's rho times the bounding box's diagonal).
    pub rho: f64,
}

impl Model {
    /// Samples the scene's surfaces (in parallel), refusing more triangles or tetrahedra
    /// than the viewer loads.
    pub fn new(scene: Scene) -> Result<Model, ViewerError> {
        scene.validate()?;
        let surfaces = crate::pipeline::Sampled::of(&scene).into_meshes();
        Model::with_meshes(scene, surfaces)
    }

    /// A model of `scene` with its surfaces' 4D meshes given (read from a file), refusing
    /// more triangles or tetrahedra than the viewer loads.
    pub fn with_meshes(scene: Scene, surfaces: Vec<(String, Mesh4)>) -> Result<Model, ViewerError> {
        let triangles: usize = surfaces.iter().map(|s| s.1.triangles.len()).sum();
        super::check_size(triangles, 6 * triangles)?;
        Ok(Model { scene, surfaces })
    }

    /// Surface vertices, all surfaces.
    pub fn vertex_count(&self) -> usize {
        self.surfaces.iter().map(|s| s.1.positions.len()).sum()
    }

    /// The largest distance of a 4D vertex from the origin (the reach of the 4D keys).
    pub fn radius_4d(&self) -> f64 {
        self.surfaces
            .iter()
            .flat_map(|s| &s.1.positions)
            .map(|p| p.length())
            .fold(f64::MIN_POSITIVE, f64::max)
    }

    /// Surface triangles, all surfaces.
    pub fn triangle_count(&self) -> usize {
        self.surfaces.iter().map(|s| s.1.triangles.len()).sum()
    }

    /// The asset the renderer draws, with the model's topology (triangles, tetrahedra,
    /// edges) and no geometry yet: [`Renderer::turn`](super::Renderer::turn) writes it.
    pub(crate) fn asset(&self) -> super::Asset {
        let mut asset = super::Asset {
            name: self.scene.name.clone(),
            camera: Some(self.scene.camera),
            render: self.scene.render,
            bounds: (DVec3::splat(-1.0), DVec3::ONE),
            fit_points: Vec::new(),
            w_range: (0.0, 1.0),
            depth_range: (0.0, 1.0),
            vertices: Vec::with_capacity(self.vertex_count()),
            triangles: Vec::with_capacity(self.triangle_count()),
            halo_vertices: Vec::with_capacity(3 * self.vertex_count()),
            tets: Vec::with_capacity(6 * self.triangle_count()),
            curve_points: Vec::new(),
            curve_segments: Vec::new(),
            edges: Vec::new(),
            face_normals: vec![[0.0; 4]; self.triangle_count()],
            surfaces_without_halo: Vec::new(),
        };
        for (_, mesh) in &self.surfaces {
            let n = mesh.positions.len();
            let base = asset.vertices.len() as u32;
            let halo_base = asset.halo_vertices.len() as u32;
            super::push_edges(
                &mut asset.edges,
                &mesh.triangles,
                base,
                asset.triangles.len() as u32,
            );
            asset
                .triangles
                .extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
            asset.tets.extend(
                halo_tets(mesh)
                    .into_iter()
                    .map(|k| k.map(|v| v + halo_base)),
            );
            asset
                .vertices
                .extend(std::iter::repeat_n(SurfaceVertex::zeroed(), n));
            asset
                .halo_vertices
                .extend(std::iter::repeat_n(HaloVertex::zeroed(), 3 * n));
        }
        asset
    }

    /// Each surface's halo as the checker reads it ([`crate::check`]), from `asset` as a
    /// renderer of this model last turned it ([`Renderer::asset`](super::Renderer::asset)).
    pub fn halo_meshes(&self, asset: &super::Asset) -> Vec<crate::check::TetMesh> {
        let mut base = 0usize;
        self.surfaces
            .iter()
            .map(|(_, mesh)| {
                let n = mesh.positions.len();
                let range = base as u32..(base + 3 * n) as u32;
                let out = crate::check::TetMesh {
                    positions: asset.halo_vertices[base..base + 3 * n]
                        .iter()
                        .map(|v| v.pos.map(f64::from))
                        .collect(),
                    surface_vertices: n,
                    tets: asset
                        .tets
                        .iter()
                        .filter(|k| range.contains(&k[0]))
                        .map(|k| k.map(|v| v - range.start))
                        .collect(),
                    surface_triangles: mesh.triangles.clone(),
                };
                base += 3 * n;
                out
            })
            .collect()
    }

    /// Projects the positions for `view` (as the build does: rotation, translation,
    /// projection, rounded to f32) and gives what frames the picture, or why the view
    /// cannot be drawn.
    pub fn framing(&self, view: &View) -> Result<Framing, ViewerError> {
        view.check()
            .map_err(|e| ViewerError::Setting(e.within("view")))?;
        let rot = view.rotation.matrix();
        let shift = DVec4::from_array(view.translation);
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        let mut w_range = (f64::INFINITY, f64::NEG_INFINITY);
        let mut points = Vec::with_capacity(self.vertex_count());
        for (name, mesh) in &self.surfaces {
            for p in &mesh.positions {
                let q = rot * *p + shift;
                let Some((pos, _)) = view.projection.apply(q) else {
                    return Err(ViewerError::View(format!(
                        "surface `{name}` reaches w = {:.4} in this view, at or behind the 4D eye at w = {:.4}; move it away (translation in w) or the eye back (eye distance)",
                        q.w,
                        view.projection.eye_w()
                    )));
                };
                let pos = pos.as_vec3().as_dvec3();
                let w = q.w as f32 as f64;
                if pos.abs().max_element().max(w.abs()) > MAX_COORDINATE {
                    return Err(ViewerError::View(format!(
                        "surface `{name}` reaches a coordinate beyond {MAX_COORDINATE:e} in this view"
                    )));
                }
                lo = lo.min(pos);
                hi = hi.max(pos);
                points.push(pos);
                w_range = (w_range.0.min(w), w_range.1.max(w));
            }
        }
        let diagonal = (hi - lo).length();
        if diagonal.is_nan() || diagonal < MIN_EXTENT {
            return Err(ViewerError::View(format!(
                "the projected surfaces are {diagonal:.3e} across in this view, less than {MIN_EXTENT:e}"
            )));
        }
        // The gap in pixels is that of the scene's own picture in this view, as a build
        // of the scene makes it: one rho for both.
        let mut start = 0;
        let sheets: Vec<(&[DVec3], &[[u32; 3]])> = self
            .surfaces
            .iter()
            .map(|(_, mesh)| {
                let n = mesh.positions.len();
                start += n;
                (&points[start - n..start], mesh.triangles.as_slice())
            })
            .collect();
        let pixel = crate::render::picture_pixel_size(
            sheets.iter().copied(),
            &self.scene.render,
            &self.scene.camera,
        )
        .map_err(|e| ViewerError::View(e.to_string()))?;
        let halo = &self.scene.halo;
        Ok(Framing {
            bounds: (lo, hi),
            points,
            w_range,
            depth_range: (
                w_range.0,
                w_range.1 + (1.0 - halo.delta_t).max(0.0) * halo.delta_d.max(0.0),
            ),
            rho: halo.half_width(diagonal, pixel),
        })
    }

    /// The curves a build of the scene shows in `view` ([`crate::pipeline::shown_curves`]:
    /// the exact curves of the positions the build projects, refined onto the analytic
    /// surfaces as the scene's `curves` say), as the renderer draws them.
    pub fn curves(&self, view: &View) -> Result<Curves, ViewerError> {
        let scene = Scene {
            view: *view,
            ..self.scene.clone()
        };
        let meshes: Vec<&Mesh4> = self.surfaces.iter().map(|(_, m)| m).collect();
        Ok(crate::pipeline::shown_curves(&scene, &meshes)?)
    }

    /// The GPU's static inputs: per vertex its 4D position and tangents, its surface, index
    /// and range in the ring; the ring (each vertex's triangles, global indices); the
    /// triangles flat.
    pub(crate) fn gpu_inputs(&self) -> GpuInputs {
        let mut out = GpuInputs::default();
        let mut base = 0u32;
        let mut first_triangle = 0u32;
        for (s, (_, mesh)) in self.surfaces.iter().enumerate() {
            let n = mesh.positions.len();
            let mut rings = vec![Vec::new(); n];
            for (t, tri) in mesh.triangles.iter().enumerate() {
                for &v in tri {
                    rings[v as usize].push(first_triangle + t as u32);
                }
                out.triangles.extend(tri.map(|v| v + base));
            }
            for (i, ring) in rings.into_iter().enumerate() {
                let f = |v: DVec4| v.as_vec4().to_array();
                out.points.push([
                    f(mesh.positions[i]),
                    f(mesh.tangent_u[i]),
                    f(mesh.tangent_v[i]),
                ]);
                let start = out.ring.len() as u32;
                out.ring.extend(ring);
                out.info
                    .push([s as u32, i as u32, start, out.ring.len() as u32]);
            }
            base += n as u32;
            first_triangle += mesh.triangles.len() as u32;
        }
        out
    }
}

/// The explorer's moving hyperplane ⟨n, x⟩ = level: the slices of a model's surfaces as
/// `halo4d slice` makes them ([`crate::slicing::motion_through`]: on the mesh its motion
/// picture is made of, sampled again through the surface's critical points where the
/// scene's mesh changes its slices elsewhere; the points moved onto the surfaces where the
/// mesh has their parameters), with the surfaces' critical levels, so that the title can
/// say between which events the level lies.
#[derive(Clone, Debug)]
pub struct Hyperplane {
    /// The unit direction n, in the surfaces' own coordinates: the scene's `slicing`'s
    /// direction (the one `halo4d slice` cuts along), fixed while the view turns.
    pub direction: DVec4,
    /// The lowest and (one float above) the highest of h = ⟨n, x⟩ over the surfaces'
    /// vertices and critical points: the levels the hyperplane moves between, where its
    /// slice is empty.
    pub range: (f64, f64),
    /// Every surface's critical points, merged by level.
    pub critical: Vec<crate::motion::CriticalPoint>,
    /// The level c.
    pub level: f64,
    /// Each surface's slice at the level.
    pub slices: Vec<crate::motion::Slice>,
    /// Each surface sampled again for its slices (as `halo4d slice` samples it), said in a
    /// line.
    pub notes: Vec<String>,
    /// Each surface's mesh that is cut, with its analytic surface where it has one.
    cut: Vec<(Mesh4, Option<crate::surfaces::Surface>)>,
}

impl Model {
    /// The hyperplane of the scene's `slicing` (as `halo4d slice` takes it: its direction,
    /// else the one the scene's view turns onto w, tilted by its `perturb`) at `level`, or
    /// at the middle of the surfaces' heights; a level outside them is refused, with them.
    pub fn hyperplane(&self, level: Option<f64>) -> Result<Hyperplane, ViewerError> {
        let slicing = self.scene.slicing.unwrap_or_default();
        let (direction, frame) = slicing.direction_and_frame(self.scene.view.rotation.matrix());
        let mut range = (f64::INFINITY, f64::NEG_INFINITY);
        let mut critical = Vec::new();
        let mut notes = Vec::new();
        let mut cut = Vec::new();
        for (index, ((name, mesh), entry)) in
            self.surfaces.iter().zip(&self.scene.surfaces).enumerate()
        {
            let (surface, shape) = crate::slicing::surface_shape(&entry.surface, mesh);
            let (picture, finest) = crate::slicing::motion_through(
                mesh,
                surface,
                self.scene.surface_sampling(index),
                (direction, frame, shape, 0),
                &mut |_| {},
            )
            .map_err(|e| ViewerError::Setting(e.within("slicing")))?;
            let mesh = finest.map_or_else(
                || mesh.clone(),
                |(again, finer)| {
                    notes.push(format!(
                        "{name} sliced as sampled again at {:.3e} of its diagonal ({} triangles)",
                        again.relative_tolerance, again.triangles
                    ));
                    finer
                },
            );
            let (lo, hi) = crate::motion::heights(&mesh, direction);
            range = (range.0.min(lo), range.1.max(hi));
            critical.extend(picture.critical.points);
            cut.push((mesh, surface.cloned()));
        }
        critical.sort_by(|a, b| a.level.total_cmp(&b.level));
        // The surfaces' highest point can lie above the mesh's (a refined maximum).
        if let (Some(first), Some(last)) = (critical.first(), critical.last()) {
            range = (range.0.min(first.level), range.1.max(last.level));
        }
        // A vertex at the level counts as above it: at the highest vertex's own level its
        // slice is a small loop, one float higher it is empty, as at the lowest.
        range.1 = range.1.next_up();
        let level = match level {
            None => 0.5 * (range.0 + range.1),
            Some(c) if c >= range.0 && c <= range.1 => c,
            Some(c) => {
                return Err(ViewerError::Setting(FieldError::new(
                    "hyperplane",
                    format!(
                        "level {c} is outside the surfaces' heights along the slicing \
                         direction, {:.6} to {:.6}",
                        range.0, range.1
                    ),
                )));
            }
        };
        let mut plane = Hyperplane {
            direction,
            range,
            critical,
            level,
            slices: Vec::new(),
            notes,
            cut,
        };
        plane.move_to(plane.level);
        Ok(plane)
    }
}

impl Hyperplane {
    /// Moves the level to `level` (kept within the surfaces' heights) and slices again.
    pub fn move_to(&mut self, level: f64) {
        self.level = level.clamp(self.range.0, self.range.1);
        self.slices = self
            .cut
            .iter()
            .map(|(mesh, surface)| {
                crate::motion::slice(mesh, surface.as_ref(), self.direction, self.level)
            })
            .collect();
    }

    /// Moves the level by `share` of the surfaces' range of heights.
    pub fn step(&mut self, share: f64) {
        self.move_to(self.level + share * (self.range.1 - self.range.0));
    }

    /// The slices' curves in the 4D `view`, projected as the build projects the surfaces;
    /// a curve is cut where it reaches the 4D eye.
    pub fn polylines(&self, view: &View) -> Vec<crate::motion::Polyline> {
        let map = |p: &DVec4| view.projection.apply(view.transform(*p)).map(|(q, _)| q);
        let mut out = Vec::new();
        for curve in self.slices.iter().flat_map(|s| &s.curves) {
            let mapped: Vec<Option<DVec3>> = curve.points.iter().map(map).collect();
            if mapped.iter().all(Option::is_some) {
                out.push((mapped.into_iter().flatten().collect(), curve.closed));
                continue;
            }
            out.extend(
                mapped
                    .split(Option::is_none)
                    .filter(|run| run.len() > 1)
                    .map(|run| (run.iter().flatten().copied().collect(), false)),
            );
        }
        out
    }

    /// The level, its curves, and the critical levels either side with their events.
    pub fn describe(&self) -> String {
        let curves: usize = self.slices.iter().map(|s| s.curves.len()).sum();
        // As the slice takes a vertex at the level to lie above it, an event at the level
        // is still to come.
        let below = self.critical.iter().rev().find(|p| p.level < self.level);
        let above = self.critical.iter().find(|p| p.level >= self.level);
        let at = |p: Option<&crate::motion::CriticalPoint>, none: &str| {
            p.map_or_else(
                || none.to_string(),
                |p| format!("{} at {:.4}", p.event.name(), p.level),
            )
        };
        format!(
            "slice h = {:.4}: {curves} curve{} | below: {} | above: {}",
            self.level,
            if curves == 1 { "" } else { "s" },
            at(below, "nothing"),
            at(above, "nothing"),
        )
    }
}

/// See [`Model::gpu_inputs`].
#[derive(Clone, Debug, Default)]
pub(crate) struct GpuInputs {
    pub points: Vec<[[f32; 4]; 3]>,
    pub info: Vec<[u32; 4]>,
    pub ring: Vec<u32>,
    pub triangles: Vec<u32>,
}

/// The tetrahedra of a surface's halo in every view: plain prisms (no corner collapsed),
/// flipped corners from the 4D tangents, split by the global vertex order (which never needs
/// an inserted vertex: a prism's lowest vertex is a source or a sink of its edges).
fn halo_tets(mesh: &Mesh4) -> Vec<[u32; 4]> {
    let corners: Vec<Corners> = mesh
        .triangles
        .iter()
        .map(|&tri| Corners {
            tri,
            flip: [0, 1, 2].map(|k| flipped(mesh, tri, k)),
            collapsed: [false; 3],
        })
        .collect();
    let n = mesh.positions.len();
    let (forward, stats) = tets::plan(&corners, &[], n, Split::GlobalOrder);
    let split = tets::emit(&corners, &forward, &[], n, stats);
    debug_assert!(
        split.inserted.is_empty(),
        "the global order inserts nothing"
    );
    split.tets
}

/// Whether corner `k` of `tri` is flipped: the triangle's bivector (b - a) ∧ (c - a) points
/// against the vertex's u ∧ v (false where those tangents are parallel).
fn flipped(mesh: &Mesh4, tri: [u32; 3], k: usize) -> bool {
    let p = tri.map(|v| mesh.positions[v as usize]);
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let v = tri[k] as usize;
    let (tu, tv) = (mesh.tangent_u[v], mesh.tangent_v[v]);
    let inner = e1.dot(tu) * e2.dot(tv) - e1.dot(tv) * e2.dot(tu);
    // |u ∧ v|^2 by Lagrange's identity: zero where the tangents are parallel.
    let frame = tu.length_squared() * tv.length_squared() - tu.dot(tv).powi(2);
    frame > 1e-12 * tu.length_squared() * tv.length_squared() && inner < 0.0
}

/// The uniform block `Turn` of `turn.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TurnUniform {
    rotation: [[f32; 4]; 4],
    shift: [f32; 4],
    centre: [f32; 4],
    counts: [u32; 4],
}

/// `SurfaceInfo` of `turn.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SurfaceInfo {
    halo: [u32; 4],
    params: [f32; 4],
}

/// The model on the GPU and the passes that turn it.
pub(crate) struct Turner {
    uniform: wgpu::Buffer,
    points: wgpu::Buffer,
    info: wgpu::Buffer,
    ring: wgpu::Buffer,
    triangles: wgpu::Buffer,
    surfaces: wgpu::Buffer,
    frames: wgpu::Buffer,
    /// Per surface: its halo's first vertex and its vertices.
    layout: Vec<[u32; 2]>,
    vertices: u32,
    triangle_count: u32,
    project: wgpu::ComputePipeline,
    shape: wgpu::ComputePipeline,
    faces: wgpu::ComputePipeline,
}

impl Turner {
    /// Uploads the model's static inputs and builds the passes.
    pub fn new(gpu: &super::Gpu, model: &Model) -> Result<Turner, ViewerError> {
        use wgpu::BufferUsages as U;
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let inputs = model.gpu_inputs();
        let points = gpu.buffer(
            "4D points",
            bytemuck::cast_slice(&inputs.points),
            U::STORAGE,
        )?;
        let info = gpu.buffer(
            "vertex rings",
            bytemuck::cast_slice(&inputs.info),
            U::STORAGE,
        )?;
        let ring = gpu.buffer(
            "ring triangles",
            bytemuck::cast_slice(&inputs.ring),
            U::STORAGE,
        )?;
        let triangles = gpu.buffer(
            "triangles (compute)",
            bytemuck::cast_slice(&inputs.triangles),
            U::STORAGE,
        )?;
        let frame_bytes = 32 * inputs.points.len() as u64;
        gpu.fits("projected tangents", frame_bytes, U::STORAGE)?;
        let frames = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("projected tangents"),
            size: frame_bytes.max(32),
            usage: U::STORAGE,
            mapped_at_creation: false,
        });
        let mut layout = Vec::new();
        let mut halo_base = 0u32;
        for (_, mesh) in &model.surfaces {
            let n = mesh.positions.len() as u32;
            layout.push([halo_base, n]);
            halo_base += 3 * n;
        }
        let surfaces = gpu.buffer(
            "surface halos",
            bytemuck::cast_slice(&vec![SurfaceInfo::zeroed(); layout.len()]),
            U::STORAGE,
        )?;
        let uniform = gpu.buffer(
            "turn",
            bytemuck::bytes_of(&TurnUniform::zeroed()),
            U::UNIFORM,
        )?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("turn.wgsl"),
            source: wgpu::ShaderSource::Wgsl(
                concat!(include_str!("vertices.wgsl"), include_str!("turn.wgsl")).into(),
            ),
        });
        let pipeline = |entry: &str| compute_pipeline(device, &module, entry);
        let (project, shape, faces) = (pipeline("project"), pipeline("shape"), pipeline("faces"));
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ViewerError::Gpu(e.to_string()));
        }
        Ok(Turner {
            uniform,
            points,
            info,
            ring,
            triangles,
            surfaces,
            frames,
            layout,
            vertices: inputs.points.len() as u32,
            triangle_count: (inputs.triangles.len() / 3) as u32,
            project,
            shape,
            faces,
        })
    }

    /// Writes the surfaces and halos of `view` (framed by `framing`, with the scene's halo
    /// parameters) into `vertices`, `halo_vertices` and `face_normals`, positions relative
    /// to the centre of the framing's box.
    pub fn run(
        &self,
        gpu: &super::Gpu,
        scene: &Scene,
        view: &View,
        framing: &Framing,
        (vertices, halo_vertices, face_normals): (&wgpu::Buffer, &wgpu::Buffer, &wgpu::Buffer),
    ) -> Result<(), ViewerError> {
        let centre = (framing.bounds.0 + framing.bounds.1) * 0.5;
        let eye = match view.projection {
            crate::view::Projection::Orthographic => 0.0,
            crate::view::Projection::Perspective { eye_distance } => eye_distance as f32,
        };
        let uniform = TurnUniform {
            rotation: view.rotation.matrix().as_mat4().to_cols_array_2d(),
            shift: DVec4::from_array(view.translation).as_vec4().to_array(),
            centre: [centre.x as f32, centre.y as f32, centre.z as f32, eye],
            counts: [self.vertices, self.triangle_count, 0, 0],
        };
        let halo = &scene.halo;
        let infos: Vec<SurfaceInfo> = self
            .layout
            .iter()
            .map(|&[base, n]| SurfaceInfo {
                halo: [base, n, 1, 0],
                params: [
                    framing.rho as f32,
                    halo.delta_t as f32,
                    halo.delta_d as f32,
                    0.0,
                ],
            })
            .collect();
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        gpu.queue
            .write_buffer(&self.surfaces, 0, bytemuck::cast_slice(&infos));
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let bind = |pipeline: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let passes = [
            (
                &self.project,
                bind(
                    &self.project,
                    &[
                        (0, &self.uniform),
                        (1, &self.points),
                        (6, vertices),
                        (9, &self.frames),
                    ],
                ),
                self.vertices,
            ),
            (
                &self.shape,
                bind(
                    &self.shape,
                    &[
                        (0, &self.uniform),
                        (2, &self.info),
                        (3, &self.ring),
                        (4, &self.triangles),
                        (5, &self.surfaces),
                        (6, vertices),
                        (7, halo_vertices),
                        (9, &self.frames),
                    ],
                ),
                self.vertices,
            ),
            (
                &self.faces,
                bind(
                    &self.faces,
                    &[
                        (0, &self.uniform),
                        (4, &self.triangles),
                        (6, vertices),
                        (8, face_normals),
                    ],
                ),
                self.triangle_count,
            ),
        ];
        let max = gpu.limits().max_compute_workgroups_per_dimension.max(1);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            // One dispatch after the other: wgpu orders a pass's dispatches that write and
            // read the same storage buffers.
            let mut pass = encoder.begin_compute_pass(&Default::default());
            for (pipeline, bind, items) in &passes {
                let groups = items.div_ceil(64);
                if groups > 0 {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, bind, &[]);
                    pass.dispatch_workgroups(groups.min(max), groups.div_ceil(max), 1);
                }
            }
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ViewerError::Gpu(e.to_string()));
        }
        Ok(())
    }
}
