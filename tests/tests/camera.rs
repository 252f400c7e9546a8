//! The thin-lens camera (`kernel::camera::thin_lens_ray`):
//!
//! 1. Every ray from the lens for an image position passes through the point where that
//!    position's pinhole ray meets the plane of focus, and starts on the lens disk.
//! 2. A flat emitter in the plane of focus is imaged exactly as by the pinhole: the same image,
//!    pixel for pixel, on both backends (each sample depends only on its position in the pixel).
//! 3. Out of focus, a small emitter is blurred into the circle of confusion: the image's second
//!    moment matches R^2/2 + s^2/6 + 1/6 pixels^2 (a disk of radius R = r |1/f - 1/d|, the
//!    square's own image of side s, the pixel's box filter), on both backends.

use glam::Vec3;
use kernel::camera::{camera_ray_direction, lens_radius, thin_lens_ray};
use kernel::scene::Camera;
use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::SceneFile;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{render_film, scene_from_toml, SplitMix};

const SIDE: u32 = 64;
const VFOV: f32 = 30.0;

/// Pixels per unit of the image plane at distance 1: the image spans tan(vfov/2) above the axis.
fn pixels_per_unit() -> f64 {
    (SIDE as f64 / 2.0) / (VFOV as f64 / 2.0).to_radians().tan()
}

/// A camera at the origin looking down -z with a lens of diameter `aperture` focused at `focus`,
/// and one emissive square of side `side` facing it, centred on the axis at depth `depth`.
fn square_scene(aperture: f32, focus: f32, side: f32, depth: f32, seed: u32) -> SceneFile {
    let h = side / 2.0;
    scene_from_toml(&format!(
        r#"
        [camera]
        eye = [0, 0, 0]
        look_at = [0, 0, -1]
        up = [0, 1, 0]
        vfov = {VFOV}
        width = {SIDE}
        height = {SIDE}
        aperture = {aperture}
        focus_distance = {focus}
        [render]
        seed = {seed}
        [materials]
        lamp = {{ emission = [1, 1, 1] }}
        [[quad]]
        corner = [{}, {}, {}]
        edge1 = [{side}, 0, 0]
        edge2 = [0, {side}, 0]
        material = "lamp"
        "#,
        -h, -h, -depth
    ))
}

#[test]
fn lens_rays_meet_in_the_plane_of_focus() {
    let scene = square_scene(0.8, 2.5, 0.1, 4.0, 1);
    let camera: Camera = scene.scene.camera.to_kernel();
    let r = lens_radius(&camera);
    assert_eq!(r, 0.4);
    let eye = Vec3::ZERO;
    let forward = -Vec3::Z;
    let mut g = SplitMix(5);
    for _ in 0..100_000 {
        let (px, py) = (
            (g.u64() % SIDE as u64) as u32,
            (g.u64() % SIDE as u64) as u32,
        );
        let dir = camera_ray_direction(&camera, SIDE, SIDE, px, py, g.unit(), g.unit());
        let focus = eye + dir * (2.5 / dir.dot(forward));
        let (origin, d) = thin_lens_ray(&camera, dir, g.unit(), g.unit());
        // On the lens: in the plane through the eye across the axis, within its radius.
        assert!(origin.z.abs() < 1e-7 && origin.truncate().length() <= r * (1.0 + 1e-6));
        // Through the focus point: its distance from the ray, relative to the distance.
        let to_focus = focus - origin;
        let miss = (to_focus - d * to_focus.dot(d)).length() / to_focus.length();
        assert!(
            miss < 4.0 * f32::EPSILON,
            "ray misses its focus point by {miss:e}"
        );
        assert!((d.length() - 1.0).abs() < 1e-6);
    }
}

/// Films of `scene` rendered with the lens and with a pinhole, same seed and spp.
fn with_and_without_lens(scene: &SceneFile, backend: Backend, spp: u32) -> (Film, Film) {
    let mut pinhole = scene.clone();
    pinhole.scene.camera.aperture = 0.0;
    (
        render_film(scene, backend, spp),
        render_film(&pinhole, backend, spp),
    )
}

#[test]
fn the_plane_of_focus_is_as_sharp_as_through_a_pinhole_on_both_backends() {
    // A square of side 0.5 at the focus distance 2: 30 pixels wide.
    let scene = square_scene(0.8, 2.0, 0.5, 2.0, 3);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let (lens, pinhole) = with_and_without_lens(&scene, backend, 16);
        let (a, b) = (lens.mean(), pinhole.mean());
        let covered = b.iter().filter(|p| p[0] > 0.0).count();
        let differing = a
            .iter()
            .zip(&b)
            .filter(|(x, y)| (x[0] - y[0]).abs() > 1e-5)
            .count();
        println!(
            "{backend:?}: {covered} pixels see the square; {differing} differ between lens and pinhole"
        );
        assert!(covered > 800);
        // Only samples within rounding of the square's edges may land on the other side.
        assert!(
            differing <= 4,
            "{backend:?}: {differing} pixels differ: the plane of focus is not sharp"
        );
    }
    assert_validation_clean();
}

