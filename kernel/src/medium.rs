//! Absorbing media inside closed dielectric shapes (coloured glass, a drink; TOML `[media]`
//! with `interior`, glTF's `KHR_materials_volume`): light travelling a distance d through a
//! medium of absorption coefficient sigma_a (per unit length, per channel) keeps
//! exp(-sigma_a d) of itself (Beer-Lambert; pbrt-v4, 4th ed., section 11.2, the transmittance of
//! a homogeneous medium). Exact and without sampling: a medium that only absorbs has nothing
//! to scatter toward, so the transmittance multiplies the path's throughput.
//!
//! Where a path is: its `PathState::absorption`, the coefficient of the medium its current ray
//! travels through (zero outside every medium). A dielectric's `Material::k` holds the medium
//! inside it; a ray leaving one of its surfaces toward its inside (against the outward normal)
//! travels in that medium, one leaving toward its outside in none ([`beyond`]): entering,
//! leaving, and reflecting on either side follow from that one rule. Any other surface leaves
//! the medium as it is. Shapes with media must not overlap (the medium inside glass inside
//! another medium is the inner glass's alone).
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
use crate::scene::{material_kind, Material};
#[cfg(target_arch = "spirv")]
use crate::Float;
use spirv_std::glam::Vec3;

/// exp(-`absorption` x `distance`) per channel; `distance` may be `f32::MAX` (a ray that left
/// the scene): then 0 where the medium absorbs, 1 where it does not.
#[inline]
pub fn transmittance(absorption: Vec3, distance: f32) -> Vec3 {
    Vec3::new(
        (-(absorption.x * distance)).exp(),
        (-(absorption.y * distance)).exp(),
        (-(absorption.z * distance)).exp(),
    )
}

/// The transmittance of the segment from `from` to `to` in the medium of absorption
/// `absorption` (a shadow ray crosses no surface, so one medium): 1 outside every medium.
/// Out of line on the CPU: only scenes with media call it.
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
pub fn along(absorption: Vec3, from: Vec3, to: Vec3) -> Vec3 {
    if absorption.max_element() > 0.0 {
        transmittance(absorption, (to - from).length())
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

/// The absorption of the medium a ray leaving the surface of `material` in direction `dir`
/// travels through: for a dielectric, the medium inside it where `dir` points against the
/// surface's outward normal `outward` and none where it points along it; for any other
/// material, `current`, the medium the path is in. Out of line on the CPU, as [`along`].
#[cfg_attr(not(target_arch = "spirv"), inline(never))]
pub fn beyond(material: &Material, outward: Vec3, dir: Vec3, current: Vec3) -> Vec3 {
    if material.kind == material_kind::DIELECTRIC {
        if dir.dot(outward) < 0.0 {
            Vec3::from(material.interior_absorption())
        } else {
            Vec3::ZERO
        }
    } else {
        current
    }
}
