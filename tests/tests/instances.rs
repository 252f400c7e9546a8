//! Instances (`kernel::scene::Instance`): a mesh stored once, in object space, and placed by
//! affine transforms; the GPU's TLAS instances of one BLAS per mesh, the CPU's two-level BVH.
//!
//! 1. An instanced mesh renders as the same triangles flattened into world space: per-pixel
//!    z-tests on both backends, with shading normals and a normal map under rotation,
//!    non-uniform scale, shear and mirroring; a placement 10 degrees off is rejected. Not bit for
//!    bit: the flattened triangles' vertices are rounded once at load, the instanced hit point
//!    is mapped at every hit, and its error bound (so the offset of the rays leaving it) is
//!    wider by the round trip through the inverse.
//! 2. An instanced hit point lies within its error bound (`instance::world_point_error`) of the
//!    exact transformed triangle's plane, and rays leaving it never hit its triangle again,
//!    under extreme transforms (scales 10^-3..10^3, anisotropy to 100, translations to 10^4,
//!    mirrors). CPU; the kernel functions are the GPU closest-hit shader's.
//! 3. A far-off, mirrored, anisotropically scaled instanced floor under a directional light is
//!    exact per pixel on both backends: a shadow ray hitting its own floor would darken one.
//! 4. Loaders: TOML entries sharing a file and glTF meshes shared by nodes become instances;
//!    emissive and small meshes are flattened; memory of 1000 instances of a 100k-triangle
//!    mesh on both backends.

use glam::{DVec3, Vec3};
use kernel::geometry::{intersect_triangle, lift_ray_origin};
use kernel::sampling::sample_cosine_hemisphere;
use std::path::{Path, PathBuf};
use twinpath::cpu::Bvh;
use twinpath::render::Backend;
use twinpath::scene::instancing::{instance_record, DETERMINANT_CONDITION_LIMIT};
use twinpath::scene::transform::Transform;
use twinpath::scene::{parse_scene, SceneFile};
use twinpath_tests::device_inverse::stored_object_to_world;
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::placements::Placements;
use twinpath_tests::{
    assert_noiseless_pixels, pixel_quadrature, render_film, with_independent_samples, z_critical,
    SplitMix,
};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-inst-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A torus (major radius 1, minor 0.35) of `rings` x `sides` quads: vertex positions, normals,
/// texture coordinates and triangle indices.
type Arrays = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u32>);
fn torus(rings: usize, sides: usize) -> Arrays {
    let (mut p, mut n, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..=rings {
        for j in 0..=sides {
            let (u, v) = (i as f64 / rings as f64, j as f64 / sides as f64);
            let (a, b) = (u * std::f64::consts::TAU, v * std::f64::consts::TAU);
            let normal = DVec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos());
            let point = DVec3::new(a.cos(), 0.0, a.sin()) + 0.35 * normal;
            p.push(point.as_vec3().to_array());
            n.push(normal.as_vec3().to_array());
            uv.push([u as f32, v as f32]);
        }
    }
    let k = |i: usize, j: usize| (i * (sides + 1) + j) as u32;
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1));
            idx.extend([a, d, c, a, c, b]);
        }
    }
    (p, n, uv, idx)
}

/// [`torus`] as an OBJ file.
fn torus_obj(rings: usize, sides: usize) -> String {
    let (p, n, uv, idx) = torus(rings, sides);
    let mut s = String::new();
    for k in 0..p.len() {
        s += &format!(
            "v {} {} {}\nvn {} {} {}\nvt {} {}\n",
            p[k][0], p[k][1], p[k][2], n[k][0], n[k][1], n[k][2], uv[k][0], uv[k][1]
        );
    }
    for f in idx.chunks(3) {
        let [a, b, c] = [f[0] + 1, f[1] + 1, f[2] + 1];
        s += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n");
    }
    s
}

