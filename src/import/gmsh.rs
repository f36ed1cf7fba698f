//! Gmsh `.msh` files of versions 2.2 and 4.1, ASCII and binary, as Gmsh's reference manual
//! ("MSH file format") describes them.
//!
//! `$MeshFormat` gives the version, the file type and the data size (`size_t`'s, which 4.1
//! binary files use for tags and counts); a binary file then has the integer 1, whose bytes
//! say the endianness. `$Nodes` and `$Elements` are read: in 2.2 a count, then a node (tag,
//! x, y, z) or element (tag, type, tags, nodes) per line, or in binary, elements in blocks
//! of one type headed by the type, count and number of tags; in 4.1 entity blocks, each of
//! its nodes' tags then their coordinates (and parametric coordinates where the block says),
//! or its elements of one type. In 2.2, `$ParametricNodes` (Gmsh's `Mesh.SaveParametric`)
//! stands for `$Nodes`: each node's tag and x, y, z, then the dimension and tag of the
//! entity it is on and its parametric coordinates (u on a curve, u and v on a surface, none
//! on a point or in a volume), skipped; in ASCII a node on no entity has none of these.
//! Node tags are arbitrary (sparse, in any order): vertices come in the order of their
//! tags. Every other section (`$PhysicalNames`, `$Entities`, `$NodeData`, `$Periodic`, ...)
//! is skipped to its `$End` line. A UTF-8 byte-order mark before `$MeshFormat` is skipped.

use super::tetfile::{
    Cells, Fail, GMSH_PRISM, Kind, Result, SAME, Scan, TagMap, Tagged, f64_at, non_finite, plain,
};
use super::{MeshFileLocation, PlainTetrahedra, SolidKind};
use crate::limits::shorten;

/// Reads the tetrahedra of a Gmsh `.msh` file (2.2 or 4.1, ASCII or binary); `name` names
/// the mesh (the file's stem). Triangles, lines and points are skipped; hexahedra, prisms
/// and pyramids are an error.
pub fn read_gmsh(bytes: &[u8], name: &str) -> Result<PlainTetrahedra> {
    let mut s = Scan::new(bytes, Fail::new("Gmsh .msh"));
    let first = s.token().unwrap_or_default();
    if first != b"$MeshFormat" {
        return Err(s.err(format!(
            "a Gmsh file begins with `$MeshFormat`, this one with `{}`",
            shorten(&String::from_utf8_lossy(first))
        )));
    }
    let version = s.word("the version")?;
    let v4 = match version {
        b"2" | b"2.0" | b"2.1" | b"2.2" => false,
        b"4.1" => true,
        other => {
            return Err(s.err(format!(
                "version {} of the MSH format: halo4d reads versions 2.2 and 4.1; save the mesh again in one of them (Gmsh: -format msh22 or msh41)",
                shorten(&String::from_utf8_lossy(other))
            )));
        }
    };
    let binary = match s.u64("the file type")? {
        0 => false,
        1 => true,
        t => return Err(s.err(format!("the file type is {t}, not 0 (ASCII) or 1 (binary)"))),
    };
    let size = s.u64("the data size")? as usize;
    let sizes: &[usize] = if v4 { &[4, 8] } else { &[8] };
    if !sizes.contains(&size) {
        return Err(s.err(format!(
            "the data size is {size}; a {} file has {}",
            if v4 { "4.1" } else { "2.2" },
            if v4 { "4 or 8 (size_t)" } else { "8" }
        )));
    }
    let format = format!(
        "Gmsh {} {}",
        if v4 { "4.1" } else { "2.2" },
        if binary { "binary" } else { "ASCII" }
    );
    s.fail = Fail::new(format.clone());
    if binary {
        s.skip_line();
        s.binary = true;
        let one = s.take(4, "the integer 1 that tells the endianness")?;
        s.little = match one {
            [1, 0, 0, 0] => true,
            [0, 0, 0, 1] => false,
            _ => {
                return Err(s.err(format!(
                    "the integer that tells a binary file's endianness must be 1, found the bytes {one:?}"
                )));
            }
        };
    }
    expect_end(&mut s, b"$EndMeshFormat")?;
    let mut nodes: Option<(Vec<[f64; 3]>, TagMap)> = None;
    let mut cells: Option<Cells> = None;
    while let Some(word) = s.token() {
        match word {
            b"$Nodes" | b"$ParametricNodes" => {
                let parametric = word == b"$ParametricNodes";
                if nodes.is_some() {
                    return Err(s.err(
                        "a second $Nodes or $ParametricNodes section: halo4d reads one, and a file has one",
                    ));
                }
                if parametric && v4 {
                    return Err(s.err(
                        "$ParametricNodes is a section of MSH 2.2; a 4.1 file gives parametric coordinates in $Nodes, in entity blocks whose `parametric` flag is 1",
                    ));
                }
                let at = s.here();
                s.skip_line();
                let tagged = match (v4, binary) {
                    (false, false) => nodes_22_ascii(&mut s, parametric)?,
                    (false, true) => nodes_22_binary(&mut s, parametric)?,
                    (true, false) => nodes_41_ascii(&mut s)?,
                    (true, true) => nodes_41_binary(&mut s, size)?,
                };
                expect_end(
                    &mut s,
                    if parametric {
                        b"$EndParametricNodes"
                    } else {
                        b"$EndNodes"
                    },
                )?;
                nodes = Some(
                    tagged
                        .finish()
                        .map_err(|t| s.fail.at(at, format!("node tag {t} appears twice")))?,
                );
            }
            b"$Elements" => {
                let Some((positions, map)) = &nodes else {
                    return Err(s.err(
                        "$Elements before any $Nodes (or, in MSH 2.2, $ParametricNodes): the nodes must come first",
                    ));
                };
                if cells.is_some() {
                    return Err(s.err("a second $Elements section: halo4d reads one"));
                }
                s.skip_line();
                let read = Elements {
                    map,
                    nodes: positions.len(),
                };
                cells = Some(match (v4, binary) {
                    (false, false) => read.v22_ascii(&mut s)?,
                    (false, true) => read.v22_binary(&mut s)?,
                    (true, false) => read.v41_ascii(&mut s)?,
                    (true, true) => read.v41_binary(&mut s, size)?,
                });
                expect_end(&mut s, b"$EndElements")?;
            }
            w if w.starts_with(b"$") && !w.starts_with(b"$End") => skip_section(&mut s, &w[1..])?,
            w => {
                return Err(s.err(format!(
                    "expected a section such as $Nodes or $Elements, found `{}`",
                    shorten(&String::from_utf8_lossy(w))
                )));
            }
        }
    }
    let (positions, _) = nodes.ok_or_else(|| {
        s.fail
            .file("the file has no $Nodes section (nor, in MSH 2.2, $ParametricNodes)")
    })?;
    let cells = cells.ok_or_else(|| s.fail.file("the file has no $Elements section"))?;
    plain(name, &format, positions, cells.finish(&s.fail)?)
}

