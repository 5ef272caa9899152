//! Format-aware mutations of a valid file: the generic ones (bit flips, bytes set to edge
//! values, truncation, extension, block duplication) and, per format, header fields replaced by
//! extremes: dimensions up to 2^31 and beyond, orientation and format lines (`.hdr`); data and
//! display windows, channel lists (types, sampling, a missing colour channel), compression,
//! offset tables and pixel values set to NaN, infinity or negative (`.exr`); numbers, types,
//! nesting and structure (JSON); glTF's container, sizes and binary data ([`crate::model`]).

use crate::Format;
use rand::Rng;

/// Integers that break size arithmetic: zero, one, powers of two and their neighbours up to and
/// past 2^31, and negatives.
pub const EXTREME_INTS: [i64; 24] = [
    0,
    1,
    -1,
    2,
    3,
    7,
    8,
    255,
    256,
    32767,
    32768,
    65535,
    65536,
    46341,
    8192,
    16384,
    1 << 27,
    (1 << 31) - 1,
    1 << 31,
    (1 << 32) - 1,
    1 << 32,
    -(1 << 31),
    -(1 << 31) + 1,
    -65536,
];

/// f32 values that break arithmetic on pixels.
pub const EXTREME_F32: [f32; 10] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, -1e30, f32::MAX, f32::MIN_POSITIVE, 1e-45, 65504.0, -0.0];

/// JSON tokens to put in place of a number.
const EXTREME_JSON: [&str; 16] = [
    "1e309",
    "-1e309",
    "NaN",
    "Infinity",
    "-0",
    "1e-400",
    "340282366920938463463374607431768211456",
    "-3.5e38",
    "3.5e38",
    "0",
    "-1",
    "null",
    "\"1\"",
    "[]",
    "{}",
    "true",
];

/// Bytes of `bytes` that form its header: every truncation inside it is a case of its own.
#[must_use]
pub fn header_len(bytes: &[u8], format: Format) -> usize {
    match format {
        Format::Hdr => hdr_header_len(bytes),
        Format::Exr => exr_header_len(bytes).unwrap_or(bytes.len()).min(bytes.len()),
        Format::Json | Format::Gltf => bytes.len().min(256),
        // the container's header and chunk header, and the start of the JSON
        Format::Glb => bytes.len().min(96),
        // a PNG's signature and IHDR; a JPEG's first markers
        Format::Png => bytes.len().min(64),
    }
}

fn hdr_header_len(bytes: &[u8]) -> usize {
    // the blank line ends the header; the resolution line follows it
    let Some(blank) = bytes.windows(2).position(|w| w == b"\n\n") else { return bytes.len() };
    let after = blank + 2;
    bytes[after..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |e| after + e + 1)
}

/// One attribute of an EXR header: name, type, and where its value lies.
struct Attribute {
    name: String,
    kind: String,
    value: std::ops::Range<usize>,
}

/// The attributes of the first EXR header and where the header ends (after its terminating
/// null byte); `None` when it does not parse.
fn exr_attributes(bytes: &[u8]) -> Option<(Vec<Attribute>, usize)> {
    let mut pos = 8;
    let mut out = Vec::new();
    let cstr = |pos: &mut usize| -> Option<String> {
        let end = bytes.get(*pos..)?.iter().position(|&b| b == 0)? + *pos;
        let s = String::from_utf8_lossy(&bytes[*pos..end]).to_string();
        *pos = end + 1;
        Some(s)
    };
    loop {
        let name = cstr(&mut pos)?;
        if name.is_empty() {
            return Some((out, pos));
        }
        let kind = cstr(&mut pos)?;
        let size = i32::from_le_bytes(bytes.get(pos..pos + 4)?.try_into().ok()?);
        pos += 4;
        let end = pos.checked_add(usize::try_from(size).ok()?)?;
        if end > bytes.len() {
            return None;
        }
        out.push(Attribute { name, kind, value: pos..end });
        pos = end;
    }
}

