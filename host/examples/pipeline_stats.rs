//! Compiles the ray-tracing pipeline that a render of SCENE would use, and nothing else: no
//! acceleration structure, no shader binding table, no dispatch; then prints the ray-generation
//! group's stack size (`vkGetRayTracingShaderGroupStackSizeKHR`). With Mesa's RADV on null
//! hardware (`RADV_FORCE_FAMILY=navi31`, no GPU needed) and `RADV_DEBUG=shaderstats`, the
//! driver prints each shader's registers, instructions, occupancy and estimated throughput: an
//! offline proxy for what a GPU compiler makes of the kernel, which lavapipe's timings cannot
//! show (`scripts/shader_stats.sh`, docs/gpu.md). With `--separate` the pipeline carries an
//! unused callable shader, which makes RADV compile the stages apart as hardware-traversal GPUs
//! do; the stack size is then what the ray-generation shader keeps live across its trace calls
//! (`vulkan::pipeline::Compilation::Separate`). On a real GPU the same run prints its driver's
//! stack size. MODULE replaces the shipped SPIR-V module, e.g. an earlier commit's
//! `kernel/shipped/kernel.spv`.
//!
//! Usage: `cargo run --example pipeline_stats -- SCENE [MODULE.spv] [--separate] [--device N]`

use anyhow::{bail, Context as _, Result};
use std::path::Path;
use twinpath::scene::SceneFile;
use twinpath::vulkan::device::Context;
use twinpath::vulkan::pipeline::{Compilation, CompiledPipeline, HitGroups};

fn main() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let device = match args.iter().position(|a| a == "--device") {
        Some(i) => {
            let n = args
                .get(i + 1)
                .context("--device needs a number")?
                .parse()?;
            args.drain(i..i + 2);
            Some(n)
        }
        None => None,
    };
    let compilation = match args.iter().position(|a| a == "--separate") {
        Some(i) => {
            args.remove(i);
            Compilation::Separate
        }
        None => Compilation::Render,
    };
    let (scene, module) = match args.as_slice() {
        [scene] => (scene, None),
        [scene, module] => (scene, Some(module)),
        _ => bail!("usage: pipeline_stats SCENE [MODULE.spv] [--separate] [--device N]"),
    };
    let file = SceneFile::load(Path::new(scene))?;
    let spv = match module {
        Some(path) => std::fs::read(path).with_context(|| format!("reading {path}"))?,
        None => twinpath::KERNEL_SPV.to_vec(),
    };
    let ctx = Context::new(device, false)?;
    let features = file.scene.features(&file.settings);
    let hit_groups = HitGroups::for_scene(&file.scene, &file.settings);
    let pipeline = CompiledPipeline::new(&ctx, &spv, features, hit_groups, compilation)?;
    println!(
        "{}: features {features:#x}, {hit_groups:?}, {compilation:?}: raygen stack {} bytes",
        ctx.device_name,
        pipeline.raygen_stack_size(&ctx)
    );
    pipeline.destroy(&ctx);
    // A null device (RADV_FORCE_FAMILY) cannot wait for idle, which dropping the context does:
    // the process exits without dropping it.
    std::process::exit(0)
}
