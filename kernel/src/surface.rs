//! The surface at a hit as the estimator sees it: the shading normal and texture coordinates
//! interpolated from the triangle's vertex attributes (`scene::ShadingTriangle`), and the
//! material with its textures applied there (`crate::texture`).
//!
//! Shading normals follow pbrt-v4 (`Triangle::InteractionFromIntersection`,
//! `SurfaceInteraction::SetShadingGeometry`, `BSDF`): the normal is the barycentric blend of
//! the vertex normals, normalised; the BSDF is evaluated and sampled in its frame only, the
//! cosine is the shading normal's, and a ray leaves offset along the *geometric* normal, on the
//! side its direction goes. The geometric normal stays authoritative for the side (inside and
//! outside of glass, the front of a light); the shading normal is turned to the side `wo` is
//! on, as pbrt-v4's two-sided BxDFs mirror `wo`'s hemisphere. Where the two normals disagree
//! about a direction (it is above one plane and below the other) pbrt-v4 lets the ray through
//! the surface: light leaks in through a thin wall, and rays enter the inside of closed meshes.
//! Here such a direction carries nothing (`path::PathState::vertex`; Veach's thesis, section
//! 5.3, and pbrt-v3's `BSDF::f` decide reflection against transmission by the geometric normal
//! the same way): no leaks, at the price of a little energy lost where the normals disagree,
//! which is near silhouettes of coarse meshes (docs/materials.md, "Shading normals").

use crate::bsdf;
use crate::bsdf::multiple_scattering::GlossyAlbedo;
use crate::features::FeatureSet;
use crate::geometry::{blend2, blend3, blend3_v3};
use crate::hit::SurfaceHit;
use crate::instance::{normal_to_world, vector_to_world};
use crate::real::{self, V3};
use crate::scene::{material_kind, shading_flags, texture_slot, Material, ShadingTriangle, NONE};
use crate::scene_view::SceneView;
use crate::texture::{self, lookup_at, textured_material, TexCoords};
use spirv_std::glam::{Vec2, Vec3};

/// The shading normal of `tri` at barycentrics `bary`: unit, or the zero vector where the blend
/// has no direction (as opposite vertex normals can give), which leaves the hit flat.
#[inline]
pub fn interpolated_normal(tri: &ShadingTriangle, bary: Vec2) -> Vec3 {
    let n = blend3(
        Vec3::from(tri.normal0),
        Vec3::from(tri.normal1),
        Vec3::from(tri.normal2),
        bary,
    );
    unit_or(n, Vec3::ZERO)
}

/// `v` scaled to unit length, or `fallback` where `v` has no direction (zero, or a length
/// that overflows or is not a number).
#[inline]
fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    match unit_v3(V3::from(v)) {
        (unit, true) => unit.into(),
        _ => fallback,
    }
}

/// The texture coordinates of `tri` at barycentrics `bary`.
#[inline]
pub fn interpolated_uv(tri: &ShadingTriangle, bary: Vec2) -> Vec2 {
    blend2(
        Vec2::from(tri.uv0),
        Vec2::from(tri.uv1),
        Vec2::from(tri.uv2),
        bary,
    )
}

/// The texture coordinates of shading record `record` (of a triangle whose material is
/// `material`) at barycentrics `bary`: its own, and the second set from the record that follows
/// its others (tangent frame, vertex colours) where it has one (`shading_flags::SECOND_UVS`, in
/// scenes with second sets); else the first again.
#[inline]
pub fn tex_coords<F: FeatureSet>(
    features: F,
    shading: &[ShadingTriangle],
    record: u32,
    material: &Material,
    bary: Vec2,
) -> TexCoords {
    let tri = &shading[record as usize];
    let mut coords = TexCoords::one(interpolated_uv(tri, bary));
    if features.second_uvs() && tri.flags & shading_flags::SECOND_UVS != 0 {
        let second =
            after_frame(record, material) + (tri.flags & shading_flags::VERTEX_COLOURS != 0) as u32;
        coords.second = interpolated_uv(&shading[second as usize], bary);
    }
    coords
}

/// The index of the first record after shading record `record`'s own and its tangent frame
/// (which a triangle of `material` has where the material has a normal map): its vertex
/// colours where it has them, then its second texture coordinates (the order the builder
/// writes them in; `ShadingTriangle`).
#[inline]
fn after_frame(record: u32, material: &Material) -> u32 {
    record + 1 + (material.textures[texture_slot::NORMAL] != NONE) as u32
}

