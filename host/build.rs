//! Compiles `kernel/` to one SPIR-V module with rust-gpu on every build; the module's path
//! reaches the host as the env var `kernel.spv` (see `vulkan::KERNEL_SPV`).
fn main() -> Result<(), Box<dyn std::error::Error>> {
    #[cfg(feature = "gpu")]
    build_kernel()?;
    Ok(())
}

#[cfg(feature = "gpu")]
fn build_kernel() -> Result<(), Box<dyn std::error::Error>> {
    use spirv_builder::{Capability, SpirvBuilder};
    let kernel = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kernel");
    // Ray-tracing pipelines only: no entry point uses ray queries, and declaring RayQueryKHR
    // would make the module unusable on devices without VK_KHR_ray_query.
    let mut builder = SpirvBuilder::new(kernel, "spirv-unknown-vulkan1.2")
        .capability(Capability::RayTracingKHR)
        .extension("SPV_KHR_ray_tracing");
    builder.build_script.defaults = true;
    builder.build_script.env_shader_spv_path = Some(true);
    builder.build()?;
    Ok(())
}
