//! Import: halos and surfaces read back from the files [`crate::export`] writes, and other
//! programs' tetrahedral meshes, for `halo4d check`.
//!
//! Takes: the bytes of a `.glb` (every mesh whose extras carry `halo`) or of a legacy `.vtk`
//! (an `UNSTRUCTURED_GRID` of tetrahedra whose field data has `surface_vertices`, ASCII or
//! binary, file version 2.0 to 5.1). Gives: [`ImportedHalo`]s, each a [`TetMesh`] in the
//! halo layout of [`crate::check`] with its name, per-vertex t and d_orig and parameters;
//! from a scene's `.glb` also its surfaces ([`read_scene_glb`]: positions, w-depth and
//! triangles, each with its halo, and the curves' polylines), which [`ImportedScene::parts`] hands on as the
//! verification and the renderer read a build.
//!
//! Also takes the tetrahedral meshes other programs write, which have no halo layout and
//! become [`PlainTetrahedra`] ([`read`] chooses by the extension):
//! - VTU, VTK's XML `UnstructuredGrid` ([`read_vtu`]): data arrays `ascii`, `binary`
//!   (base64) or `appended` (`raw` or `base64`), with UInt32 or UInt64 headers, plain or
//!   compressed (`vtkZLibDataCompressor`, `vtkLZ4DataCompressor`, `vtkLZMADataCompressor`),
//!   little- or big-endian; an inline array's data are its own text, child elements (VTK 9's
//!   `InformationKey`) and comments read past;
//! - PVTU, VTK's parallel XML `PUnstructuredGrid` ([`read_pvtu`]): its pieces' `.vtu` files
//!   (paths relative to the `.pvtu`'s folder), read side by side and joined into one mesh,
//!   a point of a piece welded to the point of an earlier piece at exactly its coordinates;
//!   which piece each tetrahedron came from is kept ([`PlainTetrahedra::piece_of`]);
//! - Gmsh `.msh` 2.2 and 4.1, ASCII and binary ([`read_gmsh`]): `$Nodes` (or, in 2.2,
//!   `$ParametricNodes`; in 4.1, entity blocks of parametric nodes) and `$Elements`, node tags
//!   sparse or in any order (vertices come in the order of their tags), every other section
//!   skipped to its `$End` line;
//! - Medit `.mesh`, ASCII ([`read_medit`]): `Vertices` and `Tetrahedra` (indices from 1),
//!   other sections skipped;
//! - TetGen `.node` with its `.ele` ([`read_tetgen`]): indices from 0 or 1 as the `.node`
//!   file's first says, 4 or 10 nodes per tetrahedron, attributes and markers skipped;
//! - legacy `.vtk` without halo4d's layout ([`read_vtk_tetrahedra`]), every array it does not
//!   need read past whatever its type (strings, bits, ...), with its METADATA.
//!
//! A text file (or an XML one) may begin with a UTF-8 byte-order mark: each reader skips it,
//! and byte offsets in errors stay the file's.
//!
//! In each, a tetrahedron (quadratic and higher-order ones: their first four nodes, the
//! corners) is read, a cell of lower dimension (point, line, triangle, quadrilateral) is
//! skipped, and any other solid (hexahedron, prism, pyramid, ...) is an error that says how
//! many of which kind: halo4d checks tetrahedral meshes. All these formats take a tetrahedron
//! (a, b, c, d) as positive when det[b − a, c − a, d − a] > 0: VTK and Gmsh by their
//! reference elements; Medit by P. L. George's convention for INRIA's meshes (the trihedron
//! (ab, ac, ad) direct); TetGen by its sources, for which d lies "above" the plane of a, b, c
//! (Shewchuk's orient3d < 0); and meshio hands tetrahedra between all four unchanged.
//! halo4d's orientation is the opposite, converted at the file boundary
//! ([`crate::convention::file_order`]). They are read from the file's bytes in one pass,
//! without a token list of the whole file: a 10 million tetrahedra binary file reads in
//! seconds.
//!
//! Guarantees: malformed input (truncated, wrong magic, bad JSON, bad base64, zlib, LZ4 or xz,
//! references out of range, counts that disagree, non-finite coordinates) is an
//! [`ImportError`] that names the problem, and for other programs' meshes the line (text) or
//! byte offset (binary) where it is ([`ImportError::Tetrahedra`]), never a panic; a count
//! claimed in a file is checked against the bytes actually there before anything is
//! allocated for it; everything comes back in halo4d's frame and orientation
//! (`convention`); an accessor that another program re-used (the tetrahedra's, the
//! polylines') is never read as ours.

