//! The SPIR-V module rust-gpu builds from `kernel/`: valid for Vulkan 1.2 (spirv-val), holding
//! exactly the entry points the Vulkan backend binds (rust-gpu can silently drop one), and laying
//! out every shared struct exactly as the host does. The tests' module (`PROBE_SPV`, the kernel
//! with its feature `probe`) holds the same entry points and the compute probe; the renderer's
//! holds no probe.

use kernel::medium::Medium;
use kernel::scene::{
    AdaptiveParams, Camera, EnvironmentParams, Instance, IntegratorParams, Light, Material,
    RenderParams, SampleParams, ShadingTriangle, Sphere, SplitParams, Triangle,
};
use std::collections::BTreeSet;
use std::mem::{offset_of, size_of};
use std::process::Command;
use twinpath::vulkan::pipeline::binding;
use twinpath_tests::spirv::{Module, StructLayout};

#[test]
fn module_has_the_ray_tracing_entry_points_and_the_tests_module_the_probe() {
    // Execution models: GLCompute 5, RayGenerationKHR 5313, IntersectionKHR 5314,
    // AnyHitKHR 5315, ClosestHitKHR 5316, MissKHR 5317.
    let mut want: BTreeSet<(u32, String)> = [
        (5313, "shaders::raygen"),
        (5317, "shaders::miss"),
        (5316, "shaders::closest_hit_triangle"),
        (5316, "shaders::closest_hit_sphere"),
        (5316, "shaders::closest_hit_instance"),
        (5314, "shaders::intersect_sphere_shader"),
        (5315, "shaders::any_hit_triangle"),
        (5315, "shaders::any_hit_instance"),
    ]
    .into_iter()
    .map(|(m, n)| (m, n.to_string()))
    .collect();
    let got = Module::parse(twinpath::KERNEL_SPV).entry_points;
    println!("entry points: {got:?}");
    assert_eq!(got, want, "the renderer's module");
    want.insert((5, "shaders::probe".to_string()));
    let probe = Module::parse(twinpath::PROBE_SPV).entry_points;
    println!("the tests' module's entry points: {probe:?}");
    assert_eq!(probe, want, "the tests' module");
    assert!(probe
        .iter()
        .any(|(_, n)| n.as_bytes() == twinpath::vulkan::compute::PROBE.to_bytes()));
    // The names the host binds are the module's.
    use twinpath::vulkan::pipeline as p;
    for name in [
        p::RAYGEN,
        p::MISS,
        p::CLOSEST_HIT_TRIANGLE,
        p::CLOSEST_HIT_SPHERE,
        p::CLOSEST_HIT_INSTANCE,
        p::INTERSECT_SPHERE,
        p::ANY_HIT_TRIANGLE,
        p::ANY_HIT_INSTANCE,
    ] {
        assert!(
            got.iter().any(|(_, n)| n.as_bytes() == name.to_bytes()),
            "{name:?}"
        );
    }
}

#[test]
fn raygen_reads_the_feature_specialization_constant() {
    // The host specializes constant 0 (`kernel::features`); rust-gpu must have kept it.
    let m = Module::parse(twinpath::KERNEL_SPV);
    assert_eq!(m.spec_ids.iter().copied().collect::<Vec<_>>(), vec![0]);
}

#[test]
fn module_needs_ray_tracing_pipelines_and_not_ray_queries() {
    // Capability numbers from the SPIR-V specification, section 3.31.
    const RAY_QUERY_KHR: u32 = 4472;
    const RAY_TRACING_KHR: u32 = 4479;
    let m = Module::parse(twinpath::KERNEL_SPV);
    println!(
        "capabilities: {:?}, extensions: {:?}",
        m.capabilities, m.extensions
    );
    assert!(m.capabilities.contains(&RAY_TRACING_KHR));
    assert!(
        !m.capabilities.contains(&RAY_QUERY_KHR),
        "the module declares RayQueryKHR: devices without VK_KHR_ray_query could not run it"
    );
    assert!(m.extensions.contains("SPV_KHR_ray_tracing"));
    assert!(!m.extensions.contains("SPV_KHR_ray_query"));
    // And the host does not ask for the extension either.
    assert!(!twinpath::vulkan::device::REQUIRED_EXTENSIONS
        .iter()
        .any(|e| e.to_bytes() == b"VK_KHR_ray_query"));
}

