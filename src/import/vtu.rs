//! VTU files: VTK's XML `UnstructuredGrid` (VTK's "VTK File Formats", XML section), one
//! `Piece` of `Points` and `Cells` (`connectivity`, `offsets`, `types`); point, cell and
//! field data are skipped.
//!
//! A `DataArray` is `ascii` (numbers in the text), `binary` (base64 in the text) or
//! `appended` (at its `offset` in the `AppendedData` after the `_`, `raw` bytes or `base64`).
//! An inline array's data are its own text: the text directly inside the element, not what is
//! inside its children (VTK 9 writes an `InformationKey` child after the values once their
//! range was computed) or comments; ascii values are read where they lie, a base64 text is
//! decoded (copied first only to drop its whitespace). Binary data start with a
//! header of `header_type` (UInt32, the default, or UInt64): the number of bytes that follow;
//! with a `compressor` (`vtkZLibDataCompressor`, `vtkLZ4DataCompressor` or
//! `vtkLZMADataCompressor`), the number of blocks, the size of a block before compression,
//! the size of the last one, then each block's compressed size, and the blocks: a zlib
//! stream, a raw LZ4 block (`LZ4_compress_default`, no frame) or an `.xz` stream
//! (`lzma_easy_buffer_encode`) each. Numbers are in `byte_order` (LittleEndian or
//! BigEndian). VTK encodes a header and its data as two base64 texts (each with its
//! padding), other writers as one: both read. The XML is parsed up to the `AppendedData`
//! tag only, so that raw bytes after it are never taken for markup. A UTF-8 byte-order mark
//! before the XML is skipped.

use super::PlainTetrahedra;
use super::tetfile::{
    Cells, Fail, Kind, Result, bom, parse_f64, parse_i64, plain, uint, vtk_cell_size, vtk_kind,
};
use crate::limits::shorten;
use base64::Engine;
use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;
use rayon::prelude::*;
use std::borrow::Cow;
use std::io::Read;
use std::ops::Range;

/// Standard base64 that takes a last text with or without its padding.
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
);

/// zlib never expands data more than about 1032 times (a deflate match of 258 bytes costs at
/// least 2 bits): a block header that claims more is not believed (and nothing is allocated
/// for it).
const ZLIB_MAX_RATIO: u64 = 1032;

/// An LZ4 block gives at most 255 bytes for each byte it holds: a match's length grows by
/// 255 with each byte of its length field, and nothing else gives more per byte.
const LZ4_MAX_RATIO: u64 = 255;

/// An `.xz` stream of LZMA2 gives at most about 7,300 bytes for each byte it holds: an LZMA2
/// chunk gives at most 2 MiB, and even with the range coder's probabilities saturated (no
/// decision costs less than 0.022 bits) its 7,700 longest matches (273 bytes, 13 decisions
/// each) take about 280 bytes, with its 5-byte header. liblzma reaches 6,900 on zeros.
const XZ_MAX_RATIO: u64 = 7_500;

/// Added to the bytes a header may claim from its compressed ones, per block: a small block
/// (a few bytes of data) takes more room compressed than plain, with every compressor.
const BLOCK_SLACK: u64 = 64;

/// Reads the tetrahedra of a VTU file (VTK XML `UnstructuredGrid`); `name` names the mesh
/// (the file's stem). Cells of types 10 (tetrahedron), 24 (quadratic tetrahedron), 71 and 78
/// (Lagrange and Bézier tetrahedra: their first four points, the corners) are read; cells
/// of lower dimension are skipped; other solids are an error.
pub fn read_vtu(bytes: &[u8], name: &str) -> Result<PlainTetrahedra> {
    let xml = Xml::parse(bytes)?;
    let d = Decoder::new(bytes, &xml);
    let (np, nc) = xml
        .piece
        .ok_or_else(|| d.fail.file("the file has no Piece"))?;
    let get = |a: &Option<Array>, what: &str| {
        a.clone().ok_or_else(|| {
            d.fail.file(format!(
                "the Piece has no {what} DataArray: a VTU UnstructuredGrid has Points, and Cells with connectivity, offsets and types"
            ))
        })
    };
    let points = get(&xml.points, "Points")?;
    let connectivity = get(&xml.connectivity, "connectivity")?;
    let offsets = get(&xml.offsets, "offsets")?;
    let types = get(&xml.types, "types")?;
    let format = d.describe(&points);
    let d = Decoder {
        fail: Fail::new(format.clone()),
        ..d
    };

    if points.components != 3 {
        return Err(d.fail.byte(
            points.at,
            format!(
                "the Points DataArray has {} components; points have 3",
                points.components
            ),
        ));
    }
    let xyz = d.floats(&points, np.saturating_mul(3))?;
    let positions: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    drop(xyz);

    let mut ends = Vec::with_capacity(nc.min(bytes.len()));
    let mut last = 0u64;
    d.ints(&offsets, nc, |k, o, at| {
        if o < 0 || (o as u64) < last {
            return Err(d.fail.byte(
                at,
                format!(
                    "offsets: cell {k} ends at {o}, before the cell before it ({last}): offsets rise from the first cell to the last"
                ),
            ));
        }
        last = o as u64;
        ends.push(last);
        Ok(())
    })?;
    let size = usize::try_from(last).unwrap_or(usize::MAX);
    let mut ids: Vec<u32> = Vec::new();
    d.ints(&connectivity, size, |k, i, at| {
        if !(0..np as i64).contains(&i) {
            return Err(d.fail.byte(
                at,
                format!("connectivity: value {k} is {i}, but there are {np} points"),
            ));
        }
        if ids.capacity() == 0 {
            ids.reserve_exact(size);
        }
        ids.push(i as u32);
        Ok(())
    })?;
    let mut kinds = Vec::with_capacity(nc.min(bytes.len()));
    d.ints(&types, nc, |k, t, at| {
        let kind = u64::try_from(t).ok().and_then(vtk_kind).ok_or_else(|| {
            d.fail.byte(
                at,
                format!("types: cell {k} has type {t}, which VTK does not define"),
            )
        })?;
        kinds.push((t as u8, kind));
        Ok(())
    })?;

    let mut cells = Cells::with_capacity(nc);
    let mut start = 0usize;
    for (k, (&end, &(t, kind))) in ends.iter().zip(&kinds).enumerate() {
        let end = end as usize;
        let len = end - start;
        vtk_cell_size(kind, u64::from(t), len)
            .map_err(|m| d.fail.byte(offsets.at, format!("cell {k} {m}")))?;
        let nodes = &ids[start..end];
        match kind {
            Kind::Tet => cells.tet([nodes[0], nodes[1], nodes[2], nodes[3]]),
            Kind::Cell(solid, order) => cells.solid(solid, order, nodes, k as u64),
            Kind::Lower => cells.skipped += 1,
            Kind::Solid(name) => {
                cells.other(name, 1, super::MeshFileLocation::Byte(types.at));
            }
        }
        start = end;
    }
    plain(name, &format, positions, cells.finish(&d.fail)?)
}

