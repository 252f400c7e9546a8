//! A lamp above a floor 10^4 wide gives the floor the light it gives a floor 8 wide, on both
//! backends: rays leaving the floor start at its plane's own height (`geometry::triangle_offsets_v3`:
//! a triangle in z = 0 has no rounding along its normal), not 8 eps of its coordinates above it
//! (docs/robustness.md, "The height a ray leaves at"). With BSDF sampling alone
//! (`mis = "bsdf"`), paths see the lamp from the height they leave at, so a lifted origin shows
//! as light: the bound rays left at before the plane weights made this image 1.70% brighter
//! (65,536 spp, CPU; z = +408 against the floor 8 wide on the same seeds).
//!
//! The same for the floor as an instanced mesh (`instance::instanced_offsets_v3`): rays leaving
//! it start at the object floor's own height carried to world space, plus the round trip's
//! rounding, where the instance's map turns directions little; every instanced ray lifted by the
//! object triangle's grazing offset before (2.6% brighter with `mis = "bsdf"`, CPU z = +25 at
//! 4096 spp; docs/robustness.md, "Instanced large triangles").

use twinpath::render::Backend;
use twinpath_tests::{
    grid_obj, image_mean_z, render_film, scene_from_toml, with_independent_samples, z_critical,
};

/// The floor `width` wide in y = 0 under a 2 x 2 lamp 1 above it (facing down), seen straight
/// down from 0.5 above it (only floor in view), with BSDF sampling alone and seed `seed`.
/// Rendered with one seed, the two floors' images draw the same numbers, so an unbiased pair
/// differs by rounding alone (z within +-0.05 on both backends), while `image_mean_z`, which
/// takes the renders as independent, overstates the difference's noise: the test is
/// conservative, and the lift it must catch is far beyond it.
fn floor_scene(width: f32, seed: u32) -> twinpath::scene::SceneFile {
    let h = width / 2.0;
    lamp_over(
        &format!(
            r#"
            [[quad]]
            corner = [-{h}, 0.0, {h}]
            edge1 = [{width}, 0.0, 0.0]
            edge2 = [0.0, 0.0, -{width}]
            material = "floor"
            "#
        ),
        seed,
    )
}

/// The scene of [`floor_scene`] with its floor given by `floor` (scene-file entries whose
/// material is "floor").
fn lamp_over(floor: &str, seed: u32) -> twinpath::scene::SceneFile {
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
        {floor}
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

/// An OBJ of the floor `width` wide in y = 0 as a 4 x 4 grid of quads, 32 triangles (enough to
/// be instanced, `scene::instancing::INSTANCE_MIN_TRIANGLES`), facing +y.
fn grid_floor_obj(width: f64) -> String {
    let h = width / 2.0;
    grid_obj(4, [-h, 0.0, -h], [[0.0, 0.0, width], [width, 0.0, 0.0]])
}

/// The floor 10^4 wide as a mesh placed twice (at the origin and 10^5 below, so that it is
/// instanced), lit as the world floor 8 wide on the same seed on both backends. With every
/// instanced ray lifted by the object triangle's grazing offset (`turns_directions_little`
/// returning 0, the mutation) the CPU's z is +25.
#[test]
fn an_instanced_floor_ten_thousand_wide_is_lit_as_a_small_one_on_both_backends() {
    let dir = std::env::temp_dir().join(format!("twinpath-floor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("floor.obj");
    std::fs::write(&obj, grid_floor_obj(10_000.0)).unwrap();
    let mesh = |translate: f32| {
        format!(
            r#"
            [[mesh]]
            file = "{}"
            material = "floor"
            translate = [0.0, {translate}, 0.0]
            "#,
            obj.display()
        )
    };
    let instanced = lamp_over(&(mesh(0.0) + &mesh(-100_000.0)), 1);
    assert_eq!(
        instanced.scene.instances.len(),
        2,
        "the floor is not instanced"
    );
    for (backend, spp) in [(Backend::Cpu, 4096), (Backend::Gpu, 1024)] {
        let small = render_film(&floor_scene(8.0, 1), backend, spp);
        let large = render_film(&instanced, backend, spp);
        let z = image_mean_z(&large, &small);
        println!("{backend:?}: the instanced large floor's image mean against the small one's, z = {z:+.2}");
        assert!(z.abs() < z_critical(1e-3, 2), "{backend:?}: z = {z:.2}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