/// The next word must be `end`.
fn expect_end(s: &mut Scan, end: &[u8]) -> Result<()> {
    let end_text = String::from_utf8_lossy(end);
    match s.token() {
        Some(w) if w == end => Ok(()),
        Some(w) => Err(s.err(format!(
            "expected {end_text}, found `{}`: the section holds more or less than its counts say",
            shorten(&String::from_utf8_lossy(w))
        ))),
        None => Err(s.err_now(format!("the file ends without {end_text}: it is truncated"))),
    }
}

/// Moves past a section this reader does not need, to the word after its `$End` line.
fn skip_section(s: &mut Scan, name: &[u8]) -> Result<()> {
    let mut end = b"$End".to_vec();
    end.extend_from_slice(name);
    let start = s.pos;
    let rest = &s.bytes[start..];
    let found = (0..rest.len())
        .filter(|&i| rest[i] == b'$')
        .find(|&i| rest[i..].starts_with(&end));
    let Some(i) = found else {
        return Err(s.err(format!(
            "the section ${} has no {}: the file is truncated",
            shorten(&String::from_utf8_lossy(name)),
            shorten(&String::from_utf8_lossy(&end))
        )));
    };
    if !s.binary {
        s.line += rest[..i].iter().filter(|&&b| b == b'\n').count();
    }
    s.pos = start + i + end.len();
    Ok(())
}

/// How many of an element's first nodes the reader keeps: a tetrahedron's, hexahedron's,
/// prism's or pyramid's corners; 0 for an element it skips or refuses.
fn corners(kind: Kind) -> usize {
    match kind {
        Kind::Tet => 4,
        Kind::Cell(solid, _) => solid.corners(),
        Kind::Lower | Kind::Solid(_) => 0,
    }
}