/// A number type of VTK XML and its size.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Num {
    Int { size: usize, signed: bool },
    Float(usize),
}

impl Num {
    fn parse(name: &[u8]) -> Option<Num> {
        let int = |size, signed| Num::Int { size, signed };
        Some(match name {
            b"Int8" => int(1, true),
            b"UInt8" => int(1, false),
            b"Int16" => int(2, true),
            b"UInt16" => int(2, false),
            b"Int32" => int(4, true),
            b"UInt32" => int(4, false),
            b"Int64" => int(8, true),
            b"UInt64" => int(8, false),
            b"Float32" => Num::Float(4),
            b"Float64" => Num::Float(8),
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Num::Int { size, .. } | Num::Float(size) => size,
        }
    }
}

/// How a DataArray holds its values.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Binary,
    Appended(u64),
}

/// A DataArray as the XML declares it.
#[derive(Clone, Debug)]
struct Array {
    ty: Num,
    components: usize,
    format: Format,
    /// Its own text (inline data), as ranges of the file's bytes: the runs of text directly
    /// inside the element, in order, without what its children and comments hold.
    text: Vec<Range<usize>>,
    /// The byte where its tag begins.
    at: usize,
    /// The byte after its start tag, where its text begins.
    text_at: usize,
}

impl Array {
    /// How many bytes its own text has.
    fn text_len(&self) -> usize {
        self.text.iter().map(|r| r.len()).sum()
    }
}

/// How a file's binary arrays are compressed (the VTKFile's `compressor`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Compressor {
    #[default]
    None,
    Zlib,
    Lz4,
    Lzma,
}

impl Compressor {
    /// The name in [`PlainTetrahedra::format`] and errors.
    fn name(self) -> &'static str {
        match self {
            Compressor::None => "none",
            Compressor::Zlib => "zlib",
            Compressor::Lz4 => "lz4",
            Compressor::Lzma => "lzma",
        }
    }

    /// The kind of block, for errors.
    fn block(self) -> &'static str {
        match self {
            Compressor::Zlib | Compressor::None => "a valid zlib stream",
            Compressor::Lz4 => "a valid LZ4 block",
            Compressor::Lzma => "a valid .xz stream",
        }
    }

    /// How many times its blocks may give the bytes they hold, at most.
    fn max_ratio(self) -> u64 {
        match self {
            Compressor::None | Compressor::Zlib => ZLIB_MAX_RATIO,
            Compressor::Lz4 => LZ4_MAX_RATIO,
            Compressor::Lzma => XZ_MAX_RATIO,
        }
    }

    /// Decompresses a block into exactly `out.len()` bytes.
    fn decompress(self, data: &[u8], out: &mut [u8]) -> std::result::Result<(), String> {
        match self {
            Compressor::None | Compressor::Zlib => inflate(data, out),
            Compressor::Lz4 => unlz4(data, out),
            Compressor::Lzma => unxz(data, out),
        }
    }
}

/// What the XML says: the file's settings, the Piece's counts, the arrays.
#[derive(Default)]
struct Xml {
    little: bool,
    header64: bool,
    compressor: Compressor,
    piece: Option<(usize, usize)>,
    points: Option<Array>,
    connectivity: Option<Array>,
    offsets: Option<Array>,
    types: Option<Array>,
    /// The AppendedData: base64 (or raw), and where its data begin (after the `_`).
    appended: Option<(bool, usize)>,
}

/// Where DataArrays are.
#[derive(Clone, Copy, PartialEq)]
enum Section {
    None,
    Points,
    Cells,
}

