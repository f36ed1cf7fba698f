//! Halos and surfaces from `.glb`: the container split by the `gltf` crate, the JSON chunk
//! read into `gltf-json`'s typed document, and the accessors the meshes name, each
//! bounds-checked against the BIN chunk before it is read.
//!
//! By hand, because the crate does not do it: the 12-byte header is checked before the
//! crate sees it (`gltf::binary::Glb::from_slice` subtracts 12 from the declared length
//! unchecked, and reads past a declared length shorter than the file); every index the
//! document holds is checked before it is followed (the crate's `Document` and its
//! validation index the arrays without a check: an out-of-range POSITION accessor panics
//! in `Gltf::from_slice`); and an accessor's elements are checked against its buffer view
//! and the BIN chunk before anything is allocated for them (the crate trusts `count`).

use super::{
    FileParams, ImportError, ImportedCurves, ImportedHalo, ImportedScene, ImportedSurface,
};
use crate::check::TetMesh;
use crate::convention::{MESH_4D, file_order, from_gltf};
use crate::view::area_normal_sums;
use glam::{DVec3, DVec4};
use gltf_json as json;
use json::accessor::{ComponentType, GenericComponentType, Type};
use json::mesh::{Mode, Primitive, Semantic};
use json::validation::Checked;
use serde_json::Value;

type Result<T> = std::result::Result<T, ImportError>;

fn glb_err(message: String) -> ImportError {
    ImportError::Glb(message)
}

/// Reads every mesh whose extras carry `halo` (see [`crate::export::to_glb`]).
pub fn read_glb(bytes: &[u8]) -> Result<Vec<ImportedHalo>> {
    let glb = container(bytes)?;
    let root = parse(&glb.json)?;
    let doc = Doc::new(&root, &glb);
    let meshes = &root.meshes;
    let mut halos = Vec::new();
    for (i, mesh) in meshes.iter().enumerate() {
        let extras = extras(&mesh.extras);
        let Some(halo) = extras.get("halo") else {
            continue;
        };
        halos.push(doc.halo(i, mesh, halo, mesh_name(mesh, i))?.validate()?);
    }
    if halos.is_empty() {
        return Err(ImportError::NoHalo(format!(
            "no halo: none of the file's {} meshes has `halo` in its extras (halo4d build writes one `<surface>-halo` mesh per surface)",
            meshes.len()
        )));
    }
    Ok(halos)
}

/// Reads a scene's `.glb` as `halo4d build` writes it: every surface (a mesh whose extras
/// carry `surface`: positions, `_W` and triangles) with its halo, if any (the mesh whose
/// extras' `halo.surface_mesh` names the surface's mesh). Each halo has t, d_orig, delta_d
/// and delta_t, and as many surface vertices as its surface, so that the scene can be
/// verified ([`crate::inspect::verify_scene`]).
pub fn read_scene_glb(bytes: &[u8]) -> Result<ImportedScene> {
    let glb = container(bytes)?;
    let root = parse(&glb.json)?;
    let doc = Doc::new(&root, &glb);
    let meshes = &root.meshes;
    let mesh_extras: Vec<Value> = meshes.iter().map(|m| extras(&m.extras)).collect();
    let mut surfaces: Vec<ImportedSurface> = Vec::new();
    // For each mesh, the surface it is.
    let mut surface_of = vec![None; meshes.len()];
    for (i, mesh) in meshes.iter().enumerate() {
        if mesh_extras[i].get("surface").is_some() {
            surface_of[i] = Some(surfaces.len());
            surfaces.push(doc.surface(i, mesh, mesh_name(mesh, i))?);
        }
    }
    if surfaces.is_empty() {
        return Err(ImportError::NoSurface(format!(
            "no surface: none of the file's {} meshes has `surface` in its extras (halo4d build writes one mesh per surface)",
            meshes.len()
        )));
    }
    for (i, mesh) in meshes.iter().enumerate() {
        let Some(extras) = mesh_extras[i].get("halo") else {
            continue;
        };
        let halo = doc.halo(i, mesh, extras, mesh_name(mesh, i))?.validate()?;
        attach_halo(&mut surfaces, &surface_of, extras, i, halo)?;
    }
    let asset = extras(&root.asset.extras);
    let name = asset
        .pointer("/halo4d/scene/name")
        .and_then(Value::as_str)
        .map(String::from);
    let camera = asset
        .pointer("/halo4d/scene/camera")
        .map(|c| {
            serde_path_to_error::deserialize(c.clone()).map_err(|e| {
                glb_err(format!(
                    "the scene camera recorded in asset.extras.halo4d.scene.camera is not valid: {e}"
                ))
            })
        })
        .transpose()?;
    let curves = match meshes
        .iter()
        .enumerate()
        .find_map(|(i, m)| Some((i, m, mesh_extras[i].get("curves")?)))
    {
        Some((i, mesh, curves)) => doc.curves(i, curves, &mesh_name(mesh, i))?,
        None => None,
    };
    Ok(ImportedScene {
        name,
        surfaces,
        curves,
        camera,
        scene: asset.pointer("/halo4d/scene").cloned(),
    })
}

