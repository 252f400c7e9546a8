//! An f64 reference of the kernel's materials (`kernel::bsdf`), written from the papers in
//! forms other than the kernel's: GGX through tan and Smith's Lambda, Fresnel through complex
//! arithmetic (total internal reflection falls out of it), the refraction's BTDF in Walter et
//! al.'s notation with indices on both sides. The tests compare the kernel's f32 functions
//! with it; agreement means two derivations agree, not that one was copied.

use glam::DVec3;
use std::f64::consts::PI;

/// A complex number (enough for the Fresnel equations).
#[derive(Clone, Copy, Debug)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
    /// The principal square root (non-negative real part).
    fn sqrt(self) -> C {
        let r = (self.0 * self.0 + self.1 * self.1).sqrt();
        let re = ((r + self.0) / 2.0).max(0.0).sqrt();
        let im = ((r - self.0) / 2.0).max(0.0).sqrt();
        C(re, if self.1 < 0.0 { -im } else { im })
    }
    fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
}

/// Unpolarised Fresnel reflectance at cosine `cos` (>= 0) into a medium of complex relative
/// index eta + i k: Snell's law with a complex cosine, then the amplitudes
/// rs = (cos - n cos_t) / (cos + n cos_t), rp = (n cos - cos_t) / (n cos + cos_t).
pub fn fresnel(cos: f64, eta: f64, k: f64) -> f64 {
    let n = C(eta, k);
    let c = C(cos, 0.0);
    let sin2 = C(1.0 - cos * cos, 0.0);
    let cos_t = C(1.0, 0.0).sub(sin2.div(n.mul(n))).sqrt();
    let rs = c.sub(n.mul(cos_t)).div(c.add(n.mul(cos_t)));
    let rp = n.mul(c).sub(cos_t).div(n.mul(c).add(cos_t));
    (rs.norm2() + rp.norm2()) / 2.0
}

/// Schlick's approximation, per channel.
pub fn schlick(f0: DVec3, cos: f64) -> DVec3 {
    f0 + (DVec3::ONE - f0) * (1.0 - cos).powi(5)
}

/// GGX D through the tangent: 1 / (pi alpha^2 cos^4 (1 + tan^2 / alpha^2)^2).
pub fn ggx_d(cos: f64, alpha: f64) -> f64 {
    if cos <= 0.0 {
        return 0.0;
    }
    let tan2 = (1.0 - cos * cos) / (cos * cos);
    1.0 / (PI * alpha * alpha * cos.powi(4) * (1.0 + tan2 / (alpha * alpha)).powi(2))
}

/// Smith's G1 of GGX through Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2.
pub fn ggx_g1(cos: f64, alpha: f64) -> f64 {
    let c = cos.abs();
    let tan2 = (1.0 - c * c) / (c * c);
    let lambda = ((1.0 + alpha * alpha * tan2).sqrt() - 1.0) / 2.0;
    1.0 / (1.0 + lambda)
}

/// Smith's height-correlated G2 of GGX for cosines `co`, `ci` > 0 (Heitz 2014, eq. 99):
/// 1 / (1 + Lambda(co) + Lambda(ci)), Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2.
pub fn g2(co: f64, ci: f64, alpha: f64) -> f64 {
    let lambda = |c: f64| {
        let tan2 = (1.0 - c * c) / (c * c);
        ((1.0 + alpha * alpha * tan2).sqrt() - 1.0) / 2.0
    };
    1.0 / (1.0 + lambda(co) + lambda(ci))
}

/// A clear coat of weight `weight` and roughness `roughness` as the kernel stores them (16-bit
/// fixed point, `Material::pack_coat`) seen at cosine `co`: (its weight c, what the coat
/// reflects: weight F(co) for a smooth coat (alpha below 1e-3), weight k A for a rough one, A
/// the coat's albedo from the table and k its multiple-scattering factor; its alpha; k).
pub fn coat_at(weight: f64, roughness: f64, co: f64) -> (f64, f64, f64) {
    let q = |x: f64| (x * 65535.0).round() / 65535.0;
    if weight <= 0.0 {
        return (0.0, 0.0, 1.0);
    }
    let (w, r) = (q(weight), q(roughness));
    let alpha = r * r;
    if alpha < 1e-3 {
        return (w * fresnel(co, 1.5, 0.0), alpha, 1.0);
    }
    let (e, e_avg, a) = crate::ggx_table::reference_albedos(r, co);
    let f_avg = coat_fresnel_average();
    let f_ms = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
    let k = 1.0 + f_ms * (1.0 - e) / e;
    (w * k * a, alpha, k)
}

