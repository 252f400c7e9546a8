//! Instancing: a mesh used in several places is stored once, in object space, and placed by
//! instance records (`kernel::scene::Instance`). Here are when a loader instances a mesh, the
//! record of a placement, and the world-space box the instances fill.

use super::transform::Transform;
use glam::{DMat4, Vec3};
use kernel::scene::{Instance, Triangle};

/// Fewest triangles a mesh used more than once needs to be instanced rather than flattened
/// into world space. An instance record (112 bytes) and the ray's map into object space cost
/// about what a couple of flattened triangles do (48 bytes each and their BVH share), so a tiny
/// mesh is cheaper flattened; from here on, instancing saves memory in proportion to the mesh.
pub const INSTANCE_MIN_TRIANGLES: usize = 16;

/// Most instances a scene may have: the GPU names an instance by its 24-bit custom index.
pub const MAX_INSTANCES: usize = 1 << 24;

/// The record of a placement of the mesh whose triangles start at `first_triangle`, by the
/// affine `transform`: both matrices (the inverse computed in f64, then rounded), their
/// infinity norms and the handedness.
pub fn instance_record(transform: &Transform, first_triangle: u32) -> Instance {
    let m: DMat4 = transform.matrix();
    let inv = m.inverse();
    let rows = |a: DMat4| -> [f32; 12] {
        let mut r = [0.0f32; 12];
        for i in 0..3 {
            let row = a.row(i);
            r[4 * i..4 * i + 4].copy_from_slice(&[
                row.x as f32,
                row.y as f32,
                row.z as f32,
                row.w as f32,
            ]);
        }
        r
    };
    let norm = |r: &[f32; 12]| {
        (0..3)
            .map(|i| r[4 * i].abs() + r[4 * i + 1].abs() + r[4 * i + 2].abs())
            .fold(0.0f32, f32::max)
    };
    let object_to_world = rows(m);
    let world_to_object = rows(inv);
    Instance {
        object_to_world,
        world_to_object,
        first_triangle,
        forward_norm: norm(&object_to_world),
        inverse_norm: norm(&world_to_object),
        handedness: if transform.mirrors() { -1.0 } else { 1.0 },
    }
}

/// The object-space box of `triangles`.
pub fn mesh_box(triangles: &[Triangle]) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in triangles {
        let p0 = Vec3::from(t.p0);
        for p in [p0, p0 + Vec3::from(t.edge1), p0 + Vec3::from(t.edge2)] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo, hi)
}

/// The world-space box of an object-space box `(lo, hi)` placed by `instance`: the box of its
/// eight corners mapped (`kernel::instance::point_to_world`).
pub fn instance_box(instance: &Instance, (lo, hi): (Vec3, Vec3)) -> (Vec3, Vec3) {
    let (mut wlo, mut whi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for corner in 0..8 {
        let c = Vec3::new(
            if corner & 1 == 0 { lo.x } else { hi.x },
            if corner & 2 == 0 { lo.y } else { hi.y },
            if corner & 4 == 0 { lo.z } else { hi.z },
        );
        let p = kernel::instance::point_to_world(instance, c);
        wlo = wlo.min(p);
        whi = whi.max(p);
    }
    (wlo, whi)
}

/// The world-space box of every instance (empty without instances): `mesh_boxes` are the
/// meshes' object-space boxes, `instance_meshes[i]` is instance i's mesh.
pub fn instances_box(
    mesh_boxes: &[(Vec3, Vec3)],
    instances: &[Instance],
    instance_meshes: &[u32],
) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (inst, &mesh) in instances.iter().zip(instance_meshes) {
        let (a, b) = instance_box(inst, mesh_boxes[mesh as usize]);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    (lo, hi)
}
