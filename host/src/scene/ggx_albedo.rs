//! The GGX albedo table of `kernel::bsdf::multiple_scattering`: the directional albedo E(mu, r)
//! of the kernel's GGX lobe of glTF's material (height-correlated Smith masking-shadowing G2,
//! `microfacet::reflection_height_correlated`; Fresnel factor 1, alpha = r^2) at
//! [`ROUGHNESSES`] perceptual roughnesses r = i / 31 by [`COSINES`] cosines mu = (j / 31)^2
//! (nodes crowd toward grazing, where E falls steeply over mu < alpha), and
//! its hemispherical average E_avg(r) = 2 \int_0^1 E(mu, r) mu dmu, and the clear coat's
//! albedo (the same lobe with the exact Fresnel reflectance of index 1.5 at each microfacet,
//! `kernel::bsdf::coat`), computed here in f64 by quadrature ([`directional_albedo`],
//! [`average_albedo`], [`coat_albedo`]). The values the renderer uses are
//! the committed [`ggx_albedo_table`](super::ggx_albedo_table) (`tests/examples/
//! ggx_albedo_table.rs` writes it from these functions; `tests/tests/multiple_scattering.rs`
//! checks that it is what they give). [`add_to`] puts it in a scene's texture table.
//!
//! The quadrature: E(mu) = \int VNDF_wo(h) G2(wo, wi) / G1(wo) dh over the half vectors h with
//! wi = the mirror image of wo about h above the surface (Heitz 2014: f cos / pdf of
//! visible-normal sampling is G2 / G1(wo)). With VNDF_wo(h) dh = G1(wo) (wo . h) / (mu cos_h)
//! D(h) cos_h dh, and D(h) cos_h dh = du dphi / (2 pi) for tan^2 theta_h = alpha^2 u / (1 - u)
//! (Walter et al. 2007, eq. 35), E is the mean over (u, phi) of G2(wo, wi) (wo . h) /
//! (mu cos_h), zero where wi is below the surface, with G2 = 2 mu c_i / (a_o c_i + a_i mu),
//! a = sqrt(alpha^2 + (1 - alpha^2) c^2). phi is folded onto [0, pi) by the symmetry about wo's
//! plane, u is integrated through s = ln tan^2 theta_h up to the horizon, found exactly for each
//! phi, so each Gauss-Legendre rule integrates a smooth function ([`directional_albedo`]).

use super::error::SceneError;
pub use super::ggx_albedo_table::{AVERAGE, COAT, DIRECTIONAL};
use super::textures::TextureTable;

/// Nodes along roughness (the table's width).
pub const ROUGHNESSES: usize = 32;
/// Nodes along the cosine of `wo` (the table's height).
pub const COSINES: usize = 32;
/// Gauss-Legendre nodes along s (and, in halves, along phi) of [`directional_albedo`] in the
/// committed table.
pub const TABLE_POINTS: usize = 128;
/// Gauss-Legendre cosines of [`average_albedo`] in the committed table.
pub const AVERAGE_COSINES: usize = 64;

/// The texture table's name for the GGX albedo table (not a file: it starts with
/// `textures::TABLE_NAME_START`).
pub const NAME: &str = "<GGX albedo table>";

/// The height-correlated Smith G2 of GGX for directions at cosines `co`, `ci` > 0 and alpha^2
/// `a2`: 1 / (1 + Lambda_o + Lambda_i) = 2 co ci / (a_o ci + a_i co).
fn g2(co: f64, ci: f64, a2: f64) -> f64 {
    let a = |c: f64| (a2 + (1.0 - a2) * c * c).sqrt();
    2.0 * co * ci / (a(co) * ci + a(ci) * co)
}

/// E(`mu`, `roughness`) by quadrature with `points` nodes per axis (module doc); 1 at
/// roughness 0 (a mirror loses nothing). `mu` at 0 is taken as 1e-7 (E's limit).
///
/// For each azimuth phi of h the integrand is non-zero for theta_h below the angle at which
/// wi reaches the horizon, theta* = (pi - atan2(mu, sin_o cos phi)) / 2 (wi . n = sin_o cos phi
/// sin 2 theta_h + mu cos 2 theta_h; where it is positive, wo . h is too): Gauss-Legendre over
/// s = ln tan^2 theta_h up to theta*, where the integrand is smooth and both of its scales (the
/// lobe's peak at tan^2 ~ alpha^2, and the half vectors a grazing wo needs, near 45 degrees)
/// span a few units of s, and Gauss-Legendre over phi in [0, pi / 2] and [pi / 2, pi] with
/// `points / 2` nodes each (at grazing mu, theta* changes steeply just before pi / 2, over a
/// width ~ mu, which the rule's nodes crowding toward the ends resolve).
pub fn directional_albedo(mu: f64, roughness: f64, points: usize) -> f64 {
    integral(mu, roughness, points, |_| 1.0)
}

