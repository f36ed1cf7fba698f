//! Pipelines, targets and the passes of a frame.

use super::gpu::compute_pipeline;
use super::stipple::StippleSet;
use super::turn::Turner;
use super::{
    Asset, Frame, Gpu, GpuCamera, HaloMode, HaloVertex, Model, SurfaceVertex, ViewSettings,
    ViewerError, bounding_radius,
};
use crate::intersect::Curves;
use crate::limits::FieldError;
use crate::motion::Polyline;
use crate::render::{Picture, Style, shade};
use crate::view::View;
use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// The colour format of offscreen frames (linear colour written as sRGB, as the CPU
/// renderer's PNGs are).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DISTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const REVEAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
/// Width of the curves in pixels (the CPU renderer's default `line_width`).
const CURVE_WIDTH: f32 = 2.5;
/// The distance target's value where no surface is (read back as infinite).
const NO_DISTANCE: wgpu::Color = wgpu::Color {
    r: -1.0,
    g: 0.0,
    b: 0.0,
    a: 0.0,
};
/// Opacity of a surface face-on in transparent mode.
const OPACITY: f32 = 0.45;

/// The uniform block `View` of `viewer.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ViewUniform {
    clip: [[f32; 4]; 4],
    eye: [f32; 4],
    forward: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    background: [f32; 4],
    w_norm: [f32; 4],
    depth_norm: [f32; 4],
    grid_lo: [f32; 4],
    slabs: [f32; 4],
    grid_dims: [u32; 4],
    options: [u32; 4],
    band: [u32; 4],
    viewport: [f32; 4],
    depth_proj: [f32; 4],
    stipple: [f32; 4],
    stops: [[f32; 4]; 8],
    cuts: [[f32; 4]; 2],
}

/// What a frame cost, in milliseconds of wall time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// Building the halo-depth grid, when this frame built it.
    pub grid_ms: Option<f64>,
    /// Preparing the frame on the CPU (the view mode's slab lists).
    pub prepare_ms: f64,
    /// From the first command to the GPU finishing the frame.
    pub frame_ms: f64,
}

/// The halo-depth grid of one slice count.
struct Grid {
    slices: u32,
    /// Low corner (relative to the centre) and voxel size.
    lo: DVec3,
    voxel: f64,
    dims: [u32; 3],
    view: wgpu::TextureView,
}

/// Render targets of one size.
struct Targets {
    size: (u32, u32),
    /// The supersampled picture, when samples > 1 (in the colour format).
    samples_view: Option<wgpu::TextureView>,
    distance: wgpu::Texture,
    distance_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    halo_view: wgpu::TextureView,
    accum_view: wgpu::TextureView,
    reveal_view: wgpu::TextureView,
}

/// Draws an [`Asset`]: its buffers on the GPU and the pipelines that draw them.
pub struct Renderer {
    asset: Asset,
    colour_format: wgpu::TextureFormat,
    uniform: wgpu::Buffer,
    vertices: wgpu::Buffer,
    triangles: wgpu::Buffer,
    curve_points: wgpu::Buffer,
    curve_segments: wgpu::Buffer,
    halo_vertices: wgpu::Buffer,
    tets: wgpu::Buffer,
    edges: wgpu::Buffer,
    face_normals: wgpu::Buffer,
    /// The view mode's per-frame lists: triangle indices and (tetrahedron, slab) items.
    slab_triangles: Option<wgpu::Buffer>,
    slab_items: Option<wgpu::Buffer>,
    surface_grid: wgpu::RenderPipeline,
    surface_view: wgpu::RenderPipeline,
    surface_grid_blend: wgpu::RenderPipeline,
    surface_view_blend: wgpu::RenderPipeline,
    composite: wgpu::RenderPipeline,
    curves: wgpu::RenderPipeline,
    silhouettes: wgpu::RenderPipeline,
    slice_lines: wgpu::RenderPipeline,
    downsample: wgpu::RenderPipeline,
    cut: wgpu::RenderPipeline,
    voxelize: wgpu::ComputePipeline,
    empty_grid: wgpu::TextureView,
    grid: Option<Grid>,
    targets: Option<Targets>,
    /// The model's passes, when the renderer turns a model in 4D.
    turner: Option<Turner>,
    stipple_pipeline: wgpu::RenderPipeline,
    stipple_place: wgpu::ComputePipeline,
    /// The stipples, once given.
    stipples: Option<StippleBuffers>,
    /// A hyperplane's slice, once given: (points, segments, how many segments).
    slice: Option<(wgpu::Buffer, wgpu::Buffer, u32)>,
}

/// The stipples on the GPU: the set, and what one frame decides to draw of it.
struct StippleBuffers {
    /// Per stipple (triangle, rank, barycentric coordinates).
    instances: wgpu::Buffer,
    /// Per triangle, its surface's 4D area over its own.
    ratio: wgpu::Buffer,
    /// How many stipples there are.
    count: u32,
    /// The stipples a frame draws (clip position and colour, 32 bytes each), room for all.
    placed: wgpu::Buffer,
    /// Their indirect draw: three vertices per placed stipple.
    draw: wgpu::Buffer,
}

/// The asset's buffers on the GPU.
struct AssetBuffers {
    vertices: wgpu::Buffer,
    triangles: wgpu::Buffer,
    curve_points: wgpu::Buffer,
    curve_segments: wgpu::Buffer,
    halo_vertices: wgpu::Buffer,
    tets: wgpu::Buffer,
    edges: wgpu::Buffer,
    face_normals: wgpu::Buffer,
}

impl AssetBuffers {
    /// Uploads the asset's vertices, triangles, curves, halos, edges and face normals.
    fn upload(gpu: &Gpu, asset: &Asset) -> Result<AssetBuffers, ViewerError> {
        use wgpu::BufferUsages as U;
        let storage = U::STORAGE;
        let vertices = gpu.buffer(
            "surface vertices",
            bytemuck::cast_slice(&asset.vertices),
            storage | U::COPY_SRC,
        )?;
        let triangles = gpu.buffer(
            "surface triangles",
            bytemuck::cast_slice(&asset.triangles),
            U::INDEX | storage,
        )?;
        let curve_points = gpu.buffer(
            "curve points",
            bytemuck::cast_slice(&asset.curve_points),
            storage,
        )?;
        let curve_segments = gpu.buffer(
            "curve segments",
            bytemuck::cast_slice(&asset.curve_segments),
            storage,
        )?;
        let halo_vertices = gpu.buffer(
            "halo vertices",
            bytemuck::cast_slice(&asset.halo_vertices),
            storage | U::COPY_SRC,
        )?;
        let tets = gpu.buffer(
            "halo tetrahedra",
            bytemuck::cast_slice(&asset.tets),
            storage,
        )?;
        let edges = gpu.buffer("mesh edges", bytemuck::cast_slice(&asset.edges), storage)?;
        let face_normals = gpu.buffer(
            "face normals",
            bytemuck::cast_slice(&asset.face_normals),
            storage,
        )?;
        Ok(AssetBuffers {
            vertices,
            triangles,
            curve_points,
            curve_segments,
            halo_vertices,
            tets,
            edges,
            face_normals,
        })
    }
}

