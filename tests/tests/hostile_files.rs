//! Hostile scene files: deeply nested TOML and 10^6 objects are a clear error or a success,
//! never a panic or a stack overflow. (Huge declared PLY counts, truncated and non-UTF-8 files
//! are in scene_errors.rs.)

use std::path::Path;
use twinpath::scene::parse_scene;

#[test]
fn deeply_nested_toml_is_a_clear_error() {
    for depth in [100usize, 10_000, 1_000_000] {
        let text = format!("[camera]\neye = {}{}", "[".repeat(depth), "]".repeat(depth));
        let e = parse_scene(&text, Path::new("deep.toml")).unwrap_err();
        println!("depth {depth}: {e}");
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("recurs"), "{e}");
    }
}

#[test]
fn a_million_spheres_load_and_build() {
    let mut text = String::from(
        "[camera]\neye = [0,0,5]\nlook_at = [0,0,0]\nup = [0,1,0]\nvfov = 40\nwidth = 8\nheight = 8\n[materials]\nw = { kd = [0.5,0.5,0.5] }\n",
    );
    for i in 0..1_000_000 {
        text.push_str(&format!(
            "[[sphere]]\ncenter = [{}, {}, 0]\nradius = 0.1\nmaterial = \"w\"\n",
            i % 1000,
            i / 1000
        ));
    }
    let scene = parse_scene(&text, Path::new("many.toml")).unwrap();
    assert_eq!(scene.scene.spheres.len(), 1_000_000);
    let cpu = twinpath::cpu::CpuRenderer::new(&scene.scene, &scene.settings);
    assert!(cpu.bvh.node_count() > 1000);
    let mut film = twinpath::film::Film::new(8, 8);
    cpu.render_into(&scene.params(0, 1), 0, 1, &mut film, None);
    assert_eq!(film.discarded, 0);
}
