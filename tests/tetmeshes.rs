//! Other programs' tetrahedral meshes (`fixtures/tetmeshes/`, written by meshio 5.3.5 and
//! by hand through `make.py`): one mesh in every format and variant, read the same; and
//! malformed files, each an error that names its line or byte, never a panic.

use crate::common::fixture;
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

#[test]
fn halo4d_check_passes_every_variant() {
    for name in VARIANTS {
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
    for name in VARIANTS {
        if name.ends_with(".vtk") || name == "cube.node" {
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
fn other_solids_are_refused_by_name_and_count() {
    // A Gmsh tetrahedron made a hexahedron (type 5, 8 nodes).
    let text = std::fs::read_to_string(path("cube-2.2-ascii.msh")).unwrap();
    let tet = text
        .lines()
        .find(|l| l.split_whitespace().nth(1) == Some("4"))
        .unwrap();
    let w: Vec<&str> = tet.split_whitespace().collect();
    let hex = format!("{} 5 {} {}", w[0], w[2..].join(" "), w[5..9].join(" "));
    fails(
        "cube.msh",
        text.replace(tet, &hex).as_bytes(),
        true,
        &["1 hexahedra", "11 tetrahedra", "tetrahedral meshes"],
    );
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
    // A VTU tetrahedron's type made 12 (hexahedron).
    let vtu = std::fs::read_to_string(path("cube-ascii.vtu")).unwrap();
    let types = vtu.find("Name=\"types\"").unwrap();
    let ten = types + vtu[types..].find("10").unwrap();
    let mut bad = vtu.clone();
    bad.replace_range(ten..ten + 2, "12");
    fails(
        "cube.vtu",
        bad.as_bytes(),
        true,
        &["1 hexahedra", "tetrahedral meshes"],
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
    for ext in [".vtu", ".msh", ".mesh", ".node", ".ele", ".glb", ".vtk"] {
        assert!(e.contains(ext), "{e}");
    }
    // Extensions in any case.
    let upper = dir.path().join("CUBE.MSH");
    std::fs::copy(path("cube-4.1-binary.msh"), &upper).unwrap();
    assert_eq!(plain(&upper).tets.len(), 12);
}
