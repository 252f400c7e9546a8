//! Kernel functions evaluated record by record, for the CPU-vs-GPU equivalence tests: the
//! compute entry point `shaders::probe` and the native tests call this same [`evaluate`].
//! Records are four `[u32; 4]` in, two out; floats travel as their bits, so no load or store
//! on either side can touch a value (denormals, NaN payloads) before the function sees it.

use crate::bsdf;
use crate::bsdf::fresnel::{conductor, dielectric, schlick};
use crate::bsdf::inputs::BsdfInputs;
use crate::bsdf::lambert::{eval_scattering, pdf_brdf, sample_brdf};
use crate::bsdf::microfacet::{ggx_d, ggx_g1, pdf_reflected, sample_visible_normal};
use crate::bsdf::multiple_scattering::GlossyAlbedo;
use crate::camera::camera_ray_direction;
use crate::environment::{direction_in_texel, map_coordinates, texel_of, DrawnTexel, MapShape};
use crate::features::Dynamic;
use crate::frame::orthonormal_basis;
use crate::free_flight;
use crate::geometry::{
    geometry_factor, intersect_sphere, intersect_triangle_uv, offset_ray_origin,
    reproject_to_sphere, shadow_ray_end, triangle_point, triangle_point_error,
};
use crate::light::{directional, punctual, triangle};
use crate::phase;
use crate::plane_side::ray_leaves_triangle_plane;
use crate::real::{self, V3};
use crate::rng::{pcg4d, u32_to_unit_f32};
use crate::sampling::{sample_lobe, sample_sphere, sample_sphere_cone};
use crate::scene::{light_kind, Camera, Light, Material, ShadingTriangle};
use crate::sobol::{sobol_pair, sobol_single};
use crate::spherical_triangle;
use crate::surface::mapped_normal;
use crate::texture::{bilerp, footprint};
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::{UVec4, Vec2, Vec3, Vec4};

