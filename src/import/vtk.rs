//! Halos from legacy VTK: an `UNSTRUCTURED_GRID` of tetrahedra (cell type 10; of 24, the
//! quadratic tetrahedron, the corners; cells of lower dimension skipped, other solids an
//! error), ASCII or
//! binary (big-endian), with the CELLS layout of file versions up to 4.2 (a count before each
//! cell's ids) and of 5.1 (OFFSETS and CONNECTIVITY arrays). `surface_vertices`, `rho`,
//! `delta_d` and `delta_t` come from the dataset's FIELD data, `t` and `d_orig` from the
//! point data (SCALARS or FIELD arrays). Sections a halo does not need (other point or cell
//! attributes: SCALARS, COLOR_SCALARS, LOOKUP_TABLE, VECTORS, NORMALS, TEXTURE_COORDINATES,
//! TENSORS, TENSORS6, GLOBAL_IDS, PEDIGREE_IDS, EDGE_FLAGS; FIELD arrays; the METADATA after
//! an array, with its COMPONENT_NAMES and INFORMATION) are read past, whatever their data
//! type, as VTK's vtkDataWriter writes them: numbers of every width (vtkIdType as a 4-byte
//! int), `bit` (8 to a byte in binary), `string` and `utf8_string` (one a line, `%`-encoded,
//! in ASCII; each after its length in binary, in 1, 2, 4 or 8 big-endian bytes whose top two
//! bits say which) and `variant` (a type and a string per value, as text). A file without
//! halo4d's layout is read as tetrahedra alone for `halo4d check`
//! ([`read_vtk_tetrahedra`]). A UTF-8 byte-order mark before the first line is skipped.

use super::tetfile::{Kind, bom, solid, vtk_cell_size, vtk_kind};
use super::{FileParams, FileTetrahedra, ImportError, ImportedHalo, PlainTetrahedra, Solid};
use crate::check::TetMesh;
use crate::convention::file_order;
use crate::limits::shorten;
use std::collections::HashMap;

type Result<T> = std::result::Result<T, ImportError>;

fn err(message: String) -> ImportError {
    ImportError::Vtk(message)
}

/// Reads the halo of a legacy VTK file (see [`crate::export::write_vtk`]).
pub fn read_vtk(bytes: &[u8]) -> Result<ImportedHalo> {
    let (mut r, title) = header(bytes)?;
    halo(r.grid()?, &title)
}

/// Reads a legacy `.vtk` of tetrahedra as `halo4d check` takes it: a halo where the file
/// gives halo4d's layout ([`read_vtk`]); otherwise (another program's file, or an earlier
/// halo4d's without `layers`) its tetrahedra alone, with why the halo's own checks cannot
/// be made. A file that gives the layout wrongly is an error, as with [`read_vtk`].
pub fn read_vtk_tetrahedra(bytes: &[u8]) -> Result<FileTetrahedra> {
    let (mut r, title) = header(bytes)?;
    let grid = r.grid()?;
    let format = format!("legacy VTK {}", if r.ascii { "ASCII" } else { "binary" });
    let has = |key: &str| grid.field.contains_key(key);
    let why = match (has("surface_vertices"), has("layers")) {
        (true, true) => return Ok(FileTetrahedra::Halos(vec![halo(grid, &title)?])),
        (false, _) => {
            "its FIELD data does not give halo4d's halo layout (`surface_vertices`, `layers`): another program wrote it"
        }
        (true, false) => {
            "its FIELD data has `surface_vertices` but not `layers`: an earlier halo4d wrote it, with one layer of prisms and no surface vertices among the halo's"
        }
    };
    PlainTetrahedra {
        name: name(&title),
        positions: grid.points,
        tets: grid.tets,
        why: format!("a {format} mesh: {why}"),
        format,
        pieces: Vec::new(),
        piece_of: Vec::new(),
        solids: grid.solids,
    }
    .validate()
    .map(FileTetrahedra::Plain)
}

/// The name of a halo or mesh: the title up to its first `: `, or `halo`.
fn name(title: &str) -> String {
    let name = title
        .split_once(": ")
        .map_or(title, |(head, _)| head)
        .trim();
    if name.is_empty() { "halo" } else { name }.to_string()
}

