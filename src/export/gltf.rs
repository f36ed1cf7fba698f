//! glTF 2.0 binary (`.glb`) export with gltf-json. Points and normals are in glTF's frame
//! (y up) and tetrahedra in VTK's orientation, both converted by [`crate::convention`].
//!
//! Per surface, two meshes, each with its own node:
//! - the surface, named after it, as TRIANGLES with POSITION (min/max computed from the f32
//!   values actually stored), unit NORMAL, float SCALAR custom attributes `_W` (w-depth),
//!   `_U`, `_V` (surface parameters) and `_PATCH` (patch index), and twelve more: the 4D mesh
//!   before the view (`_X4` … `_W4`, `_XU4` … `_WU4`, `_XV4` … `_WV4`:
//!   [`crate::convention::MESH_4D`]), from which `halo4d-view` turns the file in 4D;
//! - its halo, `<surface>-halo`: every halo vertex in the layout of [`crate::check`] with
//!   POSITION, unit NORMAL and float SCALAR attributes `_T`, `_D` (d_orig) and `_PATCH`, and
//!   as TRIANGLES only the halo's boundary faces (those of exactly one tetrahedron, turned
//!   outward), which is all a renderer shows; a top face names a collapsed corner by its
//!   positive offset, so that every offset vertex is on a triangle (importers drop the others).
//!   glTF has no tetrahedron primitive: the tetrahedra are an UNSIGNED_INT SCALAR accessor of
//!   4 indices each named `<surface>-halo tetrahedra`, in a buffer view without a target,
//!   numbered by the halo mesh's extras `{"halo": {"tetrahedra": accessor, "surface_vertices":
//!   n, "layers": 2, "rho", "delta_d", "delta_t", "split", "surface_mesh": mesh}}` in the
//!   layout of [`crate::check`] ([`crate::import`] reads them back).
//!
//! Then, when the scene has any, the intersection curves of all surfaces together in one mesh
//! `curves` with its own node: [`super::tubes`] of the given radius as TRIANGLES with POSITION,
//! NORMAL and float SCALAR attributes `_DW` (w of the far sheet minus w of the near sheet,
//! never negative), `_CURVE` (the curve's index) and `_W` (w of the near sheet), each vertex
//! those of its curve point. No glTF LINES: MeshLab crashes on them and Blender's renderers
//! skip the loose edges it makes of them. The exact polylines are accessors that no primitive
//! reads, named `curves polyline <key>`, numbered by the mesh's extras with the counts:
//! `{"curves": {"count", "closed", "open", "points", "radius", "polylines": {"POSITION",
//! "_W", "_DW", "_CURVE", "indices"}}}`; `indices` join consecutive points in pairs, and a
//! closed curve's last point back to its first.
//!
//! The file has two glTF scenes. The first, the file's `scene`, is the picture: every surface,
//! the curves, the stipples and, when the picture has one, its camera. The second, `halo4d
//! halos`, holds the halos' nodes alone. That is how the halos are in the file but hidden
//! where a reader shows the file's scene: Blender 4.5's own importer (`import_scene.gltf`)
//! makes a collection of each scene and excludes all but the default's from the view layer
//! (`io_scene_gltf2/blender/imp/scene.py`), three.js's GLTFLoader gives the default scene as
//! `gltf.scene`. `KHR_node_visibility` would say it on the nodes themselves, but Blender 4.5's
//! importer does not read it (the name occurs nowhere in its `io_scene_gltf2`), nor does
//! three.js's GLTFLoader (r187). halo4d's own readers take the meshes by their extras, in
//! whichever scene.
//!
//! Each surface has COLOR_0, the picture's colour of its w before shading (the scene's
//! `render.colormap` over the w of all the surfaces' triangle vertices, linear RGB as glTF
//! wants), and a white material, so that a viewer that multiplies the two (Blender's importer
//! puts a Color Attribute node into the material of a primitive with COLOR_0, three.js turns
//! on vertex colours) shows the picture's colours. The camera node is the picture's camera,
//! its first eye: a perspective (or orthographic) camera at the eye, looking at the picture's
//! centre (glTF's camera looks down its -z, +y up), with the picture's vertical field of view
//! and aspect ratio and near and far planes around the surfaces' box; its extras give the
//! picture's size and the point it looks at (glTF's frame), `{"picture": {"width", "height",
//! "target"}}`: Blender's importer sets no render size (it is the user's), and an orbiting
//! viewer turns about the target.
//!
//! Floats, because Blender 3.5+ imports float attributes and drops integer ones. Each
//! attribute has its own tightly packed, 4-byte aligned buffer view. The asset's extras
//! record the scene as parsed and the build's verdict: `{"halo4d": {"scene", "verified",
//! "failures"}}`.

