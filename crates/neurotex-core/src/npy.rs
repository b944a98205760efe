//! The header of a `.npy` file, read and checked against the file's size before any array
//! is allocated: no allocation larger than the input can hold
//! (docs/decisions/0017-npy-header-checked-before-reading.md).
//!
//! ndarray-npy 0.9 keeps its header parser private (`mod npy` is not public) and allocates
//! the array the header describes before it finds the data missing, so a 192-byte file
//! claiming shape `(10**12, 4, 4)` asks for 128 TB. This reads the header just far enough
//! to know the dtype, the shape and where the data starts, checks that the data the shape
//! needs is exactly what the file holds, and only then lets ndarray-npy read the file.

use std::io::Read;
use std::mem::MaybeUninit;
use std::path::Path;

use crate::error::{DataError, Result};
use crate::simd::widest_or_plain;

/// Largest header accepted, in bytes. numpy writes a few hundred bytes and itself refuses
/// headers over 10 000 bytes by default (`max_header_size`); version 1.0 cannot exceed
/// 65 535. A larger header is not a `.npy` written by numpy.
const MAX_HEADER_BYTES: usize = 1 << 16;

/// What a `.npy` header says: element type, shape, layout and where the data starts.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NpyHeader {
    /// The dtype as written, e.g. `<f8`.
    pub descr: String,
    /// Kind letter of the dtype: `f`, `i`, `u`, `b`, `U`, `S`, ...
    pub kind: char,
    /// Bytes per element.
    pub item_bytes: usize,
    /// The shape.
    pub shape: Vec<usize>,
    /// Number of elements (0 when any axis is 0).
    pub elements: usize,
    /// Byte offset of the data.
    pub data_offset: usize,
    /// Whether the data is in column-major (Fortran) order.
    pub fortran_order: bool,
    /// The fields of a structured dtype (`kind` is `V`), in record order; empty for a
    /// simple dtype.
    pub fields: Vec<NpyField>,
}

/// One field of a structured dtype such as tonic's `[('t', '<i8'), ('x', '<i8'), ...]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NpyField {
    /// The field's name.
    pub name: String,
    /// Kind letter: `f`, `i`, `u`, `b` (booleans), `V` (padding), ...
    pub kind: char,
    /// Bytes of the field.
    pub bytes: usize,
    /// Byte offset inside a record.
    pub offset: usize,
    /// Whether the field is big-endian (`>`).
    pub big_endian: bool,
}

impl NpyField {
    /// The field of record `record` (a slice of one record's bytes) as an integer, when it
    /// is a little-endian (or one-byte) integer or boolean; `None` for any other type.
    /// Unsigned 64-bit values above `i64::MAX` saturate there.
    #[inline]
    pub fn int(&self, record: &[u8]) -> Option<i64> {
        if self.big_endian && self.bytes > 1 {
            return None;
        }
        let b = &record[self.offset..];
        let le = |n: usize| {
            let mut raw = [0u8; 8];
            raw[..n].copy_from_slice(&b[..n]);
            u64::from_le_bytes(raw)
        };
        Some(match (self.kind, self.bytes) {
            ('i', 8) => i64::from_le_bytes(b[..8].try_into().ok()?),
            ('i', 4) => i64::from(i32::from_le_bytes(b[..4].try_into().ok()?)),
            ('i', 2) => i64::from(i16::from_le_bytes(b[..2].try_into().ok()?)),
            ('i', 1) => i64::from(b[0] as i8),
            ('b', 1) | ('u', 1 | 2 | 4) => le(self.bytes) as i64,
            ('u', 8) => i64::try_from(le(8)).unwrap_or(i64::MAX),
            _ => return None,
        })
    }

    /// The field as a float, when it is a little-endian float.
    pub fn float(&self, record: &[u8]) -> Option<f64> {
        let b = &record[self.offset..self.offset + self.bytes];
        match (self.kind, self.bytes, self.big_endian) {
            ('f', 8, false) => Some(f64::from_le_bytes(b.try_into().ok()?)),
            ('f', 4, false) => Some(f64::from(f32::from_le_bytes(b.try_into().ok()?))),
            _ => None,
        }
    }
}

impl NpyHeader {
    /// Whether the dtype is an integer or float type of `bytes` bytes.
    pub fn is_number(&self) -> bool {
        matches!(
            (self.kind, self.item_bytes),
            ('f', 4 | 8) | ('i' | 'u', 1 | 2 | 4 | 8)
        )
    }
}