/// The first header and its offset table.
fn exr_header_len(bytes: &[u8]) -> Option<usize> {
    let (attributes, end) = exr_attributes(bytes)?;
    let window = attributes.iter().find(|a| a.name == "dataWindow")?;
    let v = &bytes[window.value.clone()];
    if v.len() < 16 {
        return None;
    }
    let int = |k: usize| i32::from_le_bytes([v[4 * k], v[4 * k + 1], v[4 * k + 2], v[4 * k + 3]]);
    let rows = i64::from(int(3)) - i64::from(int(1)) + 1;
    let compression = attributes.iter().find(|a| a.name == "compression").map_or(0, |a| bytes[a.value.start]);
    let lines = match compression {
        0..=2 => 1,
        3 | 5 => 16,
        4 | 6 | 7 => 32,
        8 => 32,
        9 => 256,
        _ => 1,
    };
    Some(end + 8 * usize::try_from((rows + lines - 1) / lines).ok()?)
}

/// A mutated copy of `seed`: one to three operators, generic or of `format`.
pub fn mutate(seed: &[u8], format: Format, rng: &mut impl Rng) -> Vec<u8> {
    let mut bytes = seed.to_vec();
    for _ in 0..rng.random_range(1..=3) {
        if rng.random_bool(0.4) {
            generic(&mut bytes, format, rng);
        } else {
            match format {
                Format::Hdr => hdr(&mut bytes, rng),
                Format::Exr => exr(&mut bytes, rng),
                Format::Json => json(&mut bytes, rng),
                Format::Gltf => crate::model::mutate(&mut bytes, false, rng),
                Format::Glb => crate::model::mutate(&mut bytes, true, rng),
                Format::Png => png(&mut bytes, rng),
            }
        }
    }
    bytes
}

fn generic(bytes: &mut Vec<u8>, format: Format, rng: &mut impl Rng) {
    if bytes.is_empty() {
        bytes.push(rng.random());
        return;
    }
    let header = header_len(bytes, format).clamp(1, bytes.len());
    // most damage where the parsing is: the header
    let at = |rng: &mut dyn rand::RngCore, len: usize| {
        if rng.random_bool(0.7) { rng.random_range(0..header) } else { rng.random_range(0..len) }
    };
    match rng.random_range(0..6) {
        0 => {
            for _ in 0..rng.random_range(1..=8) {
                let k = at(rng, bytes.len());
                bytes[k] ^= 1 << rng.random_range(0..8);
            }
        }
        1 => {
            let k = at(rng, bytes.len());
            bytes[k] = [0, 0xff, 0x7f, 0x80, b'\n', b' '][rng.random_range(0..6)];
        }
        2 => {
            let k = rng.random_range(0..bytes.len());
            bytes.truncate(k);
        }
        3 => {
            let n = rng.random_range(1..=64);
            let fill: u8 = if rng.random_bool(0.5) { 0 } else { rng.random() };
            bytes.extend(std::iter::repeat_n(fill, n));
        }
        4 => {
            let a = rng.random_range(0..bytes.len());
            let b = rng.random_range(a..=bytes.len().min(a + 64));
            let block = bytes[a..b].to_vec();
            let k = rng.random_range(0..=bytes.len());
            bytes.splice(k..k, block);
        }
        _ => {
            let a = rng.random_range(0..bytes.len());
            let b = rng.random_range(a..=bytes.len().min(a + 16));
            bytes.drain(a..b);
        }
    }
}

fn extreme_int(rng: &mut impl Rng) -> i64 {
    EXTREME_INTS[rng.random_range(0..EXTREME_INTS.len())]
}

