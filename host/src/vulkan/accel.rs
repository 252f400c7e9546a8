//! Acceleration structures: one triangle BLAS per world-space triangle group (each flattened
//! mesh, and the quads), one AABB BLAS for all spheres (intersected by the kernel's own
//! ray/sphere function), one triangle BLAS per instanced mesh (object space), and the TLAS over
//! them: an identity instance per world-space BLAS, and per `kernel::scene::Instance` an
//! instance of its mesh's BLAS with its object-to-world matrix. Geometry a scene lacks gets no
//! BLAS.

use super::device::Context;
use super::memory::Buffer;
use super::pipeline::HitGroups;
use crate::scene::Scene;
use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// An acceleration structure and the buffer holding it.
pub struct AccelerationStructure {
    pub handle: vk::AccelerationStructureKHR,
    pub buffer: Buffer,
    pub address: vk::DeviceAddress,
}

/// The scene's acceleration structures.
pub struct SceneAccel {
    pub blases: Vec<AccelerationStructure>,
    pub tlas: AccelerationStructure,
}

impl SceneAccel {
    /// Device bytes of every acceleration structure (the driver's sizes).
    pub fn bytes(&self) -> u64 {
        self.blases.iter().map(|b| b.buffer.size).sum::<u64>() + self.tlas.buffer.size
    }
}

const INPUT_USAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR.as_raw()
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS.as_raw(),
);

