//! What a scene needs, so paths skip what it doesn't: the host analyses the scene and its
//! settings into feature bits; the GPU reads them as a Vulkan specialization constant (the
//! driver folds the branches away), the CPU as a const generic (`Static<F>`, one monomorphised
//! `trace_path` per combination). Without [`SPECIALIZED`] every question is answered from the
//! run-time parameters instead: the generic path, kept for comparison (`--no-specialize`).
//!
//! Both paths compute the same values: a feature bit may only be cleared when the run-time
//! answer is the same (`scene_features` derives both from the same parameters).

use crate::adaptive::is_adaptive;
use crate::scene::{
    light_sampling, mis, roulette, shading_flags, split_mode, texture_slot, Material, RenderParams,
    ShadingTriangle, NONE,
};

/// The bits are answers fixed before the render; without it, they are ignored.
pub const SPECIALIZED: u32 = 1 << 0;
/// The scene has lights: next-event estimation runs.
pub const LIGHTS: u32 = 1 << 1;
/// The background is not black: escaping paths add it.
pub const BACKGROUND: u32 = 1 << 2;
/// MIS uses the power heuristic (else the seed's 1/2 weights).
pub const MIS_POWER: u32 = 1 << 3;
/// Lights are sampled by the solid angle they subtend (else by area).
pub const LIGHT_SOLID_ANGLE: u32 = 1 << 4;
/// Russian roulette is driven by the throughput (else constant).
pub const RR_THROUGHPUT: u32 = 1 << 5;
/// The scene has exactly one light: no light choice.
pub const SINGLE_LIGHT: u32 = 1 << 6;
/// The scene may have Kd + Ks (`material_kind::GLOSSY`) surfaces.
pub const GLOSSY: u32 = 1 << 7;
/// The scene may have conductors.
pub const CONDUCTOR: u32 = 1 << 8;
/// The scene may have dielectrics (refraction, and roulette's eta^2 bookkeeping).
pub const DIELECTRIC: u32 = 1 << 9;
/// Every material bit: a scene with none of them is Lambertian only and runs the diffuse path.
pub const MATERIALS: u32 = GLOSSY | CONDUCTOR | DIELECTRIC | METALLIC_ROUGHNESS;
/// The light table may hold triangles (emissive quads and meshes): without it every light is
/// a sphere.
pub const TRIANGLE_LIGHTS: u32 = 1 << 10;
/// The scene has an environment map: a light, and the background of escaping paths.
pub const ENVIRONMENT: u32 = 1 << 12;
/// The camera may have a thin lens (a lens radius above 0; with the bit, a pinhole camera still
/// runs as one).
pub const THIN_LENS: u32 = 1 << 11;
/// Some triangle may have vertex normals: hits may shade with an interpolated normal.
pub const SHADING_NORMALS: u32 = 1 << 13;
/// Some material may have a texture: hits may look one up.
pub const TEXTURES: u32 = 1 << 14;
/// The scene may have glTF metallic-roughness surfaces (`material_kind::METALLIC_ROUGHNESS`),
/// resolved at each hit into the Kd + Ks form; it comes with [`GLOSSY`], whose code evaluates
/// them.
pub const METALLIC_ROUGHNESS: u32 = 1 << 15;
/// The light table may hold point and spot lights (`light_kind::PUNCTUAL`).
pub const PUNCTUAL_LIGHTS: u32 = 1 << 16;
/// A material has a normal map (`texture_slot::NORMAL`). Always set with [`SHADING_NORMALS`]:
/// a mapped normal is a shading normal, which the vertex reads only under that bit.
pub const NORMAL_MAPS: u32 = 1 << 17;
/// The scene has instances (`scene::Instance`): a hit may carry object-space shading records
/// whose normals and tangents `surface::shade` maps to world space.
pub const INSTANCES: u32 = 1 << 18;
/// Some light's material also reflects (`Material::reflects`): a path that finds it goes on.
pub const REFLECTING_LIGHTS: u32 = 1 << 19;
/// Some triangle has vertex colours (`shading_flags::VERTEX_COLOURS`): hits may read them.
pub const VERTEX_COLOURS: u32 = 1 << 20;
/// Some texture has a coordinate map (`texture::flags::TRANSFORM`, glTF's
/// `KHR_texture_transform`): lookups may read it.
pub const TEXTURE_TRANSFORMS: u32 = 1 << 21;

