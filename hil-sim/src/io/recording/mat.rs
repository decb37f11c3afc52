//! MATLAB level-5 MAT-files (what `save -v7` / `-v6` and SciPy's `savemat` write),
//! read without MATLAB: one numeric variable per channel.
//!
//! Written here rather than taken from a crate: `matfile` 0.5 prints to stdout on
//! unsupported variables, mis-types `int32` arrays and overflows on some length fields,
//! and `mat5` 0.1 panics (debug) on corrupt small-element tags. This reader uses only
//! checked slicing and arithmetic, and `flate2` (maintained by the rust-lang project)
//! for the zlib-compressed elements. Every problem becomes a [`RecordingError`].

use std::io::Read;
use std::path::Path;

use super::RecordingError;

/// What reading a MAT-file may hold in memory beyond the file itself (bytes): 24 MiB and
/// four times the file's size, for the values read as f64 and the compressed element being
/// inflated at the time. With the file itself and what a fit needs besides, a command stays
/// within four times the file's size plus 64 MiB (hil-sim/tests/hostile_generated.rs).
fn memory_budget(file_len: usize) -> u64 {
    (24 << 20) + 4 * file_len as u64
}

const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;

/// Why the byte stream is not a level-5 MAT-file we can read (before variables are judged).
enum Fault {
    /// An element at this byte offset runs past the end of its container.
    Truncated(usize),
    /// Anything else, in words.
    Format(String),
}

type R<T> = Result<T, Fault>;

#[derive(Clone, Copy)]
struct Endian {
    little: bool,
}

impl Endian {
    fn u16(self, b: [u8; 2]) -> u16 {
        if self.little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        }
    }
    fn u32(self, b: [u8; 4]) -> u32 {
        if self.little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        }
    }
    fn u64(self, b: [u8; 8]) -> u64 {
        if self.little {
            u64::from_le_bytes(b)
        } else {
            u64::from_be_bytes(b)
        }
    }
}

/// A cursor over one container (the file body, an inflated element, or a matrix).
struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
    /// Offset of `buf[0]` in the file, for messages (inflated data: the compressed element's).
    base: usize,
    e: Endian,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> R<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&end| end <= self.buf.len());
        match end.and_then(|end| self.buf.get(self.pos..end)) {
            Some(s) => {
                self.pos += n;
                Ok(s)
            }
            None => Err(Fault::Truncated(self.base + self.pos)),
        }
    }
    fn u32(&mut self) -> R<u32> {
        let b = self.take(4)?;
        Ok(self.e.u32([b[0], b[1], b[2], b[3]]))
    }
    fn at_end(&self) -> bool {
        self.pos >= self.buf.len()
    }

    /// One tagged data element: (type, payload, file offset of the tag). Consumes the
    /// padding to the next 8-byte boundary, except after compressed elements (which
    /// MATLAB and SciPy do not pad) and at the very end of the container.
    fn element(&mut self) -> R<(u32, &'a [u8], usize)> {
        let at = self.base + self.pos;
        let first = self.u32()?;
        let small = first >> 16;
        if small != 0 {
            if small > 4 {
                return Err(Fault::Format(format!("element at byte {at}: small-element size {small} > 4")));
            }
            let b = self.take(4)?;
            return Ok((first & 0xFFFF, b.get(..small as usize).unwrap_or(&[]), at));
        }
        let n = self.u32()? as usize;
        let data = self.take(n)?;
        if first != MI_COMPRESSED {
            let pad = (8 - n % 8) % 8;
            self.pos = self.pos.saturating_add(pad).min(self.buf.len());
        }
        Ok((first, data, at))
    }
}

/// A variable as stored.
pub(super) struct Variable {
    pub name: String,
    pub dims: Vec<u64>,
    pub kind: Kind,
}