/// 2 \int_0^1 F(mu) mu dmu for the exact Fresnel reflectance of index 1.5 (midpoint rule,
/// 10^5 points, computed once).
pub fn coat_fresnel_average() -> f64 {
    static AVERAGE: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *AVERAGE.get_or_init(|| {
        let n = 100_000;
        (0..n)
            .map(|i| {
                let mu = (i as f64 + 0.5) / n as f64;
                2.0 * mu * fresnel(mu, 1.5, 0.0)
            })
            .sum::<f64>()
            / n as f64
    })
}

/// The sheen's lobe at a point (`kernel::bsdf::sheen`): colour x R, the weight s = max of it
/// (at most 1), and the transform M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the frame whose x
/// axis is wo's projection onto the surface.
pub struct SheenLobe {
    pub reflectance: DVec3,
    pub weight: f64,
    pub a: f64,
    pub b: f64,
}

impl SheenLobe {
    /// The transformed cosine's density at `wi` (Heitz et al. 2016: a direction w comes from
    /// the cosine-distributed w_o = M^-1 w / |M^-1 w|, with Jacobian |det M^-1| / |M^-1 w|^3).
    pub fn density(&self, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
        let tangent = wo - n * n.dot(wo);
        let x = if tangent.length() > 1e-9 {
            tangent.normalize()
        } else {
            n.any_orthonormal_vector()
        };
        let y = n.cross(x);
        let m_inverse = glam::DMat3::from_cols(
            DVec3::new(self.a, 0.0, 0.0),
            DVec3::new(0.0, self.a, 0.0),
            DVec3::new(self.b, 0.0, 1.0),
        );
        let w = DVec3::new(wi.dot(x), wi.dot(y), wi.dot(n));
        if w.z <= 0.0 {
            return 0.0;
        }
        let v = m_inverse * w;
        let length = v.length();
        (v.z / length).max(0.0) / PI * m_inverse.determinant().abs() / length.powi(3)
    }
}

/// The sheen of `colour` and `roughness` seen at cosine `co`, from the committed sheen table
/// read in f64 here (bilinear in roughness and mu between the nodes, clamped); none for a black
/// colour or a lobe of no reflectance.
pub fn sheen_at(colour: DVec3, roughness: f64, co: f64) -> Option<SheenLobe> {
    use twinpath::scene::sheen_ltc::{COSINES, LTC, ROUGHNESSES};
    if colour.max_element() <= 0.0 {
        return None;
    }
    let locate = |t: f64, n: usize| {
        let x = t.clamp(0.0, 1.0) * (n - 1) as f64;
        let i = (x.floor() as usize).min(n - 2);
        (i, x - i as f64)
    };
    let (i, fx) = locate(roughness, ROUGHNESSES);
    let (j, fy) = locate(co, COSINES);
    let at = |j: usize, i: usize, c: usize| LTC[j][i][c] as f64;
    let lerp = |c: usize| {
        let top = at(j, i, c) * (1.0 - fx) + at(j, i + 1, c) * fx;
        let bottom = at(j + 1, i, c) * (1.0 - fx) + at(j + 1, i + 1, c) * fx;
        top * (1.0 - fy) + bottom * fy
    };
    let (a, b, r) = (lerp(0), lerp(1), lerp(2));
    if !(r > 0.0 && a > 0.0) {
        return None;
    }
    let reflectance = colour.as_vec3().as_dvec3() * r;
    Some(SheenLobe {
        reflectance,
        weight: reflectance.max_element().min(1.0),
        a,
        b,
    })
}

