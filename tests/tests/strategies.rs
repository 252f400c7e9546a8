//! Light sampling alone, BSDF sampling alone, and their MIS combination estimate the same
//! image: a glossy scene (a Kd + Ks floor, a rough gold sphere, a sharp Kd + Ks sphere, a
//! sphere light) and a scene lit by triangle lights (a two-sided tilted panel, a one-sided
//! panel, an emissive mesh; sampled by solid angle, and by area as a fifth variant) and a scene
//! lit by an environment map (by luminance, and uniformly as a fifth variant) rendered in
//! each mode (`mis = light | bsdf | half` against `power`) agree
//! block by block of 2 x 2 pixels and in the image mean: Welch t-tests on the means of 16
//! independent renders (batch means), since light sampling of a sharp lobe and BSDF sampling
//! of a small light are heavy-tailed, and a render's own sample variance understates them
//! (measured: it made a correct light-only image's mean read z = -3.9). Light sampling weighs f from `bsdf::eval`,
//! BSDF sampling the sampler's weight (f cos / pdf, analytic or computed), so a value, a pdf or
//! a sampler that disagree with each other bias one of them.

use statrs::distribution::{ContinuousCDF, StudentsT};
use twinpath::film::Film;
use twinpath::render::Backend;
use twinpath::scene::environment::EnvironmentMap;
use twinpath::scene::SceneFile;
use twinpath::settings::{LightSampling, Mis};
use twinpath_tests::{render_film, scene_from_toml};

