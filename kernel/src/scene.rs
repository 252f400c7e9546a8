//! `#[repr(C)]` plain-old-data types shared by the host and the device (storage buffers and push
//! constants). Layout rules: only `f32`/`u32` and arrays of them, every struct a multiple of 16
//! bytes, no `Vec3` (its size has differed between host and device), so std430 and the native
//! layout agree. The host checks sizes and offsets in a test.

/// Index meaning "none" in `u32` index fields (no light, no hit).
pub const NONE: u32 = u32::MAX;

/// A sphere. 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Sphere {
    pub center: [f32; 3],
    pub radius: f32,
    /// Index into the material table.
    pub material: u32,
    /// Index into the light table when the sphere emits, else [`NONE`].
    pub light: u32,
    pub _pad: [u32; 2],
}

/// One triangle with its precomputed edges (p1 = p0 + edge1, p2 = p0 + edge2). 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Triangle {
    pub p0: [f32; 3],
    pub material: u32,
    pub edge1: [f32; 3],
    /// Index into the light table when the triangle emits, else [`NONE`].
    pub light: u32,
    pub edge2: [f32; 3],
    /// Index into the shading table ([`ShadingTriangle`]) when the triangle has vertex normals
    /// or texture coordinates, else [`NONE`].
    pub shading: u32,
}

/// A triangle's vertex attributes (`Triangle::shading`): normals interpolated into the shading
/// normal, texture coordinates interpolated into the point's (u, v), both by the hit's
/// barycentrics (`crate::surface`). Vertex k is p0, p1 = p0 + edge1, p2 = p0 + edge2. 64 bytes.
///
/// A triangle whose material has a normal map (`texture_slot::NORMAL`) has a second record
/// right after its own, its tangent frame ([`ShadingTriangle::tangent_frame`]): the three
/// vertex tangents in `normal0..2` (interpolated like the normals) and the bitangent's sign in
/// `uv0[0]`, glTF's `TANGENT.w` (bitangent = sign x normal x tangent). A triangle with vertex
/// colours (`shading_flags::VERTEX_COLOURS`, glTF's `COLOR_0`) has one more record after those,
/// [`ShadingTriangle::vertex_colours`]: the three linear RGB colours in `normal0..2`,
/// interpolated like the normals, multiplying the base colour; one with a second set of texture
/// coordinates (`shading_flags::SECOND_UVS`) one more, with them in `uv0..2`. Keeping them in the
/// same table costs nothing to scenes without them and needs no further GPU binding.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct ShadingTriangle {
    /// Vertex normals (any length; ignored without `shading_flags::NORMALS`).
    pub normal0: [f32; 3],
    pub normal1: [f32; 3],
    pub normal2: [f32; 3],
    /// Texture coordinates of the three vertices (u right, v up in the image).
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    pub uv2: [f32; 2],
    /// [`shading_flags`]: whether the normals shade the triangle (else its geometric normal
    /// does) and whether a vertex-colour record follows.
    pub flags: u32,
}

/// Bits of [`ShadingTriangle::flags`].
pub mod shading_flags {
    /// The vertex normals shade the triangle.
    pub const NORMALS: u32 = 1 << 0;
    /// A vertex-colour record ([`super::ShadingTriangle::vertex_colours`]) follows the
    /// triangle's record (and its tangent frame, where its material has a normal map).
    pub const VERTEX_COLOURS: u32 = 1 << 1;
    /// A record of the triangle's second texture coordinates (glTF's `TEXCOORD_1`, in
    /// `uv0..2`) follows the others (its tangent frame and vertex colours, where it has them),
    /// for the textures that read that set (`crate::texture::flags::SECOND_SET`).
    pub const SECOND_UVS: u32 = 1 << 2;
}

impl ShadingTriangle {
    /// The tangent-frame record of a normal-mapped triangle (see the type's documentation).
    pub const fn tangent_frame(tangents: [[f32; 3]; 3], sign: f32) -> Self {
        Self {
            normal0: tangents[0],
            normal1: tangents[1],
            normal2: tangents[2],
            uv0: [sign, 0.0],
            uv1: [0.0; 2],
            uv2: [0.0; 2],
            flags: 0,
        }
    }