impl Xml {
    fn parse(bytes: &[u8]) -> Result<Xml> {
        let fail = Fail::new("VTU");
        let mut x = Xml {
            little: true,
            ..Xml::default()
        };
        let mut seen_file = false;
        let mut closed = false;
        let mut section = Section::None;
        // quick-xml would take a byte-order mark for text before the root; positions stay
        // the file's.
        let skip = bom(bytes);
        let mut reader = Reader::from_reader(&bytes[skip..]);
        let pos = |r: &Reader<&[u8]>| r.buffer_position() as usize + skip;
        loop {
            let at = pos(&reader);
            let event = reader.read_event().map_err(|e| {
                fail.byte(
                    reader.error_position() as usize + skip,
                    format!("the XML is not well formed: {e}"),
                )
            })?;
            let (e, empty) = match event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(e) => {
                    match e.local_name().as_ref() {
                        b"Points" | b"Cells" => section = Section::None,
                        b"VTKFile" => closed = true,
                        _ => {}
                    }
                    continue;
                }
                Event::Eof if !closed => {
                    return Err(fail.byte(
                        bytes.len(),
                        "the file ends before </VTKFile>: it is truncated",
                    ));
                }
                Event::Eof => break,
                _ => continue,
            };
            let attr = |key: &str| attribute(&e, key, &fail, at);
            let name = e.local_name();
            if !seen_file && name.as_ref() != b"VTKFile" {
                return Err(fail.byte(
                    at,
                    format!(
                        "a VTU file's first element is VTKFile, this one's is `{}`",
                        shorten(&String::from_utf8_lossy(name.as_ref()))
                    ),
                ));
            }
            match name.as_ref() {
                b"VTKFile" => {
                    seen_file = true;
                    x.file_attributes(&attr, &fail, at)?;
                }
                b"Piece" => {
                    if x.piece.is_some() {
                        return Err(
                            fail.byte(at, "a second Piece: halo4d reads VTU files of one piece")
                        );
                    }
                    let count = |key: &str| -> Result<usize> {
                        let v = attr(key)?.unwrap_or_default();
                        // Every point or cell takes at least a byte of the file.
                        v.trim()
                            .parse::<usize>()
                            .ok()
                            .filter(|&n| n <= bytes.len())
                            .ok_or_else(|| {
                                fail.byte(
                                    at,
                                    format!(
                                        "{key} is `{}`: a count no larger than the file's {} bytes",
                                        shorten(&v),
                                        bytes.len()
                                    ),
                                )
                            })
                    };
                    x.piece = Some((count("NumberOfPoints")?, count("NumberOfCells")?));
                }
                b"Points" | b"Cells" if !empty => {
                    section = if name.as_ref() == b"Points" {
                        Section::Points
                    } else {
                        Section::Cells
                    };
                }
                b"PointData" | b"CellData" | b"FieldData" if !empty => {
                    reader.read_to_end(e.name()).map_err(|err| {
                        fail.byte(at, format!("the XML is not well formed: {err}"))
                    })?;
                }
                b"DataArray" => {
                    let array = data_array(&attr, &fail, at)?;
                    let text_at = pos(&reader);
                    let text = if empty {
                        Vec::new()
                    } else {
                        own_text(&mut reader, skip, bytes, &fail, at, array.format)?
                    };
                    let array = Array {
                        text,
                        text_at,
                        ..array
                    };
                    let slot = match section {
                        Section::Points => Some(&mut x.points),
                        Section::Cells => match attr("Name")?.as_deref() {
                            Some("connectivity") => Some(&mut x.connectivity),
                            Some("offsets") => Some(&mut x.offsets),
                            Some("types") => Some(&mut x.types),
                            _ => None,
                        },
                        Section::None => None,
                    };
                    if let Some(slot) = slot
                        && slot.is_none()
                    {
                        *slot = Some(array);
                    }
                }
                b"AppendedData" => {
                    x.appended = Some(appended(&attr, &fail, at, bytes, pos(&reader))?);
                    // Raw data follow: no more XML to read.
                    break;
                }
                _ => {}
            }
        }
        if !seen_file {
            return Err(fail.file("no VTKFile element: this is not a VTU file"));
        }
        Ok(x)
    }
}

