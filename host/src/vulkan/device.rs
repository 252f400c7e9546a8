//! Vulkan instance, device selection and the logical device with the ray-tracing extensions.

use super::float_controls::FloatControls;
use super::limits::DeviceLimits;
use anyhow::{anyhow, bail, Context as _, Result};
use ash::{ext, khr, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Device extensions the backend needs: ray-tracing pipelines over acceleration structures.
/// Not `VK_KHR_ray_query`: the kernel module declares no RayQueryKHR capability (a test checks),
/// since some drivers (NVIDIA's data-centre ones) offer pipelines without ray queries.
pub const REQUIRED_EXTENSIONS: [&CStr; 3] = [
    khr::acceleration_structure::NAME,
    khr::ray_tracing_pipeline::NAME,
    khr::deferred_host_operations::NAME,
];

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Errors and warnings reported by the validation layers since start-up (all devices).
pub static VALIDATION_ERRORS: AtomicUsize = AtomicUsize::new(0);
pub static VALIDATION_WARNINGS: AtomicUsize = AtomicUsize::new(0);

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    let message = if data.is_null() || unsafe { (*data).p_message.is_null() } {
        std::borrow::Cow::Borrowed("(no message)")
    } else {
        unsafe { CStr::from_ptr((*data).p_message) }.to_string_lossy()
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        VALIDATION_ERRORS.fetch_add(1, Ordering::SeqCst);
        eprintln!("vulkan validation error: {message}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        VALIDATION_WARNINGS.fetch_add(1, Ordering::SeqCst);
        eprintln!("vulkan validation warning: {message}");
    }
    vk::FALSE
}

/// A candidate device and whether it can run the backend.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    pub api_version: (u32, u32, u32),
    /// Required extensions it lacks (empty: usable).
    pub missing: Vec<String>,
    /// Whether it offers `VK_KHR_ray_query` (not needed by twinpath; reported by `info`).
    pub ray_query: bool,
    /// The driver's name and version string (`VkPhysicalDeviceDriverProperties`), or empty.
    pub driver: String,
    /// What it offers for 32-bit float arithmetic (`VkPhysicalDeviceFloatControlsProperties`).
    pub float_controls: FloatControls,
}

impl DeviceInfo {
    pub fn usable(&self) -> bool {
        self.missing.is_empty()
    }
}

fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

/// Ray-tracing properties the pipeline and acceleration structures are laid out by.
#[derive(Clone, Copy, Debug)]
pub struct RtProperties {
    pub shader_group_handle_size: u32,
    pub shader_group_base_alignment: u32,
    pub shader_group_handle_alignment: u32,
    pub max_ray_recursion_depth: u32,
    pub min_scratch_offset_alignment: u32,
}

/// The Vulkan objects every part of the backend uses.
pub struct Context {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    debug: Option<(ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub physical_device: vk::PhysicalDevice,
    pub device_name: String,
    /// What the device offers for 32-bit floats; the kernel's module asks for it
    /// (`super::float_controls`).
    pub float_controls: FloatControls,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub command_pool: vk::CommandPool,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    pub accel: khr::acceleration_structure::Device,
    pub rt: khr::ray_tracing_pipeline::Device,
    pub rt_properties: RtProperties,
    /// What a scene must fit (`super::limits`).
    pub limits: DeviceLimits,
    pub validation: bool,
}

fn create_instance(entry: &ash::Entry, validation: bool) -> Result<ash::Instance> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"twinpath")
        .api_version(vk::API_VERSION_1_2);
    let layers = [VALIDATION_LAYER.as_ptr()];
    let extensions = [ext::debug_utils::NAME.as_ptr()];
    let mut info = vk::InstanceCreateInfo::default().application_info(&app);
    if validation {
        info = info
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
    }
    unsafe { entry.create_instance(&info, None) }.context("vkCreateInstance failed")
}

fn load_entry() -> Result<ash::Entry> {
    unsafe { ash::Entry::load() }
        .map_err(|e| anyhow!("cannot load the Vulkan loader (libvulkan.so.1): {e}"))
}