    /// The vertex-colour record of a triangle with vertex colours `colours` (linear RGB; see
    /// the type's documentation).
    pub const fn vertex_colours(colours: [[f32; 3]; 3]) -> Self {
        Self {
            normal0: colours[0],
            normal1: colours[1],
            normal2: colours[2],
            uv0: [0.0; 2],
            uv1: [0.0; 2],
            uv2: [0.0; 2],
            flags: 0,
        }
    }
}

/// One placement of a shared mesh: the mesh's triangles, stored once in object space in the
/// triangle table, seen through an affine transform (`crate::instance`). Both backends read the
/// same record: the GPU's TLAS instance carries `object_to_world` and its custom index names
/// the record; the CPU's two-level BVH maps rays by `world_to_object`. 116 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Instance {
    /// The 3 x 4 object-to-world matrix [linear | translation], row-major (Vulkan's
    /// `VkTransformMatrixKHR`).
    pub object_to_world: [f32; 12],
    /// Its inverse, world to object, in the same layout (rounded from an f64 inverse).
    pub world_to_object: [f32; 12],
    /// The mesh's first triangle in the triangle table; a hit's primitive index counts from it.
    pub first_triangle: u32,
    /// The infinity norm (largest absolute row sum) of `object_to_world`'s linear part.
    pub forward_norm: f32,
    /// The infinity norm of `world_to_object`'s linear part.
    pub inverse_norm: f32,
    /// 1, or -1 where the transform mirrors (a negative determinant): the sign a tangent
    /// frame's handedness takes in world space.
    pub handedness: f32,
    /// perm(|A|) / |det A| for the linear part A of `object_to_world` (computed in f64, rounded
    /// up; at least 1): how much the determinant's computed value may cancel, which a device
    /// that inverts by the adjugate over the determinant loses to
    /// (`crate::instance::DEVICE_INVERSE_EPS_PER_DETERMINANT_CONDITION`). About 1 for a
    /// rotation after or before an axis scale; up to about c^2 for a scale along a turned axis.
    pub determinant_condition: f32,
}

/// The material parameters a texture can give (`Material::textures[slot]`).
pub mod texture_slot {
    /// Kd, the diffuse reflectance (a colour map: sRGB-decoded); METALLIC_ROUGHNESS: the base
    /// colour.
    pub const KD: usize = 0;
    /// Ks, the specular reflectance (a colour map); METALLIC_ROUGHNESS: glTF's
    /// metallic-roughness map (linear; blue multiplies metallic, green roughness).
    pub const KS: usize = 1;
    /// The GGX roughness alpha (linear; the red channel).
    pub const ALPHA: usize = 2;
    /// The emitted radiance (a colour map).
    pub const EMISSION: usize = 3;
    /// A tangent-space normal map (linear; glTF's `normalTexture`): not a factor but the
    /// shading normal's direction in the triangle's tangent frame (`crate::surface`).
    pub const NORMAL: usize = 4;
    pub const COUNT: usize = 5;
}

/// The kinds of surface a [`Material`] describes (`Material::kind`); `crate::bsdf` derives each.
pub mod material_kind {
    /// Two-sided Lambertian, f = Kd / pi; also a light (emission > 0, albedo 0).
    pub const DIFFUSE: u32 = 0;
    /// The seed's BRDF: Kd / pi plus a GGX microfacet lobe with Schlick's Fresnel (F0 = Ks).
    pub const GLOSSY: u32 = 1;
    /// A metal: a GGX microfacet (or, at alpha 0, perfect) mirror with a conductor's Fresnel.
    pub const CONDUCTOR: u32 = 2;
    /// Glass: GGX (or smooth) reflection and refraction between the outside (index 1) and the
    /// inside (index `ior`) of a closed surface.
    pub const DIELECTRIC: u32 = 3;
    /// glTF 2.0's metallic-roughness material (the specification's Appendix B): a mix, by
    /// `metallic`, of a GGX metal whose Schlick Fresnel has F0 = base colour and a dielectric
    /// (index 1.5, F0 = 0.04) whose Schlick Fresnel weighs a GGX layer over the diffuse base
    /// colour; GGX alpha = roughness^2. Stored as `albedo` = base colour, `metallic`,
    /// `roughness`; `crate::surface::shade` resolves it at the point into the Kd + Ks form
    /// (`bsdf::resolve_metallic_roughness`) that `crate::bsdf` evaluates.
    pub const METALLIC_ROUGHNESS: u32 = 4;
}

