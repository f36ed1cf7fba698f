//! Triangle meshes in R^4 read from files, for surfaces that are not in the catalogue.
//!
//! Takes: the bytes of a mesh file in one of three formats ([`MeshFormat`]):
//!
//! - the Geomview OOGL OFF family: the header keyword `[ST][C][N][4][n]OFF`, optionally
//!   followed by `BINARY`. halo4d reads `4OFF` (four numbers per vertex) and `nOFF` whose
//!   dimension is 4 (`4nOFF` when the dimension plus one makes 4). Geomview itself may treat
//!   the fourth number of `4OFF` as a homogeneous component of a 3D point; 4D viewers such as
//!   Hanson's MeshView, and halo4d, read the four numbers x y z w as a point of R^4. The
//!   prefixes add numbers per vertex, in the file after the coordinates in this order: N a
//!   normal (3 numbers), C a colour (4), ST texture coordinates (2); they are read past. A
//!   text file holds one vertex and one face per line, `#` comments and blank lines anywhere;
//!   a face is `n i1 ... in` followed by an optional face colour, which is ignored.
//!   `BINARY` files are big-endian, per Geomview's binary format: after the header line, the
//!   dimension (nOFF only) and the counts as int32, each vertex's numbers as float32, each
//!   face as int32 n, n int32 indices, an int32 count of colour components (0 to 4) and that
//!   many float32.
//! - OBJ with four numbers per vertex (`v x y z w`), faces `f` with `i`, `i/t`, `i//n` or
//!   `i/t/n` references, counted from 1 or, negative, back from the last vertex so far.
//!   Every other statement (vn, vt, o, g, s, usemtl, mtllib, l, p, unknown ones) is ignored,
//!   and a backslash does not continue a line.
//! - PLY 1.0 (ascii, binary_little_endian, binary_big_endian) with an `element vertex` whose
//!   scalar properties include `x y z w` and an `element face` with a list property
//!   `vertex_indices` (or `vertex_index`); other properties and elements are read past.
//!
//! Gives: a [`MeshData4`], the positions and the triangles. A polygon of more than three
//! vertices becomes a fan of triangles around its first vertex (right for convex polygons,
//! which is what mesh writers emit).
//!
//! Guarantees: every coordinate is finite, every triangle names three distinct vertices of
//! the mesh, there is at least one triangle and at most the upper end of
//! [`crate::limits::TRIANGLES`]. Anything else is a [`MeshFileError`] naming the file, the
//! line (text) or byte offset (binary), what is wrong and how to fix it; no input makes the
//! reader panic, loop for long, or allocate more than the file's size justifies.

mod obj;
mod off;
mod ply;
#[cfg(test)]
mod tests;

use crate::limits::{TRIANGLES, shorten};
use crate::sample::MeshData4;
use glam::DVec4;
use obj::obj;
use off::off;
use ply::ply;
use std::fmt;
use std::path::Path;

/// Where in a file an error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFileLocation {
    /// The file as a whole (its name, or reading it).
    File,
    /// A line of a text file, counted from 1.
    Line(usize),
    /// A byte offset into a binary file, counted from 0.
    Byte(usize),
}

/// Why a mesh file could not be read: names the file, the line (text formats) or byte offset
/// (binary), what is wrong and how to fix it. Displays like `path:12: face 7 refers to vertex
/// 40, but the file has 36 vertices (0 to 35)`, or `path: byte 96: ...` in a binary file.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{file}{at}: {message}")]
pub struct MeshFileError {
    /// The file, as the caller named it.
    pub file: String,
    /// Where in the file.
    pub at: MeshFileLocation,
    /// What is wrong and how to fix it.
    pub message: String,
}

impl fmt::Display for MeshFileLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshFileLocation::File => Ok(()),
            MeshFileLocation::Line(n) => write!(f, ":{n}"),
            MeshFileLocation::Byte(b) => write!(f, ": byte {b}"),
        }
    }
}

/// The formats [`read_mesh4`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Geomview OFF: `4OFF`, or `nOFF` of dimension 4, text or `BINARY`.
    Off,
    /// Wavefront OBJ with `v x y z w` vertices.
    Obj,
    /// PLY 1.0 with vertex properties `x y z w`.
    Ply,
}

impl MeshFormat {
    /// The format a file's extension names: `.off`, `.4off`, `.noff`, `.obj` or `.ply` (in
    /// any case).
    pub fn from_path(path: &Path) -> std::result::Result<MeshFormat, MeshFileError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("off" | "4off" | "noff") => Ok(MeshFormat::Off),
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            other => Err(MeshFileError {
                file: path.display().to_string(),
                at: MeshFileLocation::File,
                message: format!(
                    "{}: halo4d reads meshes in R^4 from .off, .4off or .noff (Geomview OFF), .obj or .ply files",
                    match other {
                        Some(e) => format!("unknown extension `.{}`", shorten(e)),
                        None => "the file name has no extension".to_string(),
                    }
                ),
            }),
        }
    }
}