/// Reads and checks the header of the `.npy` file at `path`: magic, version, an ASCII
/// dictionary with `descr`, `fortran_order` and `shape`, a simple dtype, and a data section
/// of exactly `elements * item_bytes` bytes (computed with checked arithmetic).
///
/// # Errors
/// An unreadable file, or one that breaks any of these rules; the message names the file
/// and what the header claims.
pub(crate) fn read_header(path: &Path) -> Result<NpyHeader> {
    let bad = |message: String| -> crate::Error { DataError::invalid(path, message).into() };
    let mut file = crate::io::open_input(path)?;
    let file_len = file.metadata().map_err(|e| DataError::io(path, e))?.len();
    let mut prefix = [0u8; 12];
    let got = read_up_to(&mut file, &mut prefix).map_err(|e| DataError::io(path, e))?;
    if got < 10 || &prefix[..6] != b"\x93NUMPY" {
        return Err(bad("not a .npy file (no \\x93NUMPY magic)".into()));
    }
    let (header_len, start) = match prefix[6] {
        1 => (u16::from_le_bytes([prefix[8], prefix[9]]) as usize, 10),
        2 | 3 if got == 12 => {
            let len = u32::from_le_bytes([prefix[8], prefix[9], prefix[10], prefix[11]]);
            (usize::try_from(len).unwrap_or(usize::MAX), 12)
        }
        v => return Err(bad(format!("unsupported .npy format version {v}"))),
    };
    if header_len > MAX_HEADER_BYTES {
        return Err(bad(format!(
            ".npy header of {header_len} bytes is larger than the {MAX_HEADER_BYTES} accepted"
        )));
    }
    let mut header = vec![0u8; header_len];
    let skip = got.saturating_sub(start);
    header[..skip.min(header_len)].copy_from_slice(&prefix[start..start + skip.min(header_len)]);
    if skip < header_len {
        file.read_exact(&mut header[skip..]).map_err(|_| {
            bad(format!(
                "file ends inside its {header_len}-byte .npy header"
            ))
        })?;
    }
    let text = std::str::from_utf8(&header)
        .ok()
        .filter(|t| t.is_ascii())
        .ok_or_else(|| bad(".npy header is not ASCII text".into()))?;
    let mut parsed = parse_dict(text).map_err(|m| bad(format!(".npy header: {m}")))?;
    parsed.data_offset = start + header_len;
    check_data_size(&parsed, file_len).map_err(bad)?;
    Ok(parsed)
}

/// The largest read buffer a thread keeps between files (64 MiB): beyond it the
/// allocation's cost is small beside the file's, and memory goes back at once.
const KEPT_BYTES: usize = 64 << 20;

/// A `.npy`'s samples as f64, and whether every one is a finite number.
pub(crate) struct Floats {
    pub(crate) samples: Vec<f64>,
    pub(crate) finite: bool,
}