/// A two-sided surface's scattering (one of [`material_kind`]), or a light (emission > 0 and
/// no reflection). 112 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Material {
    /// Diffuse reflectance Kd (albedo), linear RGB: the Lambertian term Kd / pi.
    pub albedo: [f32; 3],
    /// One of [`material_kind`].
    pub kind: u32,
    /// Emitted radiance, linear RGB (zero for non-emitters).
    pub emission: [f32; 3],
    /// GGX roughness (the distribution's alpha, no remapping); below `bsdf::DELTA_ALPHA` the
    /// lobe is a perfect (delta) mirror or refraction.
    pub alpha: f32,
    /// GLOSSY: Ks, the Schlick Fresnel's reflectance at normal incidence. CONDUCTOR with `eta`
    /// zero: the constant reflectance.
    pub specular: [f32; 3],
    /// DIELECTRIC: the inside's index of refraction relative to the outside.
    pub ior: f32,
    /// CONDUCTOR: the real part eta of the complex index of refraction, positive in every
    /// channel for the exact Fresnel of `eta` + i `k` (a metal's is); zero for the constant
    /// `specular` (`Material::is_complex_conductor`). METALLIC_ROUGHNESS: the sheen's colour
    /// (`KHR_materials_sheen`'s sheenColorFactor, `crate::bsdf::sheen`; zero: no sheen),
    /// [`Material::sheen_colour`].
    pub eta: [f32; 3],
    /// Where a triangle of this material is present (glTF's `alphaMode`, `crate::opacity`),
    /// as one number: 0, everywhere (OPAQUE); t > 0, MASK: where the `KD` texture's alpha (1
    /// without one) is at least t = alphaCutoff / baseColorFactor's alpha (above 1: nowhere);
    /// t < 0, BLEND: with probability -t x that alpha, -t in (0, 1] being the factor's alpha.
    pub opacity: f32,
    /// CONDUCTOR with a complex index: the extinction coefficient k. METALLIC_ROUGHNESS: k[0]
    /// is the sheen's roughness in [0, 1] ([`Material::sheen_roughness`]).
    pub k: [f32; 3],
    /// METALLIC_ROUGHNESS: glTF's clear coat (`KHR_materials_clearcoat`, `crate::bsdf::coat`):
    /// its weight (`clearcoatFactor`) in the low 16 bits and its roughness
    /// (`clearcoatRoughnessFactor`) in the high 16, each round(x 65535)
    /// ([`Material::pack_coat`], [`Material::coat_weight`], [`Material::coat_roughness`]); 0,
    /// no coat. DIELECTRIC: its media (`crate::medium`, pbrt-v4's medium interface): in the
    /// low 16 bits the medium inside, an index into the media table (0, vacuum: clear,
    /// [`Material::interior_medium`]), in the high 16 the medium outside plus 1 (0: the
    /// scene's, [`Material::exterior_medium`]).
    pub coat: u32,
    /// Per [`texture_slot`]: the texture (an index into the texture table, `crate::texture`)
    /// whose value at the point multiplies that parameter, or [`NONE`].
    pub textures: [u32; texture_slot::COUNT],
    /// METALLIC_ROUGHNESS: glTF's metalness in [0, 1] (the `KS` texture's blue channel
    /// multiplies it).
    pub metallic: f32,
    /// METALLIC_ROUGHNESS: glTF's perceptual roughness in [0, 1] (GGX alpha = roughness^2; the
    /// `KS` texture's green channel multiplies it).
    pub roughness: f32,
    /// The normal map's x and y scale (glTF's `normalTexture.scale`; 1 without a map).
    pub normal_scale: f32,
    /// METALLIC_ROUGHNESS: the dielectric layer's reflectance at normal incidence per channel,
    /// min(((ior - 1) / (ior + 1))^2 x specularColorFactor, 1) x specularFactor (glTF's
    /// `KHR_materials_ior` and `KHR_materials_specular`; 0.04 without them).
    pub layer_f0: [f32; 3],
    /// METALLIC_ROUGHNESS: the layer's reflectance at grazing incidence, `KHR_materials_specular`'s
    /// specularFactor (1 without it). Every other kind: 1.
    pub layer_f90: f32,
}