const SPHERE_LIGHT_SCENE: &str = r#"
[camera]
eye = [0.0, 1.2, 3.5]
look_at = [0.0, 0.4, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
width = 32
height = 32

[render]
seed = 5
sampler = "independent"

[materials]
floor = { kd = [0.4, 0.4, 0.4], ks = [0.3, 0.3, 0.3], alpha = 0.3 }
gold = { conductor = "gold", alpha = 0.4 }
sharp = { kd = [0.2, 0.3, 0.5], ks = [0.4, 0.4, 0.4], alpha = 0.1 }
light = { emission = [4.0, 4.0, 4.0] }

[[quad]]
corner = [-3.0, 0.0, 3.0]
edge1 = [6.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -6.0]
material = "floor"

[[sphere]]
center = [-0.6, 0.5, 0.0]
radius = 0.5
material = "gold"

[[sphere]]
center = [0.6, 0.5, 0.0]
radius = 0.5
material = "sharp"

[[sphere]]
center = [0.0, 2.6, 1.5]
radius = 1.0
material = "light"
"#;

const TRIANGLE_LIGHT_SCENE: &str = r#"
[camera]
eye = [0.0, 1.2, 3.5]
look_at = [0.0, 0.4, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0
width = 32
height = 32

[render]
seed = 5
sampler = "independent"

[materials]
floor = { kd = [0.4, 0.4, 0.4], ks = [0.3, 0.3, 0.3], alpha = 0.3 }
gold = { conductor = "gold", alpha = 0.4 }
white = { kd = [0.7, 0.7, 0.7] }
panel = { emission = [3.0, 3.0, 3.0], two_sided = true }
front = { emission = [1.0, 2.0, 4.0] }
mesh = { emission = [0.5, 0.4, 0.1] }

[[quad]]
corner = [-3.0, 0.0, 3.0]
edge1 = [6.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -6.0]
material = "floor"

[[sphere]]
center = [-0.6, 0.5, 0.0]
radius = 0.5
material = "gold"

[[sphere]]
center = [0.6, 0.4, 0.2]
radius = 0.4
material = "white"

[[quad]] # tilted, two-sided: lights the scene with both faces
corner = [-1.2, 1.2, -0.8]
edge1 = [2.4, 0.0, 0.0]
edge2 = [0.0, 0.9, 0.6]
material = "panel"

[[quad]] # one-sided, facing down and toward the camera
corner = [0.4, 1.6, 1.2]
edge1 = [0.0, 0.0, -0.5]
edge2 = [0.5, -0.1, 0.0]
material = "front"

[[mesh]]
file = "meshes/icosphere.obj"
scale = 0.2
translate = [0.0, 0.25, 0.9]
material = "mesh"
"#;

/// Independent renders per mode, and samples per pixel of each.
const BATCHES: u32 = 16;
const SPP: u32 = 512;
/// Blocks of BLOCK x BLOCK pixels of the 32 x 32 image.
const BLOCK: usize = 2;

/// A way to render a scene: MIS mode, and whether points on lights are sampled by area.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Variant {
    mis: Mis,
    area: bool,
}

fn render(text: &str, map: Option<&EnvironmentMap>, v: Variant, batch: u32) -> Film {
    let mut scene: SceneFile = scene_from_toml(text);
    if let Some(m) = map {
        scene.scene.set_environment(Some(m.clone()));
    }
    scene.settings.mis = v.mis;
    if v.area {
        scene.settings.light_sampling = LightSampling::Area;
    }
    scene.settings.seed = 1000 * (v.mis as u32 + 1) + 100 * v.area as u32 + batch;
    // The specialised path and the generic one must agree too: only power runs specialised.
    scene.settings.specialize = v.mis == Mis::Power;
    render_film(&scene, Backend::Cpu, SPP)
}

/// The mean of each channel of each block of `film`, then of the whole image (last).
fn block_means(film: &Film) -> Vec<[f64; 3]> {
    let mean = film.mean();
    let side = 32 / BLOCK;
    let mut out: Vec<[f64; 3]> = (0..side * side)
        .map(|k| {
            let (bx, by) = (k % side, k / side);
            std::array::from_fn(|c| {
                let mut m = 0.0;
                for y in 0..BLOCK {
                    for x in 0..BLOCK {
                        m += mean[(by * BLOCK + y) * 32 + bx * BLOCK + x][c] as f64;
                    }
                }
                m / (BLOCK * BLOCK) as f64
            })
        })
        .collect();
    let n = out.len() as f64;
    out.push(std::array::from_fn(|c| {
        out.iter().map(|b| b[c]).sum::<f64>() / n
    }));
    out
}

/// Welch's t of two samples, with its degrees of freedom (Welch-Satterthwaite); t = 0 when
/// both are constant and equal, infinite when constant and different.
fn welch(a: &[f64], b: &[f64]) -> (f64, f64) {
    let stats = |x: &[f64]| {
        let n = x.len() as f64;
        let m = x.iter().sum::<f64>() / n;
        let v = x.iter().map(|y| (y - m) * (y - m)).sum::<f64>() / (n - 1.0);
        (m, v / n, n)
    };
    let ((ma, va, na), (mb, vb, nb)) = (stats(a), stats(b));
    let v = va + vb;
    if v == 0.0 {
        return (if ma == mb { 0.0 } else { f64::INFINITY }, 1.0);
    }
    let dof = v * v / (va * va / (na - 1.0) + vb * vb / (nb - 1.0));
    ((ma - mb) / v.sqrt(), dof)
}

/// Every variant of `text` agrees with power-heuristic MIS (by solid angle), block by block and
/// in the image mean.
fn variants_agree(label: &str, text: &str, map: Option<&EnvironmentMap>, variants: &[Variant]) {
    let power = Variant {
        mis: Mis::Power,
        area: false,
    };
    let batches = |v: Variant| -> Vec<Vec<[f64; 3]>> {
        (0..BATCHES)
            .map(|b| block_means(&render(text, map, v, b)))
            .collect()
    };
    let reference = batches(power);
    let blocks = reference[0].len() - 1;
    let tests = 3 * variants.len();
    for &v in variants {
        let other = batches(v);
        let mut worst_p = 1f64;
        for k in 0..reference[0].len() {
            for c in 0..3 {
                let a: Vec<f64> = reference.iter().map(|r| r[k][c]).collect();
                let b: Vec<f64> = other.iter().map(|r| r[k][c]).collect();
                let (t, dof) = welch(&a, &b);
                let p = 2.0 * (1.0 - StudentsT::new(0.0, 1.0, dof).unwrap().cdf(t.abs()));
                // Family-wise 1e-3 over the blocks, channels and variants (Bonferroni), and
                // 1e-3 over the images' channels and variants.
                let (what, bound) = if k == blocks {
                    ("image".to_string(), 1e-3 / tests as f64)
                } else {
                    worst_p = worst_p.min(p);
                    (format!("block {k}"), 1e-3 / (tests * blocks) as f64)
                };
                assert!(
                    p > bound,
                    "{label}, {v:?}: {what} channel {c}: {:.5} vs {:.5} (t = {t:.2}, dof {dof:.1}, p = {p:.1e})",
                    b.iter().sum::<f64>() / b.len() as f64,
                    a.iter().sum::<f64>() / a.len() as f64
                );
            }
        }
        let image =
            |x: &Vec<Vec<[f64; 3]>>| x.iter().map(|r| r.last().unwrap()[0]).collect::<Vec<_>>();
        let (t, _) = welch(&image(&reference), &image(&other));
        println!(
            "{label}, {v:?} vs power: smallest p over the blocks {worst_p:.2e} (bound {:.1e}); image mean t = {t:+.2}",
            1e-3 / (tests * blocks) as f64
        );
    }
}

const MODES: [Variant; 3] = [
    Variant {
        mis: Mis::Light,
        area: false,
    },
    Variant {
        mis: Mis::Bsdf,
        area: false,
    },
    Variant {
        mis: Mis::Half,
        area: false,
    },
];

#[test]
fn light_only_bsdf_only_and_mis_agree() {
    variants_agree("sphere light", SPHERE_LIGHT_SCENE, None, &MODES);
}

#[test]
fn light_only_bsdf_only_and_mis_agree_under_triangle_lights() {
    let mut variants = MODES.to_vec();
    variants.push(Variant {
        mis: Mis::Power,
        area: true,
    });
    variants_agree("triangle lights", TRIANGLE_LIGHT_SCENE, None, &variants);
}

/// The glossy scene inside a sphere of absorbing medium (an interface, `interior`: centre
/// 20 behind the scene, radius 23.4, holding the floor's corners and the light, the camera 0.13
/// outside it): next-event estimation attenuates its shadow rays in the medium, BSDF sampling
/// the extension rays that find the light (`kernel::medium`); without the shadow rays'
/// transmittance light sampling reads brighter. The sharp sphere is Lambertian here: its
/// grazing highlight, which BSDF sampling alone finds too rarely for a block's 16 batches (all
/// zero there, whatever the medium), is the plain scene's to test.
#[test]
fn light_only_bsdf_only_and_mis_agree_inside_an_absorbing_medium() {
    let text = SPHERE_LIGHT_SCENE
        .replace(
            "sharp = { kd = [0.2, 0.3, 0.5], ks = [0.4, 0.4, 0.4], alpha = 0.1 }",
            "sharp = { kd = [0.2, 0.3, 0.5] }",
        )
        .replace(
        "[materials]\n",
        "[media]\nmurk = { sigma_a = [0.1, 0.2, 0.4] }\n\n[materials]\nboundary = { interface = true }\n",
    ) + "\n[[sphere]]\ncenter = [0.0, 0.0, -20.0]\nradius = 23.4\nmaterial = \"boundary\"\ninterior = \"murk\"\n";
    variants_agree("absorbing medium", &text, None, &MODES);
}

/// The glossy scene with its sphere light inside a sphere of absorbing medium (an interface of
/// radius 1.4 around it, `interior`): next-event estimation reaches the light through the
/// interface, its shadow segment keeping the transmittance of the part inside
/// (`PathState::shadow_passes`); BSDF sampling reaches it as an extension that passes the
/// interface, weighed against light sampling from the vertex it left. While an interface
/// stopped shadow rays, light sampling alone read black.
#[test]
fn light_only_bsdf_only_and_mis_agree_through_an_interface() {
    let text = SPHERE_LIGHT_SCENE.replace(
        "[materials]\n",
        "[media]\nglow = { sigma_a = [0.2, 0.5, 0.9] }\n\n[materials]\nboundary = { interface = true }\n",
    ) + "\n[[sphere]]\ncenter = [0.0, 2.6, 1.5]\nradius = 1.4\nmaterial = \"boundary\"\ninterior = \"glow\"\n";
    variants_agree("through an interface", &text, None, &MODES);
}

/// The glossy scene filled with a fog that scatters (`[scene] medium`: the camera, the light
/// and every surface in it; chromatic coefficients, forward scattering g = 0.4): next-event
/// estimation from medium vertices (the phase function in the place of f cos) and from
/// surfaces through the fog, against phase and BSDF sampling whose extensions fly until they
/// collide or find the light; the strategies agree only if the phase function's value, its
/// density and its sampler agree, and the shadow segments' transmittance is the extension's
/// expected weight. The sharp sphere is Lambertian, as in the absorbing medium's test.
#[test]
fn light_only_bsdf_only_and_mis_agree_in_a_scattering_fog() {
    let text = SPHERE_LIGHT_SCENE
        .replace(
            "sharp = { kd = [0.2, 0.3, 0.5], ks = [0.4, 0.4, 0.4], alpha = 0.1 }",
            "sharp = { kd = [0.2, 0.3, 0.5] }",
        )
        .replace(
            "[materials]\n",
            "[media]\nfog = { sigma_a = [0.02, 0.03, 0.05], sigma_s = [0.15, 0.2, 0.3], g = 0.4 }\n\n[scene]\nmedium = \"fog\"\n\n[materials]\n",
        );
    assert!(text.contains("medium = \"fog\""));
    variants_agree("scattering fog", &text, None, &MODES);
}

/// The glossy scene without its sphere light, under an environment map with a bright patch (a
/// "sun" of 2 x 1 texels) over a smooth sky: importance sampling by luminance (power MIS)
/// against light-only, BSDF-only, half weights and uniform directions.
#[test]
fn light_only_bsdf_only_and_mis_agree_under_an_environment_map() {
    let (w, h) = (32u32, 16u32);
    let mut map = EnvironmentMap::constant(w, h, [0.0; 3]);
    for j in 0..h {
        for i in 0..w {
            let v = (j as f32 + 0.5) / h as f32;
            let sky = if v < 0.5 { 0.6 - 0.5 * v } else { 0.15 };
            let sun = if (i == 5 || i == 6) && j == 4 {
                60.0
            } else {
                0.0
            };
            map.texels[(j * w + i) as usize] = [sky + sun, sky + 0.9 * sun, 1.2 * sky + 0.7 * sun];
        }
    }
    let text = SPHERE_LIGHT_SCENE.replace("material = \"light\"", "material = \"floor\"");
    let mut variants = MODES.to_vec();
    variants.push(Variant {
        mis: Mis::Power,
        area: true,
    });
    variants_agree("environment map", &text, Some(&map), &variants);
}

/// scenes/textures.toml at 32 x 32: a checkered floor (kd map), a glossy wall whose roughness
/// is a texture, a panel whose emission is a texture (next-event estimation reads it at the
/// sampled point, BSDF sampling where the ray meets the panel), smooth meshes (shading
/// normals). The strategies agree only if both read the same texture values at the same points.
#[test]
fn light_only_bsdf_only_and_mis_agree_with_textures_and_shading_normals() {
    let text = std::fs::read_to_string(twinpath_tests::repo_root().join("scenes/textures.toml"))
        .unwrap()
        .replace("width = 320", "width = 32")
        .replace("height = 240", "height = 32")
        .replace("sampler = ", "# sampler = ")
        .replace("[render]", "[render]\nsampler = \"independent\"");
    let mut variants = MODES.to_vec();
    variants.push(Variant {
        mis: Mis::Power,
        area: true,
    });
    variants_agree("textures and shading normals", &text, None, &variants);
}

/// The glossy scene with glTF's metallic-roughness material on both spheres (a fractional
/// metalness on each, so the dielectric and the metal lobes and the (1 - F) diffuse factor are
/// all sampled) and a bumpy normal map on the floor (a mapped shading normal per point, under
/// which a direction can lie between the two planes): the strategies agree only if the
/// resolved material's value, density and sampler agree with each other under the mapped frame.
#[test]
fn light_only_bsdf_only_and_mis_agree_with_metallic_roughness_and_a_normal_map() {
    let dir = std::env::temp_dir().join(format!("twinpath-strategies-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bumps = dir.join("bumps.png");
    image::RgbImage::from_fn(8, 8, |i, j| {
        let (x, y) = ((i as f32 * 0.8).sin(), (j as f32 * 1.1).cos());
        image::Rgb([(128.0 + 90.0 * x) as u8, (128.0 + 90.0 * y) as u8, 200])
    })
    .save(&bumps)
    .unwrap();
    let text = SPHERE_LIGHT_SCENE
        .replace(
            "floor = { kd = [0.4, 0.4, 0.4], ks = [0.3, 0.3, 0.3], alpha = 0.3 }",
            &format!(
                "floor = {{ kd = [0.4, 0.4, 0.4], ks = [0.3, 0.3, 0.3], alpha = 0.3, normal_map = \"{}\" }}",
                bumps.display()
            ),
        )
        .replace(
            "gold = { conductor = \"gold\", alpha = 0.4 }",
            "gold = { base_color = [0.9, 0.6, 0.3], metallic = 0.6, roughness = 0.6 }",
        )
        .replace(
            "sharp = { kd = [0.2, 0.3, 0.5], ks = [0.4, 0.4, 0.4], alpha = 0.1 }",
            "sharp = { base_color = [0.2, 0.3, 0.5], metallic = 0.3, roughness = 0.35 }",
        );
    assert!(text.contains("normal_map") && text.contains("metallic = 0.3"));
    variants_agree("metallic-roughness and a normal map", &text, None, &MODES);
}
