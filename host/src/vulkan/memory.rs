//! Buffers and images with memory from gpu-allocator.

use super::device::Context;
use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

/// A buffer, its memory, and its device address (when created with SHADER_DEVICE_ADDRESS).
pub struct Buffer {
    pub buffer: vk::Buffer,
    pub allocation: Option<Allocation>,
    pub size: u64,
    pub address: vk::DeviceAddress,
}

/// A 2D image and its view.
pub struct Image {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub allocation: Option<Allocation>,
}

impl Context {
    /// Memory from gpu-allocator for a resource with `requirements` (`linear`: a buffer).
    fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> gpu_allocator::Result<Allocation> {
        self.allocator
            .lock()
            .expect("allocator lock")
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
    }

    /// A buffer of `size` bytes (at least 1) in `location`.
    pub fn create_buffer(
        &self,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let size = size.max(16);
        let buffer = unsafe {
            self.device.create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(size)
                    .usage(usage)
                    .sharing_mode(vk::SharingMode::EXCLUSIVE),
                None,
            )
        }
        .with_context(|| format!("cannot create buffer {name} ({size} bytes)"))?;
        let requirements = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let allocation = self
            .allocate(name, requirements, location, true)
            .with_context(|| format!("cannot allocate memory for {name} ({size} bytes)"))?;
        unsafe {
            self.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }?;
        let address = if usage.contains(vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS) {
            unsafe {
                self.device.get_buffer_device_address(
                    &vk::BufferDeviceAddressInfo::default().buffer(buffer),
                )
            }
        } else {
            0
        };
        Ok(Buffer {
            buffer,
            allocation: Some(allocation),
            size,
            address,
        })
    }

    /// A host-visible buffer holding `data` (all of lavapipe's memory is host memory; on a
    /// discrete GPU this is memory the device reads over the bus, fine for scene tables).
    pub fn upload_buffer(
        &self,
        name: &str,
        data: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Buffer> {
        let mut b = self.create_buffer(name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
        self.write_buffer(&mut b, data)?;
        Ok(b)
    }

    /// Copies `data` to the start of a host-visible buffer.
    pub fn write_buffer(&self, b: &mut Buffer, data: &[u8]) -> Result<()> {
        let slice = b
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .context("buffer is not host-visible")?;
        slice[..data.len()].copy_from_slice(data);
        Ok(())
    }

    /// The contents of a host-visible buffer.
    pub fn read_buffer(&self, b: &Buffer) -> Result<Vec<u8>> {
        let slice = b
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .context("buffer is not host-visible")?;
        Ok(slice[..b.size as usize].to_vec())
    }

    pub fn destroy_buffer(&self, mut b: Buffer) {
        unsafe { self.device.destroy_buffer(b.buffer, None) };
        if let Some(a) = b.allocation.take() {
            let _ = self.allocator.lock().expect("allocator lock").free(a);
        }
    }

    /// A device-local RGBA32F storage image, left in GENERAL layout and cleared to zero.
    pub fn create_storage_image(&self, name: &str, width: u32, height: u32) -> Result<Image> {
        let format = vk::Format::R32G32B32A32_SFLOAT;
        let image = unsafe {
            self.device.create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width,
                        height,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::OPTIMAL)
                    .usage(
                        vk::ImageUsageFlags::STORAGE
                            | vk::ImageUsageFlags::TRANSFER_SRC
                            | vk::ImageUsageFlags::TRANSFER_DST,
                    )
                    .initial_layout(vk::ImageLayout::UNDEFINED),
                None,
            )
        }?;
        let requirements = unsafe { self.device.get_image_memory_requirements(image) };
        let allocation = self
            .allocate(name, requirements, MemoryLocation::GpuOnly, false)
            .with_context(|| format!("cannot allocate image {name} ({width}x{height})"))?;
        unsafe {
            self.device
                .bind_image_memory(image, allocation.memory(), allocation.offset())
        }?;
        let view = unsafe {
            self.device.create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(color_range()),
                None,
            )
        }?;
        self.submit_and_wait(|cmd| unsafe {
            self.image_barrier(
                cmd,
                image,
                (vk::ImageLayout::UNDEFINED, vk::ImageLayout::GENERAL),
                (vk::AccessFlags::empty(), vk::AccessFlags::TRANSFER_WRITE),
                (
                    vk::PipelineStageFlags::TOP_OF_PIPE,
                    vk::PipelineStageFlags::TRANSFER,
                ),
            );
            self.device.cmd_clear_color_image(
                cmd,
                image,
                vk::ImageLayout::GENERAL,
                &vk::ClearColorValue { float32: [0.0; 4] },
                &[color_range()],
            );
        })?;
        Ok(Image {
            image,
            view,
            allocation: Some(allocation),
        })
    }

    /// Sets every texel of a storage image (in `GENERAL` layout) to zero, after every earlier
    /// dispatch's writes to it.
    pub fn clear_image(&self, image: &Image) -> Result<()> {
        self.submit_and_wait(|cmd| unsafe {
            self.image_barrier(
                cmd,
                image.image,
                (vk::ImageLayout::GENERAL, vk::ImageLayout::GENERAL),
                (
                    vk::AccessFlags::SHADER_WRITE,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
                (
                    vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR,
                    vk::PipelineStageFlags::TRANSFER,
                ),
            );
            self.device.cmd_clear_color_image(
                cmd,
                image.image,
                vk::ImageLayout::GENERAL,
                &vk::ClearColorValue { float32: [0.0; 4] },
                &[color_range()],
            );
        })
    }

    /// Copies an RGBA32F image to host memory, row-major, 4 floats per pixel.
    pub fn read_image(&self, image: &Image, width: u32, height: u32) -> Result<Vec<[f32; 4]>> {
        let bytes = width as u64 * height as u64 * 16;
        let staging = self.create_buffer(
            "image readback",
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let result = self
            .submit_and_wait(|cmd| unsafe {
                self.image_barrier(
                    cmd,
                    image.image,
                    (
                        vk::ImageLayout::GENERAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    ),
                    (
                        vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE,
                        vk::AccessFlags::TRANSFER_READ,
                    ),
                    (
                        vk::PipelineStageFlags::ALL_COMMANDS,
                        vk::PipelineStageFlags::TRANSFER,
                    ),
                );
                let region = vk::BufferImageCopy::default()
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width,
                        height,
                        depth: 1,
                    });
                self.device.cmd_copy_image_to_buffer(
                    cmd,
                    image.image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    staging.buffer,
                    &[region],
                );
                self.image_barrier(
                    cmd,
                    image.image,
                    (
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::ImageLayout::GENERAL,
                    ),
                    (
                        vk::AccessFlags::TRANSFER_READ,
                        vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                    ),
                    (
                        vk::PipelineStageFlags::TRANSFER,
                        vk::PipelineStageFlags::ALL_COMMANDS,
                    ),
                );
            })
            .and_then(|_| self.read_buffer(&staging));
        self.destroy_buffer(staging);
        let raw = result?;
        Ok(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(
            &raw[..bytes as usize],
        ))
    }

    /// Records a layout transition of a whole colour image: (old, new) layouts, (source,
    /// destination) access masks and (source, destination) pipeline stages.
    fn image_barrier(
        &self,
        cmd: vk::CommandBuffer,
        image: vk::Image,
        layouts: (vk::ImageLayout, vk::ImageLayout),
        access: (vk::AccessFlags, vk::AccessFlags),
        stages: (vk::PipelineStageFlags, vk::PipelineStageFlags),
    ) {
        let barrier = vk::ImageMemoryBarrier::default()
            .image(image)
            .old_layout(layouts.0)
            .new_layout(layouts.1)
            .src_access_mask(access.0)
            .dst_access_mask(access.1)
            .subresource_range(color_range());
        unsafe {
            self.device.cmd_pipeline_barrier(
                cmd,
                stages.0,
                stages.1,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            );
        }
    }

    /// A descriptor pool sized by `sizes` holding one set of `layout`.
    pub fn create_descriptor_set(
        &self,
        layout: vk::DescriptorSetLayout,
        sizes: &[vk::DescriptorPoolSize],
    ) -> Result<(vk::DescriptorPool, vk::DescriptorSet)> {
        let pool = unsafe {
            self.device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(sizes),
                None,
            )
        }?;
        let layouts = [layout];
        let set = unsafe {
            self.device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
        };
        match set {
            Ok(sets) => Ok((pool, sets[0])),
            Err(e) => {
                unsafe { self.device.destroy_descriptor_pool(pool, None) };
                Err(e.into())
            }
        }
    }

    pub fn destroy_image(&self, mut image: Image) {
        unsafe {
            self.device.destroy_image_view(image.view, None);
            self.device.destroy_image(image.image, None);
        }
        if let Some(a) = image.allocation.take() {
            let _ = self.allocator.lock().expect("allocator lock").free(a);
        }
    }
}

pub fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}