/// The shading normal a tangent-space normal map gives (glTF 2.0, `material.normalTexture`;
/// the MikkTSpace convention it names): the texel `texel` (linear RGB in [0, 1]) decodes to
/// m = (2 texel - 1) x (`scale`, `scale`, 1), and the normal is m's direction in the frame
/// (T, B, N) at the point: N = `base` (unit: the vertex-normal blend, or the geometric normal),
/// T = the blend of the tangent record `frame`'s vertex tangents made orthogonal to N
/// (Gram-Schmidt), B = sign x N x T with the record's sign. Unit; `base` itself where the
/// tangent is within [`MIN_TANGENT_SINE`] of N or the result has no direction (a degenerate
/// frame leaves the point unmapped).
#[inline]
pub fn mapped_normal(
    base: Vec3,
    frame: &ShadingTriangle,
    bary: Vec2,
    texel: Vec3,
    scale: f32,
) -> Vec3 {
    let tangent = |t: [f32; 3]| V3::from(Vec3::from(t));
    let tangents = [
        tangent(frame.normal0),
        tangent(frame.normal1),
        tangent(frame.normal2),
    ];
    mapped_normal_v3(
        V3::from(base),
        tangents,
        frame.uv0[0],
        (bary.x, bary.y),
        V3::from(texel),
        scale,
    )
    .into()
}

/// [`mapped_normal`] over any scalar [`real::Real`], the frame given as its three vertex
/// tangents and its handedness `sign`, in the same operations (so that a `V3<f32>` gives its
/// result bit for bit, and its error under a Vulkan device's arithmetic can be bounded by
/// running it on one: `tests/src/device_class.rs`).
#[inline]
pub fn mapped_normal_v3<R: real::Real<Bits = u32>>(
    base: V3<R>,
    tangents: [V3<R>; 3],
    sign: R,
    bary: (R, R),
    texel: V3<R>,
    scale: R,
) -> V3<R> {
    let (one, two) = (R::splat(1.0), R::splat(2.0));
    let t = blend3_v3(tangents[0], tangents[1], tangents[2], bary);
    let across = t - base * base.dot(t);
    let min_across = R::splat(MIN_TANGENT_SINE * MIN_TANGENT_SINE) * t.dot(t);
    if across.dot(across).greater_than(min_across) == 0 {
        return base;
    }
    let (t, has_direction) = unit_v3(across);
    if !has_direction {
        return base;
    }
    let b = base.cross(t) * sign;
    let m = V3::new(
        (texel.x * two - one) * scale,
        (texel.y * two - one) * scale,
        (texel.z * two - one) * one,
    );
    let (n, has_direction) = unit_v3(t * m.x + b * m.y + base * m.z);
    if has_direction {
        n
    } else {
        base
    }
}

/// The least sine between a normal map's tangent and the normal it stands on for the tangent
/// to give the frame its direction (2^-10, 0.056 degrees); below it the point is left unmapped.
/// The direction across the normal is t - n (n . t) over |t|, whose rounding is a few eps on
/// any device: with the test relative to |t| and far above that rounding, the CPU and a
/// device decide alike (except within rounding of the threshold), and a frame that passes
/// carries at most a few eps / 2^-10 of rounding in its direction. Testing against zero
/// instead let a tangent parallel to the normal take either branch on a real GPU.
const MIN_TANGENT_SINE: f32 = 1.0 / 1024.0;

/// [`unit_or`] over any scalar [`real::Real`]: `v` scaled to unit length and whether it has a
/// direction (else `v` as it is).
#[inline]
fn unit_v3<R: real::Real<Bits = u32>>(v: V3<R>) -> (V3<R>, bool) {
    let len2 = v.dot(v);
    if len2.greater_than(R::splat(0.0)) != 0 && len2.finite() != 0 {
        (v / len2.sqrt(), true)
    } else {
        (v, false)
    }
}