/// The callable shader `pipeline_stats --separate` adds (`Compilation::Separate`) is the
/// assembly of its text, valid, and a callable entry point (CallableKHR, 5318).
#[test]
fn callable_module_is_its_assembly_text() {
    use twinpath::vulkan::pipeline::{CALLABLE_SPV, CALLABLE_SPVASM};
    let dir = std::env::temp_dir();
    let text = dir.join(format!("twinpath-callable-{}.spvasm", std::process::id()));
    let binary = text.with_extension("spv");
    std::fs::write(&text, CALLABLE_SPVASM).unwrap();
    let out = Command::new("spirv-as")
        .args(["--target-env", "vulkan1.2"])
        .arg(&text)
        .arg("-o")
        .arg(&binary)
        .output()
        .expect("spirv-as (Debian package spirv-tools) must be installed: run scripts/setup.sh");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let words: Vec<u32> = std::fs::read(&binary)
        .unwrap()
        .chunks(4)
        .map(|w| u32::from_le_bytes(w.try_into().unwrap()))
        .collect();
    let _ = (std::fs::remove_file(&text), std::fs::remove_file(&binary));
    assert_eq!(words, CALLABLE_SPV);
    let bytes: Vec<u8> = CALLABLE_SPV.iter().flat_map(|w| w.to_le_bytes()).collect();
    spirv_val("callable", &bytes);
    let entry_points = Module::parse(&bytes).entry_points;
    assert_eq!(entry_points, BTreeSet::from([(5318, "main".to_string())]));
}

/// The test device compiles the pipeline with the stages apart too (the callable shader
/// accepted, the validation layers silent), and answers the ray-generation group's stack size.
#[test]
fn pipeline_compiles_with_its_stages_apart() {
    use twinpath::vulkan::pipeline::{Compilation, CompiledPipeline, HitGroups};
    let file = twinpath::scene::SceneFile::builtin_default();
    let features = file.features();
    let hit_groups = HitGroups::for_scene(&file.scene, &file.settings);
    let ctx = twinpath_tests::gpu::context().lock().unwrap();
    for compilation in [Compilation::Render, Compilation::Separate] {
        let pipeline = CompiledPipeline::new(
            &ctx,
            twinpath::KERNEL_SPV,
            features,
            hit_groups,
            compilation,
        )
        .unwrap();
        println!(
            "{}, {compilation:?}: raygen stack {} bytes",
            ctx.device_name,
            pipeline.raygen_stack_size(&ctx)
        );
        pipeline.destroy(&ctx);
    }
    drop(ctx);
    twinpath_tests::gpu::assert_validation_clean();
}

#[test]
fn modules_pass_spirv_val() {
    for (name, module) in [
        ("kernel", twinpath::KERNEL_SPV),
        ("probe", twinpath::PROBE_SPV),
    ] {
        spirv_val(name, module);
    }
}

/// Where a device offers float controls the module is loaded with them
/// (`vulkan::float_controls::request`): with every one requested, each entry point of both
/// modules sets DenormPreserve, SignedZeroInfNanPreserve and RoundingModeRTE for 32 bits, the
/// capabilities are declared, the rest of the module is unchanged, and spirv-val accepts it
/// (lavapipe, which offers the last two, renders every GPU test with them). Nothing requested
/// leaves the module as it is; a malformed module is an error, not a panic.
#[test]
fn modules_with_float_controls_requested_set_them_on_every_entry_point_and_pass_spirv_val() {
    use twinpath::vulkan::float_controls::{request, Requested};
    for (name, module) in [
        ("kernel", twinpath::KERNEL_SPV),
        ("probe", twinpath::PROBE_SPV),
    ] {
        let words: Vec<u32> = module
            .as_chunks::<4>()
            .0
            .iter()
            .map(|w| u32::from_le_bytes(*w))
            .collect();
        assert_eq!(request(&words, Requested::default()).unwrap(), words);
        let patched = request(&words, Requested::ALL).unwrap();
        // (word offset, (opcode, operands)) of every instruction.
        let instructions = |w: &[u32]| {
            let (mut at, mut out) = (5, Vec::new());
            while at < w.len() {
                let count = (w[at] >> 16) as usize;
                out.push((at, (w[at] & 0xffff, w[at + 1..at + count].to_vec())));
                at += count;
            }
            out
        };
        let (located, patched_located) = (instructions(&words), instructions(&patched));
        let before: Vec<_> = located.iter().map(|(_, i)| i.clone()).collect();
        let after: Vec<_> = patched_located.into_iter().map(|(_, i)| i).collect();
        let entries: Vec<u32> = after
            .iter()
            .filter(|(op, _)| *op == 15)
            .map(|(_, o)| o[1])
            .collect();
        assert!(!entries.is_empty());
        for cap in [4464, 4466, 4467] {
            assert!(after.contains(&(17, vec![cap])), "{name}: capability {cap}");
        }
        for &entry in &entries {
            for mode in [4459, 4461, 4462] {
                assert!(
                    after.contains(&(16, vec![entry, mode, 32])),
                    "{name}: entry {entry} mode {mode}"
                );
            }
        }
        assert_eq!(after.len(), before.len() + 3 + 3 * entries.len());
        let added = |i: &(u32, Vec<u32>)| {
            (i.0 == 17 && [4464, 4466, 4467].contains(&i.1[0]))
                || (i.0 == 16 && [4459, 4461, 4462].contains(&i.1[1]) && i.1.len() == 3)
        };
        let kept: Vec<_> = after.iter().filter(|i| !added(i)).cloned().collect();
        assert_eq!(kept, before, "{name}: the rest of the module is unchanged");
        let bytes: Vec<u8> = patched.iter().flat_map(|w| w.to_le_bytes()).collect();
        spirv_val(&format!("{name}-float-controls"), &bytes);
        // Cut inside the first entry point: its word count reaches past the end.
        let first_entry = located.iter().find(|(_, (op, _))| *op == 15).unwrap().0;
        let truncated = &words[..first_entry + 2];
        assert!(request(truncated, Requested::ALL).is_err(), "{name}");
    }
}

