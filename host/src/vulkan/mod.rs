//! The GPU backend: the kernel's SPIR-V in a Vulkan ray-tracing pipeline (ash), dispatched with
//! `vkCmdTraceRaysKHR`, accumulating progressively in float storage images.

pub mod accel;
#[cfg(feature = "test-support")]
pub mod compute;
pub mod device;
pub mod entry_module;
pub mod float_controls;
pub mod limits;
pub mod memory;
pub mod pipeline;

use crate::backend::SampleBackend;
use crate::film::Film;
use crate::fixed_sum::FixedSum;
use crate::scene::{Scene, ADAPTIVE_PASS, SPLIT_TILE};
use crate::settings::RenderSettings;
use accel::SceneAccel;
use anyhow::{Context as _, Result};
use ash::vk;
use device::Context;
use gpu_allocator::MemoryLocation;
use indicatif::ProgressBar;
use kernel::scene::RenderParams;
use memory::{Buffer, Image};
use pipeline::{binding, HitGroups, RtPipeline};
use std::time::{Duration, Instant};

/// A scene uploaded to a Vulkan device, ready to trace.
pub struct GpuRenderer {
    // Field order matters only for Drop below, which releases everything before `ctx`.
    resources: Option<Resources>,
    /// Time to build the acceleration structures.
    pub accel_build_time: Duration,
    /// Time to create the pipeline (the driver compiles the shaders here).
    pub pipeline_time: Duration,
    pub width: u32,
    pub height: u32,
    /// Adaptive sampling on: passes of `ADAPTIVE_PASS` samples.
    adaptive: bool,
    pub ctx: Context,
}

/// Largest number of samples (pixels x spp) in one launch, so a display GPU is never stalled
/// for long.
const MAX_SAMPLES_PER_LAUNCH: u32 = 1 << 22;

struct Resources {
    pipeline: RtPipeline,
    accel: SceneAccel,
    params: Buffer,
    tables: Vec<Buffer>,
    /// The split table (`kernel::split`), host-visible: one word per tile.
    splits: Buffer,
    accum: Image,
    accum_sq: Image,
    pilots: Image,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
}

const STORAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::STORAGE_BUFFER;

