//! glTF's sheen (`kernel::bsdf::sheen`, `KHR_materials_sheen`): the committed table is what its
//! derivation from the fibre layer gives (`twinpath_tests::sheen_fit`), that derivation's
//! pieces meet their closed forms (the SGGX fibre's normal density, the walk's single
//! scattering against the closed form the fit uses), the transformed cosine is normalised, and
//! a white sheen over a white Lambertian material keeps every bit of the light in a white
//! furnace, where the sheen alone reflects what the table says.

use glam::{DVec3, Vec3};
use kernel::bsdf::eval;
use kernel::bsdf::sheen::{self, Sheen};
use kernel::features::Dynamic;
use kernel::real::V3;
use std::f64::consts::PI;
use twinpath::scene::sheen_ltc::{cosine_of, roughness_of, LTC, ROUGHNESSES};
use twinpath_tests::cubature::integrate;
use twinpath_tests::ggx_table::albedo;
use twinpath_tests::reference_bsdf::RefMaterial;
use twinpath_tests::sheen_fit::{
    fit, fit_directions, layer_values, node_seed, normal_density, phase, projected_area,
    sample_visible_normal, single_scattering, volume_reflectance, NEGLIGIBLE_REFLECTANCE,
    REFLECTANCE_WALKS,
};

#[test]
fn the_committed_table_is_what_the_derivation_gives() {
    // Two rows fitted from the roughest node down as the generator fits them, and their
    // reflectances, bit for bit (each node's walks have their own stream).
    let directions = fit_directions();
    for j in [31, 9] {
        let mut start = [1.0, 0.0];
        for i in (0..ROUGHNESSES).rev() {
            let (mu, alpha) = (cosine_of(j), roughness_of(i));
            let r = volume_reflectance(mu, alpha, REFLECTANCE_WALKS, node_seed(j, i));
            if r >= NEGLIGIBLE_REFLECTANCE {
                let values = layer_values(mu, alpha, &directions, node_seed(j, i) + 1);
                start = fit(&values, r, &directions, start);
            }
            let node = [start[0] as f32, start[1] as f32, r as f32];
            assert_eq!(node, LTC[j][i], "node (cosine {j}, roughness {i})");
        }
    }
}

/// Gauss-Legendre-like adaptive cubature of `f(w)` over the unit hemisphere (z > 0) or, with
/// `sphere`, the whole sphere, in (cos theta, phi).
fn over_directions(f: &(dyn Fn(DVec3) -> f64 + Sync), sphere: bool) -> f64 {
    let g = |c: f64, phi: f64| {
        let s = (1.0 - c * c).max(0.0).sqrt();
        f(DVec3::new(s * phi.cos(), s * phi.sin(), c))
    };
    let lower = if sphere { -1.0 } else { 0.0 };
    integrate(&g, (lower, 1.0), (0.0, 2.0 * PI), 1e-8, 14)
}

#[test]
fn the_fibre_meets_the_sggx_identities() {
    // The normal density projected onto w is the projected area sigma(w) (the SGGX
    // normalisation, Heitz et al. 2015: D counts flake area over pi per unit solid angle): for
    // thin and round fibres, along the fibre, across it and between.
    for alpha in [0.3f64, 0.7, 1.0] {
        let s = alpha * alpha;
        for w in [DVec3::Z, DVec3::X, DVec3::new(0.6, 0.0, 0.8)] {
            let projected = over_directions(&|m| m.dot(w).max(0.0) * normal_density(m, s), true);
            let sigma = projected_area(w, s);
            assert!(
                (projected - sigma).abs() < 1e-4 * sigma.max(1.0),
                "alpha {alpha}, w {w}: {projected} vs sigma {sigma}"
            );
        }
    }
}

