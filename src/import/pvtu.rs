//! PVTU files: VTK's parallel XML `PUnstructuredGrid` (VTK's "VTK File Formats", parallel
//! XML section), which holds no data itself but names its pieces' `.vtu` files
//! (`<Piece Source="ball_0.vtu"/>`, a path relative to the `.pvtu`'s folder).
//!
//! Takes: the path of a `.pvtu`. Gives: one [`PlainTetrahedra`] of all its pieces, read side
//! by side (rayon), each with [`super::read_vtu`]'s reader, then joined in the `.pvtu`'s
//! order: the points of each piece after those of the pieces before it, except that a
//! point whose coordinates are exactly those (equal values) of a point of an earlier piece
//! is that point (the points where pieces meet are written in each of them); points that
//! repeat within one piece stay apart, as the piece's own file has them. Which piece each
//! tetrahedron came from and the pieces' file names are kept
//! ([`PlainTetrahedra::piece_of`], [`PlainTetrahedra::pieces`]).
//!
//! Guarantees: an error in a piece names the `.pvtu`, the piece's file and the byte in it;
//! a missing piece is an error naming the file looked for; a piece may hold no cell (a
//! process that had none), and the whole none either (its check then fails with `0
//! tetrahedra`, as for any file).

use super::tetfile::{Fail, Result, bom};
use super::vtu::{attribute, read_vtu};
use super::{ImportError, MeshFileLocation, PlainTetrahedra, Solid};
use crate::limits::shorten;
use quick_xml::events::Event;
use quick_xml::reader::Reader;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// Reads the tetrahedra of a `.pvtu` file and of the pieces it names, joined into one mesh
/// (named by the `.pvtu`'s stem) whose points are welded where pieces meet (see the
/// module's documentation).
pub fn read_pvtu(path: &Path) -> Result<PlainTetrahedra> {
    let file = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let fail = Fail::new(format!("PVTU {file}"));
    let bytes = std::fs::read(path)?;
    let sources = pieces(&bytes, &fail)?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let read: Vec<Result<PlainTetrahedra>> = sources
        .par_iter()
        .enumerate()
        .map(|(k, (source, at))| {
            let piece = folder.join(source);
            let bytes = std::fs::read(&piece).map_err(|e| {
                fail.byte(
                    *at,
                    format!(
                        "piece {k}'s file `{}` ({}) cannot be read: {e}; a .pvtu names its pieces' .vtu files relative to its own folder: keep them where it says",
                        shorten(source),
                        shorten(&piece.display().to_string())
                    ),
                )
            })?;
            let stem = Path::new(source)
                .file_stem()
                .map_or_else(|| source.clone(), |s| s.to_string_lossy().into_owned());
            read_vtu(&bytes, &stem).map_err(|e| in_piece(e, &file, source))
        })
        .collect();
    let mut meshes = Vec::with_capacity(read.len());
    for r in read {
        meshes.push(r?);
    }
    weld(
        &name,
        &fail,
        sources.into_iter().map(|s| s.0).collect(),
        meshes,
    )
}

/// An error of a piece, said as one of the `.pvtu`'s: it names both files.
fn in_piece(e: ImportError, pvtu: &str, source: &str) -> ImportError {
    let piece = format!("PVTU {pvtu}, piece {}", shorten(source));
    match e {
        ImportError::Tetrahedra {
            format,
            at,
            message,
        } => ImportError::Tetrahedra {
            format: format!("{piece} ({format})"),
            at,
            message,
        },
        ImportError::BadTetrahedra { message, .. } => ImportError::BadTetrahedra {
            name: piece,
            message,
        },
        e => ImportError::Tetrahedra {
            format: piece,
            at: MeshFileLocation::File,
            message: e.to_string(),
        },
    }
}

