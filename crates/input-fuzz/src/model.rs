//! glTF 2.0 mutations that know the file's structure: the GLB container (magic, version, total
//! length, chunk lengths and types), a `.gltf`'s embedded buffer (a base64 data URI, decoded,
//! damaged and encoded again), the document's size fields (accessor counts, byte offsets,
//! lengths and strides, references between arrays) set to extremes, positions in the binary set
//! to NaN or infinity, indices past the vertex count, types and modes changed, the buffer's file
//! made missing, compression required, and the file replaced by something that is not glTF.

use crate::mutate::{EXTREME_F32, EXTREME_INTS};
use rand::Rng;
use serde_json::Value;
use std::ops::Range;

/// The URI prefix of a buffer embedded in a `.gltf`.
pub const DATA_URI: &str = "data:application/octet-stream;base64,";

/// A GLB container around `json` and `bin` with every length right ([`scene::glb_bytes`]), so
/// damage inside a chunk reaches the reader behind the container.
#[must_use]
pub fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    scene::glb_bytes(json, bin).unwrap_or_default()
}

/// A GLB's JSON and BIN chunks (BIN empty when there is none), when its container parses.
#[must_use]
pub fn glb_chunks(bytes: &[u8]) -> Option<(&[u8], &[u8])> {
    let word = |k: usize| -> Option<usize> {
        Some(u32::from_le_bytes(bytes.get(k..k.checked_add(4)?)?.try_into().ok()?) as usize)
    };
    if bytes.get(..4)? != b"glTF" || bytes.get(16..20)? != b"JSON" {
        return None;
    }
    let json_end = 20usize.checked_add(word(12)?)?;
    let json = bytes.get(20..json_end)?;
    let bin = match (word(json_end), bytes.get(json_end + 4..json_end + 8)) {
        (Some(len), Some(b"BIN\0")) => bytes.get(json_end + 8..(json_end + 8).checked_add(len)?)?,
        _ => &[],
    };
    Some((json, bin))
}

/// Where a `.gltf`'s embedded buffer's base64 text lies, and its bytes.
#[must_use]
pub fn embedded(text: &[u8]) -> Option<(Range<usize>, Vec<u8>)> {
    let start = text.windows(DATA_URI.len()).position(|w| w == DATA_URI.as_bytes())? + DATA_URI.len();
    let end = text[start..].iter().position(|&b| b == b'"')? + start;
    let bin = base64::decode(&text[start..end]).ok()?;
    Some((start..end, bin))
}

/// The `.gltf` text with its embedded buffer replaced by `bin`.
fn embed(text: &[u8], at: Range<usize>, bin: &[u8]) -> Vec<u8> {
    [&text[..at.start], base64::encode(bin).as_bytes(), &text[at.end..]].concat()
}

/// Where the document puts a primitive's data in buffer 0: (byte offset, count, stride or
/// component size).
#[derive(Default)]
struct Layout {
    /// f32 x 3 positions: offset, count, stride.
    positions: Vec<(usize, usize, usize)>,
    /// Indices: offset, count, bytes per index.
    indices: Vec<(usize, usize, usize)>,
    /// Vertices of the primitive each index list draws.
    vertices: Vec<usize>,
}

fn layout(doc: &Value) -> Layout {
    let uint = |v: &Value, key: &str| v.get(key).and_then(Value::as_u64).map(|n| n as usize);
    let accessors = doc.get("accessors").and_then(Value::as_array).cloned().unwrap_or_default();
    let views = doc.get("bufferViews").and_then(Value::as_array).cloned().unwrap_or_default();
    // offset in the buffer, count, the view's stride and the accessor's component type
    let place = |k: usize| -> Option<(usize, usize, Option<usize>, u64)> {
        let a = accessors.get(k)?;
        let view = views.get(uint(a, "bufferView")?)?;
        let offset = uint(view, "byteOffset").unwrap_or(0) + uint(a, "byteOffset").unwrap_or(0);
        Some((offset, uint(a, "count")?, uint(view, "byteStride"), a.get("componentType")?.as_u64()?))
    };
    let mut out = Layout::default();
    for mesh in doc.get("meshes").and_then(Value::as_array).into_iter().flatten() {
        for p in mesh.get("primitives").and_then(Value::as_array).into_iter().flatten() {
            let Some(pos) = p.get("attributes").and_then(|a| uint(a, "POSITION")).and_then(place) else { continue };
            out.positions.push((pos.0, pos.1, pos.2.unwrap_or(12)));
            if let Some((offset, count, _, kind)) = uint(p, "indices").and_then(place) {
                let size = match kind {
                    5121 => 1,
                    5123 => 2,
                    _ => 4,
                };
                out.indices.push((offset, count, size));
                out.vertices.push(pos.1);
            }
        }
    }
    out
}