/// Which function a probe record evaluates (input layout -> output layout).
pub mod function {
    /// a = in0.xyz, c = in1.x, phi = in1.y -> out0.xyz = sample_lobe(a, c, phi)
    pub const SAMPLE_LOBE: u32 = 0;
    /// n = in0.xyz -> out0.xyz, out1.xyz = orthonormal_basis(n)
    pub const ORTHONORMAL_BASIS: u32 = 1;
    /// c = in0.xyz, r = in0.w, u = in1.xy -> out0.xyz position, out1.xyz normal
    pub const SAMPLE_SPHERE: u32 = 2;
    /// c = in0.xyz, r = in0.w, p = in1.xyz, u = in2.xy -> out0.xyz position, out0.w pdf,
    /// out1.xyz normal
    pub const SAMPLE_SPHERE_CONE: u32 = 3;
    /// p_a, n_a, p_b, n_b = in0..in3 .xyz -> out0.x
    pub const GEOMETRY_FACTOR: u32 = 4;
    /// o = in0.xyz, d = in1.xyz, c = in2.xyz, r = in2.w, t_min = in3.x, t_max = in3.y
    /// -> out0.x = t, out1.xyz = the hit re-projected onto the sphere (when t >= 0)
    pub const INTERSECT_SPHERE: u32 = 5;
    /// o = in0.xyz, t_max = in0.w, d = in1.xyz, p0 = in2.xyz, e1 = in3.xyz,
    /// e2 = (in1.w, in2.w, in3.w) -> out0 = (t, u, v, triangle point error),
    /// out1.xyz = triangle_point(p0, e1, e2, u, v) (when t >= 0)
    pub const INTERSECT_TRIANGLE: u32 = 6;
    /// p = in0.xyz, n = in1.xyz, error = in1.w, target = in2.xyz, target normal = in3.xyz,
    /// target error = in3.w -> out0.xyz = offset_ray_origin(p, n, error),
    /// out1.xyz = shadow_ray_end(p, target, target normal, target error)
    pub const OFFSET_RAY_ORIGIN: u32 = 7;
    /// n = in0.xyz, w = in1.xyz, albedo = in2.xyz, u = in3.xy -> out0.xyz eval_scattering,
    /// out0.w pdf_brdf(n, w), out1.xyz sample_brdf(n, u), out1.w its pdf
    pub const BRDF: u32 = 8;
    /// in0 as four u32 -> out0 = pcg4d(in0), out1.x = u32_to_unit_f32(in0.x);
    /// (pixel, sample, dimension, seed) = in0 -> out1.yz = sobol_pair, out1.w = sobol_single
    pub const RNG: u32 = 9;
    /// forward = in0.xyz, right = in1.xyz, up = in2.xyz, (u, v) = in3.xy,
    /// (width, height, px, py) = (in0.w, in1.w, in2.w, in3.z) as u32 -> out0.xyz direction
    pub const CAMERA_RAY: u32 = 10;
    /// cos = in0.x, eta = in0.y, k = in0.z, f0 = in1.xyz -> out0 = (fresnel::conductor,
    /// fresnel::dielectric's F and cos_t, schlick.x), out1.xy = schlick.yz
    pub const FRESNEL: u32 = 11;
    /// n = in0.xyz, alpha = in0.w, wo = in1.xyz, cos = in1.w, u = in2.xy, sin^2 = in2.z ->
    /// out0.xyz = sample_visible_normal(n, wo, alpha, u), out0.w = ggx_d(cos, sin^2, alpha),
    /// out1.x = ggx_g1(cos, alpha), out1.y = pdf_reflected(n . wo, (cos, sin^2), alpha)
    pub const MICROFACET: u32 = 12;
    /// n = in0.xyz, alpha = in0.w, wo = in1.xyz, eta = in1.w, wi = in2.xyz, the packed clear
    /// coat = in2.w as u32, material kind and complex flag = in3.xy as u32
    /// ([`probe_bsdf_inputs`]), GGX albedo (E, E_avg) = in3.zw ([`probe_glossy_albedo`]) ->
    /// out0 = (bsdf::eval's f cos, pdf)
    pub const BSDF_EVAL: u32 = 13;
    /// As [`BSDF_EVAL`] with (u_lobe, u1, u2) = in2.xyz -> bsdf::sample's out0 = (wi, pdf),
    /// out1 = (weight, eta2)
    pub const BSDF_SAMPLE: u32 = 14;
    /// x = in0.xyz, mode = in0.w as u32 (`scene::light_sampling`), p0 = in1.xyz, u1 = in1.w,
    /// e1 = in2.xyz, u2 = in2.w, e2 = in3.xyz, two-sided = in3.w as u32 ->
    /// out0 = light::triangle::sample's (position, pdf) for [`probe_triangle_light`],
    /// out1 = (its normal, spherical_triangle::solid_angle(x, vertices))
    pub const TRIANGLE_LIGHT: u32 = 15;
    /// uv = in0.xy, (width, height) = in0.zw as u32, wrap modes (u, v) = in1.xy as u32, an
    /// image keyed by in2.xy as u32 (texel (x, y) the RGBA8 word pcg4d(key x, x, y, key y),
    /// read as byte / 256: a value per texel, so that a device taking the neighbouring pair of
    /// texels at a boundary blends the same image) -> out0 = texture::footprint's (x0, x1, y0,
    /// y1) as u32, out1 = (texture::bilerp of the four texels, fx)
    pub const TEXTURE: u32 = 16;
    /// base normal = in0.xyz, scale = in0.w, tangent (at all three vertices) = in1.xyz,
    /// sign = in1.w, texel = in2.xyz, barycentrics = (in2.w, in3.x) -> out0.xyz =
    /// surface::mapped_normal
    pub const MAPPED_NORMAL: u32 = 17;
    /// wo = in0.xyz, g = in0.w, wi = in1.xyz, u1 = in1.w, sigma_t = in2.xyz, u2 = in2.w,
    /// sigma_s = in3.xyz, d = in3.w -> out0 = (phase::sample(g, wo, u1, u2),
    /// phase::eval(g, wo, wi)), out1 = free_flight::sample(sigma_t, sigma_s, d,
    /// hero_channel(u1), u2, (1, 1, 1))'s (t, weight)
    pub const MEDIUM: u32 = 18;
    /// receiver x = in0.xyz, selection probability = in0.w, position = in1.xyz, spot scale =
    /// in1.w, axis (and a directional light's direction of travel) = in2.xyz, spot offset =
    /// in2.w, the scene's bounding sphere (centre, radius) = in3 ([`probe_punctual_light`]) ->
    /// out0 = light::punctual::sample's (normal, pdf), out1 = (its spot_attenuation,
    /// light::directional::sample's position)
    pub const PUNCTUAL_LIGHT: u32 = 19;
    /// map rotation (cos, sin) = in0.xy, (u1, u2) = in0.zw, the drawn row's marginal CDF
    /// (r0, r1) = in1.xy and column's conditional CDF (c0, c1) = in1.zw, a unit direction d =
    /// in2.xyz; as integers, (width, height, row, column) = in3 ([`probe_environment`]) ->
    /// out0 = environment::direction_in_texel's (direction, pdf), out1 =
    /// environment::map_coordinates(d)'s (u, v, sin theta) and its texel (column, row) as
    /// column + width row
    pub const ENVIRONMENT: u32 = 20;
    /// o = in0.xyz, d = in1.xyz, p0 = in2.xyz, e1 = in3.xyz, e2 = (in0.w, in1.w, in2.w) ->
    /// out0.x = 1 where `plane_side::ray_leaves_triangle_plane(o, d, p0, e1, e2)`, else 0
    pub const PLANE_SIDE: u32 = 21;
    pub const COUNT: u32 = 22;
}