/// The second moment about its centroid of `film`'s image, in pixels^2, and the centroid.
fn second_moment(film: &Film) -> (f64, (f64, f64)) {
    let mean = film.mean();
    let at = |i: usize| {
        (
            (i as u32 % SIDE) as f64 + 0.5,
            (i as u32 / SIDE) as f64 + 0.5,
        )
    };
    let total: f64 = mean.iter().map(|p| p[0] as f64).sum();
    let (mut cx, mut cy) = (0.0, 0.0);
    for (i, p) in mean.iter().enumerate() {
        let (x, y) = at(i);
        cx += p[0] as f64 * x;
        cy += p[0] as f64 * y;
    }
    let (cx, cy) = (cx / total, cy / total);
    let mut m = 0.0;
    for (i, p) in mean.iter().enumerate() {
        let (x, y) = at(i);
        m += p[0] as f64 * ((x - cx).powi(2) + (y - cy).powi(2));
    }
    (m / total, (cx, cy))
}

#[test]
fn depth_of_field_matches_the_circle_of_confusion_on_both_backends() {
    // Lens radius 0.4 focused at 2; a square of side 0.3 at depth 4: R = 0.4 |1/2 - 1/4| = 0.1
    // image units = 11.9 pixels, the square's own image 9.0 pixels wide. Each batch is an
    // independent render (its own seed; Sobol points within it), so the batches' spread gives
    // the t-test its error.
    let (aperture, focus, side, depth) = (0.8f32, 2.0f32, 0.3f32, 4.0f32);
    let ppu = pixels_per_unit();
    let radius = 0.5 * aperture as f64 * (1.0 / focus as f64 - 1.0 / depth as f64) * ppu;
    let square = side as f64 / depth as f64 * ppu;
    // Variances add under convolution: a uniform disk of radius R has E[r^2] = R^2/2, a uniform
    // square of side s has s^2/12 per axis, a pixel's box filter 1/12 per axis. Pixel values are
    // the blurred image sampled at pixel centres, a smooth function at 12 pixels of blur, so the
    // sum over centres is its integral up to a discretisation error far below the 1% allowed.
    let want = radius * radius / 2.0 + square * square / 6.0 + 1.0 / 6.0;
    for backend in [Backend::Cpu, Backend::Gpu] {
        let batches: Vec<f64> = (0..8)
            .map(|b| {
                let film = render_film(
                    &square_scene(aperture, focus, side, depth, 100 + b),
                    backend,
                    64,
                );
                let (m, (cx, cy)) = second_moment(&film);
                assert!(
                    (cx - 32.0).abs() < 0.5 && (cy - 32.0).abs() < 0.5,
                    "centroid ({cx}, {cy}) off the axis"
                );
                m
            })
            .collect();
        let n = batches.len() as f64;
        let mean = batches.iter().sum::<f64>() / n;
        let sd = (batches.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let t = (mean - want) / (sd / n.sqrt());
        println!(
            "{backend:?}: second moment {mean:.3} +- {:.3} px^2, circle of confusion predicts {want:.3} (R = {radius:.2} px), t = {t:+.2}",
            sd / n.sqrt()
        );
        // A t-test (7 degrees of freedom, two-sided 1e-3: 5.41), and a 1% bound on the
        // difference: a lens of the wrong size (by 1%) would fail the latter.
        assert!(t.abs() < 5.41, "{backend:?}: t = {t:.2}");
        assert!(
            (mean / want - 1.0).abs() < 0.01,
            "{backend:?}: {mean} vs {want}"
        );
        // And the pinhole images the same square sharply. Its pixels are the square's coverage of
        // each pixel, whose edges fall inside pixels, so the exact expectation is the sum over
        // pixel centres c of coverage(c) |c|^2, separable in x and y.
        let mut pinhole = square_scene(aperture, focus, side, depth, 7);
        pinhole.scene.camera.aperture = 0.0;
        let (m, _) = second_moment(&render_film(&pinhole, backend, 64));
        let half = square / 2.0;
        let (mut w, mut wc2) = (0.0, 0.0);
        for k in 0..SIDE {
            let c = k as f64 + 0.5 - SIDE as f64 / 2.0;
            let cover = ((c + 0.5).min(half) - (c - 0.5).max(-half)).max(0.0);
            w += cover;
            wc2 += cover * c * c;
        }
        let sharp = 2.0 * wc2 / w;
        println!("{backend:?}: pinhole second moment {m:.3} px^2, the square's {sharp:.3}");
        assert!((m / sharp - 1.0).abs() < 0.01, "pinhole: {m} vs {sharp}");
    }
    assert_validation_clean();
}
