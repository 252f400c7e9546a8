//! PLY meshes, ASCII and binary, read here: `vertex` elements with x, y, z (and optional
//! normals and texture coordinates) and `face` elements with a vertex-index list.

use crate::scene::error::SceneError;
use crate::scene::soup::TriangleSoup;
use std::path::Path;

/// Largest element count a PLY header may declare; larger headers are rejected before any
/// allocation (a hostile header must not reserve unbounded memory).
pub const MAX_PLY_ELEMENTS: usize = 1 << 28;

#[derive(Clone, Copy, Debug, PartialEq)]
enum PlyFormat {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum PlyScalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl PlyScalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
enum PlyProperty {
    Scalar(String, PlyScalar),
    List(String, PlyScalar, PlyScalar),
}

#[derive(Clone, Debug)]
struct PlyElement {
    name: String,
    count: usize,
    properties: Vec<PlyProperty>,
}

/// Reads the values of a PLY body, ASCII (tokens, tracking lines) or binary.
struct PlyReader<'a> {
    path: &'a Path,
    format: PlyFormat,
    body: &'a [u8],
    pos: usize,
    line: usize,
}

impl PlyReader<'_> {
    fn err(&self, field: &str, msg: impl Into<String>) -> SceneError {
        let line = (self.format == PlyFormat::Ascii).then_some(self.line);
        SceneError::new(self.path, line, field, msg)
    }

    fn read(&mut self, ty: PlyScalar, field: &str) -> Result<f64, SceneError> {
        match self.format {
            PlyFormat::Ascii => {
                // skip spaces; count newlines
                while self.pos < self.body.len() && self.body[self.pos].is_ascii_whitespace() {
                    if self.body[self.pos] == b'\n' {
                        self.line += 1;
                    }
                    self.pos += 1;
                }
                let start = self.pos;
                while self.pos < self.body.len() && !self.body[self.pos].is_ascii_whitespace() {
                    self.pos += 1;
                }
                if start == self.pos {
                    return Err(self.err(field, "unexpected end of file"));
                }
                let token = std::str::from_utf8(&self.body[start..self.pos])
                    .map_err(|_| self.err(field, "value is not text"))?;
                token
                    .parse::<f64>()
                    .map_err(|_| self.err(field, format!("'{token}' is not a number")))
            }
            PlyFormat::BinaryLe | PlyFormat::BinaryBe => {
                let n = ty.size();
                let bytes = self
                    .body
                    .get(self.pos..self.pos + n)
                    .ok_or_else(|| self.err(field, "unexpected end of file"))?;
                self.pos += n;
                let mut b = [0u8; 8];
                b[..n].copy_from_slice(bytes);
                if self.format == PlyFormat::BinaryBe {
                    b[..n].reverse();
                }
                Ok(match ty {
                    PlyScalar::I8 => b[0] as i8 as f64,
                    PlyScalar::U8 => b[0] as f64,
                    PlyScalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    PlyScalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    PlyScalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    PlyScalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    PlyScalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    PlyScalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }
}

/// Parses a PLY file: `vertex` elements with x, y, z and `face` elements with a
/// `vertex_indices` (or `vertex_index`) list; polygons are fanned into triangles. Every count is
/// checked against the bytes actually present before memory is reserved for it.
pub fn parse_ply(path: &Path, bytes: &[u8]) -> Result<TriangleSoup, SceneError> {
    let header_err = |line: usize, msg: String| SceneError::new(path, Some(line), "header", msg);
    // Header: ASCII lines up to "end_header".
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<PlyElement> = Vec::new();
    loop {
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .ok_or_else(|| header_err(line_no + 1, "header has no end_header line".into()))?;
        let raw = &bytes[pos..pos + end];
        pos += end + 1;
        line_no += 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| header_err(line_no, "header line is not UTF-8 text".into()))?
            .trim_end_matches('\r');
        let words: Vec<&str> = line.split_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(header_err(
                    1,
                    "not a PLY file (first line must be 'ply')".into(),
                ));
            }
            continue;
        }
        match words.as_slice() {
            [] => {}
            ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _version] => {
                format = Some(match *f {
                    "ascii" => PlyFormat::Ascii,
                    "binary_little_endian" => PlyFormat::BinaryLe,
                    "binary_big_endian" => PlyFormat::BinaryBe,
                    other => return Err(header_err(line_no, format!("unknown format '{other}'"))),
                });
            }
            ["element", name, count] => {
                let count: usize = count
                    .parse()
                    .map_err(|_| header_err(line_no, format!("bad element count '{count}'")))?;
                if count > MAX_PLY_ELEMENTS {
                    return Err(header_err(
                        line_no,
                        format!("element count {count} exceeds the limit {MAX_PLY_ELEMENTS}"),
                    ));
                }
                elements.push(PlyElement {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count_ty, item_ty, name] => {
                let c = PlyScalar::parse(count_ty)
                    .ok_or_else(|| header_err(line_no, format!("unknown type '{count_ty}'")))?;
                let i = PlyScalar::parse(item_ty)
                    .ok_or_else(|| header_err(line_no, format!("unknown type '{item_ty}'")))?;
                elements
                    .last_mut()
                    .ok_or_else(|| header_err(line_no, "property before any element".into()))?
                    .properties
                    .push(PlyProperty::List(name.to_string(), c, i));
            }
            ["property", ty, name] => {
                let t = PlyScalar::parse(ty)
                    .ok_or_else(|| header_err(line_no, format!("unknown type '{ty}'")))?;
                elements
                    .last_mut()
                    .ok_or_else(|| header_err(line_no, "property before any element".into()))?
                    .properties
                    .push(PlyProperty::Scalar(name.to_string(), t));
            }
            ["end_header"] => break,
            _ => {
                return Err(header_err(
                    line_no,
                    format!("unrecognised header line '{line}'"),
                ))
            }
        }
    }
    let format = format.ok_or_else(|| header_err(line_no, "no format line".into()))?;
    let mut reader = PlyReader {
        path,
        format,
        body: &bytes[pos..],
        pos: 0,
        line: line_no + 1,
    };
    // Each value takes at least one byte (binary) or two (ASCII: digit and separator), so a
    // declared count larger than the remaining bytes allow is an error before any allocation.
    let min_value_bytes = if format == PlyFormat::Ascii { 2 } else { 1 };

    let mut vertices: Vec<[f32; 3]> = Vec::new();
    let mut vertex_normals: Vec<[f32; 3]> = Vec::new();
    let mut vertex_uvs: Vec<[f32; 2]> = Vec::new();
    let mut soup = TriangleSoup::default();
    for element in &elements {
        let min_bytes = element
            .count
            .saturating_mul(element.properties.len().max(1))
            .saturating_mul(min_value_bytes);
        if !element.properties.is_empty() && min_bytes > reader.body.len() - reader.pos + 1 {
            return Err(reader.err(
                &format!("element {}", element.name),
                format!("declares {} items but the file is too short", element.count),
            ));
        }
        match element.name.as_str() {
            "vertex" => {
                let idx = |n: &str| {
                    element
                        .properties
                        .iter()
                        .position(|p| matches!(p, PlyProperty::Scalar(name, _) if name == n))
                };
                let (ix, iy, iz) = match (idx("x"), idx("y"), idx("z")) {
                    (Some(x), Some(y), Some(z)) => (x, y, z),
                    _ => {
                        return Err(SceneError::new(
                            path,
                            None,
                            "element vertex",
                            "vertex needs float properties x, y and z",
                        ))
                    }
                };
                // Optional attributes: a normal, texture coordinates under any of their usual
                // names.
                let normal_at = match (idx("nx"), idx("ny"), idx("nz")) {
                    (Some(x), Some(y), Some(z)) => Some([x, y, z]),
                    _ => None,
                };
                let uv_at = [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
                    .iter()
                    .find_map(|(a, b)| Some([idx(a)?, idx(b)?]));
                vertices.reserve(element.count);
                for v in 0..element.count {
                    let mut values = [0.0f64; 16];
                    let mut p = [0.0f32; 3];
                    let field = format!("vertex {v}");
                    for (k, prop) in element.properties.iter().enumerate() {
                        let value = read_property(&mut reader, prop, &field)?;
                        if k < values.len() {
                            values[k] = value;
                        }
                        if k == ix {
                            p[0] = value as f32;
                        } else if k == iy {
                            p[1] = value as f32;
                        } else if k == iz {
                            p[2] = value as f32;
                        }
                    }
                    if !p.iter().all(|c| c.is_finite()) {
                        return Err(reader.err(&field, "vertex coordinate is not a finite number"));
                    }
                    vertices.push(p);
                    let attribute = |at: &[usize]| -> Option<Vec<f32>> {
                        at.iter()
                            .map(|&k| values.get(k).map(|&x| x as f32))
                            .collect()
                    };
                    if let Some(n) = normal_at.and_then(|at| attribute(&at)) {
                        if !n.iter().all(|c| c.is_finite()) {
                            return Err(reader.err(&field, "normal is not a finite number"));
                        }
                        vertex_normals.push([n[0], n[1], n[2]]);
                    }
                    if let Some(t) = uv_at.and_then(|at| attribute(&at)) {
                        if !t.iter().all(|c| c.is_finite()) {
                            return Err(
                                reader.err(&field, "texture coordinate is not a finite number")
                            );
                        }
                        vertex_uvs.push([t[0], t[1]]);
                    }
                }
            }
            "face" => {
                for f in 0..element.count {
                    let field = format!("face {f}");
                    for prop in &element.properties {
                        match prop {
                            PlyProperty::List(name, count_ty, item_ty)
                                if name == "vertex_indices" || name == "vertex_index" =>
                            {
                                let n = reader.read(*count_ty, &field)?;
                                if !(n >= 0.0) || n > 1024.0 || n.fract() != 0.0 {
                                    return Err(
                                        reader.err(&field, format!("bad vertex count {n} in face"))
                                    );
                                }
                                let n = n as usize;
                                let mut polygon = [0usize; 1024];
                                for slot in polygon.iter_mut().take(n) {
                                    let i = reader.read(*item_ty, &field)?;
                                    if !(i >= 0.0) || i.fract() != 0.0 || i >= vertices.len() as f64
                                    {
                                        return Err(reader.err(
                                            &field,
                                            format!(
                                                "vertex index {i} out of range (0..{})",
                                                vertices.len()
                                            ),
                                        ));
                                    }
                                    *slot = i as usize;
                                }
                                if n < 3 {
                                    return Err(reader.err(
                                        &field,
                                        format!("face has {n} vertices, needs at least 3"),
                                    ));
                                }
                                for k in 1..n - 1 {
                                    let corners = [polygon[0], polygon[k], polygon[k + 1]];
                                    soup.triangles.push(corners.map(|i| vertices[i]));
                                    if vertex_normals.len() == vertices.len() {
                                        soup.normals.push(corners.map(|i| vertex_normals[i]));
                                    }
                                    if vertex_uvs.len() == vertices.len() {
                                        soup.uvs.push(corners.map(|i| vertex_uvs[i]));
                                    }
                                }
                            }
                            other => {
                                read_property(&mut reader, other, &field)?;
                            }
                        }
                    }
                }
            }
            // An element without properties has nothing to read, whatever its count (looping
            // over a declared 2^28 of them was the fuzzer's slowest input).
            _ if element.properties.is_empty() => {}
            _ => {
                for i in 0..element.count {
                    let field = format!("{} {i}", element.name);
                    for prop in &element.properties {
                        read_property(&mut reader, prop, &field)?;
                    }
                }
            }
        }
    }
    Ok(soup.settle())
}

/// Reads one property, returning its value (lists: their length, items skipped).
fn read_property(
    reader: &mut PlyReader<'_>,
    prop: &PlyProperty,
    field: &str,
) -> Result<f64, SceneError> {
    match prop {
        PlyProperty::Scalar(_, ty) => reader.read(*ty, field),
        PlyProperty::List(_, count_ty, item_ty) => {
            let n = reader.read(*count_ty, field)?;
            if !(n >= 0.0) || n.fract() != 0.0 || n > (reader.body.len() - reader.pos) as f64 {
                return Err(reader.err(field, format!("bad list length {n}")));
            }
            for _ in 0..n as usize {
                reader.read(*item_ty, field)?;
            }
            Ok(n)
        }
    }
}