#[inline]
fn f(v: UVec4) -> Vec4 {
    Vec4::new(
        f32::from_bits(v.x),
        f32::from_bits(v.y),
        f32::from_bits(v.z),
        f32::from_bits(v.w),
    )
}

#[inline]
fn bits(v: Vec4) -> UVec4 {
    UVec4::new(v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), v.w.to_bits())
}

#[inline]
fn v3(v: Vec3) -> Vec4 {
    v.extend(0.0)
}

/// The material of the BSDF probes: kind `kind` with roughness `alpha` and, for a dielectric,
/// index `eta`; Kd (0.5, 0.4, 0.3) and Ks (0.2, 0.3, 0.4) for the Kd + Ks mixture; gold's RGB
/// index (`complex` bit 0) or reflectance (0.9, 0.8, 0.7) for a conductor; for glTF's
/// metallic-roughness material base colour (0.5, 0.4, 0.3), metallic 0.3 with a coloured,
/// weakened dielectric layer (`complex` bit 0 clear; `KHR_materials_specular`) or 0.9 with the
/// default one, roughness sqrt(alpha), with a clear coat of weight 0.8 and the same roughness
/// where bit 1 is set, resolved as `surface::shade` resolves it.
#[inline]
pub fn probe_material(kind: u32, complex: u32, alpha: f32, eta: f32) -> Material {
    let coat = Material::pack_coat(0.8, alpha.sqrt());
    let m = unresolved_probe_material(kind, complex, alpha, eta, coat);
    if kind == crate::scene::material_kind::METALLIC_ROUGHNESS {
        crate::bsdf::metallic_roughness::resolve(&m)
    } else {
        m
    }
}

/// [`probe_material`]'s scattering numbers over any scalar [`real::Real`], as the BSDF probes read
/// them: the clear coat's packed word `coat` given (the records carry it, so that no device
/// rounding of its roughness can move its 16-bit quantisation), glTF's material resolved over
/// `R` from the roughness sqrt(alpha) computed over `R` (what a device computes before the
/// scattering: `tests/src/device_class.rs` bounds it with the rest).
#[inline]
pub fn probe_bsdf_inputs<R: real::Real>(
    kind: u32,
    complex: u32,
    alpha: f32,
    eta: f32,
    coat: u32,
) -> BsdfInputs<R> {
    let m = unresolved_probe_material(kind, complex, alpha, eta, coat);
    if kind == crate::scene::material_kind::METALLIC_ROUGHNESS {
        crate::bsdf::metallic_roughness::resolve_v3(&m, R::splat(alpha).sqrt())
    } else {
        BsdfInputs::of(&m)
    }
}

