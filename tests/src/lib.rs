//! Helpers shared by twinpath's integration tests (in `tests/tests/`): statistics and small
//! programmatic scenes.

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};
use twinpath::scene::{parse_scene, Scene, SceneFile};

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

/// Asserts that `observed` counts fit `expected` ones ([`chi_square`]) at the significance of
/// one of `tests` chi-square tests sharing the family-wise level `alpha` (Sidak's split), and
/// prints the statistic under `name`.
pub fn assert_chi_square_fits(
    name: &str,
    observed: &[f64],
    expected: &[f64],
    alpha: f64,
    tests: f64,
) {
    let (stat, dof, p) = chi_square(observed, expected);
    let threshold = 1.0 - (1.0 - alpha).powf(1.0 / tests);
    println!("{name}: chi2 = {stat:.1}, dof = {dof}, p = {p:.4}");
    assert!(
        p > threshold,
        "{name}: samples do not follow the pdf (chi2 {stat:.1}, dof {dof}, p {p:.2e} < {threshold:.2e})"
    );
}

/// Parses scene text as if it were the file `name` in the `scenes/` folder.
pub fn scene_from_toml(text: &str) -> SceneFile {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/test.toml");
    parse_scene(text, &path).unwrap_or_else(|e| panic!("test scene invalid: {e}"))
}

/// The scene with independent samples. Tests whose z-scores take a pixel's error from the
/// spread of its own samples need them: Sobol points (the default) are stratified, so that
/// spread overstates their error and such a test would lose power, not validity.
pub fn with_independent_samples(mut scene: SceneFile) -> SceneFile {
    scene.settings.sampler = twinpath::settings::Sampler::Independent;
    scene
}

/// The text of `scenes/cornell.toml` with every albedo 1 and the light sphere made a white
/// diffuse sphere: no light, five quads and three spheres; a white furnace once a background is
/// added.
pub fn white_cornell_toml() -> String {
    let mut text = std::fs::read_to_string(repo_root().join("scenes/cornell.toml")).unwrap();
    for from in [
        "kd = [0.73, 0.73, 0.73]",
        "kd = [0.65, 0.05, 0.05]",
        "kd = [0.12, 0.45, 0.15]",
        "kd = [0.25, 0.35, 0.75]",
        "emission = [10.0, 10.0, 10.0]",
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, "kd = [1.0, 1.0, 1.0]");
    }
    text
}

/// The room of [`white_cornell_toml`] as a white furnace: a uniform background `lb`, `render`
/// in place of its `[render]` table's `seed = 1`, `width` x `height` pixels.
pub fn white_furnace(render: &str, width: u32, height: u32, lb: f32) -> SceneFile {
    let mut text = white_cornell_toml();
    for (from, to) in [
        ("seed = 1", render.to_string()),
        ("width = 256", format!("width = {width}")),
        ("height = 256", format!("height = {height}")),
    ] {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, &to);
    }
    text.push_str(&format!("\n[background]\nradiance = [{lb}, {lb}, {lb}]\n"));
    scene_from_toml(&text)
}

/// The repository root.
pub fn repo_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}
/// `kernel::surface::shade` at a hit on material `material` (of `materials`), shading record
/// `record` at barycentrics `bary`, geometric normal `normal`, instance `instance`, over the
/// given tables (the rest of the scene empty).
#[allow(clippy::too_many_arguments)]
pub fn shade_at(
    material: u32,
    record: u32,
    bary: glam::Vec2,
    normal: glam::Vec3,
    instance: u32,
    materials: &[kernel::scene::Material],
    shading: &[kernel::scene::ShadingTriangle],
    textures: &[u32],
    instances: &[kernel::scene::Instance],
) -> (kernel::scene::Material, glam::Vec3) {
    let params: kernel::scene::RenderParams = bytemuck::Zeroable::zeroed();
    let scene = kernel::SceneView {
        params: &params,
        materials,
        lights: &[],
        environment: &[0.0],
        shading,
        textures,
        instances,
        media: &[kernel::medium::Medium::VACUUM],
        grids: &[0],
        splits: &[1],
    };
    let hit = kernel::SurfaceHit {
        material,
        shading: record,
        barycentrics: bary,
        normal,
        instance,
        ..kernel::SurfaceHit::miss()
    };
    kernel::surface::shade(kernel::features::Dynamic(0), &scene, &hit)
}