/// Keys whose numbers say how big something is or where it lies.
const SIZE_KEYS: [&str; 14] = [
    "\"count\":",
    "\"byteOffset\":",
    "\"byteLength\":",
    "\"byteStride\":",
    "\"bufferView\":",
    "\"buffer\":",
    "\"indices\":",
    "\"POSITION\":",
    "\"NORMAL\":",
    "\"mode\":",
    "\"componentType\":",
    "\"mesh\":",
    "\"camera\":",
    "\"scene\":",
];

/// What a user's "model" can be instead of one.
const NOT_GLTF: [&[u8]; 6] = [
    b"<!DOCTYPE html>\n<html><head><title>404 Not Found</title></head><body>Not Found</body></html>\n",
    b"{\"asset\":{\"version\":\"1.0\"}}",
    b"{\"asset\":{\"version\":\"2.0\"}}",
    b"glTF\x02\x00\x00\x00\x0c\x00\x00\x00",
    b"",
    b"solid cube\nfacet normal 0 0 1\nendsolid\n",
];

/// The number after the `k`-th occurrence of `key` replaced by `token`.
fn replace_after_key(text: &[u8], key: &str, token: &[u8], rng: &mut impl Rng) -> Option<Vec<u8>> {
    let hits: Vec<usize> =
        text.windows(key.len()).enumerate().filter(|(_, w)| *w == key.as_bytes()).map(|(k, _)| k + key.len()).collect();
    let &start = hits.get(rng.random_range(0..hits.len().max(1)))?;
    let len = text[start..].iter().take_while(|b| b.is_ascii_digit() || b"-+.eE ".contains(b)).count();
    Some([&text[..start], token, &text[start + len..]].concat())
}

fn extreme_token(rng: &mut impl Rng) -> Vec<u8> {
    if rng.random_bool(0.8) {
        EXTREME_INTS[rng.random_range(0..EXTREME_INTS.len())].to_string().into_bytes()
    } else {
        ["1e309", "-0", "0.5", "null", "\"0\"", "[]", "18446744073709551616"][rng.random_range(0..7)]
            .as_bytes()
            .to_vec()
    }
}

/// The JSON text damaged where glTF's structure is; `None` when the chosen change has no place.
fn document(text: &[u8], rng: &mut impl Rng) -> Option<Vec<u8>> {
    let swap = |text: &[u8], from: &[u8], to: &[u8]| -> Option<Vec<u8>> {
        let k = text.windows(from.len()).position(|w| w == from)?;
        Some([&text[..k], to, &text[k + from.len()..]].concat())
    };
    match rng.random_range(0..8) {
        0..=2 => {
            let key = SIZE_KEYS[rng.random_range(0..SIZE_KEYS.len())];
            replace_after_key(text, key, &extreme_token(rng), rng)
        }
        3 => {
            let types: [&[u8]; 5] = [b"\"SCALAR\"", b"\"VEC2\"", b"\"VEC4\"", b"\"MAT4\"", b"\"vec3\""];
            swap(text, b"\"VEC3\"", types[rng.random_range(0..types.len())])
        }
        4 => {
            // indices as floats or signed, or a primitive of another mode
            let key = ["\"componentType\":", "\"mode\":"][rng.random_range(0..2)];
            let token = ["5126", "5120", "5122", "0", "1", "3", "5", "6", "7"][rng.random_range(0..9)];
            replace_after_key(text, key, token.as_bytes(), rng)
        }
        5 => {
            // the buffer in a file that is not there, or a directory, or an empty data URI
            let uri: &[u8] = [&b"\"missing.bin\""[..], b"\".\"", b"\"../\"", b"\"data:,\""][rng.random_range(0..4)];
            let find = |needle: &[u8]| text.windows(needle.len()).position(|w| w == needle);
            match find(b"\"uri\":\"") {
                Some(k) => {
                    let open = k + 6;
                    let close = text[open + 1..].iter().position(|&b| b == b'"')? + open + 1;
                    Some([&text[..open], uri, &text[close + 1..]].concat())
                }
                None => {
                    let k = find(b"\"buffers\":[{")? + 12;
                    Some([&text[..k], b"\"uri\":", uri, b",", &text[k..]].concat())
                }
            }
        }
        6 => {
            // compressed geometry required
            let ext = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"][rng.random_range(0..2)];
            let k = text.iter().position(|&b| b == b'{')? + 1;
            Some(
                [
                    &text[..k],
                    format!("\"extensionsRequired\":[\"{ext}\"],\"extensionsUsed\":[\"{ext}\"],").as_bytes(),
                    &text[k..],
                ]
                .concat(),
            )
        }
        _ => {
            // a node that is its own child: a cycle
            swap(text, b"\"mesh\":0", b"\"mesh\":0,\"children\":[0]")
        }
    }
}