/// The GGX albedos the BSDF probes pass `bsdf::eval` and `bsdf::sample`, over any scalar
/// [`real::Real`], from the record's (E, E_avg) = (`e`, `e_avg`): the coat's the material's (the
/// probe's coat has its roughness), its reflectance 0.05 + 0.5 (1 - E_avg), and a sheen lobe
/// (A, B, R) = (0.2 + 0.7 E_avg, -0.15 E, 0.05 + 0.6 (1 - E)) in the table's range.
#[inline]
pub fn probe_glossy_albedo<R: real::Real>(e: f32, e_avg: f32) -> GlossyAlbedo<R> {
    let c = R::splat;
    let (e, e_avg, one) = (c(e), c(e_avg), c(1.0));
    GlossyAlbedo {
        directional: e,
        average: e_avg,
        coat_directional: e,
        coat_average: e_avg,
        coat_reflectance: c(0.05) + c(0.5) * (one - e_avg),
        sheen: V3::new(
            c(0.2) + c(0.7) * e_avg,
            c(-0.15) * e,
            c(0.05) + c(0.6) * (one - e),
        ),
    }
}

/// [`probe_material`] before glTF's material is resolved, its clear coat the packed `coat`.
#[inline]
fn unresolved_probe_material(kind: u32, complex: u32, alpha: f32, eta: f32, coat: u32) -> Material {
    let mut m = Material::diffuse([0.5, 0.4, 0.3]);
    m.kind = kind;
    m.alpha = alpha;
    m.ior = eta;
    // Gold's index where `complex`, else none (the constant reflectance).
    m.eta = if complex & 1 != 0 {
        [0.143036, 0.375307, 1.44205]
    } else {
        [0.0; 3]
    };
    m.k = [3.983, 2.38556, 1.60336];
    m.specular = if complex & 1 != 0 || kind != crate::scene::material_kind::CONDUCTOR {
        [0.2, 0.3, 0.4]
    } else {
        [0.9, 0.8, 0.7]
    };
    if kind == crate::scene::material_kind::METALLIC_ROUGHNESS {
        m.specular = [0.0; 3];
        m.metallic = if complex & 1 != 0 { 0.9 } else { 0.3 };
        m.roughness = alpha.sqrt();
        if complex & 1 == 0 {
            // A coloured, weakened layer (KHR_materials_specular, KHR_materials_ior).
            m.layer_f0 = [0.06, 0.02, 0.1];
            m.layer_f90 = 0.7;
        }
        if complex & 2 != 0 {
            // A clear coat (KHR_materials_clearcoat) of weight 0.8, rough or smooth with the
            // material.
            m.coat = coat;
        }
        // Gold's index is a conductor's: no sheen, unless `complex` asks for one
        // (KHR_materials_sheen), orange (its roughness is not read: the record gives the lobe).
        m.set_sheen([0.0; 3], 0.0);
        if complex & 4 != 0 {
            m.set_sheen([0.9, 0.6, 0.3], 0.2 + 0.8 * alpha.sqrt());
        }
    }
    m
}

/// The light of the triangle-light probe: triangle p0, p0 + e1, p0 + e2 chosen with
/// probability 1, its area in f32, radiance 1.
#[inline]
pub fn probe_triangle_light(p0: Vec3, e1: Vec3, e2: Vec3, two_sided: u32) -> Light {
    let mut l = probe_light(light_kind::TRIANGLE, p0, e1, e2);
    l.two_sided = two_sided;
    l.area = 0.5 * e1.cross(e2).length();
    l
}

/// The punctual-light probe's spot light: at `position`, chosen with probability
/// `select_pmf`, its axis `axis` with (scale, offset) `spot` (`light::punctual`).
#[inline]
pub fn probe_punctual_light(
    position: Vec3,
    select_pmf: f32,
    axis: Vec3,
    spot: (f32, f32),
) -> Light {
    let mut l = probe_light(
        light_kind::PUNCTUAL,
        position,
        axis,
        Vec3::new(spot.0, spot.1, 0.0),
    );
    l.select_pmf = select_pmf;
    l
}

/// The punctual-light probe's directional light: travelling along `travel`, placed beyond the
/// scene's bounding sphere `bounds` (centre, radius) (`light::directional`).
#[inline]
pub fn probe_directional_light(travel: Vec3, bounds: Vec4) -> Light {
    let mut l = probe_light(
        light_kind::DIRECTIONAL,
        bounds.truncate(),
        travel,
        Vec3::ZERO,
    );
    l.radius = bounds.w;
    l
}

