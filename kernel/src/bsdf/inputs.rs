//! [`BsdfNumbers`]: the numbers of a material that `bsdf::eval_v3` and `bsdf::sample_v3` read,
//! over any scalar [`Real`], so that the scattering is written once and runs on the `f32` the
//! GPU and the CPU compute with, or on a test's interval type that bounds what a Vulkan device's
//! arithmetic may make of it (`tests/src/device_class.rs`, `bsdf_apart`). A [`Material`] is
//! them over `f32` as it is (read in place: the renderer copies nothing); [`BsdfInputs`] holds
//! them over any `R`.
//!
//! Invariant: every number is the material's as it is (an exact input), or one the kernel
//! computes from others before the scattering reads it (glTF's resolved Kd, Ks and alpha:
//! `metallic_roughness::resolve_v3`; the coat's weight and alpha,
//! [`BsdfNumbers::coat_weight`], [`BsdfNumbers::coat_alpha`]) computed over `R` in the
//! operations of its `f32` form, so that over `f32` they are the `Material` methods' numbers
//! bit for bit.

use crate::real::{Real, V3};
use crate::scene::Material;
use spirv_std::glam::Vec3;

/// What the scattering reads of a material, over `R` (see the module's doc).
pub trait BsdfNumbers<R: Real<Bits = u32>> {
    /// `scene::material_kind`.
    fn kind(&self) -> u32;
    /// Kd, a Lambertian lobe's albedo.
    fn albedo(&self) -> V3<R>;
    /// Ks, a glossy lobe's F0 or a constant conductor's reflectance.
    fn specular(&self) -> V3<R>;
    /// GGX alpha of the glossy, conducting or dielectric lobe.
    fn alpha(&self) -> R;
    /// glTF's metalness (the glossy lobe's F90 blends toward 1 by it).
    fn metallic(&self) -> R;
    /// The dielectric layer's reflectance at normal incidence (`mixture`'s layer).
    fn layer_f0(&self) -> V3<R>;
    /// The dielectric layer's reflectance at grazing incidence.
    fn layer_f90(&self) -> R;
    /// A conductor's complex index, real part (all zero: the constant reflectance
    /// `specular`); glTF's sheen colour (`Material::sheen_colour`).
    fn eta(&self) -> V3<R>;
    /// A conductor's complex index, imaginary part.
    fn k(&self) -> V3<R>;
    /// The packed clear coat (`Material::pack_coat`; 0: none).
    fn coat(&self) -> u32;

    /// `Material::is_complex_conductor`: eta's first channel positive.
    #[inline]
    fn is_complex_conductor(&self) -> bool {
        self.eta().x.greater_than(R::splat(0.0)) != 0
    }

    /// `Material::coat_weight`, over `R`: the 16-bit weight (exact as a float) times 1 / 65535.
    #[inline]
    fn coat_weight(&self) -> R {
        R::splat((self.coat() & 0xffff) as f32) * R::splat(1.0 / 65535.0)
    }

    /// `Material::coat_alpha`, over `R`: the coat's roughness, computed as
    /// `Material::coat_roughness` does, squared.
    #[inline]
    fn coat_alpha(&self) -> R {
        let r = R::splat((self.coat() >> 16) as f32) * R::splat(1.0 / 65535.0);
        r * r
    }

    /// `Material::sheen_colour`: stored in `eta`.
    #[inline]
    fn sheen_colour(&self) -> V3<R> {
        self.eta()
    }
}

/// A material's numbers read in place: `f32` as the renderer computes.
impl BsdfNumbers<f32> for Material {
    #[inline]
    fn kind(&self) -> u32 {
        self.kind
    }
    #[inline]
    fn albedo(&self) -> V3<f32> {
        Vec3::from(self.albedo).into()
    }
    #[inline]
    fn specular(&self) -> V3<f32> {
        Vec3::from(self.specular).into()
    }
    #[inline]
    fn alpha(&self) -> f32 {
        self.alpha
    }
    #[inline]
    fn metallic(&self) -> f32 {
        self.metallic
    }
    #[inline]
    fn layer_f0(&self) -> V3<f32> {
        Vec3::from(self.layer_f0).into()
    }
    #[inline]
    fn layer_f90(&self) -> f32 {
        self.layer_f90
    }
    #[inline]
    fn eta(&self) -> V3<f32> {
        Vec3::from(self.eta).into()
    }
    #[inline]
    fn k(&self) -> V3<f32> {
        Vec3::from(self.k).into()
    }
    #[inline]
    fn coat(&self) -> u32 {
        self.coat
    }
}

/// A material's scattering numbers held over `R` (see the module's doc).
#[derive(Clone, Copy, Debug)]
pub struct BsdfInputs<R> {
    /// `scene::material_kind`.
    pub kind: u32,
    /// Kd, a Lambertian lobe's albedo.
    pub albedo: V3<R>,
    /// Ks, a glossy lobe's F0 or a constant conductor's reflectance.
    pub specular: V3<R>,
    /// GGX alpha of the glossy, conducting or dielectric lobe.
    pub alpha: R,
    /// glTF's metalness (the glossy lobe's F90 blends toward 1 by it).
    pub metallic: R,
    /// The dielectric layer's reflectance at normal incidence (`mixture`'s layer).
    pub layer_f0: V3<R>,
    /// The dielectric layer's reflectance at grazing incidence.
    pub layer_f90: R,
    /// A conductor's complex index, real part (all zero: the constant reflectance
    /// `specular`); glTF's sheen colour (`Material::sheen_colour`).
    pub eta: V3<R>,
    /// A conductor's complex index, imaginary part.
    pub k: V3<R>,
    /// The packed clear coat (`Material::pack_coat`; 0: none).
    pub coat: u32,
}

impl<R: Real> BsdfInputs<R> {
    /// The numbers of `m` as they are.
    #[inline]
    pub fn of(m: &Material) -> Self {
        Self {
            kind: m.kind,
            albedo: V3::splat(Vec3::from(m.albedo)),
            specular: V3::splat(Vec3::from(m.specular)),
            alpha: R::splat(m.alpha),
            metallic: R::splat(m.metallic),
            layer_f0: V3::splat(Vec3::from(m.layer_f0)),
            layer_f90: R::splat(m.layer_f90),
            eta: V3::splat(Vec3::from(m.eta)),
            k: V3::splat(Vec3::from(m.k)),
            coat: m.coat,
        }
    }
}

impl<R: Real<Bits = u32>> BsdfNumbers<R> for BsdfInputs<R> {
    #[inline]
    fn kind(&self) -> u32 {
        self.kind
    }
    #[inline]
    fn albedo(&self) -> V3<R> {
        self.albedo
    }
    #[inline]
    fn specular(&self) -> V3<R> {
        self.specular
    }
    #[inline]
    fn alpha(&self) -> R {
        self.alpha
    }
    #[inline]
    fn metallic(&self) -> R {
        self.metallic
    }
    #[inline]
    fn layer_f0(&self) -> V3<R> {
        self.layer_f0
    }
    #[inline]
    fn layer_f90(&self) -> R {
        self.layer_f90
    }
    #[inline]
    fn eta(&self) -> V3<R> {
        self.eta
    }
    #[inline]
    fn k(&self) -> V3<R> {
        self.k
    }
    #[inline]
    fn coat(&self) -> u32 {
        self.coat
    }
}