/// A material of the reference, with the kernel's parameters.
#[derive(Clone, Copy, Debug)]
pub enum RefMaterial {
    /// Kd / pi + the GGX lobe with Schlick's F (F0 = ks).
    Glossy { kd: DVec3, ks: DVec3, alpha: f64 },
    /// GGX with a conductor's Fresnel (`eta`, `k`), or the constant `reflectance`.
    Conductor {
        eta: DVec3,
        k: DVec3,
        reflectance: Option<DVec3>,
        alpha: f64,
    },
    /// GGX reflection and refraction; `eta` = index beyond / index on wo's side.
    Dielectric { eta: f64, alpha: f64 },
    /// glTF 2.0's metallic-roughness material, written from the specification's Appendix B
    /// as it stands: mix(dielectric_brdf, metal_brdf, metallic) with
    /// dielectric_brdf = fresnel_mix(ior, diffuse(base), specular) and
    /// metal_brdf = specular * conductor_fresnel(f0 = base); alpha = roughness^2; with
    /// `KHR_materials_specular`'s fresnel_mix(f0_color = `specular_color`, ior,
    /// weight = `specular`, base, layer) (`KHR_materials_ior`: `ior`; 1.5, 1 and white
    /// without the extensions); under `KHR_materials_clearcoat`'s coat of weight `coat` and
    /// roughness `coat_roughness` (none at weight 0): fresnel_coat(normal, 1.5, coat, material,
    /// specular_brdf(coat_roughness^2)) with Cycles' layering: the layer weighed by coat k
    /// F(|wo . h|), F the exact reflectance of index 1.5 and k the lobe's multiple-scattering
    /// factor, the material by 1 - c, c the layer's albedo ([`coat_at`]; `kernel::bsdf::coat`
    /// says why); under the sheen (`sheen`, `sheen_roughness`): the fibre layer's transformed
    /// cosine over the rest weighed by 1 - s ([`sheen_at`]; `kernel::bsdf::sheen`).
    MetallicRoughness {
        base: DVec3,
        metallic: f64,
        roughness: f64,
        ior: f64,
        specular: f64,
        specular_color: DVec3,
        coat: f64,
        coat_roughness: f64,
        /// `KHR_materials_sheen`'s colour (zero: none) and roughness, over everything as
        /// Cycles layers it ([`sheen_at`]).
        sheen: DVec3,
        sheen_roughness: f64,
    },
}

impl RefMaterial {
    /// glTF's metallic-roughness material of base colour `base`, without the extensions: index
    /// 1.5, specular weight 1 and white, no clear coat.
    pub fn gltf(base: DVec3, metallic: f64, roughness: f64) -> Self {
        RefMaterial::MetallicRoughness {
            base,
            metallic,
            roughness,
            ior: 1.5,
            specular: 1.0,
            specular_color: DVec3::ONE,
            coat: 0.0,
            coat_roughness: 0.0,
            sheen: DVec3::ZERO,
            sheen_roughness: 0.0,
        }
    }

    /// This glTF material under a sheen of colour `colour` and roughness `roughness`.
    pub fn sheened(mut self, colour: DVec3, roughness: f64) -> Self {
        if let RefMaterial::MetallicRoughness {
            sheen,
            sheen_roughness,
            ..
        } = &mut self
        {
            (*sheen, *sheen_roughness) = (colour, roughness);
        }
        self
    }

    /// This glTF material under a clear coat of weight `weight` and roughness `roughness`.
    pub fn coated(mut self, weight: f64, roughness: f64) -> Self {
        if let RefMaterial::MetallicRoughness {
            coat,
            coat_roughness,
            ..
        } = &mut self
        {
            (*coat, *coat_roughness) = (weight, roughness);
        }
        self
    }