/// The renderer's pipelines, all from one shader module.
struct Pipelines {
    surface_grid: wgpu::RenderPipeline,
    surface_view: wgpu::RenderPipeline,
    surface_grid_blend: wgpu::RenderPipeline,
    surface_view_blend: wgpu::RenderPipeline,
    composite: wgpu::RenderPipeline,
    curves: wgpu::RenderPipeline,
    silhouettes: wgpu::RenderPipeline,
    slice_lines: wgpu::RenderPipeline,
    downsample: wgpu::RenderPipeline,
    cut: wgpu::RenderPipeline,
    voxelize: wgpu::ComputePipeline,
    stipple_pipeline: wgpu::RenderPipeline,
    stipple_place: wgpu::ComputePipeline,
}

impl Pipelines {
    /// Compiles the shaders and builds every pipeline, drawing into `colour_format`.
    fn new(device: &wgpu::Device, colour_format: wgpu::TextureFormat) -> Pipelines {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer.wgsl"),
            source: wgpu::ShaderSource::Wgsl(
                concat!(include_str!("vertices.wgsl"), include_str!("viewer.wgsl")).into(),
            ),
        });
        let opaque_targets = |distance: bool| opaque_targets(colour_format, distance);
        let blend_targets = blend_targets();
        let pipeline = |label: &str,
                        vs: &str,
                        fs: &str,
                        topology: wgpu::PrimitiveTopology,
                        targets: &[Option<wgpu::ColorTargetState>],
                        depth_stencil: Option<wgpu::DepthStencilState>| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology,
                    ..Default::default()
                },
                depth_stencil,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::CompareFunction as C;
        use wgpu::PrimitiveTopology as P;
        let surface_grid = pipeline(
            "surfaces (grid)",
            "surface_vs",
            "surface_grid_fs",
            P::TriangleList,
            &opaque_targets(true),
            depth(true, C::Less),
        );
        let surface_view = pipeline(
            "surfaces (view slices)",
            "surface_vs",
            "surface_view_fs",
            P::TriangleList,
            &opaque_targets(true),
            depth(true, C::Less),
        );
        let surface_grid_blend = pipeline(
            "transparent surfaces (grid)",
            "surface_vs",
            "surface_grid_blend_fs",
            P::TriangleList,
            &blend_targets,
            None,
        );
        let surface_view_blend = pipeline(
            "transparent surfaces (view slices)",
            "surface_vs",
            "surface_view_blend_fs",
            P::TriangleList,
            &blend_targets,
            None,
        );
        let composite = pipeline(
            "transparency composite",
            "composite_vs",
            "composite_fs",
            P::TriangleList,
            &opaque_targets(false),
            None,
        );
        let curves = pipeline(
            "curves",
            "curve_vs",
            "line_fs",
            P::TriangleList,
            &opaque_targets(false),
            None,
        );
        let downsample = pipeline(
            "downsample",
            "composite_vs",
            "downsample_fs",
            P::TriangleList,
            &opaque_targets(false)[..1],
            None,
        );
        let silhouettes = pipeline(
            "silhouettes",
            "silhouette_vs",
            "line_fs",
            P::TriangleList,
            &opaque_targets(false),
            None,
        );
        let slice_lines = pipeline(
            "slice",
            "slice_vs",
            "line_fs",
            P::TriangleList,
            &opaque_targets(false),
            None,
        );
        let stipple_pipeline = pipeline(
            "stipples",
            "stipple_vs",
            "stipple_fs",
            P::TriangleList,
            &opaque_targets(false)[..1],
            None,
        );
        let cut = cut_pipeline(device, &module);
        let voxelize = compute_pipeline(device, &module, "voxelize");
        let stipple_place = compute_pipeline(device, &module, "stipple_place");
        Pipelines {
            surface_grid,
            surface_view,
            surface_grid_blend,
            surface_view_blend,
            composite,
            curves,
            silhouettes,
            slice_lines,
            downsample,
            cut,
            voxelize,
            stipple_pipeline,
            stipple_place,
        }
    }
}

