//! TetGen's `.node` and `.ele` files (TetGen's manual, "File Formats"): the vertices, then
//! the tetrahedra, two files with the same stem.
//!
//! `.node`: a header `vertices dimension attributes boundary_markers` (dimension 3), then a
//! line per vertex `index x y z`, its attributes and marker after (skipped). The first
//! index, 0 or 1, says how the `.ele` file counts; the others follow it one by one.
//! `.ele`: a header `tetrahedra nodes region_attribute` with 4 or 10 nodes per tetrahedron
//! (`-o2`: the four corners first, then the edges' midpoints), then a line per tetrahedron
//! `index n1 ... nk`, its region attribute after (skipped). `#` starts a comment.

use super::tetfile::{Cells, Fail, Result, Scan, plain};
use super::{ImportError, PlainTetrahedra};
use std::path::Path;

/// The format's name, as [`PlainTetrahedra::format`] gives it.
const FORMAT: &str = "TetGen .node/.ele";

/// Reads the tetrahedra of TetGen's `.node` and `.ele` files, given their bytes; `name`
/// names the mesh (the files' stem) and, with `.node` or `.ele`, the file in errors.
pub fn read_tetgen(node: &[u8], ele: &[u8], name: &str) -> Result<PlainTetrahedra> {
    let (positions, first) = nodes(node, &format!("TetGen {name}.node"))?;
    let tets = elements(ele, &format!("TetGen {name}.ele"), positions.len(), first)?;
    plain(name, FORMAT, positions, tets)
}

/// Reads TetGen's files given either: the `.node` and the `.ele` beside it with the same
/// stem.
pub(super) fn read_tetgen_files(path: &Path, name: &str) -> Result<PlainTetrahedra> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let upper = !ext.is_empty() && ext.chars().all(|c| c.is_ascii_uppercase());
    let sibling = |e: &str| {
        path.with_extension(if upper {
            e.to_ascii_uppercase()
        } else {
            e.to_string()
        })
    };
    let read = |p: &Path, what: &str| {
        std::fs::read(p).map_err(|e| ImportError::Tetrahedra {
            format: FORMAT.into(),
            at: super::MeshFileLocation::File,
            message: format!(
                "cannot read {} ({what}): {e}; TetGen's mesh is a .node and an .ele file with the same stem, side by side",
                p.display()
            ),
        })
    };
    let node = read(&sibling("node"), "the vertices")?;
    let ele = read(&sibling("ele"), "the tetrahedra")?;
    read_tetgen(&node, &ele, name)
}

/// The vertices of a `.node` file, and the index of its first (0 or 1).
fn nodes(bytes: &[u8], format: &str) -> Result<(Vec<[f64; 3]>, u64)> {
    let mut s = Scan::new(bytes, Fail::new(format));
    s.comments = true;
    // "0 0 0 0\n": a vertex takes at least 8 bytes.
    let n = s.count("vertices", 8)?;
    let dimension = s.u64("the dimension")?;
    if dimension != 3 {
        return Err(s.err(format!(
            "dimension {dimension}: halo4d reads tetrahedral meshes in 3D (dimension 3)"
        )));
    }
    let attributes = s.count("attributes", 0)?;
    let markers = s.u64("the number of boundary markers")?;
    if markers > 1 {
        return Err(s.err(format!("{markers} boundary markers: 0 or 1")));
    }
    if n == 0 {
        return Err(s.err(
            "the file has no vertices (a .node of 0 vertices leaves them to a .poly file, which halo4d does not read)",
        ));
    }
    let extra = attributes + markers as usize;
    let mut positions = Vec::with_capacity(n);
    let mut first = 0;
    for k in 0..n as u64 {
        let index = s.u64("a vertex index")?;
        if k == 0 {
            if index > 1 {
                return Err(s.err(format!(
                    "the first vertex is numbered {index}: TetGen numbers vertices from 0 or 1"
                )));
            }
            first = index;
        } else if index != first + k {
            return Err(s.err(format!(
                "vertex {} is numbered {index}: the vertices must be numbered one by one from {first}",
                k + 1
            )));
        }
        let v = index as usize;
        positions.push([
            s.coordinate(v, 0)?,
            s.coordinate(v, 1)?,
            s.coordinate(v, 2)?,
        ]);
        for _ in 0..extra {
            s.word("an attribute or boundary marker")?;
        }
    }
    if let Some(w) = s.token() {
        return Err(s.err(format!(
            "`{}` after the {n} vertices the header claims",
            crate::limits::shorten(&String::from_utf8_lossy(w))
        )));
    }
    Ok((positions, first))
}

/// The tetrahedra of an `.ele` file, whose vertex indices count from `first`.
fn elements(
    bytes: &[u8],
    format: &str,
    nv: usize,
    first: u64,
) -> Result<(Vec<[u32; 4]>, Vec<super::Solid>)> {
    let fail = Fail::new(format);
    let mut s = Scan::new(bytes, fail.clone());
    s.comments = true;
    // "0 0 0 0 0\n": a tetrahedron takes at least 10 bytes.
    let n = s.count("tetrahedra", 10)?;
    let nodes = s.u64("the number of nodes per tetrahedron")?;
    if !(nodes == 4 || nodes == 10) {
        return Err(s.err(format!(
            "{nodes} nodes per tetrahedron: TetGen writes 4, or 10 with -o2"
        )));
    }
    let attributes = s.u64("the number of region attributes")?;
    let attributes = s.check_count(attributes, "region attributes per tetrahedron", 0)?;
    let mut cells = Cells::with_capacity(n);
    let last = first + nv as u64 - 1;
    for k in 1..=n {
        s.u64("a tetrahedron's index")?;
        let mut tet = [0u32; 4];
        for slot in &mut tet {
            let i = s.u64("a vertex index")?;
            if !(first..=last).contains(&i) {
                return Err(s.err(format!(
                    "tetrahedron {k} names vertex {i}, but the .node file numbers its vertices {first} to {last}"
                )));
            }
            *slot = (i - first) as u32;
        }
        for _ in 4..nodes {
            s.word("a vertex index")?;
        }
        for _ in 0..attributes {
            s.word("a region attribute")?;
        }
        cells.tet(tet);
    }
    if let Some(w) = s.token() {
        return Err(s.err(format!(
            "`{}` after the {n} tetrahedra the header claims",
            crate::limits::shorten(&String::from_utf8_lossy(w))
        )));
    }
    cells.finish(&fail)
}