/// The clear coat's directional albedo (`kernel::bsdf::coat`): [`directional_albedo`] with the
/// exact Fresnel reflectance of index 1.5 at each microfacet, F(wo . h), in the integrand; F(mu)
/// at roughness 0.
pub fn coat_albedo(mu: f64, roughness: f64, points: usize) -> f64 {
    if roughness == 0.0 {
        return dielectric_fresnel(mu.clamp(1e-7, 1.0));
    }
    integral(mu, roughness, points, dielectric_fresnel)
}

/// The exact Fresnel reflectance of a dielectric of index 1.5 seen from outside at cosine `c`
/// (unpolarised: the mean of s and p; Born and Wolf 1.5.2).
pub fn dielectric_fresnel(c: f64) -> f64 {
    let eta = 1.5;
    let cos_t = (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The quadrature of [`directional_albedo`] with the factor `fresnel(wo . h)` in the integrand.
fn integral(mu: f64, roughness: f64, points: usize, fresnel: impl Fn(f64) -> f64) -> f64 {
    let alpha = roughness * roughness;
    if alpha == 0.0 {
        return 1.0;
    }
    let a2 = alpha * alpha;
    let mu = mu.clamp(1e-7, 1.0);
    let sin_o = (1.0 - mu * mu).max(0.0).sqrt();
    let (nodes, weights) = gauss_legendre(points);
    let (phi_nodes, phi_weights) = gauss_legendre(points / 2);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut sum = 0.0;
    for (half, (p, pw)) in [0.0, half_pi]
        .iter()
        .flat_map(|&start| phi_nodes.iter().zip(&phi_weights).map(move |n| (start, n)))
    {
        let phi = half + half_pi * p;
        let cos_phi = phi.cos();
        let theta_max = 0.5 * (std::f64::consts::PI - mu.atan2(sin_o * cos_phi));
        // s = ln tan^2 theta_h from 1e-12 alpha^2 to the horizon's (or 1e12 alpha^2): the
        // density of u per unit s is alpha^2 t / (alpha^2 + t)^2, t = e^s, a bump of width ~1
        // at t = alpha^2 with tails t / alpha^2 and alpha^2 / t (what lies beyond: 1e-12).
        let s_min = (a2 * 1e-12).ln();
        let s_max = if theta_max >= half_pi {
            (a2 * 1e12).ln()
        } else {
            theta_max.tan().powi(2).ln().min((a2 * 1e12).ln())
        };
        if s_max <= s_min {
            continue;
        }
        let mut row = 0.0;
        for (x, w) in nodes.iter().zip(&weights) {
            let tan2 = (s_min + (s_max - s_min) * x).exp();
            let du_ds = a2 * tan2 / ((a2 + tan2) * (a2 + tan2));
            let cos_h = 1.0 / (1.0 + tan2).sqrt();
            let sin_h = (tan2 / (1.0 + tan2)).sqrt();
            let oh = sin_o * sin_h * cos_phi + mu * cos_h;
            let wi_z = 2.0 * oh * cos_h - mu;
            if oh <= 0.0 || wi_z <= 0.0 {
                continue;
            }
            row += w * du_ds * g2(mu, wi_z, a2) * oh / cos_h * fresnel(oh);
        }
        sum += pw * half_pi * row * (s_max - s_min);
    }
    // The mean over phi in [0, pi): the rule's sum over [0, pi) divided by pi.
    sum / (mu * std::f64::consts::PI)
}

/// The `n`-point Gauss-Legendre rule on [0, 1]: nodes and weights (Newton's iteration on the
/// Legendre polynomial from the Chebyshev guesses; Numerical Recipes, section 4.6).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut nodes, mut weights) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / derivative;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        nodes[i] = 0.5 * (1.0 - x);
        weights[i] = 1.0 / ((1.0 - x * x) * derivative * derivative);
    }
    (nodes, weights)
}

/// E_avg(`roughness`) = 2 \int_0^1 E(mu) mu dmu by Gauss-Legendre over `cosines` values of mu,
/// each E by [`directional_albedo`] with `points`.
pub fn average_albedo(roughness: f64, cosines: usize, points: usize) -> f64 {
    let (nodes, weights) = gauss_legendre(cosines);
    let sum: f64 = nodes
        .iter()
        .zip(&weights)
        .map(|(&mu, w)| w * directional_albedo(mu, roughness, points) * mu)
        .sum();
    2.0 * sum
}

/// The roughness of node `i`.
pub fn roughness_of(i: usize) -> f64 {
    i as f64 / (ROUGHNESSES - 1) as f64
}

/// The cosine of node `j`: (j / (COSINES - 1))^2.
pub fn cosine_of(j: usize) -> f64 {
    (j as f64 / (COSINES - 1) as f64).powi(2)
}

/// Adds the committed table to `textures` as a float texture (texel (i, j): E(mu_j, r_i),
/// E_avg(r_i), the coat's albedo at (mu_j, r_i)) and names its record in the table's header
/// (`kernel::texture::GGX_ALBEDO`).
pub fn add_to(textures: &mut TextureTable) -> Result<u32, SceneError> {
    textures.add_table(
        NAME,
        (ROUGHNESSES, COSINES),
        |i, j| [DIRECTIONAL[j][i], AVERAGE[i], COAT[j][i]],
        kernel::texture::GGX_ALBEDO,
    )
}