/// Some material has holes (`Material::opacity`, glTF's MASK or BLEND; `crate::opacity`): rays
/// may pass through a candidate hit (the GPU traces them without the OPAQUE flag).
pub const OPACITY: u32 = 1 << 22;

/// Some triangle has a second set of texture coordinates (`shading_flags::SECOND_UVS`, glTF's
/// `TEXCOORD_1`): lookups may read it.
pub const SECOND_UVS: u32 = 1 << 23;

/// A dielectric has a medium inside, or the scene is filled with one (`crate::medium`): paths
/// track the medium they are in, attenuate their throughput and shadow rays in it, scatter in
/// it, and pass interfaces. Scenes with it run the CPU's generic path, so that others do not
/// carry its checks.
pub const MEDIA: u32 = 1 << 24;
/// The render samples adaptively (`crate::adaptive`: pilot samples, converged pixels skipped).
/// Read by the GPU's ray-generation shader only, so that a render without it keeps no pilot
/// record live across its trace calls (`crate::shaders::raygen`); the CPU counts pilots in its
/// film and masks the bit before choosing its monomorphised path.
pub const ADAPTIVE: u32 = 1 << 25;
/// Paths split at their first vertex (`crate::split`: a split table or the pilot). Read by the
/// GPU's ray-generation shader only, so that a render without it keeps no first vertex live
/// across its trace calls; the CPU masks it and asks the parameters.
pub const SPLIT: u32 = 1 << 26;

/// The surface bits of a scene with these materials and shading records: [`TEXTURES`] if a
/// material has a texture, [`SHADING_NORMALS`] if a triangle has vertex normals,
/// [`NORMAL_MAPS`] and [`SHADING_NORMALS`] if a material has a normal map,
/// [`REFLECTING_LIGHTS`] if an emitting material reflects, [`VERTEX_COLOURS`] if a triangle
/// has vertex colours, [`OPACITY`] if a material has holes, [`SECOND_UVS`] if a triangle has
/// a second set of texture coordinates, [`MEDIA`] if a dielectric holds a medium.
#[inline]
pub fn surface_features(materials: &[Material], shading: &[ShadingTriangle]) -> u32 {
    let mut f = 0;
    if materials
        .iter()
        .any(|m| m.emission.iter().any(|&e| e > 0.0) && m.reflects())
    {
        f |= REFLECTING_LIGHTS;
    }
    if materials
        .iter()
        .any(|m| m.textures.iter().any(|&t| t != NONE))
    {
        f |= TEXTURES;
    }
    if materials
        .iter()
        .any(|m| m.textures[texture_slot::NORMAL] != NONE)
    {
        f |= NORMAL_MAPS | SHADING_NORMALS;
    }
    if shading
        .iter()
        .any(|s| s.flags & shading_flags::NORMALS != 0)
    {
        f |= SHADING_NORMALS;
    }
    if shading
        .iter()
        .any(|s| s.flags & shading_flags::VERTEX_COLOURS != 0)
    {
        f |= VERTEX_COLOURS;
    }
    if materials.iter().any(Material::has_holes) {
        f |= OPACITY;
    }
    if materials.iter().any(Material::bounds_media) {
        f |= MEDIA;
    }
    if shading
        .iter()
        .any(|s| s.flags & shading_flags::SECOND_UVS != 0)
    {
        f |= SECOND_UVS;
    }
    f
}

