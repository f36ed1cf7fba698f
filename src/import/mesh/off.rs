//! Geomview OFF: `4OFF` and `nOFF` of dimension 4, text and `BINARY`.

use super::*;

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

pub(super) fn off(bytes: &[u8], cx: Cx) -> Result<MeshData4> {
    let (header_line, header, body) = header_line(bytes, cx)?;
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
    let (nv, nf) = text_counts(&mut lines, rest, kind, keyword, header_line, cx)?;

    // A vertex takes at least 8 bytes of text, a face at least 8.
    let mut build = Build::with_capacity(nv.min(text.len() / 8), nf.min(text.len() / 8));
    text_vertices(&mut lines, nv, kind, keyword, &mut build, cx)?;
    text_faces(&mut lines, nf, &mut build, cx)?;
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

/// The header keyword's line: the first line with something other than a comment. Gives its
/// number, its bytes without the comment, and the offset of the line after it.
fn header_line<'a>(bytes: &'a [u8], cx: Cx) -> Result<(usize, &'a [u8], usize)> {
    let mut pos = 0;
    let mut line = 0;
    loop {
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
            return Ok((line, content, next));
        }
        pos = next;
    }
}

/// The dimension (nOFF) and the counts of a text file, on the header line (`rest`, the words
/// after the keyword) or the lines after it; checks the dimension and gives the numbers of
/// vertices and faces.
fn text_counts(
    lines: &mut Lines,
    rest: Vec<&str>,
    kind: OffKind,
    keyword: &str,
    header_line: usize,
    cx: Cx,
) -> Result<(usize, usize)> {
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
    Ok((nv, nf))
}

/// Reads `nv` vertices of a text file, one a line: four finite coordinates, then the numbers
/// `kind` adds, which are checked and dropped.
fn text_vertices(
    lines: &mut Lines,
    nv: usize,
    kind: OffKind,
    keyword: &str,
    build: &mut Build,
    cx: Cx,
) -> Result<()> {
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
    Ok(())
}

/// Reads `nf` faces of a text file, one a line: `n i1 ... in`, then a colour, which is
/// ignored.
fn text_faces(lines: &mut Lines, nf: usize, build: &mut Build, cx: Cx) -> Result<()> {
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
    Ok(())
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
