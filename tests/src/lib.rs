//! Helpers shared by twinpath's integration tests (in `tests/tests/`): statistics and small
//! programmatic scenes.

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};
use twinpath::scene::{parse_scene, Scene};

/// Two-sided critical |z| for a family of `tests` z-tests at family-wise error rate `alpha`
/// (Bonferroni): a correct estimator fails any of them with probability at most `alpha`.
pub fn z_critical(alpha: f64, tests: usize) -> f64 {
    let per_test = alpha / tests as f64;
    Normal::new(0.0, 1.0)
        .unwrap()
        .inverse_cdf(1.0 - per_test / 2.0)
}

/// Pearson's chi-square goodness-of-fit test of observed bin counts against expected ones.
/// Bins with expected count below 5 are pooled (as Mitsuba's `ChiSquareTest` does). Returns
/// (statistic, degrees of freedom, p-value).
pub fn chi_square(observed: &[f64], expected: &[f64]) -> (f64, usize, f64) {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut dof) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for &i in &order {
        if expected[i] == 0.0 {
            assert!(
                observed[i] == 0.0,
                "bin {i}: {} samples where the pdf integrates to 0",
                observed[i]
            );
            continue;
        }
        if expected[i] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
            pool_o += observed[i];
            pool_e += expected[i];
            if pool_e >= 5.0 {
                stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
                dof += 1;
                pool_o = 0.0;
                pool_e = 0.0;
            }
            continue;
        }
        stat += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
        dof += 1;
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1;
    }
    let dof = dof.saturating_sub(1).max(1);
    let p = 1.0 - ChiSquared::new(dof as f64).unwrap().cdf(stat);
    (stat, dof, p)
}

/// Parses scene text as if it were the file `name` in the `scenes/` folder.
pub fn scene_from_toml(text: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/test.toml");
    parse_scene(text, &path).unwrap_or_else(|e| panic!("test scene invalid: {e}"))
}

/// The repository root.
pub fn repo_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}
pub mod gpu;
pub mod spirv;

/// Renders `scene` at `spp` on `backend` (the GPU with validation layers on).
pub fn render_film(
    scene: &Scene,
    backend: twinpath::render::Backend,
    spp: u32,
) -> twinpath::film::Film {
    let mut s = scene.clone();
    s.render.spp = spp;
    let opts = twinpath::render::RenderOptions {
        backend,
        device: None,
        validation: backend == twinpath::render::Backend::Gpu,
        progress: false,
    };
    let out = twinpath::render::render(&s, &opts).expect("render");
    assert_eq!(out.backend, backend);
    assert_eq!(out.spp_done, spp);
    out.film
}

/// z of the difference between two images' overall means, each with the variance of its mean
/// (the sum of the per-pixel variances of the means over n^2): for independent renders.
pub fn image_mean_z(a: &twinpath::film::Film, b: &twinpath::film::Film) -> f64 {
    let stats = |f: &twinpath::film::Film| {
        let n = (3 * f.count.len()) as f64;
        let mean = f.mean().iter().flatten().map(|&x| x as f64).sum::<f64>() / n;
        let var = f
            .variance_of_mean()
            .iter()
            .flatten()
            .map(|&v| v as f64)
            .sum::<f64>()
            / (n * n);
        (mean, var)
    };
    let ((ma, va), (mb, vb)) = (stats(a), stats(b));
    (ma - mb) / (va + vb).sqrt()
}

/// The scene scaled by `scale` about the origin, then translated by `translate`: positions,
/// radii, edges and the camera. Radiance is scale-invariant, so the image must not change.
pub fn transform_scene(scene: &Scene, scale: f32, translate: glam::Vec3) -> Scene {
    use glam::Vec3;
    let p = |v: [f32; 3]| (Vec3::from(v) * scale + translate).to_array();
    let e = |v: [f32; 3]| (Vec3::from(v) * scale).to_array();
    let mut s = scene.clone();
    s.camera.eye = s.camera.eye * scale + translate;
    s.camera.look_at = s.camera.look_at * scale + translate;
    for sp in &mut s.spheres {
        sp.center = p(sp.center);
        sp.radius *= scale;
    }
    for l in &mut s.lights {
        l.center = p(l.center);
        l.radius *= scale;
    }
    for t in &mut s.triangles {
        t.p0 = p(t.p0);
        t.edge1 = e(t.edge1);
        t.edge2 = e(t.edge2);
    }
    s
}

/// splitmix64: the tests' own input generator, independent of the kernel's RNG under test.
pub struct SplitMix(pub u64);

impl SplitMix {
    pub fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1) with 24 random bits.
    pub fn unit(&mut self) -> f32 {
        (self.u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The closed-form test scene: a diffuse plane y = 0 of albedo `kd` (200 x 200 units) under a
/// sphere light of radius `r` and radiance `l` centred at height `h` above the origin, with the
/// given `[camera]` and `[render]` table bodies.
pub fn plane_under_light(camera: &str, render: &str, kd: f32, h: f32, r: f32, l: f32) -> Scene {
    scene_from_toml(&format!(
        r#"
        [camera]
        {camera}
        [render]
        {render}
        [materials]
        plane = {{ kd = [{kd}, {kd}, {kd}] }}
        lamp = {{ emission = [{l}, {l}, {l}] }}
        [[quad]]
        corner = [-100, 0, 100]
        edge1 = [200, 0, 0]
        edge2 = [0, 0, -200]
        material = "plane"
        [[sphere]]
        center = [0, {h}, 0]
        radius = {r}
        material = "lamp"
        "#
    ))
}
