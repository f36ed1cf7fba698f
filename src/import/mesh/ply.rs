//! PLY 1.0 with `x y z w` vertex properties: ascii and both binary byte orders.
//!
//! Read by hand rather than with `ply-rs` (0.1.3, with which the tests read halo4d's own PLY
//! files back): `ply-rs` keeps every element as a map from property name to value (a map per
//! vertex, where halo4d keeps four numbers) and its binary errors name no byte offset, while
//! a mesh file's error here names the line or the byte, as the other formats' do.

use super::*;

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

/// The header of a PLY file: how its body is encoded, its elements, and where the body starts.
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// The byte offset of the body.
    pos: usize,
    /// The number of the header's last line, `end_header`.
    line: usize,
}

/// Which elements are the vertices and the faces, and what each property of each element is
/// for.
struct Layout {
    vertex: usize,
    face: usize,
    roles: Vec<Vec<Role>>,
}

pub(super) fn ply(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    let header = header(bytes, cx)?;
    let layout = layout(&header.elements, header.line, cx)?;
    body(bytes, &header, &layout, cx)
}

/// Reads the header, the text lines up to `end_header`: the format and the elements with
/// their properties.
fn header(bytes: &[u8], cx: Cx) -> Result<Header> {
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
            ["format", name, version] => encoding = Some(format_line(name, version, line, cx)?),
            ["element", name, n] => elements.push(element_line(name, n, line, cx)?),
            ["property", rest @ ..] => {
                let (name, prop) = property_line(rest, text, line, cx)?;
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
    Ok(Header {
        encoding,
        elements,
        pos,
        line,
    })
}

/// The encoding a `format NAME VERSION` header line names.
fn format_line(name: &str, version: &str, line: usize, cx: Cx) -> Result<Encoding> {
    if version != "1.0" {
        return Err(cx.line(
            line,
            format!(
                "PLY version `{}`; halo4d reads version 1.0",
                shorten(version)
            ),
        ));
    }
    Ok(match name {
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
    })
}

/// The element an `element NAME COUNT` header line declares, still without properties; at
/// most [`MAX_COUNT`] vertices or faces.
fn element_line(name: &str, n: &str, line: usize, cx: Cx) -> Result<Element> {
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
    if matches!(name, "vertex" | "face") && count > MAX_COUNT as u64 {
        return Err(cx.line(
            line,
            format!(
                "the file declares {count} {}; halo4d reads at most {MAX_COUNT}",
                el.plural()
            ),
        ));
    }
    Ok(el)
}

/// The name and type of the property a `property ...` header line declares; `rest` is the
/// words after `property`, `text` the whole line.
fn property_line<'w>(rest: &[&'w str], text: &str, line: usize, cx: Cx) -> Result<(&'w str, Prop)> {
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
    Ok(match rest {
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
    })
}

/// Finds the vertex and face elements and what each of their properties is for; every other
/// property is skipped. `line` is the header's last line, where a missing element is reported.
fn layout(elements: &[Element], line: usize, cx: Cx) -> Result<Layout> {
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
    axis_roles(&elements[vertex], &mut roles[vertex], cx)?;
    corner_role(&elements[face], &mut roles[face], cx)?;
    Ok(Layout {
        vertex,
        face,
        roles,
    })
}