impl Xml {
    /// The VTKFile element's attributes: an UnstructuredGrid, its byte order, header type
    /// and compressor.
    fn file_attributes(
        &mut self,
        attr: &dyn Fn(&str) -> Result<Option<String>>,
        fail: &Fail,
        at: usize,
    ) -> Result<()> {
        match attr("type")?.as_deref() {
            Some("UnstructuredGrid") => {}
            Some("PUnstructuredGrid") => {
                return Err(fail.byte(
                    at,
                    "a parallel PUnstructuredGrid (.pvtu) only names its pieces' files: read it by its path (halo4d check FILE.pvtu, import::read), which reads the pieces beside it",
                ));
            }
            other => {
                return Err(fail.byte(
                    at,
                    format!(
                        "the file's type is {}, not UnstructuredGrid: halo4d reads tetrahedral meshes",
                        shorten(other.unwrap_or("missing"))
                    ),
                ));
            }
        }
        self.little = match attr("byte_order")?.as_deref() {
            None | Some("LittleEndian") => true,
            Some("BigEndian") => false,
            Some(o) => {
                return Err(fail.byte(
                    at,
                    format!("byte_order `{}`: LittleEndian or BigEndian", shorten(o)),
                ));
            }
        };
        self.header64 = match attr("header_type")?.as_deref() {
            None | Some("UInt32") => false,
            Some("UInt64") => true,
            Some(h) => {
                return Err(fail.byte(
                    at,
                    format!("header_type `{}`: UInt32 or UInt64", shorten(h)),
                ));
            }
        };
        self.compressor = match attr("compressor")?.as_deref() {
            None | Some("") => Compressor::None,
            Some("vtkZLibDataCompressor") => Compressor::Zlib,
            Some("vtkLZ4DataCompressor") => Compressor::Lz4,
            Some("vtkLZMADataCompressor") => Compressor::Lzma,
            Some(c) => {
                return Err(fail.byte(
                    at,
                    format!(
                        "compressor `{}`: halo4d reads vtkZLibDataCompressor, vtkLZ4DataCompressor, vtkLZMADataCompressor or none; save the file with one of them",
                        shorten(c)
                    ),
                ));
            }
        };
        Ok(())
    }
}

/// The AppendedData element (its tag read up to `end`): whether its data are base64 (else
/// raw), and where they begin, after the `_` that must open them.
fn appended(
    attr: &dyn Fn(&str) -> Result<Option<String>>,
    fail: &Fail,
    at: usize,
    bytes: &[u8],
    end: usize,
) -> Result<(bool, usize)> {
    let base64 = match attr("encoding")?.as_deref() {
        Some("raw") => false,
        Some("base64") => true,
        other => {
            return Err(fail.byte(
                at,
                format!(
                    "AppendedData encoding `{}`: raw or base64",
                    shorten(other.unwrap_or("missing"))
                ),
            ));
        }
    };
    let rest = &bytes[end.min(bytes.len())..];
    let skip = rest
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(rest.len());
    if rest.get(skip) != Some(&b'_') {
        return Err(fail.byte(end + skip, "the AppendedData's data must begin with `_`"));
    }
    Ok((base64, end + skip + 1))
}

/// The own text of a DataArray whose start tag was just read, up to its end tag: the runs of
/// text (and CDATA, and entity references, which no number or base64 text has and which are
/// refused as such) directly inside it, as ranges of the file's bytes; what its children
/// and comments hold is not its text. A child between two values (VTK writes its
/// `InformationKey` after them) is read past; the text is read as XML gives it, the runs one
/// after the other. One glued to an ascii value on both sides is an error: `1.5<a/>7` is
/// `1.57` to XML and `1.5 7` to a reader of words, and no writer means either.
fn own_text(
    reader: &mut Reader<&[u8]>,
    skip: usize,
    bytes: &[u8],
    fail: &Fail,
    at: usize,
    format: Format,
) -> Result<Vec<Range<usize>>> {
    let mut runs: Vec<Range<usize>> = Vec::new();
    let mut depth = 0usize;
    // Where markup (a child or a comment) began, if any came since the last run of text.
    let mut cut: Option<usize> = None;
    loop {
        let from = reader.buffer_position() as usize + skip;
        let event = reader.read_event().map_err(|e| {
            fail.byte(
                reader.error_position() as usize + skip,
                format!("the XML is not well formed: {e}"),
            )
        })?;
        let to = reader.buffer_position() as usize + skip;
        let run = match event {
            Event::Text(_) | Event::GeneralRef(_) if depth == 0 => from..to,
            // `<![CDATA[` and `]]>` around it.
            Event::CData(_) if depth == 0 => (from + 9).min(to)..to.saturating_sub(3).max(from),
            Event::Start(_) => {
                depth += 1;
                cut = Some(from);
                continue;
            }
            Event::End(_) if depth == 0 => return Ok(runs),
            Event::End(_) => {
                depth -= 1;
                continue;
            }
            Event::Eof => {
                return Err(fail.byte(
                    at,
                    "the file ends inside this DataArray, before its </DataArray>: it is truncated",
                ));
            }
            _ => {
                if depth == 0 {
                    cut = Some(from);
                }
                continue;
            }
        };
        match (runs.last_mut(), cut.take()) {
            (Some(last), None) if last.end == run.start => last.end = run.end,
            (Some(last), Some(markup)) => {
                let glued = |b: Option<&u8>| b.is_some_and(|b| !b.is_ascii_whitespace());
                if format == Format::Ascii
                    && glued(bytes.get(last.end.wrapping_sub(1)))
                    && glued(bytes.get(run.start))
                {
                    return Err(fail.byte(
                        markup,
                        "a child element or comment cuts a value of this ascii DataArray in two: put whitespace between the values and any element inside a DataArray",
                    ));
                }
                runs.push(run);
            }
            _ => runs.push(run),
        }
    }
}

/// An attribute's value, if the element has it.
pub(super) fn attribute(
    e: &BytesStart,
    key: &str,
    fail: &Fail,
    at: usize,
) -> Result<Option<String>> {
    match e.try_get_attribute(key) {
        Ok(a) => Ok(a.map(|a| String::from_utf8_lossy(&a.value).into_owned())),
        Err(err) => Err(fail.byte(at, format!("a malformed attribute: {err}"))),
    }
}

