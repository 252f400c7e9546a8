//! The SPIR-V module rust-gpu builds from `kernel/`: valid for Vulkan 1.2 (spirv-val) and
//! holding exactly the entry points the Vulkan backend binds (rust-gpu can silently drop one).

use std::collections::BTreeSet;
use std::process::Command;

const OP_ENTRY_POINT: u32 = 15;

/// (execution model, name) of every OpEntryPoint in a SPIR-V binary.
fn entry_points(spv: &[u8]) -> BTreeSet<(u32, String)> {
    assert_eq!(spv.len() % 4, 0);
    let words: Vec<u32> = spv
        .as_chunks::<4>()
        .0
        .iter()
        .map(|c| u32::from_le_bytes(*c))
        .collect();
    assert_eq!(words[0], 0x0723_0203, "not a SPIR-V module");
    let mut out = BTreeSet::new();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let opcode = words[i] & 0xffff;
        assert!(count > 0, "malformed instruction at word {i}");
        if opcode == OP_ENTRY_POINT {
            let model = words[i + 1];
            let bytes: Vec<u8> = words[i + 3..i + count]
                .iter()
                .flat_map(|w| w.to_le_bytes())
                .collect();
            let end = bytes.iter().position(|&b| b == 0).unwrap();
            out.insert((model, String::from_utf8(bytes[..end].to_vec()).unwrap()));
        }
        i += count;
    }
    out
}

#[test]
fn module_has_the_ray_tracing_entry_points() {
    // Execution models: RayGenerationKHR 5313, IntersectionKHR 5314, ClosestHitKHR 5316,
    // MissKHR 5317.
    let want: BTreeSet<(u32, String)> = [
        (5313, "shaders::raygen"),
        (5317, "shaders::miss"),
        (5316, "shaders::closest_hit_triangle"),
        (5316, "shaders::closest_hit_sphere"),
        (5314, "shaders::intersect_sphere_shader"),
    ]
    .into_iter()
    .map(|(m, n)| (m, n.to_string()))
    .collect();
    let got = entry_points(twinpath::KERNEL_SPV);
    println!("entry points: {got:?}");
    assert_eq!(got, want);
}

#[test]
fn module_passes_spirv_val() {
    let path = std::env::temp_dir().join(format!("twinpath-kernel-{}.spv", std::process::id()));
    std::fs::write(&path, twinpath::KERNEL_SPV).unwrap();
    let out = Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .arg(&path)
        .output()
        .expect("spirv-val (Debian package spirv-tools) must be installed: run scripts/setup.sh");
    let _ = std::fs::remove_file(&path);
    assert!(
        out.status.success(),
        "spirv-val rejects the module:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