/// Marks the vertex properties `x y z w` as the four axes; each must be a scalar.
fn axis_roles(v: &Element, roles: &mut [Role], cx: Cx) -> Result<()> {
    for (axis, name) in ["x", "y", "z", "w"].into_iter().enumerate() {
        let k = v.props.iter().position(|(n, _)| n == name);
        match k.map(|k| (k, v.props[k].1)) {
            Some((k, Prop::Scalar(_))) => roles[k] = Role::Axis(axis),
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
    Ok(())
}

/// Marks the face property `vertex_indices` (or `vertex_index`), a list of integers, as the
/// corners.
fn corner_role(fe: &Element, roles: &mut [Role], cx: Cx) -> Result<()> {
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
        Prop::List(_, item) if item.integer() => roles[k] = Role::Corners,
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
    Ok(())
}

/// Reads the body after the header, every element in order, into the mesh; nothing but
/// whitespace may follow the last element.
fn body(bytes: &[u8], header: &Header, layout: &Layout, cx: Cx) -> Result<MeshData4> {
    let Header {
        encoding,
        ref elements,
        pos,
        line,
    } = *header;
    let Layout {
        vertex,
        face,
        ref roles,
    } = *layout;
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
    for (el, roles) in elements.iter().zip(roles) {
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

/// An element being read: its declaration, what each property is for, and whether it is the
/// vertex or the face element.
struct Reading<'e> {
    el: &'e Element,
    roles: &'e [Role],
    is_vertex: bool,
    is_face: bool,
}

/// What is kept of one element: its point (a vertex) and its corners (a face).
struct Values {
    p: [f64; 4],
    corners: Vec<i64>,
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
            return self.skip(el);
        }
        let r = Reading {
            el,
            roles,
            is_vertex,
            is_face,
        };
        let mut values = Values {
            p: [0.0; 4],
            corners: Vec::new(),
        };
        for k in 0..el.count as usize {
            values.p = [0.0; 4];
            values.corners.clear();
            let at = match self.encoding {
                Encoding::Ascii => self.ascii_values(&r, k, &mut values)?,
                Encoding::Little | Encoding::Big => self.binary_values(&r, k, &mut values)?,
            };
            if is_vertex {
                self.vertex(values.p, k, at, build)?;
            }
            if is_face {
                build
                    .face(&values.corners, k, false)
                    .map_err(|m| self.cx.err(at, m))?;
            }
        }
        Ok(())
    }

    /// Moves past the binary elements `el`, all of fixed size, in one step.
    fn skip(&mut self, el: &Element) -> Result<()> {
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
        Ok(())
    }

    /// Reads element `k` of an ASCII body, one line, into `out`; gives the line.
    fn ascii_values(
        &mut self,
        r: &Reading,
        k: usize,
        out: &mut Values,
    ) -> Result<MeshFileLocation> {
        let el = r.el;
        let total = el.count as usize;
        let cx = self.cx;
        let lines = self.lines.as_mut().expect("ascii body has lines");
        let (n, words) = lines
            .next()
            .ok_or_else(|| cx.line(lines.last(), ends(k, total, &el.plural())))?;
        let what = if r.is_vertex {
            format!("vertex {k}")
        } else if r.is_face {
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
        for ((name, prop), role) in el.props.iter().zip(r.roles) {
            match *prop {
                Prop::Scalar(ty) => {
                    let x = next(ty, name)?;
                    if let Role::Axis(axis) = *role {
                        out.p[axis] = x;
                    }
                }
                Prop::List(count, item) => {
                    let c = next(count, name)?;
                    if !(c >= 0.0 && c.fract() == 0.0) {
                        return Err(cx.line(
                            n,
                            format!("{what}: the list `{}` has the count {c}", shorten(name)),
                        ));
                    }
                    for _ in 0..c as u64 {
                        let x = next(item, name)?;
                        if *role == Role::Corners {
                            out.corners.push(x as i64);
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
        Ok(MeshFileLocation::Line(n))
    }

    /// Reads element `k` of a binary body into `out`; gives the byte it starts at.
    fn binary_values(
        &mut self,
        r: &Reading,
        k: usize,
        out: &mut Values,
    ) -> Result<MeshFileLocation> {
        let el = r.el;
        let total = el.count as usize;
        let at = self.bin.pos;
        let cx = self.cx;
        let truncated = || cx.byte(at, ends(k, total, &el.plural()));
        for ((name, prop), role) in el.props.iter().zip(r.roles) {
            match *prop {
                Prop::Scalar(ty) => {
                    let x = ty.read(&mut self.bin).ok_or_else(truncated)?;
                    if let Role::Axis(axis) = *role {
                        out.p[axis] = x;
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
                            out.corners.push(x as i64);
                        }
                    }
                }
            }
        }
        Ok(MeshFileLocation::Byte(at))
    }

    fn vertex(&self, p: [f64; 4], k: usize, at: MeshFileLocation, build: &mut Build) -> Result<()> {
        for (axis, x) in p.iter().enumerate() {
            finite(*x, &x.to_string(), k, axis).map_err(|m| self.cx.err(at, m))?;
        }
        build.mesh.positions.push(DVec4::from_array(p));
        Ok(())
    }
}