/// A DataArray's declaration (its text range left empty).
fn data_array(
    attr: &dyn Fn(&str) -> Result<Option<String>>,
    fail: &Fail,
    at: usize,
) -> Result<Array> {
    let ty_name = attr("type")?.unwrap_or_default();
    let ty = Num::parse(ty_name.as_bytes()).ok_or_else(|| {
        fail.byte(
            at,
            format!(
                "DataArray type `{}`: one of Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64",
                shorten(&ty_name)
            ),
        )
    })?;
    let components = match attr("NumberOfComponents")? {
        None => 1,
        Some(c) => c
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|c| (1..=1000).contains(c))
            .ok_or_else(|| fail.byte(at, format!("NumberOfComponents is `{}`", shorten(&c))))?,
    };
    let format = match attr("format")?.as_deref() {
        Some("ascii") => Format::Ascii,
        Some("binary") => Format::Binary,
        Some("appended") => {
            let offset = attr("offset")?.unwrap_or_default();
            Format::Appended(offset.trim().parse().map_err(|_| {
                fail.byte(
                    at,
                    format!(
                        "an appended DataArray's offset is `{}`, not a whole number",
                        shorten(&offset)
                    ),
                )
            })?)
        }
        other => {
            return Err(fail.byte(
                at,
                format!(
                    "DataArray format `{}`: ascii, binary or appended",
                    shorten(other.unwrap_or("missing"))
                ),
            ));
        }
    };
    Ok(Array {
        ty,
        components,
        format,
        text: Vec::new(),
        at,
        text_at: at,
    })
}

/// Where an array's binary data come from: bytes (raw, or base64 decoded whole), or base64
/// text decoded as far as needed (appended data, which run on past the array).
enum Source<'a> {
    Bytes(Cow<'a, [u8]>, usize),
    Base64(&'a [u8], usize),
}

/// Reads the values of DataArrays.
struct Decoder<'a> {
    bytes: &'a [u8],
    fail: Fail,
    little: bool,
    header: usize,
    compressor: Compressor,
    appended: Option<(bool, usize)>,
}

impl<'a> Decoder<'a> {
    fn new(bytes: &'a [u8], x: &Xml) -> Self {
        Decoder {
            bytes,
            fail: Fail::new("VTU"),
            little: x.little,
            header: if x.header64 { 8 } else { 4 },
            compressor: x.compressor,
            appended: x.appended,
        }
    }

    /// `VTU appended raw zlib`, `VTU binary big-endian`, ...: the format of the points.
    fn describe(&self, a: &Array) -> String {
        let mut s = String::from("VTU");
        match a.format {
            Format::Ascii => s += " ascii",
            Format::Binary => s += " binary",
            Format::Appended(_) => {
                s += " appended";
                s += match self.appended {
                    Some((true, _)) => " base64",
                    _ => " raw",
                }
            }
        }
        if a.format != Format::Ascii {
            if self.compressor != Compressor::None {
                s += " ";
                s += self.compressor.name();
            }
            if self.header == 8 {
                s += " UInt64 headers";
            }
            if !self.little {
                s += " big-endian";
            }
        }
        s
    }

    /// `count` floating-point values of `a`.
    fn floats(&self, a: &Array, count: usize) -> Result<Vec<f64>> {
        if a.format == Format::Ascii {
            let mut out = Vec::with_capacity(self.ascii_count(a, count)?);
            self.ascii(a, count, |k, w, at| {
                let x = parse_f64(w).ok_or_else(|| {
                    self.fail.byte(
                        at,
                        format!(
                            "value {k} is `{}`, not a number",
                            shorten(&String::from_utf8_lossy(w))
                        ),
                    )
                })?;
                self.finite(k, x, at)?;
                out.push(x);
                Ok(())
            })?;
            return Ok(out);
        }
        let (raw, at) = self.binary(a, count)?;
        let size = a.ty.size();
        let out: Vec<f64> = match a.ty {
            Num::Float(4) => raw
                .chunks_exact(4)
                .map(|b| {
                    let b: [u8; 4] = b.try_into().expect("4 bytes");
                    f64::from(if self.little {
                        f32::from_le_bytes(b)
                    } else {
                        f32::from_be_bytes(b)
                    })
                })
                .collect(),
            Num::Float(_) => raw
                .chunks_exact(8)
                .map(|b| super::tetfile::f64_at(b, self.little))
                .collect(),
            Num::Int { signed, .. } => raw
                .chunks_exact(size)
                .map(|b| int_at(b, self.little, signed) as f64)
                .collect(),
        };
        if let Some(k) = out.iter().position(|x| !x.is_finite()) {
            self.finite(k, out[k], at)?;
        }
        Ok(out)
    }

    /// A point's coordinate must be finite.
    fn finite(&self, k: usize, x: f64, at: usize) -> Result<()> {
        if x.is_finite() {
            return Ok(());
        }
        Err(self
            .fail
            .byte(at, super::tetfile::non_finite(k / 3, k % 3, x)))
    }

