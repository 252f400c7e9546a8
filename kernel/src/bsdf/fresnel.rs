//! Fresnel reflectance: the fraction of light a smooth interface reflects, by the angle of
//! incidence. Derivations and sources: `docs/materials.md` ("Fresnel").

use crate::real::{Real, V3};
use spirv_std::glam::Vec3;

/// Schlick's approximation F0 + (1 - F0) (1 - cos)^5 (Schlick, "An Inexpensive BRDF Model for
/// Physically-based Rendering", Computer Graphics Forum 13(3), 1994, eq. 24), the seed's F with
/// F0 = Ks. `cos` is clamped to [0, 1].
#[inline]
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    schlick_f90(V3::from(f0), 1.0, cos).into()
}

/// Schlick's approximation with reflectance `f90` at grazing incidence instead of 1,
/// f0 + (f90 - f0) (1 - cos)^5 (`cos` clamped to [0, 1]): glTF's `KHR_materials_specular`
/// scales a dielectric's Fresnel curve by its specularFactor this way. With `f90` = 1 it is
/// [`schlick`] bit for bit. Over any scalar [`Real`], as the functions below.
#[inline]
pub fn schlick_f90<R: Real<Bits = u32>>(f0: V3<R>, f90: R, cos: R) -> V3<R> {
    let w = schlick_weight(cos);
    V3::new(
        f0.x + (f90 - f0.x) * w,
        f0.y + (f90 - f0.y) * w,
        f0.z + (f90 - f0.z) * w,
    )
}

/// [`schlick_f90`] of one channel, over any scalar [`Real`] (so that its error under a Vulkan
/// device's arithmetic can be bounded by running it on one: `tests/src/device_class.rs`).
#[inline]
pub fn schlick_f90_channel<R: Real<Bits = u32>>(f0: R, f90: R, cos: R) -> R {
    f0 + (f90 - f0) * schlick_weight(cos)
}

/// Schlick's weight (1 - cos)^5, `cos` clamped to [0, 1].
#[inline]
fn schlick_weight<R: Real<Bits = u32>>(cos: R) -> R {
    let m = R::splat(1.0) - unit_clamp(cos);
    let m2 = m * m;
    m2 * m2 * m
}

/// `x` clamped to [0, 1] (NaN stays NaN).
#[inline]
fn unit_clamp<R: Real>(x: R) -> R {
    x.clamp(R::splat(0.0), R::splat(1.0))
}

/// Unpolarised reflectance of a conductor of complex index of refraction eta + i k (relative to
/// the outside) for light arriving at cosine `cos` (clamped to [0, 1]); one channel.
///
/// With a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2) and
/// a^2 = (a^2 + b^2 + eta^2 - k^2 - sin^2) / 2, the s and p reflectances are
/// Rs = (a^2 + b^2 - 2 a cos + cos^2) / (a^2 + b^2 + 2 a cos + cos^2) and
/// Rp = Rs (cos^2 (a^2 + b^2) - 2 a cos sin^2 + sin^4)
///    / (cos^2 (a^2 + b^2) + 2 a cos sin^2 + sin^4)
/// (Born and Wolf, Principles of Optics, 14.2; the tan-free form multiplies the usual
/// a sin tan terms by cos^2). Equal to the complex-arithmetic Fresnel equations (tested in f64).
/// Generic over the scalar [`Real`] so that its error under a Vulkan device's arithmetic can be
/// bounded by running it on one (`tests/src/device_class.rs`).
#[inline]
pub fn conductor<R: Real<Bits = u32>>(cos: R, eta: R, k: R) -> R {
    let (half, two, four) = (R::splat(0.5), R::splat(2.0), R::splat(4.0));
    let c = unit_clamp(cos);
    let c2 = c * c;
    let s2 = R::splat(1.0) - c2;
    let (e2, k2) = (eta * eta, k * k);
    let t0 = e2 - k2 - s2;
    let a2b2 = (t0 * t0 + four * e2 * k2).sqrt();
    let a = (half * (a2b2 + t0)).max(R::splat(0.0)).sqrt();
    let t1 = a2b2 + c2;
    let t2 = two * a * c;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    half * (rs + rp)
}

/// [`conductor`] per RGB channel.
#[inline]
pub fn conductor_rgb<R: Real<Bits = u32>>(cos: R, eta: V3<R>, k: V3<R>) -> V3<R> {
    V3::new(
        conductor(cos, eta.x, k.x),
        conductor(cos, eta.y, k.y),
        conductor(cos, eta.z, k.z),
    )
}

/// Unpolarised reflectance of a smooth dielectric interface for light arriving at cosine `cos`
/// (in [0, 1], on the side it arrives from) when `eta` = index beyond / index on the arriving
/// side; with the cosine of the refracted direction (0 under total internal reflection, where
/// the reflectance is 1). Snell: sin_t^2 = (1 - cos^2) / eta^2;
/// rs = (cos - eta cos_t) / (cos + eta cos_t), rp = (eta cos - cos_t) / (eta cos + cos_t),
/// F = (rs^2 + rp^2) / 2 (Born and Wolf 1.5.2; pbrt-v4 9.3.1 `FrDielectric`).
/// Generic over the scalar [`Real`] as [`conductor`] is.
#[inline]
pub fn dielectric<R: Real<Bits = u32>>(cos: R, eta: R) -> (R, R) {
    let one = R::splat(1.0);
    let c = unit_clamp(cos);
    let sin2_t = (one - c * c) / (eta * eta);
    if sin2_t.at_least(one) != 0 {
        return (one, R::splat(0.0));
    }
    let cos_t = (one - sin2_t).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    (R::splat(0.5) * (rs * rs + rp * rp), cos_t)
}

/// 1 - [`dielectric`]'s reflectance, the transmitted fraction, computed without that
/// cancellation (it loses every digit near total internal reflection, where F -> 1):
/// 1 - rs^2 = 4 eta cos cos_t / (cos + eta cos_t)^2,
/// 1 - rp^2 = 4 eta cos cos_t / (eta cos + cos_t)^2.
/// `cos_t` is [`dielectric`]'s; 0 under total internal reflection.
/// Generic over the scalar [`Real`] as [`conductor`] is.
#[inline(always)]
pub fn dielectric_transmittance<R: Real<Bits = u32>>(cos: R, eta: R, cos_t: R) -> R {
    let c = unit_clamp(cos);
    let num = R::splat(4.0) * eta * c * cos_t;
    let s = c + eta * cos_t;
    let p = eta * c + cos_t;
    if num.greater_than(R::splat(0.0)) == 0 {
        return R::splat(0.0);
    }
    R::splat(0.5) * (num / (s * s) + num / (p * p))
}

/// The direction refracted from `wo` through an interface of unit normal `h` on `wo`'s side
/// (`cos_o` = wo . h >= 0), where `eta` = index beyond / index on `wo`'s side and `cos_t` the
/// refracted cosine ([`dielectric`]'s, nonzero): -wo / eta + (cos_o / eta - cos_t) h, a unit
/// vector on the far side (Snell's law in vector form; pbrt-v4 9.3.2 `Refract`).
#[inline]
pub fn refract<R: Real>(wo: V3<R>, h: V3<R>, cos_o: R, eta: R, cos_t: R) -> V3<R> {
    -wo / eta + h * (cos_o / eta - cos_t)
}
