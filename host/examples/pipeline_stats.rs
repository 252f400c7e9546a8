//! Compiles the ray-tracing pipeline that a render of SCENE would use, and nothing else: no
//! acceleration structure, no dispatch. With Mesa's RADV on null hardware
//! (`RADV_FORCE_FAMILY=navi31`, no GPU needed) and `RADV_DEBUG=shaderstats`, the driver prints
//! each shader's registers, instructions, occupancy and estimated throughput: an offline proxy
//! for what a GPU compiler makes of the kernel, which lavapipe's timings cannot show
//! (`scripts/shader_stats.sh`, docs/gpu.md). MODULE replaces the shipped SPIR-V module, e.g. an
//! earlier commit's `kernel/shipped/kernel.spv`. On null hardware the shader binding table has
//! no memory to live in, so the run ends with that error, after the driver has printed the
//! statistics.
//!
//! Usage: `cargo run --example pipeline_stats -- SCENE [MODULE.spv] [--device N]`

use anyhow::{bail, Context as _, Result};
use std::path::Path;
use twinpath::scene::SceneFile;
use twinpath::vulkan::device::Context;
use twinpath::vulkan::pipeline::{HitGroups, RtPipeline};

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
    let (scene, module) = match args.as_slice() {
        [scene] => (scene, None),
        [scene, module] => (scene, Some(module)),
        _ => bail!("usage: pipeline_stats SCENE [MODULE.spv] [--device N]"),
    };
    let file = SceneFile::load(Path::new(scene))?;
    let spv = match module {
        Some(path) => std::fs::read(path).with_context(|| format!("reading {path}"))?,
        None => twinpath::KERNEL_SPV.to_vec(),
    };
    let ctx = Context::new(device, false)?;
    let features = file.scene.features(&file.settings);
    let hit_groups = HitGroups::for_scene(&file.scene, &file.settings);
    // A null device (RADV_FORCE_FAMILY) cannot wait for idle, which dropping the context does:
    // the process exits without dropping it.
    match RtPipeline::new(&ctx, &spv, features, hit_groups) {
        Ok(pipeline) => {
            println!(
                "{}: features {features:#x}, {hit_groups:?}: compiled",
                ctx.device_name
            );
            pipeline.destroy(&ctx);
            std::process::exit(0)
        }
        Err(e) => {
            eprintln!("{}: {e:#}", ctx.device_name);
            std::process::exit(1)
        }
    }
}