/// An OBJ of an n x n grid of quads, two triangles each: the vertices are
/// `corner + (i / n) edges[0] + (j / n) edges[1]` for i, j in 0..=n, and the triangles are
/// wound so that they face along `edges[0] x edges[1]`.
pub fn grid_obj(n: usize, corner: [f64; 3], edges: [[f64; 3]; 2]) -> String {
    let mut s = String::new();
    for i in 0..=n {
        for j in 0..=n {
            let at = |c: usize| {
                corner[c] + edges[0][c] * i as f64 / n as f64 + edges[1][c] * j as f64 / n as f64
            };
            s += &format!("v {} {} {}\n", at(0), at(1), at(2));
        }
    }
    let k = |i: usize, j: usize| i * (n + 1) + j + 1;
    for i in 0..n {
        for j in 0..n {
            s += &format!(
                "f {} {} {}\nf {} {} {}\n",
                k(i, j),
                k(i + 1, j),
                k(i + 1, j + 1),
                k(i, j),
                k(i + 1, j + 1),
                k(i, j + 1)
            );
        }
    }
    s
}

pub mod ball_arithmetic;
pub mod cubature;
pub mod device_class;
pub mod device_inverse;
pub mod exact;
pub mod ggx_table;
pub mod gltf_writer;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod placements;
pub mod plane_side;
pub mod probe_inputs;
pub mod reference_bsdf;
pub mod sheen_fit;
pub mod spherical_triangle_error;
pub mod spirv;
pub mod stats;
pub mod triangle_bins;
pub mod vulkan_arithmetic;
pub mod watertight;

/// Whether the GPU tests turn the validation layers on: always, unless the environment sets
/// `TWINPATH_TESTS_NO_VALIDATION`, which only the device check uses, to tell whether the layers
/// take part in the two-thread hang (`docs/gpu.md`).
pub fn validation_wanted() -> bool {
    std::env::var_os("TWINPATH_TESTS_NO_VALIDATION").is_none()
}

/// Renders `scene` at `spp` on `backend` (the GPU with validation layers on, see
/// [`validation_wanted`]).
pub fn render_film(
    scene: &SceneFile,
    backend: twinpath::render::Backend,
    spp: u32,
) -> twinpath::film::Film {
    render_output(scene, backend, spp).film
}

/// Renders `file` with `spp` samples per pixel on the CPU (packets and one path) and the GPU,
/// and z-tests every pixel with a closed form in `exact` (`None`: not tested) per channel at
/// a family-wise level of 1e-3, and the sum over the tested pixels per channel.
pub fn assert_backends_agree_with(file: &SceneFile, exact: &[Option<[f64; 3]>], spp: u32) {
    let tested = exact.iter().flatten().count();
    let mut one_path = file.clone();
    one_path.settings.packets = false;
    for (label, scene, backend) in [
        ("cpu packets", file, twinpath::render::Backend::Cpu),
        ("cpu one path", &one_path, twinpath::render::Backend::Cpu),
        ("gpu", file, twinpath::render::Backend::Gpu),
    ] {
        let film = render_film(scene, backend, spp);
        assert_eq!(film.discarded, 0);
        let (mean, var) = (film.mean(), film.variance_of_mean());
        let z_max = z_critical(1e-3, 3 * tested);
        // Pooled per channel: a path's channels are correlated, so summing over them would
        // understate the variance of the sum.
        let (mut sum_d, mut sum_v, mut worst) = ([0.0; 3], [0.0; 3], 0f64);
        for ((want, m), v) in exact.iter().zip(&mean).zip(&var) {
            let Some(want) = want else { continue };
            for c in 0..3 {
                let d = m[c] as f64 - want[c];
                let v = v[c] as f64;
                if v == 0.0 {
                    // Every sample alike (a ray that meets only the environment): the value
                    // itself, to f32's rounding.
                    assert!(
                        d.abs() <= 1e-6 * want[c].abs().max(1.0),
                        "{label}: pixel reads {} vs {:.7} in channel {c} with no variance",
                        m[c],
                        want[c]
                    );
                    continue;
                }
                let z = d / v.sqrt();
                worst = worst.max(z.abs());
                assert!(
                    z.abs() < z_max,
                    "{label}: pixel reads {} vs {:.5} in channel {c} (z = {z:.2})",
                    m[c],
                    want[c]
                );
                sum_d[c] += d;
                sum_v[c] += v;
            }
        }
        let z_all: Vec<f64> = (0..3).map(|c| sum_d[c] / sum_v[c].sqrt()).collect();
        println!("{label}: worst |z| {worst:.2}, all pixels together z = {z_all:+.2?} (r, g, b)");
        for z in z_all {
            assert!(z.abs() < z_critical(1e-3, 3), "{label}: z = {z:.2}");
        }
    }
}

