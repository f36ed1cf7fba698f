//! Halos and surfaces from `.glb`: the container, the JSON chunk (serde_json) and the
//! accessors the meshes name, each bounds-checked against the BIN chunk before it is read.

use super::{
    FileParams, ImportError, ImportedCurves, ImportedHalo, ImportedScene, ImportedSurface,
};
use crate::check::TetMesh;
use crate::convention::{file_order, from_gltf};
use crate::view::area_normal_sums;
use glam::DVec3;
use serde_json::Value;

type Result<T> = std::result::Result<T, ImportError>;

fn glb_err(message: String) -> ImportError {
    ImportError::Glb(message)
}

/// Reads every mesh whose extras carry `halo` (see [`crate::export::to_glb`]).
pub fn read_glb(bytes: &[u8]) -> Result<Vec<ImportedHalo>> {
    let (json, bin) = chunks(bytes)?;
    let json = parse(json)?;
    let doc = Doc { json: &json, bin };
    let meshes = meshes(&json)?;
    let mut halos = Vec::new();
    for (i, mesh) in meshes.iter().enumerate() {
        let Some(halo) = extra(mesh, "halo") else {
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
    let (json, bin) = chunks(bytes)?;
    let json = parse(json)?;
    let doc = Doc { json: &json, bin };
    let meshes = meshes(&json)?;
    let mut surfaces: Vec<ImportedSurface> = Vec::new();
    // For each mesh, the surface it is.
    let mut surface_of = vec![None; meshes.len()];
    for (i, mesh) in meshes.iter().enumerate() {
        if extra(mesh, "surface").is_some() {
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
        let Some(extras) = extra(mesh, "halo") else {
            continue;
        };
        let halo = doc.halo(i, mesh, extras, mesh_name(mesh, i))?.validate()?;
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
    }
    let name = json
        .pointer("/asset/extras/halo4d/scene/name")
        .and_then(Value::as_str)
        .map(String::from);
    let camera = json
        .pointer("/asset/extras/halo4d/scene/camera")
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
        .find_map(|(i, m)| Some((i, m, extra(m, "curves")?)))
    {
        Some((i, mesh, curves)) => doc.curves(i, curves, &mesh_name(mesh, i))?,
        None => None,
    };
    Ok(ImportedScene {
        name,
        surfaces,
        curves,
        camera,
    })
}

/// The JSON chunk parsed.
fn parse(json: &[u8]) -> Result<Value> {
    serde_json::from_slice(json)
        .map_err(|e| glb_err(format!("the JSON chunk is not valid JSON: {e}")))
}

/// The document's meshes (none when it has no `meshes`).
fn meshes(json: &Value) -> Result<&[Value]> {
    match json.get("meshes") {
        None => Ok(&[]),
        Some(Value::Array(m)) => Ok(m),
        Some(_) => Err(glb_err("`meshes` is not an array".into())),
    }
}

/// The entry `key` of a mesh's extras.
fn extra<'v>(mesh: &'v Value, key: &str) -> Option<&'v Value> {
    mesh.get("extras").and_then(|e| e.get(key))
}

/// A mesh's name, or `mesh i` when it has none.
fn mesh_name(mesh: &Value, i: usize) -> String {
    match mesh.get("name") {
        Some(Value::String(s)) => s.clone(),
        _ => format!("mesh {i}"),
    }
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The JSON chunk and the BIN chunk, if any, of a GLB container.
fn chunks(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>)> {
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
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < length {
        if length - at < 8 {
            return Err(glb_err(format!(
                "truncated: a chunk header at byte {at} is incomplete"
            )));
        }
        let len = u32_at(bytes, at) as usize;
        let kind = &bytes[at + 4..at + 8];
        let start = at + 8;
        if len > length - start {
            return Err(glb_err(format!(
                "truncated: the chunk at byte {at} claims {len} bytes, {} remain",
                length - start
            )));
        }
        let data = &bytes[start..start + len];
        match (kind, json.is_some()) {
            (b"JSON", false) => json = Some(data),
            (b"JSON", true) => return Err(glb_err("a second JSON chunk".into())),
            (_, false) => return Err(glb_err("the first chunk is not the JSON chunk".into())),
            (b"BIN\0", true) if bin.is_none() => bin = Some(data),
            (b"BIN\0", true) => return Err(glb_err("a second BIN chunk".into())),
            // Chunks of unknown types are to be ignored (glTF 2.0, 4.4.3).
            _ => {}
        }
        at = start + len.next_multiple_of(4).min(length - start);
    }
    let json = json.ok_or_else(|| glb_err("no JSON chunk".into()))?;
    Ok((json, bin))
}

/// A primitive's points as [`Doc::points`] reads them.
struct Points<'a> {
    /// `meshes[i] (`name`)`, for messages.
    what: String,
    attributes: &'a Value,
    positions: Vec<DVec3>,
    w: Vec<f64>,
    indices: Vec<u32>,
}

/// A parsed glTF document and its binary chunk.
struct Doc<'a> {
    json: &'a Value,
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

impl<'a> Doc<'a> {
    /// Element `i` of the top-level array `key`.
    fn item(&self, key: &str, i: u64) -> Result<&'a Value> {
        let all = self.json.get(key).and_then(Value::as_array);
        let len = all.map_or(0, Vec::len);
        usize::try_from(i)
            .ok()
            .and_then(|i| all.and_then(|a| a.get(i)))
            .ok_or_else(|| {
                glb_err(format!(
                    "{key}[{i}] does not exist (the file has {len} {key})"
                ))
            })
    }

    /// The bytes of accessor `i` in the BIN chunk: `count` elements of `element` bytes,
    /// `stride` apart, from the returned offset, all checked to lie inside its buffer view.
    fn accessor_bytes(
        &self,
        i: u64,
        accessor: &Value,
        element: usize,
    ) -> Result<(&'a [u8], usize, usize)> {
        let what = format!("accessors[{i}]");
        if accessor.get("sparse").is_some() {
            return Err(glb_err(format!("{what} is sparse, which halos never are")));
        }
        let count = to_usize(index(accessor, "count", &what, None)?, "count")?;
        let view_index = index(accessor, "bufferView", &what, None)?;
        let view = self.item("bufferViews", view_index)?;
        let view_what = format!("bufferViews[{view_index}]");
        let buffer = index(view, "buffer", &view_what, None)?;
        let buffer_json = self.item("buffers", buffer)?;
        if buffer != 0 || buffer_json.get("uri").is_some() {
            return Err(glb_err(format!(
                "{view_what} is in buffer {buffer}, not in the .glb's own binary chunk"
            )));
        }
        let bin = self
            .bin
            .ok_or_else(|| glb_err(format!("{what} needs a BIN chunk, and there is none")))?;
        let view_offset = to_usize(index(view, "byteOffset", &view_what, Some(0))?, "offset")?;
        let view_len = to_usize(index(view, "byteLength", &view_what, None)?, "length")?;
        if view_offset
            .checked_add(view_len)
            .is_none_or(|end| end > bin.len())
        {
            return Err(glb_err(format!(
                "{view_what} (bytes {view_offset} + {view_len}) runs past the {}-byte BIN chunk",
                bin.len()
            )));
        }
        let stride = to_usize(
            index(view, "byteStride", &view_what, Some(element as u64))?,
            "stride",
        )?;
        if stride < element {
            return Err(glb_err(format!(
                "{view_what}.byteStride {stride} is less than the {element}-byte elements of {what}"
            )));
        }
        let offset = to_usize(index(accessor, "byteOffset", &what, Some(0))?, "offset")?;
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

    /// Accessor `i` as floats: FLOAT components of `type_` (`SCALAR` or `VEC3`).
    fn floats(&self, i: u64, type_: &str, components: usize) -> Result<Vec<f32>> {
        let accessor = self.item("accessors", i)?;
        let what = format!("accessors[{i}]");
        let component_type = index(accessor, "componentType", &what, None)?;
        let found = accessor.get("type").and_then(Value::as_str).unwrap_or("?");
        if component_type != 5126 || found != type_ {
            return Err(glb_err(format!(
                "{what} is {found} of component type {component_type}, expected {type_} of FLOAT (5126)"
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

    /// Accessor `i` as FLOAT VEC3s (points or directions) in halo4d's frame.
    fn vec3s(&self, i: u64) -> Result<Vec<DVec3>> {
        Ok(self
            .floats(i, "VEC3", 3)?
            .chunks_exact(3)
            .map(|c| from_gltf(DVec3::new(c[0].into(), c[1].into(), c[2].into())))
            .collect())
    }

    /// Accessor `i` as unsigned integer SCALARs (UNSIGNED_BYTE, _SHORT or _INT).
    fn unsigned(&self, i: u64) -> Result<Vec<u32>> {
        let accessor = self.item("accessors", i)?;
        let what = format!("accessors[{i}]");
        let component_type = index(accessor, "componentType", &what, None)?;
        let found = accessor.get("type").and_then(Value::as_str).unwrap_or("?");
        let size = match component_type {
            5121 => 1,
            5123 => 2,
            5125 => 4,
            _ => 0,
        };
        if size == 0 || found != "SCALAR" {
            return Err(glb_err(format!(
                "{what} is {found} of component type {component_type}, expected SCALAR of an unsigned integer type"
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
    /// indices, and its attributes.
    fn points(&self, i: usize, mesh: &'a Value, name: &str) -> Result<Points<'a>> {
        let what = format!("meshes[{i}] (`{name}`)");
        let primitive = mesh
            .get("primitives")
            .and_then(|p| p.get(0))
            .ok_or_else(|| glb_err(format!("{what} has no primitive")))?;
        let found = index(primitive, "mode", &format!("{what}.primitives[0]"), Some(4))?;
        if found != 4 {
            return Err(glb_err(format!(
                "{what} has primitives of mode {found}, expected TRIANGLES (4)"
            )));
        }
        let attributes = primitive
            .get("attributes")
            .ok_or_else(|| glb_err(format!("{what} has no attributes")))?;
        let attribute = |key: &str| -> Result<u64> {
            index(attributes, key, &format!("{what} attributes"), None)
        };
        let positions: Vec<DVec3> = self.vec3s(attribute("POSITION")?)?;
        let w: Vec<f64> = self
            .floats(attribute("_W")?, "SCALAR", 1)?
            .into_iter()
            .map(f64::from)
            .collect();
        let indices = self.unsigned(index(
            primitive,
            "indices",
            &format!("{what}.primitives[0]"),
            None,
        )?)?;
        Ok(Points {
            what,
            attributes,
            positions,
            w,
            indices,
        })
    }

    /// The surface of mesh `i`: its first primitive's POSITION, `_W`, NORMAL if any, and
    /// triangles.
    fn surface(&self, i: usize, mesh: &'a Value, name: String) -> Result<ImportedSurface> {
        let Points {
            attributes,
            positions,
            w,
            indices,
            what,
        } = self.points(i, mesh, &name)?;
        let attribute = |key: &str| -> Result<u64> {
            index(attributes, key, &format!("{what} attributes"), None)
        };
        let file_normals: Option<Vec<DVec3>> = match attributes.get("NORMAL") {
            None => None,
            Some(_) => Some(self.vec3s(attribute("NORMAL")?)?),
        };
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
        Ok(ImportedSurface {
            name,
            mesh: i,
            positions,
            w,
            triangles,
            normals,
            halo: None,
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
        let w: Vec<f64> = self
            .floats(w, "SCALAR", 1)?
            .into_iter()
            .map(f64::from)
            .collect();
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
    fn own_accessor(&self, i: u64, expected: &str) -> std::result::Result<&'a Value, String> {
        let all = self.json.get("accessors").and_then(Value::as_array);
        let accessor = all
            .and_then(|a| a.get(usize::try_from(i).ok()?))
            .ok_or_else(|| format!("does not exist (the file has {})", all.map_or(0, Vec::len)))?;
        match accessor.get("name").and_then(Value::as_str) {
            Some(n) if n == expected => {}
            Some(n) => return Err(format!("is named `{n}`, not `{expected}`")),
            None => return Err(format!("has no name (halo4d names it `{expected}`)")),
        }
        let used = self
            .json
            .get("meshes")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|m| m.get("primitives").and_then(Value::as_array))
            .flatten()
            .any(|p| {
                p.get("indices").and_then(Value::as_u64) == Some(i)
                    || p.get("attributes")
                        .and_then(Value::as_object)
                        .is_some_and(|a| a.values().any(|v| v.as_u64() == Some(i)))
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
        let type_ = accessor.get("type").and_then(Value::as_str).unwrap_or("?");
        let component = accessor.get("componentType").and_then(Value::as_u64);
        if type_ != "SCALAR" || component != Some(5125) {
            return Err(missing(format!(
                "is {type_} of component type {}, not SCALAR of UNSIGNED_INT (5125)",
                component.map_or("?".into(), |c| c.to_string())
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

    /// The halo of mesh `i`, whose extras' `halo` is `halo`.
    fn halo(&self, i: usize, mesh: &Value, halo: &Value, name: String) -> Result<ImportedHalo> {
        let what = format!("meshes[{i}] (`{name}`)");
        let extras = format!("{what}.extras.halo");
        if !halo.is_object() {
            return Err(glb_err(format!("{extras} is not an object")));
        }
        let attributes = mesh
            .get("primitives")
            .and_then(|p| p.get(0))
            .and_then(|p| p.get("attributes"))
            .ok_or_else(|| glb_err(format!("{what} has no primitive with attributes")))?;
        let attribute = |key: &str| -> Result<Option<u64>> {
            match attributes.get(key) {
                None => Ok(None),
                Some(_) => index(attributes, key, &format!("{what} attributes"), None).map(Some),
            }
        };
        let position = attribute("POSITION")?
            .ok_or_else(|| glb_err(format!("{what} has no POSITION attribute")))?;
        let positions: Vec<[f64; 3]> = self
            .vec3s(position)?
            .into_iter()
            .map(|p| p.to_array())
            .collect();
        let scalar = |key: &str| -> Result<Option<Vec<f64>>> {
            let Some(a) = attribute(key)? else {
                return Ok(None);
            };
            let values = self.floats(a, "SCALAR", 1)?;
            if values.len() != positions.len() {
                return Err(glb_err(format!(
                    "{what}: {key} has {} values for {} positions",
                    values.len(),
                    positions.len()
                )));
            }
            Ok(Some(values.into_iter().map(f64::from).collect()))
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
        Ok(ImportedHalo {
            name,
            mesh: TetMesh {
                positions,
                surface_vertices,
                tets: indices
                    .chunks_exact(4)
                    .map(|c| file_order([c[0], c[1], c[2], c[3]]))
                    .collect(),
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
                layers: number("layers"),
            },
        })
    }
}