impl Context {
    /// Builds one acceleration structure from one geometry with `primitive_count` primitives.
    fn build_accel(
        &self,
        name: &str,
        ty: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR<'_>,
        primitive_count: u32,
    ) -> Result<AccelerationStructure> {
        let geometries = [geometry];
        let mut build = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(ty)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometries);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        unsafe {
            self.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &build,
                &[primitive_count],
                &mut sizes,
            )
        };
        let buffer = self.create_buffer(
            name,
            sizes.acceleration_structure_size,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let handle = unsafe {
            self.accel.create_acceleration_structure(
                &vk::AccelerationStructureCreateInfoKHR::default()
                    .buffer(buffer.buffer)
                    .size(sizes.acceleration_structure_size)
                    .ty(ty),
                None,
            )
        }
        .with_context(|| format!("cannot create acceleration structure {name}"))?;
        let align = self.rt_properties.min_scratch_offset_alignment.max(1) as u64;
        let scratch = self.create_buffer(
            "scratch",
            sizes.build_scratch_size + align,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        build = build
            .dst_acceleration_structure(handle)
            .scratch_data(vk::DeviceOrHostAddressKHR {
                device_address: scratch.address.div_ceil(align) * align,
            });
        let range =
            [vk::AccelerationStructureBuildRangeInfoKHR::default()
                .primitive_count(primitive_count)];
        let result = self.submit_and_wait(|cmd| unsafe {
            self.accel
                .cmd_build_acceleration_structures(cmd, &[build], &[&range]);
            let barrier = vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::ACCELERATION_STRUCTURE_WRITE_KHR)
                .dst_access_mask(vk::AccessFlags::ACCELERATION_STRUCTURE_READ_KHR);
            self.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::ACCELERATION_STRUCTURE_BUILD_KHR,
                vk::PipelineStageFlags::ACCELERATION_STRUCTURE_BUILD_KHR
                    | vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            );
        });
        self.destroy_buffer(scratch);
        result?;
        let address = unsafe {
            self.accel.get_acceleration_structure_device_address(
                &vk::AccelerationStructureDeviceAddressInfoKHR::default()
                    .acceleration_structure(handle),
            )
        };
        Ok(AccelerationStructure {
            handle,
            buffer,
            address,
        })
    }

    /// A BLAS over `triangles` (non-indexed vertices p0, p0 + edge1, p0 + edge2 per
    /// triangle, as on the CPU); `inputs` keeps the vertex buffer until the TLAS is built.
    /// Its geometry is not OPAQUE, so the any-hit shaders see every candidate (they drop the
    /// hits a ray cannot make, `kernel::plane_side`, and holes, `kernel::opacity`).
    fn triangle_blas(
        &self,
        name: &str,
        triangles: &[kernel::scene::Triangle],
        inputs: &mut Vec<Buffer>,
    ) -> Result<AccelerationStructure> {
        let mut vertices: Vec<[f32; 3]> = Vec::with_capacity(3 * triangles.len());
        for t in triangles {
            let p0 = glam::Vec3::from(t.p0);
            vertices.push(t.p0);
            vertices.push((p0 + glam::Vec3::from(t.edge1)).to_array());
            vertices.push((p0 + glam::Vec3::from(t.edge2)).to_array());
        }
        let vb = self.upload_buffer("vertices", bytemuck::cast_slice(&vertices), INPUT_USAGE)?;
        let data = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
            .vertex_format(vk::Format::R32G32B32_SFLOAT)
            .vertex_data(vk::DeviceOrHostAddressConstKHR {
                device_address: vb.address,
            })
            .vertex_stride(12)
            .max_vertex(vertices.len() as u32 - 1)
            .index_type(vk::IndexType::NONE_KHR);
        inputs.push(vb);
        let geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
            .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: data })
            .flags(vk::GeometryFlagsKHR::empty());
        self.build_accel(
            &format!("BLAS {name}"),
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            geometry,
            triangles.len() as u32,
        )
    }

    /// Builds the BLASes the scene needs and the TLAS over them.
    pub fn build_scene_accel(&self, scene: &Scene, hit_groups: HitGroups) -> Result<SceneAccel> {
        let mut blases = Vec::new();
        let mut instances = Vec::new();
        let mut inputs = Vec::new();
        let result = (|| -> Result<()> {
            for group in &scene.triangle_groups {
                if group.range.is_empty() {
                    continue;
                }
                if group.range.start >= 1 << 24 {
                    anyhow::bail!(
                        "{}: triangles beyond index 2^24 cannot be addressed by a 24-bit instance index",
                        group.name
                    );
                }
                let blas = self.triangle_blas(
                    &group.name,
                    &scene.triangles[group.range.clone()],
                    &mut inputs,
                )?;
                instances.push(instance(
                    blas.address,
                    IDENTITY,
                    group.range.start as u32,
                    hit_groups.triangle_offset(),
                ));
                blases.push(blas);
            }
            let mut mesh_blases = Vec::with_capacity(scene.meshes.len());
            for mesh in &scene.meshes {
                let blas = self.triangle_blas(
                    &mesh.name,
                    &scene.triangles[mesh.range.clone()],
                    &mut inputs,
                )?;
                mesh_blases.push(blas.address);
                blases.push(blas);
            }
            for (k, (inst, &mesh)) in scene
                .instances
                .iter()
                .zip(&scene.instance_meshes)
                .enumerate()
            {
                instances.push(instance(
                    mesh_blases[mesh as usize],
                    inst.object_to_world,
                    k as u32,
                    hit_groups.instance_offset(),
                ));
            }
            if !scene.spheres.is_empty() {
                let aabbs: Vec<vk::AabbPositionsKHR> = scene
                    .spheres
                    .iter()
                    .map(|s| vk::AabbPositionsKHR {
                        min_x: s.center[0] - s.radius,
                        min_y: s.center[1] - s.radius,
                        min_z: s.center[2] - s.radius,
                        max_x: s.center[0] + s.radius,
                        max_y: s.center[1] + s.radius,
                        max_z: s.center[2] + s.radius,
                    })
                    .collect();
                let bytes: Vec<u8> = aabbs
                    .iter()
                    .flat_map(|a| {
                        [a.min_x, a.min_y, a.min_z, a.max_x, a.max_y, a.max_z]
                            .into_iter()
                            .flat_map(f32::to_ne_bytes)
                    })
                    .collect();
                let ab = self.upload_buffer("sphere AABBs", &bytes, INPUT_USAGE)?;
                let aabb_data = vk::AccelerationStructureGeometryAabbsDataKHR::default()
                    .data(vk::DeviceOrHostAddressConstKHR {
                        device_address: ab.address,
                    })
                    .stride(24);
                let geometry = vk::AccelerationStructureGeometryKHR::default()
                    .geometry_type(vk::GeometryTypeKHR::AABBS)
                    .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs: aabb_data })
                    .flags(vk::GeometryFlagsKHR::OPAQUE);
                let blas = self.build_accel(
                    "BLAS spheres",
                    vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
                    geometry,
                    scene.spheres.len() as u32,
                )?;
                inputs.push(ab);
                instances.push(instance(
                    blas.address,
                    IDENTITY,
                    0,
                    hit_groups.sphere_offset(),
                ));
                blases.push(blas);
            }
            Ok(())
        })();
        let tlas = result.and_then(|_| {
            let bytes: Vec<u8> = instances.iter().flat_map(instance_bytes).collect();
            let ib = self.upload_buffer("instances", &bytes, INPUT_USAGE)?;
            let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
                .array_of_pointers(false)
                .data(vk::DeviceOrHostAddressConstKHR {
                    device_address: ib.address,
                });
            let geometry = vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::INSTANCES)
                .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data })
                .flags(vk::GeometryFlagsKHR::OPAQUE);
            let tlas = self.build_accel(
                "TLAS",
                vk::AccelerationStructureTypeKHR::TOP_LEVEL,
                geometry,
                instances.len() as u32,
            );
            inputs.push(ib);
            tlas
        });
        for b in inputs {
            self.destroy_buffer(b);
        }
        match tlas {
            Ok(tlas) => Ok(SceneAccel { blases, tlas }),
            Err(e) => {
                for b in blases {
                    self.destroy_accel(b);
                }
                Err(e)
            }
        }
    }

    pub fn destroy_accel(&self, a: AccelerationStructure) {
        unsafe { self.accel.destroy_acceleration_structure(a.handle, None) };
        self.destroy_buffer(a.buffer);
    }

    pub fn destroy_scene_accel(&self, s: SceneAccel) {
        self.destroy_accel(s.tlas);
        for b in s.blases {
            self.destroy_accel(b);
        }
    }
}

/// The identity as a row-major 3 x 4 matrix.
const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// An instance of a BLAS placed by the row-major 3 x 4 `transform`; `custom_index` reaches the
/// shaders as `instance_custom_index` (a world-space group's first triangle, or the index of a
/// `kernel::scene::Instance`), `hit_group` selects the SBT record.
fn instance(
    blas: vk::DeviceAddress,
    transform: [f32; 12],
    custom_index: u32,
    hit_group: u32,
) -> vk::AccelerationStructureInstanceKHR {
    vk::AccelerationStructureInstanceKHR {
        transform: vk::TransformMatrixKHR { matrix: transform },
        instance_custom_index_and_mask: vk::Packed24_8::new(custom_index, 0xff),
        instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(
            hit_group,
            vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE.as_raw() as u8,
        ),
        acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
            device_handle: blas,
        },
    }
}

/// The 64 bytes of a VkAccelerationStructureInstanceKHR.
fn instance_bytes(i: &vk::AccelerationStructureInstanceKHR) -> Vec<u8> {
    let size = std::mem::size_of::<vk::AccelerationStructureInstanceKHR>();
    debug_assert_eq!(size, 64);
    // SAFETY: a repr(C) struct of plain integers and floats with no padding (64 bytes).
    unsafe { std::slice::from_raw_parts(i as *const _ as *const u8, size) }.to_vec()
}