/// The material at the vertex of `hit` (its `SurfaceHit::material`, shading record
/// `SurfaceHit::shading` and barycentrics): a copy of its table entry in `scene`, with
/// its textures applied where the scene has any, its albedo (base colour) times the record's
/// interpolated vertex colours where it has them (glTF's `COLOR_0`) and, for glTF's
/// metallic-roughness material,
/// resolved into the form `crate::bsdf` evaluates (`bsdf::at_point`); and the
/// unit shading normal (either orientation) where the record's vertex normals or the
/// material's normal map give one, else zero (the hit shades with its geometric normal).
/// The hit's unit geometric normal (`SurfaceHit::normal`, edge1 x edge2) is the front a normal
/// map's frame stands on when the triangle has no vertex normals.
/// The hit's instance (`SurfaceHit::instance`), unless `NONE`: an instanced
/// triangle's record is in object space, and its normal and tangents are mapped to world space
/// here (`crate::instance`; a mirroring instance flips the frame's handedness).
#[inline]
pub fn shade<F: FeatureSet>(features: F, scene: &SceneView, hit: &SurfaceHit) -> (Material, Vec3) {
    let (record, bary, geometric, instance) =
        (hit.shading, hit.barycentrics, hit.normal, hit.instance);
    let (shading, textures, instances) = (scene.shading, scene.textures, scene.instances);
    let mut m = scene.materials[hit.material as usize];
    let mut normal = Vec3::ZERO;
    if (features.shading_normals() || features.textures()) && record != NONE {
        let tri = shading[record as usize];
        let instanced = features.instances() && instance != NONE;
        if features.shading_normals() && tri.flags & shading_flags::NORMALS != 0 {
            normal = interpolated_normal(&tri, bary);
            if instanced {
                normal = unit_or(
                    normal_to_world(&instances[instance as usize], normal),
                    Vec3::ZERO,
                );
            }
        }
        if features.textures() {
            let coords = tex_coords(features, shading, record, &m, bary);
            m = textured_material(features, &m, textures, coords);
            let map = m.textures[texture_slot::NORMAL];
            if features.normal_maps() && map != NONE {
                let base = if normal == Vec3::ZERO {
                    geometric
                } else {
                    normal
                };
                let mut frame = shading[record as usize + 1];
                if instanced {
                    let inst = &instances[instance as usize];
                    frame.normal0 = vector_to_world(inst, Vec3::from(frame.normal0)).to_array();
                    frame.normal1 = vector_to_world(inst, Vec3::from(frame.normal1)).to_array();
                    frame.normal2 = vector_to_world(inst, Vec3::from(frame.normal2)).to_array();
                    frame.uv0[0] *= inst.handedness;
                }
                normal = mapped_normal(
                    base,
                    &frame,
                    bary,
                    lookup_at(features, textures, map, coords),
                    m.normal_scale,
                );
            }
        }
    }
    if features.vertex_colours() && record != NONE {
        let tri = shading[record as usize];
        if tri.flags & shading_flags::VERTEX_COLOURS != 0 {
            let colours = shading[after_frame(record, &m) as usize];
            let colour = blend3(
                Vec3::from(colours.normal0),
                Vec3::from(colours.normal1),
                Vec3::from(colours.normal2),
                bary,
            );
            m.albedo = (Vec3::from(m.albedo) * colour).to_array();
        }
    }
    (bsdf::at_point(features, &m), normal)
}

/// The radiance `material` emits at light hit `hit`: its emission, times its emission texture
/// at the hit's texture coordinates where it has one.
#[inline]
pub fn emission_at<F: FeatureSet>(
    features: F,
    scene: &SceneView,
    material: &Material,
    hit: &SurfaceHit,
) -> Vec3 {
    let (record, bary) = (hit.shading, hit.barycentrics);
    let emission = Vec3::from(material.emission);
    let texture = material.textures[texture_slot::EMISSION];
    if features.textures() && texture != NONE && record != NONE {
        let coords = tex_coords(features, scene.shading, record, material, bary);
        emission * lookup_at(features, scene.textures, texture, coords)
    } else {
        emission
    }
}

/// What the glossy lobes of material `m` at a point (resolved, `bsdf::at_point`) with unit
/// normal `n` lose to multiple scattering seen from `wo` (`bsdf::multiple_scattering`): for
/// glTF's metallic-roughness material, the GGX albedos at its roughness and at its clear coat's
/// from the texture table `textures` (`texture::ggx_albedo`), each where the lobe is rough (a
/// mirror loses nothing), and its sheen's lobe (`texture::sheen_ltc`) where it has one; for
/// every other kind, `GlossyAlbedo::NONE`. `bsdf::eval` and `bsdf::sample` take it; a vertex
/// looks it up once.
#[inline]
pub fn glossy_albedo<F: FeatureSet>(
    features: F,
    m: &Material,
    textures: &[u32],
    n: Vec3,
    wo: Vec3,
) -> GlossyAlbedo {
    if !(m.kind == material_kind::METALLIC_ROUGHNESS && features.metallic_roughness()) {
        return GlossyAlbedo::NONE;
    }
    let mu = n.dot(wo).max(0.0);
    let mut albedo = GlossyAlbedo::NONE;
    if !(m.alpha < bsdf::DELTA_ALPHA) {
        let e = texture::ggx_albedo(textures, m.roughness, mu);
        albedo.directional = e.x;
        albedo.average = e.y;
    }
    if m.coat != 0 && !(m.coat_alpha() < bsdf::DELTA_ALPHA) {
        let e = texture::ggx_albedo(textures, m.coat_roughness(), mu);
        albedo.coat_directional = e.x;
        albedo.coat_average = e.y;
        albedo.coat_reflectance = e.z;
    }
    if m.has_sheen() {
        albedo.sheen = texture::sheen_ltc(textures, m.sheen_roughness(), mu).into();
    }
    albedo
}