/// A probe's light of kind `kind` with `position`, `edge1` and `edge2` (what each kind reads
/// them as: `scene::Light`), one-sided, radiance 1, chosen with probability 1; no area, radius,
/// texture or material.
#[inline]
fn probe_light(kind: u32, position: Vec3, edge1: Vec3, edge2: Vec3) -> Light {
    Light {
        position: position.to_array(),
        radius: 0.0,
        edge1: edge1.to_array(),
        kind,
        edge2: edge2.to_array(),
        two_sided: 0,
        radiance: [1.0; 3],
        select_pmf: 1.0,
        alias_threshold: 1.0,
        alias: 0,
        area: 0.0,
        point_error: 0.0,
        uv: [0.0; 6],
        emission_texture: crate::scene::NONE,
        material: crate::scene::NONE,
    }
}

/// Texel (x, y) of the texture probe's image keyed by (`a`, `b`): the word pcg4d(a, x, y, b)'s
/// red, green and blue as byte / 256 (exact in f32), the probe's stand-in for a texture and
/// its decoding tables.
#[inline]
pub fn probe_image(a: u32, b: u32, x: u32, y: u32) -> Vec3 {
    let word = crate::hash::pcg4d([a, x, y, b])[0];
    let c = |shift: u32| ((word >> shift) & 0xff) as f32 * (1.0 / 256.0);
    Vec3::new(c(0), c(8), c(16))
}

/// The environment probe's outputs ([`function::ENVIRONMENT`]) over any scalar [`real::Real`]:
/// the direction and density drawn in texel `drawn` of map `map`, and unit direction `d`'s map
/// coordinates (u, v, sin theta) with its texel as column + width row. One function for the
/// shader, the CPU and the tests' balls, so that all three compute the same operations.
#[inline]
pub fn probe_environment<R: real::Real<Bits = u32>>(
    map: MapShape<R>,
    drawn: DrawnTexel<R>,
    d: V3<R>,
) -> [R; 8] {
    let (direction, pdf) = direction_in_texel(map, drawn);
    let (u, v, sin_theta) = map_coordinates(map.rotation, d);
    let (i, j) = texel_of(map.width, map.height, u, v);
    [
        direction.x,
        direction.y,
        direction.z,
        pdf,
        u,
        v,
        sin_theta,
        R::splat((i + map.width * j) as f32),
    ]
}

