//! What the readers of other programs' tetrahedral meshes (VTU, Gmsh, Medit, TetGen) share:
//! errors that name the line or byte, a scanner of text and binary bytes (which skips a
//! UTF-8 byte-order mark), the kinds of cells (tetrahedra read, lower-dimensional cells
//! skipped, other solids refused), node tags mapped to dense indices, and the
//! [`PlainTetrahedra`] they give.

use super::{ImportError, MeshFileLocation, PlainTetrahedra, Solid, SolidKind};
use crate::convention::file_order;
use crate::limits::shorten;

pub(super) type Result<T> = std::result::Result<T, ImportError>;

/// The format being read, for errors; `format` grows as the header tells more (`Gmsh` becomes
/// `Gmsh 4.1 binary`).
#[derive(Clone, Debug)]
pub(super) struct Fail {
    pub format: String,
}

impl Fail {
    pub fn new(format: impl Into<String>) -> Self {
        Fail {
            format: format.into(),
        }
    }

    pub fn at(&self, at: MeshFileLocation, message: impl Into<String>) -> ImportError {
        ImportError::Tetrahedra {
            format: self.format.clone(),
            at,
            message: message.into(),
        }
    }

    pub fn byte(&self, byte: usize, message: impl Into<String>) -> ImportError {
        self.at(MeshFileLocation::Byte(byte), message)
    }

    pub fn file(&self, message: impl Into<String>) -> ImportError {
        self.at(MeshFileLocation::File, message)
    }
}

/// `, line 12`, `, byte 96` or nothing: where [`ImportError::Tetrahedra`] is.
pub(super) fn location(at: &MeshFileLocation) -> String {
    match at {
        MeshFileLocation::File => String::new(),
        MeshFileLocation::Line(n) => format!(", line {n}"),
        MeshFileLocation::Byte(b) => format!(", byte {b}"),
    }
}

/// A position in a file's bytes, read as whitespace-separated words (text) or as binary
/// numbers. Errors name the line of the last word read, or the byte offset where `binary`.
pub(super) struct Scan<'a> {
    pub bytes: &'a [u8],
    pub pos: usize,
    /// The line `pos` is on, counted from 1 (meaningful while only text was read).
    pub line: usize,
    /// Where the last word began: its line and byte.
    word_at: (usize, usize),
    /// Whether `#` starts a comment that runs to the end of the line.
    pub comments: bool,
    /// Whether errors name byte offsets (binary files) instead of lines.
    pub binary: bool,
    /// Binary numbers are little-endian.
    pub little: bool,
    pub fail: Fail,
}

/// The length of a UTF-8 byte-order mark (EF BB BF) at the start of `bytes`, 3 or 0: Windows
/// editors write one before text files, and every reader skips it, so that byte offsets
/// stay the file's.
pub(super) fn bom(bytes: &[u8]) -> usize {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        3
    } else {
        0
    }
}

impl<'a> Scan<'a> {
    /// A scanner at the start of `bytes`, past a byte-order mark.
    pub fn new(bytes: &'a [u8], fail: Fail) -> Self {
        Scan {
            bytes,
            pos: bom(bytes),
            line: 1,
            word_at: (1, 0),
            comments: false,
            binary: false,
            little: true,
            fail,
        }
    }

    /// Where the last word read is.
    pub fn here(&self) -> MeshFileLocation {
        if self.binary {
            MeshFileLocation::Byte(self.word_at.1)
        } else {
            MeshFileLocation::Line(self.word_at.0)
        }
    }

    /// An error at the last word read.
    pub fn err(&self, message: impl Into<String>) -> ImportError {
        self.fail.at(self.here(), message)
    }

    /// An error at the current position.
    pub fn err_now(&self, message: impl Into<String>) -> ImportError {
        let at = if self.binary {
            MeshFileLocation::Byte(self.pos)
        } else {
            MeshFileLocation::Line(self.line)
        };
        self.fail.at(at, message)
    }