    /// The material as the kernel stores it.
    pub fn kernel(&self) -> kernel::scene::Material {
        use kernel::scene::{material_kind, Material};
        let f = |v: DVec3| v.as_vec3().to_array();
        match *self {
            RefMaterial::Glossy { kd, ks, alpha } => {
                let mut m = Material::diffuse(f(kd));
                m.kind = material_kind::GLOSSY;
                m.specular = f(ks);
                m.alpha = alpha as f32;
                m
            }
            RefMaterial::Conductor {
                eta,
                k,
                reflectance,
                alpha,
            } => {
                let mut m = Material::diffuse([0.0; 3]);
                m.kind = material_kind::CONDUCTOR;
                m.alpha = alpha as f32;
                match reflectance {
                    Some(r) => m.specular = f(r),
                    None => {
                        m.eta = f(eta);
                        m.k = f(k);
                    }
                }
                m
            }
            RefMaterial::Dielectric { alpha, eta } => {
                let mut m = Material::diffuse([0.0; 3]);
                m.kind = material_kind::DIELECTRIC;
                m.alpha = alpha as f32;
                m.ior = eta as f32;
                m
            }
            RefMaterial::MetallicRoughness {
                base,
                metallic,
                roughness,
                ior,
                specular,
                specular_color,
                coat,
                coat_roughness,
                sheen,
                sheen_roughness,
            } => {
                let mut m = Material::diffuse(f(base));
                m.set_sheen(f(sheen), sheen_roughness as f32);
                if coat > 0.0 {
                    m.coat = Material::pack_coat(coat as f32, coat_roughness as f32);
                }
                m.kind = material_kind::METALLIC_ROUGHNESS;
                m.metallic = metallic as f32;
                m.roughness = roughness as f32;
                let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
                m.layer_f0 = f((specular_color * f0).min(DVec3::ONE) * specular);
                m.layer_f90 = specular as f32;
                m
            }
        }
    }

    /// The material as `kernel::bsdf` receives it: [`RefMaterial::kernel`], with glTF's
    /// material resolved as `kernel::surface::shade` resolves it at a hit.
    pub fn kernel_at_hit(&self) -> kernel::scene::Material {
        let m = self.kernel();
        if m.kind == kernel::scene::material_kind::METALLIC_ROUGHNESS {
            kernel::bsdf::metallic_roughness::resolve(&m)
        } else {
            m
        }
    }

    /// The GGX alpha of the material's glossy lobe.
    pub fn alpha(&self) -> f64 {
        match *self {
            RefMaterial::Glossy { alpha, .. }
            | RefMaterial::Conductor { alpha, .. }
            | RefMaterial::Dielectric { alpha, .. } => alpha,
            RefMaterial::MetallicRoughness { roughness, .. } => roughness * roughness,
        }
    }

    /// The eta the kernel's functions take (the dielectric's, else 1).
    pub fn eta(&self) -> f64 {
        match *self {
            RefMaterial::Dielectric { eta, .. } => eta,
            _ => 1.0,
        }
    }