fn spirv_val(name: &str, module: &[u8]) {
    let path = std::env::temp_dir().join(format!("twinpath-{name}-{}.spv", std::process::id()));
    std::fs::write(&path, module).unwrap();
    let out = Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .arg(&path)
        .output()
        .expect("spirv-val (Debian package spirv-tools) must be installed: run scripts/setup.sh");
    let _ = std::fs::remove_file(&path);
    assert!(
        out.status.success(),
        "spirv-val rejects the module:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

macro_rules! host_layout {
    ($t:ty, [$($f:ident),*], $array:expr) => {
        StructLayout {
            offsets: vec![$(offset_of!($t, $f) as u32),*],
            stride: $array.then_some(size_of::<$t>() as u32),
        }
    };
}

#[test]
fn shared_structs_have_the_same_layout_on_host_and_device() {
    let m = Module::parse(twinpath::KERNEL_SPV);
    let cases = [
        (
            "RenderParams",
            binding::PARAMS,
            host_layout!(
                RenderParams,
                [camera, samples, integrator, adaptive, environment, split],
                false
            ),
        ),
        (
            "Material",
            binding::MATERIALS,
            host_layout!(
                Material,
                [
                    albedo,
                    kind,
                    emission,
                    alpha,
                    specular,
                    ior,
                    eta,
                    opacity,
                    k,
                    coat,
                    textures,
                    metallic,
                    roughness,
                    normal_scale,
                    layer_f0,
                    layer_f90
                ],
                true
            ),
        ),
        (
            "Light",
            binding::LIGHTS,
            host_layout!(
                Light,
                [
                    position,
                    radius,
                    edge1,
                    kind,
                    edge2,
                    two_sided,
                    radiance,
                    select_pmf,
                    alias_threshold,
                    alias,
                    area,
                    point_error,
                    uv,
                    emission_texture,
                    material
                ],
                true
            ),
        ),
        (
            "Triangle",
            binding::TRIANGLES,
            host_layout!(Triangle, [p0, material, edge1, light, edge2, shading], true),
        ),
        (
            "ShadingTriangle",
            binding::SHADING,
            host_layout!(
                ShadingTriangle,
                [normal0, normal1, normal2, uv0, uv1, uv2, flags],
                true
            ),
        ),
        (
            "Sphere",
            binding::SPHERES,
            host_layout!(Sphere, [center, radius, material, light, _pad], true),
        ),
        (
            "Instance",
            binding::INSTANCES,
            host_layout!(
                Instance,
                [
                    object_to_world,
                    world_to_object,
                    first_triangle,
                    forward_norm,
                    inverse_norm,
                    handedness,
                    determinant_condition
                ],
                true
            ),
        ),
        (
            "Medium",
            binding::MEDIA,
            host_layout!(Medium, [sigma_a, g, sigma_s, grid], true),
        ),
    ];
    for (name, b, host) in cases {
        let device = m.binding_layout(0, b);
        println!("{name}: host {host:?}, device {device:?}");
        assert_eq!(host, device, "{name} differs between host and device");
    }
    assert_eq!(size_of::<RenderParams>() % 16, 0);
    // The parts of RenderParams, member by member.
    let parts = [
        (
            "Camera",
            0,
            host_layout!(Camera, [eye, forward, right, up], false),
        ),
        (
            "SampleParams",
            1,
            host_layout!(
                SampleParams,
                [width, height, seed, first, count, sampler],
                false
            ),
        ),
        (
            "IntegratorParams",
            2,
            host_layout!(
                IntegratorParams,
                [
                    light_count,
                    rr_mode,
                    rr_probability,
                    rr_start_depth,
                    mis_mode,
                    max_depth,
                    light_sampling
                ],
                false
            ),
        ),
        (
            "AdaptiveParams",
            3,
            host_layout!(
                AdaptiveParams,
                [target, pilot_period, min_pilot_samples],
                false
            ),
        ),
        (
            "EnvironmentParams",
            4,
            host_layout!(
                EnvironmentParams,
                [background, width, height, light, scale, rotation, medium, _pad],
                false
            ),
        ),
        (
            "SplitParams",
            5,
            host_layout!(SplitParams, [mode, tile_size, tile_columns, _pad], false),
        ),
    ];
    for (name, member, host) in parts {
        let device = m.member_layout(0, binding::PARAMS, member);
        println!("RenderParams.{name}: host {host:?}, device {device:?}");
        assert_eq!(
            host, device,
            "RenderParams.{name} differs between host and device"
        );
    }
}
