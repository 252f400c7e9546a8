//! Runs the tests' module's `shaders::probe` compute entry point (`crate::PROBE_SPV`) over
//! buffers of records, so tests can compare every kernel function between the GPU and the CPU
//! on the same inputs. Test support only (feature `test-support`): the renderer has no probes.

use super::device::Context;
use super::pipeline::{entry_points, shader_module};
use anyhow::{anyhow, bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::ffi::CStr;

pub const PROBE: &CStr = c"shaders::probe";
const WORKGROUP: u32 = 64;

/// A compute pipeline over `shaders::probe`.
pub struct ProbeRunner {
    module: vk::ShaderModule,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl ProbeRunner {
    pub fn new(ctx: &Context) -> Result<ProbeRunner> {
        let module = shader_module(ctx, &entry_points(crate::PROBE_SPV)?, PROBE)?;
        let bindings = [0, 1].map(|b| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
        });
        let set_layout = unsafe {
            ctx.device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
        }?;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .size(8)];
        let set_layouts = [set_layout];
        let layout = unsafe {
            ctx.device.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&set_layouts)
                    .push_constant_ranges(&ranges),
                None,
            )
        }?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(PROBE);
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        let pipeline = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        }
        .map_err(|(_, e)| anyhow!("cannot create the probe pipeline: {e}"))?[0];
        Ok(ProbeRunner {
            module,
            set_layout,
            layout,
            pipeline,
        })
    }

    /// Evaluates `function` (see `kernel::probe::function`) on every 4-word record of `input`
    /// on the device; returns the 2-word output records.
    pub fn run(
        &self,
        ctx: &Context,
        function: u32,
        input: &[[[u32; 4]; 4]],
    ) -> Result<Vec<[[u32; 4]; 2]>> {
        if input.is_empty() {
            bail!("no records");
        }
        let count = input.len() as u32;
        let in_buf = ctx.upload_buffer(
            "probe input",
            bytemuck::cast_slice(input),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let out_bytes = input.len() as u64 * 32;
        let out_buf = ctx.create_buffer(
            "probe output",
            out_bytes,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let result = (|| -> Result<Vec<[[u32; 4]; 2]>> {
            let sizes = [vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: 2,
            }];
            let (pool, set) = ctx.create_descriptor_set(self.set_layout, &sizes)?;
            let infos = [&in_buf, &out_buf].map(|b| {
                [vk::DescriptorBufferInfo::default()
                    .buffer(b.buffer)
                    .range(vk::WHOLE_SIZE)]
            });
            let writes = [0usize, 1].map(|i| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(&infos[i])
            });
            unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
            let push: [u32; 2] = [function, count];
            let r = ctx.submit_and_wait(|cmd| unsafe {
                ctx.device
                    .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
                ctx.device.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    self.layout,
                    0,
                    &[set],
                    &[],
                );
                ctx.device.cmd_push_constants(
                    cmd,
                    self.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    bytemuck::cast_slice(&push),
                );
                ctx.device
                    .cmd_dispatch(cmd, count.div_ceil(WORKGROUP), 1, 1);
                let barrier = vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                    .dst_access_mask(vk::AccessFlags::HOST_READ);
                ctx.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::PipelineStageFlags::HOST,
                    vk::DependencyFlags::empty(),
                    &[barrier],
                    &[],
                    &[],
                );
            });
            unsafe { ctx.device.destroy_descriptor_pool(pool, None) };
            r?;
            let raw = ctx.read_buffer(&out_buf)?;
            Ok(bytemuck::pod_collect_to_vec(&raw[..out_bytes as usize]))
        })();
        ctx.destroy_buffer(in_buf);
        ctx.destroy_buffer(out_buf);
        result
    }

    pub fn destroy(self, ctx: &Context) {
        super::pipeline::destroy_pipeline_objects(
            ctx,
            self.pipeline,
            self.layout,
            self.set_layout,
            &[self.module],
        );
    }
}