    pub fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// Moves past whitespace (and comments), counting lines.
    fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            match b {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                b'#' if self.comments => {
                    while self.pos < self.bytes.len() && self.bytes[self.pos] != b'\n' {
                        self.pos += 1;
                    }
                }
                b if b.is_ascii_whitespace() => self.pos += 1,
                _ => break,
            }
        }
    }

    /// The next word, or `None` at the end of the file.
    pub fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            if self.comments && self.bytes[self.pos] == b'#' {
                break;
            }
            self.pos += 1;
        }
        self.word_at = (self.line, start);
        (self.pos > start).then(|| &self.bytes[start..self.pos])
    }

    /// The next word; `what` names it where the file ends before it.
    pub fn word(&mut self, what: &str) -> Result<&'a [u8]> {
        self.token()
            .ok_or_else(|| self.err_now(format!("the file ends where {what} should be")))
    }

    /// The next word as a whole number.
    pub fn u64(&mut self, what: &str) -> Result<u64> {
        let w = self.word(what)?;
        parse_u64(w).ok_or_else(|| {
            self.err(format!(
                "{what} is `{}`, not a whole number",
                shorten(&String::from_utf8_lossy(w))
            ))
        })
    }

    /// The next word as a signed whole number.
    pub fn i64(&mut self, what: &str) -> Result<i64> {
        let w = self.word(what)?;
        parse_i64(w).ok_or_else(|| {
            self.err(format!(
                "{what} is `{}`, not a whole number",
                shorten(&String::from_utf8_lossy(w))
            ))
        })
    }

    /// The next word as a count of things each of which takes at least `each` bytes of the
    /// rest of the file: checked against them, so that a lying count allocates nothing.
    pub fn count(&mut self, what: &str, each: usize) -> Result<usize> {
        let n = self.u64(&format!("the number of {what}"))?;
        self.check_count(n, what, each)
    }

    /// `n` things of at least `each` bytes must fit in the rest of the file.
    pub fn check_count(&self, n: u64, what: &str, each: usize) -> Result<usize> {
        let left = self.left();
        if n.checked_mul(each as u64).is_none_or(|b| b > left as u64) {
            return Err(self.err(format!(
                "the file claims {n} {what}, but only {left} bytes are left, and each needs at least {each}: it is truncated, or the count is wrong"
            )));
        }
        Ok(n as usize)
    }

    /// The next word as a number.
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        let w = self.word(what)?;
        parse_f64(w).ok_or_else(|| {
            self.err(format!(
                "{what} is `{}`, not a number",
                shorten(&String::from_utf8_lossy(w))
            ))
        })
    }

    /// The next word as a finite coordinate of vertex `vertex`.
    pub fn coordinate(&mut self, vertex: usize, axis: usize) -> Result<f64> {
        let what = ["x", "y", "z"][axis];
        let x = self.f64(&format!("coordinate {what} of vertex {vertex}"))?;
        if !x.is_finite() {
            return Err(self.err(non_finite(vertex, axis, x)));
        }
        Ok(x)
    }

    /// The rest of the current line (without its `\r\n` or `\n`), moving past its newline.
    pub fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        self.skip_line();
        let line = &self.bytes[start..self.pos];
        let line = line.strip_suffix(b"\n").unwrap_or(line);
        line.strip_suffix(b"\r").unwrap_or(line)
    }

    /// Moves past the rest of the current line, its newline included.
    pub fn skip_line(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            self.pos += 1;
            if b == b'\n' {
                self.line += 1;
                break;
            }
        }
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let start = self.pos;
        self.word_at = (self.line, start);
        let end = start.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(self.fail.byte(
                start,
                format!(
                    "the file ends at byte {} where {what} needs {n} bytes: it is truncated",
                    self.bytes.len()
                ),
            ));
        };
        self.pos = end;
        Ok(&self.bytes[start..end])
    }

    /// A binary 32-bit signed integer.
    pub fn bin_i32(&mut self, what: &str) -> Result<i32> {
        let b: [u8; 4] = self.take(4, what)?.try_into().expect("4 bytes");
        Ok(if self.little {
            i32::from_le_bytes(b)
        } else {
            i32::from_be_bytes(b)
        })
    }

    /// A binary unsigned integer of `size` bytes (4 or 8).
    pub fn bin_uint(&mut self, size: usize, what: &str) -> Result<u64> {
        let b = self.take(size, what)?;
        Ok(uint(b, self.little))
    }
}