use super::SurfaceData;
use super::tubes::{tubes, tubes_of};
use crate::check::LAYERS;
use crate::convention::{MESH_4D, file_order, to_gltf};
use crate::halo::Halo;
use crate::intersect::{CurvePoint, Curves};
use crate::motion::Polyline;
use crate::render::diagram::PALETTE as STILLS;
use crate::render::shade::colormap;
use crate::render::stipple::Drawn;
use crate::render::visible::PictureCamera;
use crate::render::{CameraProjection, Colormap};
use crate::view::area_normal_sums;
use glam::{DMat3, DQuat, DVec3, Vec3};
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use rayon::prelude::*;
use serde_json::value::{RawValue, to_raw_value};
use std::io::{self, Write};

/// Base colours of the halos' translucent materials, in turn (a surface's material is white:
/// its colours are its COLOR_0).
const PALETTE: [[f32; 4]; 6] = [
    [0.85, 0.62, 0.25, 1.0],
    [0.30, 0.55, 0.85, 1.0],
    [0.45, 0.75, 0.40, 1.0],
    [0.80, 0.35, 0.45, 1.0],
    [0.60, 0.45, 0.80, 1.0],
    [0.85, 0.85, 0.85, 1.0],
];

/// Base colour of the curves' tubes: the renderer's ink.
const CURVE_COLOUR: [f32; 4] = [0.02, 0.02, 0.02, 1.0];

/// The name of the file's second glTF scene, which holds the halos' nodes.
pub const HALO_SCENE: &str = "halo4d halos";

/// How the scene's picture shows it, which the `.glb` carries for programs that know nothing
/// of halo4d's attributes: the surfaces' colours of w and the picture's camera.
#[derive(Clone, Copy, Debug, Default)]
pub struct Figure {
    /// The picture's camera (its first eye), written as a camera node; none when the scene
    /// has none (no triangle to frame, or an orthographic eye inside the box).
    pub camera: Option<PictureCamera>,
    /// The picture's colour map, which gives each surface vertex its COLOR_0.
    pub colormap: Colormap,
}