pub(super) enum Kind {
    Numeric(Vec<f64>),
    /// A char array, as text.
    Text(String),
    /// A struct (array): field names, then one row of field values per element.
    Struct {
        fields: Vec<String>,
        elements: Vec<Vec<Variable>>,
    },
    Complex,
    Other(&'static str),
}

/// Nesting deeper than this (structs in structs) is refused: no recording needs it.
const MAX_DEPTH: u32 = 8;

fn class_name(class: u8) -> &'static str {
    match class {
        1 => "a cell array",
        2 => "a struct",
        3 => "an object",
        4 => "a char array",
        5 => "a sparse matrix",
        16 => "a function handle",
        17 => "an opaque object",
        _ => "of an unknown class",
    }
}

fn type_name(t: u32) -> String {
    match t {
        MI_INT8 => "int8".into(),
        MI_UINT8 => "uint8".into(),
        MI_INT16 => "int16".into(),
        MI_UINT16 => "uint16".into(),
        MI_INT32 => "int32".into(),
        MI_UINT32 => "uint32".into(),
        MI_SINGLE => "single".into(),
        MI_DOUBLE => "double".into(),
        MI_INT64 => "int64".into(),
        MI_UINT64 => "uint64".into(),
        MI_MATRIX => "matrix".into(),
        MI_COMPRESSED => "compressed".into(),
        other => format!("type {other}"),
    }
}

/// Numbers of any numeric storage type, widened to f64.
fn numbers(t: u32, data: &[u8], e: Endian, at: usize) -> R<Vec<f64>> {
    fn each<const N: usize>(data: &[u8], at: usize, f: impl Fn([u8; N]) -> f64) -> R<Vec<f64>> {
        if !data.len().is_multiple_of(N) {
            return Err(Fault::Format(format!(
                "element at byte {at}: {} bytes is not a whole number of values",
                data.len()
            )));
        }
        Ok(data
            .chunks_exact(N)
            .map(|c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                f(a)
            })
            .collect())
    }
    match t {
        MI_INT8 => Ok(data.iter().map(|&b| f64::from(b as i8)).collect()),
        MI_UINT8 | MI_UTF8 => Ok(data.iter().map(|&b| f64::from(b)).collect()),
        MI_INT16 => each::<2>(data, at, |a| f64::from(e.u16(a) as i16)),
        MI_UINT16 => each::<2>(data, at, |a| f64::from(e.u16(a))),
        MI_INT32 => each::<4>(data, at, |a| f64::from(e.u32(a) as i32)),
        MI_UINT32 => each::<4>(data, at, |a| f64::from(e.u32(a))),
        MI_SINGLE => each::<4>(data, at, |a| f64::from(f32::from_bits(e.u32(a)))),
        MI_DOUBLE => each::<8>(data, at, |a| f64::from_bits(e.u64(a))),
        MI_INT64 => each::<8>(data, at, |a| e.u64(a) as i64 as f64),
        MI_UINT64 => each::<8>(data, at, |a| e.u64(a) as f64),
        other => Err(Fault::Format(format!("element at byte {at}: {} where numbers were expected", type_name(other)))),
    }
}

