//! Import: halos read back from the files [`crate::export`] writes, for `halo4d check`.
//!
//! Takes: the bytes of a `.glb` (every mesh whose extras carry `halo`) or of a legacy `.vtk`
//! (an `UNSTRUCTURED_GRID` of tetrahedra whose field data has `surface_vertices`, ASCII or
//! binary, file version 2.0 to 5.1). Gives: [`ImportedHalo`]s, each a [`TetMesh`] in the
//! halo layout of [`crate::check`] with its name, per-vertex t and d_orig and parameters.
//! Guarantees: malformed input (truncated, wrong magic, bad JSON, references out of range,
//! counts that disagree, non-finite coordinates) is an [`ImportError`] that names the
//! problem, never a panic; a count claimed in a file is checked against the bytes actually
//! there before anything is allocated for it.

mod glb;
mod vtk;

pub use glb::read_glb;
pub use vtk::read_vtk;

use crate::check::TetMesh;
use std::path::Path;

/// A halo read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportedHalo {
    /// The glTF mesh name, or for VTK the title line up to its first `: `.
    pub name: String,
    /// Positions, surface vertices and tetrahedra, for [`crate::check::check`].
    pub mesh: TetMesh,
    /// t of each vertex, when the file has it.
    pub t: Option<Vec<f64>>,
    /// d_orig (w-depth) of each vertex, when the file has it.
    pub d_orig: Option<Vec<f64>>,
    /// The halo parameters the file records.
    pub params: FileParams,
}

/// The halo parameters a file records; absent ones are `None`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FileParams {
    /// Half-width, absolute.
    pub rho: Option<f64>,
    /// Depth increment delta_d (paper 000 eq. 3).
    pub delta_d: Option<f64>,
    /// Dead zone delta_t (paper 000 eq. 3).
    pub delta_t: Option<f64>,
    /// How prisms were split (`.glb` only).
    pub split: Option<String>,
    /// Index of the surface's own mesh (`.glb` only).
    pub surface_mesh: Option<usize>,
}

/// Why a file could not be read as halos.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The file could not be read at all.
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// The file name says neither `.glb` nor `.vtk`.
    #[error("unknown file type `{0}`: give a .glb or a .vtk file written by halo4d build")]
    UnknownType(String),
    /// The bytes are not a well-formed `.glb`.
    #[error("not a valid .glb: {0}")]
    Glb(String),
    /// The bytes are not a well-formed legacy VTK file.
    #[error("not a valid legacy VTK file: {0}")]
    Vtk(String),
    /// The file is well formed but carries no halo in halo4d's layout.
    #[error("{0}")]
    NoHalo(String),
    /// A halo's data break the layout: an index out of range, a non-finite coordinate, ...
    #[error("halo `{name}`: {message}")]
    BadHalo {
        /// The halo.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// Reads the halos of a `.glb` or `.vtk` file, chosen by its extension.
pub fn read(path: &Path) -> Result<Vec<ImportedHalo>, ImportError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "glb" => read_glb(&std::fs::read(path)?),
        "vtk" => Ok(vec![read_vtk(&std::fs::read(path)?)?]),
        _ => Err(ImportError::UnknownType(if ext.is_empty() {
            "(no extension)".into()
        } else {
            format!(".{ext}")
        })),
    }
}

impl ImportedHalo {
    /// Checks what the checker takes for granted: finite values, at least the 2n offset
    /// vertices, indices in range, one t and d_orig per vertex.
    fn validate(self) -> Result<Self, ImportError> {
        let bad = |message: String| ImportError::BadHalo {
            name: self.name.clone(),
            message,
        };
        let nv = self.mesh.positions.len();
        if let Some(i) = self
            .mesh
            .positions
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            let [x, y, z] = self.mesh.positions[i];
            return Err(bad(format!(
                "vertex {i} has a non-finite coordinate ({x}, {y}, {z})"
            )));
        }
        let n = self.mesh.surface_vertices;
        if n.checked_mul(2).is_none_or(|two_n| two_n > nv) {
            return Err(bad(format!(
                "surface_vertices = {n} needs the 2n = {} offset vertices, but the halo has {nv} vertices",
                n.saturating_mul(2)
            )));
        }
        for (k, tet) in self.mesh.tets.iter().enumerate() {
            if let Some(&i) = tet.iter().find(|&&i| i as usize >= nv) {
                return Err(bad(format!(
                    "tetrahedron {k} names vertex {i}, but there are only {nv} vertices"
                )));
            }
        }
        for (what, values) in [("t", &self.t), ("d_orig", &self.d_orig)] {
            let Some(values) = values else { continue };
            if values.len() != nv {
                return Err(bad(format!(
                    "{} values of {what} for {nv} vertices",
                    values.len()
                )));
            }
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(bad(format!(
                    "{what} of vertex {i} is not finite ({})",
                    values[i]
                )));
            }
        }
        Ok(self)
    }
}
