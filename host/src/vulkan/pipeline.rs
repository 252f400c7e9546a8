//! The ray-tracing pipeline over the kernel's SPIR-V module, its descriptor set layout and the
//! shader binding table laid out from the device's handle size and alignments.

use super::device::Context;
use super::entry_module::EntryPoints;
use super::memory::Buffer;
use crate::scene::Scene;
use crate::settings::RenderSettings;
use anyhow::{anyhow, Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::ffi::CStr;

/// Entry points of the kernel module the pipeline uses (asserted by a test on the module).
pub const RAYGEN: &CStr = c"shaders::raygen";
pub const MISS: &CStr = c"shaders::miss";
pub const CLOSEST_HIT_TRIANGLE: &CStr = c"shaders::closest_hit_triangle";
pub const CLOSEST_HIT_SPHERE: &CStr = c"shaders::closest_hit_sphere";
pub const CLOSEST_HIT_INSTANCE: &CStr = c"shaders::closest_hit_instance";
pub const INTERSECT_SPHERE: &CStr = c"shaders::intersect_sphere_shader";
pub const ANY_HIT_TRIANGLE: &CStr = c"shaders::any_hit_triangle";
pub const ANY_HIT_INSTANCE: &CStr = c"shaders::any_hit_instance";

/// Descriptor bindings, as `kernel::shaders` declares them.
pub mod binding {
    pub const TLAS: u32 = 0;
    pub const ACCUM: u32 = 1;
    pub const PARAMS: u32 = 2;
    pub const MATERIALS: u32 = 3;
    pub const LIGHTS: u32 = 4;
    pub const TRIANGLES: u32 = 5;
    pub const SPHERES: u32 = 6;
    pub const ACCUM_SQ: u32 = 7;
    pub const PILOTS: u32 = 8;
    pub const ENVIRONMENT: u32 = 9;
    pub const SHADING: u32 = 10;
    pub const TEXTURES: u32 = 11;
    pub const INSTANCES: u32 = 12;
    pub const MEDIA: u32 = 13;
    pub const GRIDS: u32 = 14;
    pub const SPLITS: u32 = 15;
}

/// Which hit groups a pipeline has: a scene without world-space triangles (or spheres, or
/// instances) gets no triangle (or sphere, or instance) hit group when specialized; the
/// generic pipeline has all three. The triangle groups have any-hit shaders (which drop the
/// hits a ray cannot make, `kernel::plane_side`, and holes, `kernel::opacity`); their BLASes
/// are built without the OPAQUE flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HitGroups {
    pub triangles: bool,
    pub spheres: bool,
    pub instances: bool,
}

impl HitGroups {
    pub const ALL: HitGroups = HitGroups {
        triangles: true,
        spheres: true,
        instances: true,
    };

    /// The groups a render of `scene` with `settings` uses: only those of the geometry it has
    /// when specialized, every group otherwise (the generic pipeline).
    pub fn for_scene(scene: &Scene, settings: &RenderSettings) -> HitGroups {
        if settings.specialize {
            HitGroups {
                triangles: scene.world_triangle_count() > 0,
                spheres: !scene.spheres.is_empty(),
                instances: !scene.instances.is_empty(),
            }
        } else {
            HitGroups::ALL
        }
    }

    /// SBT record offset of the triangle hit group (instances of triangle BLASes).
    pub fn triangle_offset(self) -> u32 {
        0
    }

    /// SBT record offset of the sphere hit group: after the triangles' when there is one.
    pub fn sphere_offset(self) -> u32 {
        self.triangles as u32
    }

    /// SBT record offset of the instanced-triangle hit group: after the others present.
    pub fn instance_offset(self) -> u32 {
        self.triangles as u32 + self.spheres as u32
    }

    fn count(self) -> u32 {
        self.triangles as u32 + self.spheres as u32 + self.instances as u32
    }
}