/// The feature bits of a render with these parameters.
#[inline]
pub fn scene_features(params: &RenderParams) -> u32 {
    let mut f = SPECIALIZED;
    if params.integrator.light_count > 0 {
        f |= LIGHTS;
    }
    if params.integrator.light_count == 1 {
        f |= SINGLE_LIGHT;
    }
    if params.environment.background[0] != 0.0
        || params.environment.background[1] != 0.0
        || params.environment.background[2] != 0.0
    {
        f |= BACKGROUND;
    }
    if params.integrator.mis_mode == mis::POWER {
        f |= MIS_POWER;
    }
    if params.integrator.light_sampling == light_sampling::SOLID_ANGLE {
        f |= LIGHT_SOLID_ANGLE;
    }
    if params.integrator.rr_mode == roulette::THROUGHPUT {
        f |= RR_THROUGHPUT;
    }
    if params.camera.eye[3] > 0.0 {
        f |= THIN_LENS;
    }
    if params.environment.width > 0 {
        f |= ENVIRONMENT | BACKGROUND;
    }
    if params.environment.medium != 0 {
        f |= MEDIA;
    }
    if is_adaptive(params) {
        f |= ADAPTIVE;
    }
    if params.split.mode != split_mode::OFF {
        f |= SPLIT;
    }
    f
}

/// A set of feature answers: fixed at compile time ([`Static`]) or read at run time
/// ([`Dynamic`], the GPU's specialization constant, or the generic path).
pub trait FeatureSet: Copy {
    fn bits(self) -> u32;

    #[inline]
    fn specialized(self) -> bool {
        self.bits() & SPECIALIZED != 0
    }
    /// Whether every bit of `bits` may be set (a kind's `FEATURES`, `crate::bsdf`); always
    /// without [`SPECIALIZED`].
    #[inline]
    fn has_all(self, bits: u32) -> bool {
        !self.specialized() || self.bits() & bits == bits
    }
    #[inline]
    fn answer(self, bit: u32, run_time: bool) -> bool {
        if self.specialized() {
            self.bits() & bit != 0
        } else {
            run_time
        }
    }
    #[inline]
    fn lights(self, p: &RenderParams) -> bool {
        self.answer(LIGHTS, p.integrator.light_count > 0)
    }
    #[inline]
    fn single_light(self, p: &RenderParams) -> bool {
        self.answer(SINGLE_LIGHT, p.integrator.light_count == 1)
    }
    /// The generic path adds the background whatever it is (adding black changes nothing).
    #[inline]
    fn background(self) -> bool {
        self.answer(BACKGROUND, true)
    }
    #[inline]
    fn mis_power(self, p: &RenderParams) -> bool {
        self.answer(MIS_POWER, p.integrator.mis_mode == mis::POWER)
    }
    /// The MIS mode (`scene::mis`): the power heuristic when specialised to it, else the
    /// run-time mode (the bit is cleared exactly when the mode is another).
    #[inline]
    fn mis_mode(self, p: &RenderParams) -> u32 {
        if self.mis_power(p) {
            mis::POWER
        } else {
            p.integrator.mis_mode
        }
    }
    /// Whether any surface may be other than Lambertian (see [`MATERIALS`]).
    #[inline]
    fn materials(self) -> bool {
        self.answer(MATERIALS, true)
    }
    #[inline]
    fn glossy(self) -> bool {
        self.answer(GLOSSY, true)
    }
    #[inline]
    fn conductor(self) -> bool {
        self.answer(CONDUCTOR, true)
    }
    #[inline]
    fn dielectric(self) -> bool {
        self.answer(DIELECTRIC, true)
    }
    #[inline]
    fn metallic_roughness(self) -> bool {
        self.answer(METALLIC_ROUGHNESS, true)
    }
    /// Whether the render may have an environment map (see [`ENVIRONMENT`]).
    #[inline]
    fn environment(self, p: &RenderParams) -> bool {
        self.answer(ENVIRONMENT, p.environment.width > 0)
    }
    /// Whether the camera may have a lens (see [`THIN_LENS`]).
    #[inline]
    fn thin_lens(self) -> bool {
        self.answer(THIN_LENS, true)
    }
    /// Whether a hit may have a shading normal (see [`SHADING_NORMALS`]).
    #[inline]
    fn shading_normals(self) -> bool {
        self.answer(SHADING_NORMALS, true)
    }
    /// Whether a material may have a texture (see [`TEXTURES`]).
    #[inline]
    fn textures(self) -> bool {
        self.answer(TEXTURES, true)
    }
    /// Whether a material may have a normal map (see [`NORMAL_MAPS`]).
    #[inline]
    fn normal_maps(self) -> bool {
        self.answer(NORMAL_MAPS, true)
    }
    /// Whether a hit may belong to an instance (see [`INSTANCES`]).
    #[inline]
    fn instances(self) -> bool {
        self.answer(INSTANCES, true)
    }
    /// Whether a light may be a point or spot light (see [`PUNCTUAL_LIGHTS`]).
    #[inline]
    fn punctual_lights(self) -> bool {
        self.answer(PUNCTUAL_LIGHTS, true)
    }
    /// Whether a light may be a triangle (see [`TRIANGLE_LIGHTS`]).
    #[inline]
    fn triangle_lights(self) -> bool {
        self.answer(TRIANGLE_LIGHTS, true)
    }
    /// The generic path asks each texture's record.
    #[inline]
    fn texture_transforms(self) -> bool {
        self.answer(TEXTURE_TRANSFORMS, true)
    }
    /// The generic path asks each triangle's record.
    #[inline]
    fn vertex_colours(self) -> bool {
        self.answer(VERTEX_COLOURS, true)
    }
    /// Whether a candidate hit may be a hole (see [`OPACITY`]; the generic path asks each
    /// candidate's material).
    #[inline]
    fn opacity(self) -> bool {
        self.answer(OPACITY, true)
    }
    /// The generic path asks each texture's record.
    #[inline]
    fn second_uvs(self) -> bool {
        self.answer(SECOND_UVS, true)
    }
    /// The generic path tracks media wherever it is (a path in vacuum, medium 0, attenuates
    /// nothing and never scatters).
    #[inline]
    fn media(self) -> bool {
        self.answer(MEDIA, true)
    }
    /// The generic path asks each light's material (`Material::reflects`).
    #[inline]
    fn reflecting_lights(self) -> bool {
        self.answer(REFLECTING_LIGHTS, true)
    }
    #[inline]
    fn light_solid_angle(self, p: &RenderParams) -> bool {
        self.answer(
            LIGHT_SOLID_ANGLE,
            p.integrator.light_sampling == light_sampling::SOLID_ANGLE,
        )
    }
    #[inline]
    fn rr_throughput(self, p: &RenderParams) -> bool {
        self.answer(RR_THROUGHPUT, p.integrator.rr_mode == roulette::THROUGHPUT)
    }
    /// Whether the render samples adaptively ([`ADAPTIVE`]: asked by the GPU's ray generation
    /// only).
    #[inline]
    fn adaptive(self, p: &RenderParams) -> bool {
        self.answer(ADAPTIVE, is_adaptive(p))
    }
    /// Whether paths split at their first vertex ([`SPLIT`]: asked by the GPU's ray
    /// generation only).
    #[inline]
    fn split(self, p: &RenderParams) -> bool {
        self.answer(SPLIT, p.split.mode != split_mode::OFF)
    }
}

