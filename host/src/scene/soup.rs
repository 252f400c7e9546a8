//! Triangles as a format reads them, before the builder places them in the tables: what an
//! OBJ or PLY file (`mesh`) and a glTF primitive (`gltf`) give `builder`.

/// Triangles as vertex positions, three per triangle, with their vertex normals, texture
/// coordinates and tangents where the file gives them (each list empty, or one entry per
/// triangle). A tangent is glTF's `TANGENT`: xyz along increasing u, w the bitangent's sign.
#[derive(Debug, Default, Clone)]
pub struct TriangleSoup {
    pub triangles: Vec<[[f32; 3]; 3]>,
    pub normals: Vec<[[f32; 3]; 3]>,
    pub uvs: Vec<[[f32; 2]; 3]>,
    pub tangents: Vec<[[f32; 4]; 3]>,
    /// Linear RGB vertex colours (glTF's `COLOR_0`), multiplying the base colour.
    pub colours: Vec<[[f32; 3]; 3]>,
    /// A second set of texture coordinates (glTF's `TEXCOORD_1`), for the textures that read it.
    pub uvs1: Vec<[[f32; 2]; 3]>,
}

impl TriangleSoup {
    /// Keeps the attribute lists only if every triangle has the attribute (a file that gives
    /// normals to some faces only is shaded flat).
    pub(crate) fn settle(mut self) -> Self {
        if self.normals.len() != self.triangles.len() {
            self.normals.clear();
        }
        if self.uvs.len() != self.triangles.len() {
            self.uvs.clear();
        }
        if self.tangents.len() != self.triangles.len() {
            self.tangents.clear();
        }
        if self.colours.len() != self.triangles.len() {
            self.colours.clear();
        }
        if self.uvs1.len() != self.triangles.len() {
            self.uvs1.clear();
        }
        self
    }
}
