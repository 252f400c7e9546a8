//! glTF 2.0 binary files (.glb) written by the tests: accessors, buffer views and images in one
//! binary chunk, the JSON built with `serde_json`. Enough of the format to state a scene and to
//! break it on purpose (the hostile-file tests edit the JSON).

use serde_json::{json, Value};

/// A glTF document being written: its JSON and its binary buffer.
pub struct GltfWriter {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Default for GltfWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl GltfWriter {
    /// An empty document (asset version 2.0, one buffer).
    pub fn new() -> Self {
        Self {
            json: json!({ "asset": { "version": "2.0" }, "buffers": [ { "byteLength": 0 } ] }),
            bin: Vec::new(),
        }
    }

    /// Appends `value` to the top-level array `key`; its index.
    pub fn push(&mut self, key: &str, value: Value) -> usize {
        if !self.json[key].is_array() {
            self.json[key] = json!([]);
        }
        let array = self.json[key].as_array_mut().expect("an array");
        array.push(value);
        array.len() - 1
    }

    /// A buffer view of `bytes` (4-byte aligned in the binary chunk); its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.json["buffers"][0]["byteLength"] = json!(self.bin.len());
        self.push(
            "bufferViews",
            json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() }),
        )
    }

    /// A FLOAT accessor of `kind` ("VEC2", "VEC3") over `data`; its index.
    pub fn floats(&mut self, data: &[f32], kind: &str) -> usize {
        let width = match kind {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            other => panic!("no accessor type {other}"),
        };
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.push(
            "accessors",
            json!({ "bufferView": view, "componentType": 5126, "count": data.len() / width,
                    "type": kind }),
        )
    }

    /// A POSITION accessor with the min and max the specification requires; its index.
    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let a = self.floats(&p.concat(), "VEC3");
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for v in p {
            for c in 0..3 {
                lo[c] = lo[c].min(v[c]);
                hi[c] = hi[c].max(v[c]);
            }
        }
        self.json["accessors"][a]["min"] = json!(lo);
        self.json["accessors"][a]["max"] = json!(hi);
        a
    }

    /// An UNSIGNED_INT index accessor; its index.
    pub fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.push(
            "accessors",
            json!({ "bufferView": view, "componentType": 5125, "count": data.len(),
                    "type": "SCALAR" }),
        )
    }

    /// An image of PNG bytes in the binary chunk and a texture of it (default sampler: repeat);
    /// the texture's index.
    pub fn png_texture(&mut self, png: &[u8]) -> usize {
        let view = self.view(png);
        let image = self.push(
            "images",
            json!({ "bufferView": view, "mimeType": "image/png" }),
        );
        self.push("textures", json!({ "source": image }))
    }

    /// A mesh of one triangle primitive (positions, optional normals and texture coordinates,
    /// indices) with material `material`; the mesh's index.
    pub fn mesh(
        &mut self,
        positions: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        uvs: Option<&[[f32; 2]]>,
        indices: &[u32],
        material: Option<usize>,
    ) -> usize {
        let p = self.positions(positions);
        let mut attributes = json!({ "POSITION": p });
        if let Some(n) = normals {
            attributes["NORMAL"] = json!(self.floats(&n.concat(), "VEC3"));
        }
        if let Some(t) = uvs {
            attributes["TEXCOORD_0"] = json!(self.floats(&t.concat(), "VEC2"));
        }
        let i = self.indices(indices);
        let mut primitive = json!({ "attributes": attributes, "indices": i });
        if let Some(m) = material {
            primitive["material"] = json!(m);
        }
        self.push("meshes", json!({ "primitives": [primitive] }))
    }

    /// The default scene: a node of mesh `mesh` and a perspective camera (yfov 0.9, aspect
    /// 4:3) at (0, 0, `eye_z`) looking down -z.
    pub fn scene_of(&mut self, mesh: usize, eye_z: f32) {
        let cam = self.push(
            "cameras",
            json!({ "type": "perspective",
                    "perspective": { "yfov": 0.9, "aspectRatio": 1.3333, "znear": 0.1 } }),
        );
        let mesh_node = self.push("nodes", json!({ "mesh": mesh }));
        let camera_node = self.push(
            "nodes",
            json!({ "camera": cam, "translation": [0.0, 0.0, eye_z] }),
        );
        self.push("scenes", json!({ "nodes": [mesh_node, camera_node] }));
    }

    /// The document as a .glb file: header, JSON chunk (space padded), binary chunk (zero
    /// padded).
    pub fn glb(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.json).expect("JSON");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }
}