/// The number of nodes of a Gmsh element type and what the reader does with it.
fn element_type(t: u64) -> Option<(usize, Kind)> {
    const HEX: Kind = Kind::Cell(SolidKind::Hexahedron, SAME);
    const PRISM: Kind = Kind::Cell(SolidKind::Wedge, GMSH_PRISM);
    const PYRAMID: Kind = Kind::Cell(SolidKind::Pyramid, SAME);
    Some(match t {
        4 => (4, Kind::Tet),
        11 => (10, Kind::Tet),
        29 => (20, Kind::Tet),
        30 => (35, Kind::Tet),
        31 => (56, Kind::Tet),
        15 => (1, Kind::Lower),
        1 => (2, Kind::Lower),
        8 => (3, Kind::Lower),
        26..=28 => (t as usize - 22, Kind::Lower),
        2 => (3, Kind::Lower),
        3 => (4, Kind::Lower),
        9 => (6, Kind::Lower),
        10 => (9, Kind::Lower),
        16 => (8, Kind::Lower),
        20 => (9, Kind::Lower),
        21 => (10, Kind::Lower),
        22 => (12, Kind::Lower),
        23 | 24 => (15, Kind::Lower),
        25 => (21, Kind::Lower),
        5 => (8, HEX),
        12 => (27, HEX),
        17 => (20, HEX),
        92 => (64, HEX),
        93 => (125, HEX),
        6 => (6, PRISM),
        13 => (18, PRISM),
        18 => (15, PRISM),
        7 => (5, PYRAMID),
        14 => (14, PYRAMID),
        19 => (13, PYRAMID),
        _ => return None,
    })
}

fn unknown_type(t: u64) -> String {
    format!(
        "element type {t} is not one this reader knows (it reads points, lines, triangles, quadrangles, tetrahedra, hexahedra, prisms and pyramids of Gmsh's numbering, up to order 2 or more)"
    )
}

/// A node tag of a binary file: a positive integer.
fn tag_of(t: i64, s: &Scan, at: usize) -> Result<u64> {
    u64::try_from(t).ok().filter(|&t| t > 0).ok_or_else(|| {
        s.fail
            .byte(at, format!("node tag {t}: tags are positive integers"))
    })
}

fn nodes_22_ascii(s: &mut Scan, parametric: bool) -> Result<Tagged> {
    // "1 0 0 0\n": a node takes at least 8 bytes.
    let n = s.count("nodes", 8)?;
    let mut t = Tagged::with_capacity(n);
    for _ in 0..n {
        let tag = s.u64("a node tag")?;
        let p = ascii_point(s, tag)?;
        if parametric {
            parametric_rest(s, tag)?;
        }
        t.push(tag, p);
    }
    Ok(t)
}

/// How many parametric coordinates a node on an entity of dimension `dim` has in
/// `$ParametricNodes`: u on a curve, u and v on a surface, none on a point or in a volume.
fn parameters(dim: i64) -> Option<usize> {
    match dim {
        0 | 3 => Some(0),
        1 => Some(1),
        2 => Some(2),
        _ => None,
    }
}

/// The rest of a `$ParametricNodes` line after x, y, z: nothing (a node on no entity), or
/// the entity's dimension and tag and its parametric coordinates.
fn parametric_rest(s: &mut Scan, tag: u64) -> Result<()> {
    let line = s.line;
    let rest = s.rest_of_line();
    let mut words = rest
        .split(u8::is_ascii_whitespace)
        .filter(|w| !w.is_empty());
    let ok = match words.next() {
        None => true,
        Some(dim) => super::tetfile::parse_i64(dim)
            .and_then(parameters)
            .is_some_and(|p| {
                words.next().and_then(super::tetfile::parse_i64).is_some()
                    && (0..p).all(|_| words.next().and_then(super::tetfile::parse_f64).is_some())
                    && words.next().is_none()
            }),
    };
    if !ok {
        return Err(s.fail.at(
            MeshFileLocation::Line(line),
            format!(
                "node {tag}: after x y z, a $ParametricNodes line has the dimension (0 to 3) and tag of the node's entity, then u on a curve, u v on a surface, nothing else; this one has `{}`",
                shorten(&String::from_utf8_lossy(rest))
            ),
        ));
    }
    Ok(())
}

fn ascii_point(s: &mut Scan, tag: u64) -> Result<[f64; 3]> {
    let v = tag as usize;
    Ok([
        s.coordinate(v, 0)?,
        s.coordinate(v, 1)?,
        s.coordinate(v, 2)?,
    ])
}