/// Whether the validation layers are installed.
pub fn validation_layer_available(entry: &ash::Entry) -> bool {
    unsafe { entry.enumerate_instance_layer_properties() }
        .map(|layers| {
            layers
                .iter()
                .any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER))
        })
        .unwrap_or(false)
}

fn describe(instance: &ash::Instance, index: usize, pd: vk::PhysicalDevice) -> DeviceInfo {
    let props = unsafe { instance.get_physical_device_properties(pd) };
    let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
    let offers = |want: &CStr| {
        exts.iter()
            .any(|e| e.extension_name_as_c_str().ok() == Some(want))
    };
    let missing = REQUIRED_EXTENSIONS
        .iter()
        .filter(|want| !offers(want))
        .map(|e| e.to_string_lossy().into_owned())
        .collect();
    let mut info = DeviceInfo {
        index,
        name: props
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        device_type: props.device_type,
        api_version: (
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version),
            vk::api_version_patch(props.api_version),
        ),
        missing,
        ray_query: offers(khr::ray_query::NAME),
        driver: String::new(),
        float_controls: FloatControls::default(),
    };
    // Vulkan 1.2 core properties: only asked of a device that reports 1.2 or later.
    if props.api_version >= vk::API_VERSION_1_2 {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut controls = vk::PhysicalDeviceFloatControlsProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver)
            .push_next(&mut controls);
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let text = |name: Result<&CStr, _>| {
            name.map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        info.driver = format!(
            "{} {}",
            text(driver.driver_name_as_c_str()),
            text(driver.driver_info_as_c_str())
        )
        .trim()
        .to_string();
        info.float_controls = FloatControls::from_properties(&controls);
    }
    info
}

/// Every Vulkan device on this machine, with what each lacks for the backend.
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let instance = create_instance(&entry, false)?;
    let pds = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
    let list = pds
        .iter()
        .enumerate()
        .map(|(i, &pd)| describe(&instance, i, pd))
        .collect();
    unsafe { instance.destroy_instance(None) };
    Ok(list)
}