    /// The BSDF f(wo, wi) (not times the cosine), for unit `n` on wo's side.
    pub fn f(&self, n: DVec3, wo: DVec3, wi: DVec3) -> DVec3 {
        let (co, ci) = (n.dot(wo), n.dot(wi));
        if co <= 0.0 || ci == 0.0 {
            return DVec3::ZERO;
        }
        match *self {
            RefMaterial::MetallicRoughness {
                base,
                metallic,
                roughness,
                ior,
                specular: weight,
                specular_color,
                coat,
                coat_roughness,
                sheen,
                sheen_roughness,
            } => {
                if ci < 0.0 {
                    return DVec3::ZERO;
                }
                let (sheen_value, s) = match sheen_at(sheen, sheen_roughness, co) {
                    Some(l) => (l.reflectance * l.density(n, wo, wi) / ci, l.weight),
                    None => (DVec3::ZERO, 0.0),
                };
                let alpha = roughness * roughness;
                let h = (wo + wi).normalize();
                let voh = wo.dot(h).abs();
                // Appendix B's visibility: the height-correlated Smith G2 = 1 / (1 + Lambda(wo)
                // + Lambda(wi)), Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2 (Heitz 2014).
                let specular = ggx_d(n.dot(h), alpha) * g2(co, ci, alpha) / (4.0 * co * ci);
                let diffuse = base / PI;
                // fresnel_mix(f0_color, ior, weight, base, layer) =
                // (1 - weight max(fr)) base + weight fr layer, fr = f0 + (1 - f0)(1 - |VdotH|)^5,
                // f0 = min(((1 - ior) / (1 + ior))^2 f0_color, 1).
                let f0 = (specular_color * ((1.0 - ior) / (1.0 + ior)).powi(2)).min(DVec3::ONE);
                let fr = f0 + (DVec3::ONE - f0) * (1.0 - voh).powi(5);
                let metal_brdf = specular * (base + (DVec3::ONE - base) * (1.0 - voh).powi(5));
                // Multiple scattering given back (Turquin 2019, Kulla and Conty 2017): the
                // specular terms times 1 + F_ms (1 - E(co)) / E(co), F_ms from the lobes'
                // Fresnel averages F_avg = F0 + (F90 - F0) / 21; none for a mirror.
                let f_avg = |f0: DVec3, f90: f64| f0 + (DVec3::splat(f90) - f0) / 21.0;
                let fresnel_average =
                    f_avg(f0, 1.0) * weight * (1.0 - metallic) + f_avg(base, 1.0) * metallic;
                let factor = if alpha < 1e-3 {
                    DVec3::ONE
                } else {
                    let (e, e_avg) = crate::ggx_table::reference_albedo(roughness, co);
                    let f_ms =
                        fresnel_average * e_avg / (DVec3::ONE - fresnel_average * (1.0 - e_avg));
                    DVec3::ONE + f_ms * ((1.0 - e) / e)
                };
                let specular_part =
                    fr * (weight * specular) * (1.0 - metallic) + metal_brdf * metallic;
                let material = diffuse * (1.0 - weight * fr.max_element()) * (1.0 - metallic)
                    + specular_part * factor;
                let (c, alpha_c, k) = coat_at(coat, coat_roughness, co);
                if c == 0.0 {
                    return sheen_value + material * (1.0 - s);
                }
                // The coat's layer: Appendix B's specular_brdf times the coat's factor and the
                // exact Fresnel reflectance at the microfacet (a smooth coat is a delta lobe, in
                // no value).
                let layer = if alpha_c < 1e-3 {
                    0.0
                } else {
                    // Cycles' coat: the exact Fresnel at the microfacet.
                    let coat_at_h = (coat * 65535.0).round() / 65535.0 * k * fresnel(voh, 1.5, 0.0);
                    coat_at_h * ggx_d(n.dot(h), alpha_c) * g2(co, ci, alpha_c) / (4.0 * co * ci)
                };
                sheen_value + (material * (1.0 - c) + DVec3::splat(layer)) * (1.0 - s)
            }
            RefMaterial::Glossy { kd, ks, alpha } => {
                if ci < 0.0 {
                    return DVec3::ZERO;
                }
                let h = (wo + wi).normalize();
                let spec = ggx_d(n.dot(h), alpha) * ggx_g1(co, alpha) * ggx_g1(ci, alpha)
                    / (4.0 * co * ci);
                kd / PI + schlick(ks, wi.dot(h)) * spec
            }
            RefMaterial::Conductor {
                eta,
                k,
                reflectance,
                alpha,
            } => {
                if ci < 0.0 {
                    return DVec3::ZERO;
                }
                let h = (wo + wi).normalize();
                let c = wo.dot(h);
                let fr = reflectance.unwrap_or_else(|| {
                    DVec3::new(
                        fresnel(c, eta.x, k.x),
                        fresnel(c, eta.y, k.y),
                        fresnel(c, eta.z, k.z),
                    )
                });
                fr * (ggx_d(n.dot(h), alpha) * ggx_g1(co, alpha) * ggx_g1(ci, alpha)
                    / (4.0 * co * ci))
            }
            RefMaterial::Dielectric { eta, alpha } => {
                if ci > 0.0 {
                    let h = (wo + wi).normalize();
                    let fr = fresnel(wo.dot(h), eta, 0.0);
                    return DVec3::splat(
                        fr * ggx_d(n.dot(h), alpha) * ggx_g1(co, alpha) * ggx_g1(ci, alpha)
                            / (4.0 * co * ci),
                    );
                }
                // Walter et al. 2007, eq. 21, with i = wi (index eta_i = eta) and o = wo
                // (index eta_o = 1): h_t = -(eta_i i + eta_o o) / |.|, taken toward n.
                let (eta_i, eta_o) = (eta, 1.0);
                let mut h = -(eta_i * wi + eta_o * wo).normalize();
                if h.dot(n) < 0.0 {
                    h = -h;
                }
                let (ih, oh) = (wi.dot(h), wo.dot(h));
                if !(oh > 0.0 && ih < 0.0) {
                    return DVec3::ZERO;
                }
                // The Fresnel transmittance, from wo's side: from wi's it is the same in exact
                // arithmetic, but ill-conditioned where wo grazes the microfacet (Snell's
                // 1 - eta^2 sin^2 cancels), which f32 inputs then show.
                let t = 1.0 - fresnel(oh, eta_i / eta_o, 0.0);
                let g = ggx_g1(co, alpha) * ggx_g1(ci, alpha);
                DVec3::splat(
                    ih.abs() * oh.abs() / (ci.abs() * co.abs())
                        * eta_o
                        * eta_o
                        * t
                        * g
                        * ggx_d(n.dot(h), alpha)
                        / (eta_i * ih + eta_o * oh).powi(2),
                )
            }
        }
    }