/// The binary damaged where the document says its data lies: a position to NaN, infinity or
/// an extreme, or an index past its primitive's vertices.
fn binary(bin: &mut [u8], doc: &Value, rng: &mut impl Rng) {
    let l = layout(doc);
    let put = |bin: &mut [u8], at: usize, bytes: &[u8]| {
        if let Some(dst) = bin.get_mut(at..at + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
    };
    if rng.random_bool(0.5) && !l.positions.is_empty() {
        let (offset, count, stride) = l.positions[rng.random_range(0..l.positions.len())];
        for _ in 0..rng.random_range(1..=3) {
            let at = offset + stride * rng.random_range(0..count.max(1)) + 4 * rng.random_range(0..3);
            let v = EXTREME_F32[rng.random_range(0..EXTREME_F32.len())];
            put(bin, at, &v.to_le_bytes());
        }
    } else if !l.indices.is_empty() {
        let k = rng.random_range(0..l.indices.len());
        let (offset, count, size) = l.indices[k];
        let vertices = l.vertices[k] as u64;
        let value = [vertices, vertices + 1, vertices + 1000, u64::MAX][rng.random_range(0..4)];
        let at = offset + size * rng.random_range(0..count.max(1));
        put(bin, at, &value.to_le_bytes()[..size]);
    }
}

/// A mutated copy of a glTF file (`glb`: a binary container) that reaches past the container and
/// the JSON parser where it can.
pub fn mutate(bytes: &mut Vec<u8>, glb_file: bool, rng: &mut impl Rng) {
    let op = rng.random_range(0..10);
    if op == 9 {
        *bytes = NOT_GLTF[rng.random_range(0..NOT_GLTF.len())].to_vec();
        return;
    }
    if glb_file {
        let Some((json, bin)) = glb_chunks(bytes).map(|(j, b)| (j.to_vec(), b.to_vec())) else {
            crate::mutate::json(bytes, rng);
            return;
        };
        match op {
            0 | 1 => {
                // the container's own fields: magic, version, total length, chunk lengths, types
                let fields = [0, 4, 8, 12, 16, 20 + json.len(), 24 + json.len()];
                let at = fields[rng.random_range(0..fields.len())];
                let v = EXTREME_INTS[rng.random_range(0..EXTREME_INTS.len())] as u32;
                if let Some(dst) = bytes.get_mut(at..at + 4) {
                    dst.copy_from_slice(&v.to_le_bytes());
                }
            }
            2..=4 => {
                let mut bin = bin;
                if let Ok(doc) = serde_json::from_slice::<Value>(&json) {
                    binary(&mut bin, &doc, rng);
                }
                *bytes = glb(&json, &bin);
            }
            _ => {
                let json = document(&json, rng).unwrap_or_else(|| {
                    let mut j = json.clone();
                    crate::mutate::json(&mut j, rng);
                    j
                });
                *bytes = glb(&json, &bin);
            }
        }
        return;
    }
    match (op, embedded(bytes)) {
        (0..=3, Some((at, mut bin))) => {
            if let Ok(doc) = serde_json::from_slice::<Value>(bytes) {
                binary(&mut bin, &doc, rng);
            }
            *bytes = embed(bytes, at, &bin);
        }
        _ => match document(bytes, rng) {
            Some(text) => *bytes = text,
            None => crate::mutate::json(bytes, rng),
        },
    }
}
