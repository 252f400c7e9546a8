//! glTF accessors read with every offset, stride and count checked against the buffer view and
//! buffer that hold them, in checked arithmetic, before a byte is read: a hostile file gets an
//! error naming the accessor, never a panic or an out-of-bounds read. (The `gltf` crate's own
//! reader trusts the counts: it computes `count - 1` and `stride * count` unchecked.)

use crate::scene::SceneError;
use gltf::accessor::{DataType, Dimensions};
use gltf::Accessor;
use std::path::Path;

/// The elements of one accessor: `count` elements of `size` bytes, `stride` bytes apart,
/// starting at the beginning of `bytes`.
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    size: usize,
    count: usize,
}

impl Elements<'_> {
    fn element(&self, i: usize) -> &[u8] {
        &self.bytes[i * self.stride..i * self.stride + self.size]
    }
}

/// An error about accessor `a` of file `path`.
pub(super) fn accessor_error(path: &Path, a: &Accessor, msg: impl Into<String>) -> SceneError {
    SceneError::new(path, None, format!("accessors[{}]", a.index()), msg)
}

/// The bytes of `a`'s elements, checked: a buffer view inside its buffer, the elements inside
/// the view, a stride no smaller than an element; sparse accessors and accessors without a
/// view are refused.
fn elements<'a>(
    path: &Path,
    a: &Accessor,
    buffers: &'a [gltf::buffer::Data],
) -> Result<Elements<'a>, SceneError> {
    let err = |msg: String| accessor_error(path, a, msg);
    if a.sparse().is_some() {
        return Err(err("sparse accessors are not supported".into()));
    }
    let Some(view) = a.view() else {
        return Err(err(
            "has no bufferView (all-zero accessors are not supported)".into(),
        ));
    };
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| err(format!("its buffer {} is missing", view.buffer().index())))?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= buffer.len())
        .ok_or_else(|| {
            err(format!(
                "bufferViews[{}] (bytes {}..+{}) lies outside its buffer of {} bytes",
                view.index(),
                view.offset(),
                view.length(),
                buffer.len()
            ))
        })?;
    let bytes = &buffer[view.offset()..view_end];
    let size = a.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(err(format!(
            "byteStride {stride} is smaller than an element ({size} bytes)"
        )));
    }
    let count = a.count();
    if count == 0 {
        return Ok(Elements {
            bytes: &[],
            stride,
            size,
            count,
        });
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(size))
        .and_then(|x| x.checked_add(a.offset()));
    match end {
        Some(end) if end <= bytes.len() => Ok(Elements {
            bytes: &bytes[a.offset()..end],
            stride,
            size,
            count,
        }),
        _ => Err(err(format!(
            "{count} elements of {size} bytes (stride {stride}, offset {}) do not fit in \
             bufferViews[{}] of {} bytes",
            a.offset(),
            view.index(),
            bytes.len()
        ))),
    }
}

fn f32_at(b: &[u8], k: usize) -> f32 {
    f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]])
}