    /// The density of the kernel's sampler for `wi` given `wo`: visible normals (Heitz 2014,
    /// D_wo(h) = G1(wo) max(0, wo . h) D(h) / cos_o), reflection's Jacobian 1 / (4 |wo . h|),
    /// refraction's eta_i^2 |wi . h| / (eta_i wi . h + eta_o wo . h)^2, the dielectric's
    /// choice by F, the mixture's by the kernel's lobe probability.
    pub fn pdf(&self, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
        let (co, ci) = (n.dot(wo), n.dot(wi));
        if co <= 0.0 {
            return 0.0;
        }
        let vndf = |h: DVec3, alpha: f64| {
            ggx_g1(co, alpha) * wo.dot(h).max(0.0) * ggx_d(n.dot(h), alpha) / co
        };
        let reflected = |alpha: f64| {
            let h = (wo + wi).normalize();
            vndf(h, alpha) / (4.0 * wo.dot(h).abs())
        };
        match *self {
            RefMaterial::MetallicRoughness {
                base,
                metallic,
                roughness,
                ior,
                specular,
                specular_color,
                coat,
                coat_roughness,
                sheen,
                sheen_roughness,
            } => {
                if ci <= 0.0 {
                    return 0.0;
                }
                // The kernel samples it as the Kd + Ks mixture of Kd = (1 - metallic) base,
                // F0 = lerp(layer F0, base, metallic) and F90 = lerp(specular, 1, metallic).
                let kd = base * (1.0 - metallic);
                let layer_f0 = (specular_color * ((ior - 1.0) / (ior + 1.0)).powi(2))
                    .min(DVec3::ONE)
                    * specular;
                let ks = layer_f0 * (1.0 - metallic) + base * metallic;
                let f90 = specular * (1.0 - metallic) + metallic;
                let fs = (ks + (DVec3::splat(f90) - ks) * (1.0 - co).powi(5)).element_sum();
                let p = fs / (fs + kd.element_sum());
                let material = (1.0 - p) * ci / PI + p * reflected(roughness * roughness);
                // Under a coat of weight c, the coat is chosen with probability c.
                let (c, alpha_c, _) = coat_at(coat, coat_roughness, co);
                let coat_pdf = if c > 0.0 && alpha_c >= 1e-3 {
                    reflected(alpha_c)
                } else {
                    0.0
                };
                let rest = (1.0 - c) * material + c * coat_pdf;
                // Over everything, the sheen chosen with probability s.
                match sheen_at(sheen, sheen_roughness, co) {
                    Some(l) => (1.0 - l.weight) * rest + l.weight * l.density(n, wo, wi),
                    None => rest,
                }
            }
            RefMaterial::Glossy { kd, ks, alpha } => {
                if ci <= 0.0 {
                    return 0.0;
                }
                let fs = schlick(ks, co).element_sum();
                let p = fs / (fs + kd.element_sum());
                (1.0 - p) * ci / PI + p * reflected(alpha)
            }
            RefMaterial::Conductor { alpha, .. } => {
                if ci <= 0.0 {
                    0.0
                } else {
                    reflected(alpha)
                }
            }
            RefMaterial::Dielectric { eta, alpha } => {
                if ci > 0.0 {
                    let h = (wo + wi).normalize();
                    return fresnel(wo.dot(h), eta, 0.0) * reflected(alpha);
                }
                if ci == 0.0 {
                    return 0.0;
                }
                let mut h = -(eta * wi + wo).normalize();
                if h.dot(n) < 0.0 {
                    h = -h;
                }
                let (ih, oh) = (wi.dot(h), wo.dot(h));
                if !(oh > 0.0 && ih < 0.0) {
                    return 0.0;
                }
                let t = 1.0 - fresnel(oh, eta, 0.0);
                t * vndf(h, alpha) * eta * eta * ih.abs() / (eta * ih + oh).powi(2)
            }
        }
    }
}
