//! Binary PLY of the projected surfaces and of the intersection curves, for MeshLab.

use super::SurfaceData;
use crate::intersect::Curves;
use crate::motion::Polyline;
use crate::render::stipple::Drawn;

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

/// Builds a binary little-endian PLY of the stipples a picture draws (`<name>-stipples.ply`):
/// a point cloud, per stipple x, y, z, `radius` (its disc's radius in scene units, which
/// MeshLab keeps as its per-vertex radius), `quality` (its w-depth), `surface` and `rank`
/// (its place in the surface's ranking). No faces.
pub fn to_stipples_ply(stipples: &[Drawn], scene_name: &str) -> Vec<u8> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\n\
         comment halo4d {}: scene {scene_name}; the stipples of its picture, quality is the w-depth\n\
         element vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float radius\nproperty float quality\n\
         property int surface\nproperty int rank\n\
         end_header\n",
        env!("CARGO_PKG_VERSION"),
        stipples.len(),
    );
    let mut out = header.into_bytes();
    out.reserve(stipples.len() * 28);
    for d in stipples {
        let p = d.position;
        for f in [p.x, p.y, p.z, d.radius, d.w] {
            out.extend_from_slice(&(f as f32).to_le_bytes());
        }
        out.extend_from_slice(&(d.surface as i32).to_le_bytes());
        out.extend_from_slice(&(d.rank as i32).to_le_bytes());
    }
    out
}

/// Builds a binary little-endian PLY of the intersection curves (`<name>-curves.ply`): per
/// curve point x, y, z, `quality` (dw, the far sheet's w minus the near sheet's, which
/// MeshLab keeps as its per-vertex scalar), `w_near`, `w_far` and `curve` (the curve's index):
/// the point and both w as double, which keeps the refined curves' 1e-15, the quality and
/// the index as float; per line segment an `edge` of `int vertex1, int vertex2` (consecutive points,
/// and a closed curve's last back to its first). No curves give a valid file with no vertex
/// and no edge.
pub fn to_curves_ply(curves: &Curves, scene_name: &str) -> Vec<u8> {
    let vertices: usize = curves.curves.iter().map(|c| c.points.len()).sum();
    let segments = curves.segments();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\n\
         comment halo4d {}: scene {scene_name}; intersection curves, quality is w_far - w_near\n\
         element vertex {vertices}\n\
         property double x\nproperty double y\nproperty double z\n\
         property float quality\nproperty double w_near\nproperty double w_far\n\
         property float curve\n\
         element edge {}\n\
         property int vertex1\nproperty int vertex2\n\
         end_header\n",
        env!("CARGO_PKG_VERSION"),
        segments.len(),
    );
    let mut out = header.into_bytes();
    out.reserve(vertices * 48 + segments.len() * 8);
    for (k, c) in curves.curves.iter().enumerate() {
        for p in &c.points {
            // The points and both sheets' w in f64, as refined (to about 1e-15); the quality
            // and the curve's number, which only colour and group, in f32.
            let near = p.near();
            for x in p.position.to_array() {
                out.extend_from_slice(&x.to_le_bytes());
            }
            out.extend_from_slice(&(p.dw() as f32).to_le_bytes());
            out.extend_from_slice(&p.w[near].to_le_bytes());
            out.extend_from_slice(&p.w[1 - near].to_le_bytes());
            out.extend_from_slice(&(k as f32).to_le_bytes());
        }
    }
    for s in segments {
        for i in s {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    out
}

/// A still's curves as a binary little-endian PLY: per point x, y, z in the hyperplane's
/// frame (double) and its curve's index (float); per segment an `edge` (a closed curve's
/// last point back to its first).
pub fn to_still_ply(curves: &[Polyline], level: f64, name: &str) -> Vec<u8> {
    let vertices: usize = curves.iter().map(|c| c.0.len()).sum();
    let edges: usize = curves
        .iter()
        .map(|(p, closed)| {
            if *closed {
                p.len()
            } else {
                p.len().saturating_sub(1)
            }
        })
        .sum();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\n\
         comment halo4d {}: surface {name}, slice at level {level:e}, in the hyperplane's frame\n\
         element vertex {vertices}\n\
         property double x\nproperty double y\nproperty double z\nproperty float curve\n\
         element edge {edges}\n\
         property int vertex1\nproperty int vertex2\n\
         end_header\n",
        env!("CARGO_PKG_VERSION"),
    );
    let mut out = header.into_bytes();
    for (k, (points, _)) in curves.iter().enumerate() {
        for p in points {
            for x in p.to_array() {
                out.extend_from_slice(&x.to_le_bytes());
            }
            out.extend_from_slice(&(k as f32).to_le_bytes());
        }
    }
    let mut first = 0i32;
    for curve in curves {
        let n = curve.0.len() as i32;
        for i in 0..segments(curve) as i32 {
            for v in [first + i, first + (i + 1) % n] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        first += n;
    }
    out
}

/// The segments of a curve: one per point when it closes, else one fewer.
pub fn segments((points, closed): &Polyline) -> usize {
    if *closed {
        points.len()
    } else {
        points.len().saturating_sub(1)
    }
}
