//! Wavefront OBJ of the projected surfaces: one object per surface with positions and
//! normals. OBJ has no per-vertex scalar, so w is not in it: use the PLY or the glTF.

use super::SurfaceData;
use std::fmt::Write;

/// Builds the OBJ text.
pub fn to_obj(surfaces: &[SurfaceData], scene_name: &str) -> String {
    let mut out = format!(
        "# halo4d {}: scene {scene_name}\n",
        env!("CARGO_PKG_VERSION")
    );
    let mut base = 1usize;
    for s in surfaces {
        let p = s.projected;
        let _ = writeln!(out, "o {}", s.name);
        for v in &p.positions {
            let _ = writeln!(out, "v {} {} {}", v.x, v.y, v.z);
        }
        for n in &p.normals {
            let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
        }
        for t in &s.mesh.triangles {
            let [a, b, c] = t.map(|i| base + i as usize);
            let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
        }
        base += p.positions.len();
    }
    out
}
