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

use crate::limits::{TRIANGLES, shorten};
use glam::DVec4;
use std::fmt;
use std::path::Path;

/// A triangle mesh in R^4 as read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData4 {
    /// The vertices' points of R^4.
    pub positions: Vec<DVec4>,
    /// Triangles as indices into `positions`, in the order and orientation of the file's
    /// faces.
    pub triangles: Vec<[u32; 3]>,
}

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

/// The mesh as ASCII `4OFF` text, every coordinate written so that it reads back to the same
/// f64 (Rust's shortest round-trip form). Non-finite coordinates are written as they are
/// (`NaN`, `inf`), which the reader refuses.
pub fn write_4off(mesh: &MeshData4) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(64 + 40 * mesh.positions.len());
    out += "4OFF\n# a triangle mesh in R^4: x y z w per vertex\n";
    let _ = writeln!(out, "{} {} 0", mesh.positions.len(), mesh.triangles.len());
    for p in &mesh.positions {
        // Debug is Display's shortest round-trip digits, with an exponent for tiny and huge
        // numbers (1e-300, not 300 zeros).
        let _ = writeln!(out, "{:?} {:?} {:?} {:?}", p.x, p.y, p.z, p.w);
    }
    for [a, b, c] in &mesh.triangles {
        let _ = writeln!(out, "3 {a} {b} {c}");
    }
    out
}

/// The most vertices, faces or triangles a file may declare.
const MAX_COUNT: usize = *TRIANGLES.end();

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

// ---------------------------------------------------------------------------------------------
// OFF

/// What an OFF header keyword `[ST][C][N][4][n]OFF` declares.
#[derive(Clone, Copy)]
struct OffKind {
    texture: bool,
    colour: bool,
    normal: bool,
    four: bool,
    dimension_follows: bool,
}

impl OffKind {
    fn parse(word: &str) -> Option<OffKind> {
        let mut rest = word.strip_suffix("OFF")?;
        let mut take = |prefix: &str| {
            let found = rest.starts_with(prefix);
            if found {
                rest = &rest[prefix.len()..];
            }
            found
        };
        let kind = OffKind {
            texture: take("ST"),
            colour: take("C"),
            normal: take("N"),
            four: take("4"),
            dimension_follows: take("n"),
        };
        rest.is_empty().then_some(kind)
    }

    /// The numbers a vertex has after its 4 coordinates.
    fn extras(self) -> usize {
        3 * self.normal as usize + 4 * self.colour as usize + 2 * self.texture as usize
    }

    /// The coordinates of a vertex, or why halo4d cannot read them.
    fn check_dimension(self, keyword: &str, ndim: Option<i64>) -> std::result::Result<(), String> {
        let components = match ndim {
            Some(d) => d.saturating_add(self.four as i64),
            None if self.four => 4,
            None => 3,
        };
        if components == 4 {
            return Ok(());
        }
        let what = match ndim {
            Some(d) if self.four => format!(
                "`{keyword}` with dimension {d} gives vertices of {components} numbers (dimension + 1)"
            ),
            Some(d) => format!("`{keyword}` with dimension {d} gives points in R^{d}"),
            None => format!("`{keyword}` gives points in R^3"),
        };
        Err(format!(
            "{what}; halo4d needs points in R^4: use the header `4OFF` with four numbers x y z w per vertex (or `nOFF` with dimension 4)"
        ))
    }

    fn layout(self) -> String {
        let mut s = String::from("x y z w");
        if self.normal {
            s += ", then a normal nx ny nz";
        }
        if self.colour {
            s += ", then a colour r g b a";
        }
        if self.texture {
            s += ", then texture coordinates s t";
        }
        s
    }
}

