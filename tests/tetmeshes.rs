//! Other programs' tetrahedral meshes (`fixtures/tetmeshes/`, written by meshio 5.3.5, VTK
//! 9.5.2, Gmsh 4.15.2 and by hand through `make.py`): one mesh in every format and variant,
//! read the same; and malformed files, each an error that names its line or byte, never a
//! panic.

use crate::common::{fixture, halo4d};
use halo4d::import::{FileTetrahedra, PlainTetrahedra, read, read_tetgen};
use std::path::{Path, PathBuf};

/// Every variant of the fixture mesh (TetGen's as its `.ele`; its `.node` beside it).
const VARIANTS: [&str; 22] = [
    "cube-ascii.vtu",
    "cube-base64.vtu",
    "cube-base64-zlib.vtu",
    "cube-base64-uint64.vtu",
    "cube-base64-zlib-uint64.vtu",
    "cube-appended-raw.vtu",
    "cube-appended-raw-zlib.vtu",
    "cube-appended-base64.vtu",
    "cube-appended-base64-zlib.vtu",
    "cube-appended-raw-bigendian.vtu",
    "cube-appended-raw-zlib-bigendian.vtu",
    "cube-4.2-ascii.vtk",
    "cube-5.1-binary.vtk",
    "cube-2.2-ascii.msh",
    "cube-2.2-binary.msh",
    "cube-2.2-sparse.msh",
    "cube-4.1-ascii.msh",
    "cube-4.1-binary.msh",
    "cube-4.1-sparse.msh",
    "cube.mesh",
    "cube.ele",
    "cube.node",
];

/// The files VTK 9.5.2 and Gmsh 4.15.2 themselves wrote (`make.py`): VTU with InformationKey
/// children, LZ4 and LZMA; legacy VTK with every kind of array; Gmsh's parametric nodes; a
/// PVTU of 3 pieces. And copies of other fixtures that begin with a UTF-8 byte-order mark.
/// Each is the fixture mesh, though Gmsh numbers its nodes by entity and the PVTU's points
/// come piece by piece.
const WRITERS: [&str; 18] = [
    "cube-vtk9-ascii.vtu",
    "cube-vtk9-binary.vtu",
    "cube-vtk9-binary-zlib.vtu",
    "cube-vtk9-binary-lz4.vtu",
    "cube-vtk9-binary-lzma.vtu",
    "cube-vtk9-appended-lz4.vtu",
    "cube-vtk9-appended-lzma.vtu",
    "cube-vtk9-arrays-ascii.vtk",
    "cube-vtk9-arrays-binary.vtk",
    "cube-vtk9-arrays-4.2-binary.vtk",
    "cube-2.2-parametric-ascii.msh",
    "cube-2.2-parametric-binary.msh",
    "cube-4.1-parametric-ascii.msh",
    "cube-4.1-parametric-binary.msh",
    "cube-bom.msh",
    "cube-bom.mesh",
    "cube-bom.vtk",
    "cube-pieces.pvtu",
];

fn path(name: &str) -> PathBuf {
    fixture(&format!("tetmeshes/{name}"))
}

fn plain(p: &Path) -> PlainTetrahedra {
    match read(p) {
        Ok(FileTetrahedra::Plain(m)) => m,
        Ok(FileTetrahedra::Halos(_)) => panic!("{}: read as a halo", p.display()),
        Err(e) => panic!("{}: {e}", p.display()),
    }
}

fn orient(m: &PlainTetrahedra, t: [u32; 4]) -> f64 {
    let c = |i: u32| {
        let [x, y, z] = m.positions[i as usize];
        robust::Coord3D { x, y, z }
    };
    robust::orient3d(c(t[0]), c(t[1]), c(t[2]), c(t[3]))
}

#[test]
fn every_format_and_variant_reads_the_same_positive_tetrahedra() {
    let reference = plain(&path("cube.mesh"));
    assert_eq!(reference.positions.len(), 12);
    assert_eq!(reference.tets.len(), 12);
    let mut formats = Vec::new();
    for name in VARIANTS {
        let m = plain(&path(name));
        assert_eq!(m.positions, reference.positions, "{name}: positions");
        assert_eq!(m.tets, reference.tets, "{name}: tetrahedra");
        for &t in &m.tets {
            // The files' det[b - a, c - a, d - a] > 0 became halo4d's orientation.
            assert!(
                orient(&m, t) > 0.0,
                "{name}: tetrahedron {t:?} is not positive"
            );
        }
        if !name.ends_with(".vtk") {
            let stem = Path::new(name).file_stem().unwrap();
            assert_eq!(m.name, stem.to_string_lossy(), "{name}");
        }
        assert!(m.why.contains(&m.format), "{name}: {}", m.why);
        if !name.contains("sparse") {
            formats.push(m.format);
        }
    }
    // Each variant is told apart by what it says it read (TetGen's two files are one, and
    // sparse node tags are no other format).
    formats.dedup();
    let mut distinct = formats.clone();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len(), formats.len(), "{formats:?}");
    for (name, format) in [
        (
            "cube-appended-raw-zlib-bigendian.vtu",
            "VTU appended raw zlib big-endian",
        ),
        ("cube-base64-uint64.vtu", "VTU binary UInt64 headers"),
        ("cube-4.1-binary.msh", "Gmsh 4.1 binary"),
        ("cube-2.2-ascii.msh", "Gmsh 2.2 ASCII"),
        ("cube.node", "TetGen .node/.ele"),
        ("cube.mesh", "Medit .mesh"),
        ("cube-5.1-binary.vtk", "legacy VTK binary"),
    ] {
        assert_eq!(plain(&path(name)).format, format);
    }
}

/// Each tetrahedron's corners (sorted), all sorted: the mesh whatever its numbering.
fn corners(m: &PlainTetrahedra) -> Vec<[[u64; 3]; 4]> {
    let mut all: Vec<[[u64; 3]; 4]> = m
        .tets
        .iter()
        .map(|t| {
            let mut c = t.map(|i| m.positions[i as usize].map(f64::to_bits));
            c.sort_unstable();
            c
        })
        .collect();
    all.sort_unstable();
    all
}