/// Accumulates the binary chunk and the JSON objects that describe it.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// An empty document whose asset names halo4d and carries `asset` in its extras as
    /// `halo4d`.
    fn new(asset: &serde_json::Value) -> Result<Builder, String> {
        Ok(Builder {
            root: json::Root {
                asset: json::Asset {
                    generator: Some(format!("halo4d {}", env!("CARGO_PKG_VERSION"))),
                    extras: raw_extras(serde_json::json!({ "halo4d": asset }))?,
                    ..Default::default()
                },
                ..Default::default()
            },
            bin: Vec::new(),
        })
    }

    /// The document with its `scenes` (name, nodes), the first the file's `scene` and any
    /// without nodes left out, and its one buffer: the JSON and the binary chunk.
    fn finish(
        mut self,
        scenes: Vec<(&str, Vec<json::Index<json::Node>>)>,
    ) -> Result<(Vec<u8>, Vec<u8>), String> {
        for (k, (name, nodes)) in scenes.into_iter().enumerate() {
            if k > 0 && nodes.is_empty() {
                continue;
            }
            let scene = self.root.push(json::Scene {
                extensions: None,
                extras: None,
                name: Some(name.into()),
                nodes,
            });
            if k == 0 {
                self.root.scene = Some(scene);
            }
        }
        self.root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        let text = self.root.to_vec().map_err(|e| e.to_string())?;
        Ok((text, self.bin))
    }

    /// Appends a buffer view of 4-byte `words` (written little-endian, as glTF's binary
    /// chunk is), copied straight into the binary chunk; `target` is `None` for data that no
    /// primitive reads (the tetrahedra).
    fn view<W: bytemuck::Pod>(
        &mut self,
        words: &[W],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        const { assert!(size_of::<W>() == 4) };
        debug_assert_eq!(self.bin.len() % 4, 0);
        let offset = self.bin.len();
        let bytes: &[u8] = bytemuck::cast_slice(words);
        if cfg!(target_endian = "little") {
            self.bin.extend_from_slice(bytes);
        } else {
            self.bin.reserve(bytes.len());
            for w in bytes.chunks_exact(4) {
                self.bin.extend(w.iter().rev());
            }
        }
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(self.bin.len() - offset),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: None,
        })
    }

    /// Appends an f32 accessor of `type_` (SCALAR or VEC3) over `values`.
    fn floats(
        &mut self,
        values: &[f32],
        type_: json::accessor::Type,
        minmax: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let components = if type_ == json::accessor::Type::Vec3 {
            3
        } else {
            1
        };
        let view = self.view(values, Some(json::buffer::Target::ArrayBuffer));
        let (min, max) = match minmax {
            Some((lo, hi)) => (Some(serde_json::json!(lo)), Some(serde_json::json!(hi))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(values.len() / components),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: None,
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// Appends a tightly packed f32 VEC3 POSITION accessor of `points` in glTF's frame, with
    /// min/max of the stored values.
    fn positions(&mut self, points: &[DVec3]) -> json::Index<json::Accessor> {
        let positions: Vec<f32> = points
            .iter()
            .flat_map(|&v| to_gltf(v).as_vec3().to_array())
            .collect();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for c in positions.chunks_exact(3) {
            for i in 0..3 {
                lo[i] = lo[i].min(c[i]);
                hi[i] = hi[i].max(c[i]);
            }
        }
        self.floats(
            &positions,
            json::accessor::Type::Vec3,
            Some((lo.to_vec(), hi.to_vec())),
        )
    }

    /// Appends an f32 VEC3 NORMAL accessor of `normals` in glTF's frame, made unit (a zero
    /// vector becomes up: glTF wants unit normals, and only a vertex that no triangle uses
    /// has none).
    fn normals(&mut self, normals: &[DVec3]) -> json::Index<json::Accessor> {
        let unit: Vec<f32> = normals
            .iter()
            .flat_map(|&n| {
                let n = to_gltf(n).normalize_or(DVec3::Y).as_vec3();
                n.normalize_or(Vec3::Y).to_array()
            })
            .collect();
        self.floats(&unit, json::accessor::Type::Vec3, None)
    }

    /// Appends an UNSIGNED_INT SCALAR accessor over `indices`, with `target` as in [`Self::view`].
    fn indices(
        &mut self,
        indices: &[u32],
        target: Option<json::buffer::Target>,
        name: Option<String>,
    ) -> json::Index<json::Accessor> {
        let view = self.view(indices, target);
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(indices.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: None,
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name,
            normalized: false,
            sparse: None,
        })
    }
}

/// The faces of exactly one tetrahedron ([`crate::check::boundary_faces`]), each turned
/// outward (counter-clockwise seen from outside, glTF's front face) by the exact orientation
/// of its tetrahedron, in a deterministic order.
fn boundary_faces(positions: &[DVec3], tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let c = |i: u32| {
        let p = positions[i as usize];
        robust::Coord3D {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    };
    crate::check::boundary_faces(tets, positions.len())
        .into_par_iter()
        .map(|([a, b, c3], o)| {
            // `orient3d` is negative where the fourth vertex lies above the face as given
            // (counter-clockwise seen from the fourth vertex): inward, so turned over.
            if robust::orient3d(c(a), c(b), c(c3), c(o)) < 0.0 {
                [a, c3, b]
            } else {
                [a, b, c3]
            }
        })
        .collect()
}

/// The halo's boundary faces as [`boundary_faces`] finds them, except that a top face (one
/// whose other corners are positive offsets) names a collapsed corner by its positive
/// offset: both indices of a collapsed vertex are then used by some triangle, so that
/// importers that drop unused vertices (Blender) keep every offset vertex at its index.
fn halo_faces(halo: &Halo) -> Vec<[u32; 3]> {
    let n = halo.surface_vertices as u32;
    let positive = |v: u32| (n..2 * n).contains(&v);
    let collapsed =
        |v: u32| v < n && halo.positions[v as usize] == halo.positions[(v + n) as usize];
    let mut faces = boundary_faces(&halo.positions, &halo.tets);
    for f in &mut faces {
        if f.iter().any(|&v| positive(v)) && f.iter().all(|&v| positive(v) || collapsed(v)) {
            *f = f.map(|v| if collapsed(v) { v + n } else { v });
        }
    }
    faces
}

/// The patch of each halo vertex: that of its surface vertex for the offsets and the surface,
/// that of the triangle whose prism it is in for an inserted vertex.
fn halo_patches(s: &SurfaceData) -> Vec<f32> {
    let halo: &Halo = s.halo;
    let n = halo.surface_vertices;
    (0..halo.positions.len())
        .map(|i| {
            if i < 3 * n {
                s.mesh.patch[i % n] as f32
            } else {
                s.mesh.triangle_patch[halo.inserted_in[i - 3 * n] as usize] as f32
            }
        })
        .collect()
}

/// Builds the `.glb` bytes for the surfaces, their halos and the scene's intersection
/// `curves`, as tubes of `curve_radius` (absolute); `asset` goes into the asset's extras
/// as `halo4d` (the build writes the scene as parsed and its verdict there). A halo without
/// tetrahedra, and curves without a segment, get no mesh (glTF accessors cannot be empty).
pub fn to_glb(
    surfaces: &[SurfaceData],
    curves: &Curves,
    curve_radius: f64,
    asset: &serde_json::Value,
) -> Result<Vec<u8>, String> {
    let (text, bin) = glb_chunks(
        surfaces,
        curves,
        curve_radius,
        &[],
        &Figure::default(),
        asset,
    )?;
    Ok(glb_container(text, bin))
}

/// The JSON and binary chunks of [`to_glb`]'s file, with the `stipples` of the scene's
/// picture as a point cloud when there are any and the `figure`'s colours and camera, for
/// [`write_glb_container`] to write without a copy of the whole file in memory.
pub fn glb_chunks(
    surfaces: &[SurfaceData],
    curves: &Curves,
    curve_radius: f64,
    stipples: &[Drawn],
    figure: &Figure,
    asset: &serde_json::Value,
) -> Result<(Vec<u8>, Vec<u8>), String> {
    let mut b = Builder::new(asset)?;
    let mut nodes = Vec::new();
    let mut halo_nodes = Vec::new();
    let scale = w_scale(surfaces);
    for (k, s) in surfaces.iter().enumerate() {
        let colours: Vec<f32> = s
            .projected
            .w
            .iter()
            .flat_map(|&w| w_colour(figure.colormap, scale, w))
            .collect();
        let mesh = surface_mesh(&mut b, s, &colours)?;
        nodes.push(b.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(s.name.to_string()),
            ..Default::default()
        }));
        if !s.halo.tets.is_empty() {
            let halo_mesh = halo_mesh(&mut b, s, mesh, PALETTE[k % PALETTE.len()])?;
            halo_nodes.push(b.root.push(json::Node {
                mesh: Some(halo_mesh),
                name: Some(format!("{}-halo", s.name)),
                ..Default::default()
            }));
        }
    }
    if let Some(mesh) = curves_mesh(&mut b, curves, curve_radius)? {
        nodes.push(b.root.push(json::Node {
            mesh: Some(mesh),
            name: Some("curves".into()),
            ..Default::default()
        }));
    }
    if !stipples.is_empty() {
        let mesh = stipples_mesh(&mut b, stipples)?;
        nodes.push(b.root.push(json::Node {
            mesh: Some(mesh),
            name: Some("stipples".into()),
            ..Default::default()
        }));
    }
    if let Some(camera) = &figure.camera {
        nodes.push(camera_node(&mut b, camera, surfaces)?);
    }
    b.finish(vec![("halo4d", nodes), (HALO_SCENE, halo_nodes)])
}