/// The samples of a `.npy` of little-endian floats (`<f8` or `<f4`) in C order, whose
/// header [`read_header`] checked: the data read in one call into a byte buffer kept for the
/// thread's next file, and converted to f64 in one pass that also finds whether every
/// sample is finite (the recording's check, without a pass of its own). `None` for any
/// other dtype or order (ndarray-npy reads those).
///
/// # Errors
/// The file cannot be read (or changed size since its header was read).
pub(crate) fn read_le_floats(path: &Path, header: &NpyHeader) -> Result<Option<Floats>> {
    use std::io::{Seek, SeekFrom};
    thread_local! {
        /// The last file's bytes: one allocation per thread, not one per recording.
        static BYTES: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    let item = match header.descr.as_str() {
        "<f8" => 8,
        "<f4" => 4,
        _ => return Ok(None),
    };
    if header.fortran_order {
        return Ok(None);
    }
    let io = |e| DataError::io(path, e);
    let mut file = crate::io::open_input(path)?;
    file.seek(SeekFrom::Start(header.data_offset as u64))
        .map_err(io)?;
    BYTES.with_borrow_mut(|bytes| {
        // Only growth is zeroed: the read overwrites every byte kept.
        let size = header.elements * item;
        bytes.truncate(size);
        bytes.resize(size, 0);
        file.read_exact(bytes).map_err(io)?;
        let n = header.elements;
        let mut samples = Vec::with_capacity(n);
        let out = &mut samples.spare_capacity_mut()[..n];
        let finite = match item {
            8 => f64_from_le(bytes, out),
            _ => f64_from_f32_le(bytes, out),
        };
        // SAFETY: both conversions wrote all `n` values (`bytes` holds `n` items).
        unsafe { samples.set_len(n) };
        // A very large file's buffer is not kept for the thread's next, smaller ones.
        if bytes.capacity() > KEPT_BYTES {
            *bytes = Vec::new();
        }
        Ok(Some(Floats { samples, finite }))
    })
}

widest_or_plain! {
    ["avx2"]
    /// Little-endian float64 `bytes` into `out`, one sample per 8 bytes; whether every
    /// sample is finite.
    fn f64_from_le(bytes: &[u8], out: &mut [MaybeUninit<f64>]) -> bool {
        decode_finite(bytes, out, f64::from_le_bytes)
    }
}

widest_or_plain! {
    ["avx2"]
    /// Little-endian float32 `bytes` into `out` as float64 (exact), one per 4 bytes;
    /// whether every sample is finite.
    fn f64_from_f32_le(bytes: &[u8], out: &mut [MaybeUninit<f64>]) -> bool {
        decode_finite(bytes, out, |b| f64::from(f32::from_le_bytes(b)))
    }
}

/// The conversions' one loop: each `N`-byte item of `bytes` through `decode` into `out`,
/// and whether every value is finite. Inlined into each compiled copy of its caller, so
/// the loop takes the caller's vector width.
///
/// # Panics
/// `bytes` holds fewer than `out.len()` items.
#[inline(always)]
fn decode_finite<const N: usize>(
    bytes: &[u8],
    out: &mut [MaybeUninit<f64>],
    decode: impl Fn([u8; N]) -> f64,
) -> bool {
    let items = bytes.as_chunks::<N>().0;
    assert!(items.len() >= out.len(), "a sample for every output value");
    let mut bad = false;
    for (o, b) in out.iter_mut().zip(items) {
        let v = decode(*b);
        bad |= !crate::values::sample_in_range(v);
        o.write(v);
    }
    !bad
}

/// Reads into `buf` until it is full or the file ends; returns the bytes read.
fn read_up_to(file: &mut std::fs::File, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match file.read(&mut buf[filled..])? {
            0 => break,
            n => filled += n,
        }
    }
    Ok(filled)
}

/// The data the shape needs must be what the file holds, byte for byte.
fn check_data_size(header: &NpyHeader, file_len: u64) -> std::result::Result<(), String> {
    let shape = &header.shape;
    let needed = (header.elements as u64).checked_mul(header.item_bytes as u64);
    let held = file_len.saturating_sub(header.data_offset as u64);
    match needed {
        Some(needed) if needed == held => Ok(()),
        Some(needed) => Err(format!(
            "the .npy header claims shape {shape:?} of `{}` ({needed} bytes of data) but the file holds {held} bytes of data",
            header.descr
        )),
        None => Err(format!(
            "the .npy header claims shape {shape:?} of `{}`, more bytes than any file holds (this one holds {held})",
            header.descr
        )),
    }
}

/// Parses the header dictionary `{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }`.
fn parse_dict(text: &str) -> std::result::Result<NpyHeader, String> {
    let descr = value_after(text, "descr")?;
    let fields = match descr.starts_with('[') {
        true => parse_fields(descr)?,
        false => Vec::new(),
    };
    let list = descr
        .get(..descr.find(']').map_or(0, |e| e + 1))
        .unwrap_or("");
    let descr = match fields.is_empty() {
        true => quoted(descr).ok_or_else(|| {
            "field `descr` must be a dtype string such as '<f8' or a list of named fields"
                .to_string()
        })?,
        false => list,
    };
    let order = value_after(text, "fortran_order")?;
    if !(order.starts_with("False") || order.starts_with("True")) {
        return Err("field `fortran_order` must be True or False".into());
    }
    let fortran_order = order.starts_with("True");
    let shape = parse_shape(value_after(text, "shape")?)?;
    let (kind, item_bytes) = match fields.last() {
        Some(last) => ('V', last.offset + last.bytes),
        None => parse_descr(descr)?,
    };
    // ndarray needs the product of the non-zero axes to fit in isize even when another
    // axis is 0, so a zero axis beside huge ones is refused rather than passed on.
    let nonzero = shape
        .iter()
        .filter(|&&d| d != 0)
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .filter(|&n| n <= isize::MAX as usize)
        .ok_or_else(|| format!("shape {shape:?} has more elements than any array can hold"))?;
    let elements = if shape.contains(&0) { 0 } else { nonzero };
    Ok(NpyHeader {
        descr: descr.to_string(),
        kind,
        item_bytes,
        shape,
        elements,
        data_offset: 0,
        fortran_order,
        fields,
    })
}

