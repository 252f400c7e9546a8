//! Image textures (`kernel::texture`, `twinpath::scene::textures`):
//!
//! 1. The decoding tables hold the sRGB curve and byte / 255, rounded once from f64.
//! 2. The lookup is bilinear interpolation between texel centres, repeated, clamped or mirrored
//!    along each axis, for 8-bit sRGB, 8-bit linear and float textures in one table (an f64
//!    reference written from the definition, OpenGL's for the wrap modes), and exact at texel
//!    centres. (The GPU computes the same bits: `gpu_functions.rs`, probe `TEXTURE`.)
//! 3. A checkered plane under a sphere light matches the closed form kd(square) L (r/D)^2 cos in
//!    every pixel inside a square, on both backends; the same images against the squares'
//!    colours swapped fail by far (the test's power).
//! 4. A record's coordinate map (glTF's `KHR_texture_transform`) applies before the lookup,
//!    (a u + b v + c, d u + e v + f), and the records of one image share its texels.
//! 5. PNG, JPEG and EXR maps load; scene errors: a texture on a sphere, on a mesh without
//!    texture coordinates, on metal, a missing file, an unknown wrap, maps that would reflect more
//!    than they receive.

use glam::{Vec2, Vec3};
use kernel::texture::{flags, lookup, wrap, LINEAR_TABLE, SRGB_TABLE};
use std::path::{Path, PathBuf};
use twinpath::render::Backend;
use twinpath::scene::textures::{srgb_to_linear, Texels, TextureTable, TextureUse, UvTransform};
use twinpath::scene::{parse_scene, SceneFile};
use twinpath_tests::gpu::assert_validation_clean;
use twinpath_tests::{
    assert_film_matches, max_abs_z, pixel_quadrature, render_film, scene_from_toml,
    with_independent_samples, SplitMix,
};

/// A fresh folder for this test's files.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twinpath-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn decoding_tables_hold_the_srgb_curve_and_linear_bytes() {
    let t = TextureTable::new();
    let value = |base: usize, b: usize| f32::from_bits(t.words[base + b]);
    for b in 0..256 {
        let c = b as f64 / 255.0;
        let srgb = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        assert_eq!(value(SRGB_TABLE, b), srgb as f32, "sRGB byte {b}");
        assert_eq!(value(LINEAR_TABLE, b), c as f32, "linear byte {b}");
    }
    assert_eq!(value(SRGB_TABLE, 0), 0.0);
    assert_eq!(value(SRGB_TABLE, 255), 1.0);
    assert_eq!(t.words[0], 0, "no textures");
}

/// The kernel's reading of texel (x, y) of a texture, from the f64 decoding.
struct Reference {
    width: u32,
    height: u32,
    /// Wrap modes along u and v (`kernel::texture::wrap`).
    wrap: [u32; 2],
    texels: Vec<[f64; 3]>,
}

impl Reference {
    /// Bilinear interpolation between texel centres ((i + 1/2) / w, 1 - (j + 1/2) / h) as OpenGL
    /// 4.6 defines it (section 8.14.2): the texel coordinate from the unreduced coordinate, the
    /// two texel indices around it wrapped: repeat, i mod n; clamp, the coordinate first
    /// clamped to [0, 1] and the indices to 0..n-1; mirrored repeat, i mod 2n folded onto
    /// 0..n-1 (mirror(i) = i for i < n, 2n - 1 - i beyond).
    fn at(&self, uv: Vec2) -> [f64; 3] {
        let unit = |t: f64, mode: u32| {
            if mode == wrap::CLAMP {
                t.clamp(0.0, 1.0)
            } else {
                t
            }
        };
        let (u, v) = (
            unit(uv.x as f64, self.wrap[0]),
            unit(uv.y as f64, self.wrap[1]),
        );
        let index = |i: f64, n: u32, mode: u32| -> usize {
            let n = n as i64;
            let i = i as i64;
            (match mode {
                wrap::CLAMP => i.clamp(0, n - 1),
                wrap::MIRROR => {
                    let j = i.rem_euclid(2 * n);
                    if j < n {
                        j
                    } else {
                        2 * n - 1 - j
                    }
                }
                _ => i.rem_euclid(n),
            }) as usize
        };
        let x = u * self.width as f64 - 0.5;
        let y = (1.0 - v) * self.height as f64 - 0.5;
        let (fx, fy) = (x - x.floor(), y - y.floor());
        let (x0, x1) = (
            index(x.floor(), self.width, self.wrap[0]),
            index(x.floor() + 1.0, self.width, self.wrap[0]),
        );
        let (y0, y1) = (
            index(y.floor(), self.height, self.wrap[1]),
            index(y.floor() + 1.0, self.height, self.wrap[1]),
        );
        let t = |x: usize, y: usize| self.texels[y * self.width as usize + x];
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let top = t(x0, y0)[c] * (1.0 - fx) + t(x1, y0)[c] * fx;
            let bottom = t(x0, y1)[c] * (1.0 - fx) + t(x1, y1)[c] * fx;
            *o = top * (1.0 - fy) + bottom * fy;
        }
        out
    }
}