/// The picture's scale of w: the least and greatest w of the surfaces' triangle vertices, as
/// the renderer takes it.
fn w_scale(surfaces: &[SurfaceData]) -> (f64, f64) {
    surfaces
        .iter()
        .flat_map(|s| {
            let w = &s.projected.w;
            s.mesh
                .triangles
                .iter()
                .flatten()
                .map(move |&v| w[v as usize])
        })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| {
            (a.min(w), b.max(w))
        })
}

/// The picture's colour of `w` before shading, linear RGB: the renderer's share of the scale
/// `(w0, w1)` through `map` (a scale of one w, or none, gives every w the same colour).
pub fn w_colour(map: Colormap, (w0, w1): (f64, f64), w: f64) -> [f32; 3] {
    let span = if w1 > w0 { w1 - w0 } else { 1.0 };
    colormap(map, (w - w0) / span).as_vec3().to_array()
}

/// Appends the picture's camera as a camera (perspective or orthographic, with the picture's
/// aspect ratio) and its node in glTF's frame, with near and far planes around the box of the
/// `surfaces`' vertices.
fn camera_node(
    b: &mut Builder,
    c: &PictureCamera,
    surfaces: &[SurfaceData],
) -> Result<json::Index<json::Node>, String> {
    let bad = || format!("the picture's camera cannot be written: {c:?}");
    let (eye, target, up) = (DVec3::from(c.eye), DVec3::from(c.target), DVec3::from(c.up));
    let forward = (target - eye).try_normalize().ok_or_else(bad)?;
    let right = forward.cross(up).try_normalize().ok_or_else(bad)?;
    let up = right.cross(forward);
    // glTF's camera looks down its -z with +y up and +x right.
    let axes = DMat3::from_cols(to_gltf(right), to_gltf(up), to_gltf(-forward));
    let rotation = DQuat::from_mat3(&axes).normalize().as_quat().to_array();
    let translation = to_gltf(eye).as_vec3().to_array();
    // Near and far: the depths of the box's corners along the view, with room on either
    // side; the near plane in front of the eye whatever the box.
    let (lo, hi) = surfaces
        .iter()
        .flat_map(|s| &s.projected.positions)
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let diagonal = (hi - lo).length();
    let depths = (0..8).map(|k| {
        let corner = DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        (corner - eye).dot(forward)
    });
    let (nearest, farthest) = depths.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, z), d| {
        (a.min(d), z.max(d))
    });
    let znear = (0.5 * nearest).max(1e-3 * diagonal);
    let zfar = (1.5 * farthest).max(2.0 * znear);
    let aspect = f64::from(c.width) / f64::from(c.height);
    let (perspective, orthographic, type_) = match (c.projection, c.fov_deg, c.half_height) {
        (CameraProjection::Perspective, Some(fov), _) => (
            Some(json::camera::Perspective {
                aspect_ratio: Some(aspect as f32),
                yfov: fov.to_radians() as f32,
                zfar: Some(zfar as f32),
                znear: znear as f32,
                extensions: None,
                extras: None,
            }),
            None,
            json::camera::Type::Perspective,
        ),
        (CameraProjection::Orthographic, _, Some(half)) => (
            None,
            Some(json::camera::Orthographic {
                xmag: (half * aspect) as f32,
                ymag: half as f32,
                zfar: zfar as f32,
                znear: znear as f32,
                extensions: None,
                extras: None,
            }),
            json::camera::Type::Orthographic,
        ),
        _ => return Err(bad()),
    };
    let numbers = [znear, zfar, aspect, c.fov_deg.unwrap_or(1.0)];
    let finite = numbers.iter().all(|x| x.is_finite())
        && rotation.iter().chain(&translation).all(|x| x.is_finite());
    if !finite || znear <= 0.0 || zfar <= znear {
        return Err(bad());
    }
    let camera = b.root.push(json::Camera {
        name: Some("camera".into()),
        orthographic,
        perspective,
        type_: Valid(type_),
        extensions: None,
        extras: raw_extras(serde_json::json!({
            "picture": {
                "width": c.width,
                "height": c.height,
                "target": to_gltf(target).as_vec3().to_array(),
            }
        }))?,
    });
    Ok(b.root.push(json::Node {
        camera: Some(camera),
        name: Some("camera".into()),
        rotation: Some(json::scene::UnitQuaternion(rotation)),
        translation: Some(translation),
        ..Default::default()
    }))
}