/// The compiled pipeline and the objects it owns, without a shader binding table: what
/// [`RtPipeline`] renders with, and what `examples/pipeline_stats` compiles for a driver's
/// statistics (on hardware without memory, where no table can be made).
pub struct CompiledPipeline {
    /// One module per stage, in stage order (`super::entry_module`).
    pub modules: Vec<vk::ShaderModule>,
    pub set_layout: vk::DescriptorSetLayout,
    pub layout: vk::PipelineLayout,
    pub pipeline: vk::Pipeline,
    /// The groups in pipeline order: ray generation, miss, the hit groups of [`HitGroups`]
    /// (then the callable group of [`Compilation::Separate`]).
    pub group_count: u32,
    callable_module: Option<vk::ShaderModule>,
}

/// How [`CompiledPipeline::new`] asks the driver to compile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compilation {
    /// As a render does: the driver chooses.
    Render,
    /// With an unused callable shader ([`CALLABLE_SPV`]) in the pipeline, which makes Mesa's
    /// RADV compile every stage separately instead of inlining them into the ray-generation
    /// shader: each trace call is then a call, across which what the ray-generation shader
    /// keeps live is saved on the ray-tracing stack, as on GPUs that traverse in hardware
    /// (NVIDIA's guides: keep the live state across `traceRay` small). The raygen group's
    /// stack size ([`CompiledPipeline::raygen_stack_size`]) then measures that state. For
    /// statistics only: the shader binding table has no callable region.
    Separate,
}

/// The text of a callable shader that returns at once ([`CALLABLE_SPV`] is its assembly).
pub const CALLABLE_SPVASM: &str = "\
OpCapability RayTracingKHR
OpExtension \"SPV_KHR_ray_tracing\"
OpMemoryModel Logical GLSL450
OpEntryPoint CallableKHR %main \"main\"
%void = OpTypeVoid
%fn = OpTypeFunction %void
%main = OpFunction %void None %fn
%l = OpLabel
OpReturn
OpFunctionEnd
";

/// [`CALLABLE_SPVASM`] assembled by `spirv-as --target-env vulkan1.2` (the test
/// `callable_module_is_its_assembly_text` assembles it again and compares).
pub const CALLABLE_SPV: [u32; 35] = [
    0x07230203, 0x00010500, 0x00070000, 0x00000005, 0x00000000, 0x00020011, 0x0000117f, 0x0006000a,
    0x5f565053, 0x5f52484b, 0x5f796172, 0x63617274, 0x00676e69, 0x0003000e, 0x00000000, 0x00000001,
    0x0005000f, 0x000014c6, 0x00000001, 0x6e69616d, 0x00000000, 0x00020013, 0x00000002, 0x00030021,
    0x00000003, 0x00000002, 0x00050036, 0x00000002, 0x00000001, 0x00000000, 0x00000003, 0x000200f8,
    0x00000004, 0x000100fd, 0x00010038,
];

/// The pipeline, the objects it owns and its shader binding table.
pub struct RtPipeline {
    pub compiled: CompiledPipeline,
    pub sbt: Buffer,
    pub raygen_region: vk::StridedDeviceAddressRegionKHR,
    pub miss_region: vk::StridedDeviceAddressRegionKHR,
    pub hit_region: vk::StridedDeviceAddressRegionKHR,
}

fn align_up(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
}

/// The entry points of SPIR-V bytes, parsed once for the stages cut from them
/// (`super::entry_module`).
pub fn entry_points(spv: &[u8]) -> Result<EntryPoints> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spv)).context("malformed SPIR-V")?;
    EntryPoints::parse(&words).map_err(|e| anyhow!("cannot parse the module: {e}"))
}

/// Creates a shader module of the entry point `entry` of `module` (the module cut to it,
/// `super::entry_module`), asking for the float controls the device offers
/// (`super::float_controls`).
pub fn shader_module(
    ctx: &Context,
    module: &EntryPoints,
    entry: &CStr,
) -> Result<vk::ShaderModule> {
    let entry = entry
        .to_str()
        .context("an entry point's name is not UTF-8")?;
    let words = module
        .module_of(entry)
        .map_err(|e| anyhow!("cannot cut the module to {entry}: {e}"))?;
    let words = super::float_controls::request(&words, ctx.float_controls.requested())
        .map_err(|e| anyhow!("cannot add float controls to the module: {e}"))?;
    unsafe {
        ctx.device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None)
    }
    .context("cannot create the shader module")
}

