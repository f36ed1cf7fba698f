//! Medit `.mesh` files, ASCII (INRIA's format, which libMeshb reads and writes): a keyword,
//! then a count, then that many entries, each ending with a reference number.
//!
//! `MeshVersionFormatted 1` to `4` and `Dimension 3` come first; `Vertices` (x y z ref) and
//! `Tetrahedra` (four vertex numbers counted from 1, and ref) are read, `TetrahedraP2` by
//! the first four of its ten vertices, the corners; edges, triangles, quadrilaterals,
//! corners, ridges, required entities, normals and tangents are skipped by their known
//! sizes, and sections this reader does not know up to the next keyword; `Hexahedra`,
//! `Prisms` and `Pyramids` are an error. `End` (or the end of the file) ends the mesh; `#`
//! starts a comment.

use super::PlainTetrahedra;
use super::tetfile::{Cells, Fail, Result, Scan, parse_f64, plain};
use crate::limits::shorten;

/// The format's name.
const FORMAT: &str = "Medit .mesh";

/// Sections skipped, with the numbers of words each entry has; cells among them count as
/// skipped cells.
const SKIPPED: [(&str, usize, bool); 20] = [
    ("Edges", 3, true),
    ("Triangles", 4, true),
    ("Quadrilaterals", 5, true),
    ("EdgesP2", 4, true),
    ("TrianglesP2", 7, true),
    ("QuadrilateralsQ2", 10, true),
    ("Corners", 1, false),
    ("Ridges", 1, false),
    ("RequiredVertices", 1, false),
    ("RequiredEdges", 1, false),
    ("RequiredTriangles", 1, false),
    ("RequiredQuadrilaterals", 1, false),
    ("RequiredTetrahedra", 1, false),
    ("Normals", 3, false),
    ("Tangents", 3, false),
    ("NormalAtVertices", 2, false),
    ("NormalAtTriangleVertices", 3, false),
    ("NormalAtQuadrilateralVertices", 3, false),
    ("TangentAtEdges", 3, false),
    ("TangentAtVertices", 2, false),
];

/// Solids other than tetrahedra, with the numbers of words each entry has.
const SOLIDS: [(&str, usize, &str); 5] = [
    ("Hexahedra", 9, "hexahedra"),
    ("HexahedraQ2", 28, "hexahedra"),
    ("Prisms", 7, "prisms"),
    ("Pentahedra", 7, "prisms"),
    ("Pyramids", 6, "pyramids"),
];

/// Reads the tetrahedra of a Medit `.mesh` file (ASCII); `name` names the mesh (the file's
/// stem).
pub fn read_medit(bytes: &[u8], name: &str) -> Result<PlainTetrahedra> {
    let mut s = Scan::new(bytes, Fail::new(FORMAT));
    s.comments = true;
    let first = s.token().unwrap_or_default();
    if !first.eq_ignore_ascii_case(b"MeshVersionFormatted") {
        return Err(s.err(format!(
            "a Medit .mesh file begins with `MeshVersionFormatted`, this one with `{}`{}",
            shorten(&String::from_utf8_lossy(first)),
            if first.len() == 4 && first[0] < 16 {
                " (a binary .meshb? halo4d reads the ASCII .mesh)"
            } else {
                ""
            }
        )));
    }
    let version = s.u64("the version")?;
    if !(1..=4).contains(&version) {
        return Err(s.err(format!(
            "MeshVersionFormatted {version}: the versions are 1 to 4"
        )));
    }
    let mut dimension = None;
    let mut positions: Option<Vec<[f64; 3]>> = None;
    let mut cells = Cells::default();
    let mut pending: Option<&[u8]> = None;
    while let Some(word) = pending.take().or_else(|| s.token()) {
        let is = |k: &str| word.eq_ignore_ascii_case(k.as_bytes());
        if is("End") {
            break;
        } else if is("Dimension") {
            let d = s.u64("the dimension")?;
            if d != 3 {
                return Err(s.err(format!(
                    "Dimension {d}: halo4d reads tetrahedral meshes in 3D (Dimension 3)"
                )));
            }
            dimension = Some(d);
        } else if is("Vertices") {
            if dimension.is_none() {
                return Err(s.err("Vertices before `Dimension 3`"));
            }
            if positions.is_some() {
                return Err(s.err("a second Vertices section"));
            }
            // "0 0 0 0\n": a vertex takes at least 8 bytes.
            let n = s.count("vertices", 8)?;
            let mut p = Vec::with_capacity(n);
            for k in 1..=n {
                p.push([
                    s.coordinate(k, 0)?,
                    s.coordinate(k, 1)?,
                    s.coordinate(k, 2)?,
                ]);
                s.word("the vertex's reference")?;
            }
            positions = Some(p);
        } else if is("Tetrahedra") || is("TetrahedraP2") {
            let nodes = if is("Tetrahedra") { 4 } else { 10 };
            let Some(p) = &positions else {
                return Err(s.err("Tetrahedra before Vertices: the vertices must come first"));
            };
            let nv = p.len() as u64;
            let n = s.count("tetrahedra", 2 * (nodes + 1))?;
            cells.tets.reserve(n);
            for k in 1..=n {
                let mut tet = [0u32; 4];
                for slot in &mut tet {
                    let i = s.u64("a vertex number")?;
                    if !(1..=nv).contains(&i) {
                        return Err(s.err(format!(
                            "tetrahedron {k} names vertex {i}, but the vertices are numbered 1 to {nv}"
                        )));
                    }
                    *slot = (i - 1) as u32;
                }
                for _ in 4..nodes {
                    s.word("a vertex number")?;
                }
                s.word("the tetrahedron's reference")?;
                cells.tet(tet);
            }
        } else if let Some(&(kw, words, cell)) = SKIPPED.iter().find(|k| is(k.0)) {
            let n = s.count(kw, 2 * words)?;
            for _ in 0..n * words {
                s.word(kw)?;
            }
            if cell {
                cells.skipped += n;
            }
        } else if let Some(&(kw, words, solid)) = SOLIDS.iter().find(|k| is(k.0)) {
            let n = s.count(kw, 2 * words)?;
            let at = s.here();
            for _ in 0..n * words {
                s.word(kw)?;
            }
            if n > 0 {
                cells.other(solid, n, at);
            }
        } else if word[0].is_ascii_alphabetic() && parse_f64(word).is_none() {
            // A section this reader does not know: up to the next keyword.
            while let Some(w) = s.token() {
                if w[0].is_ascii_alphabetic() && parse_f64(w).is_none() {
                    pending = Some(w);
                    break;
                }
            }
        } else {
            return Err(s.err(format!(
                "expected a keyword (Vertices, Tetrahedra, ..., End), found `{}`: a section holds more entries than its count says",
                shorten(&String::from_utf8_lossy(word))
            )));
        }
    }
    let positions = positions.ok_or_else(|| s.fail.file("the file has no Vertices section"))?;
    plain(name, FORMAT, positions, cells.finish(&s.fail)?)
}