fn hdr(bytes: &mut Vec<u8>, rng: &mut impl Rng) {
    let header = hdr_header_len(bytes).min(bytes.len());
    let blank = bytes.windows(2).position(|w| w == b"\n\n").map_or(header, |b| b + 2).min(header);
    let rest = bytes.split_off(header);
    let mut head = bytes[..blank].to_vec();
    let mut resolution = String::from_utf8_lossy(&bytes[blank..]).trim().to_string();
    match rng.random_range(0..6) {
        0 | 1 => {
            // dimensions to extremes, up to 2^32
            let (y, x) = (extreme_int(rng), extreme_int(rng));
            let axes = [("-Y", "+X"), ("+Y", "+X"), ("-Y", "-X"), ("+X", "-Y"), ("-X", "+Y")][rng.random_range(0..5)];
            resolution = format!("{} {y} {} {x}", axes.0, axes.1);
        }
        2 => {
            let format = ["FORMAT=32-bit_rle_xyze", "FORMAT=garbage", "FORMAT=", "FORMAT=32-bit_rle_rgbe\r"]
                [rng.random_range(0..4)];
            head = format!("#?RADIANCE\n{format}\n\n").into_bytes();
        }
        3 => {
            // a huge header line, or none at all
            head.splice(
                blank.saturating_sub(1)..blank.saturating_sub(1),
                std::iter::repeat_n(b'A', rng.random_range(1..20_000)),
            );
        }
        4 => {
            // an RLE scanline whose declared width disagrees with the header's
            let k = rest.iter().position(|&b| b == 2).unwrap_or(0);
            let mut rest = rest.clone();
            if k + 3 < rest.len() {
                let w = extreme_int(rng) as u16;
                rest[k + 2] = (w >> 8) as u8;
                rest[k + 3] = w as u8;
            }
            bytes.clear();
            bytes.extend(head);
            bytes.extend(resolution.as_bytes());
            bytes.push(b'\n');
            bytes.extend(rest);
            return;
        }
        _ => {
            resolution = resolution.replacen(' ', "  ", 1) + &" 1".repeat(rng.random_range(0..3));
        }
    }
    bytes.clear();
    bytes.extend(head);
    bytes.extend(resolution.as_bytes());
    bytes.push(b'\n');
    bytes.extend(rest);
}