impl CompiledPipeline {
    /// The pipeline with `hit_groups`, the raygen shader specialized to `features`
    /// (specialization constant 0, `kernel::features`; 0 keeps the generic path), compiled as
    /// `compilation` says.
    pub fn new(
        ctx: &Context,
        spv: &[u8],
        features: u32,
        hit_groups: HitGroups,
        compilation: Compilation,
    ) -> Result<CompiledPipeline> {
        let all = vk::ShaderStageFlags::RAYGEN_KHR
            | vk::ShaderStageFlags::CLOSEST_HIT_KHR
            | vk::ShaderStageFlags::ANY_HIT_KHR
            | vk::ShaderStageFlags::INTERSECTION_KHR
            | vk::ShaderStageFlags::MISS_KHR;
        let b = |binding: u32, ty: vk::DescriptorType| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(binding)
                .descriptor_type(ty)
                .descriptor_count(1)
                .stage_flags(all)
        };
        let bindings = [
            b(
                binding::TLAS,
                vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            ),
            b(binding::ACCUM, vk::DescriptorType::STORAGE_IMAGE),
            b(binding::PARAMS, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::MATERIALS, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::LIGHTS, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::TRIANGLES, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::SPHERES, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::ACCUM_SQ, vk::DescriptorType::STORAGE_IMAGE),
            b(binding::PILOTS, vk::DescriptorType::STORAGE_IMAGE),
            b(binding::ENVIRONMENT, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::SHADING, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::TEXTURES, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::INSTANCES, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::MEDIA, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::GRIDS, vk::DescriptorType::STORAGE_BUFFER),
            b(binding::SPLITS, vk::DescriptorType::STORAGE_BUFFER),
        ];
        let set_layout = unsafe {
            ctx.device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
        }?;
        let set_layouts = [set_layout];
        let layout = unsafe {
            ctx.device.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts),
                None,
            )
        }?;
        // The stages as (kind, entry point) in pipeline order; each gets its own module below.
        let stage = |flags: vk::ShaderStageFlags, name: &'static CStr| (flags, name);
        let spec_entries = [vk::SpecializationMapEntry {
            constant_id: 0,
            offset: 0,
            size: 4,
        }];
        let spec_data = features.to_ne_bytes();
        let spec = vk::SpecializationInfo::default()
            .map_entries(&spec_entries)
            .data(&spec_data);
        let mut stages = vec![
            stage(vk::ShaderStageFlags::RAYGEN_KHR, RAYGEN),
            stage(vk::ShaderStageFlags::MISS_KHR, MISS),
        ];
        let unused = vk::SHADER_UNUSED_KHR;
        let group = |ty, general, chit, isect| {
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(ty)
                .general_shader(general)
                .closest_hit_shader(chit)
                .any_hit_shader(unused)
                .intersection_shader(isect)
        };
        let mut groups = vec![
            group(vk::RayTracingShaderGroupTypeKHR::GENERAL, 0, unused, unused),
            group(vk::RayTracingShaderGroupTypeKHR::GENERAL, 1, unused, unused),
        ];
        // A triangle hit group of closest-hit shader `name` (world-space or instanced), with
        // any-hit shader `any`.
        let triangle_group = |stages: &mut Vec<(vk::ShaderStageFlags, &'static CStr)>,
                              groups: &mut Vec<vk::RayTracingShaderGroupCreateInfoKHR<'_>>,
                              name: &'static CStr,
                              any: &'static CStr| {
            stages.push(stage(vk::ShaderStageFlags::CLOSEST_HIT_KHR, name));
            stages.push(stage(vk::ShaderStageFlags::ANY_HIT_KHR, any));
            let closest = stages.len() as u32 - 2;
            groups.push(
                group(
                    vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP,
                    unused,
                    closest,
                    unused,
                )
                .any_hit_shader(closest + 1),
            );
        };
        // Hit groups in SBT order (HitGroups::triangle_offset, sphere_offset, instance_offset).
        if hit_groups.triangles {
            triangle_group(
                &mut stages,
                &mut groups,
                CLOSEST_HIT_TRIANGLE,
                ANY_HIT_TRIANGLE,
            );
        }
        if hit_groups.spheres {
            stages.push(stage(
                vk::ShaderStageFlags::CLOSEST_HIT_KHR,
                CLOSEST_HIT_SPHERE,
            ));
            stages.push(stage(
                vk::ShaderStageFlags::INTERSECTION_KHR,
                INTERSECT_SPHERE,
            ));
            groups.push(group(
                vk::RayTracingShaderGroupTypeKHR::PROCEDURAL_HIT_GROUP,
                unused,
                stages.len() as u32 - 2,
                stages.len() as u32 - 1,
            ));
        }
        if hit_groups.instances {
            triangle_group(
                &mut stages,
                &mut groups,
                CLOSEST_HIT_INSTANCE,
                ANY_HIT_INSTANCE,
            );
        }
        let entry_points = entry_points(spv)?;
        let mut modules = Vec::with_capacity(stages.len());
        for &(_, name) in &stages {
            match shader_module(ctx, &entry_points, name) {
                Ok(m) => modules.push(m),
                Err(e) => {
                    for m in modules {
                        unsafe { ctx.device.destroy_shader_module(m, None) };
                    }
                    return Err(e);
                }
            }
        }
        let mut stages: Vec<vk::PipelineShaderStageCreateInfo<'_>> = stages
            .iter()
            .zip(&modules)
            .map(|(&(flags, name), &module)| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(flags)
                    .module(module)
                    .name(name)
            })
            .collect();
        // The ray-generation stage (first) and the any-hit stages are specialized to the scene's
        // features (the any-hit shaders ask only whether a material may have holes).
        for stage in stages.iter_mut() {
            if stage.stage == vk::ShaderStageFlags::RAYGEN_KHR
                || stage.stage == vk::ShaderStageFlags::ANY_HIT_KHR
            {
                *stage = stage.specialization_info(&spec);
            }
        }
        let callable_module = if compilation == Compilation::Separate {
            let callable = unsafe {
                ctx.device.create_shader_module(
                    &vk::ShaderModuleCreateInfo::default().code(&CALLABLE_SPV),
                    None,
                )
            }
            .context("cannot create the callable shader's module")?;
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::CALLABLE_KHR)
                    .module(callable)
                    .name(c"main"),
            );
            groups.push(group(
                vk::RayTracingShaderGroupTypeKHR::GENERAL,
                stages.len() as u32 - 1,
                unused,
                unused,
            ));
            Some(callable)
        } else {
            None
        };
        let info = vk::RayTracingPipelineCreateInfoKHR::default()
            .stages(&stages)
            .groups(&groups)
            .max_pipeline_ray_recursion_depth(1)
            .layout(layout);
        let pipeline = unsafe {
            ctx.rt.create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                vk::PipelineCache::null(),
                &[info],
                None,
            )
        }
        .map_err(|(_, e)| anyhow!("cannot create the ray-tracing pipeline: {e}"))?[0];
        Ok(CompiledPipeline {
            modules,
            set_layout,
            layout,
            pipeline,
            group_count: groups.len() as u32,
            callable_module,
        })
    }

    /// The bytes of ray-tracing stack the ray-generation shader needs
    /// (`vkGetRayTracingShaderGroupStackSizeKHR` of group 0): with [`Compilation::Separate`] on
    /// RADV, and on drivers that compile stages apart, what it keeps live across its trace
    /// calls.
    pub fn raygen_stack_size(&self, ctx: &Context) -> u64 {
        unsafe {
            ctx.rt.get_ray_tracing_shader_group_stack_size(
                self.pipeline,
                0,
                vk::ShaderGroupShaderKHR::GENERAL,
            )
        }
    }

    pub fn destroy(self, ctx: &Context) {
        destroy_pipeline_objects(
            ctx,
            self.pipeline,
            self.layout,
            self.set_layout,
            &self.modules,
        );
        if let Some(callable) = self.callable_module {
            unsafe { ctx.device.destroy_shader_module(callable, None) };
        }
    }
}

