//! Participating media (TOML `[media]`, `interior`, `[scene] medium`; glTF's
//! `KHR_materials_volume`): their records, the transmittance of a homogeneous segment, and
//! which medium a ray is in. A medium with a density grid (`crate::density_grid`) has its
//! coefficients per unit density and is tracked by `crate::delta_tracking`.
//!
//! A medium of absorption coefficient sigma_a and scattering coefficient sigma_s (per unit
//! length, per channel) has extinction sigma_t = sigma_a + sigma_s; light travelling a distance
//! d through it keeps T(d) = exp(-sigma_t d) of itself (Beer-Lambert; pbrt-v4, 4th ed., section
//! 11.2). A medium that only absorbs scatters nothing toward the camera, so its transmittance
//! multiplies a path's throughput exactly; one that scatters is sampled (`crate::free_flight`,
//! `crate::phase`).
//!
//! Where a path is: its `PathState::medium`, an index into the media table; record 0 is
//! [`VACUUM`]. Outside every closed shape a ray is in the scene's medium
//! (`EnvironmentParams::medium`: the camera's, a fog; vacuum by default). A dielectric's
//! `Material::interior_medium` is the medium inside it and `Material::exterior_medium` the one
//! outside (pbrt-v4's medium interface per shape; the scene's unless the shape names one); a ray
//! leaving one of its surfaces toward its inside (against the outward normal) travels in the
//! inside medium, one leaving toward its outside in the outside one ([`beyond`]): entering,
//! leaving, and reflecting on either side follow from that one rule. Any other surface leaves
//! the medium as it is. So nested shapes (glass in water) name the medium around them; shapes
//! must not overlap.
//!
//! An interface ([`is_interface`], TOML's `interface = true`) is a smooth dielectric of index
//! 1: it neither reflects nor bends, so light crosses it with weight exactly 1 and it is no
//! scattering event at all, only the place where the medium changes. Paths and shadow rays
//! therefore pass through it (pbrt-v4's surfaces without a material, `TraceTransmittance`,
//! section 14.1): an extension ray that meets one continues from the far side in the medium
//! beyond, keeping the vertex it left and the density it was drawn with (a light it finds is
//! weighed against next-event estimation from that vertex), and a shadow segment that meets
//! one continues from the far side with the transmittance of the part it crossed.

use crate::bsdf::DELTA_ALPHA;
use crate::real::{Exponential, V3};
use crate::scene::{material_kind, Material};
use spirv_std::glam::Vec3;

/// The media table's record 0: no medium (every coefficient zero).
pub const VACUUM: u32 = 0;

/// A medium: coefficients per scene unit of length (per unit density where it has a grid),
/// linear RGB, the Henyey-Greenstein asymmetry of its phase function (`crate::phase`), and its
/// density grid. 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(target_arch = "spirv"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C)]
pub struct Medium {
    /// The absorption coefficient sigma_a.
    pub sigma_a: [f32; 3],
    /// The phase function's asymmetry g in (-1, 1): 0 isotropic, positive forward.
    pub g: f32,
    /// The scattering coefficient sigma_s.
    pub sigma_s: [f32; 3],
    /// The word of its density grid's record in the grid table (`crate::density_grid`), or 0:
    /// homogeneous (density 1 everywhere).
    pub grid: u32,
}

impl Medium {
    /// Record 0 of every media table.
    pub const VACUUM: Self = Self::new([0.0; 3], [0.0; 3], 0.0);

    /// The medium of absorption `sigma_a`, scattering `sigma_s` and asymmetry `g`.
    pub const fn new(sigma_a: [f32; 3], sigma_s: [f32; 3], g: f32) -> Self {
        Self {
            sigma_a,
            g,
            sigma_s,
            grid: 0,
        }
    }

    /// This medium with the density grid whose record is at word `record` of the grid table.
    pub const fn with_grid(self, record: u32) -> Self {
        Self {
            grid: record,
            ..self
        }
    }

    /// Whether its density varies (a grid), else it is homogeneous.
    #[inline]
    pub fn has_grid(&self) -> bool {
        self.grid != 0
    }

    /// sigma_t = sigma_a + sigma_s per channel.
    #[inline]
    pub fn extinction(&self) -> Vec3 {
        Vec3::from(self.sigma_a) + Vec3::from(self.sigma_s)
    }

    /// Whether the medium scatters in some channel (else it only absorbs, or is vacuum).
    #[inline]
    pub fn scatters(&self) -> bool {
        self.sigma_s[0] > 0.0 || self.sigma_s[1] > 0.0 || self.sigma_s[2] > 0.0
    }

    /// Whether the medium attenuates light in some channel (else it is vacuum).
    #[inline]
    pub fn attenuates(&self) -> bool {
        self.extinction().max_element() > 0.0
    }
}

/// exp(-`sigma_t` x `distance`) per channel; `distance` may be `f32::MAX` (a ray that left
/// the scene): then 0 where the medium attenuates, 1 where it does not.
#[inline]
pub fn transmittance(sigma_t: Vec3, distance: f32) -> Vec3 {
    transmittance_v3(sigma_t.into(), distance).into()
}

/// [`transmittance`] over any [`Exponential`] number (the kernel's `f32`, or a test's model of
/// a device's arithmetic).
#[inline]
pub fn transmittance_v3<R: Exponential>(sigma_t: V3<R>, distance: R) -> V3<R> {
    let channel = |sigma: R| (-(sigma * distance)).exp();
    V3::new(channel(sigma_t.x), channel(sigma_t.y), channel(sigma_t.z))
}

/// The transmittance of the segment from `from` to `to` in homogeneous medium `medium` of
/// `media` (a segment between surfaces lies in one medium): 1 in vacuum. Exact for a homogeneous
/// medium, so a shadow segment needs no estimate of it (ratio tracking estimates what has no closed
/// form). Out of line on the CPU: only scenes with media call it.
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
pub fn along(media: &[Medium], medium: u32, from: Vec3, to: Vec3) -> Vec3 {
    let sigma_t = media[medium as usize].extinction();
    if sigma_t.max_element() > 0.0 {
        transmittance(sigma_t, (to - from).length())
    } else {
        Vec3::ONE
    }
}

/// Whether light crosses `material` unchanged: a dielectric of index exactly 1 that is smooth
/// (GGX alpha below `bsdf::DELTA_ALPHA`), whose only lobe is the straight transmission with
/// Fresnel reflectance 0 (see the module's documentation).
#[inline]
pub fn is_interface(material: &Material) -> bool {
    material.kind == material_kind::DIELECTRIC
        && material.ior == 1.0
        && material.alpha < DELTA_ALPHA
}

/// The medium a ray leaving the surface of `material` in direction `dir` travels through: for
/// a dielectric, the medium inside it where `dir` points against the surface's outward normal
/// `outward` and the medium outside it where it points along it (the one its shape names, else
/// the scene's, `outside`); for any other material, `current`, the medium the path is in. Out
/// of line on the CPU, as [`along`].
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
pub fn beyond(material: &Material, outward: Vec3, dir: Vec3, current: u32, outside: u32) -> u32 {
    if material.kind == material_kind::DIELECTRIC {
        if dir.dot(outward) < 0.0 {
            material.interior_medium()
        } else {
            material.exterior_medium(outside)
        }
    } else {
        current
    }
}