mod glb;
mod gmsh;
mod medit;
mod mesh;
mod pvtu;
mod tetfile;
mod tetgen;
mod vtk;
mod vtu;

pub use crate::certify::{Solid, SolidKind};
pub use glb::{read_glb, read_scene_glb};
pub use gmsh::read_gmsh;
pub use medit::read_medit;
pub use mesh::{MeshFileError, MeshFileLocation, MeshFormat, parse_mesh4, read_mesh4};
pub use pvtu::read_pvtu;
pub use tetgen::read_tetgen;
pub use vtk::{read_vtk, read_vtk_tetrahedra};
pub use vtu::read_vtu;

use crate::check::{LAYERS, TetMesh};
use crate::intersect::Curves;
use crate::limits::shorten;
use crate::parts::{HaloPart, Parts, SurfacePart};
use crate::render::CameraSettings;
use glam::DVec3;
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

/// A surface read from a scene's `.glb`, with its halo.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedSurface {
    /// The glTF mesh name (the surface's name in the scene).
    pub name: String,
    /// Index of its glTF mesh.
    pub mesh: usize,
    /// Projected positions, as stored (f32 values, widened).
    pub positions: Vec<DVec3>,
    /// w-depth of each vertex (`_W`).
    pub w: Vec<f64>,
    /// Triangles, none of which repeats a vertex.
    pub triangles: Vec<[u32; 3]>,
    /// Unit normal of each vertex: the file's `NORMAL`, or where it has none, the normalized
    /// sum of the area-weighted normals of the triangles around the vertex.
    pub normals: Vec<DVec3>,
    /// Its halo, when the file has one: with t, d_orig, delta_d and delta_t, and as many
    /// surface vertices as the surface has vertices.
    pub halo: Option<ImportedHalo>,
    /// The 4D mesh before the view (positions and tangents from the file's twelve 4D
    /// attributes, `_X4` to `_WV4`; the surface's triangles; no (u, v)), or why the file has
    /// none.
    pub mesh_4d: Result<crate::sample::Mesh4, String>,
}

/// A scene read from its `.glb` ([`read_scene_glb`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportedScene {
    /// The scene's name, from the asset's extras, when recorded.
    pub name: Option<String>,
    /// Its surfaces, in the file's order.
    pub surfaces: Vec<ImportedSurface>,
    /// The intersection curves' exact polylines (named by the `curves` mesh's extras), when
    /// the file has them and no other program re-used their accessors.
    pub curves: Option<ImportedCurves>,
    /// The camera the scene was built with (`camera` of the scene recorded in the asset's
    /// extras), when recorded.
    pub camera: Option<CameraSettings>,
    /// The scene recorded in the asset's extras (`halo4d.scene`), as JSON, when recorded.
    pub scene: Option<serde_json::Value>,
}

/// The intersection curves of a scene's `.glb`, as line segments.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportedCurves {
    /// Curve points.
    pub positions: Vec<DVec3>,
    /// w of the nearer sheet at each point (`_W`).
    pub w: Vec<f64>,
    /// Segments between points.
    pub segments: Vec<[u32; 2]>,
}