impl Material {
    /// A Lambertian surface of albedo `kd`.
    pub const fn diffuse(kd: [f32; 3]) -> Self {
        Self {
            albedo: kd,
            kind: material_kind::DIFFUSE,
            emission: [0.0; 3],
            alpha: 0.0,
            specular: [0.0; 3],
            ior: 1.0,
            eta: [0.0; 3],
            opacity: 0.0,
            k: [0.0; 3],
            coat: 0,
            textures: [NONE; texture_slot::COUNT],
            metallic: 0.0,
            roughness: 0.0,
            normal_scale: 1.0,
            layer_f0: [LAYER_F0; 3],
            layer_f90: 1.0,
        }
    }

    /// A light's surface: emits `radiance`, reflects nothing.
    pub const fn emitter(radiance: [f32; 3]) -> Self {
        let mut m = Self::diffuse([0.0; 3]);
        m.emission = radiance;
        m
    }

    /// Whether the surface has holes (glTF's MASK or BLEND: `opacity` not 0; `crate::opacity`).
    #[inline]
    pub fn has_holes(&self) -> bool {
        self.opacity != 0.0
    }

    /// The [`Material::coat`] word of a coat of `weight` and `roughness` (each clamped to
    /// [0, 1]).
    pub fn pack_coat(weight: f32, roughness: f32) -> u32 {
        let q = |x: f32| (x.clamp(0.0, 1.0) * 65535.0 + 0.5) as u32;
        q(weight) | (q(roughness) << 16)
    }

    /// The clear coat's weight in [0, 1] (0: none).
    #[inline]
    pub fn coat_weight(&self) -> f32 {
        (self.coat & 0xffff) as f32 * (1.0 / 65535.0)
    }

    /// The clear coat's perceptual roughness in [0, 1] (GGX alpha = its square).
    #[inline]
    pub fn coat_roughness(&self) -> f32 {
        (self.coat >> 16) as f32 * (1.0 / 65535.0)
    }

    /// The clear coat's GGX alpha, its roughness squared (below `bsdf::DELTA_ALPHA`: a mirror).
    #[inline]
    pub fn coat_alpha(&self) -> f32 {
        let r = self.coat_roughness();
        r * r
    }

    /// METALLIC_ROUGHNESS: the sheen's colour (stored in `eta`; zero: no sheen).
    #[inline]
    pub fn sheen_colour(&self) -> [f32; 3] {
        self.eta
    }

    /// METALLIC_ROUGHNESS: the sheen's roughness (stored in `k[0]`).
    #[inline]
    pub fn sheen_roughness(&self) -> f32 {
        self.k[0]
    }

    /// Whether a METALLIC_ROUGHNESS material has a sheen: its colour is not black.
    #[inline]
    pub fn has_sheen(&self) -> bool {
        self.eta[0] > 0.0 || self.eta[1] > 0.0 || self.eta[2] > 0.0
    }

    /// Sets the sheen of a METALLIC_ROUGHNESS material (colour clamped to [0, 1] per channel,
    /// roughness to [0, 1]).
    pub fn set_sheen(&mut self, colour: [f32; 3], roughness: f32) {
        self.eta = [
            colour[0].clamp(0.0, 1.0),
            colour[1].clamp(0.0, 1.0),
            colour[2].clamp(0.0, 1.0),
        ];
        self.k = [roughness.clamp(0.0, 1.0), 0.0, 0.0];
    }

    /// DIELECTRIC: the medium inside, an index into the media table (the low 16 bits of
    /// `coat`; 0 is `medium::VACUUM`).
    #[inline]
    pub fn interior_medium(&self) -> u32 {
        self.coat & 0xffff
    }

    /// DIELECTRIC: the medium outside: the one its shape names (the high 16 bits of `coat`,
    /// minus 1), or `scene`, the scene's medium, where it names none.
    #[inline]
    pub fn exterior_medium(&self, scene: u32) -> u32 {
        let named = self.coat >> 16;
        if named == 0 {
            scene
        } else {
            named - 1
        }
    }