/// The pieces a `.pvtu` names: each one's `Source` and the byte of its tag.
fn pieces(bytes: &[u8], fail: &Fail) -> Result<Vec<(String, usize)>> {
    let skip = bom(bytes);
    let mut reader = Reader::from_reader(&bytes[skip..]);
    let mut seen_file = false;
    let mut sources = Vec::new();
    loop {
        let at = reader.buffer_position() as usize + skip;
        let event = reader.read_event().map_err(|e| {
            fail.byte(
                reader.error_position() as usize + skip,
                format!("the XML is not well formed: {e}"),
            )
        })?;
        let e = match event {
            Event::Start(e) | Event::Empty(e) => e,
            Event::Eof => break,
            _ => continue,
        };
        let name = e.local_name();
        if !seen_file {
            if name.as_ref() != b"VTKFile" {
                return Err(fail.byte(
                    at,
                    format!(
                        "a PVTU file's first element is VTKFile, this one's is `{}`",
                        shorten(&String::from_utf8_lossy(name.as_ref()))
                    ),
                ));
            }
            seen_file = true;
            match attribute(&e, "type", fail, at)?.as_deref() {
                Some("PUnstructuredGrid") => {}
                Some("UnstructuredGrid") => {
                    return Err(fail.byte(
                        at,
                        "the file is a VTU UnstructuredGrid, not a PUnstructuredGrid: name it .vtu",
                    ));
                }
                other => {
                    return Err(fail.byte(
                        at,
                        format!(
                            "the file's type is {}, not PUnstructuredGrid: halo4d reads tetrahedral meshes",
                            shorten(other.unwrap_or("missing"))
                        ),
                    ));
                }
            }
            continue;
        }
        if name.as_ref() == b"Piece" {
            let source = attribute(&e, "Source", fail, at)?
                .filter(|s| !s.trim().is_empty())
                .ok_or_else(|| {
                    fail.byte(
                        at,
                        "a Piece without a Source: each Piece of a .pvtu names its .vtu file",
                    )
                })?;
            sources.push((source.trim().to_string(), at));
        }
    }
    if !seen_file {
        return Err(fail.file("no VTKFile element: this is not a PVTU file"));
    }
    if sources.is_empty() {
        return Err(fail.file(
            "the PUnstructuredGrid names no Piece: a .pvtu lists its pieces' .vtu files as <Piece Source=\"...\"/>",
        ));
    }
    if u32::try_from(sources.len()).is_err() {
        return Err(fail.file(format!("{} pieces: too many", sources.len())));
    }
    Ok(sources)
}

