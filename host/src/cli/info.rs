//! `twinpath info`: what this build contains and which devices can run it.

use anyhow::Result;

/// What this build contains: the SPIR-V module and the backends.
pub fn run() -> Result<()> {
    println!("twinpath {}", env!("CARGO_PKG_VERSION"));
    println!("cpu backend: {} threads", rayon::current_num_threads());
    gpu();
    Ok(())
}

/// Without the `gpu` feature: no SPIR-V module, no Vulkan.
#[cfg(not(feature = "gpu"))]
fn gpu() {
    println!("gpu backend: not built (cargo feature `gpu`)");
}

/// The SPIR-V module and the Vulkan devices.
#[cfg(feature = "gpu")]
fn gpu() {
    println!(
        "kernel SPIR-V module: {} bytes, {}",
        twinpath::KERNEL_SPV.len(),
        twinpath::KERNEL_ORIGIN
    );
    match twinpath::vulkan::device::list_devices() {
        Ok(devices) if devices.is_empty() => println!("gpu backend: no Vulkan devices"),
        Ok(devices) => {
            println!("gpu backend: Vulkan devices (use --device N):");
            for d in devices {
                let (ma, mi, pa) = d.api_version;
                let status = if d.usable() {
                    "usable (ray-tracing pipelines)".to_string()
                } else {
                    format!("lacks {}", d.missing.join(", "))
                };
                let ray_query = if d.ray_query { "yes" } else { "no" };
                let status = format!("{status}; ray queries: {ray_query} (not needed)");
                println!(
                    "  [{}] {} ({:?}, Vulkan {ma}.{mi}.{pa}): {status}",
                    d.index, d.name, d.device_type
                );
                if !d.driver.is_empty() {
                    println!("      driver: {}", d.driver);
                }
                println!(
                    "      32-bit float controls offered: {}; requested by the kernel: {} (its error bounds assume none)",
                    d.float_controls.describe(),
                    d.float_controls.requested().describe()
                );
            }
        }
        Err(e) => println!("gpu backend: unavailable: {e:#}"),
    }
}