/// Feature bits known at compile time: each combination is its own monomorphised path.
#[derive(Clone, Copy, Debug, Default)]
pub struct Static<const F: u32>;

impl<const F: u32> FeatureSet for Static<F> {
    #[inline(always)]
    fn bits(self) -> u32 {
        F
    }
}

/// Feature bits known at run time (0: the generic path).
#[derive(Clone, Copy, Debug, Default)]
pub struct Dynamic(pub u32);

impl FeatureSet for Dynamic {
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0
    }
}

/// [`Dynamic`] for specialised bits known to lack every bit of `ABSENT` (constructed only from
/// such bits: the invariant): [`SPECIALIZED`] and the absent bits are constants of its
/// [`FeatureSet::bits`], so every answer about them is fixed at compile time and the code it
/// guards compiled out, while the other answers are [`Dynamic`]'s. The CPU's run-time path for
/// scenes without media is `DynamicWithout<{ MEDIA }>`.
#[derive(Clone, Copy, Debug, Default)]
pub struct DynamicWithout<const ABSENT: u32>(pub u32);

impl<const ABSENT: u32> FeatureSet for DynamicWithout<ABSENT> {
    #[inline(always)]
    fn bits(self) -> u32 {
        (self.0 | SPECIALIZED) & !ABSENT
    }
}