/// What [`render_film`]'s render produced: the film, and the rays where the backend counts
/// them.
pub fn render_output(
    scene: &SceneFile,
    backend: twinpath::render::Backend,
    spp: u32,
) -> twinpath::render::RenderOutput {
    let mut s = scene.clone();
    s.settings.spp = spp;
    let opts = twinpath::render::RenderOptions {
        backend,
        device: None,
        validation: backend == twinpath::render::Backend::Gpu && validation_wanted(),
        progress: false,
        samples: None,
    };
    let out = twinpath::render::render(&s.scene, &s.settings, &opts).expect("render");
    assert_eq!(out.backend, backend);
    assert_eq!(out.spp_done, spp);
    out
}

/// Asserts two films hold the same samples bit for bit: sample and pilot counts, and every
/// pixel's sums.
pub fn assert_films_identical(a: &twinpath::film::Film, b: &twinpath::film::Film, label: &str) {
    assert_eq!(a.count, b.count, "{label}: sample counts differ");
    assert_eq!(a.pilot_count, b.pilot_count, "{label}: pilot counts differ");
    let same = equal_pixel_sums(a, b);
    assert_eq!(
        same,
        a.sum.len(),
        "{label}: {} of {} pixel sums differ",
        a.sum.len() - same,
        a.sum.len()
    );
}

/// Renders `scene` on the CPU as it is and with `packets` off (one path at a time), `spp`
/// samples each, and asserts the films identical, sample for sample (`tests/tests/packets.rs`:
/// packets never change an image).
pub fn assert_packets_give_the_one_path_image(name: &str, scene: &SceneFile, spp: u32) {
    use twinpath::cpu::{CpuRenderer, TileStrategy};
    use twinpath::render::Backend;
    let mut one_path = scene.clone();
    one_path.settings.packets = false;
    assert!(matches!(
        CpuRenderer::new(&one_path.scene, &one_path.settings).tiles,
        TileStrategy::OnePath
    ));
    let a = render_film(scene, Backend::Cpu, spp);
    let b = render_film(&one_path, Backend::Cpu, spp);
    assert_films_identical(&a, &b, name);
    println!("{name}: packets and one path identical at {spp} spp");
}

/// [`assert_packets_give_the_one_path_image`] for a scene that must take the packets through
/// the BVH (a larger scene, instances or holes: `TileStrategy::BvhPackets`); `what` says why it
/// must, for the message when it does not.
pub fn assert_bvh_packets_give_the_one_path_image(
    name: &str,
    scene: &SceneFile,
    spp: u32,
    what: &str,
) {
    use twinpath::cpu::{CpuRenderer, TileStrategy};
    assert!(
        matches!(
            CpuRenderer::new(&scene.scene, &scene.settings).tiles,
            TileStrategy::BvhPackets
        ),
        "{name}: {what}, yet no packets through the BVH"
    );
    assert_packets_give_the_one_path_image(name, scene, spp);
}

/// How many of two films' pixel sums (per channel) are equal, bit for bit.
pub fn equal_pixel_sums(a: &twinpath::film::Film, b: &twinpath::film::Film) -> usize {
    a.sum.iter().zip(&b.sum).filter(|(x, y)| x == y).count()
}