fn off(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    // The header keyword: the first line with something other than a comment.
    let mut pos = 0;
    let mut line = 0;
    let (header_line, header, body) = loop {
        if pos >= bytes.len() {
            return Err(cx.line(
                line.max(1),
                "the file has no header: an OFF mesh in R^4 starts with `4OFF` (or `nOFF` and the dimension 4)",
            ));
        }
        line += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let content = &bytes[pos..end];
        let content = content
            .iter()
            .position(|&b| b == b'#')
            .map_or(content, |k| &content[..k]);
        let next = (end + 1).min(bytes.len());
        if content.iter().any(|b| !b.is_ascii_whitespace()) {
            break (line, content, next);
        }
        pos = next;
    };
    let header = utf8(header, header_line, cx)?;
    let mut words = header.split_whitespace();
    let keyword = words.next().unwrap_or_default();
    let kind = OffKind::parse(keyword).ok_or_else(|| {
        cx.line(
            header_line,
            format!(
                "the header keyword is `{}`; an OFF mesh in R^4 starts with `4OFF`, or `nOFF` followed by the dimension 4 (prefixes ST, C, N before them and `BINARY` after them are allowed)",
                shorten(keyword)
            ),
        )
    })?;
    let rest: Vec<&str> = words.collect();
    if rest.first() == Some(&"BINARY") {
        if rest.len() > 1 {
            return Err(cx.line(
                header_line,
                format!(
                    "text after `BINARY`: `{}`; the binary data starts on the next line",
                    shorten(&rest[1..].join(" "))
                ),
            ));
        }
        return off_binary(bytes, body, kind, keyword, cx);
    }
    let text = utf8(&bytes[body..], header_line + 1, cx)?;
    let mut lines = Lines::new(text, header_line + 1, true);

    // The dimension (nOFF) and the counts, on the header line or the lines after it.
    let need = kind.dimension_follows as usize + 2;
    let mut ints: Vec<&str> = rest;
    let mut counts_line = header_line;
    while ints.len() < need {
        let Some((n, words)) = lines.next() else {
            return Err(cx.line(
                lines.last(),
                format!(
                    "the file ends before the counts `NVertices NFaces NEdges`{}",
                    if kind.dimension_follows {
                        " (after the dimension of nOFF)"
                    } else {
                        ""
                    }
                ),
            ));
        };
        counts_line = n;
        ints.extend(words);
    }
    if ints.len() > need + 1 {
        return Err(cx.line(
            counts_line,
            format!(
                "too many numbers for the counts `{}NVertices NFaces NEdges`: `{}`",
                if kind.dimension_follows { "Ndim, " } else { "" },
                shorten(&ints.join(" "))
            ),
        ));
    }
    let ndim = if kind.dimension_follows {
        let d = ints.remove(0);
        Some(d.parse::<i64>().map_err(|_| {
            cx.line(
                counts_line,
                format!(
                    "the dimension of nOFF is `{}`, not a whole number; halo4d needs 4",
                    shorten(d)
                ),
            )
        })?)
    } else {
        None
    };
    kind.check_dimension(keyword, ndim)
        .map_err(|m| cx.line(header_line, m))?;
    let nv = count(ints[0], "vertices").map_err(|m| cx.line(counts_line, m))?;
    let nf = count(ints[1], "faces").map_err(|m| cx.line(counts_line, m))?;

    // A vertex takes at least 8 bytes of text, a face at least 8.
    let mut build = Build::with_capacity(nv.min(text.len() / 8), nf.min(text.len() / 8));
    let per = 4 + kind.extras();
    for v in 0..nv {
        let (n, words) = lines
            .next()
            .ok_or_else(|| cx.line(lines.last(), ends(v, nv, "vertices")))?;
        if words.len() != per {
            return Err(cx.line(
                n,
                format!(
                    "vertex {v} has {} numbers; `{keyword}` needs {per} per vertex, on one line: {}",
                    words.len(),
                    kind.layout()
                ),
            ));
        }
        let mut p = [0.0; 4];
        for (axis, w) in words[..4].iter().enumerate() {
            p[axis] = coordinate(w, v, axis).map_err(|m| cx.line(n, m))?;
        }
        for w in &words[4..] {
            number(w, &format!("vertex {v}")).map_err(|m| cx.line(n, m))?;
        }
        build.mesh.positions.push(DVec4::from_array(p));
    }
    let mut raw = Vec::new();
    for f in 0..nf {
        let (n, words) = lines
            .next()
            .ok_or_else(|| cx.line(lines.last(), ends(f, nf, "faces")))?;
        let corners: usize = words[0].parse().map_err(|_| {
            cx.line(
                n,
                format!(
                    "face {f}: `{}` is not a number of vertices (a face is `n i1 ... in`)",
                    shorten(words[0])
                ),
            )
        })?;
        if corners >= words.len() {
            return Err(cx.line(
                n,
                format!(
                    "face {f} lists {} of its {corners} vertices; a face is `n i1 ... in` on one line",
                    words.len() - 1
                ),
            ));
        }
        raw.clear();
        for w in &words[1..=corners] {
            raw.push(w.parse::<i64>().map_err(|_| {
                cx.line(
                    n,
                    format!("face {f}: `{}` is not a vertex index", shorten(w)),
                )
            })?);
        }
        // Numbers after the indices are the face's colour.
        build.face(&raw, f, false).map_err(|m| cx.line(n, m))?;
    }
    if let Some((n, words)) = lines.next() {
        return Err(cx.line(
            n,
            format!(
                "text after the {nv} vertices and {nf} faces the header declares: `{}`; fix the counts, or remove the text",
                shorten(&words.join(" "))
            ),
        ));
    }
    build.finish().map_err(|m| cx.line(lines.last(), m))
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

fn off_binary(
    bytes: &[u8],
    start: usize,
    kind: OffKind,
    keyword: &str,
    cx: Cx,
) -> Result<MeshData4> {
    let mut b = Bin {
        bytes,
        pos: start,
        little: false,
    };
    let int = |b: &mut Bin, what: &str| {
        let at = b.pos;
        b.i32()
            .ok_or_else(|| cx.byte(at, format!("the file ends before {what}")))
    };
    let ndim = if kind.dimension_follows {
        Some(i64::from(int(&mut b, "the dimension of nOFF (int32)")?))
    } else {
        None
    };
    kind.check_dimension(keyword, ndim)
        .map_err(|m| cx.byte(start, m))?;
    let at = b.pos;
    let nv = int(&mut b, "the counts (three int32: NVertices NFaces NEdges)")?;
    let nf = int(&mut b, "the counts (three int32: NVertices NFaces NEdges)")?;
    int(&mut b, "the counts (three int32: NVertices NFaces NEdges)")?;
    let nv = count(&nv.to_string(), "vertices").map_err(|m| cx.byte(at, m))?;
    let nf = count(&nf.to_string(), "faces").map_err(|m| cx.byte(at + 4, m))?;

    let per = 4 + kind.extras();
    // A face takes at least 16 bytes: n, three indices and the colour count... or 12 at the
    // least for the capacity's sake.
    let mut build = Build::with_capacity(nv.min(b.left() / (4 * per)), nf.min(b.left() / 16));
    for v in 0..nv {
        let at = b.pos;
        let data = b
            .take(4 * per)
            .ok_or_else(|| cx.byte(at, ends(v, nv, "vertices")))?;
        let mut p = [0.0; 4];
        for (axis, c) in data.chunks_exact(4).take(4).enumerate() {
            let x = f64::from(f32::from_be_bytes([c[0], c[1], c[2], c[3]]));
            p[axis] = finite(x, &x.to_string(), v, axis).map_err(|m| cx.byte(at + 4 * axis, m))?;
        }
        build.mesh.positions.push(DVec4::from_array(p));
    }
    let mut raw = Vec::new();
    for f in 0..nf {
        let at = b.pos;
        let truncated = || cx.byte(at, ends(f, nf, "faces"));
        let n = b.i32().ok_or_else(truncated)?;
        if n < 0 {
            return Err(cx.byte(
                at,
                format!("face {f} claims {n} vertices; a face needs at least 3"),
            ));
        }
        let n = n as usize;
        if n.saturating_mul(4) > b.left() {
            return Err(truncated());
        }
        raw.clear();
        for _ in 0..n {
            raw.push(i64::from(b.i32().ok_or_else(truncated)?));
        }
        let colours_at = b.pos;
        let colours = b.i32().ok_or_else(truncated)?;
        if !(0..=4).contains(&colours) {
            return Err(cx.byte(
                colours_at,
                format!(
                    "face {f} claims {colours} colour components; a binary OFF face has 0 to 4 (the int32 after its indices)"
                ),
            ));
        }
        for _ in 0..colours {
            b.f32().ok_or_else(truncated)?;
        }
        build.face(&raw, f, false).map_err(|m| cx.byte(at, m))?;
    }
    if !b.at_end() {
        return Err(cx.byte(
            b.pos,
            format!(
                "{} bytes after the {nv} vertices and {nf} faces the header declares; fix the counts, or remove the bytes",
                b.left()
            ),
        ));
    }
    build.finish().map_err(|m| cx.byte(b.pos, m))
}

// ---------------------------------------------------------------------------------------------
// OBJ

// OBJ's optional fourth number of `v` is officially a homogeneous weight, and tobj 4 reads it
// into the colour array; here it is the coordinate w, hence a reader of our own.
fn obj(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    let text = utf8(bytes, 1, cx)?;
    let mut lines = Lines::new(text, 1, true);
    let mut build = Build::default();
    let mut faces = 0;
    let mut raw = Vec::new();
    while let Some((n, words)) = lines.next() {
        match words[0] {
            "v" => {
                let v = build.mesh.positions.len() + 1;
                let numbers = &words[1..];
                if numbers.len() == 3 {
                    return Err(cx.line(
                        n,
                        format!(
                            "vertex {v} has 3 coordinates; halo4d needs the fourth coordinate w: `v x y z w` (not a homogeneous weight here)"
                        ),
                    ));
                }
                if numbers.len() != 4 {
                    return Err(cx.line(
                        n,
                        format!(
                            "vertex {v} has {} numbers; halo4d reads `v x y z w`",
                            numbers.len()
                        ),
                    ));
                }
                if v > MAX_COUNT {
                    return Err(cx.line(
                        n,
                        format!("more than {MAX_COUNT} vertices, the most halo4d reads"),
                    ));
                }
                let mut p = [0.0; 4];
                for (axis, w) in numbers.iter().enumerate() {
                    p[axis] = coordinate(w, v, axis).map_err(|m| cx.line(n, m))?;
                }
                build.mesh.positions.push(DVec4::from_array(p));
            }
            "f" => {
                faces += 1;
                raw.clear();
                for w in &words[1..] {
                    let mut parts = w.split('/');
                    let index = parts.next().and_then(|i| i.parse::<i64>().ok());
                    let others_ok = parts.clone().count() <= 2
                        && parts.all(|p| p.is_empty() || p.parse::<i64>().is_ok());
                    match index {
                        Some(i) if others_ok => raw.push(i),
                        _ => {
                            return Err(cx.line(
                                n,
                                format!(
                                    "face {faces}: `{}` is not a vertex reference (`i`, `i/t`, `i//n` or `i/t/n`)",
                                    shorten(w)
                                ),
                            ));
                        }
                    }
                }
                build.face(&raw, faces, true).map_err(|m| cx.line(n, m))?;
            }
            _ => {}
        }
    }
    build.finish().map_err(|m| cx.line(lines.last(), m))
}

// ---------------------------------------------------------------------------------------------
// PLY

/// A scalar type of PLY.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &str) -> Option<Ty> {
        Some(match name {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn integer(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }

    /// A binary value.
    fn read(self, b: &mut Bin) -> Option<f64> {
        let size = self.size();
        let mut x = [0u8; 8];
        x[..size].copy_from_slice(b.take(size)?);
        if b.little {
            x[..size].reverse();
        }
        Some(match self {
            Ty::I8 => f64::from(x[0] as i8),
            Ty::U8 => f64::from(x[0]),
            Ty::I16 => f64::from(i16::from_be_bytes([x[0], x[1]])),
            Ty::U16 => f64::from(u16::from_be_bytes([x[0], x[1]])),
            Ty::I32 => f64::from(i32::from_be_bytes([x[0], x[1], x[2], x[3]])),
            Ty::U32 => f64::from(u32::from_be_bytes([x[0], x[1], x[2], x[3]])),
            Ty::F32 => f64::from(f32::from_be_bytes([x[0], x[1], x[2], x[3]])),
            Ty::F64 => f64::from_be_bytes([x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]]),
        })
    }

    /// A text value.
    fn parse_text(self, word: &str) -> Option<f64> {
        if self.integer() {
            word.parse::<i64>().ok().map(|i| i as f64)
        } else {
            word.parse::<f64>().ok()
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Prop {
    Scalar(Ty),
    List(Ty, Ty),
}

struct Element {
    name: String,
    count: u64,
    /// The header line that declares it.
    line: usize,
    props: Vec<(String, Prop)>,
}

impl Element {
    fn plural(&self) -> String {
        match self.name.as_str() {
            "vertex" => "vertices".into(),
            "face" => "faces".into(),
            other => format!("`{}` elements", shorten(other)),
        }
    }

    /// The fewest bytes one element takes in a binary file.
    fn min_size(&self) -> usize {
        self.props
            .iter()
            .map(|(_, p)| match p {
                Prop::Scalar(t) | Prop::List(t, _) => t.size(),
            })
            .sum()
    }

    fn names(&self) -> String {
        if self.props.is_empty() {
            return "none".into();
        }
        shorten(
            &self
                .props
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        )
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// What is kept of each value of an element.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Skip,
    Axis(usize),
    Corners,
}

fn ply(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    // The header: text lines up to `end_header`.
    let mut pos = 0;
    let mut line = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(cx.line(
                line.max(1),
                "the header has no `end_header` line: the file is truncated, or not PLY",
            ));
        }
        line += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let text = utf8(&bytes[pos..end], line, cx)?;
        pos = (end + 1).min(bytes.len());
        let words: Vec<&str> = text.split_whitespace().collect();
        if line == 1 {
            if words != ["ply"] {
                return Err(cx.line(
                    1,
                    format!(
                        "a PLY file starts with the line `ply`, found `{}`",
                        shorten(text.trim())
                    ),
                ));
            }
            continue;
        }
        match words.as_slice() {
            [] => {}
            ["end_header"] => break,
            ["comment" | "obj_info", ..] => {}
            ["format", name, version] => {
                if *version != "1.0" {
                    return Err(cx.line(
                        line,
                        format!(
                            "PLY version `{}`; halo4d reads version 1.0",
                            shorten(version)
                        ),
                    ));
                }
                encoding = Some(match *name {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => {
                        return Err(cx.line(
                            line,
                            format!(
                                "unknown PLY format `{}`: ascii, binary_little_endian or binary_big_endian",
                                shorten(other)
                            ),
                        ));
                    }
                });
            }
            ["element", name, n] => {
                let count = n.parse::<u64>().map_err(|_| {
                    cx.line(
                        line,
                        format!(
                            "element `{}` has the count `{}`, not a whole number",
                            shorten(name),
                            shorten(n)
                        ),
                    )
                })?;
                let el = Element {
                    name: name.to_string(),
                    count,
                    line,
                    props: Vec::new(),
                };
                if matches!(*name, "vertex" | "face") && count > MAX_COUNT as u64 {
                    return Err(cx.line(
                        line,
                        format!(
                            "the file declares {count} {}; halo4d reads at most {MAX_COUNT}",
                            el.plural()
                        ),
                    ));
                }
                elements.push(el);
            }
            ["property", rest @ ..] => {
                let ty = |name: &str| {
                    Ty::parse(name).ok_or_else(|| {
                        cx.line(
                            line,
                            format!(
                                "unknown property type `{}`: PLY's types are char, uchar, short, ushort, int, uint, float, double (or int8 to float64)",
                                shorten(name)
                            ),
                        )
                    })
                };
                let (name, prop) = match rest {
                    ["list", count, item, name] => {
                        let (count, item) = (ty(count)?, ty(item)?);
                        if !count.integer() {
                            return Err(cx.line(
                                line,
                                "a list's count type must be an integer type (uchar, int, ...)",
                            ));
                        }
                        (*name, Prop::List(count, item))
                    }
                    [t, name] if *t != "list" => (*name, Prop::Scalar(ty(t)?)),
                    _ => {
                        return Err(cx.line(
                            line,
                            format!(
                                "malformed property `{}`: `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
                                shorten(text.trim())
                            ),
                        ));
                    }
                };
                let el = elements
                    .last_mut()
                    .ok_or_else(|| cx.line(line, "a property before any `element` line"))?;
                el.props.push((name.to_string(), prop));
            }
            _ => {
                return Err(cx.line(
                    line,
                    format!(
                        "unknown PLY header line `{}`: expected format, element, property, comment or end_header",
                        shorten(text.trim())
                    ),
                ));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| {
        cx.line(
            line,
            "the header has no `format` line (`format ascii 1.0`, `format binary_little_endian 1.0` or `format binary_big_endian 1.0`)",
        )
    })?;

    // What each element's properties are for.
    let vertex = elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| {
            cx.line(
                line,
                "the header declares no `element vertex`: halo4d needs vertices with properties x y z w",
            )
        })?;
    let face = elements
        .iter()
        .position(|e| e.name == "face")
        .ok_or_else(|| {
            cx.line(
                line,
                "the header declares no `element face`: halo4d reads triangle meshes (a list property `vertex_indices`)",
            )
        })?;
    let mut roles: Vec<Vec<Role>> = elements
        .iter()
        .map(|e| vec![Role::Skip; e.props.len()])
        .collect();
    let v = &elements[vertex];
    for (axis, name) in ["x", "y", "z", "w"].into_iter().enumerate() {
        let k = v.props.iter().position(|(n, _)| n == name);
        match k.map(|k| (k, v.props[k].1)) {
            Some((k, Prop::Scalar(_))) => roles[vertex][k] = Role::Axis(axis),
            Some(_) => {
                return Err(cx.line(
                    v.line,
                    format!("the vertex property `{name}` is a list; it must be a number"),
                ));
            }
            None => {
                return Err(cx.line(
                    v.line,
                    format!(
                        "the vertex element has no property `{name}` (its properties: {}); halo4d needs `x y z w`, points in R^4{}",
                        v.names(),
                        if name == "w" {
                            ": add the fourth coordinate `property double w`"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
    }
    let fe = &elements[face];
    let k = fe
        .props
        .iter()
        .position(|(n, _)| n == "vertex_indices" || n == "vertex_index")
        .ok_or_else(|| {
            cx.line(
                fe.line,
                format!(
                    "the face element has no list property `vertex_indices` (or `vertex_index`); its properties: {}",
                    fe.names()
                ),
            )
        })?;
    match fe.props[k].1 {
        Prop::List(_, item) if item.integer() => roles[face][k] = Role::Corners,
        _ => {
            return Err(cx.line(
                fe.line,
                format!(
                    "the face property `{}` must be a list of an integer type, like `property list uchar int vertex_indices`",
                    fe.props[k].0
                ),
            ));
        }
    }

    let left = bytes.len() - pos;
    let nv = elements[vertex].count as usize;
    let nf = elements[face].count as usize;
    let mut build = Build::with_capacity(
        nv.min(left / elements[vertex].min_size().max(2)),
        nf.min(left / elements[face].min_size().max(2)),
    );
    let mut body = Body {
        encoding,
        bin: Bin {
            bytes,
            pos,
            little: encoding == Encoding::Little,
        },
        lines: None,
        cx,
    };
    if encoding == Encoding::Ascii {
        let text = utf8(&bytes[pos..], line + 1, cx)?;
        body.lines = Some(Lines::new(text, line + 1, false));
    }
    for (el, roles) in elements.iter().zip(&roles) {
        body.element(el, roles, &mut build)?;
    }
    match body.lines.as_mut() {
        Some(lines) => {
            if let Some((n, words)) = lines.next() {
                return Err(cx.line(
                    n,
                    format!(
                        "text after the elements the header declares: `{}`; fix the counts, or remove the text",
                        shorten(&words.join(" "))
                    ),
                ));
            }
            let last = lines.last();
            build.finish().map_err(|m| cx.line(last, m))
        }
        None => {
            if !body.bin.at_end() {
                return Err(cx.byte(
                    body.bin.pos,
                    format!(
                        "{} bytes after the elements the header declares; fix the counts, or remove the bytes",
                        body.bin.left()
                    ),
                ));
            }
            build.finish().map_err(|m| cx.byte(body.bin.pos, m))
        }
    }
}

/// The data of a PLY file after its header.
struct Body<'a> {
    encoding: Encoding,
    bin: Bin<'a>,
    /// The text lines of an ASCII file.
    lines: Option<Lines<'a>>,
    cx: Cx<'a>,
}

impl Body<'_> {
    /// Reads the elements of `el`: vertices into the mesh, faces into its triangles, others
    /// past.
    fn element(&mut self, el: &Element, roles: &[Role], build: &mut Build) -> Result<()> {
        if el.props.is_empty() {
            return Ok(());
        }
        let is_vertex = roles.iter().any(|r| matches!(r, Role::Axis(_)));
        let is_face = roles.contains(&Role::Corners);
        // An element of scalars only that nobody reads is skipped whole.
        if self.encoding != Encoding::Ascii
            && !is_vertex
            && !is_face
            && el.props.iter().all(|(_, p)| matches!(p, Prop::Scalar(_)))
        {
            let size = el.min_size();
            let at = self.bin.pos;
            let bytes = (el.count as usize).checked_mul(size);
            if bytes.is_none_or(|b| b > self.bin.left()) {
                return Err(self.cx.byte(
                    at,
                    ends(self.bin.left() / size, el.count as usize, &el.plural()),
                ));
            }
            self.bin.pos += el.count as usize * size;
            return Ok(());
        }
        let mut corners: Vec<i64> = Vec::new();
        let total = el.count as usize;
        for k in 0..total {
            let mut p = [0.0; 4];
            corners.clear();
            match self.encoding {
                Encoding::Ascii => {
                    let cx = self.cx;
                    let lines = self.lines.as_mut().expect("ascii body has lines");
                    let (n, words) = lines
                        .next()
                        .ok_or_else(|| cx.line(lines.last(), ends(k, total, &el.plural())))?;
                    let what = if is_vertex {
                        format!("vertex {k}")
                    } else if is_face {
                        format!("face {k}")
                    } else {
                        format!("element `{}` {k}", shorten(&el.name))
                    };
                    let mut words = words.into_iter();
                    let mut next = |ty: Ty, name: &str| -> Result<f64> {
                        let w = words.next().ok_or_else(|| {
                            cx.line(
                                n,
                                format!(
                                    "{what}: too few numbers on the line, `{}` is missing (properties: {})",
                                    shorten(name),
                                    el.names()
                                ),
                            )
                        })?;
                        ty.parse_text(w).ok_or_else(|| {
                            cx.line(
                                n,
                                format!(
                                    "{what}: `{}` is not a number of the type of `{}`",
                                    shorten(w),
                                    shorten(name)
                                ),
                            )
                        })
                    };
                    for ((name, prop), role) in el.props.iter().zip(roles) {
                        match *prop {
                            Prop::Scalar(ty) => {
                                let x = next(ty, name)?;
                                if let Role::Axis(axis) = *role {
                                    p[axis] = x;
                                }
                            }
                            Prop::List(count, item) => {
                                let c = next(count, name)?;
                                if !(c >= 0.0 && c.fract() == 0.0) {
                                    return Err(cx.line(
                                        n,
                                        format!(
                                            "{what}: the list `{}` has the count {c}",
                                            shorten(name)
                                        ),
                                    ));
                                }
                                for _ in 0..c as u64 {
                                    let x = next(item, name)?;
                                    if *role == Role::Corners {
                                        corners.push(x as i64);
                                    }
                                }
                            }
                        }
                    }
                    if words.next().is_some() {
                        return Err(cx.line(
                            n,
                            format!(
                                "{what}: more numbers on the line than its properties ({}) declare",
                                el.names()
                            ),
                        ));
                    }
                    if is_vertex {
                        self.vertex(p, k, MeshFileLocation::Line(n), build)?;
                    }
                    if is_face {
                        build.face(&corners, k, false).map_err(|m| cx.line(n, m))?;
                    }
                }
                Encoding::Little | Encoding::Big => {
                    let at = self.bin.pos;
                    let cx = self.cx;
                    let truncated = || cx.byte(at, ends(k, total, &el.plural()));
                    for ((name, prop), role) in el.props.iter().zip(roles) {
                        match *prop {
                            Prop::Scalar(ty) => {
                                let x = ty.read(&mut self.bin).ok_or_else(truncated)?;
                                if let Role::Axis(axis) = *role {
                                    p[axis] = x;
                                }
                            }
                            Prop::List(count, item) => {
                                let c_at = self.bin.pos;
                                let c = count.read(&mut self.bin).ok_or_else(truncated)?;
                                if c < 0.0 {
                                    return Err(cx.byte(
                                        c_at,
                                        format!(
                                            "the list `{}` of {} {k} has the count {c}",
                                            shorten(name),
                                            el.name
                                        ),
                                    ));
                                }
                                let c = c as usize;
                                if c.saturating_mul(item.size()) > self.bin.left() {
                                    return Err(truncated());
                                }
                                for _ in 0..c {
                                    let x = item.read(&mut self.bin).ok_or_else(truncated)?;
                                    if *role == Role::Corners {
                                        corners.push(x as i64);
                                    }
                                }
                            }
                        }
                    }
                    if is_vertex {
                        self.vertex(p, k, MeshFileLocation::Byte(at), build)?;
                    }
                    if is_face {
                        build.face(&corners, k, false).map_err(|m| cx.byte(at, m))?;
                    }
                }
            }
        }
        Ok(())
    }

    fn vertex(&self, p: [f64; 4], k: usize, at: MeshFileLocation, build: &mut Build) -> Result<()> {
        for (axis, x) in p.iter().enumerate() {
            finite(*x, &x.to_string(), k, axis).map_err(|m| self.cx.err(at, m))?;
        }
        build.mesh.positions.push(DVec4::from_array(p));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The boundary of a tetrahedron in R^4, with w values f32 holds exactly.
    fn tetrahedron() -> MeshData4 {
        MeshData4 {
            positions: vec![
                DVec4::new(0.0, 0.0, 0.0, 0.5),
                DVec4::new(1.0, 0.0, 0.0, -0.25),
                DVec4::new(0.0, 1.0, 0.0, 1.5),
                DVec4::new(0.0, 0.0, 1.0, -2.0),
            ],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        }
    }

    /// A quad: two triangles around its first corner.
    fn quad() -> MeshData4 {
        MeshData4 {
            positions: vec![
                DVec4::new(0.0, 0.0, 0.0, 1.0),
                DVec4::new(1.0, 0.0, 0.0, 2.0),
                DVec4::new(1.0, 1.0, 0.0, 3.0),
                DVec4::new(0.0, 1.0, 0.0, 4.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    const OFF_TET: &str = "# a tetrahedron's boundary in R^4\n\n4OFF\n4 4 6\n\
        0 0 0 0.5\n1 0 0 -0.25   # x y z w\n0 1 0 1.5\n\n0 0 1 -2\n\
        3 0 2 1\n# a comment between faces\n3 0 1 3\n3 0 3 2 1 0 0 1\n3 1 2 3 255 0 0\n";

    const NOFF_TET: &str = "nOFF\n4\n4 4 6\n0 0 0 0.5\n1 0 0 -0.25\n0 1 0 1.5\n0 0 1 -2\n\
        3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

    /// `4nOFF` of dimension 3 (plus one), the counts on the dimension's line.
    const NOFF4_TET: &str = "4nOFF\n3 4 4 6\n0 0 0 0.5\n1 0 0 -0.25\n0 1 0 1.5\n0 0 1 -2\n\
        3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

    /// Normals, colours and texture coordinates after x y z w.
    const STCNOFF_TET: &str = "STCN4OFF\n4 4 0\n\
        0 0 0 0.5  0 0 1  1 0 0 1  0 0\n\
        1 0 0 -0.25  0 0 1  1 0 0 1  1 0\n\
        0 1 0 1.5  0 0 1  1 0 0 1  0 1\n\
        0 0 1 -2  0 0 1  1 0 0 1  1 1\n\
        3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

    const OFF_QUAD: &str = "4OFF 4 1 4\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n4 0 1 2 3\n";

    const OBJ_TET: &str = "# a tetrahedron's boundary\nmtllib x.mtl\no tet\n\
        v 0 0 0 0.5\nv 1 0 0 -0.25\nvt 0 0\nvn 0 0 1\nv 0 1 0 1.5\nv 0 0 1 -2\n\
        g group\ns off\nusemtl m\nf 1 3 2\nf 1/1 2/1 4/1\nf -4//1 -1//1 -2//1 # relative\n\
        f 2/1/1 3/1/1 4/1/1\nl 1 2\np 1\nnurbs something unknown\n";

    const OBJ_QUAD: &str = "v 0 0 0 1\nv 1 0 0 2\nv 1 1 0 3\nv 0 1 0 4\nf 1 2 3 4\n";

    const PLY_TET: &str = "ply\nformat ascii 1.0\ncomment a tetrahedron's boundary\n\
        element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
        property double w\nproperty uchar red\n\
        element face 4\nproperty list uchar int vertex_indices\nproperty int flags\n\
        element edge 1\nproperty int vertex1\nproperty list uchar int more\nend_header\n\
        0 0 0 0.5 255\n1 0 0 -0.25 0\n0 1 0 1.5 0\n0 0 1 -2 0\n\
        3 0 2 1 7\n3 0 1 3 0\n3 0 3 2 0\n3 1 2 3 0\n0 2 1 5\n";

    /// A binary OFF: `header` is the keyword line, each vertex gets `extras` numbers after
    /// its coordinates, each face the given colour components.
    fn off_bytes(
        header: &str,
        ndim: Option<i32>,
        mesh: &MeshData4,
        extras: usize,
        colours: usize,
    ) -> Vec<u8> {
        let mut b = format!("{header}\n").into_bytes();
        let int = |b: &mut Vec<u8>, i: i32| b.extend(i.to_be_bytes());
        if let Some(d) = ndim {
            int(&mut b, d);
        }
        int(&mut b, mesh.positions.len() as i32);
        int(&mut b, mesh.triangles.len() as i32);
        int(&mut b, 0);
        for p in &mesh.positions {
            for x in p.to_array() {
                b.extend((x as f32).to_be_bytes());
            }
            for k in 0..extras {
                b.extend((k as f32).to_be_bytes());
            }
        }
        for t in &mesh.triangles {
            int(&mut b, 3);
            for &i in t {
                int(&mut b, i as i32);
            }
            int(&mut b, colours as i32);
            for _ in 0..colours {
                b.extend(0.5f32.to_be_bytes());
            }
        }
        b
    }

    /// A binary PLY of `mesh` with doubles and floats, extra properties and an extra element.
    fn ply_bytes(mesh: &MeshData4, little: bool) -> Vec<u8> {
        let format = if little {
            "binary_little_endian"
        } else {
            "binary_big_endian"
        };
        let mut b = format!(
            "ply\nformat {format} 1.0\nelement vertex {}\nproperty double x\nproperty float y\n\
             property uchar flag\nproperty double z\nproperty float32 w\nproperty short s\n\
             element face {}\nproperty list uchar uint vertex_indices\nproperty float quality\n\
             element material 2\nproperty list ushort int ids\nproperty int8 k\nend_header\n",
            mesh.positions.len(),
            mesh.triangles.len()
        )
        .into_bytes();
        fn put<const N: usize>(b: &mut Vec<u8>, mut x: [u8; N], little: bool) {
            if little {
                x.reverse();
            }
            b.extend(x);
        }
        for p in &mesh.positions {
            put(&mut b, p.x.to_be_bytes(), little);
            put(&mut b, (p.y as f32).to_be_bytes(), little);
            b.push(7);
            put(&mut b, p.z.to_be_bytes(), little);
            put(&mut b, (p.w as f32).to_be_bytes(), little);
            put(&mut b, (-3i16).to_be_bytes(), little);
        }
        for t in &mesh.triangles {
            b.push(3);
            for &i in t {
                put(&mut b, i.to_be_bytes(), little);
            }
            put(&mut b, 0.25f32.to_be_bytes(), little);
        }
        for _ in 0..2 {
            put(&mut b, 2u16.to_be_bytes(), little);
            put(&mut b, 9i32.to_be_bytes(), little);
            put(&mut b, 10i32.to_be_bytes(), little);
            b.push(1);
        }
        b
    }

    fn read(
        bytes: impl AsRef<[u8]>,
        format: MeshFormat,
    ) -> std::result::Result<MeshData4, MeshFileError> {
        parse_mesh4(bytes.as_ref(), "m", format)
    }

    /// Every valid file of the tests, with its format and the mesh it holds.
    fn valid_files() -> Vec<(&'static str, Vec<u8>, MeshFormat, MeshData4)> {
        use MeshFormat::*;
        let tet = tetrahedron();
        vec![
            ("4OFF", OFF_TET.into(), Off, tet.clone()),
            ("nOFF", NOFF_TET.into(), Off, tet.clone()),
            ("4nOFF", NOFF4_TET.into(), Off, tet.clone()),
            ("STCN4OFF", STCNOFF_TET.into(), Off, tet.clone()),
            ("4OFF quad", OFF_QUAD.into(), Off, quad()),
            (
                "4OFF BINARY",
                off_bytes("4OFF BINARY", None, &tet, 0, 0),
                Off,
                tet.clone(),
            ),
            (
                "nOFF BINARY",
                off_bytes("nOFF BINARY", Some(4), &tet, 0, 4),
                Off,
                tet.clone(),
            ),
            (
                "CN4OFF BINARY",
                off_bytes("CN4OFF BINARY", None, &tet, 7, 3),
                Off,
                tet.clone(),
            ),
            ("OBJ", OBJ_TET.into(), Obj, tet.clone()),
            ("OBJ quad", OBJ_QUAD.into(), Obj, quad()),
            ("PLY ascii", PLY_TET.into(), Ply, tet.clone()),
            ("PLY little", ply_bytes(&tet, true), Ply, tet.clone()),
            ("PLY big", ply_bytes(&tet, false), Ply, tet.clone()),
            (
                "PLY quad",
                ply_bytes(&quad(), true),
                Ply,
                MeshData4 {
                    triangles: vec![[0, 1, 2], [0, 2, 3]],
                    ..quad()
                },
            ),
        ]
    }

    #[test]
    fn every_format_reads_its_mesh_exactly() {
        for (name, bytes, format, want) in valid_files() {
            let got = read(&bytes, format).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(got, want, "{name}");
        }
    }

    #[test]
    fn write_4off_reads_back_bit_for_bit() {
        let values = [
            0.1,
            1e-300,
            -0.0,
            0.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1.0 / 3.0,
            -1e300,
            123456789.125,
            2f64.powi(60),
            -7.0,
        ];
        let mesh = MeshData4 {
            positions: values
                .chunks_exact(4)
                .map(|c| DVec4::new(c[0], c[1], c[2], c[3]))
                .collect(),
            triangles: vec![[0, 1, 2], [2, 1, 0]],
        };
        let text = write_4off(&mesh);
        let back = read(&text, MeshFormat::Off).expect("reads back");
        assert_eq!(back.triangles, mesh.triangles);
        for (a, b) in mesh.positions.iter().zip(&back.positions) {
            for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
                assert_eq!(x.to_bits(), y.to_bits(), "{x:?} read back as {y:?}\n{text}");
            }
        }
        assert!(text.contains("1e-300") && text.contains("-0.0"), "{text}");
        let tet = tetrahedron();
        assert_eq!(read(write_4off(&tet), MeshFormat::Off), Ok(tet));
    }

    /// The error of reading `bytes`, as displayed.
    fn error(bytes: impl AsRef<[u8]>, format: MeshFormat) -> String {
        match read(bytes, format) {
            Ok(m) => panic!("read without error: {m:?}"),
            Err(e) => e.to_string(),
        }
    }

    /// Asserts that reading `bytes` fails at `at` (like `m:5` or `m: byte 12`) with a
    /// message holding every one of `words`.
    #[track_caller]
    fn fails(bytes: impl AsRef<[u8]>, format: MeshFormat, at: &str, words: &[&str]) {
        let e = error(bytes, format);
        assert!(e.starts_with(&format!("{at}: ")), "not at `{at}`: {e}");
        for w in words {
            assert!(e.contains(w), "lacks `{w}`: {e}");
        }
    }

    /// The tetrahedron's 4OFF text with line `n` (from 1) replaced.
    fn off_with(n: usize, line: &str) -> String {
        let mut lines: Vec<&str> = NOFF_TET.lines().collect();
        lines[0] = "4OFF";
        lines.remove(1);
        lines[n - 1] = line;
        lines.join("\n") + "\n"
    }

    #[test]
    fn off_text_errors_name_the_line() {
        use MeshFormat::Off;
        // 1 4OFF, 2 counts, 3-6 vertices, 7-10 faces.
        assert_eq!(read(off_with(3, "0 0 0 0.5"), Off), Ok(tetrahedron()));
        fails(
            off_with(3, "0 0 zero 0.5"),
            Off,
            "m:3",
            &["vertex 0", "`zero` is not a number"],
        );
        fails(
            off_with(4, "1 0 0"),
            Off,
            "m:4",
            &["vertex 1 has 3 numbers", "`4OFF` needs 4", "x y z w"],
        );
        fails(
            off_with(4, "1 0 0 0 0"),
            Off,
            "m:4",
            &["vertex 1 has 5 numbers"],
        );
        fails(
            off_with(5, "0 1 0 nan"),
            Off,
            "m:5",
            &["vertex 2", "coordinate w is nan", "finite"],
        );
        fails(
            off_with(5, "inf 1 0 0"),
            Off,
            "m:5",
            &["coordinate x is inf"],
        );
        fails(
            off_with(6, "0 0 1e999 0"),
            Off,
            "m:6",
            &["coordinate z is 1e999"],
        );
        fails(
            off_with(8, "3 0 1 40"),
            Off,
            "m:8",
            &["face 1 refers to vertex 40, but the file has 4 vertices (0 to 3)"],
        );
        fails(
            off_with(8, "3 0 1 -1"),
            Off,
            "m:8",
            &["face 1 refers to vertex -1"],
        );
        fails(
            off_with(9, "2 0 1"),
            Off,
            "m:9",
            &["face 2 has 2 vertices; a face needs at least 3"],
        );
        fails(
            off_with(10, "3 1 2 1"),
            Off,
            "m:10",
            &["face 3 repeats vertex 1", "distinct"],
        );
        fails(
            off_with(10, "4 1 2 3"),
            Off,
            "m:10",
            &["face 3 lists 3 of its 4 vertices"],
        );
        fails(
            off_with(10, "3 1 2 x"),
            Off,
            "m:10",
            &["`x` is not a vertex index"],
        );
        fails(
            off_with(10, "three 1 2 3"),
            Off,
            "m:10",
            &["`three` is not a number of vertices"],
        );
        fails(
            off_with(2, "1000000000000 4 0"),
            Off,
            "m:2",
            &["declares 1000000000000 vertices", "at most 20000000"],
        );
        fails(
            off_with(2, "4 30000000 0"),
            Off,
            "m:2",
            &["declares 30000000 faces"],
        );
        fails(
            off_with(2, "-4 4 0"),
            Off,
            "m:2",
            &["`-4`, not a whole number"],
        );
        fails(
            off_with(2, "4 4 6 8"),
            Off,
            "m:2",
            &["too many numbers for the counts"],
        );
        fails(
            "4OFF\n4 0 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n",
            Off,
            "m:6",
            &["no triangles", "4 vertices"],
        );
        fails(
            "4OFF\n4 4 0\n0 0 0 0\n1 0 0 0\n",
            Off,
            "m:4",
            &["the file ends after 2 of 4 vertices"],
        );
        fails(
            "4OFF\n4 4 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n3 0 1 2\n",
            Off,
            "m:7",
            &["the file ends after 1 of 4 faces"],
        );
        fails("4OFF\n", Off, "m:1", &["ends before the counts"]);
        fails(
            NOFF_TET.to_string() + "3 0 1 2\n",
            Off,
            "m:12",
            &["text after the 4 vertices and 4 faces", "`3 0 1 2`"],
        );
        let mut bytes = off_with(5, "0 1 0 1.5").into_bytes();
        bytes.extend(b"\xff\xfe\n");
        fails(&bytes, Off, "m:11", &["not UTF-8"]);
        fails(b"\xff\xfe\n", Off, "m:1", &["not UTF-8"]);
        fails("", Off, "m:1", &["no header"]);
        fails("# only a comment\n\n", Off, "m:2", &["no header"]);
        fails("4 4 6\n", Off, "m:1", &["header keyword is `4`", "`4OFF`"]);
        fails("NC4OFF\n", Off, "m:1", &["header keyword is `NC4OFF`"]);
    }

    #[test]
    fn off_of_another_dimension_says_which_header_to_use() {
        use MeshFormat::Off;
        let off3 = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        fails(
            off3,
            Off,
            "m:1",
            &[
                "`OFF` gives points in R^3",
                "halo4d needs points in R^4",
                "`4OFF`",
                "`nOFF` with dimension 4",
            ],
        );
        fails("COFF\n3 1 0\n", Off, "m:1", &["`COFF` gives points in R^3"]);
        fails(
            "nOFF\n5\n1 1 0\n",
            Off,
            "m:1",
            &["`nOFF` with dimension 5 gives points in R^5"],
        );
        fails(
            "4nOFF 4 1 1 0\n",
            Off,
            "m:1",
            &["dimension 4 gives vertices of 5 numbers"],
        );
        fails(
            "nOFF\nfour 1 1 0\n",
            Off,
            "m:2",
            &["dimension of nOFF is `four`"],
        );
        fails(b"OFF BINARY\n\0\0\0\x03", Off, "m: byte 11", &["R^3"]);
        fails(
            b"nOFF BINARY\n\0\0\0\x03",
            Off,
            "m: byte 12",
            &["`nOFF` with dimension 3"],
        );
    }

    #[test]
    fn binary_off_errors_name_the_byte() {
        use MeshFormat::Off;
        let tet = tetrahedron();
        let good = off_bytes("4OFF BINARY", None, &tet, 0, 0);
        let data = 12; // after "4OFF BINARY\n"
        let vertices = data + 12;
        let faces = vertices + 4 * 16;
        assert_eq!(read(&good, Off), Ok(tet.clone()));
        fails(
            &good[..vertices + 40],
            Off,
            &format!("m: byte {}", vertices + 32),
            &["the file ends after 2 of 4 vertices"],
        );
        fails(
            &good[..faces + 20 + 6],
            Off,
            &format!("m: byte {}", faces + 20),
            &["the file ends after 1 of 4 faces"],
        );
        fails(
            &good[..data + 5],
            Off,
            &format!("m: byte {}", data + 4),
            &["the file ends before the counts"],
        );
        let mut huge = good.clone();
        huge[data..data + 4].copy_from_slice(&i32::MAX.to_be_bytes());
        fails(
            &huge,
            Off,
            &format!("m: byte {data}"),
            &["declares 2147483647 vertices"],
        );
        huge[data..data + 4].copy_from_slice(&20_000_000i32.to_be_bytes());
        fails(
            &huge,
            Off,
            "m: byte 168",
            &["the file ends after 9 of 20000000 vertices"],
        );
        let mut nan = good.clone();
        nan[vertices + 16 + 12..vertices + 32].copy_from_slice(&f32::NAN.to_be_bytes());
        fails(
            &nan,
            Off,
            &format!("m: byte {}", vertices + 16 + 12),
            &["vertex 1: coordinate w is NaN"],
        );
        let mut out = good.clone();
        out[faces + 20 + 12..faces + 20 + 16].copy_from_slice(&40i32.to_be_bytes());
        fails(
            &out,
            Off,
            &format!("m: byte {}", faces + 20),
            &["face 1 refers to vertex 40, but the file has 4 vertices (0 to 3)"],
        );
        let mut colours = good.clone();
        colours[faces + 16..faces + 20].copy_from_slice(&9i32.to_be_bytes());
        fails(
            &colours,
            Off,
            &format!("m: byte {}", faces + 16),
            &["face 0 claims 9 colour components"],
        );
        let mut two = good.clone();
        two[faces..faces + 4].copy_from_slice(&(-2i32).to_be_bytes());
        fails(
            &two,
            Off,
            &format!("m: byte {faces}"),
            &["face 0 claims -2 vertices"],
        );
        let mut trailing = good.clone();
        trailing.extend(b"junk");
        fails(
            &trailing,
            Off,
            &format!("m: byte {}", good.len()),
            &["4 bytes after the 4 vertices and 4 faces"],
        );
        let mut newline = good.clone();
        newline.push(b'\n');
        assert_eq!(read(&newline, Off), Ok(tet.clone()));
        fails(b"4OFF BINARY junk\n", Off, "m:1", &["text after `BINARY`"]);
        let empty = MeshData4 {
            positions: tet.positions.clone(),
            triangles: vec![],
        };
        fails(
            off_bytes("4OFF BINARY", None, &empty, 0, 0),
            Off,
            &format!("m: byte {faces}"),
            &["no triangles"],
        );
    }

    #[test]
    fn obj_errors_name_the_line() {
        use MeshFormat::Obj;
        fails(
            "v 0 0 0 1\nv 1 0 0\n",
            Obj,
            "m:2",
            &[
                "vertex 2 has 3 coordinates",
                "fourth coordinate w",
                "`v x y z w`",
            ],
        );
        fails("v 0 0 0 1 1 1 1\n", Obj, "m:1", &["vertex 1 has 7 numbers"]);
        fails(
            "v 0 0 0 one\n",
            Obj,
            "m:1",
            &["vertex 1: `one` is not a number"],
        );
        fails("v 0 0 0 -inf\n", Obj, "m:1", &["coordinate w is -inf"]);
        fails(
            OBJ_QUAD.to_string() + "f 1 2 a/1\n",
            Obj,
            "m:6",
            &["face 2: `a/1` is not a vertex reference", "`i/t/n`"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 3/x\n",
            Obj,
            "m:6",
            &["`3/x` is not a vertex reference"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 3/1/1/1\n",
            Obj,
            "m:6",
            &["`3/1/1/1`"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 40\n",
            Obj,
            "m:6",
            &["face 2 refers to vertex 40, but the file has 4 vertices before it (1 to 4"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 -5\n",
            Obj,
            "m:6",
            &["face 2 refers to vertex -5"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 0\n",
            Obj,
            "m:6",
            &["vertex 0", "counts vertices from 1"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2\n",
            Obj,
            "m:6",
            &["face 2 has 2 vertices"],
        );
        fails(
            OBJ_QUAD.to_string() + "f 1 2 -3\n",
            Obj,
            "m:6",
            &["face 2 repeats vertex 2"],
        );
        fails(
            "f 1 2 3\nv 0 0 0 0\n",
            Obj,
            "m:1",
            &["no vertices before it"],
        );
        fails(
            "v 0 0 0 0\nv 1 0 0 0\n# no faces\n",
            Obj,
            "m:3",
            &["no triangles", "2 vertices"],
        );
        fails("", Obj, "m:1", &["no triangles"]);
        fails(
            b"v 0 0 0 0\nv 1 0 0 0\nv 0 \xc0 0 0\n",
            Obj,
            "m:3",
            &["not UTF-8"],
        );
    }

    #[test]
    fn ply_errors_name_the_line_or_byte() {
        use MeshFormat::Ply;
        let no_w = PLY_TET.replace("property double w\n", "");
        fails(
            &no_w,
            Ply,
            "m:4",
            &[
                "no property `w`",
                "its properties: x, y, z, red",
                "`x y z w`",
            ],
        );
        let huge = PLY_TET.replace("element vertex 4", "element vertex 1000000000000");
        fails(
            &huge,
            Ply,
            "m:4",
            &["declares 1000000000000 vertices", "at most 20000000"],
        );
        let huge = PLY_TET.replace("element face 4", "element face 99999999999999999999");
        fails(
            &huge,
            Ply,
            "m:10",
            &["`99999999999999999999`, not a whole number"],
        );
        let bad_list = PLY_TET.replace("3 0 1 3 0\n", "5 0 1 3 0\n");
        fails(
            &bad_list,
            Ply,
            "m:22",
            &["face 1: too few numbers", "`vertex_indices` is missing"],
        );
        let extra = PLY_TET.replace("3 0 1 3 0\n", "3 0 1 3 0 0\n");
        fails(&extra, Ply, "m:22", &["face 1: more numbers on the line"]);
        let nan = PLY_TET.replace("0 1 0 1.5 0", "0 1 0 NaN 0");
        fails(&nan, Ply, "m:19", &["vertex 2: coordinate w is NaN"]);
        let word = PLY_TET.replace("0 1 0 1.5 0", "0 1 0 1.5 red");
        fails(
            &word,
            Ply,
            "m:19",
            &["vertex 2: `red` is not a number of the type of `red`"],
        );
        let out = PLY_TET.replace("3 1 2 3 0\n", "3 1 2 4 0\n");
        fails(
            &out,
            Ply,
            "m:24",
            &["face 3 refers to vertex 4, but the file has 4 vertices (0 to 3)"],
        );
        fails(
            PLY_TET.to_string() + "1 2 3\n",
            Ply,
            "m:26",
            &["text after the elements"],
        );
        fails(
            PLY_TET.replace("0 2 1 5\n", ""),
            Ply,
            "m:24",
            &["the file ends after 0 of 1 `edge` elements"],
        );
        fails(
            &PLY_TET[..PLY_TET.find("0 0 1 -2").unwrap()],
            Ply,
            "m:19",
            &["the file ends after 3 of 4 vertices"],
        );
        fails(
            &PLY_TET[..PLY_TET.find("end_header").unwrap()],
            Ply,
            "m:15",
            &["no `end_header`"],
        );
        fails(
            PLY_TET.replace("property float y", "property float16 y"),
            Ply,
            "m:6",
            &["unknown property type `float16`"],
        );
        fails(
            PLY_TET.replace("vertex_indices", "corners"),
            Ply,
            "m:10",
            &["no list property `vertex_indices`", "corners, flags"],
        );
        fails(
            PLY_TET.replace(
                "list uchar int vertex_indices",
                "list float int vertex_indices",
            ),
            Ply,
            "m:11",
            &["count type must be an integer"],
        );
        fails(
            PLY_TET.replace("format ascii 1.0", "format ascii 2.0"),
            Ply,
            "m:2",
            &["version `2.0`"],
        );
        fails(
            PLY_TET.replace("ply\n", "PLY\n"),
            Ply,
            "m:1",
            &["starts with the line `ply`"],
        );
        fails(
            PLY_TET.replace("format ascii 1.0\n", ""),
            Ply,
            "m:15",
            &["no `format` line"],
        );
        fails(
            PLY_TET
                .replacen("comment a", "comment \0", 1)
                .into_bytes()
                .into_iter()
                .map(|b| if b == 0 { 0xff } else { b })
                .collect::<Vec<u8>>(),
            Ply,
            "m:3",
            &["not UTF-8"],
        );
        let empty = PLY_TET
            .replace("element face 4", "element face 0")
            .replace("3 0 2 1 7\n3 0 1 3 0\n3 0 3 2 0\n3 1 2 3 0\n", "");
        fails(&empty, Ply, "m:21", &["no triangles"]);

        let tet = tetrahedron();
        let good = ply_bytes(&tet, true);
        let header = good.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let vertex = 8 + 4 + 1 + 8 + 4 + 2;
        fails(
            &good[..header + vertex + 10],
            Ply,
            &format!("m: byte {}", header + vertex),
            &["the file ends after 1 of 4 vertices"],
        );
        let faces = header + 4 * vertex;
        fails(
            &good[..faces + 5],
            Ply,
            &format!("m: byte {faces}"),
            &["the file ends after 0 of 4 faces"],
        );
        let mut bad = good.clone();
        bad[faces + 1..faces + 5].copy_from_slice(&9u32.to_le_bytes());
        fails(
            &bad,
            Ply,
            &format!("m: byte {faces}"),
            &["face 0 refers to vertex 9"],
        );
        let mut bad = good.clone();
        bad[faces] = 200;
        fails(
            &bad,
            Ply,
            &format!("m: byte {faces}"),
            &["the file ends after"],
        );
        let mut nan = good.clone();
        nan[header..header + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
        fails(
            &nan,
            Ply,
            &format!("m: byte {header}"),
            &["vertex 0: coordinate x is inf"],
        );
        let mut trailing = good.clone();
        trailing.extend(b"\x01\x02");
        fails(
            &trailing,
            Ply,
            &format!("m: byte {}", good.len()),
            &["2 bytes after the elements"],
        );
        fails(
            &good[..good.len() - 3],
            Ply,
            &format!("m: byte {}", good.len() - 11),
            &["the file ends after 1 of 2 `material` elements"],
        );
    }

    #[test]
    fn extensions_choose_the_format() {
        use MeshFormat::*;
        for (name, format) in [
            ("a.off", Off),
            ("a.4off", Off),
            ("a.NOFF", Off),
            ("b.OBJ", Obj),
            ("c.ply", Ply),
        ] {
            assert_eq!(MeshFormat::from_path(Path::new(name)), Ok(format), "{name}");
        }
        let e = MeshFormat::from_path(Path::new("mesh.stl"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("mesh.stl: unknown extension `.stl`")
                && e.contains(".4off")
                && e.contains(".ply"),
            "{e}"
        );
        let e = read_mesh4(Path::new("mesh")).unwrap_err().to_string();
        assert!(e.contains("no extension"), "{e}");
        let e = read_mesh4(Path::new("/nonexistent/mesh.off"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("/nonexistent/mesh.off: cannot read the file"),
            "{e}"
        );
    }

    #[test]
    fn long_words_are_shortened_in_errors() {
        let long = format!("4OFF\n4 4 6\n0 0 0 {}\n", "9".repeat(10_000) + "x");
        let e = error(long, MeshFormat::Off);
        assert!(e.len() < 400 && e.contains("bytes left out"), "{e}");
    }

    #[test]
    fn a_polygon_of_many_corners_repeating_one_is_refused_quickly() {
        let n = 100_000;
        let mut text = format!("4OFF\n{n} 1 0\n");
        for k in 0..n {
            text += &format!("{k} 0 0 0\n");
        }
        text += &format!("{}", n + 1);
        for k in 0..n {
            text += &format!(" {k}");
        }
        text += " 5\n";
        fails(
            &text,
            MeshFormat::Off,
            &format!("m:{}", n + 3),
            &["face 0 repeats vertex 5"],
        );
    }

    /// Every prefix of every valid file, and every file with one byte changed, reads or fails:
    /// never a panic.
    #[test]
    fn truncated_and_flipped_files_never_panic() {
        for (name, bytes, format, _) in valid_files() {
            for len in 0..bytes.len() {
                let _ = read(&bytes[..len], format);
            }
            let mut b = bytes.clone();
            for i in 0..b.len() {
                let old = b[i];
                for new in [
                    old ^ 0x01,
                    old ^ 0x80,
                    0xff,
                    0,
                    b' ',
                    b'\n',
                    b'-',
                    b'9',
                    b'#',
                    b'/',
                ] {
                    b[i] = new;
                    if let Ok(m) = read(&b, format) {
                        assert!(!m.triangles.is_empty(), "{name}");
                        let n = m.positions.len() as u32;
                        assert!(m.triangles.iter().flatten().all(|&v| v < n), "{name}");
                        assert!(m.positions.iter().all(|p| p.is_finite()), "{name}");
                    }
                }
                b[i] = old;
            }
        }
    }

    #[test]
    fn broken_fixtures_get_errors_naming_file_and_place() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/broken");
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .expect("fixtures/broken")
            .map(|e| e.expect("entry").path())
            .filter(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("mesh-"))
                    && p.extension().is_some_and(|e| e != "json")
            })
            .collect();
        files.sort();
        assert!(files.len() >= 12, "{files:?}");
        for path in files {
            let e = read_mesh4(&path).expect_err(&path.display().to_string());
            let text = e.to_string();
            assert!(
                text.starts_with(&path.display().to_string()),
                "does not name the file: {text}"
            );
            assert!(
                matches!(e.at, MeshFileLocation::Line(_) | MeshFileLocation::Byte(_)),
                "no line or byte: {text}"
            );
            assert!(text.len() < 600, "{text}");
        }
    }

    #[test]
    fn the_tetrahedron_fixture_reads() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/meshes/tetrahedron.4off");
        let mesh = read_mesh4(&path).expect("fixture");
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.triangles.len(), 4);
        assert_eq!(mesh.positions[3], DVec4::new(0.0, 0.0, 1.0, -2.0));
    }
}