/// The halo of a grid whose FIELD data gives halo4d's layout.
fn halo(grid: Grid, title: &str) -> Result<ImportedHalo> {
    let field = |key: &str| grid.field.get(key).and_then(|v| v.first().copied());
    if let Some(s) = grid.solids.first() {
        return Err(err(format!(
            "its FIELD data gives halo4d's halo layout, but cell {} is a {}: a halo is built of tetrahedra only",
            s.id,
            s.kind.name()
        )));
    }
    let n = surface_vertices(&grid.field)?;
    for key in ["rho", "delta_d", "delta_t"] {
        if let Some(v) = field(key).filter(|v| !v.is_finite()) {
            return Err(err(format!(
                "the FIELD value {key} is {v}, not a finite number"
            )));
        }
    }
    let surface_triangles = surface_triangles(&grid.field, n)?;
    ImportedHalo {
        name: name(title),
        mesh: TetMesh {
            positions: grid.points,
            surface_vertices: n as usize,
            tets: grid.tets,
            surface_triangles,
        },
        t: grid.t,
        d_orig: grid.d_orig,
        params: FileParams {
            rho: field("rho"),
            delta_d: field("delta_d"),
            delta_t: field("delta_t"),
            split: None,
            surface_mesh: None,
            surface_mesh_vertices: None,
            layers: field("layers"),
        },
    }
    .validate()
}

/// Reads the header: the magic line with the file version, the title, ASCII or BINARY and
/// `DATASET UNSTRUCTURED_GRID`. Gives the reader of the rest, and the title.
fn header(bytes: &[u8]) -> Result<(Reader<'_>, String)> {
    let mut c = Cursor {
        bytes,
        pos: bom(bytes),
    };
    let magic = c.line().unwrap_or_default();
    let version = magic
        .strip_prefix("# vtk DataFile Version ")
        .ok_or_else(|| {
            err(format!(
                "wrong magic: the first line must be `# vtk DataFile Version x.x`, found {:?}",
                shorten(&magic)
            ))
        })?;
    let major: u32 = version
        .trim()
        .split('.')
        .next()
        .and_then(|m| m.parse().ok())
        .ok_or_else(|| err(format!("unreadable file version {:?}", shorten(version))))?;
    let title = c
        .line()
        .ok_or_else(|| err("truncated after the first line".into()))?;
    let ascii = match c.line().map(|l| l.trim().to_ascii_uppercase()) {
        Some(l) if l == "ASCII" => true,
        Some(l) if l == "BINARY" => false,
        Some(l) => {
            return Err(err(format!(
                "the third line must be ASCII or BINARY, found {:?}",
                shorten(&l)
            )));
        }
        None => return Err(err("truncated: the file ends before ASCII or BINARY".into())),
    };
    let mut r = Reader {
        c,
        ascii,
        new_cells: major >= 5,
        components: 1,
    };
    match r.keyword_line()?.as_deref() {
        Some([dataset, kind]) if dataset.eq_ignore_ascii_case("DATASET") => {
            if !kind.eq_ignore_ascii_case("UNSTRUCTURED_GRID") {
                return Err(err(format!(
                    "the dataset is {}; halos are UNSTRUCTURED_GRID",
                    shorten(kind)
                )));
            }
        }
        other => {
            return Err(err(format!(
                "expected `DATASET UNSTRUCTURED_GRID`, found {:?}",
                shorten(&other.map(|w| w.join(" ")).unwrap_or("end of file".into()))
            )));
        }
    }
    Ok((r, title))
}

/// The halo layout's number of surface vertices, from the FIELD data: a whole number that
/// fits a u32 (kept as the f64 read).
fn surface_vertices(field: &HashMap<String, Vec<f64>>) -> Result<f64> {
    let n = field
        .get("surface_vertices")
        .and_then(|v| v.first().copied())
        .ok_or_else(|| {
            ImportError::NoHalo(format!(
                "the file lacks the halo layout: its FIELD data has no `surface_vertices` (halo4d build writes it), so the two offset surfaces cannot be told apart; fields present: {}",
                if field.is_empty() {
                    "none".to_string()
                } else {
                    let mut keys: Vec<&str> = field.keys().map(String::as_str).collect();
                    keys.sort_unstable();
                    keys.join(", ")
                }
            ))
        })?;
    if !(n >= 0.0 && n.fract() == 0.0 && n <= u32::MAX as f64) {
        return Err(err(format!(
            "surface_vertices must be a non-negative integer, found {n}"
        )));
    }
    Ok(n)
}