impl Renderer {
    /// Uploads `asset` and builds the pipelines, drawing into `colour_format`.
    pub fn new(
        gpu: &Gpu,
        asset: &Asset,
        colour_format: wgpu::TextureFormat,
    ) -> Result<Renderer, ViewerError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let AssetBuffers {
            vertices,
            triangles,
            curve_points,
            curve_segments,
            halo_vertices,
            tets,
            edges,
            face_normals,
        } = AssetBuffers::upload(gpu, asset)?;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("view"),
            contents: bytemuck::bytes_of(&ViewUniform::zeroed()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let Pipelines {
            surface_grid,
            surface_view,
            surface_grid_blend,
            surface_view_blend,
            composite,
            curves,
            silhouettes,
            slice_lines,
            downsample,
            cut,
            voxelize,
            stipple_pipeline,
            stipple_place,
        } = Pipelines::new(device, colour_format);
        let empty_grid = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("no grid"),
                size: wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::R32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ViewerError::Gpu(e.to_string()));
        }
        gpu.take_errors()?;
        Ok(Renderer {
            asset: asset.clone(),
            colour_format,
            uniform,
            vertices,
            triangles,
            curve_points,
            curve_segments,
            halo_vertices,
            tets,
            edges,
            face_normals,
            slab_triangles: None,
            slab_items: None,
            surface_grid,
            surface_view,
            surface_grid_blend,
            surface_view_blend,
            composite,
            curves,
            silhouettes,
            slice_lines,
            downsample,
            cut,
            voxelize,
            empty_grid,
            grid: None,
            targets: None,
            turner: None,
            stipple_pipeline,
            stipple_place,
            stipples: None,
            slice: None,
        })
    }

    /// Uploads the stipples the stipple style draws (made for this renderer's asset or
    /// model: [`Source::stipples`](super::Source::stipples)).
    pub fn set_stipples(&mut self, gpu: &Gpu, set: &StippleSet) -> Result<(), ViewerError> {
        if set.triangle_count() != self.asset.triangles.len() {
            return Err(ViewerError::View(format!(
                "stipples made for {} triangles, this scene has {}",
                set.triangle_count(),
                self.asset.triangles.len()
            )));
        }
        let instances = gpu.buffer(
            "stipples",
            bytemuck::cast_slice(&set.instances),
            wgpu::BufferUsages::STORAGE,
        )?;
        let ratio = gpu.buffer(
            "stipple area ratios",
            bytemuck::cast_slice(&set.area_ratio),
            wgpu::BufferUsages::STORAGE,
        )?;
        // Room for every stipple (one at least: a binding is never empty).
        let placed_size = 32 * set.len().max(1) as u64;
        gpu.fits("placed stipples", placed_size, wgpu::BufferUsages::STORAGE)?;
        let placed = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("placed stipples"),
            size: placed_size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let draw = gpu.buffer(
            "stipple draw",
            bytemuck::cast_slice(&[0u32, 1, 0, 0]),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
        )?;
        self.stipples = Some(StippleBuffers {
            instances,
            ratio,
            count: set.len() as u32,
            placed,
            draw,
        });
        Ok(())
    }

    /// Whether the stipples have been given ([`Renderer::set_stipples`]).
    pub fn has_stipples(&self) -> bool {
        self.stipples.is_some()
    }

    /// Uploads `model` and draws it in the 4D `view`.
    pub fn for_model(
        gpu: &Gpu,
        model: &Model,
        view: &View,
        colour_format: wgpu::TextureFormat,
    ) -> Result<Renderer, ViewerError> {
        let mut renderer = Renderer::new(gpu, &model.asset(), colour_format)?;
        renderer.turner = Some(Turner::new(gpu, model)?);
        renderer.turn(gpu, model, view)?;
        Ok(renderer)
    }

    /// Rebuilds the surfaces and halos of `model` (the one this renderer was made for) in
    /// the 4D `view` on the GPU and reads them back (the view mode's slab lists and the
    /// grid's voxelization read the positions); the curves and the slice are dropped until
    /// [`Renderer::set_curves`] and [`Renderer::set_slice`] give the view's. Milliseconds
    /// it took.
    pub fn turn(&mut self, gpu: &Gpu, model: &Model, view: &View) -> Result<f64, ViewerError> {
        let start = Instant::now();
        let turner = self
            .turner
            .as_ref()
            .ok_or_else(|| ViewerError::View("this asset has no 4D mesh to turn".into()))?;
        let framing = model.framing(view)?;
        turner.run(
            gpu,
            &model.scene,
            view,
            &framing,
            (&self.vertices, &self.halo_vertices, &self.face_normals),
        )?;
        let bytes = |n: usize, size: usize| (n * size) as u64;
        let back = gpu.read_buffers(&[
            (
                &self.vertices,
                bytes(self.asset.vertices.len(), size_of::<SurfaceVertex>()),
            ),
            (
                &self.halo_vertices,
                bytes(self.asset.halo_vertices.len(), size_of::<HaloVertex>()),
            ),
        ])?;
        self.asset.vertices = bytemuck::pod_collect_to_vec(&back[0]);
        self.asset.halo_vertices = bytemuck::pod_collect_to_vec(&back[1]);
        self.asset.bounds = framing.bounds;
        self.asset.fit_points = framing.points;
        self.asset.w_range = framing.w_range;
        self.asset.depth_range = framing.depth_range;
        self.asset.curve_points.clear();
        self.asset.curve_segments.clear();
        self.slice = None;
        self.grid = None;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }

    /// Draws `curves` (of the view the renderer was last turned to).
    pub fn set_curves(&mut self, gpu: &Gpu, curves: &Curves) -> Result<(), ViewerError> {
        let centre = self.asset.centre();
        self.asset.curve_points = curves
            .curves
            .iter()
            .flat_map(|c| &c.points)
            .map(|p| {
                let [x, y, z] = (p.position - centre).as_vec3().to_array();
                [x, y, z, p.w[0].min(p.w[1]) as f32]
            })
            .collect();
        self.asset.curve_segments = curves.segments();
        // Curves come once per settled view: new buffers of their size.
        self.curve_points = gpu.buffer(
            "curve points",
            bytemuck::cast_slice(&self.asset.curve_points),
            wgpu::BufferUsages::STORAGE,
        )?;
        self.curve_segments = gpu.buffer(
            "curve segments",
            bytemuck::cast_slice(&self.asset.curve_segments),
            wgpu::BufferUsages::STORAGE,
        )?;
        Ok(())
    }

    /// Draws `polylines` (a hyperplane's slice, [`super::Hyperplane::polylines`], in the
    /// view the renderer was last turned to) in the slice's colour, over the surfaces as
    /// the curves are; none for an empty list.
    pub fn set_slice(&mut self, gpu: &Gpu, polylines: &[Polyline]) -> Result<(), ViewerError> {
        let centre = self.asset.centre();
        let mut points: Vec<[f32; 4]> = Vec::new();
        let mut segments: Vec<[u32; 2]> = Vec::new();
        for (line, closed) in polylines {
            let base = points.len() as u32;
            let n = line.len() as u32;
            points.extend(line.iter().map(|p| {
                let [x, y, z] = (*p - centre).as_vec3().to_array();
                [x, y, z, 0.0]
            }));
            segments.extend((1..n).map(|k| [base + k - 1, base + k]));
            if *closed && n > 2 {
                segments.push([base + n - 1, base]);
            }
        }
        self.slice = if segments.is_empty() {
            None
        } else {
            let count = segments.len() as u32;
            Some((
                gpu.buffer(
                    "slice points",
                    bytemuck::cast_slice(&points),
                    wgpu::BufferUsages::STORAGE,
                )?,
                gpu.buffer(
                    "slice segments",
                    bytemuck::cast_slice(&segments),
                    wgpu::BufferUsages::STORAGE,
                )?,
                count,
            ))
        };
        Ok(())
    }

    /// The asset as drawn now (after the last turn).
    pub fn asset(&self) -> &Asset {
        &self.asset
    }

    /// Renders one frame into `target` (a view of a texture of `colour_format`, of the
    /// settings' size) and waits for the GPU to finish it.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        target: &wgpu::TextureView,
        settings: &ViewSettings,
    ) -> Result<FrameTimes, ViewerError> {
        settings.check()?;
        let stipple = settings.render.style == Style::Stipple;
        if stipple && self.stipples.is_none() {
            return Err(ViewerError::Setting(FieldError::new(
                "style",
                "stipple: no stipples given to the renderer yet (Renderer::set_stipples)",
            )));
        }
        let start = Instant::now();
        let mut times = FrameTimes::default();
        let halos = settings.render.halos && !self.asset.tets.is_empty();
        if halos
            && settings.mode == HaloMode::Grid
            && self
                .grid
                .as_ref()
                .is_none_or(|g| g.slices != settings.render.slices)
        {
            let t = Instant::now();
            // The old grid's memory goes before the new one is made.
            self.grid = None;
            self.grid = Some(self.build_grid(gpu, settings.render.slices)?);
            times.grid_ms = Some(t.elapsed().as_secs_f64() * 1e3);
        }
        let prepare = Instant::now();
        // Supersampling: the frame is drawn k times larger, then averaged k x k.
        let k = settings.render.samples.isqrt();
        let max = gpu.limits().max_texture_dimension_2d;
        if settings.render.width * k > max || settings.render.height * k > max {
            return Err(ViewerError::Setting(FieldError::new(
                "samples",
                format!(
                    "{}x{} at {} samples per pixel is larger than this GPU's {max}-pixel textures; use fewer samples or a smaller size",
                    settings.render.width, settings.render.height, settings.render.samples
                ),
            )));
        }
        let final_target = target;
        // Stipples lie on opaque white surfaces.
        let settings = &ViewSettings {
            render: crate::render::RenderSettings {
                width: settings.render.width * k,
                height: settings.render.height * k,
                ..settings.render
            },
            transparent: settings.transparent && !stipple,
            ..*settings
        };
        self.ensure_targets(gpu, (settings.render.width, settings.render.height), k > 1);
        let camera = GpuCamera::new(settings, &self.asset)?;
        let slabs = self.slabs(&camera, settings.render.slices);
        let uniform = self.uniform(&camera, settings, halos, slabs, self.grid.as_ref());
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let lists = (settings.mode == HaloMode::View)
            .then(|| self.slab_lists(gpu, &camera, (slabs, settings.render.slices), halos))
            .transpose()?;
        times.prepare_ms = prepare.elapsed().as_secs_f64() * 1e3;

        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let targets = self.targets.as_ref().expect("targets made above");
        let target = targets.samples_view.as_ref().unwrap_or(final_target);
        match &lists {
            None => self.surfaces_grid(gpu, &mut encoder, target, targets, settings),
            Some(lists) => self.surfaces_view(gpu, &mut encoder, target, targets, settings, lists),
        }
        if stipple {
            self.stipples_pass(gpu, &mut encoder, target, targets);
        }
        self.lines(gpu, &mut encoder, target, targets, settings);
        if let Some(samples) = &targets.samples_view {
            self.downsample(gpu, &mut encoder, final_target, samples);
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ViewerError::Gpu(e.to_string()));
        }
        gpu.finish()?;
        times.frame_ms = start.elapsed().as_secs_f64() * 1e3 - times.grid_ms.unwrap_or(0.0);
        Ok(times)
    }

    /// The surfaces, hidden by the halo-depth grid (or by nothing).
    fn surfaces_grid(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        targets: &Targets,
        settings: &ViewSettings,
    ) {
        let pipeline = if settings.transparent {
            &self.surface_grid_blend
        } else {
            &self.surface_grid
        };
        let grid = self.grid.as_ref().map_or(&self.empty_grid, |g| &g.view);
        let bind = self.bind(
            gpu,
            pipeline.get_bind_group_layout(0),
            &[
                (1, self.vertices.as_entire_binding()),
                (2, wgpu::BindingResource::TextureView(grid)),
            ],
        );
        let mut pass = if settings.transparent {
            blend_pass(encoder, targets, true)
        } else {
            opaque_pass(encoder, target, targets, true)
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.set_index_buffer(self.triangles.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.asset.triangles.len() as u32 * 3, 0, 0..1);
    }

    /// The surfaces slab by slab along the view, each slab's halos cut into the halo depth
    /// first.
    fn surfaces_view(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        targets: &Targets,
        settings: &ViewSettings,
        lists: &SlabLists,
    ) {
        let pipeline = if settings.transparent {
            &self.surface_view_blend
        } else {
            &self.surface_view
        };
        let surface_bind = self.bind(
            gpu,
            pipeline.get_bind_group_layout(0),
            &[
                (1, self.vertices.as_entire_binding()),
                (3, wgpu::BindingResource::TextureView(&targets.halo_view)),
            ],
        );
        let cut_bind = self.bind(
            gpu,
            self.cut.get_bind_group_layout(0),
            &[
                (5, self.halo_vertices.as_entire_binding()),
                (6, self.tets.as_entire_binding()),
                (
                    7,
                    self.slab_items
                        .as_ref()
                        .expect("slab lists made above")
                        .as_entire_binding(),
                ),
            ],
        );
        let indices = self.slab_triangles.as_ref().expect("slab lists made above");
        let mut first = true;
        for k in 0..settings.render.slices as usize {
            let tris = lists.triangles[k]..lists.triangles[k + 1];
            if tris.is_empty() && !first {
                continue;
            }
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("halo cut"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &targets.halo_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                let items = lists.items[k]..lists.items[k + 1];
                if !items.is_empty() {
                    pass.set_pipeline(&self.cut);
                    pass.set_bind_group(0, &cut_bind, &[]);
                    pass.draw(0..6, items);
                }
            }
            let mut pass = if settings.transparent {
                blend_pass(encoder, targets, first)
            } else {
                opaque_pass(encoder, target, targets, first)
            };
            first = false;
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &surface_bind, &[]);
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(tris, 0, k as u32..k as u32 + 1);
        }
    }

    /// The stipples, on the opaque surfaces drawn before: each decided once, on the GPU's
    /// compute units, then the drawn ones by an indirect draw.
    fn stipples_pass(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        targets: &Targets,
    ) {
        let Some(stipples) = &self.stipples else {
            return;
        };
        // No stipple placed yet; one instance of what will be.
        gpu.queue
            .write_buffer(&stipples.draw, 0, bytemuck::cast_slice(&[0u32, 1, 0, 0]));
        if stipples.count > 0 {
            let bind = self.bind(
                gpu,
                self.stipple_place.get_bind_group_layout(0),
                &[
                    (1, self.vertices.as_entire_binding()),
                    (13, self.face_normals.as_entire_binding()),
                    (14, wgpu::BindingResource::TextureView(&targets.depth_view)),
                    (16, stipples.instances.as_entire_binding()),
                    (17, self.triangles.as_entire_binding()),
                    (18, stipples.ratio.as_entire_binding()),
                    (19, stipples.placed.as_entire_binding()),
                    (20, stipples.draw.as_entire_binding()),
                ],
            );
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.stipple_place);
            pass.set_bind_group(0, &bind, &[]);
            let groups = stipples.count.div_ceil(64);
            let max = gpu.limits().max_compute_workgroups_per_dimension.max(1);
            pass.dispatch_workgroups(groups.min(max), groups.div_ceil(max), 1);
        }
        let bind = self.bind(
            gpu,
            self.stipple_pipeline.get_bind_group_layout(0),
            &[(21, stipples.placed.as_entire_binding())],
        );
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("stipples"),
            color_attachments: &[attachment(target, false, wgpu::Color::WHITE)],
            ..Default::default()
        });
        pass.set_pipeline(&self.stipple_pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw_indirect(&stipples.draw, 0);
    }

    /// The transparency composite, then the curves and silhouettes.
    fn lines(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        targets: &Targets,
        settings: &ViewSettings,
    ) {
        let composite = settings.transparent;
        let curves = settings.render.curves && !self.asset.curve_segments.is_empty();
        let silhouettes = settings.render.silhouettes && !self.asset.edges.is_empty();
        if composite || curves || silhouettes || self.slice.is_some() {
            let mut pass = lines_pass(encoder, target, targets, composite);
            let depth = wgpu::BindingResource::TextureView(&targets.depth_view);
            if composite {
                self.draw(
                    gpu,
                    &mut pass,
                    &self.composite,
                    &[
                        (9, wgpu::BindingResource::TextureView(&targets.accum_view)),
                        (10, wgpu::BindingResource::TextureView(&targets.reveal_view)),
                    ],
                    (0..3, 0..1),
                );
            }
            if curves {
                self.draw(
                    gpu,
                    &mut pass,
                    &self.curves,
                    &[
                        (4, self.curve_points.as_entire_binding()),
                        (11, self.curve_segments.as_entire_binding()),
                        (14, depth.clone()),
                    ],
                    (0..6, 0..self.asset.curve_segments.len() as u32),
                );
            }
            if let Some((points, segments, count)) = &self.slice {
                self.draw(
                    gpu,
                    &mut pass,
                    &self.slice_lines,
                    &[
                        (4, points.as_entire_binding()),
                        (11, segments.as_entire_binding()),
                        (14, depth.clone()),
                    ],
                    (0..6, 0..*count),
                );
            }
            if silhouettes {
                self.draw(
                    gpu,
                    &mut pass,
                    &self.silhouettes,
                    &[
                        (1, self.vertices.as_entire_binding()),
                        (12, self.edges.as_entire_binding()),
                        (13, self.face_normals.as_entire_binding()),
                        (14, depth),
                    ],
                    (0..6, 0..self.asset.edges.len() as u32),
                );
            }
        }
    }

    /// The supersampled picture averaged into `target`.
    fn downsample(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        samples: &wgpu::TextureView,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("downsample"),
            color_attachments: &[attachment(target, true, wgpu::Color::WHITE)],
            ..Default::default()
        });
        self.draw(
            gpu,
            &mut pass,
            &self.downsample,
            &[(15, wgpu::BindingResource::TextureView(samples))],
            (0..3, 0..1),
        );
    }

    /// Renders one frame offscreen and reads it back with its distances.
    pub fn read_frame(&mut self, gpu: &Gpu, settings: &ViewSettings) -> Result<Frame, ViewerError> {
        settings.check()?;
        let colour = frame_texture(
            gpu,
            "frame",
            (settings.render.width, settings.render.height),
            self.colour_format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let times = self.render(gpu, &colour.create_view(&Default::default()), settings)?;
        let texels = gpu.read_texture(&colour)?;
        let bgra = matches!(
            self.colour_format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let rgb = texels
            .iter()
            .flat_map(|c| {
                if bgra {
                    [c[2], c[1], c[0]]
                } else {
                    [c[0], c[1], c[2]]
                }
            })
            .collect();
        let targets = self.targets.as_ref().expect("targets made by render");
        let all = gpu.read_texture(&targets.distance)?;
        // Each pixel's distance from its centre sample (of k x k, the one at (k/2, k/2), as
        // the CPU renderer takes it).
        let k = settings.render.samples.isqrt() as usize;
        let (w, h) = (
            settings.render.width as usize,
            settings.render.height as usize,
        );
        let distance = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let d = f32::from_le_bytes(all[(y * k + k / 2) * w * k + x * k + k / 2]);
                if d >= 0.0 { d } else { f32::INFINITY }
            })
            .collect();
        Ok(Frame {
            picture: Picture {
                width: settings.render.width,
                height: settings.render.height,
                rgb,
            },
            distance,
            times,
        })
    }

    /// Draws `vertices` x `instances` with `pipeline` and a bind group of `entries`.
    fn draw(
        &self,
        gpu: &Gpu,
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        entries: &[(u32, wgpu::BindingResource)],
        (vertices, instances): (std::ops::Range<u32>, std::ops::Range<u32>),
    ) {
        let bind = self.bind(gpu, pipeline.get_bind_group_layout(0), entries);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(vertices, instances);
    }

    /// A bind group for `layout` with the view uniform at binding 0 and `entries`.
    fn bind(
        &self,
        gpu: &Gpu,
        layout: wgpu::BindGroupLayout,
        entries: &[(u32, wgpu::BindingResource)],
    ) -> wgpu::BindGroup {
        let mut all = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: self.uniform.as_entire_binding(),
        }];
        all.extend(
            entries
                .iter()
                .map(|(binding, resource)| wgpu::BindGroupEntry {
                    binding: *binding,
                    resource: resource.clone(),
                }),
        );
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &all,
        })
    }

    /// Render targets of `size`, made when the size changes.
    fn ensure_targets(&mut self, gpu: &Gpu, size: (u32, u32), supersampled: bool) {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| t.size == size && t.samples_view.is_some() == supersampled)
        {
            return;
        }
        let texture = |label, format, extra| {
            frame_texture(
                gpu,
                label,
                size,
                format,
                wgpu::TextureUsages::RENDER_ATTACHMENT | extra,
            )
        };
        use wgpu::TextureUsages as T;
        let distance = texture("distance", DISTANCE_FORMAT, T::COPY_SRC);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        self.targets = Some(Targets {
            size,
            samples_view: supersampled
                .then(|| view(&texture("samples", self.colour_format, T::TEXTURE_BINDING))),
            distance_view: view(&distance),
            distance,
            depth_view: view(&texture("depth", DEPTH_FORMAT, T::TEXTURE_BINDING)),
            halo_view: view(&texture("halo depth", DEPTH_FORMAT, T::TEXTURE_BINDING)),
            accum_view: view(&texture("accumulated", ACCUM_FORMAT, T::TEXTURE_BINDING)),
            reveal_view: view(&texture("revealage", REVEAL_FORMAT, T::TEXTURE_BINDING)),
        });
    }

    /// The planes of the view mode: the near side of the first slab and the slab thickness,
    /// spanning the bounding sphere as the CPU renderer's slice mode does.
    fn slabs(&self, camera: &GpuCamera, slices: u32) -> (f64, f64) {
        let radius = bounding_radius(self.asset.bounds);
        let centre_depth = (-camera.eye).dot(camera.cam.forward);
        (centre_depth - radius, 2.0 * radius / f64::from(slices))
    }

    /// The uniform block for a frame of `settings` through `camera`, with the view mode's
    /// slabs and the grid, if any.
    fn uniform(
        &self,
        camera: &GpuCamera,
        settings: &ViewSettings,
        halos: bool,
        (near, step): (f64, f64),
        grid: Option<&Grid>,
    ) -> ViewUniform {
        let cam = &camera.cam;
        let v4 = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        let (w0, w1) = self.asset.w_range;
        let span = if w1 > w0 { w1 - w0 } else { 1.0 };
        let (d0, d1) = self.asset.depth_range;
        let depth_scale = 1.0 / (d1 - d0).max(f64::MIN_POSITIVE) * 0.999;
        let stops = shade::stops(settings.render.colormap);
        let mut stop_array = [[0.0f32; 4]; 8];
        for (slot, s) in stop_array.iter_mut().zip(stops) {
            *slot = [s[0] as f32, s[1] as f32, s[2] as f32, 1.0];
        }
        let (grid_lo, grid_voxel, dims) =
            grid.map_or((DVec3::ZERO, 1.0, [0; 3]), |g| (g.lo, g.voxel, g.dims));
        // A ray through a slab crosses at most this much more than its thickness.
        let obliquity = match settings.camera.projection {
            crate::render::CameraProjection::Perspective => {
                (1.0 + cam.half_height.powi(2) * (1.0 + cam.aspect.powi(2))).sqrt()
            }
            crate::render::CameraProjection::Orthographic => 1.0,
        };
        // Lines test the surfaces' depth, which transparent frames do not write.
        let stipple = settings.render.style == Style::Stipple;
        let flags = u32::from(halos)
            | (u32::from(settings.colour_by_w) << 1)
            | (u32::from(!settings.transparent) << 2)
            | (u32::from(stipple) << 3);
        ViewUniform {
            clip: camera.clip.as_mat4().to_cols_array_2d(),
            eye: v4(
                camera.eye,
                f64::from(u8::from(
                    settings.camera.projection == crate::render::CameraProjection::Perspective,
                )),
            ),
            forward: v4(cam.forward, 0.0),
            right: v4(cam.right, 0.0),
            up: v4(cam.up, 0.0),
            background: [1.0, 1.0, 1.0, OPACITY],
            w_norm: [w0 as f32, (1.0 / span) as f32, 0.0, 0.0],
            depth_norm: [
                d0 as f32,
                depth_scale as f32,
                (grid_voxel * 3f64.sqrt() * 0.5) as f32,
                (step * 0.5 * obliquity) as f32,
            ],
            grid_lo: v4(grid_lo, grid_voxel),
            slabs: [
                near as f32,
                step as f32,
                settings.render.slices as f32,
                (step * f64::from(settings.render.slices)) as f32,
            ],
            grid_dims: [dims[0], dims[1], dims[2], dims[0].next_multiple_of(64)],
            options: [
                flags,
                stops.len() as u32,
                settings
                    .render
                    .clip
                    .map_or(0, |c| c.planes().count() as u32),
                settings.render.samples.isqrt(),
            ],
            band: [0; 4],
            depth_proj: {
                let (near, far) = (camera.near, camera.far);
                [near as f32, far as f32, 0.0, 0.0]
            },
            viewport: [
                settings.render.width as f32,
                settings.render.height as f32,
                CURVE_WIDTH * 0.5 * settings.render.samples.isqrt() as f32,
                (2.0 * cam.half_height / f64::from(settings.render.height)) as f32,
            ],
            // A stipple's size in pixels of the (supersampled) frame.
            stipple: [
                (settings.render.stipple.size * f64::from(settings.render.samples.isqrt())) as f32,
                f32::from(u8::from(settings.render.stipple.colour)),
                0.0,
                0.0,
            ],
            stops: stop_array,
            cuts: {
                // The planes for positions relative to the centre: n · (p + c) > d.
                let centre = self.asset.centre();
                let mut cuts = [[0.0f32; 4]; 2];
                for (slot, plane) in cuts
                    .iter_mut()
                    .zip(settings.render.clip.iter().flat_map(|c| c.planes()))
                {
                    let n = DVec3::from(plane.normal);
                    *slot = v4(n, plane.offset - n.dot(centre));
                }
                cuts
            },
        }
    }

    /// Builds the halo-depth grid: `slices` voxels across the halos' longest side, in bands
    /// of z layers as large as one storage binding holds.
    fn build_grid(&mut self, gpu: &Gpu, slices: u32) -> Result<Grid, ViewerError> {
        let (lo, voxel, dims) = grid_placement(&self.asset, slices);
        let row = dims[0].next_multiple_of(64);
        let layer_bytes = u64::from(row) * u64::from(dims[1]) * 4;
        let limits = gpu.limits();
        let binding = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let band = (binding / layer_bytes).min(u64::from(dims[2])) as u32;
        if band == 0 {
            return Err(ViewerError::TooLarge {
                what: format!("one layer of the halo-depth grid of {slices} slices (bytes)"),
                count: layer_bytes,
                limit: binding,
                why: "this GPU's max_storage_buffer_binding_size".into(),
            });
        }
        if dims[0] > limits.max_texture_dimension_3d
            || dims[1] > limits.max_texture_dimension_3d
            || dims[2] > limits.max_texture_dimension_3d
        {
            return Err(ViewerError::Setting(FieldError::new(
                "slices",
                format!(
                    "{slices} is more than this GPU's 3D textures hold ({}); use fewer",
                    limits.max_texture_dimension_3d
                ),
            )));
        }
        let (items, per_layer) = layer_items(&self.asset, lo, voxel, dims);
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let grid_buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("halo-depth grid band"),
            size: layer_bytes * u64::from(band),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("halo-depth grid"),
            size: wgpu::Extent3d {
                width: dims[0],
                height: dims[1],
                depth_or_array_layers: dims[2],
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R32Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let grid = Grid {
            slices,
            lo,
            voxel,
            dims,
            view: texture.create_view(&Default::default()),
        };
        // Voxelization reads only the grid's placement, the depth normalization and the band
        // from the uniform block; any camera will do for the rest.
        let camera = GpuCamera::new(&ViewSettings::default(), &self.asset)?;
        let mut uniform = self.uniform(
            &camera,
            &ViewSettings::default(),
            true,
            (0.0, 1.0),
            Some(&grid),
        );
        let mut item_buffer = None;
        for first in (0..dims[2]).step_by(band as usize) {
            let layers = band.min(dims[2] - first);
            let band_items =
                &items[per_layer[first as usize]..per_layer[(first + layers) as usize]];
            upload(
                gpu,
                &mut item_buffer,
                "voxelization items",
                bytemuck::cast_slice(band_items),
                wgpu::BufferUsages::STORAGE,
            )?;
            uniform.band = [band_items.len() as u32, first, 0, 0];
            gpu.queue
                .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
            let bind = self.bind(
                gpu,
                self.voxelize.get_bind_group_layout(0),
                &[
                    (5, self.halo_vertices.as_entire_binding()),
                    (6, self.tets.as_entire_binding()),
                    (
                        7,
                        item_buffer
                            .as_ref()
                            .expect("uploaded above")
                            .as_entire_binding(),
                    ),
                    (8, grid_buffer.as_entire_binding()),
                ],
            );
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            encoder.clear_buffer(&grid_buffer, 0, None);
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.voxelize);
                pass.set_bind_group(0, &bind, &[]);
                let groups = (band_items.len() as u32).div_ceil(64);
                let max = limits.max_compute_workgroups_per_dimension.max(1);
                if groups > 0 {
                    pass.dispatch_workgroups(groups.min(max), groups.div_ceil(max), 1);
                }
            }
            encoder.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer: &grid_buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row * 4),
                        rows_per_image: Some(dims[1]),
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: first,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: layers,
                },
            );
            gpu.queue.submit([encoder.finish()]);
            // One band at a time: the next band's uniform must wait for this one.
            gpu.finish()?;
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(ViewerError::Gpu(e.to_string()));
        }
        gpu.finish()?;
        Ok(grid)
    }

    /// The view mode's lists for this frame: triangles by the slabs they reach (indices,
    /// duplicated across slabs) and (tetrahedron, slab) for every slab plane a tetrahedron
    /// spans, both grouped by slab; uploaded, with each slab's ranges returned.
    fn slab_lists(
        &mut self,
        gpu: &Gpu,
        camera: &GpuCamera,
        ((near, step), slices): ((f64, f64), u32),
        halos: bool,
    ) -> Result<SlabLists, ViewerError> {
        let n = slices as usize;
        let forward = camera.cam.forward;
        let eye = camera.eye;
        let depth = |p: [f32; 3]| (DVec3::from(p.map(f64::from)) - eye).dot(forward);
        let slab_of = |z: f64| (((z - near) / step).floor().max(0.0) as usize).min(n - 1);
        let vertex_depth: Vec<f64> = self.asset.vertices.iter().map(|v| depth(v.pos)).collect();
        // Counting sorts into slabs.
        let mut tri_spans = Vec::with_capacity(self.asset.triangles.len());
        let mut tri_count = vec![0u32; n + 1];
        for t in &self.asset.triangles {
            let z = t.map(|v| vertex_depth[v as usize]);
            let (a, b) = (
                slab_of(z[0].min(z[1]).min(z[2])),
                slab_of(z[0].max(z[1]).max(z[2])),
            );
            for k in a..=b {
                tri_count[k + 1] += 1;
            }
            tri_spans.push((a, b));
        }
        let mut item_count = vec![0u32; n + 1];
        let mut tet_spans = Vec::new();
        if halos {
            let halo_depth: Vec<f64> = self
                .asset
                .halo_vertices
                .iter()
                .map(|v| depth(v.pos))
                .collect();
            for (i, k) in self.asset.tets.iter().enumerate() {
                let z = k.map(|v| halo_depth[v as usize]);
                let lo = z.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let first = ((lo - near) / step - 0.5).ceil().max(0.0);
                let last = ((hi - near) / step - 0.5).floor().min(n as f64 - 1.0);
                if first <= last {
                    for k in first as usize..=last as usize {
                        item_count[k + 1] += 1;
                    }
                    tet_spans.push((first as usize, last as usize, i as u32));
                }
            }
        }
        for k in 0..n {
            tri_count[k + 1] += tri_count[k];
            item_count[k + 1] += item_count[k];
        }
        let mut fill = tri_count.clone();
        let mut indices = vec![0u32; tri_count[n] as usize * 3];
        for (t, &(a, b)) in self.asset.triangles.iter().zip(&tri_spans) {
            for slot in &mut fill[a..=b] {
                let at = *slot as usize;
                indices[at * 3..at * 3 + 3].copy_from_slice(t);
                *slot += 1;
            }
        }
        let mut fill = item_count.clone();
        let mut items = vec![[0u32; 2]; item_count[n] as usize];
        for &(a, b, tet) in &tet_spans {
            for k in a..=b {
                items[fill[k] as usize] = [tet, k as u32];
                fill[k] += 1;
            }
        }
        upload(
            gpu,
            &mut self.slab_triangles,
            "slab triangles",
            bytemuck::cast_slice(&indices),
            wgpu::BufferUsages::INDEX,
        )?;
        upload(
            gpu,
            &mut self.slab_items,
            "slab cuts",
            bytemuck::cast_slice(&items),
            wgpu::BufferUsages::STORAGE,
        )?;
        Ok(SlabLists {
            triangles: tri_count.iter().map(|&c| c * 3).collect(),
            items: item_count,
        })
    }
}

