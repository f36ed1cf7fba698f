//! Binary PLY of the projected surfaces, for MeshLab.

use super::SurfaceData;

/// Builds a binary little-endian PLY with all surfaces in one mesh: per vertex x, y, z,
/// nx, ny, nz, `quality` (the w-depth, which MeshLab keeps as its per-vertex scalar), u, v,
/// and integer `surface` and `patch`; faces as `vertex_indices` lists.
pub fn to_ply(surfaces: &[SurfaceData], scene_name: &str) -> Vec<u8> {
    let vertices: usize = surfaces.iter().map(|s| s.projected.positions.len()).sum();
    let faces: usize = surfaces.iter().map(|s| s.mesh.triangles.len()).sum();
    let names: Vec<&str> = surfaces.iter().map(|s| s.name).collect();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\n\
         comment halo4d {}: scene {scene_name}; quality is the w-depth\n\
         comment surfaces: {}\n\
         element vertex {vertices}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property float quality\nproperty float u\nproperty float v\n\
         property int surface\nproperty int patch\n\
         element face {faces}\n\
         property list uchar int vertex_indices\n\
         end_header\n",
        env!("CARGO_PKG_VERSION"),
        names.join(" "),
    );
    let mut out = header.into_bytes();
    out.reserve(vertices * 44 + faces * 13);
    for (k, s) in surfaces.iter().enumerate() {
        let p = s.projected;
        for i in 0..p.positions.len() {
            let [u, v] = s.mesh.uv[i];
            let floats = [
                p.positions[i].x,
                p.positions[i].y,
                p.positions[i].z,
                p.normals[i].x,
                p.normals[i].y,
                p.normals[i].z,
                p.w[i],
                u,
                v,
            ];
            for f in floats {
                out.extend_from_slice(&(f as f32).to_le_bytes());
            }
            out.extend_from_slice(&(k as i32).to_le_bytes());
            out.extend_from_slice(&(s.mesh.patch[i] as i32).to_le_bytes());
        }
    }
    let mut base = 0usize;
    for s in surfaces {
        for t in &s.mesh.triangles {
            out.push(3);
            for i in t {
                out.extend_from_slice(&((base + *i as usize) as i32).to_le_bytes());
            }
        }
        base += s.projected.positions.len();
    }
    out
}