impl Context {
    /// Opens device `index` (or the best usable one: discrete GPUs first), with the validation
    /// layers when `validation` is set (an error if they are not installed).
    pub fn new(index: Option<usize>, validation: bool) -> Result<Context> {
        let entry = load_entry()?;
        if validation && !validation_layer_available(&entry) {
            bail!("validation requested but VK_LAYER_KHRONOS_validation is not installed (Debian package vulkan-validationlayers)");
        }
        let instance = create_instance(&entry, validation)?;
        let debug = if validation {
            let loader = ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback));
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }?;
            Some((loader, messenger))
        } else {
            None
        };
        let pds = unsafe { instance.enumerate_physical_devices() }?;
        let infos: Vec<DeviceInfo> = pds
            .iter()
            .enumerate()
            .map(|(i, &pd)| describe(&instance, i, pd))
            .collect();
        let chosen = match index {
            Some(i) => {
                let info = infos.get(i).ok_or_else(|| {
                    anyhow!(
                        "--device {i}: there are only {} Vulkan devices",
                        infos.len()
                    )
                })?;
                if !info.usable() {
                    bail!(
                        "device {i} ({}) lacks {}",
                        info.name,
                        info.missing.join(", ")
                    );
                }
                info.clone()
            }
            None => {
                let mut usable: Vec<&DeviceInfo> = infos.iter().filter(|d| d.usable()).collect();
                usable.sort_by_key(|d| (type_rank(d.device_type), d.index));
                match usable.first() {
                    Some(d) => (*d).clone(),
                    None => {
                        let detail = if infos.is_empty() {
                            "no Vulkan device found".to_string()
                        } else {
                            infos
                                .iter()
                                .map(|d| format!("{} lacks {}", d.name, d.missing.join(", ")))
                                .collect::<Vec<_>>()
                                .join("; ")
                        };
                        bail!("no Vulkan device supports ray tracing: {detail}");
                    }
                }
            }
        };
        let pd = pds[chosen.index];

        let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
        let queue_family = families
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
            .ok_or_else(|| anyhow!("device has no compute queue"))?
            as u32;
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let ext_names: Vec<*const i8> = REQUIRED_EXTENSIONS.iter().map(|e| e.as_ptr()).collect();
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .buffer_device_address(true)
            .vulkan_memory_model(true);
        let mut f_as = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default()
            .acceleration_structure(true);
        let mut f_rt =
            vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&ext_names)
            .push_next(&mut f12)
            .push_next(&mut f_as)
            .push_next(&mut f_rt);
        let device =
            unsafe { instance.create_device(pd, &info, None) }.context("vkCreateDevice failed")?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let command_pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
        }?;

        let mut rt_props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut as_props = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut rt_props)
            .push_next(&mut as_props);
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let max_storage_buffer_range = props2.properties.limits.max_storage_buffer_range as u64;
        let rt_properties = RtProperties {
            shader_group_handle_size: rt_props.shader_group_handle_size,
            shader_group_base_alignment: rt_props.shader_group_base_alignment,
            shader_group_handle_alignment: rt_props.shader_group_handle_alignment,
            max_ray_recursion_depth: rt_props.max_ray_recursion_depth,
            min_scratch_offset_alignment: as_props
                .min_acceleration_structure_scratch_offset_alignment,
        };
        let limits = DeviceLimits {
            max_storage_buffer_range,
            max_primitive_count: as_props.max_primitive_count,
            max_instance_count: as_props.max_instance_count,
        };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: pd,
            debug_settings: Default::default(),
            buffer_device_address: true,
            allocation_sizes: Default::default(),
        })
        .context("cannot create the memory allocator")?;
        let accel = khr::acceleration_structure::Device::new(&instance, &device);
        let rt = khr::ray_tracing_pipeline::Device::new(&instance, &device);
        LIVE_CONTEXTS.fetch_add(1, Ordering::SeqCst);
        Ok(Context {
            entry,
            instance,
            debug,
            physical_device: pd,
            float_controls: chosen.float_controls,
            device_name: chosen.name,
            device,
            queue,
            queue_family,
            command_pool,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            accel,
            rt,
            rt_properties,
            limits,
            validation,
        })
    }

    /// Records commands with `record` into a fresh command buffer, submits it and waits.
    pub fn submit_and_wait(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let cmd = unsafe {
            self.device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(self.command_pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
        }?[0];
        let result = (|| -> Result<()> {
            unsafe {
                self.device.begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )?;
                record(cmd);
                self.device.end_command_buffer(cmd)?;
                let fence = self
                    .device
                    .create_fence(&vk::FenceCreateInfo::default(), None)?;
                let cmds = [cmd];
                let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
                let r = self
                    .device
                    .queue_submit(self.queue, &submit, fence)
                    .and_then(|_| self.wait_reporting(fence));
                self.device.destroy_fence(fence, None);
                r.context("queue submission failed (device lost?)")?;
            }
            Ok(())
        })();
        unsafe {
            self.device.free_command_buffers(self.command_pool, &[cmd]);
        }
        result
    }
}

impl Context {
    /// Waits for `fence` without a time limit, saying on stderr every minute that the work has
    /// not finished, with how many contexts this process holds: a hang reported on an NVIDIA
    /// H200 (two GPU tests in two threads of one process, each with its own context; docs/gpu.md)
    /// left no trace, and this is the trace the next run on such a device needs.
    fn wait_reporting(&self, fence: vk::Fence) -> ash::prelude::VkResult<()> {
        const STEP_S: u64 = 60;
        let mut waited = 0u64;
        loop {
            match unsafe {
                self.device
                    .wait_for_fences(&[fence], true, STEP_S * 1_000_000_000)
            } {
                Err(vk::Result::TIMEOUT) => {
                    waited += STEP_S;
                    eprintln!(
                        "twinpath: GPU work on {} not finished after {waited} s ({} Vulkan contexts open in this process)",
                        self.device_name,
                        LIVE_CONTEXTS.load(Ordering::SeqCst)
                    );
                }
                other => return other,
            }
        }
    }
}

/// How many [`Context`]s this process holds (for the report of [`Context::wait_reporting`]).
static LIVE_CONTEXTS: AtomicUsize = AtomicUsize::new(0);

impl Drop for Context {
    fn drop(&mut self) {
        LIVE_CONTEXTS.fetch_sub(1, Ordering::SeqCst);
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