#[test]
fn the_walk_scatters_once_as_the_closed_form_says() {
    // The light that leaves upward right after the first scattering, by walks (a visible
    // normal drawn, the mirror direction, the attenuation on the way up), against the integral
    // of the closed-form single scattering the fit uses: what ties the walk's sampler to the
    // density and phase function of the closed form. A binomial-like z-test per case.
    let mut failures = Vec::new();
    for (mu, alpha) in [(0.9f64, 1.0f64), (0.5, 0.6), (0.2, 0.4), (0.7, 0.3)] {
        let s = alpha * alpha;
        let wi = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let closed = over_directions(&|wo| single_scattering(wi, wo, s), false);
        // The first event's depth z has density rate e^{-rate t} along -wi (t = z / mu),
        // truncated at the bottom; the walk weighs the escape by exp(-z sigma(wo) / mu_o).
        let mut g = twinpath_tests::SplitMix(0x5eed_0001 ^ (mu * 1e4) as u64);
        let n = 400_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let dir = -wi;
            let rate = projected_area(dir, s);
            let t = -(1.0 - g.unit() as f64).ln() / rate;
            let z = t * mu;
            let mut value = 0.0;
            if z <= 1.0 {
                let m = sample_visible_normal(wi, s, g.unit() as f64, g.unit() as f64);
                let out = 2.0 * m.dot(wi) * m - wi;
                if out.z > 0.0 {
                    value = (-z * projected_area(out, s) / out.z).exp();
                }
            }
            sum += value;
            sum2 += value * value;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        let z = (mean - closed) / se;
        println!("mu {mu}, alpha {alpha}: walks {mean:.5} +- {se:.1e}, closed form {closed:.5} (z {z:+.2})");
        if z.abs() > twinpath_tests::z_critical(1e-3, 4) {
            failures.push(format!("mu {mu}, alpha {alpha}: z {z:.2}"));
        }
        // The phase function is a density over directions.
        let total = over_directions(&|wo| phase(wi, wo, s), true);
        assert!((total - 1.0).abs() < 1e-3, "phase integrates to {total}");
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn the_transformed_cosine_is_normalised() {
    // Any A > 0 and B, from the table's range: the density integrates to 1 over the hemisphere
    // (a transformed cosine never reaches below it: w_z is kept).
    for (a, b) in [
        (1.0f32, 0.0f32),
        (0.8, -0.01),
        (0.4, -0.1),
        (0.2, -0.17),
        (0.06, -0.1),
    ] {
        let lobe = Sheen {
            reflectance: V3::splat(Vec3::ONE),
            weight: 1.0,
            a,
            b,
        };
        for mu in [0.05f32, 0.5, 1.0] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let total = over_directions(
                &|w| sheen::pdf(&lobe, V3::splat(Vec3::Z), wo.into(), w.as_vec3().into()) as f64,
                false,
            );
            assert!(
                (total - 1.0).abs() < 2e-3,
                "A {a}, B {b}, mu {mu}: integrates to {total}"
            );
        }
    }
}

#[test]
fn a_white_sheen_over_a_white_surface_keeps_every_bit_of_the_light() {
    // glTF's material, white and Lambertian (no specular layer: KHR_materials_specular factor
    // 0), under a white sheen: the sheen reflects R (the table's, at this view and roughness)
    // and the surface 1 - R of the light from everywhere, exactly 1 together; the sheen alone
    // (over black) reflects R.
    for roughness in [0.3f64, 0.5, 1.0] {
        for &mu in &[0.1f32, 0.45, 0.9] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let mut reflected = [0.0; 2];
            for (k, base) in [DVec3::ONE, DVec3::ZERO].into_iter().enumerate() {
                let mut m = RefMaterial::gltf(base, 0.0, 1.0).sheened(DVec3::ONE, roughness);
                if let RefMaterial::MetallicRoughness { specular, .. } = &mut m {
                    *specular = 0.0;
                }
                let km = m.kernel_at_hit();
                let a = albedo(&km, Vec3::Z, wo);
                let total = over_directions(
                    &|w| eval(Dynamic(0), &km, Vec3::Z, wo, w.as_vec3(), 1.0, a).0.x as f64,
                    false,
                );
                reflected[k] = total;
            }
            let r = albedo(
                &RefMaterial::gltf(DVec3::ONE, 0.0, 1.0)
                    .sheened(DVec3::ONE, roughness)
                    .kernel_at_hit(),
                Vec3::Z,
                wo,
            )
            .sheen
            .z as f64;
            println!(
                "sheen roughness {roughness}, mu {mu}: over white {:.6}, alone {:.6} (R {r:.6})",
                reflected[0], reflected[1]
            );
            assert!(
                (reflected[0] - 1.0).abs() < 2e-3,
                "over white: {}",
                reflected[0]
            );
            assert!(
                (reflected[1] - r).abs() < 2e-3 * r.max(0.05),
                "alone: {} vs R {r}",
                reflected[1]
            );
        }
    }
}