/// z of the difference between two images' overall means (over pixels and channels), each
/// with a bound on the variance of its mean ([`stats::variance_of_channel_mean`]): for
/// independent renders. Summing the channels' variances as if independent understated it up
/// to threefold: two renders of a grey scene on different seeds gave z with an RMS of 1.96
/// over 12 pairs, 1.00 per pixel.
pub fn image_mean_z(a: &twinpath::film::Film, b: &twinpath::film::Film) -> f64 {
    let stats = |f: &twinpath::film::Film| {
        let n = f.count.len() as f64;
        let mean = f.mean().iter().flatten().map(|&x| x as f64).sum::<f64>() / (3.0 * n);
        (mean, stats::variance_of_channel_mean(&f.variance_of_mean()))
    };
    let ((ma, va), (mb, vb)) = (stats(a), stats(b));
    (ma - mb) / (va + vb).sqrt()
}

/// The scene scaled by `scale` about the origin, then translated by `translate`: positions,
/// radii, edges and the camera. Radiance is scale-invariant, so the image must not change.
pub fn transform_scene(scene: &SceneFile, scale: f32, translate: glam::Vec3) -> SceneFile {
    use glam::Vec3;
    let p = |v: [f32; 3]| (Vec3::from(v) * scale + translate).to_array();
    let e = |v: [f32; 3]| (Vec3::from(v) * scale).to_array();
    let mut file = scene.clone();
    let s = &mut file.scene;
    s.camera.eye = s.camera.eye * scale + translate;
    s.camera.look_at = s.camera.look_at * scale + translate;
    for sp in &mut s.spheres {
        sp.center = p(sp.center);
        sp.radius *= scale;
    }
    for l in &mut s.lights {
        l.position = p(l.position);
        l.radius *= scale;
        l.edge1 = e(l.edge1);
        l.edge2 = e(l.edge2);
        l.area *= scale * scale;
        l.point_error = kernel::geometry::triangle_light_point_error(
            Vec3::from(l.position),
            Vec3::from(l.edge1),
            Vec3::from(l.edge2),
        );
    }
    for t in &mut s.triangles {
        t.p0 = p(t.p0);
        t.edge1 = e(t.edge1);
        t.edge2 = e(t.edge2);
    }
    file
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
    /// Uniform in [0, 1) with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// A unit direction, uniform on the sphere (a point of the cube kept inside the unit ball,
    /// away from its centre, then normalised).
    pub fn direction(&mut self) -> glam::Vec3 {
        loop {
            let v = glam::Vec3::new(
                2.0 * self.unit() - 1.0,
                2.0 * self.unit() - 1.0,
                2.0 * self.unit() - 1.0,
            );
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// Each pixel's variance of the mean for `film`'s sample counts, from the per-sample variance of
/// an independent render `other` (another seed, usually more samples).
pub fn variance_of_mean_from(
    other: &twinpath::film::Film,
    film: &twinpath::film::Film,
) -> Vec<[f32; 3]> {
    other
        .variance_of_mean()
        .iter()
        .zip(&other.count)
        .zip(&film.count)
        .map(|((v, &n_other), &n)| v.map(|x| x * n_other as f32 / n.max(1) as f32))
        .collect()
}

/// The closed-form test scene: a diffuse plane y = 0 of albedo `kd` (200 x 200 units) under a
/// sphere light of radius `r` and radiance `l` centred at height `h` above the origin, with the
/// given `[camera]` and `[render]` table bodies.
pub fn plane_under_light(camera: &str, render: &str, kd: f32, h: f32, r: f32, l: f32) -> SceneFile {
    plane_under_lamps(
        camera,
        render,
        kd,
        &[Lamp {
            center: glam::Vec3::new(0.0, h, 0.0),
            radius: r,
            radiance: l,
        }],
    )
}

/// A sphere light of the plane scenes: centre, radius, radiance.
#[derive(Clone, Copy, Debug)]
pub struct Lamp {
    pub center: glam::Vec3,
    pub radius: f32,
    pub radiance: f32,
}

/// The diffuse plane y = 0 of albedo `kd` (200 x 200 units) under several sphere lights, with
/// independent samples unless `render` names a sampler (the z-tests on it need them).
pub fn plane_under_lamps(camera: &str, render: &str, kd: f32, lamps: &[Lamp]) -> SceneFile {
    let mut text = format!(
        r#"
        [camera]
        {camera}
        [render]
        {render}
        [materials]
        plane = {{ kd = [{kd}, {kd}, {kd}] }}
        [[quad]]
        corner = [-100, 0, 100]
        edge1 = [200, 0, 0]
        edge2 = [0, 0, -200]
        material = "plane"
        "#
    );
    for (i, l) in lamps.iter().enumerate() {
        let c = l.center;
        text.push_str(&format!(
            "[materials.lamp{i}]\nemission = [{0}, {0}, {0}]\n[[sphere]]\ncenter = [{1}, {2}, {3}]\nradius = {4}\nmaterial = \"lamp{i}\"\n",
            l.radiance, c.x, c.y, c.z, l.radius
        ));
    }
    let scene = scene_from_toml(&text);
    if render.contains("sampler") {
        scene
    } else {
        with_independent_samples(scene)
    }
}

/// Exact pixel values of a plane scene: the sum over lamps of kd L (r/D)^2 cos(theta) at the
/// plane point each camera ray meets (a sphere's irradiance, pi L (r/D)^2 cos, times kd/pi),
/// averaged over the pixel by a 24 x 24 midpoint quadrature (the box filter). `None` for pixels
/// any of whose quadrature rays sees a lamp or misses the plane, or where one lamp could hide
/// part of another (their cones of directions overlap).
pub fn plane_exact(scene: &Scene, kd: f32, lamps: &[Lamp]) -> Vec<Option<f64>> {
    pixel_quadrature(scene, 24, |eye, d| {
        if d.y >= 0.0 {
            return None;
        }
        for l in lamps {
            let t =
                kernel::geometry::intersect_sphere(eye, d, l.center, l.radius, 0.0, f32::INFINITY);
            if t >= 0.0 {
                return None;
            }
        }
        let x = (eye + d * (-eye.y / d.y)).as_dvec3();
        let cones: Vec<(glam::DVec3, f64)> = lamps
            .iter()
            .map(|l| {
                let to = l.center.as_dvec3() - x;
                (to.normalize(), (l.radius as f64 / to.length()).asin())
            })
            .collect();
        for (a, ca) in cones.iter().enumerate() {
            for cb in &cones[a + 1..] {
                let sep = ca.0.dot(cb.0).clamp(-1.0, 1.0).acos();
                if sep < 1.01 * (ca.1 + cb.1) {
                    return None;
                }
            }
        }
        let mut sum = 0.0;
        for l in lamps {
            let dist = (l.center.as_dvec3() - x).length();
            let cos = l.center.y as f64 / dist;
            sum += kd as f64 * l.radiance as f64 * (l.radius as f64 / dist).powi(2) * cos;
        }
        Some(sum)
    })
}

/// Each pixel's mean of `value(eye, direction)` over the camera rays through a q x q midpoint
/// quadrature of the pixel (the box filter: a pixel's samples are uniform over it), in row
/// order; `None` for a pixel where `value` is `None` at any point. The closed-form tests'
/// exact images are built on it.
pub fn pixel_quadrature(
    scene: &Scene,
    q: u32,
    value: impl Fn(glam::Vec3, glam::Vec3) -> Option<f64>,
) -> Vec<Option<f64>> {
    let cam = scene.camera.to_kernel();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let eye = glam::Vec3::new(cam.eye[0], cam.eye[1], cam.eye[2]);
    (0..w * h)
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let mut sum = 0.0;
            for sy in 0..q {
                for sx in 0..q {
                    let (u, v) = ((sx as f32 + 0.5) / q as f32, (sy as f32 + 0.5) / q as f32);
                    let d = kernel::camera::camera_ray_direction(&cam, w, h, px, py, u, v);
                    sum += value(eye, d)?;
                }
            }
            Some(sum / (q * q) as f64)
        })
        .collect()
}

/// The barycentrics (b1, b2) of corners 1 and 2 where the ray from `eye` along `d` meets
/// triangle `p`, which lies in the plane z = 0 (computed in f64); `None` outside it.
pub fn plane_triangle_barycentrics(
    p: [[f32; 3]; 3],
    eye: glam::Vec3,
    d: glam::Vec3,
) -> Option<(f64, f64)> {
    let (eye, d) = (eye.as_dvec3(), d.as_dvec3());
    let x = eye + d * (-eye.z / d.z);
    let p = p.map(|v| glam::Vec3::from(v).as_dvec3());
    let (e1, e2, q) = (p[1] - p[0], p[2] - p[0], x - p[0]);
    let det = e1.x * e2.y - e1.y * e2.x;
    let b1 = (q.x * e2.y - q.y * e2.x) / det;
    let b2 = (e1.x * q.y - e1.y * q.x) / det;
    (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0).then_some((b1, b2))
}

/// Writes `bytes` as file `name` in this test process's temporary folder for `tag` and loads
/// it as a scene.
pub fn load_scene_bytes(
    tag: &str,
    name: &str,
    bytes: &[u8],
) -> Result<SceneFile, twinpath::scene::SceneError> {
    let dir = std::env::temp_dir().join(format!("twinpath-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    SceneFile::load(&path)
}

/// Asserts that each pixel `want` gives (`None`: not compared) holds that value in the film's
/// red channel to 1e-5 relative: for pixels whose every sample is the same value (a diffuse
/// plane under a directional light, direct light only), where only the f32 rounding of the
/// estimator's ~20 operations remains (each within 2^-24 relative; the running mean of equal
/// values is exact), so 1e-5 holds it 8 times over. `label` names the render in a failure.
pub fn assert_noiseless_pixels(film: &twinpath::film::Film, want: &[Option<f64>], label: &str) {
    let mean = film.mean();
    for (i, w) in want.iter().enumerate() {
        if let Some(w) = w {
            let m = mean[i][0] as f64;
            assert!((m - w).abs() <= 1e-5 * w, "{label}: pixel {i}: {m} vs {w}");
        }
    }
}

/// The largest |z| of a film's red channel (means `mean`, variances of the mean `var`) against
/// the pixel values `wrong` of a hypothesis the test must reject (`None`: pixel not compared).
pub fn max_abs_z(mean: &[[f32; 3]], var: &[[f32; 3]], wrong: &[Option<f64>]) -> f64 {
    wrong
        .iter()
        .enumerate()
        .filter_map(|(i, e)| e.map(|e| ((mean[i][0] as f64 - e) / (var[i][0] as f64).sqrt()).abs()))
        .fold(0.0, f64::max)
}

/// z-tests a film's red channel against exact pixel values: each pixel (Sidak-corrected for
/// the number tested) and all pixels together. Returns the overall z.
pub fn assert_film_matches(film: &twinpath::film::Film, exact: &[Option<f64>], label: &str) -> f64 {
    assert_film_matches_with_variance(film, exact, film.variance_of_mean(), label)
}

/// As [`assert_film_matches`], with each pixel's variance of the mean given: for heavy-tailed
/// pixels, whose own sample variance is low exactly when their rare large samples are missing
/// (which makes the mean low too and the z-score a false alarm), pass a variance estimated
/// from an independent render ([`variance_of_mean_from`]).
pub fn assert_film_matches_with_variance(
    film: &twinpath::film::Film,
    exact: &[Option<f64>],
    var: Vec<[f32; 3]>,
    label: &str,
) -> f64 {
    let mean = film.mean();
    let tested = exact.iter().filter(|e| e.is_some()).count();
    let z_max = z_critical(1e-3, tested);
    let (mut worst, mut sum_d, mut sum_v) = (0.0f64, 0.0, 0.0);
    for (i, e) in exact.iter().enumerate() {
        let Some(e) = e else { continue };
        let (m, v) = (mean[i][0] as f64, var[i][0] as f64);
        let z = (m - e) / v.sqrt();
        worst = worst.max(z.abs());
        sum_d += m - e;
        sum_v += v;
        assert!(
            z.abs() < z_max,
            "{label}: pixel {i}: {m} vs exact {e}, |z| = {:.2} >= {z_max:.2}",
            z.abs()
        );
    }
    let z_all = sum_d / sum_v.sqrt();
    println!("{label}: {tested} pixels vs closed form: max |z| {worst:.2} (bound {z_max:.2}); all pixels together z = {z_all:+.2}");
    assert!(
        z_all.abs() < z_critical(1e-3, 1),
        "{label}: overall z = {z_all:.2}"
    );
    z_all
}