fn volume(m: &PlainTetrahedra) -> f64 {
    m.tets.iter().map(|&t| orient(m, t) / 6.0).sum()
}

#[test]
fn what_vtk_and_gmsh_write_reads_as_the_same_mesh() {
    let reference = plain(&path("cube.mesh"));
    let v = volume(&reference);
    assert!((v - 3.0).abs() < 0.5, "{v}");
    for name in WRITERS {
        let m = plain(&path(name));
        assert_eq!(m.tets.len(), reference.tets.len(), "{name}: tetrahedra");
        assert!(
            (volume(&m) - v).abs() <= 1e-12 * v,
            "{name}: volume {} (the reference's {v})",
            volume(&m)
        );
        assert_eq!(corners(&m), corners(&reference), "{name}: corners");
        assert_eq!(
            m.positions.len(),
            reference.positions.len(),
            "{name}: vertices"
        );
        for &t in &m.tets {
            assert!(
                orient(&m, t) > 0.0,
                "{name}: tetrahedron {t:?} is not positive"
            );
        }
        if name.ends_with(".pvtu") {
            continue;
        }
        assert!(m.pieces.is_empty() && m.piece_of.is_empty(), "{name}");
        if name.contains("bom") || name.ends_with(".vtk") {
            continue;
        }
        // Where the numbering is the file's own (VTK keeps the fixture's), the same arrays.
        if name.contains("vtk9") {
            assert_eq!(m.positions, reference.positions, "{name}");
            assert_eq!(m.tets, reference.tets, "{name}");
        }
    }
    for (name, format) in [
        ("cube-vtk9-binary-lz4.vtu", "VTU binary lz4"),
        ("cube-vtk9-appended-lzma.vtu", "VTU appended raw lzma"),
        ("cube-vtk9-ascii.vtu", "VTU ascii"),
        ("cube-vtk9-arrays-binary.vtk", "legacy VTK binary"),
        ("cube-2.2-parametric-binary.msh", "Gmsh 2.2 binary"),
        ("cube-4.1-parametric-ascii.msh", "Gmsh 4.1 ASCII"),
        ("cube-bom.vtk", "legacy VTK ASCII"),
        (
            "cube-pieces.pvtu",
            "PVTU, 3 pieces (VTU appended base64 zlib)",
        ),
    ] {
        assert_eq!(plain(&path(name)).format, format, "{name}");
    }
    // The byte-order mark's copies are their originals.
    for (bom, original) in [
        ("cube-bom.msh", "cube-2.2-ascii.msh"),
        ("cube-bom.mesh", "cube.mesh"),
        ("cube-bom.vtk", "cube-4.2-ascii.vtk"),
    ] {
        let (a, b) = (plain(&path(bom)), plain(&path(original)));
        assert_eq!((a.positions, a.tets), (b.positions, b.tets), "{bom}");
    }
}

#[test]
fn a_pvtu_welds_its_pieces_and_records_where_each_tetrahedron_came_from() {
    let m = plain(&path("cube-pieces.pvtu"));
    assert_eq!(m.name, "cube-pieces");
    assert_eq!(
        m.pieces,
        [
            "cube-pieces_0.vtu",
            "cube-pieces_1.vtu",
            "cube-pieces_2.vtu"
        ]
    );
    // The pieces hold 7 + 6 + 7 points, those on the cuts twice: welded, the 12 of the box.
    let pieces: Vec<PlainTetrahedra> = (0..3)
        .map(|k| plain(&path(&format!("cube-pieces_{k}.vtu"))))
        .collect();
    let written: usize = pieces.iter().map(|p| p.positions.len()).sum();
    assert!(written > 12, "{written}");
    assert_eq!(m.positions.len(), 12);
    assert_eq!(m.piece_of.len(), m.tets.len());
    let mut start = 0;
    for (k, piece) in pieces.iter().enumerate() {
        let n = piece.tets.len();
        assert!(n > 0, "piece {k}");
        // The pieces' tetrahedra, in order, each recorded as its piece's; the same corners.
        assert!(
            m.piece_of[start..start + n]
                .iter()
                .all(|&p| p as usize == k)
        );
        let own = PlainTetrahedra {
            tets: m.tets[start..start + n].to_vec(),
            ..m.clone()
        };
        assert_eq!(corners(&own), corners(piece), "piece {k}");
        // make.py cut the box at x = 1 and 2 by the tetrahedra's centroids.
        for t in &own.tets {
            let x: f64 = t.iter().map(|&i| m.positions[i as usize][0]).sum::<f64>() / 4.0;
            assert!(
                (k as f64..k as f64 + 1.0).contains(&x) || (k == 2 && x >= 2.0),
                "{x}"
            );
        }
        start += n;
    }
    assert_eq!(start, m.tets.len());

    // Pieces in a folder beside the .pvtu, as ParaView and older VTK write them.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("cube")).unwrap();
    let mut pvtu = std::fs::read_to_string(path("cube-pieces.pvtu")).unwrap();
    for k in 0..3 {
        let piece = format!("cube-pieces_{k}.vtu");
        std::fs::copy(path(&piece), dir.path().join("cube").join(&piece)).unwrap();
        pvtu = pvtu.replace(&format!("\"{piece}\""), &format!("\"cube/{piece}\""));
    }
    let p = dir.path().join("ball.PVTU");
    std::fs::write(&p, &pvtu).unwrap();
    let moved = plain(&p);
    assert_eq!(
        (moved.positions, moved.tets),
        (m.positions.clone(), m.tets.clone())
    );
    assert_eq!(moved.pieces[1], "cube/cube-pieces_1.vtu");

    // A piece that is not there: named, with the .pvtu and the byte of its Piece tag.
    std::fs::remove_file(dir.path().join("cube/cube-pieces_2.vtu")).unwrap();
    let at = pvtu
        .find("<Piece Source=\"cube/cube-pieces_2.vtu\"")
        .unwrap();
    let e = read(&p).unwrap_err().to_string();
    for needle in [
        "PVTU ball.PVTU".to_string(),
        format!("byte {at}"),
        "cube/cube-pieces_2.vtu".into(),
        "cannot be read".into(),
    ] {
        assert!(e.contains(&needle), "`{needle}` not in: {e}");
    }

    // An error inside a piece names the .pvtu, the piece and the byte in the piece.
    let mut piece = std::fs::read(path("cube-pieces_1.vtu")).unwrap();
    let data = appended(&piece);
    piece.truncate(data + 20);
    std::fs::write(dir.path().join("cube/cube-pieces_2.vtu"), &piece).unwrap();
    let e = read(&p).unwrap_err().to_string();
    assert!(
        e.starts_with(
            "PVTU ball.PVTU, piece cube/cube-pieces_2.vtu (VTU appended base64 zlib), byte "
        ),
        "{e}"
    );
}

