//! glTF 2.0 binary (`.glb`) export with gltf-json.
//!
//! One mesh per surface, named after it, as TRIANGLES with POSITION (min/max computed from the
//! f32 values actually stored), unit NORMAL, and float SCALAR custom attributes `_W`
//! (w-depth), `_U`, `_V` (surface parameters) and `_PATCH` (patch index). Floats, because
//! Blender 3.5+ imports float attributes and drops integer ones. Each attribute has its own
//! tightly packed, 4-byte aligned buffer view. The asset's extras record the scene as parsed.

use super::SurfaceData;
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use serde_json::value::to_raw_value;

/// Base colours of the surfaces' materials, in turn.
const PALETTE: [[f32; 4]; 6] = [
    [0.85, 0.62, 0.25, 1.0],
    [0.30, 0.55, 0.85, 1.0],
    [0.45, 0.75, 0.40, 1.0],
    [0.80, 0.35, 0.45, 1.0],
    [0.60, 0.45, 0.80, 1.0],
    [0.85, 0.85, 0.85, 1.0],
];

/// Accumulates the binary chunk and the JSON objects that describe it.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// Appends a buffer view with `bytes`, aligned to 4 bytes.
    fn view(
        &mut self,
        bytes: &[u8],
        target: json::buffer::Target,
    ) -> json::Index<json::buffer::View> {
        debug_assert_eq!(self.bin.len() % 4, 0);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
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
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, json::buffer::Target::ArrayBuffer);
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
}

/// Builds the `.glb` bytes for the surfaces; `scene_json` goes into the asset's extras.
pub fn to_glb(surfaces: &[SurfaceData], scene_json: &serde_json::Value) -> Result<Vec<u8>, String> {
    let extras = |v: serde_json::Value| to_raw_value(&v).map(Some).map_err(|e| e.to_string());
    let mut b = Builder {
        root: json::Root {
            asset: json::Asset {
                generator: Some(format!("halo4d {}", env!("CARGO_PKG_VERSION"))),
                extras: extras(serde_json::json!({ "halo4d": { "scene": scene_json } }))?,
                ..Default::default()
            },
            ..Default::default()
        },
        bin: Vec::new(),
    };
    let mut nodes = Vec::new();
    for (k, s) in surfaces.iter().enumerate() {
        let p = s.projected;
        let positions: Vec<f32> = p
            .positions
            .iter()
            .flat_map(|v| v.as_vec3().to_array())
            .collect();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for c in positions.chunks_exact(3) {
            for i in 0..3 {
                lo[i] = lo[i].min(c[i]);
                hi[i] = hi[i].max(c[i]);
            }
        }
        let normals: Vec<f32> = p
            .normals
            .iter()
            .flat_map(|n| n.as_vec3().normalize().to_array())
            .collect();
        let scalar = |f: &dyn Fn(usize) -> f64| {
            (0..p.positions.len())
                .map(|i| f(i) as f32)
                .collect::<Vec<f32>>()
        };
        use json::accessor::Type::{Scalar, Vec3};
        use json::mesh::Semantic;
        let attributes = [
            (
                Semantic::Positions,
                b.floats(&positions, Vec3, Some((lo.to_vec(), hi.to_vec()))),
            ),
            (Semantic::Normals, b.floats(&normals, Vec3, None)),
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
        let indices: Vec<u8> = s
            .mesh
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let index_view = b.view(&indices, json::buffer::Target::ElementArrayBuffer);
        let index_accessor = b.root.push(json::Accessor {
            buffer_view: Some(index_view),
            byte_offset: None,
            count: USize64::from(s.mesh.triangles.len() * 3),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: None,
            type_: Valid(Scalar),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        });
        let material = b.root.push(json::Material {
            name: Some(s.name.to_string()),
            double_sided: true,
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(PALETTE[k % PALETTE.len()]),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.6),
                ..Default::default()
            },
            ..Default::default()
        });
        let mesh = b.root.push(json::Mesh {
            name: Some(s.name.to_string()),
            extras: extras(serde_json::json!({
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
        nodes.push(b.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(s.name.to_string()),
            ..Default::default()
        }));
    }
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: Some("halo4d".into()),
        nodes,
    });
    b.root.scene = Some(scene);
    b.root.push(json::Buffer {
        byte_length: USize64::from(b.bin.len()),
        name: None,
        uri: None,
        extensions: None,
        extras: None,
    });
    let text = b.root.to_vec().map_err(|e| e.to_string())?;
    Ok(glb_container(text, b.bin))
}

/// Wraps JSON and binary chunks in the GLB container (header, JSON chunk padded with spaces,
/// BIN chunk padded with zeros).
fn glb_container(mut text: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    text.resize(text.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}
