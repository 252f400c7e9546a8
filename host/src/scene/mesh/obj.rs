//! OBJ meshes, read with `tobj`; materials (`mtllib`) are ignored.

use super::obj_indices::check_obj_face_indices;
use crate::scene::error::SceneError;
use crate::scene::soup::TriangleSoup;
use std::path::Path;

/// Parses OBJ text (`path` names the file in errors); materials (`mtllib`) are ignored.
pub fn parse_obj(path: &Path, bytes: &[u8]) -> Result<TriangleSoup, SceneError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    check_obj_face_indices(path, bytes)?;
    let mut reader = std::io::BufReader::new(bytes);
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default()))
        .map_err(|e| SceneError::new(path, None, "file", format!("malformed OBJ: {e}")))?;
    let mut soup = TriangleSoup::default();
    for model in &models {
        let m = &model.mesh;
        let vertex = |i: u32| -> Result<[f32; 3], SceneError> {
            let i = i as usize;
            let p = m.positions.get(3 * i..3 * i + 3).ok_or_else(|| {
                SceneError::new(
                    path,
                    None,
                    format!("object '{}' face index", model.name),
                    format!("vertex index {} out of range", i + 1),
                )
            })?;
            Ok([p[0], p[1], p[2]])
        };
        // Attributes are read only where every vertex has one: with these exact lengths, an
        // index `vertex` accepted is in range for them too.
        let has_normals = !m.normals.is_empty() && m.normals.len() == m.positions.len();
        let has_uvs = !m.texcoords.is_empty() && 3 * m.texcoords.len() == 2 * m.positions.len();
        for (k, f) in m.indices.as_chunks::<3>().0.iter().enumerate() {
            let face = format!("object '{}' face {}", model.name, k + 1);
            let tri = [vertex(f[0])?, vertex(f[1])?, vertex(f[2])?];
            check_finite(path, None, &face, &tri, "vertex coordinate")?;
            soup.triangles.push(tri);
            if has_normals {
                let n = f.map(|i| {
                    let i = 3 * i as usize;
                    [m.normals[i], m.normals[i + 1], m.normals[i + 2]]
                });
                check_finite(path, None, &face, &n, "normal")?;
                soup.normals.push(n);
            }
            if has_uvs {
                let t = f.map(|i| {
                    let i = 2 * i as usize;
                    [m.texcoords[i], m.texcoords[i + 1]]
                });
                check_finite(path, None, &face, &t, "texture coordinate")?;
                soup.uvs.push(t);
            }
        }
    }
    Ok(soup.settle())
}

/// An error naming `field` unless every component of a triangle's three `what`s (positions,
/// normals, texture coordinates) is finite.
pub(super) fn check_finite<const N: usize>(
    path: &Path,
    line: Option<usize>,
    field: &str,
    corners: &[[f32; N]; 3],
    what: &str,
) -> Result<(), SceneError> {
    if corners.iter().flatten().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(SceneError::new(
            path,
            line,
            field,
            format!("{what} is not a finite number"),
        ))
    }
}
