//! What a device can hold: the limits a scene's tables and acceleration structures must fit
//! (`VkPhysicalDeviceLimits::maxStorageBufferRange`, and the acceleration-structure
//! properties' primitive and instance counts), checked before anything is uploaded, so a scene
//! too big for the device is an error naming the table, not a truncated binding or a driver
//! failure mid-build.

use crate::scene::Scene;
use anyhow::{bail, Result};

/// The limits of one device that bound a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceLimits {
    /// Largest storage-buffer binding, in bytes (`maxStorageBufferRange`).
    pub max_storage_buffer_range: u64,
    /// Most primitives in one bottom-level acceleration structure (`maxPrimitiveCount`).
    pub max_primitive_count: u64,
    /// Most instances in the top-level acceleration structure (`maxInstanceCount`).
    pub max_instance_count: u64,
}

/// Err where `scene` does not fit `limits`: a table (as `Scene::table_bytes` sizes it, and the
/// parameters) beyond the storage-buffer range, a BLAS (a world-space triangle group, an
/// instanced mesh, the spheres) beyond the primitive count, or more TLAS instances than allowed.
/// The message names what overflows, by how much, and says the CPU backend has no such limit.
pub fn check_scene_fits(scene: &Scene, limits: &DeviceLimits) -> Result<()> {
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    for (name, bytes) in scene.table_bytes() {
        let bytes = bytes as u64;
        if bytes > limits.max_storage_buffer_range {
            bail!(
                "the {name} table takes {:.1} MiB, beyond this device's largest storage buffer \
                 ({:.1} MiB, maxStorageBufferRange); render with --backend cpu",
                mib(bytes),
                mib(limits.max_storage_buffer_range)
            );
        }
    }
    let groups = scene
        .triangle_groups
        .iter()
        .chain(&scene.meshes)
        .map(|g| (g.name.as_str(), g.range.len() as u64));
    let spheres = (!scene.spheres.is_empty()).then_some(("spheres", scene.spheres.len() as u64));
    for (name, count) in groups.chain(spheres) {
        if count > limits.max_primitive_count {
            bail!(
                "{name} has {count} primitives, beyond this device's {} per acceleration \
                 structure (maxPrimitiveCount); render with --backend cpu",
                limits.max_primitive_count
            );
        }
    }
    let tlas = scene.triangle_groups.len() as u64
        + !scene.spheres.is_empty() as u64
        + scene.instances.len() as u64;
    if tlas > limits.max_instance_count {
        bail!(
            "the scene needs {tlas} top-level instances, beyond this device's {} \
             (maxInstanceCount); render with --backend cpu",
            limits.max_instance_count
        );
    }
    Ok(())
}
