//! The energy GGX loses between microfacets, given back (`kernel::bsdf::multiple_scattering`,
//! glTF's metallic-roughness material): the committed albedo table is what its quadrature
//! gives, the quadrature has converged and meets a closed form, and a rough metal of
//! reflectance 1 reflects all the light in a white furnace (within the table's derived
//! interpolation bound), where without the compensation it loses up to 69%; under a clear coat
//! too (what the coat takes it reflects).

use glam::{DVec3, Vec3};
use kernel::bsdf::multiple_scattering::GlossyAlbedo;
use kernel::bsdf::{eval, DELTA_ALPHA};
use kernel::features::Dynamic;
use std::f64::consts::PI;
use twinpath::scene::ggx_albedo::{
    average_albedo, coat_albedo, cosine_of, directional_albedo, roughness_of, AVERAGE,
    AVERAGE_COSINES, COAT, COSINES, DIRECTIONAL, ROUGHNESSES, TABLE_POINTS,
};
use twinpath_tests::cubature::integrate;
use twinpath_tests::ggx_table::albedo;
use twinpath_tests::reference_bsdf::RefMaterial;

#[test]
fn the_committed_table_is_what_the_quadrature_gives() {
    // Every fifth node (and the last row and column), and three averages: bit for bit, so the
    // file was written by `tests/examples/ggx_albedo_table.rs` from this quadrature.
    let picks = |n: usize| (0..n).step_by(5).chain([n - 1]).collect::<Vec<_>>();
    let mut checked = 0;
    for j in picks(COSINES) {
        for i in picks(ROUGHNESSES) {
            let e = directional_albedo(cosine_of(j), roughness_of(i), TABLE_POINTS) as f32;
            assert_eq!(e, DIRECTIONAL[j][i], "E at node ({i}, {j})");
            checked += 1;
        }
    }
    for i in [3, 17, ROUGHNESSES - 1] {
        let a = average_albedo(roughness_of(i), AVERAGE_COSINES, TABLE_POINTS) as f32;
        assert_eq!(a, AVERAGE[i], "E_avg at roughness node {i}");
    }
    println!("{checked} nodes and 3 averages equal the committed table");
}

#[test]
fn the_quadrature_converged_and_meets_the_closed_form() {
    // At normal incidence and alpha 1, wi . n = cos 2 theta_h = 1 - 2u and G1(c) = 2c / (1 + c):
    // E = \int_0^{1/2} 2 (1 - 2u) / (2 - 2u) du = 1 - ln 2. The quadrature leaves out the
    // half vectors beyond tan^2 = 1e12 alpha^2 and below 1e-12 alpha^2: 1e-12 of the measure
    // each, with integrand at most 1.
    let e = directional_albedo(1.0, 1.0, TABLE_POINTS);
    assert!((e - (1.0 - 2f64.ln())).abs() < 2e-12, "E(1, 1) = {e}");
    // Doubling the points moves no value by more than 1e-6 (the table's stated accuracy),
    // grazing and nearly smooth included.
    let mut worst = 0f64;
    for &mu in &[0.0, 1e-3, 0.05, 0.3, 0.7, 1.0] {
        for &r in &[1.0 / 31.0, 0.1, 0.3, 0.6, 1.0] {
            let (a, b) = (
                directional_albedo(mu, r, TABLE_POINTS),
                directional_albedo(mu, r, 2 * TABLE_POINTS),
            );
            worst = worst.max((a - b).abs());
        }
    }
    println!(
        "largest change from {TABLE_POINTS} to {} points: {worst:.2e}",
        2 * TABLE_POINTS
    );
    assert!(worst < 1e-6, "{worst:.2e}");
    // The average: Gauss-Legendre in mu with twice the cosines agrees likewise.
    for r in [0.2, 0.6, 1.0] {
        let a = average_albedo(r, AVERAGE_COSINES, TABLE_POINTS);
        let b = average_albedo(r, 2 * AVERAGE_COSINES, TABLE_POINTS);
        assert!((a - b).abs() < 1e-6, "E_avg({r}): {a} vs {b}");
    }
}