/// The payload of an miMATRIX element.
/// `left`: the memory budget left; the values' declared size (as f64) is charged to it
/// before they are read.
fn matrix(data: &[u8], base: usize, e: Endian, left: &mut u64, depth: u32) -> R<Variable> {
    let mut c = Cursor { buf: data, pos: 0, base, e };
    let (t, flags, at) = c.element()?;
    if t != MI_UINT32 || flags.len() != 8 {
        return Err(Fault::Format(format!("array at byte {base}: bad array-flags subelement at byte {at}")));
    }
    let word = e.u32([flags[0], flags[1], flags[2], flags[3]]);
    let class = (word & 0xFF) as u8;
    let complex = word & 0x0800 != 0;
    let (t, dims, at) = c.element()?;
    if t != MI_INT32 || dims.len() < 8 {
        return Err(Fault::Format(format!("array at byte {base}: bad dimensions subelement at byte {at}")));
    }
    let dims: Vec<u64> = numbers(MI_INT32, dims, e, at)?
        .into_iter()
        .map(|d| {
            if d < 0.0 {
                Err(Fault::Format(format!("array at byte {base}: negative dimension {d}")))
            } else {
                Ok(d as u64)
            }
        })
        .collect::<R<_>>()?;
    let (t, name, at) = c.element()?;
    if t != MI_INT8 && t != MI_UINT8 && t != MI_UTF8 {
        return Err(Fault::Format(format!("array at byte {base}: bad name subelement at byte {at}")));
    }
    let name: String =
        String::from_utf8_lossy(name).trim_end_matches('\0').chars().flat_map(char::escape_default).collect();
    let kind = match class {
        6..=15 if complex => Kind::Complex,
        6..=15 => {
            charge(&name, &dims, left, base)?;
            if dims.contains(&0) && c.at_end() {
                Kind::Numeric(Vec::new())
            } else {
                let (t, re, at) = c.element()?;
                Kind::Numeric(numbers(t, re, e, at)?)
            }
        }
        4 => {
            charge(&name, &dims, left, base)?;
            let text = if c.at_end() {
                String::new()
            } else {
                let (t, re, at) = c.element()?;
                numbers(t, re, e, at)?.into_iter().filter_map(|v| char::from_u32(v as u32)).collect()
            };
            Kind::Text(text.trim_end_matches(['\0', ' ']).to_owned())
        }
        2 if depth < MAX_DEPTH => structure(&mut c, &dims, base, e, left, depth)?,
        other => Kind::Other(class_name(other)),
    };
    Ok(Variable { name, dims, kind })
}

/// The rest of a struct array's payload: field names, then each element's fields as
/// (unnamed) nested arrays.
fn structure(c: &mut Cursor<'_>, dims: &[u64], base: usize, e: Endian, left: &mut u64, depth: u32) -> R<Kind> {
    let (t, len, at) = c.element()?;
    let width = numbers(t, len, e, at)?.first().copied().unwrap_or(0.0) as usize;
    if width == 0 || width > 64 {
        return Err(Fault::Format(format!("struct at byte {base}: field-name length {width} at byte {at}")));
    }
    let (_, names, _) = c.element()?;
    let fields: Vec<String> = names
        .chunks(width)
        .map(|n| String::from_utf8_lossy(n).trim_end_matches('\0').chars().flat_map(char::escape_default).collect())
        .collect();
    let count = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d)).unwrap_or(u64::MAX);
    let cells = count.saturating_mul(fields.len() as u64);
    // Each nested array costs at least its 8-byte tag: a count the payload cannot hold is corrupt.
    if cells.saturating_mul(8) > (c.buf.len() - c.pos.min(c.buf.len())) as u64 {
        return Err(Fault::Format(format!("struct at byte {base}: {cells} fields do not fit in its data")));
    }
    // A struct without fields (MATLAB's `struct()`) holds no data whatever its size: its
    // elements are all empty, and none is kept (the count is the file's word, not a length).
    let count = if fields.is_empty() { 0 } else { count };
    let mut elements = Vec::with_capacity(count as usize);
    for _ in 0..count {
        let mut row = Vec::with_capacity(fields.len());
        for f in &fields {
            let (t, data, at) = c.element()?;
            if t != MI_MATRIX {
                return Err(Fault::Format(format!("struct field `{f}` at byte {at} is {}", type_name(t))));
            }
            let mut v = if data.is_empty() {
                Variable { name: String::new(), dims: vec![0, 0], kind: Kind::Numeric(Vec::new()) }
            } else {
                matrix(data, at + 8, e, left, depth + 1)?
            };
            v.name.clone_from(f);
            row.push(v);
        }
        elements.push(row);
    }
    Ok(Kind::Struct { fields, elements })
}

