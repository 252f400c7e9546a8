//! Hard lighting on both backends: a sphere light 1e-3 of its radius from a wall, a light of
//! radius 1e-4 of the scene, a light larger than the room's walls, and a camera inside a closed
//! sphere. Every image is finite with no discarded sample, and the two backends agree on it
//! (image means, independent seeds). The tiny light's closed-form check is in closed_form.rs.

use glam::Vec3;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{image_mean_z, render_film, repo_root, scene_from_toml, z_critical};

fn cornell_text() -> String {
    let t = std::fs::read_to_string(repo_root().join("scenes/cornell.toml")).unwrap();
    // Independent samples: the backends are compared by z-scores from each pixel's samples.
    assert!(t.contains("[render]\n"));
    t.replace("width = 256", "width = 64")
        .replace("height = 256", "height = 64")
        .replace("[render]\n", "[render]\nsampler = \"independent\"\n")
}

fn with_light(center: Vec3, radius: f32, emission: f32) -> String {
    let t = cornell_text();
    let light =
        "[[sphere]] # the light\ncenter = [0.0, 1.6, 0.0]\nradius = 0.3\nmaterial = \"light\"\n";
    assert!(t.contains(light));
    t.replace(
        light,
        &format!(
            "[[sphere]]\ncenter = [{}, {}, {}]\nradius = {radius}\nmaterial = \"light\"\n",
            center.x, center.y, center.z
        ),
    )
    .replace(
        "emission = [10.0, 10.0, 10.0]",
        &format!("emission = [{emission}, {emission}, {emission}]"),
    )
}

fn cases() -> Vec<(&'static str, SceneFile)> {
    let r = 0.3;
    // Light 1e-3 of its radius in front of the back wall (z = -1).
    let touching = with_light(Vec3::new(0.0, 1.0, -1.0 + r * (1.0 + 1e-3)), r, 10.0);
    // Radius 2e-4 (1e-4 of the room's size), as bright in total as the original.
    let tiny = with_light(
        Vec3::new(0.0, 1.6, 0.0),
        2e-4,
        10.0 * (0.3f32 / 2e-4).powi(2),
    );
    // No ceiling; a light of radius 2 (diameter twice a wall) just above where it was.
    let big = {
        let t = with_light(Vec3::new(0.0, 4.05, 0.0), 2.0, 2.0);
        let ceiling = "[[quad]] # ceiling, normal -y\ncorner = [-1.0, 2.0, -1.0]\nedge1 = [2.0, 0.0, 0.0]\nedge2 = [0.0, 0.0, 2.0]\nmaterial = \"white\"\n";
        assert!(t.contains(ceiling));
        t.replace(ceiling, "")
    };
    // The whole room and the camera inside a closed diffuse sphere.
    let enclosed = format!(
        "{}\n[[sphere]]\ncenter = [0.0, 1.0, 0.0]\nradius = 6.0\nmaterial = \"white\"\n",
        cornell_text()
    );
    vec![
        ("light 1e-3 r from a wall", scene_from_toml(&touching)),
        ("light of radius 1e-4 of the scene", scene_from_toml(&tiny)),
        ("light larger than a wall", scene_from_toml(&big)),
        ("camera inside a sphere", scene_from_toml(&enclosed)),
    ]
}

#[test]
fn hard_lighting_is_finite_and_the_same_on_both_backends() {
    let spp = 32;
    let z_max = z_critical(1e-3, 4);
    for (label, scene) in cases() {
        let cpu = render_film(&scene, Backend::Cpu, spp);
        let mut other = scene.clone();
        other.settings.seed += 1000;
        let gpu = render_film(&other, Backend::Gpu, spp);
        for (name, film) in [("cpu", &cpu), ("gpu", &gpu)] {
            assert_eq!(
                film.discarded, 0,
                "{label}: {name} discarded non-finite samples"
            );
            let mean = film.mean();
            assert!(
                mean.iter().flatten().all(|x| x.is_finite() && *x >= 0.0),
                "{label}: {name}"
            );
            assert!(
                mean.iter().flatten().any(|&x| x > 0.0),
                "{label}: {name} is black"
            );
        }
        let z = image_mean_z(&cpu, &gpu);
        println!("{label}: finite on both backends; cpu vs gpu image means z = {z:+.2}");
        assert!(z.abs() < z_max, "{label}: backends disagree, z = {z:.2}");
    }
    assert_validation_clean();
}
