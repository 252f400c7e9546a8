//! glTF's clear coat (`KHR_materials_clearcoat`) over the metallic-roughness material: a
//! dielectric GGX layer of index 1.5 that reflects c of the light arriving from everywhere
//! toward `wo` (its directional albedo with the exact Fresnel reflectance F of the dielectric at
//! each microfacet, `fresnel::dielectric`) and lets 1 - c of the material below through:
//!
//! ```text
//! f = (1 - c) f_material + k clearcoatFactor F(wo . h) D G2 / (4 |n.wo| |n.wi|)
//! ```
//!
//! (alpha_c = coat roughness^2; k the multiple-scattering factor below).
//!
//! The extension defines `fresnel_coat(normal, 1.5, weight, base, layer) = mix(base, layer,
//! weight fr)` with fr = 0.04 + 0.96 (1 - n . wo)^5, Schlick's approximation of F at the mean
//! normal, and a layer (Appendix B's D and height-correlated visibility) without a Fresnel
//! factor of its own. Cycles' coat, which Blender's exporter writes the extension for, is a
//! dielectric microfacet lobe reflecting by the exact F at each microfacet, F(wo . h), over a
//! base weighed by 1 - (the coat's albedo). twinpath follows Cycles: Schlick's F falls 17-21%
//! below the exact one between 45 and 60 degrees (0.070 against 0.089 at 60), which made a
//! coat's reflections that much darker than Cycles' (measured: `docs/gltf.md`); for a smooth
//! coat (h = n) the two forms differ only by that F. Like the extension, the weight depends
//! on `wo` alone, so the coated BSDF is not reciprocal. The coat uses the point's shading
//! normal (the extension's `clearcoatNormalTexture` is not read). Its rough lobe gets its
//! multiple scattering back as the material's does (`multiple_scattering::coat_factor`, F_avg
//! the dielectric's), as Cycles' coat does: without it a rough coat over a white base lost up
//! to 10% of the light at grazing angles in a white furnace, where Cycles keeps it. The albedo
//! from `wo` is (1 - c) A_material + c <= 1, exactly 1 over a white material (tested): taking
//! the base's share from the coat's albedo c rather than from F(n . wo) is what keeps a rough
//! coat's energy at grazing angles (with F(n . wo), 0.73 where Cycles gives 0.82 over a base of
//! 0.8 in a white furnace). A smooth coat's albedo is F(n . wo) itself; a rough one's comes from
//! the GGX albedo table's third channel (`texture::ggx_albedo`).
//!
//! Sampling (`mixture`): the coat is chosen with probability exactly c, so the material's own
//! lobes keep their weights (their (1 - c) / (1 - c) is 1); a rough coat draws a visible
//! normal of alpha_c (its weight f / pdf of the whole mixture), a smooth one (alpha_c below
//! `DELTA_ALPHA`) is a mirror of weight c / c = 1.

use super::fresnel::dielectric;
use super::inputs::BsdfNumbers;
use super::microfacet::{reflection_height_correlated, Reflection};
use super::multiple_scattering::{coat_factor, GlossyAlbedo};
use super::DELTA_ALPHA;
use crate::real::{Real, V3};

/// The coat's index of refraction (the extension's; `KHR_materials_clearcoat_ior` is not
/// read).
pub const COAT_IOR: f32 = 1.5;

/// A clear coat at a point seen from `wo`: its weight c, what it reflects of light from
/// everywhere (the probability with which the mixture samples it, [`at`]), and its GGX alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat<R> {
    pub weight: R,
    pub alpha: R,
}

impl<R: Real> Coat<R> {
    /// No coat.
    #[inline]
    pub fn none() -> Self {
        Self {
            weight: R::splat(0.0),
            alpha: R::splat(0.0),
        }
    }
}

/// The coat of material `m` seen at cosine `cos_o` > 0 with the point's GGX albedos `albedo`
/// (`surface::glossy_albedo`): its weight c, what its lobe reflects of light from everywhere,
/// clearcoatFactor x F(cos_o) for a smooth coat and clearcoatFactor x k x the table's coat
/// albedo for a rough one (k its multiple-scattering factor); weight 0 without a coat.
#[inline]
pub fn at<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    cos_o: R,
    albedo: GlossyAlbedo<R>,
) -> Coat<R> {
    let factor = m.coat_weight();
    let alpha = m.coat_alpha();
    let weight = if alpha.less_than(R::splat(DELTA_ALPHA)) != 0 {
        factor * dielectric(cos_o, R::splat(COAT_IOR)).0
    } else {
        factor * coat_factor(albedo) * albedo.coat_reflectance
    };
    Coat { weight, alpha }
}

/// The weight of the coat's rough lobe at microfacet normal `h`: clearcoatFactor x k x
/// F(wo . h), the dielectric's reflectance at the microfacet (Cycles' coat), k the
/// multiple-scattering factor of `albedo`.
#[inline]
pub fn lobe_weight<R: Real<Bits = u32>>(
    m: &impl BsdfNumbers<R>,
    wo: V3<R>,
    h: V3<R>,
    albedo: GlossyAlbedo<R>,
) -> R {
    m.coat_weight() * coat_factor(albedo) * dielectric(wo.dot(h), R::splat(COAT_IOR)).0
}

/// The coat's rough reflection from `wo` to `wi` (cosines `cos_o`, `cos_i` > 0), unweighted:
/// D G2 / (4 cos_o) (times cos_i, `Reflection::value`) and the density of `wi` from its
/// visible-normal sampling.
#[inline]
pub fn reflection<R: Real<Bits = u32>>(
    coat: &Coat<R>,
    n: V3<R>,
    wo: V3<R>,
    wi: V3<R>,
    cos_o: R,
    cos_i: R,
) -> Reflection<R> {
    reflection_height_correlated(n, wo, wi, cos_o, cos_i, coat.alpha)
}