/// A 2D texture of a frame's `size`.
pub(crate) fn frame_texture(
    gpu: &Gpu,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Per slab, where its triangle indices and its cut items start (one more entry than slabs).
struct SlabLists {
    triangles: Vec<u32>,
    items: Vec<u32>,
}

/// Writes `bytes` into `buffer`, replacing it with a larger one when they do not fit.
fn upload(
    gpu: &Gpu,
    buffer: &mut Option<wgpu::Buffer>,
    what: &str,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) -> Result<(), ViewerError> {
    let needed = (bytes.len() as u64).max(16);
    if buffer.as_ref().is_none_or(|b| b.size() < needed) {
        gpu.fits(what, needed, usage)?;
        *buffer = Some(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size: needed.next_power_of_two(),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
    }
    if !bytes.is_empty() {
        gpu.queue
            .write_buffer(buffer.as_ref().expect("made above"), 0, bytes);
    }
    Ok(())
}

/// A colour attachment of `view`, cleared to `colour` when `clear`, else loaded.
fn attachment(
    view: &wgpu::TextureView,
    clear: bool,
    colour: wgpu::Color,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: if clear {
                wgpu::LoadOp::Clear(colour)
            } else {
                wgpu::LoadOp::Load
            },
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A pass drawing the lines (after the transparency composite, which starts the frame when
/// `clear`) over the frame, reading the surfaces' depth.
fn lines_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    targets: &Targets,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("lines"),
        color_attachments: &[
            attachment(target, clear, wgpu::Color::WHITE),
            attachment(&targets.distance_view, clear, NO_DISTANCE),
        ],
        ..Default::default()
    })
}

/// A pass drawing opaque surfaces into the frame; `clear` starts the frame.
fn opaque_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    targets: &Targets,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("frame"),
        color_attachments: &[
            attachment(target, clear, wgpu::Color::WHITE),
            attachment(&targets.distance_view, clear, NO_DISTANCE),
        ],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &targets.depth_view,
            depth_ops: Some(wgpu::Operations {
                load: if clear {
                    wgpu::LoadOp::Clear(1.0)
                } else {
                    wgpu::LoadOp::Load
                },
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    })
}