/// Gives `halo`, the halo of glTF mesh `i` whose extras are `extras`, to the surface its
/// `surface_mesh` names (`surface_of`: the surface each mesh is, if any), after checking that
/// the surface has no halo yet, that their vertices agree, and that the halo has what the
/// halo depth needs.
fn attach_halo(
    surfaces: &mut [ImportedSurface],
    surface_of: &[Option<usize>],
    extras: &Value,
    i: usize,
    halo: ImportedHalo,
) -> Result<()> {
    let bad = |message: String| ImportError::BadHalo {
        name: halo.name.clone(),
        message,
    };
    let m = index(
        extras,
        "surface_mesh",
        &format!("meshes[{i}].extras.halo"),
        None,
    )?;
    let s = usize::try_from(m)
        .ok()
        .and_then(|m| surface_of.get(m).copied().flatten())
        .ok_or_else(|| {
            bad(format!(
                "surface_mesh = {m} is not one of the file's surface meshes"
            ))
        })?;
    let surface = &surfaces[s];
    if surface.halo.is_some() {
        return Err(bad(format!(
            "surface `{}` (meshes[{m}]) has a halo already",
            surface.name
        )));
    }
    if halo.mesh.surface_vertices != surface.positions.len() {
        return Err(bad(format!(
            "surface_vertices = {}, but its surface `{}` has {} vertices",
            halo.mesh.surface_vertices,
            surface.name,
            surface.positions.len()
        )));
    }
    for (what, present) in [
        ("the attribute _T (t)", halo.t.is_some()),
        ("the attribute _D (d_orig)", halo.d_orig.is_some()),
        ("delta_d in its extras", halo.params.delta_d.is_some()),
        ("delta_t in its extras", halo.params.delta_t.is_some()),
    ] {
        if !present {
            return Err(bad(format!(
                "has no {what}, which the halo depth of paper 000 eq. 3 needs"
            )));
        }
    }
    surfaces[s].halo = Some(halo);
    Ok(())
}

/// The JSON chunk as `gltf-json`'s document; an error names the field.
fn parse(json: &[u8]) -> Result<json::Root> {
    let patched = scenes_with_nodes(json);
    let json = patched.as_deref().unwrap_or(json);
    let mut de = serde_json::Deserializer::from_slice(json);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        glb_err(format!(
            "the JSON chunk is not valid JSON for glTF 2: {}{}",
            if path == "." {
                String::new()
            } else {
                format!("{path}: ")
            },
            e.into_inner()
        ))
    })
}

/// The JSON chunk with `"nodes": []` in each scene that leaves it out, or `None` when none
/// does (or it is not JSON, which [`parse`] reports). glTF's scenes may leave it out (Blender
/// 4.5's exporter does, for the collection of a scene without objects, such as the hidden
/// halos' after their objects moved), and `gltf-json` requires it.
fn scenes_with_nodes(json: &[u8]) -> Option<Vec<u8>> {
    let mut document: Value = serde_json::from_slice(json).ok()?;
    let mut changed = false;
    for scene in document.get_mut("scenes")?.as_array_mut()? {
        if let Some(scene) = scene.as_object_mut()
            && !scene.contains_key("nodes")
        {
            scene.insert("nodes".into(), Value::Array(Vec::new()));
            changed = true;
        }
    }
    if changed {
        serde_json::to_vec(&document).ok()
    } else {
        None
    }
}

/// An object's extras as JSON (null when it has none).
fn extras(extras: &json::Extras) -> Value {
    extras
        .as_ref()
        .and_then(|raw| serde_json::from_str(raw.get()).ok())
        .unwrap_or(Value::Null)
}

