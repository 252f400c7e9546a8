//! A lamp above a floor 10^4 wide gives the floor the light it gives a floor 8 wide, on both
//! backends: rays leaving the floor start at its plane's own height (`geometry::triangle_offsets_v3`:
//! a triangle in z = 0 has no rounding along its normal), not 8 eps of its coordinates above it
//! (docs/robustness.md, "The height a ray leaves at"). With BSDF sampling alone
//! (`mis = "bsdf"`), paths see the lamp from the height they leave at, so a lifted origin shows
//! as light: the bound rays left at before the plane weights made this image 1.70% brighter
//! (65,536 spp, CPU; z = +408 against the floor 8 wide on the same seeds).

use twinpath::render::Backend;
use twinpath_tests::{
    image_mean_z, render_film, scene_from_toml, with_independent_samples, z_critical,
};

/// The floor `width` wide in y = 0 under a 2 x 2 lamp 1 above it (facing down), seen straight
/// down from 0.5 above it (only floor in view), with BSDF sampling alone and seed `seed`.
/// Rendered with one seed, the two floors' images draw the same numbers, so an unbiased pair
/// differs by rounding alone (z within +-0.05 on both backends), while `image_mean_z`, which
/// takes the renders as independent, overstates the difference's noise: the test is
/// conservative, and the lift it must catch is far beyond it.
fn floor_scene(width: f32, seed: u32) -> twinpath::scene::SceneFile {
    let h = width / 2.0;
    with_independent_samples(scene_from_toml(&format!(
        r#"
        [camera]
        eye = [0.3, 0.5, 0.2]
        look_at = [0.3, 0.0, 0.2]
        up = [0.0, 0.0, -1.0]
        vfov = 40.0
        width = 24
        height = 18
        [render]
        seed = {seed}
        mis = "bsdf"
        [materials]
        floor = {{ kd = [0.5, 0.5, 0.5] }}
        lamp = {{ emission = [1.0, 1.0, 1.0] }}
        [[quad]]
        corner = [-{h}, 0.0, {h}]
        edge1 = [{width}, 0.0, 0.0]
        edge2 = [0.0, 0.0, -{width}]
        material = "floor"
        [[quad]]
        corner = [-1.0, 1.0, -1.0]
        edge1 = [2.0, 0.0, 0.0]
        edge2 = [0.0, 0.0, 2.0]
        material = "lamp"
        "#
    )))
}

#[test]
fn a_floor_ten_thousand_wide_is_lit_as_a_small_one_on_both_backends() {
    for (backend, spp) in [(Backend::Cpu, 4096), (Backend::Gpu, 1024)] {
        // The same seed: the paths of the two images differ only where the floors do.
        let small = render_film(&floor_scene(8.0, 1), backend, spp);
        let large = render_film(&floor_scene(10_000.0, 1), backend, spp);
        let z = image_mean_z(&large, &small);
        println!("{backend:?}: the large floor's image mean against the small one's, z = {z:+.2}");
        assert!(z.abs() < z_critical(1e-3, 2), "{backend:?}: z = {z:.2}");
    }
}