    /// Sets the medium inside a DIELECTRIC (an index into the media table, below 65535).
    pub fn set_interior_medium(&mut self, medium: u32) {
        self.coat = (self.coat & 0xffff_0000) | (medium & 0xffff);
    }

    /// Sets the medium outside a DIELECTRIC (an index into the media table, below 65535).
    pub fn set_exterior_medium(&mut self, medium: u32) {
        self.coat = (self.coat & 0xffff) | (((medium + 1) & 0xffff) << 16);
    }

    /// Whether the material is a dielectric with a medium inside (not vacuum).
    #[inline]
    pub fn has_interior_medium(&self) -> bool {
        self.kind == material_kind::DIELECTRIC && self.interior_medium() != 0
    }

    /// Whether the material is a dielectric that names a medium, inside or outside.
    #[inline]
    pub fn bounds_media(&self) -> bool {
        self.kind == material_kind::DIELECTRIC && self.coat != 0
    }

    /// Whether a CONDUCTOR reflects by the exact Fresnel of its complex index `eta` + i `k`
    /// (its `eta` positive) rather than its constant `specular` (`eta` zero).
    #[inline]
    pub fn is_complex_conductor(&self) -> bool {
        self.eta[0] > 0.0
    }

    /// Whether the surface reflects at all: any kind but the Lambertian, which reflects when
    /// its albedo is not black (a light's own surface, [`Material::emitter`], is a black
    /// Lambertian). A path that finds a light on a reflecting surface goes on.
    #[inline]
    pub fn reflects(&self) -> bool {
        self.kind != material_kind::DIFFUSE
            || self.albedo[0] > 0.0
            || self.albedo[1] > 0.0
            || self.albedo[2] > 0.0
    }
}

/// The dielectric layer's reflectance at normal incidence of glTF's metallic-roughness material
/// without `KHR_materials_specular` and `KHR_materials_ior`: ((1 - 1.5) / (1 + 1.5))^2 (glTF
/// 2.0, Appendix B, "dielectric_brdf", index 1.5); [`Material::layer_f0`]'s default.
pub const LAYER_F0: f32 = 0.04;

/// The shapes a [`Light`] can have (`Light::kind`).
pub mod light_kind {
    /// An emissive sphere: emits from its outer surface.
    pub const SPHERE: u32 = 0;
    /// An emissive triangle (of a quad or a mesh): emits from its front face, the side
    /// edge1 x edge2 points to, or from both faces when `Light::two_sided`.
    pub const TRIANGLE: u32 = 1;
    /// The environment map: radiance arriving from infinitely far in every direction
    /// (`environment`). `position` and `radius` hold a sphere bounding the scene, which shadow
    /// rays toward it leave; `radiance` its mean (for the selection by power).
    pub const ENVIRONMENT: u32 = 2;
    /// A point or spot light (glTF's `KHR_lights_punctual`): a delta light at `position` of
    /// radiant intensity `radiance` (per steradian) along its axis `edge1` (unit), attenuated
    /// off the axis by glTF's spot falloff, clamp(cos * edge2[0] + edge2[1], 0, 1)^2 (a point
    /// light: edge2 = [0, 1]). Next-event estimation alone finds it (`light::punctual`).
    pub const PUNCTUAL: u32 = 3;
    /// A directional light (glTF's "directional"; pbrt-v4's `DistantLight`): irradiance
    /// `radiance` arriving along `edge1` (unit: the direction the light travels) from beyond
    /// the sphere `position`, `radius` that bounds the scene. Next-event estimation alone
    /// finds it (`light::directional`).
    pub const DIRECTIONAL: u32 = 4;
}