/// A mesh's name, or `mesh i` when it has none.
fn mesh_name(mesh: &json::Mesh, i: usize) -> String {
    mesh.name.clone().unwrap_or_else(|| format!("mesh {i}"))
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The JSON chunk and the BIN chunk, if any, of a GLB container: the header checked here,
/// the chunks split by the `gltf` crate.
fn container(bytes: &[u8]) -> Result<gltf::binary::Glb<'_>> {
    if bytes.len() < 12 {
        return Err(glb_err(format!(
            "truncated: the 12-byte header is incomplete, the file has {} bytes",
            bytes.len()
        )));
    }
    if &bytes[..4] != b"glTF" {
        return Err(glb_err(format!(
            "wrong magic {:?}: a .glb starts with `glTF`",
            String::from_utf8_lossy(&bytes[..4])
        )));
    }
    let version = u32_at(bytes, 4);
    if version != 2 {
        return Err(glb_err(format!(
            "container version {version}; only glTF 2 is read"
        )));
    }
    let length = u32_at(bytes, 8) as usize;
    if length > bytes.len() {
        return Err(glb_err(format!(
            "truncated: the header says {length} bytes, the file has {}",
            bytes.len()
        )));
    }
    if length < bytes.len() {
        return Err(glb_err(format!(
            "the header says {length} bytes, but the file has {} (trailing data)",
            bytes.len()
        )));
    }
    gltf::binary::Glb::from_slice(bytes).map_err(|e| {
        use gltf::binary::{ChunkType, Error};
        let chunk = |ty: ChunkType| match ty {
            ChunkType::Json => "JSON",
            ChunkType::Bin => "BIN",
        };
        glb_err(match e {
            gltf::Error::Binary(Error::ChunkLength {
                ty,
                length,
                length_read,
            }) => format!(
                "truncated: the {} chunk claims {length} bytes, {length_read} remain",
                chunk(ty)
            ),
            gltf::Error::Binary(Error::ChunkType(ChunkType::Json)) => {
                "a second JSON chunk where the BIN chunk belongs".into()
            }
            gltf::Error::Binary(Error::ChunkType(ChunkType::Bin)) => {
                "the first chunk is not the JSON chunk".into()
            }
            gltf::Error::Binary(Error::UnknownChunkType(ty)) => format!(
                "a chunk of unknown type {:?} (halo4d reads a JSON and a BIN chunk)",
                String::from_utf8_lossy(&ty)
            ),
            gltf::Error::Binary(Error::Io(_)) => "truncated: a chunk header is incomplete".into(),
            other => format!("the container cannot be split into its chunks: {other}"),
        })
    })
}

/// A primitive's points as [`Doc::points`] reads them.
struct Points<'a> {
    primitive: &'a Primitive,
    positions: Vec<DVec3>,
    w: Vec<f64>,
    indices: Vec<u32>,
}

/// A parsed glTF document and its binary chunk.
struct Doc<'a> {
    root: &'a json::Root,
    bin: Option<&'a [u8]>,
}

/// A non-negative integer field of a JSON object, or `default` when absent.
fn index(obj: &Value, key: &str, what: &str, default: Option<u64>) -> Result<u64> {
    match obj.get(key) {
        Some(v) => v
            .as_u64()
            .ok_or_else(|| glb_err(format!("{what}.{key} is not a non-negative integer: {v}"))),
        None => default.ok_or_else(|| glb_err(format!("{what} has no `{key}`"))),
    }
}

fn to_usize(x: u64, what: &str) -> Result<usize> {
    usize::try_from(x).map_err(|_| glb_err(format!("{what} is too large: {x}")))
}

/// An accessor's type as the file spells it.
fn type_name(t: &Checked<Type>) -> &'static str {
    match t {
        Checked::Valid(Type::Scalar) => "SCALAR",
        Checked::Valid(Type::Vec2) => "VEC2",
        Checked::Valid(Type::Vec3) => "VEC3",
        Checked::Valid(Type::Vec4) => "VEC4",
        Checked::Valid(Type::Mat2) => "MAT2",
        Checked::Valid(Type::Mat3) => "MAT3",
        Checked::Valid(Type::Mat4) => "MAT4",
        Checked::Invalid => "?",
    }
}

/// An accessor's component type, when it is a valid one.
fn component(c: &Checked<GenericComponentType>) -> Option<ComponentType> {
    match c {
        Checked::Valid(GenericComponentType(c)) => Some(*c),
        Checked::Invalid => None,
    }
}