fn nodes_22_binary(s: &mut Scan, parametric: bool) -> Result<Tagged> {
    if parametric {
        return parametric_nodes_22_binary(s);
    }
    let n = s.count("nodes", 28)?;
    s.skip_line();
    let start = s.pos;
    let data = s.take(n * 28, "the nodes")?;
    let mut t = Tagged::with_capacity(n);
    for (k, c) in data.chunks_exact(28).enumerate() {
        let at = start + 28 * k;
        let tag = tag_of(i64::from(i32_at(c, s.little)), s, at)?;
        t.push(tag, binary_point(&c[4..], s, at + 4, tag)?);
    }
    Ok(t)
}

/// Binary `$ParametricNodes`: each node's tag, x, y, z, its entity's dimension and tag (4-byte
/// ints), then as many doubles as the dimension asks ([`parameters`]).
fn parametric_nodes_22_binary(s: &mut Scan) -> Result<Tagged> {
    // A node takes at least 4 + 24 + 8 bytes.
    let n = s.count("nodes", 36)?;
    s.skip_line();
    let mut t = Tagged::with_capacity(n);
    for _ in 0..n {
        let at = s.pos;
        let node = s.take(36, "a node")?;
        let tag = tag_of(i64::from(i32_at(node, s.little)), s, at)?;
        let p = binary_point(&node[4..], s, at + 4, tag)?;
        let dim = i32_at(&node[28..], s.little);
        let params = parameters(i64::from(dim)).ok_or_else(|| {
            s.fail.byte(
                at + 28,
                format!(
                    "node {tag} is on an entity of dimension {dim}: a $ParametricNodes entry gives 0 to 3 (a point, a curve, a surface, a volume)"
                ),
            )
        })?;
        s.take(8 * params, "the node's parametric coordinates")?;
        t.push(tag, p);
    }
    Ok(t)
}

/// Three doubles, finite.
fn binary_point(b: &[u8], s: &Scan, at: usize, tag: u64) -> Result<[f64; 3]> {
    let p = [0, 1, 2].map(|i| f64_at(&b[8 * i..], s.little));
    if let Some(i) = p.iter().position(|x| !x.is_finite()) {
        return Err(s.fail.byte(at + 8 * i, non_finite(tag as usize, i, p[i])));
    }
    Ok(p)
}

fn i32_at(b: &[u8], little: bool) -> i32 {
    let b: [u8; 4] = b[..4].try_into().expect("4 bytes");
    if little {
        i32::from_le_bytes(b)
    } else {
        i32::from_be_bytes(b)
    }
}

fn nodes_41_ascii(s: &mut Scan) -> Result<Tagged> {
    let blocks = s.count("node blocks", 8)?;
    let total = s.count("nodes", 8)?;
    s.u64("the smallest node tag")?;
    s.u64("the largest node tag")?;
    let mut t = Tagged::with_capacity(total);
    for _ in 0..blocks {
        let dim = s.u64("the entity's dimension")?;
        s.i64("the entity's tag")?;
        let parametric = s.u64("whether the nodes are parametric")?;
        let n = s.count("nodes in the block", 8)?;
        if n > total - t.tags.len() {
            return Err(s.err(format!(
                "the blocks hold more nodes than the {total} the section claims"
            )));
        }
        let params = if parametric == 1 { dim.min(3) } else { 0 };
        let first = t.tags.len();
        for _ in 0..n {
            let tag = s.u64("a node tag")?;
            t.tags.push(tag);
        }
        for k in 0..n {
            let p = ascii_point(s, t.tags[first + k])?;
            t.positions.push(p);
            for _ in 0..params {
                s.f64("a parametric coordinate")?;
            }
        }
    }
    if t.tags.len() != total {
        return Err(s.err(format!(
            "the blocks hold {} nodes, the section claims {total}",
            t.tags.len()
        )));
    }
    Ok(t)
}