/// The surface's triangles, where the FIELD data lists them (halo4d writes them since the
/// checker needs them to see a missing prism; an older file has none), each a triple of
/// surface vertices below `n`.
fn surface_triangles(field: &HashMap<String, Vec<f64>>, n: f64) -> Result<Vec<[u32; 3]>> {
    let Some(v) = field.get("surface_triangles") else {
        return Ok(Vec::new());
    };
    if v.len() % 3 != 0 {
        return Err(err(format!(
            "the FIELD array surface_triangles has {} values, not three per triangle",
            v.len()
        )));
    }
    if let Some(x) = v
        .iter()
        .find(|x| !(**x >= 0.0 && x.fract() == 0.0 && **x < n))
    {
        return Err(err(format!(
            "the FIELD array surface_triangles names {x}, not a surface vertex (0 to {})",
            n - 1.0
        )));
    }
    Ok(v.chunks_exact(3)
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect())
}

/// A position in the file's bytes.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Cursor<'_> {
    /// The rest of the current line (without `\r\n`), moving past it; `None` at the end.
    fn line(&mut self) -> Option<String> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        let line = &rest[..end];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        Some(String::from_utf8_lossy(line).into_owned())
    }

    /// The next whitespace-separated token, moving past it.
    fn token(&mut self) -> Option<&[u8]> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| &self.bytes[start..self.pos])
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

/// A data type of legacy VTK (vtkDataWriter's names), and for numbers, their size in binary
/// files.
#[derive(Clone, Copy, PartialEq)]
enum Type {
    Int(usize, bool),
    Float(usize),
    /// Bits: `0` and `1` in ASCII, 8 to a byte in binary.
    Bit,
    /// `string` or `utf8_string`: one a line in ASCII, each after its length in binary.
    String,
    /// `variant`: a type number and a string per value, as text in ASCII and binary files.
    Variant,
}

impl Type {
    fn parse(name: &str) -> Result<Type> {
        Ok(match name.to_ascii_lowercase().as_str() {
            "bit" => Type::Bit,
            "unsigned_char" => Type::Int(1, false),
            "char" | "signed_char" => Type::Int(1, true),
            "unsigned_short" => Type::Int(2, false),
            "short" => Type::Int(2, true),
            "unsigned_int" | "vtktypeuint32" => Type::Int(4, false),
            // vtkDataWriter writes vtkIdType arrays as 4-byte ints.
            "int" | "vtktypeint32" | "vtkidtype" => Type::Int(4, true),
            "unsigned_long" | "vtktypeuint64" => Type::Int(8, false),
            "long" | "vtktypeint64" => Type::Int(8, true),
            "float" => Type::Float(4),
            "double" => Type::Float(8),
            "string" | "utf8_string" => Type::String,
            "variant" => Type::Variant,
            other => {
                return Err(err(format!(
                    "data type `{}` is none that legacy VTK writes (bit, char, signed_char, unsigned_char, short, unsigned_short, int, unsigned_int, long, unsigned_long, vtktypeint64, vtktypeuint64, vtkIdType, float, double, string, utf8_string, variant)",
                    shorten(other)
                )));
            }
        })
    }

    /// Whether the values are numbers of a fixed size.
    fn is_number(self) -> bool {
        matches!(self, Type::Int(..) | Type::Float(_))
    }

    /// The size of a number in binary files.
    fn size(self) -> usize {
        match self {
            Type::Int(s, _) | Type::Float(s) => s,
            Type::Bit | Type::String | Type::Variant => 1,
        }
    }

    /// A big-endian binary value.
    fn decode(self, b: &[u8]) -> f64 {
        let mut x = [0u8; 8];
        match self {
            Type::Float(4) => f64::from(f32::from_be_bytes(b[..4].try_into().expect("4 bytes"))),
            Type::Float(_) => f64::from_be_bytes(b[..8].try_into().expect("8 bytes")),
            Type::Bit | Type::String | Type::Variant => f64::NAN,
            Type::Int(size, signed) => {
                x[8 - size..].copy_from_slice(&b[..size]);
                let u = u64::from_be_bytes(x);
                if signed && size < 8 && (u >> (8 * size - 1)) & 1 == 1 {
                    (u as i64 - (1i64 << (8 * size))) as f64
                } else if signed {
                    u as i64 as f64
                } else {
                    u as f64
                }
            }
        }
    }
}

/// What the reader keeps of the file.
#[derive(Default)]
struct Grid {
    points: Vec<[f64; 3]>,
    tets: Vec<[u32; 4]>,
    /// Hexahedra, wedges and pyramids (a halo has none).
    solids: Vec<Solid>,
    field: HashMap<String, Vec<f64>>,
    t: Option<Vec<f64>>,
    d_orig: Option<Vec<f64>>,
}