/// An accessor's component type as the file numbers it.
fn component_name(c: &Checked<GenericComponentType>) -> String {
    component(c).map_or("?".into(), |c| c.as_gl_enum().to_string())
}

/// The accessor a primitive's attribute `semantic` names, when it has one.
fn attribute(primitive: &Primitive, semantic: Semantic) -> Option<u64> {
    primitive
        .attributes
        .get(&Checked::Valid(semantic))
        .map(|a| a.value() as u64)
}

/// A custom attribute (`_W`, `_T`, `_D`).
fn custom(name: &str) -> Semantic {
    Semantic::Extras(name.trim_start_matches('_').to_string())
}

impl<'a> Doc<'a> {
    fn new(root: &'a json::Root, glb: &'a gltf::binary::Glb) -> Self {
        Doc {
            root,
            bin: glb.bin.as_deref(),
        }
    }

    /// Accessor `i`, checked to exist.
    fn accessor(&self, i: u64) -> Result<&'a json::Accessor> {
        let all = &self.root.accessors;
        usize::try_from(i)
            .ok()
            .and_then(|i| all.get(i))
            .ok_or_else(|| {
                glb_err(format!(
                    "accessors[{i}] does not exist (the file has {} accessors)",
                    all.len()
                ))
            })
    }

    /// The bytes of accessor `i` in the BIN chunk: `count` elements of `element` bytes,
    /// `stride` apart, from the returned offset, all checked to lie inside its buffer view.
    fn accessor_bytes(
        &self,
        i: u64,
        accessor: &json::Accessor,
        element: usize,
    ) -> Result<(&'a [u8], usize, usize)> {
        let what = format!("accessors[{i}]");
        if accessor.sparse.is_some() {
            return Err(glb_err(format!("{what} is sparse, which halos never are")));
        }
        let count = to_usize(accessor.count.0, "count")?;
        let view_index = accessor
            .buffer_view
            .ok_or_else(|| glb_err(format!("{what} has no `bufferView`")))?
            .value();
        let view = self.root.buffer_views.get(view_index).ok_or_else(|| {
            glb_err(format!(
                "bufferViews[{view_index}] does not exist (the file has {} bufferViews)",
                self.root.buffer_views.len()
            ))
        })?;
        let view_what = format!("bufferViews[{view_index}]");
        let buffer = view.buffer.value();
        let buffer_json = self.root.buffers.get(buffer).ok_or_else(|| {
            glb_err(format!(
                "buffers[{buffer}] does not exist (the file has {} buffers)",
                self.root.buffers.len()
            ))
        })?;
        if buffer != 0 || buffer_json.uri.is_some() {
            return Err(glb_err(format!(
                "{view_what} is in buffer {buffer}, not in the .glb's own binary chunk"
            )));
        }
        let bin = self
            .bin
            .ok_or_else(|| glb_err(format!("{what} needs a BIN chunk, and there is none")))?;
        let view_offset = to_usize(view.byte_offset.map_or(0, |o| o.0), "offset")?;
        let view_len = to_usize(view.byte_length.0, "length")?;
        if view_offset
            .checked_add(view_len)
            .is_none_or(|end| end > bin.len())
        {
            return Err(glb_err(format!(
                "{view_what} (bytes {view_offset} + {view_len}) runs past the {}-byte BIN chunk",
                bin.len()
            )));
        }
        let stride = view.byte_stride.map_or(element, |s| s.0);
        if stride < element {
            return Err(glb_err(format!(
                "{view_what}.byteStride {stride} is less than the {element}-byte elements of {what}"
            )));
        }
        let offset = to_usize(accessor.byte_offset.map_or(0, |o| o.0), "offset")?;
        let needed = match count {
            0 => Some(offset),
            _ => (count - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(element))
                .and_then(|x| x.checked_add(offset)),
        };
        if needed.is_none_or(|n| n > view_len) {
            return Err(glb_err(format!(
                "{what} claims {count} elements of {element} bytes, more than its {view_len}-byte buffer view holds"
            )));
        }
        Ok((
            &bin[view_offset + offset..view_offset + view_len],
            count,
            stride,
        ))
    }

    /// Accessor `i` as floats: FLOAT components of `expected` (`SCALAR` or `VEC3`).
    fn floats(&self, i: u64, expected: Type, components: usize) -> Result<Vec<f32>> {
        let accessor = self.accessor(i)?;
        if component(&accessor.component_type) != Some(ComponentType::F32)
            || accessor.type_ != Checked::Valid(expected)
        {
            return Err(glb_err(format!(
                "accessors[{i}] is {} of component type {}, expected {} of FLOAT (5126)",
                type_name(&accessor.type_),
                component_name(&accessor.component_type),
                type_name(&Checked::Valid(expected))
            )));
        }
        let (bytes, count, stride) = self.accessor_bytes(i, accessor, 4 * components)?;
        let mut out = Vec::with_capacity(count * components);
        for k in 0..count {
            for c in 0..components {
                out.push(f32::from_le_bytes(
                    bytes[k * stride + 4 * c..][..4]
                        .try_into()
                        .expect("4 bytes"),
                ));
            }
        }
        Ok(out)
    }

    /// Accessor `i` as FLOAT SCALARs, widened.
    fn scalars(&self, i: u64) -> Result<Vec<f64>> {
        Ok(self
            .floats(i, Type::Scalar, 1)?
            .into_iter()
            .map(f64::from)
            .collect())
    }

    /// Accessor `i` as FLOAT VEC3s (points or directions) in halo4d's frame.
    fn vec3s(&self, i: u64) -> Result<Vec<DVec3>> {
        Ok(self
            .floats(i, Type::Vec3, 3)?
            .chunks_exact(3)
            .map(|c| from_gltf(DVec3::new(c[0].into(), c[1].into(), c[2].into())))
            .collect())
    }

    /// Accessor `i` as unsigned integer SCALARs (UNSIGNED_BYTE, _SHORT or _INT).
    fn unsigned(&self, i: u64) -> Result<Vec<u32>> {
        let accessor = self.accessor(i)?;
        let size = match component(&accessor.component_type) {
            Some(ComponentType::U8) => 1,
            Some(ComponentType::U16) => 2,
            Some(ComponentType::U32) => 4,
            _ => 0,
        };
        if size == 0 || accessor.type_ != Checked::Valid(Type::Scalar) {
            return Err(glb_err(format!(
                "accessors[{i}] is {} of component type {}, expected SCALAR of an unsigned integer type",
                type_name(&accessor.type_),
                component_name(&accessor.component_type)
            )));
        }
        let (bytes, count, stride) = self.accessor_bytes(i, accessor, size)?;
        Ok((0..count)
            .map(|k| {
                let b = &bytes[k * stride..];
                match size {
                    1 => u32::from(b[0]),
                    2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                }
            })
            .collect())
    }

    /// The first primitive of mesh `i`, which must be of TRIANGLES: its POSITION, `_W` and
    /// indices, and the primitive.
    fn points(&self, i: usize, mesh: &'a json::Mesh, name: &str) -> Result<Points<'a>> {
        let what = format!("meshes[{i}] (`{name}`)");
        let primitive = mesh
            .primitives
            .first()
            .ok_or_else(|| glb_err(format!("{what} has no primitive")))?;
        if primitive.mode != Checked::Valid(Mode::Triangles) {
            return Err(glb_err(format!(
                "{what} has primitives of mode {}, expected TRIANGLES (4)",
                match primitive.mode {
                    Checked::Valid(m) => m.as_gl_enum().to_string(),
                    Checked::Invalid => "?".into(),
                }
            )));
        }
        let needed = |key: &str, semantic: Semantic| {
            attribute(primitive, semantic)
                .ok_or_else(|| glb_err(format!("{what} attributes has no `{key}`")))
        };
        let positions = self.vec3s(needed("POSITION", Semantic::Positions)?)?;
        let w = self.scalars(needed("_W", custom("_W"))?)?;
        let indices = primitive
            .indices
            .ok_or_else(|| glb_err(format!("{what}.primitives[0] has no `indices`")))?;
        let indices = self.unsigned(indices.value() as u64)?;
        Ok(Points {
            primitive,
            positions,
            w,
            indices,
        })
    }

    /// The surface of mesh `i`: its first primitive's POSITION, `_W`, NORMAL if any, and
    /// triangles.
    fn surface(&self, i: usize, mesh: &'a json::Mesh, name: String) -> Result<ImportedSurface> {
        let Points {
            primitive,
            positions,
            w,
            indices,
        } = self.points(i, mesh, &name)?;
        let file_normals: Option<Vec<DVec3>> = attribute(primitive, Semantic::Normals)
            .map(|a| self.vec3s(a))
            .transpose()?;
        let bad = |message: String| ImportError::BadSurface {
            name: name.clone(),
            message,
        };
        let nv = positions.len();
        if w.len() != nv {
            return Err(bad(format!("_W has {} values for {nv} positions", w.len())));
        }
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            let p = positions[k];
            return Err(bad(format!(
                "vertex {k} has a non-finite coordinate ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        if let Some(k) = w.iter().position(|x| !x.is_finite()) {
            return Err(bad(format!("_W of vertex {k} is not finite ({})", w[k])));
        }
        if let Some(normals) = &file_normals {
            if normals.len() != nv {
                return Err(bad(format!(
                    "NORMAL has {} values for {nv} positions",
                    normals.len()
                )));
            }
            if let Some(k) = normals.iter().position(|n| !n.is_finite()) {
                return Err(bad(format!("the normal of vertex {k} is not finite")));
            }
        }
        if indices.len() % 3 != 0 {
            return Err(bad(format!(
                "{} triangle indices, not a multiple of 3",
                indices.len()
            )));
        }
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        for (k, t) in triangles.iter().enumerate() {
            if let Some(&v) = t.iter().find(|&&v| v as usize >= nv) {
                return Err(bad(format!(
                    "triangle {k} names vertex {v}, but there are only {nv} vertices"
                )));
            }
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                return Err(bad(format!(
                    "triangle {k} repeats a vertex: {t:?} (halo4d never writes one)"
                )));
            }
        }
        let normals = file_normals.unwrap_or_else(|| {
            area_normal_sums(&positions, &triangles)
                .into_iter()
                .map(|n| n.normalize_or_zero())
                .collect()
        });
        let mesh_4d = self.mesh_4d(primitive, &triangles, nv);
        Ok(ImportedSurface {
            name,
            mesh: i,
            positions,
            w,
            triangles,
            normals,
            halo: None,
            mesh_4d,
        })
    }

    /// The 4D mesh before the view, from its twelve float SCALAR custom attributes
    /// ([`crate::convention::MESH_4D`], in the scene's own coordinates), or why there is
    /// none: the file is read without it (a program that re-saved the file may have dropped
    /// or converted them), and only the viewer's 4D turning needs it.
    fn mesh_4d(
        &self,
        primitive: &json::mesh::Primitive,
        triangles: &[[u32; 3]],
        nv: usize,
    ) -> std::result::Result<crate::sample::Mesh4, String> {
        let mut columns = Vec::with_capacity(3);
        for names in MESH_4D {
            let mut column = vec![DVec4::ZERO; nv];
            for (c, name) in names.iter().enumerate() {
                let accessor = attribute(primitive, Semantic::Extras((*name).into()))
                    .ok_or_else(|| format!("no _{name}"))?;
                let values = self
                    .scalars(accessor)
                    .map_err(|e| format!("_{name}: {e}"))?;
                if values.len() != nv {
                    return Err(format!(
                        "_{name} has {} values for {nv} positions",
                        values.len()
                    ));
                }
                if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                    return Err(format!("_{name} of vertex {k} is not finite"));
                }
                for (p, x) in column.iter_mut().zip(values) {
                    p[c] = x;
                }
            }
            columns.push(column);
        }
        let tangent_v = columns.pop().expect("three columns");
        let tangent_u = columns.pop().expect("three columns");
        let positions = columns.pop().expect("three columns");
        Ok(crate::sample::Mesh4 {
            positions,
            tangent_u,
            tangent_v,
            triangles: triangles.to_vec(),
            ..Default::default()
        })
    }

    /// The exact polylines of the curves mesh `i`, whose extras' `curves` is `curves`: the
    /// own accessors ([`Self::own_accessor`]) its `polylines` names, POSITION, `_W` and
    /// `indices` (pairs of points). `None` when the extras name none or name accessors that
    /// are not (any more) halo4d's, as after a program re-saved the file.
    fn curves(&self, i: usize, curves: &Value, name: &str) -> Result<Option<ImportedCurves>> {
        let what = format!("meshes[{i}] (`{name}`).extras.curves.polylines");
        let Some(lines) = curves.get("polylines") else {
            return Ok(None);
        };
        let mut ids = [0u64; 3];
        for (id, key) in ids.iter_mut().zip(["POSITION", "_W", "indices"]) {
            *id = index(lines, key, &what, None)?;
            if self
                .own_accessor(*id, &format!("curves polyline {key}"))
                .is_err()
            {
                return Ok(None);
            }
        }
        let [position, w, indices] = ids;
        let positions: Vec<DVec3> = self.vec3s(position)?;
        let w = self.scalars(w)?;
        let indices = self.unsigned(indices)?;
        let nv = positions.len();
        let bad = |message: String| glb_err(format!("{what}: {message}"));
        if w.len() != nv {
            return Err(bad(format!("_W has {} values for {nv} positions", w.len())));
        }
        if positions.iter().any(|p| !p.is_finite()) || w.iter().any(|x| !x.is_finite()) {
            return Err(bad("a curve point is not finite".into()));
        }
        if indices.len() % 2 != 0 || indices.iter().any(|&v| v as usize >= nv) {
            return Err(bad(format!(
                "{} line indices for {nv} points: not pairs of points in range",
                indices.len()
            )));
        }
        Ok(Some(ImportedCurves {
            positions,
            w,
            segments: indices.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
        }))
    }

    /// Accessor `i`, if it is one that halo4d writes for no primitive (tetrahedra,
    /// polylines): named `expected` and read by no primitive; else why not, as a phrase
    /// that follows "accessors[i], which". A program that re-saves a `.glb` keeps the
    /// meshes' extras but may drop such accessors and give their numbers to others (Blender
    /// 4.5 makes the tetrahedra's a triangle index buffer).
    fn own_accessor(
        &self,
        i: u64,
        expected: &str,
    ) -> std::result::Result<&'a json::Accessor, String> {
        let all = &self.root.accessors;
        let accessor = usize::try_from(i)
            .ok()
            .and_then(|i| all.get(i))
            .ok_or_else(|| format!("does not exist (the file has {})", all.len()))?;
        match &accessor.name {
            Some(n) if n == expected => {}
            Some(n) => return Err(format!("is named `{n}`, not `{expected}`")),
            None => return Err(format!("has no name (halo4d names it `{expected}`)")),
        }
        let used = self
            .root
            .meshes
            .iter()
            .flat_map(|m| &m.primitives)
            .any(|p| {
                p.indices.is_some_and(|a| a.value() as u64 == i)
                    || p.attributes.values().any(|a| a.value() as u64 == i)
            });
        if used {
            return Err("a primitive reads as its indices or an attribute".into());
        }
        Ok(accessor)
    }

    /// The indices of accessor `i`, which a halo mesh `name` of `vertices` vertices names
    /// as its tetrahedra, if it is what [`crate::export::to_glb`] writes: an own accessor
    /// ([`Self::own_accessor`]) named `<name> tetrahedra`, SCALAR of UNSIGNED_INT, a
    /// multiple of 4 indices, each below `vertices`. Anything else is
    /// [`ImportError::NoTetrahedra`], so that triangles are never read as tetrahedra.
    fn tetrahedra(&self, i: u64, name: &str, vertices: usize) -> Result<Vec<u32>> {
        let missing = |why: String| ImportError::NoTetrahedra {
            mesh: name.to_string(),
            why: format!("its extras name accessors[{i}], which {why}"),
        };
        let accessor = self
            .own_accessor(i, &format!("{name} tetrahedra"))
            .map_err(missing)?;
        if accessor.type_ != Checked::Valid(Type::Scalar)
            || component(&accessor.component_type) != Some(ComponentType::U32)
        {
            return Err(missing(format!(
                "is {} of component type {}, not SCALAR of UNSIGNED_INT (5125)",
                type_name(&accessor.type_),
                component_name(&accessor.component_type)
            )));
        }
        let indices = self.unsigned(i)?;
        if indices.len() % 4 != 0 {
            return Err(missing(format!(
                "has {} indices, not a multiple of 4",
                indices.len()
            )));
        }
        if let Some(k) = indices.iter().position(|&v| v as usize >= vertices) {
            return Err(missing(format!(
                "names vertex {} at index {k}, but the mesh has {vertices} vertices",
                indices[k]
            )));
        }
        Ok(indices)
    }

    /// The vertex count and triangles of mesh `m`, the surface a halo's `surface_mesh` (in
    /// `what`) names.
    fn triangles_of(&self, m: u64, what: &str) -> Result<(usize, Vec<[u32; 3]>)> {
        let i = usize::try_from(m)
            .ok()
            .filter(|&i| i < self.root.meshes.len());
        let i = i.ok_or_else(|| {
            glb_err(format!(
                "{what}.surface_mesh = {m}, but the file has {} meshes",
                self.root.meshes.len()
            ))
        })?;
        let mesh = &self.root.meshes[i];
        if extras(&mesh.extras).get("surface").is_none() {
            return Err(glb_err(format!(
                "{what}.surface_mesh = {m} is not one of the file's surface meshes"
            )));
        }
        let surface = format!("meshes[{i}] (`{}`)", mesh_name(mesh, i));
        let primitive = mesh
            .primitives
            .first()
            .filter(|p| p.mode == Checked::Valid(Mode::Triangles))
            .ok_or_else(|| {
                glb_err(format!(
                    "{surface}, the surface of {what}, has no primitive of TRIANGLES"
                ))
            })?;
        let indices = primitive.indices.ok_or_else(|| {
            glb_err(format!(
                "{surface}.primitives[0], the surface of {what}, has no `indices`"
            ))
        })?;
        let indices = self.unsigned(indices.value() as u64)?;
        if indices.len() % 3 != 0 {
            return Err(glb_err(format!(
                "meshes[{i}], the surface of {what}: {} triangle indices, not a multiple of 3",
                indices.len()
            )));
        }
        let position = attribute(primitive, Semantic::Positions).ok_or_else(|| {
            glb_err(format!(
                "{surface}, the surface of {what}, has no POSITION attribute"
            ))
        })?;
        let vertices = self.accessor(position)?.count.0 as usize;
        let triangles = indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Ok((vertices, triangles))
    }

    /// The halo of mesh `i`, whose extras' `halo` is `halo`.
    fn halo(
        &self,
        i: usize,
        mesh: &json::Mesh,
        halo: &Value,
        name: String,
    ) -> Result<ImportedHalo> {
        let what = format!("meshes[{i}] (`{name}`)");
        let extras = format!("{what}.extras.halo");
        if !halo.is_object() {
            return Err(glb_err(format!("{extras} is not an object")));
        }
        let primitive = mesh
            .primitives
            .first()
            .ok_or_else(|| glb_err(format!("{what} has no primitive with attributes")))?;
        let position = attribute(primitive, Semantic::Positions)
            .ok_or_else(|| glb_err(format!("{what} has no POSITION attribute")))?;
        let positions: Vec<[f64; 3]> = self
            .vec3s(position)?
            .into_iter()
            .map(|p| p.to_array())
            .collect();
        let scalar = |key: &str| -> Result<Option<Vec<f64>>> {
            let Some(a) = attribute(primitive, custom(key)) else {
                return Ok(None);
            };
            let values = self.scalars(a)?;
            if values.len() != positions.len() {
                return Err(glb_err(format!(
                    "{what}: {key} has {} values for {} positions",
                    values.len(),
                    positions.len()
                )));
            }
            Ok(Some(values))
        };
        let t = scalar("_T")?;
        let d_orig = scalar("_D")?;
        let tetrahedra = index(halo, "tetrahedra", &extras, None)?;
        let indices = self.tetrahedra(tetrahedra, &name, positions.len())?;
        let surface_vertices = to_usize(
            index(halo, "surface_vertices", &extras, None)?,
            "surface_vertices",
        )?;
        let number = |key: &str| halo.get(key).and_then(Value::as_f64);
        // The surface's triangles, from the mesh `surface_mesh` names, so that the checker
        // sees a prism missing whole; none where the halo names no surface.
        let (surface_mesh_vertices, surface_triangles) =
            match halo.get("surface_mesh").and_then(Value::as_u64) {
                Some(m) => {
                    let (vertices, triangles) = self.triangles_of(m, &extras)?;
                    (Some(vertices), triangles)
                }
                None => (None, Vec::new()),
            };
        Ok(ImportedHalo {
            name,
            mesh: TetMesh {
                positions,
                surface_vertices,
                tets: indices
                    .chunks_exact(4)
                    .map(|c| file_order([c[0], c[1], c[2], c[3]]))
                    .collect(),
                surface_triangles,
            },
            t,
            d_orig,
            params: FileParams {
                rho: number("rho"),
                delta_d: number("delta_d"),
                delta_t: number("delta_t"),
                split: halo.get("split").and_then(Value::as_str).map(String::from),
                surface_mesh: halo
                    .get("surface_mesh")
                    .and_then(Value::as_u64)
                    .and_then(|m| usize::try_from(m).ok()),
                surface_mesh_vertices,
                layers: number("layers"),
            },
        })
    }
}
