//! A glTF node's perspective camera, and the camera that frames a file without one.

use super::import::Import;
use crate::scene::builder::SceneTables;
use crate::scene::instancing::instances_box;
use crate::scene::limits::MAX_IMAGE_SIDE;
use crate::scene::{CameraDesc, SceneError};
use glam::{DMat4, DVec4, Vec3};

/// Image height of a scene whose glTF camera gives an aspect ratio (width follows from it), and
/// the 1280 x 720 of one that gives none.
pub const IMAGE_HEIGHT: u32 = 720;
pub const IMAGE_WIDTH: u32 = 1280;

/// A perspective camera of the file, placed by its node.
#[derive(Clone, Debug)]
pub struct GltfCamera {
    pub name: String,
    pub desc: CameraDesc,
}

impl Import<'_> {
    /// Camera `camera` of `node` at `world`: perspective cameras only (orthographic ones are
    /// noted and skipped).
    pub(super) fn camera(
        &mut self,
        node: &gltf::Node,
        camera: &gltf::Camera,
        world: DMat4,
    ) -> Result<Option<GltfCamera>, SceneError> {
        let name = camera
            .name()
            .map_or_else(|| format!("cameras[{}]", camera.index()), str::to_string);
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            self.note(format!("camera '{name}' is orthographic: skipped"));
            return Ok(None);
        };
        let err = |msg: String| {
            SceneError::new(
                &self.path,
                None,
                format!("cameras[{}]", camera.index()),
                msg,
            )
        };
        let vfov = p.yfov().to_degrees();
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(err(format!("yfov {} is not in (0, pi)", p.yfov())));
        }
        let (width, height) = match p.aspect_ratio() {
            Some(a) => {
                let w = (a as f64 * IMAGE_HEIGHT as f64).round();
                if !(w >= 1.0 && w <= MAX_IMAGE_SIDE as f64) {
                    return Err(err(format!("aspectRatio {a} gives no image width")));
                }
                (w as u32, IMAGE_HEIGHT)
            }
            None => (IMAGE_WIDTH, IMAGE_HEIGHT),
        };
        let eye = (world * DVec4::W).truncate();
        let forward = (world * DVec4::new(0.0, 0.0, -1.0, 0.0)).truncate();
        let up = (world * DVec4::Y).truncate();
        if !(forward.length() > 0.0 && up.cross(forward).length() > 0.0) || !eye.is_finite() {
            return Err(SceneError::new(
                &self.path,
                None,
                format!("nodes[{}]", node.index()),
                "its transform leaves the camera no viewing direction",
            ));
        }
        let forward = forward.normalize();
        Ok(Some(GltfCamera {
            name,
            desc: CameraDesc {
                eye: eye.as_vec3(),
                look_at: (eye + forward).as_vec3(),
                up: up.normalize().as_vec3(),
                vfov_degrees: vfov,
                width,
                height,
                aperture: 0.0,
                focus_distance: 1.0,
            },
        }))
    }
}

/// A camera that sees the whole scene from +z (up +y, 40 degrees vertical field of view,
/// 1280 x 720): for files without a perspective camera. `None` without triangles.
pub(super) fn framing_camera(tables: &SceneTables) -> Option<CameraDesc> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in &tables.triangles {
        let p0 = Vec3::from(t.p0);
        for p in [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let (ilo, ihi) = instances_box(
        &tables.mesh_boxes,
        &tables.instances,
        &tables.instance_meshes,
    );
    (lo, hi) = (lo.min(ilo), hi.max(ihi));
    if !(lo.x <= hi.x) {
        return None;
    }
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let vfov: f32 = 40.0;
    let distance = 1.1 * radius / (0.5 * vfov.to_radians()).sin();
    Some(CameraDesc {
        eye: centre + Vec3::Z * distance,
        look_at: centre,
        up: Vec3::Y,
        vfov_degrees: vfov,
        width: IMAGE_WIDTH,
        height: IMAGE_HEIGHT,
        aperture: 0.0,
        focus_distance: distance,
    })
}