impl ImportedScene {
    /// The scene as the verification, the renderer and the viewer read it, with `curves`
    /// (recomputed from [`Parts::sheets`], as `halo4d check DIR` does, or none). A halo
    /// without tetrahedra, t, d_orig, delta_d or delta_t counts as none; a surface has no
    /// (u, v).
    pub fn parts<'a>(&'a self, curves: &'a Curves) -> Parts<'a> {
        Parts {
            surfaces: self
                .surfaces
                .iter()
                .map(|s| SurfacePart {
                    positions: &s.positions,
                    w: &s.w,
                    normals: &s.normals,
                    uv: None,
                    triangles: &s.triangles,
                    stipples: None,
                })
                .collect(),
            halos: self
                .surfaces
                .iter()
                .map(|s| {
                    let h = s.halo.as_ref().filter(|h| !h.mesh.tets.is_empty())?;
                    Some(HaloPart {
                        positions: bytemuck::cast_slice(&h.mesh.positions),
                        t: h.t.as_deref()?,
                        d_orig: h.d_orig.as_deref()?,
                        tets: &h.mesh.tets,
                        surface_vertices: h.mesh.surface_vertices,
                        delta_d: h.params.delta_d?,
                        delta_t: h.params.delta_t?,
                    })
                })
                .collect(),
            curves,
        }
    }
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
    /// The vertices of that surface mesh, which must be the halo's surface vertices.
    pub surface_mesh_vertices: Option<usize>,
    /// Layers of prisms the halo's layout has (`LAYERS`, 2: the offsets, then the surface itself).
    pub layers: Option<f64>,
}

