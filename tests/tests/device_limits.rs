//! A scene too big for the GPU is an error naming what overflows, before anything is uploaded
//! (`twinpath::vulkan::limits`): the storage-buffer range of a table, the primitives of one
//! acceleration structure, the top-level instances. Checked against made-up limits, and the
//! real device's limits (lavapipe here) hold the shipped instancing scene.

use twinpath::scene::SceneFile;
use twinpath::vulkan::limits::{check_scene_fits, DeviceLimits};
use twinpath_tests::repo_root;

const ROOMY: DeviceLimits = DeviceLimits {
    max_storage_buffer_range: 1 << 31,
    max_primitive_count: 1 << 29,
    max_instance_count: 1 << 24,
};

#[test]
fn each_limit_is_checked_and_named() {
    let scene = SceneFile::load(&repo_root().join("scenes/instances.toml")).unwrap();
    check_scene_fits(&scene.scene, &ROOMY).unwrap();
    let err = |limits: DeviceLimits| {
        check_scene_fits(&scene.scene, &limits)
            .unwrap_err()
            .to_string()
    };
    // The environment map's table (2.0 MiB) is the largest.
    let e = err(DeviceLimits {
        max_storage_buffer_range: 1 << 20,
        ..ROOMY
    });
    assert!(
        e.contains("the environment table takes 2.0 MiB") && e.contains("--backend cpu"),
        "{e}"
    );
    // The torus mesh has 2304 triangles, the sphere mesh 1280.
    let e = err(DeviceLimits {
        max_primitive_count: 2000,
        ..ROOMY
    });
    assert!(e.contains("torus_smooth.ply has 2304 primitives"), "{e}");
    // The ground's group and 15 instances.
    let e = err(DeviceLimits {
        max_instance_count: 15,
        ..ROOMY
    });
    assert!(e.contains("16 top-level instances"), "{e}");
}

#[test]
fn the_devices_own_limits_are_read_and_hold_the_instancing_scene() {
    let ctx = twinpath::vulkan::device::Context::new(None, false).expect("a Vulkan device");
    println!("{}: {:?}", ctx.device_name, ctx.limits);
    // Read, not defaulted (lavapipe: 2^27 bytes, 2^24 - 1 primitives and instances).
    assert!(ctx.limits.max_storage_buffer_range >= 1 << 20);
    assert!(ctx.limits.max_primitive_count >= 1 << 16);
    assert!(ctx.limits.max_instance_count >= 1 << 16);
    let scene = SceneFile::load(&repo_root().join("scenes/instances.toml")).unwrap();
    check_scene_fits(&scene.scene, &ctx.limits).unwrap();
}