fn nodes_41_binary(s: &mut Scan, size: usize) -> Result<Tagged> {
    let blocks = s.bin_uint(size, "the number of node blocks")?;
    s.check_count(blocks, "node blocks", 12 + size)?;
    let total = s.bin_uint(size, "the number of nodes")?;
    let total = s.check_count(total, "nodes", size + 24)?;
    s.bin_uint(size, "the smallest node tag")?;
    s.bin_uint(size, "the largest node tag")?;
    let mut t = Tagged::with_capacity(total);
    for _ in 0..blocks {
        let dim = s.bin_i32("the entity's dimension")?;
        s.bin_i32("the entity's tag")?;
        let parametric = s.bin_i32("whether the nodes are parametric")?;
        let n = s.bin_uint(size, "the number of nodes in the block")?;
        let params = if parametric == 1 {
            dim.clamp(0, 3) as usize
        } else {
            0
        };
        let each = size + 24 + 8 * params;
        let n = s.check_count(n, "nodes in the block", each)?;
        if n > total - t.tags.len() {
            return Err(s.err(format!(
                "the blocks hold more nodes than the {total} the section claims"
            )));
        }
        let tags = s.take(n * size, "the node tags")?;
        t.tags.extend(
            tags.chunks_exact(size)
                .map(|b| super::tetfile::uint(b, s.little)),
        );
        let start = s.pos;
        let stride = 24 + 8 * params;
        let coordinates = s.take(n * stride, "the node coordinates")?;
        let first = t.tags.len() - n;
        for (k, c) in coordinates.chunks_exact(stride).enumerate() {
            let p = binary_point(c, s, start + stride * k, t.tags[first + k])?;
            t.positions.push(p);
        }
    }
    if t.tags.len() != total {
        return Err(s.err_now(format!(
            "the blocks hold {} nodes, the section claims {total}",
            t.tags.len()
        )));
    }
    Ok(t)
}

/// Reads elements against the nodes read.
struct Elements<'m> {
    map: &'m TagMap,
    nodes: usize,
}