/// Why a file could not be read as halos.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The file could not be read at all.
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// The file name's extension is none that [`read`] takes.
    #[error(
        "unknown file type `{}`: halo4d reads tetrahedral meshes from .vtu and .pvtu (VTK XML), .vtk (legacy VTK), .msh (Gmsh 2.2 or 4.1), .mesh (Medit), .node with .ele (TetGen), and halos from .glb or .vtk files halo4d build wrote",
        shorten(.0)
    )]
    UnknownType(String),
    /// Another program's tetrahedral mesh (VTU, PVTU, Gmsh, Medit, TetGen) that is malformed
    /// or holds other solids than tetrahedra. Displays like `Gmsh 4.1 binary, byte 96: ...`,
    /// `Medit .mesh, line 12: ...` or `PVTU ball.pvtu, piece ball_3.vtu (VTU appended raw
    /// zlib), byte 523: ...`.
    #[error("{format}{}: {}", tetfile::location(.at), shorten(.message))]
    Tetrahedra {
        /// The format as far as it was read (`Gmsh 4.1 binary`, `VTU`), or which of a
        /// format's files (`TetGen cube.node`).
        format: String,
        /// Where in the file: a line of text, or a byte offset.
        at: MeshFileLocation,
        /// What is wrong.
        message: String,
    },
    /// The bytes are not a well-formed `.glb`.
    #[error("not a valid .glb: {}", shorten(.0))]
    Glb(String),
    /// The bytes are not a well-formed legacy VTK file.
    #[error("not a valid legacy VTK file: {}", shorten(.0))]
    Vtk(String),
    /// The file is well formed but carries no halo in halo4d's layout.
    #[error("{}", shorten(.0))]
    NoHalo(String),
    /// The file is well formed but carries no surface in halo4d's layout.
    #[error("{}", shorten(.0))]
    NoSurface(String),
    /// A surface's data break the layout: an index out of range, a non-finite coordinate, ...
    #[error("surface `{}`: {}", shorten(.name), shorten(.message))]
    BadSurface {
        /// The surface.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A halo mesh whose extras name tetrahedra that the file does not hold as halo4d
    /// writes them: an accessor that another program re-used for something else.
    #[error(
        "this file has no tetrahedra for {} (a program that re-saved it may have dropped them): {}",
        shorten(.mesh),
        shorten(.why)
    )]
    NoTetrahedra {
        /// The halo mesh.
        mesh: String,
        /// What the accessor the extras name is instead.
        why: String,
    },
    /// A halo's data break the layout: an index out of range, a non-finite coordinate, ...
    #[error("halo `{}`: {}", shorten(.name), shorten(.message))]
    BadHalo {
        /// The halo.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// Tetrahedra without a halo layout break what the checker takes for granted.
    #[error("mesh `{}`: {}", shorten(.name), shorten(.message))]
    BadTetrahedra {
        /// The mesh's name (the title).
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// Reads the tetrahedra of a file, chosen by its extension (in any case): the halos of a
/// `.glb`, or of a `.vtk` in halo4d's layout; the tetrahedra alone of another program's
/// `.vtk`, `.vtu`, `.pvtu` (and the pieces it names), `.msh` (Gmsh), `.mesh` (Medit), or
/// `.node` and `.ele` (TetGen: given either, the other with the same stem is read too).
pub fn read(path: &Path) -> Result<FileTetrahedra, ImportError> {
    // A path that is not there is that, whatever its extension says.
    std::fs::metadata(path)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let plain = |read: Result<PlainTetrahedra, ImportError>| read.map(FileTetrahedra::Plain);
    match ext.as_str() {
        "glb" => read_glb(&std::fs::read(path)?).map(FileTetrahedra::Halos),
        "vtk" => read_vtk_tetrahedra(&std::fs::read(path)?),
        "vtu" => plain(read_vtu(&std::fs::read(path)?, &name)),
        "pvtu" => plain(read_pvtu(path)),
        "msh" => plain(read_gmsh(&std::fs::read(path)?, &name)),
        "mesh" => plain(read_medit(&std::fs::read(path)?, &name)),
        "node" | "ele" => plain(tetgen::read_tetgen_files(path, &name)),
        _ => Err(ImportError::UnknownType(if ext.is_empty() {
            "(no extension)".into()
        } else {
            format!(".{ext}")
        })),
    }
}

/// The tetrahedra of a file, as `halo4d check` reads them ([`read`]).
#[derive(Clone, Debug, PartialEq)]
pub enum FileTetrahedra {
    /// Halos in halo4d's layout (every halo of a `.glb`; a `.vtk` that gives the layout).
    Halos(Vec<ImportedHalo>),
    /// Tetrahedra without halo4d's layout: another program's mesh (`.vtk`, `.vtu`, `.pvtu`,
    /// `.msh`, `.mesh`, `.node`/`.ele`).
    Plain(PlainTetrahedra),
}

/// Tetrahedra without halo4d's halo layout (another program's mesh, or an earlier
/// halo4d's `.vtk`): what [`crate::check::check_tetrahedra`] checks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlainTetrahedra {
    /// For a legacy `.vtk`, the title up to its first `: `; otherwise the file's stem.
    pub name: String,
    /// Vertex positions, all finite.
    pub positions: Vec<[f64; 3]>,
    /// Four vertex indices each, all in range, positively oriented in halo4d's convention.
    pub tets: Vec<[u32; 4]>,
    /// Why the file is not read as a halo: what says that halo4d's layout is missing.
    pub why: String,
    /// The format read: `legacy VTK ASCII`, `VTU appended raw zlib`, `Gmsh 4.1 binary`,
    /// `Medit .mesh`, `TetGen .node/.ele`, `PVTU, 8 pieces (VTU appended raw zlib)`, ...
    pub format: String,
    /// The files of a `.pvtu`'s pieces, in its order, as it names them (relative to its
    /// folder); empty for a mesh of one file.
    pub pieces: Vec<String>,
    /// For each tetrahedron, then each of [`PlainTetrahedra::solids`], the index in
    /// [`PlainTetrahedra::pieces`] of the piece it came from; empty for a mesh of one file
    /// (else as long as `tets` and `solids` together).
    pub piece_of: Vec<u32>,
    /// The hexahedra, wedges and pyramids of a mixed mesh, as the file gives them (their
    /// corners in VTK's order); empty for a mesh of tetrahedra only.
    pub solids: Vec<Solid>,
}

impl PlainTetrahedra {
    /// Another program's tetrahedra given in memory (a PyVista grid's, a meshio mesh's,
    /// arrays), in VTK's and Gmsh's convention as the files have them (a, b, c, d positive
    /// when det[b − a, c − a, d − a] > 0), converted to halo4d's (`convention`); `format`
    /// says where they came from. Non-finite positions and indices out of range are an
    /// [`ImportError::BadTetrahedra`].
    pub fn from_arrays(
        name: &str,
        format: &str,
        positions: Vec<[f64; 3]>,
        tets: &[[u32; 4]],
    ) -> Result<Self, ImportError> {
        PlainTetrahedra {
            name: name.to_string(),
            positions,
            tets: tets
                .iter()
                .map(|&t| crate::convention::file_order(t))
                .collect(),
            why: format!("{format}, which has no halo layout (another program's tetrahedra)"),
            format: format.to_string(),
            pieces: Vec::new(),
            piece_of: Vec::new(),
            solids: Vec::new(),
        }
        .validate()
    }

    /// The mesh with `solids` (hexahedra, wedges, pyramids in VTK's corner order) beside its
    /// tetrahedra; corners out of range are an [`ImportError::BadTetrahedra`].
    pub fn with_solids(mut self, solids: Vec<Solid>) -> Result<Self, ImportError> {
        self.solids = solids;
        self.validate()
    }

    /// Checks what the checker takes for granted: finite positions, indices in range, and
    /// for a mesh of pieces, a piece for each tetrahedron.
    fn validate(self) -> Result<Self, ImportError> {
        let bad = |message: String| ImportError::BadTetrahedra {
            name: self.name.clone(),
            message,
        };
        if let Some(i) = self
            .positions
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            let [x, y, z] = self.positions[i];
            return Err(bad(format!(
                "vertex {i} has a non-finite coordinate ({x}, {y}, {z})"
            )));
        }
        let nv = self.positions.len();
        for (k, tet) in self.tets.iter().enumerate() {
            if let Some(&i) = tet.iter().find(|&&i| i as usize >= nv) {
                return Err(bad(format!(
                    "tetrahedron {k} names vertex {i}, but there are only {nv} vertices"
                )));
            }
        }
        // A hexahedron or wedge is certified around a vertex of its own.
        let apexes = self
            .solids
            .iter()
            .filter(|s| s.kind != SolidKind::Pyramid)
            .count();
        if nv + apexes > u32::MAX as usize {
            return Err(bad(format!(
                "{nv} vertices and {apexes} hexahedra and wedges: more than the {} vertices halo4d's certificate can number with the vertex it adds inside each of these",
                u32::MAX
            )));
        }
        for s in &self.solids {
            if let Some(&i) = s.used().iter().find(|&&i| i as usize >= nv) {
                return Err(bad(format!(
                    "{} {} names vertex {i}, but there are only {nv} vertices",
                    s.kind.name(),
                    s.id
                )));
            }
        }
        if !self.pieces.is_empty() || !self.piece_of.is_empty() {
            let np = self.pieces.len();
            if self.piece_of.len() != self.tets.len() + self.solids.len() {
                return Err(bad(format!(
                    "{} pieces recorded for {} cells",
                    self.piece_of.len(),
                    self.tets.len() + self.solids.len()
                )));
            }
            if let Some(k) = self.piece_of.iter().position(|&p| p as usize >= np) {
                return Err(bad(format!(
                    "cell {k} came from piece {}, but there are {np} pieces",
                    self.piece_of[k]
                )));
            }
        }
        Ok(self)
    }
}