#[test]
fn halo4d_check_passes_every_variant() {
    for name in VARIANTS.into_iter().chain(WRITERS) {
        let checked = halo4d::check_file(&path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            checked.failures().is_empty(),
            "{name}: {:?}",
            checked.failures()
        );
        let text = checked.text();
        assert!(text.contains("not a halo"), "{name}: {text}");
    }
}

#[test]
fn quadratic_tetrahedra_are_read_by_their_corners() {
    // Gmsh's 10-node tetrahedron (type 11): the corners, then the edges' nodes.
    let text = std::fs::read_to_string(path("cube-2.2-ascii.msh")).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 9 && w[1] == "4" {
            let edges = [(5, 6), (6, 7), (5, 7), (5, 8), (7, 8), (6, 8)].map(|(a, b)| {
                // Any node will do for the reader: it takes the corners alone.
                if a < b { w[a] } else { w[b] }
            });
            out += &format!("{} 11 {} {}\n", w[0], w[2..].join(" "), edges.join(" "));
        } else {
            out += line;
            out += "\n";
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("quadratic.msh");
    std::fs::write(&p, out).unwrap();
    let m = plain(&p);
    assert_eq!(m.tets, plain(&path("cube.mesh")).tets);

    // TetGen's -o2 .ele: 10 nodes per tetrahedron.
    let ele = std::fs::read_to_string(path("cube.ele")).unwrap();
    let mut out = String::new();
    for line in ele.lines().filter(|l| !l.starts_with('#')) {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 3 {
            out += &format!("{} 10 {}\n", w[0], w[2]);
        } else {
            out += &format!("{} {} {}\n", line, w[1..].join(" "), w[1..3].join(" "));
        }
    }
    let node = std::fs::read(path("cube.node")).unwrap();
    let m = read_tetgen(&node, out.as_bytes(), "cube").unwrap();
    assert_eq!(m.tets, plain(&path("cube.mesh")).tets);
}

/// The error of reading `bytes` as a file named `name`: one that names where (when `at`),
/// short, never a panic.
fn fails(name: &str, bytes: &[u8], at: bool, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    if let Some(node) = name.strip_suffix(".ele") {
        std::fs::copy(path("cube.node"), dir.path().join(format!("{node}.node"))).unwrap();
    }
    let e = match read(&p) {
        Ok(_) => panic!("{name}: read, but it should fail with {needles:?}"),
        Err(e) => e.to_string(),
    };
    assert!(e.len() < 1000, "{name}: {} bytes: {e}", e.len());
    if at {
        assert!(
            e.contains(", line ") || e.contains(", byte "),
            "{name}: names no line or byte: {e}"
        );
    }
    for n in needles {
        assert!(e.contains(n), "{name}: `{n}` not in: {e}");
    }
    e
}

fn edit(name: &str, from: &str, to: &str) -> Vec<u8> {
    let bytes = std::fs::read(path(name)).unwrap();
    let at = find(&bytes, from.as_bytes()).unwrap_or_else(|| panic!("{name}: no {from:?}"));
    let mut out = bytes[..at].to_vec();
    out.extend_from_slice(to.as_bytes());
    out.extend_from_slice(&bytes[at + from.len()..]);
    out
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Where a VTU file's appended data begin: after the `_` that follows the AppendedData tag.
fn appended(bytes: &[u8]) -> usize {
    let tag = find(bytes, b"<AppendedData").unwrap();
    tag + find(&bytes[tag..], b"_").unwrap() + 1
}

#[test]
fn truncated_files_fail_naming_where() {
    for name in VARIANTS.into_iter().chain(WRITERS) {
        if name.ends_with(".vtk") || name.ends_with(".pvtu") || name == "cube.node" {
            continue;
        }
        let bytes = std::fs::read(path(name)).unwrap();
        for k in 1..10 {
            let cut = &bytes[..bytes.len() * k / 10];
            fails(name, cut, true, &[]);
        }
    }
    // A .node cut short: the .ele names vertices it lacks, or the .node ends early.
    let node = std::fs::read(path("cube.node")).unwrap();
    let ele = std::fs::read(path("cube.ele")).unwrap();
    for k in 1..10 {
        let e = read_tetgen(&node[..node.len() * k / 10], &ele, "cube").unwrap_err();
        assert!(e.to_string().contains(", line "), "{e}");
    }
}

#[test]
fn counts_past_the_file_fail_before_allocating() {
    let huge = "1000000000000";
    fails(
        "cube.msh",
        &edit(
            "cube-2.2-ascii.msh",
            "$Nodes\n12\n",
            &format!("$Nodes\n{huge}\n"),
        ),
        true,
        &["line 5", "claims 1000000000000 nodes"],
    );
    fails(
        "cube.msh",
        &edit(
            "cube-2.2-ascii.msh",
            "$Elements\n17\n",
            &format!("$Elements\n{huge}\n"),
        ),
        true,
        &["claims 1000000000000 elements"],
    );
    // Gmsh 4.1 binary: the number of nodes, a size_t after the number of blocks.
    let mut bytes = std::fs::read(path("cube-4.1-binary.msh")).unwrap();
    let at = find(&bytes, b"$Nodes\n").unwrap() + 7 + 8;
    bytes[at..at + 8].copy_from_slice(&1u64.wrapping_shl(40).to_le_bytes());
    fails("cube.msh", &bytes, true, &[&format!("byte {at}"), "claims"]);
    fails(
        "cube.mesh",
        &edit(
            "cube.mesh",
            "Vertices\n12\n",
            &format!("Vertices\n{huge}\n"),
        ),
        true,
        &["line 5", "claims"],
    );
    fails(
        "cube.ele",
        &edit("cube.ele", "12 4 0", &format!("{huge} 4 0")),
        true,
        &["line 2", "claims"],
    );
    fails(
        "cube.vtu",
        &edit(
            "cube-base64.vtu",
            "NumberOfPoints=\"12\"",
            &format!("NumberOfPoints=\"{huge}\""),
        ),
        true,
        &["NumberOfPoints"],
    );
    // The array's header claims more bytes than there are.
    let raw = std::fs::read(path("cube-appended-raw.vtu")).unwrap();
    let data = appended(&raw);
    let mut bytes = raw.clone();
    bytes[data..data + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    fails(
        "cube.vtu",
        &bytes,
        true,
        &[&format!("byte {data}"), "header"],
    );
    // A zlib header that claims more blocks than the file holds.
    let raw = std::fs::read(path("cube-appended-raw-zlib.vtu")).unwrap();
    let data = appended(&raw);
    let mut bytes = raw.clone();
    bytes[data..data + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
    fails("cube.vtu", &bytes, true, &[&format!("byte {data}")]);
}

#[test]
fn indices_out_of_range_and_nan_coordinates_fail() {
    // Medit counts vertices from 1: 13 is past the 12.
    let mesh = std::fs::read_to_string(path("cube.mesh")).unwrap();
    let tets = mesh.find("Tetrahedra\n12\n").unwrap() + "Tetrahedra\n12\n".len();
    let line = mesh[..tets].lines().count() + 1;
    let mut bad = mesh.clone();
    bad.replace_range(tets..tets + 1, "13");
    fails(
        "cube.mesh",
        bad.as_bytes(),
        true,
        &[&format!("line {line}"), "vertex 13", "1 to 12"],
    );
    fails(
        "cube.mesh",
        &edit(
            "cube.mesh",
            "0.0000000000000000e+00 0.0000000000000000e+00 0.0000000000000000e+00 1",
            "nan 0 0 1",
        ),
        true,
        &["line 6", "not a finite number"],
    );
    fails(
        "cube.msh",
        &edit(
            "cube-2.2-ascii.msh",
            "\n1 0.0000000000000000e+00",
            "\n1 inf",
        ),
        true,
        &["line 6", "not a finite number"],
    );
    fails(
        "cube.msh",
        &edit(
            "cube-2.2-ascii.msh",
            "\n6 4 2 0 0 1 5 7 8",
            "\n6 4 2 0 0 1 5 99 8",
        ),
        true,
        &["line 26", "node 99"],
    );
    fails(
        "cube.ele",
        &edit("cube.ele", "\n0 0 4 6 7", "\n0 0 4 6 12"),
        true,
        &["line 3", "vertex 12", "0 to 11"],
    );
    let e = read_tetgen(
        &edit("cube.node", "\n0 0.0000000000000000e+00", "\n0 NaN"),
        &std::fs::read(path("cube.ele")).unwrap(),
        "cube",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("cube.node, line 3") && e.contains("finite"),
        "{e}"
    );
    fails(
        "cube.vtu",
        &edit("cube-ascii.vtu", "0.00000000000e+00", "NaN"),
        true,
        &["byte", "not a finite number"],
    );
    // Gmsh 2.2 binary: a node's x set to NaN (after its 4-byte tag).
    let mut bytes = std::fs::read(path("cube-2.2-binary.msh")).unwrap();
    let at = find(&bytes, b"$Nodes\n12\n").unwrap() + 10 + 4;
    bytes[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    fails("cube.msh", &bytes, true, &[&format!("byte {at}"), "finite"]);
    // A raw appended connectivity value past the points.
    let raw = std::fs::read(path("cube-appended-raw.vtu")).unwrap();
    let text = String::from_utf8_lossy(&raw);
    let offset: usize = text
        .split("Name=\"connectivity\"")
        .nth(1)
        .and_then(|t| t.split("offset=\"").nth(1))
        .and_then(|t| t.split('"').next())
        .and_then(|o| o.parse().ok())
        .unwrap();
    let data = appended(&raw) + offset + 4;
    let mut bytes = raw.clone();
    bytes[data..data + 4].copy_from_slice(&40i32.to_le_bytes());
    fails(
        "cube.vtu",
        &bytes,
        true,
        &["connectivity", "40", "12 points"],
    );
}

#[test]
fn solids_other_than_the_four_are_refused_by_name_and_count() {
    // A Gmsh tetrahedron made a hexahedron (type 5, 8 nodes): read as one.
    let text = std::fs::read_to_string(path("cube-2.2-ascii.msh")).unwrap();
    let tet = text
        .lines()
        .find(|l| l.split_whitespace().nth(1) == Some("4"))
        .unwrap();
    let w: Vec<&str> = tet.split_whitespace().collect();
    let hex = format!("{} 5 {} {}", w[0], w[2..].join(" "), w[5..9].join(" "));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cube.msh");
    std::fs::write(&p, text.replace(tet, &hex)).unwrap();
    let m = plain(&p);
    assert_eq!((m.tets.len(), m.solids.len()), (11, 1));
    assert_eq!(m.solids[0].id, w[0].parse::<u64>().unwrap());
    // Medit's hexahedra and prisms are not read (their corner order is not VTK's or Gmsh's
    // for certain).
    fails(
        "cube.mesh",
        &edit(
            "cube.mesh",
            "\nEnd",
            "\nHexahedra\n2\n1 2 3 4 5 6 7 8 0\n1 2 3 4 5 6 7 8 0\nPrisms\n1\n1 2 3 4 5 6 0\nEnd",
        ),
        true,
        &["2 hexahedra", "1 prisms", "12 tetrahedra"],
    );
    // A VTU tetrahedron's type made 16 (a hexagonal prism).
    let vtu = std::fs::read_to_string(path("cube-ascii.vtu")).unwrap();
    let types = vtu.find("Name=\"types\"").unwrap();
    let ten = types + vtu[types..].find("10").unwrap();
    let mut bad = vtu.clone();
    bad.replace_range(ten..ten + 2, "16");
    fails(
        "cube.vtu",
        bad.as_bytes(),
        true,
        &["1 hexagonal prisms", "four kinds of cell"],
    );
}

/// The mixed mesh as Gmsh 4.15.2 and VTK 9.5.2 write it (`make.py`), each file's cells as
/// the writer gave them.
const MIXED: [&str; 5] = [
    "mixed-4.1-ascii.msh",
    "mixed-2.2-binary.msh",
    "mixed-order2.msh",
    "mixed.vtk",
    "mixed-vtk9.vtu",
];

/// Each cell's corners' coordinates in VTK's order (to 1e-9: Gmsh's text keeps 16 digits,
/// not every bit), the cells sorted: the same mesh whatever the numbering of its points and
/// cells.
fn mixed_corners(m: &PlainTetrahedra) -> Vec<Vec<[i64; 3]>> {
    let at = |i: &u32| m.positions[*i as usize].map(|x| (x * 1e9).round() as i64);
    let mut out: Vec<Vec<[i64; 3]>> = m
        .tets
        .iter()
        .map(|t| t.iter().map(at).collect())
        .chain(m.solids.iter().map(|s| s.used().iter().map(at).collect()))
        .collect();
    out.sort();
    out
}

#[test]
fn a_mixed_mesh_reads_the_same_from_gmsh_and_vtk_in_vtk_corner_order() {
    let first = plain(&path(MIXED[0]));
    let kinds = |m: &PlainTetrahedra| {
        use halo4d::import::SolidKind::*;
        [Hexahedron, Wedge, Pyramid].map(|k| m.solids.iter().filter(|s| s.kind == k).count())
    };
    assert_eq!((first.tets.len(), kinds(&first)), (133, [12, 24, 6]));
    // Gmsh's prisms turn their first triangle towards the opposite one, VTK's wedges away
    // from it: read from either, every wedge is VTK's.
    for name in MIXED {
        let m = plain(&path(name));
        assert!(mixed_corners(&m) == mixed_corners(&first), "{name}");
        let checked = halo4d::check_file(&path(name)).unwrap();
        assert!(
            checked.failures().is_empty(),
            "{name}: {:?}",
            checked.failures()
        );
        let c = checked.certificate.as_ref().unwrap();
        let cells = c.cells.as_ref().unwrap();
        assert_eq!(cells.certified_tetrahedra, 133 + 12 * 12 + 24 * 8 + 6 * 2);
        assert_eq!((cells.quads, cells.nonplanar_quads), (94, 78), "{name}");
        assert_eq!(c.convention, halo4d::certify::Convention::Positive);
        // The twist turns each horizontal section rigidly: the volume is the box's within
        // what the bent quadrilaterals' split moves.
        assert!((c.stats.volume - 3.0).abs() < 0.01, "{}", c.stats.volume);
        assert!(checked.text().contains("ok: a valid subdivision"), "{name}");
    }
}

#[test]
fn a_split_hexahedron_conforms_where_its_faces_are_planar_and_is_named_where_bent() {
    let checked = halo4d::check_file(&path("mixed-untwisted-split-hex.vtu")).unwrap();
    assert!(checked.failures().is_empty(), "{:?}", checked.failures());
    let checked = halo4d::check_file(&path("mixed-split-hex.vtu")).unwrap();
    assert_eq!(
        checked.failures(),
        ["2 nonconforming_quads (bent quadrilaterals against two triangles of other cells)"]
    );
    let cells = checked.certificate.as_ref().unwrap().cells.clone().unwrap();
    // The two hexahedra whose bent faces meet the split one's tetrahedra.
    assert_eq!(cells.faulty_cells, 2);
    assert!(
        cells
            .faulty
            .iter()
            .all(|f| f.kind == "hexahedron" && f.faults == ["non-conforming quadrilateral"]),
        "{:?}",
        cells.faulty
    );
    let text = checked.text();
    assert!(text.contains("nonconforming_quads   2"), "{text}");

    let checked = halo4d::check_file(&path("mixed-inverted-wedge.vtu")).unwrap();
    assert_eq!(checked.failures(), ["8 inverted"]);
    let cells = checked.certificate.as_ref().unwrap().cells.clone().unwrap();
    assert_eq!(cells.faulty_cells, 1);
    assert_eq!(cells.faulty[0].kind, "wedge");
    assert!(cells.faulty[0].faults.contains(&"inverted"));
}

#[test]
fn mark_writes_a_mixed_mesh_as_its_cells_with_their_faults() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("marked.vtu");
    let o = halo4d(
        &[
            "check",
            path("mixed-split-hex.vtu").to_str().unwrap(),
            "--mark",
            out.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("2 non-conforming quadrilateral"),
        "{stdout}"
    );
    // The marked file holds the same cells, and is certified alike.
    let (a, b) = (plain(&out), plain(&path("mixed-split-hex.vtu")));
    assert!(mixed_corners(&a) == mixed_corners(&b));
    assert_eq!(
        halo4d::check_file(&out).unwrap().failures(),
        halo4d::check_file(&path("mixed-split-hex.vtu"))
            .unwrap()
            .failures()
    );
}

#[test]
fn bad_base64_and_zlib_fail_naming_the_byte() {
    let vtu = std::fs::read(path("cube-base64.vtu")).unwrap();
    let at = find(&vtu, b"format=\"binary\">").unwrap() + 16;
    let at = at
        + vtu[at..]
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap()
        + 5;
    let mut bytes = vtu.clone();
    bytes[at] = b'!';
    fails("cube.vtu", &bytes, true, &[&format!("byte {at}"), "base64"]);

    // A zlib stream's bytes changed, raw and in base64.
    let raw = std::fs::read(path("cube-appended-raw-zlib.vtu")).unwrap();
    let data = appended(&raw);
    let mut bytes = raw.clone();
    // The points' header: 3 + blocks UInt64s; then the first block's zlib header, spoilt.
    let blocks = u64::from_le_bytes(raw[data..data + 8].try_into().unwrap()) as usize;
    let stream = data + 8 * (3 + blocks);
    bytes[stream] ^= 0xff;
    bytes[stream + 1] ^= 0xff;
    fails("cube.vtu", &bytes, true, &["zlib"]);
    let vtu = std::fs::read(path("cube-base64-zlib.vtu")).unwrap();
    let at = find(&vtu, b"==eJ").unwrap() + 2;
    let mut bytes = vtu.clone();
    bytes[at] = b'A';
    bytes[at + 1] = b'A';
    fails("cube.vtu", &bytes, true, &["zlib"]);
}

#[test]
fn gmsh_sections_need_their_end() {
    let e = fails(
        "cube.msh",
        &edit("cube-2.2-ascii.msh", "$EndNodes\n", ""),
        true,
        &["$EndNodes"],
    );
    assert!(e.contains("line 18"), "{e}");
    fails(
        "cube.msh",
        &edit("cube-4.1-binary.msh", "$EndNodes\n", ""),
        true,
        &["$EndNodes"],
    );
    fails(
        "cube.msh",
        &edit("cube-4.1-ascii.msh", "$EndEntities", "$EndEntitie"),
        true,
        &["$EndEntities"],
    );
}

#[test]
fn tetgen_needs_both_files() {
    let dir = tempfile::tempdir().unwrap();
    let ele = dir.path().join("alone.ele");
    std::fs::copy(path("cube.ele"), &ele).unwrap();
    let e = read(&ele).unwrap_err().to_string();
    assert!(e.contains("alone.node") && e.contains(".ele"), "{e}");
    let node = dir.path().join("lone.node");
    std::fs::copy(path("cube.node"), &node).unwrap();
    let e = read(&node).unwrap_err().to_string();
    assert!(e.contains("lone.ele"), "{e}");
}

#[test]
fn unknown_extensions_list_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("mesh.stl");
    std::fs::write(&p, b"solid").unwrap();
    let e = read(&p).unwrap_err().to_string();
    for ext in [
        ".vtu", ".pvtu", ".msh", ".mesh", ".node", ".ele", ".glb", ".vtk",
    ] {
        assert!(e.contains(ext), "{e}");
    }
    // Extensions in any case.
    let upper = dir.path().join("CUBE.MSH");
    std::fs::copy(path("cube-4.1-binary.msh"), &upper).unwrap();
    assert_eq!(plain(&upper).tets.len(), 12);
}

/// The Points' compressed header in an appended raw VTU of UInt32 headers: where it is, its
/// blocks' compressed sizes, and where its first block begins.
fn points_blocks(bytes: &[u8]) -> (usize, Vec<u32>, usize) {
    let text = String::from_utf8_lossy(bytes);
    let offset: usize = text
        .split("Name=\"Points\"")
        .nth(1)
        .and_then(|t| t.split("offset=\"").nth(1))
        .and_then(|t| t.split('"').next())
        .and_then(|o| o.trim().parse().ok())
        .unwrap();
    let data = appended(bytes) + offset;
    let u =
        |i: usize| u32::from_le_bytes(bytes[data + 4 * i..data + 4 * i + 4].try_into().unwrap());
    let blocks = u(0) as usize;
    let sizes = (0..blocks).map(|k| u(3 + k)).collect();
    (data, sizes, data + 4 * (3 + blocks))
}

#[test]
fn bad_lz4_and_xz_blocks_fail_naming_the_block() {
    for (name, kind) in [
        ("cube-vtk9-appended-lz4.vtu", "LZ4 block"),
        ("cube-vtk9-appended-lzma.vtu", ".xz stream"),
    ] {
        let raw = std::fs::read(path(name)).unwrap();
        let (data, sizes, first) = points_blocks(&raw);
        assert!(sizes.len() > 2, "{name}: {sizes:?}");
        let last = sizes.len() - 1;
        if kind == ".xz stream" {
            // lzma_easy_buffer_encode: each block an .xz stream, magic and all.
            assert_eq!(&raw[first..first + 6], b"\xFD7zXZ\0", "{name}");
        }
        // The last block cut short by a byte (its header says one byte less).
        let mut bytes = raw.clone();
        let at = data + 4 * (3 + last);
        bytes[at..at + 4].copy_from_slice(&(sizes[last] - 1).to_le_bytes());
        let block_at = first + sizes[..last].iter().map(|&s| s as usize).sum::<usize>();
        fails(
            "cube.vtu",
            &bytes,
            true,
            &[&format!("block {last}"), kind, &format!("byte {block_at}")],
        );
        // A block's bytes spoilt in the middle.
        let mut bytes = raw.clone();
        for b in &mut bytes[first + 4..first + sizes[0] as usize - 2] {
            *b ^= 0x5a;
        }
        fails("cube.vtu", &bytes, true, &["block 0", kind]);
        // The whole file cut inside the blocks.
        fails("cube.vtu", &raw[..first + 10], true, &["truncated"]);
    }
}

/// A VTU of `np` points whose Points array is appended raw: one compressed block of `block`
/// bytes that claims to give all of the points' bytes.
fn one_block_vtu(compressor: &str, np: usize, block: &[u8]) -> Vec<u8> {
    let mut head = Vec::new();
    for v in [1u32, 24 * np as u32, 24 * np as u32, block.len() as u32] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    let mut out = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\" compressor=\"{compressor}\">\n<!-- {} -->\n<UnstructuredGrid><Piece NumberOfPoints=\"{np}\" NumberOfCells=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece></UnstructuredGrid>\n<AppendedData encoding=\"raw\">_",
        " ".repeat(np)
    )
    .into_bytes();
    out.extend_from_slice(&head);
    out.extend_from_slice(block);
    out.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    out
}

#[test]
fn headers_that_claim_more_than_the_compressor_can_give_are_refused() {
    // 1000 points are 24000 bytes: more than 255 times 2 bytes of LZ4 (plus a block's 64),
    // or 7500 times 2 bytes of .xz; nothing is allocated for them.
    for (compressor, name) in [
        ("vtkLZ4DataCompressor", "lz4"),
        ("vtkLZMADataCompressor", "lzma"),
        ("vtkZLibDataCompressor", "zlib"),
    ] {
        let bytes = one_block_vtu(compressor, 1000, &[0, 0]);
        let at = appended(&bytes);
        fails(
            "cube.vtu",
            &bytes,
            true,
            &[
                &format!("byte {at}"),
                "claims 24000 bytes",
                &format!("than {name} can give"),
            ],
        );
    }
    // Within the bound, a block that does not give what it claims is an error all the same.
    let bytes = one_block_vtu("vtkLZ4DataCompressor", 4, &[0x40, 1, 2, 3, 4]);
    fails("cube.vtu", &bytes, true, &["block 0", "LZ4 block"]);
    let bytes = one_block_vtu("vtkLZMADataCompressor", 4, b"\xFD7zXZ\0\0\x04");
    fails("cube.vtu", &bytes, true, &["block 0", ".xz stream"]);
    let e = fails(
        "cube.vtu",
        &one_block_vtu("vtkBloscDataCompressor", 4, &[]),
        true,
        &["vtkLZ4DataCompressor", "vtkLZMADataCompressor"],
    );
    assert!(e.contains("Blosc"), "{e}");
}

#[test]
fn a_data_array_is_its_own_text() {
    // VTK writes its InformationKey after the values; one moved among them is read past.
    let vtu = std::fs::read_to_string(path("cube-vtk9-ascii.vtu")).unwrap();
    let points = vtu.find("Name=\"Points\"").unwrap();
    let key_start = points + vtu[points..].find("<InformationKey").unwrap();
    let key_end = key_start + vtu[key_start..].find("</InformationKey>").unwrap() + 17;
    let key = &vtu[key_start..key_end];
    let values = points + vtu[points..].find('>').unwrap() + 1;
    let middle = values + vtu[values..key_start].find("1.5 ").unwrap();
    let mut moved = vtu.clone();
    moved.replace_range(key_start..key_end, "");
    moved.insert_str(middle, &format!("{key} <!-- a comment --> "));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("moved.vtu");
    std::fs::write(&p, &moved).unwrap();
    let reference = plain(&path("cube-vtk9-ascii.vtu"));
    assert_eq!(plain(&p).positions, reference.positions);
    // Glued to a value on one side only: still whitespace between the values.
    let value = middle + moved[middle..].find("0.0625").unwrap();
    let mut one_side = moved.clone();
    one_side.insert_str(value + 6, "<a/>");
    std::fs::write(&p, &one_side).unwrap();
    assert_eq!(plain(&p).positions, reference.positions);

    // A child glued to a value on both sides: `0.06<a/>25` is one word to XML and two to a
    // reader of words; refused, naming the byte of the child.
    let mut glued = moved.clone();
    glued.insert_str(value + 4, "<a/>");
    fails(
        "cube.vtu",
        glued.as_bytes(),
        true,
        &[&format!("byte {}", value + 4), "cuts a value"],
    );

    // In base64 a child between two parts of the text is read past: the parts are one text.
    let vtu = std::fs::read_to_string(path("cube-vtk9-binary.vtu")).unwrap();
    let points = vtu.find("Name=\"Points\"").unwrap();
    let values = points + vtu[points..].find('>').unwrap() + 1;
    let text = values + vtu[values..].find(|c: char| !c.is_whitespace()).unwrap();
    let mut split = vtu.clone();
    split.insert_str(text + 10, "<Split/>");
    std::fs::write(&p, &split).unwrap();
    assert_eq!(
        plain(&p).positions,
        plain(&path("cube-vtk9-binary.vtu")).positions
    );
}

#[test]
fn legacy_vtk_reads_past_every_array_it_does_not_need() {
    // A string array in the FIELD data refused the whole file once.
    let ascii = std::fs::read_to_string(path("cube-vtk9-arrays-ascii.vtk")).unwrap();
    assert!(ascii.contains("notes 1 3 string\nwritten%20by%20VTK\n\n"));
    // Cut inside its strings: an error that says so, never a panic.
    let cut = ascii.find("xxxx").unwrap();
    let e = fails("cube.vtk", &ascii.as_bytes()[..cut], false, &[]);
    assert!(e.contains("notes") || e.contains("POINTS"), "{e}");
    // Binary: each string after its length; one that claims more than the file has left.
    let binary = std::fs::read(path("cube-vtk9-arrays-binary.vtk")).unwrap();
    let at = find(&binary, b"notes 1 3 string\n").unwrap() + 17;
    assert_eq!(binary[at], 0xC0 | 14, "a 1-byte length: 11 then 14");
    let mut bytes = binary.clone();
    bytes[at] = 0x3F;
    fails(
        "cube.vtk",
        &bytes,
        false,
        &["FIELD array notes", "string 0"],
    );
    // A type no VTK writes is named.
    fails(
        "cube.vtk",
        ascii.replace("3 bit", "3 quaternion").as_bytes(),
        false,
        &["quaternion", "string"],
    );
}

#[test]
fn a_byte_order_mark_is_skipped_and_bytes_stay_the_files() {
    let bom = |b: &[u8]| [b"\xEF\xBB\xBF".as_slice(), b].concat();
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "cube-ascii.vtu",
        "cube-appended-raw-zlib.vtu",
        "cube-4.1-binary.msh",
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, bom(&std::fs::read(path(name)).unwrap())).unwrap();
        let (a, b) = (plain(&p), plain(&path(name)));
        assert_eq!((a.positions, a.tets), (b.positions, b.tets), "{name}");
    }
    // TetGen's two files.
    let node = std::fs::read(path("cube.node")).unwrap();
    let ele = std::fs::read(path("cube.ele")).unwrap();
    let m = read_tetgen(&bom(&node), &bom(&ele), "cube").unwrap();
    assert_eq!(m.tets, plain(&path("cube.mesh")).tets);
    // An error's byte is the file's, the mark counted: a raw appended value spoilt.
    let raw = bom(&std::fs::read(path("cube-appended-raw.vtu")).unwrap());
    let data = appended(&raw);
    let mut bytes = raw.clone();
    bytes[data..data + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    fails("cube.vtu", &bytes, true, &[&format!("byte {data}")]);
}

#[test]
fn a_pvtu_piece_without_cells_is_read_as_none() {
    // VTK 9.5's vtkXMLUnstructuredGridWriter (binary) of an empty grid, as a process that
    // had no cells writes its piece.
    let empty = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian" header_type="UInt32" compressor="vtkZLibDataCompressor">
  <UnstructuredGrid>
    <Piece NumberOfPoints="0" NumberOfCells="0">
      <PointData>
      </PointData>
      <CellData>
      </CellData>
      <Points>
        <DataArray type="Float64" Name="Points" NumberOfComponents="3" format="binary" RangeMin="1e+299" RangeMax="-1e+299">
          AAAAAACAAAAAAAAA
          <InformationKey name="L2_NORM_RANGE" location="vtkDataArray" length="2">
            <Value index="0">
              1e+299
            </Value>
            <Value index="1">
              -1e+299
            </Value>
          </InformationKey>
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="binary" RangeMin="1e+299" RangeMax="-1e+299">
          AAAAAACAAAAAAAAA
        </DataArray>
        <DataArray type="Int64" Name="offsets" format="binary" RangeMin="1e+299" RangeMax="-1e+299">
          AAAAAACAAAAAAAAA
        </DataArray>
        <DataArray type="UInt8" Name="types" format="binary" RangeMin="1e+299" RangeMax="-1e+299">
          AAAAAACAAAAAAAAA
        </DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;
    let dir = tempfile::tempdir().unwrap();
    // Alone, it holds no tetrahedron: read, and its check fails as in every format.
    let alone = dir.path().join("empty.vtu");
    std::fs::write(&alone, empty).unwrap();
    assert_eq!(plain(&alone).tets.len(), 0);
    // Among pieces, it adds none.
    let mut pvtu = std::fs::read_to_string(path("cube-pieces.pvtu")).unwrap();
    for k in 0..3 {
        let piece = format!("cube-pieces_{k}.vtu");
        std::fs::copy(path(&piece), dir.path().join(&piece)).unwrap();
    }
    pvtu = pvtu.replace(
        "<Piece Source=\"cube-pieces_0.vtu\"/>",
        "<Piece Source=\"empty.vtu\"/>\n    <Piece Source=\"cube-pieces_0.vtu\"/>",
    );
    let p = dir.path().join("cube.pvtu");
    std::fs::write(&p, &pvtu).unwrap();
    let m = plain(&p);
    let reference = plain(&path("cube-pieces.pvtu"));
    assert_eq!(
        (&m.positions, &m.tets),
        (&reference.positions, &reference.tets)
    );
    assert_eq!(m.pieces.len(), 4);
    assert!(m.piece_of.iter().all(|&k| k > 0));
    assert_eq!(
        m.format,
        "PVTU, 4 pieces (VTU binary zlib; VTU appended base64 zlib)"
    );
    // Only empty pieces: no tetrahedra, read; the check fails.
    std::fs::write(
        &p,
        "<VTKFile type=\"PUnstructuredGrid\"><PUnstructuredGrid><Piece Source=\"empty.vtu\"/></PUnstructuredGrid></VTKFile>",
    )
    .unwrap();
    assert_eq!(plain(&p).tets.len(), 0);
    for file in [&alone, &p] {
        let checked = halo4d::check_file(file).unwrap();
        assert_eq!(
            checked.failures(),
            ["0 tetrahedra (the file holds none to check)"],
            "{}",
            file.display()
        );
    }
}

#[test]
fn a_mesh_without_tetrahedra_fails_its_check_alike_in_every_format() {
    // A triangle and its points, and no tetrahedron: read in every format, and the check
    // fails (exit status 1) with the same failure, not an error of the reader (2).
    let dir = tempfile::tempdir().unwrap();
    let files: [(&str, &[u8]); 6] = [
        (
            "empty.vtk",
            b"# vtk DataFile Version 4.2\nno cells\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n0 0 0\n1 0 0\n0 1 0\nCELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n",
        ),
        (
            "empty.msh",
            b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n1\n1 2 0 1 2 3\n$EndElements\n",
        ),
        (
            "empty.mesh",
            b"MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 3 0\nEnd\n",
        ),
        ("empty.node", b"3 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n"),
        ("empty.ele", b"0 4 0\n"),
        (
            "empty.vtu",
            b"<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"3\" NumberOfCells=\"0\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0</DataArray></Points><Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\"></DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\"></DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\"></DataArray></Cells></Piece></UnstructuredGrid></VTKFile>",
        ),
    ];
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    for name in [
        "empty.vtk",
        "empty.msh",
        "empty.mesh",
        "empty.ele",
        "empty.vtu",
    ] {
        let out = halo4d(&["check", name], dir.path());
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{name}: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(text.contains("FAILED 0 tetrahedra"), "{name}: {text}");
    }
}

#[test]
fn parametric_nodes_that_break_their_layout_fail_naming_where() {
    // A node on a surface (dimension 2) with one parametric coordinate, not two.
    fails(
        "cube.msh",
        &edit(
            "cube-2.2-parametric-ascii.msh",
            "\n4 0.125 1 0 2 1 0.125 1\n",
            "\n4 0.125 1 0 2 1 0.125\n",
        ),
        true,
        &["line 9", "node 4", "$ParametricNodes", "u v on a surface"],
    );
    // A node on no entity: x y z alone, as Gmsh writes it in ASCII.
    let m = plain(&path("cube-2.2-parametric-ascii.msh"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bare.msh");
    std::fs::write(
        &p,
        edit(
            "cube-2.2-parametric-ascii.msh",
            "\n9 1.625 0.0625 0.75 3 1\n",
            "\n9 1.625 0.0625 0.75\n",
        ),
    )
    .unwrap();
    assert_eq!(plain(&p).positions, m.positions);
    // Binary: an entity of dimension 7 (after the node's tag and x, y, z).
    let mut bytes = std::fs::read(path("cube-2.2-parametric-binary.msh")).unwrap();
    let nodes = find(&bytes, b"$ParametricNodes\n12\n").unwrap() + 20;
    let dim = nodes + 4 + 24;
    bytes[dim..dim + 4].copy_from_slice(&7i32.to_le_bytes());
    fails(
        "cube.msh",
        &bytes,
        true,
        &[&format!("byte {dim}"), "dimension 7"],
    );
    // $ParametricNodes in a 4.1 file is no section of it.
    let text = std::fs::read_to_string(path("cube-4.1-parametric-ascii.msh")).unwrap();
    fails(
        "cube.msh",
        text.replace("$Nodes", "$ParametricNodes").as_bytes(),
        true,
        &["MSH 2.2", "parametric` flag"],
    );
}