#[test]
fn lookup_is_bilinear_between_texel_centres_repeated_clamped_or_mirrored() {
    let mut g = SplitMix(0x7e47);
    let mut table = TextureTable::new();
    let mut refs = Vec::new();
    // 8-bit textures (sRGB and linear, repeat and clamp) and float textures, odd sizes, all in
    // one table: each later push moves the earlier records' texels.
    for (k, (width, height)) in [
        (5u32, 3u32),
        (1, 1),
        (7, 2),
        (4, 6),
        (3, 5),
        (2, 2),
        (6, 1),
        (1, 4),
        (3, 3),
    ]
    .into_iter()
    .enumerate()
    {
        let (float, srgb) = (k % 3 == 2, k % 2 == 0);
        // Every pair of modes along u and v appears once among the nine textures.
        let modes = [wrap::REPEAT, wrap::CLAMP, wrap::MIRROR];
        let mode = [modes[k % 3], modes[(k / 3) % 3]];
        let n = (width * height) as usize;
        let (words, texels): (Vec<u32>, Vec<[f64; 3]>) = if float {
            let t: Vec<[f32; 3]> = (0..n).map(|_| [0; 3].map(|_| 4.0 * g.unit())).collect();
            (
                t.iter().flat_map(|c| c.map(f32::to_bits)).collect(),
                t.iter().map(|c| c.map(f64::from)).collect(),
            )
        } else {
            let bytes: Vec<[u8; 4]> = (0..n).map(|_| (g.u64() as u32).to_le_bytes()).collect();
            let decode = |b: u8| {
                if srgb {
                    srgb_to_linear(b) as f32 as f64
                } else {
                    (b as f64 / 255.0) as f32 as f64
                }
            };
            (
                bytes.iter().map(|b| u32::from_le_bytes(*b)).collect(),
                bytes
                    .iter()
                    .map(|b| [decode(b[0]), decode(b[1]), decode(b[2])])
                    .collect(),
            )
        };
        let mut tex_flags = 0;
        if float {
            tex_flags |= flags::FLOAT;
        } else if srgb {
            tex_flags |= flags::SRGB;
        }
        tex_flags |= flags::wrap(mode[0], mode[1]);
        let usage = TextureUse {
            colour: srgb,
            wrap: mode,
            transform: None,
            second_set: false,
        };
        table.push(
            Path::new("generated"),
            usage,
            tex_flags,
            width,
            height,
            Texels::Own(&words),
        );
        refs.push(Reference {
            width,
            height,
            wrap: mode,
            texels,
        });
    }
    assert_eq!(table.words[0], refs.len() as u32);
    let mut worst = 0f64;
    for (k, r) in refs.iter().enumerate() {
        for _ in 0..20_000 {
            let uv = Vec2::new(g.unit() * 5.0 - 2.0, g.unit() * 5.0 - 2.0);
            let got = lookup(&table.words, k as u32, uv);
            let want = r.at(uv);
            for c in 0..3 {
                let d = (got[c] as f64 - want[c]).abs();
                worst = worst.max(d / want[c].abs().max(1.0));
                assert!(
                    d <= 4e-6 * want[c].abs().max(1.0),
                    "texture {k} at {uv}: channel {c} {} vs {}",
                    got[c],
                    want[c]
                );
            }
        }
        // Texel centres give the texel; repeating, u + 1 reads as u.
        for j in 0..r.height {
            for i in 0..r.width {
                let uv = Vec2::new(
                    (i as f32 + 0.5) / r.width as f32,
                    1.0 - (j as f32 + 0.5) / r.height as f32,
                );
                let got = lookup(&table.words, k as u32, uv);
                let want = r.texels[(j * r.width + i) as usize];
                for c in 0..3 {
                    assert!((got[c] as f64 - want[c]).abs() <= 1e-6 * want[c].max(1.0));
                }
                // Repeating, u + 1 reads as u; mirrored, u + 2 does, and -u mirrors u (the
                // texel's centre maps onto itself). (u + 1 rounds u to fewer bits: a texel's
                // value times 2^-23 times the texture's width, at most.)
                let same =
                    |a: Vec3, b: Vec3| (0..3).all(|c| (a[c] - b[c]).abs() <= 1e-5 * b[c].max(1.0));
                let at = |p: Vec2| lookup(&table.words, k as u32, p);
                if r.wrap == [wrap::REPEAT; 2] {
                    assert!(same(at(uv + Vec2::new(1.0, -2.0)), got));
                }
                if r.wrap == [wrap::MIRROR; 2] {
                    assert!(same(at(uv + Vec2::new(2.0, -4.0)), got));
                    assert!(same(at(Vec2::new(-uv.x, 2.0 - uv.y)), got));
                }
            }
        }
        // Far outside and non-finite coordinates stay in range.
        for uv in [
            Vec2::new(1e30, -1e30),
            Vec2::new(f32::NAN, 0.5),
            Vec2::new(f32::INFINITY, f32::NEG_INFINITY),
        ] {
            assert!(lookup(&table.words, k as u32, uv).is_finite());
        }
    }
    println!("lookup vs f64 bilinear reference: worst relative difference {worst:.2e}");
}

