//! The mesh readers on every format, and on broken files.

use super::*;
use crate::export::to_4off;
use glam::DVec4;

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
fn to_4off_reads_back_bit_for_bit() {
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
    let text = to_4off(&mesh.positions, &mesh.triangles, "mesh");
    let back = read(&text, MeshFormat::Off).expect("reads back");
    assert_eq!(back.triangles, mesh.triangles);
    for (a, b) in mesh.positions.iter().zip(&back.positions) {
        for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
            assert_eq!(x.to_bits(), y.to_bits(), "{x:?} read back as {y:?}\n{text}");
        }
    }
    assert!(text.contains("1e-300") && text.contains("-0.0"), "{text}");
    let tet = tetrahedron();
    assert_eq!(
        read(
            to_4off(&tet.positions, &tet.triangles, "tet"),
            MeshFormat::Off
        ),
        Ok(tet)
    );
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