impl Elements<'_> {
    /// The index of the node tagged `tag`.
    fn node(&self, tag: u64, fail: &Fail, at: MeshFileLocation) -> Result<u32> {
        self.map.get(tag).ok_or_else(|| {
            fail.at(
                at,
                format!(
                    "an element names node {tag}, which $Nodes does not list ({} nodes)",
                    self.nodes
                ),
            )
        })
    }

    /// One element of an ASCII file, its tag (`tag`) and tags read: its `n` nodes.
    fn ascii_element(
        &self,
        s: &mut Scan,
        cells: &mut Cells,
        (n, kind): (usize, Kind),
        tag: u64,
    ) -> Result<()> {
        let corners = corners(kind);
        let at = s.here();
        let mut nodes = [0u32; 8];
        for slot in &mut nodes[..corners] {
            let node = s.u64("a node tag")?;
            *slot = self.node(node, &s.fail, s.here())?;
        }
        for _ in corners..n {
            s.u64("a node tag")?;
        }
        match kind {
            Kind::Tet => cells.tet([nodes[0], nodes[1], nodes[2], nodes[3]]),
            Kind::Cell(solid, order) => cells.solid(solid, order, &nodes, tag),
            Kind::Lower => cells.skipped += 1,
            Kind::Solid(name) => cells.other(name, 1, at),
        }
        Ok(())
    }

    fn v22_ascii(&self, s: &mut Scan) -> Result<Cells> {
        // "1 15 0 1\n": an element takes at least 9 bytes.
        let n = s.count("elements", 9)?;
        let mut cells = Cells::with_capacity(n);
        for _ in 0..n {
            let tag = s.u64("an element tag")?;
            let t = s.u64("an element type")?;
            let element = element_type(t).ok_or_else(|| s.err(unknown_type(t)))?;
            let tags = s.count("tags", 2)?;
            for _ in 0..tags {
                s.word("a tag")?;
            }
            self.ascii_element(s, &mut cells, element, tag)?;
        }
        Ok(cells)
    }

    fn v41_ascii(&self, s: &mut Scan) -> Result<Cells> {
        let blocks = s.count("element blocks", 8)?;
        let total = s.count("elements", 4)?;
        s.u64("the smallest element tag")?;
        s.u64("the largest element tag")?;
        let mut cells = Cells::with_capacity(total);
        let mut read = 0;
        for _ in 0..blocks {
            s.u64("the entity's dimension")?;
            s.i64("the entity's tag")?;
            let t = s.u64("the element type")?;
            let n = s.count("elements in the block", 4)?;
            let element = element_type(t).ok_or_else(|| s.err(unknown_type(t)))?;
            if n > total - read {
                return Err(s.err(format!(
                    "the blocks hold more elements than the {total} the section claims"
                )));
            }
            read += n;
            for _ in 0..n {
                let tag = s.u64("an element tag")?;
                self.ascii_element(s, &mut cells, element, tag)?;
            }
        }
        if read != total {
            return Err(s.err(format!(
                "the blocks hold {read} elements, the section claims {total}"
            )));
        }
        Ok(cells)
    }

    /// A block of `count` binary elements of `nodes` nodes each, `skip` integers of `size`
    /// bytes before each one's nodes.
    #[allow(clippy::too_many_arguments)]
    fn binary_block(
        &self,
        s: &mut Scan,
        cells: &mut Cells,
        count: usize,
        size: usize,
        skip: usize,
        nodes: usize,
        kind: Kind,
    ) -> Result<()> {
        let per = (skip + nodes) * size;
        let count = s.check_count(count as u64, "elements in the block", per)?;
        let start = s.pos;
        let data = s.take(count * per, "the elements")?;
        let corners = corners(kind);
        if corners == 0 {
            match kind {
                Kind::Solid(name) if count > 0 => {
                    cells.other(name, count, MeshFileLocation::Byte(start))
                }
                _ => cells.skipped += count,
            }
            return Ok(());
        }
        if kind == Kind::Tet {
            cells.tets.reserve(count);
        }
        // 4-byte integers are signed: a negative node tag is no node.
        let int = |b: &[u8]| {
            let raw = super::tetfile::uint(b, s.little);
            if size == 4 {
                raw as u32 as i32 as i64 as u64
            } else {
                raw
            }
        };
        for (k, e) in data.chunks_exact(per).enumerate() {
            let mut nodes = [0u32; 8];
            for (j, slot) in nodes[..corners].iter_mut().enumerate() {
                let off = (skip + j) * size;
                let at = MeshFileLocation::Byte(start + per * k + off);
                *slot = self.node(int(&e[off..off + size]), &s.fail, at)?;
            }
            match kind {
                Kind::Cell(solid, order) => cells.solid(solid, order, &nodes, int(&e[..size])),
                _ => cells.tet([nodes[0], nodes[1], nodes[2], nodes[3]]),
            }
        }
        Ok(())
    }

    fn v22_binary(&self, s: &mut Scan) -> Result<Cells> {
        let n = s.count("elements", 8)?;
        s.skip_line();
        let mut cells = Cells::with_capacity(n.min(s.left() / 20));
        let mut read = 0;
        while read < n {
            let t = s.bin_i32("an element type")?;
            let (nodes, kind) = u64::try_from(t)
                .ok()
                .and_then(element_type)
                .ok_or_else(|| s.err(unknown_type(t as u64)))?;
            let count = s.bin_i32("the number of elements")?;
            let tags = s.bin_i32("the number of tags")?;
            let (Ok(count), Ok(tags)) = (usize::try_from(count), usize::try_from(tags)) else {
                return Err(s.err(format!(
                    "an element block claims {count} elements of {tags} tags"
                )));
            };
            if count == 0 || count > n - read {
                return Err(s.err(format!(
                    "an element block claims {count} elements, but {} of the {n} are left",
                    n - read
                )));
            }
            self.binary_block(s, &mut cells, count, 4, 1 + tags, nodes, kind)?;
            read += count;
        }
        Ok(cells)
    }

    fn v41_binary(&self, s: &mut Scan, size: usize) -> Result<Cells> {
        let blocks = s.bin_uint(size, "the number of element blocks")?;
        s.check_count(blocks, "element blocks", 12 + size)?;
        let total = s.bin_uint(size, "the number of elements")?;
        let total = s.check_count(total, "elements", 2 * size)?;
        s.bin_uint(size, "the smallest element tag")?;
        s.bin_uint(size, "the largest element tag")?;
        let mut cells = Cells::with_capacity(total.min(s.left() / (5 * size)));
        let mut read = 0;
        for _ in 0..blocks {
            s.bin_i32("the entity's dimension")?;
            s.bin_i32("the entity's tag")?;
            let t = s.bin_i32("the element type")?;
            let (nodes, kind) = u64::try_from(t)
                .ok()
                .and_then(element_type)
                .ok_or_else(|| s.err(unknown_type(t as u64)))?;
            let count = s.bin_uint(size, "the number of elements in the block")?;
            if count > (total - read) as u64 {
                return Err(s.err(format!(
                    "the blocks hold more elements than the {total} the section claims"
                )));
            }
            self.binary_block(s, &mut cells, count as usize, size, 1, nodes, kind)?;
            read += count as usize;
        }
        if read != total {
            return Err(s.err_now(format!(
                "the blocks hold {read} elements, the section claims {total}"
            )));
        }
        Ok(cells)
    }
}