    /// `count` integers of `a`, each given to `sink` with its index and a byte to name.
    fn ints(
        &self,
        a: &Array,
        count: usize,
        mut sink: impl FnMut(usize, i64, usize) -> Result<()>,
    ) -> Result<()> {
        if a.format == Format::Ascii {
            self.ascii_count(a, count)?;
            return self.ascii(a, count, |k, w, at| {
                let i = parse_i64(w).ok_or_else(|| {
                    self.fail.byte(
                        at,
                        format!(
                            "value {k} is `{}`, not a whole number",
                            shorten(&String::from_utf8_lossy(w))
                        ),
                    )
                })?;
                sink(k, i, at)
            });
        }
        let Num::Int { size, signed } = a.ty else {
            return Err(self.fail.byte(
                a.at,
                "connectivity, offsets and types must be arrays of integers, this one is of floats",
            ));
        };
        let (raw, at) = self.binary(a, count)?;
        for (k, b) in raw.chunks_exact(size).enumerate() {
            sink(k, int_at(b, self.little, signed), at)?;
        }
        Ok(())
    }

    /// `count` values in text take at least `2 count - 1` bytes.
    fn ascii_count(&self, a: &Array, count: usize) -> Result<usize> {
        let len = a.text_len();
        if count > len.div_ceil(2) {
            return Err(self.fail.byte(
                a.text_at,
                format!(
                    "the DataArray must hold {count} values, but its text has only {len} bytes"
                ),
            ));
        }
        Ok(count)
    }

    /// The words of an ascii array's own text, exactly `count` of them.
    fn ascii(
        &self,
        a: &Array,
        count: usize,
        mut each: impl FnMut(usize, &[u8], usize) -> Result<()>,
    ) -> Result<()> {
        let mut k = 0;
        for run in &a.text {
            let text = &self.bytes[run.clone()];
            let mut i = 0;
            while i < text.len() {
                if text[i].is_ascii_whitespace() {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < text.len() && !text[i].is_ascii_whitespace() {
                    i += 1;
                }
                if k == count {
                    return Err(self.fail.byte(
                        run.start + start,
                        format!("the DataArray holds more than the {count} values it should"),
                    ));
                }
                each(k, &text[start..i], run.start + start)?;
                k += 1;
            }
        }
        if k != count {
            let end = a.text.last().map_or(a.text_at, |r| r.end);
            return Err(self
                .fail
                .byte(end, format!("the DataArray holds {k} values, not {count}")));
        }
        Ok(())
    }

    /// The data of a binary or appended array of `count` values, uncompressed, in the
    /// file's byte order; and the byte where they are.
    fn binary(&self, a: &Array, count: usize) -> Result<(Cow<'a, [u8]>, usize)> {
        let want = count
            .checked_mul(a.ty.size())
            .filter(|&w| w <= isize::MAX as usize)
            .ok_or_else(|| self.fail.byte(a.at, format!("{count} values: too many")))?;
        let source = self.source(a)?;
        let at = match &source {
            Source::Bytes(_, at) | Source::Base64(_, at) => *at,
        };
        let hs = self.header;
        if self.compressor == Compressor::None {
            return self.uncompressed(source, a, count, want, at);
        }
        // Compressed: blocks, block size, last block's size, each block's compressed size.
        let head = self.get(&source, 3 * hs)?;
        let [blocks, block, last] =
            [0, 1, 2].map(|i| uint(&head[i * hs..(i + 1) * hs], self.little));
        let header_len = usize::try_from(blocks)
            .ok()
            .and_then(|b| b.checked_add(3))
            .and_then(|b| b.checked_mul(hs))
            .ok_or_else(|| {
                self.fail
                    .byte(at, format!("{blocks} compressed blocks: too many"))
            })?;
        self.check_left(&source, header_len, at)?;
        let head = self.get(&source, header_len)?;
        let sizes: Vec<u64> = head[3 * hs..]
            .chunks_exact(hs)
            .map(|b| uint(b, self.little))
            .collect();
        let compressed: u64 = sizes.iter().fold(0u64, |s, &c| s.saturating_add(c));
        let total = if blocks == 0 {
            0
        } else {
            let last = if last == 0 { block } else { last };
            (blocks - 1)
                .checked_mul(block)
                .and_then(|t| t.checked_add(last))
                .unwrap_or(u64::MAX)
        };
        if total != want as u64 || (blocks > 0 && last > block) {
            return Err(self.fail.byte(
                at,
                format!(
                    "the compressed array's header says {blocks} blocks of {block} bytes, the last of {last}: {total} bytes, but {count} values of {} bytes make {want}",
                    a.ty.size()
                ),
            ));
        }
        let c = self.compressor;
        let most = c
            .max_ratio()
            .saturating_mul(compressed)
            .saturating_add(BLOCK_SLACK.saturating_mul(blocks));
        if total > most {
            return Err(self.fail.byte(
                at,
                format!(
                    "the compressed array's header claims {total} bytes from {compressed} compressed ones, more than {} can give ({} times as many, at most): the header is wrong",
                    c.name(),
                    c.max_ratio()
                ),
            ));
        }
        let end = usize::try_from(compressed)
            .ok()
            .and_then(|c| c.checked_add(header_len))
            .unwrap_or(usize::MAX);
        self.check_left(&source, end, at)?;
        let data = self.get(&source, end)?;
        let mut out = vec![0u8; want];
        let mut ranges = Vec::with_capacity(sizes.len());
        let mut from = header_len;
        for &c in &sizes {
            ranges.push(from..from + c as usize);
            from += c as usize;
        }
        let data_at = |r: &Range<usize>| match &source {
            Source::Bytes(..) => at + r.start,
            // A byte of the decoded data lies about 4/3 as far into the base64 text.
            Source::Base64(..) => at + r.start / 3 * 4,
        };
        out.par_chunks_mut(block.max(1) as usize)
            .zip(ranges.par_iter())
            .enumerate()
            .try_for_each(|(k, (o, r))| {
                c.decompress(&data[r.clone()], o).map_err(|why| {
                    self.fail.byte(
                        data_at(r),
                        format!(
                            "block {k} of the compressed array is not {}: {why}",
                            c.block()
                        ),
                    )
                })
            })?;
        Ok((Cow::Owned(out), at))
    }

    /// Where the data of a binary or appended array are: its own base64 text decoded, or
    /// the AppendedData's bytes from its offset (base64 or raw), with the byte where they
    /// are.
    fn source(&self, a: &Array) -> Result<Source<'a>> {
        Ok(match a.format {
            Format::Binary => Source::Bytes(Cow::Owned(self.base64_all(a)?), a.text_at),
            Format::Appended(offset) => {
                let Some((base64, start)) = self.appended else {
                    return Err(self.fail.byte(
                        a.at,
                        "the DataArray is appended, but the file has no AppendedData",
                    ));
                };
                let at = usize::try_from(offset)
                    .ok()
                    .and_then(|o| o.checked_add(start))
                    .filter(|&at| at < self.bytes.len())
                    .ok_or_else(|| {
                        self.fail.byte(
                            a.at,
                            format!(
                                "the DataArray's offset {offset} lies past the end of the file"
                            ),
                        )
                    })?;
                let rest = &self.bytes[at..];
                if base64 {
                    let run = rest
                        .iter()
                        .position(|&b| !(b.is_ascii_alphanumeric() || b"+/=".contains(&b)))
                        .unwrap_or(rest.len());
                    Source::Base64(&rest[..run], at)
                } else {
                    Source::Bytes(Cow::Borrowed(rest), at)
                }
            }
            Format::Ascii => unreachable!("ascii arrays are read as text"),
        })
    }