/// Reads a triangle mesh in R^4 from a file, in the format its extension names
/// ([`MeshFormat::from_path`]).
pub fn read_mesh4(path: &Path) -> std::result::Result<MeshData4, MeshFileError> {
    let format = MeshFormat::from_path(path)?;
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshFileError {
        file: file.clone(),
        at: MeshFileLocation::File,
        message: format!("cannot read the file: {e}"),
    })?;
    parse_mesh4(&bytes, &file, format)
}

/// Reads a triangle mesh in R^4 from the bytes of a file; `file` names it in errors.
/// Polygons become fans of triangles around their first vertex; the module documentation
/// says what each format may hold.
pub fn parse_mesh4(
    bytes: &[u8],
    file: &str,
    format: MeshFormat,
) -> std::result::Result<MeshData4, MeshFileError> {
    let cx = Cx { file };
    match format {
        MeshFormat::Off => off(bytes, cx),
        MeshFormat::Obj => obj(bytes, cx),
        MeshFormat::Ply => ply(bytes, cx),
    }
}

/// The most vertices, faces or triangles a file may declare.
const MAX_COUNT: usize = TRIANGLES.hi;

type Result<T> = std::result::Result<T, MeshFileError>;

/// The file being read, for errors.
#[derive(Clone, Copy)]
struct Cx<'a> {
    file: &'a str,
}

impl Cx<'_> {
    fn err(self, at: MeshFileLocation, message: impl Into<String>) -> MeshFileError {
        MeshFileError {
            file: self.file.to_string(),
            at,
            message: message.into(),
        }
    }

    fn line(self, n: usize, message: impl Into<String>) -> MeshFileError {
        self.err(MeshFileLocation::Line(n), message)
    }

    fn byte(self, b: usize, message: impl Into<String>) -> MeshFileError {
        self.err(MeshFileLocation::Byte(b), message)
    }
}

/// `bytes` as text, the first of them on line `first`; an error names the first line that is
/// not UTF-8.
fn utf8<'a>(bytes: &'a [u8], first: usize, cx: Cx) -> Result<&'a str> {
    std::str::from_utf8(bytes).map_err(|e| {
        let good = &bytes[..e.valid_up_to()];
        let line = first + good.iter().filter(|&&b| b == b'\n').count();
        cx.line(
            line,
            "the text is not UTF-8: is this a binary file, or one in another encoding? Save it as UTF-8 (or ASCII) text",
        )
    })
}

/// The lines of a text with something in them, `#` comments cut, as their numbers and words.
struct Lines<'a> {
    lines: std::str::Lines<'a>,
    /// The number of the last line taken (the line before the first, at the start).
    number: usize,
    /// Whether `#` starts a comment (OFF and OBJ; not PLY data).
    comments: bool,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str, first: usize, comments: bool) -> Self {
        Lines {
            lines: text.lines(),
            number: first - 1,
            comments,
        }
    }

    /// The next line with words: its number and its words.
    fn next(&mut self) -> Option<(usize, Vec<&'a str>)> {
        for line in self.lines.by_ref() {
            self.number += 1;
            let line = match line.find('#') {
                Some(k) if self.comments => &line[..k],
                _ => line,
            };
            let words: Vec<&str> = line.split_whitespace().collect();
            if !words.is_empty() {
                return Some((self.number, words));
            }
        }
        None
    }

    /// The number of the last line read, at least 1: where an error at the end of the file
    /// points.
    fn last(&self) -> usize {
        self.number.max(1)
    }
}

/// A number of a text file.
fn number(word: &str, what: &str) -> std::result::Result<f64, String> {
    word.parse::<f64>()
        .map_err(|_| format!("{what}: `{}` is not a number", shorten(word)))
}

/// A coordinate of a text file: a finite number.
fn coordinate(word: &str, vertex: usize, axis: usize) -> std::result::Result<f64, String> {
    let x = number(word, &format!("vertex {vertex}"))?;
    finite(x, word, vertex, axis)
}

fn finite(x: f64, shown: &str, vertex: usize, axis: usize) -> std::result::Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!(
            "vertex {vertex}: coordinate {} is {}, not a finite number: every coordinate must be finite",
            ["x", "y", "z", "w"][axis.min(3)],
            shorten(shown)
        ))
    }
}

/// A count of a header: a whole number within the limits.
fn count(word: &str, what: &str) -> std::result::Result<usize, String> {
    let n: u64 = word.parse().map_err(|_| {
        format!(
            "the number of {what} is `{}`, not a whole number",
            shorten(word)
        )
    })?;
    if n > MAX_COUNT as u64 {
        return Err(format!(
            "the file declares {n} {what}; halo4d reads at most {MAX_COUNT}"
        ));
    }
    Ok(n as usize)
}