/// An area light: the light table lists every emissive sphere and every emissive triangle.
/// 112 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Light {
    /// SPHERE: the centre. TRIANGLE: the vertex p0.
    pub position: [f32; 3],
    /// SPHERE: the radius (0 for a triangle).
    pub radius: f32,
    /// TRIANGLE: p1 - p0 and p2 - p0, the triangle's own edges (`Triangle::edge1`, `edge2`).
    pub edge1: [f32; 3],
    /// One of [`light_kind`].
    pub kind: u32,
    pub edge2: [f32; 3],
    /// TRIANGLE: 1 if both faces emit, 0 for the front face alone.
    pub two_sided: u32,
    /// Emitted radiance, uniform over the emitting surface and all outgoing directions.
    pub radiance: [f32; 3],
    /// Probability of choosing this light in next-event estimation.
    pub select_pmf: f32,
    /// Alias table (Walker; Vose's construction): slot i of n keeps light i with this
    /// probability, else gives [`Light::alias`]. See `light::choose_light`.
    pub alias_threshold: f32,
    /// The light slot i gives when it does not keep light i.
    pub alias: u32,
    /// TRIANGLE: the area |edge1 x edge2| / 2.
    pub area: f32,
    /// TRIANGLE: a bound on the rounding error of any point sampled on it, which sizes the lift
    /// of shadow rays' ends off it (`geometry::triangle_light_point_error`).
    pub point_error: f32,
    /// TRIANGLE with `emission_texture`: the texture coordinates of p0, p1 and p2.
    pub uv: [f32; 6],
    /// TRIANGLE: the texture multiplying `radiance` (`Material::textures[EMISSION]`), or
    /// [`NONE`].
    pub emission_texture: u32,
    /// TRIANGLE: its material, whose holes (`Material::opacity`) weigh its light samples
    /// (`crate::opacity::coverage`); [`NONE`] for every other kind.
    pub material: u32,
}

/// Pinhole or thin-lens camera: a ray through image-plane point (x, y) in [-1, 1]^2 (y up) has
/// the pinhole direction `forward + x * right + y * up`, where `right` and `up` already carry
/// the half-extents tan(vfov/2) * aspect and tan(vfov/2); `eye[3]` is the lens radius (0: a
/// pinhole) and `forward[3]` the focus distance along `forward` (`camera::thin_lens_ray`).
/// 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Camera {
    pub eye: [f32; 4],
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
}

/// How Russian roulette picks the survival probability q of a path's extension.
pub mod roulette {
    /// The seed's constant q (`IntegratorParams::rr_probability`) at every vertex.
    pub const CONSTANT: u32 = 0;
    /// q = min(1, max component of the path throughput), from `rr_start_depth` on.
    pub const THROUGHPUT: u32 = 1;
}

/// How next-event estimation and BRDF sampling of lights are combined.
pub mod mis {
    /// The seed's constant weights: 1/2 for each strategy.
    pub const HALF: u32 = 0;
    /// Veach's power heuristic (beta = 2).
    pub const POWER: u32 = 1;
    /// Light sampling alone: a light found by BSDF sampling adds nothing, unless the direction
    /// was a delta lobe's, which light sampling cannot find (for comparisons, not renders).
    pub const LIGHT_ONLY: u32 = 2;
    /// BSDF sampling alone: no next-event estimation (for comparisons, not renders).
    pub const BSDF_ONLY: u32 = 3;
}

/// How a point on a light is chosen for next-event estimation.
pub mod light_sampling {
    /// A uniform point on the light's surface: the seed's way for spheres (half of the points
    /// face away), and uniform in area for triangles.
    pub const AREA: u32 = 0;
    /// By the solid angle the light subtends: a direction uniform in the cone of a sphere
    /// (pbrt-v4 `Sphere::Sample`; area sampling from inside it), uniform in the spherical
    /// triangle of a triangle (Arvo 1995) where its solid angle is neither tiny nor nearly a
    /// hemisphere (`spherical_triangle::USES_SOLID_ANGLE`; area sampling otherwise).
    pub const SOLID_ANGLE: u32 = 1;
}

/// How next-event estimation picks one of several lights (the host fills the light table's
/// `select_pmf` and alias table accordingly; the kernel only reads them).
pub mod light_selection {
    /// The seed's uniform choice: 1 / number of lights.
    pub const UNIFORM: u32 = 0;
    /// Proportional to emitted power (radiance luminance x area), by an alias table.
    pub const POWER: u32 = 1;
}