/// The albedo \int f cos dwi of material `km` (resolved) from `wo` at normal +Z, by adaptive
/// cubature over the hemisphere (cos theta_i, phi), phi folded by symmetry.
fn directional_reflectance(km: &kernel::scene::Material, wo: Vec3, a: GlossyAlbedo) -> DVec3 {
    let n = Vec3::Z;
    let channel = |c: usize| {
        let f = |cos_i: f64, phi: f64| {
            let s = (1.0 - cos_i * cos_i).max(0.0).sqrt();
            let wi = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, cos_i as f32);
            eval(Dynamic(0), km, n, wo, wi, 1.0, a).0[c] as f64
        };
        2.0 * integrate(&f, (0.0, 1.0), (0.0, PI), 1e-7, 12)
    };
    DVec3::new(channel(0), channel(1), channel(2))
}

/// The bound on the table's bilinear interpolation error at (roughness, sqrt(mu)) in the cell
/// with lower node (i, j): (h_x^2 max|E_xx| + h_y^2 max|E_yy|) / 8 (the error of linear
/// interpolation, per axis), the second derivatives times h^2 being the largest second
/// differences over the cell's nodes and their neighbours; plus the quadrature's 1e-6.
fn interpolation_bound(i: usize, j: usize) -> f64 {
    interpolation_bound_of(&DIRECTIONAL, i, j)
}

/// [`interpolation_bound`] of table `table` (E's or the coat's).
fn interpolation_bound_of(table: &[[f32; ROUGHNESSES]; COSINES], i: usize, j: usize) -> f64 {
    let e = |j: usize, i: usize| table[j][i] as f64;
    let mut dxx = 0f64;
    let mut dyy = 0f64;
    for jj in j.saturating_sub(1)..=(j + 2).min(COSINES - 1) {
        for ii in i.saturating_sub(1)..=(i + 2).min(ROUGHNESSES - 1) {
            if ii > 0 && ii + 1 < ROUGHNESSES {
                dxx = dxx.max((e(jj, ii - 1) - 2.0 * e(jj, ii) + e(jj, ii + 1)).abs());
            }
            if jj > 0 && jj + 1 < COSINES {
                dyy = dyy.max((e(jj - 1, ii) - 2.0 * e(jj, ii) + e(jj + 1, ii)).abs());
            }
        }
    }
    (dxx + dyy) / 8.0 + 1e-6
}

#[test]
fn a_rough_metal_of_reflectance_one_passes_the_white_furnace() {
    let mut worst_ratio = 0f64;
    let mut lowest_uncompensated = 1f64;
    for &roughness in &[0.25, 0.5, 0.7, 0.9, 1.0] {
        // A metal of base colour 1: F = 1 at every angle, so all the light must come back.
        let m = RefMaterial::gltf(DVec3::ONE, 1.0, roughness);
        let km = m.kernel_at_hit();
        assert!(km.alpha >= DELTA_ALPHA);
        // Cosines between the nodes (where interpolation errs most) and on them.
        for &mu in &[0.04f32, 0.1, 0.3, 0.55, 0.8, 1.0] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let a = albedo(&km, Vec3::Z, wo);
            let reflected = directional_reflectance(&km, wo, a);
            let single = directional_reflectance(&km, wo, GlossyAlbedo::NONE);
            lowest_uncompensated = lowest_uncompensated.min(single.x);
            let x = roughness * (ROUGHNESSES - 1) as f64;
            let y = (mu as f64).sqrt() * (COSINES - 1) as f64;
            let (i, j) = (
                (x.floor() as usize).min(ROUGHNESSES - 2),
                (y.floor() as usize).min(COSINES - 2),
            );
            // reflected = E_true / E_table: off 1 by the table's error over E; the cubature
            // adds at most 1e-5.
            let bound = interpolation_bound(i, j) / single.x + 1e-5;
            for c in 0..3 {
                let off = (reflected[c] - 1.0).abs();
                worst_ratio = worst_ratio.max(off / bound);
                assert!(
                    off <= bound,
                    "roughness {roughness}, mu {mu}: reflects {:.5} (single scattering {:.5}), \
                     bound {bound:.2e}",
                    reflected[c],
                    single.x
                );
            }
        }
    }
    println!(
        "white furnace: worst |albedo - 1| is {worst_ratio:.2} of its bound; without the \
         compensation the albedo falls to {lowest_uncompensated:.4}"
    );
    assert!(
        lowest_uncompensated < 0.5,
        "the furnace would not see the loss"
    );
}

