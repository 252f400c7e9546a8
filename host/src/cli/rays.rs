//! `twinpath rays`: rays per second of the CPU traversal, and the BVH's build time and memory.

use super::{load_scene, mib, scene_stem, show_notes};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use twinpath::scene::SceneFile;

/// Ray throughput of the CPU traversal on one thread (camera rays, diffuse bounce rays and the
/// rays of one path per pixel), one ray at a time and in packets of 16 as the renderer traces
/// them, and the BVH's build time and memory.
#[derive(Args)]
pub struct RaysArgs {
    /// Scene file (TOML). Without it, the built-in Cornell scene.
    scene: Option<PathBuf>,
    /// Add a generated mesh of about N triangles (a rippled torus-knot tube) at the point
    /// the camera looks at.
    #[arg(long)]
    mesh_triangles: Option<usize>,
    /// Width of the camera-ray image (its height follows the scene's aspect ratio).
    #[arg(long, default_value_t = 1024)]
    width: u32,
    /// Timed passes per measurement; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    repeats: u32,
    /// Write the rays and our hits here, for scripts/embree_rays.c.
    #[arg(long)]
    ray_file: Option<PathBuf>,
    /// Append the results to this CSV file (header written when it is new).
    #[arg(long)]
    csv: Option<PathBuf>,
}

pub fn run(a: RaysArgs) -> Result<()> {
    let SceneFile {
        mut scene,
        settings,
    } = load_scene(a.scene.as_deref())?;
    show_notes(&scene);
    if let Some(n) = a.mesh_triangles {
        twinpath::bench::rays::add_knot_mesh(&mut scene, n);
    }
    if a.width == 0 {
        bail!("--width must be at least 1");
    }
    let height =
        ((a.width as u64 * scene.camera.height as u64) / scene.camera.width as u64).max(1) as u32;
    let r = twinpath::bench::rays::measure(
        &scene,
        &settings,
        a.width,
        height,
        a.repeats,
        a.ray_file.as_deref(),
    )
    .context("writing the ray file")?;
    println!(
        "{}: {} triangles, {} spheres; BVH build {:.3} s ({} threads), {} nodes, {:.1} MiB hierarchy + {:.1} MiB primitives",
        scene.name, r.triangles, r.spheres, r.build_seconds, rayon::current_num_threads(), r.nodes,
        mib(r.hierarchy_bytes as u64), mib(r.primitive_bytes as u64)
    );
    for s in &r.sets {
        println!(
            "  {:<28} {:>9} rays ({:>9} hit): closest {:>7.3} Mrays/s, occluded {:>7.3} Mrays/s (one thread)",
            s.name, s.rays, s.hits, s.closest_per_second * 1e-6, s.occluded_per_second * 1e-6
        );
        if let Some((closest, occluded)) = s.packets {
            println!(
                "  {:<28} {:>9} rays in packets of 16:  closest {:>7.3} Mrays/s, occluded {:>7.3} Mrays/s (one thread)",
                "", s.rays, closest * 1e-6, occluded * 1e-6
            );
        }
    }
    let Some(path) = a.csv else { return Ok(()) };
    let new = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    if new {
        writeln!(f, "tracer,scene,triangles,spheres,build_seconds,hierarchy_bytes,primitive_bytes,rays_name,rays,hits,closest_mrays_per_s,occluded_mrays_per_s")?;
    }
    let stem = scene_stem(&scene.name);
    for s in &r.sets {
        writeln!(
            f,
            "twinpath,{stem},{},{},{:.6},{},{},{},{},{},{:.4},{:.4}",
            r.triangles,
            r.spheres,
            r.build_seconds,
            r.hierarchy_bytes,
            r.primitive_bytes,
            s.name,
            s.rays,
            s.hits,
            s.closest_per_second * 1e-6,
            s.occluded_per_second * 1e-6
        )?;
        if let Some((closest, occluded)) = s.packets {
            writeln!(
                f,
                "twinpath_packets,{stem},{},{},0,0,{},{},{},{},{:.4},{:.4}",
                r.triangles,
                r.spheres,
                r.primitive_bytes,
                s.name,
                s.rays,
                s.hits,
                closest * 1e-6,
                occluded * 1e-6
            )?;
        }
    }
    Ok(())
}