impl GpuRenderer {
    /// Opens a device (see [`Context::new`]) and uploads `scene`, to be rendered with
    /// `settings`.
    pub fn new(
        scene: &Scene,
        settings: &RenderSettings,
        device: Option<usize>,
        validation: bool,
    ) -> Result<GpuRenderer> {
        let ctx = Context::new(device, validation)?;
        limits::check_scene_fits(scene, &ctx.limits)?;
        let (w, h) = (scene.camera.width, scene.camera.height);
        let features = scene.features(settings);
        let hit_groups = HitGroups::for_scene(scene, settings);
        let t0 = Instant::now();
        let accel = ctx.build_scene_accel(scene, hit_groups)?;
        let accel_build_time = t0.elapsed();
        let t1 = Instant::now();
        let pipeline = RtPipeline::new(&ctx, crate::KERNEL_SPV, features, hit_groups)?;
        let pipeline_time = t1.elapsed();

        let params = ctx.create_buffer(
            "params",
            std::mem::size_of::<RenderParams>() as u64,
            STORAGE,
            MemoryLocation::CpuToGpu,
        )?;
        let tiles = w.div_ceil(SPLIT_TILE) as u64 * h.div_ceil(SPLIT_TILE) as u64;
        let mut splits = ctx.create_buffer(
            "splits",
            4 * tiles.max(1),
            STORAGE,
            MemoryLocation::CpuToGpu,
        )?;
        ctx.write_buffer(
            &mut splits,
            bytemuck::cast_slice(&vec![1u32; tiles as usize]),
        )?;
        // Empty tables still need a buffer behind their binding.
        let tables = vec![
            ctx.upload_buffer("materials", bytemuck::cast_slice(&scene.materials), STORAGE)?,
            ctx.upload_buffer(
                "lights",
                bytemuck::cast_slice(&scene.light_table(settings)),
                STORAGE,
            )?,
            ctx.upload_buffer("triangles", bytemuck::cast_slice(&scene.triangles), STORAGE)?,
            ctx.upload_buffer("spheres", bytemuck::cast_slice(&scene.spheres), STORAGE)?,
            ctx.upload_buffer(
                "environment",
                bytemuck::cast_slice(&scene.environment_table()),
                STORAGE,
            )?,
            ctx.upload_buffer(
                "shading",
                bytemuck::cast_slice(&scene.shading_table()),
                STORAGE,
            )?,
            ctx.upload_buffer(
                "textures",
                bytemuck::cast_slice(&scene.textures.words),
                STORAGE,
            )?,
            ctx.upload_buffer(
                "instances",
                bytemuck::cast_slice(&scene.instance_table()),
                STORAGE,
            )?,
            ctx.upload_buffer("media", bytemuck::cast_slice(&scene.media), STORAGE)?,
            ctx.upload_buffer("grids", bytemuck::cast_slice(&scene.grids.words), STORAGE)?,
        ];
        let accum = ctx.create_storage_image("accum", w, h)?;
        let accum_sq = ctx.create_storage_image("accum_sq", w, h)?;
        let pilots = ctx.create_storage_image("pilots", w, h)?;

        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_IMAGE,
                descriptor_count: 3,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: 12,
            },
        ];
        let (pool, set) = ctx.create_descriptor_set(pipeline.compiled.set_layout, &sizes)?;
        let tlas = [accel.tlas.handle];
        let mut as_write = vk::WriteDescriptorSetAccelerationStructureKHR::default()
            .acceleration_structures(&tlas);
        let image_info = |i: &Image| {
            [vk::DescriptorImageInfo::default()
                .image_view(i.view)
                .image_layout(vk::ImageLayout::GENERAL)]
        };
        let accum_info = image_info(&accum);
        let accum_sq_info = image_info(&accum_sq);
        let pilots_info = image_info(&pilots);
        let buffer_info = |b: &Buffer| {
            [vk::DescriptorBufferInfo::default()
                .buffer(b.buffer)
                .offset(0)
                .range(vk::WHOLE_SIZE)]
        };
        let infos = [
            buffer_info(&params),
            buffer_info(&tables[0]),
            buffer_info(&tables[1]),
            buffer_info(&tables[2]),
            buffer_info(&tables[3]),
            buffer_info(&tables[4]),
            buffer_info(&tables[5]),
            buffer_info(&tables[6]),
            buffer_info(&tables[7]),
            buffer_info(&tables[8]),
            buffer_info(&tables[9]),
            buffer_info(&splits),
        ];
        let buffer_bindings = [
            binding::PARAMS,
            binding::MATERIALS,
            binding::LIGHTS,
            binding::TRIANGLES,
            binding::SPHERES,
            binding::ENVIRONMENT,
            binding::SHADING,
            binding::TEXTURES,
            binding::INSTANCES,
            binding::MEDIA,
            binding::GRIDS,
            binding::SPLITS,
        ];
        let mut writes = vec![
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(binding::TLAS)
                .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                .descriptor_count(1)
                .push_next(&mut as_write),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(binding::ACCUM)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .image_info(&accum_info),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(binding::ACCUM_SQ)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .image_info(&accum_sq_info),
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(binding::PILOTS)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .image_info(&pilots_info),
        ];
        for (b, info) in buffer_bindings.iter().zip(&infos) {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(*b)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(info),
            );
        }
        unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(GpuRenderer {
            resources: Some(Resources {
                pipeline,
                accel,
                params,
                tables,
                splits,
                accum,
                accum_sq,
                pilots,
                pool,
                set,
            }),
            accel_build_time,
            pipeline_time,
            width: w,
            height: h,
            adaptive: settings.adaptive(),
            ctx,
        })
    }

    fn res(&self) -> &Resources {
        self.resources.as_ref().expect("resources live until drop")
    }

    /// One dispatch: `params.samples.count` samples per pixel starting at
    /// `params.samples.first`, added to the accumulation images.
    pub fn dispatch(&mut self, params: &RenderParams) -> Result<()> {
        let (w, h) = (self.width, self.height);
        let res = self.resources.as_mut().expect("resources live until drop");
        self.ctx
            .write_buffer(&mut res.params, bytemuck::bytes_of(params))?;
        let res = self.res();
        let ctx = &self.ctx;
        ctx.submit_and_wait(|cmd| unsafe {
            // Earlier dispatches' image writes (and the host's params write) before this one.
            let barrier = vk::MemoryBarrier::default()
                .src_access_mask(
                    vk::AccessFlags::SHADER_WRITE
                        | vk::AccessFlags::TRANSFER_WRITE
                        | vk::AccessFlags::HOST_WRITE,
                )
                .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
            ctx.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::ALL_COMMANDS | vk::PipelineStageFlags::HOST,
                vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            );
            ctx.device.cmd_bind_pipeline(
                cmd,
                vk::PipelineBindPoint::RAY_TRACING_KHR,
                res.pipeline.compiled.pipeline,
            );
            ctx.device.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::RAY_TRACING_KHR,
                res.pipeline.compiled.layout,
                0,
                &[res.set],
                &[],
            );
            ctx.rt.cmd_trace_rays(
                cmd,
                &res.pipeline.raygen_region,
                &res.pipeline.miss_region,
                &res.pipeline.hit_region,
                &vk::StridedDeviceAddressRegionKHR::default(),
                w,
                h,
                1,
            );
        })
        .context("ray-tracing dispatch failed")
    }

    /// Reads the running means and M2 back (one readback per image) into a film of sums:
    /// sum = n mean, sum of squares = M2 + n mean^2 (in f64, where this loses nothing).
    pub fn read_film(&self) -> Result<Film> {
        let res = self.res();
        let means = self.ctx.read_image(&res.accum, self.width, self.height)?;
        let m2s = self
            .ctx
            .read_image(&res.accum_sq, self.width, self.height)?;
        let pilots = self.ctx.read_image(&res.pilots, self.width, self.height)?;
        let mut film = Film::new(self.width, self.height);
        for (i, ((m, q), p)) in means.iter().zip(&m2s).zip(&pilots).enumerate() {
            // Pilots: luminance mean, M2 and count back to a sum and a sum of squares.
            let (mean, n) = (p[0] as f64, p[2] as f64);
            film.pilot[i] = [n * mean, p[1] as f64 + n * mean * mean];
            film.pilot_count[i] = p[2] as u32;
            let n = m[3] as f64;
            for c in 0..3 {
                let mean = m[c] as f64;
                film.sum[i][c] = FixedSum::from_f64(n * mean);
                film.sum_sq[i][c] = q[c] as f64 + n * mean * mean;
            }
            film.count[i] = m[3] as u32;
            film.discarded += q[3] as u64;
        }
        Ok(film)
    }
}