/// An unsigned integer of 1, 2, 4 or 8 bytes.
pub(super) fn uint(b: &[u8], little: bool) -> u64 {
    let mut x = [0u8; 8];
    if little {
        x[..b.len()].copy_from_slice(b);
        u64::from_le_bytes(x)
    } else {
        x[8 - b.len()..].copy_from_slice(b);
        u64::from_be_bytes(x)
    }
}

/// A binary double.
pub(super) fn f64_at(b: &[u8], little: bool) -> f64 {
    let b: [u8; 8] = b[..8].try_into().expect("8 bytes");
    if little {
        f64::from_le_bytes(b)
    } else {
        f64::from_be_bytes(b)
    }
}

pub(super) fn non_finite(vertex: usize, axis: usize, x: f64) -> String {
    format!(
        "coordinate {} of vertex {vertex} is {x}, not a finite number: every coordinate must be finite",
        ["x", "y", "z"][axis]
    )
}

pub(super) fn parse_u64(w: &[u8]) -> Option<u64> {
    let w = w.strip_prefix(b"+").unwrap_or(w);
    if w.is_empty() || w.len() > 20 {
        return None;
    }
    let mut n: u64 = 0;
    for &b in w {
        if !b.is_ascii_digit() {
            return None;
        }
        n = n.checked_mul(10)?.checked_add(u64::from(b - b'0'))?;
    }
    Some(n)
}

pub(super) fn parse_i64(w: &[u8]) -> Option<i64> {
    match w.strip_prefix(b"-") {
        Some(rest) => {
            let n = parse_u64(rest)?;
            if n <= i64::MAX as u64 + 1 {
                Some((n as i64).wrapping_neg())
            } else {
                None
            }
        }
        None => parse_u64(w).and_then(|n| i64::try_from(n).ok()),
    }
}

pub(super) fn parse_f64(w: &[u8]) -> Option<f64> {
    std::str::from_utf8(w).ok()?.parse().ok()
}