/// An OBJ grid of n x n quads over [-1, 1]^2 in the plane z = 0, front face +z.
fn grid_obj(n: usize) -> String {
    twinpath_tests::grid_obj(n, [-1.0, -1.0, 0.0], [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
}

fn load(dir: &Path, text: &str) -> SceneFile {
    parse_scene(text, &dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The placements of test 1: rotation, anisotropic scale, a mirror, a shear matrix, and a
/// stretch by 23.2 along (1, 1, 1) scaled by 0.06 (0.06 (I + 7.4 J)): a determinant condition
/// of 120, just within the loader's limit of 125 (`instancing::DETERMINANT_CONDITION_LIMIT`),
/// where the offsets carry the most of a device's adjugate inverse.
const PLACEMENTS: [&str; 5] = [
    "rotate = [35, 1, 0.3, 0]\ntranslate = [-1.3, 0.6, 0]",
    "scale = [0.6, 1.4, 0.8]\nrotate = [-20, 0, 0, 1]\ntranslate = [1.3, 0.6, 0.2]",
    "scale = [-0.8, 0.8, 0.8]\nrotate = [70, 1, 0, 0]\ntranslate = [0, 0.5, -1.4]",
    "matrix = [[0.7, 0.3, 0, 0.1], [0, 0.7, 0.2, 1.6], [0.1, 0, 0.7, -0.5], [0, 0, 0, 1]]",
    "matrix = [[0.504, 0.444, 0.444, 0], [0.444, 0.504, 0.444, 0.9], [0.444, 0.444, 0.504, 1.3], [0, 0, 0, 1]]",
];

/// Test 1's scene: a floor, a sphere light, and the torus placed five times, from the files
/// `files` (one name five times: instanced; five names: flattened), with `placements`.
fn tori_scene(dir: &Path, files: [&str; 5], placements: [&str; 5]) -> SceneFile {
    let mut text = String::from(
        "[camera]\neye = [0, 3.5, 5.5]\nlook_at = [0, 0.5, 0]\nup = [0, 1, 0]\nvfov = 45\nwidth = 32\nheight = 24\n\
         [render]\nseed = 3\n[materials]\nfloor = { kd = [0.6, 0.6, 0.6] }\n\
         ring = { kd = [0.7, 0.5, 0.3], ks = [0.3, 0.3, 0.3], alpha = 0.1, normal_map = \"bumps.png\" }\n\
         lamp = { emission = [20, 20, 20] }\n\
         [[quad]]\ncorner = [-4, 0, 4]\nedge1 = [8, 0, 0]\nedge2 = [0, 0, -8]\nmaterial = \"floor\"\n\
         [[sphere]]\ncenter = [1, 4, 2]\nradius = 0.5\nmaterial = \"lamp\"\n"
    );
    for (file, placement) in files.iter().zip(placements) {
        text += &format!("[[mesh]]\nfile = \"{file}\"\nmaterial = \"ring\"\n{placement}\n");
    }
    with_independent_samples(load(dir, &text))
}

/// A normal map of bumps: the texel's tangent-space normal tilts with position.
fn bumps_png(dir: &Path) {
    image::RgbImage::from_fn(16, 16, |x, y| {
        let (u, v) = (x as f32 / 15.0 - 0.5, y as f32 / 15.0 - 0.5);
        let n = Vec3::new(0.8 * u, 0.8 * v, 1.0).normalize();
        image::Rgb([0, 1, 2].map(|c| ((n[c] * 0.5 + 0.5) * 255.0).round() as u8))
    })
    .save(dir.join("bumps.png"))
    .unwrap();
}

/// The largest per-pixel |z| of the difference of two independent renders (red channel).
fn max_pair_z(a: &twinpath::film::Film, b: &twinpath::film::Film) -> f64 {
    let (ma, va, mb, vb) = (
        a.mean(),
        a.variance_of_mean(),
        b.mean(),
        b.variance_of_mean(),
    );
    (0..ma.len())
        .filter_map(|i| {
            let v = va[i][0] as f64 + vb[i][0] as f64;
            (v > 0.0).then(|| ((ma[i][0] - mb[i][0]) as f64 / v.sqrt()).abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn an_instanced_mesh_renders_as_its_flattened_copies_on_both_backends() {
    let dir = temp_dir("tori");
    bumps_png(&dir);
    let obj = torus_obj(16, 8);
    let copies = ["a.obj", "b.obj", "c.obj", "d.obj", "e.obj"];
    for name in std::iter::once("torus.obj").chain(copies) {
        std::fs::write(dir.join(name), &obj).unwrap();
    }
    let instanced = tori_scene(&dir, ["torus.obj"; 5], PLACEMENTS);
    let flattened = tori_scene(&dir, copies, PLACEMENTS);
    assert_eq!(
        (
            instanced.scene.meshes.len(),
            instanced.scene.instances.len()
        ),
        (1, 5)
    );
    let conditions: Vec<f32> = (instanced.scene.instances.iter())
        .map(|i| i.determinant_condition)
        .collect();
    println!("determinant conditions of the placements: {conditions:?}");
    assert!(
        conditions
            .iter()
            .any(|&h| h > 100.0 && h <= DETERMINANT_CONDITION_LIMIT),
        "no placement near the determinant condition's limit: {conditions:?}"
    );
    assert_eq!(
        instanced.scene.triangles.len(),
        2 + 16 * 8 * 2,
        "the torus once"
    );
    assert!(flattened.scene.instances.is_empty());
    assert_eq!(flattened.scene.triangles.len(), 2 + 5 * 16 * 8 * 2);
    assert_ne!(instanced.features() & kernel::features::INSTANCES, 0);
    assert_eq!(flattened.features() & kernel::features::INSTANCES, 0);
    // The first torus turned 10 degrees further: a placement the test must tell apart.
    let mut off = PLACEMENTS;
    off[0] = "rotate = [45, 1, 0.3, 0]\ntranslate = [-1.3, 0.6, 0]";
    let wrong = tori_scene(&dir, copies, off);
    let pixels = (instanced.scene.camera.width * instanced.scene.camera.height) as usize;
    let bound = z_critical(1e-3, pixels);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let spp = 256;
        let a = render_film(&instanced, backend, spp);
        let mut b_scene = flattened.clone();
        b_scene.settings.seed = 11;
        let b = render_film(&b_scene, backend, spp);
        let z = max_pair_z(&a, &b);
        println!("{backend:?}: instanced vs flattened: max |z| {z:.2} over {pixels} pixels (bound {bound:.2})");
        assert!(z < bound, "{backend:?}: max |z| {z:.2} >= {bound:.2}");
        if backend == Backend::Cpu {
            let mut w_scene = wrong.clone();
            w_scene.settings.seed = 11;
            let w = render_film(&w_scene, backend, spp);
            let zw = max_pair_z(&a, &w);
            println!("{backend:?}: instanced vs a torus 10 degrees off: max |z| {zw:.2}");
            assert!(
                zw > 2.0 * bound,
                "a 10-degree rotation is not rejected: {zw:.2}"
            );
        }
    }
    assert_validation_clean();
}

/// A random affine placement for test 2 (`Placements::instance_map`, as the robustness tests
/// draw them: scale 10^U(-3, 3), anisotropy up to 100, a random rotation, a mirror in half the
/// cases, translation up to 10^4 x the scale, capped at 10^4), and its largest stretch.
fn random_transform(g: &mut Placements) -> (Transform, f64) {
    loop {
        let (m, stretch) = g.instance_map();
        if let Ok(Some(transform)) = Transform::affine(m) {
            return (transform, stretch);
        }
    }
}

#[test]
fn instanced_hits_lie_within_their_error_bound_and_rays_leaving_them_never_return() {
    // One torus mesh under 400 random extreme placements, one BVH: rays toward random points
    // of random instances' triangles.
    let dir = temp_dir("reint");
    std::fs::write(dir.join("torus.obj"), torus_obj(12, 6)).unwrap();
    let base = load(
        &dir,
        "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 4\nheight = 4\n\
         [materials]\nwhite = { kd = [0.5, 0.5, 0.5] }\n[[mesh]]\nfile = \"torus.obj\"\nmaterial = \"white\"\n",
    );
    let mesh = base.scene.triangles.clone();
    let mut scene = base.clone();
    scene.scene.triangles.clear();
    scene.scene.triangle_groups.clear();
    scene.scene.triangles.extend(&mesh);
    scene.scene.meshes = vec![twinpath::scene::TriangleGroup {
        name: "torus".into(),
        range: 0..mesh.len(),
    }];
    let mut g = Placements(SplitMix(7));
    let mut scales = Vec::new();
    for _ in 0..400 {
        let (t, s) = random_transform(&mut g);
        scene.scene.instances.push(instance_record(&t, 0));
        scene.scene.instance_meshes.push(0);
        scales.push(s);
    }
    let bvh = Bvh::build_scene(&scene.scene);
    let cases = 200_000;
    let (mut tested, mut outside, mut returned, mut worst) = (0, 0, 0, 0.0f64);
    for _ in 0..cases {
        let k =
            (g.unit() * scene.scene.instances.len() as f32) as usize % scene.scene.instances.len();
        let inst = scene.scene.instances[k];
        let tri = mesh[(g.unit() * mesh.len() as f32) as usize % mesh.len()];
        let (a, b) = (g.unit(), g.unit());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let p_obj = Vec3::from(tri.p0) + a * Vec3::from(tri.edge1) + b * Vec3::from(tri.edge2);
        let target = kernel::instance::point_to_world(&inst, p_obj);
        let away = Vec3::new(g.unit() - 0.5, g.unit() - 0.5, g.unit() - 0.5).normalize();
        let origin = target + away * (scales[k] as f32) * 3.0;
        let dir = (target - origin).normalize();
        let hit = bvh.closest_prim(origin, dir, f32::INFINITY);
        if hit.instance == kernel::scene::NONE || !dir.is_finite() {
            continue; // hidden by another instance, or slipped past an edge
        }
        tested += 1;
        let record = bvh.surface(hit, origin, dir);
        // The exact plane of the hit triangle under the exact map of the stored matrix.
        let h_inst = scene.scene.instances[hit.instance as usize];
        let t = mesh[hit.prim as usize];
        let stored = stored_object_to_world(&h_inst);
        let m = |p: Vec3| -> DVec3 { stored.transform_point3(p.as_dvec3()) };
        let p0 = Vec3::from(t.p0);
        let (q0, q1, q2) = (
            m(p0),
            m(p0 + Vec3::from(t.edge1)),
            m(p0 + Vec3::from(t.edge2)),
        );
        let n = (q1 - q0).cross(q2 - q0).normalize();
        let distance = n.dot(record.position.as_dvec3() - q0).abs();
        let allowed = record.offset as f64;
        worst = worst.max(distance / allowed);
        outside += (distance > allowed) as usize;
        // Rays leaving the hit on the side it came from, as the renderer spawns them.
        let n_side = record.facing_normal();
        let o = lift_ray_origin(record.position, n_side, record.offset);
        let w = sample_cosine_hemisphere(n_side, g.unit(), g.unit());
        let (oo, wo) = kernel::instance::ray_to_object(&h_inst, o, w);
        let again = intersect_triangle(
            oo,
            wo,
            p0,
            Vec3::from(t.edge1),
            Vec3::from(t.edge2),
            0.0,
            f32::INFINITY,
        );
        returned += (w.dot(n_side) > 0.0 && again >= 0.0) as usize;
    }
    println!(
        "{tested} instanced hits: {outside} farther from the exact plane than their bound \
         (worst distance / bound {worst:.3}), {returned} leaving rays hit their triangle again"
    );
    assert!(tested > cases / 2, "{tested} hits");
    assert_eq!((outside, returned), (0, 0));
}

/// The world height that `instance::world_height_v3` gives for an object-space height of 1
/// moves a point at least 1 along the object triangle's exact normal n_o once mapped back by the
/// exact inverse X of the stored `object_to_world` (the map the device places the mesh by,
/// inverted in f64): H n_w . X^T n_o >= 1, with n_w normalised from the world normal the kernel
/// computes of the triangle's computed normal, for 400 maps of test 2 (scales 10^-3..10^3,
/// anisotropy to 100, mirrors, translations) and 250 triangles each, a quarter of them slivers
/// (edges 10^-4..10^-1 radians apart). Where `carries_heights` refuses the bound the host
/// names the triangle; those are counted, not held.
///
/// And tight where the triangle is well-conditioned: at most 1 + 2^-6. The bound's slack is
/// its deviation over L_low (`world_height_v3`): eps w (16 + 7 s) / L + 2 eps m w, which for
/// s <= `WELL_CONDITIONED_WEIGHTS` and these maps (m w <= 300, w / L <= sqrt(3) m w) is below
/// 2^-7. A height carried loosely is not safer (a needle's grazing rays are met again from too
/// high, docs/robustness.md, "Known limits"). Three mutations must fail: sqrt(3) ||M|| alone
/// (the first version) exceeds 1 + 2^-6; the height without its rounding spares (1 / length)
/// falls below 1; and the previous bound, L (1 - 8 eps) - 8 eps w, which counted neither the
/// stored inverse's pairing with the rounded forward matrix nor the normal's rounding, falls
/// below 1.
#[test]
fn world_heights_carry_object_heights_tightly_under_every_map() {
    use kernel::geometry::{TriangleShape, WELL_CONDITIONED_WEIGHTS};
    use kernel::instance::{carries_heights, normal_to_world, world_height_v3, SQRT_3_ABOVE};
    let mut g = Placements(SplitMix(77));
    let (mut lowest, mut highest, mut refused, mut slivers) = (f64::INFINITY, 0f64, 0, 0);
    // The three mutations: no rounding spares (1 / length), sqrt(3) ||M|| alone, and the
    // previous bound.
    let (mut bare_lowest, mut loose_highest, mut previous_lowest) =
        (f64::INFINITY, 0f64, f64::INFINITY);
    for _ in 0..400 {
        let (transform, _) = random_transform(&mut g);
        let inst = instance_record(&transform, 0);
        let inverse_transpose = stored_object_to_world(&inst).inverse().transpose();
        for k in 0..250 {
            let e1 = g.dir() * g.pow10(-1.0, 1.0);
            let e2 = if k % 4 == 0 {
                let across = e1.cross(g.dir()).normalize() * e1.length();
                e1 * g.pow10(-0.5, 0.5) + across * g.pow10(-4.0, -1.0)
            } else {
                g.dir() * g.pow10(-1.0, 1.0)
            };
            let shape = TriangleShape::of(e1, e2);
            let exact_normal = e1.as_dvec3().cross(e2.as_dvec3()).normalize();
            if !exact_normal.is_finite() {
                continue;
            }
            let weight_sum = shape.weights.element_sum();
            let world_normal = normal_to_world(&inst, shape.normal);
            let length = world_normal.length();
            let n_world = world_normal.normalize().as_dvec3();
            let along = n_world.dot(inverse_transpose.transform_vector3(exact_normal));
            if !carries_heights(&inst, length, weight_sum) {
                refused += 1;
                continue;
            }
            let height = world_height_v3(&inst, length, weight_sum, 1.0f32) as f64;
            lowest = lowest.min(height * along);
            bare_lowest = bare_lowest.min(along / length as f64);
            let eps = f32::EPSILON as f64;
            let previous = length as f64 * (1.0 - 8.0 * eps) - 8.0 * eps * inst.inverse_norm as f64;
            previous_lowest = previous_lowest.min((1.0 + 4.0 * eps) / previous * along);
            if weight_sum <= WELL_CONDITIONED_WEIGHTS {
                highest = highest.max(height * along);
                loose_highest =
                    loose_highest.max(SQRT_3_ABOVE as f64 * inst.forward_norm as f64 * along);
            } else {
                slivers += 1;
            }
        }
    }
    println!("world heights of an object height of 1, mapped back: from {lowest:.9}, well-conditioned up to {highest:.9} ({slivers} slivers beyond, {refused} refused); without the rounding spares from {bare_lowest:.9}, by the previous bound from {previous_lowest:.9}, by sqrt(3) ||M|| alone up to {loose_highest:.3}");
    assert!(lowest >= 1.0, "{lowest}");
    assert!(highest <= 1.0 + 1.0 / 64.0, "{highest}");
    assert!(
        bare_lowest < 1.0,
        "the rounding spares are not shown to be needed"
    );
    assert!(
        previous_lowest < 1.0,
        "the previous bound is not shown to fall short"
    );
    assert!(
        loose_highest > 1.0 + 1.0 / 64.0,
        "the loose factor is not shown to fail"
    );
}

#[test]
fn a_far_mirrored_instanced_floor_is_exact_under_a_directional_light_on_both_backends() {
    // The grid (front +z) turned to face +y, stretched 100 x 100 (x 1 in its normal), placed
    // twice side by side far from the origin, the second mirrored; direct light only.
    let dir = temp_dir("floor");
    std::fs::write(dir.join("grid.obj"), grid_obj(4)).unwrap();
    let far = Vec3::new(4000.0, -3000.0, 6000.0);
    let (kd, e) = (0.6f32, 2.5f64);
    let travel = Vec3::new(0.3, -1.0, 0.6);
    let place = |scale_x: f32, dx: f32| {
        format!(
            "[[mesh]]\nfile = \"grid.obj\"\nmaterial = \"floor\"\nscale = [{scale_x}, 100, 1]\nrotate = [-90, 1, 0, 0]\ntranslate = [{}, {}, {}]\n",
            far.x + dx,
            far.y,
            far.z
        )
    };
    let text = format!(
        "[camera]\neye = [{}, {}, {}]\nlook_at = [{}, {}, {}]\nup = [0, 1, 0]\nvfov = 50\nwidth = 24\nheight = 18\n\
         [render]\nmax_depth = 1\n[materials]\nfloor = {{ kd = [{kd}, {kd}, {kd}] }}\n\
         [[light]]\ndirection = [{}, {}, {}]\nirradiance = [{e}, {e}, {e}]\n{}{}",
        far.x,
        far.y + 3.0,
        far.z + 5.0,
        far.x,
        far.y,
        far.z,
        travel.x,
        travel.y,
        travel.z,
        place(100.0, -100.0),
        place(-100.0, 100.0)
    );
    let scene = with_independent_samples(load(&dir, &text));
    assert_eq!(
        (scene.scene.meshes.len(), scene.scene.instances.len()),
        (1, 2)
    );
    assert_eq!(scene.scene.instances[1].handedness, -1.0);
    let toward = -travel.as_dvec3().normalize();
    let lit = kd as f64 / std::f64::consts::PI * e * toward.y;
    // Pixels whose every quadrature ray meets the floor away from the seam between the two
    // instances (a ray through the seam may meet either or, between their roundings, neither).
    let want = pixel_quadrature(&scene.scene, 8, |eye, d| {
        if d.y >= 0.0 {
            return None;
        }
        let x = eye.as_dvec3() + d.as_dvec3() * ((far.y - eye.y) as f64 / d.y as f64);
        ((x.x - far.x as f64).abs() > 0.05).then_some(lit)
    });
    assert!(want.iter().flatten().count() > want.len() * 3 / 4);
    for backend in [Backend::Cpu, Backend::Gpu] {
        // Every sample of a lit pixel is kd E cos / pi; a shadow ray meeting its own floor
        // would make a sample 0.
        let film = render_film(&scene, backend, 64);
        assert_noiseless_pixels(&film, &want, &format!("{backend:?}"));
    }
    // The hypothesis of a floor without its transform's normal (the object-space +z): the
    // cosine would differ; the exact test above rejects it by far.
    let wrong = kd as f64 / std::f64::consts::PI * e * toward.z.abs();
    assert!((wrong - lit).abs() > 0.1 * lit);
    assert_validation_clean();
}

/// A glTF file of the torus placed by three nodes: one mesh the nodes share (`shared`), or a
/// copy of it per node. Seen by the framing camera under the default white sky.
fn tori_gltf(shared: bool) -> SceneFile {
    use serde_json::json;
    let mut g = twinpath_tests::gltf_writer::GltfWriter::new();
    let (p, n, uv, idx) = torus(16, 8);
    let material = g.push(
        "materials",
        json!({ "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0.3, "roughnessFactor": 0.5 } }),
    );
    let copies = if shared { 1 } else { 3 };
    let meshes: Vec<usize> = (0..copies)
        .map(|_| g.mesh(&p, Some(&n), Some(&uv), &idx, Some(material)))
        .collect();
    let nodes = [
        json!({ "translation": [-1.2, 0, 0], "rotation": [0.3826834, 0, 0, 0.9238795] }),
        json!({ "translation": [1.2, 0, 0], "scale": [0.7, 1.5, 0.7] }),
        json!({ "translation": [0, -1.0, -0.5], "scale": [-1, 1, 1] }),
    ];
    for (k, mut node) in nodes.into_iter().enumerate() {
        node["mesh"] = json!(meshes[k % copies]);
        g.push("nodes", node);
    }
    g.push("scenes", json!({ "nodes": [0, 1, 2] }));
    let mut scene = twinpath::scene::gltf::load_bytes(Path::new("tori.glb"), &g.glb(), None, None)
        .unwrap_or_else(|e| panic!("{e}"));
    scene.camera.width = 32;
    scene.camera.height = 18;
    with_independent_samples(SceneFile {
        scene,
        settings: Default::default(),
    })
}

#[test]
fn gltf_meshes_shared_by_nodes_are_instanced_and_render_as_their_copies() {
    let mut shared = tori_gltf(true);
    let copies = tori_gltf(false);
    assert_eq!(
        (shared.scene.meshes.len(), shared.scene.instances.len()),
        (1, 3)
    );
    assert_eq!(shared.scene.triangles.len(), 16 * 8 * 2);
    assert!(copies.scene.instances.is_empty());
    // The framing camera frames the instances' boxes (the mesh box's corners mapped), which
    // hold the copies' exact box: it stands a little farther back. Both are seen through the
    // copies' camera here.
    assert!(shared.scene.camera.focus_distance >= copies.scene.camera.focus_distance);
    shared.scene.camera = copies.scene.camera;
    let bound = z_critical(1e-3, (32 * 18) as usize);
    for backend in [Backend::Cpu, Backend::Gpu] {
        let a = render_film(&shared, backend, 64);
        let mut c = copies.clone();
        c.settings.seed = 9;
        let b = render_film(&c, backend, 64);
        let z = max_pair_z(&a, &b);
        println!("{backend:?}: glTF instances vs copies: max |z| {z:.2} (bound {bound:.2})");
        assert!(z < bound, "{backend:?}: {z:.2}");
    }
    assert_validation_clean();
}

/// A glTF mesh shared by three nodes: placed as it is, by a stretch of 29.5 along (1, 1, 1)
/// (`matrix`; condition 39, determinant condition 194) and by a scale of 2000 along z
/// (condition 2000). Only the first is instanced; the other two are flattened into world space
/// (`instancing::flattening_reason`), with one note naming the mesh and the first's reason.
#[test]
fn gltf_placements_a_device_inverse_may_not_keep_are_flattened() {
    use serde_json::json;
    let mut g = twinpath_tests::gltf_writer::GltfWriter::new();
    let (p, n, uv, idx) = torus(16, 8);
    let mesh = g.mesh(&p, Some(&n), Some(&uv), &idx, None);
    let stretch = [
        10.5, 9.5, 9.5, 0.0, 9.5, 10.5, 9.5, 0.0, 9.5, 9.5, 10.5, 0.0, 0.0, 0.0, 0.0, 1.0,
    ];
    for node in [
        json!({ "mesh": mesh }),
        json!({ "mesh": mesh, "matrix": stretch }),
        json!({ "mesh": mesh, "scale": [1, 1, 2000] }),
    ] {
        g.push("nodes", node);
    }
    g.push("scenes", json!({ "nodes": [0, 1, 2] }));
    let scene = twinpath::scene::gltf::load_bytes(Path::new("placed.glb"), &g.glb(), None, None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((scene.meshes.len(), scene.instances.len()), (1, 1));
    assert_eq!(scene.world_triangle_count(), 2 * 16 * 8 * 2);
    let flattened: Vec<_> = scene
        .notes
        .iter()
        .filter(|n| n.contains("flattened"))
        .collect();
    println!("{flattened:?}");
    assert_eq!(flattened.len(), 1, "{:?}", scene.notes);
    assert!(
        flattened[0].contains("meshes[0]: 2 placements flattened")
            && flattened[0].contains("determinant condition perm(|A|) / |det A| is 194"),
        "{flattened:?}"
    );
}

/// Flattening for the device's inverse is bounded per mesh: a 16-triangle torus placed 70 times
/// by a stretch of 29.5 along (1, 1, 1) (determinant condition 194) is flattened 64 times
/// (`instancing::MAX_FLATTENED_PLACEMENTS`) and instanced 6 times; a 100,352-triangle grid placed
/// 12 times so is flattened 10 times (1,003,520 triangles, within
/// `instancing::MAX_FLATTENED_TRIANGLES` = 1,048,576; an 11th copy would pass it) and instanced
/// twice. Each mesh gets one note saying both.
#[test]
fn flattened_copies_of_a_mesh_stay_within_their_budget() {
    use twinpath::scene::instancing::{MAX_FLATTENED_PLACEMENTS, MAX_FLATTENED_TRIANGLES};
    let dir = temp_dir("budget");
    std::fs::write(dir.join("torus.obj"), torus_obj(4, 2)).unwrap();
    std::fs::write(dir.join("grid.obj"), grid_obj(224)).unwrap();
    let stretch =
        "matrix = [[10.5, 9.5, 9.5, 0], [9.5, 10.5, 9.5, 0], [9.5, 9.5, 10.5, 0], [0, 0, 0, 1]]";
    let mut text = String::from(
        "[camera]\neye = [0, 0, 9]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 4\nheight = 4\n\
         [materials]\nwhite = { kd = [0.5, 0.5, 0.5] }\n",
    );
    for (file, copies) in [("torus.obj", 70), ("grid.obj", 12)] {
        for _ in 0..copies {
            text += &format!("[[mesh]]\nfile = \"{file}\"\nmaterial = \"white\"\n{stretch}\n");
        }
    }
    let scene = load(&dir, &text).scene;
    let grid = 224 * 224 * 2;
    assert_eq!(MAX_FLATTENED_PLACEMENTS, 64);
    assert!(10 * grid <= MAX_FLATTENED_TRIANGLES && 11 * grid > MAX_FLATTENED_TRIANGLES);
    assert_eq!((scene.meshes.len(), scene.instances.len()), (2, 6 + 2));
    assert_eq!(scene.world_triangle_count(), 64 * 16 + 10 * grid);
    for n in &scene.notes {
        println!("note: {n}");
    }
    let note = |file: &str| scene.notes.iter().find(|n| n.starts_with(file)).unwrap();
    assert!(note("torus.obj").contains("64 placements flattened"));
    assert!(note("torus.obj").contains("; 6 more stay instanced"));
    assert!(note("grid.obj").contains("10 placements flattened"));
    assert!(note("grid.obj").contains("; 2 more stay instanced"));
    assert_eq!(scene.notes.len(), 2);
}

#[test]
fn emissive_and_small_shared_meshes_are_flattened() {
    let dir = temp_dir("policy");
    std::fs::write(dir.join("torus.obj"), torus_obj(4, 2)).unwrap();
    std::fs::write(dir.join("tiny.obj"), grid_obj(2)).unwrap();
    let scene = load(
        &dir,
        "[camera]\neye = [0, 0, 9]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 4\nheight = 4\n\
         [materials]\nwhite = { kd = [0.5, 0.5, 0.5] }\nlamp = { emission = [1, 1, 1] }\n\
         [[mesh]]\nfile = \"torus.obj\"\nmaterial = \"lamp\"\n[[mesh]]\nfile = \"torus.obj\"\nmaterial = \"lamp\"\ntranslate = [3, 0, 0]\n\
         [[mesh]]\nfile = \"tiny.obj\"\nmaterial = \"white\"\n[[mesh]]\nfile = \"tiny.obj\"\nmaterial = \"white\"\ntranslate = [0, 3, 0]\n\
         [[mesh]]\nfile = \"torus.obj\"\nmaterial = \"white\"\ntranslate = [0, -3, 0]\n[[mesh]]\nfile = \"torus.obj\"\nmaterial = \"white\"\ntranslate = [-3, 0, 0]\n",
    );
    // The lamp torus (16 triangles, emissive) twice and the tiny grid (8 triangles) twice are
    // flattened; the white torus, shared by two entries, is instanced.
    assert_eq!(
        (scene.scene.meshes.len(), scene.scene.instances.len()),
        (1, 2)
    );
    assert_eq!(scene.scene.world_triangle_count(), 2 * 16 + 2 * 8);
    assert_eq!(scene.scene.lights.len(), 2 * 16);
    assert_eq!(scene.scene.triangles.len(), 2 * 16 + 2 * 8 + 16);
}

#[test]
fn a_thousand_instances_of_a_100k_triangle_mesh_store_it_once_on_both_backends() {
    let dir = temp_dir("thousand");
    std::fs::write(dir.join("grid.obj"), grid_obj(224)).unwrap();
    let mut text = String::from(
        "[camera]\neye = [5, 12, 30]\nlook_at = [5, 4, 5]\nup = [0, 1, 0]\nvfov = 40\nwidth = 32\nheight = 24\n\
         [background]\nradiance = [1, 1, 1]\n[materials]\nwhite = { kd = [0.5, 0.5, 0.5] }\n",
    );
    for k in 0..1000 {
        let (x, y, z) = (k % 10, (k / 10) % 10, k / 100);
        text += &format!(
            "[[mesh]]\nfile = \"grid.obj\"\nmaterial = \"white\"\nscale = 0.4\nrotate = [{}, 0, 1, 0]\ntranslate = [{x}, {y}, {z}]\n",
            k * 7
        );
    }
    let mut scene = load(&dir, &text);
    let triangles = 224 * 224 * 2;
    assert_eq!(scene.scene.triangles.len(), triangles);
    assert_eq!(
        (scene.scene.meshes.len(), scene.scene.instances.len()),
        (1, 1000)
    );
    scene.settings.spp = 2;
    // Flattened, the triangles alone would take 1000 x 100352 x 48 bytes = 4.5 GiB.
    let flattened = (1000 * triangles * 48) as f64;
    let tables: usize = scene.scene.table_bytes().iter().map(|t| t.1).sum();
    println!("scene tables: {}", scene.scene.memory_report());
    for backend in [Backend::Cpu, Backend::Gpu] {
        let out = twinpath::render::render(
            &scene.scene,
            &scene.settings,
            &twinpath::render::RenderOptions {
                backend,
                device: None,
                validation: backend == Backend::Gpu,
                progress: false,
                samples: None,
            },
        )
        .unwrap();
        let total = tables as f64 + out.accel_bytes as f64;
        println!(
            "{backend:?}: 1000 instances of a {triangles}-triangle mesh: acceleration structure \
             {:.1} MiB, with the scene's tables {:.1} MiB ({:.4} of the flattened triangles' \
             4.5 GiB); BVH/AS build {:.3} s",
            out.accel_bytes as f64 / 1048576.0,
            total / 1048576.0,
            total / flattened,
            out.accel_build.as_secs_f64()
        );
        assert!(out.accel_bytes > 0);
        assert!(total < flattened / 50.0, "{backend:?}: {total} bytes");
        // The grids cover much of the view: pixels darker than the white sky see them.
        let seen = out.film.mean().iter().filter(|p| p[0] < 0.9).count();
        assert!(seen > 32 * 24 / 4, "{backend:?}: {seen} pixels see a grid");
    }
    assert_validation_clean();
}

#[test]
fn the_shipped_instances_scene_stores_its_two_meshes_once() {
    let scene =
        SceneFile::load(&twinpath_tests::repo_root().join("scenes/instances.toml")).unwrap();
    assert_eq!(
        (scene.scene.meshes.len(), scene.scene.instances.len()),
        (2, 15)
    );
    assert_eq!(scene.scene.world_triangle_count(), 2, "the ground alone");
    assert_eq!(scene.scene.triangles.len(), 2 + 2304 + 1280);
}