/// The pieces joined into one mesh: a point of a piece whose coordinates are exactly those
/// of a point of an earlier piece (equal values; 0.0 and -0.0 alike) becomes that point (the
/// first such).
fn weld(
    name: &str,
    fail: &Fail,
    pieces: Vec<String>,
    meshes: Vec<PlainTetrahedra>,
) -> Result<PlainTetrahedra> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut tets = Vec::with_capacity(meshes.iter().map(|m| m.tets.len()).sum());
    let mut solids = Vec::with_capacity(meshes.iter().map(|m| m.solids.len()).sum());
    let mut piece_of = Vec::with_capacity(tets.capacity() + solids.capacity());
    let mut solid_piece_of = Vec::with_capacity(solids.capacity());
    // The points of the pieces before the current one, by their coordinates' bits.
    let mut earlier: HashMap<[u64; 3], u32> = HashMap::new();
    let mut formats: Vec<&str> = Vec::new();
    for (k, m) in meshes.iter().enumerate() {
        if !formats.contains(&m.format.as_str()) {
            formats.push(&m.format);
        }
        // Equal values (0.0 and -0.0 one point), by their bits.
        let bits = |p: &[f64; 3]| p.map(|x| (x + 0.0).to_bits());
        let first = positions.len();
        let mut index = Vec::with_capacity(m.positions.len());
        for (i, p) in m.positions.iter().enumerate() {
            let j = match earlier.get(&bits(p)) {
                Some(&j) => j,
                None => {
                    let j = u32::try_from(positions.len()).map_err(|_| {
                        fail.file(format!(
                            "piece {k}'s point {i}: more than {} points in all",
                            u32::MAX
                        ))
                    })?;
                    positions.push(*p);
                    j
                }
            };
            index.push(j);
        }
        for (j, p) in positions[first..].iter().enumerate() {
            earlier.entry(bits(p)).or_insert((first + j) as u32);
        }
        tets.extend(m.tets.iter().map(|t| t.map(|i| index[i as usize])));
        piece_of.extend(std::iter::repeat_n(k as u32, m.tets.len()));
        solids.extend(m.solids.iter().map(|s| Solid {
            corners: s.corners.map(|i| index[i as usize]),
            ..*s
        }));
        solid_piece_of.extend(std::iter::repeat_n(k as u32, m.solids.len()));
    }
    piece_of.extend(solid_piece_of);
    let format = format!(
        "PVTU, {} piece{} ({})",
        pieces.len(),
        if pieces.len() == 1 { "" } else { "s" },
        formats.join("; ")
    );
    PlainTetrahedra {
        name: name.to_string(),
        positions,
        tets,
        why: format!("a {format} mesh, which has no halo layout (another program's tetrahedra)"),
        format,
        pieces,
        piece_of,
        solids,
    }
    .validate()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(positions: Vec<[f64; 3]>, tets: Vec<[u32; 4]>) -> PlainTetrahedra {
        PlainTetrahedra {
            positions,
            tets,
            format: "VTU ascii".into(),
            ..PlainTetrahedra::default()
        }
    }

    #[test]
    fn points_weld_to_earlier_pieces_only() {
        let o = [0.0, 0.0, 0.0];
        let x = [1.0, 0.0, 0.0];
        let y = [0.0, 1.0, 0.0];
        let z = [0.0, 0.0, 1.0];
        let w = [1.0, 1.0, 1.0];
        // Piece 0 repeats `o` (its own two points, kept apart); piece 1 shares x, y, z
        // with piece 0 and has -0.0 where piece 0 has 0.0 (the same value: welded to the
        // first `o`).
        let a = piece(vec![o, x, y, z, o], vec![[0, 1, 2, 3], [4, 1, 2, 3]]);
        let b = piece(
            vec![x, y, z, w, [-0.0, 0.0, 0.0]],
            vec![[0, 1, 2, 3], [4, 0, 1, 2]],
        );
        let m = weld(
            "m",
            &Fail::new("PVTU m.pvtu"),
            vec!["a.vtu".into(), "b.vtu".into()],
            vec![a, b],
        )
        .unwrap();
        assert_eq!(m.positions, vec![o, x, y, z, o, w]);
        assert_eq!(
            m.tets,
            vec![[0, 1, 2, 3], [4, 1, 2, 3], [1, 2, 3, 5], [0, 1, 2, 3]]
        );
        assert_eq!(m.piece_of, vec![0, 0, 1, 1]);
        assert_eq!(m.format, "PVTU, 2 pieces (VTU ascii)");
    }

    #[test]
    fn a_later_repeated_point_welds_to_the_first_of_an_earlier_piece() {
        let p = [0.5, 0.25, 0.125];
        let a = piece(vec![p, p, [1.0; 3], [2.0; 3]], vec![[0, 1, 2, 3]]);
        let b = piece(vec![[1.0; 3], [2.0; 3], [3.0; 3], p], vec![[3, 0, 1, 2]]);
        let m = weld(
            "m",
            &Fail::new("PVTU m.pvtu"),
            vec!["a.vtu".into(), "b.vtu".into()],
            vec![a, b],
        )
        .unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.tets[1], [0, 2, 3, 4]);
    }

    #[test]
    fn pieces_without_tetrahedra_add_none() {
        let fail = Fail::new("PVTU m.pvtu");
        let empty = piece(Vec::new(), Vec::new());
        // All of them empty: read (the check then fails with 0 tetrahedra, as for a file).
        let m = weld("m", &fail, vec!["a.vtu".into()], vec![empty.clone()]).unwrap();
        assert!(m.tets.is_empty() && m.piece_of.is_empty());
        let one = piece(
            vec![[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]],
            vec![[0, 1, 2, 3]],
        );
        let m = weld(
            "m",
            &fail,
            vec!["a.vtu".into(), "b.vtu".into()],
            vec![empty, one],
        )
        .unwrap();
        assert_eq!(m.piece_of, vec![1]);
    }

    #[test]
    fn the_pieces_are_named_in_order_and_a_sourceless_piece_is_refused() {
        let fail = Fail::new("PVTU m.pvtu");
        let xml = b"\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid><Piece Source=\"a/m_0.vtu\"/><Piece Source=\"m_1.vtu\"></Piece></PUnstructuredGrid></VTKFile>";
        let names: Vec<String> = pieces(xml, &fail)
            .unwrap()
            .into_iter()
            .map(|p| p.0)
            .collect();
        assert_eq!(names, ["a/m_0.vtu", "m_1.vtu"]);
        let bad = b"<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid><Piece/></PUnstructuredGrid></VTKFile>";
        let at = bad.windows(7).position(|w| w == b"<Piece/").unwrap();
        let e = pieces(bad, &fail).unwrap_err().to_string();
        assert!(
            e.contains(&format!("byte {at}")) && e.contains("Source"),
            "{e}"
        );
        let none = b"<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid/></VTKFile>";
        let e = pieces(none, &fail).unwrap_err().to_string();
        assert!(e.contains("names no Piece"), "{e}");
        let vtu = b"<VTKFile type=\"UnstructuredGrid\"></VTKFile>";
        let e = pieces(vtu, &fail).unwrap_err().to_string();
        assert!(e.contains("name it .vtu"), "{e}");
    }
}