/// Evaluates `function` on one input record; see [`function`] for the layouts.
#[inline]
pub fn evaluate(function: u32, input: [UVec4; 4]) -> [UVec4; 2] {
    let i0 = f(input[0]);
    let i1 = f(input[1]);
    let i2 = f(input[2]);
    let i3 = f(input[3]);
    let (o0, o1) = if function == function::SAMPLE_LOBE {
        (v3(sample_lobe(i0.truncate(), i1.x, i1.y)), Vec4::ZERO)
    } else if function == function::ORTHONORMAL_BASIS {
        let (t, b) = orthonormal_basis(i0.truncate());
        (v3(t), v3(b))
    } else if function == function::SAMPLE_SPHERE {
        let s = sample_sphere(i0.truncate(), i0.w, i1.x, i1.y);
        (v3(s.position), v3(s.normal))
    } else if function == function::SAMPLE_SPHERE_CONE {
        let s = sample_sphere_cone(i0.truncate(), i0.w, i1.truncate(), i2.x, i2.y);
        (
            s.point.position.extend(s.pdf_solid_angle),
            v3(s.point.normal),
        )
    } else if function == function::GEOMETRY_FACTOR {
        let g = geometry_factor(i0.truncate(), i1.truncate(), i2.truncate(), i3.truncate());
        (Vec4::new(g, 0.0, 0.0, 0.0), Vec4::ZERO)
    } else if function == function::INTERSECT_SPHERE {
        let (o, d, c) = (i0.truncate(), i1.truncate(), i2.truncate());
        let t = intersect_sphere(o, d, c, i2.w, i3.x, i3.y);
        let p = if t >= 0.0 {
            reproject_to_sphere(o + t * d, c, i2.w)
        } else {
            Vec3::ZERO
        };
        (Vec4::new(t, 0.0, 0.0, 0.0), v3(p))
    } else if function == function::INTERSECT_TRIANGLE {
        let (p0, e1, e2) = (i2.truncate(), i3.truncate(), Vec3::new(i1.w, i2.w, i3.w));
        let h = intersect_triangle_uv(i0.truncate(), i1.truncate(), p0, e1, e2, 0.0, i0.w);
        if h.t >= 0.0 {
            (
                Vec4::new(h.t, h.u, h.v, triangle_point_error(p0, e1, e2, h.u, h.v)),
                v3(triangle_point(p0, e1, e2, h.u, h.v)),
            )
        } else {
            (Vec4::new(h.t, 0.0, 0.0, 0.0), Vec4::ZERO)
        }
    } else if function == function::PLANE_SIDE {
        let e2 = Vec3::new(i0.w, i1.w, i2.w);
        let (o, d, p0, e1) = (i0.truncate(), i1.truncate(), i2.truncate(), i3.truncate());
        let leaves = ray_leaves_triangle_plane(o, d, p0, e1, e2);
        (
            Vec4::new(if leaves { 1.0 } else { 0.0 }, 0.0, 0.0, 0.0),
            Vec4::ZERO,
        )
    } else if function == function::OFFSET_RAY_ORIGIN {
        (
            v3(offset_ray_origin(i0.truncate(), i1.truncate(), i1.w)),
            v3(shadow_ray_end(
                i0.truncate(),
                i2.truncate(),
                i3.truncate(),
                i3.w,
            )),
        )
    } else if function == function::MEDIUM {
        let (wo, wi) = (i0.truncate(), i1.truncate());
        let (g, u1, u2) = (i0.w, i1.w, i2.w);
        let hero = free_flight::hero_channel(u1);
        let flight = free_flight::sample(i2.truncate(), i3.truncate(), i3.w, hero, u2, Vec3::ONE);
        (
            phase::sample(g, wo, u1, u2).extend(phase::eval(g, wo, wi)),
            Vec4::new(flight.t, flight.weight.x, flight.weight.y, flight.weight.z),
        )
    } else if function == function::ENVIRONMENT {
        let ints = input[3];
        let map = MapShape {
            rotation: [i0.x, i0.y],
            width: ints.x,
            height: ints.y,
        };
        let drawn = DrawnTexel {
            row: ints.z,
            row_cdf: [i1.x, i1.y],
            u2: i0.w,
            column: ints.w,
            column_cdf: [i1.z, i1.w],
            u1: i0.z,
        };
        let o = probe_environment(map, drawn, V3::from(i2.truncate()));
        (
            Vec4::new(o[0], o[1], o[2], o[3]),
            Vec4::new(o[4], o[5], o[6], o[7]),
        )
    } else if function == function::PUNCTUAL_LIGHT {
        let l = probe_punctual_light(i1.truncate(), i0.w, i2.truncate(), (i1.w, i2.w));
        let s = punctual::sample(&l, 0, i0.truncate());
        let sun = probe_directional_light(i2.truncate(), i3);
        let far = directional::sample(&sun, 0, i0.truncate()).point.position;
        (
            s.point.normal.extend(s.pdf_solid_angle),
            Vec4::new(
                punctual::spot_attenuation(&l, s.point.normal),
                far.x,
                far.y,
                far.z,
            ),
        )
    } else if function == function::BRDF {
        let (n, w) = (i0.truncate(), i1.truncate());
        let s = sample_brdf(n, i3.x, i3.y);
        (
            eval_scattering(n, w, i2.truncate()).extend(pdf_brdf(n, w)),
            s.extend(pdf_brdf(n, s)),
        )
    } else if function == function::RNG {
        let i = input[0];
        let h = pcg4d([i.x, i.y, i.z, i.w]);
        let (sx, sy) = sobol_pair(i.w, i.x, i.y, i.z);
        return [
            UVec4::new(h[0], h[1], h[2], h[3]),
            UVec4::new(
                u32_to_unit_f32(i.x).to_bits(),
                sx,
                sy,
                sobol_single(i.w, i.x, i.y, i.z),
            ),
        ];
    } else if function == function::CAMERA_RAY {
        let camera = Camera {
            eye: [0.0; 4],
            forward: [i0.x, i0.y, i0.z, 0.0],
            right: [i1.x, i1.y, i1.z, 0.0],
            up: [i2.x, i2.y, i2.z, 0.0],
        };
        let d = camera_ray_direction(
            &camera, input[0].w, input[1].w, input[2].w, input[3].z, i3.x, i3.y,
        );
        (v3(d), Vec4::ZERO)
    } else if function == function::FRESNEL {
        let (f, cos_t) = dielectric(i0.x, i0.y);
        let s = schlick(i1.truncate(), i0.x);
        (
            Vec4::new(conductor(i0.x, i0.y, i0.z), f, cos_t, s.x),
            Vec4::new(s.y, s.z, 0.0, 0.0),
        )
    } else if function == function::MICROFACET {
        let (n, wo) = (i0.truncate(), i1.truncate());
        let h = sample_visible_normal(n, wo, i0.w, i2.x, i2.y);
        (
            h.extend(ggx_d(i1.w, i2.z, i0.w)),
            Vec4::new(
                ggx_g1(i1.w, i0.w),
                pdf_reflected(n.dot(wo), (i1.w, i2.z), i0.w),
                0.0,
                0.0,
            ),
        )
    } else if function == function::BSDF_EVAL || function == function::BSDF_SAMPLE {
        let m = probe_bsdf_inputs::<f32>(input[3].x, input[3].y, i0.w, i1.w, input[2].w);
        let albedo = probe_glossy_albedo::<f32>(i3.z, i3.w);
        let (n, wo) = (V3::from(i0.truncate()), V3::from(i1.truncate()));
        if function == function::BSDF_EVAL {
            let wi = V3::from(i2.truncate());
            let (f, pdf) = bsdf::eval_v3(Dynamic(0), &m, n, wo, wi, i1.w, albedo);
            (Vec3::from(f).extend(pdf), Vec4::ZERO)
        } else {
            let u = (i2.x, i2.y, i2.z);
            let s = bsdf::sample_v3(Dynamic(0), &m, n, wo, i1.w, albedo, u);
            (
                Vec3::from(s.wi).extend(s.pdf),
                Vec3::from(s.weight).extend(s.eta2),
            )
        }
    } else if function == function::TRIANGLE_LIGHT {
        let (x, p0, e1, e2) = (i0.truncate(), i1.truncate(), i2.truncate(), i3.truncate());
        let l = probe_triangle_light(p0, e1, e2, input[3].w);
        let s = triangle::sample(&l, 0, input[0].w, x, i1.w, i2.w);
        (
            s.point.position.extend(s.pdf_solid_angle),
            s.point
                .normal
                .extend(spherical_triangle::solid_angle(x, p0, e1, e2)),
        )
    } else if function == function::TEXTURE {
        let i = input[0];
        let fp = footprint(Vec2::new(i0.x, i0.y), i.z, i.w, input[1].x, input[1].y);
        let key = input[2];
        let c = bilerp(
            probe_image(key.x, key.y, fp.x0, fp.y0),
            probe_image(key.x, key.y, fp.x1, fp.y0),
            probe_image(key.x, key.y, fp.x0, fp.y1),
            probe_image(key.x, key.y, fp.x1, fp.y1),
            fp.fx,
            fp.fy,
        );
        return [
            UVec4::new(fp.x0, fp.x1, fp.y0, fp.y1),
            bits(c.extend(fp.fx)),
        ];
    } else if function == function::MAPPED_NORMAL {
        let t = i1.truncate().to_array();
        let frame = ShadingTriangle::tangent_frame([t, t, t], i1.w);
        let n = mapped_normal(
            i0.truncate(),
            &frame,
            Vec2::new(i2.w, i3.x),
            i2.truncate(),
            i0.w,
        );
        (v3(n), Vec4::ZERO)
    } else {
        (Vec4::ZERO, Vec4::ZERO)
    };
    [bits(o0), bits(o1)]
}
