//! glTF's sheen (`KHR_materials_sheen`) over the metallic-roughness material, as Cycles'
//! Principled sheen renders it, which Blender's exporter writes the extension for: the light a
//! layer of fibres standing along the normal reflects (Zeltner, Burley and Chiang, "Practical
//! Multiple-Scattering Sheen Using Linearly Transformed Cosines", SIGGRAPH 2022), over the
//! material, which keeps what the sheen does not reflect:
//!
//! ```text
//! f cos_i = sheenColor R D(M^-1 w / |M^-1 w|) A^2 / |M^-1 w|^3  +  (1 - s) f_material cos_i
//! ```
//!
//! in the frame (x, y, n) with x along `wo`'s projection onto the surface, w = `wi` in it;
//! M^-1 = [[A, 0, B], [0, A, 0], [0, 0, 1]], D(w) = max(0, w_z) / pi. A linearly transformed
//! cosine (Heitz, Dupuy, Hill and Neubelt, "Real-Time Polygonal-Light Shading with Linearly
//! Transformed Cosines", 2016) integrates to 1 over the sphere for any A > 0, B: the lobe
//! reflects exactly sheenColor x R of the light arriving from everywhere, and sampling it is a
//! cosine sample mapped by M (`sample`), its density the normalised lobe. (A, B, R) depend on
//! the view cosine and the sheen roughness: the sheen table (`texture::sheen_ltc`), derived by
//! `twinpath_tests::sheen_fit` from the fibre layer's physics: R is the probability that light
//! from `wo` leaves the layer upward, (A, B) the transformed cosine closest to the layer's
//! reflection. The material below is weighed by 1 - s, s = max over channels of sheenColor x
//! R, what Cycles' layering takes (`closure_layering_weight`): a white sheen over a white
//! Lambertian material reflects exactly 1 in a white furnace (tested). As there, the weights
//! depend on `wo` alone, so the sheen is not reciprocal. The extension's own suggestion (the
//! "Charlie" distribution of Estevez and Kulla 2017) differs from Cycles' sheen by factors of 2
//! and more; `docs/materials.md` gives the numbers.
//!
//! Sampling (`mixture`): the sheen is chosen with probability s, so the material's lobes keep
//! their weights ((1 - s) / (1 - s)).

use crate::frame::orthonormal_basis_v3;
use crate::real::{Real, V3};
use crate::sampling::sample_cosine_hemisphere_v3;
use core::f32::consts::PI;
use spirv_std::glam::Vec3;

/// A sheen at a point seen from `wo`: its colour times its reflectance R, the weight s with
/// which it is chosen and takes from the material below, and its transform (A, B).
#[derive(Clone, Copy, Debug)]
pub struct Sheen<R> {
    pub reflectance: V3<R>,
    pub weight: R,
    pub a: R,
    pub b: R,
}

impl<R: Real> Sheen<R> {
    /// No sheen.
    #[inline]
    pub fn none() -> Self {
        Self {
            reflectance: V3::splat(Vec3::ZERO),
            weight: R::splat(0.0),
            a: R::splat(1.0),
            b: R::splat(0.0),
        }
    }
}

/// The sheen of colour `colour` whose lobe at the point and view is `ltc` = (A, B, R)
/// (`GlossyAlbedo::sheen`); none where R or A is not positive.
#[inline]
pub fn at<R: Real<Bits = u32>>(colour: V3<R>, ltc: V3<R>) -> Sheen<R> {
    let zero = R::splat(0.0);
    if ltc.z.greater_than(zero) == 0 || ltc.x.greater_than(zero) == 0 {
        return Sheen::none();
    }
    let reflectance = colour * ltc.z;
    Sheen {
        reflectance,
        weight: reflectance.max_element().min(R::splat(1.0)),
        a: ltc.x,
        b: ltc.y,
    }
}

/// The frame (x, y) around `n` with x along `wo`'s projection onto the surface (any, where
/// `wo` is the normal: the lobe is then symmetric about it, B being 0 at normal view).
#[inline]
fn frame<R: Real<Bits = u32>>(n: V3<R>, wo: V3<R>) -> (V3<R>, V3<R>) {
    let tangential = wo - n * n.dot(wo);
    let length2 = tangential.length_squared();
    if length2.greater_than(R::splat(1e-12)) != 0 {
        let x = tangential / length2.sqrt();
        (x, n.cross(x))
    } else {
        orthonormal_basis_v3(n)
    }
}

/// The normalised lobe's density at `wi` (per unit solid angle): D(w') A^2 / |M^-1 w|^3.
#[inline]
pub fn pdf<R: Real<Bits = u32>>(sheen: &Sheen<R>, n: V3<R>, wo: V3<R>, wi: V3<R>) -> R {
    let zero = R::splat(0.0);
    let (x, y) = frame(n, wo);
    let (wx, wy, wz) = (wi.dot(x), wi.dot(y), wi.dot(n));
    let v = V3::new(sheen.a * wx + sheen.b * wz, sheen.a * wy, wz);
    let length = v.length();
    if wz.greater_than(zero) == 0 || length.greater_than(zero) == 0 {
        return zero;
    }
    let cos = v.z / length;
    cos.max(zero) * R::splat(1.0 / PI) * sheen.a * sheen.a / (length * length * length)
}

/// The sheen's f cos_i from `wo` to `wi` (before the layering) and its density.
#[inline]
pub fn eval<R: Real<Bits = u32>>(sheen: &Sheen<R>, n: V3<R>, wo: V3<R>, wi: V3<R>) -> (V3<R>, R) {
    let p = pdf(sheen, n, wo, wi);
    (sheen.reflectance * p, p)
}

/// A direction drawn from the normalised lobe with (u1, u2): w' cosine-distributed about z,
/// then w = M w' = (w'_x / A - B w'_z / A, w'_y / A, w'_z) normalised.
#[inline]
pub fn sample<R: Real<Bits = u32>>(sheen: &Sheen<R>, n: V3<R>, wo: V3<R>, u1: R, u2: R) -> V3<R> {
    let (x, y) = frame(n, wo);
    let w = sample_cosine_hemisphere_v3(V3::splat(Vec3::Z), u1, u2);
    let inverse_a = R::splat(1.0) / sheen.a;
    let local = V3::new((w.x - sheen.b * w.z) * inverse_a, w.y * inverse_a, w.z).normalize();
    x * local.x + y * local.y + n * local.z
}