/// A structured dtype's list `[('t', '<i8'), ('x', '<i8'), ...]` into its fields with
/// their offsets. Fields with a shape of their own, nested structures and empty records
/// are refused.
fn parse_fields(text: &str) -> std::result::Result<Vec<NpyField>, String> {
    let end = text
        .find(']')
        .ok_or("field `descr`: a list of fields without its closing `]`")?;
    let inner = &text[1..end];
    let mut fields = Vec::new();
    let mut offset = 0usize;
    for part in inner.split(')').map(str::trim) {
        let part = part.trim_start_matches(',').trim();
        if part.is_empty() {
            continue;
        }
        let bad = || format!("unsupported structured dtype field `{part})`");
        let body = part.strip_prefix('(').ok_or_else(bad)?.trim();
        let name = quoted(body).ok_or_else(bad)?;
        let rest = body[name.len() + 2..].trim_start();
        let rest = rest.strip_prefix(',').ok_or_else(bad)?.trim_start();
        let dtype = quoted(rest).ok_or_else(bad)?;
        if !rest[dtype.len() + 2..].trim().is_empty() {
            return Err(format!(
                "{}: fields with a shape of their own are not supported",
                bad()
            ));
        }
        let (kind, bytes) = match dtype.strip_prefix('|').and_then(|w| w.strip_prefix('V')) {
            Some(width) => ('V', width.parse::<usize>().map_err(|_| bad())?),
            None => parse_descr(dtype)?,
        };
        fields.push(NpyField {
            name: name.to_string(),
            kind,
            bytes,
            offset,
            big_endian: dtype.starts_with('>'),
        });
        offset = offset.checked_add(bytes).ok_or_else(bad)?;
    }
    if offset == 0 {
        return Err("field `descr`: a structured dtype without fields".into());
    }
    Ok(fields)
}

/// The data section of a `.npy` whose header [`read_header`] checked, as bytes.
///
/// # Errors
/// The file cannot be read, or changed size since its header was read.
pub(crate) fn read_data(path: &Path, header: &NpyHeader) -> Result<Vec<u8>> {
    use std::io::{Seek, SeekFrom};
    let io = |e| DataError::io(path, e);
    let mut file = crate::io::open_input(path)?;
    file.seek(SeekFrom::Start(header.data_offset as u64))
        .map_err(io)?;
    let mut bytes = vec![0u8; header.elements * header.item_bytes];
    file.read_exact(&mut bytes).map_err(io)?;
    Ok(bytes)
}

/// The text after `'key':` (or `"key":`), leading blanks removed.
fn value_after<'a>(text: &'a str, key: &str) -> std::result::Result<&'a str, String> {
    [format!("'{key}'"), format!("\"{key}\"")]
        .iter()
        .find_map(|k| text.find(k.as_str()).map(|at| &text[at + k.len()..]))
        .and_then(|rest| rest.trim_start().strip_prefix(':'))
        .map(str::trim_start)
        .ok_or_else(|| format!("missing field `{key}`"))
}

/// The content of a quoted string at the start of `text`.
fn quoted(text: &str) -> Option<&str> {
    let quote = text.chars().next().filter(|&c| c == '\'' || c == '"')?;
    let rest = &text[1..];
    rest.find(quote).map(|end| &rest[..end])
}

/// `(3, 4)`, `(5,)` or `()` into its dimensions.
fn parse_shape(text: &str) -> std::result::Result<Vec<usize>, String> {
    let bad = || "field `shape` must be a tuple of non-negative integers".to_string();
    let inner = text.strip_prefix('(').ok_or_else(bad)?;
    let inner = &inner[..inner.find(')').ok_or_else(bad)?];
    inner
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
        .map(|d| d.parse::<usize>().map_err(|_| bad()))
        .collect()
}