/// Where a sample's random numbers come from.
pub mod sampler {
    /// Independent uniform numbers, a hash of (seed, pixel, sample, dimension) (`hash::pcg4d`).
    pub const INDEPENDENT: u32 = 0;
    /// Owen-scrambled Sobol points, two dimensions at a time (`sobol::sobol_pair`): stratified
    /// within each pixel, independent across pixels. The host's default.
    pub const SOBOL: u32 = 1;
}

/// Everything a launch of the kernel needs besides the scene's tables, one part per concern:
/// the camera, which samples of which image, how a path is estimated, adaptive sampling, and
/// what rays that leave the scene see, and where paths split. 192 bytes; every part is 4-byte
/// words, so the host's `repr(C)` layout is the std430 layout the GPU reads (checked by
/// `tests/tests/spirv_module.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct RenderParams {
    pub camera: Camera,
    pub samples: SampleParams,
    pub integrator: IntegratorParams,
    pub adaptive: AdaptiveParams,
    pub environment: EnvironmentParams,
    pub split: SplitParams,
}

/// Which samples a launch computes: the image's size, and samples `first..first + count` of
/// every pixel, numbered from `seed` by `sampler`. 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct SampleParams {
    pub width: u32,
    pub height: u32,
    pub seed: u32,
    /// Index of the first sample of this launch (progressive rendering).
    pub first: u32,
    /// Samples per pixel in this launch.
    pub count: u32,
    /// One of [`sampler`].
    pub sampler: u32,
}

/// How a path is estimated: next-event estimation, its combination with BSDF sampling, Russian
/// roulette and the depth bound. 28 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct IntegratorParams {
    /// Entries of the light table.
    pub light_count: u32,
    /// One of [`roulette`].
    pub rr_mode: u32,
    /// Constant survival probability for [`roulette::CONSTANT`], in (0, 1].
    pub rr_probability: f32,
    /// Number of path vertices that always continue before roulette applies (0: from the first).
    pub rr_start_depth: u32,
    /// One of [`mis`].
    pub mis_mode: u32,
    /// Hard bound on path vertices, a guard against endless paths (`u32::MAX`: none).
    pub max_depth: u32,
    /// One of [`light_sampling`].
    pub light_sampling: u32,
}

/// Adaptive sampling's constants (see `adaptive`). 12 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct AdaptiveParams {
    /// Target relative standard error of a pixel's mean (0: off, every pixel gets every
    /// sample).
    pub target: f32,
    /// Every `pilot_period`-th sample index is a pilot sample: it estimates the pixel's error
    /// and is not part of the image (0: no pilots).
    pub pilot_period: u32,
    /// Pilot samples a pixel needs before it may be declared converged.
    pub min_pilot_samples: u32,
}

/// Whether and how paths split at their first vertex (`crate::split`). 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct SplitParams {
    /// One of [`split_mode`].
    pub mode: u32,
    /// The side of a tile of the split table, in pixels.
    pub tile_size: u32,
    /// Tiles per row of the split table: `width.div_ceil(tile_size)`.
    pub tile_columns: u32,
    pub _pad: u32,
}

/// How a path treats its first vertex (`crate::split`).
pub mod split_mode {
    /// One continuation: the path as it always was.
    pub const OFF: u32 = 0;
    /// As many continuations as the split table gives the pixel's tile.
    pub const TABLE: u32 = 1;
    /// The pilot's measurement: two continuations, and the sample's value is what the pilot
    /// reads (`crate::split::pilot_value`), not radiance.
    pub const PILOT: u32 = 2;
}

/// What rays that leave the scene see: the uniform `background`, or the environment map
/// (`environment`), whose texels and sampling tables are the environment table. 48 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct EnvironmentParams {
    /// Uniform radiance seen by rays that leave the scene, where there is no map.
    pub background: [f32; 4],
    /// The map's width and height in texels (0 x 0: none).
    pub width: u32,
    pub height: u32,
    /// Index of the map in the light table, or [`NONE`].
    pub light: u32,
    /// Factor on every texel.
    pub scale: f32,
    /// Cosine and sine of the map's rotation about +y.
    pub rotation: [f32; 2],
    /// The medium outside every closed shape, the camera's (an index into the media table,
    /// `crate::medium`; 0: vacuum).
    pub medium: u32,
    pub _pad: u32,
}