/// A pass accumulating transparent surfaces; `clear` starts the frame.
fn blend_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    targets: &Targets,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("transparent surfaces"),
        color_attachments: &[
            attachment(&targets.accum_view, clear, wgpu::Color::TRANSPARENT),
            attachment(&targets.reveal_view, clear, wgpu::Color::WHITE),
        ],
        ..Default::default()
    })
}

/// The halo-depth grid of `slices` across the halos' box: its low corner, the voxel's side
/// and the voxels along each axis (at most `slices`).
fn grid_placement(asset: &Asset, slices: u32) -> (DVec3, f64, [u32; 3]) {
    let (lo, hi) = asset
        .halo_vertices
        .iter()
        .map(|v| DVec3::from(v.pos.map(f64::from)))
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let side = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let voxel = side / f64::from(slices);
    let dims = ((hi - lo) / voxel)
        .ceil()
        .max(DVec3::ONE)
        .as_uvec3()
        .min(glam::UVec3::splat(slices))
        .to_array();
    (lo, voxel, dims)
}

/// Work items (tetrahedron, z layer) for every layer of voxel centres a tetrahedron's box
/// spans, sorted by layer, and where each layer's items begin (one more entry than layers).
fn layer_items(
    asset: &Asset,
    lo: DVec3,
    voxel: f64,
    dims: [u32; 3],
) -> (Vec<[u32; 2]>, Vec<usize>) {
    // Work items (tetrahedron, z layer) for every layer of voxel centres a
    // tetrahedron's box spans, sorted by layer.
    let mut spans = Vec::with_capacity(asset.tets.len());
    let mut per_layer = vec![0usize; dims[2] as usize + 1];
    for (i, k) in asset.tets.iter().enumerate() {
        let z = k.map(|v| f64::from(asset.halo_vertices[v as usize].pos[2]));
        let z0 = z.iter().copied().fold(f64::INFINITY, f64::min);
        let z1 = z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let first = ((z0 - lo.z) / voxel - 0.5).ceil().max(0.0);
        let last = ((z1 - lo.z) / voxel - 0.5)
            .floor()
            .min(f64::from(dims[2]) - 1.0);
        if first <= last {
            for layer in first as usize..=last as usize {
                per_layer[layer + 1] += 1;
            }
            spans.push((i as u32, first as u32, last as u32));
        }
    }
    for layer in 0..dims[2] as usize {
        per_layer[layer + 1] += per_layer[layer];
    }
    let mut fill = per_layer.clone();
    let mut items = vec![[0u32; 2]; per_layer[dims[2] as usize]];
    for &(tet, first, last) in &spans {
        for layer in first..=last {
            items[fill[layer as usize]] = [tet, layer];
            fill[layer as usize] += 1;
        }
    }
    (items, per_layer)
}