/// Side of the checker texture in texels, and of one square.
const TEXELS: u32 = 32;
const SQUARE: u32 = 4;
/// The two squares' sRGB bytes (grey) and the material's kd factor.
const LIGHT_BYTE: u8 = 230;
const DARK_BYTE: u8 = 60;
const KD_FACTOR: f64 = 0.9;
/// The plane: a 4 x 4 quad centred at the origin, the texture once across it.
const HALF: f32 = 2.0;
/// The sphere light: centre height, radius, radiance.
const LAMP_H: f32 = 2.0;
const LAMP_R: f32 = 0.3;
const LAMP_L: f32 = 8.0;

/// Writes the checker (squares of SQUARE texels; the top-left one light) and returns its path.
fn checker_png(dir: &Path) -> PathBuf {
    let path = dir.join("checker.png");
    let img = image::RgbImage::from_fn(TEXELS, TEXELS, |i, j| {
        let b = if (i / SQUARE + j / SQUARE).is_multiple_of(2) {
            LIGHT_BYTE
        } else {
            DARK_BYTE
        };
        image::Rgb([b, b, b])
    });
    img.save(&path).unwrap();
    path
}

fn checker_scene(png: &Path) -> SceneFile {
    let text = format!(
        r#"
        [camera]
        eye = [0.0, 4.0, 3.0]
        look_at = [0.0, 0.0, 0.0]
        up = [0.0, 1.0, 0.0]
        vfov = 50.0
        width = 48
        height = 48
        [render]
        seed = 21
        [materials]
        floor = {{ kd = [{KD_FACTOR}, {KD_FACTOR}, {KD_FACTOR}], kd_map = "{}" }}
        lamp = {{ emission = [{LAMP_L}, {LAMP_L}, {LAMP_L}] }}
        [[quad]]
        corner = [-{HALF}, 0.0, {HALF}]
        edge1 = [{w}, 0.0, 0.0]
        edge2 = [0.0, 0.0, -{w}]
        material = "floor"
        [[sphere]]
        center = [0.0, {LAMP_H}, 0.0]
        radius = {LAMP_R}
        material = "lamp"
        "#,
        png.display(),
        w = 2.0 * HALF,
    );
    with_independent_samples(scene_from_toml(&text))
}