    /// An uncompressed array of `count` values (`want` bytes) after its header, from
    /// `source` at byte `at`.
    fn uncompressed(
        &self,
        source: Source<'a>,
        a: &Array,
        count: usize,
        want: usize,
        at: usize,
    ) -> Result<(Cow<'a, [u8]>, usize)> {
        let hs = self.header;
        let head = self.get(&source, hs)?;
        let n = uint(&head[..hs], self.little);
        if n != want as u64 {
            return Err(self.fail.byte(
                at,
                format!(
                    "the array's header says {n} bytes, but {count} values of {} bytes make {want}",
                    a.ty.size()
                ),
            ));
        }
        self.check_left(&source, hs + want, at)?;
        let data = match source {
            Source::Bytes(Cow::Borrowed(b), _) => Cow::Borrowed(&b[hs..hs + want]),
            Source::Bytes(Cow::Owned(mut v), _) => {
                v.truncate(hs + want);
                v.drain(..hs);
                Cow::Owned(v)
            }
            Source::Base64(..) => {
                let mut v = self.get(&source, hs + want)?.into_owned();
                v.drain(..hs);
                Cow::Owned(v)
            }
        };
        Ok((data, at))
    }

    /// The first `n` bytes of a source (all of them where it has fewer).
    fn get<'s>(&self, source: &'s Source<'a>, n: usize) -> Result<Cow<'s, [u8]>> {
        match source {
            Source::Bytes(b, at) => {
                if b.len() < n {
                    return Err(self.truncated(*at, n, b.len()));
                }
                Ok(Cow::Borrowed(&b[..n]))
            }
            Source::Base64(text, at) => {
                let out = self.base64_prefix(text, *at, n)?;
                if out.len() < n {
                    return Err(self.truncated(*at, n, out.len()));
                }
                Ok(Cow::Owned(out))
            }
        }
    }

    /// Whether a source holds at least `n` bytes, before decoding them.
    fn check_left(&self, source: &Source, n: usize, at: usize) -> Result<()> {
        let have = match source {
            Source::Bytes(b, _) => b.len(),
            Source::Base64(text, _) => text.len() / 4 * 3 + 2,
        };
        if n > have {
            return Err(self.truncated(at, n, have));
        }
        Ok(())
    }

    fn truncated(&self, at: usize, n: usize, have: usize) -> super::ImportError {
        self.fail.byte(
            at,
            format!(
                "the array's data need {n} bytes, but only {have} are there: the file is truncated, or a header or count is wrong"
            ),
        )
    }

