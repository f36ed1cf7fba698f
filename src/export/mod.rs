//! Export: the products of a build as files.
//!
//! Takes: the sampled and projected surfaces. Gives: `.glb` (glTF 2.0 binary, for Blender),
//! `.ply` (binary PLY with w as vertex `quality`, for MeshLab), `.obj` (Wavefront, positions
//! and normals only) and `report.json`. Guarantees: every file is written to a temporary
//! name and renamed into place, so a failure never leaves a half-written file.

mod gltf;
mod obj;
mod plot;
mod ply;

pub use gltf::to_glb;
pub use obj::to_obj;
pub use plot::{encode_png, speed_vs_error_png};
pub use ply::to_ply;

use crate::sample::Mesh4;
use crate::view::Projected;
use std::io::Write;
use std::path::Path;

/// What the writers need of one surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceData<'a> {
    /// Mesh name.
    pub name: &'a str,
    /// Catalogue type of the surface.
    pub surface_type: &'a str,
    /// Number of parameter patches.
    pub patches: usize,
    /// The 4D mesh (triangles, parameters, patches).
    pub mesh: &'a Mesh4,
    /// Its projection (3D positions, w-depth, normals).
    pub projected: &'a Projected,
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.partial"));
    let result = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