impl ImportedHalo {
    /// Checks what the checker takes for granted: the layout of [`crate::check`] (its number
    /// of layers), finite values, at least the 3n offset and surface vertices, indices in
    /// range, one t and d_orig per vertex.
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
        match self.params.layers {
            Some(l) if l == LAYERS as f64 => {}
            Some(l) => {
                return Err(bad(format!(
                    "layers = {l}, but halo4d {} reads halos of {LAYERS} layers of prisms (offsets, then the surface itself); build the scene again with this halo4d",
                    env!("CARGO_PKG_VERSION")
                )));
            }
            None => {
                return Err(bad(format!(
                    "the file does not say its halo layout (`layers`): an earlier halo4d wrote it, with one layer of prisms and no surface vertices among the halo's; build the scene again with halo4d {}",
                    env!("CARGO_PKG_VERSION")
                )));
            }
        }
        let n = self.mesh.surface_vertices;
        if n.checked_mul(3).is_none_or(|three_n| three_n > nv) {
            return Err(bad(format!(
                "surface_vertices = {n} needs the 3n = {} offset and surface vertices, but the halo has {nv} vertices",
                n.saturating_mul(3)
            )));
        }
        if let Some(m) = self.params.surface_mesh_vertices.filter(|&m| m != n) {
            return Err(bad(format!(
                "surface_vertices = {n}, but its surface (meshes[{}]) has {m} vertices",
                self.params.surface_mesh.unwrap_or_default()
            )));
        }
        for (k, t) in self.mesh.surface_triangles.iter().enumerate() {
            if let Some(&v) = t.iter().find(|&&v| v as usize >= n) {
                return Err(bad(format!(
                    "surface triangle {k} names vertex {v}, but the surface has {n} vertices (surface_vertices)"
                )));
            }
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