/// "the file ends after 12 of 36 vertices"
fn ends(done: usize, of: usize, what: &str) -> String {
    format!(
        "the file ends after {done} of {of} {what}: it is truncated, or its header declares too many"
    )
}

/// The mesh under construction: positions, and faces checked and cut into triangles.
#[derive(Default)]
struct Build {
    mesh: MeshData4,
    /// The corners of the face being added, reused.
    ids: Vec<u32>,
}

impl Build {
    /// A mesh with room for `vertices` and `triangles`, each no more than the file's bytes can
    /// hold, so that a lying header allocates nothing.
    fn with_capacity(vertices: usize, triangles: usize) -> Self {
        Build {
            mesh: MeshData4 {
                positions: Vec::with_capacity(vertices.min(MAX_COUNT)),
                triangles: Vec::with_capacity(triangles.min(MAX_COUNT)),
            },
            ids: Vec::new(),
        }
    }

    /// Adds face `face` whose corners are `raw` as the file numbers vertices: from 0, or as
    /// OBJ does (from 1, negative counting back from the last vertex so far).
    fn face(&mut self, raw: &[i64], face: usize, obj: bool) -> std::result::Result<(), String> {
        let n = self.mesh.positions.len();
        if raw.len() < 3 {
            return Err(format!(
                "face {face} has {} vertices; a face needs at least 3",
                raw.len()
            ));
        }
        self.ids.clear();
        for &r in raw {
            let id = match (obj, r) {
                (false, _) => r,
                (true, 0) => {
                    return Err(format!(
                        "face {face} refers to vertex 0, but OBJ counts vertices from 1 (or back from -1)"
                    ));
                }
                (true, r) if r > 0 => r - 1,
                (true, r) => (n as i64).saturating_add(r),
            };
            if !(0..n as i64).contains(&id) {
                return Err(match (obj, n) {
                    (_, 0) => format!(
                        "face {face} refers to vertex {r}, but the file has no vertices before it"
                    ),
                    (true, _) => format!(
                        "face {face} refers to vertex {r}, but the file has {n} vertices before it (1 to {n}, or -1 to -{n} counting back)"
                    ),
                    (false, _) => format!(
                        "face {face} refers to vertex {r}, but the file has {n} vertices (0 to {})",
                        n - 1
                    ),
                });
            }
            self.ids.push(id as u32);
        }
        if let Some(v) = repeated(&self.ids) {
            let shown = if obj { v as u64 + 1 } else { v as u64 };
            return Err(format!(
                "face {face} repeats vertex {shown}: a face's corners must be distinct vertices"
            ));
        }
        let triangles = self.mesh.triangles.len() + self.ids.len() - 2;
        if triangles > MAX_COUNT {
            return Err(format!(
                "the faces make more than {MAX_COUNT} triangles, the most halo4d reads"
            ));
        }
        let first = self.ids[0];
        for pair in self.ids[1..].windows(2) {
            self.mesh.triangles.push([first, pair[0], pair[1]]);
        }
        Ok(())
    }

    /// The mesh, unless it has no triangle.
    fn finish(self) -> std::result::Result<MeshData4, String> {
        if self.mesh.triangles.is_empty() {
            return Err(format!(
                "the mesh has no triangles ({} vertices, no faces): halo4d needs a surface, at least one face of 3 vertices",
                self.mesh.positions.len()
            ));
        }
        Ok(self.mesh)
    }
}

/// A vertex a face names twice, if any.
fn repeated(ids: &[u32]) -> Option<u32> {
    if ids.len() <= 16 {
        for (k, a) in ids.iter().enumerate() {
            if ids[k + 1..].contains(a) {
                return Some(*a);
            }
        }
        None
    } else {
        let mut sorted = ids.to_vec();
        sorted.sort_unstable();
        sorted.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }
}

/// A position in a binary file.
struct Bin<'a> {
    bytes: &'a [u8],
    pos: usize,
    little: bool,
}

impl<'a> Bin<'a> {
    fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let out = self.bytes.get(self.pos..self.pos.checked_add(n)?)?;
        self.pos += n;
        Some(out)
    }

    fn word(&mut self) -> Option<[u8; 4]> {
        let b = self.take(4)?;
        let mut w = [b[0], b[1], b[2], b[3]];
        if self.little {
            w.reverse();
        }
        Some(w)
    }

    fn i32(&mut self) -> Option<i32> {
        self.word().map(i32::from_be_bytes)
    }

    fn f32(&mut self) -> Option<f32> {
        self.word().map(f32::from_be_bytes)
    }

    /// Whether only whitespace is left.
    fn at_end(&self) -> bool {
        self.bytes[self.pos..].iter().all(u8::is_ascii_whitespace)
    }
}