/// Inflate the array a compressed element holds: its tag (the first 8 bytes) declares the
/// array's size, which is checked against `budget` before the rest is inflated, and no more
/// than the declared size is ever inflated.
fn inflate(data: &[u8], at: usize, e: Endian, budget: u64) -> R<Vec<u8>> {
    let broken =
        |err: std::io::Error| Fault::Format(format!("compressed element at byte {at} does not inflate: {err}"));
    let mut z = flate2::read::ZlibDecoder::new(data);
    let mut tag = [0u8; 8];
    z.read_exact(&mut tag).map_err(broken)?;
    let t = e.u32([tag[0], tag[1], tag[2], tag[3]]);
    if t != MI_MATRIX {
        return Err(Fault::Format(format!("compressed element at byte {at} holds {}, not a matrix", type_name(t))));
    }
    let declared = u64::from(e.u32([tag[4], tag[5], tag[6], tag[7]]));
    if declared > budget {
        return Err(Fault::Format(format!(
            "compressed element at byte {at} declares an array of {declared} bytes, more than the {budget} bytes \
             left for this file (24 MiB + 4 × its size, less what its other arrays hold)"
        )));
    }
    let mut out = tag.to_vec();
    out.reserve(declared as usize);
    z.take(declared).read_to_end(&mut out).map_err(broken)?;
    Ok(out)
}

/// Charge an array's values (as f64) to the reading budget.
fn charge(name: &str, dims: &[u64], left: &mut u64, at: usize) -> R<()> {
    let count = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    let bytes = count.and_then(|c| c.checked_mul(8));
    match bytes {
        Some(b) if b <= *left => {
            *left -= b;
            Ok(())
        }
        _ => Err(Fault::Format(format!(
            "array `{}` at byte {at} declares {} values, more than this file may hold in memory \
             (24 MiB + 4 × its size)",
            name,
            shape(dims)
        ))),
    }
}

/// Every variable in the file, in file order.
fn variables(bytes: &[u8]) -> R<Vec<Variable>> {
    let header = bytes
        .get(..128)
        .ok_or_else(|| Fault::Format(format!("{} bytes, shorter than the 128-byte MAT-file header", bytes.len())))?;
    if header.starts_with(b"MATLAB 7.3") {
        return Err(Fault::Format("a version 7.3 (HDF5) MAT-file; save it with `save -v7`".into()));
    }
    if !header.starts_with(b"MATLAB 5.0 MAT-file") {
        return Err(Fault::Format("no `MATLAB 5.0 MAT-file` header: not a level-5 MAT-file".into()));
    }
    let e = match &header[126..128] {
        b"IM" => Endian { little: true },
        b"MI" => Endian { little: false },
        _ => return Err(Fault::Format("header has no endian indicator (`IM`/`MI`)".into())),
    };
    let version = e.u16([header[124], header[125]]);
    if version != 0x0100 {
        return Err(Fault::Format(format!("header version {version:#06x}, expected 0x0100")));
    }
    let mut left = memory_budget(bytes.len());
    let mut out = Vec::new();
    let mut body = Cursor { buf: &bytes[128..], pos: 0, base: 128, e };
    while !body.at_end() {
        let (t, data, at) = body.element()?;
        match t {
            MI_MATRIX => {
                out.push(matrix(data, at + 8, e, &mut left, 0)?);
            }
            MI_COMPRESSED => {
                // The inflated bytes are charged while they live, then given back.
                let inner = inflate(data, at, e, left)?;
                let held = inner.len() as u64;
                left -= held.min(left);
                let mut c = Cursor { buf: &inner, pos: 0, base: at + 8, e };
                let (_, data, _) = c.element()?;
                out.push(matrix(data, at + 8, e, &mut left, 0)?);
                drop(inner);
                left += held;
            }
            other => {
                return Err(Fault::Format(format!(
                    "top-level element at byte {at} is {}, not a matrix",
                    type_name(other)
                )))
            }
        }
    }
    Ok(out)
}

pub(super) fn shape(dims: &[u64]) -> String {
    dims.iter().map(u64::to_string).collect::<Vec<_>>().join("×")
}

/// The variables of level-5 MAT bytes, in file order; `path` is used in messages only.
pub(super) fn read(path: &Path, bytes: &[u8]) -> Result<Vec<Variable>, RecordingError> {
    let p = || path.to_path_buf();
    if bytes.is_empty() {
        return Err(RecordingError::Empty { path: p() });
    }
    variables(bytes).map_err(|f| match f {
        Fault::Truncated(offset) => RecordingError::MatTruncated { path: p(), offset, size: bytes.len() },
        Fault::Format(reason) => RecordingError::MatFormat { path: p(), reason },
    })
}