/// Exact pixel values: kd(square) L (r/D)^2 cos at each of 16 x 16 quadrature points of the
/// pixel, averaged; `None` where a point sees the lamp, leaves the quad, or lies within 0.6
/// texel of a square's edge (where bilinear filtering blends the two colours). `swap` exchanges
/// the squares' colours.
fn checker_exact(scene: &SceneFile, swap: bool) -> Vec<Option<f64>> {
    let lamp = Vec3::new(0.0, LAMP_H, 0.0);
    let kd = |b: u8| KD_FACTOR * srgb_to_linear(b) as f32 as f64;
    pixel_quadrature(&scene.scene, 16, |eye, d| {
        if d.y >= 0.0
            || kernel::geometry::intersect_sphere(eye, d, lamp, LAMP_R, 0.0, f32::INFINITY) >= 0.0
        {
            return None;
        }
        let x = (eye + d * (-eye.y / d.y)).as_dvec3();
        // Texture coordinates of the quad: u along +x, v along -z.
        let (tu, tv) = (
            (x.x + HALF as f64) / (2.0 * HALF as f64),
            (HALF as f64 - x.z) / (2.0 * HALF as f64),
        );
        if !(0.0..1.0).contains(&tu) || !(0.0..1.0).contains(&tv) {
            return None;
        }
        let (tx, ty) = (tu * TEXELS as f64, (1.0 - tv) * TEXELS as f64);
        let margin = |t: f64| {
            let r = t.rem_euclid(SQUARE as f64);
            (0.6..SQUARE as f64 - 0.6).contains(&r)
        };
        if !margin(tx) || !margin(ty) {
            return None;
        }
        let square = (tx as u32 / SQUARE + ty as u32 / SQUARE).is_multiple_of(2);
        let k = if square != swap {
            kd(LIGHT_BYTE)
        } else {
            kd(DARK_BYTE)
        };
        let to = lamp.as_dvec3() - x;
        let dist = to.length();
        Some(k * LAMP_L as f64 * (LAMP_R as f64 / dist).powi(2) * (to.y / dist))
    })
}

#[test]
fn checkered_plane_matches_the_closed_form_on_both_backends() {
    let dir = temp_dir("checker");
    let scene = checker_scene(&checker_png(&dir));
    let exact = checker_exact(&scene, false);
    let swapped = checker_exact(&scene, true);
    let tested = exact.iter().filter(|e| e.is_some()).count();
    assert!(tested > 300, "only {tested} pixels inside squares");
    for (backend, spp) in [(Backend::Cpu, 256), (Backend::Gpu, 64)] {
        let film = render_film(&scene, backend, spp);
        assert_film_matches(&film, &exact, &format!("checker, {backend:?}"));
        // Power: the squares' colours swapped are rejected by far.
        let mean = film.mean();
        let var = film.variance_of_mean();
        let worst = max_abs_z(&mean, &var, &swapped);
        println!("checker, {backend:?}: squares swapped: max |z| {worst:.0}");
        assert!(
            worst > 20.0,
            "swapped colours not rejected: max |z| {worst}"
        );
    }
    assert_validation_clean();
}