/// A motion picture's stills as a `.glb`: one node per still, named `still-NN` with its
/// level in its extras, each curve of it a tube of `radius` (its own material, in the
/// colours of the stills' pictures, [`STILLS`]); the vertices in the hyperplane's frame (as glTF's y up), each
/// node moved by `offset(k)` (glTF's frame) so that the stills lie side by side. A still
/// without curves gets an empty node.
pub fn stills_glb(
    stills: &[(f64, Vec<Polyline>)],
    radius: f64,
    offset: impl Fn(usize) -> DVec3,
    asset: &serde_json::Value,
) -> Result<Vec<u8>, String> {
    let mut b = Builder::new(asset)?;
    // Each colour's material, made when a curve first takes it (the validator counts an
    // unused one).
    let mut materials: Vec<Option<json::Index<json::Material>>> = vec![None; STILLS.len()];
    let mut nodes = Vec::new();
    for (k, (level, curves)) in stills.iter().enumerate() {
        let mut primitives = Vec::new();
        for (c, curve) in curves.iter().enumerate() {
            let tube = tubes_of(std::slice::from_ref(curve), radius);
            if tube.triangles.is_empty() {
                continue;
            }
            let positions = b.positions(&tube.positions);
            let normals = b.normals(&tube.normals);
            let triangles: Vec<u32> = tube.triangles.iter().flatten().copied().collect();
            let indices = b.indices(
                &triangles,
                Some(json::buffer::Target::ElementArrayBuffer),
                None,
            );
            primitives.push(json::mesh::Primitive {
                attributes: [
                    (Valid(json::mesh::Semantic::Positions), positions),
                    (Valid(json::mesh::Semantic::Normals), normals),
                ]
                .into_iter()
                .collect(),
                extensions: None,
                extras: None,
                indices: Some(indices),
                material: Some(material(&mut b, &mut materials, c % STILLS.len())),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            });
        }
        let mesh = (!primitives.is_empty()).then(|| {
            b.root.push(json::Mesh {
                extensions: None,
                extras: None,
                name: Some(format!("still-{k:02}")),
                primitives,
                weights: None,
            })
        });
        let translation = offset(k).as_vec3().to_array();
        nodes.push(b.root.push(json::Node {
            mesh,
            name: Some(format!("still-{k:02}")),
            translation: Some(translation),
            extras: raw_extras(serde_json::json!({ "level": level, "curves": curves.len() }))?,
            ..Default::default()
        }));
    }
    let (text, bin) = b.finish(vec![("motion picture", nodes)])?;
    Ok(glb_container(text, bin))
}

/// The material of palette colour `k` for [`stills_glb`], made on first use.
fn material(
    b: &mut Builder,
    made: &mut [Option<json::Index<json::Material>>],
    k: usize,
) -> json::Index<json::Material> {
    *made[k].get_or_insert_with(|| {
        b.root.push(json::Material {
            name: Some(format!("curve {k}")),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor({
                    let [r, g, b] = STILLS[k].map(|c| c as f32);
                    [r, g, b, 1.0]
                }),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        })
    })
}