fn exr(bytes: &mut Vec<u8>, rng: &mut impl Rng) {
    let Some((attributes, end)) = exr_attributes(bytes) else {
        let k = rng.random_range(0..bytes.len().max(1));
        if let Some(b) = bytes.get_mut(k) {
            *b = rng.random();
        }
        return;
    };
    let int32 = |bytes: &mut Vec<u8>, at: usize, v: i64| {
        if at + 4 <= bytes.len() {
            bytes[at..at + 4].copy_from_slice(&(v as i32).to_le_bytes());
        }
    };
    match rng.random_range(0..7) {
        0 | 1 => {
            // data or display window: dimensions up to 2^31 and past, inverted, negative
            let names = ["dataWindow", "displayWindow"];
            if let Some(a) = attributes.iter().find(|a| a.name == names[rng.random_range(0..2)]) {
                for k in 0..4 {
                    if rng.random_bool(0.5) {
                        int32(bytes, a.value.start + 4 * k, extreme_int(rng));
                    }
                }
            }
        }
        2 => {
            // channels: types, sampling, a colour channel renamed away (wrong channel counts)
            if let Some(a) = attributes.iter().find(|a| a.kind == "chlist") {
                let list = a.value.clone();
                let names: Vec<usize> = (list.start..list.end)
                    .filter(|&k| (k == list.start || bytes[k - 1] == 0) && bytes[k] != 0)
                    .collect();
                if let Some(&at) = names.get(rng.random_range(0..names.len().max(1))) {
                    let name_end = bytes[at..list.end].iter().position(|&b| b == 0).map_or(list.end, |e| at + e);
                    match rng.random_range(0..3) {
                        0 => bytes[at] = [b'Z', b'R', b'G', b'B', b'A'][rng.random_range(0..5)],
                        1 => int32(bytes, name_end + 1, [-1, 0, 1, 2, 3, 255][rng.random_range(0..6)]),
                        _ => int32(bytes, name_end + 1 + 8 + 4 * rng.random_range(0..2), extreme_int(rng)),
                    }
                }
            }
        }
        3 => {
            if let Some(a) = attributes.iter().find(|a| a.name == "compression" || a.name == "lineOrder") {
                bytes[a.value.start] = rng.random();
            }
        }
        4 => {
            // an offset-table entry to an extreme
            let n = (bytes.len().saturating_sub(end) / 8).clamp(1, 64);
            let at = end + 8 * rng.random_range(0..n);
            let v = extreme_int(rng) as u64;
            if at + 8 <= bytes.len() {
                bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
            }
        }
        5 => {
            // pixel values to NaN, infinity or negative (uncompressed f32 data lies past the
            // table; in compressed chunks this is damage of another kind)
            for _ in 0..rng.random_range(1..=8) {
                let at = rng.random_range(end.min(bytes.len())..bytes.len().max(end + 1));
                let v = EXTREME_F32[rng.random_range(0..EXTREME_F32.len())];
                let at = at - at % 4;
                if at + 4 <= bytes.len() {
                    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
        }
        _ => {
            // an attribute's size field to an extreme
            if let Some(a) = attributes.get(rng.random_range(0..attributes.len().max(1))) {
                int32(bytes, a.value.start - 4, extreme_int(rng));
            }
        }
    }
}

/// Where `needle` first stands in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// `parts` joined: JSON is mutated as bytes, so a damaged file need not be UTF-8.
fn join(parts: &[&[u8]]) -> Vec<u8> {
    parts.concat()
}

pub(crate) fn json(bytes: &mut Vec<u8>, rng: &mut impl Rng) {
    let text = bytes.clone();
    if text.is_empty() {
        bytes.extend(b"{\"lights\":[");
        return;
    }
    let numbers: Vec<(usize, usize)> = {
        let b = &text;
        let mut out = Vec::new();
        let mut k = 0;
        while k < b.len() {
            if b[k] == b'-' || b[k].is_ascii_digit() {
                let start = k;
                k += 1;
                while k < b.len() && (b[k].is_ascii_digit() || b"+-.eE".contains(&b[k])) {
                    k += 1;
                }
                out.push((start, k));
            } else {
                k += 1;
            }
        }
        out
    };
    *bytes = match rng.random_range(0..6) {
        0 | 1 if !numbers.is_empty() => {
            let (a, b) = numbers[rng.random_range(0..numbers.len())];
            let token = EXTREME_JSON[rng.random_range(0..EXTREME_JSON.len())].as_bytes();
            join(&[&text[..a], token, &text[b..]])
        }
        2 => {
            // deep nesting in place of a value
            let depth = [10, 127, 129, 1000, 100_000][rng.random_range(0..5)];
            let k = find(&text, b"\"lights\":").map_or(0, |k| k + 9);
            join(&[&text[..k], &b"[".repeat(depth), &b"]".repeat(depth), &text[k..]])
        }
        3 => {
            // arrays of the wrong length
            let k = find(&text, b"[").map_or(0, |k| k + 1);
            let extra: &[u8] = [&b"1,"[..], b"1,2,3,4,", b"", b"[1],"][rng.random_range(0..4)];
            join(&[&text[..k], extra, &text[k..]])
        }
        4 => {
            // a key renamed away, or the object replaced by another type
            let keys: [&[u8]; 5] =
                [b"\"lights\"", b"\"direction\"", b"\"solid_angle\"", b"\"radiance\"", b"\"interleaved\""];
            let key = keys[rng.random_range(0..keys.len())];
            match find(&text, key) {
                Some(k) if rng.random_bool(0.8) => join(&[&text[..k], b"\"x\"", &text[k + key.len()..]]),
                _ => [&b"[]"[..], b"null", b"1", b"\"\""][rng.random_range(0..4)].to_vec(),
            }
        }
        _ => {
            // a light repeated many times
            match (find(&text, b"{\"direction\""), text.iter().position(|&b| b == b'}')) {
                (Some(a), Some(b)) if b > a => {
                    let mut light = text[a..=b].to_vec();
                    light.push(b',');
                    let n = rng.random_range(1..2000);
                    join(&[&text[..a], &light.repeat(n), &text[a..]])
                }
                _ => text.clone(),
            }
        }
    };
}

/// A PNG's IHDR width or height (bytes 16-23, big-endian) set to an extreme: the size a
/// decoder believes before it reads a pixel (a JPEG's bytes there are flipped alike).
fn png(bytes: &mut [u8], rng: &mut impl Rng) {
    if bytes.len() < 24 {
        return;
    }
    let at = if rng.random_bool(0.5) { 16 } else { 20 };
    let v: u32 = match rng.random_range(0..5) {
        0 => 0,
        1 => 1,
        2 => u32::MAX,
        3 => 1 << rng.random_range(10..31),
        _ => rng.random(),
    };
    bytes[at..at + 4].copy_from_slice(&v.to_be_bytes());
}