/// Destroys a pipeline with its layout, its descriptor set layout and its shader modules (the
/// ray-tracing pipeline's and the compute probe's, `super::compute`).
pub(super) fn destroy_pipeline_objects(
    ctx: &Context,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    modules: &[vk::ShaderModule],
) {
    unsafe {
        ctx.device.destroy_pipeline(pipeline, None);
        ctx.device.destroy_pipeline_layout(layout, None);
        ctx.device.destroy_descriptor_set_layout(set_layout, None);
        for &module in modules {
            ctx.device.destroy_shader_module(module, None);
        }
    }
}

impl RtPipeline {
    /// The pipeline of a render ([`CompiledPipeline::new`] with [`Compilation::Render`]) and
    /// its shader binding table.
    pub fn new(
        ctx: &Context,
        spv: &[u8],
        features: u32,
        hit_groups: HitGroups,
    ) -> Result<RtPipeline> {
        let compiled = CompiledPipeline::new(ctx, spv, features, hit_groups, Compilation::Render)?;
        let pipeline = compiled.pipeline;

        // Shader binding table: raygen | miss | hit (triangles, spheres), each region starting
        // at the base alignment, records at the handle alignment.
        let p = ctx.rt_properties;
        let handle_size = p.shader_group_handle_size as u64;
        let stride = align_up(handle_size, p.shader_group_handle_alignment as u64);
        let base = p.shader_group_base_alignment as u64;
        let raygen_size = align_up(stride, base);
        let miss_size = align_up(stride, base);
        let hits = hit_groups.count() as u64;
        let hit_size = align_up(hits.max(1) * stride, base);
        let handles = unsafe {
            ctx.rt.get_ray_tracing_shader_group_handles(
                pipeline,
                0,
                compiled.group_count,
                compiled.group_count as usize * handle_size as usize,
            )
        }?;
        let mut table = vec![0u8; (raygen_size + miss_size + hit_size + base) as usize];
        let mut sbt = ctx.create_buffer(
            "shader binding table",
            table.len() as u64,
            vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::CpuToGpu,
        )?;
        // The buffer's address need not be base-aligned: start the table at the next multiple.
        let start = align_up(sbt.address, base) - sbt.address;
        let hs = handle_size as usize;
        let mut put = |offset: u64, group: usize| {
            let o = (start + offset) as usize;
            table[o..o + hs].copy_from_slice(&handles[group * hs..(group + 1) * hs]);
        };
        put(0, 0);
        put(raygen_size, 1);
        for k in 0..hits {
            put(raygen_size + miss_size + k * stride, 2 + k as usize);
        }
        ctx.write_buffer(&mut sbt, &table)?;
        let at = sbt.address + start;
        let raygen_region = vk::StridedDeviceAddressRegionKHR {
            device_address: at,
            stride: raygen_size,
            size: raygen_size,
        };
        let miss_region = vk::StridedDeviceAddressRegionKHR {
            device_address: at + raygen_size,
            stride,
            size: miss_size,
        };
        // No hit group at all (an empty scene): a null region, never used.
        let hit_region = if hits == 0 {
            vk::StridedDeviceAddressRegionKHR::default()
        } else {
            vk::StridedDeviceAddressRegionKHR {
                device_address: at + raygen_size + miss_size,
                stride,
                size: hit_size,
            }
        };
        Ok(RtPipeline {
            compiled,
            sbt,
            raygen_region,
            miss_region,
            hit_region,
        })
    }

    pub fn destroy(self, ctx: &Context) {
        self.compiled.destroy(ctx);
        ctx.destroy_buffer(self.sbt);
    }
}