#[test]
fn a_clear_coat_over_the_furnace_metal_keeps_every_bit_of_the_light() {
    // Under a coat (`kernel::bsdf::coat`) the metal of reflectance 1 keeps 1 - c of its albedo 1
    // and the coat's lobe reflects what it takes, c, its own albedo: the sum is 1, off only by the
    // tables' interpolation (the metal's E and the coat's albedo) and the cubature.
    let mut worst_ratio = 0f64;
    for &(roughness, coat, coat_roughness) in &[(0.5, 1.0, 0.3), (0.9, 0.6, 0.7), (0.3, 0.8, 1.0)] {
        let m = RefMaterial::gltf(DVec3::ONE, 1.0, roughness).coated(coat, coat_roughness);
        let km = m.kernel_at_hit();
        for &mu in &[0.1f32, 0.45, 0.9] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let reflected = directional_reflectance(&km, wo, albedo(&km, Vec3::Z, wo));
            let (c, _, k) =
                twinpath_tests::reference_bsdf::coat_at(coat, coat_roughness, mu as f64);
            let cell = |r: f64| {
                let x = r * (ROUGHNESSES - 1) as f64;
                let y = (mu as f64).sqrt() * (COSINES - 1) as f64;
                (
                    (x.floor() as usize).min(ROUGHNESSES - 2),
                    (y.floor() as usize).min(COSINES - 2),
                )
            };
            let (i, j) = cell(roughness);
            let (ic, jc) = cell(coat_roughness);
            let e = directional_albedo(mu as f64, roughness, TABLE_POINTS);
            let bound = (1.0 - c) * interpolation_bound(i, j) / e
                + coat * k * interpolation_bound_of(&COAT, ic, jc)
                + 1e-5;
            for ch in 0..3 {
                let off = (reflected[ch] - 1.0).abs();
                worst_ratio = worst_ratio.max(off / bound);
                assert!(
                    off <= bound,
                    "roughness {roughness}, coat {coat} of roughness {coat_roughness}, mu {mu}: \
                     reflects {:.5} (c {c:.4}), bound {bound:.2e}",
                    reflected[ch]
                );
            }
        }
    }
    println!("coated furnace: worst |albedo - 1| is {worst_ratio:.2} of its bound");
}

#[test]
fn the_coat_table_and_fresnel_average_are_their_integrals() {
    // The coat's albedo at a few nodes, bit for bit; F_avg of index 1.5 against the reference's
    // own quadrature.
    for (j, i) in [(3, 4), (17, 9), (31, 31), (0, 20)] {
        let a = coat_albedo(cosine_of(j), roughness_of(i), TABLE_POINTS) as f32;
        assert_eq!(a, COAT[j][i], "coat albedo at node ({i}, {j})");
    }
    let f_avg = twinpath_tests::reference_bsdf::coat_fresnel_average();
    let kernel = kernel::bsdf::multiple_scattering::COAT_FRESNEL_AVERAGE as f64;
    assert!((kernel - f_avg).abs() < 1e-7, "{kernel} vs {f_avg}");
}
