//! The tangent frame of a normal-mapped triangle: the direction in which its texture's u grows
//! across it, and which way its v grows relative to the normal (`kernel::surface::mapped_normal`
//! reads it from the record `ShadingTriangle::tangent_frame` makes).
//!
//! The partial derivatives of position in (u, v) over a triangle follow pbrt-v4
//! (`Triangle::InteractionFromIntersection`; Pharr, Jakob, Humphreys, *Physically Based
//! Rendering*, 4th ed., section 6.5.3): with duv02 = uv0 - uv2, duv12 = uv1 - uv2 and
//! dp02 = p0 - p2, dp12 = p1 - p2, the linear map (u, v) -> p gives
//! dp/du = (duv12.v dp02 - duv02.v dp12) / det and dp/dv = (duv02.u dp12 - duv12.u dp02) / det,
//! det = duv02.u duv12.v - duv02.v duv12.u. The tangent is dp/du; the sign is +1 where
//! (N x dp/du) . dp/dv > 0 (v grows toward N x T, the image's up: glTF's bitangent with
//! `TANGENT.w` = +1), else -1 (a mirrored parametrisation).
//!
//! That is one tangent per triangle, for meshes without vertex normals or texture coordinates.
//! A normal-mapped mesh that has both but no tangents of its own (a glTF mesh without
//! `TANGENT`, any OBJ or PLY mesh) gets MikkTSpace's vertex tangents instead
//! ([`mikktspace_tangents`]), as the glTF specification asks and Blender computes them: the tangents of the triangles around a vertex, averaged (Mikkelsen 2008,
//! "Simulation of Wrinkled Surfaces Revisited"), so a curved mesh's mapped normal shows no
//! facets (docs/gltf.md).

use super::soup::TriangleSoup;
use kernel::frame::orthonormal_basis;

/// MikkTSpace tangents of `soup`'s triangles, one per corner, as glTF's `TANGENT` holds them (xyz
/// along increasing u, w the bitangent's sign), from its positions, vertex normals and texture
/// coordinates (the soup's, v up, so the sign is the one [`face_tangent`] would give). None
/// where the soup lacks normals or coordinates, or the generator fails.
pub fn mikktspace_tangents(soup: &TriangleSoup) -> Option<Vec<[[f32; 4]; 3]>> {
    struct Corners<'a> {
        soup: &'a TriangleSoup,
        tangents: Vec<[[f32; 4]; 3]>,
    }
    impl mikktspace::Geometry for Corners<'_> {
        fn num_faces(&self) -> usize {
            self.soup.triangles.len()
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.soup.triangles[face][vert]
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.soup.normals[face][vert]
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            self.soup.uvs[face][vert]
        }
        fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
            self.tangents[face][vert] = tangent;
        }
    }
    let n = soup.triangles.len();
    if n == 0 || soup.normals.len() != n || soup.uvs.len() != n {
        return None;
    }
    let mut corners = Corners {
        soup,
        tangents: vec![[[0.0; 4]; 3]; n],
    };
    mikktspace::generate_tangents(&mut corners).then_some(corners.tangents)
}

/// The unit tangent dp/du of the triangle `p` with texture coordinates `uv`, and the
/// bitangent sign, for geometric normal `normal` (unit). Where (u, v) does not span the
/// triangle (coincident or collinear texture coordinates: det = 0) there is no dp/du; any unit
/// vector perpendicular to `normal` serves, with sign +1 (the map then reads one texel, so
/// the frame's rotation about N matters only as much as the texel tilts).
pub fn face_tangent(p: [glam::Vec3; 3], uv: [[f32; 2]; 3], normal: glam::Vec3) -> ([f32; 3], f32) {
    let p = p.map(|v| v.as_dvec3());
    let uv = uv.map(|t| [t[0] as f64, t[1] as f64]);
    let n = normal.as_dvec3();
    let (duv02, duv12) = (
        [uv[0][0] - uv[2][0], uv[0][1] - uv[2][1]],
        [uv[1][0] - uv[2][0], uv[1][1] - uv[2][1]],
    );
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02[0] * duv12[1] - duv02[1] * duv12[0];
    let scale = (duv02[0].abs() + duv02[1].abs()) * (duv12[0].abs() + duv12[1].abs());
    if det.abs() > 1e-12 * scale && det.is_finite() {
        let dpdu = (duv12[1] * dp02 - duv02[1] * dp12) / det;
        let dpdv = (duv02[0] * dp12 - duv12[0] * dp02) / det;
        let t = dpdu - n * n.dot(dpdu);
        if t.length() > 0.0 && t.is_finite() {
            let sign = if n.cross(t).dot(dpdv) < 0.0 {
                -1.0
            } else {
                1.0
            };
            return (t.normalize().as_vec3().to_array(), sign);
        }
    }
    (orthonormal_basis(normal).0.to_array(), 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn tangent_follows_u_and_the_sign_follows_v() {
        // A quad's half in the plane z = 0, u along +x, v along +y: T = +x, N x T = +y = dp/dv.
        let p = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        let (t, s) = face_tangent(p, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], Vec3::Z);
        assert_eq!((t, s), ([1.0, 0.0, 0.0], 1.0));
        // v mirrored (grows along -y): the same tangent, sign -1.
        let (t, s) = face_tangent(p, [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]], Vec3::Z);
        assert_eq!((t, s), ([1.0, 0.0, 0.0], -1.0));
        // u along the third vertex's direction, rotated parametrisation: T = +y.
        let (t, s) = face_tangent(p, [[0.0, 0.0], [0.0, -1.0], [1.0, 0.0]], Vec3::Z);
        assert!((Vec3::from(t) - Vec3::Y).length() < 1e-6, "{t:?}");
        assert_eq!(s, 1.0);
    }

    #[test]
    fn degenerate_coordinates_give_some_perpendicular_unit_tangent() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.6, 0.0, 0.8)] {
            let (t, s) = face_tangent(p, [[0.5, 0.5]; 3], n);
            let t = Vec3::from(t);
            assert!(
                (t.length() - 1.0).abs() < 1e-6 && t.dot(n).abs() < 1e-6,
                "{t} for {n}"
            );
            assert_eq!(s, 1.0);
        }
    }
}