/// N-component float vectors (POSITION and NORMAL: VEC3; TANGENT: VEC4, xyz and the
/// bitangent sign w), each finite.
pub(super) fn read_floats<const N: usize>(
    path: &Path,
    a: &Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<[f32; N]>, SceneError> {
    let (dimensions, name) = match N {
        3 => (Dimensions::Vec3, "VEC3"),
        4 => (Dimensions::Vec4, "VEC4"),
        _ => unreachable!("POSITION, NORMAL and TANGENT are VEC3 or VEC4"),
    };
    if a.data_type() != DataType::F32 || a.dimensions() != dimensions {
        return Err(accessor_error(
            path,
            a,
            format!(
                "is {:?} {:?}: expected {name} of FLOAT",
                a.dimensions(),
                a.data_type()
            ),
        ));
    }
    read_finite(path, a, buffers, f32_at)
}

/// Texture coordinates (TEXCOORD_n): float, or normalised unsigned bytes or shorts.
pub(super) fn read_uv(
    path: &Path,
    a: &Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<[f32; 2]>, SceneError> {
    let bad = || {
        accessor_error(
            path,
            a,
            format!(
                "is {:?} {:?}{}: texture coordinates are VEC2 of FLOAT, or of normalized \
                 UNSIGNED_BYTE or UNSIGNED_SHORT",
                a.dimensions(),
                a.data_type(),
                if a.normalized() { " normalized" } else { "" }
            ),
        )
    };
    if a.dimensions() != Dimensions::Vec2 {
        return Err(bad());
    }
    let read: fn(&[u8], usize) -> f32 = match (a.data_type(), a.normalized()) {
        (DataType::F32, _) => f32_at,
        (DataType::U8, true) => |b, k| b[k] as f32 / 255.0,
        (DataType::U16, true) => {
            |b, k| u16::from_le_bytes([b[2 * k], b[2 * k + 1]]) as f32 / 65535.0
        }
        _ => return Err(bad()),
    };
    read_finite(path, a, buffers, read)
}

/// Vertex colours (COLOR_n): VEC3 or VEC4 (alpha dropped) of float, or of normalised
/// unsigned bytes or shorts; linear RGB.
pub(super) fn read_colour(
    path: &Path,
    a: &Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<[f32; 3]>, SceneError> {
    let read: fn(&[u8], usize) -> f32 = match (a.data_type(), a.normalized()) {
        (DataType::F32, _) => f32_at,
        (DataType::U8, true) => |b, k| b[k] as f32 / 255.0,
        (DataType::U16, true) => {
            |b, k| u16::from_le_bytes([b[2 * k], b[2 * k + 1]]) as f32 / 65535.0
        }
        _ => {
            return Err(accessor_error(
                path,
                a,
                format!(
                    "is {:?} {:?}{}: vertex colours are VEC3 or VEC4 of FLOAT, or of normalized \
                     UNSIGNED_BYTE or UNSIGNED_SHORT",
                    a.dimensions(),
                    a.data_type(),
                    if a.normalized() { " normalized" } else { "" }
                ),
            ))
        }
    };
    let colours = match a.dimensions() {
        Dimensions::Vec3 => read_finite::<3>(path, a, buffers, read)?,
        Dimensions::Vec4 => read_finite::<4>(path, a, buffers, read)?
            .into_iter()
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        other => {
            return Err(accessor_error(
                path,
                a,
                format!("is {other:?}: vertex colours are VEC3 or VEC4"),
            ))
        }
    };
    if let Some((i, c)) = colours
        .iter()
        .enumerate()
        .find(|(_, c)| !c.iter().all(|&x| (0.0..=1.0).contains(&x)))
    {
        return Err(accessor_error(
            path,
            a,
            format!("element {i} is {c:?}: colours lie within 0..=1"),
        ));
    }
    Ok(colours)
}

/// The N-component elements of accessor `a`, component k of an element's bytes `b` being
/// `read(b, k)`, each component finite.
fn read_finite<const N: usize>(
    path: &Path,
    a: &Accessor,
    buffers: &[gltf::buffer::Data],
    read: fn(&[u8], usize) -> f32,
) -> Result<Vec<[f32; N]>, SceneError> {
    let e = elements(path, a, buffers)?;
    (0..e.count)
        .map(|i| {
            let b = e.element(i);
            let v: [f32; N] = std::array::from_fn(|k| read(b, k));
            if v.iter().all(|c| c.is_finite()) {
                Ok(v)
            } else {
                Err(accessor_error(
                    path,
                    a,
                    format!("element {i} is {v:?}: not finite"),
                ))
            }
        })
        .collect()
}

/// Vertex indices: unsigned bytes, shorts or ints, each below `vertex_count`.
pub(super) fn read_indices(
    path: &Path,
    a: &Accessor,
    buffers: &[gltf::buffer::Data],
    vertex_count: usize,
) -> Result<Vec<u32>, SceneError> {
    if a.dimensions() != Dimensions::Scalar {
        return Err(accessor_error(path, a, "indices must be SCALAR"));
    }
    let read: fn(&[u8]) -> u32 = match a.data_type() {
        DataType::U8 => |b| b[0] as u32,
        DataType::U16 => |b| u16::from_le_bytes([b[0], b[1]]) as u32,
        DataType::U32 => |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        other => {
            return Err(accessor_error(
                path,
                a,
                format!("indices are {other:?}: expected an unsigned integer type"),
            ))
        }
    };
    let e = elements(path, a, buffers)?;
    (0..e.count)
        .map(|i| {
            let index = read(e.element(i));
            if (index as usize) < vertex_count {
                Ok(index)
            } else {
                Err(accessor_error(
                    path,
                    a,
                    format!("index {i} is {index}, beyond the {vertex_count} vertices"),
                ))
            }
        })
        .collect()
}