/// A scene text with a textured material `m` on `shape`, or the error parsing it gives.
fn scene_error(materials: &str, shapes: &str) -> String {
    let dir = temp_dir("texture-errors");
    checker_png(&dir);
    image::Rgb32FImage::from_pixel(2, 2, image::Rgb([2.0, 2.0, 2.0]))
        .save(dir.join("bright.exr"))
        .unwrap();
    image::open(dir.join("checker.png"))
        .unwrap()
        .to_rgb8()
        .save(dir.join("checker.jpg"))
        .unwrap();
    let text = format!(
        "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n[materials]\n{materials}\n{shapes}"
    );
    match parse_scene(&text, &dir.join("scene.toml")) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

#[test]
fn texture_errors_name_the_field_and_the_reason() {
    let quad =
        "[[quad]]\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, -1]\nmaterial = \"m\"";
    let sphere = "[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"";
    let flat_mesh = format!(
        "[[mesh]]\nfile = \"{}\"\nmaterial = \"m\"",
        twinpath_tests::repo_root()
            .join("scenes/meshes/icosphere.obj")
            .display()
    );
    let cases: [(&str, &str, &str); 10] = [
        ("m = { kd_map = \"checker.png\" }", quad, ""),
        (
            "m = { kd_map = \"checker.jpg\", wrap = \"clamp\" }",
            quad,
            "",
        ),
        (
            "m = { kd_map = \"checker.jpg\", wrap = \"mirror\" }",
            quad,
            "",
        ),
        (
            "m = { emission_map = \"bright.exr\", two_sided = true }",
            quad,
            "",
        ),
        (
            "m = { kd_map = \"checker.png\" }",
            sphere,
            "spheres have no texture coordinates",
        ),
        (
            "m = { kd_map = \"checker.png\" }",
            &flat_mesh,
            "has no texture coordinates",
        ),
        (
            "m = { kd_map = \"missing.png\" }",
            quad,
            "materials.m.kd_map",
        ),
        (
            "m = { kd_map = \"checker.png\", wrap = \"wobble\" }",
            quad,
            "unknown wrap 'wobble' (expected repeat, clamp or mirror)",
        ),
        (
            "m = { kd = [0.6, 0.6, 0.6], kd_map = \"bright.exr\" }",
            quad,
            "would reflect more than it receives",
        ),
        (
            "m = { conductor = \"gold\", kd_map = \"checker.png\" }",
            quad,
            "textures apply to diffuse",
        ),
    ];
    for (materials, shape, want) in cases {
        let got = scene_error(materials, shape);
        println!("{materials}: {got}");
        if want.is_empty() {
            assert!(got.is_empty(), "{materials}: unexpected error {got}");
        } else {
            assert!(
                got.contains(want),
                "{materials}: error '{got}' lacks '{want}'"
            );
        }
    }
}

/// The memory report counts every table, the texture table by its words, and lists each
/// texture once (two materials sharing a file as the same use share its texels).
#[test]
fn memory_report_lists_tables_and_textures() {
    let scene = SceneFile::load(&twinpath_tests::repo_root().join("scenes/textures.toml")).unwrap();
    let bytes: std::collections::BTreeMap<_, _> = scene.scene.table_bytes().into_iter().collect();
    assert_eq!(bytes["textures"], 4 * scene.scene.textures.words.len());
    assert_eq!(bytes["shading"], 64 * scene.scene.shading.len());
    let report = scene.scene.memory_report();
    println!("{report}");
    assert!(
        report.contains("3 textures (64x64, 32x16, 64x64)"),
        "{report}"
    );

    let dir = temp_dir("texture-sharing");
    let png = checker_png(&dir);
    let text = format!(
        "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n\
         [materials]\na = {{ kd_map = \"{p}\" }}\nb = {{ kd = [0.5, 0.5, 0.5], kd_map = \"{p}\" }}\n\
         c = {{ emission_map = \"{p}\" }}\nd = {{ kd_map = \"{p}\", wrap = \"clamp\" }}\n",
        p = png.display()
    );
    let scene = parse_scene(&text, &dir.join("scene.toml")).unwrap();
    // a, b and c read it as colour and repeat; d clamps: two records.
    assert_eq!(scene.scene.textures.textures.len(), 2);
}

#[test]
fn a_coordinate_map_applies_before_the_lookup_and_shares_the_texels() {
    let mut g = SplitMix(0x7e48);
    let bytes: Vec<u8> = (0..5 * 3 * 4).map(|_| g.u64() as u8).collect();
    let image = image::DynamicImage::ImageRgba8(image::RgbaImage::from_raw(5, 3, bytes).unwrap());
    let path = Path::new("generated.png");
    let usage = |transform| TextureUse {
        colour: true,
        wrap: [wrap::REPEAT, wrap::MIRROR],
        transform,
        second_set: false,
    };
    let mut table = TextureTable::new();
    let plain = table
        .add_image(path, image.clone(), usage(None), "map")
        .unwrap();
    let size = table.words.len();
    let map = [0.8f32, -1.2, 0.3, 0.6, 0.4, -0.7];
    let mapped = table
        .add_image(path, image, usage(Some(UvTransform(map))), "map")
        .unwrap();
    assert_ne!(plain, mapped);
    assert_eq!(
        table.words.len(),
        size + kernel::texture::RECORD_WORDS,
        "a second record, no second copy of the texels"
    );
    assert!(table.textures[mapped as usize].flags & flags::TRANSFORM != 0);
    assert!(table.textures[plain as usize].flags & flags::TRANSFORM == 0);
    for _ in 0..10_000 {
        let uv = Vec2::new(g.unit() * 6.0 - 3.0, g.unit() * 6.0 - 3.0);
        let moved = Vec2::new(
            map[0] * uv.x + map[1] * uv.y + map[2],
            map[3] * uv.x + map[4] * uv.y + map[5],
        );
        assert_eq!(
            lookup(&table.words, mapped, uv),
            lookup(&table.words, plain, moved),
            "at {uv}"
        );
    }
}