/// A simple dtype `<f8`, `|u1`, `<U12`, `|S5`: its kind letter and bytes per element.
fn parse_descr(descr: &str) -> std::result::Result<(char, usize), String> {
    let unknown = || format!("unsupported dtype `{descr}`");
    let mut chars = descr.chars();
    let (order, kind) = (chars.next(), chars.next());
    let (Some('<' | '>' | '|' | '='), Some(kind)) = (order, kind) else {
        return Err(unknown());
    };
    let width: usize = chars.as_str().parse().map_err(|_| unknown())?;
    let item_bytes = match kind {
        'U' => width.checked_mul(4).ok_or_else(unknown)?,
        'f' | 'i' | 'u' | 'b' | 'S' | 'c' => width,
        _ => return Err(unknown()),
    };
    if item_bytes == 0 {
        return Err(unknown());
    }
    Ok((kind, item_bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A version 1.0 `.npy` of the simple dtype `descr` with `data` bytes.
    fn npy_bytes(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
        npy_of(&format!("'{descr}'"), shape, data)
    }

    /// A version 1.0 `.npy` whose `descr` is `descr` as written (a quoted dtype or a list
    /// of fields), its header padded as numpy pads it, then `data` bytes.
    fn npy_of(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut h = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(' ');
        }
        h.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((h.len() as u16).to_le_bytes());
        out.extend(h.as_bytes());
        out.extend(data);
        out
    }

    fn header_of(bytes: &[u8]) -> Result<NpyHeader> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.npy");
        std::fs::write(&path, bytes).unwrap();
        read_header(&path)
    }

    #[test]
    fn a_shape_larger_than_the_file_is_refused_before_allocating() {
        let bytes = npy_bytes("<f8", "(1000000000000, 4, 4)", &[0; 64]);
        let message = header_of(&bytes).unwrap_err().to_string();
        assert!(message.contains("[1000000000000, 4, 4]"), "{message}");
        assert!(message.contains("holds 64 bytes"), "{message}");
    }

    #[test]
    fn a_zero_axis_beside_huge_ones_is_refused() {
        let bytes = npy_bytes("<f8", "(0, 1000000000000, 1000000000000)", &[]);
        let message = header_of(&bytes).unwrap_err().to_string();
        assert!(
            message.contains("more elements than any array"),
            "{message}"
        );
        // a zero axis beside reasonable ones is an empty array, which is fine here
        let ok = header_of(&npy_bytes("<f8", "(0, 4, 4)", &[])).unwrap();
        assert_eq!((ok.elements, ok.shape), (0, vec![0, 4, 4]));
    }

    #[test]
    fn non_ascii_and_unknown_dtypes_are_errors() {
        for descr in ["<f\u{e9}8", "<q16", "<f", "", "<U0"] {
            let message = header_of(&npy_bytes(descr, "(2,)", &[0; 16]))
                .unwrap_err()
                .to_string();
            assert!(message.contains("header"), "{descr}: {message}");
        }
    }

    #[test]
    fn a_well_formed_header_is_read() {
        let h = header_of(&npy_bytes("<U3", "(2,)", &[0; 24])).unwrap();
        assert_eq!((h.kind, h.item_bytes, h.elements), ('U', 12, 2));
        assert_eq!(h.data_offset % 64, 0, "numpy pads the header to 64 bytes");
        let h = header_of(&npy_bytes("<f4", "(2, 3)", &[0; 24])).unwrap();
        assert!(h.is_number());
        // one byte too few or too many
        assert!(header_of(&npy_bytes("<f4", "(2, 3)", &[0; 23])).is_err());
        assert!(header_of(&npy_bytes("<f4", "(2, 3)", &[0; 25])).is_err());
    }

    #[test]
    fn a_structured_dtype_is_read_field_by_field() {
        // numpy: np.array([(5, 1, 2, True)], dtype=[('t','<i8'),('x','<i2'),('y','<u1'),('p','|b1')])
        let descr = "[('t', '<i8'), ('x', '<i2'), ('y', '|u1'), ('p', '|b1')]";
        let mut data = 5i64.to_le_bytes().to_vec();
        data.extend((-1i16).to_le_bytes());
        data.extend([2u8, 1]);
        let bytes = npy_of(descr, "(1,)", &data);
        let header = header_of(&bytes).unwrap();
        assert_eq!((header.kind, header.item_bytes), ('V', 12));
        let names: Vec<&str> = header.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["t", "x", "y", "p"]);
        let record = &bytes[header.data_offset..];
        let values: Vec<i64> = header
            .fields
            .iter()
            .map(|f| f.int(record).unwrap())
            .collect();
        assert_eq!(values, [5, -1, 2, 1]);
        assert!(!header.is_number());
        for bad in ["[('t', '<i8', (2,))]", "[]", "[('t')]"] {
            let b = npy_of(bad, "(0,)", &[]);
            assert!(header_of(&b).is_err(), "{bad}");
        }
    }

    #[test]
    fn garbage_is_an_error_not_a_panic() {
        for bytes in [
            &b""[..],
            b"\x93NUMPY",
            b"\x93NUMPY\x01\x00\xff\xff{",
            b"\x93NUMPY\x02\x00\xff\xff\xff\xff",
            b"\x93NUMPY\x09\x00\x00\x00",
        ] {
            assert!(header_of(bytes).is_err());
        }
    }
}