impl SampleBackend for GpuRenderer {
    /// 1, 2, 4, ... samples per pixel, up to `MAX_SAMPLES_PER_LAUNCH` samples per launch (the
    /// running mean's rounding depends on how samples are split into launches, so the split
    /// depends only on the image size and `done`); with adaptive sampling, `ADAPTIVE_PASS`,
    /// the same decision points as the CPU's.
    fn next_pass(&self, done: u32, spp: u32) -> u32 {
        let pass = if self.adaptive {
            ADAPTIVE_PASS
        } else {
            let pixels = (self.width * self.height).max(1);
            let cap = (MAX_SAMPLES_PER_LAUNCH / pixels).clamp(1, 64);
            // The doubling from 1: after k passes `done` = 2^k - 1 below the cap.
            (done + 1).min(cap)
        };
        pass.min(spp - done)
    }

    fn add_samples(
        &mut self,
        params: &RenderParams,
        _first: u32,
        count: u32,
        progress: Option<&ProgressBar>,
    ) -> Result<()> {
        self.dispatch(params)?;
        if let Some(p) = progress {
            p.inc(self.width as u64 * self.height as u64 * count as u64);
        }
        Ok(())
    }

    fn read_film(&self) -> Result<Film> {
        GpuRenderer::read_film(self)
    }

    fn clear_film(&mut self) -> Result<()> {
        let res = self.res();
        for image in [&res.accum, &res.accum_sq, &res.pilots] {
            self.ctx.clear_image(image)?;
        }
        Ok(())
    }

    /// Writes the table into the split buffer (no dispatch is in flight between passes:
    /// each waits for its end).
    fn set_splits(&mut self, splits: &[u32]) -> Result<()> {
        let res = self.resources.as_mut().expect("resources live until drop");
        let room = (res.splits.size / 4) as usize;
        anyhow::ensure!(
            splits.len() <= room,
            "split table of {} tiles for {room}",
            splits.len()
        );
        self.ctx
            .write_buffer(&mut res.splits, bytemuck::cast_slice(splits))
    }

    fn setup_times(&self) -> (Duration, Duration) {
        (self.accel_build_time, self.pipeline_time)
    }

    fn accel_bytes(&self) -> u64 {
        self.resources.as_ref().map_or(0, |r| r.accel.bytes())
    }
}

impl Drop for GpuRenderer {
    fn drop(&mut self) {
        if let Some(r) = self.resources.take() {
            let ctx = &self.ctx;
            unsafe {
                let _ = ctx.device.device_wait_idle();
                ctx.device.destroy_descriptor_pool(r.pool, None);
            }
            r.pipeline.destroy(ctx);
            ctx.destroy_scene_accel(r.accel);
            ctx.destroy_buffer(r.params);
            for b in r.tables {
                ctx.destroy_buffer(b);
            }
            ctx.destroy_buffer(r.splits);
            ctx.destroy_image(r.accum);
            ctx.destroy_image(r.accum_sq);
            ctx.destroy_image(r.pilots);
        }
    }
}