/// What a reader does with a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// A tetrahedron whose first four nodes are its corners (linear, quadratic or higher
    /// order).
    Tet,
    /// A point, line, triangle, quadrilateral or other cell of dimension below 3: skipped.
    Lower,
    /// A hexahedron, wedge or pyramid (linear or of higher order), read by its corners:
    /// corner i in VTK's order is the file's node `order[i]`.
    Cell(SolidKind, &'static [usize]),
    /// Another solid (a polyhedron, a hexagonal prism, ...), named in the plural: refused.
    Solid(&'static str),
}

/// VTK's and Gmsh's corner order of a hexahedron or pyramid, and VTK's of a wedge.
pub(super) const SAME: &[usize] = &[0, 1, 2, 3, 4, 5, 6, 7];
/// A VTK voxel's corners (x fastest, then y, then z) in a hexahedron's order.
const VOXEL: &[usize] = &[0, 1, 3, 2, 4, 5, 7, 6];
/// A Gmsh prism's corners in VTK's wedge order: Gmsh's first triangle turns towards the
/// opposite one, VTK's away from it.
pub(super) const GMSH_PRISM: &[usize] = &[0, 2, 1, 3, 5, 4];

/// The kind of a VTK cell type, or `None` where VTK defines no such type.
pub(super) fn vtk_kind(t: u64) -> Option<Kind> {
    Some(match t {
        10 | 24 | 71 | 78 => Kind::Tet,
        0..=9 | 21..=23 | 28 | 30 | 34..=36 | 51..=54 | 60..=63 | 68..=70 | 75..=77 => Kind::Lower,
        11 => Kind::Cell(SolidKind::Hexahedron, VOXEL),
        12 | 25 | 29 | 33 => Kind::Cell(SolidKind::Hexahedron, SAME),
        13 | 26 | 31 | 32 => Kind::Cell(SolidKind::Wedge, SAME),
        14 | 27 | 37 => Kind::Cell(SolidKind::Pyramid, SAME),
        15 => Kind::Solid("pentagonal prisms"),
        16 => Kind::Solid("hexagonal prisms"),
        41 => Kind::Solid("convex point sets"),
        42 => Kind::Solid("polyhedra"),
        55 | 64 => Kind::Solid("parametric or higher-order tetrahedra (no corner order known)"),
        56 | 67 | 72 | 79 => Kind::Solid("higher-order hexahedra"),
        65 | 73 | 80 => Kind::Solid("higher-order wedges"),
        66 | 74 | 81 => Kind::Solid("higher-order pyramids"),
        _ => return None,
    })
}

/// Whether a VTK cell of type `t` and kind `kind` (of [`vtk_kind`]) may have `len` points:
/// a tetrahedron, hexahedron, wedge or pyramid has as many as its type says (at least its
/// corners where the type does not fix them); the message after `cell N` if not.
pub(super) fn vtk_cell_size(kind: Kind, t: u64, len: usize) -> std::result::Result<(), String> {
    let least = match kind {
        Kind::Tet => 4,
        Kind::Cell(solid, _) => solid.corners(),
        Kind::Lower | Kind::Solid(_) => return Ok(()),
    };
    match vtk_nodes(t) {
        Some(n) if n != len => Err(format!("has {len} points, but a cell of type {t} has {n}")),
        None if len < least => Err(format!(
            "has {len} points, but a cell of type {t} has at least {least}"
        )),
        _ => Ok(()),
    }
}

/// The number of nodes of a VTK cell type where it has a fixed one (a tetrahedron, a
/// hexahedron, a wedge or a pyramid, linear or of higher order).
fn vtk_nodes(t: u64) -> Option<usize> {
    Some(match t {
        10 => 4,
        24 => 10,
        11 | 12 => 8,
        25 => 20,
        29 => 27,
        33 => 24,
        13 => 6,
        26 => 15,
        31 => 12,
        32 => 18,
        14 => 5,
        27 => 13,
        37 => 19,
        _ => return None,
    })
}

/// A hexahedron, wedge or pyramid whose nodes, as the file orders them, are `nodes` (at least
/// its corners), its corner i in VTK's order being `nodes[order[i]]`; `id` its number in the
/// file.
pub(super) fn solid(kind: SolidKind, order: &[usize], nodes: &[u32], id: u64) -> Solid {
    let mut corners = [0u32; 8];
    for (c, &o) in corners.iter_mut().zip(&order[..kind.corners()]) {
        *c = nodes[o];
    }
    Solid { kind, corners, id }
}

/// The cells read so far: the tetrahedra (in halo4d's orientation), the hexahedra, wedges and
/// pyramids, how many lower-dimensional cells were skipped, and the other solids found.
#[derive(Default)]
pub(super) struct Cells {
    pub tets: Vec<[u32; 4]>,
    pub solids: Vec<Solid>,
    pub skipped: usize,
    /// Each kind of other solid: its name, how many, where the first is.
    others: Vec<(&'static str, usize, MeshFileLocation)>,
}

impl Cells {
    pub fn with_capacity(tets: usize) -> Self {
        Cells {
            tets: Vec::with_capacity(tets),
            ..Cells::default()
        }
    }

    /// A tetrahedron as the file orders it (det[b − a, c − a, d − a] > 0 when positive).
    #[inline]
    pub fn tet(&mut self, tet: [u32; 4]) {
        self.tets.push(file_order(tet));
    }

    /// A hexahedron, wedge or pyramid whose nodes (as the file orders them, at least its
    /// corners) are `nodes`, its corner i in VTK's order being `nodes[order[i]]`; `id` its
    /// number in the file.
    pub fn solid(&mut self, kind: SolidKind, order: &[usize], nodes: &[u32], id: u64) {
        self.solids.push(solid(kind, order, nodes, id));
    }

    /// `n` solids that halo4d does not read, the first at `at`.
    pub fn other(&mut self, name: &'static str, n: usize, at: MeshFileLocation) {
        match self.others.iter_mut().find(|o| o.0 == name) {
            Some(o) => o.1 += n,
            None => self.others.push((name, n, at)),
        }
    }

    /// The tetrahedra and the hexahedra, wedges and pyramids, none or more, unless the file
    /// has other solids. A file without a cell is read (its check fails with `0
    /// tetrahedra`, in every format alike).
    pub fn finish(self, fail: &Fail) -> Result<(Vec<[u32; 4]>, Vec<Solid>)> {
        if let Some(&(_, _, at)) = self.others.first() {
            let list: Vec<String> = self
                .others
                .iter()
                .map(|(name, n, at)| match at {
                    MeshFileLocation::File => format!("{n} {name}"),
                    MeshFileLocation::Line(l) => format!("{n} {name} (the first at line {l})"),
                    MeshFileLocation::Byte(b) => format!("{n} {name} (the first at byte {b})"),
                })
                .collect();
            return Err(fail.at(
                at,
                format!(
                    "the mesh has {} besides its {} tetrahedra and {} hexahedra, wedges and pyramids: halo4d checks meshes of these four kinds of cell only; split the other cells into them first",
                    list.join(", "),
                    self.tets.len(),
                    self.solids.len()
                ),
            ));
        }
        Ok((self.tets, self.solids))
    }
}

/// Node tags (Gmsh's, which may be sparse and in any order) and their positions, as read.
#[derive(Default)]
pub(super) struct Tagged {
    pub tags: Vec<u64>,
    pub positions: Vec<[f64; 3]>,
}

/// Tags mapped to dense indices, in the order of the tags.
pub(super) enum TagMap {
    /// Tags from `min` with few gaps: the index of each, `u32::MAX` for none.
    Dense { min: u64, index: Vec<u32> },
    /// Sparse tags, sorted: a tag's index is its place.
    Sparse(Vec<u64>),
}

impl TagMap {
    #[inline]
    pub fn get(&self, tag: u64) -> Option<u32> {
        match self {
            TagMap::Dense { min, index } => {
                let i = *index.get(usize::try_from(tag.checked_sub(*min)?).ok()?)?;
                (i != u32::MAX).then_some(i)
            }
            TagMap::Sparse(tags) => tags.binary_search(&tag).ok().map(|i| i as u32),
        }
    }
}

impl Tagged {
    /// Room for `n` nodes (a count already checked against the file's bytes).
    pub fn with_capacity(n: usize) -> Self {
        Tagged {
            tags: Vec::with_capacity(n),
            positions: Vec::with_capacity(n),
        }
    }

    pub fn push(&mut self, tag: u64, position: [f64; 3]) {
        self.tags.push(tag);
        self.positions.push(position);
    }

    /// The positions in the order of their tags, and the map from tags to their indices;
    /// or the first tag that appears twice.
    pub fn finish(self) -> std::result::Result<(Vec<[f64; 3]>, TagMap), u64> {
        let n = self.tags.len();
        let (Some(&min), Some(&max)) = (self.tags.iter().min(), self.tags.iter().max()) else {
            return Ok((Vec::new(), TagMap::Sparse(Vec::new())));
        };
        let span = max - min;
        if span < 2 * n as u64 + 1024 {
            // Place each node at its tag, then number the tags in order.
            let mut index = vec![u32::MAX; span as usize + 1];
            for (k, &t) in self.tags.iter().enumerate() {
                let slot = &mut index[(t - min) as usize];
                if *slot != u32::MAX {
                    return Err(t);
                }
                *slot = k as u32;
            }
            let mut positions = Vec::with_capacity(n);
            for slot in index.iter_mut().filter(|s| **s != u32::MAX) {
                positions.push(self.positions[*slot as usize]);
                *slot = positions.len() as u32 - 1;
            }
            Ok((positions, TagMap::Dense { min, index }))
        } else {
            let mut order: Vec<u32> = (0..n as u32).collect();
            order.sort_unstable_by_key(|&k| self.tags[k as usize]);
            let tags: Vec<u64> = order.iter().map(|&k| self.tags[k as usize]).collect();
            if let Some(w) = tags.windows(2).find(|w| w[0] == w[1]) {
                return Err(w[0]);
            }
            let positions = order.iter().map(|&k| self.positions[k as usize]).collect();
            Ok((positions, TagMap::Sparse(tags)))
        }
    }
}

/// The cells of a file without halo4d's layout: `name` (the file's stem), `format` as
/// [`PlainTetrahedra::format`] says it, the tetrahedra and other solids of
/// [`Cells::finish`].
pub(super) fn plain(
    name: &str,
    format: &str,
    positions: Vec<[f64; 3]>,
    (tets, solids): (Vec<[u32; 4]>, Vec<Solid>),
) -> Result<PlainTetrahedra> {
    PlainTetrahedra {
        name: name.to_string(),
        positions,
        tets,
        why: format!("a {format} mesh, which has no halo layout (another program's tetrahedra)"),
        format: format.to_string(),
        pieces: Vec::new(),
        piece_of: Vec::new(),
        solids,
    }
    .validate()
}