/// The cells of a CELLS section: all their point ids, and where each cell's are.
struct CellList {
    ids: Vec<f64>,
    /// Each cell's first id in `ids`, and how many it has.
    spans: Vec<(usize, usize)>,
}

/// Where attribute sections belong.
#[derive(Clone, Copy, PartialEq)]
enum Attach {
    Dataset,
    Points(usize),
    Cells(usize),
}

struct Reader<'a> {
    c: Cursor<'a>,
    ascii: bool,
    /// Version 5 CELLS: OFFSETS and CONNECTIVITY arrays.
    new_cells: bool,
    /// The components of the last array read: as many COMPONENT_NAMES as its METADATA may
    /// list.
    components: usize,
}

/// A count from a header line, as usize.
fn count(word: Option<&String>, what: &str) -> Result<usize> {
    let word = word.ok_or_else(|| err(format!("{what}: a count is missing")))?;
    word.parse()
        .map_err(|_| err(format!("{what}: {:?} is not a count", shorten(word))))
}

impl Reader<'_> {
    /// The words of the next line that is not blank; `None` at the end of the file.
    fn keyword_line(&mut self) -> Result<Option<Vec<String>>> {
        while let Some(line) = self.c.line() {
            let words: Vec<String> = line.split_whitespace().map(String::from).collect();
            if !words.is_empty() {
                return Ok(Some(words));
            }
        }
        Ok(None)
    }

    /// `count` numbers of type `ty`; `what` names them in errors. The claimed count is
    /// checked against the bytes left before anything is allocated.
    fn numbers(&mut self, count: usize, ty: Type, what: &str) -> Result<Vec<f64>> {
        if !ty.is_number() {
            return Err(err(format!(
                "{what}: the data type must be a number type (int, float, ...), this one holds {}",
                match ty {
                    Type::Bit => "bits",
                    Type::String => "strings",
                    _ => "variants",
                }
            )));
        }
        let mut out = Vec::new();
        self.each_number(count, ty, what, |k, x| {
            if k == 0 {
                out.reserve_exact(count);
            }
            out.push(x);
        })?;
        Ok(out)
    }

    /// `count` numbers of type `ty`, each given to `each` with its index; `what` names them
    /// in errors. The claimed count is checked against the bytes left first.
    fn each_number(
        &mut self,
        count: usize,
        ty: Type,
        what: &str,
        mut each: impl FnMut(usize, f64),
    ) -> Result<()> {
        let left = self.c.remaining();
        if self.ascii {
            // Every ASCII number takes a character and a separator (the last one may lack it).
            if count > left.div_ceil(2) {
                return Err(err(format!(
                    "{what}: {count} values claimed, but only {left} bytes are left"
                )));
            }
            for k in 0..count {
                let word = self.c.token().ok_or_else(|| {
                    err(format!("{what}: the file ends after {k} of {count} values"))
                })?;
                let len = word.len();
                let text = String::from_utf8_lossy(word).into_owned();
                let value = match ty {
                    Type::Float(_) => text.parse::<f64>().ok(),
                    _ => text.parse::<i64>().ok().map(|i| i as f64),
                };
                let at = self.c.pos - len;
                each(
                    k,
                    value.ok_or_else(|| {
                        err(format!(
                            "{what}: value {k} is {:?} (byte {at}), not a number of the declared type",
                            shorten(&text)
                        ))
                    })?,
                );
            }
        } else {
            let size = ty.size();
            if count.checked_mul(size).is_none_or(|b| b > left) {
                return Err(err(format!(
                    "{what}: {count} values of {size} bytes claimed at byte {}, but only {left} bytes are left (truncated?)",
                    self.c.pos
                )));
            }
            let bytes = &self.c.bytes[self.c.pos..self.c.pos + count * size];
            self.c.pos += count * size;
            self.end_of_binary();
            for (k, b) in bytes.chunks_exact(size).enumerate() {
                each(k, ty.decode(b));
            }
        }
        Ok(())
    }

    /// Binary data end with a newline.
    fn end_of_binary(&mut self) {
        if self.c.bytes.get(self.c.pos) == Some(&b'\n') {
            self.c.pos += 1;
        }
    }

    /// Reads past an array this reader does not need, of `tuples` tuples of `components`
    /// values of type `ty`, as vtkDataWriter writes it; `what` names it in errors.
    fn skip(&mut self, tuples: usize, components: usize, ty: Type, what: &str) -> Result<()> {
        let count = tuples
            .checked_mul(components)
            .ok_or_else(|| err(format!("{what}: {tuples} tuples of {components}: too many")))?;
        self.components = components;
        let left = self.c.remaining();
        let at = self.c.pos;
        match ty {
            Type::Int(..) | Type::Float(_) => self.each_number(count, ty, what, |_, _| ()),
            Type::Bit if self.ascii => {
                self.each_number(count, Type::Int(1, false), what, |_, _| ())
            }
            Type::Bit => {
                // VTK's reader reads (tuples components + 7) / 8 bytes, its writer writes
                // (tuples - 1) / 8 + 1 whatever the components: the two agree for one
                // component. Where they differ, the writer's count is taken when the file
                // goes on after it as after an array (a newline, then a line that begins
                // with a letter, or the end), else the reader's.
                let read = count.div_ceil(8);
                let written = if tuples == 0 { 0 } else { (tuples - 1) / 8 + 1 };
                let after = |n: usize| {
                    let b = &self.c.bytes[(at + n).min(self.c.bytes.len())..];
                    n <= left
                        && (b.is_empty()
                            || (b[0] == b'\n' && b.get(1).is_none_or(u8::is_ascii_alphabetic)))
                };
                let n = if written != read && after(written) {
                    written
                } else {
                    read
                };
                if n > left {
                    return Err(err(format!(
                        "{what}: {count} bits take {n} bytes from byte {at}, but only {left} are left (truncated?)"
                    )));
                }
                self.c.pos += n;
                self.end_of_binary();
                Ok(())
            }
            Type::String if self.ascii => {
                // One a line (an empty string an empty line), each line at least its newline.
                if count > left {
                    return Err(err(format!(
                        "{what}: {count} strings claimed, but only {left} bytes are left"
                    )));
                }
                for k in 0..count {
                    if self.c.line().is_none() {
                        return Err(err(format!(
                            "{what}: the file ends after {k} of {count} strings"
                        )));
                    }
                }
                Ok(())
            }
            Type::String => {
                for k in 0..count {
                    let at = self.c.pos;
                    let rest = &self.c.bytes[at..];
                    let Some(&first) = rest.first() else {
                        return Err(err(format!(
                            "{what}: the file ends after {k} of {count} strings"
                        )));
                    };
                    // The top two bits say the length's size: 11 one byte, 10 two, 01 four,
                    // 00 eight; the rest of it is the length, big-endian.
                    let head = [8, 4, 2, 1][usize::from(first >> 6)];
                    let mask = [u64::MAX, 0x3fff_ffff, 0x3fff, 0x3f][usize::from(first >> 6)];
                    let len = rest
                        .get(..head)
                        .map(|b| super::tetfile::uint(b, false) & mask)
                        .filter(|&len| len <= (rest.len() - head) as u64)
                        .ok_or_else(|| {
                            err(format!(
                                "{what}: string {k} of {count}, at byte {at}, claims more bytes than the file has left (truncated?)"
                            ))
                        })?;
                    self.c.pos += head + len as usize;
                }
                self.end_of_binary();
                Ok(())
            }
            Type::Variant => {
                // A type and a string per value, each a word (and a separator).
                if count > left / 2 {
                    return Err(err(format!(
                        "{what}: {count} variants claimed, but only {left} bytes are left"
                    )));
                }
                for k in 0..2 * count {
                    if self.c.token().is_none() {
                        return Err(err(format!(
                            "{what}: the file ends after {} of {count} variants",
                            k / 2
                        )));
                    }
                }
                Ok(())
            }
        }
    }

    /// Reads sections up to the end of the file.
    fn grid(&mut self) -> Result<Grid> {
        let mut g = Grid::default();
        let mut points: Option<usize> = None;
        let mut cells: Option<CellList> = None;
        let mut types: Option<Vec<f64>> = None;
        let mut attach = Attach::Dataset;
        while let Some(words) = self.keyword_line()? {
            let key = words[0].to_ascii_uppercase();
            match key.as_str() {
                "POINTS" => {
                    let n = count(words.get(1), "POINTS")?;
                    let ty = Type::parse(words.get(2).map_or("", String::as_str))?;
                    let xyz = self.numbers(
                        n.checked_mul(3)
                            .ok_or_else(|| err("POINTS: count too large".into()))?,
                        ty,
                        "POINTS",
                    )?;
                    g.points = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                    points = Some(n);
                    self.components = 3;
                }
                "CELLS" => {
                    cells = Some(self.cells(&words)?);
                    self.components = 1;
                }
                "CELL_TYPES" => {
                    let n = count(words.get(1), "CELL_TYPES")?;
                    types = Some(self.numbers(n, Type::Int(4, true), "CELL_TYPES")?);
                    self.components = 1;
                }
                "POINT_DATA" => {
                    let n = count(words.get(1), "POINT_DATA")?;
                    if Some(n) != points {
                        return Err(err(format!(
                            "POINT_DATA is for {n} points, POINTS lists {}",
                            points.map_or("none".into(), |p| p.to_string())
                        )));
                    }
                    attach = Attach::Points(n);
                }
                "CELL_DATA" => {
                    let n = count(words.get(1), "CELL_DATA")?;
                    let have = cells.as_ref().map(|c| c.spans.len());
                    if Some(n) != have {
                        return Err(err(format!(
                            "CELL_DATA is for {n} cells, CELLS lists {}",
                            have.map_or("none".into(), |c| c.to_string())
                        )));
                    }
                    attach = Attach::Cells(n);
                }
                "FIELD" => {
                    let arrays = self.field(&words, attach)?;
                    for (name, values) in arrays {
                        match attach {
                            Attach::Dataset => {
                                g.field.insert(name, values);
                            }
                            Attach::Points(_) => g.point_array(&name, values),
                            Attach::Cells(_) => {}
                        }
                    }
                }
                "METADATA" => self.skip_metadata(),
                _ => self.attribute(&words, attach, &mut g)?,
            }
        }
        let points = points.ok_or_else(|| err("no POINTS section".into()))?;
        let cells = cells.ok_or_else(|| err("no CELLS section".into()))?;
        let types = types.ok_or_else(|| err("no CELL_TYPES section".into()))?;
        if types.len() != cells.spans.len() {
            return Err(err(format!(
                "CELL_TYPES lists {} cells, CELLS {}",
                types.len(),
                cells.spans.len()
            )));
        }
        g.tets = Vec::with_capacity(cells.spans.len());
        // Each kind of solid halo4d does not read: how many, and the first's cell and type.
        let mut others: Vec<(&str, usize, usize, f64)> = Vec::new();
        for (k, (&t, &(start, len))) in types.iter().zip(&cells.spans).enumerate() {
            let kind = (t >= 0.0 && t.fract() == 0.0)
                .then(|| vtk_kind(t as u64))
                .flatten()
                .ok_or_else(|| err(format!("cell {k} has type {t}, which VTK does not define")))?;
            match kind {
                Kind::Lower => continue,
                Kind::Solid(name) => {
                    match others.iter_mut().find(|o| o.0 == name) {
                        Some(o) => o.1 += 1,
                        None => others.push((name, 1, k, t)),
                    }
                    continue;
                }
                Kind::Tet | Kind::Cell(..) => {}
            }
            vtk_cell_size(kind, t as u64, len).map_err(|m| err(format!("cell {k} {m}")))?;
            let mut nodes = [0u32; 8];
            let used = if let Kind::Cell(solid, _) = kind {
                solid.corners()
            } else {
                4
            };
            for (slot, &id) in nodes[..used].iter_mut().zip(&cells.ids[start..start + len]) {
                if !(id >= 0.0 && id.fract() == 0.0 && id < points as f64) {
                    return Err(err(format!(
                        "cell {k} names point {id}, but there are {points} points"
                    )));
                }
                *slot = id as u32;
            }
            match kind {
                Kind::Cell(kind, order) => g.solids.push(solid(kind, order, &nodes, k as u64)),
                _ => g
                    .tets
                    .push(file_order([nodes[0], nodes[1], nodes[2], nodes[3]])),
            }
        }
        if let Some(&(_, _, k, t)) = others.first() {
            let list: Vec<String> = others
                .iter()
                .map(|(name, n, _, _)| format!("{n} {name}"))
                .collect();
            return Err(err(format!(
                "cell {k} has type {t}: the mesh has {} besides its {} tetrahedra and {} hexahedra, wedges and pyramids, and halo4d checks meshes of these four kinds of cell only; split the other cells into them first",
                list.join(", "),
                g.tets.len(),
                g.solids.len()
            )));
        }
        Ok(g)
    }

    /// The cells of a CELLS section: their point ids, of any number (the cell types say
    /// which are tetrahedra).
    fn cells(&mut self, words: &[String]) -> Result<CellList> {
        let first = count(words.get(1), "CELLS")?;
        let size = count(words.get(2), "CELLS")?;
        if !self.new_cells {
            let ids = self.numbers(size, Type::Int(4, true), "CELLS")?;
            let mut spans: Vec<(usize, usize)> = Vec::with_capacity(first.min(ids.len()));
            // Where the counts go wrong, the first cell that is not a tetrahedron is the
            // likely culprit.
            let hint = |spans: &[(usize, usize)]| {
                spans
                    .iter()
                    .position(|s| s.1 != 4)
                    .map(|k| format!(" (cell {k} has {} points: is its count right?)", spans[k].1))
                    .unwrap_or_default()
            };
            let mut at = 0;
            for k in 0..first {
                let len = ids.get(at).copied().ok_or_else(|| {
                    err(format!(
                        "CELLS: its {size} values end at cell {k} of {first}{}",
                        hint(&spans)
                    ))
                })?;
                if !(len >= 0.0 && len.fract() == 0.0 && (len as usize) < ids.len() - at) {
                    return Err(err(format!(
                        "CELLS: cell {k} claims {len} points, more than its {size} values hold{}",
                        hint(&spans)
                    )));
                }
                spans.push((at + 1, len as usize));
                at += 1 + len as usize;
            }
            if at != ids.len() {
                return Err(err(format!(
                    "CELLS: {first} cells use {at} of its {size} values{}",
                    hint(&spans)
                )));
            }
            return Ok(CellList { ids, spans });
        }
        // Version 5: `CELLS offsets connectivity`, then the two arrays.
        let mut array = |name: &str, n: usize| -> Result<Vec<f64>> {
            match self.keyword_line()?.as_deref() {
                Some([word, ty]) if word.eq_ignore_ascii_case(name) => {
                    self.numbers(n, Type::parse(ty)?, name)
                }
                other => Err(err(format!(
                    "CELLS: expected `{name} <type>`, found {:?}",
                    shorten(&other.map(|w| w.join(" ")).unwrap_or("end of file".into()))
                ))),
            }
        };
        let offsets = array("OFFSETS", first)?;
        let ids = array("CONNECTIVITY", size)?;
        if offsets.first().is_some_and(|&o| o != 0.0)
            || offsets.last().is_some_and(|&o| o != size as f64)
        {
            return Err(err(format!(
                "CELLS: OFFSETS must run from 0 to the {size} CONNECTIVITY values"
            )));
        }
        let mut spans = Vec::with_capacity(offsets.len().saturating_sub(1));
        for (k, w) in offsets.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            if !(a.fract() == 0.0 && b.fract() == 0.0 && 0.0 <= a && a <= b && b <= size as f64) {
                return Err(err(format!(
                    "CELLS: the OFFSETS of cell {k} ({a}, {b}) are out of order"
                )));
            }
            spans.push((a as usize, (b - a) as usize));
        }
        Ok(CellList { ids, spans })
    }

    /// A FIELD section: `FIELD name arrays`, then per array `name components tuples type`
    /// and its values (or `NULL_ARRAY`), each perhaps followed by its METADATA.
    fn field(&mut self, words: &[String], attach: Attach) -> Result<Vec<(String, Vec<f64>)>> {
        let arrays = count(words.get(2), "FIELD")?;
        let mut out = Vec::new();
        let mut k = 0;
        while k < arrays {
            let line = self
                .keyword_line()?
                .ok_or_else(|| err(format!("FIELD: the file ends after {k} of {arrays} arrays")))?;
            if line[0].eq_ignore_ascii_case("METADATA") {
                self.skip_metadata();
                continue;
            }
            if line[0] == "NULL_ARRAY" {
                k += 1;
                continue;
            }
            let [name, components, tuples, ty] = &line[..] else {
                return Err(err(format!(
                    "FIELD: expected `name components tuples type`, found {:?}",
                    shorten(&line.join(" "))
                )));
            };
            let what = format!("FIELD array {name}");
            let components = count(Some(components), &what)?;
            let tuples = count(Some(tuples), &what)?;
            if let Attach::Points(n) | Attach::Cells(n) = attach
                && tuples != n
            {
                return Err(err(format!("{what}: {tuples} tuples for {n} elements")));
            }
            let total = components
                .checked_mul(tuples)
                .ok_or_else(|| err(format!("{what}: size too large")))?;
            let ty = Type::parse(ty)?;
            // Only single-component arrays of numbers matter to a halo, and the surface's
            // triangles.
            if ty.is_number()
                && (components == 1 || (components == 3 && name == "surface_triangles"))
            {
                let values = self.numbers(total, ty, &what)?;
                self.components = components;
                out.push((name.clone(), values));
            } else {
                self.skip(tuples, components, ty, &what)?;
            }
            k += 1;
        }
        Ok(out)
    }

    /// A point or cell attribute section (SCALARS, VECTORS, ...): read, and kept when it
    /// is `t` or `d_orig` of the points.
    fn attribute(&mut self, words: &[String], attach: Attach, g: &mut Grid) -> Result<()> {
        let key = words[0].to_ascii_uppercase();
        let n = match attach {
            Attach::Points(n) | Attach::Cells(n) => n,
            Attach::Dataset => {
                return Err(err(format!(
                    "unknown section `{}` (expected POINTS, CELLS, CELL_TYPES, FIELD, POINT_DATA or CELL_DATA)",
                    shorten(&words[0])
                )));
            }
        };
        let word = |i: usize| words.get(i).map_or("", String::as_str);
        match key.as_str() {
            "SCALARS" => {
                let components = match words.get(3) {
                    Some(c) => count(Some(c), "SCALARS")?,
                    None => 1,
                };
                if !(1..=4).contains(&components) {
                    return Err(err(format!(
                        "SCALARS {}: {components} components (1 to 4 allowed)",
                        word(1)
                    )));
                }
                let ty = Type::parse(word(2))?;
                match self.keyword_line()?.as_deref() {
                    Some([lt, _]) if lt.eq_ignore_ascii_case("LOOKUP_TABLE") => {}
                    _ => {
                        return Err(err(format!(
                            "SCALARS {}: a `LOOKUP_TABLE name` line must follow",
                            word(1)
                        )));
                    }
                }
                let what = format!("SCALARS {}", word(1));
                if ty.is_number() && components == 1 && matches!(attach, Attach::Points(_)) {
                    let values = self.numbers(n, ty, &what)?;
                    self.components = 1;
                    g.point_array(word(1), values);
                } else {
                    self.skip(n, components, ty, &what)?;
                }
            }
            "VECTORS" | "NORMALS" | "TENSORS" | "TENSORS6" | "GLOBAL_IDS" | "PEDIGREE_IDS"
            | "EDGE_FLAGS" => {
                let components = match key.as_str() {
                    "VECTORS" | "NORMALS" => 3,
                    "TENSORS" => 9,
                    "TENSORS6" => 6,
                    _ => 1,
                };
                let what = format!("{key} {}", word(1));
                self.skip(n, components, Type::parse(word(2))?, &what)?;
            }
            "TEXTURE_COORDINATES" => {
                let dim = count(words.get(2), &key)?;
                if !(1..=3).contains(&dim) {
                    return Err(err(format!(
                        "TEXTURE_COORDINATES {}: {dim} components (1 to 3 allowed)",
                        word(1)
                    )));
                }
                let what = format!("{key} {}", word(1));
                self.skip(n, dim, Type::parse(word(3))?, &what)?;
            }
            "COLOR_SCALARS" => {
                let m = count(words.get(2), &key)?.min(4);
                let ty = if self.ascii {
                    Type::Float(4)
                } else {
                    Type::Int(1, false)
                };
                self.skip(n, m, ty, &key)?;
            }
            "LOOKUP_TABLE" => {
                let m = count(words.get(2), &key)?;
                let ty = if self.ascii {
                    Type::Float(4)
                } else {
                    Type::Int(1, false)
                };
                self.skip(m, 4, ty, &key)?;
            }
            _ => {
                return Err(err(format!(
                    "unknown section `{}` in the point or cell data",
                    shorten(&words[0])
                )));
            }
        }
        Ok(())
    }

    /// Reads past a METADATA block (its line read): COMPONENT_NAMES, one a line for each
    /// component of the array before it (a name may be empty), and INFORMATION, up to the
    /// blank line that ends the block.
    fn skip_metadata(&mut self) {
        while let Some(line) = self.c.line() {
            let line = line.trim();
            if line.is_empty() {
                break;
            }
            if line.eq_ignore_ascii_case("COMPONENT_NAMES") {
                for _ in 0..self.components {
                    self.c.line();
                }
            }
        }
    }
}

impl Grid {
    /// Keeps a single-component point array when it is `t` or `d_orig`.
    fn point_array(&mut self, name: &str, values: Vec<f64>) {
        match name {
            "t" => self.t = Some(values),
            "d_orig" => self.d_orig = Some(values),
            _ => {}
        }
    }
}