/// The colour target, and the distance target written or not, of an opaque pass.
fn opaque_targets(
    colour_format: wgpu::TextureFormat,
    distance: bool,
) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(wgpu::ColorTargetState {
            format: colour_format,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        }),
        Some(wgpu::ColorTargetState {
            format: DISTANCE_FORMAT,
            blend: None,
            write_mask: if distance {
                wgpu::ColorWrites::ALL
            } else {
                wgpu::ColorWrites::empty()
            },
        }),
    ]
}

/// A depth buffer that is written or not, with its test.
fn depth(write: bool, compare: wgpu::CompareFunction) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    })
}

/// The transparent pass's targets: the weighted sum of colours and the revealage.
fn blend_targets() -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(wgpu::ColorTargetState {
            format: ACCUM_FORMAT,
            blend: Some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
            }),
            write_mask: wgpu::ColorWrites::ALL,
        }),
        Some(wgpu::ColorTargetState {
            format: REVEAL_FORMAT,
            blend: Some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Zero,
                    dst_factor: wgpu::BlendFactor::OneMinusSrc,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent::REPLACE,
            }),
            write_mask: wgpu::ColorWrites::ALL,
        }),
    ]
}

/// The pass that writes the halos' depth at a slab plane (`cut_vs`, `cut_fs`): depth only.
fn cut_pipeline(device: &wgpu::Device, module: &wgpu::ShaderModule) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("halo cuts"),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("cut_vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: depth(true, wgpu::CompareFunction::Less),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("cut_fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}