    /// An inline array's own base64 text (whitespace allowed, and runs cut by child
    /// elements, one after the other), decoded.
    fn base64_all(&self, a: &Array) -> Result<Vec<u8>> {
        let bytes = self.bytes;
        let chars = || {
            a.text
                .iter()
                .flat_map(|r| r.clone())
                .filter(|&i| !bytes[i].is_ascii_whitespace())
        };
        if let [run] = &a.text[..]
            && !bytes[run.clone()].iter().any(u8::is_ascii_whitespace)
        {
            return self.base64_prefix(&bytes[run.clone()], run.start, usize::MAX);
        }
        let clean: Vec<u8> = chars().map(|i| bytes[i]).collect();
        self.base64_prefix(&clean, 0, usize::MAX).map_err(|e| {
            // Name the byte of the file, not of the text without its whitespace.
            match e {
                super::ImportError::Tetrahedra {
                    format,
                    at: super::MeshFileLocation::Byte(nth),
                    message,
                } => super::ImportError::Tetrahedra {
                    format,
                    at: super::MeshFileLocation::Byte(
                        chars()
                            .nth(nth)
                            .unwrap_or_else(|| a.text.last().map_or(a.text_at, |r| r.end)),
                    ),
                    message,
                },
                e => e,
            }
        })
    }

    /// Decodes base64 `text` (no whitespace) until at least `want` bytes, or all of it. A
    /// text may be several base64 texts one after the other, each ending with its padding
    /// (VTK encodes a header and its data apart).
    fn base64_prefix(&self, text: &[u8], at: usize, want: usize) -> Result<Vec<u8>> {
        let mut out = Vec::with_capacity(want.min(text.len() / 4 * 3 + 3));
        let mut pos = 0;
        while pos < text.len() && out.len() < want {
            let rest = &text[pos..];
            let end = match rest.iter().position(|&b| b == b'=') {
                Some(i) => i + rest[i..].iter().take_while(|&&b| b == b'=').count(),
                None => rest.len(),
            };
            let need = want - out.len();
            let chars = need.div_ceil(3).checked_mul(4).map_or(end, |c| c.min(end));
            BASE64.decode_vec(&rest[..chars], &mut out).map_err(|e| {
                let (offset, why) = match e {
                    base64::DecodeError::InvalidByte(i, b) => (
                        i,
                        format!("`{}` is not a base64 character", b.escape_ascii()),
                    ),
                    base64::DecodeError::InvalidLastSymbol(i, b) => (
                        i,
                        format!("`{}` cannot end a base64 text", b.escape_ascii()),
                    ),
                    base64::DecodeError::InvalidLength(n) => {
                        (0, format!("a base64 text of {n} characters is cut short"))
                    }
                    base64::DecodeError::InvalidPadding => {
                        (0, "the base64 text's padding is wrong".to_string())
                    }
                };
                self.fail
                    .byte(at + pos + offset, format!("bad base64 data: {why}"))
            })?;
            pos += chars;
        }
        Ok(out)
    }
}

/// A signed or unsigned integer of 1, 2, 4 or 8 bytes; a UInt64 past i64's range becomes -1,
/// which no count or index is.
fn int_at(b: &[u8], little: bool, signed: bool) -> i64 {
    let u = uint(b, little);
    let bits = 8 * b.len() as u32;
    if signed && bits < 64 {
        // Sign-extend.
        ((u << (64 - bits)) as i64) >> (64 - bits)
    } else {
        i64::try_from(u).unwrap_or(if signed { u as i64 } else { -1 })
    }
}

/// Decompresses a raw LZ4 block (no frame, as `LZ4_compress_default` gives it) into exactly
/// `out.len()` bytes.
fn unlz4(data: &[u8], out: &mut [u8]) -> std::result::Result<(), String> {
    match lz4_flex::block::decompress_into(data, out) {
        Ok(n) if n == out.len() => Ok(()),
        Ok(n) => Err(format!("it gives {n} bytes, the header says {}", out.len())),
        Err(lz4_flex::block::DecompressError::OutputTooSmall { .. }) => Err(format!(
            "it gives more than the {} bytes the header says",
            out.len()
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// Decompresses an `.xz` stream (as `lzma_easy_buffer_encode` gives it) into exactly
/// `out.len()` bytes, and checks its end (index, footer, checksum). The stream is decoded
/// as it is read: nothing past `out.len() + 1` bytes is decoded, whatever it would give.
fn unxz(data: &[u8], out: &mut [u8]) -> std::result::Result<(), String> {
    let mut xz = lzma_rust2::XzReader::new(data, false);
    let mut filled = 0;
    while filled < out.len() {
        match xz.read(&mut out[filled..]) {
            Ok(0) => {
                return Err(format!(
                    "it gives {filled} bytes, the header says {}",
                    out.len()
                ));
            }
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e.to_string()),
        }
    }
    let mut more = [0u8; 1];
    match xz.read(&mut more) {
        Ok(0) => Ok(()),
        Ok(_) => Err(format!(
            "it gives more than the {} bytes the header says",
            out.len()
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// Inflates a zlib stream into exactly `out.len()` bytes.
fn inflate(data: &[u8], out: &mut [u8]) -> std::result::Result<(), String> {
    let mut z = flate2::Decompress::new(true);
    match z.decompress(data, out, flate2::FlushDecompress::Finish) {
        Ok(flate2::Status::StreamEnd) if z.total_out() as usize == out.len() => Ok(()),
        Ok(flate2::Status::StreamEnd) => Err(format!(
            "it gives {} bytes, the header says {}",
            z.total_out(),
            out.len()
        )),
        Ok(_) => Err(format!(
            "it ends early or gives more than the {} bytes the header says",
            out.len()
        )),
        Err(e) => Err(e.to_string()),
    }
}
