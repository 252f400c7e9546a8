//! Which backend renders, and opening it for a scene: the CPU always, the GPU (Vulkan ray
//! tracing) where the crate is built with the `gpu` feature and a device is usable; `auto`
//! chooses as a user would.

use super::SampleBackend;
use crate::cpu::CpuBackend;
use crate::scene::Scene;
use crate::settings::RenderSettings;
#[cfg(not(feature = "gpu"))]
use anyhow::bail;
use anyhow::Result;

/// Which backend renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Backend {
    /// The GPU when a Vulkan ray-tracing device is present, else the CPU.
    Auto,
    Cpu,
    Gpu,
}

/// The backend `kind` asks for, prepared for `scene` rendered with `settings`, and the kind it
/// is (never `Auto`):
/// `Gpu` opens Vulkan device `device` (or the best usable one), with the validation layers
/// if `validation`; `Auto` the GPU where one is usable and not itself a CPU implementation,
/// else the CPU (saying why on stderr); `Cpu` the CPU.
pub fn open(
    kind: Backend,
    scene: &Scene,
    settings: &RenderSettings,
    device: Option<usize>,
    validation: bool,
) -> Result<(Box<dyn SampleBackend>, Backend)> {
    let gpu = match kind {
        Backend::Cpu => None,
        Backend::Gpu => Some(open_gpu(scene, settings, device, validation)?),
        Backend::Auto => match auto_prefers_cpu(device) {
            Some(reason) => {
                eprintln!("twinpath: --backend auto: {reason}; using the CPU backend");
                None
            }
            None => match open_gpu(scene, settings, device, validation) {
                Ok(g) => Some(g),
                Err(e) => {
                    eprintln!("twinpath: --backend auto: no usable GPU ({e:#}); using the CPU");
                    None
                }
            },
        },
    };
    Ok(match gpu {
        Some(g) => (g, Backend::Gpu),
        None => (Box::new(CpuBackend::new(scene, settings)), Backend::Cpu),
    })
}

/// The GPU backend for `scene` on device `device`.
#[cfg(feature = "gpu")]
fn open_gpu(
    scene: &Scene,
    settings: &RenderSettings,
    device: Option<usize>,
    validation: bool,
) -> Result<Box<dyn SampleBackend>> {
    Ok(Box::new(crate::vulkan::GpuRenderer::new(
        scene, settings, device, validation,
    )?))
}

/// Without the `gpu` feature there is no GPU backend.
#[cfg(not(feature = "gpu"))]
fn open_gpu(
    _scene: &Scene,
    _settings: &RenderSettings,
    _device: Option<usize>,
    _validation: bool,
) -> Result<Box<dyn SampleBackend>> {
    bail!("this twinpath was built without the GPU backend (cargo feature `gpu`)")
}

#[cfg(feature = "gpu")]
/// Why `--backend auto` should render on the CPU without trying a Vulkan device: the best
/// usable device is itself a CPU implementation (lavapipe/llvmpipe runs the same kernel on the
/// same cores, about 3x slower than the native backend). None when a real GPU is usable, or a
/// device was named with `--device`, or no device is usable (then opening one reports why).
fn auto_prefers_cpu(device: Option<usize>) -> Option<String> {
    if device.is_some() {
        return None;
    }
    let devices = crate::vulkan::device::list_devices().ok()?;
    let usable: Vec<_> = devices.iter().filter(|d| d.usable()).collect();
    if !usable.is_empty()
        && usable
            .iter()
            .all(|d| d.device_type == ash::vk::PhysicalDeviceType::CPU)
    {
        Some(format!(
            "the only ray-tracing Vulkan device is a CPU implementation ({}; --backend gpu uses it)",
            usable[0].name
        ))
    } else {
        None
    }
}

/// Without the GPU backend, `auto` renders on the CPU without saying so.
#[cfg(not(feature = "gpu"))]
fn auto_prefers_cpu(_device: Option<usize>) -> Option<String> {
    None
}