/// Appends the mesh of surface `s`: its projected positions and normals, its `colours`
/// (COLOR_0, RGB per vertex), W, U, V and PATCH, the 4D mesh before the view, its triangles,
/// and a white material (which COLOR_0 colours).
fn surface_mesh(
    b: &mut Builder,
    s: &SurfaceData,
    colours: &[f32],
) -> Result<json::Index<json::Mesh>, String> {
    let p = s.projected;
    let scalar = |f: &dyn Fn(usize) -> f64| {
        (0..p.positions.len())
            .map(|i| f(i) as f32)
            .collect::<Vec<f32>>()
    };
    use json::accessor::Type::Scalar;
    use json::mesh::Semantic;
    let mut attributes = vec![
        (Semantic::Positions, b.positions(&p.positions)),
        (Semantic::Normals, b.normals(&p.normals)),
        (
            Semantic::Colors(0),
            b.floats(colours, json::accessor::Type::Vec3, None),
        ),
        (
            Semantic::Extras("W".into()),
            b.floats(&scalar(&|i| p.w[i]), Scalar, None),
        ),
        (
            Semantic::Extras("U".into()),
            b.floats(&scalar(&|i| s.mesh.uv[i][0]), Scalar, None),
        ),
        (
            Semantic::Extras("V".into()),
            b.floats(&scalar(&|i| s.mesh.uv[i][1]), Scalar, None),
        ),
        (
            Semantic::Extras("PATCH".into()),
            b.floats(&scalar(&|i| f64::from(s.mesh.patch[i])), Scalar, None),
        ),
    ];
    // The 4D mesh before the view, a SCALAR per coordinate (see `crate::convention`).
    let columns = [&s.mesh.positions, &s.mesh.tangent_u, &s.mesh.tangent_v];
    for (column, names) in columns.iter().zip(MESH_4D) {
        for (c, name) in names.iter().enumerate() {
            let values: Vec<f32> = column.iter().map(|p| p[c] as f32).collect();
            attributes.push((
                Semantic::Extras((*name).into()),
                b.floats(&values, Scalar, None),
            ));
        }
    }
    let triangles: Vec<u32> = s.mesh.triangles.iter().flatten().copied().collect();
    let index_accessor = b.indices(
        &triangles,
        Some(json::buffer::Target::ElementArrayBuffer),
        None,
    );
    let material = b.root.push(json::Material {
        name: Some(s.name.to_string()),
        double_sided: true,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([1.0; 4]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.6),
            ..Default::default()
        },
        ..Default::default()
    });
    let mesh = b.root.push(json::Mesh {
        name: Some(s.name.to_string()),
        extras: raw_extras(serde_json::json!({
            "surface": s.surface_type,
            "patches": s.patches,
            "w_range": p.w_range(),
        }))?,
        extensions: None,
        primitives: vec![json::mesh::Primitive {
            attributes: attributes.into_iter().map(|(k, v)| (Valid(k), v)).collect(),
            extensions: None,
            extras: None,
            indices: Some(index_accessor),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    });
    Ok(mesh)
}

/// A JSON value as glTF extras.
fn raw_extras(v: serde_json::Value) -> Result<Option<Box<RawValue>>, String> {
    to_raw_value(&v).map(Some).map_err(|e| e.to_string())
}

/// Appends the stipples as a mesh of POINTS: positions, `_RADIUS` (each disc's radius in
/// scene units, which Blender's importer gives a point cloud as its radius) and `_W` (the
/// w-depth), in black.
fn stipples_mesh(b: &mut Builder, stipples: &[Drawn]) -> Result<json::Index<json::Mesh>, String> {
    use json::accessor::Type::Scalar;
    use json::mesh::Semantic;
    let positions: Vec<DVec3> = stipples.iter().map(|d| d.position).collect();
    let column =
        |f: &dyn Fn(&Drawn) -> f64| stipples.iter().map(|d| f(d) as f32).collect::<Vec<f32>>();
    let attributes = [
        (Semantic::Positions, b.positions(&positions)),
        (
            Semantic::Extras("RADIUS".into()),
            b.floats(&column(&|d| d.radius), Scalar, None),
        ),
        (
            Semantic::Extras("W".into()),
            b.floats(&column(&|d| d.w), Scalar, None),
        ),
    ];
    let material = b.root.push(json::Material {
        name: Some("stipples".into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([0.02, 0.02, 0.02, 1.0]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    });
    let extras = serde_json::json!({ "stipples": { "count": stipples.len() } });
    Ok(b.root.push(json::Mesh {
        name: Some("stipples".into()),
        extras: Some(to_raw_value(&extras).map_err(|e| e.to_string())?),
        extensions: None,
        primitives: vec![json::mesh::Primitive {
            attributes: attributes.into_iter().map(|(k, v)| (Valid(k), v)).collect(),
            extensions: None,
            extras: None,
            indices: None,
            material: Some(material),
            mode: Valid(json::mesh::Mode::Points),
            targets: None,
        }],
        weights: None,
    }))
}

/// Appends the halo mesh of `s` (see the module documentation); `surface_mesh` is the
/// surface's own mesh and `colour` its base colour.
fn halo_mesh(
    b: &mut Builder,
    s: &SurfaceData,
    surface_mesh: json::Index<json::Mesh>,
    colour: [f32; 4],
) -> Result<json::Index<json::Mesh>, String> {
    use json::accessor::Type::Scalar;
    use json::mesh::Semantic;
    let halo = s.halo;
    let name = format!("{}-halo", s.name);
    let scalar = |values: &[f64]| values.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let faces = halo_faces(halo);
    let normals = area_normal_sums(&halo.positions, &faces);
    let attributes = [
        (Semantic::Positions, b.positions(&halo.positions)),
        (Semantic::Normals, b.normals(&normals)),
        (
            Semantic::Extras("T".into()),
            b.floats(&scalar(&halo.t), Scalar, None),
        ),
        (
            Semantic::Extras("D".into()),
            b.floats(&scalar(&halo.d_orig), Scalar, None),
        ),
        (
            Semantic::Extras("PATCH".into()),
            b.floats(&halo_patches(s), Scalar, None),
        ),
    ];
    let faces: Vec<u32> = faces.into_iter().flatten().collect();
    let indices = b.indices(&faces, Some(json::buffer::Target::ElementArrayBuffer), None);
    let tet_indices: Vec<u32> = halo.tets.iter().flat_map(|&t| file_order(t)).collect();
    let tetrahedra = b.indices(&tet_indices, None, Some(format!("{name} tetrahedra")));
    let [r, g, bl, _] = colour;
    let material = b.root.push(json::Material {
        name: Some(name.clone()),
        alpha_mode: Valid(json::material::AlphaMode::Blend),
        double_sided: true,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([r, g, bl, 0.35]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.6),
            ..Default::default()
        },
        ..Default::default()
    });
    let extras = serde_json::json!({
        "halo": {
            "tetrahedra": tetrahedra.value(),
            "surface_vertices": halo.surface_vertices,
            "layers": LAYERS,
            "rho": s.rho,
            "delta_d": s.halo_params.delta_d,
            "delta_t": s.halo_params.delta_t,
            "split": s.halo_params.split.name(),
            "surface_mesh": surface_mesh.value(),
        }
    });
    Ok(b.root.push(json::Mesh {
        name: Some(name),
        extras: Some(to_raw_value(&extras).map_err(|e| e.to_string())?),
        extensions: None,
        primitives: vec![json::mesh::Primitive {
            attributes: attributes.into_iter().map(|(k, v)| (Valid(k), v)).collect(),
            extensions: None,
            extras: None,
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    }))
}

/// Appends the mesh `curves` (see the module documentation), or nothing when the curves have
/// no segment.
fn curves_mesh(
    b: &mut Builder,
    curves: &Curves,
    radius: f64,
) -> Result<Option<json::Index<json::Mesh>>, String> {
    use json::accessor::Type::Scalar;
    use json::mesh::Semantic;
    let segments: Vec<u32> = curves.segments().into_iter().flatten().collect();
    let tubes = tubes(curves, radius);
    if segments.is_empty() || tubes.triangles.is_empty() {
        return Ok(None);
    }
    let points: Vec<&CurvePoint> = curves.curves.iter().flat_map(|c| &c.points).collect();
    let positions: Vec<DVec3> = points.iter().map(|p| p.position).collect();
    let dw: Vec<f32> = points.iter().map(|p| p.dw() as f32).collect();
    let index: Vec<f32> = curves
        .curves
        .iter()
        .enumerate()
        .flat_map(|(k, c)| std::iter::repeat_n(k as f32, c.points.len()))
        .collect();
    let w_near: Vec<f32> = points.iter().map(|p| p.w[p.near()] as f32).collect();
    let per_vertex =
        |values: &[f32]| -> Vec<f32> { tubes.point.iter().map(|&k| values[k as usize]).collect() };
    let attributes = [
        (Semantic::Positions, b.positions(&tubes.positions)),
        (Semantic::Normals, b.normals(&tubes.normals)),
        (
            Semantic::Extras("DW".into()),
            b.floats(&per_vertex(&dw), Scalar, None),
        ),
        (
            Semantic::Extras("CURVE".into()),
            b.floats(&per_vertex(&index), Scalar, None),
        ),
        (
            Semantic::Extras("W".into()),
            b.floats(&per_vertex(&w_near), Scalar, None),
        ),
    ];
    let triangles: Vec<u32> = tubes.triangles.iter().flatten().copied().collect();
    let indices = b.indices(
        &triangles,
        Some(json::buffer::Target::ElementArrayBuffer),
        None,
    );
    // The exact polylines, read by no primitive (see the module documentation).
    let mut lines = serde_json::Map::new();
    let polyline = [
        ("POSITION", b.positions(&positions)),
        ("_W", b.floats(&w_near, Scalar, None)),
        ("_DW", b.floats(&dw, Scalar, None)),
        ("_CURVE", b.floats(&index, Scalar, None)),
        ("indices", b.indices(&segments, None, None)),
    ];
    for (key, accessor) in polyline {
        b.root.accessors[accessor.value()].name = Some(format!("curves polyline {key}"));
        lines.insert(key.into(), accessor.value().into());
    }
    let material = b.root.push(json::Material {
        name: Some("curves".into()),
        double_sided: true,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor(CURVE_COLOUR),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        ..Default::default()
    });
    let extras = serde_json::json!({
        "curves": {
            "count": curves.curves.len(),
            "closed": curves.curves.iter().filter(|c| c.closed).count(),
            "open": curves.curves.iter().filter(|c| !c.closed).count(),
            "points": positions.len(),
            "radius": radius,
            "polylines": lines,
        }
    });
    Ok(Some(b.root.push(json::Mesh {
        name: Some("curves".into()),
        extras: Some(to_raw_value(&extras).map_err(|e| e.to_string())?),
        extensions: None,
        primitives: vec![json::mesh::Primitive {
            attributes: attributes.into_iter().map(|(k, v)| (Valid(k), v)).collect(),
            extensions: None,
            extras: None,
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    })))
}

/// Wraps JSON and binary chunks in the GLB container (header, JSON chunk padded with spaces,
/// BIN chunk padded with zeros).
pub fn glb_container(text: Vec<u8>, bin: Vec<u8>) -> Vec<u8> {
    let mut out = Vec::with_capacity(28 + text.len() + bin.len() + 6);
    write_glb_container(&mut out, &text, &bin).expect("writing into memory cannot fail");
    out
}

/// Writes [`glb_container`]'s bytes to `out`, the chunks as they are.
pub fn write_glb_container(out: &mut dyn Write, text: &[u8], bin: &[u8]) -> io::Result<()> {
    let (text_pad, bin_pad) = (
        text.len().next_multiple_of(4) - text.len(),
        bin.len().next_multiple_of(4) - bin.len(),
    );
    let (text_len, bin_len) = (text.len() + text_pad, bin.len() + bin_pad);
    let total = 12 + 8 + text_len + 8 + bin_len;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&(total as u32).to_le_bytes())?;
    out.write_all(&(text_len as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(text)?;
    out.write_all(&b"   "[..text_pad])?;
    out.write_all(&(bin_len as u32).to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    out.write_all(bin)?;
    out.write_all(&[0; 3][..bin_pad])
}

#[cfg(test)]
mod tests {
    use super::boundary_faces;
    use glam::DVec3;

    /// Signed volume enclosed by faces turned counter-clockwise seen from outside.
    fn enclosed(p: &[DVec3], faces: &[[u32; 3]]) -> f64 {
        faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| p[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn boundary_faces_skip_shared_faces_and_turn_outward_whatever_the_tets_orientation() {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, -1.0),
        ];
        let up = [0, 1, 2, 3];
        let positive = |t: [u32; 4]| {
            let c = |i: u32| robust::Coord3D {
                x: p[i as usize].x,
                y: p[i as usize].y,
                z: p[i as usize].z,
            };
            robust::orient3d(c(t[0]), c(t[1]), c(t[2]), c(t[3])) > 0.0
        };
        let (up, flipped_up) = if positive(up) {
            (up, [1, 0, 2, 3])
        } else {
            ([1, 0, 2, 3], up)
        };
        let down = if positive([0, 1, 2, 4]) {
            [0, 1, 2, 4]
        } else {
            [1, 0, 2, 4]
        };
        let one = boundary_faces(&p, &[up]);
        assert_eq!(one.len(), 4);
        assert!((enclosed(&p, &one) - 1.0 / 6.0).abs() < 1e-15);
        // A tetrahedron listed the wrong way round still gets outward faces.
        let one = boundary_faces(&p, &[flipped_up]);
        assert!((enclosed(&p, &one) - 1.0 / 6.0).abs() < 1e-15);
        // Two sharing the face (0, 1, 2): it is inside, six faces remain.
        let two = boundary_faces(&p, &[up, down]);
        assert_eq!(two.len(), 6);
        assert!(
            two.iter()
                .all(|f| !(f.contains(&0) && f.contains(&1) && f.contains(&2)))
        );
        assert!((enclosed(&p, &two) - 2.0 / 6.0).abs() < 1e-15);
    }
}
